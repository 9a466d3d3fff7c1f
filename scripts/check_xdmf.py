#!/usr/bin/python3
"""Check a dcm XDMF file against the HDF5 file(s) it references.

Usage: /usr/bin/python3 scripts/check_xdmf.py out/run.xmf

Every <DataItem Format="HDF"> must name an existing dataset ("file.h5:/path", the file relative to the
.xmf) whose shape and number type match what the XDMF declares. Prints "xdmf ok: N frames" (N = the
Uniform grids of the temporal collection, 0 for a static mesh) or one line "xdmf error: ..." and exits 1.
Works on the files of a running simulation (HDF5 file locking is turned off for this read-only check).
"""
import os
import sys
import xml.etree.ElementTree as ET

os.environ.setdefault("HDF5_USE_FILE_LOCKING", "FALSE")

import h5py  # noqa: E402  (after the environment is set)
import numpy as np  # noqa: E402


class CheckError(Exception):
    pass


# XDMF (NumberType, Precision) -> numpy kind and item size.
NUMBER_TYPES = {("Int", "4"): ("i", 4), ("Int", "8"): ("i", 8), ("UInt", "4"): ("u", 4),
                ("Float", "4"): ("f", 4), ("Float", "8"): ("f", 8)}


class H5Files:
    """Opens each referenced HDF5 file once."""

    def __init__(self, folder):
        self.folder = folder
        self.open = {}

    def get(self, name):
        if name not in self.open:
            path = os.path.join(self.folder, name)
            try:
                self.open[name] = h5py.File(path, "r")
            except OSError as e:
                raise CheckError(f"cannot open {path}: {e}")
        return self.open[name]

    def close(self):
        for f in self.open.values():
            f.close()


def check_data_item(item, files):
    """Checks one HDF DataItem; returns its declared dimensions as a tuple."""
    ref = (item.text or "").strip()
    if item.get("Format") != "HDF":
        raise CheckError(f"DataItem {ref[:40]!r} is not Format=\"HDF\"")
    name, sep, path = ref.partition(":")
    if not sep or not path.startswith("/"):
        raise CheckError(f"DataItem reference {ref!r} is not 'file.h5:/path'")
    try:
        dims = tuple(int(d) for d in item.get("Dimensions", "").split())
    except ValueError:
        raise CheckError(f"{ref}: bad Dimensions {item.get('Dimensions')!r}")
    obj = files.get(name).get(path)
    if not isinstance(obj, h5py.Dataset):
        raise CheckError(f"{ref}: no such dataset")
    if obj.shape != dims:
        raise CheckError(f"{ref}: XDMF declares Dimensions {dims}, the dataset has shape {obj.shape}")
    kind = NUMBER_TYPES.get((item.get("NumberType", "Float"), item.get("Precision", "4")))
    if kind is None:
        raise CheckError(f"{ref}: unsupported NumberType/Precision")
    if (obj.dtype.kind, obj.dtype.itemsize) != kind:
        raise CheckError(f"{ref}: XDMF declares {kind}, the dataset is {obj.dtype}")
    return dims


def only_child(elem, tag, where):
    found = elem.findall(tag)
    if len(found) != 1:
        raise CheckError(f"{where}: expected one <{tag}>, found {len(found)}")
    return found[0]


def check_uniform_grid(grid, files):
    where = f"grid {grid.get('Name')!r}"
    topology = only_child(grid, "Topology", where)
    if topology.get("TopologyType") != "Triangle":
        raise CheckError(f"{where}: TopologyType is not Triangle")
    tri_dims = check_data_item(only_child(topology, "DataItem", where), files)
    if len(tri_dims) != 2 or tri_dims[1] != 3 or str(tri_dims[0]) != topology.get("NumberOfElements"):
        raise CheckError(f"{where}: triangles {tri_dims} do not match NumberOfElements")
    geometry = only_child(grid, "Geometry", where)
    if geometry.get("GeometryType") != "XYZ":
        raise CheckError(f"{where}: GeometryType is not XYZ")
    x_dims = check_data_item(only_child(geometry, "DataItem", where), files)
    if len(x_dims) != 2 or x_dims[1] != 3:
        raise CheckError(f"{where}: geometry dimensions {x_dims} are not [n][3]")
    for attr in grid.findall("Attribute"):
        dims = check_data_item(only_child(attr, "DataItem", where), files)
        expected = (x_dims[0],) if attr.get("AttributeType") == "Scalar" else (x_dims[0], 3)
        if attr.get("Center") != "Node" or dims != expected:
            name = attr.get("Name")
            raise CheckError(f"{where}: attribute {name!r} is not a node field of shape {expected}")


def check(xmf_path):
    """Returns the number of frames."""
    try:
        root = ET.parse(xmf_path).getroot()
    except (OSError, ET.ParseError) as e:
        raise CheckError(f"cannot parse: {e}")
    if root.tag != "Xdmf" or root.get("Version") != "3.0":
        raise CheckError("root element is not <Xdmf Version=\"3.0\">")
    grid = only_child(only_child(root, "Domain", "Xdmf"), "Grid", "Domain")
    files = H5Files(os.path.dirname(os.path.abspath(xmf_path)))
    try:
        if grid.get("GridType", "Uniform") == "Uniform":
            check_uniform_grid(grid, files)
            return 0
        if grid.get("GridType") != "Collection" or grid.get("CollectionType") != "Temporal":
            raise CheckError("top grid is neither Uniform nor a Temporal Collection")
        frames = grid.findall("Grid")
        times = []
        for frame in frames:
            times.append(float(only_child(frame, "Time", f"grid {frame.get('Name')!r}").get("Value")))
            check_uniform_grid(frame, files)
        if np.any(np.diff(times) < 0):
            raise CheckError("frame times decrease")
        return len(frames)
    finally:
        files.close()


def main():
    if len(sys.argv) == 2 and sys.argv[1] in ("-h", "--help"):
        print(__doc__)
        return 0
    if len(sys.argv) != 2 or sys.argv[1].startswith("-"):
        print("usage: check_xdmf.py FILE.xmf", file=sys.stderr)
        return 2
    try:
        n = check(sys.argv[1])
    except (CheckError, ValueError, KeyError, OSError) as e:
        print(f"xdmf error: {sys.argv[1]}: " + " ".join(str(e).split()))
        return 1
    print(f"xdmf ok: {n} frames")
    return 0


if __name__ == "__main__":
    sys.exit(main())

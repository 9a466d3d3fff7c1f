"""Opens every XDMF file dcm wrote under the given folders in ParaView, as a user would, and checks what it reads.

usage: pvbatch scripts/check_paraview.py DIR [DIR ...]      (Debian: apt-get install paraview python3-paraview)

For each *.xmf (with its .h5 beside it): ParaView's XDMF reader (Xdmf 2) and its Xdmf3 readers (S and T) must
read as many points and triangles as /mesh holds, one time step per /frames group (or one static grid without
frames), and every per-node field of the last frame as a point array. Prints a line per file and reader; exit
status 0 if all read right, 1 otherwise, 2 on bad usage. (Plain h5py, not ParaView, reads the .h5 side.)
"""
import os
import sys

if __name__ == "__main__" and any(a in ("-h", "--help") for a in sys.argv[1:]):
    print(__doc__.strip())
    sys.exit(0)

from paraview import servermanager  # noqa: F401  (pvbatch's Python)
from paraview.simple import Delete, XDMFReader, Xdmf3ReaderS, Xdmf3ReaderT

import h5py  # the .h5 side (Debian: python3-h5py, which pvbatch's Python sees)


def expected(h5_path):
    """(points, triangles, frames, last frame's field names) from the .h5 file."""
    with h5py.File(h5_path, "r") as f:
        points, tris = f["mesh/x"].shape[0], f["mesh/triangles"].shape[0]
        frames = sorted(f["frames"].keys()) if "frames" in f else []
        fields = sorted(k for k in f["frames"][frames[-1]].keys() if k != "x") if frames else []
    return points, tris, len(frames), fields


def check(path):
    problems = []
    want = expected(os.path.splitext(path)[0] + ".h5")
    for name, make in (("XDMFReader", lambda: XDMFReader(FileNames=[path])),
                       ("Xdmf3ReaderS", lambda: Xdmf3ReaderS(FileName=[path])),
                       ("Xdmf3ReaderT", lambda: Xdmf3ReaderT(FileName=[path]))):
        try:
            reader = make()
            reader.UpdatePipelineInformation()
            times = list(reader.TimestepValues) if reader.TimestepValues else []
            reader.UpdatePipeline(times[-1] if times else 0.0)
            info = reader.GetDataInformation()
            points, cells = info.GetNumberOfPoints(), info.GetNumberOfCells()
            arrays = sorted(reader.PointData.keys())
            Delete(reader)
        except Exception as error:  # a reader that cannot open the file at all
            problems.append(f"{path} [{name}]: cannot read: {type(error).__name__}: {error}")
            continue
        line = f"{path} [{name}]: {points} points, {cells} triangles, {len(times)} time steps, arrays {arrays}"
        w_points, w_tris, w_frames, w_fields = want
        if points != w_points or cells != w_tris:
            problems.append(f"{line}: the .h5 has {w_points} nodes and {w_tris} triangles")
        elif len(times) != w_frames and not (w_frames <= 1 and len(times) <= 1):  # one frame: no time axis
            problems.append(f"{line}: the .h5 has {w_frames} frames")
        elif any(f not in arrays for f in w_fields):
            problems.append(f"{line}: fields of the .h5's last frame not read: "
                            f"{[f for f in w_fields if f not in arrays]}")
        else:
            print(line)
    return problems


def main(argv):
    if len(argv) < 2 or argv[1] in ("-h", "--help"):
        print(__doc__.strip())
        return 0 if len(argv) >= 2 else 2
    problems, files = [], 0
    for root in argv[1:]:
        if not os.path.isdir(root):
            print(f"check_paraview: {root} is not a folder", file=sys.stderr)
            return 2
        for folder, _, names in os.walk(root):
            for name in sorted(names):
                if name.endswith(".xmf"):
                    files += 1
                    problems += check(os.path.join(folder, name))
    for p in problems:
        print("PROBLEM:", p)
    print(f"{files} XDMF files opened with 3 ParaView readers each, {len(problems)} problems")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))

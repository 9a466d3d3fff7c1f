#!/usr/bin/env python3
"""Makes a checkpoint look older: removes the lines of one key from its resolved scene (texts/scene), as a
checkpoint written before the key existed holds it.   strip_checkpoint_key.py CHECKPOINT KEY_LEAF"""
import os
import sys

os.environ.setdefault("HDF5_USE_FILE_LOCKING", "FALSE")
import h5py  # noqa: E402


def main():
    path, leaf = sys.argv[1], sys.argv[2]
    with h5py.File(path, "r+") as f:
        text = f["texts/scene"][()]
        text = text.decode() if isinstance(text, bytes) else str(text)
        kept = [line for line in text.splitlines() if line.split("=")[0].strip() != leaf]
        if len(kept) == len(text.splitlines()):
            print(f"strip_checkpoint_key: {path}: no key {leaf} in its scene")
            return 1
        del f["texts/scene"]
        f.create_dataset("texts/scene", data="\n".join(kept) + "\n", dtype=h5py.string_dtype())
    print(f"strip_checkpoint_key: {path}: {leaf} removed from its scene")
    return 0


if __name__ == "__main__":
    sys.exit(main())

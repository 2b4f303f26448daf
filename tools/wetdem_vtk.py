"""Reads the VTK files of a wetdem many-particle run into numpy arrays (docs/many.md, "From
Python"): particle frames PREFIX_NNNNNN.vtk and links PREFIX_links_NNNNNN.vtk, legacy POLYDATA
in ASCII or big-endian binary (src/output_vtk.c), and their ParaView .vtk.series indexes.

    import sys; sys.path.insert(0, "tools")
    from wetdem_vtk import read_series, read_vtk
    for time, path in read_series("out/settling/particles_links.vtk.series"):
        links = read_vtk(path)          # {"force_normal": array, "i": array, ...}

Usage: /usr/bin/python3 tools/wetdem_vtk.py FILE.vtk   (prints the arrays, their shapes and
ranges). Needs numpy (Debian python3-numpy).
"""
import json
import os
import sys

import numpy as np


# The arrays of a frame (point data) and of a links file (cell data), in the order
# src/output_vtk.c writes them, with their numbers of components.
POINT_ARRAYS = {"radius": 1, "velocity": 3, "spin": 3, "contacts": 1, "bridges": 1,
                "agglomerate": 1, "material": 1, "id": 1, "fixed": 1}
LINK_ARRAYS = {"i": 1, "j": 1, "contact": 1, "bridge": 1, "gap": 1, "force_normal": 1,
               "force_tangential": 1, "force": 3}


def read_vtk(path):
    """The arrays of a frame or links file written by wetdem (legacy POLYDATA, ASCII or
    big-endian binary: src/output_vtk.c) as {name: array}: TIME, POINTS (n x 3), VERTICES or
    LINES, and every point array (radius, velocity n x 3, spin, contacts, bridges,
    agglomerate, material, id, fixed) or cell array (i, j, contact, bridge, gap, force_normal,
    force_tangential, force n x 3)."""
    data = open(path, "rb").read()
    binary = data.split(b"\n", 3)[2].strip() == b"BINARY"
    at, out = 0, {}

    def line():
        nonlocal at
        end = data.index(b"\n", at)
        words = data[at:end].decode().split()
        at = end + 1
        return words

    def values(count, kind):  # count values of kind "double" or "int"
        nonlocal at
        if binary:
            dtype = ">f8" if kind == "double" else ">i4"
            a = np.frombuffer(data, dtype, count, at)
            at += a.nbytes + 1  # the data, then its newline
            # native float64 / int64, writable, as the ASCII branch gives (frombuffer's view is
            # big-endian and read-only: an in-place edit raised "output array is read-only")
            return a.astype(float if kind == "double" else int)
        got = []
        while len(got) < count:
            got += line()
        return np.array(got, float if kind == "double" else int)

    for _ in range(4):  # version, title, format, dataset
        line()
    while at < len(data):
        w = line()
        if not w or w[0] in ("FIELD", "POINT_DATA", "CELL_DATA"):
            continue
        if w[0] == "POINTS":
            out["POINTS"] = values(3 * int(w[1]), w[2]).reshape(-1, 3)
        elif w[0] in ("VERTICES", "LINES"):
            out[w[0]] = values(int(w[2]), "int")
        else:  # a field array: name, components, tuples, type
            a = values(int(w[1]) * int(w[2]), w[3])
            out[w[0]] = a.reshape(-1, int(w[1])) if int(w[1]) > 1 else a
    return out


def read_series(path):
    """[(time [s], path of the file)] of a .vtk.series index, in its order."""
    series = json.load(open(path))
    here = os.path.dirname(path)
    return [(e["time"], os.path.join(here, e["name"])) for e in series["files"]]


def main():
    if len(sys.argv) != 2:
        print("usage: /usr/bin/python3 tools/wetdem_vtk.py FILE.vtk", file=sys.stderr)
        sys.exit(2)
    for name, a in read_vtk(sys.argv[1]).items():
        a = np.asarray(a)
        span = f"{a.min():.6g} .. {a.max():.6g}" if a.size else "empty"
        print(f"{name:18s} {str(a.shape):14s} {span}")


if __name__ == "__main__":
    main()

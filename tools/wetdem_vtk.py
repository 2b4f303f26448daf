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
    force_tangential, force n x 3). A file that is cut short or does not hold what its
    headers announce (FIELD counts, POINT_DATA / CELL_DATA tuples, the binary blocks'
    newlines) raises ValueError naming the file: a frame cut by a crash is not returned with
    arrays missing."""
    data = open(path, "rb").read()
    try:
        return _parse_vtk(data)
    except (ValueError, IndexError, UnicodeDecodeError) as e:
        raise ValueError(f"{path}: not a whole wetdem VTK file (truncated or corrupt?): {e}") \
            from None


def _parse_vtk(data):
    head = data.split(b"\n", 4)
    if len(head) < 5 or not head[0].startswith(b"# vtk DataFile"):
        raise ValueError("no '# vtk DataFile' header of 4 lines")
    binary = head[2].strip() == b"BINARY"
    at, out = 0, {}

    def line():
        nonlocal at
        end = data.find(b"\n", at)
        if end < 0:
            raise ValueError(f"the file ends inside a line at byte {at}")
        words = data[at:end].decode().split()
        at = end + 1
        return words

    def values(count, kind):  # count values of kind "double" or "int"
        nonlocal at
        if binary:
            dtype = ">f8" if kind == "double" else ">i4"
            a = np.frombuffer(data, dtype, count, at)
            if data[at + a.nbytes:at + a.nbytes + 1] != b"\n":
                raise ValueError(f"no newline after a binary block at byte {at + a.nbytes}")
            at += a.nbytes + 1  # the data, then its newline
            # native float64 / int64, writable, as the ASCII branch gives (frombuffer's view is
            # big-endian and read-only: an in-place edit raised "output array is read-only")
            return a.astype(float if kind == "double" else int)
        got = []
        while len(got) < count:
            got += line()
        if len(got) != count:
            raise ValueError(f"{len(got)} values where {count} were announced")
        return np.array(got, float if kind == "double" else int)

    for _ in range(4):  # version, title, format, dataset
        line()
    field_left, tuples = 0, None  # arrays still due in the FIELD block; tuples of the data
    while at < len(data):
        w = line()
        if not w:
            continue
        if w[0] == "FIELD":
            if field_left:
                raise ValueError(f"a FIELD block with {field_left} arrays missing")
            field_left = int(w[2])
        elif w[0] in ("POINT_DATA", "CELL_DATA"):
            tuples = int(w[1])
        elif w[0] == "POINTS":
            out["POINTS"] = values(3 * int(w[1]), w[2]).reshape(-1, 3)
        elif w[0] in ("VERTICES", "LINES"):
            out[w[0]] = values(int(w[2]), "int")
        else:  # a field array: name, components, tuples, type
            if not field_left:
                raise ValueError(f"array {w[0]} outside a FIELD block or beyond its count")
            if tuples is not None and int(w[2]) != tuples:
                raise ValueError(f"array {w[0]} has {w[2]} tuples, the data {tuples}")
            a = values(int(w[1]) * int(w[2]), w[3])
            out[w[0]] = a.reshape(-1, int(w[1])) if int(w[1]) > 1 else a
            field_left -= 1
    if field_left:
        raise ValueError(f"the file ends with {field_left} arrays of its FIELD block missing")
    if "POINTS" not in out or "TIME" not in out:
        raise ValueError("no POINTS or no TIME")
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

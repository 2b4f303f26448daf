"""Reads a many-particle run's VTK output with VTK's own legacy reader, the one ParaView uses
for .vtk files, and checks it (scripts/validate.d/42-vtk.sh; docs/many.md, Outputs):

- every .vtk.series index is the JSON ParaView reads ("file-series-version" "1.0", a list of
  name and time), its times increase, and each file it names exists;
- every frame is POLYDATA that VTK reads without an error, with one vertex a particle, the
  point arrays of docs/many.md with their components, and a TIME field equal to the time the
  index gives it;
- every links file is POLYDATA of one line a link, with its cell arrays; the line starts at
  particle i's centre in the frame of the same number and is |x_i - x_j| = R_i + R_j + gap
  long (nearest periodic image) or R_i + gap to a wall; its force vector is the sum of its
  normal and tangential parts (|F|^2 = F_n^2 + F_t^2);
- each array VTK reads is bit for bit the one tools/wetdem_vtk.py reads, so that the figure
  scripts and ParaView see the same numbers;
- with --same DIR_A DIR_B, two runs of one scenario written in binary and in ASCII (17
  digits) give bit-identical arrays.

Usage: /usr/bin/python3 tools/check_vtk_with_vtk.py RUN_DIR...  [--same DIR_A DIR_B] [--all-kinds]
With --all-kinds, the links checked must include pairs, pairs across a periodic face and
particle-wall links, so that the geometry check has met each.
Exit 0 when every check holds, 1 otherwise (each failure is printed). Needs Debian's
python3-vtk9 and python3-numpy.
"""
import json
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from wetdem_vtk import LINK_ARRAYS, POINT_ARRAYS, read_series, read_vtk  # noqa: E402

try:
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkCommonCore import vtkCommand
    from vtkmodules.vtkIOLegacy import vtkPolyDataReader
except ImportError:
    print("check_vtk_with_vtk: needs VTK's Python module (Debian package python3-vtk9)",
          file=sys.stderr)
    sys.exit(2)

failures = []
link_kinds = {"pair": 0, "periodic": 0, "wall": 0}  # links checked, by kind


def fail(where, what):
    failures.append(f"{where}: {what}")
    print(f"  FAIL {where}: {what}")


def vtk_read(path):
    """The file read by VTK's legacy POLYDATA reader as {name: array}, with POINTS, the cells
    (VERTS, LINES as lists of point ids) and the field data; None when VTK reports an error."""
    reader = vtkPolyDataReader()
    errors = []
    for event in (vtkCommand.ErrorEvent, vtkCommand.WarningEvent):
        reader.AddObserver(event, lambda obj, ev: errors.append(ev))
    reader.SetFileName(path)
    reader.ReadAllScalarsOn()
    reader.ReadAllVectorsOn()
    reader.ReadAllFieldsOn()
    reader.Update()
    if errors or not reader.IsFilePolyData():
        fail(path, "VTK's reader reports an error or a warning, or does not see POLYDATA")
        return None
    poly = reader.GetOutput()
    out = {"POINTS": vtk_to_numpy(poly.GetPoints().GetData()) if poly.GetNumberOfPoints()
           else np.zeros((0, 3))}
    for name, cells in (("VERTS", poly.GetVerts()), ("LINES", poly.GetLines())):
        ids, c = [], cells.NewIterator()
        c.GoToFirstCell()
        while not c.IsDoneWithTraversal():
            got = c.GetCurrentCell()
            ids.append([got.GetId(k) for k in range(got.GetNumberOfIds())])
            c.GoToNextCell()
        out[name] = ids
    for data in (poly.GetPointData(), poly.GetCellData(), poly.GetFieldData()):
        for k in range(data.GetNumberOfArrays()):
            a = data.GetArray(k)
            out[a.GetName()] = vtk_to_numpy(a)
    out["_point_names"] = [poly.GetPointData().GetArrayName(k)
                           for k in range(poly.GetPointData().GetNumberOfArrays())]
    out["_cell_names"] = [poly.GetCellData().GetArrayName(k)
                          for k in range(poly.GetCellData().GetNumberOfArrays())]
    return out


def same_as_own_reader(path, v):
    """Every array of VTK's reading bit for bit that of tools/wetdem_vtk.py."""
    own = read_vtk(path)
    for name, a in own.items():
        if name in ("VERTICES", "LINES"):
            continue
        b = v.get(name)
        if b is None or not np.array_equal(np.asarray(b).reshape(np.shape(a)), a):
            fail(path, f"array {name} read by VTK differs from tools/wetdem_vtk.py's")


def check_arrays(path, v, names, kind):
    got = v["_point_names"] if kind == "point" else v["_cell_names"]
    if sorted(got) != sorted(names):
        fail(path, f"{kind} arrays {got}, expected {sorted(names)}")
        return False
    for name, comps in names.items():
        a = v[name]
        if (a.shape[1] if a.ndim > 1 else 1) != comps:
            fail(path, f"array {name} has {a.shape} values, expected {comps} components")
            return False
    return True


def check_frame(path, time, v):
    """Whether the frame passes (its links are checked against it only then)."""
    before = len(failures)
    n = len(v["POINTS"])
    if v["VERTS"] != [[k] for k in range(n)] or v["LINES"]:
        fail(path, f"expected one vertex a particle ({n}) and no lines")
    if not check_arrays(path, v, POINT_ARRAYS, "point"):
        return False
    if len(v["radius"]) != n or not np.all(v["radius"] > 0):
        fail(path, "radius: not one positive value a particle")
    if "TIME" not in v or v["TIME"][0] != time:
        fail(path, f"TIME field {v.get('TIME')} is not the index's time {time!r}")
    same_as_own_reader(path, v)
    return len(failures) == before


def check_links(path, time, v, frame):
    n = len(v["LINES"])
    if v["LINES"] != [[2 * k, 2 * k + 1] for k in range(n)] or v["VERTS"]:
        fail(path, f"expected one line of two points a link ({n}) and no vertices")
    if not check_arrays(path, v, LINK_ARRAYS, "cell"):
        return
    if "TIME" not in v or v["TIME"][0] != time:
        fail(path, f"TIME field {v.get('TIME')} is not the index's time {time!r}")
    same_as_own_reader(path, v)
    if frame is None or n == 0:
        return
    p, x, r = v["POINTS"], frame["POINTS"], frame["radius"]
    i, j = v["i"].astype(int), v["j"].astype(int)
    if np.any(i < 0) or np.any(i >= len(x)) or np.any(j >= len(x)) or np.any(j == i):
        fail(path, "a link's i or j is not a particle of its frame")
        return
    if not np.array_equal(p[0::2], x[i]):
        fail(path, "a line does not start at particle i's centre in the frame")
    image = np.any(p[1::2] != x[np.maximum(j, 0)], axis=1)  # j's periodic image, not j
    link_kinds["wall"] += int(np.sum(j < 0))
    link_kinds["periodic"] += int(np.sum((j >= 0) & image))
    link_kinds["pair"] += int(np.sum((j >= 0) & ~image))
    length = np.linalg.norm(p[1::2] - p[0::2], axis=1)
    pair = j >= 0
    reach = np.where(pair, r[i] + r[np.maximum(j, 0)], r[i]) + v["gap"]
    # The gap is computed from the centres as |x_i - x_j| - R_i - R_j: the two sides agree to
    # the rounding of numbers of the size of the distance (about 1e-16 of 1 mm here); 1e-12
    # of the radius sum leaves four orders for the operations' order and no room for a wrong
    # endpoint or an image off by a box length.
    tol = 1e-12 * (r[i] + np.where(pair, r[np.maximum(j, 0)], 0.0))
    bad = np.abs(length - reach) > tol
    if np.any(bad):
        fail(path, f"{bad.sum()} lines are not R_i + R_j + gap long (first: link "
             f"{np.argmax(bad)}, {length[bad][0]:.17g} against {reach[bad][0]:.17g})")
    f2 = np.sum(v["force"] ** 2, axis=1)
    parts = v["force_normal"] ** 2 + v["force_tangential"] ** 2
    # |F|^2 against F_n^2 + F_t^2, both sums of squares of doubles: a few ulp of the larger.
    bad = np.abs(f2 - parts) > 1e-12 * np.maximum(f2, parts) + 1e-300
    if np.any(bad):
        fail(path, f"{bad.sum()} links' force vector is not the sum of its normal and "
             "tangential parts")


def check_series(index):
    try:
        series = json.load(open(index))
        ok = series.get("file-series-version") == "1.0" and all(
            set(e) == {"name", "time"} and isinstance(e["time"], (int, float))
            for e in series["files"])
    except (OSError, ValueError, KeyError, TypeError) as e:
        fail(index, f"not a ParaView file series: {e}")
        return []
    if not ok:
        fail(index, "not a ParaView file series (file-series-version 1.0, name and time)")
        return []
    entries = read_series(index)
    times = [t for t, _ in entries]
    if any(b <= a for a, b in zip(times, times[1:])) or not all(map(math.isfinite, times)):
        fail(index, "times do not increase")
    for _, path in entries:
        if not os.path.isfile(path):
            fail(index, f"names {path}, which does not exist")
    return entries


def check_run(run):
    """Checks every series of a run directory; returns {file name: VTK's reading}."""
    read = {}
    indexes = sorted(f for f in os.listdir(run) if f.endswith(".vtk.series"))
    if not indexes:
        fail(run, "no .vtk.series index")
    frames = [f for f in indexes if "_links" not in f]
    for index in frames + [f for f in indexes if f not in frames]:
        links = index not in frames
        entries = check_series(os.path.join(run, index))
        for time, path in entries:
            if not os.path.isfile(path):
                continue
            v = vtk_read(path)
            if v is None:
                continue
            name = os.path.basename(path)
            if links:
                frame = read.get(name.replace("_links_", "_"))
                check_links(path, time, v, frame)
                read[name] = v
            elif check_frame(path, time, v):
                read[name] = v
        kind = "links files" if links else "frames"
        print(f"  {os.path.join(run, index)}: {len(entries)} {kind} read by VTK "
              f"{'and checked' if entries else ''}")
    return read


def main():
    args = sys.argv[1:]
    same = None
    all_kinds = "--all-kinds" in args
    args = [a for a in args if a != "--all-kinds"]
    if "--same" in args:
        k = args.index("--same")
        same, args = args[k + 1:k + 3], args[:k] + args[k + 3:]
        if len(same) != 2:
            print(__doc__, file=sys.stderr)
            sys.exit(2)
    if not args and not same:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
    for run in args:
        check_run(run)
    if same:
        a, b = (check_run(d) for d in same)
        if sorted(a) != sorted(b):
            fail(same[1], f"other files than {same[0]}")
        for name in sorted(set(a) & set(b)):
            for key in a[name]:
                if key.startswith("_"):
                    continue
                if not np.array_equal(np.asarray(a[name][key]), np.asarray(b[name][key])):
                    fail(os.path.join(same[1], name), f"array {key} differs from "
                         f"{os.path.join(same[0], name)}")
        print(f"  {same[0]} and {same[1]}: {len(a)} files, the same arrays bit for bit")
    print(f"  links checked: {link_kinds['pair']} between particles, {link_kinds['periodic']} "
          f"across a periodic face, {link_kinds['wall']} to a wall")
    if all_kinds and min(link_kinds.values()) == 0:
        fail("--all-kinds", "the links checked lack a kind")
    if failures:
        print(f"check_vtk_with_vtk: {len(failures)} check(s) failed", file=sys.stderr)
        sys.exit(1)
    print("check_vtk_with_vtk: every file read by VTK and every check holds")


if __name__ == "__main__":
    main()

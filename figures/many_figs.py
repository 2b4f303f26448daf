"""Figures and checks of the many-particle validation piece (scripts/validate.d/40-many.sh).

Reads the --out directories of the three shipped scenarios (global.csv, summary.json and, for
the cradle, the ASCII VTK frames) and writes docs/figures/many_cradle.png,
many_settling.png and many_agglomeration.png. Checks, each printed and failing the script:
  cradle        x momentum conserved (no walls, no gravity: only pair forces, equal and
                opposite) to 1e-9 of the striker's; the last sphere leaves with more than
                half the striker's speed and faster than every other sphere;
  settling      energy closure |balance_error| < 2e-3 of the work of all forces (O(dt^2)
                Verlet error plus the film forces' jumps at h = delta and h_min); the bed is
                at rest (kinetic < 1e-4 of the potential energy released); every sphere ends
                in contact or bridged (contacts + bridges >= number of spheres);
  agglomeration the number of liquid bridges grows tenfold, the mean agglomerate size grows
                tenfold, the agglomerate count first rises above its start (clusters form)
                and then falls (they merge); closure < 2e-2 of the work (larger steps: 1/20
                of the contact time).
Usage: /usr/bin/python3 figures/many_figs.py --dir out/validate/many
"""
import argparse
import json
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import FIGURES, ROOT, np, plt  # noqa: E402

failures = []


def check(ok, text):
    print(f"  [{'ok' if ok else 'FAIL'}] {text}")
    if not ok:
        failures.append(text)


def read_global(path):
    """global.csv as {column: array}."""
    with open(path) as f:
        lines = [ln.strip() for ln in f if not ln.startswith("#") and ln.strip()]
    names = lines[0].split(",")
    rows = np.array([[float(x) for x in ln.split(",")] for ln in lines[1:]])
    return {n: rows[:, k] for k, n in enumerate(names)}


def read_vtk_ascii(path):
    """(time, positions n x 3, velocities n x 3) of an ASCII frame written by wetdem."""
    with open(path) as f:
        tok = f.read().split()
    t = float(tok[tok.index("TIME") + 4])
    k = tok.index("POINTS")
    n = int(tok[k + 1])
    pos = np.array(tok[k + 3:k + 3 + 3 * n], float).reshape(n, 3)
    k = tok.index("velocity")
    vel = np.array(tok[k + 4:k + 4 + 3 * n], float).reshape(n, 3)
    return t, pos, vel


def frames(run_dir):
    series = json.load(open(os.path.join(run_dir, "particles.vtk.series")))
    return [read_vtk_ascii(os.path.join(run_dir, e["name"])) for e in series["files"]]


def cradle(run_dir):
    print("Stokes cradle")
    fr = frames(run_dir)
    t = np.array([f[0] for f in fr]) * 1e3
    vx = np.array([f[2][:, 0] for f in fr])
    v0 = vx[0, 0]
    drift = np.max(np.abs(vx.sum(axis=1) - vx[0].sum()))
    check(drift < 1e-9 * v0, f"x momentum conserved: largest change {drift / v0:.2e} of the striker's")
    last = vx[-1]
    check(last[-1] > 0.5 * v0 and last[-1] == last.max(),
          f"the last sphere leaves at {last[-1]:.3f} m/s = {last[-1] / v0:.2f} v0, the others at "
          f"{', '.join(f'{v:.3f}' for v in last[:-1])} m/s")
    fig, ax = plt.subplots(figsize=(6, 3.6))
    for k in range(vx.shape[1]):
        ax.plot(t, vx[:, k], marker=".", label=f"sphere {k + 1}")
    ax.set_xlabel("time [ms]")
    ax.set_ylabel("velocity $v_x$ [m/s]")
    ax.set_title("Stokes cradle: five coated steel spheres, 0.1 Pa s oil")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(FIGURES, "many_cradle.png"), dpi=120)


def settling(run_dir):
    print("wet granular settling")
    g = read_global(os.path.join(run_dir, "global.csv"))
    s = json.load(open(os.path.join(run_dir, "summary.json")))
    e = s["energy_J"]
    released = g["potential_J"][0] - e["potential"]
    check(abs(e["balance_error"]) < 2e-3 * abs(e["work_total"]),
          f"energy closure {abs(e['balance_error']) / abs(e['work_total']):.2e} of the work")
    check(e["kinetic"] < 1e-4 * released,
          f"at rest: kinetic {e['kinetic']:.2e} J against {released:.2e} J released")
    check(s["contacts"] + s["bridges"] >= s["particles"],
          f"{s['contacts']} contacts and {s['bridges']} bridges hold {s['particles']} spheres")
    t = g["time_s"] * 1e3
    fig, (a, b) = plt.subplots(1, 2, figsize=(9, 3.6))
    a.semilogy(t, np.maximum(g["kinetic_J"], 1e-14), label="kinetic")
    a.semilogy(t, g["dissipated_J"].clip(1e-14), label="dissipated")
    a.semilogy(t, (g["potential_J"][0] - g["potential_J"]).clip(1e-14), label="potential released")
    a.set_xlabel("time [ms]")
    a.set_ylabel("energy [J]")
    a.legend(fontsize=8)
    for name in [c for c in g if c.startswith("work_")]:
        b.plot(t, -g[name] * 1e6, label=name[5:-2])
    b.set_xlabel("time [ms]")
    b.set_ylabel("energy taken by the model [uJ]")
    b.legend(fontsize=8)
    fig.suptitle("Wet settling of 2000 spheres: energy budget per model")
    fig.tight_layout()
    fig.savefig(os.path.join(FIGURES, "many_settling.png"), dpi=120)


def agglomeration(run_dir):
    print("agglomeration in a periodic box")
    g = read_global(os.path.join(run_dir, "global.csv"))
    e = json.load(open(os.path.join(run_dir, "summary.json")))["energy_J"]
    n, size, br = g["agglomerates"], g["mean_agglomerate_size"], g["bridges"]
    check(br[-1] > 10 * max(br[0], 1), f"bridges {br[0]:.0f} -> {br[-1]:.0f}")
    check(size[-1] > 10 * max(size[0], 1), f"mean agglomerate size {size[0]:.3g} -> {size[-1]:.3g}")
    check(n.max() > n[0] and n[-1] < n.max(),
          f"agglomerates {n[0]:.0f} at the start, {n.max():.0f} at most, {n[-1]:.0f} at the end")
    check(abs(e["balance_error"]) < 2e-2 * abs(e["work_total"]),
          f"energy closure {abs(e['balance_error']) / abs(e['work_total']):.2e} of the work")
    t = g["time_s"] * 1e3
    fig, (a, b) = plt.subplots(1, 2, figsize=(9, 3.6))
    a.semilogy(t, g["kinetic_J"])
    a.set_xlabel("time [ms]")
    a.set_ylabel("kinetic energy [J]")
    b.plot(t, n, label="agglomerates")
    b.set_xlabel("time [ms]")
    b.set_ylabel("number of agglomerates")
    c = b.twinx()
    c.plot(t, size, color="C1", label="mean size")
    c.set_ylabel("mean agglomerate size [spheres]", color="C1")
    fig.suptitle("400 wet spheres in a periodic box")
    fig.tight_layout()
    fig.savefig(os.path.join(FIGURES, "many_agglomeration.png"), dpi=120)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--dir", default=os.path.join(ROOT, "out", "validate", "many"))
    d = ap.parse_args().dir
    os.makedirs(FIGURES, exist_ok=True)
    cradle(os.path.join(d, "cradle"))
    settling(os.path.join(d, "settling"))
    agglomeration(os.path.join(d, "agglomeration"))
    if failures:
        print(f"{len(failures)} check(s) failed")
        sys.exit(1)


if __name__ == "__main__":
    main()

"""Nijssen 2023 Fig. 2: gap h during head-on collisions of Delrin spheres in water at several
Stokes numbers, including St = 1 where the spheres never touch.

Input: DIR/fig2_st<St>/trajectory.csv and summary.json from `wetdem run ... --out`.
Usage: nijssen_fig2.py [--dir DIR]
"""
import argparse
import glob
import os
import re
import sys

import common
from common import plt


def load(directory):
    runs = []
    for d in glob.glob(os.path.join(directory, "fig2_st*")):
        st = float(re.search(r"fig2_st([0-9.e+-]+)$", d).group(1))
        runs.append((st, common.read_csv(os.path.join(d, "trajectory.csv")),
                     common.read_json(os.path.join(d, "summary.json"))))
    runs.sort(key=lambda r: r[0])
    # (without this, a missing or mistyped --dir drew empty axes over the committed figure)
    if not runs or runs[0][0] > 1 or runs[-1][0] < 100:
        sys.exit(f"nijssen_fig2: no fig2_st* runs from St = 1 to St >= 100 in {directory} "
                 "(run scripts/validate.d/10-nijssen.sh)")
    return runs


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--dir", default=common.VALIDATE)
    a = p.parse_args()
    runs = load(a.dir)
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    c = common.Checks("Fig. 2")
    print(f"  {'St':>6s} {'v0 [m/s]':>10s} {'min gap/R*':>11s} {'contact':>8s} {'e':>7s}")
    for st, tr, sm in runs:
        r_eff = sm["setup"]["r_eff"]
        v0 = sm["result"]["impact_speed"]
        t = tr["time"] * v0 / r_eff
        h = tr["gap"] / r_eff
        ax.plot(t, h, label=f"St = {st:g}")
        ax2.plot(t, tr["gap"] * 1e6, label=f"St = {st:g}")
        res = sm["result"]
        print(f"  {st:6g} {v0:10.4g} {res['min_gap'] / r_eff:11.3g} "
              f"{str(res['solid_contact']):>8s} {res['e']:7.3f}")
        if st <= 1.0:
            c.check(not res["solid_contact"] and res["min_gap"] > 0,
                    f"St = {st:g}: the spheres never touch (min gap {res['min_gap']:.3g} m)")
            c.check(not res["separated"], f"St = {st:g}: no rebound")
        if st >= 100:
            c.check(res["separated"] and res["e"] > 0, f"St = {st:g}: rebound, e = {res['e']:.3f}")
    ax.set_xlabel(r"$t\,v_0/R^*$")
    ax.set_ylabel(r"gap $h/R^*$")
    ax.set_xlim(0, 3)
    ax.set_ylim(-0.05, 1.3)
    ax.axhline(0, color="k", lw=0.6)
    ax.set_title("Nijssen 2023 Fig. 2: Delrin, head-on, water")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    ax2.set_xlabel(r"$t\,v_0/R^*$")
    ax2.set_ylabel(r"gap $h$ [$\mu$m] (near contact)")
    ax2.set_xlim(0.9, 1.5)
    ax2.set_ylim(-4, 8)
    ax2.axhline(0, color="k", lw=0.6)
    ax2.axhline(0.796, color="grey", ls=":", lw=1)
    ax2.text(0.91, 1.0, r"$h_\sigma$ = 796 nm", fontsize=8, color="grey")
    ax2.set_title("close-up of the approach")
    ax2.grid(alpha=0.3)
    common.save(fig, "nijssen_fig2.png")
    c.finish()


if __name__ == "__main__":
    main()

"""Nijssen 2023 Fig. 5: rebound angle theta_1 of the striker vs impact angle theta_0 for oblique
collisions in the three normal-Stokes ranges of the caption: St_n < 25 (Steel I in 80 w%
glycerol), 40 < St_n < 200 (Delrin in water), 500 < St_n < 2400 (Steel I in water). Angles are
measured from the line of centres (the normal), Nijssen Fig. 1c; St_n = St cos(theta_0).

Impact angle: wetdem's collision.angle_deg is the angle of the undisturbed straight-line
approach at contact, sin(theta_0) = b / 2R with the impact parameter b, as in the experiments
and Fig. 1c, so it is plotted as it is (column angle_in). St_n = m* v cos(theta_0)/(6 pi mu R*^2).

Input: DIR/fig5_<range>_st<St_n>.csv, sweeps over collision.angle_deg.
Usage: nijssen_fig5.py [--dir DIR]
"""
import argparse
import glob
import os
import re
import sys

import numpy as np

import common
from common import plt

RANGES = [("low", r"$St_n < 25$: Steel I, 80 w% glycerol"),
          ("mid", r"$40 < St_n < 200$: Delrin, water"),
          ("high", r"$500 < St_n < 2400$: Steel I, water")]


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--dir", default=common.VALIDATE)
    a = p.parse_args()
    fig, axes = plt.subplots(1, 3, figsize=(13, 4.2), sharey=True)
    c = common.Checks("Fig. 5")
    mean_out = {}
    for ax, (key, title) in zip(axes, RANGES):
        files = glob.glob(os.path.join(a.dir, f"fig5_{key}_st*.csv"))
        if not files:  # (it drew empty axes over the committed figure, then failed a check)
            sys.exit(f"nijssen_fig5: no fig5_{key}_st*.csv in {a.dir} "
                     "(run scripts/validate.d/10-nijssen.sh)")
        runs = sorted((float(re.search(r"_st([0-9.e+-]+)\.csv$", f).group(1)),
                       common.read_csv(f)) for f in files)
        outs = []
        for st, d in runs:
            ok = d["separated"] > 0
            theta0 = d["angle_in"][ok]
            out = d["striker_angle_out"][ok]
            ax.plot(theta0, out, "-o", ms=3, label=f"St_n = {st:g}")
            outs.append(out[(theta0 > 10) & (theta0 < 70)])
            print(f"  {key:4s} St_n = {st:6g}: " + ", ".join(
                f"{ai:.0f}->{ao:.1f}" for ai, ao in zip(theta0[::4], out[::4])))
        mean_out[key] = float(np.mean(np.concatenate(outs))) if outs else float("nan")
        x = np.linspace(0, 90, 50)
        ax.plot(x, x, "k:", lw=0.8, label=r"$\theta_1 = \theta_0$")
        ax.set_title(title, fontsize=10)
        ax.set_xlabel(r"impact angle at contact $\theta_{i,0}$ [deg]")
        ax.set_xlim(0, 90)
        ax.set_ylim(0, 95)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    axes[0].set_ylabel(r"rebound angle $\theta_{i,1}$ [deg]")
    fig.suptitle("Nijssen 2023 Fig. 5: oblique collisions (angles from the line of centres)")
    common.save(fig, "nijssen_fig5.png")
    print("  mean rebound angle for 10-70 deg impact: " +
          ", ".join(f"{k} {v:.1f} deg" for k, v in mean_out.items()))
    c.check(mean_out["low"] < mean_out["mid"] < mean_out["high"],
            "damping lowers the rebound angle: mean theta_1 low St_n < mid < high")
    c.finish()


if __name__ == "__main__":
    main()

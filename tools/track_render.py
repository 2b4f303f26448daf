"""Renders the painted dots of a simulated collision as a Stokes-cradle camera would see them,
for `wetdem track` (docs/tracking.md, "Demo"; Punch et al. 2023 Sec. 3.1-3.2).

Usage: /usr/bin/python3 tools/track_render.py TRAJECTORY.csv --out DOTS.csv
       [--fps 5000] [--pixel-size 175e-6] [--radius 12.7e-3] [--noise 0.05] [--seed 45]
       [--frames 120] [--pre 50]

TRAJECTORY.csv is the trajectory of `wetdem run SCENARIO --out DIR` for a two-sphere collision
in the x-y plane (spins about z): rows every 1/(n fps) s for an integer n (set
output.trajectory_interval), plus the final state at separation. Each sphere carries dot 1 at
its bottom pole (imaged on the centre) and dots 2 and 3 at the polar angle beta = 25 deg from
it, forming an equilateral triangle with dot 1. The camera looks up along +z from below with
its columns along +x, so its rows run along +y: pixel = (x, y)/pixel_size + (600, 400) and
`wetdem track` reports omega_z without --y-down. The spins are integrated into the dots'
azimuths by the trapezoidal rule over the trajectory rows (an error there only shifts the
azimuth by a constant after the collision, which the tracking does not see). Frame f is at
t = (f - pre)/fps; before t = 0 and after the last row the spheres fly freely (no force acts
outside the interaction range), so the motion is extrapolated with the first/last state.
Gaussian noise of `noise` pixels (seeded, numpy PCG64) is added to every coordinate.
"""
import argparse
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "figures"))
from common import read_csv  # noqa: E402

BETA = math.radians(25.0)  # polar angle of dots 2 and 3 from dot 1 [rad]
# Equal chords |p1 p2| = |p2 p3|: 2R sin(beta/2) = 2R sin(beta) sin(dphi/2).
DPHI = 2 * math.asin(math.sin(BETA / 2) / math.sin(BETA))
YAW0 = (0.4, 2.1)  # azimuth of dot 2 of each sphere at t = 0 [rad]
OFFSET_PX = (600.0, 400.0)


def states(traj):
    """Per sphere: arrays t, x, y, vx, vy, wz and the integrated azimuth yaw."""
    t = traj["time"]
    out = []
    for k, s in enumerate("ij"):
        wz = traj[f"wz_{s}"]
        yaw = YAW0[k] + np.concatenate(([0.0], np.cumsum(0.5 * (wz[1:] + wz[:-1]) * np.diff(t))))
        out.append(dict(x=traj[f"x_{s}"], y=traj[f"y_{s}"], vx=traj[f"vx_{s}"],
                        vy=traj[f"vy_{s}"], wz=wz, yaw=yaw))
    return t, out


def pose(t_rows, st, t, row_of):
    """Centre (x, y) [m] and azimuth [rad] at time t (a trajectory row, or free flight)."""
    if 0 < t <= t_rows[-1]:
        i = row_of(t)
        return st["x"][i], st["y"][i], st["yaw"][i]
    i = 0 if t <= 0 else len(t_rows) - 1
    tau = t - t_rows[i]
    return st["x"][i] + st["vx"][i] * tau, st["y"][i] + st["vy"][i] * tau, \
        st["yaw"][i] + st["wz"][i] * tau


def dots(x, y, yaw, radius, pixel):
    rho = radius * math.sin(BETA)  # projected distance of dots 2, 3 from dot 1 [m]
    pts = [(x, y), (x + rho * math.cos(yaw), y + rho * math.sin(yaw)),
           (x + rho * math.cos(yaw + DPHI), y + rho * math.sin(yaw + DPHI))]
    return [c / pixel + OFFSET_PX[j % 2] for p in pts for j, c in enumerate(p)]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("trajectory")
    ap.add_argument("--out", required=True)
    ap.add_argument("--fps", type=float, default=5000.0)
    ap.add_argument("--pixel-size", type=float, default=175e-6)
    ap.add_argument("--radius", type=float, default=12.7e-3)
    ap.add_argument("--noise", type=float, default=0.05)
    ap.add_argument("--seed", type=int, default=45)
    ap.add_argument("--frames", type=int, default=120)
    ap.add_argument("--pre", type=int, default=50)
    a = ap.parse_args()
    traj = read_csv(a.trajectory)
    t_rows, st = states(traj)
    step = t_rows[1] - t_rows[0]
    sub = round(1.0 / (a.fps * step))
    if sub < 1 or abs(sub * step * a.fps - 1) > 1e-9:
        sys.exit(f"track_render: {a.trajectory}: row interval {step:g} s is not 1/(n fps) "
                 f"with fps = {a.fps:g}; set output.trajectory_interval")

    def row_of(t):
        i = int(round(t / step))
        if i >= len(t_rows) or abs(t_rows[i] - t) > 1e-9 * step:
            sys.exit(f"track_render: no trajectory row at t = {t:.9g} s")
        return i

    rng = np.random.default_rng(a.seed)
    with open(a.out, "w") as f:
        f.write(f"# dots rendered by tools/track_render.py from {a.trajectory}: {a.fps:g} "
                f"frames/s, {a.pixel_size:g} m/pixel, R = {a.radius:g} m, noise {a.noise:g} px "
                f"(seed {a.seed}); frame {a.pre} is t = 0 of the simulation\n")
        f.write("# sphere 1: striker, sphere 2: target; camera below, rows along +y\n")
        f.write("frame,sphere,x1,y1,x2,y2,x3,y3\n")
        for fr in range(a.frames):
            t = (fr - a.pre) / a.fps
            for k in range(2):
                xy = np.array(dots(*pose(t_rows, st[k], t, row_of), a.radius, a.pixel_size))
                xy += rng.normal(0.0, a.noise, 6)
                f.write(f"{fr},{k + 1}," + ",".join(f"{v:.4f}" for v in xy) + "\n")
    print(f"wrote {a.out} ({a.frames} frames)")


if __name__ == "__main__":
    main()

"""Tracking demo in the style of Punch et al. (2023) Fig. 5: the raw dot-1 positions, vx, vy
and omega per frame of both spheres from `wetdem track --frames`, with the straight lines
fitted before and after the collision, and a check of the tracked values against the
simulation that the dots were rendered from (docs/tracking.md, "Demo").

Usage: /usr/bin/python3 figures/punch_track.py [--dots DOTS.csv] [--frames FRAMES.csv]
       [--summary TRACK.json] [--sim RUN_SUMMARY.json] [--png OUT.png] [--fps 5000]
       [--pixel-size 175e-6]
Defaults: the files scripts/validate.d/25-track.sh writes. The fitted lines are refitted here
over the windows docs/tracking.md defines (default options: window 7, offset 5) and must give
the summary's before/after values; the tracked e_n, spins and impact angle must match the
simulation within the tolerances tests/test_track.c derives for 0.05 px noise (e_n 0.03,
omega 2 rad/s, angle 1.5 deg). Exit code 1 when a check fails.
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import FIGURES, ROOT, plt, read_csv, read_json  # noqa: E402

import numpy as np  # noqa: E402

OUT = os.path.join(ROOT, "out", "validate", "track")
WINDOW, OFFSET = 7, 5  # wetdem track defaults [frames]
H = WINDOW // 2


def read_dots(path, pixel):
    """{sphere: (frames, x1 [mm], y1 [mm])} from a track input file."""
    rows = [ln.split(",") for ln in open(path)
            if ln.strip() and not ln.startswith("#") and not ln.lower().startswith("frame")]
    out = {}
    for s in sorted({int(r[1]) for r in rows}):
        sel = [r for r in rows if int(r[1]) == s]
        out[s] = (np.array([int(r[0]) for r in sel]),
                  np.array([float(r[2]) for r in sel]) * pixel * 1e3,
                  np.array([float(r[3]) for r in sel]) * pixel * 1e3)
    return out


def fitted_lines(fr, k, comp):
    """Straight lines before and after the collision frame k over the documented windows:
    intervals [0, k - H) and [k + WINDOW, end); returns (t, value) pairs and the values at
    k -/+ OFFSET (time of frame f: f/fps, interval midpoints (f + 1/2)/fps)."""
    lines = []
    for lo, hi, at in ((0, k - H, k - OFFSET), (k + WINDOW, fr["frame"].max() + 1, k + OFFSET)):
        m = (fr["frame"] >= lo) & (fr["frame"] < hi)
        x, y = fr["frame"][m] + 0.5, fr[comp][m]
        p = np.polyfit(x, y, 1)
        lines.append((x, np.polyval(p, x), np.polyval(p, at)))
    return lines


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dots", default=os.path.join(ROOT, "examples", "tracks", "punch_45deg.csv"))
    ap.add_argument("--frames", default=os.path.join(OUT, "frames.csv"))
    ap.add_argument("--summary", default=os.path.join(OUT, "track.json"))
    ap.add_argument("--sim", default=os.path.join(OUT, "run", "summary.json"))
    ap.add_argument("--png", default=os.path.join(FIGURES, "punch_track.png"))
    ap.add_argument("--pixel-size", type=float, default=175e-6)
    a = ap.parse_args()
    dots = read_dots(a.dots, a.pixel_size)
    frames = read_csv(a.frames)
    tr = read_json(a.summary)
    sim = read_json(a.sim)["result"]
    k, striker = int(tr["collision_frame"]), int(tr["striker"])
    fails = []

    fig, axes = plt.subplots(2, 2, figsize=(10, 7.5), sharex=True)
    ax = axes[0, 0]
    for n, (s, (f, x, y)) in enumerate(sorted(dots.items())):
        name = "striker" if s == striker else "target"
        ax.plot(f, x, ".", color=f"C{n}", ms=3, label=f"{name} x")
        ax.plot(f, y, "+", color=f"C{n}", ms=3, label=f"{name} y")
    ax.axvline(k, color="k", ls="--", lw=0.8)
    ax.set_ylabel("dot 1 position [mm]")
    ax.set_title("(a) raw dot-1 positions (0.05 px noise)", fontsize=10)
    ax.legend(fontsize=7, ncol=2)
    # (frames columns raw and smoothed, the summary's key suffix: the summary keeps its units in
    # the key, striker_after_vx_m_s)
    panels = [("vx", "vx_raw", "vx", "vx_m_s", "v_x [m/s]", "(b)"),
              ("vy", "vy_raw", "vy", "vy_m_s", "v_y [m/s]", "(c)"),
              ("omega", "omega_raw", "omega", "omega_rad_s", "omega [rad/s]", "(d)")]
    for (key, raw, comp, suffix, label, tag), ax in zip(panels,
                                                         [axes[0, 1], axes[1, 0], axes[1, 1]]):
        for n, s in enumerate(sorted(dots)):
            fr = {c: v[frames["sphere"] == s] for c, v in frames.items()}
            who = "striker" if s == striker else "target"
            col = f"C{n}"
            ax.plot(fr["frame"] + 0.5, fr[raw], ".", color=col, alpha=0.25, ms=3,
                    label=f"{who}: raw dots")
            ax.plot(fr["frame"] + 0.5, fr[comp], "o", color=col, ms=2.5, mfc="none",
                    label=f"{who}: smoothed")
            lo, hi = np.percentile(fr[comp], [1, 99])
            span = [min(span[0], lo), max(span[1], hi)] if n else [lo, hi]
            for (x, y, v_at), when in zip(fitted_lines(fr, k, comp), ("before", "after")):
                ax.plot(x, y, "-", color=col, lw=1.5,
                        label=f"{who}: fitted lines" if when == "before" else None)
                want = tr[f"{who}_{when}_{suffix}"]
                tol = 1e-4 if key == "omega" else 1e-6
                if abs(v_at - want) > tol:
                    fails.append(f"{who} {when} {suffix}: refit {v_at:.9g} vs summary "
                                 f"{want:.9g}")
                ax.plot(k + (OFFSET if when == "after" else -OFFSET), want, "*", color=col,
                        ms=9)
        ax.axvline(k, color="k", ls="--", lw=0.8)
        pad = 0.3 * (span[1] - span[0])
        ax.set_ylim(span[0] - pad, span[1] + pad)  # raw spins scatter far more (Eq. 23)
        ax.set_ylabel(label)
        ax.set_title(f"{tag} {key} per frame; stars: values at k -/+ {OFFSET}", fontsize=10)
    handles, names = axes[1, 1].get_legend_handles_labels()
    fig.legend(handles, names, loc="lower center", ncol=6, fontsize=7.5)
    for ax in axes[1]:
        ax.set_xlabel("frame (5000 frames/s)")
    checks = [("e_n", tr["e_n"], sim["e_n"], 0.03),
              ("striker omega", tr["striker_after_omega_rad_s"], sim["omega_i_z"], 2.0),
              ("target omega", tr["target_after_omega_rad_s"], sim["omega_j_z"], 2.0),
              ("impact angle [deg]", tr["impact_angle_deg"], sim["angle_in"], 1.5)]
    lines = []
    for name, got, want, tol in checks:
        ok = abs(got - want) <= tol
        lines.append(f"{name}: tracked {got:.4g}, simulated {want:.4g} (tol {tol:g})"
                     f"{'' if ok else '  FAIL'}")
        if not ok:
            fails.append(lines[-1])
    fig.suptitle(f"wetdem track on dots rendered from a wetdem simulation (Punch set-up, "
                 f"St_n = {sim['stokes_n']:.3g}, {sim['angle_in']:.0f} deg), collision frame "
                 f"k = {k} (dashed)\n" + "; ".join(lines[:2]) + "\n" + "; ".join(lines[2:]),
                 fontsize=8.5)
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    os.makedirs(os.path.dirname(os.path.abspath(a.png)), exist_ok=True)
    fig.savefig(a.png, dpi=120)
    print(f"wrote {a.png}")
    print("\n".join(lines))
    if fails:
        print("FAILED:\n  " + "\n  ".join(fails))
        sys.exit(1)


if __name__ == "__main__":
    main()

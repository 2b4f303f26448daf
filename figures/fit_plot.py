"""Plot of a `wetdem fit` result: measured e_n (markers) and the fitted model (line, from
--curve, or the fitted values at the data points), per impact angle, with the residuals.

Usage: /usr/bin/python3 figures/fit_plot.py [FIT.csv] [--curve CURVE.csv] [--png OUT.png]
       [--title TEXT] [--summary SUMMARY.csv]
Without FIT.csv: the example of scripts/validate.d/26-fit.sh (out/validate/fit/fit.csv with its
curve.csv and summary.csv) into docs/figures/fit_example.png.
FIT.csv is the --out file of `wetdem fit` (stokes_n, angle_deg, e_n_data, e_n_fit,
e_n_residual[, omega_data, omega_fit, omega_residual]); CURVE.csv its --curve file;
SUMMARY.csv its standard output, whose fitted values, standard errors and units are written
on the plot. docs/calibration.md.
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import FIGURES, ROOT, plt, read_csv  # noqa: E402

import numpy as np  # noqa: E402


def fitted_values(path):
    """Lines "KEY = value +- std_error unit" from the standard output of `wetdem fit`."""
    rows = [ln.strip().split(",") for ln in open(path) if ln.strip() and not ln.startswith("#")]
    col = {name.split(" [")[0]: k for k, name in enumerate(rows[0])}  # "value [unit]": value
    out = []
    for r in rows[1:]:
        unit = r[col["unit"]] if "unit" in col else ""
        out.append(f"{r[col['parameter']]} = {float(r[col['value']]):.4g} "
                   f"+- {float(r[col['std_error']]):.2g} {'' if unit == '-' else unit}")
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("fit", nargs="?")
    ap.add_argument("--curve")
    ap.add_argument("--png")
    ap.add_argument("--title", default="wetdem fit")
    ap.add_argument("--summary")
    a = ap.parse_args()
    if a.fit is None:
        example = os.path.join(ROOT, "out", "validate", "fit")
        a.fit = os.path.join(example, "fit.csv")
        a.curve = a.curve or os.path.join(example, "curve.csv")
        a.summary = a.summary or os.path.join(example, "summary.csv")
        a.png = a.png or os.path.join(FIGURES, "fit_example.png")
        a.title = "P_gt fitted to examples/fit/punch_0deg.csv"
    d = read_csv(a.fit)
    c = read_csv(a.curve) if a.curve else None
    png = a.png or os.path.splitext(a.fit)[0] + ".png"
    has_omega = "omega_data" in d
    fig, axes = plt.subplots(2 + has_omega, 1, figsize=(6, 6.5 + 2.5 * has_omega), sharex=True,
                             gridspec_kw={"height_ratios": [3, 1] + [3] * has_omega})
    ax, axr = axes[0], axes[1]
    angles = sorted(set(d["angle_deg"]))
    for k, ang in enumerate(angles):
        col = f"C{k}"
        m = d["angle_deg"] == ang
        ax.plot(d["stokes_n"][m], d["e_n_data"][m], "o", color=col, label=f"data {ang:g} deg")
        axr.plot(d["stokes_n"][m], d["e_n_residual"][m], "o", color=col)
        if c is not None:
            mc = c["angle_deg"] == ang
            ax.plot(c["stokes_n"][mc], c["e_n_fit"][mc], "-", color=col, label=f"fit {ang:g} deg")
            if has_omega:
                axes[2].plot(c["stokes_n"][mc], c["omega_fit"][mc], "-", color=col)
        else:
            order = np.argsort(d["stokes_n"][m])
            ax.plot(d["stokes_n"][m][order], d["e_n_fit"][m][order], "-", color=col)
        if has_omega:
            axes[2].plot(d["stokes_n"][m], d["omega_data"][m], "o", color=col)
    ax.set_ylabel("e_n [-]")
    ax.set_title(a.title)
    ax.legend(fontsize=8, loc="lower right")
    if a.summary:
        ax.text(0.03, 0.97, "\n".join(fitted_values(a.summary)), transform=ax.transAxes,
                va="top", fontsize=9)
    axr.axhline(0, color="k", lw=0.5)
    axr.set_ylabel("fit - data [-]")
    if has_omega:
        axes[2].set_ylabel("|omega| striker [rad/s]")
    axes[-1].set_xlabel("St_n [-]")
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(png)), exist_ok=True)
    fig.savefig(png, dpi=120)
    print(f"wrote {png}")


if __name__ == "__main__":
    main()

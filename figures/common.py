"""Shared helpers of the figure scripts: reading wetdem CSV output, paths, closed forms.

wetdem CSV files start with '#' provenance lines, then a header whose columns are
"name [unit]"; read_csv() returns a dict name -> numpy array (float where every value parses,
else str). Run the scripts with /usr/bin/python3 (numpy + matplotlib).
"""
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
VALIDATE = os.path.join(ROOT, "out", "validate", "nijssen")
FIGURES = os.path.join(ROOT, "docs", "figures")

# Nijssen 2023 Table 1 (spheres of d = 12.7 mm); "gamma" is Young's modulus E (SPEC §6).
MATERIALS = {
    "steel1": dict(label="Steel I", rho=7780, E=190e9, nu=0.27, sigma=24e-9),
    "steel2": dict(label="Steel II", rho=7780, E=190e9, nu=0.27, sigma=272e-9),
    "glass": dict(label="Glass", rho=2540, E=60e9, nu=0.23, sigma=134e-9),
    "delrin": dict(label="Delrin", rho=1400, E=2.8e9, nu=0.35, sigma=796e-9),
}
RADIUS = 6.35e-3  # [m]
E_DRY = 0.97  # Nijssen Table 1, every material


def read_csv(path):
    """Columns of a wetdem CSV as {name: array}; the units of the last file read in
    read_csv.units[name] (the header's [unit], "" without one). A table of an interrupted
    sweep or map (rows with status NOT_RUN) raises ValueError naming the file: those rows
    hold nan, which a figure would draw as results ("no rebound")."""
    with open(path) as f:
        lines = [ln.rstrip("\r\n") for ln in f if not ln.startswith("#") and ln.strip()]
    if not lines:
        raise ValueError(f"{path}: no header and no rows")
    header = lines[0].split(",")
    names = [h.split(" [")[0].strip() for h in header]
    read_csv.units = {n: (h.split(" [", 1)[1].rstrip("]") if " [" in h else "")
                      for n, h in zip(names, header)}
    rows = [ln.split(",") for ln in lines[1:]]
    if "status" in names:
        k = names.index("status")
        left = sum(1 for r in rows if len(r) > k and r[k] == "NOT_RUN")
        if left:
            raise ValueError(f"{path}: {left} of {len(rows)} points NOT_RUN (an interrupted "
                             f"batch): finish it with the same command and --resume {path}")
    data = {}
    for k, name in enumerate(names):
        col = [r[k] for r in rows]
        try:
            data[name] = np.array([float(v) for v in col])
        except ValueError:
            data[name] = np.array(col)
    return data


def read_json(path):
    with open(path) as f:
        return json.load(f)


def reduced(material, target="sphere"):
    """(m*, R*, E*) of two equal spheres of a material, or a sphere and a wall of it."""
    m = MATERIALS[material]
    mass = m["rho"] * 4.0 / 3.0 * math.pi * RADIUS**3
    e_star = 1.0 / (2.0 * (1.0 - m["nu"] ** 2) / m["E"])
    if target == "wall":
        return mass, RADIUS, e_star
    return mass / 2.0, RADIUS / 2.0, e_star


def stokes_speed(stokes, mu, m_eff, r_eff):
    """Head-on impact speed of a normal Stokes number [m/s]."""
    return stokes * 6.0 * math.pi * mu * r_eff**2 / m_eff


def h_eps(v, mu, r_eff, e_star):
    """Elastohydrodynamic minimum approach, Nijssen Eq. 5 with the fifth root [m]."""
    return 0.37 * r_eff * (mu * v / (e_star * r_eff)) ** 0.4


def legendre(stokes, e_dry=E_DRY):
    """Legendre et al. (2006): e / e_dry = exp(-35 / St)."""
    return e_dry * np.exp(-35.0 / np.asarray(stokes))


def save(fig, name):
    os.makedirs(FIGURES, exist_ok=True)
    path = os.path.join(FIGURES, name)
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)
    print(f"wrote {os.path.relpath(path, ROOT)}")
    return path


class Checks:
    """Collects the paper's statements checked against the data; exit 1 if any fails."""

    def __init__(self, figure):
        self.figure = figure
        self.failed = 0

    def check(self, ok, text):
        print(f"  [{'ok' if ok else 'FAIL'}] {self.figure}: {text}")
        if not ok:
            self.failed += 1

    def finish(self):
        if self.failed:
            print(f"{self.figure}: {self.failed} check(s) failed", file=sys.stderr)
            sys.exit(1)


def critical_stokes(stokes, separated):
    """Smallest Stokes number of the sweep whose spheres separated (rebound), or nan."""
    idx = np.nonzero(np.asarray(separated) > 0)[0]
    return float(stokes[idx[0]]) if len(idx) else float("nan")

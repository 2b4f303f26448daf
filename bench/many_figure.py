"""The many-particle benchmark's results against its three targets, in one figure.

Reads the results file of bench/20-many.sh (build/bench/many/results.txt; its line formats are
described there) and draws three panels:
  per core   wetdem / LIGGGHTS particle-steps per second on one thread, dry and wet, for each
             protocol (full, same, frozen), against the target of 2x;
  2 threads  wetdem's two-thread speed-up, the median of the pairs of runs back to back with
             their least and largest, dry and wet, each protocol, and LIGGGHTS' two ranks on
             the frozen protocol, against the target of 1.8x;
  wet / dry  the frozen protocol's wet / dry cost on one thread against the number of pairs
             within the films: the film sweep (one point per film thickness), the median and
             range of the dry / wet pairs back to back at the benchmark's films, and the floor
             (bench/bridge_floor.c, the bare loop over the bridges apart) on top of the dry
             run, against the target of 1.3x.
A panel whose lines the run did not write (LIGGGHTS not installed, PAIRS=0, FILMS="") says so.
Usage: /usr/bin/python3 bench/many_figure.py --results build/bench/many/results.txt \
           --out build/bench/many/many_bench.png --n 20000
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "figures"))
from common import np, plt  # noqa: E402  (matplotlib without a display)

PROTOCOLS = ("full", "same", "frozen")
VARIANTS = ("dry", "wet")
COLOURS = {"dry": "#4c72b0", "wet": "#dd8452", "liggghts": "#8c8c8c"}


def read_results(path):
    """The lines of a results file, by kind: rates, pairs within the films of wetdem's runs,
    pairs of runs, cost pairs, films, floor."""
    r = {"rate": {}, "within": {}, "pair": {}, "costpair": None, "film": [], "floor": None}
    with open(path) as f:
        for line in f:
            w = line.split()
            if not w:
                continue
            if w[0] in PROTOCOLS and len(w) >= 5:  # proto code variant threads rate ...
                key = (w[0], w[1], w[2], int(w[3]))
                r["rate"][key] = float(w[4])
                if len(w) >= 9 and w[8].isdigit():  # ... kb cpu contacts bridges (wetdem)
                    r["within"][key] = int(w[8])
            elif w[0] == "pair":  # pair proto code variant ratios...
                r["pair"][(w[1], w[2], w[3])] = [float(x) for x in w[4:]]
            elif w[0] == "costpair":  # costpair frozen ratios...
                r["costpair"] = [float(x) for x in w[2:]]
            elif w[0] == "film":  # film thickness wet_rate dry_rate contacts within
                r["film"].append((float(w[1]), float(w[2]), float(w[3]), int(w[4]), int(w[5])))
            elif w[0] == "floor":  # floor bridges_apart scalar_ns vector_ns [gather_ns]
                ns = [float(x) for x in w[2:5] if float(x) > 0]
                r["floor"] = (int(w[1]), min(ns)) if ns else None
    return r


def note(ax, text):
    ax.text(0.5, 0.5, text, ha="center", va="center", transform=ax.transAxes, fontsize=9)


def per_core(ax, r):
    x = np.arange(len(PROTOCOLS))
    drew = False
    for k, v in enumerate(VARIANTS):
        ratios = []
        for p in PROTOCOLS:
            w, lg = r["rate"].get((p, "wetdem", v, 1)), r["rate"].get((p, "liggghts", v, 1))
            ratios.append(w / lg if w and lg else np.nan)
        if np.all(np.isnan(ratios)):
            continue
        drew = True
        bars = ax.bar(x + (k - 0.5) * 0.38, ratios, 0.36, color=COLOURS[v], label=v)
        ax.bar_label(bars, fmt="%.2f", fontsize=8, padding=2)
    ax.axhline(2.0, color="k", ls="--", lw=1, label="target $\\geq$ 2")
    ax.set_xticks(x, PROTOCOLS)
    ax.set_ylabel("wetdem / LIGGGHTS, particle-steps per s")
    ax.set_title("per core (1 thread, 1 rank)")
    if drew:
        ax.legend(fontsize=8, loc="lower right")
    else:
        note(ax, "no LIGGGHTS runs in this results file")


def two_threads(ax, r):
    groups = [(p, "wetdem", v) for p in PROTOCOLS for v in VARIANTS]
    groups += [("frozen", "liggghts", v) for v in VARIANTS]
    labels, lows, drew = [], [1.8], False
    for g, key in enumerate(groups):
        vals = r["pair"].get(key)
        labels.append(f"{key[0]}\n{'LIGGGHTS' + chr(10) if key[1] == 'liggghts' else ''}{key[2]}")
        if not vals:
            continue
        drew = True
        med, lo, hi = np.median(vals), min(vals), max(vals)
        lows.append(lo)
        colour = COLOURS["liggghts"] if key[1] == "liggghts" else COLOURS[key[2]]
        ax.errorbar(g, med, yerr=[[med - lo], [hi - med]], fmt="o", color=colour, capsize=3)
        ax.annotate(f"{med:.2f}", (g, hi), textcoords="offset points", xytext=(0, 4),
                    ha="center", fontsize=7)
    ax.axhline(1.8, color="k", ls="--", lw=1, label="target $\\geq$ 1.8")
    ax.set_xticks(range(len(groups)), labels, fontsize=7)
    ax.set_ylabel("speed-up on 2 threads (pairs back to back)")
    ax.set_title("2 threads: median and range of the pairs")
    ax.set_ylim(bottom=min(lows) - 0.05)
    ax.legend(fontsize=8, loc="lower right")
    if not drew:
        note(ax, "no pairs of runs in this results file (PAIRS=0)")


def wet_cost(ax, r, n):
    films = sorted(r["film"], key=lambda f: f[4])
    drew = False
    if films:
        drew = True
        within = [f[4] for f in films]
        cost = [f[2] / f[1] for f in films]
        ax.plot(within, cost, "o-", color=COLOURS["wet"], label="film sweep (best of each)")
        for f, c in zip(films, cost):
            ax.annotate(f"{f[0] * 1e6:g} um: {c:.2f}", (f[4], c), textcoords="offset points",
                        xytext=(-6, 7), ha="right", fontsize=7)
    # the pairs within the films of the benchmark's wet variant (its frozen run's bridges)
    within_bench = r["within"].get(("frozen", "wetdem", "wet", 1))
    if r["costpair"] and within_bench:
        drew = True
        v = r["costpair"]
        med = np.median(v)
        ax.errorbar(within_bench, med, yerr=[[med - min(v)], [max(v) - med]], fmt="s",
                    color="k", capsize=4, label=f"{len(v)} dry / wet pairs: median {med:.2f}")
    dry = r["rate"].get(("frozen", "wetdem", "dry", 1))
    if r["floor"] and dry and within_bench:
        n_apart, ns = r["floor"]
        # a dry step takes n / dry seconds; the floor adds n_apart * ns to it (the report's)
        floor = 1 + n_apart * ns * 1e-9 * dry / n
        ax.plot([within_bench], [floor], "v", color="#55a868", ms=8,
                label=f"floor, {n_apart} bridges apart: {floor:.2f}")
    ax.axhline(1.3, color="k", ls="--", lw=1, label="target $\\leq$ 1.3")
    ax.set_xlabel("pairs within the films (frozen state)")
    ax.set_ylabel("wet / dry time per step")
    ax.set_title("cost of the wet models (frozen, 1 thread)")
    ax.margins(x=0.18, y=0.15)  # room for the points' labels, which sit above and to the left
    ax.legend(fontsize=7, loc="upper left")
    if not drew:
        note(ax, "no film sweep or cost pairs in this results file")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--results", default="build/bench/many/results.txt")
    ap.add_argument("--out", default="build/bench/many/many_bench.png")
    ap.add_argument("--n", type=int, default=20000, help="spheres of the run (its N)")
    a = ap.parse_args()
    if not os.path.isfile(a.results):
        print(f"many_figure: no results file {a.results} (run bench/20-many.sh first)",
              file=sys.stderr)
        sys.exit(2)
    r = read_results(a.results)
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6))
    per_core(axes[0], r)
    two_threads(axes[1], r)
    wet_cost(axes[2], r, a.n)
    fig.tight_layout()
    fig.savefig(a.out, dpi=110)
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()

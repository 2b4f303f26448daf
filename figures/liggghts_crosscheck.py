"""Checks and figure of the cross-check against LIGGGHTS 3.8 (scripts/validate.d/47-liggghts.sh).

Reads the traces of 2000 spheres settling in a closed box from the same state, written by
wetdem (bench/many_bench.c --trace: "step id x y z vx vy vz") and LIGGGHTS (dump custom of
bench/liggghts/frictionless.in), and writes docs/figures/liggghts_crosscheck.png. Checks, each
printed and failing the script:
  elastic  (e = 1, mu = 0: the same map in both codes) at every dump, the largest difference of
           a sphere's velocity between the codes is at most 10 times that between wetdem and
           wetdem from the state moved by one unit in the last place: the codes differ by
           rounding only, which this chaotic system amplifies alike. 10: the two measures are
           maxima over 2000 spheres of differences seeded at random by rounding, and were
           within a factor 3 of each other at every dump when this was written; a physical
           difference does not stay within it (next check);
  control  LIGGGHTS with Young's modulus changed by 1e-8 differs from wetdem at the first dump
           by more than 100 times the rounding reference, so the check above can fail;
  order    damped (e = 0.5): the velocity difference between the codes at 0.5 ms shrinks by
           a factor of 1.6 to 2.5 for each halving of dt (first order: 2), so the codes tend to
           the same solution and differ by their evaluation of the damping within a step;
  accuracy at each dt, wetdem's largest velocity error against a converged run (wetdem at
           3.125e-7 s) is not above LIGGGHTS'.
Usage: /usr/bin/python3 figures/liggghts_crosscheck.py [--dir out/validate/liggghts]
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import ROOT, np, plt  # noqa: E402
from many_figs import check, save_and_finish  # noqa: E402  (the many pieces' checks)

DTS = ["1e-5", "5e-6", "2.5e-6", "1.25e-6"]
DT_REFERENCE = 3.125e-7


def read_wetdem(path):
    """{step: array (n, 6) of x y z vx vy vz, by id} of a many_bench trace."""
    a = np.loadtxt(path)
    return {int(s): a[a[:, 0] == s][:, 2:] for s in np.unique(a[:, 0])}


def read_liggghts(path):
    """{step: array (n, 6)} of a LIGGGHTS dump custom of id x y z vx vy vz, sorted by id."""
    out, lines, k = {}, open(path).read().split("\n"), 0
    while k < len(lines):
        if lines[k].startswith("ITEM: TIMESTEP"):
            step, n = int(lines[k + 1]), int(lines[k + 3])
            while not lines[k].startswith("ITEM: ATOMS"):
                k += 1
            rows = np.array([r.split() for r in lines[k + 1:k + 1 + n]], float)
            if not np.array_equal(rows[:, 0], np.arange(1, n + 1)):
                check(False, f"{path}: step {step} is not sorted by id")
            out[step] = rows[:, 1:]
            k += n
        k += 1
    return out


def largest(a, b, part):
    """Largest difference of a sphere's position (part 0) or velocity (part 1) component."""
    cols = slice(0, 3) if part == 0 else slice(3, 6)
    return float(np.abs(a[:, cols] - b[:, cols]).max())


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--dir", default=os.path.join(ROOT, "out", "validate", "liggghts"))
    d = ap.parse_args().dir
    w = read_wetdem(os.path.join(d, "elastic_wetdem.txt"))
    ulp = read_wetdem(os.path.join(d, "elastic_wetdem_ulp.txt"))
    lg = read_liggghts(os.path.join(d, "elastic_liggghts.txt"))
    lge = read_liggghts(os.path.join(d, "elastic_liggghts_E.txt"))
    steps = sorted(s for s in w if s > 0)
    if sorted(lg) != sorted(w) or sorted(ulp) != sorted(w) or sorted(lge) != sorted(w):
        check(False, "the elastic traces hold other steps")
        sys.exit(1)
    dv = {k: [largest(w[s], r[s], 1) for s in steps] for k, r in
          (("liggghts", lg), ("ulp", ulp), ("E", lge))}
    dx = {k: [largest(w[s], r[s], 0) for s in steps] for k, r in
          (("liggghts", lg), ("ulp", ulp), ("E", lge))}
    ratio = [a / max(b, 1e-300) for a, b in zip(dv["liggghts"], dv["ulp"])]
    check(max(ratio) <= 10,
          f"elastic: wetdem - LIGGGHTS velocity difference / wetdem - wetdem (1 ulp) at every "
          f"dump: {min(ratio):.2g} .. {max(ratio):.2g} (<= 10); at 20 ms "
          f"{dv['liggghts'][-1]:.2g} against {dv['ulp'][-1]:.2g} m/s, positions "
          f"{dx['liggghts'][-1]:.2g} against {dx['ulp'][-1]:.2g} m")
    check(dv["E"][0] > 100 * dv["ulp"][0],
          f"control: LIGGGHTS with E x (1 + 1e-8) differs by {dv['E'][0]:.2g} m/s at "
          f"{steps[0]} steps, {dv['E'][0] / dv['ulp'][0]:.2g} x the rounding reference (> 100)")

    ref = read_wetdem(os.path.join(d, "damped_reference.txt"))
    ref_at = {round(s * DT_REFERENCE * 1e9): v for s, v in ref.items()}
    between, err_w, err_l = [], [], []
    for dt in DTS:
        wd = read_wetdem(os.path.join(d, f"damped_wetdem_{dt}.txt"))
        ld = read_liggghts(os.path.join(d, f"damped_liggghts_{dt}.txt"))
        s = sorted(x for x in wd if x > 0)[0]  # 0.5 ms
        r = ref_at[round(s * float(dt) * 1e9)]
        between.append(largest(wd[s], ld[s], 1))
        err_w.append(largest(wd[s], r, 1))
        err_l.append(largest(ld[s], r, 1))
    factors = [a / b for a, b in zip(between, between[1:])]
    check(all(1.6 <= f <= 2.5 for f in factors),
          "damped: the codes' velocity difference at 0.5 ms shrinks by "
          + ", ".join(f"{f:.2f}" for f in factors) + " per halving of dt (1.6 .. 2.5: first order)")
    check(all(a <= b for a, b in zip(err_w, err_l)),
          "damped: largest velocity error against the converged run, wetdem / LIGGGHTS: "
          + ", ".join(f"{a:.2g} / {b:.2g}" for a, b in zip(err_w, err_l))
          + " m/s at dt = " + ", ".join(DTS) + " s (wetdem not above)")

    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    t = np.array(steps) * 1e-5 * 1e3
    ax[0].semilogy(t, dv["liggghts"], "o-", ms=4, color="C0", label="wetdem - LIGGGHTS")
    ax[0].semilogy(t, dv["ulp"], "s--", ms=4, color="C2",
                   label="wetdem - wetdem with x moved by 1 ulp")
    ax[0].semilogy(t, dv["E"], "^-", ms=4, color="C3",
                   label="wetdem - LIGGGHTS with E x (1 + 1e-8)")
    ax[0].set_xlabel("t [ms]")
    ax[0].set_ylabel("largest velocity difference of a sphere [m/s]")
    ax[0].set_title("Elastic, frictionless: the same trajectories to rounding")
    ax[0].legend(fontsize=8, loc="lower right")
    dts = np.array([float(x) for x in DTS])
    ax[1].loglog(dts, err_w, "o-", color="C0", label="wetdem: error vs converged run")
    ax[1].loglog(dts, err_l, "s-", color="C1", label="LIGGGHTS: error vs converged run")
    ax[1].loglog(dts, between, "^:", color="C7", label="wetdem - LIGGGHTS")
    ax[1].loglog(dts, between[0] * dts / dts[0], "k--", lw=0.8, label="first order")
    ax[1].set_xticks(dts, [f"{x:g}" for x in dts])
    ax[1].minorticks_off()
    ax[1].set_xlabel("dt [s]")
    ax[1].set_ylabel("largest velocity difference at 0.5 ms [m/s]")
    ax[1].set_title("Damped (e = 0.5): both tend to one solution")
    ax[1].legend(fontsize=8, loc="upper left")
    fig.suptitle("2000 spheres settling in a box, from one state: wetdem against LIGGGHTS 3.8",
                 fontsize=11)
    save_and_finish(fig, "liggghts_crosscheck.png")


if __name__ == "__main__":
    main()

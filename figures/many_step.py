"""Checks and figure of the step-bound validation piece (scripts/validate.d/45-many-step.sh).

Reads the runs of a sphere pair in a constant viscous damping (relaxation time tau, in
tau.txt) at steps lambda = dt/tau from 0.02 to 0.95 (lambda_<value>/global.csv) and writes
docs/figures/many_step_bound.png. The scheme of the many-particle engine maps the speed v and
the kick u = a dt of a pure damping as u' = -lambda (v + u), v' = v + (u + u')/2, from
u = -lambda v (docs/many.md, Time step). Checks, each printed and failing the script:
  decay    the approach speed sqrt(2 K / m*) after N steps is the map's to 1e-6 (the motion is
           exactly that linear decay; the CSV carries 9 digits), for every lambda run;
  accuracy at lambda = 1/4, the bound of the derived step, the decay rate is within 3 % of
           exp(-t/tau);
  budget   the closure error |balance error| / |work| is second order in lambda: the slope of
           log(error) against log(lambda) for lambda <= 0.25 is within 1.8-2.2, and the error
           at lambda = 1/4 is below 2 % (the run's 5 % check passes).
Usage: /usr/bin/python3 figures/many_step.py [--dir out/validate/many_step]
"""
import argparse
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import ROOT, np, plt  # noqa: E402
from many_figs import check, read_global, save_and_finish  # noqa: E402  (the many pieces' checks)


def map_speed(lam, steps):
    """v_N / v_0 of the scheme's map for a pure damping at dt = lam tau."""
    v, u = 1.0, -lam
    for _ in range(steps):
        u_next = -lam * (v + u)
        v += 0.5 * (u + u_next)
        u = u_next
    return v


def spectral_radius(lam):
    """Largest |root| of z^2 - (1 - 3 lam/2) z - lam/2 (the map's amplification)."""
    return max(abs(z) for z in np.roots([1.0, -(1 - 1.5 * lam), -0.5 * lam]))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dir", default=os.path.join(ROOT, "out", "validate", "many_step"))
    args = ap.parse_args()
    tau = float(open(os.path.join(args.dir, "tau.txt")).read())
    runs = sorted((float(d.split("_", 1)[1]), os.path.join(args.dir, d))
                  for d in os.listdir(args.dir) if d.startswith("lambda_")
                  and os.path.isdir(os.path.join(args.dir, d)))
    lams, rates, map_rates, closures = [], [], [], []
    worst = 0.0
    for lam, d in runs:
        g = read_global(os.path.join(d, "global.csv"))
        steps = int(g["step"][-1])
        ratio = math.sqrt(g["kinetic"][-1] / g["kinetic"][0])
        expected = map_speed(lam, steps)
        worst = max(worst, abs(ratio / expected - 1))
        t = g["time"][-1] / tau
        lams.append(lam)
        rates.append(-math.log(ratio) / t)
        map_rates.append(-math.log(expected) / t)
        closures.append(abs(g["balance_error"][-1]) / abs(g["work_reynolds"][-1]))
    lams, rates, closures = np.array(lams), np.array(rates), np.array(closures)
    check(worst < 1e-6, f"the decay follows the scheme's map at every step (worst {worst:.1e})")
    quarter = int(np.argmin(abs(lams - 0.25)))
    check(abs(rates[quarter] - 1) < 0.03,
          f"at dt = tau/4 the decay rate is {rates[quarter]:.4f} of exp(-t/tau) (within 3 %)")
    low = lams <= 0.25 + 1e-12
    slope = np.polyfit(np.log(lams[low]), np.log(closures[low]), 1)[0]
    check(1.8 < slope < 2.2, f"the budget closes to second order (slope {slope:.2f})")
    check(closures[quarter] < 0.02,
          f"closure at dt = tau/4 is {closures[quarter]:.3g} of the work (below 2 %)")

    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    grid = np.linspace(0.005, 1.3, 300)
    ax[0].plot(grid, [spectral_radius(x) for x in grid], "k-", lw=1,
               label="largest |root| of the map (> 1: unstable)")
    ax[0].plot(grid, [(1 - 1.5 * x + math.sqrt((1 - 1.5 * x) ** 2 + 2 * x)) / 2 for x in grid],
               "k--", lw=0.8, label="its slow root (the decay)")
    ax[0].plot(grid, np.exp(-grid), "k:", lw=1, label="exact exp(-dt/tau)")
    ax[0].plot(lams, np.exp(-rates * lams), "o", color="C0", ms=5,
               label="engine: decay per step over 4 tau")
    ax[0].axhline(1, color="C3", lw=0.8)
    ax[0].axvspan(1, 1.3, color="C3", alpha=0.12, label="refused: unstable (dt >= tau)")
    ax[0].axvline(0.25, color="C2", ls="--", lw=1, label="derived step at most tau/4")
    ax[0].set_xlabel("dt / tau")
    ax[0].set_ylabel("speed ratio per step")
    ax[0].set_xlim(0, 1.3)
    ax[0].set_ylim(0, 1.2)
    ax[0].legend(fontsize=8, loc="lower left")
    ax[0].set_title("Velocity Verlet in a viscous damping")
    ax[1].loglog(lams, closures, "o-", color="C1", ms=5, label="engine: |closure| / |work|")
    ax[1].loglog(lams[low], 0.23 * lams[low] ** 2, "k:", lw=1, label="0.23 (dt/tau)^2")
    ax[1].axhline(0.05, color="C3", lw=0.8, label="the run's 5 % check")
    ax[1].axvline(0.25, color="C2", ls="--", lw=1)
    ax[1].set_xlabel("dt / tau")
    ax[1].set_ylabel("energy-budget closure error")
    ax[1].legend(fontsize=8, loc="upper left")
    ax[1].set_title("Energy budget (trapezoid rule), second order")
    save_and_finish(fig, "many_step_bound.png")


if __name__ == "__main__":
    main()

"""Report of bench/10-two-body.sh: work, wall time and accuracy of the adaptive (cvode) and
fixed-step (verlet, dt = 2 % of the Hertz time) Fig. 3 sweeps. Exits 1 when a target fails:
>= 50x fewer force evaluations with cvode, the cvode sweep under 2 s on one core, and both
within 0.5 % of the converged e on the reference subset.
Usage: two_body_report.py DIR
"""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "figures"))
import common  # noqa: E402
import numpy as np  # noqa: E402

MATERIALS = ["steel1", "steel2", "glass", "delrin"]
TOL = 0.005  # 0.5 % of the converged e


def totals(directory, label):
    """Sum of the '# totals:' trailers of the four sweeps of a label."""
    tot = {}
    for m in MATERIALS:
        with open(os.path.join(directory, f"{label}_{m}.csv")) as f:
            line = [ln for ln in f if ln.startswith("# totals:")][-1]
        for item in line[len("# totals:"):].split():
            k, v = item.split("=")
            tot[k] = tot.get(k, 0) + float(v)
    return tot


def errors(directory, label, ref):
    """Largest relative error of e against the reference on the subset points that rebound
    (separated by t_end), and the number of points where one separated and the other not."""
    worst = (0.0, "")
    mism = 0
    for m in MATERIALS:
        d = common.read_csv(os.path.join(directory, f"{label}_{m}.csv"))
        r = common.read_csv(os.path.join(directory, f"{ref}_{m}.csv"))
        st = d["collision.stokes"]
        for s, er, sr in zip(r["collision.stokes"], r["e"], r["separated"]):
            k = int(np.argmin(np.abs(np.log(st / s))))
            e, sep = d["e"][k], d["separated"][k]
            if not (sr > 0 and sep > 0):  # e of a pair that never separated is not a rebound
                mism += (sr > 0) != (sep > 0)
                continue
            rel = abs(e - er) / er
            if rel > worst[0]:
                worst = (rel, f"{m} St = {s:.4g}: e = {e:.5f} vs {er:.5f}")
    return worst, mism


def main():
    d = sys.argv[1]
    cv, vv = totals(d, "cvode"), totals(d, "verlet")
    print(f"{'':8s} {'runs':>5s} {'force evals':>13s} {'steps':>11s} {'wall [s]':>9s}")
    for name, t in (("cvode", cv), ("verlet", vv)):
        print(f"{name:8s} {t['runs']:5.0f} {t['force_evals']:13.0f} {t['steps']:11.0f} "
              f"{t['wall_time_s']:9.3f}")
    fe_ratio = vv["force_evals"] / cv["force_evals"]
    wall_ratio = vv["wall_time_s"] / cv["wall_time_s"]
    print(f"ratio verlet/cvode: force evaluations {fe_ratio:.1f}x, wall time {wall_ratio:.1f}x")
    (ref_agree, where), mism = errors(d, "check_verlet", "check_cvode")
    print(f"reference check: verlet dt = 0.2 % t_H vs cvode rtol 1e-12 at St 100..3000: max "
          f"relative difference {ref_agree:.2e} ({where}), {mism} rebound/stick mismatches")
    ok = ref_agree < TOL / 5 and mism == 0
    for label in ("cvode", "verlet"):
        (worst, where), mism = errors(d, label, "ref_cvode")
        good = worst <= TOL and mism == 0
        ok &= good
        print(f"accuracy {label:6s}: max |e - e_ref|/e_ref = {worst:.2e} ({where}); "
              f"{mism} rebound/stick mismatches  [{'ok' if good else 'FAIL'}]")
    targets = [(fe_ratio >= 50, f"cvode needs >= 50x fewer force evaluations ({fe_ratio:.1f}x)"),
               (cv["wall_time_s"] < 2.0, f"cvode sweep under 2 s on one core "
                f"({cv['wall_time_s']:.3f} s)")]
    for good, text in targets:
        print(f"[{'ok' if good else 'FAIL'}] {text}")
        ok &= good
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()

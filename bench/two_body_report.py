"""Report of bench/10-two-body.sh: work, CPU and wall time and accuracy of the adaptive (cvode,
default method auto; and bdf) and fixed-step (verlet, dt = 2 % of the Hertz time) Fig. 3 sweeps.

Ratios verlet/cvode are taken on the same collisions (the every-3rd-St subset, where both ran);
Verlet's full-sweep cost is also given as an estimate (subset x 100/34). Exits 1 when a target
fails: >= 50x fewer force evaluations with cvode, the whole cvode sweep (400 collisions) under
2 s of CPU time on one core, and every sweep within 0.5 % of the converged e on the reference
subset with the same rebound/stick outcome.
Usage: two_body_report.py DIR
"""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "figures"))
import common  # noqa: E402
import numpy as np  # noqa: E402

MATERIALS = ["steel1", "steel2", "glass", "delrin"]
TOL = 0.005  # 0.5 % of the converged e
FULL, SUBSET = 100, 34  # Stokes numbers per material in the sweep and in the Verlet subset


def totals(directory, label):
    """Sums of the '# totals:' trailers of the four sweeps of a label, plus the CPU time
    (user + sys) of the four processes from LABEL.cpu."""
    tot = {}
    for m in MATERIALS:
        with open(os.path.join(directory, f"{label}_{m}.csv")) as f:
            line = [ln for ln in f if ln.startswith("# totals:")][-1]
        for item in line[len("# totals:"):].split():
            k, v = item.split("=")
            tot[k] = tot.get(k, 0) + float(v)
    with open(os.path.join(directory, f"{label}.cpu")) as f:
        rows = [ln.split() for ln in f if ln.strip() and ln.split()[0][0].isdigit()]
    tot["cpu_s"] = sum(float(r[0]) + float(r[1]) for r in rows)
    return tot


def errors(directory, label, ref):
    """Largest relative error of e against the reference on the reference points that rebound
    (separated by t_end) in both, and the number of points where one separated and the other
    not."""
    worst = (0.0, "")
    mism = 0
    for m in MATERIALS:
        d = common.read_csv(os.path.join(directory, f"{label}_{m}.csv"))
        r = common.read_csv(os.path.join(directory, f"{ref}_{m}.csv"))
        st = d["collision.stokes"]
        for s, er, sr in zip(r["collision.stokes"], r["e"], r["separated"]):
            k = int(np.argmin(np.abs(np.log(st / s))))
            if abs(np.log(st[k] / s)) > 1e-9:
                sys.exit(f"{label}_{m}: St = {s:.6g} of the reference is not in the sweep")
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
    t = {k: totals(d, k) for k in ("cvode", "cvode_bdf", "cvode_sub", "verlet_sub")}
    est = {k: t["verlet_sub"][k] * FULL / SUBSET for k in ("force_evals", "steps", "cpu_s",
                                                            "wall_time_s")}
    est["runs"] = 4 * FULL
    print(f"{'sweep':30s} {'runs':>5s} {'force evals':>13s} {'steps':>11s} {'CPU [s]':>9s} "
          f"{'wall [s]':>9s} {'us/eval':>8s}")
    rows = [("cvode, method auto (default)", t["cvode"]), ("cvode, method bdf", t["cvode_bdf"]),
            ("subset: cvode (auto)", t["cvode_sub"]), ("subset: verlet 2 % t_H", t["verlet_sub"]),
            ("verlet, full sweep (estimate)", est)]
    for name, v in rows:
        print(f"{name:30s} {v['runs']:5.0f} {v['force_evals']:13.0f} {v['steps']:11.0f} "
              f"{v['cpu_s']:9.3f} {v['wall_time_s']:9.3f} "
              f"{1e6 * v['cpu_s'] / v['force_evals']:8.2f}")
    sub_v, sub_c = t["verlet_sub"], t["cvode_sub"]
    fe_ratio = sub_v["force_evals"] / sub_c["force_evals"]
    cpu_ratio = sub_v["cpu_s"] / sub_c["cpu_s"]
    wall_ratio = sub_v["wall_time_s"] / sub_c["wall_time_s"]
    print(f"ratio verlet/cvode on the same {4 * SUBSET} collisions: force evaluations "
          f"{fe_ratio:.0f}x, CPU time {cpu_ratio:.0f}x, wall time {wall_ratio:.0f}x")
    print(f"method: bdf / auto over the full sweep: force evaluations "
          f"{t['cvode_bdf']['force_evals'] / t['cvode']['force_evals']:.2f}x, CPU time "
          f"{t['cvode_bdf']['cpu_s'] / t['cvode']['cpu_s']:.2f}x")
    (ref_agree, where), mism = errors(d, "check_verlet", "check_cvode")
    print(f"reference check: verlet dt = 0.2 % t_H vs cvode rtol 1e-12 at St 100..3000: max "
          f"relative difference {ref_agree:.2e} ({where}), {mism} rebound/stick mismatches")
    ok = ref_agree < TOL / 5 and mism == 0
    for label in ("cvode", "cvode_bdf", "cvode_sub", "verlet_sub"):
        (worst, where), mism = errors(d, label, "ref_cvode")
        good = worst <= TOL and mism == 0
        ok &= good
        print(f"accuracy {label:10s}: max |e - e_ref|/e_ref = {worst:.2e} ({where}); "
              f"{mism} rebound/stick mismatches  [{'ok' if good else 'FAIL'}]")
    cv = t["cvode"]
    targets = [(fe_ratio >= 50, f"cvode needs >= 50x fewer force evaluations ({fe_ratio:.0f}x)"),
               (cv["cpu_s"] < 2.0, f"cvode sweep of 400 collisions under 2 s on one core "
                f"({cv['cpu_s']:.2f} s CPU, {cv['wall_time_s']:.2f} s wall)")]
    for good, text in targets:
        print(f"[{'ok' if good else 'FAIL'}] {text}")
        ok &= good
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()

"""Davis (2023) three wet spheres, pairwise engine: figures from out/validate/davis/ (written by
scripts/validate.d/30-davis.sh) into docs/figures/davis_*.png, and checks of behaviour the
derivation predicts or the paper states (Sec. VI); exits 1 when one fails.

Spheres are numbered as in Davis (1 striker, 2 target, 3 its neighbour); e_ij,w is the normal
separation speed of pair i-j at its last film separation over v_n0 (0 when still bound).
Run with /usr/bin/python3 (numpy + matplotlib).
"""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import FIGURES, ROOT, np, plt, read_csv  # noqa: E402

DATA = os.path.join(ROOT, "out", "validate", "davis")
OUTCOME_CODE = {"FA": 0, "PA": 1, "FS": 2}
failures = []


def check(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok:
        failures.append(what)


def load(name):
    return read_csv(os.path.join(DATA, name + ".csv"))


def st_of(d):
    return d["davis.stokes"]


def first_st(d, outcomes):
    """Smallest St_n whose outcome is in `outcomes` (inf if none)."""
    idx = [k for k, o in enumerate(d["outcome"]) if o in outcomes]
    return st_of(d)[idx[0]] if idx else math.inf


def closed_form_ew(st, hm=0.01, e=1.0):
    """Head-on, no capillarity: e_w = e (1 - I/St) - I/St (docs/derivations/pairwise.md Sec. 5)."""
    i = 2 - math.log(hm) - 3 * math.log(2 - hm) - 2 / (2 - hm)
    return np.maximum(0.0, e * (1 - i / st) - i / st)


def shade_outcomes(ax, d):
    colors = {"FA": "#dddddd", "PA": "#fde8c8", "FS": "#d8ecf8"}
    st = st_of(d)
    for k in range(len(st)):
        lo = st[k - 1] if k else st[k]
        hi = st[k]
        ax.axvspan(math.sqrt(lo * hi) if k else lo, math.sqrt(hi * st[min(k + 1, len(st) - 1)]),
                   color=colors[d["outcome"][k]], lw=0)


def fig_restitution():
    three, two, head = load("three"), load("two_oblique"), load("two_headon")
    head_nc, three_head = load("two_headon_nocap"), load("three_headon")
    fig, ax = plt.subplots(1, 2, figsize=(11, 4.2))
    shade_outcomes(ax[0], three)
    ax[0].semilogx(st_of(three), three["e_w_12"], "C0-", label="three spheres: $e_{12,w}$")
    ax[0].semilogx(st_of(three), three["e_w_23"], "C1-", label="three spheres: $e_{23,w}$")
    ax[0].semilogx(st_of(two), two["e_w_12"], "k--", label="two spheres, oblique 30°")
    ax[0].semilogx(st_of(head), head["e_w_12"], "k:", label="two spheres, head-on")
    ax[0].set(xlabel="$St_n$", ylabel="$e_{ij,w}$", ylim=(0, 1),
              title="β = 30°, Ca = 1000, $h_a = h_m$ = 0.01 (grey FA, orange PA, blue FS)")
    ax[0].legend(fontsize=8, loc="upper left")
    ax[1].semilogx(st_of(three_head), three_head["e_w_12"], "C0-", label="three, head-on: $e_{12,w}$")
    ax[1].semilogx(st_of(three_head), three_head["e_w_23"], "C1-", label="three, head-on: $e_{23,w}$")
    ax[1].semilogx(st_of(head_nc), head_nc["e_w_12"], "ks", ms=3, label="two, head-on, no capillarity")
    ax[1].semilogx(st_of(head_nc), closed_form_ew(st_of(head_nc)), "k-", lw=0.8,
                   label="closed form $e(1 - I/St) - I/St$")
    ax[1].set(xlabel="$St_n$", ylabel="$e_{ij,w}$", ylim=(0, 1), title="head-on (β = 0)")
    ax[1].legend(fontsize=8, loc="upper left")
    fig.tight_layout()
    fig.savefig(os.path.join(FIGURES, "davis_restitution_vs_st.png"), dpi=130)
    plt.close(fig)
    err = np.max(np.abs(head_nc["e_w_12"] - closed_form_ew(st_of(head_nc))))
    check(err < 1e-6, f"two spheres head-on, no capillarity: |e_w - closed form| = {err:.2e} < 1e-6")
    codes = [OUTCOME_CODE[o] for o in three["outcome"]]
    check(all(b >= a for a, b in zip(codes, codes[1:])),
          "three spheres, beta 30: FA, then PA, then FS as St_n grows")
    jump = np.max(np.diff(three["e_w_12"]))
    check(jump > 0.2, f"e_12,w jumps (by {jump:.2f}) when the 2-3 contact comes before the 1-2 film separation")
    rest = load("three_rest1e-4")
    dr = np.nanmax(np.abs(rest["e_w_12"] - three["e_w_12"]))
    check(dr < 1e-6, f"rest speed 1e-4 instead of 1e-3 changes e_12,w by {dr:.1e} < 1e-6")


def fig_curves(names, labels, title, fname, key="e_w_12"):
    fig, ax = plt.subplots(1, 2, figsize=(11, 4))
    for k, (n, lab) in enumerate(zip(names, labels)):
        d = load(n)
        ax[0].semilogx(st_of(d), d["e_w_12"], f"C{k}-", label=lab)
        ax[1].semilogx(st_of(d), d["e_w_23"], f"C{k}-", label=lab)
    ax[0].set(xlabel="$St_n$", ylabel="$e_{12,w}$", ylim=(0, 1), title=title)
    ax[1].set(xlabel="$St_n$", ylabel="$e_{23,w}$", ylim=(0, 1), title=title)
    ax[0].legend(fontsize=8, loc="upper left")
    fig.tight_layout()
    fig.savefig(os.path.join(FIGURES, fname), dpi=130)
    plt.close(fig)


def fig_parameters():
    fig_curves(["ca_0", "three", "ca_100", "ca_30"], ["no capillarity", "Ca = 1000", "Ca = 100",
               "Ca = 30"], "effect of Ca (β = 30°)", "davis_capillary.png")
    sep = [first_st(load(n), ("PA", "FS")) for n in ["ca_0", "three", "ca_100", "ca_30"]]
    check(all(b >= a for a, b in zip(sep, sep[1:])),
          f"stronger capillarity (smaller Ca) needs a larger St_n to separate: {sep}")
    fig_curves(["angle_0", "angle_15", "three", "angle_45", "angle_60"],
               ["β = 0°", "15°", "30°", "45°", "60°"], "effect of impact angle (Ca = 1000)",
               "davis_angle.png")
    sep = [first_st(load(n), ("PA", "FS")) for n in ["angle_0", "angle_15", "three", "angle_45",
                                                     "angle_60"]]
    check(all(b <= a for a, b in zip(sep, sep[1:])),
          f"more glancing impacts separate at smaller St_n: {sep}")
    fig, ax = plt.subplots(1, 3, figsize=(15, 4))
    for k, (n, lab) in enumerate(zip(["film_0.005", "three", "film_0.02", "film_0.05"],
                                     ["$h_a$ = 0.005", "0.01", "0.02", "0.05"])):
        d = load(n)
        ax[0].semilogx(st_of(d), d["e_w_12"], f"C{k}-", label=lab + " (groups fixed)")
        if n != "three":
            p = load("filmphys_" + n.split("_")[1])
            ax[0].semilogx(st_of(p), p["e_w_12"], f"C{k}:", label=lab + r" ($\sigma$, $h_{min}$ fixed)")
    ax[0].set(xlabel="$St_n$", ylabel="$e_{12,w}$", ylim=(0, 1), title="film thickness")
    ax[0].legend(fontsize=7)
    for k, (n, lab) in enumerate(zip(["hmin_0.001", "three", "hmin_0.05"],
                                     ["$h_m$ = 0.001", "0.01", "0.05"])):
        d = load(n)
        ax[1].semilogx(st_of(d), d["e_w_12"], f"C{k}-", label=lab)
    ax[1].set(xlabel="$St_n$", ylabel="$e_{12,w}$", ylim=(0, 1), title="minimum separation")
    ax[1].legend(fontsize=8)
    for k, (n, lab) in enumerate(zip(["friction_0", "friction_0.1", "friction_0.3"],
                                     ["$\\mu_f$ = 0", "0.1", "0.3"])):
        d = load(n)
        ax[2].semilogx(st_of(d), d["e_w_12"], f"C{k}-", label=lab + ": $e_{12,w}$")
        ax[2].semilogx(st_of(d), d["e_w_23"], f"C{k}:", label=lab + ": $e_{23,w}$")
    ax[2].set(xlabel="$St_n$", ylabel="$e_{ij,w}$", ylim=(0, 1), title="friction ($e_{dry}$ = 0.9)")
    ax[2].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(FIGURES, "davis_film_hmin_friction.png"), dpi=130)
    plt.close(fig)
    sep = [first_st(load(n), ("PA", "FS")) for n in ["hmin_0.001", "three", "hmin_0.05"]]
    check(all(b <= a for a, b in zip(sep, sep[1:])),
          f"a larger h_min (less viscous dissipation) separates at smaller St_n: {sep}")
    fs = [first_st(load(n), ("FS",)) for n in ["friction_0", "friction_0.1", "friction_0.3"]]
    check(all(b >= a for a, b in zip(fs, fs[1:])),
          f"friction delays full separation: first FS at St_n = {fs}")


def fig_map():
    d = load("map_st_angle")
    st, ang = d["davis.stokes"], d["davis.angle_deg"]
    sts, angs = np.unique(st), np.unique(ang)
    code = np.zeros((len(angs), len(sts)))
    e12 = np.zeros_like(code)
    for k in range(len(st)):
        i, j = np.searchsorted(angs, ang[k]), np.searchsorted(sts, st[k])
        o = d["outcome"][k]
        # 0 FA, 1 PA with sphere 1 leaving, 2 PA with sphere 3 leaving (or another), 3 FS
        code[i, j] = {"FA": 0, "FS": 3}.get(o, 1 if d["separated_sphere"][k] == 1 else 2)
        e12[i, j] = d["e_w_12"][k]
    fig, ax = plt.subplots(1, 2, figsize=(12, 4.5))
    cmap = plt.matplotlib.colors.ListedColormap(["#bbbbbb", "#f5b35c", "#c77cd1", "#7fb8e0"])
    ax[0].pcolormesh(sts, angs, code, cmap=cmap, vmin=-0.5, vmax=3.5, shading="nearest")
    ax[0].set(xlabel="$St_n$", ylabel="impact angle β [deg]",
              title="grey FA, orange PA (1 leaves), purple PA (3 leaves), blue FS")
    cs = ax[1].contourf(sts, angs, e12, levels=np.linspace(0, 1, 11), cmap="viridis")
    fig.colorbar(cs, ax=ax[1], label="$e_{12,w}$")
    ax[1].set(xlabel="$St_n$", ylabel="impact angle β [deg]", title="$e_{12,w}$")
    fig.tight_layout()
    fig.savefig(os.path.join(FIGURES, "davis_angle_map.png"), dpi=130)
    plt.close(fig)


def snapshot_positions(traj, n, tstar):
    """Sphere centres [mm] relative to the centre of mass (equal masses: the mean) at t*."""
    ts = traj["t_star"]
    k = min(np.searchsorted(ts, tstar), len(ts) - 1)
    # beyond the end of a run that stopped early the spheres fly freely: extrapolate
    dt = (tstar - ts[k]) * 4e-3 / (traj["vx_1"][0] if "vx_1" in traj else 1.0)
    dt = max(dt, 0.0)
    xs = np.array([traj[f"x_{i}"][k] + traj[f"vx_{i}"][k] * dt for i in range(1, n + 1)])
    ys = np.array([traj[f"y_{i}"][k] + traj[f"vy_{i}"][k] * dt for i in range(1, n + 1)])
    return (xs - np.mean(xs)) * 1e3, (ys - np.mean(ys)) * 1e3


def snapshot_box(pos, radius, aspect):
    """Limits (x0, x1, y0, y1) [mm] holding every sphere at every shown time, width/height =
    aspect, never smaller than 20 mm x 16 mm so rows where the spheres stay together keep
    one scale."""
    xs = np.concatenate([p[0] for p in pos])
    ys = np.concatenate([p[1] for p in pos])
    margin = radius * 1.15
    x0, x1 = min(xs.min() - margin, -10.0), max(xs.max() + margin, 10.0)
    y0, y1 = min(ys.min() - margin, -8.0), max(ys.max() + margin, 8.0)
    w, h = x1 - x0, y1 - y0
    if w < aspect * h:  # widen about the middle to keep the panel shape and equal aspect
        x0, x1 = 0.5 * (x0 + x1) - 0.5 * aspect * h, 0.5 * (x0 + x1) + 0.5 * aspect * h
    else:
        y0, y1 = 0.5 * (y0 + y1) - 0.5 * w / aspect, 0.5 * (y0 + y1) + 0.5 * w / aspect
    return x0, x1, y0, y1


def snapshot_row(ax_row, name, t_stars, title):
    """Spheres in the centre-of-mass frame at given t*, one scale per row (equal aspect) that
    holds every sphere at every shown time; a 5 mm scale bar in the first panel."""
    traj = read_csv(os.path.join(DATA, "snap_" + name, "trajectory.csv"))
    n = sum(1 for k in traj if k.startswith("x_"))
    radius = 2.0  # [mm]: sphere radius 2a, a = 1 mm (Table-I builder default)
    pos = [snapshot_positions(traj, n, t) for t in t_stars]
    x0, x1, y0, y1 = snapshot_box(pos, radius, 1.25)
    for ax, tstar, (xs, ys) in zip(ax_row, t_stars, pos):
        for i in range(n):
            ax.add_patch(plt.Circle((xs[i], ys[i]), radius, fc=f"C{i}", alpha=0.5))
            ax.text(xs[i], ys[i], str(i + 1), ha="center", va="center", fontsize=9, clip_on=True)
        ax.set(xlim=(x0, x1), ylim=(y0, y1), aspect="equal", xticks=[], yticks=[])
        ax.set_title(f"t* = {tstar:g}", fontsize=8)
    bx, by = x0 + 0.05 * (x1 - x0), y0 + 0.06 * (y1 - y0)
    ax_row[0].plot([bx, bx + 5], [by, by], "k-", lw=1.5)
    ax_row[0].text(bx + 2.5, by + 0.02 * (y1 - y0), "5 mm", ha="center", va="bottom", fontsize=7)
    ax_row[0].set_ylabel(title, fontsize=8)


def fig_snapshots():
    rows = [("stick", [0, 2, 5, 9.5, 20], "St 2: FA, 1 turns to 3\n(partner change)"),
            ("pa", [0, 1, 3, 8, 20], "St 7: PA, sphere 1 leaves\n(smaller scale)"),
            ("fs", [0, 0.02, 0.05, 0.2, 0.5], "St 30: FS (rapid bounces)"),
            ("theta45", [0, 1, 3, 8, 20], "St 7, θ23,0 = -45°\n(smaller scale)")]
    fig, ax = plt.subplots(len(rows), 5, figsize=(11, 9.4))
    for r, (name, ts, title) in enumerate(rows):
        snapshot_row(ax[r], name, ts, title)
    fig.suptitle("Centre-of-mass frame of the three spheres; one scale per row (5 mm bar)",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(os.path.join(FIGURES, "davis_snapshots.png"), dpi=110)
    plt.close(fig)


def fig_gaps():
    fig, ax = plt.subplots(1, 3, figsize=(14, 4))
    for a, name, title in zip(ax, ["pa", "stick", "srs2"],
                              ["St 7 (PA)", "St 2 (FA, partner change)",
                               "two spheres, St 1.2, 60°, no capillarity"]):
        t = read_csv(os.path.join(DATA, "snap_" + name, "trajectory.csv"))
        delta = 4e-5  # delta_12 = 4a h_a, a = 1 mm, h_a = 0.01
        for pair in ["12", "13", "23"]:
            if "h_" + pair in t:
                a.semilogy(t["t_hat"], t["h_" + pair] / delta, label=f"$h_{{{pair}}}/\\delta_{{12}}$")
        a.axhline(1, color="k", lw=0.5)
        a.axhline(0.01, color="k", lw=0.5, ls=":")
        a.set(xlabel=r"$\hat t = v_{n0} t / \delta_{12}$", ylabel="gap / $\\delta_{12}$",
              ylim=(5e-3, 1e2), title=title)
        a.set_xscale("symlog", linthresh=1)
        a.set_xlim(0, None)
        a.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(FIGURES, "davis_gap_time.png"), dpi=130)
    plt.close(fig)
    ev = read_csv(os.path.join(DATA, "snap_stick", "events.csv"))
    check("partner_change" in list(ev["event"]), "St 2: the striker meets sphere 3 and a partner change is logged")


def fig_energy():
    """The energy budget over time (docs/derivations/pairwise.md Sec. 11), each term over the
    initial energy E0: kinetic, capillary potential, the viscous work so far and the
    impulses' losses, whose sum with the residual is E0 at every row."""
    import json
    fig, ax = plt.subplots(1, 2, figsize=(12, 4.2))
    terms = [("kinetic", "kinetic"), ("capillary", "capillary potential"),
             ("viscous_normal", "viscous work, normal"),
             ("viscous_tangential", "viscous work, tangential"), ("contact", "impulses")]
    for a, name, title in zip(ax, ["fig3", "deepwell"],
                              ["St 2, Ca 1000 (Fig. 3: FA)",
                               "St 2, Ca 0.01: a well 150 E0 deep, e_dry = 1"]):
        t = read_csv(os.path.join(DATA, "energy_" + name, "trajectory.csv"))
        e0 = t["kinetic"][0] + t["capillary"][0] + t["gravity"][0]
        scale = np.max([np.abs(t[k]) for k, _ in terms] + [np.full(len(t["kinetic"]), abs(e0))],
                       axis=0)
        worst = np.max(np.abs(t["energy_residual"]) / scale)
        for key, label in terms:
            a.plot(t["t_star"], t[key] / e0, label=label)
        a.axhline(0, color="k", lw=0.5)
        a.set(xlabel=r"$t^* = v_{10} t / 4a$", ylabel="energy / $E_0$",
              title=f"{title}\nlargest |residual| {worst:.1e} of the largest term")
        a.set_yscale("symlog", linthresh=1e-2)
        a.set_xscale("symlog", linthresh=1e-3)
        a.set_xlim(0, t["t_star"][-1])
        a.legend(fontsize=8)
        check(worst <= 1e-5, f"{name}: the energy budget closes at every output row "
              f"(largest residual {worst:.1e} <= 1e-5 of the largest term)")
        mono = all(np.all(np.diff(t[k]) >= 0) for k in ("viscous_normal", "viscous_tangential"))
        check(mono, f"{name}: the viscous work never decreases")
        if name == "deepwell":
            with open(os.path.join(DATA, "energy_deepwell", "summary.json")) as f:
                summary = json.load(f)
            check(summary["outcome"] == "PA" and t["kinetic"][-1] > e0,
                  f"deep well: the well's energy throws sphere 3 out (PA, outcome "
                  f"{summary['outcome']}), ending with {t['kinetic'][-1] / e0:.1f} E0 of kinetic energy")
    fig.tight_layout()
    fig.savefig(os.path.join(FIGURES, "davis_energy.png"), dpi=120)
    plt.close(fig)


def main():
    os.makedirs(FIGURES, exist_ok=True)
    fig_restitution()
    fig_parameters()
    fig_map()
    fig_snapshots()
    fig_gaps()
    fig_energy()
    if failures:
        print(f"{len(failures)} check(s) failed")
        sys.exit(1)


if __name__ == "__main__":
    main()

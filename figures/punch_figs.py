"""Punch et al. (2023) simulation curves: Figs. 8 (a-d), 9, 10, 11, 12, 13 and 14 from the
sweeps of scripts/validate.d/20-punch.sh, and checks of the paper's statements on them.

Each curve NAME is NAME_lo.csv (St_n <= 0.6, t_end = 1 s) + NAME_hi.csv (t_end = 0.2 s), the
CSV of `wetdem sweep`. e_n is the fully resolved value, e_n_observed the value at 0.07 s
(Fig. 9 window); the spin is |omega_z| of the striker. A failed check prints FAIL and makes
the script exit with status 1 after all figures are drawn.

Usage: /usr/bin/python3 figures/punch_figs.py [--dir out/validate/punch]
"""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import FIGURES, ROOT, plt, read_csv  # noqa: E402

import numpy as np  # noqa: E402

ANGLES = [0, 15, 30, 45, 60]
MARK = {0: "o", 15: "s", 30: "^", 45: "D", 60: "v"}
FIG8 = {
    "fig8a": "(a) SB, NC, P_gt = 4.9 MPa",
    "fig8b": "(b) SB, C, P_gt = 23 MPa",
    "fig8c": "(c) DB, NC, P_gt = 2.6 MPa",
    "fig8d": "(d) DB, C, P_gt = 11.6 MPa",
}
failures = []


def load(d, name):
    lo, hi = read_csv(f"{d}/{name}_lo.csv"), read_csv(f"{d}/{name}_hi.csv")
    out = {k: np.concatenate([lo[k], hi[k]]) for k in lo}
    out["spin"] = np.abs(out["omega_i_z"])
    bad = out["status"] != "WETDEM_OK"
    if bad.any():
        failures.append(f"{name}: {bad.sum()} runs failed")
    return out


def check(ok, text):
    print(("ok   " if ok else "FAIL ") + text)
    if not ok:
        failures.append(text)


def save(fig, name):
    os.makedirs(FIGURES, exist_ok=True)
    path = os.path.join(FIGURES, name)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    print(f"wrote {os.path.relpath(path, ROOT)}")


def angle_panel(ax, curves, key, title, ylabel):
    for a in ANGLES:
        if a in curves:
            c = curves[a]
            ax.plot(c["stokes_n"], c[key], "-", marker=MARK[a], ms=3, label=f"{a} deg")
    ax.set_title(title, fontsize=10)
    ax.set_xlabel("St_n [-]")
    ax.set_ylabel(ylabel)
    ax.set_xlim(0, 4)
    ax.legend(fontsize=7)


def fig8_9(d):
    data = {f: {a: load(d, f"{f}_a{a}") for a in ANGLES} for f in FIG8}
    fig, axes = plt.subplots(2, 2, figsize=(10, 8), sharey=True)
    for ax, (f, title) in zip(axes.flat, FIG8.items()):
        angle_panel(ax, data[f], "e_n", title + ", fully resolved", "e_n [-]")
    save(fig, "punch_fig8.png")
    fig, ax = plt.subplots(figsize=(6, 4.5))
    angle_panel(ax, data["fig8d"], "e_n_observed", "Fig. 9: DB, C, e_n at t = 0.07 s", "e_n [-]")
    save(fig, "punch_fig9.png")
    # e_n independent of the angle in contact-bounce (St_n >= 2.5), every model (Punch Sec.
    # 4.2, the experiments). The impact angle and v_n0 = U cos(angle) refer to contact of the
    # straight-line approach (Punch Eq. 16); the contact's own restitution, e_n_contact,
    # referred to the line of centres at the closest approach, is the same at every angle
    # (spread 0.003). e_n (Punch Eq. 3, the line where the films part, turned by 1.5-2 deg
    # from contact at 60 deg) is about 0.04 higher at 60 deg (docs/engines.md).
    for f in FIG8:
        st = data[f][0]["stokes_n"]
        en = np.array([data[f][a]["e_n_contact"] for a in ANGLES])
        hi = st >= 2.5
        spread = (en.max(axis=0) - en.min(axis=0))[hi].max()
        check(spread < 0.01,
              f"{f}: e_n_contact spread over 0-60 deg at St_n >= 2.5 is {spread:.3f} < 0.01")
    # e_n rises with St_n past the critical St_n, at every angle, with no step where the
    # outcome turns from stick-rotate-separate to bounce (one rebound normal for both)
    for f in FIG8:
        for a in ANGLES:
            c = data[f][a]
            m = c["stokes_n"] >= 1.5
            drop = -np.diff(c["e_n"][m]).min()
            check(drop < 0.01, f"{f}, {a} deg: largest fall of e_n between neighbouring St_n >= 1.5 "
                  f"is {max(drop, 0.0):.4f} < 0.01")
    # SB vs DB with the c treatment: negligible difference (Punch Sec. 4.2.1)
    for a in ANGLES:
        b, dd = data["fig8b"][a], data["fig8d"][a]
        m = b["stokes_n"] >= 1.6
        diff = np.abs(b["e_n"] - dd["e_n"])[m].max()
        check(diff < 0.05, f"SB-C vs DB-C at {a} deg: max |de_n| = {diff:.3f} < 0.05 (St_n >= 1.6)")
    # Fig. 9: the 0.07 s window removes the elongated non-zero e_n at low St_n, high angle
    c = data["fig8d"][60]
    low = c["stokes_n"] <= 0.6
    full, obs = c["e_n"][low].mean(), c["e_n_observed"][low].mean()
    check(full > 0.03 and obs < 0.5 * full,
          f"60 deg, St_n <= 0.6: mean e_n {full:.3f} fully resolved, {obs:.3f} at 0.07 s")
    return data


def fig10_14(d, davis):
    curves = {"none": load(d, "fig10_none"), "Davis": davis, "Nase": load(d, "fig10_nase"),
              "Davis + capillary": load(d, "fig10_capillary")}
    for key, name, title in [("e_n_observed", "punch_fig10.png", "Fig. 10: 60 deg, t = 0.07 s"),
                             ("e_n", "punch_fig14.png", "Fig. 14: 60 deg, fully resolved")]:
        fig, ax = plt.subplots(figsize=(6, 4.5))
        for label, c in curves.items():
            ax.plot(c["stokes_n"], c[key], "-o", ms=3, label=f"tangential: {label}")
        ax.set_xlabel("St_n [-]")
        ax.set_ylabel("e_n [-]")
        ax.set_title(title + " (DB, C, P_gt = 11.6 MPa)", fontsize=10)
        ax.set_xlim(0, 4)
        ax.legend(fontsize=8)
        save(fig, name)
    st = davis["stokes_n"]
    mid, high = (st > 0.4) & (st < 1.6), st >= 2.5
    d_mid = np.abs(curves["none"]["e_n"] - davis["e_n"])[mid].max()
    d_high = np.abs(curves["none"]["e_n"] - davis["e_n"])[high].max()
    check(d_mid > 2 * d_high,
          f"tangential force matters at 0.4 < St_n < 1.6 (max de_n {d_mid:.3f}) more than in "
          f"contact-bounce (St_n >= 2.5: {d_high:.3f})")
    dn = np.abs(curves["Nase"]["e_n"] - davis["e_n"]).max()
    check(dn < 0.05, f"Davis vs Nase tangential force: max |de_n| = {dn:.3f} < 0.05")
    cap = curves["Davis + capillary"]
    dc = np.abs(cap["e_n"] - davis["e_n"])[st >= 0.4].max()
    check(dc < 0.03, f"capillary force: max |de_n| = {dc:.3f} < 0.03 for St_n >= 0.4")


def fig11_13(d, fig8d):
    mus = {0.0: fig8d[60]}
    for mu in ["0.05", "0.1", "0.2"]:
        mus[float(mu)] = load(d, f"fig11_mu{mu}")
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for mu, c in mus.items():
        ax.plot(c["stokes_n"], c["spin"], "-o", ms=3, label=f"mu_f = {mu:g}")
    ax.set_xlabel("St_n [-]")
    ax.set_ylabel("|omega_z| of the striker [rad/s]")
    ax.set_title("Fig. 11: 60 deg, DB, C, Davis, P_gt = 11.6 MPa", fontsize=10)
    ax.set_xlim(0, 4)
    ax.legend(fontsize=8)
    save(fig, "punch_fig11.png")
    fig, ax = plt.subplots(figsize=(6, 4.5))
    for mu, c in mus.items():
        ax.plot(c["stokes_n"], c["e_n"], "-o", ms=3, label=f"mu_f = {mu:g}")
    ax.set_xlabel("St_n [-]")
    ax.set_ylabel("e_n [-]")
    ax.set_title("Fig. 13: 60 deg, e_n fully resolved", fontsize=10)
    ax.set_xlim(0, 4)
    ax.set_ylim(0, 1)
    ax.legend(fontsize=8, loc="upper left")
    ins = ax.inset_axes([0.6, 0.12, 0.35, 0.35])
    for mu, c in mus.items():
        ins.plot(c["stokes_n"], c["e_n"], "-o", ms=2)
    ins.set_xlim(3.5, 3.9)
    ins.set_ylim(0.75, 0.80)
    ins.tick_params(labelsize=6)
    save(fig, "punch_fig13.png")
    st = mus[0.0]["stokes_n"]
    c05 = mus[0.05]
    peak = st[np.argmax(c05["spin"])]
    check(1.0 <= peak <= 2.0, f"60 deg, mu_f = 0.05: spin peaks at St_n = {peak:.2f} "
          "(Punch: near 1.5; accepted 1-2)")
    hi = st >= 2.5
    for mu in [0.05, 0.1, 0.2]:
        c = mus[mu]
        check(c["spin"][st >= 3.9].mean() > c["spin"][(st > 2.0) & (st < 2.2)].mean(),
              f"mu_f = {mu:g}: the spin rises again with St_n in contact-bounce")
    spins = [mus[mu]["spin"][st >= 3.9].mean() for mu in sorted(mus)]
    check(all(np.diff(spins) > 0), "the high-St_n spin grows with mu_f: " +
          ", ".join(f"{s:.2f}" for s in spins) + " rad/s")
    low = st < 1.0
    de_low = max(np.abs(mus[mu]["e_n"] - mus[0.0]["e_n"])[low].max() for mu in mus)
    de_high = max(np.abs(mus[mu]["e_n"] - mus[0.0]["e_n"])[hi].max() for mu in mus)
    check(de_low < 0.01, f"e_n independent of mu_f at St_n < 1 (max |de_n| {de_low:.4f})")
    check(de_high < 0.05, f"e_n only slightly dependent on mu_f in contact-bounce "
          f"(max |de_n| {de_high:.3f} < 0.05)")
    return mus


def fig12(d, fig8d, mus):
    fr = {a: load(d, f"fig12_mu0.05_a{a}") for a in [15, 30, 45]}
    fr[60] = mus[0.05]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.5), sharey=True)
    angle_panel(axes[0], {a: fig8d[a] for a in [15, 30, 45, 60]}, "spin", "Fig. 12(a): mu_f = 0",
                "|omega_z| of the striker [rad/s]")
    angle_panel(axes[1], fr, "spin", "Fig. 12(b): mu_f = 0.05", "|omega_z| of the striker [rad/s]")
    save(fig, "punch_fig12.png")
    peaks = []
    for a in [15, 30, 45, 60]:
        c = fig8d[a]
        st = c["stokes_n"]
        pk = c["spin"].max()
        peaks.append(pk)
        tail = c["spin"][st >= 3.0].max()
        check(tail < 0.2 * pk, f"mu_f = 0, {a} deg: contact-bounce spin {tail:.2f} < 0.2 x peak "
              f"{pk:.2f} rad/s")
    check(all(np.diff(peaks) > 0), "the peak spin grows with the angle: " +
          ", ".join(f"{p:.1f}" for p in peaks) + " rad/s")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dir", default=os.path.join(ROOT, "out", "validate", "punch"))
    d = ap.parse_args().dir
    fig8 = fig8_9(d)
    fig10_14(d, fig8["fig8d"][60])
    mus = fig11_13(d, fig8["fig8d"])
    fig12(d, fig8["fig8d"], mus)
    if failures:
        print(f"{len(failures)} check(s) failed")
        sys.exit(1)
    print("all Punch checks hold")


if __name__ == "__main__":
    main()

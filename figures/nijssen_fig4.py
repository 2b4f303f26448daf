"""Nijssen 2023 Fig. 4: restitution of head-on Delrin collisions in water for several surface
roughness values sigma, with the line where h_sigma = h_eps (the plateau: below that roughness
the surfaces deform before the asperities touch and h_min no longer decreases).

h_eps = 0.37 R* (mu v / (E* R*))^(2/5) (Nijssen Eq. 5 with the fifth root), v from St; for
equal spheres h_sigma = sigma, so the plateau roughness at a given St is sigma_eps(St) = h_eps.

Input (DIR): fig4_sigma<nm>.csv (sweeps over St at fixed sigma), fig4_plateau.csv (runs with
sigma = sigma_eps(St)), fig4_st<St>.csv (sweeps over sigma at fixed St).
Usage: nijssen_fig4.py [--dir DIR]
"""
import argparse
import glob
import os
import re

import numpy as np

import common
from common import plt


def sigma_eps(st):
    m_eff, r_eff, e_star = common.reduced("delrin")
    v = common.stokes_speed(np.asarray(st), 1e-3, m_eff, r_eff)
    return common.h_eps(v, 1e-3, r_eff, e_star)


def by_number(pattern, directory):
    out = []
    for path in glob.glob(os.path.join(directory, pattern)):
        num = float(re.search(r"([0-9.e+-]+)\.csv$", path).group(1))
        out.append((num, common.read_csv(path)))
    return sorted(out, key=lambda x: x[0])


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--dir", default=common.VALIDATE)
    a = p.parse_args()
    curves = by_number("fig4_sigma*.csv", a.dir)
    fixed_st = by_number("fig4_st*.csv", a.dir)
    plateau = common.read_csv(os.path.join(a.dir, "fig4_plateau.csv"))
    c = common.Checks("Fig. 4")
    fig, (ax, ax2) = plt.subplots(1, 2, figsize=(11.5, 4.3))
    for sigma_nm, d in curves:
        ax.semilogx(d["collision.stokes"], d["e"], lw=1.2, label=rf"$\sigma$ = {sigma_nm:g} nm")
    ax.semilogx(plateau["stokes"], plateau["e"], "k:", lw=2,
                label=r"$h_\sigma = h_\epsilon$ (plateau)")
    ax.set_xlabel("Stokes number St")
    ax.set_ylabel("restitution e")
    ax.set_xlim(1, 3000)
    ax.set_title("Nijssen 2023 Fig. 4: Delrin, head-on, water")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3, which="both")
    print(f"  {'St':>6s} {'sigma_eps [nm]':>15s} {'e(plateau)':>11s} {'spread below':>13s} "
          f"{'e(2 um)':>8s}")
    for st, d in fixed_st:
        sig, e = d["material.rough.roughness"], d["e"]
        se = float(sigma_eps(st))
        ax2.semilogx(sig * 1e9, e, "-o", ms=3, label=f"St = {st:g}")
        ax2.axvline(se * 1e9, color=ax2.lines[-1].get_color(), ls=":", lw=1)
        below = e[sig < 0.8 * se]
        spread = float(below.max() - below.min()) if len(below) > 1 else float("nan")
        print(f"  {st:6g} {se * 1e9:15.4g} {below.mean() if len(below) else float('nan'):11.4f} "
              f"{spread:13.2e} {e[-1]:8.4f}")
        if len(below) > 1:
            c.check(spread <= 0.01 * max(below.max(), 1e-3) + 1e-6,
                    f"St = {st:g}: plateau, e independent of sigma below sigma_eps = "
                    f"{se * 1e9:.3g} nm (spread {spread:.2e})")
        if below.size and below.mean() > 0:
            c.check(e[-1] >= below.mean() - 1e-9,
                    f"St = {st:g}: rougher spheres rebound at least as well (e = {e[-1]:.3f} at "
                    f"{sig[-1] * 1e9:.3g} nm vs {below.mean():.3f} on the plateau)")
    ax2.set_xlabel(r"roughness $\sigma$ [nm] (dotted: $\sigma = h_\epsilon$)")
    ax2.set_ylabel("restitution e")
    ax2.set_title("the same at fixed St: plateau left of the dotted lines")
    ax2.legend(fontsize=8)
    ax2.grid(alpha=0.3, which="both")
    common.save(fig, "nijssen_fig4.png")
    # influence of roughness strongest in the transitional regime 20 < St < 1000
    lo, hi = curves[0][1], curves[-1][1]
    st = lo["collision.stokes"]
    diff = np.abs(np.interp(st, hi["collision.stokes"], hi["e"]) - lo["e"])
    mid = diff[(st > 20) & (st < 1000)].max()
    end = diff[st >= 0.9 * st.max()].max()
    c.check(mid > end, f"roughness matters most for 20 < St < 1000 (max |de| {mid:.3f} there vs "
            f"{end:.3f} at St = {st.max():g})")
    c.finish()


if __name__ == "__main__":
    main()

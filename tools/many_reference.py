"""An independent reference of the many-particle engine (docs/many.md) in plain Python/numpy,
written from the documented step and force laws, not from the C code: velocity Verlet with the
forces at the predicted velocities and the tangential springs advanced with the slip of the
half-step velocities (docs/many.md, "Time step"), the step derived when none is given (the
speed scale with gravity's term over the fall of "What a fall adds", the contact, relaxation
and h_min crossing times of the pairs that can occur), the speeds behind it ("Speeds beyond
the step's": the speed scale V, the bound B = V - v0, infinite where nothing stops a fall,
and the largest half-step speed u of a free particle over the run), the pair and wall
geometry and signs of docs/concepts.md, the laws of docs/models.md and docs/derivations/
(hertz with damping = tsuji or exact, hooke, mindlin beside either, sb, db,
davis, nase, capillary, reynolds with a fixed h_min, nijssen with its own h_min record and
blended contact; h_min fixed, roughness, ehd, max, glass), walls, periodic axes by the minimum
image, gravity, and the energy budget (work per model by the trapezoid rule over the force
passes, the stored energy of hertz and hooke).

Each scenario below is written as a scenario file, run with `build/wetdem run` (binary VTK,
exact), and followed by the reference; positions, velocities and spins are compared at every
frame, and the budget and the speeds V, B and u of summary.json at the end, whatever the
step. A scenario without a step compares the engine's derived step (summary.json) and the
time scales `wetdem run --check` prints with the reference's. Variants of a scenario run
the engine again (3 and 4 threads; stopped at a step and resumed with --restart) against the
same reference run.

    /usr/bin/python3 tools/many_reference.py [--wetdem build/wetdem] [--only NAME]
        [--every N] [--coverage] [-v] [--mutants]

prints one line per run with the largest difference over the run of the positions (over the
largest radius), velocities and spins (R w, over the largest speed of the run), of the largest
speed u (relative) and of the budget's terms (over the larger of the input and the models'
work), and exits with 1 when a run is off by more than its tolerance: 1e-9, rounding grown
over some thousand steps (the cases agree to 1e-16..1e-13); 1e-8 with the exact damping of
hertz or nijssen, whose coefficient the engine tabulates to about 4e-9 relative
(docs/derivations/contact.md Sec. 1.3) where this reference bisects Eq. 1.7 (a shift of c by
4e-9 moves these cases by up to 2e-9). V and B agree to 1e-12 relative (a closed form of the
start; SPEED_TOL). A derived step agrees to 1e-12 where a closed form binds, 1e-9 where
mindlin's contact time does (the engine's central differences, derived_contact), 1e-8 where
the exact dashpot of hertz or nijssen does (the tabulated coefficient, derived_hertz_exact,
derived_nijssen), and the printed time scales to 1e-5 (6 digits). --every N compares a frame
every N steps, between which the engine takes its fused paths; --coverage prints what each
case exercised; --mutants checks instead that deliberate errors of the reference are detected.
Needs numpy (Debian python3-numpy); with a frame every 25 steps (the piece) about 1.8 min,
and 0.4 min for --mutants; at every step, writing and reading every frame, 5.5 min.
"""
import argparse
import functools
import json
import math
import os
import re
import subprocess
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from wetdem_vtk import read_series, read_vtk  # noqa: E402

PI = math.pi


def cross(a, b):
    """a x b of two 3-vectors (numpy's cross is slow on single vectors)."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                     a[0] * b[1] - a[1] * b[0]])


# ------------------------------------------------------------------ materials and pairs ---
class Material:
    def __init__(self, density=7780.0, youngs_modulus=1.9e11, poisson_ratio=0.27,
                 restitution=0.97, friction_dry=0.11, friction_lub=0.02, roughness=0.0,
                 film=0.0):
        self.density, self.E, self.nu = density, youngs_modulus, poisson_ratio
        self.e, self.mu_dry, self.mu_lub = restitution, friction_dry, friction_lub
        self.rough, self.film = roughness, film

    def ini(self):
        return {"density": self.density, "youngs_modulus": self.E,
                "poisson_ratio": self.nu, "restitution": self.e,
                "friction_dry": self.mu_dry, "friction_lub": self.mu_lub,
                "roughness": self.rough, "film": self.film}


@functools.lru_cache(maxsize=None)
def mixed(a, b):
    """Mixed properties of a pair (docs/concepts.md)."""
    e_star = 1.0 / ((1 - a.nu ** 2) / a.E + (1 - b.nu ** 2) / b.E)
    ga, gb = a.E / (2 * (1 + a.nu)), b.E / (2 * (1 + b.nu))
    g_star = 1.0 / ((2 - a.nu) / ga + (2 - b.nu) / gb)
    return dict(E=e_star, G=g_star, e=(a.e + b.e) / 2, mu_dry=(a.mu_dry + b.mu_dry) / 2,
                mu_lub=(a.mu_lub + b.mu_lub) / 2, rough=(a.rough + b.rough) / 2,
                film=a.film + b.film)


def beta_of(e):
    le = math.log(e)
    return le / math.sqrt(le * le + PI * PI)


@functools.lru_cache(maxsize=None)
def hertz_c_exact(e):
    """c of damping = exact: the root of ln e = -(c/2) J(c) (docs/derivations/contact.md,
    Eq. 1.7), by bisection on ln e(c), which falls monotonically."""
    if e >= 1.0:
        return 0.0

    def ln_e(c):
        if c * c < 5:
            s = math.sqrt(5 - c * c)
            j = 2 / s * math.atan2(c * s, c * c - 2.5)
        elif c * c == 5:
            j = 4 / math.sqrt(5)
        else:
            s = math.sqrt(c * c - 5)
            j = 2 / s * math.log((c * c + c * s - 2.5) / 2.5)
        return -c / 2 * j

    lo, hi, target = 0.0, 1.0, math.log(e)
    while ln_e(hi) > target:
        hi *= 2
    for _ in range(200):
        mid = (lo + hi) / 2
        if ln_e(mid) > target:
            lo = mid
        else:
            hi = mid
    return (lo + hi) / 2


# --------------------------------------------------------------------------- reference ---
class Reference:
    """The state and the step of docs/many.md. models: list of names in the order enabled
    (the budget's per-model work follows it)."""

    def __init__(self, sc):
        self.sc = sc
        self.mats = sc["materials"]
        ps = sc["particles"]
        self.n = len(ps)
        self.x = np.array([p["x"] for p in ps], float)
        self.v = np.array([p.get("v", (0, 0, 0)) for p in ps], float)
        self.w = np.array([p.get("w", (0, 0, 0)) for p in ps], float)
        self.R = np.array([p["R"] for p in ps], float)
        self.mat = [p["mat"] for p in ps]
        self.fixed = np.array([p.get("fixed", False) for p in ps])
        self.m = np.array([4 / 3 * PI * r ** 3 * self.mats[k].density
                           for r, k in zip(self.R, self.mat)])
        self.I = 0.4 * self.m * self.R ** 2
        self.g = np.array(sc.get("gravity", (0, 0, 0)), float)
        self.lo = np.zeros(3)
        self.hi = np.array(sc["box"], float)
        self.periodic = [ax in sc.get("periodic", "") for ax in "xyz"]
        self.walls = []  # (point, inward normal, material)
        for face in sc.get("walls", []):
            ax = "xyz".index(face[0])
            nrm = np.zeros(3)
            pt = np.zeros(3)
            if face.endswith("min"):
                nrm[ax] = 1.0
            else:
                nrm[ax] = -1.0
                pt[ax] = self.hi[ax]
            self.walls.append((pt, nrm, sc.get("wall_material", self.mat[0])))
        self.models = sc["models"].split()
        self.params = sc.get("params", {})
        # the largest range and record range of the models, as a multiple of R*
        self.reach_ratio = 0.0
        if {"nijssen", "reynolds"} & set(self.models) or \
                sc.get("min_separation") in ("ehd", "max"):
            self.reach_ratio = max([1.0] + [float(v) for k, v in self.params.items()
                                            if k.endswith("cutoff_ratio") or
                                            k.endswith("reset_ratio")])
        self.mu_f = sc.get("viscosity", 1e-3)
        self.sigma = sc.get("surface_tension", 0.072)
        self.dt = sc["dt"]
        self.hist = {}  # key -> dict of per-model history
        self.unwrap = np.zeros((self.n, 3))  # box lengths taken off by wraps
        self.work = {m: [0.0, 0.0] for m in self.models}  # [pairs, walls], trapezoid sums
        self.last_power = None
        # the largest |v'|^2 of a free particle over the steps so far, v' the half-step
        # velocity of the drift (docs/many.md, Speeds beyond the step's)
        self.u2 = 0.0
        # what the run exercised: evaluations with a non-zero force per model and kind,
        # Coulomb slides, pairs acting across a periodic face, the most partners acting on
        # one sphere at once, wraps
        self.cover = {"across_face": 0, "max_partners": 0,
                      "wraps": 0, "blend": 0, "below_hmin": 0}
        self.cover_model = {}

    # -------------------------------------------------------------- one pair's forces ---
    def film_gap(self, name, h, hmin, film, dt):
        """The gap a thin-film law of model `name` takes at gap h (docs/models.md): h within
        [h_min', delta] with h_min' = min(h_min, delta), h_min' below it with below_hmin = nc,
        else None (the law does not act)."""
        if not film > 0:
            return None
        hm = min(hmin, film)
        he = None
        if hm <= h <= film:
            he = h
        elif h < hm and self.params.get(name + ".below_hmin", "c") == "nc" and hm > 0:
            he = hm
        if he is None or not he > 0:
            return None
        self.cover["below_hmin"] += he != h and dt > 0
        return he

    def pair_force(self, key, ri, rj, mi, mj, mp, d, vi, vj, wi, wj, dt, wall, half=None):
        """Forces of every model on i: list of (model, F_i (3), T_i, T_j) and the new history.
        d = x_i - x_j (minimum image) for a sphere, or for a wall the normal times the
        centre's distance from it. rj, mj = inf for a wall or fixed sphere (mj). half: the
        half-step (vi, vj, wi, wj), whose slip the springs advance with (None: the slip of
        the velocities given, as at the start, where dt = 0)."""
        dist = math.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
        n = d / dist
        if wall:
            h = dist - ri
            rstar = ri
        else:
            h = dist - ri - rj
            rstar = ri * rj / (ri + rj)
        if h > max(mp["film"], self.reach_ratio * rstar):  # beyond every model's range
            return [], {}, h
        mstar = mi if math.isinf(mj) else (mj if math.isinf(mi) else mi * mj / (mi + mj))
        vn = -np.dot(vi - vj, n)
        vs = (vi + cross(wi, -ri * n)) - (vj + (np.zeros(3) if wall else
                                                   cross(wj, rj * n)))
        vt = vs - np.dot(vs, n) * n
        vts = vt
        if half is not None:
            hvi, hvj, hwi, hwj = half
            us = (hvi + cross(hwi, -ri * n)) - (hvj + (np.zeros(3) if wall else
                                                       cross(hwj, rj * n)))
            vts = us - np.dot(us, n) * n
        old = self.hist.get(key, {})
        new = {}
        out = []
        film = mp["film"]
        hmin = self.min_separation(old, new, h, vn, rstar, mp)

        def tangential(name, ft):
            ti = cross(-ri * n, ft)
            tj = np.zeros(3) if wall else cross(rj * n, -ft)
            out.append((name, ft, ti, tj))

        def normal(name, fn):
            out.append((name, fn * n, np.zeros(3), np.zeros(3)))

        hooke_k = self.params.get("hooke.stiffness", 1e6) if "hooke" in self.models else 0.0
        for name in self.models:
            if name == "hertz":
                if h < 0:
                    delta = -h
                    k = 4 / 3 * mp["E"] * math.sqrt(rstar)
                    fel = k * delta ** 1.5
                    if self.params.get("hertz.damping", "exact") == "tsuji":
                        c = -math.sqrt(5) * beta_of(mp["e"])
                        f = fel + c * math.sqrt(mstar * k) * delta ** 0.25 * vn
                    else:
                        c = hertz_c_exact(mp["e"])
                        f = max(0.0, fel + c * math.sqrt(mstar * k) * delta ** 0.25 * vn)
                    normal(name, f)
                else:
                    normal(name, 0.0)
            elif name == "hooke":
                if h < 0:
                    le = math.log(mp["e"])
                    gam = -2 * le * math.sqrt(mstar * hooke_k) / math.sqrt(le * le + PI * PI)
                    normal(name, hooke_k * (-h) + gam * vn)
                else:
                    normal(name, 0.0)
            elif name == "mindlin":
                s = old.get("s", np.zeros(3))
                if h < 0:
                    delta = -h
                    mu = mp["mu_dry"] if self.params.get("mindlin.friction", "dry") == "dry" \
                        else mp["mu_lub"]
                    if hooke_k > 0:
                        kt = 4 * mp["G"] / mp["E"] * hooke_k
                        flim = mu * hooke_k * delta
                    else:
                        kt = 8 * mp["G"] * math.sqrt(rstar * delta)
                        flim = mu * 4 / 3 * mp["E"] * math.sqrt(rstar) * delta ** 1.5
                    ft, s = mindlin_update(s, n, vt, dt, kt, mstar, mp["e"], flim, vts)
                    new["s"] = s
                    tangential(name, ft)
                else:
                    tangential(name, np.zeros(3))
            elif name in ("sb", "db"):
                f = 0.0
                he = self.film_gap(name, h, hmin, film, dt)
                if he is not None:
                    if name == "sb":
                        br = (1 - he / film) ** 2
                    else:
                        br = (1 - he / (2 * film - he)) ** 2
                    f = 6 * PI * self.mu_f * rstar ** 2 * vn / he * br
                normal(name, f)
            elif name in ("davis", "nase"):
                ft = np.zeros(3)
                he = self.film_gap(name, h, hmin, film, dt)
                if he is not None:
                    if name == "davis":
                        ft = -2 * PI * self.mu_f * rstar * math.log((2 * film - he) / he) * vt
                    else:
                        fac = max(0.0, 8 / 15 * math.log(rstar / he) + 0.9588)
                        ft = -6 * PI * self.mu_f * rstar * fac * vt
                tangential(name, ft)
            elif name == "capillary":
                f = -8 * PI * rstar * self.sigma if (film > 0 and h <= film) else 0.0
                normal(name, f)
            elif name == "reynolds":
                hco = self.params.get("reynolds.cutoff_ratio", 1.0) * rstar
                f = 0.0
                if 0 < h <= hco:
                    f = 6 * PI * self.mu_f * rstar ** 2 * vn / max(h, hmin)
                normal(name, f)
            elif name == "nijssen":
                fn, ft, st = self.nijssen(old, h, vn, vt, vts, n, rstar, mstar, mp, dt)
                new.update(st)
                out.append((name, fn * n + ft, cross(-ri * n, ft),
                            np.zeros(3) if wall else cross(rj * n, -ft)))
            else:
                raise ValueError(name)
        return out, new, h

    def min_separation(self, old, new, h, vn, rstar, mp):
        """h_min of the min-separation model (docs/models.md; docs/derivations/fluid.md
        Sec. 6), with its record kept in the pair's history."""
        model = self.sc.get("min_separation", "fixed")
        if model == "fixed":
            return self.params.get("fixed.h_min", 1e-6)
        if model == "roughness":
            return mp["rough"]
        if model in ("ehd", "max"):
            reset = self.params.get(model + ".reset_ratio", 1.0) * rstar
            v0 = max(vn, 0.0)
            if h <= reset:
                v0 = max(old.get("v0_ms", 0.0), v0)
                new["v0_ms"] = v0
            heps = 0.37 * rstar * (self.mu_f * v0 / (mp["E"] * rstar)) ** 0.4
            return heps if model == "ehd" else max(heps, mp["rough"])
        if model == "glass":
            film = mp["film"]
            mode = self.params.get("glass.speed", "max")
            if mode == "current":
                v = abs(vn)
            elif h > film:
                v = max(vn, 0.0)
            else:
                first = old.get("glass_first")
                if first is None:
                    first = max(vn, 0.0)
                largest = max(old.get("glass_max", 0.0), vn)
                new["glass_first"], new["glass_max"] = first, largest
                v = first if mode == "initial" else largest
            return min(math.sqrt(3 * self.mu_f * rstar * v /
                                 self.params.get("glass.p_gt", 1.16e7)), film)
        raise ValueError(model)

    def nijssen(self, old, h, vn, vt, vts, n, rstar, mstar, mp, dt):
        """Nijssen Eqs. 1, 3-10 as docs/derivations/fluid.md Sec. 5 states them."""
        hco = self.params.get("nijssen.cutoff_ratio", 1.0) * rstar
        if h > hco:
            return 0.0, np.zeros(3), {}
        v0 = max(old.get("v0", 0.0), vn)
        h_sig = mp["rough"]
        h_eps = 0.37 * rstar * (self.mu_f * max(v0, 0.0) / (mp["E"] * rstar)) ** 0.4
        hmin = max(h_sig, h_eps)
        st = {"v0": v0, "hmin": hmin}
        fl = 6 * PI * self.mu_f * rstar ** 2 * vn / max(h, hmin)
        dn = max(0.0, hmin - h)
        k = 4 / 3 * mp["E"] * math.sqrt(rstar)
        fel = k * dn ** 1.5
        if self.params.get("nijssen.damping", "exact") == "tsuji":
            c = -math.sqrt(5) * beta_of(mp["e"])
        else:
            c = hertz_c_exact(mp["e"])
        fc = max(0.0, fel + c * math.sqrt(mstar * k) * dn ** 0.25 * vn) if dn > 0 else 0.0
        if h > hmin:
            fn, wc = fl, 0.0
        elif h > 0:
            self.cover["blend"] += dt > 0
            wc = (hmin - h) / hmin
            fn = (h / hmin) * fl + wc * fc
        else:
            fn, wc = fc, 1.0
        ft = np.zeros(3)
        if dn > 0:
            mu = mp["mu_dry"] if h_sig >= h_eps else mp["mu_lub"]
            kt = 8 * mp["G"] * math.sqrt(rstar * dn)
            ft, s = mindlin_update(old.get("s", np.zeros(3)), n, vt, dt, kt, mstar, mp["e"],
                                   mu * wc * fel, vts)
            st["s"] = s
        return fn, ft, st

    # --------------------------------------------------------------------- force pass ---
    def near_pairs(self):
        """The pairs (i < j, in order) that any model may act on: a gap below the largest
        film sum plus reach_ratio R_max (with a margin); the others are out of range and get a
        fresh history, as pair_force gives them."""
        x = self.x
        d = x[:, None, :] - x[None, :, :]
        L = self.hi - self.lo
        for a in range(3):
            if self.periodic[a]:
                d[:, :, a] -= L[a] * np.round(d[:, :, a] / L[a])
        h = np.sqrt(np.sum(d * d, axis=2)) - self.R[:, None] - self.R[None, :]
        film = max(m.film for m in self.mats) * 2
        far = film + self.reach_ratio * self.R.max() + 1e-9
        near = (h <= 1.01 * far) & ~(self.fixed[:, None] & self.fixed[None, :])
        ii, jj = np.nonzero(np.triu(near, 1))
        return zip(ii.tolist(), jj.tolist())

    def forces(self, v, w, dt, keep, vh=None, wh=None):
        """The force pass at velocities v and spins w; the springs advance over dt with the
        slip of the half-step ones vh, wh (None: of v, w)."""
        F = np.zeros((self.n, 3))
        T = np.zeros((self.n, 3))
        power = {m: [0.0, 0.0] for m in self.models}
        newhist = {}
        L = self.hi - self.lo
        partners = np.zeros(self.n, int)
        for i, j in self.near_pairs():
            if True:
                d = self.x[i] - self.x[j]
                for a in range(3):
                    if self.periodic[a]:
                        d[a] -= L[a] * round(d[a] / L[a])
                mi = math.inf if self.fixed[i] else self.m[i]
                mj = math.inf if self.fixed[j] else self.m[j]
                mp = mixed(self.mats[self.mat[i]], self.mats[self.mat[j]])
                half = None if vh is None else (vh[i], vh[j], wh[i], wh[j])
                out, new, h = self.pair_force((i, j), self.R[i], self.R[j], mi, mj, mp, d,
                                              v[i], v[j], w[i], w[j], dt, False, half)
                newhist[(i, j)] = new
                crossed = any(self.periodic[a] and abs(self.x[i][a] - self.x[j][a]) > L[a] / 2
                              for a in range(3))
                if keep and any(np.any(f != 0) for _, f, _, _ in out):
                    partners[i] += 1
                    partners[j] += 1
                    self.cover["across_face"] += crossed
                self.count(out, "pairs", keep)
                for name, f, ti, tj in out:
                    F[i] += f
                    F[j] -= f
                    T[i] += ti
                    T[j] += tj
                    power[name][0] += (np.dot(f, v[i] - v[j]) + np.dot(ti, w[i]) +
                                       np.dot(tj, w[j]))
        for i in range(self.n):
            if self.fixed[i]:
                continue
            for k, (pt, nrm, wm) in enumerate(self.walls):
                dist = np.dot(self.x[i] - pt, nrm)
                mp = mixed(self.mats[self.mat[i]], self.mats[wm])
                half = None if vh is None else (vh[i], np.zeros(3), wh[i], np.zeros(3))
                out, new, h = self.pair_force((i, "w", k), self.R[i], math.inf, self.m[i],
                                              math.inf, mp, dist * nrm, v[i], np.zeros(3),
                                              w[i], np.zeros(3), dt, True, half)
                newhist[(i, "w", k)] = new
                if keep and any(np.any(f != 0) for _, f, _, _ in out):
                    partners[i] += 1
                self.count(out, "walls", keep)
                for name, f, ti, tj in out:
                    F[i] += f
                    T[i] += ti
                    power[name][1] += np.dot(f, v[i]) + np.dot(ti, w[i])
        if keep:
            self.hist = newhist
            self.cover["max_partners"] = max(self.cover["max_partners"], int(partners.max()))
        return F, T, power

    def count(self, out, kind, keep):
        if not keep:
            return
        for name, f, ti, tj in out:
            if np.any(f != 0):
                key = f"{name}.{kind}"
                self.cover_model[key] = self.cover_model.get(key, 0) + 1

    # ------------------------------------------------------------------ energies ---
    def kinetic(self):
        free = ~self.fixed
        return float(np.sum(0.5 * self.m[free] * np.sum(self.v[free] ** 2, axis=1)) +
                     np.sum(0.5 * self.I[free] * np.sum(self.w[free] ** 2, axis=1)))

    def potential(self):
        free = ~self.fixed
        xu = self.x + self.unwrap
        return float(-np.sum(self.m[free] * (xu[free] @ self.g)))

    # --------------------------------------------------------------------------- run ---
    def start(self):
        self.F, self.T, p = self.forces(self.v, self.w, 0.0, keep=False)
        self.last_power = p
        self.E0 = self.kinetic() + self.potential()
        self.input = self.E0 + self.elastic()

    def step(self):
        dt = self.dt
        free = ~self.fixed
        a = np.where(free[:, None], self.F / self.m[:, None] + self.g, 0.0)
        al = np.where(free[:, None], self.T / self.I[:, None], 0.0)
        vh = self.v + a * dt / 2
        wh = self.w + al * dt / 2
        if free.any():
            self.u2 = max(self.u2, float(np.max(np.sum(vh[free] ** 2, axis=1))))
        self.x = self.x + vh * dt
        for ax in range(3):
            if self.periodic[ax]:
                L = self.hi[ax] - self.lo[ax]
                under = self.x[:, ax] < self.lo[ax]
                over = self.x[:, ax] >= self.hi[ax]
                self.x[under, ax] += L
                self.unwrap[under, ax] -= L
                self.x[over, ax] -= L
                self.unwrap[over, ax] += L
                self.cover["wraps"] += int(under.sum() + over.sum())
        vp = vh + a * dt / 2
        wp = wh + al * dt / 2
        self.F, self.T, p = self.forces(vp, wp, dt, keep=True, vh=vh, wh=wh)
        a = np.where(free[:, None], self.F / self.m[:, None] + self.g, 0.0)
        al = np.where(free[:, None], self.T / self.I[:, None], 0.0)
        self.v = vh + a * dt / 2
        self.w = wh + al * dt / 2
        # trapezoid: the previous pass's half was counted; add its other half and this half
        for m in self.models:
            for k in (0, 1):
                self.work[m][k] += 0.5 * dt * (self.last_power[m][k] + p[m][k])
        self.last_power = p

    def elastic(self):
        """Stored energy of hertz and hooke over the pairs and walls (docs/many.md)."""
        tot = 0.0
        hooke_k = self.params.get("hooke.stiffness", 1e6)
        L = self.hi - self.lo

        def store(h, rstar, mp, key):
            s = 0.0
            hm = self.hist.get(key, {}).get("hmin")
            if "nijssen" in self.models and hm is not None and h < hm:
                # the potential of the lever-blended elastic force (docs/many.md)
                k = 4 / 3 * mp["E"] * math.sqrt(rstar)
                d = hm - h
                if h > 0:
                    s += 2 / 7 * k * d ** 3.5 / hm
                else:
                    s += 2 / 7 * k * hm ** 2.5 + 2 / 5 * k * (d ** 2.5 - hm ** 2.5)
            if h >= 0:
                return s
            if "hertz" in self.models:
                s += 8 / 15 * mp["E"] * math.sqrt(rstar) * (-h) ** 2.5
            if "hooke" in self.models:
                s += hooke_k * h * h / 2
            return s
        for i in range(self.n):
            for j in range(i + 1, self.n):
                if self.fixed[i] and self.fixed[j]:
                    continue
                d = self.x[i] - self.x[j]
                for a in range(3):
                    if self.periodic[a]:
                        d[a] -= L[a] * round(d[a] / L[a])
                h = np.linalg.norm(d) - self.R[i] - self.R[j]
                mp = mixed(self.mats[self.mat[i]], self.mats[self.mat[j]])
                tot += store(h, self.R[i] * self.R[j] / (self.R[i] + self.R[j]), mp, (i, j))
            if not self.fixed[i]:
                for k, (pt, nrm, wm) in enumerate(self.walls):
                    h = np.dot(self.x[i] - pt, nrm) - self.R[i]
                    tot += store(h, self.R[i], mixed(self.mats[self.mat[i]], self.mats[wm]),
                                 (i, "w", k))
        return tot


def mindlin_update(s, n, vt, dt, kt, mstar, e, flim, vs):
    """docs/derivations/contact.md Sec. 2: rotate s into the tangent plane keeping its
    length, advance by v_s dt (the slip of the half-step velocities), trial force spring +
    dashpot (at v_t), cap at flim with the spring set to match."""
    sp = s - np.dot(s, n) * n
    ns, nsp = np.linalg.norm(s), np.linalg.norm(sp)
    s = sp * (ns / nsp) if nsp > 0 else np.zeros(3)
    s = s + vs * dt
    gam = -2 * math.sqrt(5 / 6) * beta_of(e) * math.sqrt(mstar * kt)
    f = -kt * s - gam * vt
    nf = np.linalg.norm(f)
    if nf > flim:
        f = f * (flim / nf)
        s = -(f + gam * vt) / kt
        SLIDES[0] += 1
    else:
        SLIDES[1] += 1
    return f, s


SLIDES = [0, 0]


# ------------------------------------------------------------------ the derived step ---
def glass_hmin(mu_f, rstar, v, p_gt, film):
    """glass's h_min = min((3 mu a v / P_gt)^(1/2), delta), a = R* (docs/models.md)."""
    return min(math.sqrt(3 * mu_f * rstar * v / p_gt), film)


# t_c = (4/5)(15/16)^(2/5) B(2/5, 1/2) (m*^2/(E*^2 R* v))^(1/5), docs/derivations/contact.md
# Eq. 1.8
HERTZ_TC = 0.8 * (15 / 16) ** 0.4 * math.gamma(0.4) * math.gamma(0.5) / math.gamma(0.9)


# the thin-film laws whose force jumps to zero at h_min with below_hmin = c (docs/many.md,
# Travel per step)
JUMPING_LAWS = ("sb", "db", "davis", "nase")


def face_walls(sc):
    """The walls of [walls] faces: (a point, the unit normal into the box)."""
    out = []
    for face in sc.get("walls", []):
        ax = "xyz".index(face[0])
        nrm, pt = np.zeros(3), np.zeros(3)
        nrm[ax] = 1.0 if face.endswith("min") else -1.0
        if face.endswith("max"):
            pt[ax] = sc["box"][ax]
        out.append((pt, nrm))
    return out


def fall_height(sc):
    """H of docs/many.md, *What a fall adds*: with g^ the unit gravity and heights h = -g^.x,
    the largest over the free spheres of (1) for each wall that faces up, a = -n.g^ > 0,
    U - R_min (1 - a)/a + (max over the box B of the free centres of t.x - n.q)/a, with t =
    n + a g^, U the largest h - R, R_min the smallest free radius; (2) the highest free
    centre's fall to min over fixed spheres of (h - R) less the largest free radius; (3) the
    extent of the free centres' heights. 0 without gravity or free spheres."""
    gv = np.array(sc.get("gravity", (0, 0, 0)), float)
    g = math.sqrt(float(gv @ gv))
    free = [p for p in sc["particles"] if not p.get("fixed")]
    if g == 0 or not free:
        return 0.0
    gh = gv / g
    xs = np.array([p["x"] for p in free], float)
    rs = np.array([p["R"] for p in free], float)
    h = -(xs @ gh)
    terms = [h.max() - h.min()]
    fixed = [p for p in sc["particles"] if p.get("fixed")]
    if fixed:
        low = min(-float(np.array(p["x"], float) @ gh) - p["R"] for p in fixed)
        terms.append(h.max() - low + rs.max())
    u, lo, hi = (h - rs).max(), xs.min(axis=0), xs.max(axis=0)
    for q, n in face_walls(sc):
        a = -float(n @ gh)
        if a > 0:
            t = n + a * gh
            across = sum(max(t[k] * lo[k], t[k] * hi[k]) for k in range(3))
            terms.append(u - rs.min() * (1 - a) / a + (across - float(n @ q)) / a)
    return max(max(terms), 0.0)


def speed_scale(sc):
    """The speed scale V and the speed bound B of docs/many.md (*Time step*, *Speeds beyond
    the step's*) from the scenario alone: V = 2 v0 + sqrt(2 |g| H), at least sim.speed_floor
    (1e-3 m/s), v0 the largest particle speed at the start (spins not counted) and H the fall
    of *What a fall adds*; B = V - v0, infinite where gravity acts and neither a wall nor a
    fixed sphere stops a fall (everything falls together)."""
    ps = sc["particles"]
    g = math.sqrt(sum(c * c for c in sc.get("gravity", (0, 0, 0))))
    v0 = max(math.sqrt(sum(c * c for c in p.get("v", (0, 0, 0)))) for p in ps)
    speed = max(1e-3, 2 * v0 + math.sqrt(2 * g * fall_height(sc)))
    stops = bool(sc.get("walls")) or any(p.get("fixed") for p in ps)
    return speed, (math.inf if g > 0 and not stops else speed - v0)


def step_scales(sc):
    """The derived step of docs/many.md, *Time step*, from the scenario alone: the speed
    scale, and over the pairs that can occur the shortest contact time (normal or
    tangential), viscous relaxation time and time to cross the smallest gap where the laws
    jump; dt the shortest of dt_fraction (0.02) of the first, a quarter of the second and
    many_hmin_fraction (0.5) of the third. Every force model is written out, for the
    combinations the engine accepts (it refuses hertz with hooke, both a normal contact, and
    nijssen beside either or mindlin)."""
    mats = sc["materials"]
    ps = sc["particles"]
    models = sc["models"].split()
    params = sc.get("params", {})
    mu_f = sc.get("viscosity", 1e-3)

    def mass(p):
        return 4 / 3 * PI * p["R"] ** 3 * mats[p["mat"]].density
    free = [p for p in ps if not p.get("fixed")]
    fixed = [p for p in ps if p.get("fixed")]
    walls = bool(sc.get("walls"))
    speed = speed_scale(sc)[0]
    first_min = functools.partial(min, key=lambda p: p["R"])  # the first of equal radii
    first_max = functools.partial(max, key=lambda p: p["R"])
    small = first_min(free) if free else first_min(ps)
    probes = []  # (partner radius, partner mass, is a wall)
    if len(free) >= 2 or not (fixed or walls):
        probes.append((small["R"], mass(small), False))
    if len(free) >= 2:
        big = first_max(free)
        probes.append((big["R"], mass(big), False))
    if free and fixed:
        probes += [(first_min(fixed)["R"], math.inf, False),
                   (first_max(fixed)["R"], math.inf, False)]
    if free and walls:
        probes.append((math.inf, math.inf, True))
    used = {p["mat"] for p in ps}
    wall_mat = sc.get("wall_material", ps[0]["mat"])
    ms = sc.get("min_separation", "fixed")
    hooke_k = params.get("hooke.stiffness", 1e6)
    t_contact = tau = gap = math.inf
    for a in range(len(mats)):
        for b in range(len(mats)):
            for r_j, m_j, wall in probes:
                mp = mixed(mats[a], mats[b])
                m_i = mass(small)
                mstar = m_i if math.isinf(m_j) else m_i * m_j / (m_i + m_j)
                rstar = small["R"] if wall else small["R"] * r_j / (small["R"] + r_j)
                k = 4 / 3 * mp["E"] * math.sqrt(rstar)
                le = math.log(mp["e"])
                gam = -2 * le * math.sqrt(mstar * hooke_k) / math.sqrt(le * le + PI * PI)
                # normal contact time: hertz's (also with fluid forces alone), hooke's
                # damped half period; the tangential one beside mindlin
                t_hertz = HERTZ_TC * (mstar ** 2 / (mp["E"] ** 2 * rstar * speed)) ** 0.2
                t_n = math.inf
                if "hertz" in models or "nijssen" in models:
                    t_n = t_hertz
                if "hooke" in models:
                    t_n = min(t_n, PI / math.sqrt(hooke_k / mstar - (gam / (2 * mstar)) ** 2))
                if math.isinf(t_n):
                    t_n = t_hertz
                t = t_n
                if "mindlin" in models or "nijssen" in models:
                    # nijssen's spring on the shifted overlap d: k_t / k_n = 8 G* sqrt(R* d) /
                    # (2 E* sqrt(R* d)), mindlin's ratio at every overlap (docs/many.md)
                    t = min(t, t_n * math.sqrt(mp["E"] / (14 * mp["G"])))
                t_contact = min(t_contact, t)
                if not (a in used and (b == wall_mat if wall else b in used)):
                    continue
                # the viscous relaxation times at the speed scale
                if ms == "fixed":
                    hmin = params.get("fixed.h_min", 1e-6)
                elif ms == "roughness":
                    hmin = mp["rough"]
                else:  # ehd, max: the elastohydrodynamic gap at the speed scale
                    hmin = 0.37 * rstar * (mu_f * speed / (mp["E"] * rstar)) ** 0.4
                    if ms == "max":
                        hmin = max(hmin, mp["rough"])
                film = mp["film"]
                if ms == "glass":  # docs/models.md, glass: at the speed scale, capped at delta
                    hmin = glass_hmin(mu_f, rstar, speed, params.get("glass.p_gt", 1.16e7),
                                      film)
                hf = min(hmin, film)
                dmax = (5 * mstar * speed ** 2 / (4 * k)) ** 0.4
                for name in models:
                    if name == "hertz" and mp["e"] < 1:
                        c = (-math.sqrt(5) * beta_of(mp["e"])
                             if params.get("hertz.damping", "exact") == "tsuji"
                             else hertz_c_exact(mp["e"]))
                        tau = min(tau, mstar / (c * math.sqrt(mstar * k) * dmax ** 0.25))
                    elif name == "hooke" and mp["e"] < 1:
                        tau = min(tau, mstar / gam)
                    elif name == "mindlin" and mp["e"] < 1:
                        kt = (4 * mp["G"] / mp["E"] * hooke_k if "hooke" in models
                              else 8 * mp["G"] * math.sqrt(rstar * dmax))
                        gt = -2 * math.sqrt(5 / 6) * beta_of(mp["e"]) * math.sqrt(mstar * kt)
                        tau = min(tau, 2 / 7 * mstar / gt)
                    elif name in ("sb", "db") and film > 0:
                        br = (1 - hf / film) ** 2 if name == "sb" else \
                            (1 - hf / (2 * film - hf)) ** 2
                        tau = min(tau, mstar / (6 * PI * mu_f * rstar ** 2 / hf * br))
                    elif name == "davis" and film > 0:
                        cd = 2 * PI * mu_f * rstar * math.log((2 * film - hf) / hf)
                        tau = min(tau, 2 / 7 * mstar / cd)
                    elif name == "nase" and film > 0:
                        fac = max(0.0, 8 / 15 * math.log(rstar / hf) + 0.9588)
                        tau = min(tau, 2 / 7 * mstar / (6 * PI * mu_f * rstar * fac))
                    elif name == "reynolds":
                        tau = min(tau, mstar / (6 * PI * mu_f * rstar ** 2 / hmin))
                    elif name == "nijssen":
                        # its own h_min at the speed scale (docs/models.md), its lubrication
                        # there, and its hertz and mindlin dashpots at the largest shifted
                        # overlap of an undamped approach (docs/many.md, Viscous relaxation)
                        hn = max(mp["rough"], 0.37 * rstar * (mu_f * speed / (mp["E"] * rstar))
                                 ** 0.4)
                        tau = min(tau, mstar / (6 * PI * mu_f * rstar ** 2 / hn))
                        if mp["e"] < 1:
                            dn = (1.25 * mstar * speed ** 2 / k + 2 / 7 * hn ** 2.5) ** 0.4
                            c = (-math.sqrt(5) * beta_of(mp["e"])
                                 if params.get("nijssen.damping", "exact") == "tsuji"
                                 else hertz_c_exact(mp["e"]))
                            tau = min(tau, mstar / (c * math.sqrt(mstar * k) * dn ** 0.25))
                            kt = 8 * mp["G"] * math.sqrt(rstar * dn)
                            gt = -2 * math.sqrt(5 / 6) * beta_of(mp["e"]) * math.sqrt(mstar * kt)
                            tau = min(tau, 2 / 7 * mstar / gt)
                    elif name not in ("hertz", "hooke", "mindlin", "capillary"):
                        raise ValueError(f"no derived step for {name} here")
                # the jump at h_min' of the thin-film laws cut off below it (c), inside
                # their range (the film); nase's only where its factor is positive there
                for name in JUMPING_LAWS:
                    if name in models and film > 0 and 0 < hf < film and \
                            params.get(name + ".below_hmin", "c") == "c" and \
                            (name != "nase" or 8 / 15 * math.log(rstar / hf) + 0.9588 > 0):
                        gap = min(gap, hf)
    fraction = params.get("verlet.dt_fraction", 0.02)
    crossing = gap / speed
    dt = min(fraction * t_contact, 0.25 * tau, 0.5 * crossing)
    return dict(speed=speed, contact=t_contact, tau=tau, crossing=crossing, dt=dt)


# ------------------------------------------------------------------ scenario files ---
def write_ini(sc, path, steps, every=1, checkpoint=False):
    lines = ["[box]"]
    for ax, size in zip("xyz", sc["box"]):
        lines.append(f"size_{ax} = {size!r}")
    lines.append("periodic = " + (" ".join(sc.get("periodic", "")) or "none"))
    lines += ["[walls]", "faces = " + (" ".join(sc.get("walls", [])) or "none")]
    if sc.get("walls"):
        lines.append(f"material = m{sc.get('wall_material', sc['particles'][0]['mat'])}")
    for k, m in enumerate(sc["materials"]):
        lines.append(f"[material.m{k}]")
        lines += [f"{key} = {val!r}" for key, val in m.ini().items()]
    lines += ["[fluid]", f"viscosity = {sc.get('viscosity', 1e-3)!r}",
              f"surface_tension = {sc.get('surface_tension', 0.072)!r}"]
    lines += ["[models]", "force = " + sc["models"],
              "min_separation = " + sc.get("min_separation", "fixed")]
    sections = {}
    integrator = []  # verlet's parameters: [integrator]
    for key, val in sc.get("params", {}).items():
        model, name = key.split(".")
        if model == "verlet":
            integrator.append(f"{name} = {val}")
        else:
            sections.setdefault(model, []).append(f"{name} = {val}")
    for model, keys in sections.items():
        lines += [f"[model.{model}]"] + keys
    g = sc.get("gravity", (0, 0, 0))
    lines += ["[sim]"] + [f"gravity_{ax} = {gv!r}" for ax, gv in zip("xyz", g)]
    for k, p in enumerate(sc["particles"]):
        lines += [f"[particle.p{k}]", f"material = m{p['mat']}", f"radius = {p['R']!r}"]
        lines += [f"{ax} = {val!r}" for ax, val in zip("xyz", p["x"])]
        lines += [f"v{ax} = {val!r}" for ax, val in zip("xyz", p.get("v", (0, 0, 0)))]
        lines += [f"spin_{ax} = {val!r}" for ax, val in zip("xyz", p.get("w", (0, 0, 0)))]
        if p.get("fixed"):
            lines.append("fixed = yes")
    # a given step, without the bound on the travel per step; or the step derived by the
    # engine, with that bound at its default (docs/many.md, Time step)
    if sc["dt"] is None:
        lines += (["[integrator]"] + integrator if integrator else []) + \
            ["[run]", f"steps = {steps}", "energy_budget = yes"]
    else:
        lines += ["[integrator]", "many_hmin_fraction = 0"] + integrator + \
            ["[run]", f"steps = {steps}", f"dt = {sc['dt']!r}", "energy_budget = yes"]
    # a skin of 0.5 um rebuilds the lists every few steps, so that the histories are carried
    # across many rebuilds
    lines.append(f"skin = {sc.get('skin', 5e-7)!r}")
    lines += ["[dump]", f"vtk_every = {every}", "vtk_binary = yes", f"csv_every = {every}",
              "checkpoint = " + ("checkpoint.ckpt" if checkpoint else "none")]
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def engine_run(sc, wetdem, steps, every, tmp, threads, restart_at=None, threads_after=None,
               every_after=None):
    """Runs the case through wetdem in directory tmp on `threads` threads; with restart_at,
    the run ends at that step (writing its checkpoint) and `--restart` resumes it to `steps`
    on threads_after threads with a frame every every_after steps (the CLI's changes between
    the calls of a run), in the same directory. Returns the frames {step: frame} of the
    directory's index and summary.json."""
    ini = os.path.join(tmp, "case.ini")
    write_ini(sc, ini, steps if restart_at is None else restart_at, every,
              checkpoint=restart_at is not None)

    def run(args, n):
        r = subprocess.run([wetdem, "run", ini, "--out", tmp] + args, capture_output=True,
                           text=True, env=dict(os.environ, OMP_NUM_THREADS=str(n),
                                               OMP_WAIT_POLICY="passive"))
        if r.returncode != 0:
            raise RuntimeError(f"{sc['name']}: wetdem exit {r.returncode}: {r.stderr}")
    run([], threads)
    if restart_at is not None:
        run(["--restart", os.path.join(tmp, "checkpoint.ckpt"), "--set", f"run.steps={steps}",
             "--set", f"dump.vtk_every={every_after or every}"], threads_after or threads)
    summary = json.load(open(os.path.join(tmp, "summary.json")))
    dt = summary["dt_s"]
    series = read_series(os.path.join(tmp, "particles.vtk.series"))
    return {round(t / dt): read_vtk(p) for t, p in series}, summary


def engine_check(sc, wetdem, tmp):
    """The time scales `wetdem run --check` prints (6 digits; inf where a line is left out:
    no such bound)."""
    ini = os.path.join(tmp, "check.ini")
    write_ini(sc, ini, sc["steps"])
    r = subprocess.run([wetdem, "run", ini, "--check"], capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{sc['name']}: wetdem --check exit {r.returncode}: {r.stderr}")
    out = {}
    for key, label in (("contact", "contact time"), ("tau", "relaxation"),
                       ("crossing", "h_min crossed")):
        hit = re.search(r"^\s*" + label + r"\s+(\S+) s", r.stdout, re.M)
        out[key] = float(hit.group(1)) if hit else math.inf
    return out


def budget_diff(ref, summary, verbose=False):
    """The largest difference of a term of summary.json's energy budget from the
    reference's, over the larger of the input and the models' work."""
    e = summary["energy_J"]
    kin, pot, ela = ref.kinetic(), ref.potential(), ref.elastic()
    # the budget counts the latest pass's power by half (trapezoid), as ref.work holds it
    wscale = max(abs(e["input"]), sum(abs(m["pairs"]) + abs(m["walls"])
                                      for m in e["work_by_model"]), 1e-300)
    total_work = sum(a + b for a, b in ref.work.values())
    bud = {"kinetic": abs(e["kinetic"] - kin), "potential": abs(e["potential"] - pot),
           "elastic": abs(e["elastic"] - ela), "input": abs(e["input"] - ref.input),
           "dissipated": abs(e["dissipated"] - (ref.input - kin - pot - ela)),
           "work_total": abs(e["work_total"] - total_work),
           "balance_error": abs(e["balance_error"] - ((kin + pot - ref.E0) - total_work))}
    for m in e["work_by_model"]:
        bud[m["model"] + ".pairs"] = abs(m["pairs"] - ref.work[m["model"]][0])
        bud[m["model"] + ".walls"] = abs(m["walls"] - ref.work[m["model"]][1])
    if verbose:
        for key, val in bud.items():
            print(f"  budget {key}: {val / wscale:.3g}")
        print(f"  balance error engine {e['balance_error']:.6g} reference "
              f"{(kin + pot - ref.E0) - total_work:.6g}, work scale {wscale:.6g}")
        for m in e["work_by_model"]:
            print(f"  work {m['model']}: engine {m['pairs']:.17g} {m['walls']:.17g}, "
                  f"reference {ref.work[m['model']][0]:.17g} {ref.work[m['model']][1]:.17g}")
    return max(bud.values()) / wscale


def run_case(sc, wetdem, steps, verbose=False, every=1):
    """Runs the case through wetdem with a frame every `every` steps (and at the last), and
    its variants (sc["variants"]: other thread counts, a run stopped and resumed from its
    checkpoint), and follows it once with the reference, against which each run is compared.
    With every > 1 the engine steps between frames without handing the state out, taking
    its fused paths (the closing half kick left to the next step, the next step begun in the
    force pass: docs/many.md). A case without a step (sc["dt"] None) takes the engine's
    derived step, which the reference derives too (step_scales): the result's "dt" is their
    relative difference, "check" the largest relative difference of the three time scales
    that `wetdem run --check` prints. Returns ({label: worst differences}, the last step,
    the reference); the label of the run itself is ""."""
    variants = [dict(label="", threads=sc.get("threads", 1))] + sc.get("variants", [])
    runs = []
    with tempfile.TemporaryDirectory() as top:
        for k, var in enumerate(variants):
            tmp = os.path.join(top, str(k))
            os.mkdir(tmp)
            frames, summary = engine_run(sc, wetdem, steps, every, tmp, var["threads"],
                                         var.get("restart_at"), var.get("threads_after"),
                                         var.get("every_after"))
            # the frames of the uninterrupted run; resumed with frames every e2 steps, those
            # of its grid up to the checkpoint's step r and of e2's from r on (docs/many.md,
            # Interrupting, restarting, extending)
            r, e2 = var.get("restart_at", steps), var.get("every_after") or every
            expect = {k for k in range(steps + 1) if (k <= r and k % every == 0) or
                      (k >= r and k % e2 == 0)} | {steps}
            runs.append((var["label"], frames, summary, expect))
        check = engine_check(sc, wetdem, top) if sc["dt"] is None else None
    results = {label: {"x": 0.0, "v": 0.0, "w": 0.0} for label, _, _, _ in runs}
    grid = sorted(set().union(*(frames for _, frames, _, _ in runs)))
    if sc["dt"] is None:
        scales = step_scales(sc)
        dt_engine = runs[0][2]["dt_s"]
        results[""]["dt"] = abs(scales["dt"] / dt_engine - 1)
        # (1 where one of the two has no such bound)
        results[""]["check"] = max(abs(scales[key] / check[key] - 1)
                                   if max(check[key], scales[key]) < math.inf
                                   else float(check[key] != scales[key]) for key in check)
        if verbose:
            print(f"  step: reference {scales}, engine dt {dt_engine!r}, --check {check}")
        # the trajectory at the reference's own step, or (sc["follow_dt"]) at the engine's
        # where the two differ by the engine's finite differences (step_scales)
        sc = dict(sc, dt=dt_engine if sc.get("follow_dt") else scales["dt"])
    for label, frames, _, expect in runs:
        if set(frames) != expect:  # a frame lost or off the grid
            results[label]["frames"] = math.inf
    ref = Reference(sc)
    ref.start()
    scale_x = max(ref.R)
    vmax = max(1e-300, max(np.abs(ref.v).max(), (np.abs(ref.w) * ref.R[:, None]).max()))
    L = ref.hi - ref.lo
    at = 0
    for k in grid:
        while at < k:
            ref.step()
            at += 1
        vmax = max(vmax, np.abs(ref.v).max(), (np.abs(ref.w) * ref.R[:, None]).max())
        for label, frames, _, _ in runs:
            if k not in frames:
                continue
            fr, worst = frames[k], results[label]
            dx = fr["POINTS"] - ref.x
            for a in range(3):
                if ref.periodic[a]:
                    dx[:, a] -= L[a] * np.round(dx[:, a] / L[a])
            worst["x"] = max(worst["x"], np.abs(dx).max() / scale_x)
            worst["v"] = max(worst["v"], np.abs(fr["velocity"] - ref.v).max() / vmax)
            worst["w"] = max(worst["w"],
                             (np.abs(fr["spin"] - ref.w) * ref.R[:, None]).max() / vmax)
            if verbose and not label and (k % 50 == 0 or k == grid[-1]):
                print(f"  step {k}: x {np.abs(dx).max():.3g} v "
                      f"{np.abs(fr['velocity'] - ref.v).max():.3g} "
                      f"w {np.abs(fr['spin'] - ref.w).max():.3g}")
    # the speeds behind the step (docs/many.md, Speeds beyond the step's): V and B of the
    # start, whatever the step, and the largest half-step speed of the whole run, which a
    # resumed run reports too (its checkpoint keeps them)
    speed, bound = speed_scale(sc)
    largest = math.sqrt(ref.u2)
    for label, _, summary, _ in runs:
        results[label]["budget"] = budget_diff(ref, summary, verbose and not label)
        results[label].update(speeds_diff(speed, bound, largest, summary))
        if verbose:
            print(f"  speeds{' ' + label if label else ''}: engine V "
                  f"{summary['speed_scale_m_s']!r} B {summary['speed_bound_m_s']!r} u "
                  f"{summary['largest_speed_m_s']!r}, reference V {speed!r} B {bound!r} u "
                  f"{largest!r}")
    return results, grid[-1], ref


def speeds_diff(speed, bound, largest, summary):
    """The relative differences of summary.json's speed scale ("V"), speed bound ("B"; null
    for infinite) and largest half-step speed ("u") from the reference's: 0 where both are
    infinite or zero, infinite where only one is."""
    def rel(engine, ref):
        engine = math.inf if engine is None else engine
        if engine == ref:
            return 0.0
        return abs(engine / ref - 1) if 0 < ref < math.inf else math.inf
    return {"V": rel(summary["speed_scale_m_s"], speed),
            "B": rel(summary["speed_bound_m_s"], bound),
            "u": rel(summary["largest_speed_m_s"], largest)}


# ----------------------------------------------------------------------------- cases ---
def glass(**kw):
    base = dict(density=2500.0, youngs_modulus=1e8, poisson_ratio=0.3, restitution=0.6,
                friction_dry=0.3, friction_lub=0.1)
    base.update(kw)
    return Material(**base)


CASES = []


def case(fn):
    CASES.append(fn)
    return fn


@case
def friction_spin_unequal():
    """Two spheres of radii 1 and 0.5 mm meeting obliquely with spins: hertz (tsuji) +
    mindlin, sticking and sliding; the torques' lever arms R_i and R_j differ."""
    return dict(name="friction_spin_unequal", box=(0.01, 0.01, 0.01),
                materials=[glass(), glass(youngs_modulus=2e8, poisson_ratio=0.25,
                                          restitution=0.8, friction_dry=0.5)],
                models="hertz mindlin", params={"hertz.damping": "tsuji"},
                particles=[dict(R=1e-3, x=(0.004, 0.005, 0.005), v=(0.2, 0.05, -0.03),
                                w=(10, -20, 30), mat=0),
                           dict(R=0.5e-3, x=(0.00549, 0.0052, 0.005), v=(-0.1, 0, 0.02),
                                w=(-40, 5, 0), mat=1)],
                dt=2e-7, steps=600)


@case
def friction_spin_exact():
    """The same pair with hertz's exact damping (clipped; coefficient from the engine's table,
    about 4e-9 relative, against a bisection of Eq. 1.7 here)."""
    sc = friction_spin_unequal()
    sc.update(name="friction_spin_exact", params={}, tol=1e-8)
    return sc


def beside(centre, r0, r1, direction, gap):
    """The centre of a sphere of radius r1 at surface gap `gap` from a sphere of radius r0 at
    `centre`, along `direction`."""
    u = np.asarray(direction, float)
    u = u / np.linalg.norm(u)
    return tuple(float(c) for c in np.asarray(centre) + (r0 + r1 + gap) * u)


@case
def three_and_wall():
    """A sphere (R 1 mm) falling onto a floor under gravity while two smaller ones (0.6 and
    0.8 mm, another material) strike it from two sides, all spinning: hertz + mindlin, up to
    three contacts on the large sphere at once, each with its own lever arms."""
    big = (0.005, 0.005, 0.001 + 1e-6)
    return dict(name="three_and_wall", box=(0.01, 0.01, 0.01), walls=["z_min"],
                materials=[glass(), glass(youngs_modulus=3e8, restitution=0.9,
                                          friction_dry=0.2)],
                models="hertz mindlin", gravity=(0, 0, -9.81), wall_material=1,
                particles=[dict(R=1e-3, x=big, v=(0.01, 0.02, -0.05), w=(0, 30, 5), mat=0),
                           dict(R=0.6e-3, x=beside(big, 1e-3, 0.6e-3, (1, 0, -0.2), 1e-6),
                                v=(-0.05, 0.01, -0.05), w=(3, 0, -10), mat=1),
                           dict(R=0.8e-3, x=beside(big, 1e-3, 0.8e-3, (0, 1, 0.2), 1e-6),
                                v=(0, -0.05, 0.01), w=(20, 0, 0), mat=0)],
                dt=2e-7, steps=1500, tol=1e-8)


@case
def periodic_straddle():
    """A wet polydisperse pair meeting across the periodic x face (radii 0.9 and 0.4 mm, the
    larger sphere wrapping through the face during the run), a third sphere striking the
    larger one, periodic x and y, a floor and gravity along x and z (so that the unwrapped
    potential counts the wrap): hertz + mindlin + sb + capillary with 20 and 30 um films."""
    p0 = (0.005995, 0.003, 0.0011)
    p1 = beside(p0, 0.9e-3, 0.4e-3, (1, 0.05, -0.15), 6e-6)
    p1 = (p1[0] - 0.006,) + p1[1:]
    return dict(name="periodic_straddle", box=(0.006, 0.006, 0.006), periodic="xy",
                walls=["z_min"],
                materials=[glass(film=20e-6), glass(film=30e-6, youngs_modulus=2e8)],
                viscosity=0.01, surface_tension=0.05,
                models="hertz mindlin sb capillary", params={"fixed.h_min": 2e-6},
                gravity=(3.0, 0, -9.81),
                particles=[dict(R=0.9e-3, x=p0, v=(0.1, 0.02, 0), w=(0, 0, 40), mat=0),
                           dict(R=0.4e-3, x=p1, v=(-0.1, 0, 0.01), w=(10, 0, 0), mat=1),
                           dict(R=0.5e-3, x=beside(p0, 0.9e-3, 0.5e-3, (-0.1, 1, -0.3), 5e-6),
                                v=(0.1, -0.1, 0), mat=1)],
                dt=1e-7, steps=2000, tol=1e-8)


@case
def slide_wall_hooke():
    """A sphere set down on a floor under gravity, sliding at 0.1 m/s without spin: hooke +
    mindlin (linear history spring, limit mu k delta), sliding at every step."""
    return dict(name="slide_wall_hooke", box=(0.02, 0.01, 0.01), walls=["z_min"],
                materials=[glass(restitution=0.3, friction_dry=0.4)],
                models="hooke mindlin", params={"hooke.stiffness": 200.0},
                gravity=(0, 0, -9.81),
                particles=[dict(R=1e-3, x=(0.003, 0.005, 1e-3), v=(0.1, 0, 0),
                                mat=0)],
                dt=2e-6, steps=600, skin=2e-6)


@case
def slide_wall_hertz():
    """A sphere sliding and spinning on a floor and a second sphere rolling along it in
    contact: hertz + mindlin with a small skin, so that the lists are rebuilt many times
    while the tangential springs persist."""
    return dict(name="slide_wall_hertz", box=(0.02, 0.01, 0.01), walls=["z_min"],
                materials=[glass(friction_dry=0.15)],
                models="hertz mindlin", params={"hertz.damping": "tsuji"},
                gravity=(0, 0, -9.81),
                particles=[dict(R=1e-3, x=(0.003, 0.005, 1e-3), v=(0.3, 0.05, 0),
                                w=(0, -100, 20), mat=0),
                           dict(R=0.7e-3, x=(0.003, 0.005 + 1.67383e-3, 0.7e-3),
                                v=(0.29, 0.04, 0), w=(0, 0, 0), mat=0)],
                dt=2e-7, steps=800, skin=1e-6)


def wet_pair(name, models, params=None, **kw):
    """Three wet spheres (0.8, 0.5, 0.6 mm) and a wet floor: the smaller two strike the
    larger one from 5 and 4 um (films of 40 and 50 um), which falls onto the floor from
    8 um, all spinning, so that the films act apart, below h_min and in contact."""
    p0 = (0.005, 0.005, 0.0008 + 8e-6)
    sc = dict(name=name, box=(0.01, 0.01, 0.01), walls=["z_min"],
              materials=[glass(film=25e-6), glass(film=15e-6, youngs_modulus=3e8)],
              viscosity=0.01, surface_tension=0.06, models=models,
              params=params or {"fixed.h_min": 3e-6},
              particles=[dict(R=0.8e-3, x=p0, v=(0.03, 0.01, -0.1), w=(5, -10, 30), mat=0),
                         dict(R=0.5e-3, x=beside(p0, 0.8e-3, 0.5e-3, (1, 0.02, 0.05), 5e-6),
                              v=(-0.2, 0.005, 0), w=(0, 20, -5), mat=1),
                         dict(R=0.6e-3, x=beside(p0, 0.8e-3, 0.6e-3, (0, 1, 0.1), 4e-6),
                              v=(0.0, -0.15, 0.0), w=(-15, 0, 0), mat=0)],
              dt=1e-7, steps=1500)
    sc.update(kw)
    return sc


@case
def wet_sb_davis():
    return wet_pair("wet_sb_davis", "hertz mindlin sb davis capillary",
                    {"fixed.h_min": 3e-6, "hertz.damping": "tsuji"})


@case
def wet_db_nase_nc():
    return wet_pair("wet_db_nase_nc", "hertz mindlin db nase capillary",
                    {"fixed.h_min": 3e-6, "hertz.damping": "tsuji", "db.below_hmin": "nc",
                     "nase.below_hmin": "nc"})


@case
def wet_films_only():
    """Film forces alone (no contact model): sb, db, davis, nase, capillary together."""
    return wet_pair("wet_films_only", "sb db davis nase capillary",
                    {"fixed.h_min": 1e-6, "sb.below_hmin": "nc"}, steps=500)


@case
def reynolds_hooke():
    return wet_pair("reynolds_hooke", "hooke mindlin reynolds",
                    {"fixed.h_min": 2e-6, "hooke.stiffness": 300.0,
                     "reynolds.cutoff_ratio": 0.5}, viscosity=0.05)


@case
def nijssen_three():
    return wet_pair("nijssen_three", "nijssen", {"nijssen.damping": "tsuji"},
                    viscosity=0.05,
                    materials=[glass(roughness=0.5e-6), glass(roughness=2e-6,
                                                              youngs_modulus=3e8)])



def struck_fixed_sphere(base, tilt):
    """A fixed sphere (0.7 mm, material 1) at base and two free ones (0.5 and 0.4 mm, material
    0) a few um from it, closing in from either side with spin; the second's direction is
    (-1, 0, tilt)."""
    return [dict(R=0.7e-3, x=base, fixed=True, mat=1),
            dict(R=0.5e-3, x=beside(base, 0.7e-3, 0.5e-3, (1, 0.2, 0), 4e-6),
                 v=(-0.2, 0.03, 0.01), w=(0, 10, 50), mat=0),
            dict(R=0.4e-3, x=beside(base, 0.7e-3, 0.4e-3, (-1, 0, tilt), 3e-6),
                 v=(0.1, 0.0, -0.08), w=(-30, 0, 0), mat=0)]


@case
def fixed_sphere_ehd():
    """Two wet spheres striking a fixed one (infinite mass: m* the other's mass, no motion
    of its own) from either side, with ehd's h_min set by each pair's largest approach
    speed: hertz + mindlin + sb + davis + capillary."""
    base = (0.005, 0.005, 0.005)
    return dict(name="fixed_sphere_ehd", box=(0.01, 0.01, 0.01),
                materials=[glass(film=20e-6), glass(film=10e-6, youngs_modulus=5e8)],
                viscosity=0.01, surface_tension=0.03, min_separation="ehd",
                models="hertz mindlin sb davis capillary",
                params={"hertz.damping": "tsuji"},
                particles=struck_fixed_sphere(base, 0.5),
                dt=1e-7, steps=1500)


@case
def glass_films():
    """Wet spheres with glass's h_min (largest approach speed since the films overlapped,
    p_gt lowered so that h_min is some um), db and nase below it held (nc), capillary."""
    return wet_pair("glass_films", "hertz mindlin db nase capillary",
                    {"glass.p_gt": 1e5, "hertz.damping": "tsuji", "db.below_hmin": "nc",
                     "nase.below_hmin": "nc"}, min_separation="glass")


@case
def max_roughness_films():
    """max(roughness, ehd) as h_min of sb and davis beside hooke + mindlin."""
    return wet_pair("max_roughness_films", "hooke mindlin sb davis capillary",
                    {"hooke.stiffness": 500.0}, min_separation="max",
                    materials=[glass(film=25e-6, roughness=1e-6),
                               glass(film=15e-6, roughness=3e-6, youngs_modulus=3e8)])


@case
def nijssen_tsuji_wall():
    """nijssen (its own blended Hertz-Mindlin, tsuji damping) with a sphere falling onto a
    floor into full contact under gravity."""
    sc = wet_pair("nijssen_tsuji_wall", "nijssen", {"nijssen.damping": "tsuji"},
                  viscosity=0.002, gravity=(0, 0, -9.81),
                  materials=[glass(roughness=0.2e-6), glass(roughness=0.5e-6,
                                                            youngs_modulus=3e8)])
    sc["particles"][0]["v"] = (0.03, 0.01, -0.3)
    return sc


def cluster_eight():
    """Eight wet polydisperse spheres (0.3-0.5 mm) grown as a cluster, each placed 1-8 um
    from one before it, around the periodic x face of a box periodic in x and y with a
    floor and gravity, and thrown about: several neighbours per sphere at once, contacts,
    bridges and periodic images, hertz + mindlin + sb + davis + capillary. Also stopped at
    step 1513 (two contacts sticking or sliding) and resumed from its checkpoint with a frame
    every 10 steps from there on: the springs, the unwrapped positions and the budget's
    sums carried across, the frames of both grids written once each."""
    rng = np.random.default_rng(5)
    L = np.array([2.6e-3, 2.6e-3, 0.005])
    radii = [0.5e-3, 0.45e-3, 0.4e-3, 0.5e-3, 0.3e-3, 0.35e-3, 0.45e-3, 0.3e-3]
    xs = [np.array([0.1e-3, 1.3e-3, 0.6e-3])]
    while len(xs) < len(radii):
        r = radii[len(xs)]
        k = rng.integers(len(xs))
        u = rng.normal(size=3)
        c = np.array(beside(xs[k], radii[k], r, u, rng.uniform(1e-6, 8e-6)))
        c[:2] %= L[:2]
        ok = c[2] - r > 2e-6 and c[2] + r < L[2]
        for x, rr in zip(xs, radii):
            d = c - x
            d[:2] -= L[:2] * np.round(d[:2] / L[:2])
            ok = ok and np.linalg.norm(d) > r + rr + 0.5e-6
        if ok:
            xs.append(c)
    parts = [dict(R=r, x=tuple(float(v) for v in x), v=tuple(rng.normal(0, 0.1, 3)),
                  w=tuple(rng.normal(0, 100, 3)), mat=k % 2)
             for k, (r, x) in enumerate(zip(radii, xs))]
    return dict(name="cluster_eight", box=tuple(L), periodic="xy", walls=["z_min"],
                materials=[glass(film=30e-6, friction_dry=0.4),
                           glass(film=20e-6, youngs_modulus=2e8, restitution=0.4)],
                viscosity=0.02, surface_tension=0.05,
                models="hertz mindlin sb davis capillary",
                params={"fixed.h_min": 2e-6, "hertz.damping": "tsuji"},
                gravity=(0, 0, -9.81), particles=parts, dt=1e-7, steps=2000, skin=2e-6,
                variants=[dict(label="resumed at 1513, frames every 10", threads=1,
                               restart_at=1513, every_after=10)])


CASES.append(cluster_eight)


def cluster_variant(name, models, one_material, params, **kw):
    sc = cluster_eight()
    del sc["variants"]
    sc.update(name=name, models=models, params=params, **kw)
    if one_material:  # one material pair: the lean kernel four pairs at a time
        for p in sc["particles"]:
            p["mat"] = 0
    return sc


@case
def cluster_lean_wet():
    """cluster_eight with one material and hertz mindlin sb capillary: the lean kernel, four
    pairs and four walls at a time (docs/many.md, Fast path)."""
    return cluster_variant("cluster_lean_wet", "hertz mindlin sb capillary", True,
                           {"fixed.h_min": 2e-6, "hertz.damping": "tsuji"})


@case
def cluster_lean_dry():
    """Dry, each sphere also thrown at 0.3 m/s towards the cluster's centre."""
    sc = cluster_variant("cluster_lean_dry", "hertz mindlin", True, {"hertz.damping": "tsuji"})
    L = np.array(sc["box"])
    x0 = np.array(sc["particles"][0]["x"])
    rel = []
    for p in sc["particles"]:
        d = np.array(p["x"]) - x0
        d[:2] -= L[:2] * np.round(d[:2] / L[:2])
        rel.append(d)
    centre = np.mean(rel, axis=0)
    for p, d in zip(sc["particles"], rel):
        u = (centre - d) / np.linalg.norm(centre - d)
        p["v"] = tuple(float(c) for c in np.array(p["v"]) + 0.3 * u)
    return sc


@case
def cluster_lean_exact_order():
    """Another model order, exact damping and sb held below h_min (nc)."""
    return cluster_variant("cluster_lean_exact_order", "capillary sb mindlin hertz", True,
                           {"fixed.h_min": 2e-6, "sb.below_hmin": "nc"}, tol=1e-8)


@case
def cluster_mindlin_no_hertz():
    """mindlin and the films without a normal contact law (the spring still acts on
    overlaps)."""
    return cluster_variant("cluster_mindlin_no_hertz", "mindlin sb capillary", True,
                           {"fixed.h_min": 2e-6})


@case
def bounce_ehd_record():
    """A wet sphere (film 10 um on it and on the floor) bouncing on a floor under strong
    gravity with spin: it leaves the films (and the wall's list) and comes back, with ehd's
    record kept within reset_ratio R and the spring reset at each lift-off. Also stopped at
    step 2513 and resumed from its checkpoint, the record carried across."""
    return dict(name="bounce_ehd_record", box=(0.01, 0.01, 0.01), walls=["z_min"],
                materials=[glass(film=10e-6, restitution=0.9, friction_dry=0.3)],
                viscosity=1e-4, surface_tension=0.02, min_separation="ehd",
                models="hertz mindlin sb davis capillary",
                params={"hertz.damping": "tsuji", "sb.below_hmin": "nc",
                        "davis.below_hmin": "nc"}, gravity=(0, 0, -1000.0),
                particles=[dict(R=0.5e-3, x=(0.005, 0.005, 0.5e-3 + 19e-6),
                                v=(0.05, 0.02, -0.4), w=(100, -50, 20), mat=0)],
                dt=2e-7, steps=5000,
                variants=[dict(label="resumed at 2513", threads=1, restart_at=2513)])


@case
def bounce_fixed_hmin():
    """The same bounce with a fixed h_min and a second sphere bouncing beside it."""
    sc = bounce_ehd_record()
    sc.update(name="bounce_fixed_hmin", min_separation="fixed",
              params={"hertz.damping": "tsuji", "fixed.h_min": 1e-6})
    sc["particles"].append(dict(R=0.3e-3, x=(0.005, 0.005 + 0.8e-3 + 3e-6, 0.3e-3 + 30e-6),
                                v=(0.0, -0.1, -0.5), w=(0, 0, -300), mat=0))
    return sc


@case
def hooke_fixed():
    """hooke + mindlin against a fixed sphere and a wall, with davis and capillary films."""
    base = (0.005, 0.005, 0.0009)
    return dict(name="hooke_fixed", box=(0.01, 0.01, 0.01), walls=["z_min"],
                materials=[glass(film=20e-6), glass(film=10e-6, youngs_modulus=5e8)],
                viscosity=0.01, surface_tension=0.03,
                models="hooke mindlin davis capillary",
                params={"hooke.stiffness": 400.0, "fixed.h_min": 1e-6},
                gravity=(0, 0, -9.81),
                particles=struck_fixed_sphere(base, 0.3),
                dt=1e-7, steps=1500)



@case
def roll_off_fixed():
    """A sphere (0.4 mm) rolling off the top of a fixed one (1 mm) under strong gravity with
    a high friction: the contact sticks while its normal turns by tens of degrees, so the
    spring is rotated into each new tangent plane (kept at its length) at every step."""
    base = (0.005, 0.005, 0.004)
    return dict(name="roll_off_fixed", box=(0.01, 0.01, 0.01),
                materials=[glass(friction_dry=1.0, restitution=0.5)], models="hertz mindlin",
                params={"hertz.damping": "tsuji"}, gravity=(0, 0, -5000.0),
                particles=[dict(R=1e-3, x=base, fixed=True, mat=0),
                           dict(R=0.4e-3, x=beside(base, 1e-3, 0.4e-3, (0.15, 0.05, 1), 1e-8),
                                mat=0)],
                dt=2e-7, steps=3000)



@case
def channel_walls():
    """A wet sphere squeezed across a channel one diameter wide (walls at x_min and x_max,
    of another material with a film of its own) and a second one striking it along the
    channel, under gravity along y: both walls act on the first sphere at once."""
    return dict(name="channel_walls", box=(2.004e-3, 0.01, 0.01), walls=["x_min", "x_max"],
                materials=[glass(film=10e-6), glass(film=5e-6, youngs_modulus=4e8,
                                                     friction_dry=0.5)],
                wall_material=1, viscosity=0.005, surface_tension=0.04,
                models="hertz mindlin sb nase capillary",
                params={"fixed.h_min": 1e-6, "hertz.damping": "tsuji",
                        "nase.below_hmin": "nc"}, gravity=(0, -2000.0, 0),
                particles=[dict(R=1e-3, x=(1.002e-3, 0.005, 0.005), v=(0.1, 0, 0.02),
                                w=(0, 100, -50), mat=0),
                           dict(R=0.6e-3, x=(1.2e-3, 0.005 + 1.6e-3 + 5e-6, 0.005),
                                v=(-0.05, -0.2, 0), w=(30, 0, 0), mat=0)],
                dt=1e-7, steps=1500)


@case
def nijssen_exact():
    """nijssen with its exact damping (tabulated coefficient, as hertz's)."""
    sc = wet_pair("nijssen_exact", "nijssen", {}, viscosity=0.002, gravity=(0, 0, -9.81),
                  materials=[glass(roughness=0.2e-6), glass(roughness=0.5e-6,
                                                            youngs_modulus=3e8)], tol=1e-8)
    sc["particles"][0]["v"] = (0.03, 0.01, -0.3)
    return sc


def glass_speed(speed):
    """A wet pair with glass's h_min set by the approach speed `speed` reads (glass.speed)."""
    return wet_pair(f"glass_{speed}", "hertz mindlin sb davis capillary",
                    {"glass.p_gt": 1e5, "glass.speed": speed, "hertz.damping": "tsuji",
                     "sb.below_hmin": "nc", "davis.below_hmin": "nc"},
                    min_separation="glass")


@case
def glass_initial():
    return glass_speed("initial")


@case
def glass_current():
    return glass_speed("current")


@case
def periodic_fixed_straddle():
    """periodic_straddle with its small sphere fixed across the face from the large one."""
    sc = periodic_straddle()
    sc["name"] = "periodic_fixed_straddle"
    sc["particles"][1].update(fixed=True, v=(0, 0, 0), w=(0, 0, 0))
    return sc



# the same runs on 3 and 4 threads: the blocks and the crossing pairs change, the results
# keep their bits (docs/many.md, Parallel force loop and determinism)
THREADS = [dict(label="3 threads", threads=3), dict(label="4 threads", threads=4)]


@case
def pack_512_threads():
    """512 wet spheres (R 0.47-0.5 mm, two materials) on a simple cubic lattice 3 um apart at
    the closest, periodic in x and y over a floor, with random velocities and spins and
    gravity, run on two threads: the blocks, the pairs crossing them and the summation
    order of the parallel force pass (docs/many.md), with hertz + mindlin + sb + davis +
    capillary. The same on 3 and 4 threads, and stopped at step 73 and resumed on 3."""
    rng = np.random.default_rng(11)
    nx, nz, a = 8, 8, 1.003e-3
    parts = []
    for k in range(nz):
        for j in range(nx):
            for i in range(nx):
                r = rng.uniform(0.47e-3, 0.5e-3)
                parts.append(dict(R=r, x=(a * (i + 0.5), a * (j + 0.5), 0.502e-3 + a * k),
                                  v=tuple(rng.normal(0, 0.3, 3)),
                                  w=tuple(rng.normal(0, 300, 3)), mat=(i + j + k) % 2))
    return dict(name="pack_512_threads", box=(nx * a, nx * a, 0.012), periodic="xy",
                walls=["z_min"],
                materials=[glass(film=20e-6, friction_dry=0.4),
                           glass(film=10e-6, youngs_modulus=2e8, restitution=0.4)],
                viscosity=0.01, surface_tension=0.05,
                models="hertz mindlin sb davis capillary",
                params={"fixed.h_min": 1e-6, "hertz.damping": "tsuji"},
                gravity=(0, 0, -9.81), particles=parts, dt=1e-7, steps=150, threads=2,
                skin=2e-6, variants=THREADS + [dict(label="resumed at 73 on 3 threads",
                                                    threads=2, restart_at=73,
                                                    threads_after=3)])


@case
def pack_512_lean():
    """The same packing with one material and hertz mindlin sb capillary: the lean kernel
    four pairs at a time, on two threads."""
    sc = pack_512_threads()
    sc.update(name="pack_512_lean", models="hertz mindlin sb capillary", variants=THREADS)
    for p in sc["particles"]:
        p["mat"] = 0
    return sc



@case
def derived_contact():
    """wet_sb_davis under gravity with the step derived by the engine (no dt given): the
    tangential contact time of the smallest sphere binds, at the speed scale that gravity
    raises. The engine takes mindlin's stiffness by central differences (docs/many.md): k_n
    of F ~ delta^(3/2) at a relative 1e-4 is off by eps^2/24 = 4e-10, the step by half of
    that; so the steps agree to 1e-9, and the trajectory is followed at the engine's step.
    Also stopped at step 437 (in contact, off the frame grid) and resumed from its
    checkpoint, which must give the same step and the uninterrupted run's frames."""
    return wet_pair("derived_contact", "hertz mindlin sb davis capillary",
                    {"fixed.h_min": 3e-6, "hertz.damping": "tsuji"}, gravity=(0, 0, -9.81),
                    dt=None, dt_tol=1e-9, follow_dt=True,
                    variants=[dict(label="resumed at 437", threads=1, restart_at=437)])


@case
def derived_roughness():
    """The min-separation model roughness alone (h_min the mean roughness of the pair, 0.1,
    0.2 and 0.3 um), with sb and davis cut off below it (c), under gravity, the step
    derived: many_hmin_fraction x the time to cross the smallest h_min binds, a closed form,
    so the steps agree to rounding."""
    return wet_pair("derived_roughness", "hertz mindlin sb davis capillary",
                    {"hertz.damping": "tsuji"}, min_separation="roughness",
                    materials=[glass(film=25e-6, roughness=0.1e-6),
                               glass(film=15e-6, roughness=0.3e-6, youngs_modulus=3e8)],
                    gravity=(0, 0, -9.81), dt=None, steps=2000)


@case
def derived_relaxation():
    """A viscous liquid (0.2 Pa s) and hooke + mindlin beside sb, db, davis and nase (db and
    nase held below h_min, nc), the step derived: a quarter of the thin films' viscous
    relaxation time binds."""
    return wet_pair("derived_relaxation", "hooke mindlin sb db davis nase capillary",
                    {"fixed.h_min": 3e-6, "hooke.stiffness": 300.0, "db.below_hmin": "nc",
                     "nase.below_hmin": "nc"},
                    viscosity=0.2, dt=None)


@case
def derived_from_rest():
    """The three wet spheres released at rest under gravity, pulled together by their
    bridges, with the tangential films davis and nase cut off below a fixed h_min of 0.1 um
    (c) and no normal thin-film law: the step derived at the speed scale that gravity alone
    sets, many_hmin_fraction x the time to cross h_min, a jump of the tangential laws, binds
    (a pair at rest slides at the speed scale as it closes at it). Gravity is inclined to the
    floor, so that the fall to it takes the part of the normal across gravity."""
    sc = wet_pair("derived_from_rest", "hertz mindlin davis nase capillary",
                  {"fixed.h_min": 1e-7, "hertz.damping": "tsuji"}, gravity=(1.5, -1.0, -9.7),
                  dt=None)
    for p in sc["particles"]:
        p.update(v=(0, 0, 0), w=(0, 0, 0))
    return sc


@case
def derived_fixed():
    """Two wet spheres striking a fixed one (0.7 mm) under gravity, a larger fixed sphere
    (1 mm) lower down and no wall, the step derived: the probe pairs with the smallest and
    the largest fixed sphere (infinite mass, m* the free sphere's), the largest giving the
    shortest (tangential) contact time, which binds, at the speed scale raised by the fixed
    spheres' term of the fall (docs/many.md, What a fall adds, 2: to the lowest point of the
    lower fixed sphere, 4.5 mm, against 0.04 mm of the free centres' extent). mindlin's
    stiffness by the engine's central differences: 1e-9, and the engine's step followed, as
    in derived_contact."""
    base = (0.005, 0.005, 0.005)
    return dict(name="derived_fixed", box=(0.01, 0.01, 0.01),
                materials=[glass(film=20e-6), glass(film=10e-6, youngs_modulus=5e8)],
                viscosity=0.01, surface_tension=0.03,
                models="hertz mindlin sb davis capillary",
                params={"fixed.h_min": 1e-6, "hertz.damping": "tsuji"},
                gravity=(0, 0, -9.81),
                particles=[dict(R=0.7e-3, x=base, fixed=True, mat=1),
                           dict(R=0.5e-3, x=beside(base, 0.7e-3, 0.5e-3, (1, 0.2, 0.5), 4e-6),
                                v=(-0.2, 0.03, 0.01), w=(0, 10, 50), mat=0),
                           dict(R=0.4e-3, x=beside(base, 0.7e-3, 0.4e-3, (-1, 0, 0.5), 3e-6),
                                v=(0.1, 0.0, -0.08), w=(-30, 0, 0), mat=0),
                           dict(R=1e-3, x=(0.005, 0.005, 0.0025), fixed=True, mat=0)],
                dt=None, dt_tol=1e-9, follow_dt=True, steps=1500)


@case
def derived_reynolds():
    """reynolds beside hooke + mindlin in a 0.2 Pa s liquid, the step derived: a quarter of
    reynolds' relaxation time m* h_min / (6 pi mu R*^2) at the fixed h_min binds, a closed
    form; reynolds is held at h_min and sets no bound on the travel per step."""
    return wet_pair("derived_reynolds", "hooke mindlin reynolds",
                    {"fixed.h_min": 2e-6, "hooke.stiffness": 300.0,
                     "reynolds.cutoff_ratio": 0.5}, viscosity=0.2, dt=None)


@case
def derived_nijssen():
    """nijssen (exact damping, e_dry 0.01 and 0.02) under gravity, the step derived: its
    h_min at the speed scale (max of the mean roughness and the ehd gap), its lubrication
    there and its hertz and mindlin dashpots at the largest shifted overlap of an undamped
    approach (docs/many.md, Viscous relaxation time); a quarter of the hertz dashpot's time
    binds (0.87 of the step from the contact time). The engine tabulates the exact
    coefficient to about 4e-9 relative, this reference bisects Eq. 1.7: the relaxation time
    moves by as much, so the steps agree to 1e-8, and the run to 1e-8 (nijssen_exact)."""
    sc = wet_pair("derived_nijssen", "nijssen", {}, viscosity=0.002, gravity=(0, 0, -9.81),
                  materials=[glass(roughness=0.2e-6, restitution=0.01),
                             glass(roughness=0.5e-6, youngs_modulus=3e8, restitution=0.02)],
                  dt=None, dt_tol=1e-8, tol=1e-8)
    sc["particles"][0]["v"] = (0.03, 0.01, -0.3)
    return sc


@case
def derived_hertz_exact():
    """The three wet spheres falling freely under gravity (no wall, no fixed sphere) with
    hertz's exact damping at e_dry 0.01 and 0.02, mindlin, and sb and davis cut off below
    ehd's h_min (c) in a 0.1 Pa s liquid, the step derived: a quarter of the hertz dashpot's
    relaxation time at the largest overlap of an undamped impact at the speed scale binds
    (0.87 of the step from the tangential contact time; docs/many.md, Viscous relaxation
    time); many_hmin_fraction x the time to cross ehd's h_min at the speed scale (0.38 um)
    is 1.34 times it.
    Nothing stops a fall: the fall is the extent of the free centres along g (What a fall
    adds, 3), and the speed bound is infinite (null in summary.json). The exact coefficient
    is tabulated by the engine (derived_nijssen): the steps and the run agree to 1e-8."""
    return wet_pair("derived_hertz_exact", "hertz mindlin sb davis capillary",
                    {"hertz.damping": "exact"},
                    min_separation="ehd", viscosity=0.1, walls=[], gravity=(0, 0, -9.81),
                    materials=[glass(film=25e-6, restitution=0.01),
                               glass(film=15e-6, youngs_modulus=3e8, restitution=0.02)],
                    dt=None, dt_tol=1e-8, tol=1e-8)


@case
def derived_hertz_tsuji():
    """The three spheres of derived_hertz_exact with hertz's tsuji damping, no tangential
    contact and no film law (capillary alone: nothing jumps at h_min) and verlet.dt_fraction
    0.05, the step derived: the dashpot takes c = -sqrt(5) beta(e_dry) = 1.85 and 1.74 for
    e_dry 0.01 and 0.02, and a quarter of its relaxation time at the largest overlap of an
    undamped impact at the speed scale, 1.34 us, binds (0.87 of the step from the contact
    time; at the default dt_fraction 0.02 the contact time would bind). Tsuji's coefficient
    itself sets the step here, where beside mindlin (derived_glass, derived_nijssen_tsuji)
    another time binds. A closed form: the steps agree to rounding."""
    sc = derived_hertz_exact()
    sc.update(name="derived_hertz_tsuji", models="hertz capillary",
              params={"hertz.damping": "tsuji", "verlet.dt_fraction": 0.05},
              viscosity=0.001, dt_tol=1e-12, tol=1e-9)
    return sc


@case
def derived_nijssen_tsuji():
    """derived_nijssen with nijssen's tsuji damping and verlet.dt_fraction 0.03, the step
    derived: the normal dashpot takes c = -sqrt(5) beta(e_dry) = 1.85 and 1.74 for e_dry 0.01
    and 0.02 (the exact coefficient is 10.7 and 7.4), so its relaxation time at the largest
    shifted overlap, 4.9 us, is 3.2 times that of nijssen's Mindlin dashpot (Eq. 10), a
    quarter of which binds (0.78 of the step from the contact time; at the default
    dt_fraction 0.02 the contact time would bind); with the exact coefficient the normal
    dashpot's would (derived_nijssen). A closed form: the steps agree to rounding."""
    sc = derived_nijssen()
    sc.update(name="derived_nijssen_tsuji", params={"nijssen.damping": "tsuji",
                                                    "verlet.dt_fraction": 0.03},
              dt_tol=1e-12, tol=1e-9)
    return sc


@case
def derived_glass():
    """glass's h_min (p_gt 1e8 Pa) with sb and davis cut off below it (c), the step derived:
    many_hmin_fraction x the time to cross the smallest h_min at the speed scale,
    (3 mu R* v / P_gt)^(1/2) = 0.19 um (docs/models.md), binds (0.55 of the step from the
    contact time), a closed form."""
    return wet_pair("derived_glass", "hertz mindlin sb davis capillary",
                    {"glass.p_gt": 1e8, "hertz.damping": "tsuji"}, min_separation="glass",
                    gravity=(0, 0, -9.81), dt=None)


# ----------------------------------------------------------------------------- mutants ---
# Deliberate errors in the reference, each of which the comparison must detect in the case
# named: they show that the agreement above is not reached by cases that miss the point.
def _mutant_lever(ctx, sc):
    orig = Reference.pair_force

    def pf(self, key, ri, rj, *a):
        out, new, h = orig(self, key, ri, rj, *a)
        if not a[9]:  # (wall) spheres: j's torque with i's lever arm
            out = [(nm, f, ti, tj * (ri / rj)) for nm, f, ti, tj in out]
        return out, new, h
    ctx.append((Reference, "pair_force", orig))
    Reference.pair_force = pf


def _mutant_record(ctx, sc):
    orig = Reference.min_separation

    def ms(self, old, new, h, vn, rstar, mp):
        return orig(self, {} if h > mp["film"] else old, new, h, vn, rstar, mp)
    ctx.append((Reference, "min_separation", orig))
    Reference.min_separation = ms


def _mutant_coulomb(ctx, sc):
    orig = globals()["mindlin_update"]
    ctx.append((sys.modules[__name__], "mindlin_update", orig))
    globals()["mindlin_update"] = lambda s, n, vt, dt, kt, m, e, fl, vs: \
        orig(s, n, vt, dt, kt, m, e, fl * 0.999, vs)


def _mutant_image(ctx, sc):
    orig = Reference.near_pairs

    def near(self):  # the pairs across a periodic face are lost
        return [(i, j) for i, j in orig(self)
                if not any(self.periodic[a] and abs(self.x[i][a] - self.x[j][a]) >
                           (self.hi[a] - self.lo[a]) / 2 for a in range(3))]
    ctx.append((Reference, "near_pairs", orig))
    Reference.near_pairs = near


def _mutant_power(ctx, sc):
    orig = Reference.forces

    def forces(self, v, w, dt, keep, vh=None, wh=None):  # the power at the step's start
        F, T, p = orig(self, v, w, dt, keep, vh, wh)
        if keep:
            self.hist, saved = dict(self.hist), self.hist
            _, _, p = orig(self, self.v, self.w, dt, False)
            self.hist = saved
        return F, T, p
    ctx.append((Reference, "forces", orig))
    Reference.forces = forces


def _mutant_spring(ctx, sc):
    orig = Reference.forces

    def forces(self, v, w, dt, keep, vh=None, wh=None):  # the springs with the predicted slip
        return orig(self, v, w, dt, keep)
    ctx.append((Reference, "forces", orig))
    Reference.forces = forces


def _mutant_tangential(ctx, sc):  # the derived step from the normal contact time alone
    orig = globals()["step_scales"]
    ctx.append((sys.modules[__name__], "step_scales", orig))
    globals()["step_scales"] = lambda sc: orig(dict(sc, models=sc["models"].replace(
        "mindlin", "")))


def _mutant_speed(ctx, sc):  # the speed scale without what gravity adds
    orig = globals()["step_scales"]
    ctx.append((sys.modules[__name__], "step_scales", orig))
    globals()["step_scales"] = lambda sc: orig(dict(sc, gravity=(0, 0, 0)))


def _mutant_mixed_axes(ctx, sc):  # the rule before: the largest coordinate less the smallest
    ctx.append((sys.modules[__name__], "fall_height", fall_height))
    globals()["fall_height"] = lambda sc: max(
        max(c for p in sc["particles"] for c in p["x"]) -
        min(c for p in sc["particles"] for c in p["x"]), 0.0)


def _mutant_jumps(ctx, sc):  # the step bound by the normal laws' jumps alone
    ctx.append((sys.modules[__name__], "JUMPING_LAWS", JUMPING_LAWS))
    globals()["JUMPING_LAWS"] = ("sb", "db")


def _mutant_roughness(ctx, sc):  # h_min the sum of the roughnesses, not their mean
    orig = Reference.min_separation

    def ms(self, old, new, h, vn, rstar, mp):
        return orig(self, old, new, h, vn, rstar, dict(mp, rough=2 * mp["rough"]))
    ctx.append((Reference, "min_separation", orig))
    Reference.min_separation = ms


def _after_restart_step(ctx, sc, forget):
    """Reference.step patched to call forget(ref) after the step the case's first variant is
    resumed from (what a checkpoint that lost something would do)."""
    at = sc["variants"][0]["restart_at"]
    orig = Reference.step

    def step(self):
        orig(self)
        self.steps_done = getattr(self, "steps_done", 0) + 1
        if self.steps_done == at:
            forget(self)
    ctx.append((Reference, "step", orig))
    Reference.step = step


def _mutant_restart(ctx, sc):  # the histories lost at the step the run was resumed from
    _after_restart_step(ctx, sc, lambda ref: setattr(ref, "hist", {}))


def _mutant_blocks(ctx, sc):  # the pairs between quarters of the index range lost
    orig = Reference.near_pairs

    def near(self):
        return [(i, j) for i, j in orig(self) if 4 * i // self.n == 4 * j // self.n]
    ctx.append((Reference, "near_pairs", orig))
    Reference.near_pairs = near


def _mutant_fixed_fall(ctx, sc):  # the fall to the fixed spheres left out
    orig = globals()["fall_height"]
    ctx.append((sys.modules[__name__], "fall_height", orig))
    globals()["fall_height"] = lambda sc: orig(dict(sc, particles=[
        p for p in sc["particles"] if not p.get("fixed")]))


def _mutant_reynolds_jump(ctx, sc):  # reynolds taken for a law that jumps at h_min
    ctx.append((sys.modules[__name__], "JUMPING_LAWS", JUMPING_LAWS))
    globals()["JUMPING_LAWS"] = JUMPING_LAWS + ("reynolds",)


def _mutant_nijssen_lub(ctx, sc):  # nijssen's lubrication alone (the rule before)
    orig = globals()["step_scales"]
    ctx.append((sys.modules[__name__], "step_scales", orig))

    def scales(sc):  # e_dry = 1 for the step alone: no dashpot counts
        return orig(dict(sc, materials=[Material(**dict(m.ini(), restitution=1.0))
                                        for m in sc["materials"]]))
    globals()["step_scales"] = scales


def _mutant_glass_factor(ctx, sc):  # glass's h_min without the 3 of the Reynolds pressure
    orig = globals()["glass_hmin"]
    ctx.append((sys.modules[__name__], "glass_hmin", orig))
    globals()["glass_hmin"] = lambda mu, r, v, p, film: orig(mu / 3, r, v, p, film)


def _mutant_full_step_speed(ctx, sc):  # the largest speed over the full-step velocities
    orig = Reference.step

    def step(self):
        u2 = self.u2
        orig(self)
        free = ~self.fixed
        self.u2 = max(u2, float(np.max(np.sum(self.v[free] ** 2, axis=1))))
    ctx.append((Reference, "step", orig))
    Reference.step = step


def _mutant_resumed_speed(ctx, sc):  # the largest speed of the resumed part of a run alone
    _after_restart_step(ctx, sc, lambda ref: setattr(ref, "u2", 0.0))


def _mutant_bound_as_scale(ctx, sc):  # B taken as V
    orig = globals()["speed_scale"]
    ctx.append((sys.modules[__name__], "speed_scale", orig))
    globals()["speed_scale"] = lambda sc: (orig(sc)[0],) * 2


def _mutant_bound_finite(ctx, sc):  # B = V - v0 also where nothing stops a fall
    orig = globals()["speed_scale"]
    ctx.append((sys.modules[__name__], "speed_scale", orig))

    def scale(sc):
        speed, _ = orig(sc)
        return speed, speed - max(math.sqrt(sum(c * c for c in p.get("v", (0, 0, 0))))
                                  for p in sc["particles"])
    globals()["speed_scale"] = scale


def _mutant_damping_swapped(ctx, sc):  # the step from the other damping's coefficient
    orig = globals()["step_scales"]
    ctx.append((sys.modules[__name__], "step_scales", orig))

    def scales(sc):
        params = dict(sc.get("params", {}))
        for key in ("hertz.damping", "nijssen.damping"):
            params[key] = "exact" if params.get(key, "exact") == "tsuji" else "tsuji"
        return orig(dict(sc, params=params))
    globals()["step_scales"] = scales


# (what, the mutant, the case, the run of it that must detect it, steps: None for the case's)
MUTANTS = [("torque on j with i's lever arm", _mutant_lever, "friction_spin_unequal", "",
            None),
           ("springs advanced with the predicted slip (first order)", _mutant_spring,
            "friction_spin_unequal", "", None),
           ("ehd record forgotten at the film edge", _mutant_record, "bounce_ehd_record", "",
            None),
           ("Coulomb limit 0.1 % low", _mutant_coulomb, "slide_wall_hertz", "", None),
           ("pairs across a periodic face lost", _mutant_image, "periodic_straddle", "", None),
           ("work at the velocities of the step's start", _mutant_power, "wet_films_only", "",
            None),
           ("derived step without the tangential contact time", _mutant_tangential,
            "derived_contact", "", None),
           ("speed scale without gravity", _mutant_speed, "derived_roughness", "", None),
           ("fall over the three axes together (the rule before)", _mutant_mixed_axes,
            "derived_roughness", "", None),
           ("the tangential laws' jump at h_min left out", _mutant_jumps,
            "derived_from_rest", "", None),
           ("roughness h_min the sum, not the mean", _mutant_roughness, "derived_roughness",
            "", None),
           ("fall to the fixed spheres left out", _mutant_fixed_fall, "derived_fixed", "",
            None),
           ("reynolds taken for a law that jumps at h_min", _mutant_reynolds_jump,
            "derived_reynolds", "", None),
           ("nijssen's lubrication alone in the relaxation time (the rule before)",
            _mutant_nijssen_lub, "derived_nijssen", "", None),
           ("glass's h_min without the 3 of the Reynolds pressure", _mutant_glass_factor,
            "derived_glass", "", None),
           ("hertz's exact dashpot with tsuji's coefficient in the step",
            _mutant_damping_swapped, "derived_hertz_exact", "", 100),
           ("hertz's tsuji dashpot with the exact coefficient in the step",
            _mutant_damping_swapped, "derived_hertz_tsuji", "", 100),
           ("nijssen's tsuji dashpot with the exact coefficient in the step",
            _mutant_damping_swapped, "derived_nijssen_tsuji", "", 100),
           ("largest speed over the full-step velocities", _mutant_full_step_speed,
            "derived_contact", "", 200),
           ("speed bound taken as the speed scale", _mutant_bound_as_scale, "slide_wall_hooke",
            "", 100),
           ("speed bound finite where nothing stops a fall", _mutant_bound_finite,
            "derived_hertz_exact", "", 100),
           ("largest speed of the resumed part alone", _mutant_resumed_speed,
            "derived_contact", "resumed at 437", 600),
           ("histories lost at the checkpoint", _mutant_restart, "cluster_eight",
            "resumed at 1513, frames every 10", None),
           ("pairs between index quarters lost", _mutant_blocks, "pack_512_lean", "4 threads",
            25)]


# V and B of summary.json against speed_scale(), relative: the same closed form evaluated in
# another order, a few roundings of 1e-16 each (a norm, sums of coordinates, a square root),
# so 1e-12 leaves a margin of 1e3 and still catches any change of a term. The fall H is a
# difference of coordinates (rounded to some 1e-18 m) that the square root turns into
# sqrt(2 |g| dH) = 4e-9 m/s at H = 0; but the cases' H is either 19 um or more, or exactly 0
# on both sides (no gravity; a sphere set on a floor square to g, its height less its
# radius), and they agree bit for bit. The largest speed u is
# compared to the velocities' tolerance (sc["tol"]): it is the largest norm of the half-step
# velocities, which carry the rounding, or the tabulated damping's shift, of the velocities.
SPEED_TOL = 1e-12


def judge(sc, worst):
    """The largest of a run's differences over its tolerance: the state's, the largest
    speed's and the budget's (sc["tol"], 1e-9 unless set); the speed scale's and bound's
    (SPEED_TOL); a derived step's (sc["dt_tol"], 1e-12: a closed form
    evaluated in another order, unless set); the time scales `--check` prints to 6 digits
    (1e-5)."""
    tol = sc.get("tol", 1e-9)
    ratio = max(v for k, v in worst.items() if k not in ("dt", "check", "V", "B")) / tol
    ratio = max(ratio, worst["V"] / SPEED_TOL, worst["B"] / SPEED_TOL)
    if "dt" in worst:
        ratio = max(ratio, worst["dt"] / sc.get("dt_tol", 1e-12), worst["check"] / 1e-5)
    return ratio


def describe(sc, label, steps, worst):
    extra = f" V {worst['V']:.2g} B {worst['B']:.2g} (tol {SPEED_TOL:g})"
    if "dt" in worst:
        extra += (f" dt {worst['dt']:.2g} (tol {sc.get('dt_tol', 1e-12):g})"
                 f" --check {worst['check']:.2g} (tol 1e-05)")
    if "frames" in worst:
        extra += " frames not those of the uninterrupted run"
    name = sc["name"] + (f" {label}" if label else "")
    return (f"{name:<28} {steps} steps: x {worst['x']:.2g} v {worst['v']:.2g} "
            f"w {worst['w']:.2g} u {worst['u']:.2g} budget {worst['budget']:.2g} "
            f"(tol {sc.get('tol', 1e-9):g})"
            + extra)


def run_mutants(wetdem, every):
    """1 when a mutant of the reference still agrees with the engine."""
    by_name = {fn.__name__: fn for fn in CASES}
    bad = 0
    for what, patch, name, label, steps in MUTANTS:
        sc = by_name[name]()
        sc["variants"] = [v for v in sc.get("variants", []) if v["label"] == label]
        ctx = []
        patch(ctx, sc)
        try:
            results, _, _ = run_case(sc, wetdem, steps or sc["steps"], False, every)
        finally:
            for owner, attr, orig in ctx:
                setattr(owner, attr, orig)
        worst = results[label]
        ratio = judge(sc, worst)
        caught = ratio > 100
        bad += not caught
        off = max(worst.values())
        print(f"{'ok ' if caught else 'BAD'} mutant '{what}' on {name}"
              f"{' ' + label if label else ''}: off by {off:.2g} ({ratio:.2g} x the "
              f"tolerance){'' if caught else ' (not detected)'}")
    return 1 if bad else 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--wetdem", default="build/wetdem")
    ap.add_argument("--only")
    ap.add_argument("-v", action="store_true")
    ap.add_argument("--every", type=int, default=1,
                    help="steps between the frames compared (default 1)")
    ap.add_argument("--coverage", action="store_true",
                    help="print what each case exercised (contacts, slides, films, ...)")
    ap.add_argument("--mutants", action="store_true",
                    help="instead, check that deliberate errors of the reference are detected")
    args = ap.parse_args()
    if args.mutants:
        return run_mutants(args.wetdem, args.every)
    bad = 0
    for fn in CASES:
        sc = fn()
        if args.only and sc["name"] != args.only:
            continue
        SLIDES[:] = [0, 0]
        results, steps, ref = run_case(sc, args.wetdem, sc["steps"], args.v, args.every)
        for label, worst in results.items():
            ok = judge(sc, worst) <= 1
            bad += not ok
            print(f"{'ok ' if ok else 'BAD'} {describe(sc, label, steps, worst)}")
        if args.v or args.coverage:
            print("    exercised:", ", ".join(f"{k} {v}" for k, v in ref.cover.items()),
                  f"slides {SLIDES[0]} sticks {SLIDES[1]};",
                  ", ".join(f"{k} {v}" for k, v in sorted(ref.cover_model.items())))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())

"""Binary oblique collisions with friction, wetdem against LIGGGHTS 3.8
(scripts/validate.d/48-liggghts-friction.sh).

`setup DIR` writes one initial state of isolated pairs of equal spheres, as a CSV for wetdem
(`[read.NAME]`) and a data file for LIGGGHTS (bench/liggghts/friction.in), both with 17
digits, wetdem's scenario of each set, and DIR/runs.txt, the runs the piece makes (name, set,
dt, steps, e, E, nu, mu, and which codes: the controls run LIGGGHTS alone). In each
pair a striker meets a sphere at rest with normal speed V_N along the line of centres at first
touch (x) and tangential speed V_N tan(theta) (y), over ANGLES, without and with a spin of the
striker (SPIN); it touches after 0.2 t_c, and each run ends after the contact. `check DIR` reads the
two codes' final velocities and spins, runs the reference (`step_map`, below: each code's
scheme written out, with switches for each of their differences), checks and draws
docs/figures/liggghts_friction.png.

The two schemes (docs/validation.md, "LIGGGHTS: friction"):
  wetdem    spring rotated into the tangent plane keeping its length, then advanced by v_s dt
            with v_s the slip of the half-step velocities and spins v', w' at the current
            normal (midpoint rule; docs/engines.md); the dashpots (tangential and normal) take
            the velocities predicted for the step's end, v' + a dt/2; force, v_t and v_s with
            the lever arm R (contact point at -R n); Coulomb: spring + dashpot against mu F_el;
  LIGGGHTS  spring advanced by v_t dt with the half-step velocities v', w', then projected
            into the plane (length not kept); the dashpots take v' too; lever arm R - delta/2;
            Coulomb: spring alone against mu |F_n| (F_n with damping), the dashpot added only
            while it sticks.
`step_map`'s switches: lever, spring (rotate or project), limit, and velocity ('midpoint':
wetdem's; 'half': LIGGGHTS'; 'predicted': the spring at the predicted slip too, wetdem's
scheme before the midpoint rule, first order, kept to show the order check can fail).
With e = 1 the dashpots vanish and F_n = F_el, so the Coulomb limits coincide and the
velocities the dashpots see do not matter: the spring advances with the same slip in both.
What remains: the spring's rotation against its projection (first order, but 7e-13 V_N at the
coarsest step: the normal turns by 4.2e-4 rad at most, and a step's projection shortens the
spring by |s| theta^2 / 2) and the lever arm (R against R - delta/2: an O(delta/R) difference
that does not vanish with dt). The stiff set (E = 70 GPa, V_N = 0.01 m/s, delta/R = 5e-5)
makes the last small (1e-5 V_N): the codes differ by it at every dt, and by the projection
and rounding once the reference sets LIGGGHTS' lever arm to R; the soft set (the
benchmark's E = 10 MPa, V_N = 0.1 m/s, delta/R ~ 1e-2) shows the lever arm larger; the damped
runs (e = 0.5) add the Coulomb limits' conventions, which stay at dt = 0, and the dashpots'
velocity (first order: LIGGGHTS' half-step one is a first-order estimate of the velocity at
the step's end, wetdem's predicted one second order).

Checks, each printed and failing the script (differences: the largest of a velocity or R
times a spin component of either sphere, over V_N):
  reference  each code's final velocities and spins equal its scheme's (step_map), from the
             same state, for every pair and run (stiff, soft, damped), to 1e-9 (the reference
             sums in another order; measured 8.9e-16, rounding);
  decomposition  e = 1: the reference with wetdem's scheme and with LIGGGHTS' but the lever
             arm R differ by 7.0e-13 V_N at 25 steps per contact time, 1.1e-14 at 1600, the
             spring's rotation against projection: first order (factors 1.6-2.5 per halving
             from 25 to 400 steps, where it is 30 times rounding or more; measured 1.97-2.32),
             at most 1e-6 of the codes' difference (measured 6.8e-8): at e = 1 the two codes
             follow one scheme but for the lever arm;
  agreement  stiff, e = 1, at each of 25 ... 1600 steps per contact time: the codes differ by
             the lever arm's effect (1.03e-5, by the reference); less it, by at most 1e-11
             (the projection above, 7.0e-13 at the coarsest step, and rounding, 1e-15; a
             margin of 14; measured 7.0e-13 ... 1.1e-14);
  order      stiff, e = 1, each code against itself: its results at n and 2n steps per
             contact time differ by D(n), which falls by a factor 4 per halving of dt for a
             second-order scheme and 2 for a first-order one. Required: 3-5 from 100 steps on
             (measured 3.53-4.23 for both codes) and a fitted order of 1.8-2.2 over 25 ... 1600
             (1.92). The band allows for the stick-slip transitions and the contact's start
             and end, which fall anywhere within a step: per pair the differences change sign
             and their factors scatter (0.1-350), and the largest over the pairs is set by
             other pairs at other steps (2.57 from 25 to 50 steps, where a sticking phase lasts
             a few steps). The former scheme (velocity 'predicted', by the reference) must
             fail it (measured factors 2.00-2.07, order 1.03);
  control    stiff, e = 1, LIGGGHTS with nu = 0.31 (G* 0.2 % lower, E* 0.7 % higher) or
             mu x 1.01 at 800 and 1600 steps per contact time, compared in the same way: more
             than 100 times the agreement's bound (measured 1.2e-3 and 5.0e-3 V_N), so that
             check can fail;
  sliding    stiff, e = 1, the pairs that slide throughout (|u_t0| > 1.15 x 3.5 mu (1 + e)
             v_n): wetdem's e_t = -(1 - 3.5 mu (1 + e) v_n / |u_t0|) and spin change
             R dw = (5/2) mu (1 + e)/2 v_n n x u_hat of the rigid-body impact (Maw, Barber &
             Fawcett 1976; Walton 1993) to 5e-5, in the frame of the line of centres at
             mid-contact (with the normal of the first touch e_t is off by up to 4e-4: the
             line of centres turns by up to 4.2e-4 rad during the contact);
  lever      soft, e = 1, at 400 and 800 steps per contact time: the codes' difference
             (2.2e-3 V_N) equals the reference's effect of the lever arm alone (LIGGGHTS'
             scheme with R against R - delta/2) to 1e-8 V_N (the projection, 1.7e-9 at 400
             steps by the reference, first order, and rounding; measured 1.7e-9 and 8.7e-10);
  damped dashpots  stiff, e = 0.5: the codes' difference less the conventions' effect
             (LIGGGHTS' scheme with wetdem's Coulomb limit and lever arm, by the reference) is
             the dashpots' velocity, predicted against half-step: it halves with dt (factor
             1.8-2.2 from 800 to 1600 steps; measured 2.00, and 1.99-2.01 by the reference
             from 200 to 3200);
  damped     stiff, e = 0.5: so the codes' difference extrapolated to dt = 0 (Richardson,
             first order, from 800 and 1600 steps) equals the conventions' effect, extrapolated
             in the same way, to 1 % of it (measured 0.09 %: the extrapolation's remainder).
Usage: /usr/bin/python3 figures/liggghts_friction.py [setup|check] [DIR]
  (check by default; DIR: out/validate/liggghts_friction)
"""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from common import ROOT, np, plt  # noqa: E402
from many_figs import check, save_and_finish  # noqa: E402

R, RHO, NU, MU = 1e-3, 2500.0, 0.3, 0.2
SETS = {"stiff": dict(E=7e10, vn=0.01), "soft": dict(E=1e7, vn=0.1)}
ANGLES = [2, 5, 10, 15, 20, 30, 40, 50, 60, 70, 80]  # impact angle at first touch [deg]
SPIN = (1.0, 0.4, 0.3)  # the striker's spin in V_N / R: twist, out-of-plane slip, in-plane
N_STIFF = [25, 50, 100, 200, 400, 800, 1600]  # steps per head-on contact time
N_SOFT = [400, 800]
N_CONTROL = [800, 1600]
NU_CONTROL, MU_CONTROL = 0.31, 1.01 * MU  # LIGGGHTS' parameters in the controls
N_DAMPED = [800, 1600]
E_DAMPED = 0.5
SPACING = 10e-3  # between pairs [m]: far beyond the neighbour lists' reach
OFFSET = 5e-3  # of the first pair from the box's corner at the origin [m]


def mass():
    return RHO * 4.0 / 3.0 * math.pi * R ** 3


def star(E, nu=NU):
    """E* and G* of two spheres of one material [Pa] (as both codes mix them)."""
    return E / (2.0 * (1.0 - nu * nu)), E / (4.0 * (2.0 - nu) * (1.0 + nu))


def contact_time(E, vn):
    """Hertz contact time of the head-on impact at vn [s] (m* = m/2, R* = R/2)."""
    ms, rs, es = mass() / 2, R / 2, star(E)[0]
    return 2.868 * (ms * ms / (rs * es * es * vn)) ** 0.2


def pairs(vn):
    """[(striker velocity, striker spin)] of every pair, the target at rest."""
    out = []
    for spin in ((0.0, 0.0, 0.0), SPIN):
        for a in ANGLES:
            out.append(((-vn, vn * math.tan(math.radians(a)), 0.0),
                        tuple(s * vn / R for s in spin)))
    return out


def t_gap(E, vn):
    return 0.2 * contact_time(E, vn)


def initial_state(name):
    """[(x1, v1, w1, x2, v2, w2)] of set `name`, as the files give it (17 digits)."""
    E, vn = SETS[name]["E"], SETS[name]["vn"]
    t0, state = t_gap(E, vn), []
    for k, (v, w) in enumerate(pairs(vn)):
        c = (OFFSET + k * SPACING, OFFSET, OFFSET)
        x1 = (c[0] + 2 * R - v[0] * t0, c[1] - v[1] * t0, c[2])
        state.append(tuple(tuple(float(f"{q:.17g}") for q in vec)
                           for vec in (x1, v, w, c, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))))
    return state


def run_name(name, n, e=1.0):
    """The name of a run's files: SET_N, with _damped for e < 1."""
    return f"{name}_{n}" + ("" if e == 1.0 else "_damped")


def run_steps(name, n):
    E, vn = SETS[name]["E"], SETS[name]["vn"]
    tc = contact_time(E, vn)
    dt = float(f"{tc / n:.6g}")
    return dt, int(math.ceil((t_gap(E, vn) + 1.4 * tc) / dt))


def setup(d):
    os.makedirs(d, exist_ok=True)
    runs = []
    for name in SETS:
        st = initial_state(name)
        lo = [0.0, 0.0, 0.0]
        hi = [max(max(p[0][k], p[3][k]) for p in st) + OFFSET for k in range(3)]
        with open(os.path.join(d, f"{name}.csv"), "w") as f:
            f.write("x [m], y [m], z [m], radius [m], vx [m/s], vy [m/s], vz [m/s], "
                    "spin_x [rad/s], spin_y [rad/s], spin_z [rad/s]\n")
            for p in st:
                for x, v, w in ((p[0], p[1], p[2]), (p[3], p[4], p[5])):
                    f.write(", ".join(f"{q:.17g}" for q in (*x, R, *v, *w)) + "\n")
        with open(os.path.join(d, f"{name}.data"), "w") as f:
            f.write(f"wetdem friction cross-check, set {name}\n\n{2 * len(st)} atoms\n"
                    "1 atom types\n\n")
            for k, ax in enumerate("xyz"):
                f.write(f"{lo[k]:.17g} {hi[k]:.17g} {ax}lo {ax}hi\n")
            f.write("\nAtoms\n\n")
            i = 1
            for p in st:
                for x in (p[0], p[3]):
                    f.write(f"{i} 1 {2 * R:.17g} {RHO:.17g} {x[0]:.17g} {x[1]:.17g} "
                            f"{x[2]:.17g}\n")
                    i += 1
            f.write("\nVelocities\n\n")
            i = 1
            for p in st:
                for v, w in ((p[1], p[2]), (p[4], p[5])):
                    f.write(f"{i} " + " ".join(f"{q:.17g}" for q in (*v, *w)) + "\n")
                    i += 1
        with open(os.path.join(d, f"wetdem_{name}.ini"), "w") as f:
            f.write(f"""# set {name} of the friction cross-check (liggghts_friction.py setup)
[box]
size_x = {hi[0]:.17g}
size_y = {hi[1]:.17g}
size_z = {hi[2]:.17g}
[walls]
faces = none
[material.m]
density = {RHO:.17g}
youngs_modulus = {SETS[name]['E']:.17g}
poisson_ratio = {NU:.17g}
restitution = 1      ; each run sets material.m.restitution
friction_dry = {MU:.17g}
[models]
force = hertz mindlin
[model.hertz]
damping = tsuji      ; LIGGGHTS' model hertz
[read.pairs]
file = {name}.csv
material = m
[run]
steps = 1            ; each run sets run.dt and run.steps
energy_budget = no
[dump]
csv = none
checkpoint = none
summary = none
""")
        for n, e in ([(n, 1.0) for n in N_STIFF] + [(n, E_DAMPED) for n in N_DAMPED]
                     if name == "stiff" else [(n, 1.0) for n in N_SOFT]):
            dt, steps = run_steps(name, n)
            base = f"{name} {dt:.6g} {steps} {e:g} {SETS[name]['E']:.17g}"
            runs.append(f"{run_name(name, n, e)} {base} {NU:g} {MU:g} both")
            if name == "stiff" and e == 1.0 and n in N_CONTROL:  # the controls: LIGGGHTS
                runs.append(f"{run_name(name, n, e)}_nu {base} {NU_CONTROL:g} {MU:g} liggghts")
                runs.append(f"{run_name(name, n, e)}_mu {base} {NU:g} {MU_CONTROL:g} liggghts")
    with open(os.path.join(d, "runs.txt"), "w") as f:
        f.write("# name set dt steps e E nu mu codes\n" + "\n".join(runs) + "\n")


# ---- the reference: both schemes, step for step ----

def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _axpy(a, x, y):
    return (a * x[0] + y[0], a * x[1] + y[1], a * x[2] + y[2])


def _sc(a, x):
    return (a * x[0], a * x[1], a * x[2])


def pair_force(x1, v1, w1, x2, v2, w2, s, adv, p, scheme, spring_vel=None):
    """Force on the striker (1; the target gets its opposite), the torque on either sphere
    (the same for equal spheres), the new spring, and whether the contact slides (the limit
    caps the force), of one evaluation with the spring advanced over adv [s]. p: E, nu, mu,
    e; scheme: lever ('R' or 'R-d/2'), spring ('rotate' or 'project'), limit ('wetdem' or
    'liggghts'). The spring advances with the slip of spring_vel (v1, w1, v2, w2; at the
    current normal and lever arm) when given, else with that of v1, w1, v2, w2, which the
    dashpots and the normal damping take."""
    d = (x1[0] - x2[0], x1[1] - x2[1], x1[2] - x2[2])
    r = math.sqrt(_dot(d, d))
    n = _sc(1.0 / r, d)
    delta = 2 * R - r
    zero = (0.0, 0.0, 0.0)
    if delta <= 0:
        return zero, zero, zero, False
    es, gs = star(p["E"], p["nu"])
    ms, rs = mass() / 2, R / 2
    c = R if scheme["lever"] == "R" else R - 0.5 * delta
    vr = (v1[0] - v2[0], v1[1] - v2[1], v1[2] - v2[2])
    vn = _dot(vr, n)
    vt = _axpy(-vn, n, vr)
    rot = _cross(_axpy(c, w1, _sc(c, w2)), n)  # (c w1 + c w2) x n
    vt = (vt[0] - rot[0], vt[1] - rot[1], vt[2] - rot[2])
    vs = vt
    if spring_vel is not None:
        sv1, sw1, sv2, sw2 = spring_vel
        vr = (sv1[0] - sv2[0], sv1[1] - sv2[1], sv1[2] - sv2[2])
        vs = _axpy(-_dot(vr, n), n, vr)
        rot = _cross(_axpy(c, sw1, _sc(c, sw2)), n)
        vs = (vs[0] - rot[0], vs[1] - rot[1], vs[2] - rot[2])
    sq = math.sqrt(rs * delta)
    kt = 8 * gs * sq
    f_el = 4.0 / 3.0 * es * sq * delta
    le = math.log(p["e"])
    beta = le / math.sqrt(le * le + math.pi * math.pi)
    gamma_n = -2 * math.sqrt(5.0 / 6.0) * beta * math.sqrt(2 * es * sq * ms)
    gamma_t = -2 * math.sqrt(5.0 / 6.0) * beta * math.sqrt(kt * ms)
    f_n = f_el - gamma_n * vn
    if scheme["spring"] == "rotate":
        length = math.sqrt(_dot(s, s))
        q = _axpy(-_dot(s, n), n, s)
        ql = math.sqrt(_dot(q, q))
        s = _sc(length / ql, q) if ql > 0 else zero
        s = _axpy(adv, vs, s)
    else:
        s = _axpy(adv, vs, s)
        s = _axpy(-_dot(s, n), n, s)
    if scheme["limit"] == "wetdem":
        ft = _axpy(-gamma_t, vt, _sc(-kt, s))
        f, fmax = math.sqrt(_dot(ft, ft)), p["mu"] * f_el
        slides = f > fmax
        if slides:
            ft = _sc(fmax / f, ft)
            s = _sc(-1.0 / kt, _axpy(gamma_t, vt, ft))
    else:
        ft = _sc(-kt, s)
        f, fmax = kt * math.sqrt(_dot(s, s)), p["mu"] * abs(f_n)
        slides = f > fmax
        if slides:
            ft = _sc(fmax / f, ft) if f > 0 else zero
            s = _sc(-1.0 / kt, ft)
        else:
            ft = _axpy(-gamma_t, vt, ft)
    force = _axpy(f_n, n, ft)
    torque = _sc(-c, _cross(n, ft))
    return force, torque, s, slides


WETDEM = dict(lever="R", spring="rotate", limit="wetdem", velocity="midpoint")
LIGGGHTS = dict(lever="R-d/2", spring="project", limit="liggghts", velocity="half")


def step_map(state, p, dt, steps, scheme, stats=None):
    """Final (v1, w1, v2, w2) of one pair after `steps` velocity Verlet steps of dt; with
    stats (a dict), the numbers of steps in contact and sliding into it."""
    x1, v1, w1, x2, v2, w2 = state
    m = mass()
    inertia = 0.4 * m * R * R
    s = (0.0, 0.0, 0.0)
    f, t, _, _ = pair_force(x1, v1, w1, x2, v2, w2, s, 0.0, p, scheme)
    touching = sliding = 0
    for _ in range(steps):
        v1, v2 = _axpy(dt / 2 / m, f, v1), _axpy(-dt / 2 / m, f, v2)
        w1, w2 = _axpy(dt / 2 / inertia, t, w1), _axpy(dt / 2 / inertia, t, w2)
        x1, x2 = _axpy(dt, v1, x1), _axpy(dt, v2, x2)
        half = (v1, w1, v2, w2)
        u = half if scheme["velocity"] == "half" else (
            _axpy(dt / 2 / m, f, v1), _axpy(dt / 2 / inertia, t, w1),
            _axpy(-dt / 2 / m, f, v2), _axpy(dt / 2 / inertia, t, w2))
        f, t, s, slides = pair_force(x1, u[0], u[1], x2, u[2], u[3], s, dt, p, scheme,
                                     half if scheme["velocity"] == "midpoint" else None)
        touching += f != (0.0, 0.0, 0.0)  # (the last step's stays in f: apart at the end?)
        sliding += slides
        v1, v2 = _axpy(dt / 2 / m, f, v1), _axpy(-dt / 2 / m, f, v2)
        w1, w2 = _axpy(dt / 2 / inertia, t, w1), _axpy(dt / 2 / inertia, t, w2)
    if stats is not None:
        stats.update(touching=touching, sliding=sliding, apart=f == (0.0, 0.0, 0.0))
    return np.array([*v1, *w1, *v2, *w2])


def params(name, **kw):
    p = dict(E=SETS[name]["E"], nu=NU, mu=MU, e=1.0)
    p.update(kw)
    return p


# ---- reading the runs ----

def read_wetdem(d, run):
    """(pairs, 12) of v1, w1, v2, w2 at the end of wetdem's run `run` (run_name)."""
    sys.path.insert(0, os.path.join(ROOT, "tools"))
    from wetdem_vtk import read_series, read_vtk
    frame = read_vtk(read_series(os.path.join(d, f"wetdem_{run}",
                                              "particles.vtk.series"))[-1][1])
    v, w = frame["velocity"], frame["spin"]
    return np.hstack([v[0::2], w[0::2], v[1::2], w[1::2]])


def read_liggghts(path):
    """(pairs, 12) of v1, w1, v2, w2 at the last dump of a LIGGGHTS run."""
    lines = open(path).read().split("\n")
    starts = [k for k, ln in enumerate(lines) if ln.startswith("ITEM: ATOMS")]
    natoms = int(lines[starts[-1] - 5])  # after ITEM: NUMBER OF ATOMS
    rows = np.array([ln.split() for ln in lines[starts[-1] + 1:starts[-1] + 1 + natoms]],
                    float)
    if not np.array_equal(rows[:, 0], np.arange(1, natoms + 1)):
        check(False, f"{path} is not sorted by id")
    a = rows[:, 1:]
    return np.hstack([a[0::2], a[1::2]])


def scaled(a, vn):
    """Velocities over vn and spins times R over vn."""
    out = a / vn
    out[:, 3:6] *= R
    out[:, 9:12] *= R
    return out


def largest(a, b, vn):
    """Per pair, the largest difference of a velocity or R x spin component, over vn."""
    return np.abs(scaled(a, vn) - scaled(b, vn)).max(axis=1)


def slip(a, vn):
    """Tangential slip (y, z) of the striker's contact point relative to the target's, with
    n = x, from (pairs, 12) states, over vn."""
    v1, w1, v2, w2 = a[:, 0:3], a[:, 3:6], a[:, 6:9], a[:, 9:12]
    u = (v1 - v2) - R * np.cross(w1 + w2, np.array([1.0, 0.0, 0.0]))
    return u[:, 1:] / vn


def initial_array(name):
    return np.array([[*p[1], *p[2], *p[4], *p[5]] for p in initial_state(name)])


def mean_normal(a0, a1, tc):
    """Unit normals of the pairs at mid-contact, from the first touch (x, a distance 2R) and
    the centres' relative tangential velocity, taken linear in time from its value before
    (a0) to after (a1) the contact of duration tc."""
    w0, w1 = a0[:, 0:3] - a0[:, 6:9], a1[:, 0:3] - a1[:, 6:9]
    off = (tc / 2) * (3 * w0 + w1) / 4
    nb = np.column_stack([np.full(len(a0), 2 * R), off[:, 1], off[:, 2]])
    return nb / np.linalg.norm(nb, axis=1)[:, None]


def slip_in(a, nb, vn):
    """Tangential slip of the striker's contact point relative to the target's, normal to
    nb (3-vectors), and the normal approach speed along nb, over vn."""
    v, w = a[:, 0:3] - a[:, 6:9], a[:, 3:6] + a[:, 9:12]
    u = v - R * np.cross(w, nb)
    u -= np.einsum("ij,ij->i", u, nb)[:, None] * nb
    return u / vn, -np.einsum("ij,ij->i", v, nb) / vn


def tangential_restitution(a0, a1, nb, vn):
    u0, _ = slip_in(a0, nb, vn)
    u1, _ = slip_in(a1, nb, vn)
    return -np.einsum("ij,ij->i", u1, u0) / np.einsum("ij,ij->i", u0, u0)


def reference_all(name, n, scheme, p):
    dt, steps = run_steps(name, n)
    return np.array([step_map(s, p, dt, steps, scheme) for s in initial_state(name)])


AGREE_BOUND = 1e-11  # [V_N]: stiff, e = 1, codes less the lever arm; docstring, "agreement"
SOFT_BOUND = 1e-8  # [V_N]: the same in the soft set; docstring, "lever"
ORDER_FROM, ORDER_BAND, FIT_BAND = 100, (3.0, 5.0), (1.8, 2.2)  # docstring, "order"
FORMER = dict(WETDEM, velocity="predicted")  # wetdem's spring before: the predicted slip


def order(a, ns):
    """Successive differences D(n) = largest |a[n] - a[2n]| (scaled), their factors per
    halving of dt, and the order fitted to all of them (slope of log D against log dt)."""
    big = [np.abs(a[n] - a[2 * n]).max() for n in ns[:-1]]
    factors = [x / y for x, y in zip(big, big[1:])]
    fit = np.polyfit(np.log(1.0 / np.array(ns[:-1], float)), np.log(big), 1)[0]
    return big, factors, fit


def second_order(factors, fit):
    lo, hi = ORDER_BAND
    tail = factors[N_STIFF.index(ORDER_FROM):]
    return all(lo <= f <= hi for f in tail) and FIT_BAND[0] <= fit <= FIT_BAND[1]


def main_check(d):
    vn = SETS["stiff"]["vn"]
    p1, pd = params("stiff"), params("stiff", e=E_DAMPED)
    wd, lg, diff, lever, corr, proj, former, ref_err = {}, {}, {}, {}, {}, {}, {}, []
    for n in N_STIFF:
        wd[n] = read_wetdem(d, run_name("stiff", n))
        lg[n] = read_liggghts(os.path.join(d, f"liggghts_{run_name('stiff', n)}.dump"))
        diff[n] = scaled(wd[n], vn) - scaled(lg[n], vn)
        ref = {"wetdem": reference_all("stiff", n, WETDEM, p1),
               "LIGGGHTS": reference_all("stiff", n, LIGGGHTS, p1)}
        for code, got in (("wetdem", wd[n]), ("LIGGGHTS", lg[n])):
            ref_err.append((largest(got, ref[code], vn).max(), code, n, "stiff"))
        # LIGGGHTS as it would be with wetdem's lever arm R (its scheme, one switch changed)
        lever_r = reference_all("stiff", n, dict(LIGGGHTS, lever="R"), p1)
        lever[n] = scaled(lever_r - ref["LIGGGHTS"], vn)
        corr[n] = diff[n] - lever[n]
        proj[n] = largest(ref["wetdem"], lever_r, vn).max()  # rotation against projection
        former[n] = scaled(reference_all("stiff", n, FORMER, p1), vn)
    dmp = {}
    for n in N_DAMPED:
        w = read_wetdem(d, run_name("stiff", n, E_DAMPED))
        g = read_liggghts(os.path.join(d, f"liggghts_{run_name('stiff', n, E_DAMPED)}.dump"))
        rl = reference_all("stiff", n, LIGGGHTS, pd)
        for code, got, sch in (("wetdem", w, WETDEM), ("LIGGGHTS", g, LIGGGHTS)):
            ref = rl if code == "LIGGGHTS" else reference_all("stiff", n, sch, pd)
            ref_err.append((largest(got, ref, vn).max(), code, n, "damped"))
        conv = reference_all("stiff", n, dict(LIGGGHTS, lever="R", limit="wetdem"), pd) - rl
        dmp[n] = dict(w=w, g=g, diff=scaled(w, vn) - scaled(g, vn), conv=scaled(conv, vn))
    vs, ps = SETS["soft"]["vn"], params("soft")
    soft, lever_soft, proj_soft = {}, {}, {}
    for n in N_SOFT:
        w = read_wetdem(d, run_name("soft", n))
        g = read_liggghts(os.path.join(d, f"liggghts_{run_name('soft', n)}.dump"))
        rl, rw = reference_all("soft", n, LIGGGHTS, ps), reference_all("soft", n, WETDEM, ps)
        ref_err.append((largest(g, rl, vs).max(), "LIGGGHTS", n, "soft"))
        ref_err.append((largest(w, rw, vs).max(), "wetdem", n, "soft"))
        lever_r = reference_all("soft", n, dict(LIGGGHTS, lever="R"), ps)
        soft[n] = scaled(w, vs) - scaled(g, vs)
        lever_soft[n] = scaled(lever_r - rl, vs)
        proj_soft[n] = largest(rw, lever_r, vs).max()
    worst = max(ref_err)
    check(worst[0] <= 1e-9,
          f"reference: each code equals its scheme written out, for every pair and step, to "
          f"{worst[0]:.2g} V_N at most ({worst[1]}, {worst[3]}, {worst[2]} steps per contact "
          "time; <= 1e-9), in the stiff, damped and soft runs")

    # e = 1: no dashpots, one Coulomb rule, one spring velocity (the half step's slip): the
    # schemes differ by the lever arm and the spring's rotation against its projection
    pf = [proj[a] / proj[b] for a, b in zip(N_STIFF, N_STIFF[1:]) if b <= 400]
    dec_rel = max(proj[n] / np.abs(diff[n]).max() for n in N_STIFF)
    check(dec_rel <= 1e-6 and all(1.6 <= f <= 2.5 for f in pf),
          "decomposition: e = 1, wetdem's scheme and LIGGGHTS' with the lever arm R differ by "
          + ", ".join(f"{proj[n]:.2g}" for n in N_STIFF) + " V_N at "
          + ", ".join(str(n) for n in N_STIFF) + " steps per contact time, the spring's "
          "rotation against projection (first order: factors "
          + ", ".join(f"{f:.2f}" for f in pf) + " to 400, 1.6-2.5), at most "
          f"{dec_rel:.2g} of the codes' difference (<= 1e-6)")

    big = [np.abs(diff[n]).max() for n in N_STIFF]
    lev = [np.abs(lever[n]).max() for n in N_STIFF]
    agree = [np.abs(corr[n]).max() for n in N_STIFF]
    check(max(agree) <= AGREE_BOUND,
          "agreement: stiff, e = 1, the codes differ by " + ", ".join(f"{b:.4g}" for b in big)
          + " V_N at " + ", ".join(str(n) for n in N_STIFF) + " steps per contact time, the "
          f"lever arm's effect by the reference ({min(lev):.4g}-{max(lev):.4g}); less it, by "
          + ", ".join(f"{a:.2g}" for a in agree) + f" (<= {AGREE_BOUND:g}: the projection "
          "above and rounding)")

    # each code against itself: second order (the spring at the half step's slip); the
    # former wetdem scheme (the predicted slip, by the reference) is first order
    own, orders = {}, {}
    sw = {n: scaled(wd[n], vn) for n in N_STIFF}
    sg = {n: scaled(lg[n], vn) for n in N_STIFF}
    n1, n0 = N_STIFF[-1], N_STIFF[-2]
    for code, a, richardson in (("wetdem", sw, 3), ("LIGGGHTS", sg, 3), ("former", former, 1)):
        big_c, factors, fit = order(a, N_STIFF)
        orders[code] = (big_c, factors, fit)
        lim = a[n1] + (a[n1] - a[n0]) / richardson  # 2nd order: /3; 1st: /1
        own[code] = [np.abs(a[n] - lim).max() for n in N_STIFF]
    for code in ("wetdem", "LIGGGHTS"):
        big_c, factors, fit = orders[code]
        check(second_order(factors, fit),
              f"order: {code}, e = 1, its own results at successive halvings of dt differ by "
              + ", ".join(f"{b:.2g}" for b in big_c) + " V_N (25 ... 800 against twice the "
              "steps): factors " + ", ".join(f"{f:.2f}" for f in factors)
              + f" (from {ORDER_FROM}: {ORDER_BAND[0]:g}-{ORDER_BAND[1]:g}), fitted order "
              f"{fit:.2f} ({FIT_BAND[0]:g}-{FIT_BAND[1]:g}): second order")
    big_c, factors, fit = orders["former"]
    check(not second_order(factors, fit),
          "order control: wetdem's former scheme (the spring at the predicted slip; "
          "reference): factors " + ", ".join(f"{f:.2f}" for f in factors)
          + f", fitted order {fit:.2f}: first order, which the check above refuses")
    print("  accuracy: largest error against the code's own dt = 0 limit (Richardson from "
          f"{n0} and {n1}), wetdem / LIGGGHTS / former wetdem: "
          + ", ".join(f"{a:.2g} / {b:.2g} / {c:.2g}" for a, b, c in
                      zip(own["wetdem"], own["LIGGGHTS"], own["former"]))
          + " V_N at " + ", ".join(str(n) for n in N_STIFF) + " steps per t_c")

    controls = {}
    for tag, label in (("nu", f"nu = {NU_CONTROL:g}"), ("mu", f"mu x {MU_CONTROL / MU:g}")):
        # wetdem against the perturbed LIGGGHTS, with the same lever correction
        controls[tag] = {n: np.abs(corr[n] + sg[n] - scaled(read_liggghts(os.path.join(
            d, f"liggghts_{run_name('stiff', n)}_{tag}.dump")), vn)).max()
            for n in N_CONTROL}
        worst_c = min(controls[tag].values())
        check(worst_c > 100 * AGREE_BOUND,
              f"control: LIGGGHTS with {label} differs, less the lever arm, by "
              + ", ".join(f"{controls[tag][n]:.2g}" for n in N_CONTROL) + " V_N at "
              + ", ".join(str(n) for n in N_CONTROL) + f" steps per t_c, "
              f"{worst_c / AGREE_BOUND:.2g} x the agreement's bound (> 100)")

    # gross sliding: the rigid-body closed form (e = 1), in the frame of the mid-contact normal
    tc = contact_time(SETS["stiff"]["E"], vn)
    a0, a1 = initial_array("stiff"), wd[n1]
    nb = mean_normal(a0, a1, tc)
    u0, vneff = slip_in(a0, nb, vn)
    u0n = np.linalg.norm(u0, axis=1)
    sliding = u0n > 1.15 * 3.5 * MU * 2 * vneff
    e_t = tangential_restitution(a0, a1, nb, vn)
    e_t_closed = -(1 - 3.5 * MU * 2 * vneff / u0n)
    dw1 = (a1[:, 3:6] - a0[:, 3:6]) * R / vn
    # spin change of either sphere: R mu J_n / I  n x u_hat, J_n = m* (1 + e) v_n = m v_n
    dw_closed = 2.5 * MU * vneff[:, None] * np.cross(nb, u0 / u0n[:, None])
    err_et = np.abs(e_t - e_t_closed)[sliding].max()
    err_w = np.abs(dw1 - dw_closed)[sliding].max()
    e_t_touch = tangential_restitution(a0, a1, np.tile([1.0, 0.0, 0.0], (len(a0), 1)), vn)
    e_t_touch_closed = -(1 - 3.5 * MU * 2 / np.linalg.norm(slip(a0, vn), axis=1))
    err_touch = np.abs(e_t_touch - e_t_touch_closed)[sliding].max()
    check(sliding.sum() >= 4 and err_et <= 5e-5 and err_w <= 5e-5,
          f"sliding: {sliding.sum()} pairs slide throughout; wetdem's e_t and R dw / V_N "
          f"differ from the closed form by at most {err_et:.2g} and {err_w:.2g} (<= 5e-5; "
          f"{err_touch:.2g} in e_t with the normal of the first touch)")

    # soft: the lever arm is the difference, at every step
    soft_mis = {n: np.abs(soft[n] - lever_soft[n]).max() for n in N_SOFT}
    soft_big = min(np.abs(soft[n]).max() for n in N_SOFT)
    check(max(soft_mis.values()) <= SOFT_BOUND and soft_big > 1e4 * SOFT_BOUND,
          f"lever: soft set, the codes differ by up to {soft_big:.2g} V_N at "
          + " and ".join(str(n) for n in N_SOFT) + " steps per t_c; the lever arm alone "
          "(reference) gives that to " + " and ".join(f"{soft_mis[n]:.2g}" for n in N_SOFT)
          + f" (<= {SOFT_BOUND:g}: the projection, "
          + " and ".join(f"{proj_soft[n]:.2g}" for n in N_SOFT) + " by the reference)")

    # damped: the codes differ by the conventions (Coulomb limit, lever arm), which stay at
    # dt = 0, and by the dashpots' velocity (wetdem's predicted, LIGGGHTS' half-step), first
    # order: what is left once the reference takes the conventions out
    na, nb_ = N_DAMPED
    rest = {n: dmp[n]["diff"] - dmp[n]["conv"] for n in N_DAMPED}
    rest_big = [np.abs(rest[n]).max() for n in N_DAMPED]
    rest_factor = rest_big[0] / rest_big[1]
    dmp_lim = 2 * dmp[nb_]["diff"] - dmp[na]["diff"]
    conv = 2 * dmp[nb_]["conv"] - dmp[na]["conv"]
    mis_d = np.abs(dmp_lim - conv).max() / np.abs(conv).max()
    check(1.8 <= rest_factor <= 2.2,
          f"damped dashpots: e = {E_DAMPED}, the codes' difference less the conventions' "
          "(LIGGGHTS' scheme with wetdem's Coulomb limit and lever arm) is "
          + " and ".join(f"{b:.2g}" for b in rest_big) + " V_N at "
          + " and ".join(str(n) for n in N_DAMPED) + f" steps per t_c, factor "
          f"{rest_factor:.2f} (1.8-2.2: first order, the dashpots' velocity)")
    check(mis_d <= 0.01 and np.abs(dmp_lim).max() > 1e3 * AGREE_BOUND,
          f"damped: e = {E_DAMPED}, the codes differ at dt = 0 by up to "
          f"{np.abs(dmp_lim).max():.2g} V_N; LIGGGHTS' scheme with wetdem's Coulomb limit "
          f"and lever arm gives that to {mis_d:.2g} of its size (<= 0.01)")
    e_t_lg = tangential_restitution(a0, lg[n1], nb, vn)
    e_t_dw = tangential_restitution(a0, dmp[nb_]["w"], nb, vn)
    e_t_dl = tangential_restitution(a0, dmp[nb_]["g"], nb, vn)
    share, apart = [], True
    for state in initial_state("stiff"):  # wetdem's steps that slide, at 400 steps per t_c
        stats = {}
        step_map(state, p1, *run_steps("stiff", 400), WETDEM, stats)
        share.append(stats["sliding"] / stats["touching"])
        apart = apart and stats["apart"]
    check(apart, "the runs end after the contacts: every pair is apart at the last step "
          "(reference, 400 steps per t_c)")
    n25 = N_STIFF[0]
    print(f"  per pair ({n1} steps per t_c; differences: largest of v, R w over V_N; slides: "
          "wetdem's share of sliding steps in contact)")
    print(f"  angle spin  |u_t0|/v_n slides  e_t wetdem  LIGGGHTS  closed  diff@{n25}  "
          f"diff@{n1}  less lever@{n25}  err@{n25} wetdem  former  e_t(e=0.5) wetdem  "
          "LIGGGHTS")
    lim_w = sw[n1] + (sw[n1] - sw[n0]) / 3
    lim_f = 2 * former[n1] - former[n0]
    for k in range(len(a0)):
        print(f"  {ANGLES[k % len(ANGLES)]:5d} {'yes' if k >= len(ANGLES) else 'no':4s} "
              f"{u0n[k]:9.3f} {share[k]:6.0%}  {e_t[k]:10.5f}  {e_t_lg[k]:8.5f}  "
              + (f"{e_t_closed[k]:7.4f}" if sliding[k] else "      -")
              + f"  {np.abs(diff[n25][k]).max():8.3g}  {np.abs(diff[n1][k]).max():8.3g}"
              f"  {np.abs(corr[n25][k]).max():13.2g}"
              f"  {np.abs(sw[n25][k] - lim_w[k]).max():13.2g}"
              f"  {np.abs(former[n25][k] - lim_f[k]).max():6.2g}"
              f"  {e_t_dw[k]:17.4f}  {e_t_dl[k]:8.4f}")
    # the striker's tangential over normal impulse in the pairs that slide throughout
    ratio = {}
    for code, got in (("wetdem", dmp[nb_]["w"]), ("LIGGGHTS", dmp[nb_]["g"])):
        dv = got[:, 0:3] - a0[:, 0:3]
        jn = np.einsum("ij,ij->i", dv, nb)  # the target pushes the striker back along nb
        jt = np.linalg.norm(dv - jn[:, None] * nb, axis=1)
        ratio[code] = (jt / (MU * jn))[sliding]
    print(f"  e = {E_DAMPED}, the {sliding.sum()} sliding pairs: J_t / (mu J_n) "
          + ", ".join(f"{c} {r.min():.3f}-{r.max():.3f}" for c, r in ratio.items()))
    return dict(wd=wd, lg=lg, big=big, agree=agree, own=own, orders=orders,
                controls=controls, e_t=e_t, e_t_closed=e_t_closed, sliding=sliding,
                soft=soft, lever_soft=lever_soft, corr=corr, nb=nb, dmp_lim=dmp_lim,
                conv=conv, dmp=dmp)


def figure(r):
    vn = SETS["stiff"]["vn"]
    n1 = N_STIFF[-1]
    a0 = initial_array("stiff")
    fig, ax = plt.subplots(1, 3, figsize=(16, 4.8))
    na = len(ANGLES)
    e_t_lg = tangential_restitution(a0, r["lg"][n1], r["nb"], vn)
    e_t_d = {c: tangential_restitution(a0, r["dmp"][N_DAMPED[1]][c], r["nb"], vn)
             for c in ("w", "g")}
    for k, lab in enumerate(("no spin", "spin")):
        sl = slice(k * na, (k + 1) * na)
        ax[0].plot(ANGLES, r["e_t"][sl], "o-", color=f"C{k}", ms=5,
                   label=f"wetdem, e = 1, {lab}")
        ax[0].plot(ANGLES, e_t_lg[sl], "x", color="k", ms=7,
                   label="LIGGGHTS, e = 1" if k == 0 else None)
        ax[0].plot(ANGLES, e_t_d["w"][sl], "^--", color=f"C{k}", ms=4, lw=0.8, alpha=0.7,
                   label=f"wetdem, e = {E_DAMPED}, {lab}")
        ax[0].plot(ANGLES, e_t_d["g"][sl], "+", color="0.3", ms=7,
                   label=f"LIGGGHTS, e = {E_DAMPED}" if k == 0 else None)
        ax[0].plot(np.array(ANGLES)[r["sliding"][sl]], r["e_t_closed"][sl][r["sliding"][sl]],
                   "o", mfc="none", color="C3", ms=11,
                   label="gross sliding, closed form (e = 1)" if k == 0 else None)
    ax[0].set_xlabel("impact angle at first touch [deg]")
    ax[0].set_ylabel("tangential restitution e_t of the contact slip")
    ax[0].set_title(f"mu = {MU}: sticking, micro-slip, gross sliding ({n1} steps per t_c)",
                    fontsize=10)
    ax[0].legend(fontsize=6.5, loc=(0.24, 0.02))  # the empty corner below 20-50 deg
    dts = 1.0 / np.array(N_STIFF)
    ax[1].loglog(dts, r["big"], "o-", color="C1", label="wetdem - LIGGGHTS: lever arm")
    ax[1].loglog(dts, r["agree"], "s-", color="C2", ms=4,
                 label="less the lever arm: projection")
    ax[1].loglog(dts, r["own"]["wetdem"], "o:", ms=4, color="C0", lw=1,
                 label="wetdem vs its dt = 0 limit")
    ax[1].loglog(dts, r["own"]["LIGGGHTS"], "x", ms=7, color="k",
                 label="LIGGGHTS vs its dt = 0 limit")
    ax[1].loglog(dts, r["own"]["wetdem"][2] * (dts / dts[2]) ** 2, "k--", lw=0.8,
                 label="second order")
    ax[1].loglog(dts, r["own"]["former"], "v-.", ms=4, color="0.5", lw=0.8,
                 label="former wetdem (predicted slip)")
    for tag, col, lab in (("nu", "C3", f"nu = {NU_CONTROL:g}"),
                          ("mu", "C4", f"mu x {MU_CONTROL / MU:g}")):
        c = r["controls"][tag]
        ax[1].loglog([1.0 / n for n in N_CONTROL], [c[n] for n in N_CONTROL], "*", ms=9,
                     color=col, label=f"control: LIGGGHTS, {lab}")
    ax[1].set_xlabel("dt / head-on contact time t_c")
    ax[1].set_ylabel("largest difference of v, R w [V_N]")
    ax[1].set_ylim(1e-16, 1)
    ax[1].set_title("Stiff, e = 1 (delta/R = 5e-5): the lever arm at every dt,\n"
                    "each code second order to its limit", fontsize=10)
    ax[1].legend(fontsize=6, loc="center", bbox_to_anchor=(0.5, 0.44), ncol=2)  # the gap
    x = np.arange(2 * na)
    ax[2].semilogy(x, np.abs(r["dmp_lim"]).max(axis=1), "^", color="C1",
                   label=f"stiff, e = {E_DAMPED}, at dt = 0: wetdem - LIGGGHTS")
    ax[2].semilogy(x, np.abs(r["conv"]).max(axis=1), "+", ms=11, color="C1",
                   label="  reference: Coulomb limit and lever arm")
    ns = N_SOFT[-1]
    ax[2].semilogy(x, np.abs(r["soft"][ns]).max(axis=1), "o", color="C0",
                   label=f"soft, e = 1, {ns} steps per t_c: wetdem - LIGGGHTS")
    ax[2].semilogy(x, np.abs(r["lever_soft"][ns]).max(axis=1), "x", ms=9, color="C0",
                   label="  reference: lever arm R vs R - delta/2")
    ax[2].semilogy(x, np.maximum(np.abs(r["corr"][n1]).max(axis=1), 1e-17), "s", color="C2",
                   ms=4, label=f"stiff, e = 1, {n1} steps per t_c, less the lever arm")
    ax[2].set_xticks(x, [f"{a}" for a in ANGLES] * 2, fontsize=7)
    ax[2].set_xlabel("impact angle [deg] (left: no spin, right: spin)")
    ax[2].set_ylabel("largest difference of v, R w [V_N]")
    ax[2].set_title("What the codes differ by: the documented differences only", fontsize=10)
    ax[2].set_ylim(1e-18, 1)
    ax[2].legend(fontsize=6.5, loc="center", bbox_to_anchor=(0.5, 0.5))  # the gap
    fig.suptitle("Binary oblique collisions with friction (Hertz-Mindlin): wetdem against "
                 "LIGGGHTS 3.8", fontsize=11)
    save_and_finish(fig, "liggghts_friction.png")


def main():
    mode = sys.argv[1] if len(sys.argv) > 1 else "check"  # make figures: redraw, recheck
    if mode not in ("setup", "check"):
        print("usage: " + __doc__.split("Usage: ")[1].strip(), file=sys.stderr)
        sys.exit(2)
    d = sys.argv[2] if len(sys.argv) > 2 else os.path.join(ROOT, "out", "validate",
                                                          "liggghts_friction")
    if mode == "setup":
        setup(d)
    else:
        figure(main_check(d))


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Frictional simultaneous hard contacts of planar spheres: an independent computation of the
pairwise engine's joint rule (docs/derivations/pairwise.md Sec. 6, "Simultaneous contacts"),
written in 2-D vector form and plain Python for the reference values of tests/test_pairwise.c.

Compression: the impulses P = (J_n, J_t) of the contacts that bring every normal approach
speed to zero and leave the least kinetic energy within the friction cone |J_t| <= mu J_n;
restitution: normal impulses e J_n more (Poisson) and tangential increments d, |d| <= mu e J_n,
again of least kinetic energy. Each is found by enumerating the cone's faces (per contact:
free, or sliding at -+mu times its normal impulse) and keeping the least energy among the
faces' constrained minimisers (Lagrange multipliers) that lie in the cone.

Usage: python3 tools/simultaneous_friction.py   (prints the set-ups of the tests)
       python3 tools/simultaneous_friction.py --random 2000 --seed 7
           (random sets of two and three contacts on one sphere: how many would gain energy)
"""
import argparse
import itertools
import math
import random


def solve(A, b):
    """Gauss-Jordan elimination with partial pivoting."""
    n = len(b)
    M = [row[:] + [b[i]] for i, row in enumerate(A)]
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(M[r][c]))
        M[c], M[p] = M[p], M[c]
        for r in range(n):
            if r != c:
                f = M[r][c] / M[c][c]
                M[r] = [x - f * y for x, y in zip(M[r], M[c])]
    return [M[i][n] / M[i][i] for i in range(n)]


class Contacts:
    """Spheres (centres X, velocities V, spins W, masses m, radii a; I = 2/5 m a^2) and the
    contacts (i, j) met at one instant. P[q] is contact q's normal impulse on i along n (unit,
    from j's centre to i's), P[n + q] its tangential impulse on i along t = (n_y, -n_x); j
    receives the opposite."""

    def __init__(self, X, V, W, m, a, contacts):
        self.V, self.W, self.m, self.a, self.c = V, W, m, a, contacts
        self.I = [0.4 * mi * ai * ai for mi, ai in zip(m, a)]
        self.n = len(contacts)
        self.geo = []
        for i, j in contacts:
            dx, dy = X[i][0] - X[j][0], X[i][1] - X[j][1]
            d = math.hypot(dx, dy)
            self.geo.append(((dx / d, dy / d), (dy / d, -dx / d)))

    def after(self, P):
        """Velocities and spins after the impulses P (Newton's laws for each sphere)."""
        V = [list(v) for v in self.V]
        W = list(self.W)
        for q, (i, j) in enumerate(self.c):
            (nx, ny), (tx, ty) = self.geo[q]
            px, py = P[q] * nx + P[self.n + q] * tx, P[q] * ny + P[self.n + q] * ty
            V[i][0] += px / self.m[i]
            V[i][1] += py / self.m[i]
            V[j][0] -= px / self.m[j]
            V[j][1] -= py / self.m[j]
            # torque of the impulse at the contact point: r x P, r = -a_i n on i, +a_j n on j
            W[i] += -self.a[i] * (nx * py - ny * px) / self.I[i]
            W[j] += self.a[j] * (nx * -py - ny * -px) / self.I[j]
        return V, W

    def energy(self, P):
        V, W = self.after(P)
        return sum(0.5 * self.m[k] * (V[k][0] ** 2 + V[k][1] ** 2) + 0.5 * self.I[k] * W[k] ** 2
                   for k in range(len(V)))

    def approach(self, P):
        """Normal approach speed of every contact after P."""
        V, _ = self.after(P)
        return [-((V[i][0] - V[j][0]) * self.geo[q][0][0] + (V[i][1] - V[j][1]) * self.geo[q][0][1])
                for q, (i, j) in enumerate(self.c)]


def quadratic(f, x0, dim):
    """Gradient and Hessian of the quadratic f at x0 by exact differences of a quadratic."""
    f0 = f(x0)
    unit = [[1.0 if r == c else 0.0 for r in range(dim)] for c in range(dim)]
    fp = [f([x0[r] + unit[c][r] for r in range(dim)]) for c in range(dim)]
    fm = [f([x0[r] - unit[c][r] for r in range(dim)]) for c in range(dim)]
    g = [(fp[c] - fm[c]) / 2 for c in range(dim)]
    H = [[0.0] * dim for _ in range(dim)]
    for r in range(dim):
        for c in range(dim):
            both = f([x0[k] + unit[r][k] + unit[c][k] for k in range(dim)])
            H[r][c] = both - fp[r] - fp[c] + f0
    return g, H


def least_energy(cs, P0, B, plastic):
    """min T(P0 + B z), with every approach speed brought to zero if plastic."""
    M, k = 2 * cs.n, len(B[0]) if B else 0
    scale = max(cs.m)  # impulses of order m v: differences in units of the mass
    T = lambda z: cs.energy([P0[r] + sum(B[r][i] * z[i] * scale for i in range(k))
                             for r in range(M)])
    g, H = quadratic(T, [0.0] * k, k)
    rows = []
    if plastic:  # approach speed is linear in z: its rows by differences
        base = cs.approach(P0)
        for i in range(k):
            moved = cs.approach([P0[r] + B[r][i] * scale for r in range(M)])
            rows.append([moved[q] - base[q] for q in range(cs.n)])
    nc = cs.n if plastic else 0
    A = [[0.0] * (k + nc) for _ in range(k + nc)]
    b = [0.0] * (k + nc)
    for i in range(k):
        b[i] = -g[i]
        for j in range(k):
            A[i][j] = H[i][j]
        for q in range(nc):
            A[i][k + q] = A[k + q][i] = rows[i][q]
    for q in range(nc):
        b[k + q] = -base[q]
    z = solve(A, b) if k + nc else []
    return [P0[r] + sum(B[r][i] * z[i] * scale for i in range(k)) for r in range(M)]


def joint(cs, e, mu):
    n, M = cs.n, 2 * cs.n
    best = None
    for modes in itertools.product((0, 1, -1), repeat=n):  # compression
        cols = []
        for q in range(n):
            col = [0.0] * M
            col[q] = 1.0
            if modes[q]:
                col[n + q] = -modes[q] * mu
                cols.append(col)
            else:
                cols.append(col)
                col = [0.0] * M
                col[n + q] = 1.0
                cols.append(col)
        P = least_energy(cs, [0.0] * M, [[c[r] for c in cols] for r in range(M)], True)
        if all(P[q] > 0 and abs(P[n + q]) <= mu * P[q] * (1 + 1e-9) for q in range(n)):
            if best is None or cs.energy(P) < cs.energy(best):
                best = P
    if best is None:  # a contact would pull: no joint solution
        return None
    P1, best = best, None
    for modes in itertools.product((0, 1, -1), repeat=n):  # restitution
        P0 = P1[:]
        cols = []
        for q in range(n):
            P0[q] = (1 + e) * P1[q]
            if modes[q]:
                P0[n + q] -= modes[q] * mu * e * P1[q]
            else:
                col = [0.0] * M
                col[n + q] = 1.0
                cols.append(col)
        P = least_energy(cs, P0, [[c[r] for c in cols] for r in range(M)], False)
        if all(abs(P[n + q] - P1[n + q]) <= mu * e * P1[q] * (1 + 1e-9) for q in range(n)):
            if best is None or cs.energy(P) < cs.energy(best):
                best = P
    return best


def report(name, cs, e, mu):
    P = joint(cs, e, mu)
    V, W = cs.after(P)
    T0 = cs.energy([0.0] * (2 * cs.n))
    print(f"{name}: e_dry = {e}, mu_f = {mu}, T/T0 = {cs.energy(P) / T0:.12f}")
    for k in range(len(V)):
        print(f"  sphere {k + 1}: v = ({V[k][0]:.15f}, {V[k][1]:.15f}), "
              f"a omega = {W[k] * cs.a[k]:.15f}")


def random_sets(trials, seed):
    """Random sets of two or three contacts on sphere 1 (radii 0.5-1.5 mm, masses
    0.3-3e-5 kg, spins up to 500 rad/s, e_dry 0.5-1, mu_f 0.05-1, contacts at least 1.2 rad
    apart, all approaching): the sets solved and those whose kinetic energy would grow."""
    rng = random.Random(seed)
    solved, gains = 0, []
    for _ in range(trials):
        n = rng.choice([2, 2, 3])
        a = [rng.uniform(0.5e-3, 1.5e-3) for _ in range(n + 1)]
        m = [rng.uniform(0.3e-5, 3e-5) for _ in range(n + 1)]
        X, V, W = [[0.0, 0.0]], [[rng.uniform(-1, 1), rng.uniform(-1, 1)]], [rng.uniform(-500, 500)]
        angs = sorted(rng.uniform(0, 2 * math.pi) for _ in range(n))
        gaps = [angs[i] - angs[i - 1] for i in range(1, n)] + [2 * math.pi - angs[-1] + angs[0]]
        if min(gaps) <= 1.2:
            continue
        for k in range(n):
            r, c, s = a[0] + a[k + 1] + 1e-6, math.cos(angs[k]), math.sin(angs[k])
            X.append([r * c, r * s])
            inward, across = rng.uniform(0.2, 1), rng.uniform(-1, 1)
            V.append([-c * inward - s * across, -s * inward + c * across])
            W.append(rng.uniform(-500, 500))
        cs = Contacts(X, V, W, m, a, [(0, k + 1) for k in range(n)])
        if any(v <= 0 for v in cs.approach([0.0] * (2 * n))):
            continue
        e, mu = rng.choice([1.0, 0.9, 0.5]), rng.choice([0.05, 0.1, 0.3, 0.6, 1.0])
        P = joint(cs, e, mu)
        if P is None:
            continue
        solved += 1
        ratio = cs.energy(P) / cs.energy([0.0] * (2 * n))
        if ratio > 1 + 1e-12:
            gains.append((n, e, mu, ratio))
    print(f"{solved} sets solved, {len(gains)} would gain energy")
    for n, e, mu, ratio in gains:
        print(f"  {n} contacts, e_dry = {e}, mu_f = {mu}: T/T0 = {ratio:.4f}")


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--random", type=int, default=0)
    ap.add_argument("--seed", type=int, default=7)
    args = ap.parse_args()
    if args.random:
        random_sets(args.random, args.seed)
        raise SystemExit(0)
    h = 1e-6
    a, m, d = 1e-3, 1e-5, 2e-3 + h
    for e in (1.0, 0.8):  # +-30 degrees
        X = [[-math.sqrt(d * d - d * d / 4), 0.0], [0.0, d / 2], [0.0, -d / 2]]
        cs = Contacts(X, [[1.0, 0.0], [0.0, 0.0], [0.0, 0.0]], [0.0] * 3, [m] * 3, [a] * 3,
                      [(0, 1), (0, 2)])
        report("+-30 deg", cs, e, 0.3)
    A, Ms = [1.0e-3, 1.3e-3, 0.8e-3], [1e-5, 2.2e-5, 0.7e-5]  # unequal
    X = [[0.0, 0.0]] + [[(A[0] + A[k] + h) * math.cos(math.radians(t)),
                         (A[0] + A[k] + h) * math.sin(math.radians(t))]
                        for k, t in ((1, 40.0), (2, -25.0))]
    for mu in (0.3, 0.02):
        cs = Contacts(X, [[1.0, 0.1], [0.0, 0.0], [0.0, 0.0]], [200.0, 0.0, 0.0], Ms, A,
                      [(0, 1), (0, 2)])
        report("unequal", cs, 1.0, mu)
    X, V = [[0.0, 0.0]], [[0.0, 0.0]]  # three contacts
    for k in range(3):
        t = 2 * math.pi * k / 3
        X.append([d * math.cos(t), d * math.sin(t)])
        V.append([-math.cos(t) - 0.4 * math.sin(t), -math.sin(t) + 0.4 * math.cos(t)])
    for mu in (0.3, 0.01):
        cs = Contacts(X, V, [0.0] * 4, [m] * 4, [a] * 4, [(0, 1), (0, 2), (0, 3)])
        report("three contacts", cs, 1.0, mu)
    A, Ms = [0.9e-3, 1.4e-3, 0.7e-3], [1.0e-5, 1.35e-5, 2.3e-5]  # energy would grow
    X = [[0.0, 0.0]] + [[(A[0] + A[k] + h) * math.cos(math.radians(t)),
                         (A[0] + A[k] + h) * math.sin(math.radians(t))]
                        for k, t in ((1, 7.565), (2, -84.21))]
    cs = Contacts(X, [[0.0, -0.85], [-0.35, 0.57], [-1.0, 0.23]], [210.0, 480.0, 130.0], Ms, A,
                  [(0, 1), (0, 2)])
    report("energy would grow (the engine falls back)", cs, 0.9, 1.0)

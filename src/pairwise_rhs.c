/*
 * pairwise_rhs.c — forces and equations of motion of the pairwise engine (Davis 2023 Sec. II):
 *
 * Film forces of pair i-j while the films overlap (0 < h <= delta_ij), Eqs. 3-4:
 *     F_n = 6 pi mu a^2 v_n [1 - h/(2 delta - h)]^2 / h - 8 pi a sigma      [N], > 0 repulsive
 *     F_t = 2 pi mu a v_s ln[(2 delta - h)/h],  v_s = -r Omega + a_i w_i + a_j w_j      [N]
 * a = a_ij reduced radius [m], mu [Pa s], sigma [N/m], v_n > 0 approaching [m/s]. On sphere i
 * the force is -(F_n e_ij + F_t t_ij), on j the opposite; both receive the torque -a F_t.
 * These are the formulas of force_db.c, force_davis.c and force_capillary.c in scalar form;
 * tests/test_pairwise.c compares them with those models at the same state.
 *
 * Relative motion of a tracked pair (i < j), with M = m_i + m_j, m* = m_i m_j / M,
 * Delta = theta_q - theta_ij and, for a neighbour pair q of sphere s, sigma = +1 when q is
 * oriented from s (s = i_q) and -1 otherwise:
 *     N_sq = sigma [F_n,q cos Delta - F_t,q sin Delta]          e_ij . F_sk     (Eq. 6)
 *     T_sq = sigma [F_n,q sin Delta + F_t,q cos Delta]          t_ij . F_sk     (Eq. 11,
 *                                                     sign corrected, see docs/derivations)
 *     m* dv_n/dt = -m* r Omega^2 - F_n - (m_j/M) sum_k N_ik + (m_i/M) sum_l N_jl     (Eq. 9)
 *     m* r dOmega/dt = 2 m* v_n Omega + F_t + (m_j/M) sum_k T_ik - (m_i/M) sum_l T_jl (Eq. 14)
 *     dv_omega/dt = -(a_i^2/I_i + a_j^2/I_j) F_t - (a_i^2/I_i) sum_k F_t,ik
 *                   - (a_j^2/I_j) sum_l F_t,jl                                    (Eq. 17)
 *     dh/dt = -v_n,  dtheta/dt = Omega                                            (Eq. 18)
 * Uniform gravity cancels in the relative equations; it acts on sphere 0 (Eqs. 34-36, 39):
 *     m_0 dv_0/dt = sum_q -(F_n,q e_q + F_t,q t_q) + m_0 g,   I_0 dw_0/dt = -a_0 sum_q F_t,q.
 *
 * Resting contact (an extension, docs/derivations/pairwise.md): a pair held at h = h_min
 * carries an extra normal force lambda (> 0 compressive) chosen so that dv_n/dt = 0 for every
 * held pair; the small linear system A lambda = -b is solved by GSL's LU decomposition.
 * Energy (docs/derivations/pairwise.md Sec. 11): the film forces of pair p do work at the rate
 * -(F_n v_n + F_t v_s) on the two spheres (translation and spin), so with the capillary
 * potential U = 8 pi a sigma (h - delta) <= 0 of each film pair and gravity's -sum m g . x,
 *     d/dt (kinetic + U + gravity) = -sum_p [F_visc,n v_n + F_t v_s] <= 0,
 *     F_visc,n v_n = 6 pi mu a^2 v_n^2 [1 - h/(2 delta - h)]^2 / h,
 *     F_t v_s = 2 pi mu a v_s^2 ln[(2 delta - h)/h];
 * the constraint force of a held pair does no work (v_n = 0).
 * Validity: thin films delta << a, low Reynolds number, motion in a plane.
 */
#include <gsl/gsl_linalg.h>
#include <math.h>
#include <string.h>

#include "pairwise.h"

double wetdem_pairwise_rhs_normal_force(double mu, double sigma, double a, double delta, double h,
                                        double v_n)
{
    double bracket = 1.0 - h / (2.0 * delta - h);
    return 6.0 * M_PI * mu * a * a * v_n * bracket * bracket / h - 8.0 * M_PI * a * sigma;
}

double wetdem_pairwise_rhs_tangential_force(double mu, double a, double delta, double h, double v_s)
{
    return 2.0 * M_PI * mu * a * v_s * log((2.0 * delta - h) / h);
}

/* Film forces (no constraint) of every pair; false if an overlapping pair has h <= 0. */
static bool film_forces(const struct wetdem_pairwise_system* sys,
                        const struct wetdem_pairwise_mode* md, const struct wetdem_pairwise_kin* k,
                        struct wetdem_pairwise_forces* f)
{
    for (size_t p = 0; p < sys->n_pairs; p++) {
        f->f_n[p] = f->f_t[p] = f->lambda[p] = 0.0;
        if (!md->film[p])
            continue;
        double h = k->h[p];
        if (!(h > 0.0))
            return false;
        double v_s = -k->r[p] * k->omega_lc[p] + k->v_w[p];
        f->f_n[p] = wetdem_pairwise_rhs_normal_force(sys->mu, sys->sigma, sys->a_eff[p],
                                                     sys->delta[p], h, k->v_n[p]);
        f->f_t[p] =
            wetdem_pairwise_rhs_tangential_force(sys->mu, sys->a_eff[p], sys->delta[p], h, v_s);
    }
    return true;
}

/* Projections of neighbour pair q's force on sphere s onto pair p's normal and tangent
 * (Eqs. 6 and 11 with the orientation sign): *n_proj = N_sq, *t_proj = T_sq. */
static void neighbour_projection(const struct wetdem_pairwise_system* sys,
                                 const struct wetdem_pairwise_kin* k, double f_n, double f_t,
                                 size_t p, size_t q, size_t s, double* n_proj, double* t_proj)
{
    double sign = (sys->pi[q] == s) ? 1.0 : -1.0;
    double cd = k->c[q] * k->c[p] + k->s[q] * k->s[p]; /* cos(theta_q - theta_p) */
    double sd = k->s[q] * k->c[p] - k->c[q] * k->s[p]; /* sin(theta_q - theta_p) */
    *n_proj = sign * (f_n * cd - f_t * sd);
    *t_proj = sign * (f_n * sd + f_t * cd);
}

/* Eqs. 9 and 14 for any pair p: *dvn = dv_n/dt [m/s^2], *rdom = r dOmega/dt [m/s^2]. */
static void pair_accel(const struct wetdem_pairwise_system* sys,
                       const struct wetdem_pairwise_kin* k, const struct wetdem_pairwise_forces* f,
                       size_t p, double* dvn, double* rdom)
{
    size_t i = sys->pi[p], j = sys->pj[p];
    double mi = sys->m[i], mj = sys->m[j], M = mi + mj, ms = sys->m_eff[p];
    double sn_i = 0.0, st_i = 0.0, sn_j = 0.0, st_j = 0.0;
    for (size_t q = 0; q < sys->n_pairs; q++) {
        if (q == p || (f->f_n[q] == 0.0 && f->f_t[q] == 0.0))
            continue;
        double np, tp;
        if (sys->pi[q] == i || sys->pj[q] == i) {
            neighbour_projection(sys, k, f->f_n[q], f->f_t[q], p, q, i, &np, &tp);
            sn_i += np;
            st_i += tp;
        } else if (sys->pi[q] == j || sys->pj[q] == j) {
            neighbour_projection(sys, k, f->f_n[q], f->f_t[q], p, q, j, &np, &tp);
            sn_j += np;
            st_j += tp;
        }
    }
    double r = k->r[p], om = k->omega_lc[p];
    *dvn = -r * om * om + (-f->f_n[p] - (mj / M) * sn_i + (mi / M) * sn_j) / ms;
    *rdom = 2.0 * k->v_n[p] * om + (f->f_t[p] + (mj / M) * st_i - (mi / M) * st_j) / ms;
}

/* Eq. 17 divided by I_i I_j: dv_omega/dt of pair p [m/s^2]. */
static double spin_accel(const struct wetdem_pairwise_system* sys,
                         const struct wetdem_pairwise_forces* f, size_t p)
{
    size_t i = sys->pi[p], j = sys->pj[p];
    double ci = sys->a[i] * sys->a[i] / sys->inertia[i];
    double cj = sys->a[j] * sys->a[j] / sys->inertia[j];
    double sum_i = 0.0, sum_j = 0.0;
    for (size_t q = 0; q < sys->n_pairs; q++) {
        if (q == p || f->f_t[q] == 0.0)
            continue;
        if (sys->pi[q] == i || sys->pj[q] == i)
            sum_i += f->f_t[q];
        else if (sys->pi[q] == j || sys->pj[q] == j)
            sum_j += f->f_t[q];
    }
    return -(ci + cj) * f->f_t[p] - ci * sum_i - cj * sum_j;
}

double wetdem_pairwise_rhs_coupling(const struct wetdem_pairwise_system* sys,
                                    const struct wetdem_pairwise_kin* k, size_t p, size_t q)
{
    if (p == q)
        return -1.0 / sys->m_eff[p];
    size_t i = sys->pi[p], j = sys->pj[p];
    double np, tp;
    if (sys->pi[q] == i || sys->pj[q] == i) {
        neighbour_projection(sys, k, 1.0, 0.0, p, q, i, &np, &tp);
        return -np / sys->m[i];
    }
    if (sys->pi[q] == j || sys->pj[q] == j) {
        neighbour_projection(sys, k, 1.0, 0.0, p, q, j, &np, &tp);
        return np / sys->m[j];
    }
    return 0.0;
}

bool wetdem_pairwise_rhs_solve(size_t n, double* a, size_t tda, double* b)
{
    if (n == 0)
        return true;
    if (n > PW_SOLVE_MAX)
        return false;
    gsl_matrix_view m = gsl_matrix_view_array_with_tda(a, n, n, tda);
    size_t perm[PW_SOLVE_MAX];
    gsl_permutation p = {n, perm};
    int sign;
    /* no GSL error path is reached: the sizes agree, and a singular matrix is caught here
       before gsl_linalg_LU_svx would report it */
    gsl_linalg_LU_decomp(&m.matrix, &p, &sign);
    for (size_t c = 0; c < n; c++)
        if (!(fabs(a[c * tda + c]) > 0.0))
            return false;
    gsl_vector_view x = gsl_vector_view_array(b, n);
    gsl_linalg_LU_svx(&m.matrix, &p, &x.vector);
    return true;
}

/* Constraint forces of the resting pairs: dv_n/dt = 0 for each; the solve yields each held
 * pair's net normal force N = F_n + lambda (docs/derivations/pairwise.md Sec. 7).
 * The film force of a held pair is its capillary pull -8 pi a sigma (v_n = 0), and the contact
 * force lambda cancels it but for what the net force needs (centripetal, the neighbours').
 * Formed as F_n + lambda, N would carry a rounding of DBL_EPSILON 8 pi a sigma, an
 * acceleration of DBL_EPSILON 8 pi a sigma / m* that grows as 1 / (Ca St_n): at Ca = 0.01 and
 * St_n = 1e-6 ~2e-3 m/s^2 against a net ~0 and CVODE's velocity tolerance of 1e-9 m/s, which
 * limited the steps of a held cluster to ~1e-6 s (50 000 steps a run, 880 000 at
 * St_n = 1e-7), failed the Newton iteration every tenth step on a Jacobian whose difference
 * quotients were that rounding, and let the pair that is not tracked (its v_n = 0 held only at
 * the acceleration level) drift from h_min by a random walk of it (the capillary energy
 * 8 pi a sigma (h - h_min) came out of the budget: residuals of 6.5e-4 to 1.7e-2 of the
 * largest term). So the held pairs' normal forces are left out of the right-hand side b, the
 * solve yields N itself, free of the pull, and lambda (the release guard) is N - F_n. */
static bool constraint_forces(const struct wetdem_pairwise_system* sys,
                              const struct wetdem_pairwise_mode* md,
                              const struct wetdem_pairwise_kin* k, struct wetdem_pairwise_forces* f)
{
    size_t rest[PW_PMAX], n = 0;
    for (size_t p = 0; p < sys->n_pairs; p++)
        if (md->resting[p])
            rest[n++] = p;
    if (n == 0)
        return true;
    double A[PW_PMAX][PW_PMAX], b[PW_PMAX], film_n[PW_PMAX];
    for (size_t a = 0; a < n; a++) {
        film_n[a] = f->f_n[rest[a]];
        f->f_n[rest[a]] = 0.0;
    }
    for (size_t a = 0; a < n; a++) {
        double dvn, rdom;
        pair_accel(sys, k, f, rest[a], &dvn, &rdom);
        b[a] = -dvn;
        if (md->edge_of_pair[rest[a]] < 0) { /* closed loop: gap from geometry, see above */
            double al = sys->hold_rate;
            b[a] += al * al * (k->h[rest[a]] - sys->h_min) - 2.0 * al * k->v_n[rest[a]];
        }
        for (size_t c = 0; c < n; c++)
            A[a][c] = wetdem_pairwise_rhs_coupling(sys, k, rest[a], rest[c]);
    }
    if (!wetdem_pairwise_rhs_solve(n, &A[0][0], PW_PMAX, b))
        return false;
    for (size_t a = 0; a < n; a++) {
        f->lambda[rest[a]] = b[a] - film_n[a];
        f->f_n[rest[a]] = b[a];
    }
    return true;
}

bool wetdem_pairwise_rhs_forces(const struct wetdem_pairwise_system* sys,
                                const struct wetdem_pairwise_mode* md,
                                const struct wetdem_pairwise_kin* k,
                                struct wetdem_pairwise_forces* f)
{
    return film_forces(sys, md, k, f) && constraint_forces(sys, md, k, f);
}

/* Is `mask` (bit a = cand[a]) a solution of the contact problem: lambda >= 0 on the held
 * pairs and no approaching acceleration on the others? Writes lambda into lam. */
static bool hold_valid(size_t m, double A[PW_PMAX][PW_PMAX], const double* b, unsigned long mask,
                       double scale, double* lam)
{
    size_t idx[PW_PMAX], n = 0;
    double M[PW_PMAX][PW_PMAX], x[PW_PMAX];
    for (size_t a = 0; a < m; a++)
        if (mask >> a & 1UL)
            idx[n++] = a;
    for (size_t a = 0; a < n; a++) {
        x[a] = -b[idx[a]];
        for (size_t c = 0; c < n; c++)
            M[a][c] = A[idx[a]][idx[c]];
    }
    if (n > 0 && !wetdem_pairwise_rhs_solve(n, &M[0][0], PW_PMAX, x))
        return false;
    for (size_t a = 0; a < m; a++)
        lam[a] = 0.0;
    for (size_t a = 0; a < n; a++) {
        if (x[a] < 0.0)
            return false;
        lam[idx[a]] = x[a];
    }
    for (size_t a = 0; a < m; a++) { /* dv_n/dt <= 0 (not approaching) where not held */
        if (mask >> a & 1UL)
            continue;
        double acc = b[a];
        for (size_t c = 0; c < m; c++)
            acc += A[a][c] * lam[c];
        if (acc > 1e-12 * scale)
            return false;
    }
    return true;
}

bool wetdem_pairwise_rhs_hold_set(const struct wetdem_pairwise_system* sys,
                                  const struct wetdem_pairwise_mode* md,
                                  const struct wetdem_pairwise_kin* k, const bool* cand, bool* hold)
{
    struct wetdem_pairwise_mode free_md = *md;
    struct wetdem_pairwise_forces f;
    size_t list[PW_PMAX], m = 0;
    for (size_t p = 0; p < sys->n_pairs; p++) {
        free_md.resting[p] = false;
        hold[p] = false;
        if (cand[p])
            list[m++] = p;
    }
    if (m == 0)
        return true;
    if (m > 16 || !wetdem_pairwise_rhs_forces(sys, &free_md, k, &f))
        return false;
    double A[PW_PMAX][PW_PMAX], b[PW_PMAX], lam[PW_PMAX], scale = 0.0;
    for (size_t a = 0; a < m; a++) {
        double rdom;
        pair_accel(sys, k, &f, list[a], &b[a], &rdom);
        scale = fmax(scale, fabs(b[a]));
        for (size_t c = 0; c < m; c++)
            A[a][c] = wetdem_pairwise_rhs_coupling(sys, k, list[a], list[c]);
    }
    /* enumeration, largest held sets first: unique solution for this positive definite
     * problem; at most 2^16 subsets (never more than a few in practice) */
    for (unsigned long mask = (1UL << m); mask-- > 0;)
        if (hold_valid(m, A, b, mask, scale, lam)) {
            for (size_t a = 0; a < m; a++)
                hold[list[a]] = mask >> a & 1UL;
            return true;
        }
    return false;
}

/* Eqs. 34-36, 39 for sphere 0. */
static void anchor_rhs(const struct wetdem_pairwise_system* sys,
                       const struct wetdem_pairwise_kin* k, const struct wetdem_pairwise_forces* f,
                       const double* y, double* dydt)
{
    double fx = 0.0, fy = 0.0, torque = 0.0;
    for (size_t q = 0; q + 1 < sys->n; q++) { /* pairs (0, j) come first */
        fx += -f->f_n[q] * k->c[q] + f->f_t[q] * k->s[q];
        fy += -f->f_n[q] * k->s[q] - f->f_t[q] * k->c[q];
        torque += -sys->a[0] * f->f_t[q];
    }
    dydt[0] = y[2];
    dydt[1] = y[3];
    dydt[2] = fx / sys->m[0] + sys->gx;
    dydt[3] = fy / sys->m[0] + sys->gy;
    dydt[4] = torque / sys->inertia[0];
}

bool wetdem_pairwise_rhs_eval(const struct wetdem_pairwise_system* sys,
                              const struct wetdem_pairwise_mode* md, const double* y, double* dydt)
{
    struct wetdem_pairwise_kin k;
    struct wetdem_pairwise_forces f;
    if (!wetdem_pairwise_state_kin(sys, md, y, &k) || !wetdem_pairwise_rhs_forces(sys, md, &k, &f))
        return false;
    anchor_rhs(sys, &k, &f, y, dydt);
    for (size_t e = 0; e + 1 < sys->n; e++) {
        size_t p = md->edge[e];
        const double* v = y + PW_ANCHOR_LEN + PW_EDGE_LEN * e;
        double* d = dydt + PW_ANCHOR_LEN + PW_EDGE_LEN * e;
        double dvn, rdom;
        pair_accel(sys, &k, &f, p, &dvn, &rdom);
        d[PW_H] = -v[PW_VN];
        d[PW_THETA] = v[PW_OMEGA];
        d[PW_VN] = md->resting[p] ? 0.0 : dvn;
        d[PW_OMEGA] = rdom / k.r[p];
        d[PW_VW] = spin_accel(sys, &f, p);
    }
    for (size_t a = 0; a < PW_YMAX; a++)
        if (a < 5 * sys->n && !isfinite(dydt[a]))
            return false;
    return true;
}

void wetdem_pairwise_rhs_energy(const struct wetdem_pairwise_system* sys,
                                const struct wetdem_pairwise_mode* md,
                                const struct wetdem_pairwise_kin* k, double* kinetic,
                                double* capillary, double* gravity)
{
    double ke = 0.0, u_c = 0.0, u_g = 0.0;
    for (size_t i = 0; i < sys->n; i++) {
        ke += 0.5 * sys->m[i] * (k->vx[i] * k->vx[i] + k->vy[i] * k->vy[i]) +
              0.5 * sys->inertia[i] * k->w[i] * k->w[i];
        u_g -= sys->m[i] * (sys->gx * k->x[i] + sys->gy * k->y[i]);
    }
    for (size_t p = 0; p < sys->n_pairs; p++)
        if (md->film[p])
            u_c += 8.0 * M_PI * sys->a_eff[p] * sys->sigma * (k->h[p] - sys->delta[p]);
    *kinetic = ke;
    *capillary = u_c;
    *gravity = u_g;
}

void wetdem_pairwise_rhs_dissipation(const struct wetdem_pairwise_system* sys,
                                     const struct wetdem_pairwise_mode* md,
                                     const struct wetdem_pairwise_kin* k, double* normal,
                                     double* tangential)
{
    double pn = 0.0, pt = 0.0;
    for (size_t p = 0; p < sys->n_pairs; p++) {
        if (!md->film[p])
            continue;
        double h = k->h[p], v_n = k->v_n[p], v_s = -k->r[p] * k->omega_lc[p] + k->v_w[p];
        pn += v_n *
              wetdem_pairwise_rhs_normal_force(sys->mu, 0.0, sys->a_eff[p], sys->delta[p], h, v_n);
        pt += v_s *
              wetdem_pairwise_rhs_tangential_force(sys->mu, sys->a_eff[p], sys->delta[p], h, v_s);
    }
    *normal = pn;
    *tangential = pt;
}

/*
 * pairwise_jump.c — hard-sphere contact in the pairwise engine (Davis 2023 Appendix A).
 *
 * When the gap of pair i-j reaches h_min while approaching, the impulse is computed in
 * Cartesian vector form by wetdem_hard_impulse() (src/hard.c: A1-A3 normal reversal with
 * e_dry, A8-A11 sliding friction mu_f, A30-A36 arrest of slip). The velocity and spin jumps
 * of spheres i and j are then projected on every tracked pair:
 *     dv_n = e_q . (dv_a - dv_b),  dv_t = t_q . (dv_a - dv_b),  dOmega = -dv_t / r_q,
 *     dv_omega = a_a dw_a + a_b dw_b                        for tracked pair q = (a, b),
 * which is Appendix A's A5-A14 for the neighbours without writing them out. Only the jumps
 * are added, so the small relative variables keep their precision.
 *
 * The explicit scalar formulas are kept here too, corrected (docs/derivations/pairwise.md),
 * so that tests can compare them with the vector route. With the normal impulse
 * I_n = m_ij (1 + e_dry) v_ij,n (A3) and the tangential impulse I_t = q I_n acting on j along
 * t_ij (q = +-mu_f sliding, A8; q = I_t,stick / I_n when sliding is arrested, A33, A36):
 *   own pair:   v_n' = -e v_n (A1), Omega' = Omega + I_t/(m_ij r) (A10, A31),
 *               v_omega' = v_omega - (a_i^2/I_i + a_j^2/I_j) I_t (A11, A32),
 *               I_t,stick = v_s / (1/m_ij + a_i^2/I_i + a_j^2/I_j) (= 2 m_ij v_s / 7, A33)
 *   neighbour j-k, X = (m_ij/m_j)(1 + e) v_ij,n, D = theta_jk - theta_ij:
 *               dv_jk,n = X [cos D + q sin D]                          (A6, A13)
 *               dv_jk,t = -X [sin D - q cos D]   (A7 has the sign wrong; A14 is right)
 *               dOmega_jk = X [sin D - q cos D] / r_jk                 (A12)
 * Resting contact (plastic): a contact slower than the rest speed stops the normal relative
 * velocity of the new pair and of every slow pair touching at h_min together (simultaneous
 * normal impulses from one small linear system), with no tangential impulse (its size
 * mu_f I_n vanishes with the contact speed); which pairs then stay held is decided at the
 * force level (wetdem_pairwise_rhs_hold_set).
 * Simultaneous contacts without friction, or with friction when none of them slips: the pairs
 * met at one instant get their normal impulses together, sum_q coupling(p, q) J_q =
 * -(1 + e_dry) v_n,p, so that every v_n of the set is reversed to -e_dry v_n at once (Newton's
 * rule for each contact of a multiple collision); applied only when every J_q > 0 (else the
 * engine resolves them one by one).
 */
#include <math.h>

#include "pairwise.h"

void wetdem_pairwise_jump_neighbour(double v_n_b, double theta_ij, double theta_jk, double r_jk,
                                    double m_ij, double m_j, double q, double e_dry, double* dv_n,
                                    double* dv_t, double* d_omega)
{
    double x = (m_ij / m_j) * (1.0 + e_dry) * v_n_b;
    double d = theta_jk - theta_ij;
    *dv_n = x * (cos(d) + q * sin(d));
    *dv_t = -x * (sin(d) - q * cos(d));
    *d_omega = x * (sin(d) - q * cos(d)) / r_jk;
}

bool wetdem_pairwise_jump_own(double v_n, double omega_lc, double v_w, double r, double a_i,
                              double a_j, double m_i, double m_j, double e_dry, double mu_f,
                              double* v_n_a, double* omega_lc_a, double* v_w_a, double* q)
{
    double m_ij = m_i * m_j / (m_i + m_j);
    double rot = a_i * a_i / (0.4 * m_i * a_i * a_i) + a_j * a_j / (0.4 * m_j * a_j * a_j);
    double i_n = m_ij * (1.0 + e_dry) * v_n;     /* A3 */
    double v_s = -r * omega_lc + v_w;            /* slip at contact */
    double i_stick = v_s / (1.0 / m_ij + rot);   /* A33 */
    bool sticking = fabs(i_stick) <= mu_f * i_n; /* A36 */
    double i_t = sticking ? i_stick : (v_s > 0.0 ? 1.0 : (v_s < 0.0 ? -1.0 : 0.0)) * mu_f * i_n;
    *v_n_a = -e_dry * v_n;                     /* A1 */
    *omega_lc_a = omega_lc + i_t / (m_ij * r); /* A10, A31 */
    *v_w_a = v_w - rot * i_t;                  /* A11, A32 */
    *q = i_n > 0.0 ? i_t / i_n : 0.0;
    return sticking;
}

/* Velocity and spin jumps of spheres i and j of pair p from wetdem_hard_impulse() [m/s, rad/s]. */
static int impulse_deltas(const struct wetdem_pairwise_system* sys, size_t p,
                          const struct wetdem_pairwise_kin* k, double dv[2][2], double dw[2])
{
    size_t s[2] = {sys->pi[p], sys->pj[p]};
    /* normal from j to i: -e_ij */
    struct wetdem_vec3 n = {-k->c[p], -k->s[p], 0.0};
    struct wetdem_impulse_body body[2];
    for (int b = 0; b < 2; b++)
        body[b] = (struct wetdem_impulse_body){
            .vel = {k->vx[s[b]], k->vy[s[b]], 0.0},
            .omega = {0.0, 0.0, k->w[s[b]]},
            .mass = sys->m[s[b]],
            .radius = sys->a[s[b]],
            .inertia = sys->inertia[s[b]],
        };
    struct wetdem_impulse_result res;
    int st = wetdem_hard_impulse(&body[0], &body[1], n, sys->e_dry, sys->mu_f, &res);
    if (st != WETDEM_OK)
        return st;
    for (int b = 0; b < 2; b++) {
        dv[b][0] = body[b].vel.x - k->vx[s[b]];
        dv[b][1] = body[b].vel.y - k->vy[s[b]];
        dw[b] = body[b].omega.z - k->w[s[b]];
    }
    return WETDEM_OK;
}

/* Adds sphere jumps (gvx, gvy [m/s], gw [rad/s] per sphere) to sphere 0 and every tracked
 * pair of y: dv_n = e . dv_rel, dOmega = -t . dv_rel / r, dv_omega = a_a dw_a + a_b dw_b. */
static void add_jumps(const struct wetdem_pairwise_system* sys,
                      const struct wetdem_pairwise_mode* md, const struct wetdem_pairwise_kin* k,
                      const double* gvx, const double* gvy, const double* gw, double* y)
{
    y[2] += gvx[0];
    y[3] += gvy[0];
    y[4] += gw[0];
    for (size_t e = 0; e + 1 < sys->n; e++) {
        size_t q = md->edge[e], a = sys->pi[q], b = sys->pj[q];
        double rx = gvx[a] - gvx[b], ry = gvy[a] - gvy[b];
        if (rx == 0.0 && ry == 0.0 && gw[a] == 0.0 && gw[b] == 0.0)
            continue;
        double* v = y + PW_ANCHOR_LEN + PW_EDGE_LEN * e;
        double dv_t = -k->s[q] * rx + k->c[q] * ry;
        v[PW_VN] += k->c[q] * rx + k->s[q] * ry;
        v[PW_OMEGA] += -dv_t / k->r[q];
        v[PW_VW] += sys->a[a] * gw[a] + sys->a[b] * gw[b];
    }
}

int wetdem_pairwise_jump_apply(const struct wetdem_pairwise_system* sys,
                               const struct wetdem_pairwise_mode* md, size_t p,
                               struct wetdem_pairwise_kin* k, double* y)
{
    double dv[2][2], dw[2];
    int st = impulse_deltas(sys, p, k, dv, dw);
    if (st != WETDEM_OK)
        return st;
    size_t s[2] = {sys->pi[p], sys->pj[p]};
    double gvx[PW_NMAX] = {0}, gvy[PW_NMAX] = {0}, gw[PW_NMAX] = {0};
    for (int b = 0; b < 2; b++) {
        gvx[s[b]] = dv[b][0];
        gvy[s[b]] = dv[b][1];
        gw[s[b]] = dw[b];
    }
    add_jumps(sys, md, k, gvx, gvy, gw, y);
    return WETDEM_OK;
}

/* The pairs of `set` into list; their number. */
static size_t set_list(const struct wetdem_pairwise_system* sys, const bool* set, size_t* list)
{
    size_t n = 0;
    for (size_t p = 0; p < sys->n_pairs; p++)
        if (set[p])
            list[n++] = p;
    return n;
}

/* Normal impulses J of the pairs in list[0..n) that change each v_n by -factor v_n (factor 1:
 * to zero, plastic; 1 + e_dry: reversed to -e_dry v_n); false if singular. J > 0 pushes the
 * pair apart (coupling(p, p) = -1/m*). */
static bool normal_solve(const struct wetdem_pairwise_system* sys,
                         const struct wetdem_pairwise_kin* k, const size_t* list, size_t n,
                         double factor, double* J)
{
    double A[PW_PMAX][PW_PMAX];
    for (size_t a = 0; a < n; a++) {
        J[a] = -factor * k->v_n[list[a]];
        for (size_t c = 0; c < n; c++)
            A[a][c] = wetdem_pairwise_rhs_coupling(sys, k, list[a], list[c]);
    }
    return wetdem_pairwise_rhs_solve(n, A, J);
}

/* Adds to y the velocity jumps of the normal impulses J of the pairs in list[0..n): on i
 * -J e_ij / m_i, on j +J e_ij / m_j. */
static void apply_normal_impulses(const struct wetdem_pairwise_system* sys,
                                  const struct wetdem_pairwise_mode* md,
                                  const struct wetdem_pairwise_kin* k, const size_t* list, size_t n,
                                  const double* J, double* y)
{
    double gvx[PW_NMAX] = {0}, gvy[PW_NMAX] = {0}, gw[PW_NMAX] = {0};
    for (size_t a = 0; a < n; a++) {
        size_t q = list[a], i = sys->pi[q], j = sys->pj[q];
        gvx[i] -= J[a] * k->c[q] / sys->m[i];
        gvy[i] -= J[a] * k->s[q] / sys->m[i];
        gvx[j] += J[a] * k->c[q] / sys->m[j];
        gvy[j] += J[a] * k->s[q] / sys->m[j];
    }
    add_jumps(sys, md, k, gvx, gvy, gw, y);
}

bool wetdem_pairwise_jump_simultaneous(const struct wetdem_pairwise_system* sys,
                                       const struct wetdem_pairwise_mode* md,
                                       const struct wetdem_pairwise_kin* k, const bool* set,
                                       double* y)
{
    size_t list[PW_PMAX] = {0}; /* (filled by set_list; zeroed for the compiler's flow analysis) */
    size_t n = set_list(sys, set, list);
    double J[PW_PMAX];
    if (!normal_solve(sys, k, list, n, 1.0 + sys->e_dry, J))
        return false;
    for (size_t a = 0; a < n; a++)
        if (!(J[a] > 0.0))
            return false;
    apply_normal_impulses(sys, md, k, list, n, J, y);
    return true;
}

bool wetdem_pairwise_jump_plastic(const struct wetdem_pairwise_system* sys,
                                  const struct wetdem_pairwise_mode* md,
                                  const struct wetdem_pairwise_kin* k, const bool* set, double* y)
{
    size_t list[PW_PMAX] = {0}; /* (filled by set_list; zeroed for the compiler's flow analysis) */
    size_t n = set_list(sys, set, list);
    double J[PW_PMAX];
    if (!normal_solve(sys, k, list, n, 1.0, J))
        return false;
    apply_normal_impulses(sys, md, k, list, n, J, y);
    for (size_t a = 0; a < n; a++) {
        int e = md->edge_of_pair[list[a]];
        if (e >= 0)
            y[PW_ANCHOR_LEN + PW_EDGE_LEN * (size_t)e + PW_VN] = 0.0;
    }
    return true;
}

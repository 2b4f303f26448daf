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
 * Simultaneous contacts with friction that slip (docs/derivations/pairwise.md Sec. 6): with the
 * impulses P = (J_n,q, J_t,q) of the set, the kinetic energy after is T0 + g.P + P.H.P / 2
 * (g: the contact velocities -v_n and v_s; H: mass-weighted products of the velocity and spin
 * changes of unit impulses, the vector-form application above). Compression: every v_n to
 * zero, P of least T in the friction cone |J_t| <= mu_f J_n (Coulomb friction as maximal
 * dissipation); restitution: J_n,q grows by e_dry J_n,q (Poisson), the J_t,q by d_q of least T
 * with |d_q| <= mu_f e_dry J_n,q. For one contact this is Davis's A1-A3, A8 and A30-A36: stick
 * with I_t = m_t v_s (A33) if that is at most mu_f I_n, else slide at mu_f I_n.
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
    return wetdem_pairwise_rhs_solve(n, &A[0][0], PW_PMAX, J);
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

/* ---------------------------------------- simultaneous contacts with friction (Sec. 6) ---- */

/* Largest frictional set solved jointly: 3^6 = 729 faces of the friction cone per phase. */
#define FR_MAX 6
#define FR_DIM (2 * FR_MAX)
#define FR_KKT (3 * FR_MAX)
_Static_assert(FR_KKT <= PW_SOLVE_MAX, "the KKT system fits the solver");

/* Impulse space of a frictional set of n contacts: component a < n is the normal impulse J_n
 * of contact list[a] on its sphere i along n = -e_ij (J_n > 0 pushes the pair apart), component
 * n + a its tangential impulse J_t on i along t_ij = (-sin theta, cos theta); j receives the
 * opposite. H is the kinetic energy's Hessian and g its gradient at P = 0, so that the kinetic
 * energy after the impulses P is T0 + g.P + P.H.P / 2. */
struct fr_problem {
    size_t n, list[FR_MAX];
    double H[FR_DIM][FR_DIM], g[FR_DIM];
    double mu, e;
};

/* Sphere velocity and spin changes (dvx, dvy, dw per sphere) of unit impulse component c. */
static void fr_unit(const struct wetdem_pairwise_system* sys, const struct wetdem_pairwise_kin* k,
                    const struct fr_problem* fp, size_t c, double dv[PW_NMAX][3])
{
    for (size_t s = 0; s < sys->n; s++)
        dv[s][0] = dv[s][1] = dv[s][2] = 0.0;
    size_t q = fp->list[c % fp->n], i = sys->pi[q], j = sys->pj[q];
    bool normal = c < fp->n;
    /* impulse on i: n = (-c, -s) for J_n, t = (-s, c) for J_t */
    double px = normal ? -k->c[q] : -k->s[q], py = normal ? -k->s[q] : k->c[q];
    dv[i][0] = px / sys->m[i];
    dv[i][1] = py / sys->m[i];
    dv[j][0] = -px / sys->m[j];
    dv[j][1] = -py / sys->m[j];
    if (!normal) { /* (-a_i n) x t and (a_j n) x (-t) both have z component +a (n = -e) */
        dv[i][2] = sys->a[i] / sys->inertia[i];
        dv[j][2] = sys->a[j] / sys->inertia[j];
    }
}

/* H from the unit impulses' velocity changes (mass-weighted inner products); g from the contact
 * velocities: dT/dJ_n = -v_n, dT/dJ_t = v_s = -r Omega + v_omega (the slip along t_ij). */
static void fr_setup(const struct wetdem_pairwise_system* sys, const struct wetdem_pairwise_kin* k,
                     struct fr_problem* fp)
{
    size_t m = 2 * fp->n;
    double u[FR_DIM][PW_NMAX][3];
    for (size_t c = 0; c < m; c++)
        fr_unit(sys, k, fp, c, u[c]);
    for (size_t r = 0; r < m; r++)
        for (size_t c = 0; c < m; c++) {
            double h = 0.0;
            for (size_t s = 0; s < sys->n; s++)
                h += sys->m[s] * (u[r][s][0] * u[c][s][0] + u[r][s][1] * u[c][s][1]) +
                     sys->inertia[s] * u[r][s][2] * u[c][s][2];
            fp->H[r][c] = h;
        }
    for (size_t a = 0; a < fp->n; a++) {
        size_t q = fp->list[a];
        fp->g[a] = -k->v_n[q];
        fp->g[fp->n + a] = -k->r[q] * k->omega_lc[q] + k->v_w[q];
    }
}

/* Kinetic energy change g.P + P.H.P / 2 of impulses P [J]. */
static double fr_energy(const struct fr_problem* fp, const double* P)
{
    size_t m = 2 * fp->n;
    double d = 0.0;
    for (size_t r = 0; r < m; r++) {
        double hp = 0.0;
        for (size_t c = 0; c < m; c++)
            hp += fp->H[r][c] * P[c];
        d += P[r] * (fp->g[r] + 0.5 * hp);
    }
    return d;
}

/* Minimiser of the kinetic energy over P = P0 + B z (B: m x nz, its columns in B[.][col]),
 * with every v_n after brought to zero if plastic: dT/dJ_n = -v_n' = (g + H P)_a = 0 for
 * a < n. Lagrange's conditions, multipliers l:
 *     (B^T H B) z + (H_N B)^T l = -B^T (g + H P0),   (H_N B) z = -(g + H P0)_N.
 * Writes P; false if singular. */
static bool fr_minimise(const struct fr_problem* fp, const double* P0, double B[FR_DIM][FR_DIM],
                        size_t nz, bool plastic, double* P)
{
    size_t m = 2 * fp->n, nc = plastic ? fp->n : 0;
    double grad[FR_DIM], HB[FR_DIM][FR_DIM], A[FR_KKT][FR_KKT], z[FR_KKT];
    for (size_t r = 0; r < m; r++) {
        grad[r] = fp->g[r];
        for (size_t c = 0; c < m; c++)
            grad[r] += fp->H[r][c] * P0[c];
        for (size_t b = 0; b < nz; b++) {
            HB[r][b] = 0.0;
            for (size_t c = 0; c < m; c++)
                HB[r][b] += fp->H[r][c] * B[c][b];
        }
    }
    for (size_t a = 0; a < nz; a++) {
        z[a] = 0.0;
        for (size_t r = 0; r < m; r++)
            z[a] -= B[r][a] * grad[r];
        for (size_t b = 0; b < nz; b++) {
            A[a][b] = 0.0;
            for (size_t r = 0; r < m; r++)
                A[a][b] += B[r][a] * HB[r][b];
        }
    }
    for (size_t l = 0; l < nc; l++) { /* H_N B = (B^T H)_N, H symmetric */
        z[nz + l] = -grad[l];
        for (size_t b = 0; b < nz; b++)
            A[nz + l][b] = A[b][nz + l] = HB[l][b];
        for (size_t l2 = 0; l2 < nc; l2++)
            A[nz + l][nz + l2] = 0.0;
    }
    if (nz + nc > 0 && !wetdem_pairwise_rhs_solve(nz + nc, &A[0][0], FR_KKT, z))
        return false;
    for (size_t r = 0; r < m; r++) {
        P[r] = P0[r];
        for (size_t b = 0; b < nz; b++)
            P[r] += B[r][b] * z[b];
    }
    return true;
}

/* Relative slack of the friction cone |dJ_t| <= mu J_n accepted as rounding: a face's minimiser
 * comes from at most 18 linear equations in impulses of one scale, whose rounding is some
 * 1e-16 times their condition number; 1e-9 lies far above that for contacts that are not
 * nearly parallel, and changes a velocity by 1e-9 of mu_f v_n, what the integration resolves
 * at the default rtol. A face minimiser let in by the slack lies on the cone's boundary but
 * for rounding, where the neighbouring face's minimiser gives the same point. */
#define FR_CONE_SLACK 1e-9

/* The minimiser of the kinetic energy over the faces of the friction cone: phase 1
 * (compression, restitution == false) over all P that bring every v_n to zero with
 * |J_t| <= mu J_n and J_n > 0; phase 2 (restitution) over J_t = J_t1 + d with
 * J_n = (1 + e) J_n1 and |d| <= mu e J_n1. A face fixes each contact's mode: free (its
 * components vary), or sliding with J_t (phase 1) or d (phase 2) at -s mu times its normal
 * impulse, s = +-1. The least energy among the faces' minimisers that lie in the cone is the
 * minimum over the cone (the energy is strictly convex, the conditions linear). False if no
 * face has one (a J_n1 <= 0: a contact of the set would pull). */
static bool fr_phase(const struct fr_problem* fp, const double* P1, bool restitution, double* P)
{
    size_t n = fp->n, m = 2 * n, faces = 1;
    for (size_t a = 0; a < n; a++)
        faces *= 3;
    double best = INFINITY;
    for (size_t f = 0; f < faces; f++) {
        double B[FR_DIM][FR_DIM] = {{0}}, P0[FR_DIM] = {0}, Pf[FR_DIM];
        size_t nz = 0, code = f;
        for (size_t a = 0; a < n; a++, code /= 3) {
            size_t mode = code % 3; /* 0 free, 1 slide with s = +1, 2 with s = -1 */
            double s = mode == 1 ? 1.0 : -1.0;
            if (restitution) {
                P0[a] = (1.0 + fp->e) * P1[a];
                P0[n + a] = P1[n + a] - (mode ? s * fp->mu * fp->e * P1[a] : 0.0);
                if (!mode)
                    B[n + a][nz++] = 1.0;
            } else {
                B[a][nz] = 1.0; /* J_n */
                if (mode) {
                    B[n + a][nz++] = -s * fp->mu; /* J_t = -s mu J_n */
                } else {
                    nz++;
                    B[n + a][nz++] = 1.0; /* J_t */
                }
            }
        }
        if (!fr_minimise(fp, P0, B, nz, !restitution, Pf))
            continue;
        bool inside = true;
        for (size_t a = 0; a < n && inside; a++) {
            double jn = restitution ? fp->e * P1[a] : Pf[a];
            double jt = restitution ? Pf[n + a] - P1[n + a] : Pf[n + a];
            inside = jn > 0.0 && fabs(jt) <= fp->mu * jn * (1.0 + FR_CONE_SLACK);
        }
        double dT = inside ? fr_energy(fp, Pf) : INFINITY;
        if (dT < best) {
            best = dT;
            for (size_t r = 0; r < m; r++)
                P[r] = Pf[r];
        }
    }
    return best < INFINITY;
}

bool wetdem_pairwise_jump_simultaneous_friction(const struct wetdem_pairwise_system* sys,
                                                const struct wetdem_pairwise_mode* md,
                                                const struct wetdem_pairwise_kin* k,
                                                const bool* set, double* y)
{
    struct fr_problem fp = {.mu = sys->mu_f, .e = sys->e_dry};
    size_t list[PW_PMAX] = {0}; /* (filled by set_list; zeroed for the compiler's flow analysis) */
    fp.n = set_list(sys, set, list);
    if (fp.n < 1 || fp.n > FR_MAX || !(fp.mu > 0.0))
        return false;
    for (size_t a = 0; a < fp.n; a++)
        fp.list[a] = list[a];
    fr_setup(sys, k, &fp);
    double P1[FR_DIM], P[FR_DIM];
    if (!fr_phase(&fp, NULL, false, P1) || !fr_phase(&fp, P1, true, P))
        return false;
    /* energy not increased (e_dry <= 1), to the rounding of the impulses' work */
    double work = 0.0;
    for (size_t r = 0; r < 2 * fp.n; r++)
        work += fabs(fp.g[r] * P[r]);
    if (!(fr_energy(&fp, P) <= 1e-12 * work))
        return false;
    double gvx[PW_NMAX] = {0}, gvy[PW_NMAX] = {0}, gw[PW_NMAX] = {0};
    for (size_t c = 0; c < 2 * fp.n; c++) {
        double u[PW_NMAX][3];
        fr_unit(sys, k, &fp, c, u);
        for (size_t s = 0; s < sys->n; s++) {
            gvx[s] += P[c] * u[s][0];
            gvy[s] += P[c] * u[s][1];
            gw[s] += P[c] * u[s][2];
        }
    }
    add_jumps(sys, md, k, gvx, gvy, gw, y);
    return true;
}

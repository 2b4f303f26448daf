/*
 * pairwise.h — internals of the pairwise engine (Davis 2023 Sec. II, Appendices A-B),
 * shared by pairwise.c (driver, public API), pairwise_state.c (tracked-pair tree, state <->
 * sphere conversion, Appendix B geometry), pairwise_rhs.c (film forces Eqs. 3-4, relative
 * equations of motion Eqs. 9, 14, 17, 18, sphere 0 Eqs. 34-36, 39, resting-contact
 * constraint), pairwise_jump.c (hard-sphere impulse and the explicit jumps A6-A14, A33-A35)
 * and pairwise_davis.c (Table-I configuration). SI units throughout.
 *
 * State vector y (length 5 n): y[0..4] = x_0, y_0, vx_0, vy_0, omega_0 of sphere 0 (the
 * anchor, Eqs. 34-36, 39); then for tracked edge e = 0..n-2 the five variables of its pair
 * (i < j): h [m], theta [rad], v_n [m/s], Omega [rad/s], v_omega = a_i w_i + a_j w_j [m/s]
 * (Eqs. 9, 14, 17, 18).
 */
#ifndef WETDEM_PAIRWISE_H
#define WETDEM_PAIRWISE_H

#include <stdbool.h>
#include <stddef.h>

#include "wetdem.h"

#define PW_NMAX WETDEM_PAIRWISE_MAX_SPHERES
#define PW_PMAX WETDEM_PAIRWISE_MAX_PAIRS
#define PW_YMAX (5 * PW_NMAX)
#define PW_ANCHOR_LEN 5
#define PW_EDGE_LEN 5

/* Offsets of the five tracked-pair variables inside an edge block. */
enum { PW_H = 0, PW_THETA = 1, PW_VN = 2, PW_OMEGA = 3, PW_VW = 4 };

/* Constant data of a run derived from the configuration. */
struct wetdem_pairwise_system {
    size_t n, n_pairs;
    size_t pi[PW_PMAX], pj[PW_PMAX];                 /* pair p joins spheres pi < pj */
    double a[PW_NMAX], m[PW_NMAX], inertia[PW_NMAX]; /* a_i [m], m_i [kg], I_i = 2/5 m a^2 */
    double a_eff[PW_PMAX], m_eff[PW_PMAX];           /* a_ij [m], m_ij [kg] */
    double delta[PW_PMAX];                           /* delta_ij [m] */
    double mu, sigma, h_min, e_dry, mu_f;            /* [Pa s], [N/m], [m], [-], [-] */
    double gx, gy;                                   /* [m/s^2] */
    double hold_rate; /* alpha [1/s]: a held pair that is not tracked is kept at h_min by
                         dv_n/dt = alpha^2 (h - h_min) - 2 alpha v_n (pairwise_rhs.c) */
};

/* Discrete mode of a run: tracked tree and the per-pair switches. */
struct wetdem_pairwise_mode {
    size_t edge[PW_NMAX - 1];  /* pair index of tracked edge e */
    int edge_of_pair[PW_PMAX]; /* tracked edge of pair p, or -1 */
    size_t order[PW_NMAX];     /* spheres in reconstruction order (order[0] = 0) */
    size_t via[PW_NMAX];       /* edge that reaches order[k] (k >= 1) */
    bool film[PW_PMAX];        /* films overlap: forces of Eqs. 3-4 act */
    bool resting[PW_PMAX];     /* held at h = h_min by a constraint force */
};

/* Every sphere and every pair at one state (the output of the reconstruction). */
struct wetdem_pairwise_kin {
    double x[PW_NMAX], y[PW_NMAX];                 /* absolute centre [m] */
    double dx[PW_NMAX], dy[PW_NMAX];               /* centre relative to sphere 0 [m] */
    double vx[PW_NMAX], vy[PW_NMAX];               /* absolute velocity [m/s] */
    double ux[PW_NMAX], uy[PW_NMAX];               /* velocity relative to sphere 0 [m/s] */
    double w[PW_NMAX];                             /* spin [rad/s] */
    double h[PW_PMAX], r[PW_PMAX];                 /* gap, centre distance [m] */
    double theta[PW_PMAX], c[PW_PMAX], s[PW_PMAX]; /* angle of x_j - x_i, cos, sin */
    double v_n[PW_PMAX];                           /* e_ij . (v_i - v_j), > 0 approaching [m/s] */
    double omega_lc[PW_PMAX];                      /* Omega_ij = d theta_ij / dt [rad/s] */
    double v_w[PW_PMAX];                           /* a_i w_i + a_j w_j [m/s] */
};

/* Film and constraint forces of every pair (Davis sign convention: on i the force is
 * -(F_n e_ij + F_t t_ij), on j +(F_n e_ij + F_t t_ij)). */
struct wetdem_pairwise_forces {
    double f_n[PW_PMAX];    /* normal, > 0 repulsive [N] (Eq. 3 plus constraint) */
    double f_t[PW_PMAX];    /* tangential, Eq. 4 [N] */
    double lambda[PW_PMAX]; /* resting-contact constraint force, > 0 compressive [N] */
};

/* ---- pairwise_state.c ---- */

/* Fills the pair list and derived constants from a validated configuration. */
void wetdem_pairwise_state_system(const struct wetdem_pairwise_config* cfg,
                                  struct wetdem_pairwise_system* sys);
/* Chooses the tracked tree by Kruskal over all pairs with keys (must-have pair `force`
 * (or PW_PMAX for none), resting, films overlapping, already tracked in `old` (may be NULL),
 * gap); fills md->edge, edge_of_pair, order, via. gaps: h of every pair [m]. */
void wetdem_pairwise_state_tree(const struct wetdem_pairwise_system* sys, const double* gaps,
                                const struct wetdem_pairwise_mode* old, size_t force,
                                struct wetdem_pairwise_mode* md);
/* Reconstructs every sphere and pair from the state y (Eqs. 37-38, Appendix B). Returns
 * false if a tracked gap or distance is not finite. */
bool wetdem_pairwise_state_kin(const struct wetdem_pairwise_system* sys,
                               const struct wetdem_pairwise_mode* md, const double* y,
                               struct wetdem_pairwise_kin* k);
/* Packs the state y of tree md from the pair values of k (tracked pairs of a previous tree
 * keep their exact values, since state_kin copies them into k) and sphere 0. */
void wetdem_pairwise_state_pack(const struct wetdem_pairwise_system* sys,
                                const struct wetdem_pairwise_mode* md,
                                const struct wetdem_pairwise_kin* k, double* y);
/* Fills the relative sphere fields and every pair quantity of k from its absolute sphere
 * fields x, y, vx, vy, w (Appendix B: r_ij = x_j - x_i, v_ij = v_i - v_j). */
void wetdem_pairwise_state_pairs_from_spheres(const struct wetdem_pairwise_system* sys,
                                              struct wetdem_pairwise_kin* k);

/* ---- pairwise_rhs.c ---- */

/* Normal film force of Eq. 3 [N]: 6 pi mu a^2 v_n [1 - h/(2 delta - h)]^2 / h - 8 pi a sigma,
 * for 0 < h <= delta. */
double wetdem_pairwise_rhs_normal_force(double mu, double sigma, double a, double delta, double h,
                                        double v_n);
/* Tangential film force of Eq. 4 [N]: 2 pi mu a v_s ln[(2 delta - h)/h], 0 < h <= delta,
 * v_s = -r Omega + a_i w_i + a_j w_j the relative surface speed [m/s]. */
double wetdem_pairwise_rhs_tangential_force(double mu, double a, double delta, double h,
                                            double v_s);
/* Film and constraint forces at state k. Returns false if an active pair has h <= 0 or the
 * constraint system is singular. */
bool wetdem_pairwise_rhs_forces(const struct wetdem_pairwise_system* sys,
                                const struct wetdem_pairwise_mode* md,
                                const struct wetdem_pairwise_kin* k,
                                struct wetdem_pairwise_forces* f);
/* Change of dv_n/dt of pair p per unit normal force (or of v_n per unit normal impulse) on
 * pair q, repulsive positive [1/kg]: -1/m_ij for q = p, the Eq. 6 projection over the mass of
 * a shared sphere otherwise, 0 for pairs without a common sphere. */
double wetdem_pairwise_rhs_coupling(const struct wetdem_pairwise_system* sys,
                                    const struct wetdem_pairwise_kin* k, size_t p, size_t q);
/* Solves A x = b in place for the n x n matrix whose rows start tda doubles apart at a
 * (overwritten by its LU factors), by GSL's LU decomposition with partial pivoting; false if
 * A is singular (a zero or NaN pivot). n <= PW_SOLVE_MAX. */
#define PW_SOLVE_MAX 32
_Static_assert(PW_PMAX <= PW_SOLVE_MAX, "every pair fits the solver");
bool wetdem_pairwise_rhs_solve(size_t n, double* a, size_t tda, double* b);
/* Which of the candidate pairs (touching at h_min with v_n = 0) must be held: the solution of
 * the contact problem lambda >= 0, dv_n/dt = 0 where held, dv_n/dt <= 0 elsewhere, found by
 * enumerating the subsets (<= 16 candidates). False if none is consistent. */
bool wetdem_pairwise_rhs_hold_set(const struct wetdem_pairwise_system* sys,
                                  const struct wetdem_pairwise_mode* md,
                                  const struct wetdem_pairwise_kin* k, const bool* cand,
                                  bool* hold);
/* dy/dt of the state (Eqs. 9, 14, 17, 18 per tracked pair; 34-36, 39 for sphere 0). Returns
 * false when the state is outside the domain (see wetdem_pairwise_rhs_forces). */
bool wetdem_pairwise_rhs_eval(const struct wetdem_pairwise_system* sys,
                              const struct wetdem_pairwise_mode* md, const double* y, double* dydt);

/* Parts of the mechanical energy of state k [J]: kinetic (translation and spin), the
 * capillary potential sum over film pairs of 8 pi a sigma (h - delta) (<= 0) and gravity's
 * -sum m g . x (the driver takes it from its value at t = 0). */
void wetdem_pairwise_rhs_energy(const struct wetdem_pairwise_system* sys,
                                const struct wetdem_pairwise_mode* md,
                                const struct wetdem_pairwise_kin* k, double* kinetic,
                                double* capillary, double* gravity);
/* Power dissipated by the film forces at state k [W], >= 0: the viscous part of Eq. 3 times
 * v_n and Eq. 4 times v_s, summed over the film pairs. */
void wetdem_pairwise_rhs_dissipation(const struct wetdem_pairwise_system* sys,
                                     const struct wetdem_pairwise_mode* md,
                                     const struct wetdem_pairwise_kin* k, double* normal,
                                     double* tangential);

/* ---- pairwise_jump.c ---- */

/* Applies the hard-sphere impulse of pair p at state k (through wetdem_hard_impulse(),
 * Appendix A in vector form) and updates sphere 0 and the tracked variables of y by the
 * velocity jumps (A5-A14 follow in neighbouring pairs). Returns a status. */
int wetdem_pairwise_jump_apply(const struct wetdem_pairwise_system* sys,
                               const struct wetdem_pairwise_mode* md, size_t p,
                               struct wetdem_pairwise_kin* k, double* y);

/* Frictionless impulses of the pairs in `set`, met at one instant while approaching: normal
 * impulses J_q that reverse every v_n of the set to -e_dry v_n at once, sum_q coupling(p, q)
 * J_q = -(1 + e_dry) v_n,p. Updates y and returns true only when every J_q pushes the pair
 * apart; false (y untouched) if one would pull, or the system is singular. */
bool wetdem_pairwise_jump_simultaneous(const struct wetdem_pairwise_system* sys,
                                       const struct wetdem_pairwise_mode* md,
                                       const struct wetdem_pairwise_kin* k, const bool* set,
                                       double* y);

/* Frictional impulses of the pairs in `set` (at most 6), met at one instant while approaching
 * with mu_f > 0 (docs/derivations/pairwise.md Sec. 6): compression, the impulses that bring
 * every v_n of the set to zero with the least kinetic energy after within the friction cone
 * |J_t| <= mu_f J_n (each slip arrested, or slid against at mu_f J_n); restitution, normal
 * impulses e_dry J_n more (Poisson) with friction by the same rule within mu_f e_dry J_n.
 * Updates y and returns true; false (y untouched) if a J_n would pull, the set is larger, or
 * the kinetic energy would grow. */
bool wetdem_pairwise_jump_simultaneous_friction(const struct wetdem_pairwise_system* sys,
                                                const struct wetdem_pairwise_mode* md,
                                                const struct wetdem_pairwise_kin* k,
                                                const bool* set, double* y);

/* Plastic impulses of the pairs in `set` (a contact slower than the rest speed and the pairs
 * touching at h_min that move slower than it): normal impulses J_q that bring every v_n of the
 * set to zero at once, sum_q coupling(p, q) J_q = -v_n,p. A J_q < 0 (a pull of at most
 * m* x rest speed) is the regularisation that lets the force-level contact problem decide
 * which pairs stay held. Updates y; false if the system is singular. */
bool wetdem_pairwise_jump_plastic(const struct wetdem_pairwise_system* sys,
                                  const struct wetdem_pairwise_mode* md,
                                  const struct wetdem_pairwise_kin* k, const bool* set, double* y);

/* Jumps of a neighbour pair j-k caused by a collision of pair i-j (A12-A14, corrected):
 * inputs v_ij,n before [m/s], theta_ij, theta_jk [rad], r_jk [m], m_ij, m_j [kg], the
 * tangential impulse ratio q = I_ij,t / I_ij,n (+-mu_f sliding, A33/I_n sticking) and e_dry.
 * Outputs the changes of v_jk,n [m/s], v_jk,t [m/s] and Omega_jk [rad/s]. */
void wetdem_pairwise_jump_neighbour(double v_n_b, double theta_ij, double theta_jk, double r_jk,
                                    double m_ij, double m_j, double q, double e_dry, double* dv_n,
                                    double* dv_t, double* d_omega);
/* Jumps of the colliding pair i-j itself (A1, A9-A11 sliding or A33-A35 sticking): inputs
 * v_n, Omega, v_omega before, r_ij, a_i, a_j, m_i, m_j, e_dry, mu_f; outputs the values
 * after and the tangential impulse ratio q = I_t / I_n (sign: I_t acts on j along t_ij).
 * Returns true when sliding is arrested (A36 holds). */
bool wetdem_pairwise_jump_own(double v_n, double omega_lc, double v_w, double r, double a_i,
                              double a_j, double m_i, double m_j, double e_dry, double mu_f,
                              double* v_n_a, double* omega_lc_a, double* v_w_a, double* q);

#endif

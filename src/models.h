/*
 * models.h — internal declarations of the built-in model objects (one per source file) and
 * small shared kernels. The registry (model_registry.c) lists them in one table.
 */
#ifndef WETDEM_MODELS_H
#define WETDEM_MODELS_H

#include <math.h>

#include "wetdem.h"

/* contact */
extern const struct wetdem_model wetdem_force_hertz;
extern const struct wetdem_model wetdem_force_mindlin;
extern const struct wetdem_model wetdem_force_hooke;
extern const struct wetdem_model wetdem_hard_model;
/* fluid */
extern const struct wetdem_model wetdem_force_nijssen;
extern const struct wetdem_model wetdem_force_reynolds;
extern const struct wetdem_model wetdem_force_sb;
extern const struct wetdem_model wetdem_force_db;
extern const struct wetdem_model wetdem_force_davis;
extern const struct wetdem_model wetdem_force_nase;
extern const struct wetdem_model wetdem_force_capillary;
/* minimum separation */
extern const struct wetdem_model wetdem_minsep_fixed;
extern const struct wetdem_model wetdem_minsep_roughness;
extern const struct wetdem_model wetdem_minsep_ehd;
extern const struct wetdem_model wetdem_minsep_max;
extern const struct wetdem_model wetdem_minsep_glass;

/* ---- hooks shared by the models that act only in solid contact (hertz, mindlin, hooke) ---- */

/* Relaxation time m / c_d [s] of a motion of mass m [kg] damped with coefficient c_d
 * [kg/s]: INFINITY without damping, 0 when c_d has no bound (not finite). The models'
 * relaxation_time hooks return it. */
static inline double viscous_relaxation_time(double m, double c_d)
{
    if (!(c_d > 0.0))
        return INFINITY;
    return isfinite(c_d) ? m / c_d : 0.0;
}

/* Range of a contact-only model [m]: 0, it acts only where the gap is negative. */
static inline double contact_only_range(const void* params, const struct wetdem_contact* c)
{
    (void)params;
    (void)c;
    return 0.0;
}

/* Branch gaps of a contact-only model: the force switches on at gap 0 [m]. Returns 1. */
static inline size_t contact_only_thresholds(const void* params, const struct wetdem_contact* c,
                                             const double* history, double* gaps)
{
    (void)params;
    (void)c;
    (void)history;
    gaps[0] = 0.0;
    return 1;
}

/* is_in_contact hook of a contact-only model: its force acts where the surfaces overlap,
 * gap < 0. */
static inline bool contact_only_is_in_contact(const void* params, const struct wetdem_contact* c,
                                              const double* history)
{
    (void)params;
    (void)history;
    return c->gap < 0.0;
}

/* ---- hooks shared by the film models (sb, db, davis, nase, capillary) ---- */

/* is_bridged hook of a film model: the liquid bridge joins the pair while the films overlap,
 * delta = delta_i + delta_j > 0 and h <= delta, solid overlap included (the liquid surrounds
 * the contact: force_capillary.c). */
static inline bool film_is_bridged(const void* params, const struct wetdem_contact* c,
                                   const double* history)
{
    (void)params;
    (void)history;
    return c->film > 0.0 && c->gap <= c->film;
}

/* ---- shared kernels (pure functions; defined in the file of the family they belong to) ---- */

/* force_hertz.c: Hertz elastic normal force (4/3) E* sqrt(R*) delta^(3/2) [N]; 0 if delta <= 0. */
double wetdem_force_hertz_elastic(double e_star, double r_eff, double overlap);
/* force_hertz.c: energy stored in the Hertz contact, (8/15) E* sqrt(R*) delta^(5/2) [J], the
 * integral of wetdem_force_hertz_elastic over the overlap (Johnson 1985 Eq. 4.23); 0 if
 * delta <= 0. */
double wetdem_force_hertz_energy(double e_star, double r_eff, double overlap);
/* Hertz stiffness factor k = (4/3) E* sqrt(R*) [N/m^(3/2)] and the parts of the hertz law
 * written with it: the elastic force k delta^(3/2) and the damping force
 * (coefficient sqrt(m* k)) delta^(1/4) v_n [N] (delta > 0), whose first factor depends on the
 * pair only. The one definition of this
 * arithmetic: force_hertz.c and the many-particle kernel (sim_many_force.c) both use it, so
 * that their forces are bit-identical. */
static inline double hertz_stiffness(double e_star, double r_eff)
{
    return (4.0 / 3.0) * e_star * sqrt(r_eff);
}
/* Largest overlap [m] of an undamped Hertz impact of reduced mass m* [kg] at approach speed v
 * [m/s], stiffness factor k (hertz_stiffness): (1/2) m* v^2 = (2/5) k delta^(5/2), so
 * delta_max = (5 m* v^2 / (4 k))^(2/5); where the dampers that grow with the overlap are
 * largest (the hertz and mindlin relaxation times). */
static inline double hertz_impact_overlap(double m_eff, double v, double k)
{
    return pow(1.25 * m_eff * v * v / k, 0.4);
}
static inline double hertz_elastic_k(double k, double overlap)
{
    return k * overlap * sqrt(overlap);
}
static inline double hertz_damping_factor(double coefficient, double k, double m_eff)
{
    return coefficient * sqrt(m_eff * k);
}
static inline double hertz_damping_from(double factor, double overlap, double v_n)
{
    return factor * sqrt(sqrt(overlap)) * v_n;
}
/* The hertz law of damping form `form` from its elastic and damping parts [N]: form 1 (tsuji)
 * their sum, form 0 (exact) the sum clipped at >= 0 (contact.md Secs. 1.1, 1.5); a NaN sum
 * clips to 0, as fmax does. */
static inline double hertz_total(double f_el, double f_damp, int form)
{
    double sum = f_el + f_damp;
    return form == 1 ? sum : (sum > 0.0 ? sum : 0.0);
}
static inline double hertz_damping_k(double coefficient, double k, double m_eff, double overlap,
                                     double v_n)
{
    return hertz_damping_from(hertz_damping_factor(coefficient, k, m_eff), overlap, v_n);
}
/* force_hertz.c: normal viscous damping force of the Hertz contact [N], > 0 (repulsive) for
 * v_n > 0 (approaching), proportional to delta^(1/4) v_n so that the restitution is
 * independent of speed. form 0 "exact": coefficient chosen so that an isolated Hertz
 * spring + dashpot collision, with elastic + damping clipped at >= 0, rebounds with exactly
 * `restitution`; form 1 "tsuji": the LIGGGHTS/Tsuji coefficient -2 sqrt(5/6) beta
 * sqrt(S_n m*) (exact for the unclipped sum, which the hertz model uses with this form).
 * NAN for restitution outside (0, 1] or another form. Combine with the elastic part through
 * wetdem_force_hertz_total to get the hertz law of the form. */
double wetdem_force_hertz_damping(double e_star, double r_eff, double m_eff, double overlap,
                                  double v_n, double restitution, int form);
/* force_hertz.c: the dimensionless damping coefficient of wetdem_force_hertz_damping for
 * `restitution` and `form` [-] (the exact-table or Tsuji value; NAN for restitution outside
 * (0, 1] or another form), to be computed once per material pair. */
double wetdem_force_hertz_damping_coefficient(double restitution, int form);
/* force_hertz.c: wetdem_force_hertz_damping from a precomputed coefficient
 * (wetdem_force_hertz_damping_coefficient) [N]: bit-identical to it for valid arguments;
 * 0 if overlap <= 0. */
double wetdem_force_hertz_damping_with(double coefficient, double e_star, double r_eff,
                                       double m_eff, double overlap, double v_n);
/* force_hertz.c: total normal force of the hertz law [N] from its elastic part f_el and its
 * damping part f_damp (wetdem_force_hertz_damping with the same form): the one place that
 * decides whether the sum is clipped at zero for a damping form. Every caller that composes
 * the hertz law (the hertz model, the many-particle fused kernel) goes through it. */
double wetdem_force_hertz_total(double f_el, double f_damp, int form);
/* force_hertz.c: duration of an undamped head-on Hertz collision at impact speed v [s]:
 * 2.868266... (m*^2 / (E*^2 R* v))^(1/5) (Hertz theory; Johnson 1985 Sec. 11.4). */
double wetdem_force_hertz_contact_time(double e_star, double r_eff, double m_eff, double v);
/* The contact_time hook of the models with a Hertz contact (hertz, nijssen): the Hertz
 * contact time at the approach speed c->v_n [s] (speeds below 1e-12 m/s count as 1e-12: the
 * time grows without bound as the speed vanishes). */
static inline double hertz_contact_time_hook(const void* params, const struct wetdem_contact* c)
{
    (void)params;
    return wetdem_force_hertz_contact_time(c->e_star, c->r_eff, c->m_eff, fmax(c->v_n, 1e-12));
}
/* force_mindlin.c: Mindlin tangential spring with Coulomb limit. spring (3 doubles of history:
 * the elastic tangential displacement [m]) is rotated into the current tangent plane and
 * advanced by v_t dt; stiffness k_t = 8 G* sqrt(R* delta); Tsuji damping from `restitution`
 * with k_t; when the total spring + dashpot force exceeds mu |f_limit| it is capped at
 * |F_t| = mu |f_limit| and the spring set so that spring + dashpot give the capped force
 * (sliding, LAMMPS pair granular semantics), so |F_t| <= mu |f_limit| always. Returns the
 * tangential force on i [N]. overlap <= 0 resets the spring. slip (NULL: not wanted): for
 * overlap > 0, |F_t| before the cap minus the cap [N] (struct wetdem_pair_force slip). */
struct wetdem_vec3 wetdem_force_mindlin_update(const struct wetdem_contact* c, double overlap,
                                               double f_limit, double mu, double* spring,
                                               double* slip);
/* force_mindlin.c: the factor -2 sqrt(5/6) beta(e) of the Tsuji tangential damping [-],
 * beta = ln e / sqrt(ln^2 e + pi^2), to be computed once per material pair (e in (0, 1]). */
double wetdem_force_mindlin_damping_factor(double restitution);
/* force_mindlin.c: wetdem_force_mindlin_update with the damping factor precomputed
 * (wetdem_force_mindlin_damping_factor(c->restitution)); bit-identical results. */
struct wetdem_vec3 wetdem_force_mindlin_update_with(const struct wetdem_contact* c, double overlap,
                                                    double f_limit, double mu,
                                                    double damping_factor, double* spring,
                                                    double* slip);

#endif

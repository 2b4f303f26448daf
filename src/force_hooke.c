/*
 * force_hooke.c — "hooke": linear spring-dashpot normal contact, a cheap alternative to hertz
 * (Cundall & Strack 1979; LIGGGHTS `model hooke`). Derivation: docs/derivations/contact.md
 * Sec. 3.
 *
 *   F_n = k delta + gamma v_n                          [N], delta = -h > 0, v_n > 0 approaching
 *   gamma = -2 ln e sqrt(m* k) / sqrt(ln^2 e + pi^2)   [kg/s]
 *
 * The contact is a damped linear oscillator m* delta'' = -k delta - gamma delta', so a head-on
 * collision lasts half a damped period, t_c = pi / sqrt(k/m* - (gamma/(2 m*))^2) [s], and
 * rebounds with e = exp(-gamma t_c/(2 m*)); solving for gamma gives the expression above, so
 * e_dry is reproduced exactly at every impact speed. The force is NOT clipped at zero: near
 * the end of unloading it pulls by up to gamma v; clipping would raise the rebound speed and
 * break both closed forms. At delta = 0 the force jumps by gamma v_n (the dashpot acts from
 * the first overlap), the one discontinuity of the law; thresholds() reports that gap. k is a
 * model parameter, independent of the material moduli; the engines pass it to the other models
 * as c->linear_stiffness (linear_stiffness hook), from which mindlin beside hooke takes its
 * linear form, k_t = 4 (G* / E*) k and the Coulomb limit mu k delta (contact.md Sec. 3.1).
 * Validity: e in (0, 1]; choose k so that the overlap stays small, delta_max = v sqrt(m* / k)
 * (undamped) << R*.
 */
#include <math.h>
#include <stddef.h>

#include "models.h"

struct hooke_params {
    double stiffness; /* k [N/m] */
};

static const struct wetdem_param_desc hooke_params_desc[] = {
    {"stiffness", "N/m", "Normal spring constant k of the linear contact.",
     offsetof(struct hooke_params, stiffness), 1e6, 0, 1e15, true, false, NULL, false},
    {0},
};

/* Dashpot coefficient that gives restitution e for a linear oscillator of mass m, spring k
 * [kg/s]; 0 at e = 1. */
static double hooke_damping(double k, double m_eff, double e)
{
    double l = log(e);
    return -2.0 * l * sqrt(m_eff * k) / sqrt(l * l + M_PI * M_PI);
}

static int hooke_pair(const void* params, const struct wetdem_contact* c, double* history,
                      struct wetdem_pair_force* out)
{
    (void)history;
    double k = ((const struct hooke_params*)params)->stiffness;
    if (!(c->restitution > 0.0 && c->restitution <= 1.0))
        return WETDEM_ERR_INVALID;
    double overlap = -c->gap;
    if (!(overlap > 0.0))
        return WETDEM_OK;
    out->f_normal += k * overlap + hooke_damping(k, c->m_eff, c->restitution) * c->v_n;
    return WETDEM_OK;
}

/* Half the damped period of the linear contact, pi / sqrt(k/m* - (gamma/(2 m*))^2) [s]: the
 * same at every impact speed. */
static double hooke_contact_time(const void* params, const struct wetdem_contact* c)
{
    double k = ((const struct hooke_params*)params)->stiffness;
    double e = c->restitution > 0.0 && c->restitution <= 1.0 ? c->restitution : 1.0;
    double decay = hooke_damping(k, c->m_eff, e) / (2.0 * c->m_eff);
    return M_PI / sqrt(k / c->m_eff - decay * decay);
}

/* Relaxation time m* / gamma of the dashpot [s], the same at every overlap and speed. As
 * e_dry -> 0, gamma -> 2 sqrt(m* k) (critical damping) and the contact time above grows
 * without bound (the motion no longer oscillates), so this time, sqrt(m* / k) / 2 at the least,
 * and not the contact time, bounds the many-particle step there (docs/many.md, Time step);
 * INFINITY without damping (e_dry = 1). */
static double hooke_relaxation_time(const void* params, const struct wetdem_contact* c)
{
    double k = ((const struct hooke_params*)params)->stiffness;
    if (!(c->restitution > 0.0 && c->restitution <= 1.0))
        return INFINITY;
    return viscous_relaxation_time(c->m_eff, hooke_damping(k, c->m_eff, c->restitution));
}

/* The spring constant k [N/m]: the engines pass it to every model as c->linear_stiffness, and
 * mindlin beside hooke takes its linear form from it (force_mindlin.c). */
static double hooke_linear_stiffness(const void* params, const struct wetdem_contact* c)
{
    (void)c;
    return ((const struct hooke_params*)params)->stiffness;
}

/* Energy stored in the spring, k delta^2 / 2 [J] (the dashpot stores none). */
static double hooke_elastic_energy(const void* params, const struct wetdem_contact* c,
                                   const double* history)
{
    (void)history;
    double k = ((const struct hooke_params*)params)->stiffness;
    double overlap = -c->gap;
    return overlap > 0.0 ? 0.5 * k * overlap * overlap : 0.0;
}

const struct wetdem_model wetdem_force_hooke = {
    .name = "hooke",
    .kind = WETDEM_MODEL_CONTACT,
    .summary = "linear spring-dashpot normal contact with damping from e_dry",
    .doc = "Normal solid contact for overlap delta = -h > 0: F_n = k delta + gamma v_n with "
           "the spring constant k (parameter stiffness) and gamma = -2 ln e sqrt(m* k) / "
           "sqrt(ln^2 e + pi^2), which makes a head-on collision rebound with exactly e_dry at "
           "any speed; contact time pi / sqrt(k/m* - (gamma/(2 m*))^2). The force is not "
           "clipped, so it pulls slightly at the end of unloading (clipping would break both "
           "closed forms), and the dashpot makes it jump by gamma v_n where the overlap "
           "begins and ends. Cheaper and stiffer-to-tune than hertz; k does not follow from the "
           "material moduli. Keep the overlap v sqrt(m* / k) small compared with R*. mindlin "
           "beside it becomes the linear history spring: tangential stiffness (4 G*/E*) k (the "
           "Hertz-Mindlin ratio of tangential to normal stiffness) and Coulomb limit mu k delta, "
           "so friction stays within mu times this model's elastic force; it reads the current "
           "k (the engines pass it as the contact's linear_stiffness).",
    .equations = "linear spring-dashpot (Cundall & Strack 1979; LIGGGHTS model hooke); "
                 "docs/derivations/contact.md",
    .params = hooke_params_desc,
    .params_size = sizeof(struct hooke_params),
    .history_len = 0,
    .range = contact_only_range,
    .pair = hooke_pair,
    .thresholds = contact_only_thresholds,
    .contact_time = hooke_contact_time,
    .linear_stiffness = hooke_linear_stiffness,
    .relaxation_time = hooke_relaxation_time,
    .elastic_energy = hooke_elastic_energy,
    .is_in_contact = contact_only_is_in_contact,
};

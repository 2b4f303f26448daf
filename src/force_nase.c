/*
 * force_nase.c — "nase": tangential viscous force of O'Neill / Goldman et al. for fully
 * immersed spheres, as used by Nase et al. (2001) and Punch 2023 Eq. 10 for film-coated
 * spheres:
 *
 *     F_t = -6 pi mu a (8/15 ln(a/h) + 0.9588) v_t     [N], for h_min' <= h <= delta
 *
 * on i, with a = R* [m], mu [Pa s], delta = delta_i + delta_j [m] (Punch's h_max) and v_t the
 * tangential velocity of i's surface relative to j's at the contact point [m/s] (spins
 * included). It opposes v_t and acts at the contact point (torques -R_i n x F_t on i,
 * -R_j n x F_t on j). Below h_min' = min(h_min, delta): "c" zero (Punch Eq. 12) or "nc" the
 * law at h_min' (Eq. 13).
 *
 * Validity: the factor is the small-gap asymptote of a sphere sliding near a wall, for
 * h/a << 1. It does not vanish at the film edge, so the force jumps from its value at delta
 * to 0 when the films separate (Punch's model has this jump). The factor
 * 8/15 ln(a/h) + 0.9588 changes sign at h = a exp(15 * 0.9588 / 8) = 6.04 a: a film that
 * thick is far outside the thin-film range (delta << a), and a negative factor would push the
 * sliding instead of resisting it, so the factor is floored at zero (force zero for
 * h >= 6.04 a). The nc form with h_min >= delta evaluates at delta and so gives the constant
 * value there, unlike sb, db and davis, which vanish at delta.
 */
#include <math.h>
#include <stddef.h>

#include "models.h"
#include "thin_film.h"
#include "vec3.h"

struct nase_params {
    double below_hmin; /* enum thin_film_below */
};

static const struct wetdem_param_desc nase_params_desc[] = {
    THIN_FILM_BELOW_PARAM(struct nase_params),
    {0},
};

/* Resistance coefficient 6 pi mu a max(0, 8/15 ln(a/h) + 0.9588) [N s/m], h > 0. */
static double nase_resistance(double mu, double a, double h)
{
    double factor = (8.0 / 15.0) * log(a / h) + 0.9588;
    return 6.0 * M_PI * mu * a * fmax(factor, 0.0);
}

static int nase_pair(const void* params, const struct wetdem_contact* c, double* history,
                     struct wetdem_pair_force* out)
{
    (void)history;
    const struct nase_params* p = params;
    double h;
    if (!thin_film_eval_gap(c->gap, c->h_min, c->film, p->below_hmin, &h))
        return WETDEM_OK;
    double k = nase_resistance(c->viscosity, c->r_eff, h);
    wetdem_pair_force_add_tangential(out, c, vec3_scale(c->v_t, -k));
    return WETDEM_OK;
}

/* (2/7) m* / k at h_min', k = 6 pi mu a (8/15 ln(a/h) + 0.9588) (tangential mass as in
 * force_davis.c) [s]. */
static double nase_relaxation_time(const void* params, const struct wetdem_contact* c)
{
    (void)params;
    double h;
    if (!thin_film_stiffest_gap(c, &h))
        return INFINITY;
    return viscous_relaxation_time(2.0 / 7.0 * c->m_eff,
                                   nase_resistance(c->viscosity, c->r_eff, h));
}

const struct wetdem_model wetdem_force_nase = {
    .name = "nase",
    .kind = WETDEM_MODEL_FLUID,
    .summary = "tangential viscous force -6 pi mu a (8/15 ln(a/h) + 0.9588) v_t within the film",
    .doc = "Tangential viscous force of O'Neill and Goldman et al. for a sphere sliding near "
           "another (fully immersed), applied within the film as by Nase et al. and Punch: "
           "F_t = -6 pi mu a (8/15 ln(a/h) + 0.9588) v_t [N] on i for h_min <= h <= delta, "
           "with a = R*, delta = delta_i + delta_j and v_t the tangential velocity of i's "
           "surface relative to j's at the contact point, spins included. It opposes v_t and "
           "acts at the contact point (torques on both spheres). It does not vanish at "
           "h = delta: the force drops to zero there when the films separate. Below h_min "
           "(from the min-separation model, capped at delta): below_hmin = c gives zero, nc "
           "holds the law at h_min with the current v_t. Valid for h << R*; the factor would "
           "turn negative for h > 6.04 R* (films far thicker than this model's range) and is "
           "floored at zero there.",
    .equations = "Punch 2023 Eq. 10, Eqs. 12-13 (c/nc); O'Neill 1964; Goldman et al. 1967",
    .params = nase_params_desc,
    .params_size = sizeof(struct nase_params),
    .history_len = 0,
    .range = thin_film_range,
    .pair = nase_pair,
    .thresholds = thin_film_thresholds,
    .relaxation_time = nase_relaxation_time,
    .is_bridged = film_is_bridged,
};

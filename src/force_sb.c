/*
 * force_sb.c — "sb": normal viscous force of a static liquid bridge between two film-coated
 * spheres (Punch 2023 Eq. 7 with the bracket corrected to [1 - h/h_max]^2, SPEC §6;
 * Punch's ref. [31]):
 *
 *     F_n = 6 pi mu a^2 v_n / h [1 - h/delta]^2      [N], for h_min' <= h <= delta
 *
 * a = R* [m], mu [Pa s], v_n [m/s] (> 0 approaching: repulsive; < 0 separating: suction),
 * h the gap [m], delta = delta_i + delta_j the combined film thickness [m] (Punch's h_max).
 * The bracket is the finite-extent correction of the Reynolds squeeze force: the film ends
 * where the gap equals delta, so the force goes continuously to zero there (bracket 0) and is
 * zero beyond. Below h_min' = min(h_min, delta) the parameter below_hmin selects zero ("c",
 * Punch Eq. 12) or the law at h_min' ("nc", Eq. 13); see thin_film.h. As h -> 0 the bracket
 * tends to 1 and the force to Reynolds' 6 pi mu a^2 v_n / h, the same limit as "db".
 * Validity: thin films delta << a, small Reynolds number rho v_n delta / mu << 1.
 */
#include <math.h>
#include <stddef.h>

#include "models.h"
#include "thin_film.h"

struct sb_params {
    double below_hmin; /* enum thin_film_below */
};

static const struct wetdem_param_desc sb_params_desc[] = {
    THIN_FILM_BELOW_PARAM(struct sb_params),
    {0},
};

/* Static-bridge normal force 6 pi mu a^2 v_n/h [1 - h/delta]^2 [N], h > 0. */
static double sb_force(double mu, double a, double v_n, double h, double delta)
{
    double bracket = 1.0 - h / delta;
    return 6.0 * M_PI * mu * a * a * v_n / h * bracket * bracket;
}

static int sb_pair(const void* params, const struct wetdem_contact* c, double* history,
                   struct wetdem_pair_force* out)
{
    (void)history;
    const struct sb_params* p = params;
    double h;
    if (thin_film_eval_gap(c->gap, c->h_min, c->film, p->below_hmin, &h))
        out->f_normal += sb_force(c->viscosity, c->r_eff, c->v_n, h, c->film);
    return WETDEM_OK;
}

/* m* / c_d at h_min', c_d = 6 pi mu a^2 / h [1 - h/delta]^2 (the force per unit v_n) [s]. */
static double sb_relaxation_time(const void* params, const struct wetdem_contact* c)
{
    (void)params;
    double h;
    if (!thin_film_stiffest_gap(c, &h))
        return INFINITY;
    return viscous_relaxation_time(c->m_eff, sb_force(c->viscosity, c->r_eff, 1.0, h, c->film));
}

const struct wetdem_model wetdem_force_sb = {
    .name = "sb",
    .kind = WETDEM_MODEL_FLUID,
    .summary = "thin-film normal viscous force, static bridge: 6 pi mu a^2 v_n/h [1 - h/delta]^2",
    .doc = "Normal viscous force of the liquid bridge between two film-coated spheres when the "
           "bridge is static (displaced liquid ignored): F = 6 pi mu a^2 v_n / h "
           "[1 - h/delta]^2 [N] for h_min <= h <= delta, with a = R*, delta = delta_i + delta_j "
           "the combined film thickness and h_min from the min-separation model (capped at "
           "delta). Repulsive while the surfaces approach, suction while they separate; zero "
           "for h > delta, and it falls continuously to zero at h = delta. Below h_min: "
           "below_hmin = c gives zero, nc holds the law at h_min (with the current v_n). "
           "With h_min >= delta the force is zero throughout. As h -> 0 it tends to the "
           "Reynolds force, like db. Valid for thin films (delta << R*) at small Reynolds "
           "number. Bracket as corrected in docs/derivations/fluid.md.",
    .equations = "Punch 2023 Eq. 7 (bracket [1 - h/h_max]^2), Eqs. 12-13 (c/nc); "
                 "Davis 2023 Eq. 3 limit h << delta",
    .params = sb_params_desc,
    .params_size = sizeof(struct sb_params),
    .history_len = 0,
    .range = thin_film_range,
    .pair = sb_pair,
    .thresholds = thin_film_thresholds,
    .relaxation_time = sb_relaxation_time,
    .is_bridged = film_is_bridged,
};

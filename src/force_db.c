/*
 * force_db.c — "db": normal viscous force of a deforming liquid bridge between two
 * film-coated spheres (Punch 2023 Eq. 8 = the viscous term of Davis 2023 Eq. 3; Davis &
 * Sitison 2020):
 *
 *     F_n = 6 pi mu a^2 v_n / h [1 - h/(2 delta - h)]^2     [N], for h_min' <= h <= delta
 *
 * a = R* [m], mu [Pa s], v_n [m/s] (> 0 approaching: repulsive; < 0 separating: suction, as
 * Davis notes below his Eq. 3), h the gap [m], delta = delta_i + delta_j [m] (Punch's h_max).
 * The bracket models the liquid displaced from the gap into the bridge: at h = delta it is
 * 1 - delta/delta = 0, so the force falls continuously to zero at the film edge; for h -> 0
 * it is 1 - h/(2 delta) + O(h^2), so db and sb agree to relative order h/delta. Below
 * h_min' = min(h_min, delta): "c" zero (Punch Eq. 12) or "nc" the law at h_min' (Eq. 13).
 * Validity: thin films delta << a, small Reynolds number rho v_n delta / mu << 1.
 */
#include <math.h>
#include <stddef.h>

#include "models.h"
#include "thin_film.h"

struct db_params {
    double below_hmin; /* enum thin_film_below */
};

static const struct wetdem_param_desc db_params_desc[] = {
    THIN_FILM_BELOW_PARAM(struct db_params),
    {0},
};

/* Deforming-bridge normal force 6 pi mu a^2 v_n/h [1 - h/(2 delta - h)]^2 [N], 0 < h <= delta. */
static double db_force(double mu, double a, double v_n, double h, double delta)
{
    double bracket = 1.0 - h / (2.0 * delta - h);
    return 6.0 * M_PI * mu * a * a * v_n / h * bracket * bracket;
}

static int db_pair(const void* params, const struct wetdem_contact* c, double* history,
                   struct wetdem_pair_force* out)
{
    (void)history;
    const struct db_params* p = params;
    double h;
    if (thin_film_eval_gap(c->gap, c->h_min, c->film, p->below_hmin, &h))
        out->f_normal += db_force(c->viscosity, c->r_eff, c->v_n, h, c->film);
    return WETDEM_OK;
}

/* m* / c_d at h_min', c_d = 6 pi mu a^2 / h [1 - h/(2 delta - h)]^2 [s]. */
static double db_relaxation_time(const void* params, const struct wetdem_contact* c)
{
    (void)params;
    double h;
    if (!thin_film_stiffest_gap(c, &h))
        return INFINITY;
    return viscous_relaxation_time(c->m_eff, db_force(c->viscosity, c->r_eff, 1.0, h, c->film));
}

const struct wetdem_model wetdem_force_db = {
    .name = "db",
    .kind = WETDEM_MODEL_FLUID,
    .summary = "thin-film normal viscous force, deforming bridge: "
               "6 pi mu a^2 v_n/h [1 - h/(2 delta - h)]^2",
    .doc = "Normal viscous force of the liquid bridge between two film-coated spheres with "
           "the displaced liquid joining the bridge (Davis's deforming bridge): "
           "F = 6 pi mu a^2 v_n / h [1 - h/(2 delta - h)]^2 [N] for h_min <= h <= delta, with "
           "a = R*, delta = delta_i + delta_j the combined film thickness and h_min from the "
           "min-separation model (capped at delta). Repulsive while the surfaces approach, "
           "suction while they separate; zero for h > delta, and it falls continuously to zero "
           "at h = delta. Below h_min: below_hmin = c gives zero, nc holds the law at h_min "
           "(with the current v_n). With h_min >= delta the force is zero throughout. As "
           "h -> 0 it tends to the Reynolds force, like sb. Valid for thin films "
           "(delta << R*) at small Reynolds number. Add the capillary model for the second "
           "term of Davis Eq. 3.",
    .equations = "Punch 2023 Eq. 8, Eqs. 12-13 (c/nc); Davis 2023 Eq. 3 (viscous term)",
    .params = db_params_desc,
    .params_size = sizeof(struct db_params),
    .history_len = 0,
    .range = thin_film_range,
    .pair = db_pair,
    .thresholds = thin_film_thresholds,
    .relaxation_time = db_relaxation_time,
    .is_bridged = film_is_bridged,
};

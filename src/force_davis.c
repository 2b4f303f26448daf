/*
 * force_davis.c — "davis": tangential viscous force of the thin film between two
 * film-coated spheres (Punch 2023 Eq. 9 = Davis 2023 Eq. 4; Kantak & Davis 2006):
 *
 *     F_t = -2 pi mu a ln[(2 delta - h)/h] v_t       [N], for h_min' <= h <= delta
 *
 * on i, with a = R* [m], mu [Pa s], delta = delta_i + delta_j [m] (Punch's h_max) and v_t the
 * tangential velocity of i's surface relative to j's at the contact point [m/s]. v_t already
 * contains the spins (Davis's v^s_t = -r Omega + omega_i a_i + omega_j a_j), so a pure spin
 * with no sliding of the centres is resisted too. The force opposes v_t (ln > 0 for h < delta)
 * and acts at the contact point, giving the torques -R_i n x F_t on i and -R_j n x F_t on j.
 * It comes from integrating the shear stress mu v_t / h(r) over the wetted disc
 * h(r) = h + r^2/(2a) <= 2 delta - h, i.e. out to the edge of the deforming bridge; at h = delta
 * the log is ln 1 = 0, so the force falls continuously to zero at the film edge.
 * Below h_min' = min(h_min, delta): "c" zero (Punch Eq. 12) or "nc" the law at h_min'
 * (Eq. 13). Validity: thin films delta << a; small Reynolds number.
 */
#include <math.h>
#include <stddef.h>

#include "models.h"
#include "thin_film.h"
#include "vec3.h"

struct davis_params {
    double below_hmin; /* enum thin_film_below */
};

static const struct wetdem_param_desc davis_params_desc[] = {
    THIN_FILM_BELOW_PARAM(struct davis_params),
    {0},
};

/* Resistance coefficient 2 pi mu a ln[(2 delta - h)/h] [N s/m], 0 < h <= delta. */
static double davis_resistance(double mu, double a, double h, double delta)
{
    return 2.0 * M_PI * mu * a * log((2.0 * delta - h) / h);
}

static int davis_pair(const void* params, const struct wetdem_contact* c, double* history,
                      struct wetdem_pair_force* out)
{
    (void)history;
    const struct davis_params* p = params;
    double h;
    if (!thin_film_eval_gap(c->gap, c->h_min, c->film, p->below_hmin, &h))
        return WETDEM_OK;
    double k = davis_resistance(c->viscosity, c->r_eff, h, c->film);
    wetdem_pair_force_add_tangential(out, c, vec3_scale(c->v_t, -k));
    return WETDEM_OK;
}

/* (2/7) m* / k at h_min', k = 2 pi mu a ln[(2 delta - h)/h]: the sliding of two spheres
 * free to spin responds to a tangential force F as (2/7) m* dv_t/dt = F [s]. */
static double davis_relaxation_time(const void* params, const struct wetdem_contact* c)
{
    (void)params;
    double h;
    if (!thin_film_stiffest_gap(c, &h))
        return INFINITY;
    return viscous_relaxation_time(2.0 / 7.0 * c->m_eff,
                                   davis_resistance(c->viscosity, c->r_eff, h, c->film));
}

const struct wetdem_model wetdem_force_davis = {
    .name = "davis",
    .kind = WETDEM_MODEL_FLUID,
    .summary = "thin-film tangential viscous force -2 pi mu a ln[(2 delta - h)/h] v_t",
    .doc = "Tangential viscous force of the thin film between two film-coated spheres "
           "(Davis): F_t = -2 pi mu a ln[(2 delta - h)/h] v_t [N] on i for h_min <= h <= "
           "delta, with a = R*, delta = delta_i + delta_j and v_t the tangential velocity of "
           "i's surface relative to j's at the contact point, spins included, so a pure "
           "rolling or spinning mismatch is resisted too. It opposes v_t, acts at the contact "
           "point (torques on both spheres), is zero for h > delta and falls continuously to "
           "zero at h = delta. Below h_min (from the min-separation model, capped at delta): "
           "below_hmin = c gives zero, nc holds the law at h_min with the current v_t. Valid "
           "for thin films (delta << R*) at small Reynolds number.",
    .equations = "Punch 2023 Eq. 9, Eqs. 12-13 (c/nc); Davis 2023 Eq. 4",
    .params = davis_params_desc,
    .params_size = sizeof(struct davis_params),
    .history_len = 0,
    .range = thin_film_range,
    .pair = davis_pair,
    .thresholds = thin_film_thresholds,
    .relaxation_time = davis_relaxation_time,
    .is_bridged = film_is_bridged,
};

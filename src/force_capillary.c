/*
 * force_capillary.c — "capillary": constant capillary suction of the pendular bridge between
 * two film-coated spheres (Punch 2023 Eq. 15 = Davis 2023 Eq. 3, second term; Davis &
 * Sitison 2020):
 *
 *     F_n = -8 pi a sigma      [N] (attractive), for h <= delta, delta > 0
 *
 * a = R* [m], sigma the surface tension [N/m], delta = delta_i + delta_j [m]. It is the
 * Laplace suction of the thin bridge between the near-touching coated surfaces, independent of
 * the gap while the bridge exists (Davis & Sitison 2020); the value is the seeds' (twice the
 * classic pendular-ring limit 4 pi a sigma of a small bridge of wetting liquid; see
 * docs/derivations/fluid.md Sec. 4). The bridge forms when the films overlap (h = delta) and
 * breaks when they separate: zero for h > delta (Davis: the bridge breaks or has negligible
 * influence there). At solid overlap (h <= 0) the bridge stays: the liquid surrounds the
 * contact and the suction keeps acting, as in Davis, where contact is an instant inside a
 * continuing bridge (dropping it would add a jump of 8 pi a sigma at contact). A film of zero
 * thickness gives no force.
 * Validity: delta << a, contact angle zero, bridge volume from the films.
 */
#include <math.h>
#include <stddef.h>

#include "models.h"

static const struct wetdem_param_desc capillary_params_desc[] = {
    {0},
};

/* Capillary suction magnitude 8 pi a sigma [N]. */
static double capillary_force(double a, double sigma)
{
    return 8.0 * M_PI * a * sigma;
}

static double capillary_range(const void* params, const struct wetdem_contact* c)
{
    (void)params;
    return c->film > 0.0 ? c->film : 0.0;
}

static int capillary_pair(const void* params, const struct wetdem_contact* c, double* history,
                          struct wetdem_pair_force* out)
{
    (void)params;
    (void)history;
    if (c->film > 0.0 && c->gap <= c->film)
        out->f_normal -= capillary_force(c->r_eff, c->surface_tension);
    return WETDEM_OK;
}

static size_t capillary_thresholds(const void* params, const struct wetdem_contact* c,
                                   const double* history, double* gaps)
{
    (void)history;
    gaps[0] = capillary_range(params, c);
    return 1;
}

const struct wetdem_model wetdem_force_capillary = {
    .name = "capillary",
    .kind = WETDEM_MODEL_FLUID,
    .summary = "constant capillary suction -8 pi a sigma while the films overlap",
    .doc = "Capillary suction of the thin pendular bridge between two film-coated spheres: "
           "a constant attraction F = -8 pi a sigma [N] with a = R* and sigma the fluid's "
           "surface tension, acting while the films overlap (h <= delta = delta_i + delta_j) "
           "and also at solid overlap (the bridge surrounds the contact), zero when the films "
           "separate (h > delta) or when there is no film. Normal only: no torque. Valid for "
           "thin films (delta << R*) of a wetting liquid.",
    .equations = "Punch 2023 Eq. 15; Davis 2023 Eq. 3 (second term)",
    .params = capillary_params_desc,
    .params_size = 0,
    .history_len = 0,
    .range = capillary_range,
    .pair = capillary_pair,
    .thresholds = capillary_thresholds,
    .is_bridged = film_is_bridged,
};

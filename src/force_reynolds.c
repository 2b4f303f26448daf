/*
 * force_reynolds.c — "reynolds": normal lubrication between two fully immersed spheres,
 * the leading Reynolds-lubrication term (Brenner 1961; Cox & Brenner 1967; Nijssen Eq. 1):
 *
 *     F_n = 6 pi mu R*^2 v_n / max(h, h_min)     [N], for 0 < h <= h_co = cutoff_ratio R*
 *
 * v_n > 0 approaching gives a repulsive force; separating gives suction. Zero for h > h_co and
 * for h <= 0 (solid contact is left to a contact model). h_min comes from the simulation's
 * min-separation model. For comparison with the blended Nijssen model; no tangential part.
 */
#include <math.h>
#include <stddef.h>

#include "models.h"

struct reynolds_params {
    double cutoff_ratio; /* h_co / R* [-] */
};

static const struct wetdem_param_desc reynolds_params_desc[] = {
    {"cutoff_ratio", "-", "Cut-off gap h_co as a multiple of R*.",
     offsetof(struct reynolds_params, cutoff_ratio), 1.0, 0, 100, true, false, NULL, false},
    {0},
};

/* Reynolds squeeze force 6 pi mu R*^2 v_n / h [N]. */
static double reynolds_force(double mu, double r_eff, double v_n, double h)
{
    return 6.0 * M_PI * mu * r_eff * r_eff * v_n / h;
}

static double reynolds_range(const void* params, const struct wetdem_contact* c)
{
    return ((const struct reynolds_params*)params)->cutoff_ratio * c->r_eff;
}

static int reynolds_pair(const void* params, const struct wetdem_contact* c, double* history,
                         struct wetdem_pair_force* out)
{
    (void)history;
    if (c->gap <= 0.0 || c->gap > reynolds_range(params, c))
        return WETDEM_OK;
    out->f_normal += reynolds_force(c->viscosity, c->r_eff, c->v_n, fmax(c->gap, c->h_min));
    return WETDEM_OK;
}

static size_t reynolds_thresholds(const void* params, const struct wetdem_contact* c,
                                  const double* history, double* gaps)
{
    (void)history;
    gaps[0] = reynolds_range(params, c);
    gaps[1] = c->h_min;
    gaps[2] = 0.0;
    return 3;
}

/* m* / c_d at h_min, c_d = 6 pi mu R*^2 / h_min (the law is held at h_min below it) [s]. */
static double reynolds_relaxation_time(const void* params, const struct wetdem_contact* c)
{
    (void)params;
    double c_d = reynolds_force(c->viscosity, c->r_eff, 1.0, fmax(c->h_min, 0.0));
    return viscous_relaxation_time(c->m_eff, c_d);
}

const struct wetdem_model wetdem_force_reynolds = {
    .name = "reynolds",
    .kind = WETDEM_MODEL_FLUID,
    .summary = "normal lubrication 6 pi mu R*^2 v_n / h of fully immersed spheres",
    .doc = "Leading-order Reynolds lubrication between two fully immersed spheres, "
           "F = 6 pi mu R*^2 v_n / max(h, h_min), acting for 0 < h <= cutoff_ratio R*. "
           "Repulsive when approaching, suction when separating; zero at solid overlap, so it "
           "jumps at h = 0 (from its h_min value) and at the cut-off. "
           "For comparison with the nijssen model, which blends it into Hertz contact.",
    .equations = "Nijssen 2023 Eq. 1 (with the h_min truncation of Eq. 8)",
    .params = reynolds_params_desc,
    .params_size = sizeof(struct reynolds_params),
    .range = reynolds_range,
    .pair = reynolds_pair,
    .thresholds = reynolds_thresholds,
    .relaxation_time = reynolds_relaxation_time,
};

/*
 * minsep_max.c — minimum separation "max": rough and deformable spheres stop at whichever
 * mechanism holds them further apart (Nijssen 2023 Eq. 6):
 *
 *     h_min = max(h_sigma, h_eps)      [m]
 *
 * h_sigma = (sigma_i + sigma_j)/2 (Eq. 3, minsep_roughness.c) and
 * h_eps = 0.37 R* (mu v0/(E* R*))^(2/5) (Eq. 5 corrected, minsep_ehd.c) with v0 the pair's
 * largest approach speed during the current interaction (h <= reset_ratio R*), kept in one
 * double of per-pair history. This is the h_min of the composite nijssen model, offered here
 * for the other fluid models. Validity: as for the two parts.
 */
#include <math.h>
#include <stdbool.h>
#include <stddef.h>

#include "minsep_ehd.h"
#include "models.h"

static const struct wetdem_param_desc max_params[] = {
    MINSEP_RESET_RATIO_PARAM,
    {0},
};

static double max_min_separation(const void* params, const struct wetdem_contact* c,
                                 double* history)
{
    return fmax(c->roughness, minsep_ehd_recorded_gap(params, c, history));
}

const struct wetdem_model wetdem_minsep_max = {
    .name = "max",
    .kind = WETDEM_MODEL_MIN_SEPARATION,
    .summary = "h_min = max(roughness, elastohydrodynamic gap)",
    .doc = "Minimum separation of rough, deformable spheres: h_min = max(h_sigma, h_eps) [m], "
           "with h_sigma = (sigma_i + sigma_j)/2 the mean roughness and "
           "h_eps = 0.37 R* (mu v0 / (E* R*))^(2/5) the elastohydrodynamic gap, v0 the largest "
           "normal approach speed of this pair during the current interaction "
           "(gap <= reset_ratio R*; forgotten beyond). One double of per-pair history. The "
           "same h_min as the composite nijssen model.",
    .equations = "Nijssen 2023 Eqs. 3, 5 (corrected), 6",
    .params = max_params,
    .params_size = sizeof(struct minsep_speed_params),
    .history_len = 1,
    .min_separation = max_min_separation,
    .record_range = minsep_speed_record_range,
};

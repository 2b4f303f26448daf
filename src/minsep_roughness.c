/*
 * minsep_roughness.c — minimum separation "roughness": rigid rough surfaces touch at the tops
 * of their asperities (Nijssen 2023 Eq. 3):
 *
 *     h_min = h_sigma = (sigma_i + sigma_j)/2      [m]
 *
 * sigma_i [m] the mean asperity height of material i; the contact already holds the mean
 * (wetdem_contact.roughness). Independent of the motion; no per-pair state.
 * Validity: rigid surfaces whose asperities are not flattened by the lubrication pressure.
 */
#include <stddef.h>

#include "models.h"

static const struct wetdem_param_desc roughness_params[] = {
    {0},
};

static double roughness_min_separation(const void* params, const struct wetdem_contact* c,
                                       double* history)
{
    (void)params;
    (void)history;
    return c->roughness;
}

const struct wetdem_model wetdem_minsep_roughness = {
    .name = "roughness",
    .kind = WETDEM_MODEL_MIN_SEPARATION,
    .summary = "h_min = mean roughness (sigma_i + sigma_j)/2 of the two surfaces",
    .doc = "Minimum separation of rigid rough surfaces, which touch at the tops of their "
           "asperities: h_min = (sigma_i + sigma_j)/2 [m] from the materials' roughness "
           "sigma. Independent of the motion. Valid while the asperities stay rigid; for soft "
           "smooth spheres see ehd, for both mechanisms see max.",
    .equations = "Nijssen 2023 Eq. 3",
    .params = roughness_params,
    .params_size = 0,
    .history_len = 0,
    .min_separation = roughness_min_separation,
};

/*
 * minsep_fixed.c — minimum separation "fixed": h_min is an input length [m], e.g. a measured
 * roughness or the h_m of Davis (2023) Table I. Reads no pair state.
 */
#include <math.h>
#include <stddef.h>

#include "models.h"

struct minsep_fixed_params {
    double h_min; /* [m] */
};

static const struct wetdem_param_desc fixed_params[] = {
    {"h_min", "m", "Minimum separation of the surfaces.",
     offsetof(struct minsep_fixed_params, h_min), 1e-6, 0, 1e-1, false, false, NULL, false},
    {0},
};

static double fixed_min_separation(const void* params, const struct wetdem_contact* c,
                                   double* history)
{
    (void)c;
    (void)history;
    return ((const struct minsep_fixed_params*)params)->h_min;
}

const struct wetdem_model wetdem_minsep_fixed = {
    .name = "fixed",
    .kind = WETDEM_MODEL_MIN_SEPARATION,
    .summary = "h_min is a fixed input length",
    .doc = "The minimum separation h_min [m] is given directly, e.g. from a measured surface "
           "roughness, or as the h_m of Davis (2023). Thin-film models switch to their "
           "below-h_min treatment there; the pairwise engine places hard contact there.",
    .equations = "Davis 2023 Sec. II (h_min input); Punch 2023 Eqs. 12-13 (use of h_min)",
    .params = fixed_params,
    .params_size = sizeof(struct minsep_fixed_params),
    .history_len = 0,
    .min_separation = fixed_min_separation,
};

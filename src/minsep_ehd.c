/*
 * minsep_ehd.c — minimum separation "ehd": smooth elastic spheres deform under the
 * lubrication pressure and keep a finite gap (Davis, Serayssol & Hinch 1986; Nijssen 2023
 * Eqs. 4-5 with the exponents corrected, SPEC §6, docs/derivations/fluid.md):
 *
 *     h_min = h_eps = 0.37 R* (mu v0 / (E* R*))^(2/5)       [m]
 *
 * mu [Pa s], E* [Pa], R* [m] and v0 [m/s] the largest normal approach speed the pair has had
 * during the current interaction (Nijssen: the highest approach velocity, for non-monotonic
 * motion). The interaction is h <= reset_ratio R*: beyond it the recorded speed is forgotten,
 * so a later encounter of the same pair starts afresh (one double of per-pair history). The
 * speed is the pair's own relative speed, not a particle property.
 * Validity: smooth surfaces, elasticity parameter eps << 1, Reynolds lubrication.
 */
#include <stdbool.h>
#include <stddef.h>

#include "minsep_ehd.h"
#include "models.h"

static const struct wetdem_param_desc ehd_params[] = {
    MINSEP_RESET_RATIO_PARAM,
    {0},
};

static double ehd_min_separation(const void* params, const struct wetdem_contact* c,
                                 double* history)
{
    return minsep_ehd_recorded_gap(params, c, history);
}

const struct wetdem_model wetdem_minsep_ehd = {
    .name = "ehd",
    .kind = WETDEM_MODEL_MIN_SEPARATION,
    .summary = "h_min = 0.37 R* (mu v0/(E* R*))^(2/5), elastohydrodynamic deformation",
    .doc = "Minimum separation of smooth elastic spheres that deform under the lubrication "
           "pressure: h_min = 0.37 R* (mu v0 / (E* R*))^(2/5) [m], Nijssen's Eq. 5 with the "
           "fifth root that dimensional analysis and Davis et al. (1986) require. v0 is the "
           "largest normal approach speed of this pair during the current interaction "
           "(gap <= reset_ratio R*); the record is forgotten when the pair moves beyond that "
           "gap. One double of per-pair history. Valid for small elasticity parameter "
           "eps = 4 mu v0 R*^(3/2) / (pi E* h0^(5/2)).",
    .equations = "Nijssen 2023 Eqs. 4-5 (exponents corrected); Davis et al. 1986",
    .params = ehd_params,
    .params_size = sizeof(struct minsep_speed_params),
    .history_len = 1,
    .min_separation = ehd_min_separation,
    .record_range = minsep_speed_record_range,
};

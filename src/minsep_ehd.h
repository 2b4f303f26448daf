/*
 * minsep_ehd.h — shared kernels of the velocity-dependent minimum separations (internal):
 * the elastohydrodynamic minimum gap of Nijssen 2023 Eq. 5 (root corrected to a fifth root,
 * SPEC §6; derivation in docs/derivations/fluid.md) and the per-pair record of the largest
 * approach speed that sets it, and the reset_ratio parameter of the two min-separation models
 * built on them. Used by minsep_ehd.c, minsep_max.c and force_nijssen.c.
 *
 *     h_eps = 0.37 ((mu v0 / E*)^2 R*^3)^(1/5) = 0.37 R* (mu v0 / (E* R*))^(2/5)     [m]
 *
 * mu [Pa s], v0 the approach speed [m/s] (>= 0), E* [Pa], R* [m]. From Davis et al. (1986):
 * h_eps ~ (1/3) h0 eps^(2/5) with eps = 4 mu v0 R*^(3/2) / (pi E* h0^(5/2)); h0 cancels.
 * Validity: smooth elastic spheres, eps << 1 (deformation small against the gap).
 */
#ifndef WETDEM_MINSEP_EHD_H
#define WETDEM_MINSEP_EHD_H

#include <math.h>
#include <stdbool.h>
#include <stddef.h>

#include "wetdem.h"

/* Elastohydrodynamic minimum gap 0.37 R* (mu v0/(E* R*))^(2/5) [m]; 0 for v0 <= 0. */
static inline double minsep_ehd_gap(double mu, double v0, double e_star, double r_eff)
{
    if (!(v0 > 0.0) || !(mu > 0.0))
        return 0.0;
    return 0.37 * r_eff * pow(mu * v0 / (e_star * r_eff), 0.4);
}

/* Largest approach speed of a pair [m/s]. *v_max (one double of history, 0 when fresh) holds
 * the largest v_n seen while the pair interacts; it is forgotten (set to 0) when the pair is
 * outside the interaction. Returns the speed to use now: max(*v_max, v_n, 0) inside,
 * max(v_n, 0) outside (the value the pair would record if it entered now). */
static inline double minsep_largest_speed(double* v_max, double v_n, bool is_interacting)
{
    double v = fmax(v_n, 0.0);
    if (!is_interacting) {
        *v_max = 0.0;
        return v;
    }
    if (v > *v_max)
        *v_max = v;
    return *v_max;
}

/* Parameters of the min-separation models whose h_min follows the recorded speed (ehd, max). */
struct minsep_speed_params {
    double reset_ratio; /* gap, as a multiple of R*, beyond which the speed record resets [-] */
};

/* Descriptor row of reset_ratio in struct minsep_speed_params. */
#define MINSEP_RESET_RATIO_PARAM                                                                   \
    {                                                                                              \
        "reset_ratio", "-",                                                                        \
            "Gap, as a multiple of R*, beyond which the pair's largest approach speed is "         \
            "forgotten.",                                                                          \
            offsetof(struct minsep_speed_params, reset_ratio), 1.0, 0, 100, true, false, NULL,     \
            false                                                                                  \
    }

/* h_eps [m] of the pair of contact c with v0 its largest approach speed during the current
 * interaction (gap <= reset_ratio R*), recorded in history[0] (minsep_largest_speed). */
static inline double minsep_ehd_recorded_gap(const struct minsep_speed_params* p,
                                             const struct wetdem_contact* c, double* history)
{
    bool is_interacting = c->gap <= p->reset_ratio * c->r_eff;
    double v0 = minsep_largest_speed(&history[0], c->v_n, is_interacting);
    return minsep_ehd_gap(c->viscosity, v0, c->e_star, c->r_eff);
}

/* The gap up to which the speed record lives, reset_ratio R* [m] (the record_range hook of
 * ehd and max: the engines keep the record there even beyond the force range). */
static inline double minsep_speed_record_range(const void* params, const struct wetdem_contact* c)
{
    return ((const struct minsep_speed_params*)params)->reset_ratio * c->r_eff;
}

#endif

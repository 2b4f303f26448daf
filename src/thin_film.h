/*
 * thin_film.h — shared logic of the thin-film (pendular) viscous models sb, db, davis and nase
 * (internal): where the law acts and at which gap it is evaluated (Punch 2023 Eqs. 12-13).
 *
 * For a pair with combined film thickness delta = delta_i + delta_j [m] (Punch's h_max) and
 * minimum separation h_min [m] from the simulation's min-separation model, a thin-film law
 * F_mod(v, h) is applied as
 *
 *     F = 0                      h > delta                 (films apart; Eqs. 12-13, line 1)
 *     F = F_mod(v, h)            h_min' <= h <= delta      (Eqs. 12-13, line 2)
 *     F = 0             ("c")    h < h_min'                (Eq. 12, line 3)
 *     F = F_mod(v, h_min') ("nc") h < h_min'               (Eq. 13, line 3)
 *
 * with h_min' = min(h_min, delta): the cap of Punch Eq. 14 (h_min = h_max when h_min >= h_max)
 * applied to whatever min-separation model is in use. The velocity v is always the current
 * one, so below h_min' the "nc" force still follows the relative velocity (and changes sign
 * with it: suction while separating). With h_min >= delta the evaluation gap is delta, where
 * the sb, db and davis laws vanish: those forces are zero throughout; nase does not vanish at
 * delta (see force_nase.c). A film of zero thickness gives no force. A law is never evaluated
 * at a gap <= 0: with h_min = 0 the "nc" form has no finite value at solid contact and the
 * force is zero there, as in "c".
 */
#ifndef WETDEM_THIN_FILM_H
#define WETDEM_THIN_FILM_H

#include <math.h>
#include <stdbool.h>
#include <stddef.h>

#include "wetdem.h"

/* Treatment below h_min: index of the word in thin_film_below_choices. */
enum thin_film_below {
    THIN_FILM_BELOW_C = 0,  /* zero (Punch Eq. 12, "constant") */
    THIN_FILM_BELOW_NC = 1, /* evaluated at h_min (Punch Eq. 13, "near-constant") */
};

static const char* const thin_film_below_choices[] = {"c", "nc", NULL};

/* Descriptor row of the "below_hmin" parameter of a params struct `type` with a double
 * field below_hmin. Default "c". */
#define THIN_FILM_BELOW_PARAM(type)                                                                \
    {                                                                                              \
        "below_hmin", "-",                                                                         \
            "Below h_min: c = force zero (Punch Eq. 12), nc = law evaluated at h_min (Eq. 13).",   \
            offsetof(type, below_hmin), THIN_FILM_BELOW_C, 0, 1, false, false,                     \
            thin_film_below_choices, false                                                         \
    }

/* h_min capped at the film thickness (Punch Eq. 14 cap) [m]. */
static inline double thin_film_h_min(double h_min, double delta)
{
    return fmin(h_min, delta);
}

/* Gap [m] at which a thin-film law is evaluated for gap h, capped minimum separation
 * hm = thin_film_h_min(h_min, delta) and film thickness delta (all [m]) with treatment `below`
 * (enum thin_film_below). Returns false when the force is zero (films apart, "c" below h_min,
 * no film, or no positive gap to use). */
static inline bool thin_film_eval_gap_at(double h, double hm, double delta, double below,
                                         double* h_eval)
{
    if (!(delta > 0.0) || h > delta)
        return false;
    if (h >= hm)
        *h_eval = h;
    else if ((int)below == THIN_FILM_BELOW_NC)
        *h_eval = hm;
    else
        return false;
    return *h_eval > 0.0;
}

/* The same with the minimum separation h_min [m] itself. */
static inline bool thin_film_eval_gap(double h, double h_min, double delta, double below,
                                      double* h_eval)
{
    return thin_film_eval_gap_at(h, thin_film_h_min(h_min, delta), delta, below, h_eval);
}

/* Range of a thin-film law: the film thickness delta [m]. The models' range hook. */
static inline double thin_film_range(const void* params, const struct wetdem_contact* c)
{
    (void)params;
    return c->film > 0.0 ? c->film : 0.0;
}

/* Branch gaps of a thin-film law: delta (on/off) and h_min' (c/nc switch). Returns 2. The
 * models' thresholds hook. */
static inline size_t thin_film_thresholds(const void* params, const struct wetdem_contact* c,
                                          const double* history, double* gaps)
{
    (void)history;
    gaps[0] = thin_film_range(params, c);
    gaps[1] = thin_film_h_min(c->h_min, gaps[0]);
    return 2;
}

/* Gap [m] at which a thin-film law damps most, h_min' = min(h_min, delta) (the laws grow
 * as the gap closes and are not evaluated below h_min'). Returns false when no film acts
 * (delta <= 0); *h = 0 when h_min' = 0, where the damping has no bound. */
static inline bool thin_film_stiffest_gap(const struct wetdem_contact* c, double* h)
{
    if (!(c->film > 0.0))
        return false;
    *h = fmax(thin_film_h_min(c->h_min, c->film), 0.0);
    return true;
}

#endif

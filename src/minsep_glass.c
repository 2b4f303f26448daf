/*
 * minsep_glass.c — minimum separation "glass": the lubrication pressure turns the film into a
 * glass, which then behaves as a solid contact (Donahue et al. 2010; Punch 2023 Eq. 14):
 *
 *     h_min = min( (3 mu a v / P_gt)^(1/2), delta )      [m]
 *
 * mu [Pa s], a = R* [m], v a normal approach speed [m/s], P_gt the glass-transition pressure
 * [Pa], delta = delta_i + delta_j [m] (Punch's h_max; the cap is Eq. 14's first line).
 * Dimensions: 3 mu a v / P_gt has units Pa s * m * m/s / Pa = m^2, so its square root is a
 * length. It is the gap at which the central Reynolds pressure 3 mu a v / h^2 reaches P_gt.
 *
 * Which speed: Punch says only "the normal velocity". Parameter `speed`:
 *   "max"     (default) the largest approach speed of the pair since its films overlapped:
 *             the pressure history sets the glass, and h_min never shrinks while the surfaces
 *             decelerate towards it;
 *   "initial" the approach speed when the films first overlapped (Punch's v_n,0 of Ca, St_n);
 *   "current" the instantaneous |v_n|.
 * History (3 doubles): [largest speed, speed at film overlap, 1 if recorded], reset to zero
 * whenever the films are apart (h > delta). Outside the film the value returned uses the
 * current approach speed max(v_n, 0) (|v_n| for "current"), i.e. what would be recorded if
 * the films overlapped now. Validity: viscous films with a glass transition (Punch Fig. 8:
 * P_gt = 11.6 MPa for 10 Pa s silicone oil and steel spheres).
 */
#include <math.h>
#include <stdbool.h>
#include <stddef.h>

#include "models.h"

enum glass_speed { GLASS_SPEED_MAX = 0, GLASS_SPEED_INITIAL = 1, GLASS_SPEED_CURRENT = 2 };

static const char* const glass_speed_choices[] = {"max", "initial", "current", NULL};

struct minsep_glass_params {
    double p_gt;  /* glass-transition pressure [Pa] */
    double speed; /* enum glass_speed */
};

static const struct wetdem_param_desc glass_params[] = {
    {"p_gt", "Pa", "Glass-transition pressure of the liquid (Punch Fig. 8d: 11.6 MPa).",
     offsetof(struct minsep_glass_params, p_gt), 11.6e6, 0, 1e12, true, false, NULL, false},
    {"speed", "-",
     "Normal speed setting h_min: max = largest approach speed since the films overlapped, "
     "initial = approach speed at film overlap, current = instantaneous |v_n|.",
     offsetof(struct minsep_glass_params, speed), GLASS_SPEED_MAX, 0, 2, false, false,
     glass_speed_choices, false},
    {0},
};

/* Glass-transition gap (3 mu a v / P_gt)^(1/2) [m], v >= 0. */
static double glass_gap(double mu, double a, double v, double p_gt)
{
    return sqrt(3.0 * mu * a * v / p_gt);
}

/* Updates the history and returns the speed that sets h_min [m/s]. */
static double glass_speed(int choice, double v_n, bool in_film, double* history)
{
    double v_approach = fmax(v_n, 0.0);
    if (!in_film) {
        history[0] = history[1] = history[2] = 0.0;
    } else {
        history[0] = fmax(history[0], v_approach);
        if (history[2] == 0.0) {
            history[1] = v_approach;
            history[2] = 1.0;
        }
    }
    switch (choice) {
    case GLASS_SPEED_CURRENT: return fabs(v_n);
    case GLASS_SPEED_INITIAL: return in_film ? history[1] : v_approach;
    default: return in_film ? history[0] : v_approach;
    }
}

static double glass_min_separation(const void* params, const struct wetdem_contact* c,
                                   double* history)
{
    const struct minsep_glass_params* p = params;
    double delta = fmax(c->film, 0.0);
    bool in_film = c->gap <= delta;
    double v = glass_speed((int)p->speed, c->v_n, in_film, history);
    return fmin(glass_gap(c->viscosity, c->r_eff, v, p->p_gt), delta);
}

/* The record lives while the films overlap: up to delta [m] (glass_min_separation's test). */
static double glass_record_range(const void* params, const struct wetdem_contact* c)
{
    (void)params;
    return fmax(c->film, 0.0);
}

const struct wetdem_model wetdem_minsep_glass = {
    .name = "glass",
    .kind = WETDEM_MODEL_MIN_SEPARATION,
    .summary = "h_min = min((3 mu a v / P_gt)^(1/2), delta), glass transition of the film",
    .doc = "Minimum separation set by the glass transition of a viscous film: the Reynolds "
           "pressure 3 mu a v / h^2 reaches the glass-transition pressure P_gt at "
           "h_min = (3 mu a v / P_gt)^(1/2) [m] (a = R*; 3 mu a v / P_gt is in m^2), capped "
           "at the combined film thickness delta. The speed v is chosen by `speed`: max "
           "(default) the largest approach speed since the films overlapped, initial the "
           "approach speed when they first overlapped, current the instantaneous |v_n|. The "
           "record (3 doubles of per-pair history) is cleared whenever the films are apart. "
           "Punch fitted P_gt = 11.6 MPa for 10 Pa s silicone oil on steel.",
    .equations = "Punch 2023 Eq. 14; Donahue et al. 2010",
    .params = glass_params,
    .params_size = sizeof(struct minsep_glass_params),
    .history_len = 3,
    .min_separation = glass_min_separation,
    .record_range = glass_record_range,
};

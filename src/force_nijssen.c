/*
 * force_nijssen.c — "nijssen": immersed lubrication blended continuously into Hertz–Mindlin
 * contact (Nijssen, Ottens & Padding 2023, Eqs. 1, 3-10; typos corrected per SPEC §6, see
 * docs/derivations/fluid.md). One composite model because its laws blend (STYLE §6.4).
 *
 * Minimum approach (Eqs. 3-6):   h_min = max(h_sigma, h_eps)                           [m]
 *     h_sigma = (sigma_i + sigma_j)/2 (contact.roughness),
 *     h_eps   = 0.37 R* (mu v0/(E* R*))^(2/5)  (Eq. 5 with the fifth root),
 *     v0 = the largest approach speed of this pair since it came within h_co (history).
 * Lubrication (Eqs. 1, 8):       F_l = 6 pi mu R*^2 v_n / max(h, h_min)                [N]
 * Contact (Eq. 7):               F_c = max(0, Hertz(delta) + damping(delta, v_n)),
 *                                delta = max(0, h_min - h), the hertz model's clipped law
 * Normal force (Eq. 9, lever weights as corrected):
 *     F_n = 0                                         h > h_co = cutoff_ratio R*
 *         = F_l                                       h_min < h <= h_co
 *         = (h/h_min) F_l + ((h_min - h)/h_min) F_c   0 < h <= h_min
 *         = F_c                                       h <= 0
 * Continuity: at h = h_min the lever gives 1 * F_l + 0 * F_c(delta = 0) = F_l(h_min), the
 * value of the lubrication branch (Hertz and its delta^(1/4) damping vanish at zero overlap);
 * at h = 0 it gives 0 * F_l + 1 * F_c(delta = h_min), the contact branch. The only jump is at
 * h_co, from F_l(h_co) = 6 pi mu R* v_n / cutoff_ratio to 0, as the paper states.
 * Tangential (Eq. 10): Mindlin spring on the shifted overlap delta, Coulomb coefficient
 *     mu_f = mu_dry if h_sigma >= h_eps (asperity contact) else mu_lub (a film remains),
 *     limited by mu_f w_c F_el(delta): the elastic load of the contact part of the blend
 *     (w_c the lever weight of F_c), as the mindlin model limits by the Hertz elastic force.
 * v_n > 0 approaching: F_l repulsive; separating: F_l is suction (attraction).
 * History (4 doubles): [v0, tangential spring x, y, z]. Both reset when the pair leaves
 * h_co, so each encounter of a pair starts with its own v0; v0 is a property of the pair's
 * relative motion, not of either particle.
 * Stored energy (the elastic_energy hook): the work of the elastic part of the blended contact,
 * w_c k delta^(3/2) with k = (4/3) E* sqrt(R*), from h up to h_min at the pair's h_min now
 * (d = h_min - h):
 *     E = 0                                                    h >= h_min
 *       = (2/7) k d^(7/2) / h_min                              0 < h < h_min
 *       = (2/7) k h_min^(5/2) + (2/5) k (d^(5/2) - h_min^(5/2)) h <= 0
 * For a constant h_min this is the potential of that force, so the budget's dissipated energy
 * is the work of the damping, lubrication and friction alone. h_min follows v0, which can grow
 * during an encounter: E then changes without work (by the change of the integral's bounds),
 * and the budget counts that change as dissipated (docs/many.md, Energy budget). Validity: immersed spheres, Reynolds lubrication
 * (small particle Reynolds number), St from about 1 to 10^4 (Nijssen Fig. 3).
 */
#include <math.h>
#include <stdbool.h>
#include <stddef.h>

#include "mindlin.h"
#include "minsep_ehd.h"
#include "models.h"
#include "vec3.h"

static const char* const nijssen_damping_choices[] = {"exact", "tsuji", NULL};

struct nijssen_params {
    double cutoff_ratio; /* h_co / R* [-] */
    double damping;      /* Hertz damping form: index into nijssen_damping_choices */
};

static const struct wetdem_param_desc nijssen_params_desc[] = {
    {"cutoff_ratio", "-", "Cut-off gap h_co as a multiple of R* (Nijssen: 1).",
     offsetof(struct nijssen_params, cutoff_ratio), 1.0, 0, 100, true, false, NULL, false},
    {"damping", "-",
     "Hertz damping from e_dry: exact = rebound with exactly e_dry, tsuji = the LIGGGHTS "
     "coefficient; both on the contact branch clipped at zero (unlike hertz.damping = tsuji).",
     offsetof(struct nijssen_params, damping), 0, 0, 1, false, false, nijssen_damping_choices,
     false},
    {0},
};

/* History slots. */
enum { HIST_V0 = 0, HIST_SPRING = 1, HIST_LEN = 4 };

/* Reynolds lubrication truncated at h_min, 6 pi mu R*^2 v_n / max(h, h_min) [N] (Eq. 8). */
static double lubrication_force(double mu, double r_eff, double v_n, double h, double h_min)
{
    return 6.0 * M_PI * mu * r_eff * r_eff * v_n / fmax(h, h_min);
}

/* Lever weights of Eq. 9: *w_l on F_l, *w_c on F_c (sum 1 in the blend zone). */
static void lever_weights(double h, double h_min, double* w_l, double* w_c)
{
    if (h > h_min) {
        *w_l = 1.0;
        *w_c = 0.0;
    } else if (h > 0.0) {
        *w_l = h / h_min;
        *w_c = (h_min - h) / h_min;
    } else {
        *w_l = 0.0;
        *w_c = 1.0;
    }
}

/* Hertz contact force on the shifted overlap, max(0, elastic + damping) [N] (Eq. 7), the
 * same clipped law as the hertz model, for which the "exact" damping gives e_dry. */
static double contact_force(const struct wetdem_contact* c, double overlap, int form)
{
    if (overlap <= 0.0)
        return 0.0;
    double f = wetdem_force_hertz_elastic(c->e_star, c->r_eff, overlap) +
               wetdem_force_hertz_damping(c->e_star, c->r_eff, c->m_eff, overlap, c->v_n,
                                          c->restitution, form);
    return fmax(f, 0.0);
}

static double nijssen_range(const void* params, const struct wetdem_contact* c)
{
    return ((const struct nijssen_params*)params)->cutoff_ratio * c->r_eff;
}

static void reset_history(double* history)
{
    for (int k = 0; k < HIST_LEN; k++)
        history[k] = 0.0;
}

static int nijssen_pair(const void* params, const struct wetdem_contact* c, double* history,
                        struct wetdem_pair_force* out)
{
    const struct nijssen_params* p = params;
    double h = c->gap;
    if (h > nijssen_range(params, c)) {
        reset_history(history);
        return WETDEM_OK;
    }
    if (!(c->restitution > 0.0 && c->restitution <= 1.0))
        return WETDEM_ERR_INVALID;
    double v0 = minsep_largest_speed(&history[HIST_V0], c->v_n, true);
    double h_eps = minsep_ehd_gap(c->viscosity, v0, c->e_star, c->r_eff);
    double h_min = fmax(c->roughness, h_eps);
    double overlap = fmax(0.0, h_min - h);
    double w_l, w_c;
    lever_weights(h, h_min, &w_l, &w_c);
    if (w_l > 0.0)
        out->f_normal += w_l * lubrication_force(c->viscosity, c->r_eff, c->v_n, h, h_min);
    if (w_c > 0.0)
        out->f_normal += w_c * contact_force(c, overlap, (int)p->damping);
    double mu_f = c->roughness >= h_eps ? c->friction_dry : c->friction_lub;
    double f_limit = w_c * wetdem_force_hertz_elastic(c->e_star, c->r_eff, overlap);
    struct wetdem_vec3 ft =
        wetdem_force_mindlin_update(c, overlap, f_limit, mu_f, &history[HIST_SPRING], &out->slip);
    wetdem_pair_force_add_tangential(out, c, ft);
    return WETDEM_OK;
}

/* h_min = max(h_sigma, h_eps) [m] of the pair's latest evaluation: v0 as pair() recorded it. */
static double recorded_h_min(const struct wetdem_contact* c, const double* history)
{
    double h_eps = minsep_ehd_gap(c->viscosity, fmax(history[HIST_V0], 0.0), c->e_star, c->r_eff);
    return fmax(c->roughness, h_eps);
}

/* Whether the contact part of the blend acts: w_c > 0 (h < h_min) within the range. */
static bool nijssen_is_in_contact(const void* params, const struct wetdem_contact* c,
                                  const double* history)
{
    return c->gap <= nijssen_range(params, c) && c->gap < recorded_h_min(c, history);
}

/* The work of the elastic part of the blended contact, w_c (4/3) E* sqrt(R*) delta^(3/2), from
 * the gap up to h_min at the recorded h_min [J] (header comment). */
static double nijssen_elastic_energy(const void* params, const struct wetdem_contact* c,
                                     const double* history)
{
    if (!nijssen_is_in_contact(params, c, history))
        return 0.0;
    double h = c->gap, h_min = recorded_h_min(c, history), d = h_min - h;
    double k = hertz_stiffness(c->e_star, c->r_eff);
    if (h > 0.0) /* integral of (d/h_min) k d^(3/2) */
        return 2.0 / 7.0 * k * d * d * d * sqrt(d) / h_min;
    double at_zero = h_min * h_min * sqrt(h_min); /* h_min^(5/2) */
    return 2.0 / 7.0 * k * at_zero + 0.4 * k * (d * d * sqrt(d) - at_zero);
}

static size_t nijssen_thresholds(const void* params, const struct wetdem_contact* c,
                                 const double* history, double* gaps)
{
    double v0 = fmax(fmax(history[HIST_V0], c->v_n), 0.0);
    double h_eps = minsep_ehd_gap(c->viscosity, v0, c->e_star, c->r_eff);
    gaps[0] = nijssen_range(params, c);
    gaps[1] = fmax(c->roughness, h_eps);
    gaps[2] = 0.0;
    return 3;
}

/* The shortest relaxation time m / c_d of the model's dampers at approach speed v0 = c->v_n
 * [s]: a fresh pair, h_min = max(h_sigma, h_eps(v0)).
 *   - lubrication (Eq. 8): c_d = 6 pi mu R*^2 / h_min, m = m*, largest at h_min (the lever
 *     blend below h_min weights it down by h/h_min);
 *   - the contact branch's Hertz dashpot (Eq. 7): c_d = c(e) sqrt(m* k) d^(1/4),
 *     k = (4/3) E* sqrt(R*), m = m*;
 *   - its Mindlin dashpot (Eq. 10): gamma_t = -2 sqrt(5/6) beta sqrt(m* k_t),
 *     k_t = 8 G* sqrt(R* d), m = (2/7) m* (a tangential force also spins both spheres).
 * Both contact dashpots grow with the shifted overlap d = h_min - h and act with the lever
 * weight w_c <= 1, so they are taken at the largest d of an undamped approach at v0: from the
 * stored energy of the header comment, (1/2) m* v0^2 = (2/7) k h_min^(5/2) +
 * (2/5) k (d^(5/2) - h_min^(5/2)), d_max^(5/2) = (5/4) m* v0^2 / k + (2/7) h_min^(5/2), which
 * also bounds d where the pair stops inside the blend. The exact c(e) grows as sqrt(5/(4 e)),
 * so for a small e_dry the Hertz dashpot, not the lubrication, sets this time (docs/many.md,
 * Time step), as in the hertz model. */
static double nijssen_relaxation_time(const void* params, const struct wetdem_contact* c)
{
    const struct nijssen_params* p = params;
    double v0 = fmax(c->v_n, 0.0), m = c->m_eff;
    double h_eps = minsep_ehd_gap(c->viscosity, v0, c->e_star, c->r_eff);
    double h_min = fmax(c->roughness, h_eps);
    double tau =
        viscous_relaxation_time(m, lubrication_force(c->viscosity, c->r_eff, 1.0, h_min, h_min));
    double k = hertz_stiffness(c->e_star, c->r_eff);
    if (!(v0 > 0.0 && k > 0.0 && m > 0.0 && c->restitution > 0.0 && c->restitution < 1.0))
        return tau;
    double d = pow(1.25 * m * v0 * v0 / k + 2.0 / 7.0 * h_min * h_min * sqrt(h_min), 0.4);
    double coef = wetdem_force_hertz_damping_coefficient(c->restitution, (int)p->damping);
    double c_n = hertz_damping_k(coef, k, m, d, 1.0); /* (the force at unit speed) */
    double c_t = tangential_damping(tangential_stiffness(c->g_star, c->r_eff, d), m,
                                    wetdem_force_mindlin_damping_factor(c->restitution));
    tau = fmin(tau, viscous_relaxation_time(m, c_n));
    return fmin(tau, viscous_relaxation_time(2.0 / 7.0 * m, c_t));
}

const struct wetdem_model wetdem_force_nijssen = {
    .name = "nijssen",
    .kind = WETDEM_MODEL_FLUID,
    .summary = "immersed lubrication with minimum approach, lever blend into Hertz-Mindlin",
    .doc = "Lubrication model of Nijssen et al. for immersed spheres in unresolved DEM, with "
           "its own Hertz-Mindlin contact (hertz, hooke or mindlin beside it are refused). Minimum "
           "approach h_min = max(h_sigma, h_eps): mean roughness (sigma_i + sigma_j)/2 or the "
           "elastohydrodynamic gap 0.37 R* (mu v0/(E* R*))^(2/5), v0 being the largest "
           "approach speed of this pair since it came within the cut-off (per-pair history, "
           "reset when the pair leaves it). Normal force: Reynolds lubrication 6 pi mu R*^2 "
           "v_n / max(h, h_min) for h_min < h <= h_co = cutoff_ratio R* (suction when "
           "separating); for h <= 0 Hertz contact with damping from e_dry (clipped at zero, "
           "as the hertz model) on the overlap shifted by h_min, delta = max(0, h_min - h); "
           "in between the lever blend (h/h_min) F_l + ((h_min - h)/h_min) F_c, continuous at "
           "h_min and at 0; the force jumps only at h_co. Tangential: Mindlin spring on the "
           "shifted overlap with friction mu_dry when h_sigma >= h_eps (asperity contact), "
           "else mu_lub (a film remains), limited by mu times the elastic load of the contact "
           "part. The simulation's min-separation model is not used by this model. A pair "
           "whose h_min at its approach speed reaches h_co would meet the solid force at the "
           "cut-off; it is refused when the run starts (lower the roughness, raise E or "
           "cutoff_ratio). Validated "
           "by Nijssen against Yang & Hunt for St ~ 1 to 10^4.",
    .equations = "Nijssen 2023 Eqs. 1, 3-10 (Eq. 5 fifth root; Eq. 9 lever weights)",
    .params = nijssen_params_desc,
    .params_size = sizeof(struct nijssen_params),
    .history_len = HIST_LEN,
    .range = nijssen_range,
    .pair = nijssen_pair,
    .thresholds = nijssen_thresholds,
    .contact_time = hertz_contact_time_hook, /* of the contact branch */
    .relaxation_time = nijssen_relaxation_time,
    .elastic_energy = nijssen_elastic_energy,
    .is_in_contact = nijssen_is_in_contact,
};

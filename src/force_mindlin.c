/*
 * force_mindlin.c — "mindlin": tangential contact force with a history spring and a Coulomb
 * limit (Mindlin 1949; Di Renzo & Di Maio 2004; LIGGGHTS `tangential_model history`), and the
 * shared kernel wetdem_force_mindlin_update that the nijssen model reuses on its shifted
 * overlap. Derivation and conventions: docs/derivations/contact.md Sec. 2.
 *
 * Per pair the history holds the elastic tangential displacement s [m] (3 doubles). At each
 * evaluation, with overlap delta > 0, unit normal n (j to i) and tangential surface velocity
 * v_t of i relative to j (struct wetdem_contact):
 *   1. s is rotated into the current tangent plane: s <- |s| (s - (s.n) n)/|s - (s.n) n|;
 *   2. s <- s + v_s dt          (dt = c->dt; v_s = v_t + c->dv_t_spring, the engines'
 *                                 mean of the slip over dt: docs/engines.md)
 *   3. k_t = 8 G* sqrt(R* delta)                            [N/m]
 *      gamma_t = -2 sqrt(5/6) beta sqrt(m* k_t),  beta = ln e / sqrt(ln^2 e + pi^2)   [kg/s]
 *   4. F_t = -k_t s - gamma_t v_t (spring and dashpot); if |F_t| > mu F_lim (sliding), the
 *      total is capped, F_t <- F_t mu F_lim / |F_t|, and the spring is set to what gives
 *      the capped total with this dashpot, s <- -(F_t + gamma_t v_t) / k_t.
 * The slip margin |F_t| - mu F_lim before the cap goes to struct wetdem_pair_force slip (the
 * adaptive engine locates the stick-slip transitions with it).
 * So |F_t| <= mu F_lim at every evaluation (Coulomb), as LAMMPS pair granular does, and the
 * stored spring is consistent with the force (re-evaluating the same state with dt = 0 gives
 * the same F_t). LIGGGHTS compares only the spring with the limit, which lets a sticking
 * dashpot carry |F_t| far above mu F_lim at small overlaps; contact.md Sec. 2 shows the
 * violations (up to 3.7 mu F_lim in oblique collisions at 5-20 deg) and why the cap is kept.
 * F_lim is the Hertz elastic normal force (4/3) E* sqrt(R*) delta^(3/2) for this model
 * (LIGGGHTS takes the total normal force, damping included; models do not read each other's
 * force here, and the elastic part stays positive while unloading).
 * Beside a linear normal law (c->linear_stiffness = k > 0, which the engines fill in from the
 * enabled contact model's linear_stiffness hook: hooke) the spring is its linear counterpart
 * (contact.md Sec. 3.1): F_lim = k delta, hooke's elastic force, and in step 3
 *      k_t = (4 G* / E*) k                                      [N/m]
 * the ratio k_t / k_n = 8 G* a / (2 E* a) of Hertz-Mindlin (a the contact radius), with the
 * same gamma_t formula; so friction is bounded by mu times hooke's elastic force, not by a
 * Hertz force of the same overlap (many times larger for a soft k). LIGGGHTS projects s into
 * the plane without restoring its length; here the length is kept (rigid rotation).
 * delta <= 0 resets s to zero and gives no force. The damping is the normal Tsuji form with
 * k_t in place of S_n = 2 E* sqrt(R* delta) (as LIGGGHTS): the tangential restitution of a
 * Mindlin contact depends on the impact angle and mu, so no "exact" value exists.
 * Validity: small overlaps, no micro-slip inside the contact (no Mindlin-Deresiewicz
 * hysteresis), mu >= 0, e in (0, 1]. Units SI.
 */
#include <math.h>
#include <stddef.h>

#include "mindlin.h"
#include "models.h"
#include "vec3.h"

struct mindlin_params {
    double friction; /* index into friction_choices: 0 dry, 1 lubricated */
};

static const char* const friction_choices[] = {"dry", "lubricated", NULL};

static const struct wetdem_param_desc mindlin_params_desc[] = {
    {"friction", "-",
     "Which Coulomb coefficient of the pair limits the tangential force: dry "
     "(material friction_dry) or lubricated (material friction_lub).",
     offsetof(struct mindlin_params, friction), 0, 0, 1, false, false, friction_choices, false},
    {0},
};

double wetdem_force_mindlin_damping_factor(double restitution)
{
    double l = log(restitution);
    double beta = l / sqrt(l * l + M_PI * M_PI);
    return -2.0 * sqrt(5.0 / 6.0) * beta;
}

struct wetdem_vec3 wetdem_force_mindlin_update(const struct wetdem_contact* c, double overlap,
                                               double f_limit, double mu, double* spring,
                                               double* slip)
{
    double factor = overlap > 0.0 ? wetdem_force_mindlin_damping_factor(c->restitution) : 0.0;
    return wetdem_force_mindlin_update_with(c, overlap, f_limit, mu, factor, spring, slip);
}

struct wetdem_vec3 wetdem_force_mindlin_update_with(const struct wetdem_contact* c, double overlap,
                                                    double f_limit, double mu,
                                                    double damping_factor, double* spring,
                                                    double* slip)
{
    struct wetdem_vec3 v_s = vec3_add(c->v_t, c->dv_t_spring);
    return mindlin_spring(c->normal, c->v_t, v_s, c->dt, c->g_star, c->r_eff, c->m_eff, overlap,
                          f_limit, mu, damping_factor, spring, slip);
}

static int mindlin_pair(const void* params, const struct wetdem_contact* c, double* history,
                        struct wetdem_pair_force* out)
{
    const struct mindlin_params* p = params;
    if (!(c->restitution > 0.0 && c->restitution <= 1.0))
        return WETDEM_ERR_INVALID;
    double overlap = -c->gap;
    double mu = p->friction == 0 ? c->friction_dry : c->friction_lub;
    /* beside a linear normal law its linear counterpart, else Hertz-Mindlin (the operations of
       wetdem_force_mindlin_update, bit for bit) */
    double k = c->linear_stiffness;
    double k_t = !(overlap > 0.0) ? 0.0
                 : k > 0.0        ? linear_tangential_stiffness(c->g_star, c->e_star, k)
                                  : tangential_stiffness(c->g_star, c->r_eff, overlap);
    double f_limit =
        k > 0.0 ? k * overlap : wetdem_force_hertz_elastic(c->e_star, c->r_eff, overlap);
    double factor = overlap > 0.0 ? wetdem_force_mindlin_damping_factor(c->restitution) : 0.0;
    struct wetdem_vec3 ft =
        mindlin_spring_k(c->normal, c->v_t, vec3_add(c->v_t, c->dv_t_spring), c->dt, k_t, c->m_eff,
                         overlap, f_limit, mu, factor, history, &out->slip);
    if (overlap > 0.0)
        wetdem_pair_force_add_tangential(out, c, ft);
    return WETDEM_OK;
}

/* Relaxation time (2/7) m* / gamma_t of the tangential dashpot [s]: a tangential force also
 * spins both spheres, so the slip velocity relaxes with the mass (2/7) m* (docs/many.md, Viscous
 * relaxation time), gamma_t = -2 sqrt(5/6) beta sqrt(m* k_t). Beside a linear normal law k_t =
 * 4 G* k / E* at every overlap; for Hertz-Mindlin k_t = 8 G* sqrt(R* delta) is taken at the
 * largest overlap of an undamped head-on impact at c->v_n, delta_max = (5 m* v_n^2 / (4 k))^(2/5)
 * with k = (4/3) E* sqrt(R*), where it is largest (as the hertz model's own time). Written as
 * (2/7) sqrt(m* / k_t) / factor so that m* k_t cannot overflow. INFINITY without damping
 * (e_dry = 1) and, for Hertz-Mindlin, without approach speed. */
static double mindlin_relaxation_time(const void* params, const struct wetdem_contact* c)
{
    (void)params;
    if (!(c->restitution > 0.0 && c->restitution < 1.0 && c->m_eff > 0.0))
        return INFINITY;
    double k = c->linear_stiffness, k_t;
    if (k > 0.0) {
        k_t = linear_tangential_stiffness(c->g_star, c->e_star, k);
    } else {
        double k_hertz = hertz_stiffness(c->e_star, c->r_eff), v = c->v_n;
        if (!(v > 0.0 && k_hertz > 0.0))
            return INFINITY;
        k_t = tangential_stiffness(c->g_star, c->r_eff, hertz_impact_overlap(c->m_eff, v, k_hertz));
    }
    double factor = wetdem_force_mindlin_damping_factor(c->restitution);
    if (!(k_t > 0.0 && factor > 0.0))
        return INFINITY;
    return 2.0 / 7.0 * sqrt(c->m_eff / k_t) / factor;
}

const struct wetdem_model wetdem_force_mindlin = {
    .name = "mindlin",
    .kind = WETDEM_MODEL_CONTACT,
    .summary = "Mindlin tangential spring with history, damping and a Coulomb limit",
    .doc = "Tangential solid contact for overlap delta = -h > 0, after LIGGGHTS tangential "
           "history. Per pair the elastic tangential displacement s [m] is kept; each "
           "evaluation rotates it into the current tangent plane (length kept, where LIGGGHTS "
           "projects it), adds v_s dt with v_s the tangential slip over the step (its "
           "midpoint in the fixed-step engines, second order; in CVODE the increment of the "
           "integral of v_t it integrates under its error control, with the stick-slip "
           "transitions located), "
           "and gives F_t = -k_t s - gamma_t v_t with k_t = 8 G* sqrt(R* delta) and "
           "gamma_t = -2 sqrt(5/6) beta sqrt(m* k_t), beta = ln e / sqrt(ln^2 e + pi^2) (the "
           "normal Tsuji damping with k_t). If this total, spring and dashpot, exceeds "
           "mu F_el = mu (4/3) E* sqrt(R*) delta^(3/2) (the Hertz elastic normal force, where "
           "LIGGGHTS takes the total normal force), the contact slides: F_t is scaled down to "
           "|F_t| = mu F_el and s is set so that -k_t s - gamma_t v_t gives that force, as "
           "LAMMPS pair granular does. So Coulomb's |F_t| <= mu F_el holds at every "
           "evaluation; LIGGGHTS compares only the spring, which lets a sticking dashpot exceed "
           "the limit many times at small overlaps. Separation (delta <= 0) resets s. The force "
           "acts at the contact point "
           "and gives torques on both spheres. Beside hooke (a linear normal spring k) it is the "
           "linear counterpart: k_t = (4 G*/E*) k, the Hertz-Mindlin ratio of tangential to "
           "normal stiffness, the same gamma_t formula, and the limit mu k delta (hooke's "
           "elastic force), so Coulomb's law holds against hooke's normal force; the engines "
           "pass hooke's current k to it. mu is the pair's dry or "
           "lubricated coefficient (parameter friction). Valid for small overlaps; no "
           "micro-slip hysteresis inside the contact area.",
    .equations = "tangential part of Punch 2023 Eq. 6 (Hertz-Mindlin as in LIGGGHTS); the "
                 "friction switch of Nijssen 2023 Eq. 10 selects mu; Mindlin 1949; Di Renzo "
                 "& Di Maio 2004; beside hooke the linear history model (LIGGGHTS hooke/"
                 "history) with k_t/k_n of Hertz-Mindlin; docs/derivations/contact.md",
    .params = mindlin_params_desc,
    .params_size = sizeof(struct mindlin_params),
    .history_len = 3,
    .range = contact_only_range,
    .pair = mindlin_pair,
    .thresholds = contact_only_thresholds,
    .relaxation_time = mindlin_relaxation_time,
    /* no elastic_energy: the spring's k_t |s|^2 / 2 is no potential (k_t follows the overlap,
       so its work depends on the path, and sliding resets s) */
    .is_in_contact = contact_only_is_in_contact,
};

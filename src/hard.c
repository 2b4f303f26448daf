/*
 * hard.c — "hard": instantaneous hard-sphere collision with restitution and Coulomb friction,
 * Davis (2023) Appendix A (Eqs. A1-A36) written for two bodies of any mass, radius and
 * moment of inertia in 3-D vector form. Derivation: docs/derivations/contact.md Sec. 4.
 *
 * Bodies i and j touch at a point; n is the unit normal from j to i, so the contact point is
 * at -R_i n from i's centre and at +R_j n from j's. The impulse on i is J = J_n n + J_t
 * (j receives -J). The relative velocity of i's surface with respect to j's there is
 *   u = (v_i + w_i x (-R_i n)) - (v_j + w_j x (R_j n)),   v_n = -u.n (> 0 approaching),
 *   computed as -(v_i - v_j).n since w x n is normal to n,
 *   u_t = u - (u.n) n                                       (the slip velocity).
 * The impulse changes u by  du = J/m* + (R_i^2/I_i + R_j^2/I_j) J_t,  so
 *   normal (A1-A3):     J_n = m* (1 + e) v_n,               after: v_n' = -e v_n
 *   sticking (A30-A35): J_t = -m_t u_t,  1/m_t = 1/m_i + 1/m_j + R_i^2/I_i + R_j^2/I_j,
 *                       after: u_t' = 0 (rolling without slip)
 *   sliding (A8-A11):   J_t = -mu J_n u_t/|u_t|,
 *                       after: u_t' = u_t (1 - mu J_n / (m_t |u_t|))
 * sticking if m_t |u_t| <= mu J_n (A36; at equality both rules give the same impulse).
 * Velocities: v_i += J/m_i, v_j -= J/m_j, w_i += (-R_i n) x J / I_i,
 * w_j += (R_j n) x (-J) / I_j.
 * For equal solid spheres (m_i = m_j = 2m, R = 2a, I = 16 m a^2/5) m_t = 2m/7: A33-A36.
 * A body with infinite mass is immovable (a wall: radius INFINITY as well, and its surface
 * velocity is its translation velocity); its 1/m and R^2/I terms are zero.
 * Validity: instantaneous contact (contact time << every other time scale), constant e and
 * mu, no rolling or twisting resistance. Units SI.
 */
#include <math.h>
#include <stddef.h>

#include "models.h"
#include "vec3.h"

struct hard_params {
    double friction; /* index into friction_choices: 0 dry, 1 lubricated */
};

static const char* const friction_choices[] = {"dry", "lubricated", NULL};

static const struct wetdem_param_desc hard_params_desc[] = {
    {"friction", "-",
     "Which Coulomb coefficient of the pair the engine passes to the impulse: dry "
     "(material friction_dry) or lubricated (material friction_lub, Davis's mu_f).",
     offsetof(struct hard_params, friction), 1, 0, 1, false, false, friction_choices, false},
    {0},
};

static bool is_immovable(const struct wetdem_impulse_body* b)
{
    return isinf(b->mass);
}

/* Finite velocities, m > 0, R > 0 and I > 0; an immovable body's inertia is not used, and
 * only an immovable body may be a plane (R = INFINITY). A movable body's 1/m and R^2/I must be
 * finite: a mass or inertia near the least double made them infinite and the velocities NaN. */
static bool body_is_valid(const struct wetdem_impulse_body* b)
{
    if (!vec3_is_finite(b->vel) || !vec3_is_finite(b->omega))
        return false;
    if (!(b->mass > 0.0) || !(b->radius > 0.0))
        return false;
    if (is_immovable(b))
        return true;
    return b->inertia > 0.0 && !isinf(b->radius) && isfinite(1.0 / b->mass) &&
           isfinite(b->radius * b->radius / b->inertia);
}

/* Velocity of body b's surface at the contact point, which lies at R n_out from its centre. */
static struct wetdem_vec3 surface_velocity(const struct wetdem_impulse_body* b,
                                           struct wetdem_vec3 n_out)
{
    if (isinf(b->radius))
        return b->vel;
    return vec3_add(b->vel, vec3_cross(b->omega, vec3_scale(n_out, b->radius)));
}

/* 1/m [1/kg] and R^2/I [1/kg] of one body; zero for an immovable one. */
static double inverse_mass(const struct wetdem_impulse_body* b)
{
    return is_immovable(b) ? 0.0 : 1.0 / b->mass;
}

static double inverse_rotational_mass(const struct wetdem_impulse_body* b)
{
    return is_immovable(b) ? 0.0 : b->radius * b->radius / b->inertia;
}

/* Applies impulse J at the contact point R n_out of body b (n_out points from its centre). */
static void apply_impulse(struct wetdem_impulse_body* b, struct wetdem_vec3 n_out,
                          struct wetdem_vec3 impulse)
{
    if (is_immovable(b))
        return;
    b->vel = vec3_axpy(b->vel, 1.0 / b->mass, impulse);
    struct wetdem_vec3 dl = vec3_cross(vec3_scale(n_out, b->radius), impulse);
    b->omega = vec3_axpy(b->omega, 1.0 / b->inertia, dl);
}

static bool inputs_are_valid(const struct wetdem_impulse_body* bi,
                             const struct wetdem_impulse_body* bj, struct wetdem_vec3 normal,
                             double restitution, double friction)
{
    if (!body_is_valid(bi) || !body_is_valid(bj) || (is_immovable(bi) && is_immovable(bj)))
        return false;
    if (!vec3_is_finite(normal) || !(fabs(vec3_norm(normal) - 1.0) <= 1e-9))
        return false;
    return restitution > 0.0 && restitution <= 1.0 && friction >= 0.0 && isfinite(friction);
}

/* Tangential impulse on i for slip u_t (A30-A36): arrests the slip when that needs at most
 * mu J_n, else slides with |J_t| = mu J_n against the slip. */
static struct wetdem_vec3 tangential_impulse(struct wetdem_vec3 u_t, double m_t, double j_n,
                                             double mu, bool* is_sticking)
{
    double slip = vec3_norm(u_t);
    *is_sticking = m_t * slip <= mu * j_n;
    if (*is_sticking)
        return vec3_scale(u_t, -m_t);
    return vec3_scale(u_t, -mu * j_n / slip);
}

int wetdem_hard_impulse(struct wetdem_impulse_body* bi, struct wetdem_impulse_body* bj,
                        struct wetdem_vec3 normal, double restitution, double friction,
                        struct wetdem_impulse_result* result)
{
    if (result)
        *result = (struct wetdem_impulse_result){0};
    if (!inputs_are_valid(bi, bj, normal, restitution, friction))
        return WETDEM_ERR_INVALID;
    struct wetdem_vec3 n = normal, n_i = vec3_neg(normal);
    struct wetdem_vec3 u = vec3_sub(surface_velocity(bi, n_i), surface_velocity(bj, n));
    /* -u.n without the spin terms, which are normal to n: their rounding (eps |w R|) would
     * make spinning spheres at rest approach, and a slow approach under fast spin inexact */
    double v_n = -vec3_dot(vec3_sub(bi->vel, bj->vel), n);
    if (!(v_n > 0.0))
        return WETDEM_OK;
    double inv_m = inverse_mass(bi) + inverse_mass(bj);
    double inv_mt = inv_m + inverse_rotational_mass(bi) + inverse_rotational_mass(bj);
    double j_n = (1.0 + restitution) * v_n / inv_m;
    bool is_sticking;
    struct wetdem_vec3 j_t =
        tangential_impulse(vec3_reject(u, n), 1.0 / inv_mt, j_n, friction, &is_sticking);
    struct wetdem_vec3 impulse = vec3_axpy(j_t, j_n, n);
    struct wetdem_impulse_body after_i = *bi, after_j = *bj;
    apply_impulse(&after_i, n_i, impulse);
    apply_impulse(&after_j, n, vec3_neg(impulse));
    if (!vec3_is_finite(impulse) || !vec3_is_finite(after_i.vel) ||
        !vec3_is_finite(after_i.omega) || !vec3_is_finite(after_j.vel) ||
        !vec3_is_finite(after_j.omega)) /* speeds near the largest double: left as they were */
        return WETDEM_ERR_NUMERIC;
    *bi = after_i;
    *bj = after_j;
    if (result)
        *result = (struct wetdem_impulse_result){j_n, j_t, is_sticking};
    return WETDEM_OK;
}

const struct wetdem_model wetdem_hard_model = {
    .name = "hard",
    .kind = WETDEM_MODEL_IMPULSE,
    .summary = "hard-sphere impulse: normal reversal with e_dry and Coulomb friction impulse",
    .doc = "Instantaneous solid contact for the pairwise engine (wetdem_hard_impulse). The "
           "normal relative velocity of the contact point is reversed and scaled by e_dry, "
           "J_n = m* (1 + e_dry) v_n. Friction acts on the slip velocity u_t of the contact "
           "point (including spin): if the impulse m_t |u_t| that stops the slip, with "
           "1/m_t = 1/m_i + 1/m_j + R_i^2/I_i + R_j^2/I_j, is at most mu J_n, the surfaces "
           "leave rolling without slip (sticking); otherwise the tangential impulse is "
           "mu J_n against the slip (sliding) and the slip keeps its direction. Linear "
           "momentum is conserved, and angular momentum for touching spheres (at a gap h, "
           "with the lever arms R_i and R_j, it changes by h n x J_t). For equal solid "
           "spheres m_t = 2 m*/7 (Davis's A33-A36). Walls: mass and radius INFINITY. mu is "
           "the pair's dry or lubricated coefficient (parameter friction; Davis uses the "
           "lubricated one). Valid when the solid contact time is far shorter than the "
           "other time scales of the collision.",
    .equations = "Davis 2023 Appendix A, Eqs. A1-A3 (normal), A8-A11 (sliding; A11 with I_j "
                 "for omega_j), A30-A36 (arrest of slip), generalised to unequal spheres in "
                 "3-D in docs/derivations/contact.md",
    .params = hard_params_desc,
    .params_size = sizeof(struct hard_params),
    .history_len = 0,
};

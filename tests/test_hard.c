/*
 * test_hard.c — hard-sphere impulses (wetdem_hard_impulse, Davis 2023 Appendix A in 3-D):
 * conservation of linear and angular momentum, normal reversal with e_dry, the sticking /
 * sliding switch exactly at the A36 threshold, Davis's A9-A11 and A33-A35 for equal spheres,
 * i<->j symmetry for unequal spheres, walls and fixed spheres, invalid input and separating
 * pairs.
 */
#include <stdbool.h>

#include "harness.h"
#include "test_vec.h"
#include "models.h"

/* A solid sphere, I = 2/5 m R^2. */
static struct wetdem_impulse_body sphere(double m, double r, struct wetdem_vec3 v,
                                         struct wetdem_vec3 w)
{
    return (struct wetdem_impulse_body){v, w, m, r, 0.4 * m * r * r};
}

static struct wetdem_impulse_body wall(void)
{
    return (struct wetdem_impulse_body){v3(0, 0, 0), v3(0, 0, 0), INFINITY, INFINITY, INFINITY};
}

/* Relative velocity of i's surface with respect to j's at the contact point. */
static struct wetdem_vec3 contact_velocity(const struct wetdem_impulse_body* bi,
                                           const struct wetdem_impulse_body* bj,
                                           struct wetdem_vec3 n)
{
    struct wetdem_vec3 ui = add(bi->vel, cross(bi->omega, scale(n, -bi->radius)));
    struct wetdem_vec3 uj =
        isinf(bj->radius) ? bj->vel : add(bj->vel, cross(bj->omega, scale(n, bj->radius)));
    return sub(ui, uj);
}

static struct wetdem_vec3 tangential(struct wetdem_vec3 u, struct wetdem_vec3 n)
{
    return sub(u, scale(n, dot(u, n)));
}

/* Total linear momentum and angular momentum about the origin; the centres are at
 * x_c + R_i n and x_c - R_j n around the contact point x_c. */
static void momenta(const struct wetdem_impulse_body* bi, const struct wetdem_impulse_body* bj,
                    struct wetdem_vec3 n, struct wetdem_vec3 x_c, struct wetdem_vec3* p,
                    struct wetdem_vec3* l)
{
    struct wetdem_vec3 xi = add(x_c, scale(n, bi->radius)), xj = sub(x_c, scale(n, bj->radius));
    *p = add(scale(bi->vel, bi->mass), scale(bj->vel, bj->mass));
    *l = add(add(cross(xi, scale(bi->vel, bi->mass)), scale(bi->omega, bi->inertia)),
             add(cross(xj, scale(bj->vel, bj->mass)), scale(bj->omega, bj->inertia)));
}

/* Unequal spheres in an oblique 3-D configuration (used by several tests). */
static void oblique_pair(struct wetdem_impulse_body* bi, struct wetdem_impulse_body* bj,
                         struct wetdem_vec3* n)
{
    *n = unit(v3(0.6, -0.3, 0.74));
    *bi = sphere(0.3, 0.02, v3(-1.2, 0.7, -0.9), v3(20, -35, 12));
    *bj = sphere(1.1, 0.035, v3(0.4, -0.2, 0.5), v3(-8, 4, 30));
}

static void test_hard_conserves_momentum(void** state)
{
    (void)state;
    const double mus[] = {0.02, 5.0}; /* sliding, sticking */
    for (int k = 0; k < 2; k++) {
        struct wetdem_impulse_body bi, bj;
        struct wetdem_vec3 n, p0, l0, p1, l1, x_c = v3(0.3, -0.2, 0.1);
        oblique_pair(&bi, &bj, &n);
        momenta(&bi, &bj, n, x_c, &p0, &l0);
        struct wetdem_impulse_result r;
        CHECK_OK(wetdem_hard_impulse(&bi, &bj, n, 0.7, mus[k], &r));
        assert_int_equal(r.is_sticking, k == 1);
        momenta(&bi, &bj, n, x_c, &p1, &l1);
        /* 1e-14 of the momentum scale: the update is a few roundings per component */
        double ps = 1.1 * 1.0, ls = 0.5 * ps;
        CHECK_ABS(p1.x, p0.x, 1e-14 * ps);
        CHECK_ABS(p1.y, p0.y, 1e-14 * ps);
        CHECK_ABS(p1.z, p0.z, 1e-14 * ps);
        CHECK_ABS(l1.x, l0.x, 1e-14 * ls);
        CHECK_ABS(l1.y, l0.y, 1e-14 * ls);
        CHECK_ABS(l1.z, l0.z, 1e-14 * ls);
        /* the impulse changed something: the check is not vacuous */
        assert_true(r.impulse_normal > 0.1 && norm(r.impulse_tan) > 1e-3);
    }
}

static void test_hard_reverses_normal_velocity_with_e(void** state)
{
    (void)state;
    const double mus[] = {0.02, 5.0};
    for (int k = 0; k < 2; k++) {
        struct wetdem_impulse_body bi, bj;
        struct wetdem_vec3 n;
        oblique_pair(&bi, &bj, &n);
        double vn0 = -dot(contact_velocity(&bi, &bj, n), n);
        assert_true(vn0 > 0.0);
        struct wetdem_impulse_result r;
        CHECK_OK(wetdem_hard_impulse(&bi, &bj, n, 0.7, mus[k], &r));
        double vn1 = -dot(contact_velocity(&bi, &bj, n), n);
        CHECK_REL(vn1, -0.7 * vn0, 1e-14); /* roundings only */
        /* J_n = m* (1 + e) v_n, m* = 0.3 * 1.1 / 1.4 */
        CHECK_REL(r.impulse_normal, 0.3 * 1.1 / 1.4 * 1.7 * vn0, 1e-14);
        CHECK_ABS(dot(r.impulse_tan, n), 0.0, 1e-15 * norm(r.impulse_tan));
    }
}

/* Equal spheres as in Davis Sec. III: m_i = m_j = 2m, a_i = a_j = 2a, I = 16 m a^2/5 with
 * m = 1 kg, a = 0.25 m (so m_i = 2 kg, R = 0.5 m, I = 0.2 kg m^2). n = +x (j to i), the
 * Davis normal n_D = -x (i to j), t_D = z x n_D = -y. Head-on approach v_n = 1 m/s. */
static void equal_pair(double slip_d, struct wetdem_impulse_body* bi,
                       struct wetdem_impulse_body* bj)
{
    /* Davis slip v^s = v_ij,t + a_i w_i + a_j w_j with v_ij,t = (v_i - v_j).t_D; here 30 % of
     * it from i's tangential velocity (v_i,y = -0.3 slip) and 70 % from j's spin
     * (a_j w_jz = 0.7 slip). */
    *bi = sphere(2.0, 0.5, v3(-0.5, -0.3 * slip_d, 0), v3(0, 0, 0));
    *bj = sphere(2.0, 0.5, v3(0.5, 0, 0), v3(0, 0, 0.7 * slip_d / 0.5));
}

static double davis_slip(const struct wetdem_impulse_body* bi, const struct wetdem_impulse_body* bj)
{
    struct wetdem_vec3 t_d = v3(0, -1, 0);
    double v_t = dot(sub(bi->vel, bj->vel), t_d);
    return v_t + bi->radius * bi->omega.z + bj->radius * bj->omega.z;
}

static void test_hard_switch_exactly_at_a36_threshold(void** state)
{
    (void)state;
    /* A36: sticking iff |v^s| < 7 mu (1 + e) v_n / 2 = 7 * 0.5 * 1.8 * 1 / 2 = 3.15 m/s. */
    const double e = 0.8, mu = 0.5, threshold = 3.15;
    struct wetdem_impulse_body bi, bj;
    struct wetdem_impulse_result r;
    struct wetdem_vec3 n = v3(1, 0, 0);
    equal_pair(threshold * (1 - 1e-9), &bi, &bj);
    CHECK_REL(davis_slip(&bi, &bj), threshold * (1 - 1e-9), 1e-15);
    CHECK_OK(wetdem_hard_impulse(&bi, &bj, n, e, mu, &r));
    assert_true(r.is_sticking);
    /* rolling without slip after the impact: contact-point tangential velocity 0 (to the
     * roundings of a ~3 m/s slip) */
    CHECK_ABS(norm(tangential(contact_velocity(&bi, &bj, n), n)), 0.0, 1e-14);
    equal_pair(threshold * (1 + 1e-9), &bi, &bj);
    CHECK_OK(wetdem_hard_impulse(&bi, &bj, n, e, mu, &r));
    assert_false(r.is_sticking);
    CHECK_REL(norm(r.impulse_tan), mu * r.impulse_normal, 1e-15);
    /* slip after = 3.15e-9 m/s, same sign as before (resolved: the roundings are ~1e-15) */
    double after = davis_slip(&bi, &bj);
    assert_true(after > 0.0);
    CHECK_REL(after, threshold * 1e-9, 1e-5);
    /* and the sign of the impulse opposes the slip: along -t_D = +y on i */
    assert_true(r.impulse_tan.y > 0.0);
}

static void test_hard_equal_spheres_reproduce_davis(void** state)
{
    (void)state;
    const double e = 0.8, mu = 0.5, m = 1.0, r_c = 1.0; /* r = a_i + a_j = 4a */
    struct wetdem_impulse_body bi, bj;
    struct wetdem_impulse_result r;
    struct wetdem_vec3 n = v3(1, 0, 0), t_d = v3(0, -1, 0);
    /* sticking, slip 1 m/s < 3.15: A33-A35 */
    equal_pair(1.0, &bi, &bj);
    double omega_b = -dot(sub(bi.vel, bj.vel), t_d) / r_c; /* Omega = -v_t/r */
    double vw_b = bi.radius * bi.omega.z + bj.radius * bj.omega.z;
    CHECK_OK(wetdem_hard_impulse(&bi, &bj, n, e, mu, &r));
    assert_true(r.is_sticking);
    double omega_a = -dot(sub(bi.vel, bj.vel), t_d) / r_c;
    double vw_a = bi.radius * bi.omega.z + bj.radius * bj.omega.z;
    /* A33: I_t = 2m (v_w - r Omega)/7 = 2/7 * 1 = 0.2857142857142857 N s (on j along t_D;
     * on i it is -I_t t_D) */
    CHECK_REL(dot(r.impulse_tan, t_d), -2.0 * m * (vw_b - r_c * omega_b) / 7.0, 1e-15);
    CHECK_REL(norm(r.impulse_tan), 2.0 / 7.0, 1e-15);
    /* A34, A35: both sides are small differences of ~1 m/s terms: absolute 1e-14 m/s */
    CHECK_ABS(omega_a, 5.0 * omega_b / 7.0 + 2.0 * vw_b / (7.0 * r_c), 1e-14);
    CHECK_ABS(vw_a, 5.0 * r_c * omega_b / 7.0 + 2.0 * vw_b / 7.0, 1e-14);
    assert_true(fabs(vw_a - vw_b) > 0.1); /* the spins did change */
    /* sliding, slip 10 m/s > 3.15: A9 (with its lost sign: v_t decreases by mu (1+e) v_n
     * for positive slip), A10, A11 (omega_j with I_j) */
    equal_pair(10.0, &bi, &bj);
    double vt_b = dot(sub(bi.vel, bj.vel), t_d), wi_b = bi.omega.z, wj_b = bj.omega.z;
    omega_b = -vt_b / r_c;
    CHECK_OK(wetdem_hard_impulse(&bi, &bj, n, e, mu, &r));
    assert_false(r.is_sticking);
    double jump = mu * (1 + e) * 1.0;                             /* mu (1 + e) v_n = 0.9 m/s */
    CHECK_REL(dot(sub(bi.vel, bj.vel), t_d), vt_b - jump, 1e-15); /* A9 */
    CHECK_REL(-dot(sub(bi.vel, bj.vel), t_d) / r_c, omega_b + jump / r_c, 1e-15); /* A10 */
    CHECK_REL(bi.omega.z, wi_b - jump * bi.radius * m / bi.inertia, 1e-15);       /* A11 */
    CHECK_REL(bj.omega.z, wj_b - jump * bj.radius * m / bj.inertia, 1e-15);
    /* normal: A1 v_n' = -e v_n, the centres' normal velocities after: -0.8 */
    CHECK_REL(dot(sub(bi.vel, bj.vel), n), 0.8, 1e-15);
}

static void test_hard_unequal_spheres_swap_symmetric(void** state)
{
    (void)state;
    const double mus[] = {0.02, 5.0};
    for (int k = 0; k < 2; k++) {
        struct wetdem_impulse_body a, b, a2, b2;
        struct wetdem_vec3 n;
        oblique_pair(&a, &b, &n);
        a2 = a;
        b2 = b;
        struct wetdem_impulse_result r1, r2;
        CHECK_OK(wetdem_hard_impulse(&a, &b, n, 0.6, mus[k], &r1));
        CHECK_OK(wetdem_hard_impulse(&b2, &a2, scale(n, -1.0), 0.6, mus[k], &r2));
        assert_int_equal(r1.is_sticking, r2.is_sticking);
        /* 1e-14: the same arithmetic up to the order of a few sums */
        CHECK_REL(r1.impulse_normal, r2.impulse_normal, 1e-14);
        CHECK_ABS(r1.impulse_tan.x, -r2.impulse_tan.x, 1e-14 * norm(r1.impulse_tan));
        CHECK_ABS(r1.impulse_tan.y, -r2.impulse_tan.y, 1e-14 * norm(r1.impulse_tan));
        CHECK_ABS(r1.impulse_tan.z, -r2.impulse_tan.z, 1e-14 * norm(r1.impulse_tan));
        CHECK_ABS(norm(sub(a.vel, a2.vel)), 0.0, 1e-14 * norm(a.vel));
        CHECK_ABS(norm(sub(b.vel, b2.vel)), 0.0, 1e-14 * norm(b.vel));
        CHECK_ABS(norm(sub(a.omega, a2.omega)), 0.0, 1e-14 * norm(a.omega));
        CHECK_ABS(norm(sub(b.omega, b2.omega)), 0.0, 1e-14 * norm(b.omega));
    }
}

static void test_hard_sphere_on_wall(void** state)
{
    (void)state;
    /* m = 0.5 kg, R = 0.1 m, I = 2/5 m R^2 = 0.002 kg m^2, wall normal +y (wall to sphere).
     * v = (1, -2, 0), w = (0, 0, 5): slip u_t = v_x + (w x (-R y))_x = 1 + 5 * 0.1 = 1.5 m/s.
     * J_n = m (1 + e) v_n = 0.5 * 1.6 * 2 = 1.6 N s. m_t = 1/(1/m + R^2/I) = 2m/7 = 1/7 kg,
     * arrest impulse 1.5/7 = 0.2143 N s < mu J_n = 0.3 * 1.6 = 0.48: sticking. */
    struct wetdem_vec3 n = v3(0, 1, 0);
    struct wetdem_impulse_body s = sphere(0.5, 0.1, v3(1, -2, 0), v3(0, 0, 5)), w = wall();
    struct wetdem_impulse_result r;
    CHECK_OK(wetdem_hard_impulse(&s, &w, n, 0.6, 0.3, &r));
    assert_true(r.is_sticking);
    CHECK_REL(r.impulse_normal, 1.6, 1e-15);
    CHECK_REL(r.impulse_tan.x, -1.5 / 7.0, 1e-15);
    CHECK_REL(s.vel.y, 1.2, 1e-15); /* -e v_n */
    CHECK_ABS(norm(tangential(contact_velocity(&s, &w, n), n)), 0.0, 1e-15);
    CHECK_ABS(norm(w.vel) + norm(w.omega), 0.0, 0.0); /* the wall does not move */
    assert_true(isinf(w.mass) && isinf(w.radius));
    /* sliding with mu = 0.05: |J_t| = mu J_n = 0.08, v_x' = 1 - 0.08/0.5 = 0.84 */
    s = sphere(0.5, 0.1, v3(1, -2, 0), v3(0, 0, 5));
    CHECK_OK(wetdem_hard_impulse(&s, &w, n, 0.6, 0.05, &r));
    assert_false(r.is_sticking);
    CHECK_REL(s.vel.x, 0.84, 1e-15);
    /* spin change: (-R n) x J / I = (-0.1 y) x (-0.08 x) / 0.002 = -4 z: w_z = 1 */
    CHECK_REL(s.omega.z, 1.0, 1e-14);
    /* A fixed sphere (infinite mass, finite radius, e.g. a target on a support) is not moved
     * and a sphere bouncing head-on off it reverses with e. */
    struct wetdem_impulse_body f = {v3(0, 0, 0), v3(0, 0, 0), INFINITY, 0.2, 0.0};
    s = sphere(0.5, 0.1, v3(0, -2, 0), v3(0, 0, 0));
    CHECK_OK(wetdem_hard_impulse(&s, &f, n, 0.6, 0.3, &r));
    CHECK_REL(s.vel.y, 1.2, 1e-15);
    CHECK_ABS(norm(f.vel) + norm(f.omega), 0.0, 0.0);
}

static void test_hard_rejects_invalid_input(void** state)
{
    (void)state;
    struct wetdem_impulse_body bi0, bj0;
    struct wetdem_vec3 n0;
    oblique_pair(&bi0, &bj0, &n0);
    struct {
        double e, mu;
        int field; /* 0 none, 1 NaN velocity, 2 negative mass, 3 zero radius, 4 NaN mass,
                      5 infinite radius with finite mass, 6 both immovable, 7 bad normal,
                      8 zero inertia, 9 NaN normal */
    } cases[] = {{0.0, 0.1, 0},  {1.0001, 0.1, 0}, {-0.5, 0.1, 0},     {NAN, 0.1, 0},
                 {0.5, -0.1, 0}, {0.5, NAN, 0},    {0.5, INFINITY, 0}, {0.5, 0.1, 1},
                 {0.5, 0.1, 2},  {0.5, 0.1, 3},    {0.5, 0.1, 4},      {0.5, 0.1, 5},
                 {0.5, 0.1, 6},  {0.5, 0.1, 7},    {0.5, 0.1, 8},      {0.5, 0.1, 9}};
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        struct wetdem_impulse_body bi = bi0, bj = bj0;
        struct wetdem_vec3 n = n0;
        switch (cases[k].field) {
        case 1: bi.vel.y = NAN; break;
        case 2: bj.mass = -1.0; break;
        case 3: bi.radius = 0.0; break;
        case 4: bj.mass = NAN; break;
        case 5: bi.radius = INFINITY; break;
        case 6:
            bi = wall();
            bj = wall();
            break;
        case 7: n = scale(n0, 1.01); break;
        case 8: bj.inertia = 0.0; break;
        case 9: n.x = NAN; break;
        default: break;
        }
        struct wetdem_impulse_body ci = bi, cj = bj;
        struct wetdem_impulse_result r = {1.0, v3(1, 1, 1), true};
        CHECK_STATUS(wetdem_hard_impulse(&bi, &bj, n, cases[k].e, cases[k].mu, &r),
                     WETDEM_ERR_INVALID);
        assert_memory_equal(&bi, &ci, sizeof bi); /* untouched on error */
        assert_memory_equal(&bj, &cj, sizeof bj);
        CHECK_ABS(r.impulse_normal, 0.0, 0.0);
    }
    /* the boundaries themselves are valid: e = 1, mu = 0 */
    struct wetdem_impulse_body bi = bi0, bj = bj0;
    CHECK_OK(wetdem_hard_impulse(&bi, &bj, n0, 1.0, 0.0, NULL));
}

static void test_hard_separating_pair_unchanged(void** state)
{
    (void)state;
    struct wetdem_impulse_body bi, bj;
    struct wetdem_vec3 n;
    oblique_pair(&bi, &bj, &n);
    /* reverse all motion: now separating; then exactly tangential (v_n = 0) */
    for (int k = 0; k < 2; k++) {
        struct wetdem_impulse_body ai = bi, aj = bj;
        ai.vel = scale(bi.vel, -1.0);
        aj.vel = scale(bj.vel, -1.0);
        if (k == 1) {
            ai.vel = tangential(ai.vel, n);
            aj.vel = tangential(aj.vel, n);
        }
        double vn = -dot(contact_velocity(&ai, &aj, n), n);
        assert_true(k == 0 ? vn < 0.0 : fabs(vn) < 1e-15);
        if (k == 1 && vn > 0.0)
            continue; /* rounding made it approach by 1e-16: not the case under test */
        struct wetdem_impulse_body ci = ai, cj = aj;
        struct wetdem_impulse_result r = {1.0, v3(1, 1, 1), true};
        CHECK_OK(wetdem_hard_impulse(&ai, &aj, n, 0.5, 0.3, &r));
        assert_memory_equal(&ai, &ci, sizeof ai);
        assert_memory_equal(&aj, &cj, sizeof aj);
        CHECK_ABS(r.impulse_normal + norm(r.impulse_tan), 0.0, 0.0);
        assert_false(r.is_sticking);
    }
}

/* Spin has no normal component at the contact point (omega x n is perpendicular to n), so the
 * approach speed is that of the centres alone: spheres whose centres do not approach get no
 * impulse however fast they spin, and the normal impulse of a slow approach under fast spin
 * carries no rounding from the spin. */
static void test_hard_spin_does_not_enter_normal_approach(void** state)
{
    (void)state;
    const struct wetdem_vec3 normals[] = {{0.28, 0.96, 0.0}, {0.36, 0.48, 0.8}};
    const double spins[] = {1e3, 12345.0};
    for (int a = 0; a < 2; a++) {
        struct wetdem_vec3 n = normals[a];
        for (int b = 0; b < 2; b++) {
            double w = spins[b];
            struct wetdem_impulse_body bi = sphere(1.0, 0.1, v3(0.2, -0.1, 0.3), v3(0, 0, w));
            struct wetdem_impulse_body bj =
                sphere(2.0, 0.3, v3(0.2, -0.1, 0.3), v3(w / 3.0, 0, -w));
            struct wetdem_impulse_body ci = bi, cj = bj;
            struct wetdem_impulse_result r;
            CHECK_OK(wetdem_hard_impulse(&bi, &bj, n, 0.9, 0.5, &r));
            assert_memory_equal(&bi, &ci, sizeof bi);
            assert_memory_equal(&bj, &cj, sizeof bj);
            CHECK_ABS(r.impulse_normal, 0.0, 0.0);
            /* approaching at 1 mm/s under a surface speed of 10^2-10^3 m/s, sliding; 1e-14:
               some ten roundings of products of eps = 2.2e-16 each, where the spin terms'
               rounding (eps |w R| / v_n ~ 1e-11) showed before */
            bi.vel = sub(bi.vel, scale(n, 1e-3));
            double v_n = -dot(sub(bi.vel, bj.vel), n), m_red = 2.0 / 3.0;
            CHECK_OK(wetdem_hard_impulse(&bi, &bj, n, 0.9, 0.5, &r));
            assert_false(r.is_sticking);
            CHECK_REL(r.impulse_normal, m_red * 1.9 * v_n, 1e-14);
            CHECK_REL(norm(r.impulse_tan), 0.5 * m_red * 1.9 * v_n, 1e-14);
        }
    }
}

static void test_hard_model_object(void** state)
{
    (void)state;
    assert_string_equal(wetdem_hard_model.name, "hard");
    assert_int_equal(wetdem_hard_model.kind, WETDEM_MODEL_IMPULSE);
    assert_null(wetdem_hard_model.pair);
    assert_true(strlen(wetdem_hard_model.summary) > 20 && strlen(wetdem_hard_model.doc) > 200);
    CHECK_CONTAINS(wetdem_hard_model.equations, "A36");
    const struct wetdem_param_desc* d = wetdem_param_find(wetdem_hard_model.params, "friction");
    assert_non_null(d);
    assert_int_equal(wetdem_param_choice_index(d, "lubricated"), (int)d->default_value);
    assert_int_equal(wetdem_param_choice_index(d, "dry"), 0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_hard_conserves_momentum),
        cmocka_unit_test(test_hard_reverses_normal_velocity_with_e),
        cmocka_unit_test(test_hard_switch_exactly_at_a36_threshold),
        cmocka_unit_test(test_hard_equal_spheres_reproduce_davis),
        cmocka_unit_test(test_hard_unequal_spheres_swap_symmetric),
        cmocka_unit_test(test_hard_sphere_on_wall),
        cmocka_unit_test(test_hard_rejects_invalid_input),
        cmocka_unit_test(test_hard_separating_pair_unchanged),
        cmocka_unit_test(test_hard_spin_does_not_enter_normal_approach),
        cmocka_unit_test(test_hard_model_object),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

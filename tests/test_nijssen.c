/*
 * test_nijssen.c — the composite nijssen model (Nijssen 2023 Eqs. 1, 3-10): minimum approach
 * with the fifth root of Eq. 5, the per-pair largest approach speed and its reset, the
 * lubrication, blend and contact branches of Eq. 9 at hand-computed points, continuity at
 * h = h_min and h = 0 and the single jump at h_co, the dry/lubricated friction switch of
 * Eq. 10, suction, i<->j symmetry and parameter validation.
 *
 * Pair: R_i = 4 mm, R_j = 12 mm -> R* = 48e-6/16e-3 = 3e-3 m; m_i = 0.05, m_j = 0.2 kg;
 * mu = 1 Pa s, E* = 1e8 Pa, roughness 1 um, mu_dry 0.1, mu_lub 0.02, e_dry 0.9.
 * With v0 = 3 m/s: mu v0/(E* R*) = 3/(1e8 * 3e-3) = 1e-5, (1e-5)^(2/5) = 1e-2,
 * h_eps = 0.37 * 3e-3 * 1e-2 = 1.11e-5 m > h_sigma, so h_min = 11.1 um.
 */
#include "harness.h"
#include "models.h"

#define RI 4e-3
#define RJ 12e-3
#define R_EFF 3e-3
#define H_EPS 1.11e-5
/* closed forms: a pow() and a few products, each within an ulp or two: 1e-13 is ample */
#define TOL_CLOSED 1e-13

enum { HIST_LEN = 4 };

static struct wetdem_contact pair_at(double gap, double v_n)
{
    struct wetdem_contact c = test_contact(RI, RJ, 0.05, 0.2, gap, v_n);
    c.e_star = 1e8;
    c.g_star = 4e7;
    c.viscosity = 1.0;
    c.roughness = 1e-6;
    c.friction_dry = 0.1;
    c.friction_lub = 0.02;
    c.restitution = 0.9;
    c.h_min = 0; /* not read by nijssen */
    return c;
}

struct run {
    double params[4];
    double history[HIST_LEN];
};

/* Default params; history with the recorded largest approach speed v0. */
static struct run fresh(double v0)
{
    struct run r = {{0}, {0}};
    wetdem_param_init_defaults(wetdem_force_nijssen.params, r.params);
    r.history[0] = v0;
    return r;
}

static struct wetdem_pair_force eval(struct run* r, struct wetdem_contact c)
{
    struct wetdem_pair_force f = {0};
    CHECK_OK(wetdem_force_nijssen.pair(r->params, &c, r->history, &f));
    return f;
}

/* F_n of a fresh evaluation with recorded speed v0 (history not kept). */
static double normal_force(double v0, double gap, double v_n)
{
    struct run r = fresh(v0);
    return eval(&r, pair_at(gap, v_n)).f_normal;
}

static double h_min_of(double v0, const struct wetdem_contact* c)
{
    struct run r = fresh(v0);
    double gaps[WETDEM_MAX_THRESHOLDS];
    CHECK_REL((double)wetdem_force_nijssen.thresholds(r.params, c, r.history, gaps), 3, 0);
    return gaps[1];
}

/* h_min = max(h_sigma, h_eps) with the fifth root (1.11e-5 m at 3 m/s; the printed cube root
 * would give 0.37 * (9e-16 * 2.7e-8)^(1/3) = 1.1e-8 m), and thresholds {h_co, h_min, 0}. */
static void test_nijssen_min_approach_fifth_root(void** state)
{
    (void)state;
    struct wetdem_contact c = pair_at(1e-4, 0.0);
    CHECK_REL(h_min_of(3.0, &c), H_EPS, TOL_CLOSED);
    CHECK_REL(h_min_of(0.0, &c), 1e-6, 0); /* at rest: roughness */
    c.v_n = 3.0;                           /* current speed counts as well as the record */
    CHECK_REL(h_min_of(0.0, &c), H_EPS, TOL_CLOSED);
    struct run r = fresh(0);
    double gaps[WETDEM_MAX_THRESHOLDS];
    wetdem_force_nijssen.thresholds(r.params, &c, r.history, gaps);
    CHECK_REL(gaps[0], R_EFF, 0); /* h_co = cutoff_ratio R* = R* */
    CHECK_REL(gaps[2], 0, 0);
}

/* Lubrication branch, h = 100 um, v_n = 0.5: 6 pi * 1 * 9e-6 * 0.5 / 1e-4 = 6 pi * 0.045
 * = 0.848230016469244 N. Contact branch at v_n = 0 (no damping, no lubrication), h = -5 um:
 * delta = 11.1 + 5 = 16.1 um, F = (4/3) 1e8 sqrt(3e-3) (1.61e-5)^(3/2) = 0.471778535614611 N. */
static void test_nijssen_branches_closed_form(void** state)
{
    (void)state;
    CHECK_REL(normal_force(3.0, 1e-4, 0.5), 0.8482300164692441, TOL_CLOSED);
    CHECK_REL(normal_force(3.0, -5e-6, 0.0), 0.4717785356146108, TOL_CLOSED);
    /* blend midpoint h = h_min/2 at v_n = 0: half the Hertz force at delta = h_min/2 */
    double half = 0.5 * wetdem_force_hertz_elastic(1e8, R_EFF, 0.5 * H_EPS);
    CHECK_REL(normal_force(3.0, 0.5 * H_EPS, 0.0), half, 1e-12);
    /* with motion: 0.5 F_l(h_min) + 0.5 max(0, Hertz + damping) (Eq. 9 lever weights) */
    double f_l = 6 * M_PI * R_EFF * R_EFF * 0.5 / H_EPS;
    double f_c = wetdem_force_hertz_elastic(1e8, R_EFF, 0.5 * H_EPS) +
                 wetdem_force_hertz_damping(1e8, R_EFF, 0.04, 0.5 * H_EPS, 0.5, 0.9, 0);
    CHECK_REL(normal_force(3.0, 0.5 * H_EPS, 0.5), 0.5 * f_l + 0.5 * fmax(f_c, 0), 1e-12);
}

/* Continuity of Eq. 9 at h = h_min and h = 0: evaluate at h (1 +- 1e-12). A continuous force
 * changes there by about 1e-12 of its scale S = max(|F_l(h_min)|, F_el(h_min), |F| on either
 * side), the largest of the lubrication and contact forces met at the switch
 * (F_l ~ 1/h; the contact part enters with weight ~1e-12 near h_min, the lubrication part
 * with weight ~1e-12 near 0), so a jump tolerance of 1e-9 S is 1000 times that and far below
 * the O(S) jump a wrong lever weight would make. Separating (v_n < 0) the clipped contact
 * force can be zero at h = 0 while the lubrication suction is not: hence S uses F_l(h_min).
 * At h_co the force jumps from F_l(h_co) = 6 pi * 9e-6 * 0.5 / 3e-3 = 0.0282743 N to zero. */
static void test_nijssen_continuity_and_single_jump(void** state)
{
    (void)state;
    const double v_n[] = {0.5, -0.5, 0.0, 2.0};
    for (size_t k = 0; k < 4; k++) {
        double f_l = fmax(fabs(6 * M_PI * R_EFF * R_EFF * v_n[k] / H_EPS),
                          wetdem_force_hertz_elastic(1e8, R_EFF, H_EPS));
        double above = normal_force(3.0, H_EPS * (1 + 1e-12), v_n[k]);
        double below = normal_force(3.0, H_EPS * (1 - 1e-12), v_n[k]);
        CHECK_ABS(above, below, 1e-9 * fmax(f_l, fmax(fabs(above), fabs(below))));
        double plus = normal_force(3.0, 1e-12 * H_EPS, v_n[k]);
        double minus = normal_force(3.0, -1e-12 * H_EPS, v_n[k]);
        CHECK_ABS(plus, minus, 1e-9 * fmax(f_l, fmax(fabs(plus), fabs(minus))));
        if (!(fmax(fabs(above), fabs(minus)) > 0))
            fail_msg("no force at v_n = %g", v_n[k]);
    }
    CHECK_REL(normal_force(3.0, R_EFF, 0.5), 0.02827433388230814, TOL_CLOSED);
    CHECK_ABS(normal_force(3.0, R_EFF * (1 + 1e-12), 0.5), 0, 0);
    /* no other jump: scan the whole range in steps of 1e-3 h_min and 1e-3 h_co, bounding
     * each step's change by the force's own local variation (F_l ~ 1/h: |dF| <= |F| dh/h
     * with a factor 3 margin; near and below h_min the slope is bounded by the contact law). */
    double prev = normal_force(3.0, -H_EPS, 0.5);
    for (int k = -999; k <= 3000; k++) {
        double h = k <= 1000 ? k * 1e-3 * H_EPS : H_EPS + (k - 1000) * 1e-3 * (R_EFF - H_EPS) / 2;
        double f = normal_force(3.0, h, 0.5);
        double step = k <= 1000 ? 1e-3 * H_EPS : 0.5e-3 * (R_EFF - H_EPS);
        double bound = 3 * fabs(f) * step / fmax(fabs(h), H_EPS) + 1e-2 * fabs(prev);
        if (!(fabs(f - prev) <= bound))
            fail_msg("force jumps from %g to %g N at h = %g m", prev, f, h);
        prev = f;
    }
}

/* The record keeps the largest approach speed (1, 3, then 2 m/s -> 3), separation does not
 * lower it, and leaving the cut-off clears it and the tangential spring. */
static void test_nijssen_history_largest_speed_and_reset(void** state)
{
    (void)state;
    struct run r = fresh(0);
    const double v[] = {1.0, 3.0, 2.0, -4.0};
    const double want[] = {1.0, 3.0, 3.0, 3.0};
    for (size_t k = 0; k < 4; k++) {
        struct wetdem_contact c = pair_at(-1e-6, v[k]);
        c.v_t = (struct wetdem_vec3){0, 1e-3, 0};
        eval(&r, c);
        CHECK_REL(r.history[0], want[k], 0);
    }
    if (!(fabs(r.history[2]) > 0))
        fail_msg("the tangential spring did not load in contact");
    eval(&r, pair_at(R_EFF * 1.01, -0.1));
    for (int k = 0; k < HIST_LEN; k++)
        CHECK_ABS(r.history[k], 0, 0);
}

/* Eq. 10: mu_dry if h_sigma >= h_eps else mu_lub. In full sliding the tangential force is
 * mu w_c F_el(delta) exactly: at h = -5 um (w_c = 1) with v_t dt = 10 * 1e-3 = 1 cm of spring
 * (far past the Coulomb limit). The boundary: roughness exactly h_eps -> dry; one ulp
 * below -> lubricated; both give h_min = h_eps, hence the same load. */
static void test_nijssen_friction_switch(void** state)
{
    (void)state;
    struct wetdem_contact c = pair_at(-5e-6, 0.0);
    c.roughness = 0;
    double h_eps = h_min_of(3.0, &c);
    c.v_t = (struct wetdem_vec3){0, 10, 0};
    c.dt = 1e-3;
    double load = wetdem_force_hertz_elastic(1e8, R_EFF, h_eps + 5e-6);
    c.roughness = h_eps;
    struct run r = fresh(3.0);
    CHECK_REL(-eval(&r, c).f_tan.y, 0.1 * load, 1e-14);
    c.roughness = nextafter(h_eps, 0);
    r = fresh(3.0);
    CHECK_REL(-eval(&r, c).f_tan.y, 0.02 * load, 1e-14);
    /* blend zone h = h_min/2: the limit carries the lever weight 1/2 */
    c.gap = 0.5 * h_eps;
    r = fresh(3.0);
    double half = 0.5 * wetdem_force_hertz_elastic(1e8, R_EFF, 0.5 * h_eps);
    CHECK_REL(-eval(&r, c).f_tan.y, 0.02 * half, 1e-14);
}

/* Separating surfaces are pulled together (suction) in the lubrication and blend branches;
 * with h_min set by the record (3 m/s), the force is odd in v_n exactly in the lubrication
 * branch. */
static void test_nijssen_suction_when_separating(void** state)
{
    (void)state;
    double in = normal_force(3.0, 1e-4, 0.5), out = normal_force(3.0, 1e-4, -0.5);
    if (!(out < 0))
        fail_msg("separating force %g N is not attractive", out);
    CHECK_REL(out, -in, 0);
    if (!(normal_force(3.0, 0.9 * H_EPS, -2.0) < 0))
        fail_msg("no suction in the blend zone near h_min");
}

/* i<->j swap with unequal radii and masses: equal normal force, opposite tangential force,
 * exchanged torques, each with its own fresh history (sign flips only: exact). */
static void test_nijssen_swap_symmetry(void** state)
{
    (void)state;
    const double gaps[] = {1e-4, 0.3 * H_EPS, -3e-6};
    for (size_t g = 0; g < 3; g++) {
        struct wetdem_contact c = pair_at(gaps[g], 0.7);
        c.normal = (struct wetdem_vec3){0, 0.6, 0.8};
        c.v_t = (struct wetdem_vec3){0.05, 0.04, -0.03};
        struct wetdem_contact s = wetdem_contact_swapped(&c);
        struct run a = fresh(3.0), b = fresh(3.0);
        struct wetdem_pair_force fa = eval(&a, c), fb = eval(&b, s);
        CHECK_REL(fb.f_normal, fa.f_normal, 0);
        CHECK_REL(fb.f_tan.x, -fa.f_tan.x, 0);
        CHECK_REL(fb.f_tan.z, -fa.f_tan.z, 0);
        CHECK_REL(fb.torque_i.x, fa.torque_j.x, 0);
        CHECK_REL(fb.torque_j.y, fa.torque_i.y, 0);
        CHECK_REL(b.history[1], -a.history[1], 0);
        if (g > 0 && !(fabs(fa.f_tan.x) > 0))
            fail_msg("no tangential force in contact at h = %g", gaps[g]);
    }
}

/* damping = exact or tsuji: the contact branch is max(0, Hertz + damping(form)). Fast
 * separation (v_n = -1 m/s at delta = 13.1 um) makes the damping exceed the elastic force
 * (about 2.4 N against 0.35 N): the clipped contact then gives zero, never attraction. */
static void test_nijssen_damping_forms(void** state)
{
    (void)state;
    double delta = H_EPS + 2e-6;
    const double v_n[] = {0.4, -1.0};
    for (int form = 0; form < 2; form++)
        for (size_t k = 0; k < 2; k++) {
            struct run r = fresh(3.0);
            r.params[1] = form; /* struct order: cutoff_ratio, damping */
            CHECK_REL(r.params[0], 1.0, 0);
            double f = eval(&r, pair_at(-2e-6, v_n[k])).f_normal;
            double sum = wetdem_force_hertz_elastic(1e8, R_EFF, delta) +
                         wetdem_force_hertz_damping(1e8, R_EFF, 0.04, delta, v_n[k], 0.9, form);
            if (k == 1 && !(sum < 0))
                fail_msg("set-up: the unclipped contact force %g N should pull", sum);
            CHECK_REL(f, fmax(sum, 0), 1e-14);
        }
    struct run r = fresh(3.0);
    struct wetdem_contact c = pair_at(-2e-6, 0.4);
    c.restitution = 0; /* invalid e_dry is reported, never a NaN force */
    struct wetdem_pair_force f = {0};
    CHECK_STATUS(wetdem_force_nijssen.pair(r.params, &c, r.history, &f), WETDEM_ERR_INVALID);
}

static void test_nijssen_params_validated(void** state)
{
    (void)state;
    struct wetdem_sim* sim = wetdem_sim_create();
    CHECK_OK(wetdem_sim_enable_model(sim, "nijssen"));
    CHECK_STATUS(wetdem_sim_set_param(sim, "nijssen.cutoff_ratio", 0), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "nijssen.cutoff_ratio");
    CHECK_STATUS(wetdem_sim_set_param(sim, "nijssen.cutoff_ratio", -1), WETDEM_ERR_INVALID);
    CHECK_STATUS(wetdem_sim_set_param(sim, "nijssen.cutoff_ratio", INFINITY), WETDEM_ERR_INVALID);
    CHECK_OK(wetdem_sim_set_param(sim, "nijssen.cutoff_ratio", 2));
    CHECK_OK(wetdem_sim_set_param_str(sim, "nijssen.damping", "tsuji"));
    CHECK_STATUS(wetdem_sim_set_param_str(sim, "nijssen.damping", "tsuij"), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "exact, tsuji");
    double v = -1;
    CHECK_OK(wetdem_sim_param(sim, "nijssen.cutoff_ratio", &v));
    CHECK_REL(v, 2, 0);
    wetdem_sim_free(sim);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_nijssen_min_approach_fifth_root),
        cmocka_unit_test(test_nijssen_branches_closed_form),
        cmocka_unit_test(test_nijssen_continuity_and_single_jump),
        cmocka_unit_test(test_nijssen_history_largest_speed_and_reset),
        cmocka_unit_test(test_nijssen_friction_switch),
        cmocka_unit_test(test_nijssen_suction_when_separating),
        cmocka_unit_test(test_nijssen_swap_symmetry),
        cmocka_unit_test(test_nijssen_damping_forms),
        cmocka_unit_test(test_nijssen_params_validated),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

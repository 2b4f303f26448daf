/*
 * test_minsep.c — minimum-separation models roughness, ehd, max, glass (and fixed): values at
 * hand-computed points, the fifth root of Nijssen Eq. 5, the per-pair record of the largest
 * approach speed and its reset, the glass cap at delta and its three speed choices, and
 * parameter validation through the simulation.
 */
#include "harness.h"
#include "models.h"

/* Relative tolerance for closed forms: a pow() or sqrt() and a few products, each correctly
 * rounded or within 1 ulp in glibc, so a few 1e-16; 1e-13 leaves margin. */
#define TOL_CLOSED 1e-13

/* h_min of model m for contact c with the given history (history_len doubles) and params. */
static double minsep(const struct wetdem_model* m, const void* params,
                     const struct wetdem_contact* c, double* history)
{
    if (m->kind != WETDEM_MODEL_MIN_SEPARATION || !m->min_separation)
        fail_msg("%s is not a min-separation model", m->name);
    return m->min_separation(params, c, history);
}

/* Sets a numeric or enumerated parameter of a params block by name. */
static void set(const struct wetdem_model* m, void* params, const char* name, double v)
{
    const struct wetdem_param_desc* d = wetdem_param_find(m->params, name);
    if (!d)
        fail_msg("%s has no parameter %s", m->name, name);
    *(double*)((char*)params + d->offset) = v;
}

/* EHD pair: mu = 1 Pa s, E* = 1e8 Pa, R* = 1e-3 m (R_i = R_j = 2 mm), v0 = 1 m/s:
 * mu v0/(E* R*) = 1/(1e8 * 1e-3) = 1e-5; (1e-5)^(2/5) = 1e-2; h_eps = 0.37 * 1e-3 * 1e-2
 * = 3.7e-6 m. The printed cube root would give 0.37 (1e-16 * 1e-9)^(1/3) = 1.7e-9 m. */
static struct wetdem_contact ehd_pair(double gap, double v_n)
{
    struct wetdem_contact c = test_contact(2e-3, 2e-3, 0.1, 0.1, gap, v_n);
    c.viscosity = 1.0;
    c.e_star = 1e8;
    c.roughness = 1e-6;
    return c;
}

static void test_roughness_is_mean_asperity_height(void** state)
{
    (void)state;
    struct wetdem_contact c = ehd_pair(1e-5, 3.0);
    c.roughness = 4.3e-7; /* already the mean (sigma_i + sigma_j)/2, Nijssen Eq. 3 */
    CHECK_REL(minsep(&wetdem_minsep_roughness, NULL, &c, NULL), 4.3e-7, 0);
    CHECK_REL((double)wetdem_minsep_roughness.history_len, 0, 0);
}

static void test_ehd_fifth_root_hand_value(void** state)
{
    (void)state;
    double params[4], history[1] = {0};
    wetdem_param_init_defaults(wetdem_minsep_ehd.params, params);
    struct wetdem_contact c = ehd_pair(1e-5, 1.0);
    CHECK_REL(minsep(&wetdem_minsep_ehd, params, &c, history), 3.7e-6, TOL_CLOSED);
    CHECK_REL(history[0], 1.0, 0);
    /* scaling: h_eps ~ v0^(2/5); 32 times the speed gives 32^(2/5) = 4 times the gap */
    double h2[1] = {0};
    c.v_n = 32.0;
    CHECK_REL(minsep(&wetdem_minsep_ehd, params, &c, h2), 4 * 3.7e-6, TOL_CLOSED);
}

/* The record keeps the largest approach speed while the pair interacts (gap <= R* by
 * default) and is forgotten beyond; separating (v_n < 0) never lowers it. */
static void test_ehd_history_keeps_largest_speed(void** state)
{
    (void)state;
    double params[4], history[1] = {0};
    wetdem_param_init_defaults(wetdem_minsep_ehd.params, params);
    const double v[] = {0.25, 1.0, 0.5, -2.0};
    const double want[] = {0.25, 1.0, 1.0, 1.0};
    for (size_t k = 0; k < 4; k++) {
        struct wetdem_contact c = ehd_pair(1e-5, v[k]);
        minsep(&wetdem_minsep_ehd, params, &c, history);
        CHECK_REL(history[0], want[k], 0);
    }
    struct wetdem_contact c = ehd_pair(1e-5, 0.5);
    CHECK_REL(minsep(&wetdem_minsep_ehd, params, &c, history), 3.7e-6, TOL_CLOSED);
    /* leaving the interaction (gap > reset_ratio R* = 1e-3 m): record cleared */
    c.gap = 1.1e-3;
    c.v_n = 1.0 / 32.0; /* h = 3.7e-6 / 4 from the current speed only */
    CHECK_REL(minsep(&wetdem_minsep_ehd, params, &c, history), 3.7e-6 / 4, TOL_CLOSED);
    CHECK_REL(history[0], 0, 0);
    /* a larger reset_ratio keeps the record at that gap */
    set(&wetdem_minsep_ehd, params, "reset_ratio", 2.0);
    history[0] = 1.0;
    CHECK_REL(minsep(&wetdem_minsep_ehd, params, &c, history), 3.7e-6, TOL_CLOSED);
}

/* max (Nijssen Eq. 6): max(h_sigma, h_eps) with h_eps = 3.7 um at v0 = 1 m/s. */
static void test_max_takes_larger_mechanism(void** state)
{
    (void)state;
    double params[4], history[1] = {0};
    wetdem_param_init_defaults(wetdem_minsep_max.params, params);
    struct wetdem_contact c = ehd_pair(1e-5, 1.0);
    c.roughness = 1e-6;
    CHECK_REL(minsep(&wetdem_minsep_max, params, &c, history), 3.7e-6, TOL_CLOSED);
    c.roughness = 5e-6;
    c.v_n = 0.1; /* the record of 1 m/s stays: h_eps = 3.7 um < 5 um */
    CHECK_REL(minsep(&wetdem_minsep_max, params, &c, history), 5e-6, 0);
    CHECK_REL(history[0], 1.0, 0);
}

/* glass (Punch Eq. 14), Punch's set-up: mu = 10 Pa s, a = R* = 6.35 mm (two 12.7 mm radius
 * spheres), v = 0.3 m/s, P_gt = 11.6 MPa: 3 mu a v / P_gt = 3 * 10 * 6.35e-3 * 0.3 / 11.6e6
 * = 0.05715 / 11.6e6 = 4.92672e-9 m^2 (Pa s * m * m/s / Pa = m^2), h_min = 7.01906e-5 m.
 * At v = 10 m/s: 1.6422e-7 m^2 -> 4.05e-4 m > delta = 270 um: capped at delta. */
static struct wetdem_contact glass_pair(double gap, double v_n)
{
    struct wetdem_contact c = test_contact(12.7e-3, 12.7e-3, 0.067, 0.067, gap, v_n);
    c.viscosity = 10.0;
    c.film = 270e-6;
    return c;
}

static void test_glass_hand_value_and_cap(void** state)
{
    (void)state;
    double params[4], history[3] = {0};
    wetdem_param_init_defaults(wetdem_minsep_glass.params, params);
    struct wetdem_contact c = glass_pair(100e-6, 0.3);
    CHECK_REL(minsep(&wetdem_minsep_glass, params, &c, history), 7.019062713732535e-05, TOL_CLOSED);
    double fresh[3] = {0};
    c.v_n = 10.0;
    CHECK_REL(minsep(&wetdem_minsep_glass, params, &c, fresh), 270e-6, 0);
    /* h_min ~ sqrt(v / P_gt): quadrupling P_gt halves it */
    double h3[3] = {0};
    c.v_n = 0.3;
    set(&wetdem_minsep_glass, params, "p_gt", 4 * 11.6e6);
    CHECK_REL(minsep(&wetdem_minsep_glass, params, &c, h3), 0.5 * 7.019062713732535e-05,
              TOL_CLOSED);
}

/* The three speed choices along one approach: outside the film (v 0.5), entering at 0.3,
 * accelerating to 0.4, slowing to 0.1, separating at -0.2, leaving the film.
 * Expected speeds: max 0.3, 0.4, 0.4, 0.4; initial 0.3 throughout; current |v_n|. */
static void test_glass_speed_choices(void** state)
{
    (void)state;
    const double gaps[] = {300e-6, 200e-6, 100e-6, 50e-6, 60e-6};
    const double v[] = {0.5, 0.3, 0.4, 0.1, -0.2};
    const double want[3][5] = {
        {0.5, 0.3, 0.4, 0.4, 0.4}, {0.5, 0.3, 0.3, 0.3, 0.3}, {0.5, 0.3, 0.4, 0.1, 0.2}};
    const char* words[] = {"max", "initial", "current"};
    const struct wetdem_param_desc* d = wetdem_param_find(wetdem_minsep_glass.params, "speed");
    for (int choice = 0; choice < 3; choice++) {
        double params[4], history[3] = {0};
        wetdem_param_init_defaults(wetdem_minsep_glass.params, params);
        CHECK_REL((double)wetdem_param_choice_index(d, words[choice]), choice, 0);
        set(&wetdem_minsep_glass, params, "speed", choice);
        for (size_t k = 0; k < 5; k++) {
            struct wetdem_contact c = glass_pair(gaps[k], v[k]);
            double h = minsep(&wetdem_minsep_glass, params, &c, history);
            double expect = sqrt(3.0 * 10.0 * 12.7e-3 / 2 * want[choice][k] / 11.6e6);
            CHECK_REL(h, expect, TOL_CLOSED);
        }
        /* leaving the film clears the record */
        struct wetdem_contact out = glass_pair(300e-6, 0.05);
        minsep(&wetdem_minsep_glass, params, &out, history);
        CHECK_REL(history[0] + history[1] + history[2], 0, 0);
    }
}

/* h_min is a property of the pair: swapping i and j (unequal radii and masses) gives the
 * same value and the same history, bit for bit (only n and v_t change sign). */
static void test_minsep_swap_invariant(void** state)
{
    (void)state;
    const struct wetdem_model* models[] = {&wetdem_minsep_fixed, &wetdem_minsep_roughness,
                                           &wetdem_minsep_ehd,   &wetdem_minsep_max,
                                           &wetdem_minsep_glass, NULL};
    for (size_t k = 0; models[k]; k++) {
        struct wetdem_contact c = test_contact(3e-3, 9e-3, 0.02, 0.5, 40e-6, 0.8);
        c.v_t = (struct wetdem_vec3){0, 0.3, -0.1};
        struct wetdem_contact s = wetdem_contact_swapped(&c);
        double params[4], ha[3] = {0.2, 0, 0}, hb[3] = {0.2, 0, 0};
        wetdem_param_init_defaults(models[k]->params, params);
        CHECK_REL(minsep(models[k], params, &s, hb), minsep(models[k], params, &c, ha), 0);
        assert_true(models[k]->history_len <= 3);
        for (size_t q = 0; q < models[k]->history_len; q++)
            CHECK_REL(hb[q], ha[q], 0);
    }
}

/* Parameters through the simulation: out-of-range and NaN rejected with a message naming the
 * parameter and its range; choices by word. */
static void test_minsep_params_validated(void** state)
{
    (void)state;
    struct wetdem_sim* sim = wetdem_sim_create();
    CHECK_OK(wetdem_sim_enable_model(sim, "glass"));
    CHECK_REL((double)(wetdem_sim_min_separation_model(sim) == &wetdem_minsep_glass), 1, 0);
    CHECK_STATUS(wetdem_sim_set_param(sim, "glass.p_gt", -1e6), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "glass.p_gt");
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "(0, ");
    CHECK_STATUS(wetdem_sim_set_param(sim, "glass.p_gt", 0), WETDEM_ERR_INVALID);
    CHECK_STATUS(wetdem_sim_set_param(sim, "glass.p_gt", NAN), WETDEM_ERR_INVALID);
    CHECK_OK(wetdem_sim_set_param(sim, "glass.p_gt", 5e6));
    CHECK_OK(wetdem_sim_set_param_str(sim, "glass.speed", "initial"));
    double v = -1;
    CHECK_OK(wetdem_sim_param(sim, "glass.speed", &v));
    CHECK_REL(v, 1, 0);
    CHECK_STATUS(wetdem_sim_set_param_str(sim, "glass.speed", "maximum"), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "one of: max, initial, current");
    CHECK_OK(wetdem_sim_enable_model(sim, "ehd"));
    CHECK_STATUS(wetdem_sim_set_param(sim, "ehd.reset_ratio", 0), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "reset_ratio");
    CHECK_STATUS(wetdem_sim_param(sim, "glass.p_gt", &v), WETDEM_ERR_NOT_FOUND);
    wetdem_sim_free(sim);
}

/* Every min-separation model documents itself and has a min_separation function. */
static void test_minsep_models_documented(void** state)
{
    (void)state;
    const char* names[] = {"fixed", "roughness", "ehd", "max", "glass", NULL};
    for (size_t k = 0; names[k]; k++) {
        const struct wetdem_model* m = wetdem_model_find(names[k]);
        if (!m || m->kind != WETDEM_MODEL_MIN_SEPARATION || !m->min_separation || !m->doc ||
            !m->summary || !m->equations || m->pair)
            fail_msg("min-separation model %s is missing or incomplete", names[k]);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_roughness_is_mean_asperity_height),
        cmocka_unit_test(test_ehd_fifth_root_hand_value),
        cmocka_unit_test(test_ehd_history_keeps_largest_speed),
        cmocka_unit_test(test_max_takes_larger_mechanism),
        cmocka_unit_test(test_glass_hand_value_and_cap),
        cmocka_unit_test(test_glass_speed_choices),
        cmocka_unit_test(test_minsep_swap_invariant),
        cmocka_unit_test(test_minsep_params_validated),
        cmocka_unit_test(test_minsep_models_documented),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

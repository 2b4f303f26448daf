/*
 * test_pairwise_soft.c — the soft engine with the same film forces (db, davis; fixed h_min,
 * "c" below it) and an increasingly stiff damped Hertz contact converges to the pairwise
 * engine's hard-sphere result (SPEC §3: where the engines' assumptions coincide they agree).
 *
 * Head-on, equal steel-density spheres of radius 2 mm, delta = 100 um, h_min = 1 um,
 * mu = 1 Pa s, St_n = 10, e_dry = 0.8, no capillarity. What must agree:
 *  - e_w: identical for every stiffness, because the "exact" Hertz damping rebounds with exactly
 *    e_dry and the films exert no force below h_min ("c"): the normal speed at h_min is
 *    reversed and scaled by e_dry in both engines;
 *  - the time from film overlap to h_min: the same film dynamics;
 *  - the time from film overlap to film separation: the soft engine needs in addition the
 *    force-free flight through [0, h_min] in and out, (1 + 1/e_dry) h_min / v_c, and the Hertz
 *    contact time t_c ~ E^(-2/5); what remains after removing the flight tends to zero like
 *    t_c as E grows.
 */
#include "harness.h"

#define RADIUS 2e-3
#define DENSITY 7800.0
#define FILM 50e-6 /* per sphere: delta = 100 um */
#define HMIN 1e-6
#define EDRY 0.8
#define STOKES 10.0

struct soft_times {
    double e_n, t_hmin, t_sep, t_contact;
};

static struct soft_times soft_run(double youngs)
{
    struct wetdem_sim* sim = wetdem_sim_create();
    struct wetdem_material m = {.density = DENSITY,
                                .youngs_modulus = youngs,
                                .poisson_ratio = 0.3,
                                .restitution = EDRY,
                                .film = FILM};
    int im = wetdem_sim_add_material(sim, &m);
    struct wetdem_fluid fl = {.viscosity = 1.0, .surface_tension = 0.0, .density = 1000};
    CHECK_OK(wetdem_sim_set_fluid(sim, &fl));
    wetdem_sim_clear_models(sim);
    CHECK_OK(wetdem_sim_enable_model(sim, "db"));
    CHECK_OK(wetdem_sim_enable_model(sim, "davis"));
    CHECK_OK(wetdem_sim_enable_model(sim, "hertz"));
    CHECK_OK(wetdem_sim_enable_model(sim, "fixed"));
    CHECK_OK(wetdem_sim_set_param(sim, "fixed.h_min", HMIN));
    CHECK_OK(wetdem_sim_set_integrator(sim, "cvode"));
    CHECK_OK(wetdem_sim_set_param(sim, "cvode.rtol", 1e-10));
    struct wetdem_collision_spec sp = {.material_i = im,
                                       .material_j = im,
                                       .radius_i = RADIUS,
                                       .radius_j = RADIUS,
                                       .stokes = STOKES,
                                       .t_end = 0.01};
    struct wetdem_collision_result r;
    CHECK_OK(wetdem_collision_run(sim, &sp, &r));
    size_t n;
    const struct wetdem_event_record* ev = wetdem_sim_events(sim, &n);
    double t0 = NAN, t_hmin = NAN, t_sep = NAN;
    for (size_t k = 0; k < n; k++) {
        if (ev[k].kind == WETDEM_EVENT_INTERACTION_START && isnan(t0))
            t0 = ev[k].time;
        if (ev[k].kind == WETDEM_EVENT_HMIN_REACHED && isnan(t_hmin))
            t_hmin = ev[k].time;
        if (ev[k].kind == WETDEM_EVENT_INTERACTION_END)
            t_sep = ev[k].time;
    }
    wetdem_sim_free(sim);
    return (struct soft_times){r.e_n, t_hmin - t0, t_sep - t0, r.contact_duration};
}

static void test_pairwise_soft_engine_converges_to_hard_contact(void** state)
{
    (void)state;
    /* the pairwise run of the same collision */
    double mass = 4.0 / 3.0 * M_PI * RADIUS * RADIUS * RADIUS * DENSITY;
    double a = RADIUS / 2, m_eff = mass / 2, v0 = STOKES * 6 * M_PI * 1.0 * a * a / m_eff;
    struct wetdem_pairwise_config c;
    wetdem_pairwise_config_init(&c);
    c.n_spheres = 2;
    c.spheres[0] =
        (struct wetdem_pairwise_sphere){.radius = RADIUS, .mass = mass, .film = FILM, .vx = v0};
    c.spheres[1] = (struct wetdem_pairwise_sphere){
        .radius = RADIUS, .mass = mass, .film = FILM, .x = 2 * RADIUS + 2 * FILM};
    c.viscosity = 1.0;
    c.h_min = HMIN;
    c.restitution = EDRY;
    c.t_end = 0.01;
    c.rtol = 1e-11;
    struct wetdem_pairwise* pw = wetdem_pairwise_create();
    struct wetdem_pairwise_result r;
    CHECK_OK(wetdem_pairwise_run(pw, &c, &r));
    size_t n;
    const struct wetdem_pairwise_event* ev = wetdem_pairwise_events(pw, &n);
    double t_hit = NAN, v_c = NAN;
    for (size_t k = 0; k < n; k++)
        if (ev[k].kind == WETDEM_PAIRWISE_CONTACT) {
            t_hit = ev[k].time;
            v_c = ev[k].v_n;
        }
    double t_sep = r.pairs[0].t_end, flight = (1.0 + 1.0 / EDRY) * HMIN / v_c;
    wetdem_pairwise_free(pw);

    double prev = INFINITY;
    const double youngs[] = {1e10, 1e11, 1e12};
    for (int k = 0; k < 3; k++) {
        struct soft_times s = soft_run(youngs[k]);
        /* e_w: the soft engine's CVODE at rtol 1e-10 reproduces it to ~1e-7; 1e-5 is safe */
        CHECK_REL(s.e_n, r.pairs[0].e_wet, 1e-5);
        /* same film dynamics up to h_min: 1e-6 (both located to ~1e-10) */
        CHECK_REL(s.t_hmin, t_hit, 1e-6);
        /* what remains of the separation time after the force-free flight is the Hertz
         * contact: equal to 1e-3 of the film time, and shrinking like E^(-2/5) */
        double excess = s.t_sep - flight - t_sep;
        CHECK_ABS(excess, s.t_contact, 1e-3 * t_sep);
        assert_true(excess > 0.0 && excess < prev);
        if (k > 0)
            CHECK_REL(excess / prev, pow(10.0, -0.4), 0.05); /* t_c ~ E^(-2/5) */
        prev = excess;
    }
    /* at E = 1e12 Pa the event time differs from the hard-sphere one by < 2 % */
    assert_true(prev < 0.02 * t_sep);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pairwise_soft_engine_converges_to_hard_contact),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

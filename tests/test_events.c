/*
 * test_events.c — event location of the soft engine (STYLE §6.9.3): crossing times of a
 * free flight (t* = (h0 - h_k)/v) for every threshold, by both integrators; two events in one
 * Verlet step; direction (approach gives only start events, receding only end events);
 * simultaneous thresholds in a fixed order; terminal (stop on separation) versus non-terminal
 * events; and the approach speed logged at h_min against the closed form of Reynolds
 * lubrication, for a wall and for two free spheres (lubrication acts on walls).
 */
#include "harness.h"

/* Test-local model that exerts no force but acts (for events) within RANGE and lists the
 * thresholds range, h_min, 0. */
#define RANGE 1e-3 /* [m] */
#define HMIN 2e-4  /* [m], set as fixed.h_min */

static double null_range(const void* params, const struct wetdem_contact* c)
{
    (void)params;
    (void)c;
    return RANGE;
}

static int null_pair(const void* params, const struct wetdem_contact* c, double* history,
                     struct wetdem_pair_force* out)
{
    (void)params, (void)c, (void)history, (void)out;
    return WETDEM_OK;
}

static size_t null_thresholds(const void* params, const struct wetdem_contact* c,
                              const double* history, double* gaps)
{
    (void)params, (void)history;
    gaps[0] = RANGE;
    gaps[1] = c->h_min;
    gaps[2] = 0.0;
    return 3;
}

static const struct wetdem_param_desc no_params[] = {{0}};

static const struct wetdem_model null_model = {
    .name = "test_null",
    .kind = WETDEM_MODEL_FLUID,
    .summary = "no force, thresholds only",
    .doc = "",
    .equations = "",
    .params = no_params,
    .params_size = 0,
    .range = null_range,
    .pair = null_pair,
    .thresholds = null_thresholds,
};

static const char* const integrators[] = {"verlet", "cvode"};

/* Sphere of radius 1 mm at gap h0 from the wall x = 0 moving with v along x. */
static struct wetdem_sim* wall_sim(const char* integrator, double h0, double v,
                                   const struct wetdem_model* model)
{
    struct wetdem_sim* sim = wetdem_sim_create();
    int mat = wetdem_sim_add_material_preset(sim, "steel1");
    struct wetdem_particle p = {
        .pos = {1e-3 + h0, 0, 0}, .vel = {v, 0, 0}, .radius = 1e-3, .material = mat};
    CHECK_OK(wetdem_sim_add_particle(sim, p));
    CHECK_OK(wetdem_sim_add_wall(sim, (struct wetdem_vec3){0, 0, 0}, (struct wetdem_vec3){1, 0, 0},
                                 mat));
    if (model)
        CHECK_OK(wetdem_sim_add_model(sim, model, NULL));
    CHECK_OK(wetdem_sim_set_param(sim, "fixed.h_min", HMIN));
    CHECK_OK(wetdem_sim_set_integrator(sim, integrator));
    return sim;
}

/* Asserts the log holds exactly the given kinds at the given times (tolerance tol [s]). */
static void check_log(const struct wetdem_sim* sim, const enum wetdem_event_kind* kinds,
                      const double* times, size_t n, double tol)
{
    size_t m;
    const struct wetdem_event_record* ev = wetdem_sim_events(sim, &m);
    if (m != n)
        fail_msg("%zu events logged, expected %zu (first: %s)", m, n,
                 m ? wetdem_event_kind_name(ev[0].kind) : "none");
    for (size_t k = 0; k < n; k++) {
        if (ev[k].kind != kinds[k])
            fail_msg("event %zu is %s, expected %s", k, wetdem_event_kind_name(ev[k].kind),
                     wetdem_event_kind_name(kinds[k]));
        CHECK_ABS(ev[k].time, times[k], tol);
    }
}

/* Approach at v = 0.1 m/s from h0 = 2 mm: interaction at (2 - 1)/0.1 = 10 ms, h_min at
 * (2 - 0.2)/0.1 = 18 ms, contact at 20 ms. The gap is linear in time, so CVODE's root finder
 * (tolerance ~100 unit roundoffs of t) and Verlet's linear interpolation are both exact to
 * round-off: 1e-12 s. Verlet's step 1.5 ms does not divide the event times. */
static void test_events_free_flight_times(void** state)
{
    (void)state;
    enum wetdem_event_kind kinds[] = {WETDEM_EVENT_INTERACTION_START, WETDEM_EVENT_HMIN_REACHED,
                                      WETDEM_EVENT_CONTACT_START};
    double times[] = {0.010, 0.018, 0.020};
    for (int q = 0; q < 2; q++) {
        struct wetdem_sim* sim = wall_sim(integrators[q], 2e-3, -0.1, &null_model);
        CHECK_OK(wetdem_sim_set_param(sim, "verlet.dt", 1.5e-3));
        CHECK_OK(wetdem_sim_integrate(sim, 0.0205));
        check_log(sim, kinds, times, 3, 1e-12);
        size_t n;
        const struct wetdem_event_record* ev = wetdem_sim_events(sim, &n);
        CHECK_ABS(ev[1].gap, HMIN, 1e-15);
        CHECK_REL(ev[1].v_n, 0.1, 1e-12);
        assert_true(ev[1].is_wall && ev[1].i == 0 && ev[1].j == 0);
        struct wetdem_stats s = wetdem_sim_stats(sim);
        assert_int_equal(s.events, 3);
        assert_true(s.root_evals > 0);
        wetdem_sim_free(sim);
    }
}

/* A Verlet step of 9.5 ms spans [9.5, 19] ms and holds both the interaction start (10 ms) and
 * h_min (18 ms): both are logged, in time order, at their exact times. */
static void test_events_two_in_one_step(void** state)
{
    (void)state;
    struct wetdem_sim* sim = wall_sim("verlet", 2e-3, -0.1, &null_model);
    CHECK_OK(wetdem_sim_set_param(sim, "verlet.dt", 9.5e-3));
    CHECK_OK(wetdem_sim_integrate(sim, 0.0285));
    enum wetdem_event_kind kinds[] = {WETDEM_EVENT_INTERACTION_START, WETDEM_EVENT_HMIN_REACHED,
                                      WETDEM_EVENT_CONTACT_START};
    double times[] = {0.010, 0.018, 0.020};
    check_log(sim, kinds, times, 3, 1e-12);
    wetdem_sim_free(sim);
}

/* Receding from an overlap of 0.1 mm at 0.1 m/s: only end events, contact end at 1 ms,
 * h_min left at 3 ms, interaction end at 11 ms; approaching gave only start events above. */
static void test_events_direction(void** state)
{
    (void)state;
    enum wetdem_event_kind kinds[] = {WETDEM_EVENT_CONTACT_END, WETDEM_EVENT_HMIN_LEFT,
                                      WETDEM_EVENT_INTERACTION_END};
    double times[] = {0.001, 0.003, 0.011};
    for (int q = 0; q < 2; q++) {
        struct wetdem_sim* sim = wall_sim(integrators[q], -1e-4, 0.1, &null_model);
        CHECK_OK(wetdem_sim_set_param(sim, "verlet.dt", 7e-4));
        CHECK_OK(wetdem_sim_integrate(sim, 0.02));
        check_log(sim, kinds, times, 3, 1e-12);
        wetdem_sim_free(sim);
    }
}

/* Dry Hertz has range 0: the interaction and the contact start together and end together;
 * the log orders starts as (interaction, contact) and ends as (contact, interaction). */
static void test_events_simultaneous_order(void** state)
{
    (void)state;
    enum wetdem_event_kind kinds[] = {WETDEM_EVENT_INTERACTION_START, WETDEM_EVENT_CONTACT_START,
                                      WETDEM_EVENT_CONTACT_END, WETDEM_EVENT_INTERACTION_END};
    for (int q = 0; q < 2; q++) {
        struct wetdem_sim* sim = wall_sim(integrators[q], 1e-4, -0.1, NULL);
        CHECK_OK(wetdem_sim_enable_model(sim, "hertz"));
        CHECK_OK(wetdem_sim_integrate(sim, 0.003));
        size_t n;
        const struct wetdem_event_record* ev = wetdem_sim_events(sim, &n);
        assert_int_equal(n, 4);
        double times[] = {1e-3, 1e-3, ev[2].time, ev[2].time};
        check_log(sim, kinds, times, 4, 1e-9); /* Verlet: 1e-9 s is 1 % of its step */
        wetdem_sim_free(sim);
    }
}

/* Terminal event: with sim.stop_on_separation the run stops (WETDEM_EVENT) once the pair that
 * interacted is beyond its range and receding: at 11 ms exactly for CVODE (located root), at
 * the first step after it for Verlet (step 0.7 ms). A second call runs on to t_end with
 * WETDEM_OK (the separation has been reported). With separation_factor = 2 the stop moves to
 * gap 2 mm, t = 21 ms. Without the setting the same events are logged and the run goes on. */
static void test_events_terminal(void** state)
{
    (void)state;
    for (int q = 0; q < 2; q++) {
        double tol = q ? 1e-12 : 7e-4;
        struct wetdem_sim* sim = wall_sim(integrators[q], -1e-4, 0.1, &null_model);
        CHECK_OK(wetdem_sim_set_param(sim, "verlet.dt", 7e-4));
        CHECK_OK(wetdem_sim_set_param_str(sim, "sim.stop_on_separation", "yes"));
        CHECK_STATUS(wetdem_sim_integrate(sim, 0.05), WETDEM_EVENT);
        double t = wetdem_sim_time(sim);
        assert_true(t >= 0.011 - 1e-12 && t <= 0.011 + tol);
        CHECK_OK(wetdem_sim_integrate(sim, 0.05));
        CHECK_REL(wetdem_sim_time(sim), 0.05, 1e-15);
        wetdem_sim_free(sim);

        sim = wall_sim(integrators[q], -1e-4, 0.1, &null_model);
        CHECK_OK(wetdem_sim_set_param(sim, "verlet.dt", 7e-4));
        CHECK_OK(wetdem_sim_set_param_str(sim, "sim.stop_on_separation", "yes"));
        CHECK_OK(wetdem_sim_set_param(sim, "sim.separation_factor", 2));
        CHECK_STATUS(wetdem_sim_integrate(sim, 0.05), WETDEM_EVENT);
        t = wetdem_sim_time(sim);
        assert_true(t >= 0.021 - 1e-12 && t <= 0.021 + tol);
        size_t n;
        wetdem_sim_events(sim, &n);
        assert_int_equal(n, 3); /* the separation threshold itself is not logged */
        wetdem_sim_free(sim);

        sim = wall_sim(integrators[q], -1e-4, 0.1, &null_model);
        CHECK_OK(wetdem_sim_integrate(sim, 0.05));
        wetdem_sim_events(sim, &n);
        assert_int_equal(n, 3);
        wetdem_sim_free(sim);
    }
}

/* Reynolds lubrication between a sphere and a wall (R* = R, m* = m):
 *     m dv/dt = -6 pi mu R^2 v / h,  dh/dt = -v   =>   v(h) = v0 - (6 pi mu R^2/m) ln(h_co/h)
 * for h_min <= h <= h_co = R. At h = h_min = 0.2 mm with R = 1 mm, mu = 0.05 Pa s, steel
 * (m = 7780 x 4/3 pi 1e-9 = 3.259e-5 kg), v0 = 0.5 m/s: 6 pi mu R^2/m = 9.425e-7/3.259e-5
 * = 0.02892 m/s per e-fold, ln(5) = 1.609, v = 0.5 - 0.04655 = 0.45345 m/s.
 * The logged v_n at the h_min event must match: CVODE to 1e-6 (rtol 1e-10), Verlet at
 * dt = 1 us to 1e-4 (its O(dt^2) error and the linear interpolation of v_n over one step). */
static void test_events_wall_lubrication_acts(void** state)
{
    (void)state;
    for (int q = 0; q < 2; q++) {
        struct wetdem_sim* sim = wall_sim(integrators[q], 1.5e-3, -0.5, NULL);
        CHECK_OK(wetdem_sim_enable_model(sim, "reynolds"));
        struct wetdem_fluid f = {.viscosity = 0.05, .surface_tension = 0, .density = 1000};
        CHECK_OK(wetdem_sim_set_fluid(sim, &f));
        CHECK_OK(wetdem_sim_set_param(sim, "verlet.dt", 1e-6));
        CHECK_OK(wetdem_sim_set_param(sim, "cvode.rtol", 1e-10));
        CHECK_OK(wetdem_sim_set_param(sim, "cvode.atol", 1e-12));
        CHECK_OK(wetdem_sim_integrate(sim, 0.0035));
        size_t n;
        const struct wetdem_event_record* ev = wetdem_sim_events(sim, &n);
        assert_true(n >= 2);
        assert_int_equal(ev[1].kind, WETDEM_EVENT_HMIN_REACHED);
        size_t np;
        double m = wetdem_sim_particles(sim, &np)[0].mass;
        double v = 0.5 - 6 * M_PI * 0.05 * 1e-6 / m * log(1e-3 / HMIN);
        CHECK_REL(ev[1].v_n, v, q ? 1e-6 : 1e-4);
        wetdem_sim_free(sim);
    }
}

/* The same law between two free spheres of radii 1 and 2 mm (R* = 2/3 mm, cut-off h_co = R*),
 * with reduced mass m*: v_n(h_min) = v0 - (6 pi mu R*^2 / m_eff) ln(R* / h_min), to 1e-7
 * (rtol 1e-10, atol 1e-12: ~100 steps of local errors 1e-10). Swapping which sphere moves
 * (Galilean invariance and i-j symmetry) gives the same relative speed at the event within
 * the same accumulated tolerance, 1e-7. */
static void test_events_pair_lubrication(void** state)
{
    (void)state;
    double r1 = 1e-3, r2 = 2e-3, rs = r1 * r2 / (r1 + r2), v_first = 0;
    for (int swap = 0; swap < 2; swap++) {
        struct wetdem_sim* sim = wetdem_sim_create();
        int mat = wetdem_sim_add_material_preset(sim, "glass");
        double x1 = r1 + r2 + 1e-3;
        struct wetdem_particle a = {
            .pos = {x1, 0, 0}, .vel = {swap ? 0 : -0.5, 0, 0}, .radius = r1, .material = mat};
        struct wetdem_particle b = {
            .pos = {0, 0, 0}, .vel = {swap ? 0.5 : 0, 0, 0}, .radius = r2, .material = mat};
        CHECK_OK(wetdem_sim_add_particle(sim, a));
        CHECK_OK(wetdem_sim_add_particle(sim, b));
        CHECK_OK(wetdem_sim_enable_model(sim, "reynolds"));
        struct wetdem_fluid f = {.viscosity = 0.05, .surface_tension = 0, .density = 1000};
        CHECK_OK(wetdem_sim_set_fluid(sim, &f));
        CHECK_OK(wetdem_sim_set_param(sim, "fixed.h_min", 1e-4));
        CHECK_OK(wetdem_sim_set_integrator(sim, "cvode"));
        CHECK_OK(wetdem_sim_set_param(sim, "cvode.rtol", 1e-10));
        CHECK_OK(wetdem_sim_set_param(sim, "cvode.atol", 1e-12));
        CHECK_OK(wetdem_sim_integrate(sim, 0.003));
        size_t n, np;
        const struct wetdem_event_record* ev = wetdem_sim_events(sim, &n);
        assert_true(n >= 2);
        assert_int_equal(ev[1].kind, WETDEM_EVENT_HMIN_REACHED);
        const struct wetdem_particle* p = wetdem_sim_particles(sim, &np);
        double ms = p[0].mass * p[1].mass / (p[0].mass + p[1].mass);
        double v = 0.5 - 6 * M_PI * 0.05 * rs * rs / ms * log(rs / 1e-4);
        CHECK_REL(ev[1].v_n, v, 1e-7);
        if (swap)
            CHECK_REL(ev[1].v_n, v_first, 1e-7);
        v_first = ev[1].v_n;
        wetdem_sim_free(sim);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_events_free_flight_times),
        cmocka_unit_test(test_events_two_in_one_step),
        cmocka_unit_test(test_events_direction),
        cmocka_unit_test(test_events_simultaneous_order),
        cmocka_unit_test(test_events_terminal),
        cmocka_unit_test(test_events_wall_lubrication_acts),
        cmocka_unit_test(test_events_pair_lubrication),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

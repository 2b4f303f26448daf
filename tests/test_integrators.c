/*
 * test_integrators.c — conformance matrix of the soft engine's integrators (STYLE §6.9.2):
 * every integrator on free flight, constant force (gravity and a constant torque), the
 * harmonic oscillator and the damped oscillator against their closed forms; the convergence
 * order of Verlet; its time reversibility; CVODE meeting its tolerance; parameter names; the
 * CVODE vector kernels giving the same bits as the SUNDIALS serial kernels they replace.
 *
 * The oscillators use a test-local force model between a sphere and a plane wall:
 *     f_normal = -k h + c v_n,   h = gap, v_n = -dh/dt,
 * so that m h'' = -k h - c h': omega_0 = sqrt(k/m), zeta = c/(2 sqrt(k m)).
 */
#include "harness.h"

#include <string.h>

#include "integrator_cvode_nvec.h"
#include "sim.h"

struct spring_params {
    double k;      /* [N/m] */
    double c;      /* [N s/m] */
    double torque; /* constant torque on i about z [N m] */
};

static const struct wetdem_param_desc spring_desc[] = {
    {"k", "N/m", "stiffness", offsetof(struct spring_params, k), 0, 0, 1e12, false, false, NULL,
     false},
    {"c", "N s/m", "damping", offsetof(struct spring_params, c), 0, 0, 1e12, false, false, NULL,
     false},
    {"torque", "N m", "torque", offsetof(struct spring_params, torque), 0, -1, 1, false, false,
     NULL, false},
    {0},
};

static double spring_range(const void* params, const struct wetdem_contact* c)
{
    (void)params;
    (void)c;
    return 10.0; /* acts everywhere in these tests [m] */
}

static int spring_pair(const void* params, const struct wetdem_contact* c, double* history,
                       struct wetdem_pair_force* out)
{
    (void)history;
    const struct spring_params* p = params;
    out->f_normal += -p->k * c->gap + p->c * c->v_n;
    out->torque_i.z += p->torque;
    return WETDEM_OK;
}

static const struct wetdem_model spring_model = {
    .name = "test_spring",
    .kind = WETDEM_MODEL_FLUID,
    .summary = "linear spring-dashpot for tests",
    .doc = "",
    .equations = "",
    .params = spring_desc,
    .params_size = sizeof(struct spring_params),
    .range = spring_range,
    .pair = spring_pair,
};

static const char* const integrators[] = {"verlet", "cvode"};

#define MASS 2e-3   /* [kg] */
#define RADIUS 1e-3 /* [m] */

/* A sphere of MASS and RADIUS at x = RADIUS + gap0 moving with v0 along x, a wall x = 0
 * with normal +x when with_wall, the given integrator. */
static struct wetdem_sim* make_sim(const char* integrator, double gap0, double v0, bool with_wall,
                                   const struct spring_params* sp)
{
    struct wetdem_sim* sim = wetdem_sim_create();
    assert_non_null(sim);
    int mat = wetdem_sim_add_material_preset(sim, "steel1");
    assert_true(mat >= 0);
    struct wetdem_particle p = {.pos = {RADIUS + gap0, 0, 0},
                                .vel = {v0, 0, 0},
                                .radius = RADIUS,
                                .mass = MASS,
                                .material = mat};
    CHECK_OK(wetdem_sim_add_particle(sim, p));
    if (with_wall)
        CHECK_OK(wetdem_sim_add_wall(sim, (struct wetdem_vec3){0, 0, 0},
                                     (struct wetdem_vec3){1, 0, 0}, mat));
    if (sp)
        CHECK_OK(wetdem_sim_add_model(sim, &spring_model, sp));
    CHECK_OK(wetdem_sim_set_integrator(sim, integrator));
    CHECK_OK(wetdem_sim_set_param(sim, "cvode.rtol", 1e-10));
    CHECK_OK(wetdem_sim_set_param(sim, "cvode.atol", 1e-12));
    return sim;
}

static struct wetdem_particle particle0(struct wetdem_sim* sim)
{
    size_t n;
    return wetdem_sim_particles(sim, &n)[0];
}

/* Free flight: x = x0 + v t. Verlet is exact (zero force); CVODE's error test sees zero
 * derivatives of the acceleration, so it is exact to round-off as well: 1e-12 relative. */
static void test_integrators_free_flight(void** state)
{
    (void)state;
    for (int q = 0; q < 2; q++) {
        struct wetdem_sim* sim = make_sim(integrators[q], 0.5, 0.3, false, NULL);
        CHECK_OK(wetdem_sim_set_param(sim, "verlet.dt", 1e-3));
        CHECK_OK(wetdem_sim_integrate(sim, 0.25));
        struct wetdem_particle p = particle0(sim);
        CHECK_REL(wetdem_sim_time(sim), 0.25, 1e-15);
        CHECK_REL(p.pos.x, RADIUS + 0.5 + 0.3 * 0.25, 1e-12);
        CHECK_REL(p.vel.x, 0.3, 1e-14);
        wetdem_sim_free(sim);
    }
}

/* A span below WETDEM_MIN_SPAN: CVODE's own check failed ("tstop is behind t"); it is
 * refused with the span in the message and the state untouched. */
static void test_integrators_shortest_span(void** state)
{
    (void)state;
    struct wetdem_sim* sim = make_sim("cvode", 0.5, 0.3, false, NULL);
    CHECK_STATUS(wetdem_sim_integrate(sim, 1e-300), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "t_end - t = 1e-300 s is shorter than the 1e-150 s");
    assert_true(wetdem_sim_time(sim) == 0);
    CHECK_OK(wetdem_sim_integrate(sim, 1e-150)); /* at the bound: integrated */
    assert_true(wetdem_sim_time(sim) == 1e-150);
    wetdem_sim_free(sim);
}

/* CVODE cannot tell t_end from t when they are within 2 DBL_EPSILON of each other (its "tout
 * too close to t0"): a call from t = 0.25 s to the next double, 5.6e-17 s on, far above
 * WETDEM_MIN_SPAN, failed as WETDEM_ERR_STEP with CVODE's message. It is refused as a span
 * too short, with the state untouched, and a span of 1e-15 s (9 of those roundings) is
 * integrated. */
static void test_integrators_shortest_span_after_t(void** state)
{
    (void)state;
    struct wetdem_sim* sim = make_sim("cvode", 0.5, 0.3, false, NULL);
    CHECK_OK(wetdem_sim_integrate(sim, 0.25));
    struct wetdem_particle p = particle0(sim);
    CHECK_STATUS(wetdem_sim_integrate(sim, nextafter(0.25, 1)), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "t_end - t = 5.55112e-17 s is shorter than the "
                                           "1.11022e-16 s that CVODE integrates from t");
    assert_true(wetdem_sim_time(sim) == 0.25);
    struct wetdem_particle q = particle0(sim);
    assert_memory_equal(&p, &q, sizeof p);
    CHECK_OK(wetdem_sim_integrate(sim, 0.25 + 1e-15));
    assert_true(wetdem_sim_time(sim) == 0.25 + 1e-15);
    wetdem_sim_free(sim);
}

/* A failure message may quote the one before it (wetdem_sim_fail formats into its own
 * buffer first: formatting into the message it reads garbled both) */
static void test_integrators_message_quotes_the_last(void** state)
{
    (void)state;
    struct wetdem_sim* sim = make_sim("cvode", 0.5, 0.3, false, NULL);
    wetdem_sim_fail(sim, WETDEM_ERR_STEP, "inner %d", 7);
    wetdem_sim_fail(sim, WETDEM_ERR_STEP, "outer (%s)", wetdem_sim_errmsg(sim));
    assert_string_equal(wetdem_sim_errmsg(sim), "outer (inner 7)");
    wetdem_sim_free(sim);
}

/* Constant force: gravity g = -9.81 z: z = v0 t + g t^2/2, v = g t; constant torque tau on a
 * sphere of I = 2/5 m R^2 = 8e-10 kg m^2: w = tau t / I. Both integrators are exact for a
 * constant acceleration up to round-off (Verlet: the Taylor series ends at t^2; CVODE: the
 * second derivative is constant, the error estimate vanishes): 1e-10 relative. */
static void test_integrators_constant_force(void** state)
{
    (void)state;
    struct spring_params sp = {.k = 0, .c = 0, .torque = 1e-6};
    for (int q = 0; q < 2; q++) {
        struct wetdem_sim* sim = make_sim(integrators[q], 0.5, 0.0, true, &sp);
        CHECK_OK(wetdem_sim_set_param(sim, "sim.gravity_z", -9.81));
        CHECK_OK(wetdem_sim_set_param(sim, "verlet.dt", 1e-3));
        size_t n;
        wetdem_sim_particles(sim, &n)[0].vel.z = 2.0;
        CHECK_OK(wetdem_sim_integrate(sim, 0.4));
        struct wetdem_particle p = particle0(sim);
        CHECK_REL(p.pos.z, 2.0 * 0.4 - 0.5 * 9.81 * 0.4 * 0.4, 1e-10);
        CHECK_REL(p.vel.z, 2.0 - 9.81 * 0.4, 1e-10);
        double inertia = 0.4 * MASS * RADIUS * RADIUS;
        CHECK_REL(p.omega.z, 1e-6 * 0.4 / inertia, 1e-10);
        wetdem_sim_free(sim);
    }
}

/* Closed form of m h'' + c h' + k h = 0 with h(0) = h0, h'(0) = u0 (underdamped). */
static void oscillator(double k, double c, double h0, double u0, double t, double* h, double* u)
{
    double w0 = sqrt(k / MASS), zeta = c / (2.0 * sqrt(k * MASS));
    double wd = w0 * sqrt(1.0 - zeta * zeta), s = zeta * w0;
    double a = h0, b = (u0 + s * h0) / wd;
    double e = exp(-s * t), cs = cos(wd * t), sn = sin(wd * t);
    *h = e * (a * cs + b * sn);
    *u = e * ((-s * a + wd * b) * cs + (-s * b - wd * a) * sn);
}

/* Error of one integrator on the oscillator released at h0 = 2e-4 m with speed u0 over 1.3
 * periods: max(|dh|/A, |du|/(A w0)). */
static double oscillator_error_from(const char* integrator, double c, double dt, double rtol,
                                    double u0)
{
    struct spring_params sp = {.k = 50.0, .c = c};
    double h0 = 2e-4, w0 = sqrt(sp.k / MASS), t_end = 1.3 * 2 * M_PI / w0;
    struct wetdem_sim* sim = make_sim(integrator, h0, u0, true, &sp);
    CHECK_OK(wetdem_sim_set_param(sim, "verlet.dt", dt));
    CHECK_OK(wetdem_sim_set_param(sim, "cvode.rtol", rtol));
    CHECK_OK(wetdem_sim_set_param(sim, "cvode.atol", rtol * 0.1));
    CHECK_OK(wetdem_sim_integrate(sim, t_end));
    struct wetdem_particle p = particle0(sim);
    double h, u, amp = sqrt(h0 * h0 + u0 * u0 / (w0 * w0));
    oscillator(sp.k, c, h0, u0, t_end, &h, &u);
    wetdem_sim_free(sim);
    return fmax(fabs(p.pos.x - RADIUS - h) / amp, fabs(p.vel.x - u) / (amp * w0));
}

/* The same, released with u0 = -0.05 m/s. */
static double oscillator_error(const char* integrator, double c, double dt, double rtol)
{
    return oscillator_error_from(integrator, c, dt, rtol, -0.05);
}

/* Harmonic and damped oscillators: both integrators within 1e-4 of the amplitude at
 * omega_0 dt = 0.005 (Verlet's global error ~ (omega dt)^2 omega t / 24 ~ 1e-5 here) and
 * rtol = 1e-8 (a global error of ~100 local tolerances is allowed for the accumulation over
 * the ~100s of steps of 1.3 periods). */
static void test_integrators_oscillators(void** state)
{
    (void)state;
    double w0 = sqrt(50.0 / MASS), dt = 0.005 / w0;
    double cs[] = {0.0, 0.2 * 2 * sqrt(50.0 * MASS)}; /* zeta = 0 and 0.2 */
    for (int q = 0; q < 2; q++)
        for (int d = 0; d < 2; d++) {
            double err = oscillator_error(integrators[q], cs[d], dt, 1e-8);
            if (!(err < 1e-4))
                fail_msg("%s, zeta = %g: error %g >= 1e-4", integrators[q], d ? 0.2 : 0.0, err);
        }
}

/* Released from rest, nothing moves at the start: CVODE's default largest step, 0.1 L over the
 * pairs' largest relative speed, is then unbounded, and its error control alone resolves the
 * oscillation: the same 1e-4 as from motion (measured 7.5e-7 undamped, 6.3e-8 at zeta 0.2; the
 * largest step was 0.1 L / sim.speed_floor before). */
static void test_integrators_cvode_released_from_rest(void** state)
{
    (void)state;
    double cs[] = {0.0, 0.2 * 2 * sqrt(50.0 * MASS)};
    for (int d = 0; d < 2; d++) {
        double err = oscillator_error_from("cvode", cs[d], 0, 1e-8, 0.0);
        if (!(err < 1e-4))
            fail_msg("zeta = %g: error %g >= 1e-4", d ? 0.2 : 0.0, err);
    }
}

/* Verlet is second order, also with damping (velocity-dependent forces on the predicted
 * velocity): halving dt divides the error by 4; accepted within [3.6, 4.4], which the O(dt^3)
 * remainder at omega dt <= 0.04 stays well inside. */
static void test_integrators_verlet_order_two(void** state)
{
    (void)state;
    double w0 = sqrt(50.0 / MASS);
    for (int d = 0; d < 2; d++) {
        double c = d ? 0.2 * 2 * sqrt(50.0 * MASS) : 0.0;
        double e1 = oscillator_error("verlet", c, 0.04 / w0, 1e-8);
        double e2 = oscillator_error("verlet", c, 0.02 / w0, 1e-8);
        double ratio = e1 / e2;
        if (!(ratio > 3.6 && ratio < 4.4))
            fail_msg("zeta = %g: error ratio %g (errors %g, %g), expected ~4", d ? 0.2 : 0.0, ratio,
                     e1, e2);
    }
}

/* Velocity Verlet is time-reversible: N steps forward, velocities reversed, N steps forward
 * again return to the start position with the reversed velocity, up to round-off (1e-12
 * relative after 2 x 1000 steps of O(1e-16) errors each). */
static void test_integrators_verlet_reversible(void** state)
{
    (void)state;
    struct spring_params sp = {.k = 50.0};
    struct wetdem_sim* sim = make_sim("verlet", 2e-4, -0.05, true, &sp);
    double dt = 0.05 / sqrt(50.0 / MASS);
    CHECK_OK(wetdem_sim_set_param(sim, "verlet.dt", dt));
    CHECK_OK(wetdem_sim_integrate(sim, 1000 * dt));
    size_t n;
    struct wetdem_particle* p = wetdem_sim_particles(sim, &n);
    p[0].vel.x = -p[0].vel.x;
    CHECK_OK(wetdem_sim_integrate(sim, 2000 * dt));
    CHECK_REL(p[0].pos.x, RADIUS + 2e-4, 1e-12);
    CHECK_REL(p[0].vel.x, 0.05, 1e-11);
    wetdem_sim_free(sim);
}

/* CVODE meets its tolerance: the global error of the oscillator falls with rtol, stays
 * within 200 rtol (local control, accumulated over ~100 steps), and tightening rtol by 1000
 * reduces it by more than 10. (Not by 100 over two decades: while the sphere closes in on
 * the wall the contact step bound, a stop time, also shortens steps, and the more so at the
 * looser tolerance: errors measured 3.1e-6, 3.1e-7 and 4.4e-8 at rtol 1e-6, 1e-8, 1e-9.) */
static void test_integrators_cvode_tolerance(void** state)
{
    (void)state;
    double c = 0.1 * 2 * sqrt(50.0 * MASS);
    double e6 = oscillator_error("cvode", c, 0, 1e-6);
    double e9 = oscillator_error("cvode", c, 0, 1e-9);
    if (!(e6 < 200 * 1e-6 && e9 < 200 * 1e-9 && e6 / e9 > 10))
        fail_msg("cvode errors %g (rtol 1e-6), %g (rtol 1e-9)", e6, e9);
}

/* Work counters: Verlet takes exactly ceil(t/dt) steps with one force evaluation each (plus
 * one at the start); CVODE counts its steps and far fewer evaluations on a smooth problem. */
static void test_integrators_stats(void** state)
{
    (void)state;
    struct spring_params sp = {.k = 50.0};
    struct wetdem_sim* sim = make_sim("verlet", 2e-4, -0.05, true, &sp);
    CHECK_OK(wetdem_sim_set_param(sim, "verlet.dt", 1e-4));
    CHECK_OK(wetdem_sim_integrate(sim, 0.05));
    struct wetdem_stats s = wetdem_sim_stats(sim);
    assert_int_equal(s.steps, 500);
    assert_int_equal(s.force_evals, 501);
    assert_int_equal(s.pair_evals, 501);
    wetdem_sim_free(sim);
    sim = make_sim("cvode", 2e-4, -0.05, true, &sp);
    CHECK_OK(wetdem_sim_integrate(sim, 0.05));
    s = wetdem_sim_stats(sim);
    assert_true(s.steps > 10 && s.steps < 2000);
    assert_true(s.force_evals >= s.steps && s.force_evals < 501);
    wetdem_sim_free(sim);
}

/* Parameter names reach the integrators, with range checks and suggestions. */
static void test_integrators_params(void** state)
{
    (void)state;
    struct wetdem_sim* sim = wetdem_sim_create();
    double v;
    CHECK_OK(wetdem_sim_param(sim, "verlet.dt_fraction", &v));
    CHECK_REL(v, 0.02, 0);
    CHECK_OK(wetdem_sim_set_param(sim, "cvode.rtol", 1e-6));
    CHECK_OK(wetdem_sim_param(sim, "cvode.rtol", &v));
    CHECK_REL(v, 1e-6, 0);
    CHECK_OK(wetdem_sim_set_param_str(sim, "cvode.method", "bdf"));
    CHECK_STATUS(wetdem_sim_set_param(sim, "cvode.rtol", -1), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "rtol");
    CHECK_STATUS(wetdem_sim_set_param(sim, "verlet.dt_fractoin", 0.01), WETDEM_ERR_NOT_FOUND);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "verlet.dt_fraction");
    CHECK_STATUS(wetdem_sim_set_integrator(sim, "cvod"), WETDEM_ERR_NOT_FOUND);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "cvode");
    assert_string_equal(wetdem_sim_integrator_name(sim), "verlet");
    CHECK_OK(wetdem_sim_set_integrator(sim, "cvode"));
    assert_string_equal(wetdem_sim_integrator_name(sim), "cvode");
    CHECK_STATUS(wetdem_sim_integrate(sim, -1.0), WETDEM_ERR_INVALID);
    CHECK_STATUS(wetdem_sim_integrate(sim, NAN), WETDEM_ERR_INVALID);
    wetdem_sim_free(sim);
}

/* The BDF variant agrees with the closed form too (damped oscillator, 1e-4). */
static void test_integrators_cvode_bdf(void** state)
{
    (void)state;
    struct spring_params sp = {.k = 50.0, .c = 0.2 * 2 * sqrt(50.0 * MASS)};
    double h0 = 2e-4, u0 = -0.05, w0 = sqrt(sp.k / MASS), t_end = 1.3 * 2 * M_PI / w0;
    struct wetdem_sim* sim = make_sim("cvode", h0, u0, true, &sp);
    CHECK_OK(wetdem_sim_set_param_str(sim, "cvode.method", "bdf"));
    CHECK_OK(wetdem_sim_set_param(sim, "cvode.rtol", 1e-9));
    CHECK_OK(wetdem_sim_integrate(sim, t_end));
    double h, u;
    oscillator(sp.k, sp.c, h0, u0, t_end, &h, &u);
    struct wetdem_particle p = particle0(sim);
    CHECK_ABS(p.pos.x - RADIUS, h, 1e-4 * h0);
    wetdem_sim_free(sim);
}

/* Observer: called at t = 0, every interval and at the end; a non-zero return stops the run
 * with WETDEM_ERR_CALLBACK. */
struct obs {
    int calls;
    double last_t;
    int stop_after;
};

static int observer(const struct wetdem_sim* sim, void* ctx)
{
    struct obs* o = ctx;
    o->calls++;
    o->last_t = wetdem_sim_time(sim);
    return o->stop_after && o->calls >= o->stop_after;
}

static void test_integrators_observer(void** state)
{
    (void)state;
    for (int q = 0; q < 2; q++) {
        struct spring_params sp = {.k = 50.0};
        struct wetdem_sim* sim = make_sim(integrators[q], 2e-4, -0.05, true, &sp);
        CHECK_OK(wetdem_sim_set_param(sim, "verlet.dt", 1e-5));
        struct obs o = {0};
        wetdem_sim_set_observer(sim, 0.01, observer, &o);
        CHECK_OK(wetdem_sim_integrate(sim, 0.1));
        /* t = 0, 0.01, ..., 0.1: 11 calls (the last one is the end) */
        assert_int_equal(o.calls, 11);
        CHECK_REL(o.last_t, 0.1, 1e-12);
        o = (struct obs){.stop_after = 3};
        CHECK_STATUS(wetdem_sim_integrate(sim, 0.2), WETDEM_ERR_CALLBACK);
        /* an interval that is not finite and >= 0 is refused with an observer, and is nothing
           without one (fn NULL removes it: the run was refused all the same) */
        wetdem_sim_set_observer(sim, NAN, observer, &o);
        double t = wetdem_sim_time(sim);
        CHECK_STATUS(wetdem_sim_integrate(sim, 0.3), WETDEM_ERR_INVALID);
        CHECK_CONTAINS(wetdem_sim_errmsg(sim), "observer interval = nan");
        CHECK_REL(wetdem_sim_time(sim), t, 0);
        wetdem_sim_set_observer(sim, NAN, NULL, NULL);
        CHECK_OK(wetdem_sim_integrate(sim, 0.3));
        wetdem_sim_free(sim);
    }
}

/* The observer sees each multiple k of its interval once: cvode on its interpolant at k x
 * interval itself, the fixed-step engines (verlet, the many-particle mode) at the first step end
 * at or after it; then once at the end of the run. The interval, 1e-7 s, is no binary fraction,
 * so that the multiples computed as products and the step ends or the multiples computed as sums
 * land either side of one another by a rounding: cvode observed one multiple in about 27 twice
 * (1.3999999999999997e-06 s and 1.3999999999999999e-06 s), verlet with a step of 3e-8 s one in
 * 50, and the many-particle mode the start twice (at t = 0 and after the first step). */
struct grid_obs {
    int calls;
    double t[256];
};

static int grid_observer(const struct wetdem_sim* sim, void* ctx)
{
    struct grid_obs* o = ctx;
    if (o->calls < 256)
        o->t[o->calls] = wetdem_sim_time(sim);
    o->calls++;
    return 0;
}

static void test_integrators_observer_sees_each_multiple_once(void** state)
{
    (void)state;
    const double interval = 1e-7, t_end = 200.5 * interval, dt = 3e-8;
    const char* const engine[] = {"verlet", "cvode", "many"};
    for (int q = 0; q < 3; q++) {
        struct spring_params sp = {.k = 50.0};
        struct wetdem_sim* sim = make_sim(q == 1 ? "cvode" : "verlet", 2e-4, -0.05, true, &sp);
        CHECK_OK(wetdem_sim_set_param(sim, "verlet.dt", dt));
        struct wetdem_many_settings ms = {.dt = dt};
        if (q == 2)
            CHECK_OK(wetdem_sim_set_many(sim, &ms));
        struct grid_obs o = {0};
        wetdem_sim_set_observer(sim, interval, grid_observer, &o);
        CHECK_OK(wetdem_sim_integrate(sim, t_end));
        /* the multiples 0 .. 200 and the end (at 200.5) */
        if (o.calls != 202)
            fail_msg("%s: %d observer calls, want 202", engine[q], o.calls);
        for (int k = 0; k <= 200; k++) {
            double lo = k * interval * (1 - 1e-12), hi = k * interval + (q == 1 ? 0.0 : dt);
            if (!(o.t[k] >= lo && o.t[k] <= hi * (1 + 1e-12)))
                fail_msg("%s: call %d at t = %.17g s, want the multiple %.17g s%s", engine[q], k,
                         o.t[k], k * interval, q == 1 ? "" : " or the step end after it");
        }
        CHECK_REL(o.t[201], wetdem_sim_time(sim), 0); /* t_end; many: the step end after it */
        CHECK_REL(wetdem_sim_time(sim), q == 2 ? ceil(t_end / dt) * dt : t_end, 1e-12);
        wetdem_sim_free(sim);
    }
}

/* An observer that stops the run leaves it at the state it saw: cvode calls it on its
 * interpolant within a step, and the run stayed at the end of that step, up to a step past
 * the time the observer was told (3.07e-3 s for 3e-3 s here), so that the state it
 * returned was not the one the observer saw and a further call skipped the multiples in
 * between. Now the time, the positions and the observer's view agree (verlet stops at a step
 * end, where it called the observer), and a further call goes on to see every multiple once,
 * as the run that was not stopped, and to end where it ends (to the integrator's tolerance). */
struct stop_obs {
    int calls, stop_at;
    double t, x;
};

static int stopping_observer(const struct wetdem_sim* sim, void* ctx)
{
    struct stop_obs* o = ctx;
    o->calls++;
    o->t = wetdem_sim_time(sim);
    o->x = wetdem_sim_particles_const(sim, NULL)[0].pos.x;
    return o->calls == o->stop_at;
}

static void test_integrators_observer_stop_leaves_the_state_it_saw(void** state)
{
    (void)state;
    for (int q = 0; q < 2; q++) {
        struct spring_params sp = {.k = 50.0};
        double x_end[2], t_end = 0.1;
        int calls[2];
        for (int stop = 0; stop < 2; stop++) {
            struct wetdem_sim* sim = make_sim(integrators[q], 2e-4, -0.05, true, &sp);
            CHECK_OK(wetdem_sim_set_param(sim, "verlet.dt", 1e-5));
            struct stop_obs o = {.stop_at = stop ? 4 : 0};
            wetdem_sim_set_observer(sim, 0.001, stopping_observer, &o);
            if (stop) {
                CHECK_STATUS(wetdem_sim_integrate(sim, t_end), WETDEM_ERR_CALLBACK);
                CHECK_REL(o.t, 0.003, q ? 1e-12 : 1e-5 / 0.003); /* verlet: a step end */
                CHECK_REL(wetdem_sim_time(sim), o.t, 0);
                CHECK_REL(particle0(sim).pos.x, o.x, 0);
            }
            CHECK_OK(wetdem_sim_integrate(sim, t_end));
            x_end[stop] = particle0(sim).pos.x;
            calls[stop] = o.calls;
            wetdem_sim_free(sim);
        }
        assert_int_equal(calls[1], calls[0]); /* t = 0, 0.001, ..., 0.1 */
        assert_int_equal(calls[0], 101);
        CHECK_REL(x_end[1], x_end[0], 1e-6); /* cvode.rtol 1e-10, restarted once */
    }
}

/* ---- CVODE vector kernels (integrator_cvode_nvec.c) ---- */

#define NV_N 19 /* odd length: no loop remainder left untested */

/* Fills v with values of both signs and magnitudes and signed zeros from seed k, and two
 * components equal in every vector. */
static void nv_fill(N_Vector v, int k)
{
    double* d = N_VGetArrayPointer(v);
    for (int i = 0; i < NV_N; i++) {
        double u = sin(12.9898 * (i + 1) + 78.233 * (k + 1)) * 43758.5453;
        d[i] = (u - floor(u) - 0.5) * pow(10.0, (i * 7 + k) % 9 - 4);
    }
    d[(3 + k) % NV_N] = 0.0;
    d[(5 + 2 * k) % NV_N] = -0.0;
    d[NV_N - 1] = 0.0; /* equal in every vector: x - y = +0, -(x - y) = -0 */
    d[NV_N - 2] = 1.5;
}

/* Two copies of three vectors: L with the library's kernels, W with ours. */
struct nv_pair {
    N_Vector l[3], w[3];
};

static void nv_reset(struct nv_pair* p)
{
    for (int k = 0; k < 3; k++) {
        nv_fill(p->l[k], k);
        nv_fill(p->w[k], k);
    }
}

/* Every component of every vector bit-identical between the two copies. */
static void nv_same(const struct nv_pair* p, const char* what)
{
    for (int k = 0; k < 3; k++)
        if (memcmp(N_VGetArrayPointer(p->l[k]), N_VGetArrayPointer(p->w[k]),
                   NV_N * sizeof(double)) != 0)
            fail_msg("%s: vector %d differs from the library's", what, k);
}

/* The replaced kernels must give exactly the library's bits (results of the Fig. 3 sweep are
 * unchanged by them): linear sums for every special case of the coefficients (+-1, equal,
 * opposite, general) and every aliasing of the output, scaling, constants, products,
 * quotients, abs, inverse, WRMS and max norms, and the fused and array forms; exact equality,
 * no tolerance. */
static void test_integrators_cvode_vector_kernels(void** state)
{
    (void)state;
    SUNContext ctx;
    assert_int_equal(SUNContext_Create(NULL, &ctx), 0);
    struct nv_pair p;
    N_Vector proto = N_VNew_Serial(NV_N, ctx);
    N_VEnableFusedOps_Serial(proto, SUNTRUE);
    N_Vector mine = N_VClone(proto);
    wetdem_integrator_cvode_nvec_install(mine);
    for (int k = 0; k < 3; k++) {
        p.l[k] = N_VClone(proto);
        p.w[k] = N_VClone(mine); /* clones keep the installed kernels */
    }
    const double coef[] = {1.0, -1.0, 0.5, -0.5, 2.0, 0.0, 3.0};
    for (int ia = 0; ia < 7; ia++)
        for (int ib = 0; ib < 7; ib++)
            for (int out = 0; out < 3; out++) { /* z = x, z = y, z separate */
                double a = coef[ia], b = coef[ib];
                nv_reset(&p);
                N_VLinearSum_Serial(a, p.l[0], b, p.l[1], p.l[out == 2 ? 2 : out]);
                N_VLinearSum(a, p.w[0], b, p.w[1], p.w[out == 2 ? 2 : out]);
                nv_same(&p, "linear sum");
            }
    for (int ia = 0; ia < 7; ia++) {
        double c = coef[ia];
        nv_reset(&p);
        N_VScale_Serial(c, p.l[0], p.l[2]);
        N_VScale(c, p.w[0], p.w[2]);
        N_VScale_Serial(c, p.l[1], p.l[1]);
        N_VScale(c, p.w[1], p.w[1]);
        N_VAddConst_Serial(p.l[0], c, p.l[0]);
        N_VAddConst(p.w[0], c, p.w[0]);
        nv_same(&p, "scale, add constant");
        N_VConst_Serial(c, p.l[2]);
        N_VConst(c, p.w[2]);
        nv_same(&p, "constant");
    }
    nv_reset(&p);
    assert_true(N_VWrmsNorm_Serial(p.l[0], p.l[1]) == N_VWrmsNorm(p.w[0], p.w[1]));
    assert_true(N_VMaxNorm_Serial(p.l[0]) == N_VMaxNorm(p.w[0]));
    N_VProd_Serial(p.l[0], p.l[1], p.l[2]);
    N_VProd(p.w[0], p.w[1], p.w[2]);
    N_VAbs_Serial(p.l[2], p.l[1]);
    N_VAbs(p.w[2], p.w[1]);
    N_VInv_Serial(p.l[1], p.l[0]);
    N_VInv(p.w[1], p.w[0]);
    N_VDiv_Serial(p.l[2], p.l[0], p.l[1]);
    N_VDiv(p.w[2], p.w[0], p.w[1]);
    nv_same(&p, "prod, abs, inv, div");
    for (int nvec = 1; nvec <= 3; nvec++)
        for (int alias = 0; alias < 2; alias++) {
            double c[3] = {alias ? 1.0 : 0.7, -1.3, 2.1};
            nv_reset(&p);
            N_Vector zl = alias ? p.l[0] : p.l[2], zw = alias ? p.w[0] : p.w[2];
            N_VLinearCombination_Serial(nvec, c, p.l, zl);
            N_VLinearCombination(nvec, c, p.w, zw);
            nv_same(&p, "linear combination");
            c[0] = 0.7;
            nv_reset(&p);
            N_VLinearCombination_Serial(nvec, c, p.l, p.l[0]);
            N_VLinearCombination(nvec, c, p.w, p.w[0]);
            nv_same(&p, "linear combination in place");
            nv_reset(&p);
            N_Vector yl[2] = {p.l[1], p.l[2]}, yw[2] = {p.w[1], p.w[2]};
            N_Vector zl2[2] = {p.l[2], p.l[1]}, zw2[2] = {p.w[2], p.w[1]};
            int m = nvec < 3 ? nvec : 2;
            N_VScaleAddMulti_Serial(m, c, p.l[0], yl, alias ? yl : zl2);
            N_VScaleAddMulti(m, c, p.w[0], yw, alias ? yw : zw2);
            nv_same(&p, "scale-add multi");
            nv_reset(&p);
            N_VScaleVectorArray_Serial(m, c, yl, alias ? yl : zl2);
            N_VScaleVectorArray(m, c, yw, alias ? yw : zw2);
            N_VLinearSumVectorArray_Serial(m, c[0], yl, c[1], yl, zl2);
            N_VLinearSumVectorArray(m, c[0], yw, c[1], yw, zw2);
            double nl[2], nw[2];
            N_VWrmsNormVectorArray_Serial(m, yl, zl2, nl);
            N_VWrmsNormVectorArray(m, yw, zw2, nw);
            assert_true(memcmp(nl, nw, (size_t)m * sizeof(double)) == 0);
            N_VConstVectorArray_Serial(m, c[2], yl);
            N_VConstVectorArray(m, c[2], yw);
            nv_same(&p, "vector arrays");
        }
    for (int k = 0; k < 3; k++) {
        N_VDestroy(p.l[k]);
        N_VDestroy(p.w[k]);
    }
    N_VDestroy(mine);
    N_VDestroy(proto);
    SUNContext_Free(&ctx);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_integrators_free_flight),
        cmocka_unit_test(test_integrators_constant_force),
        cmocka_unit_test(test_integrators_shortest_span),
        cmocka_unit_test(test_integrators_shortest_span_after_t),
        cmocka_unit_test(test_integrators_message_quotes_the_last),
        cmocka_unit_test(test_integrators_oscillators),
        cmocka_unit_test(test_integrators_cvode_released_from_rest),
        cmocka_unit_test(test_integrators_verlet_order_two),
        cmocka_unit_test(test_integrators_verlet_reversible),
        cmocka_unit_test(test_integrators_cvode_tolerance),
        cmocka_unit_test(test_integrators_stats),
        cmocka_unit_test(test_integrators_params),
        cmocka_unit_test(test_integrators_cvode_bdf),
        cmocka_unit_test(test_integrators_observer),
        cmocka_unit_test(test_integrators_observer_sees_each_multiple_once),
        cmocka_unit_test(test_integrators_observer_stop_leaves_the_state_it_saw),
        cmocka_unit_test(test_integrators_cvode_vector_kernels),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

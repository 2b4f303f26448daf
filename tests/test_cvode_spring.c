/*
 * test_cvode_spring.c — the tangential spring as part of CVODE's state (docs/engines.md,
 * integrator_cvode.c): a start of sliding located where the spring reaches the Coulomb limit,
 * the collision's symmetry under swapping which particle is i and which j, and a chain of
 * three spheres in 3D against the fixed-step model.
 */
#include "harness.h"
#include "sim.h" /* engine.pairs: the committed pair state */
#include "vec3.h"

/* Per commit of pair 0: whether its spring acted and slid at the previous one, and the
 * largest |slip margin| / |F_t| at a commit where a sticking spring started to slide. */
struct watch {
    bool acted, slid;
    int starts;   /* starts of sliding from a sticking spring */
    double worst; /* largest |margin| / |F_t| there [-] */
    int ends;     /* sliding springs that stuck at a commit */
};

static int watch_pair(struct wetdem_sim* sim, void* ctx)
{
    struct watch* w = ctx;
    const struct wetdem_pair* p = &sim->engine.pairs.items[0];
    bool acts = p->slip != 0.0;
    if (w->acted && acts && !w->slid && p->sliding) {
        w->starts++;
        w->worst = fmax(w->worst, fabs(p->slip) / p->f_t);
    }
    if (w->acted && acts && w->slid && !p->sliding)
        w->ends++;
    w->acted = acts;
    w->slid = p->sliding;
    return WETDEM_OK;
}

/* Two dry steel spheres (hertz + mindlin, mu 0.3, e 0.9) of radii 3 and 4 mm meeting at 10
 * degrees at 0.5 m/s, in the x-y plane; `spin` adds spins with components out of that plane
 * and `swap` adds the spheres in the other order (so that i and j trade places). */
static struct wetdem_sim* make_pair(bool swap, bool spin, struct watch* w)
{
    struct wetdem_sim* sim = wetdem_sim_create();
    int mat = wetdem_sim_add_material_preset(sim, "steel1");
    double r1 = 3e-3, r2 = 4e-3, d = r1 + r2 + 1e-5, a = 10 * M_PI / 180, v = 0.5;
    struct wetdem_particle p1 = {.pos = {d, 0, 0},
                                 .vel = {-v * cos(a), v * sin(a), 0},
                                 .omega = {spin ? 30.0 : 0.0, spin ? -20.0 : 0.0, 10.0},
                                 .radius = r1,
                                 .material = mat};
    struct wetdem_particle p2 = {.pos = {0, 0, 0},
                                 .omega = {spin ? -15.0 : 0.0, spin ? 25.0 : 0.0, 0.0},
                                 .radius = r2,
                                 .material = mat};
    CHECK_OK(wetdem_sim_add_particle(sim, swap ? p2 : p1));
    CHECK_OK(wetdem_sim_add_particle(sim, swap ? p1 : p2));
    CHECK_OK(wetdem_sim_enable_model(sim, "hertz"));
    CHECK_OK(wetdem_sim_enable_model(sim, "mindlin"));
    CHECK_OK(wetdem_sim_set_integrator(sim, "cvode"));
    if (w) {
        sim->engine.monitor = watch_pair;
        sim->engine.monitor_ctx = w;
    }
    return sim;
}

/* A sticking spring starts to slide where |F_t| (spring and dashpot) reaches mu F_el: the
 * transition is the root of the trial's slip margin, located by bisection on CVODE's
 * interpolant to 1e-12 of the step, and the run restarted there, so the commit at it finds
 * the margin zero to that precision (measured at most 2e-11 |F_t| in this impact, whose
 * spring slides and sticks three times each; the rounding of |F_t| minus the cap, two numbers
 * of size |F_t|, sets that floor). At an unlocated step end the margin is what the force rose
 * past the limit during the step: up to 0.38 |F_t| here (measured with the location switched
 * off). 1e-9 asserted. The ends of sliding are located too (at
 * the peak of the margin: watch.ends counts them). */
static void test_cvode_spring_start_of_sliding_located(void** state)
{
    (void)state;
    struct watch w = {0};
    struct wetdem_sim* sim = make_pair(false, false, &w);
    CHECK_OK(wetdem_sim_integrate(sim, 3e-4));
    print_message("starts of sliding %d (worst margin %.3g |F_t|), ends %d\n", w.starts, w.worst,
                  w.ends);
    assert_true(w.starts >= 1);
    assert_true(w.ends >= 1);
    assert_true(w.worst < 1e-9);
    wetdem_sim_free(sim);
}

/* Swapping which sphere is i (the pair's normal, v_t, spring and q all change sign) gives the
 * same motion: a 3D impact (spins out of the plane, so that the tangent plane turns and the
 * spring is rotated) run with rtol 1e-10 and atol 1e-12 in both orders; the final velocities
 * and spins of each sphere agree to 3e-7 of the impact speed (or of the spins, 30 rad/s: the
 * two runs order the state differently, so CVODE's error norm rounds differently and the
 * steps differ at the level of the tolerances; measured 2.2e-9 and 3.0e-8). Without the
 * location of the stick-slip transitions the two orders differed by 2.4e-7 and 3.3e-6: each
 * transition then fell where the step of that order ended. */
static void test_cvode_spring_swap_symmetric(void** state)
{
    (void)state;
    struct wetdem_particle out[2][2];
    for (int swap = 0; swap < 2; swap++) {
        struct wetdem_sim* sim = make_pair(swap, true, NULL);
        CHECK_OK(wetdem_sim_set_param(sim, "cvode.rtol", 1e-10));
        CHECK_OK(wetdem_sim_set_param(sim, "cvode.atol", 1e-12));
        CHECK_OK(wetdem_sim_integrate(sim, 3e-4));
        size_t n;
        const struct wetdem_particle* p = wetdem_sim_particles(sim, &n);
        out[swap][0] = p[swap ? 1 : 0]; /* the 3 mm sphere */
        out[swap][1] = p[swap ? 0 : 1];
        wetdem_sim_free(sim);
    }
    double worst_v = 0, worst_w = 0;
    for (int b = 0; b < 2; b++) {
        struct wetdem_vec3 dv = vec3_sub(out[0][b].vel, out[1][b].vel);
        struct wetdem_vec3 dw = vec3_sub(out[0][b].omega, out[1][b].omega);
        worst_v = fmax(worst_v, sqrt(vec3_dot(dv, dv)) / 0.5);
        worst_w = fmax(worst_w, sqrt(vec3_dot(dw, dw)) / 30.0);
    }
    print_message("swap: velocities %.3g, spins %.3g (relative)\n", worst_v, worst_w);
    assert_true(worst_v < 3e-7);
    assert_true(worst_w < 3e-7);
}

/* Final velocities [m/s] and spins [rad/s] of three dry steel spheres (hertz + mindlin, R = 3
 * mm) in a 3D chain: the first meets the second at 0.5 m/s off its line of centres and the
 * third meets the second later, with spins out of the plane, so that two pairs touch, slide
 * and stick in turning tangent planes. integrator verlet with step `dt` [s], or cvode with
 * rtol `rtol` and atol rtol / 10. */
static void chain_of_three(const char* integrator, double dt, double rtol, double out[18])
{
    struct wetdem_sim* sim = wetdem_sim_create();
    int mat = wetdem_sim_add_material_preset(sim, "steel1");
    double r = 3e-3, d = 2 * r + 1e-5;
    struct wetdem_particle p[3] = {
        {.pos = {0, 0, 0}, .vel = {0.5, 0.05, 0.02}, .omega = {0, 5, 20}, .radius = r},
        {.pos = {d, 0.3 * r, 0}, .radius = r},
        {.pos = {2 * d, -0.2 * r, 0.1 * r},
         .vel = {-0.3, 0, 0},
         .omega = {10, 0, -10},
         .radius = r},
    };
    for (int k = 0; k < 3; k++) {
        p[k].material = mat;
        CHECK_OK(wetdem_sim_add_particle(sim, p[k]));
    }
    CHECK_OK(wetdem_sim_enable_model(sim, "hertz"));
    CHECK_OK(wetdem_sim_enable_model(sim, "mindlin"));
    CHECK_OK(wetdem_sim_set_integrator(sim, integrator));
    if (dt > 0) {
        CHECK_OK(wetdem_sim_set_param(sim, "verlet.dt", dt));
    } else {
        CHECK_OK(wetdem_sim_set_param(sim, "cvode.rtol", rtol));
        CHECK_OK(wetdem_sim_set_param(sim, "cvode.atol", 0.1 * rtol));
    }
    CHECK_OK(wetdem_sim_integrate(sim, 1e-3));
    size_t n;
    const struct wetdem_particle* q = wetdem_sim_particles(sim, &n);
    for (int k = 0; k < 3; k++) {
        out[6 * k] = q[k].vel.x, out[6 * k + 1] = q[k].vel.y, out[6 * k + 2] = q[k].vel.z;
        out[6 * k + 3] = q[k].omega.x, out[6 * k + 4] = q[k].omega.y;
        out[6 * k + 5] = q[k].omega.z;
    }
    wetdem_sim_free(sim);
}

/* Several pairs in contact at once, in 3D, against the fixed-step model: the chain of three
 * with CVODE at rtol 1e-10 against Verlet at dt 5e-10 s (2e6 steps). The largest difference
 * of a velocity, in units of the 0.5 m/s impact, and of a spin, in units of 50 rad/s (the
 * largest final spin is 47 rad/s), was 5e-9 and 4e-8 (Verlet itself moved by 5e-8 of the
 * spins' scale from dt 1e-9 s: first order, the Coulomb cap's radial return in turning
 * planes); with the trapezoidal spring 4.5e-5 of the spins' scale. 3e-7 asserted. */
static void test_cvode_spring_chain_matches_verlet(void** state)
{
    (void)state;
    double v[18], c[18], worst_v = 0, worst_w = 0;
    chain_of_three("verlet", 5e-10, 0, v);
    chain_of_three("cvode", 0, 1e-10, c);
    for (int k = 0; k < 18; k++) {
        if (k % 6 < 3)
            worst_v = fmax(worst_v, fabs(c[k] - v[k]) / 0.5);
        else
            worst_w = fmax(worst_w, fabs(c[k] - v[k]) / 50.0);
    }
    print_message("chain: velocities %.3g, spins %.3g (relative)\n", worst_v, worst_w);
    assert_true(worst_v < 3e-7);
    assert_true(worst_w < 3e-7);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cvode_spring_start_of_sliding_located),
        cmocka_unit_test(test_cvode_spring_swap_symmetric),
        cmocka_unit_test(test_cvode_spring_chain_matches_verlet),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

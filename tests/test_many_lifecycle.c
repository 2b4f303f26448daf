/*
 * test_many_lifecycle.c — the many-particle mode driven through the C API as an embedding
 * program drives it (a CFD coupling that integrates in short pieces and edits the state in
 * between; docs/many.md, "Limits of this version"): walls added between calls, the models
 * changed between calls, radii grown into contact between calls, pieces shorter than a step.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "many.h"
#include "vec3.h"

/* A glass-like material (2500 kg/m^3, E = 10 MPa, e = 0.6, friction 0.4) and `models`
 * (space-separated), in a new simulation. */
static struct wetdem_sim* dry_sim(const char* models)
{
    struct wetdem_sim* sim = wetdem_sim_create();
    struct wetdem_material m = test_soft_glass(0);
    assert_int_equal(wetdem_sim_add_material(sim, &m), 0);
    char names[64];
    snprintf(names, sizeof names, "%s", models);
    for (char* name = strtok(names, " "); name; name = strtok(NULL, " "))
        CHECK_OK(wetdem_sim_enable_model(sim, name));
    return sim;
}

/* Three spheres (R = 0.5 mm) on the floor z = 0 (0.2 um overlap, about their weight's) (hertz, mindlin:
 * each floor contact holds a tangential spring), sliding at 0.1 m/s towards x = 4 mm, where
 * a side wall is added between two calls (when the first sphere is about 0.2 mm from it) or stands
 * from the start. The wall was ignored until some sphere moved half the skin (1 mm here, after the bounce) and
 * rebuilt the lists, and the wall histories, laid out for one wall a particle, were read and
 * written as for two: the floor springs of the spheres after the first were read from the
 * wrong places and the last ones past the end of the array (AddressSanitizer: heap buffer
 * overflow). A wall the spheres had not reached when it was added acts as if it had stood
 * from the start: the runs are the same bit for bit (any valid list holds every pair within
 * range), and the spheres bounce off it. */
static void test_many_wall_added_between_calls(void** state)
{
    (void)state;
    const double R = 0.5e-3, dt = 1e-6;
    struct wetdem_sim* sims[2];
    for (int added = 0; added < 2; added++) {
        struct wetdem_sim* sim = sims[added] = dry_sim("hertz mindlin");
        CHECK_OK(wetdem_sim_set_param(sim, "sim.gravity_z", -9.81));
        CHECK_OK(wetdem_sim_add_wall(sim, vec3(0, 0, 0), vec3(0, 0, 1), 0));
        if (!added)
            CHECK_OK(wetdem_sim_add_wall(sim, vec3(4e-3, 0, 0), vec3(-1, 0, 0), 0));
        for (int k = 0; k < 3; k++)
            CHECK_OK(wetdem_sim_add_particle(
                sim, (struct wetdem_particle){.pos = {3.2e-3 - 1.1e-3 * k, 0, R - 0.2e-6},
                                              .vel = {0.1, 0, 0},
                                              .radius = R}));
        CHECK_OK(wetdem_sim_set_many(
            sim, &(struct wetdem_many_settings){.dt = dt, .skin = 1e-3, .energy_budget = true}));
        CHECK_OK(wetdem_sim_integrate(sim, 1.2e-3));
        if (added) { /* about 0.2 mm from the first sphere */
            CHECK_OK(wetdem_sim_add_wall(sim, vec3(4e-3, 0, 0), vec3(-1, 0, 0), 0));
            struct wetdem_many_stats s; /* the readers of the histories see the new layout */
            CHECK_OK(wetdem_sim_many_stats(sim, &s));
            struct wetdem_energy_budget b;
            CHECK_OK(wetdem_sim_energy_budget(sim, &b));
        }
        CHECK_OK(wetdem_sim_integrate(sim, 10e-3));
    }
    test_check_same_particles(sims[0], sims[1]);
    assert_true(wetdem_sim_particles(sims[1], NULL)[0].vel.x < -0.005); /* (-0.012 m/s) */
    struct wetdem_energy_budget a, b;
    CHECK_OK(wetdem_sim_energy_budget(sims[0], &a));
    CHECK_OK(wetdem_sim_energy_budget(sims[1], &b));
    CHECK_ABS(b.work_total, a.work_total, 0);
    for (int k = 0; k < 2; k++)
        wetdem_sim_free(sims[k]);
}

/* 60 wet spheres (hertz mindlin sb capillary) in a box periodic in x and y with a floor,
 * under gravity, dt 2 us: the wet granular gas of tests/harness.h in the
 * many-particle mode. */
static struct wetdem_sim* wet_gas(void)
{
    struct wetdem_sim* sim = wetdem_sim_create();
    CHECK_OK(test_wet_gas(sim, 60, 4e-3, 6e-3, 20e-6, 7, NULL));
    CHECK_OK(
        wetdem_sim_set_many(sim, &(struct wetdem_many_settings){.periodic = {true, true, false},
                                                                .box_hi = {4e-3, 4e-3, 6e-3},
                                                                .dt = 2e-6,
                                                                .energy_budget = true}));
    return sim;
}

/* The models of a started run changed between calls: its pair histories are laid out by the
 * models it started with and its work summed per model. Enabling mindlin after a run of
 * hertz sb capillary made the histories of every pair one double longer than their storage:
 * the next call wrote past the pair histories (AddressSanitizer: heap buffer overflow) and
 * stopped on a corrupted particle ("non-finite position or a bad radius 0 m"), and the energy
 * budget summed the work of the models by their new places. A call and the reports that read
 * the histories refuse such a change, name both sets and leave the run as it was: with the
 * models enabled again as they were, it goes on bit for bit as if nothing had happened, and
 * wetdem_sim_set_many() starts the mode afresh with the new ones. */
static void test_many_models_changed_between_calls(void** state)
{
    (void)state;
    struct wetdem_sim* whole = wet_gas();
    CHECK_OK(wetdem_sim_integrate(whole, 4e-4));
    struct wetdem_sim* sim = wet_gas();
    CHECK_OK(wetdem_sim_integrate(sim, 2e-4));
    double t = wetdem_sim_time(sim);
    wetdem_sim_clear_models(sim);
    CHECK_OK(wetdem_sim_enable_model(sim, "hertz"));
    CHECK_OK(wetdem_sim_enable_model(sim, "sb"));
    CHECK_STATUS(wetdem_sim_integrate(sim, 4e-4), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim),
                   "integrate: the models of the many-particle run changed since it started "
                   "(hertz mindlin sb capillary min-separation fixed; now hertz sb "
                   "min-separation fixed)");
    CHECK_ABS(wetdem_sim_time(sim), t, 0);
    struct wetdem_many_stats st;
    struct wetdem_energy_budget b;
    CHECK_STATUS(wetdem_sim_many_stats(sim, &st), WETDEM_ERR_INVALID);
    CHECK_STATUS(wetdem_sim_energy_budget(sim, &b), WETDEM_ERR_INVALID);
    CHECK_STATUS(wetdem_sim_write_checkpoint(sim, "/nonexistent/x.ckpt"), WETDEM_ERR_INVALID);
    CHECK_STATUS(wetdem_sim_write_vtk_links(sim, "/nonexistent/x.vtk", false), WETDEM_ERR_INVALID);
    CHECK_STATUS(wetdem_sim_write_vtk(sim, "/nonexistent/x.vtk", false), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "write_vtk: the models of the many-particle run");
    /* one more model (a longer history) too */
    CHECK_OK(wetdem_sim_enable_model(sim, "mindlin"));
    CHECK_OK(wetdem_sim_enable_model(sim, "capillary"));
    CHECK_STATUS(wetdem_sim_integrate(sim, 4e-4), WETDEM_ERR_INVALID);
    wetdem_sim_clear_models(sim);
    const char* models[] = {"hertz", "mindlin", "sb", "capillary"};
    for (int k = 0; k < 4; k++)
        CHECK_OK(wetdem_sim_enable_model(sim, models[k]));
    CHECK_OK(wetdem_sim_integrate(sim, 4e-4));
    test_check_same_particles(whole, sim);
    /* a new start of the mode takes other models */
    wetdem_sim_clear_models(sim);
    CHECK_OK(wetdem_sim_enable_model(sim, "hertz"));
    CHECK_OK(
        wetdem_sim_set_many(sim, &(struct wetdem_many_settings){.periodic = {true, true, false},
                                                                .box_hi = {4e-3, 4e-3, 6e-3},
                                                                .dt = 2e-6,
                                                                .energy_budget = true}));
    CHECK_OK(wetdem_sim_integrate(sim, 6e-4));
    CHECK_OK(wetdem_sim_energy_budget(sim, &b));
    assert_int_equal(b.n_models, 1);
    wetdem_sim_free(whole);
    wetdem_sim_free(sim);
}

/* Radii edited between calls change the gaps without a move. Two spheres 20 um apart and one
 * 20 um above the floor, at rest, without gravity (hertz alone, skin 5 um: no candidate
 * pairs), are grown by 30 um each between two calls, into 40 um of overlap with each other
 * and 10 um with the floor. The lists were rebuilt only on a move of half the skin, which
 * never came: no force acted, while wetdem_sim_pair_force gave 0.030 N and 0.0053 N, and the
 * spheres stayed overlapped for good. The next call's first force pass sees the overlaps: the
 * step's first half kick has the forces of the previous call (none), the drift moves nothing,
 * and the closing half kick gives v = F dt / (2 m) with F the force at the grown radii
 * (1e-12: the same formulas, a rounding or two apart). */
static void test_many_radius_grown_between_calls(void** state)
{
    (void)state;
    const double R = 0.5e-3, dt = 1e-7, grow = 30e-6;
    struct wetdem_sim* sim = dry_sim("hertz");
    CHECK_OK(wetdem_sim_add_wall(sim, vec3(0, 0, 0), vec3(0, 0, 1), 0));
    CHECK_OK(
        wetdem_sim_add_particle(sim, (struct wetdem_particle){.pos = {0, 0, 2e-3}, .radius = R}));
    CHECK_OK(wetdem_sim_add_particle(
        sim, (struct wetdem_particle){.pos = {2 * R + 20e-6, 0, 2e-3}, .radius = R}));
    CHECK_OK(wetdem_sim_add_particle(
        sim, (struct wetdem_particle){.pos = {5e-3, 0, R + 20e-6}, .radius = R}));
    CHECK_OK(wetdem_sim_set_many(sim, &(struct wetdem_many_settings){.dt = dt, .skin = 5e-6}));
    CHECK_OK(wetdem_sim_integrate(sim, 10 * dt));
    struct wetdem_particle* p = wetdem_sim_particles(sim, NULL);
    for (int k = 0; k < 3; k++) {
        p[k].radius += grow;
        p[k].mass = 2500 * 4.0 / 3.0 * M_PI * pow(p[k].radius, 3);
    }
    struct wetdem_pair_force pair, wall;
    CHECK_OK(wetdem_sim_pair_force(sim, 1, 0, NULL, &pair)); /* normal from 0 to 1: +x */
    CHECK_OK(wetdem_sim_pair_force(sim, 2, (size_t)-1 - 0, NULL, &wall)); /* +z */
    assert_true(pair.f_normal > 0.02 && wall.f_normal > 0.004);           /* 0.030 N, 0.0053 N */
    double m = p[0].mass;
    CHECK_OK(wetdem_sim_integrate(sim, 11 * dt));
    p = wetdem_sim_particles(sim, NULL);
    CHECK_REL(p[1].vel.x, pair.f_normal * dt / (2 * m), 1e-12);
    CHECK_REL(p[0].vel.x, -pair.f_normal * dt / (2 * m), 1e-12);
    CHECK_REL(p[2].vel.z, wall.f_normal * dt / (2 * m), 1e-12);
    wetdem_sim_free(sim);
}

/* A driver whose own step is shorter than the engine's (a CFD solver at 0.3 dt) calls
 * integrate at every one of its steps. The engine takes whole steps: the call to 0.3 dt ends
 * at dt, and the header says a run ends at its first point of the grid at or after
 * t_end - 1e-9 dt, which for the next call, to 0.6 dt, is dt itself: no step. That call was
 * refused as a t_end in the past, and so was every other one of the driver's. Now the calls
 * within a step the run has passed take no step, the pieces give the run of one call bit for
 * bit, and a t_end a whole step back is still refused. */
static void test_many_pieces_shorter_than_a_step(void** state)
{
    (void)state;
    const double dt = 2e-6;
    struct wetdem_sim* whole = wet_gas();
    CHECK_OK(wetdem_sim_integrate(whole, 60 * dt));
    struct wetdem_sim* sim = wet_gas();
    for (int k = 1; k <= 200; k++) {
        CHECK_OK(wetdem_sim_integrate(sim, k * 0.3 * dt));
        assert_true(wetdem_sim_time(sim) >= k * 0.3 * dt - 1e-9 * dt);
        assert_true(wetdem_sim_time(sim) < k * 0.3 * dt + dt);
    }
    test_check_same_particles(whole, sim);
    struct wetdem_energy_budget a, b;
    CHECK_OK(wetdem_sim_energy_budget(whole, &a));
    CHECK_OK(wetdem_sim_energy_budget(sim, &b));
    CHECK_ABS(b.work_total, a.work_total, 0);
    double t = wetdem_sim_time(sim);
    CHECK_OK(wetdem_sim_integrate(sim, t - 0.999 * dt)); /* within the step passed */
    CHECK_ABS(wetdem_sim_time(sim), t, 0);
    CHECK_STATUS(wetdem_sim_integrate(sim, t - dt), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "less the step it passed");
    CHECK_STATUS(wetdem_sim_integrate(sim, NAN), WETDEM_ERR_INVALID);
    CHECK_ABS(wetdem_sim_time(sim), t, 0);
    wetdem_sim_free(whole);
    wetdem_sim_free(sim);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_many_wall_added_between_calls),
        cmocka_unit_test(test_many_models_changed_between_calls),
        cmocka_unit_test(test_many_radius_grown_between_calls),
        cmocka_unit_test(test_many_pieces_shorter_than_a_step),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/*
 * test_lifecycle.c — the two-body soft engine driven through the C API as an embedding
 * program drives it (docs/engines.md): integrate called in pieces, the models changed between
 * calls. The many-particle mode has its own file, test_many_lifecycle.c.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"

/* Two Punch spheres with 270 um silicone-oil films (R = 6.35 mm), the striker 1 um from the
 * target and coming head-on at 0.5 m/s, integrated by cvode with `a` and `b` enabled. */
static struct wetdem_sim* punch_head_on(const char* a, const char* b)
{
    const double R = 6.35e-3;
    struct wetdem_sim* sim = wetdem_sim_create();
    assert_int_equal(wetdem_sim_add_material_preset(sim, "punch_steel_coated"), 0);
    CHECK_OK(wetdem_sim_set_fluid(
        sim, &(struct wetdem_fluid){.viscosity = 10, .surface_tension = 0.02}));
    CHECK_OK(wetdem_sim_enable_model(sim, a));
    CHECK_OK(wetdem_sim_enable_model(sim, b));
    CHECK_OK(wetdem_sim_set_integrator(sim, "cvode"));
    CHECK_OK(wetdem_sim_add_particle(sim, (struct wetdem_particle){.radius = R}));
    CHECK_OK(wetdem_sim_add_particle(
        sim,
        (struct wetdem_particle){.pos = {2 * R + 1e-6, 0, 0}, .vel = {-0.5, 0, 0}, .radius = R}));
    return sim;
}

/* The models changed between two calls in mid-contact, from hertz and the glass-transition
 * h_min to hertz and mindlin. Both sets keep three doubles per pair, glass's record of the
 * approach speeds (0.5 m/s, 0.5 m/s, 1) and mindlin's tangential spring [m]: the record was
 * carried over as the spring, 0.5 m along the line of centres, which Coulomb's limit turned
 * into a sliding friction force on a head-on impact, and the spheres of a head-on collision
 * left it spinning (omega 0.07 rad/s) and moving sideways (1.7e-4 m/s after 1 us). A history
 * is carried over only to the same models that laid it out; otherwise it starts fresh, as a
 * new pair's does, and the motion stays on the line of centres: every y and z component
 * exactly 0, as with the models of the second call from the start. */
static void test_lifecycle_models_changed_in_contact(void** state)
{
    (void)state;
    struct wetdem_sim* sim = punch_head_on("hertz", "glass");
    CHECK_OK(wetdem_sim_integrate(sim, 1e-5));
    struct wetdem_contact c;
    struct wetdem_pair_force f;
    CHECK_OK(wetdem_sim_pair_force(sim, 1, 0, &c, &f));
    assert_true(c.gap < -1e-6); /* in contact (-3.8 um) */
    wetdem_sim_clear_models(sim);
    CHECK_OK(wetdem_sim_enable_model(sim, "hertz"));
    CHECK_OK(wetdem_sim_enable_model(sim, "mindlin"));
    CHECK_OK(wetdem_sim_integrate(sim, 1e-5 + 1e-6));
    const struct wetdem_particle* p = wetdem_sim_particles(sim, NULL);
    for (int k = 0; k < 2; k++) {
        CHECK_ABS(p[k].vel.y, 0, 0);
        CHECK_ABS(p[k].pos.y, 0, 0);
        CHECK_ABS(p[k].omega.z, 0, 0);
    }
    assert_true(p[1].vel.x < -0.4); /* still in contact, slowed (-0.459 m/s) */
    wetdem_sim_free(sim);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_lifecycle_models_changed_in_contact),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/*
 * 01_pair_force — the force between two immersed steel spheres as they approach.
 *
 * Two "steel1" spheres (Nijssen 2023 Table 1, d = 12.7 mm) in water approach each other at
 * v_n = 0.1 m/s. With the "nijssen" model enabled, the pair force is Reynolds lubrication
 * 6 pi mu R*^2 v_n / h far from contact, blended into Hertz contact below h_min. The program
 * prints the normal force on sphere i (> 0 repulsive) at a few gaps h, including one overlap,
 * using only the public header wetdem.h.
 *
 * Build and run: make examples && build/examples/01_pair_force
 */
#include <stdio.h>

#include "wetdem.h"

/* Prints the library's message for a failed call and returns 1 (the exit code). */
static int report(struct wetdem_sim* sim, const char* what)
{
    fprintf(stderr, "01_pair_force: %s: %s\n", what, wetdem_sim_errmsg(sim));
    wetdem_sim_free(sim);
    return 1;
}

int main(void)
{
    const double radius = 6.35e-3;                               /* [m] */
    const double speed = 0.1;                                    /* normal approach speed [m/s] */
    const double gaps[] = {1e-3, 1e-4, 1e-5, 1e-6, 1e-7, -1e-7}; /* [m]; < 0: overlap */

    struct wetdem_sim* sim = wetdem_sim_create();
    if (!sim)
        return 1;
    int steel = wetdem_sim_add_material_preset(sim, "steel1");
    if (steel < 0)
        return report(sim, "material");
    /* Sphere j rests at the origin; sphere i moves towards it along -x. Mass 0: from density. */
    struct wetdem_particle pi = {.pos = {2 * radius + gaps[0], 0, 0},
                                 .vel = {-speed, 0, 0},
                                 .radius = radius,
                                 .material = steel};
    struct wetdem_particle pj = {.radius = radius, .material = steel};
    if (wetdem_sim_add_particle(sim, pi) != WETDEM_OK ||
        wetdem_sim_add_particle(sim, pj) != WETDEM_OK)
        return report(sim, "particles");
    if (wetdem_sim_enable_model(sim, "nijssen") != WETDEM_OK)
        return report(sim, "model");

    printf("gap [m],f_normal [N]\n");
    for (size_t k = 0; k < sizeof gaps / sizeof gaps[0]; k++) {
        wetdem_sim_particles(sim, NULL)[0].pos.x = 2 * radius + gaps[k];
        struct wetdem_pair_force f;
        if (wetdem_sim_pair_force(sim, 0, 1, NULL, &f) != WETDEM_OK)
            return report(sim, "pair force");
        printf("%g,%.6g\n", gaps[k], f.f_normal);
    }
    wetdem_sim_free(sim);
    return 0;
}

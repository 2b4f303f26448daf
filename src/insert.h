/*
 * insert.h — placing many spheres in a box without overlap (internal). Prefix: wetdem_insert.
 */
#ifndef WETDEM_INSERT_H
#define WETDEM_INSERT_H

#include <stdbool.h>
#include <stddef.h>

#include "wetdem.h"

enum wetdem_insert_layout {
    WETDEM_INSERT_LATTICE = 0, /* simple cubic lattice of spacing 2 R_max + gap, x fastest */
    WETDEM_INSERT_RANDOM = 1,  /* random sequential addition, largest spheres first */
};

/* What to insert and where. Seeded: the same spec gives bit-identical particles. */
struct wetdem_insert_spec {
    enum wetdem_insert_layout layout;
    size_t n;                    /* number of spheres, >= 1 */
    struct wetdem_vec3 lo, hi;   /* region [m]; spheres lie inside it on non-periodic axes */
    bool periodic[3];            /* axes on which the region wraps (overlaps through images) */
    double radius_min;           /* radii uniform in [radius_min, radius_max] [m], > 0 */
    double radius_max;           /* [m], >= radius_min */
    const double* radii;         /* optional: n radii [m] used instead of the uniform draw */
    double gap;                  /* least surface gap between spheres and to the region's
                                    faces on non-periodic axes [m], >= 0 */
    struct wetdem_vec3 velocity; /* mean velocity [m/s] */
    double velocity_sigma;       /* standard deviation of each velocity component [m/s] >= 0 */
    int material;                /* material index given to every sphere */
    unsigned long seed;          /* seed of the gsl_rng mt19937 generator */
    size_t max_attempts;         /* random layout: trials per sphere; 0 means 10000 */
};

/* Fills out[0 .. spec->n-1] (caller memory): positions, radii, velocities (spins 0, mass 0 so
 * that the simulation fills it from the material density, material). Returns WETDEM_OK,
 * WETDEM_ERR_INVALID (bad spec, or the region cannot hold the spheres: the message says how
 * many fit and what to change) or WETDEM_ERR_NOMEM; the message goes to msg (may be NULL). */
int wetdem_insert_particles(const struct wetdem_insert_spec* spec, struct wetdem_particle* out,
                            char* msg, size_t msg_size);

#endif

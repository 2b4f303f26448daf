/*
 * insert.h — placing many spheres in a box without overlap (internal). Prefix: wetdem_insert.
 */
#ifndef WETDEM_INSERT_H
#define WETDEM_INSERT_H

#include <stdbool.h>
#include <stddef.h>

#include "wetdem.h"

/* struct wetdem_insert_spec and enum wetdem_insert_layout are public (wetdem.h). */

/* Checks spec without drawing anything: layout, count, region, radii, gap, velocities, and
 * that the spheres' least volume fits the region's. Returns WETDEM_OK or WETDEM_ERR_INVALID
 * (message in msg). */
int wetdem_insert_check(const struct wetdem_insert_spec* spec, char* msg, size_t msg_size);

/* Fills out[0 .. spec->n-1] (caller memory): positions, radii, velocities (spins 0, mass 0 so
 * that the simulation fills it from the material density, material). Returns WETDEM_OK,
 * WETDEM_ERR_INVALID (bad spec, or the region cannot hold the spheres: the message says how
 * many fit and what to change), WETDEM_ERR_NOMEM or WETDEM_EVENT (stopped by spec->progress);
 * the message goes to msg (may be NULL). */
int wetdem_insert_particles(const struct wetdem_insert_spec* spec, struct wetdem_particle* out,
                            char* msg, size_t msg_size);

/* The same for a spec that wetdem_insert_check accepted (it is not checked again), and the
 * random layout also keeps spec->gap clear of existing[0 .. n_existing-1] (minimum image on the
 * region's periodic axes). The lattice does not look at them. */
int wetdem_insert_particles_among(const struct wetdem_insert_spec* spec,
                                  const struct wetdem_particle* existing, size_t n_existing,
                                  struct wetdem_particle* out, char* msg, size_t msg_size);

/* Cells per sphere above which the random layout's search grid is coarsened. */
#define INSERT_CELLS_PER_SPHERE 8

/* Shape nc[3] of the random layout's search grid for n_balls spheres in cells of edge >= edge
 * [m] (at most 1024 per axis and INSERT_CELLS_PER_SPHERE n_balls + 27 in all); returns the
 * number of cells. */
size_t wetdem_insert_grid_shape(const struct wetdem_insert_spec* spec, size_t n_balls, double edge,
                                int nc[3]);

#endif

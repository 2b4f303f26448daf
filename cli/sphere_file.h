/*
 * sphere_file.h — spheres read from a file for a many-particle scenario ([read.NAME]): a CSV
 * table or a particle frame that a wetdem run wrote (PREFIX_NNNNNN.vtk, ASCII or binary).
 */
#ifndef WETDEM_CLI_SPHERE_FILE_H
#define WETDEM_CLI_SPHERE_FILE_H

#include <stdbool.h>
#include <stddef.h>

#include "cli.h"
#include "wetdem.h"

/* Reads the spheres of `path` into a malloc'd array *out of *n (caller frees): a file whose
 * name ends in .vtk.series as the last frame that index lists, one ending in .vtk as a wetdem
 * frame (POINTS, the point arrays radius and, when present,
 * velocity, spin, fixed and material), any other as CSV ('#' lines and blank lines skipped; a
 * header naming the columns, x, y, z and radius required, vx, vy, vz, spin_x, spin_y, spin_z,
 * fixed and material optional, a name may carry its unit as "x [m]"; one row a sphere). Every
 * value must be a finite number within the range of the [particle.NAME] key of that name,
 * fixed 0 or 1 (is_fixed, and a fixed sphere at rest, when marks_fixed: the file says which
 * spheres are fixed; otherwise every sphere is read as free), material a whole number in
 * [0, 1000] (the
 * file's index, left in .material for the caller to map; -1 when the file has none); no two
 * spheres at one centre (a row given twice; with period, NULL or the box lengths of the
 * periodic axes and 0 for the others, a centre at 0 and one at the length are one centre). Film
 * and mass are left at zero for the caller. Returns CLI_EXIT_OK, or CLI_EXIT_USAGE (bad input) or
 * CLI_EXIT_RUNTIME (out of memory) with a one-line reason in err ("LINE: ..." for a CSV,
 * naming the array for a frame). */
int cli_read_sphere_file(const char* path, bool marks_fixed, const double* period,
                         struct wetdem_particle** out, size_t* n, char* err, size_t err_len);

#endif

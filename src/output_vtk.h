/*
 * output_vtk.h — VTK files of particles for ParaView (internal). Prefix: wetdem_output_vtk.
 */
#ifndef WETDEM_OUTPUT_VTK_H
#define WETDEM_OUTPUT_VTK_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "wetdem.h"

/* Each particle's counts (arrays of n entries): contacts with particles and walls, liquid
 * bridges, and the label of its agglomerate (0: none). */
struct wetdem_output_vtk_counts {
    const uint32_t* contacts;
    const uint32_t* bridges;
    const uint32_t* agglomerate;
};

/* Writes n particles as a legacy VTK POLYDATA file (one vertex per sphere) with the point
 * data radius [m], velocity [m/s], spin [rad/s], contacts, bridges and agglomerate (counts may
 * be NULL for zeros), material, id and fixed (1 for a sphere held in place), and the
 * simulated time [s] as field data TIME. binary:
 * big-endian binary arrays as the legacy format requires, else ASCII with 17 significant
 * digits (exact round trip). The file is written to a temporary name and renamed, so a
 * reader never sees half a file. Returns WETDEM_OK or WETDEM_ERR_IO (message in msg). */
int wetdem_output_vtk_write(const char* path, const struct wetdem_particle* p, size_t n,
                            const struct wetdem_output_vtk_counts* counts, double time, bool binary,
                            char* msg, size_t msg_size);

/* A link between two spheres, or a sphere and a wall, for wetdem_output_vtk_links_write: the
 * line from a to b (the centres, the second as seen from the first across periodic
 * boundaries; or the centre and the foot of the perpendicular on the wall). */
struct wetdem_output_vtk_link {
    struct wetdem_vec3 a, b;
    int32_t i, j;             /* particle indices; j = -1 - w for wall w */
    bool contact, bridge;     /* a solid contact, a liquid bridge (as the models define them) */
    double gap;               /* surface gap h [m], < 0: overlap */
    double f_normal;          /* normal force on i [N], > 0 repulsive */
    double f_tangential;      /* size of the tangential force [N] */
    struct wetdem_vec3 force; /* the whole force on i [N] (on j: its opposite) */
};

/* Writes n links as a legacy VTK POLYDATA file of lines (two points a line) with the cell data
 * i, j, contact, bridge (0 or 1), gap [m], force_normal [N], force_tangential [N] and force
 * (3 components, on i) [N], and the time [s] as field data TIME; binary and atomic as wetdem_output_vtk_write. Returns WETDEM_OK
 * or WETDEM_ERR_IO (message in msg). */
int wetdem_output_vtk_links_write(const char* path, const struct wetdem_output_vtk_link* links,
                                  size_t n, double time, bool binary, char* msg, size_t msg_size);

/* Formats "<prefix>_<index, 6 digits>.vtk" into buf. Returns the length snprintf would write. */
int wetdem_output_vtk_path(char* buf, size_t size, const char* prefix, uint64_t index);

/* Writes a ParaView time-series file (path ends in ".vtk.series": JSON listing the files,
 * given relative to the series file's directory, with their times [s]). Atomic like the
 * above. Returns WETDEM_OK or WETDEM_ERR_IO. */
int wetdem_output_vtk_series_write(const char* path, const char* const* files, const double* times,
                                   size_t n, char* msg, size_t msg_size);

#endif

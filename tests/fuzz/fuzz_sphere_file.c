/*
 * fuzz_sphere_file.c — libFuzzer target: any bytes as the file of a [read.NAME] section, read
 * by cli_read_sphere_file (cli/sphere_file.c) as a frame of a wetdem run (.vtk) when the first
 * byte is odd, else as a CSV. A finding is a crash, a sanitizer report, a leak, a hang, or
 * spheres accepted with a value outside the ranges the reader promises (finite everywhere, a
 * radius in (0, 1] m, centres and speeds within 1000, spins within 1e6, a fixed sphere at
 * rest, a material index in [0, 1000] or -1 for none), or an error without a message.
 * The same bytes also go to wetdem_output_vtk_frame_time, which must give a finite time or an
 * error that leaves the time as it was.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "../../cli/sphere_file.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

static int within(double v, double bound)
{
    return isfinite(v) && fabs(v) <= bound;
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    char path[64];
    snprintf(path, sizeof path, "/tmp/wetdem_fuzz_spheres_%ld.%s", (long)getpid(),
             size && (data[0] & 1) ? "vtk" : "csv");
    FILE* f = fopen(path, "wb");
    if (!f || (size && fwrite(data, 1, size, f) != size) || fclose(f) != 0)
        abort();
    struct wetdem_particle* p = NULL;
    size_t n = 0;
    char err[512] = "";
    int rc = cli_read_sphere_file(path, true, NULL, &p, &n, err, sizeof err);
    double t = NAN;
    int st = wetdem_output_vtk_frame_time(path, &t);
    remove(path);
    if (st == WETDEM_OK ? !isfinite(t) : (st != WETDEM_ERR_PARSE || !isnan(t)))
        abort();
    if (rc != 0 && (!err[0] || p || n))
        abort();
    for (size_t k = 0; rc == 0 && k < n; k++)
        if (!(p[k].radius > 0 && p[k].radius <= 1) || !within(p[k].pos.x, 1e3) ||
            !within(p[k].pos.y, 1e3) || !within(p[k].pos.z, 1e3) || !within(p[k].vel.x, 1e3) ||
            !within(p[k].vel.y, 1e3) || !within(p[k].vel.z, 1e3) || !within(p[k].omega.x, 1e6) ||
            !within(p[k].omega.y, 1e6) || !within(p[k].omega.z, 1e6) || p[k].material < -1 ||
            p[k].material > 1000 ||
            (p[k].is_fixed && (p[k].vel.x != 0 || p[k].vel.y != 0 || p[k].vel.z != 0 ||
                               p[k].omega.x != 0 || p[k].omega.y != 0 || p[k].omega.z != 0)))
            abort();
    if (rc == 0 && n == 0)
        abort();
    free(p);
    return 0;
}

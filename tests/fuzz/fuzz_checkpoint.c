/*
 * fuzz_checkpoint.c — libFuzzer target: any bytes as a checkpoint of a small wet box (30
 * spheres, Hertz–Mindlin + Stokes–Reynolds thin film + capillary bridges, two walls, periodic
 * in x and y), restored with wetdem_sim_read_checkpoint into a fresh set-up of the same box;
 * a checkpoint the library accepts is written as a VTK frame and a links file (the counts,
 * agglomerate labels and link forces of the restored state and histories), then run on for
 * 20 steps. Built and run by `make fuzz`.
 *
 * The seed is the box's own checkpoint after 50 steps, written by LLVMFuzzerInitialize into
 * the corpus directory (the first argument that is not an option). The input's last four bytes
 * are replaced by the CRC-32 of the others before it is read, so that mutations reach the
 * sections behind the checksum (a wrong checksum, the reader's first test, is covered by
 * tests/test_checkpoint.c). A finding is a crash, a
 * sanitizer report, a leak, a hang, a rejected checkpoint, a failed frame or run on from an
 * accepted one without a message, or the seed itself rejected.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "checkpoint.h"
#include "wetdem.h"

int LLVMFuzzerInitialize(int* argc, char*** argv);
int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

#define STEP 2e-6 /* [s] */

static void must(int status)
{
    if (status != WETDEM_OK)
        abort();
}

/* The box of the target, started (no outputs). */
static struct wetdem_sim* small_wet_box(void)
{
    struct wetdem_sim* sim = wetdem_sim_create();
    if (!sim)
        abort();
    struct wetdem_material m = {.density = 2500,
                                .youngs_modulus = 1e7,
                                .poisson_ratio = 0.3,
                                .restitution = 0.6,
                                .friction_dry = 0.4,
                                .friction_lub = 0.1,
                                .film = 20e-6};
    if (wetdem_sim_add_material(sim, &m) < 0)
        abort();
    struct wetdem_fluid f = {.viscosity = 0.01, .surface_tension = 0.02, .density = 1000};
    must(wetdem_sim_set_fluid(sim, &f));
    const char* models[] = {"hertz", "mindlin", "sb", "capillary"};
    for (int k = 0; k < 4; k++)
        must(wetdem_sim_enable_model(sim, models[k]));
    struct wetdem_insert_spec spec = {.layout = WETDEM_INSERT_RANDOM,
                                      .n = 30,
                                      .lo = {0, 0, 0},
                                      .hi = {4e-3, 4e-3, 6e-3},
                                      .periodic = {true, true, false},
                                      .radius_min = 0.4e-3,
                                      .radius_max = 0.5e-3,
                                      .velocity_sigma = 0.2,
                                      .seed = 7};
    must(wetdem_sim_insert(sim, &spec));
    must(wetdem_sim_add_wall(sim, (struct wetdem_vec3){0, 0, 0}, (struct wetdem_vec3){0, 0, 1}, 0));
    must(wetdem_sim_add_wall(sim, (struct wetdem_vec3){0, 0, 6e-3}, (struct wetdem_vec3){0, 0, -1},
                             0));
    must(wetdem_sim_set_param(sim, "sim.gravity_z", -9.81));
    struct wetdem_many_settings s = {.periodic = {true, true, false},
                                     .box_lo = {0, 0, 0},
                                     .box_hi = {4e-3, 4e-3, 6e-3},
                                     .dt = STEP,
                                     .skin = 0.05e-3,
                                     .energy_budget = true};
    must(wetdem_sim_set_many(sim, &s));
    return sim;
}

int LLVMFuzzerInitialize(int* argc, char*** argv)
{
    const char* corpus = NULL;
    for (int k = 1; k < *argc && !corpus; k++)
        if ((*argv)[k][0] != '-')
            corpus = (*argv)[k];
    if (!corpus)
        return 0;
    char path[4096];
    snprintf(path, sizeof path, "%s/seed_50_steps", corpus);
    struct wetdem_sim* sim = small_wet_box();
    must(wetdem_sim_integrate(sim, 50 * STEP));
    must(wetdem_sim_write_checkpoint(sim, path));
    wetdem_sim_free(sim);
    /* the seed restores into a fresh box, or the fuzzing would never pass the first checks */
    sim = small_wet_box();
    must(wetdem_sim_read_checkpoint(sim, path));
    wetdem_sim_free(sim);
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    char path[64];
    snprintf(path, sizeof path, "/tmp/wetdem_fuzz_ck_%ld", (long)getpid());
    uint8_t* bytes = malloc(size ? size : 1);
    if (!bytes)
        return 0;
    memcpy(bytes, data, size);
    if (size >= 4) {
        uint32_t crc = wetdem_checkpoint_crc32(0, bytes, size - 4);
        memcpy(bytes + size - 4, &crc, 4); /* the writer's byte order, as the file records */
    }
    FILE* f = fopen(path, "wb");
    if (!f || (size && fwrite(bytes, 1, size, f) != size) || fclose(f) != 0)
        abort();
    free(bytes);
    struct wetdem_sim* sim = small_wet_box();
    if (wetdem_sim_read_checkpoint(sim, path) == WETDEM_OK) {
        double t = wetdem_sim_time(sim);
        /* an accepted state runs on, or the engine says why not; its frame and links (the
           counts, labels and forces of the restored histories) are written, or why not said */
        char vtk[64];
        snprintf(vtk, sizeof vtk, "/tmp/wetdem_fuzz_ck_%ld.vtk", (long)getpid());
        if ((wetdem_sim_write_vtk(sim, vtk, true) != WETDEM_OK ||
             wetdem_sim_write_vtk_links(sim, vtk, false) != WETDEM_OK) &&
            !wetdem_sim_errmsg(sim)[0])
            abort();
        remove(vtk);
        if (wetdem_sim_integrate(sim, t + 20 * STEP) != WETDEM_OK && !wetdem_sim_errmsg(sim)[0])
            abort();
    } else if (!wetdem_sim_errmsg(sim)[0])
        abort();
    wetdem_sim_free(sim);
    remove(path);
    return 0;
}

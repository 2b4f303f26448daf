/*
 * sim.h — definition of struct wetdem_sim (opaque to users) and hidden helpers shared by the
 * sim_*.c, engine and analysis files.
 */
#ifndef WETDEM_SIM_H
#define WETDEM_SIM_H

#include <stdarg.h>

#include "wetdem.h"

#define WETDEM_MAX_MODELS 16
#define WETDEM_ERRMSG_SIZE 1024

/* A model enabled on this simulation with its own parameter block. */
struct wetdem_model_slot {
    const struct wetdem_model* model;
    void* params;          /* model->params_size bytes, owned */
    size_t history_offset; /* first double of this model's slice in a pair's history */
};

struct wetdem_wall {
    struct wetdem_vec3 point;  /* a point of the plane [m] */
    struct wetdem_vec3 normal; /* unit normal into the domain */
    int material;
};

/* Simulation-wide settings addressed as "sim.<name>" (descriptor table in sim_params.c). */
struct wetdem_sim_settings {
    double gravity_x, gravity_y, gravity_z; /* [m/s^2] */
};

struct wetdem_sim {
    char errmsg[WETDEM_ERRMSG_SIZE];

    struct wetdem_particle* particles;
    size_t n_particles, particles_cap;
    struct wetdem_material* materials;
    int n_materials, materials_cap;
    struct wetdem_wall* walls;
    size_t n_walls, walls_cap;
    struct wetdem_fluid fluid;
    struct wetdem_sim_settings settings;

    struct wetdem_model_slot models[WETDEM_MAX_MODELS]; /* force models, summed */
    size_t n_models;
    struct wetdem_model_slot minsep;                    /* gives h_min; history at offset 0 */
    size_t history_len;                                 /* doubles per pair, all slices */
};

/* Formats a message into sim->errmsg and returns status (printf-style). */
int wetdem_sim_fail(struct wetdem_sim* sim, int status, const char* fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* Fills c->h_min from the min-separation model, then sums every enabled force model into
 * *out (zeroed first). history: sim->history_len doubles (committed state in, advanced state
 * out), or NULL for a fresh pair with nothing kept. per_model (optional, n_models entries)
 * receives each model's own contribution. */
int wetdem_sim_eval_contact(const struct wetdem_sim* sim, struct wetdem_contact* c,
                            double* history, struct wetdem_pair_force* out,
                            struct wetdem_pair_force* per_model);

/* Largest gap at which any enabled force model acts for this contact [m]. */
double wetdem_sim_contact_range(const struct wetdem_sim* sim, const struct wetdem_contact* c);

/* Initial value of a pair's history: zeros except NAN-free defaults; writes history_len. */
void wetdem_sim_history_init(const struct wetdem_sim* sim, double* history);

/* Builds the contact of particle i with particle j, or with wall w when is_wall. */
void wetdem_sim_build_contact(const struct wetdem_sim* sim, size_t i, size_t j, bool is_wall,
                              struct wetdem_contact* c);

#endif

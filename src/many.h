/*
 * many.h — internal state of the many-particle mode of the soft engine (sim_many.c,
 * sim_many_io.c). The public settings are struct wetdem_many_settings in wetdem.h.
 */
#ifndef WETDEM_MANY_H
#define WETDEM_MANY_H

#include "celllist.h"
#include "sim.h"

/* Result of one candidate pair at the latest force evaluation. */
struct wetdem_many_pair_out {
    struct wetdem_vec3 force;    /* on i (j receives the opposite) [N] */
    struct wetdem_vec3 torque_i; /* [N m] */
    struct wetdem_vec3 torque_j; /* [N m] */
    unsigned char flags;         /* MANY_ACTIVE | MANY_CONTACT | MANY_BRIDGE */
};

#define WETDEM_MANY_ACTIVE 1u  /* within the interaction range: force applied */
#define WETDEM_MANY_CONTACT 2u /* gap < 0: solid contact */
#define WETDEM_MANY_BRIDGE 4u  /* gap < film delta_ij with a fluid model: liquid bridge */
#define WETDEM_MANY_DIRTY 8u   /* history may differ from a fresh one (reset when out of range) */

/* Energy bookkeeping (sim_many.c accumulates, sim_many_io.c reports). */
struct wetdem_many_energy {
    double k0, u0, el0;                     /* kinetic, potential, elastic at the start [J] */
    double work_pair[WETDEM_MAX_MODELS];    /* work of model k on particle pairs [J] */
    double work_wall[WETDEM_MAX_MODELS];    /* work of model k on particle-wall pairs [J] */
};

struct wetdem_many {
    struct wetdem_many_settings set; /* copy; the strings below are owned copies */
    char* output_prefix;
    char* checkpoint_path;
    struct wetdem_celllist cl;
    double reach;   /* largest interaction gap of any pair [m] (start-up bound) */
    double dt;      /* time step [s], fixed once the many run starts */
    double t0;      /* time of step 0 [s] */
    uint64_t step;  /* steps since t0 */
    bool started;
    double* history;             /* cl.n_pairs x history_len, aligned with cl.pairs */
    size_t history_cap;
    double* wall_history;        /* n_particles x n_walls x history_len */
    size_t wall_history_cap;
    struct wetdem_celllist_pair* old_pairs; /* previous list, for history remapping */
    double* old_history;
    size_t old_cap, old_history_cap;
    struct wetdem_many_pair_out* out; /* per candidate pair */
    size_t out_cap;
    unsigned char* old_flags;    /* out[].flags of the previous list, for remapping */
    size_t old_flags_cap;
    uint64_t* wall_mask;         /* per particle: bit w set if wall w is within reach + skin
                                    at the last build (walls >= 64 are always evaluated) */
    size_t wall_mask_cap;
    uint32_t* wall_list;         /* particles with a non-zero wall_mask (or all if > 64 walls) */
    size_t n_wall_list, wall_list_cap;
    double max_disp2;            /* largest squared displacement since the build [m^2], */
    bool max_disp_valid;         /* measured during the latest drift */
    bool forces_zeroed;          /* force, torque, contacts cleared during the latest drift */
    struct wetdem_vec3 *force, *torque, *vh, *wh; /* per particle */
    uint32_t* contacts;          /* per particle: solid contacts at the latest evaluation */
    size_t particle_cap;
    struct wetdem_many_energy energy;
    double* thread_work;         /* per thread: 2 x WETDEM_MAX_MODELS accumulators */
    size_t thread_work_cap;
    /* outputs */
    uint64_t vtk_files, csv_rows;
    uint64_t next_vtk_step, next_csv_step, next_checkpoint_step;
    char** vtk_names;            /* names of the files written, for the .vtk.series file */
    double* vtk_times;
    size_t vtk_names_cap;
};

/* sim_many.c */
/* wetdem_sim_many_free and wetdem_sim_many_integrate: sim.h. */
/* Kinetic (translational + rotational), gravitational potential and Hertz elastic energy at
 * the current state [J]. */
void wetdem_sim_many_energies(const struct wetdem_sim* sim, double* kinetic, double* potential,
                              double* elastic);
/* Makes sure the pair list, histories and per-particle arrays fit the current particles
 * (builds the cell list when needed). */
int wetdem_sim_many_prepare(struct wetdem_sim* sim);

/* sim_many_io.c */
/* Writes the outputs due at the current step (VTK, CSV, periodic checkpoint). */
int wetdem_sim_many_outputs(struct wetdem_sim* sim, bool final);
/* Number of agglomerates (clusters of >= 2 particles joined by liquid bridges) and their mean
 * size, from the latest force evaluation. */
void wetdem_sim_many_agglomerates(const struct wetdem_sim* sim, size_t* count, double* mean);

#endif

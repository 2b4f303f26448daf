/*
 * sim.h — definition of struct wetdem_sim (opaque to users) and hidden helpers shared by the
 * sim_*.c, engine and analysis files.
 */
#ifndef WETDEM_SIM_H
#define WETDEM_SIM_H

#include <stdarg.h>

#include "pairs.h"
#include "wetdem.h"

#define WETDEM_MAX_MODELS 16
#define WETDEM_ERRMSG_SIZE 1024
#define WETDEM_MAX_INTEGRATORS 4        /* registered integrators (integrator.c) */
#define WETDEM_INTEGRATOR_PARAMS_MAX 16 /* doubles of one integrator's parameter block */
/* Doubles of per-pair history a force evaluation can hold on the stack (scratch copies, fresh
 * histories); a set-up with more is refused when a run starts (sim_integrate.c). */
#define WETDEM_HISTORY_SCRATCH 64

/* A model enabled on this simulation with its own parameter block. */
struct wetdem_model_slot {
    const struct wetdem_model* model;
    void* params;          /* wetdem_sim_slot_size(model) bytes, owned */
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
    double stop_on_separation; /* 0/1: stop once every pair that interacted has separated */
    double separation_factor;  /* separated: gap > factor x interaction range [-], >= 1 */
    double speed_floor;        /* smallest relative speed used for step and tolerance
                                  scales [m/s] > 0 (sim_integrate.c) */
};

struct wetdem_event_slot; /* integrator.h */
struct wetdem_sim;

/* Run-time state of the soft engine (sim_integrate.c, integrator_*.c, event.c). */
struct wetdem_engine {
    double time;        /* simulated time [s] */
    double t_committed; /* time at which the pair histories hold the committed state [s] */
    /* the tangential spring advances by the increment of the pair's q since t_committed
     * (struct wetdem_pair q_trial, struct wetdem_contact dv_t_spring); set from the
     * integrator at each run */
    bool spring_state;
    /* velocity and spin of every particle at the half step (verlet, during a step's force
     * evaluation; else NULL): the tangential spring advances with the slip they give
     * (midpoint rule, struct wetdem_contact dv_t_spring) */
    const struct wetdem_vec3 *half_vel, *half_omega;
    size_t integrator; /* index into the integrator registry (integrator.c) */
    /* parameter blocks of every registered integrator, addressed as "<name>.<param>" */
    double integrator_params[WETDEM_MAX_INTEGRATORS][WETDEM_INTEGRATOR_PARAMS_MAX];

    struct wetdem_pairs pairs;
    /* per pair, at the latest event-function evaluation: gap [m], approach speed [m/s] */
    double *pair_gap, *pair_vn, *pair_gap_prev, *pair_vn_prev;
    double* pair_range; /* per pair: largest model range at the latest evaluation [m] */
    size_t pair_scratch_cap;
    /* event functions g = gap - threshold, grouped by pair (event.c) */
    struct wetdem_event_slot* slots;
    double *g_prev, *g_new;
    size_t n_slots, slots_cap;

    struct wetdem_event_record* events; /* the event log */
    size_t n_events, events_cap;
    struct wetdem_stats stats;

    struct wetdem_vec3 *force, *torque; /* per particle, from the latest force evaluation */
    size_t force_cap;

    wetdem_observer_fn observer;
    void* observer_ctx;
    double observer_interval; /* [s], 0: only at the start and the end of a run */
    double next_observe;      /* next observer time [s] */
    double last_observed;     /* time of the latest observer call [s], NAN if none */

    /* progress callback (wetdem_sim_set_progress), called by wetdem_sim_step_done every
     * WETDEM_PROGRESS_STEPS steps and at the end of wetdem_sim_integrate */
    wetdem_time_progress_fn progress;
    void* progress_ctx;
    double progress_t_end;             /* t_end of the integrate call [s] */
    double progress_start;             /* omp_get_wtime() at its start [s] */
    unsigned long long progress_steps; /* its accepted steps */

    /* internal per-step hook (collision analysis): called after every accepted step with
     * the state at engine.time; a negative return stops the run with that status */
    int (*monitor)(struct wetdem_sim* sim, void* ctx);
    void* monitor_ctx;
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
    struct wetdem_model_slot minsep; /* gives h_min; history at offset 0 */
    size_t history_len;              /* doubles per pair, all slices */

    struct wetdem_engine engine; /* soft engine: time, pairs, events, integrator */
    struct wetdem_many* many;    /* many-particle mode (many.h, sim_many.c), NULL if off */
};

/* Bytes of the parameter block of a slot of `model`: its params_size (at least 1); a
 * min-separation model's block also holds the fixed model's parameters, so that
 * wetdem_sim_clear_models() goes back to it in place, with no allocation that could fail. */
size_t wetdem_sim_slot_size(const struct wetdem_model* model);

/* Formats a message into sim->errmsg and returns status (printf-style). */
int wetdem_sim_fail(struct wetdem_sim* sim, int status, const char* fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* Whether particle p is one simulation sim can hold: a material sim has, finite position,
 * velocity and spin, radius and mass finite and > 0, a fixed one at rest. If not, why[0 .. n)
 * receives what is wrong, with the value (for wetdem_sim_add_particle, the start of a run,
 * wetdem_sim_pair_force and a checkpoint being restored alike: the first two read particles a
 * caller may have edited through wetdem_sim_particles()). */
bool wetdem_sim_particle_valid(const struct wetdem_sim* sim, const struct wetdem_particle* p,
                               char* why, size_t n);

/* The normal force of the enabled models on contact c at gap `gap` with the surfaces at rest
 * [N]: the conservative part (elastic contact, capillary bridge), every damping and viscous
 * term being proportional to a speed; from a copy of `history` (NULL: a fresh pair). NAN if a
 * model fails or the force is not finite. */
double wetdem_sim_force_at_rest(const struct wetdem_sim* sim, struct wetdem_contact c,
                                const double* history, double gap);
/* The normal stiffness of the enabled linear solid-contact law, from the models'
 * linear_stiffness hooks (hooke's k) [N/m]; 0 when none is linear (struct wetdem_contact). */
double wetdem_sim_linear_stiffness(const struct wetdem_sim* sim, const struct wetdem_contact* c);
/* Fills c->h_min from the min-separation model and c->linear_stiffness
 * (wetdem_sim_linear_stiffness), then sums every enabled force model into
 * *out (zeroed first). history: sim->history_len doubles (committed state in, advanced state
 * out), or NULL for a fresh pair with nothing kept. per_model (optional, n_models entries)
 * receives each model's own contribution. */
int wetdem_sim_eval_contact(const struct wetdem_sim* sim, struct wetdem_contact* c, double* history,
                            struct wetdem_pair_force* out, struct wetdem_pair_force* per_model);

/* Largest gap at which any enabled force model acts for this contact [m]. */
double wetdem_sim_contact_range(const struct wetdem_sim* sim, const struct wetdem_contact* c);

/* Shortest impact duration [s] of the enabled models for contact c at approach speed c->v_n:
 * their contact_time hooks, or the Hertz contact time of c's materials when no enabled model
 * has a solid contact (fluid forces only). */
double wetdem_sim_contact_time(const struct wetdem_sim* sim, const struct wetdem_contact* c);

/* Shortest viscous relaxation time [s] of the enabled models for contact c at approach speed
 * c->v_n (their relaxation_time hooks; INFINITY when none damps). Fills c->h_min from the
 * min-separation model for a fresh pair first. *which (optional) receives the model that
 * sets it, NULL if none. */
double wetdem_sim_relaxation_time(const struct wetdem_sim* sim, struct wetdem_contact* c,
                                  const struct wetdem_model** which);

/* What the enabled models say of a pair at its latest evaluation (their elastic_energy,
 * is_in_contact and is_bridged hooks, wetdem.h), from its contact c and its history as the
 * evaluation left it (sim->history_len doubles, read only; non-NULL when history_len > 0):
 * the energy stored in their solid contacts [J] (the sum; 0 where none stores any), whether
 * one of them exerts a solid-contact force, whether the liquid bridge of one joins the pair. */
double wetdem_sim_contact_elastic_energy(const struct wetdem_sim* sim,
                                         const struct wetdem_contact* c, const double* history);
bool wetdem_sim_contact_is_in_contact(const struct wetdem_sim* sim, const struct wetdem_contact* c,
                                      const double* history);
bool wetdem_sim_contact_is_bridged(const struct wetdem_sim* sim, const struct wetdem_contact* c,
                                   const double* history);
/* True when the enabled force laws of contact c (committed history `history`; NULL: a fresh
 * pair) jump at the gap h: their change across 1e-9 h is at least half that across 1e-6 h. A
 * jump keeps its size as the interval shrinks; a law continuous at h changes 1000 times less
 * (smooth) or at least 5.6 times less (the steepest of the catalogue, Hertz damping on
 * nijssen's overlap shifted to h_min, ~(h_min - h)^1/4). */
bool wetdem_sim_laws_jump_at(const struct wetdem_sim* sim, const struct wetdem_contact* c,
                             const double* history, double h);
/* True when a fixed step must resolve the gap h of contact c: the laws jump there
 * (wetdem_sim_laws_jump_at), or their normal force peaks there and falls steeply below it,
 * by more than a quarter within h/2 (nijssen's lever blend in a viscous liquid: the
 * lubrication force at h_min far above the contact's at an overlap of h_min, so the blend
 * falls from the peak nearly to zero over h_min; in water the contact force takes over and
 * it falls by ~10 %). */
bool wetdem_sim_laws_resolve_at(const struct wetdem_sim* sim, const struct wetdem_contact* c,
                                const double* history, double h);
/* Smallest gap 0 < h < range [m] at which the enabled force laws of contact c (a fresh pair
 * at approach speed c->v_n) jump: a branch gap from the models' thresholds() where the summed
 * forces change as much across 1e-9 of it as across 1e-6 (h_min where the thin-film laws
 * stop, below_hmin = c; not where a law is held, as reynolds', nijssen's and nc are).
 * INFINITY if there is none. Sets h_min from the min-separation model itself. */
double wetdem_sim_jump_gap(const struct wetdem_sim* sim, const struct wetdem_contact* c);

/* Checks that no enabled model of contact c (a fresh pair approaching at c->v_n) is already in
 * solid contact at the edge of its range: there its solid force would switch on with a jump
 * (nijssen when its minimum approach max(h_sigma, h_eps) reaches the cut-off h_co), which
 * either stalls the integration or adds energy. Returns WETDEM_OK, or WETDEM_ERR_INVALID with
 * a message naming the model, the gaps and the parameters that set them. */
int wetdem_sim_check_range_edge(struct wetdem_sim* sim, const struct wetdem_contact* c);

/* The time scale of the tangential oscillation of contact c [s], comparable with its normal
 * contact time t_contact at approach speed c->v_n (c at first touch): t_contact x
 * omega_n/omega_t, with omega^2 = k/m the enabled models' normal and tangential stiffnesses
 * (finite differences of their forces) at the impact's largest overlap and the tangential
 * mass (2/7) m* (both spheres spin). Below t_contact where the tangential spring (mindlin,
 * nijssen's) is the stiffer; INFINITY where no model has one. */
double wetdem_sim_tangential_time(const struct wetdem_sim* sim, const struct wetdem_contact* c,
                                  double t_contact);

/* The gap up to which the min-separation model keeps its per-pair record (its record_range
 * hook) [m]; 0 when it keeps none. */
double wetdem_sim_record_range(const struct wetdem_sim* sim, const struct wetdem_contact* c);

/* The history of a pair beyond its force range (c->gap > wetdem_sim_contact_range), on commit:
 * within record_range (wetdem_sim_record_range of c), the min-separation model is evaluated on
 * the history, which keeps and updates its record (c->h_min receives its value), and the
 * force models' slices are fresh; beyond it, the whole history is fresh, as
 * wetdem_sim_history_init makes it. Returns whether the record is kept. Both engines call it,
 * so a record ends at the same gap in each: reset_ratio R* for ehd and max, the films' delta
 * for glass. */
bool wetdem_sim_history_beyond_range(const struct wetdem_sim* sim, struct wetdem_contact* c,
                                     double record_range, double* history);

/* Initial value of a pair's history: zeros except NAN-free defaults; writes history_len. */
void wetdem_sim_history_init(const struct wetdem_sim* sim, double* history);

/* Builds the contact of particle i with particle j, or with wall w when is_wall. In the
 * many-particle mode j is taken at its periodic image nearest to i, as that engine pairs them. */
void wetdem_sim_build_contact(const struct wetdem_sim* sim, size_t i, size_t j, bool is_wall,
                              struct wetdem_contact* c);

/* sim_many.c: frees the many-particle state (wetdem_sim_free calls it). */
void wetdem_sim_many_free(struct wetdem_sim* sim);
/* sim_many.c: after wetdem_sim_add_wall, lays the many-particle state's particle-wall
 * histories out for the walls (the new wall's fresh), so that every reader of them and the
 * next call see the wall. WETDEM_OK (also without the mode) or WETDEM_ERR_NOMEM. */
int wetdem_sim_many_walls_added(struct wetdem_sim* sim);
/* sim_many.c: the step of a started many-particle run [s], 0 otherwise. Its time stays on
 * the grid t0 + k dt, so a call may end up to a step past its t_end: a later call to a t_end
 * within that step takes no step (wetdem_sim_integrate). */
double wetdem_sim_many_step(const struct wetdem_sim* sim);
/* sim_many.c: starts the many-particle state afresh with its settings (wetdem_sim_reset calls
 * it): step 0, no lists, a new energy budget; nothing without the mode. */
void wetdem_sim_many_reset(struct wetdem_sim* sim);
/* sim_many.c: the periodic image of position b nearest to position a in the box of the
 * many-particle mode (b itself on its open axes) [m]. */
struct wetdem_vec3 wetdem_sim_many_nearest_image(const struct wetdem_sim* sim, struct wetdem_vec3 a,
                                                 struct wetdem_vec3 b);
/* sim_many.c: runs the many-particle engine to t_end (wetdem_sim_integrate dispatches). */
int wetdem_sim_many_integrate(struct wetdem_sim* sim, double t_end);

/* sim_integrate.c: sets the engine defaults (integrator "verlet" and every integrator's
 * default parameters); called by wetdem_sim_create(). */
void wetdem_sim_engine_init(struct wetdem_sim* sim);
/* sim_integrate.c: frees the engine's storage (not the sim). */
void wetdem_sim_engine_free(struct wetdem_sim* sim);
/* sim_integrate.c: empties pairs, event log, statistics, time (reset). */
void wetdem_sim_engine_clear(struct wetdem_sim* sim);
/* sim_integrate.c: deep copy of src's engine into dst (observer and monitor not copied).
 * WETDEM_OK or WETDEM_ERR_NOMEM. */
int wetdem_sim_engine_copy(struct wetdem_sim* dst, const struct wetdem_sim* src);

#endif

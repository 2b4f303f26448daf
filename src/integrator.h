/*
 * integrator.h — internal interface between the soft engine's run loop (sim_integrate.c),
 * its integrators (integrator_verlet.c, integrator_cvode.c), event location (event.c) and the
 * collision analysis (collision.c). docs/engines.md describes the semantics.
 *
 * The "system" every integrator advances is the state of all free particles: positions x_k,
 * velocities v_k and angular velocities w_k, with
 *     dx/dt = v,   dv/dt = F/m + g,   dw/dt = T/I,   I = (2/5) m R^2,
 * F and T summed over the pairs of the pair list (wetdem_sim_compute_forces). Fixed
 * particles and walls do not move.
 */
#ifndef WETDEM_INTEGRATOR_H
#define WETDEM_INTEGRATOR_H

#include <stdbool.h>

#include "sim.h"

/* One integrator: a named, documented parameter table and a run function. */
struct wetdem_integrator {
    const char* name;                       /* "verlet", "cvode" */
    const char* summary;                    /* one line */
    const struct wetdem_param_desc* params; /* terminated by {0}; doubles only */
    size_t params_size;                     /* <= WETDEM_INTEGRATOR_PARAMS_MAX doubles */
    /* Advances sim from engine.time to t_end. Called by wetdem_sim_integrate() after the pair
     * list, the event slots and the forces at the start state are ready. Returns WETDEM_OK,
     * WETDEM_EVENT (stop condition) or a negative status with the message in sim. */
    int (*integrate)(struct wetdem_sim* sim, const void* params, double t_end);
    /* Whether the integrator carries q, the integral of every pair's v_t while its tangential
     * spring acts, as part of its state (cvode, whose evaluations are trials at any time in
     * the step): the spring then advances from its committed value by the increment of q
     * since the commit, integrated under the integrator's error control (struct wetdem_pair
     * q_trial). A fixed step that commits every evaluation (verlet) advances it with v_t at
     * the half step instead (midpoint rule, engine.half_vel). */
    bool spring_state;
};

extern const struct wetdem_integrator wetdem_integrator_verlet;
extern const struct wetdem_integrator wetdem_integrator_cvode;

/* ---- integrator.c ---- */

/* NULL-terminated table of the integrators (index = engine.integrator). */
const struct wetdem_integrator* const* wetdem_integrator_registry(void);
/* Index of the integrator whose name is the first len characters of name, or -1. */
int wetdem_integrator_index(const char* name, size_t len);

/* ---- event.c ---- */

/* What an event function's threshold is. */
enum wetdem_event_source {
    WETDEM_EVENT_SOURCE_RANGE = 0,      /* largest model range: interaction start/end */
    WETDEM_EVENT_SOURCE_MODEL = 1,      /* a threshold a model lists inside its range */
    WETDEM_EVENT_SOURCE_ZERO = 2,       /* gap 0: solid contact start/end */
    WETDEM_EVENT_SOURCE_SEPARATION = 3, /* separation_factor x range: stop check only */
    WETDEM_EVENT_SOURCE_RECORD = 4,     /* record range of the min-separation model where it
                                           differs from the range: the record's start (not
                                           logged) */
};

/* One event function g = gap - threshold of one pair. */
struct wetdem_event_slot {
    size_t pair; /* index in engine.pairs */
    enum wetdem_event_source source;
    size_t model, index; /* SOURCE_MODEL: force model slot, threshold index */
    bool as_hmin;        /* SOURCE_MODEL: logged as h_min reached/left */
};

/* Builds the event functions of every pair of engine.pairs at the current state. Returns
 * WETDEM_OK or WETDEM_ERR_NOMEM. */
int wetdem_event_slots_build(struct wetdem_sim* sim);
/* Geometry of pair k at the current state: its contact c (h_min from the min-separation
 * model on a scratch copy of the committed history, left in scratch: sim->history_len
 * doubles) and its interaction range *range [m]. */
void wetdem_event_pair_state(const struct wetdem_sim* sim, size_t k, struct wetdem_contact* c,
                             double* range, double* scratch);
/* Evaluates every event function at the current particle state with the committed pair
 * histories (not modified) into g[n_slots]; writes engine.pair_gap and engine.pair_vn.
 * Counts one root evaluation. */
void wetdem_event_values(struct wetdem_sim* sim, double* g);
/* Records the events of slot k crossing in direction dir (-1: gap fell below the threshold,
 * +1: rose above it) at time t [s] with gap [m] and approach speed v_n [m/s]; marks the pair
 * as having interacted when its range is entered. Returns WETDEM_OK or WETDEM_ERR_NOMEM. */
int wetdem_event_record(struct wetdem_sim* sim, size_t k, int dir, double t, double gap,
                        double v_n);
/* Smallest threshold 0 < h_k < range of the force laws' branch boundaries where the laws
 * jump (wetdem_sim_laws_jump_at: h_min of below_hmin = c; not nijssen's continuous blend)
 * over every pair at the latest evaluation of the event functions (engine.g_prev after
 * wetdem_event_values at the start of a run) [m]; INFINITY when there is none. */
double wetdem_event_smallest_branch_gap(const struct wetdem_sim* sim);
/* The state a run starts from: the event functions into engine.g_prev and the pairs' gaps and
 * speeds as the previous state of the first step. */
void wetdem_event_start(struct wetdem_sim* sim);
/* After a step from t0 to t1 [s] (or a return of CVODE): evaluates the event functions at the
 * current state into engine.g_new and, for every slot whose side of its threshold changed
 * since g_prev (inside: g < 0; exactly at the threshold is outside), records the events in
 * time order, with the crossing time and the pair's gap and v_n interpolated linearly
 * (engine.pair_gap_prev to engine.pair_gap), or at t1 for a slot that roots[] marks as a root
 * located there (CVODE; it reports no root for a function that is exactly zero where it
 * starts or restarts, which a pair placed at a threshold is, so its crossing is found here).
 * roots == NULL (Verlet): also raises stats.hmin_step_ratio to the gap change of a step that
 * crossed a branch gap h_k of the force laws (0 < h_k < range) over h_k. Then the current
 * state becomes the previous one (g_prev, pair_*_prev). Returns WETDEM_OK or
 * WETDEM_ERR_NOMEM. */
int wetdem_event_advance(struct wetdem_sim* sim, double t0, double t1, const int* roots);

/* ---- sim_integrate.c: engine services ---- */

/* Sums the pair forces and torques on every particle at the current particle state and
 * time t into engine.force/torque. Pair histories are advanced by t - engine.t_committed on
 * scratch copies; with commit, the advanced histories are kept and t_committed = t. Pairs
 * out of range get a fresh history on commit. Returns WETDEM_OK or a negative status. */
int wetdem_sim_compute_forces(struct wetdem_sim* sim, double t, bool commit);
/* Commits the pair histories at the current state and time t without summing forces (for
 * integrators whose RHS evaluations are trials). */
int wetdem_sim_commit_histories(struct wetdem_sim* sim, double t);
/* Evaluates pair k at the current state as a trial at time t (nothing committed) and returns
 * its slip margin (struct wetdem_pair_force slip; 0 where no tangential spring acts) [N];
 * *f_t: the magnitude of its tangential force [N]; *status: WETDEM_OK or the failure. */
double wetdem_sim_slip_margin(struct wetdem_sim* sim, size_t k, double t, double* f_t, int* status);
/* Linear acceleration of free particle k from engine.force plus gravity [m/s^2]. */
struct wetdem_vec3 wetdem_sim_acceleration(const struct wetdem_sim* sim, size_t k);
/* Angular acceleration of free particle k from engine.torque [rad/s^2]. */
struct wetdem_vec3 wetdem_sim_angular_acceleration(const struct wetdem_sim* sim, size_t k);
/* Largest relative speed of any pair, including the speed gravity can add over the pair's gap,
 * floored by sim.speed_floor [m/s]; *t_contact (if non-NULL) receives the shortest impact
 * duration of any pair at its speed (wetdem_sim_contact_time: the enabled models' contact
 * times, else Hertz's) [s] (INFINITY without pairs). */
double wetdem_sim_speed_scale(const struct wetdem_sim* sim, double* t_contact);
/* The same largest relative speed without the floor [m/s]: 0 when every pair rests (no gravity
 * to close a gap) or there is none. */
double wetdem_sim_motion_speed(const struct wetdem_sim* sim);
/* Smallest radius of a free particle [m] (1 if none). */
double wetdem_sim_length_scale(const struct wetdem_sim* sim);
/* Checks sim.stop_on_separation at the current state (engine.pair_gap/pair_vn must be
 * current): true when some pair has interacted and every such pair is at or beyond
 * separation_factor x range and receding (v_n < 0); their flags are then cleared. */
bool wetdem_sim_separation_reached(struct wetdem_sim* sim);
/* After an accepted step at engine.time: calls the monitor, and the progress callback every
 * WETDEM_PROGRESS_STEPS steps of the integrate call. Returns the first failing status. */
int wetdem_sim_step_done(struct wetdem_sim* sim);
/* Calls the observer, if any, with the current state at engine.time, and with an interval
 * sets the next observer time, the first multiple of it after engine.time (engine.time a few
 * roundings below a multiple counting as at it); maps a non-zero return to
 * WETDEM_ERR_CALLBACK (message stored). */
int wetdem_sim_observe(struct wetdem_sim* sim);
/* Calls the observer once at the current state if engine.time has reached the next observer
 * time (or lies a few roundings below it), which advances that time past engine.time
 * (fixed-step integrators). */
int wetdem_sim_observe_due(struct wetdem_sim* sim);

#endif

/*
 * pairs.h — internal interface of the pair list of the soft engine: which (particle, particle)
 * and (particle, wall) pairs are candidates for interaction, each with its committed per-pair
 * history (sim->history_len doubles, layout of sim_models.c).
 *
 * The present implementation is an O(N^2) all-pairs list (every pair with at least one free
 * particle), rebuilt by wetdem_pairs_update() with the histories of surviving pairs carried
 * over by key (i, is_wall, j). A cell list with a skin can replace it behind the same
 * functions: callers only iterate over items[0..n) and read histories through
 * wetdem_pairs_history().
 */
#ifndef WETDEM_PAIRS_H
#define WETDEM_PAIRS_H

#include <stdbool.h>
#include <stddef.h>

#include "wetdem.h"

struct wetdem_sim;
struct wetdem_model;

/* Most models a pair's history is laid out for: the min-separation model and WETDEM_MAX_MODELS
 * force models (sim.h). */
#define WETDEM_PAIRS_LAYOUT_MAX 17

/* One candidate pair. The key (i, is_wall, j) orders the list. */
struct wetdem_pair {
    size_t i;            /* particle index */
    size_t j;            /* particle index (> i), or wall index when is_wall */
    bool is_wall;        /* j is a plane wall */
    bool has_interacted; /* came within the interaction range since the last separation stop */
    /* engine.spring_state (sim_integrate.c, integrator_cvode.c): q = the integral of v_t
     * while the pair's tangential spring acts [m], part of the integrator's state, at
     * engine.t_committed and at the state of the latest evaluation; its rate at that
     * evaluation [m/s] (v_t while a spring acts, else 0); the spring's slip margin there
     * (struct wetdem_pair_force slip) and |F_t| [N]; whether the spring acted and whether it
     * slid at the last commit. */
    struct wetdem_vec3 q_committed, q_trial, q_rate;
    double slip, f_t;
    bool acting, sliding;
    bool spring_zone; /* within its spring's range at that evaluation: h < max(h_min, 0) */
};

struct wetdem_pairs {
    struct wetdem_pair* items; /* n pairs, sorted by key */
    size_t n, cap;
    double* history;    /* n * history_len doubles: committed per-pair state */
    size_t history_cap; /* doubles allocated */
    size_t history_len; /* doubles per pair when the list was built */
    /* the models whose slices make up the history when the list was built, in their order:
     * the min-separation model, then the force models, each if it keeps any history */
    const struct wetdem_model* layout[WETDEM_PAIRS_LAYOUT_MAX];
    size_t n_layout;
};

/* Rebuilds the list for the particles and walls of sim; keeps the history and flags of pairs
 * that stay in the list (same key) while the models laying out the history are the same, in
 * the same order; initialises new ones, and every history when those models changed (one
 * model's record is no state of another: glass's approach speeds would become mindlin's
 * spring). Returns WETDEM_OK
 * or WETDEM_ERR_NOMEM (message stored in sim). */
int wetdem_pairs_update(struct wetdem_pairs* pl, struct wetdem_sim* sim);
/* Committed history of pair k (history_len doubles; NULL when history_len is 0). */
double* wetdem_pairs_history(const struct wetdem_pairs* pl, size_t k);
/* Empties the list (capacity kept). */
void wetdem_pairs_clear(struct wetdem_pairs* pl);
/* Releases the storage; the list is empty afterwards. */
void wetdem_pairs_free(struct wetdem_pairs* pl);
/* Deep copy of src into dst (dst must be empty or freed). WETDEM_OK or WETDEM_ERR_NOMEM. */
int wetdem_pairs_copy(struct wetdem_pairs* dst, const struct wetdem_pairs* src);

#endif

/*
 * pairs.c — the pair list of the soft engine (see pairs.h): an O(N^2) all-pairs list with
 * per-pair committed history, keyed by (i, is_wall, j). Pairs of two fixed particles, and
 * walls with a fixed particle, never interact and are left out. Prefix: wetdem_pairs_.
 */
#include <stdlib.h>
#include <string.h>

#include "pairs.h"
#include "sim.h"

/* Orders pair keys: by i, then particle partners before walls, then by j. */
static int compare_keys(const struct wetdem_pair* a, const struct wetdem_pair* b)
{
    if (a->i != b->i)
        return a->i < b->i ? -1 : 1;
    if (a->is_wall != b->is_wall)
        return a->is_wall ? 1 : -1;
    if (a->j != b->j)
        return a->j < b->j ? -1 : 1;
    return 0;
}

/* Index of key in the sorted list, or -1. */
static long find_pair(const struct wetdem_pairs* pl, const struct wetdem_pair* key)
{
    size_t lo = 0, hi = pl->n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        int c = compare_keys(&pl->items[mid], key);
        if (c == 0)
            return (long)mid;
        if (c < 0)
            lo = mid + 1;
        else
            hi = mid;
    }
    return -1;
}

/* Number of candidate pairs of sim, in key order. */
static size_t count_pairs(const struct wetdem_sim* sim)
{
    size_t n = 0;
    for (size_t i = 0; i < sim->n_particles; i++) {
        bool fixed_i = sim->particles[i].is_fixed;
        for (size_t j = i + 1; j < sim->n_particles; j++)
            n += !(fixed_i && sim->particles[j].is_fixed);
        n += fixed_i ? 0 : sim->n_walls;
    }
    return n;
}

/* Writes the keys of every candidate pair into items (count_pairs() entries). */
static void list_pairs(const struct wetdem_sim* sim, struct wetdem_pair* items)
{
    size_t n = 0;
    for (size_t i = 0; i < sim->n_particles; i++) {
        bool fixed_i = sim->particles[i].is_fixed;
        for (size_t j = i + 1; j < sim->n_particles; j++)
            if (!(fixed_i && sim->particles[j].is_fixed))
                items[n++] = (struct wetdem_pair){.i = i, .j = j, .is_wall = false};
        for (size_t w = 0; !fixed_i && w < sim->n_walls; w++)
            items[n++] = (struct wetdem_pair){.i = i, .j = w, .is_wall = true};
    }
}

_Static_assert(WETDEM_PAIRS_LAYOUT_MAX == WETDEM_MAX_MODELS + 1,
               "a pair's history holds the slices of the min-separation and the force models");

/* The models whose slices make up a pair's history (sim_models.c), in their order; returns
 * their number. */
static size_t history_layout(const struct wetdem_sim* sim, const struct wetdem_model** layout)
{
    size_t n = 0;
    if (sim->minsep.model->history_len)
        layout[n++] = sim->minsep.model;
    for (size_t k = 0; k < sim->n_models; k++)
        if (sim->models[k].model->history_len)
            layout[n++] = sim->models[k].model;
    return n;
}

int wetdem_pairs_update(struct wetdem_pairs* pl, struct wetdem_sim* sim)
{
    size_t n = count_pairs(sim), len = sim->history_len;
    const struct wetdem_model* layout[WETDEM_PAIRS_LAYOUT_MAX];
    size_t n_layout = history_layout(sim, layout);
    bool same_layout = len == pl->history_len && n_layout == pl->n_layout &&
                       memcmp(layout, pl->layout, n_layout * sizeof *layout) == 0;
    struct wetdem_pair* items = malloc((n ? n : 1) * sizeof *items);
    double* history = malloc((n * len > 0 ? n * len : 1) * sizeof *history);
    if (!items || !history) {
        free(items);
        free(history);
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory building %zu pairs", n);
    }
    list_pairs(sim, items);
    for (size_t k = 0; k < n; k++) {
        long old = same_layout ? find_pair(pl, &items[k]) : -1;
        if (old >= 0) {
            items[k].has_interacted = pl->items[old].has_interacted;
            memcpy(history + k * len, pl->history + (size_t)old * len, len * sizeof *history);
        } else {
            wetdem_sim_history_init(sim, history + k * len);
        }
    }
    free(pl->items);
    free(pl->history);
    pl->items = items;
    pl->history = history;
    pl->n = pl->cap = n;
    pl->history_cap = n * len;
    pl->history_len = len;
    memcpy(pl->layout, layout, n_layout * sizeof *layout);
    pl->n_layout = n_layout;
    return WETDEM_OK;
}

double* wetdem_pairs_history(const struct wetdem_pairs* pl, size_t k)
{
    return pl->history_len ? pl->history + k * pl->history_len : NULL;
}

void wetdem_pairs_clear(struct wetdem_pairs* pl)
{
    pl->n = 0;
}

void wetdem_pairs_free(struct wetdem_pairs* pl)
{
    free(pl->items);
    free(pl->history);
    memset(pl, 0, sizeof *pl);
}

int wetdem_pairs_copy(struct wetdem_pairs* dst, const struct wetdem_pairs* src)
{
    memset(dst, 0, sizeof *dst);
    size_t nh = src->n * src->history_len;
    dst->items = malloc((src->n ? src->n : 1) * sizeof *dst->items);
    dst->history = malloc((nh ? nh : 1) * sizeof *dst->history);
    if (!dst->items || !dst->history) {
        wetdem_pairs_free(dst);
        return WETDEM_ERR_NOMEM;
    }
    if (src->n)
        memcpy(dst->items, src->items, src->n * sizeof *dst->items);
    if (nh)
        memcpy(dst->history, src->history, nh * sizeof *dst->history);
    dst->n = dst->cap = src->n;
    dst->history_cap = nh;
    dst->history_len = src->history_len;
    memcpy(dst->layout, src->layout, sizeof dst->layout);
    dst->n_layout = src->n_layout;
    return WETDEM_OK;
}

/*
 * celllist.h — cell-list neighbour search with a Verlet skin for many polydisperse spheres
 * (internal). Prefix: wetdem_celllist.
 *
 * A candidate pair (i < j) is listed when its gap, measured with the minimum-image convention
 * on periodic axes, is below reach + skin at the time of the build:
 *
 *     h_ij = |x_i - x_j| - R_i - R_j < reach + skin                                   (1)
 *
 * where `reach` [m] is the largest gap at which any enabled model acts for any pair (the
 * lubrication cut-off, a film thickness delta_ij, a bridge rupture distance) and `skin` [m] > 0
 * is the Verlet margin. Between builds no particle may move more than skin/2 (rebuild
 * criterion, wetdem_celllist_needs_rebuild), so a gap can shrink by at most skin and every pair
 * with h_ij < reach at any time is in the list (Verlet 1967; the guarantee that LAMMPS PR #4685
 * restored for beyond-contact granular pairs). A pair of two fixed particles (is_fixed) is not
 * listed: neither moves, and infinite masses have no pair force (the two-body engine's pair
 * set, pairs.c, leaves them out alike).
 *
 * Cells are cubes-or-boxes of edge >= 2 R_max + reach + skin, so every candidate of a particle
 * lies in its own cell or one of the 26 neighbouring cells; each pair of neighbouring cells is
 * searched once (half stencil, see celllist.c). The list is sorted by (i, j): it is a pure
 * function of the positions and radii, independent of the thread count, and two lists can be
 * merged in one pass to carry per-pair history across rebuilds.
 *
 * Validity: radii > 0 and constant between builds; on a periodic axis the box length must be
 * at least 2 (2 R_max + reach + skin) so that a pair interacts through one image only.
 */
#ifndef WETDEM_CELLLIST_H
#define WETDEM_CELLLIST_H

#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "wetdem.h"

/* Periodicity of the domain. Non-periodic axes are unbounded for the search (the cells span
 * the particles' bounding box at each build); periodic axes wrap on [lo, hi). */
struct wetdem_celllist_box {
    double lo[3], hi[3]; /* [m], used on periodic axes only */
    bool periodic[3];
};

/* Position [m] and radius [m] of a particle, in cell order (cache-friendly scans). */
struct wetdem_celllist_item {
    double x, y, z, r;
};

/* One candidate pair, i < j (particle indices). */
struct wetdem_celllist_pair {
    uint32_t i, j;
};

struct wetdem_celllist {
    struct wetdem_celllist_box box;
    double reach; /* largest interaction gap [m] >= 0 */
    double skin;  /* Verlet skin [m] > 0 */
    /* current cell grid */
    double origin[3], cell[3]; /* [m] */
    int n_cells[3];
    size_t* cell_start;                  /* n_cells_total + 1 offsets into cell_items */
    uint32_t* cell_items;                /* particle indices grouped by cell */
    uint32_t* cell_of;                   /* cell of each particle */
    struct wetdem_celllist_item* sorted; /* positions and radii aligned with cell_items */
    unsigned char* fixed_sorted;         /* is_fixed aligned with cell_items, when any_fixed */
    bool any_fixed;                      /* a particle of the build is fixed */
    size_t cells_cap, items_cap, cell_of_cap, sorted_cap, fixed_cap;
    /* pair list, sorted by (i, j) */
    struct wetdem_celllist_pair* pairs;
    size_t n_pairs, pairs_cap;
    size_t* first_pair; /* n + 1 offsets: pairs of i are first_pair[i] .. first_pair[i+1] */
    size_t first_cap;
    /* per-thread scratch of a build (pairs in cell order), kept to avoid reallocation */
    struct wetdem_celllist_pair** scratch;
    size_t* scratch_cap;
    size_t* scratch_used;
    int n_scratch;
    size_t* counts; /* per-thread counts of the parallel counting sorts (cells, pairs) */
    size_t counts_cap;
    /* state at the last build */
    struct wetdem_vec3* pos_at_build;
    size_t n_at_build, at_build_cap;
    double r_max;      /* largest radius at the build [m] */
    uint64_t n_builds; /* number of builds so far */
};

/* Sets up an empty list. reach >= 0 and skin > 0 [m], finite; box lengths > 0 on periodic
 * axes. Returns WETDEM_OK or WETDEM_ERR_INVALID with a message in msg (may be NULL). */
int wetdem_celllist_init(struct wetdem_celllist* cl, const struct wetdem_celllist_box* box,
                         double reach, double skin, char* msg, size_t msg_size);
/* Releases the arrays of cl (cl itself is caller memory). */
void wetdem_celllist_clear(struct wetdem_celllist* cl);

/* Rebuilds the candidate list from n particles (positions and radii). Returns WETDEM_OK,
 * WETDEM_ERR_NOMEM, or WETDEM_ERR_INVALID (non-finite position, n >= 2^32, periodic box too
 * small for the interaction distance) with a message in msg. */
int wetdem_celllist_build(struct wetdem_celllist* cl, const struct wetdem_particle* p, size_t n,
                          char* msg, size_t msg_size);

/* Largest displacement of a particle since the last build [m] (minimum image on periodic
 * axes); INFINITY when the particle count changed or nothing was built yet. */
double wetdem_celllist_max_displacement(const struct wetdem_celllist* cl,
                                        const struct wetdem_particle* p, size_t n);
/* True when the list must be rebuilt: max displacement > skin/2 (criterion of Eq. 1). */
bool wetdem_celllist_needs_rebuild(const struct wetdem_celllist* cl,
                                   const struct wetdem_particle* p, size_t n);

/* wetdem_celllist_remap_history that also carries per-pair flags: new_flags[b] =
 * old_flags[a] & keep for a pair kept from old index a, 0 for a new pair (both flag arrays
 * may be NULL). Parallel over chunks of the new list; the result does not depend on the
 * thread count. */
size_t wetdem_celllist_remap(const struct wetdem_celllist_pair* old_pairs, const double* old_hist,
                             const unsigned char* old_flags, size_t n_old,
                             const struct wetdem_celllist_pair* new_pairs, double* new_hist,
                             unsigned char* new_flags, unsigned char keep, size_t n_new, size_t len,
                             const double* fresh);
/* Carries per-pair history across a rebuild. old_pairs (n_old, sorted by (i, j)) with
 * old_hist (n_old x len doubles) and new_pairs (n_new, sorted) -> new_hist (n_new x len):
 * a pair present in both keeps its history, a new pair gets `fresh` (len doubles).
 * Returns the number of pairs whose history was carried over. */
size_t wetdem_celllist_remap_history(const struct wetdem_celllist_pair* old_pairs,
                                     const double* old_hist, size_t n_old,
                                     const struct wetdem_celllist_pair* new_pairs, double* new_hist,
                                     size_t n_new, size_t len, const double* fresh);

/* Minimum-image displacement a - b on the periodic axes of box [m]. */
static inline struct wetdem_vec3 celllist_delta(const struct wetdem_celllist_box* box,
                                                struct wetdem_vec3 a, struct wetdem_vec3 b)
{
    double d[3] = {a.x - b.x, a.y - b.y, a.z - b.z};
    for (int k = 0; k < 3; k++) {
        if (!box->periodic[k])
            continue;
        double len = box->hi[k] - box->lo[k];
        d[k] -= len * nearbyint(d[k] / len);
    }
    return (struct wetdem_vec3){d[0], d[1], d[2]};
}

#endif

/*
 * celllist.c — cell-list neighbour search with a Verlet skin (see celllist.h for the
 * criterion, Eq. 1 there, and its validity domain). Prefix: wetdem_celllist.
 *
 * A build bins the particles into cells of edge >= d_cut = 2 R_max + reach + skin [m]
 * (counting sort, particles of a cell in index order), then for every particle i scans its
 * own and the 26 neighbouring cells for j > i with h_ij < reach + skin. Two passes (count,
 * then fill) give every i its own segment of the list, so the parallel loops write disjoint
 * memory and the list is the same for any thread count; each segment is sorted by j.
 * On a periodic axis with fewer than 3 cells the neighbouring cells coincide; they are
 * de-duplicated so that no pair is listed twice.
 */
#include <omp.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "celllist.h"
#include "vec3.h"

/* Upper bound on the number of cells per particle: keeps memory O(n) for sparse systems. */
#define CELLS_PER_PARTICLE 4
/* Fewest particles for which a build runs in parallel (threads cost more below). */
#define PARALLEL_MIN 512

static void set_msg(char* msg, size_t n, const char* fmt, ...)
    __attribute__((format(printf, 3, 4)));
static void set_msg(char* msg, size_t n, const char* fmt, ...)
{
    if (!msg || !n)
        return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, n, fmt, ap);
    va_end(ap);
}

int wetdem_celllist_init(struct wetdem_celllist* cl, const struct wetdem_celllist_box* box,
                         double reach, double skin, char* msg, size_t msg_size)
{
    memset(cl, 0, sizeof *cl);
    if (!(isfinite(reach) && reach >= 0)) {
        set_msg(msg, msg_size, "neighbour reach must be finite and >= 0 m, got %g", reach);
        return WETDEM_ERR_INVALID;
    }
    if (!(isfinite(skin) && skin > 0)) {
        set_msg(msg, msg_size, "neighbour skin must be finite and > 0 m, got %g", skin);
        return WETDEM_ERR_INVALID;
    }
    if (box) {
        cl->box = *box;
        for (int k = 0; k < 3; k++) {
            double len = box->hi[k] - box->lo[k];
            if (box->periodic[k] && !(isfinite(len) && len > 0)) {
                set_msg(msg, msg_size, "periodic box length along %c must be > 0 m, got %g",
                        "xyz"[k], len);
                return WETDEM_ERR_INVALID;
            }
        }
    }
    cl->reach = reach;
    cl->skin = skin;
    return WETDEM_OK;
}

void wetdem_celllist_clear(struct wetdem_celllist* cl)
{
    free(cl->cell_start);
    free(cl->cell_items);
    free(cl->cell_of);
    free(cl->sorted);
    free(cl->pairs);
    free(cl->first_pair);
    free(cl->pos_at_build);
    memset(cl, 0, sizeof *cl);
}

/* Grows *a to hold `need` elements of `size` bytes (capacity doubles). */
static int reserve(void** a, size_t* cap, size_t need, size_t size)
{
    if (need <= *cap && *a)
        return WETDEM_OK;
    size_t c = *cap > 16 ? *cap : 16;
    while (c < need)
        c *= 2;
    void* p = realloc(*a, c * size);
    if (!p)
        return WETDEM_ERR_NOMEM;
    *a = p;
    *cap = c;
    return WETDEM_OK;
}

static double coord(struct wetdem_vec3 v, int k)
{
    return k == 0 ? v.x : (k == 1 ? v.y : v.z);
}

/* Cell grid: periodic axes span the box, the others the particles' bounding box. */
static int setup_grid(struct wetdem_celllist* cl, const struct wetdem_particle* p, size_t n,
                      double d_cut, char* msg, size_t msg_size)
{
    double total = 1;
    for (int k = 0; k < 3; k++) {
        double lo = cl->box.lo[k], hi = cl->box.hi[k];
        if (cl->box.periodic[k]) {
            if (hi - lo < 2 * d_cut) {
                set_msg(msg, msg_size,
                        "periodic box length %g m is below twice the interaction distance "
                        "2 R_max + reach + skin = %g m: a pair would interact through two images",
                        hi - lo, d_cut);
                return WETDEM_ERR_INVALID;
            }
        } else {
            lo = INFINITY;
            hi = -INFINITY;
            for (size_t i = 0; i < n; i++) {
                lo = fmin(lo, coord(p[i].pos, k));
                hi = fmax(hi, coord(p[i].pos, k));
            }
            if (n == 0)
                lo = hi = 0;
        }
        double nc = floor((hi - lo) / d_cut);
        cl->n_cells[k] = nc < 1 ? 1 : (nc > 1e6 ? 1000000 : (int)nc);
        cl->origin[k] = lo;
        cl->cell[k] = hi > lo ? (hi - lo) / cl->n_cells[k] : d_cut;
        total *= cl->n_cells[k];
    }
    /* Coarsen a sparse grid: larger cells stay correct (edge >= d_cut), only slower. */
    double cap = (double)CELLS_PER_PARTICLE * (double)n + 27;
    while (total > cap) {
        total = 1;
        for (int k = 0; k < 3; k++) {
            double len = cl->cell[k] * cl->n_cells[k];
            cl->n_cells[k] = cl->n_cells[k] > 1 ? cl->n_cells[k] / 2 : 1;
            cl->cell[k] = len > 0 ? len / cl->n_cells[k] : d_cut;
            total *= cl->n_cells[k];
        }
    }
    return WETDEM_OK;
}

static int cell_coord(const struct wetdem_celllist* cl, double x, int k)
{
    double t = (x - cl->origin[k]) / cl->cell[k];
    int nc = cl->n_cells[k];
    if (cl->box.periodic[k])
        t -= nc * floor(t / nc);
    int c = (int)floor(t);
    return c < 0 ? 0 : (c >= nc ? nc - 1 : c);
}

static size_t cell_index(const struct wetdem_celllist* cl, const int c[3])
{
    return ((size_t)c[2] * (size_t)cl->n_cells[1] + (size_t)c[1]) * (size_t)cl->n_cells[0] +
           (size_t)c[0];
}

/* Counting sort of the particles into cells (cell_start, cell_items; items in index order). */
static int bin_particles(struct wetdem_celllist* cl, const struct wetdem_particle* p, size_t n)
{
    size_t n_cells = (size_t)cl->n_cells[0] * (size_t)cl->n_cells[1] * (size_t)cl->n_cells[2];
    if (reserve((void**)&cl->cell_start, &cl->cells_cap, n_cells + 1, sizeof(size_t)) ||
        reserve((void**)&cl->cell_items, &cl->items_cap, n, sizeof(uint32_t)) ||
        reserve((void**)&cl->cell_of, &cl->cell_of_cap, n, sizeof(uint32_t)))
        return WETDEM_ERR_NOMEM;
    memset(cl->cell_start, 0, (n_cells + 1) * sizeof(size_t));
    for (size_t i = 0; i < n; i++) {
        int c[3] = {cell_coord(cl, p[i].pos.x, 0), cell_coord(cl, p[i].pos.y, 1),
                    cell_coord(cl, p[i].pos.z, 2)};
        cl->cell_of[i] = (uint32_t)cell_index(cl, c);
        cl->cell_start[cl->cell_of[i] + 1]++;
    }
    for (size_t c = 0; c < n_cells; c++)
        cl->cell_start[c + 1] += cl->cell_start[c];
    if (reserve((void**)&cl->sorted, &cl->sorted_cap, n, sizeof *cl->sorted))
        return WETDEM_ERR_NOMEM;
    for (size_t i = 0; i < n; i++) {
        size_t s = cl->cell_start[cl->cell_of[i]]++;
        cl->cell_items[s] = (uint32_t)i;
        cl->sorted[s] =
            (struct wetdem_celllist_item){p[i].pos.x, p[i].pos.y, p[i].pos.z, p[i].radius};
    }
    for (size_t c = n_cells; c > 0; c--) /* undo the shift left by the fill */
        cl->cell_start[c] = cl->cell_start[c - 1];
    cl->cell_start[0] = 0;
    return WETDEM_OK;
}

/* Distinct neighbouring cell coordinates of c along axis k (1 to 3 values). */
static int axis_neighbours(const struct wetdem_celllist* cl, int c, int k, int out[3])
{
    int nc = cl->n_cells[k], m = 0;
    for (int d = -1; d <= 1; d++) {
        int x = c + d;
        if (cl->box.periodic[k])
            x = (x + nc) % nc;
        else if (x < 0 || x >= nc)
            continue;
        bool seen = false;
        for (int q = 0; q < m; q++)
            seen = seen || out[q] == x;
        if (!seen)
            out[m++] = x;
    }
    return m;
}

/* Distinct neighbouring cells (including its own) of the cell of particle i; returns count. */
static int stencil(const struct wetdem_celllist* cl, struct wetdem_vec3 x, size_t cells[27])
{
    int c[3] = {cell_coord(cl, x.x, 0), cell_coord(cl, x.y, 1), cell_coord(cl, x.z, 2)};
    int ax[3][3], m[3];
    for (int k = 0; k < 3; k++)
        m[k] = axis_neighbours(cl, c[k], k, ax[k]);
    int count = 0;
    for (int a = 0; a < m[2]; a++)
        for (int b = 0; b < m[1]; b++)
            for (int d = 0; d < m[0]; d++)
                cells[count++] = cell_index(cl, (int[3]){ax[0][d], ax[1][b], ax[2][a]});
    return count;
}

/* Scans the candidates j > i of particle i in the nc cells `cells` (its stencil); writes them
 * to out (sorted by j) and returns their number. Positions and radii come from the
 * cell-ordered copy, so each cell is read as one contiguous block. */
static size_t scan_particle(const struct wetdem_celllist* cl, const struct wetdem_particle* p,
                            size_t i, const size_t* cells, int nc, struct wetdem_celllist_pair* out)
{
    size_t count = 0;
    double extra = cl->reach + cl->skin;
    bool periodic = cl->box.periodic[0] || cl->box.periodic[1] || cl->box.periodic[2];
    struct wetdem_vec3 xi = p[i].pos;
    double ri = p[i].radius;
    for (int q = 0; q < nc; q++) {
        for (size_t s = cl->cell_start[cells[q]]; s < cl->cell_start[cells[q] + 1]; s++) {
            uint32_t j = cl->cell_items[s];
            if (j <= i)
                continue;
            const struct wetdem_celllist_item* b = &cl->sorted[s];
            struct wetdem_vec3 xj = vec3(b->x, b->y, b->z);
            struct wetdem_vec3 d = periodic ? celllist_delta(&cl->box, xi, xj) : vec3_sub(xi, xj);
            double lim = ri + b->r + extra;
            if (vec3_dot(d, d) >= lim * lim)
                continue;
            size_t k = count; /* insertion sort by j: segments are short */
            while (k > 0 && out[k - 1].j > j) {
                out[k] = out[k - 1];
                k--;
            }
            out[k] = (struct wetdem_celllist_pair){(uint32_t)i, j};
            count++;
        }
    }
    return count;
}

static int check_input(const struct wetdem_particle* p, size_t n, double* r_max, char* msg,
                       size_t msg_size)
{
    if (n >= UINT32_MAX) {
        set_msg(msg, msg_size, "too many particles for the neighbour list: %zu (limit %u)", n,
                UINT32_MAX - 1);
        return WETDEM_ERR_INVALID;
    }
    *r_max = 0;
    for (size_t i = 0; i < n; i++) {
        if (!vec3_is_finite(p[i].pos) || !(p[i].radius > 0 && isfinite(p[i].radius))) {
            set_msg(msg, msg_size, "particle %zu has a non-finite position or a bad radius %g m", i,
                    p[i].radius);
            return WETDEM_ERR_INVALID;
        }
        *r_max = fmax(*r_max, p[i].radius);
    }
    return WETDEM_OK;
}

/* Upper bound of the candidates of a particle: the particles of its stencil cells. */
static size_t stencil_population(const struct wetdem_celllist* cl, const size_t* cells, int nc)
{
    size_t total = 0;
    for (int q = 0; q < nc; q++)
        total += cl->cell_start[cells[q] + 1] - cl->cell_start[cells[q]];
    return total;
}

/* One pass: each thread scans a contiguous block of particles into its own buffer (count per
 * particle into first_pair); the buffers are then concatenated in thread order, which is
 * particle order, so the list is the same for any thread count. */
static int fill_pairs(struct wetdem_celllist* cl, const struct wetdem_particle* p, size_t n)
{
    if (reserve((void**)&cl->first_pair, &cl->first_cap, n + 1, sizeof(size_t)))
        return WETDEM_ERR_NOMEM;
    int max_threads = omp_get_max_threads(), used_threads = 1;
    struct wetdem_celllist_pair** buf = calloc((size_t)max_threads, sizeof *buf);
    size_t* used = calloc((size_t)max_threads, sizeof *used);
    bool nomem = !buf || !used;
#pragma omp parallel if (!nomem && n >= PARALLEL_MIN)
    {
        int t = omp_get_thread_num(), nt = omp_get_num_threads();
#pragma omp single
        used_threads = nt;
        size_t lo = n * (size_t)t / (size_t)nt, hi = n * (size_t)(t + 1) / (size_t)nt, cap = 0;
        for (size_t i = lo; i < hi; i++) {
            size_t cells[27];
            int nc = stencil(cl, p[i].pos, cells);
            size_t bound = stencil_population(cl, cells, nc);
            if (used[t] + bound > cap) {
                cap = 2 * (used[t] + bound) + 64;
                struct wetdem_celllist_pair* b = realloc(buf[t], cap * sizeof *b);
                if (!b) {
#pragma omp atomic write
                    nomem = true;
                    break;
                }
                buf[t] = b;
            }
            size_t c = scan_particle(cl, p, i, cells, nc, buf[t] + used[t]);
            cl->first_pair[i + 1] = c;
            used[t] += c;
        }
    }
    size_t total = 0;
    for (int t = 0; !nomem && t < used_threads; t++)
        total += used[t];
    nomem =
        nomem || reserve((void**)&cl->pairs, &cl->pairs_cap, total ? total : 1, sizeof *cl->pairs);
    size_t at = 0;
    for (int t = 0; !nomem && t < used_threads; at += used[t], t++)
        if (used[t])
            memcpy(cl->pairs + at, buf[t], used[t] * sizeof *cl->pairs);
    for (int t = 0; buf && t < max_threads; t++)
        free(buf[t]);
    free(buf);
    free(used);
    if (nomem)
        return WETDEM_ERR_NOMEM;
    cl->first_pair[0] = 0;
    for (size_t i = 0; i < n; i++)
        cl->first_pair[i + 1] += cl->first_pair[i];
    cl->n_pairs = total;
    return WETDEM_OK;
}

int wetdem_celllist_build(struct wetdem_celllist* cl, const struct wetdem_particle* p, size_t n,
                          char* msg, size_t msg_size)
{
    double r_max;
    int st = check_input(p, n, &r_max, msg, msg_size);
    if (st != WETDEM_OK)
        return st;
    st = setup_grid(cl, p, n, 2 * r_max + cl->reach + cl->skin, msg, msg_size);
    if (st != WETDEM_OK)
        return st;
    if (bin_particles(cl, p, n) != WETDEM_OK || fill_pairs(cl, p, n) != WETDEM_OK ||
        reserve((void**)&cl->pos_at_build, &cl->at_build_cap, n, sizeof *cl->pos_at_build)) {
        set_msg(msg, msg_size, "out of memory building the neighbour list of %zu particles", n);
        return WETDEM_ERR_NOMEM;
    }
    for (size_t i = 0; i < n; i++)
        cl->pos_at_build[i] = p[i].pos;
    cl->n_at_build = n;
    cl->r_max = r_max;
    cl->n_builds++;
    return WETDEM_OK;
}

double wetdem_celllist_max_displacement(const struct wetdem_celllist* cl,
                                        const struct wetdem_particle* p, size_t n)
{
    if (cl->n_builds == 0 || n != cl->n_at_build)
        return INFINITY;
    double worst = 0; /* max is exact, so the reduction order does not matter */
#pragma omp parallel for reduction(max : worst) schedule(static) if (n >= PARALLEL_MIN)
    for (size_t i = 0; i < n; i++) {
        struct wetdem_vec3 d = celllist_delta(&cl->box, p[i].pos, cl->pos_at_build[i]);
        double d2 = vec3_dot(d, d);
        worst = d2 > worst ? d2 : worst;
    }
    return sqrt(worst);
}

bool wetdem_celllist_needs_rebuild(const struct wetdem_celllist* cl,
                                   const struct wetdem_particle* p, size_t n)
{
    return !(wetdem_celllist_max_displacement(cl, p, n) <= 0.5 * cl->skin);
}

static uint64_t pair_key(struct wetdem_celllist_pair q)
{
    return ((uint64_t)q.i << 32) | q.j;
}

size_t wetdem_celllist_remap_history(const struct wetdem_celllist_pair* old_pairs,
                                     const double* old_hist, size_t n_old,
                                     const struct wetdem_celllist_pair* new_pairs, double* new_hist,
                                     size_t n_new, size_t len, const double* fresh)
{
    size_t a = 0, kept = 0;
    for (size_t b = 0; b < n_new; b++) {
        uint64_t key = pair_key(new_pairs[b]);
        while (a < n_old && pair_key(old_pairs[a]) < key)
            a++;
        bool found = a < n_old && pair_key(old_pairs[a]) == key;
        if (len)
            memcpy(new_hist + b * len, found ? old_hist + a * len : fresh, len * sizeof(double));
        kept += found;
    }
    return kept;
}

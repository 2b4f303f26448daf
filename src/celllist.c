/*
 * celllist.c — cell-list neighbour search with a Verlet skin (see celllist.h for the
 * criterion, Eq. 1 there, and its validity domain). Prefix: wetdem_celllist.
 *
 * A build
 *  1. bins the particles into cells of edge >= d_cut = 2 R_max + reach + skin [m] (counting
 *     sort; the particles of a cell are in index order and their positions and radii are copied
 *     into one contiguous, cell-ordered array);
 *  2. searches every pair of neighbouring cells once (half stencil): a cell A is paired with
 *     itself and with the 13 "forward" neighbours A + o, o = (dx, dy, dz) in {-1, 0, 1}^3 with
 *     dz > 0, or dz = 0 and dy > 0, or dz = dy = 0 and dx > 0. Cells of one x row are
 *     contiguous in memory, so the forward neighbours of a cell are at most 5 contiguous runs
 *     of particles: (x+1, y, z), (x-1..x+1, y+1, z) and (x-1..x+1, y-1..y+1, z+1). On a
 *     periodic axis with n >= 3 cells the offsets wrap and still name distinct cells; with
 *     n <= 2 they would coincide, so there the distinct neighbours B of A are enumerated and
 *     only those with index B > A are searched. A pair (a, b) with h_ab < reach + skin, not
 *     both fixed, is stored as (min, max) in a per-thread buffer; threads take contiguous
 *     blocks of cells with about n / threads particles each;
 *  3. counting-sorts the buffers by i into the list (first_pair holds the offsets) and sorts
 *     each segment by j (insertion sort: segments are short). The result does not depend on
 *     the order in which pairs were found, so it is the same for any thread count.
 * The gap test evaluates exactly the expression of the minimum-image convention of
 * celllist_delta, so the list equals a brute-force search bit for bit.
 * Cost: each neighbouring pair of particles is tested once instead of twice, and no particle
 * recomputes its stencil.
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
/* Most runs of particles searched against one cell: 26 distinct neighbours at worst. */
#define MAX_RUNS 27
/* Blocks of cells per thread in the pair search (fewer leave a thread idle at the end) */
#define SCAN_CHUNKS 8

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
    free(cl->fixed_sorted);
    free(cl->pairs);
    free(cl->first_pair);
    free(cl->pos_at_build);
    for (int t = 0; t < cl->n_scratch; t++)
        free(cl->scratch[t]);
    free(cl->scratch);
    free(cl->scratch_cap);
    free(cl->scratch_used);
    free(cl->counts);
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

/* Cell grid: periodic axes span the box, the others the particles' bounding box [bb_lo,
 * bb_hi]. The cells are at least d_cut (1 + 1e-9) wide: the margin covers the rounding of the
 * cell coordinate, so two particles closer than d_cut are never binned two cells apart. */
static int setup_grid(struct wetdem_celllist* cl, const double bb_lo[3], const double bb_hi[3],
                      size_t n, double d_cut, char* msg, size_t msg_size)
{
    double total = 1, edge_min = d_cut * (1 + 1e-9);
    for (int k = 0; k < 3; k++) {
        double lo = cl->box.lo[k], hi = cl->box.hi[k];
        if (cl->box.periodic[k]) {
            if (hi - lo < 2 * d_cut) {
                set_msg(msg, msg_size,
                        "periodic box length along %c, %g m, is below twice the interaction "
                        "distance 2 R_max + reach + skin = %g m (R_max %g m, reach %g m, skin "
                        "%g m): it must be at least %g m, or a pair would interact through two "
                        "images",
                        "xyz"[k], hi - lo, d_cut, 0.5 * (d_cut - cl->reach - cl->skin), cl->reach,
                        cl->skin, 2 * d_cut);
                return WETDEM_ERR_INVALID;
            }
        } else {
            lo = n ? bb_lo[k] : 0;
            hi = n ? bb_hi[k] : 0;
        }
        double nc = floor((hi - lo) / edge_min);
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
    if (cl->box.periodic[k] && !(t >= 0 && t < nc))
        t -= nc * floor(t / nc);
    int c = (int)t; /* t >= 0 up to rounding: truncation is floor, and the clamp catches -0.x */
    return c < 0 ? 0 : (c >= nc ? nc - 1 : c);
}

static size_t cell_index(const struct wetdem_celllist* cl, int x, int y, int z)
{
    return ((size_t)z * (size_t)cl->n_cells[1] + (size_t)y) * (size_t)cl->n_cells[0] + (size_t)x;
}

/* Counting sort of the particles into cells (cell_start, cell_items; items in index order),
 * in parallel: thread t of nt takes the particles [n t / nt, n (t + 1) / nt), counts them per
 * cell, and places them after the same cell's particles of the threads before it, so each
 * cell lists its particles in index order whatever the thread count. */
static int bin_particles(struct wetdem_celllist* cl, const struct wetdem_particle* p, size_t n)
{
    size_t n_cells = (size_t)cl->n_cells[0] * (size_t)cl->n_cells[1] * (size_t)cl->n_cells[2];
    int nt = n >= PARALLEL_MIN ? omp_get_max_threads() : 1;
    if (reserve((void**)&cl->cell_start, &cl->cells_cap, n_cells + 1, sizeof(size_t)) ||
        reserve((void**)&cl->cell_items, &cl->items_cap, n, sizeof(uint32_t)) ||
        reserve((void**)&cl->cell_of, &cl->cell_of_cap, n, sizeof(uint32_t)) ||
        reserve((void**)&cl->sorted, &cl->sorted_cap, n, sizeof *cl->sorted) ||
        (cl->any_fixed && reserve((void**)&cl->fixed_sorted, &cl->fixed_cap, n, 1)) ||
        reserve((void**)&cl->counts, &cl->counts_cap, (size_t)nt * n_cells, sizeof(size_t)))
        return WETDEM_ERR_NOMEM;
#pragma omp parallel num_threads(nt)
    {
        size_t t = (size_t)omp_get_thread_num(), team = (size_t)omp_get_num_threads();
        size_t lo = n * t / team, hi = n * (t + 1) / team, *count = cl->counts + t * n_cells;
        memset(count, 0, n_cells * sizeof *count);
        for (size_t i = lo; i < hi; i++) {
            size_t c = cell_index(cl, cell_coord(cl, p[i].pos.x, 0), cell_coord(cl, p[i].pos.y, 1),
                                  cell_coord(cl, p[i].pos.z, 2));
            cl->cell_of[i] = (uint32_t)c;
            count[c]++;
        }
#pragma omp barrier
#pragma omp single
        { /* each thread's first place in each cell */
            size_t run = 0;
            for (size_t c = 0; c < n_cells; c++) {
                cl->cell_start[c] = run;
                for (size_t u = 0; u < team; u++) {
                    size_t k = cl->counts[u * n_cells + c];
                    cl->counts[u * n_cells + c] = run;
                    run += k;
                }
            }
            cl->cell_start[n_cells] = run;
        }
        for (size_t i = lo; i < hi; i++) {
            size_t s = count[cl->cell_of[i]]++;
            cl->cell_items[s] = (uint32_t)i;
            cl->sorted[s] =
                (struct wetdem_celllist_item){p[i].pos.x, p[i].pos.y, p[i].pos.z, p[i].radius};
            if (cl->any_fixed)
                cl->fixed_sorted[s] = p[i].is_fixed;
        }
    }
    return WETDEM_OK;
}

/* A contiguous block [lo, hi) of the cell-ordered particles. */
struct run {
    size_t lo, hi;
};

/* Wraps a cell coordinate on a periodic axis; false when it lies outside a bounded axis. */
static bool wrap_cell(const struct wetdem_celllist* cl, int k, int* c)
{
    int nc = cl->n_cells[k];
    if (*c >= 0 && *c < nc)
        return true;
    if (!cl->box.periodic[k])
        return false;
    *c = (*c + nc) % nc;
    return true;
}

/* Appends the particles of cells x0..x1 of row (y, z) (x already wrapped or in range) as runs. */
static int row_runs(const struct wetdem_celllist* cl, int x0, int x1, int y, int z,
                    struct run* runs, int m)
{
    int nx = cl->n_cells[0];
    if (!cl->box.periodic[0]) {
        x0 = x0 < 0 ? 0 : x0;
        x1 = x1 >= nx ? nx - 1 : x1;
    } else if (x0 < 0 || x1 >= nx) { /* wrapped row: one run per cell */
        for (int x = x0; x <= x1; x++) {
            int w = x;
            wrap_cell(cl, 0, &w);
            m = row_runs(cl, w, w, y, z, runs, m);
        }
        return m;
    }
    if (x0 > x1)
        return m;
    size_t base = cell_index(cl, 0, y, z);
    struct run r = {cl->cell_start[base + (size_t)x0], cl->cell_start[base + (size_t)x1 + 1]};
    if (r.hi > r.lo)
        runs[m++] = r;
    return m;
}

/* Forward half stencil of cell (x, y, z) as runs (valid when every periodic axis has >= 3
 * cells): rows (x+1; y; z), (x-1..x+1; y+1; z), (x-1..x+1; y-1..y+1; z+1). */
static int forward_runs(const struct wetdem_celllist* cl, int x, int y, int z, struct run* runs)
{
    static const int rows[5][3] = {{1, 0, 0}, {-1, 1, 0}, {-1, -1, 1}, {-1, 0, 1}, {-1, 1, 1}};
    int m = 0;
    for (int r = 0; r < 5; r++) {
        int yy = y + rows[r][1], zz = z + rows[r][2];
        if (wrap_cell(cl, 1, &yy) && wrap_cell(cl, 2, &zz))
            m = row_runs(cl, x + rows[r][0], x + 1, yy, zz, runs, m);
    }
    return m;
}

/* Distinct neighbouring cell coordinates of c along axis k (1 to 3 values). */
static int axis_neighbours(const struct wetdem_celllist* cl, int c, int k, int out[3])
{
    int m = 0;
    for (int d = -1; d <= 1; d++) {
        int x = c + d;
        if (!wrap_cell(cl, k, &x))
            continue;
        bool seen = false;
        for (int q = 0; q < m; q++)
            seen = seen || out[q] == x;
        if (!seen)
            out[m++] = x;
    }
    return m;
}

/* Half stencil for periodic axes of 1 or 2 cells, where offsets coincide: the distinct
 * neighbouring cells with a larger index than cell a = (x, y, z), one run each. */
static int distinct_runs(const struct wetdem_celllist* cl, int x, int y, int z, struct run* runs)
{
    int ax[3][3], m[3] = {axis_neighbours(cl, x, 0, ax[0]), axis_neighbours(cl, y, 1, ax[1]),
                          axis_neighbours(cl, z, 2, ax[2])};
    size_t a = cell_index(cl, x, y, z);
    int count = 0;
    for (int k = 0; k < m[2]; k++)
        for (int j = 0; j < m[1]; j++)
            for (int i = 0; i < m[0]; i++) {
                size_t b = cell_index(cl, ax[0][i], ax[1][j], ax[2][k]);
                struct run r = {cl->cell_start[b], cl->cell_start[b + 1]};
                if (b > a && r.hi > r.lo)
                    runs[count++] = r;
            }
    return count;
}

/* What the scan of one cell needs. */
struct scan {
    const struct wetdem_celllist_item* x; /* cell-ordered positions and radii */
    const uint32_t* id;                   /* cell-ordered particle indices */
    const struct wetdem_celllist_box* box;
    const unsigned char* fixed; /* cell-ordered is_fixed, NULL when no particle is fixed */
    double extra;               /* reach + skin [m] */
    ptrdiff_t off[5]; /* first cell of the 5 forward rows of an interior cell, from the cell */
};

static struct wetdem_celllist_pair ordered(uint32_t a, uint32_t b)
{
    return a < b ? (struct wetdem_celllist_pair){a, b} : (struct wetdem_celllist_pair){b, a};
}

/* Tests particle s against the runs; appends the listed pairs as (min, max) to out and
 * returns their number. `periodic`: the minimum-image displacement of celllist_delta, else
 * the plain difference; `s_fixed`: s is fixed, and its fixed partners are left out (constants
 * at each call, so each variant compiles to its own loop). */
static inline __attribute__((always_inline)) size_t scan_loop(const struct scan* sc, size_t s,
                                                              const struct run* runs, int m,
                                                              struct wetdem_celllist_pair* out,
                                                              bool periodic, bool s_fixed)
{
    const struct wetdem_celllist_item a = sc->x[s];
    size_t count = 0;
    for (int r = 0; r < m; r++)
        for (size_t t = runs[r].lo; t < runs[r].hi; t++) {
            const struct wetdem_celllist_item* b = &sc->x[t];
            struct wetdem_vec3 d =
                periodic ? celllist_delta(sc->box, vec3(a.x, a.y, a.z), vec3(b->x, b->y, b->z))
                         : vec3(a.x - b->x, a.y - b->y, a.z - b->z);
            double lim = a.r + b->r + sc->extra;
            if (vec3_dot(d, d) < lim * lim && !(s_fixed && sc->fixed[t]))
                out[count++] = ordered(sc->id[s], sc->id[t]);
        }
    return count;
}

/* scan_loop of particle s, with its fixed partners left out when s is fixed. */
static inline __attribute__((always_inline)) size_t scan_runs(const struct scan* sc, size_t s,
                                                              const struct run* runs, int m,
                                                              struct wetdem_celllist_pair* out,
                                                              bool periodic)
{
    return sc->fixed && sc->fixed[s] ? scan_loop(sc, s, runs, m, out, periodic, true)
                                     : scan_loop(sc, s, runs, m, out, periodic, false);
}

static size_t scan_plain(const struct scan* sc, size_t s, const struct run* runs, int m,
                         struct wetdem_celllist_pair* out)
{
    return scan_runs(sc, s, runs, m, out, false);
}

static size_t scan_image(const struct scan* sc, size_t s, const struct run* runs, int m,
                         struct wetdem_celllist_pair* out)
{
    return scan_runs(sc, s, runs, m, out, true);
}

/* Runs of the half stencil of cell c = (x, y, z) after runs[0] (kept for the cell itself). */
static int stencil_runs(const struct wetdem_celllist* cl, const struct scan* sc, size_t c, int x,
                        int y, int z, bool distinct, struct run* runs)
{
    if (distinct)
        return 1 + distinct_runs(cl, x, y, z, runs + 1);
    if (x < 1 || x > cl->n_cells[0] - 2 || y < 1 || y > cl->n_cells[1] - 2 ||
        z > cl->n_cells[2] - 2)
        return 1 + forward_runs(cl, x, y, z, runs + 1);
    static const int width[5] = {1, 3, 3, 3, 3}; /* interior: fixed offsets */
    for (int r = 0; r < 5; r++) {
        size_t first = (size_t)((ptrdiff_t)c + sc->off[r]);
        runs[r + 1] = (struct run){cl->cell_start[first], cl->cell_start[first + width[r]]};
    }
    return 6;
}

/* A thread's pair buffer during the search, in the thread's own memory (the arrays of
 * struct wetdem_celllist that hold it share cache lines between threads). */
struct pair_buffer {
    struct wetdem_celllist_pair* pairs;
    size_t cap, used;
};

/* Searches cell (x, y, z) against itself and its half stencil; appends to the buffer b (grown
 * as needed). Returns WETDEM_OK or WETDEM_ERR_NOMEM. */
static int scan_cell(const struct wetdem_celllist* cl, const struct scan* sc, int x, int y, int z,
                     bool distinct, struct pair_buffer* b)
{
    size_t c = cell_index(cl, x, y, z), a0 = cl->cell_start[c], a1 = cl->cell_start[c + 1];
    struct run runs[MAX_RUNS + 1];
    int m = stencil_runs(cl, sc, c, x, y, z, distinct, runs);
    size_t others = 0, na = a1 - a0;
    for (int r = 1; r < m; r++)
        others += runs[r].hi - runs[r].lo;
    size_t used = b->used, need = used + na * (na - 1) / 2 + na * others;
    if (need == used) /* one particle and no neighbours: no pair (b->pairs may be NULL) */
        return WETDEM_OK;
    if (need > b->cap && reserve((void**)&b->pairs, &b->cap, need, sizeof *b->pairs))
        return WETDEM_ERR_NOMEM;
    bool image = cl->box.periodic[0] || cl->box.periodic[1] || cl->box.periodic[2];
    struct wetdem_celllist_pair* out = b->pairs;
    for (size_t s = a0; s < a1; s++) {
        runs[0] = (struct run){s + 1, a1};
        used +=
            image ? scan_image(sc, s, runs, m, out + used) : scan_plain(sc, s, runs, m, out + used);
    }
    b->used = used;
    return WETDEM_OK;
}

/* First cell of the block of thread t of nt: blocks hold about n / nt particles each. */
static size_t block_start(const struct wetdem_celllist* cl, size_t n_cells, size_t n, int t, int nt)
{
    size_t target = n * (size_t)t / (size_t)nt, lo = 0, hi = n_cells;
    while (lo < hi) { /* first c with cell_start[c] >= target */
        size_t mid = lo + (hi - lo) / 2;
        if (cl->cell_start[mid] < target)
            lo = mid + 1;
        else
            hi = mid;
    }
    return t == 0 ? 0 : (t == nt ? n_cells : lo);
}

/* Scans the cells [c0, c1) into the buffer of thread t (kept in a local while it runs). */
static int scan_block(struct wetdem_celllist* cl, const struct scan* sc, size_t c0, size_t c1,
                      bool distinct, int t)
{
    int nx = cl->n_cells[0], ny = cl->n_cells[1];
    int x = (int)(c0 % (size_t)nx), y = (int)(c0 / (size_t)nx % (size_t)ny);
    int z = (int)(c0 / ((size_t)nx * (size_t)ny));
    struct pair_buffer b = {cl->scratch[t], cl->scratch_cap[t], cl->scratch_used[t]};
    int st = WETDEM_OK;
    for (size_t c = c0; c < c1 && st == WETDEM_OK; c++) {
        if (cl->cell_start[c + 1] > cl->cell_start[c])
            st = scan_cell(cl, sc, x, y, z, distinct, &b);
        if (++x == nx) {
            x = 0;
            if (++y == ny) {
                y = 0;
                z++;
            }
        }
    }
    cl->scratch[t] = b.pairs;
    cl->scratch_cap[t] = b.cap;
    cl->scratch_used[t] = b.used;
    return st;
}

/* Checks the particles; r_max [m] is the largest radius, [lo, hi] the bounding box [m]. */
static int check_input(const struct wetdem_particle* p, size_t n, double* r_max, double lo[3],
                       double hi[3], bool* any_fixed, char* msg, size_t msg_size)
{
    if (n >= UINT32_MAX) {
        set_msg(msg, msg_size, "too many particles for the neighbour list: %zu (limit %u)", n,
                UINT32_MAX - 1);
        return WETDEM_ERR_INVALID;
    }
    /* in parallel: min and max are exact, so the same for any thread count; the first bad
       particle is the lowest index of one */
    double r = 0, l[3] = {INFINITY, INFINITY, INFINITY}, h[3] = {-INFINITY, -INFINITY, -INFINITY};
    size_t bad = SIZE_MAX;
    int fixed = 0;
#pragma omp parallel for schedule(static) reduction(max                                            \
                                                    : r, h[:3], fixed)                             \
    reduction(min                                                                                  \
              : l[:3], bad) if (n >= PARALLEL_MIN)
    for (size_t i = 0; i < n; i++) {
        double x[3] = {p[i].pos.x, p[i].pos.y, p[i].pos.z};
        fixed = p[i].is_fixed ? 1 : fixed;
        if (!vec3_is_finite(p[i].pos) || !(p[i].radius > 0 && isfinite(p[i].radius))) {
            bad = i < bad ? i : bad;
            continue;
        }
        r = p[i].radius > r ? p[i].radius : r;
        for (int k = 0; k < 3; k++) {
            l[k] = x[k] < l[k] ? x[k] : l[k];
            h[k] = x[k] > h[k] ? x[k] : h[k];
        }
    }
    if (bad != SIZE_MAX) {
        set_msg(msg, msg_size, "particle %zu has a non-finite position or a bad radius %g m", bad,
                p[bad].radius);
        return WETDEM_ERR_INVALID;
    }
    *r_max = r;
    *any_fixed = fixed != 0;
    memcpy(lo, l, sizeof l);
    memcpy(hi, h, sizeof h);
    return WETDEM_OK;
}

/* One per-thread pair buffer for each of nt threads (kept across builds). */
static int reserve_scratch(struct wetdem_celllist* cl, int nt)
{
    if (nt <= cl->n_scratch)
        return WETDEM_OK;
    struct wetdem_celllist_pair** s = realloc(cl->scratch, (size_t)nt * sizeof *s);
    if (s)
        cl->scratch = s;
    size_t* cap = realloc(cl->scratch_cap, (size_t)nt * sizeof *cap);
    if (cap)
        cl->scratch_cap = cap;
    size_t* used = realloc(cl->scratch_used, (size_t)nt * sizeof *used);
    if (used)
        cl->scratch_used = used;
    if (!s || !cap || !used)
        return WETDEM_ERR_NOMEM;
    for (int t = cl->n_scratch; t < nt; t++) {
        cl->scratch[t] = NULL;
        cl->scratch_cap[t] = 0;
    }
    cl->n_scratch = nt;
    return WETDEM_OK;
}

/* Sorts the j of one segment (all with the same i): insertion sort, segments are short. */
static void sort_segment(struct wetdem_celllist_pair* q, size_t len)
{
    for (size_t a = 1; a < len; a++) {
        struct wetdem_celllist_pair key = q[a];
        size_t b = a;
        while (b > 0 && q[b - 1].j > key.j) {
            q[b] = q[b - 1];
            b--;
        }
        q[b] = key;
    }
}

/* Chunks of the particle range over which the prefix sum of the pair counts is shared. */
#define GATHER_CHUNKS 64

/* Counting sort of the nt thread buffers by i into pairs / first_pair, then each segment by
 * j, in parallel: the buffers are counted per i on their own, the prefix sum over i (each
 * buffer's first place in each segment, buffers in order) runs in chunks of i, and each
 * buffer is scattered on its own. Segments are sorted by j, so the list does not depend on
 * which buffer held a pair. */
static int gather_pairs(struct wetdem_celllist* cl, size_t n, int nt)
{
    size_t total = 0, nb = (size_t)nt;
    for (int t = 0; t < nt; t++)
        total += cl->scratch_used[t];
    if (reserve((void**)&cl->first_pair, &cl->first_cap, n + 2, sizeof(size_t)) ||
        reserve((void**)&cl->pairs, &cl->pairs_cap, total ? total : 1, sizeof *cl->pairs) ||
        reserve((void**)&cl->counts, &cl->counts_cap, nb * (n ? n : 1), sizeof(size_t)))
        return WETDEM_ERR_NOMEM;
    size_t* start = cl->first_pair;
    size_t chunk_start[GATHER_CHUNKS + 1];
    size_t n_chunks = n < GATHER_CHUNKS ? 1 : GATHER_CHUNKS;
#pragma omp parallel num_threads(nt) if (n >= PARALLEL_MIN)
    {
#pragma omp for schedule(static)
        for (size_t b = 0; b < nb; b++) { /* counts of buffer b per i */
            size_t* count = cl->counts + b * n;
            memset(count, 0, n * sizeof *count);
            for (size_t q = 0; q < cl->scratch_used[b]; q++)
                count[cl->scratch[b][q].i]++;
        }
#pragma omp for schedule(static)
        for (size_t k = 0; k < n_chunks; k++) { /* pairs of each chunk of i */
            size_t sum = 0;
            for (size_t i = n * k / n_chunks; i < n * (k + 1) / n_chunks; i++)
                for (size_t b = 0; b < nb; b++)
                    sum += cl->counts[b * n + i];
            chunk_start[k + 1] = sum;
        }
#pragma omp single
        {
            chunk_start[0] = 0;
            for (size_t k = 0; k < n_chunks; k++)
                chunk_start[k + 1] += chunk_start[k];
        }
#pragma omp for schedule(static)
        for (size_t k = 0; k < n_chunks; k++) { /* segment starts, and each buffer's place */
            size_t run = chunk_start[k];
            for (size_t i = n * k / n_chunks; i < n * (k + 1) / n_chunks; i++) {
                start[i] = run;
                for (size_t b = 0; b < nb; b++) {
                    size_t c = cl->counts[b * n + i];
                    cl->counts[b * n + i] = run;
                    run += c;
                }
            }
        }
#pragma omp for schedule(static)
        for (size_t b = 0; b < nb; b++) { /* each buffer into its places */
            size_t* place = cl->counts + b * n;
            for (size_t q = 0; q < cl->scratch_used[b]; q++)
                cl->pairs[place[cl->scratch[b][q].i]++] = cl->scratch[b][q];
        }
#pragma omp for schedule(static)
        for (size_t i = 0; i < n; i++)
            sort_segment(cl->pairs + start[i], (i + 1 < n ? start[i + 1] : total) - start[i]);
    }
    start[n] = start[n + 1] = total;
    cl->n_pairs = total;
    return WETDEM_OK;
}

/* Finds the pairs: threads scan contiguous blocks of cells (SCAN_CHUNKS per thread, taken as
 * they come: packings are denser in places) into their own buffers, which are then sorted into
 * the list by (i, j): the same list for any thread count and any share of the blocks. */
static int fill_pairs(struct wetdem_celllist* cl, size_t n)
{
    int max_threads = n >= PARALLEL_MIN ? omp_get_max_threads() : 1, used_threads = 1;
    if (reserve_scratch(cl, max_threads))
        return WETDEM_ERR_NOMEM;
    size_t n_cells = (size_t)cl->n_cells[0] * (size_t)cl->n_cells[1] * (size_t)cl->n_cells[2];
    bool distinct = false, nomem = false;
    for (int k = 0; k < 3; k++)
        distinct = distinct || (cl->box.periodic[k] && cl->n_cells[k] < 3);
    ptrdiff_t nx = cl->n_cells[0], nxy = nx * cl->n_cells[1];
    struct scan sc = {cl->sorted,
                      cl->cell_items,
                      &cl->box,
                      cl->any_fixed ? cl->fixed_sorted : NULL,
                      cl->reach + cl->skin,
                      {1, nx - 1, nxy - nx - 1, nxy - 1, nxy + nx - 1}};
#pragma omp parallel num_threads(max_threads)
    {
        int t = omp_get_thread_num(), nt = omp_get_num_threads();
        int chunks = nt > 1 ? SCAN_CHUNKS * nt : 1;
#pragma omp single
        used_threads = nt;
        cl->scratch_used[t] = 0;
#pragma omp barrier
#pragma omp for schedule(dynamic, 1)
        for (int k = 0; k < chunks; k++)
            if (scan_block(cl, &sc, block_start(cl, n_cells, n, k, chunks),
                           block_start(cl, n_cells, n, k + 1, chunks), distinct, t)) {
#pragma omp atomic write
                nomem = true;
            }
    }
    return nomem ? WETDEM_ERR_NOMEM : gather_pairs(cl, n, used_threads);
}

int wetdem_celllist_build(struct wetdem_celllist* cl, const struct wetdem_particle* p, size_t n,
                          char* msg, size_t msg_size)
{
    double r_max, lo[3], hi[3];
    int st = check_input(p, n, &r_max, lo, hi, &cl->any_fixed, msg, msg_size);
    if (st != WETDEM_OK)
        return st;
    st = setup_grid(cl, lo, hi, n, 2 * r_max + cl->reach + cl->skin, msg, msg_size);
    if (st != WETDEM_OK)
        return st;
    if (bin_particles(cl, p, n) != WETDEM_OK || fill_pairs(cl, n) != WETDEM_OK ||
        reserve((void**)&cl->pos_at_build, &cl->at_build_cap, n, sizeof *cl->pos_at_build)) {
        set_msg(msg, msg_size,
                "out of memory building the neighbour list of %zu particles, the pairs with a "
                "gap below reach + skin = %g + %g m: a smaller skin shortens it",
                n, cl->reach, cl->skin);
        return WETDEM_ERR_NOMEM;
    }
#pragma omp parallel for schedule(static) if (n >= PARALLEL_MIN)
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

/* First index of sorted `pairs` (n) whose key is >= key. */
static size_t lower_bound(const struct wetdem_celllist_pair* pairs, size_t n, uint64_t key)
{
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (pair_key(pairs[mid]) < key)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

/* Chunks of the new list merged independently (a fixed count: the same work split for any
 * number of threads). */
#define REMAP_CHUNKS 64

size_t wetdem_celllist_remap(const struct wetdem_celllist_pair* old_pairs, const double* old_hist,
                             const unsigned char* old_flags, size_t n_old,
                             const struct wetdem_celllist_pair* new_pairs, double* new_hist,
                             unsigned char* new_flags, unsigned char keep, size_t n_new, size_t len,
                             const double* fresh)
{
    size_t kept = 0;
#pragma omp parallel for schedule(static) reduction(+ : kept) if (n_new >= 4096)
    for (size_t c = 0; c < REMAP_CHUNKS; c++) {
        size_t b0 = n_new * c / REMAP_CHUNKS, b1 = n_new * (c + 1) / REMAP_CHUNKS;
        if (b0 == b1)
            continue;
        size_t a = lower_bound(old_pairs, n_old, pair_key(new_pairs[b0]));
        for (size_t b = b0; b < b1; b++) { /* merge walk over both sorted lists */
            uint64_t key = pair_key(new_pairs[b]);
            while (a < n_old && pair_key(old_pairs[a]) < key)
                a++;
            bool found = a < n_old && pair_key(old_pairs[a]) == key;
            if (len)
                memcpy(new_hist + b * len, found ? old_hist + a * len : fresh,
                       len * sizeof(double));
            if (new_flags)
                new_flags[b] = found && old_flags ? old_flags[a] & keep : 0;
            kept += found;
        }
    }
    return kept;
}

size_t wetdem_celllist_remap_history(const struct wetdem_celllist_pair* old_pairs,
                                     const double* old_hist, size_t n_old,
                                     const struct wetdem_celllist_pair* new_pairs, double* new_hist,
                                     size_t n_new, size_t len, const double* fresh)
{
    return wetdem_celllist_remap(old_pairs, old_hist, NULL, n_old, new_pairs, new_hist, NULL, 0,
                                 n_new, len, fresh);
}

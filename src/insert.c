/*
 * insert.c — initial configurations of many spheres: a simple cubic lattice or random
 * sequential addition without overlap, polydisperse radii, Gaussian velocities; seeded with
 * gsl_rng mt19937 so that a spec always gives bit-identical particles. Prefix: wetdem_insert.
 *
 * Lattice: spacing a = 2 R_max + gap [m]. On a non-periodic axis of length L the sites are
 * lo + gap + R_max + k a, k = 0 .. floor((L - 2 gap - 2 R_max)/a); on a periodic axis there are
 * floor(L/a) sites spread evenly over L (spacing >= a across the wrap too). Sites are filled
 * x fastest, then y, then z (bottom layers first, as for settling).
 * Random: spheres are tried at uniform positions (centres >= R_i + gap from non-periodic faces)
 * in order of decreasing radius and accepted when |x_i - x_j| >= R_i + R_j + gap for every
 * accepted j and every sphere already in the simulation that can reach the region (minimum
 * image on the region's periodic axes). They are found with a grid of cells of edge at least
 * R_max + max(R_max, R of those spheres) + gap, merged pairwise along the finest axis while
 * there are more than INSERT_CELLS_PER_SPHERE cells per sphere, so that a sparse region costs
 * no more memory than a dense one. Random sequential addition of equal spheres jams near a
 * volume fraction of 0.38 (Widom 1966; Talbot et al. 2000), which bounds what the random
 * layout can reach; the trials per sphere grow near it, so it reports its progress
 * (spec->progress).
 */
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "insert.h"
#include "status.h"
#include "vec3.h"

#define DEFAULT_ATTEMPTS 10000
#define RSA_JAMMING 0.38 /* random sequential addition limit of equal spheres [-] */
#define INSERT_MAX_COUNT (SIZE_MAX / (2 * sizeof(struct wetdem_particle)))

static double axis(struct wetdem_vec3 v, int k)
{
    return k == 0 ? v.x : (k == 1 ? v.y : v.z);
}

static void set_axis(struct wetdem_vec3* v, int k, double x)
{
    *(k == 0 ? &v->x : (k == 1 ? &v->y : &v->z)) = x;
}

static int lattice_capacity(const struct wetdem_insert_spec* s, double r, const char* what,
                            char* msg, size_t n);

int wetdem_insert_check(const struct wetdem_insert_spec* s, char* msg, size_t n)
{
    if (s->layout != WETDEM_INSERT_LATTICE && s->layout != WETDEM_INSERT_RANDOM)
        return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID,
                                  "insert.layout must be lattice or random");
    if (s->n == 0)
        return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID, "insert.count must be >= 1, got 0");
    /* the spheres' arrays (particles, and the random layout's two doubles a sphere) must have a
       size that size_t holds: a larger count wrapped it to a small block */
    if (s->n > INSERT_MAX_COUNT)
        return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID,
                                  "insert.count = %zu is more than the %zu spheres an array can "
                                  "address",
                                  s->n, (size_t)INSERT_MAX_COUNT);
    for (int k = 0; k < 3; k++) {
        double lo = axis(s->lo, k), hi = axis(s->hi, k);
        if (!(isfinite(lo) && isfinite(hi) && hi > lo))
            return wetdem_status_fail(
                msg, n, WETDEM_ERR_INVALID,
                "insert region: %c range [%g, %g] m must be finite with hi > lo", "xyz"[k], lo, hi);
    }
    if (!s->radii && !(isfinite(s->radius_min) && s->radius_min > 0 && isfinite(s->radius_max) &&
                       s->radius_max >= s->radius_min))
        return wetdem_status_fail(
            msg, n, WETDEM_ERR_INVALID,
            "insert radii: need 0 < radius_min <= radius_max (finite), got [%g, %g] m",
            s->radius_min, s->radius_max);
    if (!(isfinite(s->gap) && s->gap >= 0))
        return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID,
                                  "insert.gap must be finite and >= 0 m, got %g", s->gap);
    if (!(isfinite(s->velocity_sigma) && s->velocity_sigma >= 0) || !vec3_is_finite(s->velocity))
        return wetdem_status_fail(
            msg, n, WETDEM_ERR_INVALID,
            "insert velocity: mean must be finite and sigma >= 0 m/s, got sigma %g",
            s->velocity_sigma);
    /* the least volume the spheres can fill [m^3] */
    double least = s->radii ? 0 : (double)s->n * 4.0 / 3.0 * M_PI * pow(s->radius_min, 3);
    for (size_t i = 0; s->radii && i < s->n; i++) {
        if (!(isfinite(s->radii[i]) && s->radii[i] > 0))
            return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID,
                                      "insert radii: radius %zu must be finite and > 0 m, got %g",
                                      i, s->radii[i]);
        least += 4.0 / 3.0 * M_PI * pow(s->radii[i], 3);
    }
    if (s->layout == WETDEM_INSERT_LATTICE) { /* the most sites the radii drawn can leave */
        double r = s->radius_min;
        for (size_t i = 0; s->radii && i < s->n; i++)
            r = i ? fmax(r, s->radii[i]) : s->radii[i];
        const char* what = s->radii ? "the largest radius given"
                           : s->radius_min == s->radius_max
                               ? "the largest radius drawn"
                               : "radius_min, the least the largest radius drawn can be";
        return lattice_capacity(s, r, what, msg, n);
    }
    double region = (s->hi.x - s->lo.x) * (s->hi.y - s->lo.y) * (s->hi.z - s->lo.z);
    if (least > region) /* before any memory is taken for the spheres */
        return wetdem_status_fail(
            msg, n, WETDEM_ERR_INVALID,
            "insert: count = %zu spheres fill at least %.3g m^3, %.3g times the region's "
            "%.3g m^3: reduce count or the radii, or enlarge the region",
            s->n, least, least / region, region);
    return WETDEM_OK;
}

/* Radii into out[i].radius; returns the largest. */
static double draw_radii(const struct wetdem_insert_spec* s, gsl_rng* rng,
                         struct wetdem_particle* out)
{
    double r_max = 0;
    for (size_t i = 0; i < s->n; i++) {
        double r = s->radii
                       ? s->radii[i]
                       : s->radius_min + (s->radius_max - s->radius_min) * gsl_rng_uniform(rng);
        out[i] = (struct wetdem_particle){.radius = r, .material = s->material};
        r_max = fmax(r_max, r);
    }
    return r_max;
}

/* Sites along axis k of the lattice: count, first site and spacing [m]. The count is capped
 * at n, which no row needs more than: it then fits a size_t however fine the lattice, and
 * the sites that are filled (and the spacing) are those of the whole row. */
static size_t lattice_axis(const struct wetdem_insert_spec* s, int k, double r_max, double* first,
                           double* step)
{
    double lo = axis(s->lo, k), len = axis(s->hi, k) - lo, a = 2 * r_max + s->gap, m;
    if (s->periodic[k]) {
        m = floor(len / a);
        *step = m > 0 ? len / m : 0;
        *first = lo + 0.5 * *step;
    } else {
        double room = len - 2 * s->gap - 2 * r_max;
        m = room < 0 ? 0 : floor(room / a) + 1;
        *first = lo + s->gap + r_max;
        *step = a;
    }
    return m < (double)s->n ? (size_t)m : s->n;
}

/* The first axis along which the region is narrower than one sphere of radius r with its gaps
 * (2 r + 2 gap; 2 r + gap across a periodic axis, which a lattice fills with whole spacings,
 * when `lattice`; a periodic axis has room for any sphere at random), or -1; *need is that
 * width [m]. */
static int narrow_axis(const struct wetdem_insert_spec* s, double r, bool lattice, double* need)
{
    for (int k = 0; k < 3; k++) {
        double len = axis(s->hi, k) - axis(s->lo, k);
        if (s->periodic[k] && !lattice)
            continue;
        *need = s->periodic[k] ? 2 * r + s->gap : 2 * r + 2 * s->gap;
        if (len < *need)
            return k;
    }
    return -1;
}

/* WETDEM_OK if the lattice for spheres of largest radius r has at least n sites; `what` says
 * what r is. */
static int lattice_capacity(const struct wetdem_insert_spec* s, double r, const char* what,
                            char* msg, size_t n)
{
    double first, step;
    size_t m[3];
    for (int k = 0; k < 3; k++)
        m[k] = lattice_axis(s, k, r, &first, &step);
    double sites = (double)m[0] * (double)m[1] * (double)m[2];
    if (sites >= (double)s->n)
        return WETDEM_OK;
    double need;
    int k = narrow_axis(s, r, true, &need);
    if (k >= 0)
        return wetdem_status_fail(
            msg, n, WETDEM_ERR_INVALID,
            "insert: the region is %g m across in %c, narrower than one sphere: 2 r + %s = %g m "
            "(r = %g m, %s; gap = %g m); enlarge the region in %c or reduce radius_max or gap",
            axis(s->hi, k) - axis(s->lo, k), "xyz"[k], s -> periodic[k] ? "gap" : "2 gap", need, r,
            what, s->gap, "xyz"[k]);
    return wetdem_status_fail(
        msg, n, WETDEM_ERR_INVALID,
        "insert: the region holds at most %.0f spheres (%zu x %zu x %zu) on a lattice of "
        "spacing 2 r + gap = %g m (r = %g m, %s), but count = %zu; enlarge the region or "
        "reduce count, radius_max or gap (%g m)",
        sites, m[0], m[1], m[2], 2 * r + s->gap, r, what, s->n, s->gap);
}

static int place_lattice(const struct wetdem_insert_spec* s, double r_max,
                         struct wetdem_particle* out, char* msg, size_t n)
{
    double first[3], step[3];
    size_t m[3];
    for (int k = 0; k < 3; k++)
        m[k] = lattice_axis(s, k, r_max, &first[k], &step[k]);
    int st = lattice_capacity(s, r_max, "the largest radius drawn", msg, n);
    if (st != WETDEM_OK)
        return st;
    for (size_t i = 0; i < s->n; i++) {
        size_t c[3] = {i % m[0], (i / m[0]) % m[1], i / m[0] / m[1]};
        for (int k = 0; k < 3; k++)
            set_axis(&out[i].pos, k, first[k] + (double)c[k] * step[k]);
    }
    return WETDEM_OK;
}

/* ---- random sequential addition on a grid ---- */

/* A sphere the random layout must keep clear of: one already in the simulation or one it
 * placed. */
struct ball {
    double x[3], r;
};

struct grid {
    int nc[3];
    double lo[3], cell[3], len[3];
    bool periodic[3];
    long* head;         /* first ball of each cell, -1 if none */
    long* next;         /* next ball of the same cell */
    struct ball* balls; /* the spheres binned so far */
    size_t n_balls;
};

static int cell_of(const struct grid* g, double x, int k)
{
    int c = (int)floor((x - g->lo[k]) / g->cell[k]);
    if (g->periodic[k])
        c = ((c % g->nc[k]) + g->nc[k]) % g->nc[k];
    return c < 0 ? 0 : (c >= g->nc[k] ? g->nc[k] - 1 : c);
}

static size_t grid_index(const struct grid* g, int cx, int cy, int cz)
{
    return ((size_t)cz * (size_t)g->nc[1] + (size_t)cy) * (size_t)g->nc[0] + (size_t)cx;
}

size_t wetdem_insert_grid_shape(const struct wetdem_insert_spec* s, size_t n_balls, double edge,
                                int nc[3])
{
    for (int k = 0; k < 3; k++) {
        double m = floor((axis(s->hi, k) - axis(s->lo, k)) / edge);
        nc[k] = m < 1 ? 1 : (m > 1024 ? 1024 : (int)m);
    }
    /* A sparse region (few spheres, large box) would otherwise get up to 1024^3 cells: 8 GB
     * of heads for ten spheres. Merging cells pairwise along the finest axis keeps every edge
     * >= `edge`, so the search stays exact and the positions do not depend on the grid. */
    double cap = INSERT_CELLS_PER_SPHERE * (double)n_balls + 27;
    while ((double)nc[0] * nc[1] * nc[2] > cap) {
        int k = nc[0] >= nc[1] && nc[0] >= nc[2] ? 0 : (nc[1] >= nc[2] ? 1 : 2);
        nc[k] /= 2;
    }
    return (size_t)nc[0] * (size_t)nc[1] * (size_t)nc[2];
}

static void grid_add(struct grid* g, struct ball b)
{
    size_t c = grid_index(g, cell_of(g, b.x[0], 0), cell_of(g, b.x[1], 1), cell_of(g, b.x[2], 2));
    g->balls[g->n_balls] = b;
    g->next[g->n_balls] = g->head[c];
    g->head[c] = (long)g->n_balls++;
}

/* Whether an existing sphere can reach a new one (radius <= r_max): on every axis on which the
 * region does not wrap, its centre lies within r + r_max + gap of the region. */
static bool can_reach(const struct wetdem_insert_spec* s, const struct wetdem_particle* q,
                      double r_max)
{
    double reach = q->radius + r_max + s->gap;
    for (int k = 0; k < 3; k++) {
        double x = axis(q->pos, k);
        if (!s->periodic[k] && (x < axis(s->lo, k) - reach || x > axis(s->hi, k) + reach))
            return false;
    }
    return true;
}

/* Grid over the region holding the existing spheres that can reach the new ones, with room
 * for those. A new sphere (<= r_max) meets a binned one (<= r_far) within r_max + r_far + gap:
 * the cells are at least that wide. */
static int grid_init(struct grid* g, const struct wetdem_insert_spec* s, double r_max,
                     const struct wetdem_particle* existing, size_t n_existing)
{
    size_t near = 0;
    double r_far = r_max;
    for (size_t q = 0; q < n_existing; q++)
        if (can_reach(s, &existing[q], r_max)) {
            near++;
            r_far = fmax(r_far, existing[q].radius);
        }
    size_t cells = wetdem_insert_grid_shape(s, s->n + near, r_max + r_far + s->gap, g->nc);
    for (int k = 0; k < 3; k++) {
        g->lo[k] = axis(s->lo, k);
        g->len[k] = axis(s->hi, k) - g->lo[k];
        g->periodic[k] = s->periodic[k];
        g->cell[k] = g->len[k] / g->nc[k];
    }
    g->head = malloc(cells * sizeof *g->head);
    g->next = malloc((s->n + near) * sizeof *g->next);
    g->balls = malloc((s->n + near) * sizeof *g->balls);
    if (!g->head || !g->next || !g->balls)
        return WETDEM_ERR_NOMEM;
    for (size_t c = 0; c < cells; c++)
        g->head[c] = -1;
    for (size_t q = 0; q < n_existing; q++)
        if (can_reach(s, &existing[q], r_max))
            grid_add(g, (struct ball){{existing[q].pos.x, existing[q].pos.y, existing[q].pos.z},
                                      existing[q].radius});
    return WETDEM_OK;
}

/* Distinct cells along axis k around cell c (periodic wrap; fewer than 3 cells de-duplicated). */
static int around(const struct grid* g, int c, int k, int out[3])
{
    int m = 0;
    for (int d = -1; d <= 1; d++) {
        int x = g->periodic[k] ? (c + d + g->nc[k]) % g->nc[k] : c + d;
        if (x < 0 || x >= g->nc[k] || (m > 0 && out[m - 1] == x) || (m == 2 && out[0] == x))
            continue;
        out[m++] = x;
    }
    return m;
}

static bool is_free(const struct grid* g, struct wetdem_vec3 x, double r, double gap)
{
    int ax[3][3], m[3];
    for (int k = 0; k < 3; k++)
        m[k] = around(g, cell_of(g, axis(x, k), k), k, ax[k]);
    for (int a = 0; a < m[2]; a++)
        for (int b = 0; b < m[1]; b++)
            for (int c = 0; c < m[0]; c++)
                for (long j = g->head[grid_index(g, ax[0][c], ax[1][b], ax[2][a])]; j >= 0;
                     j = g->next[j]) {
                    const struct ball* q = &g->balls[j];
                    double d[3], lim = r + q->r + gap;
                    for (int k = 0; k < 3; k++) {
                        d[k] = axis(x, k) - q->x[k];
                        if (g->periodic[k])
                            d[k] -= g->len[k] * nearbyint(d[k] / g->len[k]);
                    }
                    if (d[0] * d[0] + d[1] * d[1] + d[2] * d[2] < lim * lim)
                        return false;
                }
    return true;
}

/* Random position of a sphere of radius r; false if the region is too thin for it. */
static bool random_position(const struct wetdem_insert_spec* s, gsl_rng* rng, double r,
                            struct wetdem_vec3* x)
{
    for (int k = 0; k < 3; k++) {
        double lo = axis(s->lo, k), hi = axis(s->hi, k);
        if (!s->periodic[k]) {
            lo += r + s->gap;
            hi -= r + s->gap;
        }
        if (hi < lo)
            return false;
        set_axis(x, k, lo + (hi - lo) * gsl_rng_uniform(rng));
    }
    return true;
}

static int by_radius_desc(const void* a, const void* b)
{
    const double* x = a; /* (radius, index) pairs */
    const double* y = b;
    return x[0] != y[0] ? (x[0] < y[0] ? 1 : -1) : (x[1] > y[1]) - (x[1] < y[1]);
}

/* Volume fraction of the region that the new spheres and the binned existing ones whose
 * centres lie in it would fill [-]. */
static double requested_fraction(const struct wetdem_insert_spec* s, const struct grid* g,
                                 const struct wetdem_particle* out, size_t n_existing_binned)
{
    double solid = 0;
    for (size_t q = 0; q < s->n; q++)
        solid += 4.0 / 3.0 * M_PI * out[q].radius * out[q].radius * out[q].radius;
    for (size_t q = 0; q < n_existing_binned; q++) {
        const struct ball* b = &g->balls[q];
        bool inside = true;
        for (int k = 0; k < 3; k++)
            inside = inside && b->x[k] >= g->lo[k] && b->x[k] <= g->lo[k] + g->len[k];
        solid += inside ? 4.0 / 3.0 * M_PI * b->r * b->r * b->r : 0;
    }
    return solid / (g->len[0] * g->len[1] * g->len[2]);
}

static int place_one(const struct wetdem_insert_spec* s, gsl_rng* rng, struct grid* g,
                     struct wetdem_particle* out, size_t i, size_t placed, size_t n_existing_binned,
                     char* msg, size_t n)
{
    size_t attempts = s->max_attempts ? s->max_attempts : DEFAULT_ATTEMPTS;
    for (size_t t = 0; t < attempts; t++) {
        struct wetdem_vec3 x;
        if (!random_position(s, rng, out[i].radius, &x)) {
            double need = 0;
            int k = narrow_axis(s, out[i].radius, false, &need);
            if (k < 0) /* (rounding: the two tests may differ in the last bit) */
                return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID,
                                          "insert: sphere %zu of radius %g m plus gap %g m does "
                                          "not fit in the region",
                                          i, out[i].radius, s->gap);
            return wetdem_status_fail(
                msg, n, WETDEM_ERR_INVALID,
                "insert: sphere %zu of radius %g m plus gap %g m does not fit in the region: it "
                "is %g m across in %c, narrower than 2 r + 2 gap = %g m; enlarge the region in "
                "%c or reduce the radius or gap",
                i, out[i].radius, s->gap, axis(s->hi, k) - axis(s->lo, k), "xyz"[k], need,
                "xyz"[k]);
        }
        if (!is_free(g, x, out[i].radius, s->gap))
            continue;
        out[i].pos = x;
        grid_add(g, (struct ball){{x.x, x.y, x.z}, out[i].radius});
        return WETDEM_OK;
    }
    if (n_existing_binned)
        return wetdem_status_fail(
            msg, n, WETDEM_ERR_INVALID,
            "insert: placed %zu of %zu spheres (the largest first); the next, of radius %g m, "
            "found no free place in %zu random trials among them and the %zu spheres already "
            "there (volume fraction %.3f with them): insert the groups of larger spheres "
            "first (groups go in file order), or use a larger region or fewer spheres",
            placed, s->n, out[i].radius, attempts, n_existing_binned,
            requested_fraction(s, g, out, n_existing_binned));
    return wetdem_status_fail(
        msg, n, WETDEM_ERR_INVALID,
        "insert: placed %zu of %zu spheres (the largest first); the next, of radius %g m, "
        "found no free place in %zu random trials. The requested volume fraction %.3f is "
        "too close to the random-insertion limit (~%.2f): use layout = lattice, a larger "
        "region or fewer spheres",
        placed, s->n, out[i].radius, attempts, requested_fraction(s, g, out, 0), RSA_JAMMING);
}

static int place_random(const struct wetdem_insert_spec* s, gsl_rng* rng, double r_max,
                        const struct wetdem_particle* existing, size_t n_existing,
                        struct wetdem_particle* out, char* msg, size_t n)
{
    for (int k = 0; k < 3; k++)
        if (s->periodic[k] && axis(s->hi, k) - axis(s->lo, k) < 2 * r_max + s->gap)
            return wetdem_status_fail(
                msg, n, WETDEM_ERR_INVALID,
                "insert: periodic length along %c (%g m) is below 2 radius_max + gap "
                "= %g m: a sphere would touch its own image",
                "xyz"[k], axis(s->hi, k) - axis(s->lo, k), 2 * r_max + s->gap);
    struct grid g = {0};
    double* order = malloc(2 * s->n * sizeof *order);
    int st = order ? grid_init(&g, s, r_max, existing, n_existing) : WETDEM_ERR_NOMEM;
    size_t binned = g.n_balls;
    if (st != WETDEM_OK) {
        st = wetdem_status_fail(msg, n, WETDEM_ERR_NOMEM, "insert: out of memory for %zu spheres",
                                s->n);
    } else {
        for (size_t i = 0; i < s->n; i++) {
            order[2 * i] = out[i].radius;
            order[2 * i + 1] = (double)i;
        }
        qsort(order, s->n, 2 * sizeof *order, by_radius_desc);
        double t0 = omp_get_wtime();
        for (size_t q = 0; q < s->n && st == WETDEM_OK; q++) {
            st = place_one(s, rng, &g, out, (size_t)order[2 * q + 1], q, binned, msg, n);
            size_t done = q + 1;
            bool due = done % WETDEM_INSERT_PROGRESS_EVERY == 0 || done == s->n;
            if (st == WETDEM_OK && s->progress && due &&
                s->progress(done, s->n, omp_get_wtime() - t0, s->progress_ctx) != 0)
                st = wetdem_status_fail(msg, n, WETDEM_EVENT,
                                        "insert: stopped after %zu of %zu spheres", done, s->n);
        }
    }
    free(order);
    free(g.head);
    free(g.next);
    free(g.balls);
    return st;
}

int wetdem_insert_particles(const struct wetdem_insert_spec* spec, struct wetdem_particle* out,
                            char* msg, size_t msg_size)
{
    int st = wetdem_insert_check(spec, msg, msg_size);
    return st != WETDEM_OK ? st : wetdem_insert_particles_among(spec, NULL, 0, out, msg, msg_size);
}

int wetdem_insert_particles_among(const struct wetdem_insert_spec* spec,
                                  const struct wetdem_particle* existing, size_t n_existing,
                                  struct wetdem_particle* out, char* msg, size_t msg_size)
{
    /* the generator in memory of our own: gsl_rng_alloc calls GSL's error handler, whose
       default aborts, when out of memory */
    gsl_rng gen = {gsl_rng_mt19937, calloc(1, gsl_rng_mt19937->size)}, *rng = &gen;
    if (!gen.state)
        return wetdem_status_fail(msg, msg_size, WETDEM_ERR_NOMEM, "insert: out of memory");
    gsl_rng_set(rng, spec->seed);
    double r_max = draw_radii(spec, rng, out);
    int st = spec->layout == WETDEM_INSERT_LATTICE
                 ? place_lattice(spec, r_max, out, msg, msg_size)
                 : place_random(spec, rng, r_max, existing, n_existing, out, msg, msg_size);
    for (size_t i = 0; st == WETDEM_OK && i < spec->n; i++) {
        /* one statement a draw: as arguments of one call their order was the compiler's (GCC
           drew z first, clang x), and a seed gave other velocities with clang; z, y, x keeps
           the spheres that earlier builds gave */
        double sd = spec->velocity_sigma;
        double dz = gsl_ran_gaussian_ziggurat(rng, sd);
        double dy = gsl_ran_gaussian_ziggurat(rng, sd);
        double dx = gsl_ran_gaussian_ziggurat(rng, sd);
        out[i].vel = vec3(spec->velocity.x + dx, spec->velocity.y + dy, spec->velocity.z + dz);
    }
    free(gen.state);
    return st;
}

/*
 * bridge_floor.c — the floor of the wet models' cost in bench/20-many.sh: the bare loop over
 * the liquid bridges apart of a benchmark state, with nothing of an engine around it.
 *
 * For every pair apart within the films of a state written by many_bench --state-out
 * (0 <= gap < delta, delta = 40 um: the two 20 um films of the benchmark's material), each
 * step computes what wetdem's wet variant adds for such a pair and nothing else: the distance,
 * the unit normal n (j to i), the normal velocity v_n = -(v_i - v_j) . n, R* = R_i R_j /
 * (R_i + R_j), the thin-film force of sb (force_sb.c; Punch 2023 Eq. 7 with the corrected
 * bracket, SPEC section 6)
 *   F_sb = 6 pi mu R*^2 v_n / h [1 - h/delta]^2 for h = gap >= h_min' (1 um, the default
 *   minimum separation), else 0,
 * the capillary force (force_capillary.c; Punch 2023 Eq. 15) F_cap = -8 pi R* sigma, and adds
 * (F_sb + F_cap) n to i and subtracts it from j. The positions and velocities stay those of the
 * state. Not kept, unlike wetdem: the pair list from the cell list and its gap test, the pairs
 * beyond the films and those in contact, each pair's flags (the bridge counts), the order of the
 * sums that makes results independent of the thread count, the walls, the film terms of the
 * contacts. Any engine pays at least this for the bridges apart, so on top of the dry run it
 * bounds the wet / dry cost from below.
 *
 * Three versions of the loop, the same operations in the same order: one pair at a time; four
 * pairs at a time in vector units from the 32-byte records (AVX2 where the processor has it, as
 * wetdem's kernel); and eight pairs at a time from arrays by component (x[], y[], ... of all
 * spheres) with the AVX-512 gather instructions, where the processor has AVX-512F: the other
 * layout a redesign would choose, measured on the same pairs. A version the processor lacks is
 * not run. Their force sums must agree bit for bit, or the program fails.
 *
 * Usage: bridge_floor --state-in FILE [--steps S] [--repeat R]
 *                     [--kernel scalar|vector|gather|both|all]   (both: scalar and vector)
 * Prints one line: "floor n=.. bridges_apart=.. steps=.. scalar_ns=.. vector_ns=.. gather_ns=.."
 * (ns per bridge-step, best of R rounds of S steps; 0 for a version not run).
 */
#include <math.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

/* the wet variant of bench/many_bench.c (change them together) */
#define FILM 40e-6     /* delta of a pair [m]: 2 x 20 um */
#define H_MIN 1e-6     /* h_min' [m] */
#define VISCOSITY 0.01 /* [Pa s] */
#define TENSION 0.02   /* [N/m] */
#define MAX_ATOMS 10000000

struct sphere { /* one 32-byte record, as wetdem's position records */
    double x, y, z, r;
};
struct motion { /* velocity and spin, as wetdem's */
    double vx, vy, vz, wx, wy, wz;
};
struct state {
    size_t n;
    struct sphere* s;
    struct motion* v;
    double* comp[7]; /* by component, for the gather version: x, y, z, r, vx, vy, vz */
};
struct bridges {
    size_t n;
    uint32_t *i, *j; /* i < j, in (i, j) order */
};

static double now(void)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static void fail(const char* what, const char* path)
{
    fprintf(stderr, "bridge_floor: %s%s%s\n", what, path ? ": " : "", path ? path : "");
    exit(1);
}

/* The atoms and velocities of a data file written by many_bench (ids 1..n). */
static struct state read_state(const char* path)
{
    FILE* f = fopen(path, "r");
    if (!f)
        fail("cannot read", path);
    char line[512];
    size_t n = 0, seen = 0;
    int section = 0; /* 1 atoms, 2 velocities */
    struct state st = {0};
    while (fgets(line, sizeof line, f)) {
        size_t id;
        double a[6];
        if (sscanf(line, "%zu atoms", &id) == 1 && !st.s) {
            if (id < 1 || id > MAX_ATOMS)
                fail("atom count out of range", path);
            n = id;
            st.s = calloc(n, sizeof *st.s);
            st.v = calloc(n, sizeof *st.v);
            if (!st.s || !st.v)
                fail("out of memory", NULL);
        } else if (!strncmp(line, "Atoms", 5))
            section = 1;
        else if (!strncmp(line, "Velocities", 10))
            section = 2;
        else if (section == 1 && st.s &&
                 sscanf(line, "%zu %*d %lf %*f %lf %lf %lf", &id, &a[0], &a[1], &a[2], &a[3]) ==
                     5 &&
                 id >= 1 && id <= n) {
            st.s[id - 1] = (struct sphere){a[1], a[2], a[3], 0.5 * a[0]};
            seen++;
        } else if (section == 2 && st.v &&
                   sscanf(line, "%zu %lf %lf %lf %lf %lf %lf", &id, &a[0], &a[1], &a[2], &a[3],
                          &a[4], &a[5]) == 7 &&
                   id >= 1 && id <= n)
            st.v[id - 1] = (struct motion){a[0], a[1], a[2], a[3], a[4], a[5]};
    }
    fclose(f);
    if (!n || seen != n)
        fail("not a complete many_bench data file", path);
    st.n = n;
    return st;
}

static double gap_of(const struct state* st, size_t i, size_t j)
{
    const struct sphere *a = &st->s[i], *b = &st->s[j];
    double dx = a->x - b->x, dy = a->y - b->y, dz = a->z - b->z;
    return sqrt(dx * dx + dy * dy + dz * dz) - a->r - b->r;
}

/* The cell grid of find_bridges: particles item[start[c] .. start[c + 1]) in cell c of
 * dim[0] x dim[1] x dim[2] cells of side h from lo. */
struct grid {
    double lo[3], h;
    size_t dim[3];
    size_t *start, *item, *cell; /* cell: each particle's */
};

/* Appends to mine[*m] the partners j > i of particle i apart within the films in cell (x, y, z),
 * if it is in the grid. */
static void partners_in_cell(const struct state* st, const struct grid* g, size_t i, long x, long y,
                             long z, uint32_t* mine, size_t* m)
{
    if (x < 0 || y < 0 || z < 0 || x >= (long)g->dim[0] || y >= (long)g->dim[1] ||
        z >= (long)g->dim[2])
        return;
    size_t d = ((size_t)z * g->dim[1] + (size_t)y) * g->dim[0] + (size_t)x;
    for (size_t t = g->start[d]; t < g->start[d + 1]; t++) {
        size_t j = g->item[t];
        if (j <= i)
            continue;
        double gap = gap_of(st, i, j);
        if (gap >= 0 && gap < FILM)
            mine[(*m)++] = (uint32_t)j;
    }
}

static int by_index(const void* a, const void* b)
{
    uint32_t x = *(const uint32_t*)a, y = *(const uint32_t*)b;
    return (x > y) - (x < y);
}

/* The pairs apart within the films, (i, j) order: for each particle i, the partners j > i in
 * its cell and the 26 around it (cells of the largest diameter plus the film), sorted. */
static struct bridges find_bridges(const struct state* st)
{
    struct grid g = {.lo = {INFINITY, INFINITY, INFINITY}};
    double hi[3] = {-INFINITY, -INFINITY, -INFINITY}, r_max = 0;
    for (size_t k = 0; k < st->n; k++) {
        double p[3] = {st->s[k].x, st->s[k].y, st->s[k].z};
        for (int c = 0; c < 3; c++) {
            g.lo[c] = p[c] < g.lo[c] ? p[c] : g.lo[c];
            hi[c] = p[c] > hi[c] ? p[c] : hi[c];
        }
        r_max = st->s[k].r > r_max ? st->s[k].r : r_max;
    }
    g.h = 2 * r_max + FILM;
    size_t cells = 1;
    for (int c = 0; c < 3; c++) {
        g.dim[c] = (size_t)((hi[c] - g.lo[c]) / g.h) + 1;
        cells *= g.dim[c];
    }
    g.start = calloc(cells + 1, sizeof *g.start);
    g.item = malloc(st->n * sizeof *g.item);
    g.cell = malloc(st->n * sizeof *g.cell);
    size_t* fill = malloc(cells * sizeof *fill);
    if (!g.start || !g.item || !g.cell || !fill)
        fail("out of memory", NULL);
    for (size_t k = 0; k < st->n; k++) { /* counting sort of the particles into cells */
        double p[3] = {st->s[k].x, st->s[k].y, st->s[k].z};
        size_t c[3];
        for (int a = 0; a < 3; a++) {
            c[a] = (size_t)((p[a] - g.lo[a]) / g.h);
            c[a] = c[a] < g.dim[a] ? c[a] : g.dim[a] - 1;
        }
        g.cell[k] = (c[2] * g.dim[1] + c[1]) * g.dim[0] + c[0];
        g.start[g.cell[k] + 1]++;
    }
    for (size_t c = 0; c < cells; c++)
        g.start[c + 1] += g.start[c];
    memcpy(fill, g.start, cells * sizeof *fill);
    for (size_t k = 0; k < st->n; k++)
        g.item[fill[g.cell[k]]++] = k;
    size_t cap = 16 * st->n, count = 0;
    struct bridges b = {0, malloc(cap * sizeof *b.i), malloc(cap * sizeof *b.j)};
    uint32_t* mine = malloc(st->n * sizeof *mine);
    if (!b.i || !b.j || !mine)
        fail("out of memory", NULL);
    for (size_t i = 0; i < st->n; i++) {
        size_t m = 0, c = g.cell[i];
        long x = (long)(c % g.dim[0]), y = (long)(c / g.dim[0] % g.dim[1]),
             z = (long)(c / (g.dim[0] * g.dim[1]));
        for (int a = 0; a < 27; a++)
            partners_in_cell(st, &g, i, x + a % 3 - 1, y + a / 3 % 3 - 1, z + a / 9 - 1, mine, &m);
        qsort(mine, m, sizeof *mine, by_index);
        for (size_t a = 0; a < m; a++) {
            if (count == cap)
                fail("more bridges than 16 per particle", NULL);
            b.i[count] = (uint32_t)i;
            b.j[count++] = mine[a];
        }
    }
    b.n = count;
    free(g.start);
    free(g.item);
    free(g.cell);
    free(fill);
    free(mine);
    return b;
}

/* One step, one pair at a time: force[k] gets the bridges' sum (3 doubles per particle). */
static void step_scalar(const struct state* st, const struct bridges* b, double (*force)[3])
{
    const double sb = 6.0 * M_PI * VISCOSITY, cap = 8.0 * M_PI;
    for (size_t q = 0; q < b->n; q++) {
        size_t i = b->i[q], j = b->j[q];
        const struct sphere *a = &st->s[i], *c = &st->s[j];
        const struct motion *va = &st->v[i], *vc = &st->v[j];
        double dx = a->x - c->x, dy = a->y - c->y, dz = a->z - c->z;
        double dist = sqrt(dx * dx + dy * dy + dz * dz), inv = 1.0 / dist;
        double nx = dx * inv, ny = dy * inv, nz = dz * inv;
        double gap = dist - a->r - c->r, r_eff = a->r * c->r / (a->r + c->r);
        double v_n = -((va->vx - vc->vx) * nx + (va->vy - vc->vy) * ny + (va->vz - vc->vz) * nz);
        double bracket = 1.0 - gap / FILM;
        double f_sb = gap >= H_MIN ? sb * r_eff * r_eff * v_n / gap * bracket * bracket : 0.0;
        double f_n = f_sb + -(cap * r_eff * TENSION);
        double fx = f_n * nx, fy = f_n * ny, fz = f_n * nz;
        force[i][0] += fx;
        force[i][1] += fy;
        force[i][2] += fz;
        force[j][0] -= fx;
        force[j][1] -= fy;
        force[j][2] -= fz;
    }
}

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define FLOOR_VECTOR 1
#include <immintrin.h>
typedef double v4d __attribute__((vector_size(32)));
typedef long long v4i __attribute__((vector_size(32)));

/* Lane by lane, the forces fx, fy, fz of `lanes` pairs (I[l], J[l]) onto both spheres, in pair
 * order as step_scalar adds them (inlined with a constant lane count, so unrolled). */
static inline void add_lanes(double (*force)[3], const uint32_t* I, const uint32_t* J,
                             const double* fx, const double* fy, const double* fz, int lanes)
{
#pragma GCC unroll 8
    for (int l = 0; l < lanes; l++) {
        double *a = force[I[l]], *c = force[J[l]];
        a[0] += fx[l];
        a[1] += fy[l];
        a[2] += fz[l];
        c[0] -= fx[l];
        c[1] -= fy[l];
        c[2] -= fz[l];
    }
}

/* The first four doubles at p0..p3 as columns: c[k] lane l = p_l[k] (two unpacks and two
 * lane permutes per pair of columns, as wetdem's kernel reads its records). */
__attribute__((target("avx2"))) static inline void
columns(const double* p0, const double* p1, const double* p2, const double* p3, v4d c[4])
{
    __m256d a0 = _mm256_loadu_pd(p0), a1 = _mm256_loadu_pd(p1), a2 = _mm256_loadu_pd(p2),
            a3 = _mm256_loadu_pd(p3);
    __m256d t0 = _mm256_unpacklo_pd(a0, a1), t1 = _mm256_unpackhi_pd(a0, a1);
    __m256d t2 = _mm256_unpacklo_pd(a2, a3), t3 = _mm256_unpackhi_pd(a2, a3);
    c[0] = (v4d)_mm256_permute2f128_pd(t0, t2, 0x20);
    c[1] = (v4d)_mm256_permute2f128_pd(t1, t3, 0x20);
    c[2] = (v4d)_mm256_permute2f128_pd(t0, t2, 0x31);
    c[3] = (v4d)_mm256_permute2f128_pd(t1, t3, 0x31);
}

/* The same, four pairs at a time (the pairs past the last multiple of four one at a time). */
__attribute__((target("avx2"))) static void step_vector(const struct state* st,
                                                        const struct bridges* b, double (*force)[3])
{
    const v4d sb = {6.0 * M_PI * VISCOSITY, 6.0 * M_PI * VISCOSITY, 6.0 * M_PI * VISCOSITY,
                    6.0 * M_PI * VISCOSITY},
              cap = {8.0 * M_PI, 8.0 * M_PI, 8.0 * M_PI, 8.0 * M_PI},
              tension = {TENSION, TENSION, TENSION, TENSION}, film = {FILM, FILM, FILM, FILM},
              h_min = {H_MIN, H_MIN, H_MIN, H_MIN}, one = {1, 1, 1, 1}, zero = {0, 0, 0, 0};
    size_t q = 0;
    for (; q + 4 <= b->n; q += 4) {
        const uint32_t *I = b->i + q, *J = b->j + q;
        v4d p[2][4], v[2][4];
        for (int s = 0; s < 2; s++) { /* s = 0: the first particles, 1: the second */
            const uint32_t* K = s ? J : I;
            columns(&st->s[K[0]].x, &st->s[K[1]].x, &st->s[K[2]].x, &st->s[K[3]].x, p[s]);
            columns(&st->v[K[0]].vx, &st->v[K[1]].vx, &st->v[K[2]].vx, &st->v[K[3]].vx, v[s]);
        }
        v4d dx = p[0][0] - p[1][0], dy = p[0][1] - p[1][1], dz = p[0][2] - p[1][2];
        v4d dist = dx * dx + dy * dy + dz * dz;
        dist = (v4d)_mm256_sqrt_pd((__m256d)dist);
        v4d inv = one / dist, nx = dx * inv, ny = dy * inv, nz = dz * inv;
        v4d gap = dist - p[0][3] - p[1][3], r_eff = p[0][3] * p[1][3] / (p[0][3] + p[1][3]);
        v4d v_n = -((v[0][0] - v[1][0]) * nx + (v[0][1] - v[1][1]) * ny + (v[0][2] - v[1][2]) * nz);
        v4d bracket = one - gap / film;
        v4d f_sb = sb * r_eff * r_eff * v_n / gap * bracket * bracket;
        v4i acts = gap >= h_min;
        f_sb = (v4d)(((v4i)f_sb & acts) | ((v4i)zero & ~acts));
        v4d f_n = f_sb + -(cap * r_eff * tension);
        double f[3][4] __attribute__((aligned(32))); /* (stored, then read lane by lane) */
        *(v4d*)f[0] = f_n * nx;
        *(v4d*)f[1] = f_n * ny;
        *(v4d*)f[2] = f_n * nz;
        add_lanes(force, I, J, f[0], f[1], f[2], 4);
    }
    struct bridges rest = {b->n - q, b->i + q, b->j + q};
    step_scalar(st, &rest, force);
}

/* The same, eight pairs at a time from the arrays by component with AVX-512 gathers (fourteen
 * gathers of eight doubles for eight pairs; the pairs past the last multiple of eight one at a
 * time). */
__attribute__((target("avx512f"))) static void
step_gather(const struct state* st, const struct bridges* b, double (*force)[3])
{
    const __m512d sb = _mm512_set1_pd(6.0 * M_PI * VISCOSITY), cap = _mm512_set1_pd(8.0 * M_PI),
                  tension = _mm512_set1_pd(TENSION), film = _mm512_set1_pd(FILM),
                  h_min = _mm512_set1_pd(H_MIN), one = _mm512_set1_pd(1.0),
                  minus = _mm512_set1_pd(-1.0);
    size_t q = 0;
    for (; q + 8 <= b->n; q += 8) {
        __m256i ij[2] = {_mm256_loadu_si256((const __m256i*)(const void*)(b->i + q)),
                         _mm256_loadu_si256((const __m256i*)(const void*)(b->j + q))};
        __m512d c[2][7]; /* c[s][k]: component k of the first (s = 0) or second particles */
        for (int t = 0; t < 2; t++)
            for (int k = 0; k < 7; k++)
                c[t][k] = _mm512_i32gather_pd(ij[t], st->comp[k], 8);
        __m512d dx = _mm512_sub_pd(c[0][0], c[1][0]), dy = _mm512_sub_pd(c[0][1], c[1][1]),
                dz = _mm512_sub_pd(c[0][2], c[1][2]);
        __m512d dist = _mm512_sqrt_pd(_mm512_add_pd(
            _mm512_add_pd(_mm512_mul_pd(dx, dx), _mm512_mul_pd(dy, dy)), _mm512_mul_pd(dz, dz)));
        __m512d inv = _mm512_div_pd(one, dist), nx = _mm512_mul_pd(dx, inv),
                ny = _mm512_mul_pd(dy, inv), nz = _mm512_mul_pd(dz, inv);
        __m512d ri = c[0][3], rj = c[1][3];
        __m512d gap = _mm512_sub_pd(_mm512_sub_pd(dist, ri), rj),
                r_eff = _mm512_div_pd(_mm512_mul_pd(ri, rj), _mm512_add_pd(ri, rj));
        __m512d v_n = _mm512_mul_pd(
            minus, _mm512_add_pd(_mm512_add_pd(_mm512_mul_pd(_mm512_sub_pd(c[0][4], c[1][4]), nx),
                                               _mm512_mul_pd(_mm512_sub_pd(c[0][5], c[1][5]), ny)),
                                 _mm512_mul_pd(_mm512_sub_pd(c[0][6], c[1][6]), nz)));
        __m512d bracket = _mm512_sub_pd(one, _mm512_div_pd(gap, film));
        __m512d f_sb = _mm512_mul_pd(
            _mm512_mul_pd(
                _mm512_div_pd(_mm512_mul_pd(_mm512_mul_pd(_mm512_mul_pd(sb, r_eff), r_eff), v_n),
                              gap),
                bracket),
            bracket);
        f_sb = _mm512_maskz_mov_pd(_mm512_cmp_pd_mask(gap, h_min, _CMP_GE_OQ), f_sb);
        __m512d f_n = _mm512_add_pd(
            f_sb, _mm512_mul_pd(minus, _mm512_mul_pd(_mm512_mul_pd(cap, r_eff), tension)));
        double f[3][8] __attribute__((aligned(64))); /* (stored, then read lane by lane) */
        _mm512_store_pd(f[0], _mm512_mul_pd(f_n, nx));
        _mm512_store_pd(f[1], _mm512_mul_pd(f_n, ny));
        _mm512_store_pd(f[2], _mm512_mul_pd(f_n, nz));
        add_lanes(force, b->i + q, b->j + q, f[0], f[1], f[2], 8);
    }
    struct bridges rest = {b->n - q, b->i + q, b->j + q};
    step_scalar(st, &rest, force);
}
#endif

/* Best ns per bridge-step of `rounds` rounds of `steps` steps of one version; the sums of its
 * last round into force. */
static double timed(void (*step)(const struct state*, const struct bridges*, double (*)[3]),
                    const struct state* st, const struct bridges* b, int steps, int rounds,
                    double (*force)[3])
{
    double best = INFINITY;
    for (int r = 0; r < rounds; r++) {
        memset(force, 0, st->n * sizeof *force);
        double t0 = now();
        for (int s = 0; s < steps; s++)
            step(st, b, force);
        double t = now() - t0;
        best = t < best ? t : best;
    }
    return b->n && steps ? 1e9 * best / ((double)steps * (double)b->n) : 0.0;
}

int main(int argc, char** argv)
{
    const char *path = NULL, *kernel = "all";
    int steps = 300, rounds = 5;
    for (int k = 1; k < argc; k++) {
        if (!strcmp(argv[k], "--state-in") && k + 1 < argc)
            path = argv[++k];
        else if (!strcmp(argv[k], "--steps") && k + 1 < argc)
            steps = atoi(argv[++k]);
        else if (!strcmp(argv[k], "--repeat") && k + 1 < argc)
            rounds = atoi(argv[++k]);
        else if (!strcmp(argv[k], "--kernel") && k + 1 < argc)
            kernel = argv[++k];
        else {
            fprintf(stderr, "usage: bridge_floor --state-in FILE [--steps S] [--repeat R] "
                            "[--kernel scalar|vector|gather|both|all]\n");
            return 2;
        }
    }
    bool all = !strcmp(kernel, "all"), both = !strcmp(kernel, "both");
    bool scalar = all || both || !strcmp(kernel, "scalar"),
         vector = all || both || !strcmp(kernel, "vector"),
         gather = all || !strcmp(kernel, "gather");
    if (!path || steps < 0 || rounds < 1 || (!scalar && !vector && !gather)) {
        fprintf(stderr, "bridge_floor: --state-in FILE is needed; --steps >= 0, --repeat >= 1, "
                        "--kernel scalar, vector, gather, both or all\n");
        return 2;
    }
    struct state st = read_state(path);
    struct bridges b = find_bridges(&st);
    double(*f_scalar)[3] = calloc(st.n, sizeof *f_scalar),
    (*f_vector)[3] = calloc(st.n, sizeof *f_vector);
    if (!f_scalar || !f_vector)
        fail("out of memory", NULL);
    double ns_scalar = scalar ? timed(step_scalar, &st, &b, steps, rounds, f_scalar) : 0.0;
    double ns_vector = 0.0, ns_gather = 0.0;
#ifdef FLOOR_VECTOR
    if (vector && __builtin_cpu_supports("avx2")) {
        ns_vector = timed(step_vector, &st, &b, steps, rounds, f_vector);
        if (scalar && memcmp(f_scalar, f_vector, st.n * sizeof *f_scalar))
            fail("the scalar and vector versions' sums differ", NULL);
    }
    if (gather && __builtin_cpu_supports("avx512f")) {
        for (int k = 0; k < 7; k++) {
            st.comp[k] = malloc(st.n * sizeof *st.comp[k]);
            if (!st.comp[k])
                fail("out of memory", NULL);
        }
        for (size_t k = 0; k < st.n; k++) {
            const double c[7] = {st.s[k].x,  st.s[k].y,  st.s[k].z, st.s[k].r,
                                 st.v[k].vx, st.v[k].vy, st.v[k].vz};
            for (int a = 0; a < 7; a++)
                st.comp[a][k] = c[a];
        }
        double(*f_gather)[3] = calloc(st.n, sizeof *f_gather);
        if (!f_gather)
            fail("out of memory", NULL);
        ns_gather = timed(step_gather, &st, &b, steps, rounds, f_gather);
        if ((scalar && memcmp(f_scalar, f_gather, st.n * sizeof *f_scalar)) ||
            (vector && ns_vector > 0 && memcmp(f_vector, f_gather, st.n * sizeof *f_vector)))
            fail("the gather version's sums differ from the others'", NULL);
        free(f_gather);
        for (int k = 0; k < 7; k++)
            free(st.comp[k]);
    }
#endif
    printf("floor n=%zu bridges_apart=%zu steps=%d scalar_ns=%.2f vector_ns=%.2f gather_ns=%.2f\n",
           st.n, b.n, steps, ns_scalar, ns_vector, ns_gather);
    free(f_scalar);
    free(f_vector);
    free(b.i);
    free(b.j);
    free(st.s);
    free(st.v);
    return 0;
}

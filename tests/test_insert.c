/*
 * test_insert.c — initial configurations (src/insert.c): reproducibility from the seed, no
 * overlap (brute force, minimum image on periodic axes), spheres inside the region, lattice
 * capacity by hand arithmetic, radius and velocity statistics, the order of the draws (so
 * that a seed gives the same spheres whatever the compiler), clear errors.
 */
#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>
#include <stdlib.h>

#include "harness.h"
#include "insert.h"
#include "vec3.h"

static struct wetdem_insert_spec base_spec(enum wetdem_insert_layout layout, size_t n)
{
    return (struct wetdem_insert_spec){
        .layout = layout,
        .n = n,
        .lo = {0, 0, 0},
        .hi = {20e-3, 20e-3, 20e-3},
        .radius_min = 0.5e-3,
        .radius_max = 1.0e-3,
        .gap = 0.05e-3,
        .velocity_sigma = 0.1,
        .seed = 42,
    };
}

/* Gap of spheres a and b minus the required gap (>= 0: clear), minimum image on the axes
 * periodic in s [m]. */
static double gap_excess(const struct wetdem_insert_spec* s, const struct wetdem_particle* a,
                         const struct wetdem_particle* b)
{
    double len[3] = {s->hi.x - s->lo.x, s->hi.y - s->lo.y, s->hi.z - s->lo.z};
    double d[3] = {a->pos.x - b->pos.x, a->pos.y - b->pos.y, a->pos.z - b->pos.z};
    for (int k = 0; k < 3; k++)
        if (s->periodic[k])
            d[k] -= len[k] * round(d[k] / len[k]);
    return sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) - a->radius - b->radius - s->gap;
}

/* Smallest gap over all pairs minus the required gap (>= 0 when nothing overlaps) [m]. */
static double worst_gap_excess(const struct wetdem_insert_spec* s, const struct wetdem_particle* p)
{
    double worst = INFINITY;
    for (size_t i = 0; i < s->n; i++)
        for (size_t j = i + 1; j < s->n; j++)
            worst = fmin(worst, gap_excess(s, &p[i], &p[j]));
    return worst;
}

static void check_inside(const struct wetdem_insert_spec* s, const struct wetdem_particle* p)
{
    for (size_t i = 0; i < s->n; i++) {
        double x[3] = {p[i].pos.x, p[i].pos.y, p[i].pos.z};
        double lo[3] = {s->lo.x, s->lo.y, s->lo.z}, hi[3] = {s->hi.x, s->hi.y, s->hi.z};
        for (int k = 0; k < 3; k++) {
            double margin = s->periodic[k] ? 0 : p[i].radius + s->gap;
            /* 1e-15 m: rounding of lo + k a on a 20 mm region */
            assert_true(x[k] >= lo[k] + margin - 1e-15 && x[k] <= hi[k] - margin + 1e-15);
        }
        assert_true(p[i].radius >= s->radius_min && p[i].radius <= s->radius_max);
    }
}

static void test_insert_same_seed_gives_identical_particles(void** state)
{
    (void)state;
    struct wetdem_insert_spec s = base_spec(WETDEM_INSERT_RANDOM, 300);
    struct wetdem_particle a[300], b[300], c[300];
    CHECK_OK(wetdem_insert_particles(&s, a, NULL, 0));
    CHECK_OK(wetdem_insert_particles(&s, b, NULL, 0));
    assert_memory_equal(a, b, sizeof a);
    s.seed = 43;
    CHECK_OK(wetdem_insert_particles(&s, c, NULL, 0));
    assert_memory_not_equal(a, c, sizeof a);
}

/* The draws of a lattice spec, redone here from the seed with GSL: the radii in sphere order,
 * then each sphere's velocity, z, y and x. Bit for bit: as the arguments of one call, the
 * three velocity draws came in the compiler's order, and a clang build gave other velocities
 * than a GCC build for the same seed (x and z exchanged). */
static void test_insert_draws_in_a_stated_order(void** state)
{
    (void)state;
    struct wetdem_insert_spec s = base_spec(WETDEM_INSERT_LATTICE, 5);
    s.velocity = (struct wetdem_vec3){0.5, -0.25, 1};
    struct wetdem_particle p[5];
    CHECK_OK(wetdem_insert_particles(&s, p, NULL, 0));
    gsl_rng* rng = gsl_rng_alloc(gsl_rng_mt19937);
    assert_non_null(rng);
    gsl_rng_set(rng, s.seed);
    for (size_t i = 0; i < s.n; i++)
        CHECK_ABS(p[i].radius, s.radius_min + (s.radius_max - s.radius_min) * gsl_rng_uniform(rng),
                  0);
    for (size_t i = 0; i < s.n; i++) {
        double dz = gsl_ran_gaussian_ziggurat(rng, s.velocity_sigma);
        double dy = gsl_ran_gaussian_ziggurat(rng, s.velocity_sigma);
        double dx = gsl_ran_gaussian_ziggurat(rng, s.velocity_sigma);
        CHECK_ABS(p[i].vel.x, s.velocity.x + dx, 0);
        CHECK_ABS(p[i].vel.y, s.velocity.y + dy, 0);
        CHECK_ABS(p[i].vel.z, s.velocity.z + dz, 0);
    }
    gsl_rng_free(rng);
}

static void test_insert_random_has_no_overlap(void** state)
{
    (void)state;
    /* 1500 spheres of mean volume 4/3 pi (0.75 mm)^3 ~ 1.9e-9 m^3 (mean of r^3 over [0.5, 1]
     * mm is 0.47e-9 m^3, so 1.97e-9 m^3) in 8e-6 m^3: volume fraction 0.37, close to the
     * jamming limit of random sequential addition, a hard case for the grid search. */
    struct wetdem_insert_spec s = base_spec(WETDEM_INSERT_RANDOM, 1500);
    struct wetdem_particle* p = calloc(s.n, sizeof *p);
    char msg[512] = "";
    s.gap = 0;
    int st = wetdem_insert_particles(&s, p, msg, sizeof msg);
    if (st != WETDEM_OK)
        fail_msg("%s", msg);
    assert_true(worst_gap_excess(&s, p) >= 0);
    check_inside(&s, p);
    free(p);
}

static void test_insert_random_periodic_respects_images(void** state)
{
    (void)state;
    struct wetdem_insert_spec s = base_spec(WETDEM_INSERT_RANDOM, 800);
    s.periodic[0] = s.periodic[2] = true;
    struct wetdem_particle* p = calloc(s.n, sizeof *p);
    CHECK_OK(wetdem_insert_particles(&s, p, NULL, 0));
    assert_true(worst_gap_excess(&s, p) >= 0);
    check_inside(&s, p);
    free(p);
}

/* Lattice, 10 mm cube, R = 1 mm, gap 0: spacing a = 2 mm; sites per axis
 * floor((10 - 0 - 2)/2) + 1 = 5, so 125 sites at 1, 3, 5, 7, 9 mm. With gap 0.1 mm:
 * a = 2.1 mm, floor((10 - 0.2 - 2)/2.1) + 1 = 3 + 1 = 4 per axis, 64 sites. */
static void test_insert_lattice_capacity_by_hand(void** state)
{
    (void)state;
    struct wetdem_insert_spec s = base_spec(WETDEM_INSERT_LATTICE, 125);
    s.hi = vec3(10e-3, 10e-3, 10e-3);
    s.radius_min = s.radius_max = 1e-3;
    s.gap = 0;
    struct wetdem_particle p[126];
    char msg[512] = "";
    CHECK_OK(wetdem_insert_particles(&s, p, msg, sizeof msg));
    /* the sites are lo + gap + R + k a, a few roundings of lengths up to 1e-2 m: 1e-15
       (measured 1.9e-16); their spacing is a difference of two of them, each a few ulp of
       3e-3 m (4.3e-19 m) against 2e-3 m: 1e-14 (measured 0) */
    CHECK_REL(p[0].pos.x, 1e-3, 1e-15);   /* first site lo + gap + R */
    CHECK_REL(p[124].pos.z, 9e-3, 1e-15); /* last site 1 + 4 x 2 mm */
    CHECK_REL(p[1].pos.x - p[0].pos.x, 2e-3, 1e-14);
    assert_true(worst_gap_excess(&s, p) >= -1e-15); /* touching: gap 0 up to rounding */
    s.n = 126;
    CHECK_STATUS(wetdem_insert_particles(&s, p, msg, sizeof msg), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(msg, "at most 125 spheres (5 x 5 x 5)");
    s.gap = 0.1e-3;
    s.n = 65;
    CHECK_STATUS(wetdem_insert_particles(&s, p, msg, sizeof msg), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(msg, "at most 64 spheres");
    /* a = 2 r + gap = 2 x 1 mm + 0.1 mm; r is the largest radius drawn, not the key */
    CHECK_CONTAINS(msg, "spacing 2 r + gap = 0.0021 m (r = 0.001 m, the largest radius drawn)");
    s.n = 64;
    CHECK_OK(wetdem_insert_particles(&s, p, msg, sizeof msg));
    check_inside(&s, p);
}

static void test_insert_lattice_with_more_sites_than_a_size_t_holds(void** state)
{
    (void)state;
    /* A periodic 1 m cube and R = 1 / (2 (2^32 + 0.5)) m: 2^32 sites an axis, 2^96 in all.
     * Products of the site counts wrap a size_t (2^64 = 0), which must neither divide by
     * zero nor lose the spacing: the spheres lie along x, 1 / 2^32 m apart. */
    struct wetdem_insert_spec s = base_spec(WETDEM_INSERT_LATTICE, 4);
    s.hi = vec3(1, 1, 1);
    s.gap = 0;
    s.radius_min = s.radius_max = 1 / (2 * (4294967296.0 + 0.5));
    s.periodic[0] = s.periodic[1] = s.periodic[2] = true;
    struct wetdem_particle p[4];
    CHECK_OK(wetdem_insert_particles(&s, p, NULL, 0));
    double step = 1 / 4294967296.0; /* exact in binary, as is every site below */
    for (size_t i = 0; i < 4; i++) {
        assert_true(p[i].pos.x == (0.5 + (double)i) * step);
        assert_true(p[i].pos.y == 0.5 * step && p[i].pos.z == 0.5 * step);
    }
}

static void test_insert_lattice_polydisperse_no_overlap(void** state)
{
    (void)state;
    struct wetdem_insert_spec s = base_spec(WETDEM_INSERT_LATTICE, 700);
    s.periodic[1] = true;
    struct wetdem_particle* p = calloc(s.n, sizeof *p);
    CHECK_OK(wetdem_insert_particles(&s, p, NULL, 0));
    assert_true(worst_gap_excess(&s, p) >= 0);
    check_inside(&s, p);
    free(p);
}

static void test_insert_random_reports_jamming(void** state)
{
    (void)state;
    /* 1000 spheres of R = 1 mm in a 20 mm cube: 4.19e-6 m^3 of spheres in 8e-6 m^3 (0.524),
     * beyond the random-insertion limit of 0.38 (and the 0.52 of the simple cubic lattice). */
    struct wetdem_insert_spec s = base_spec(WETDEM_INSERT_RANDOM, 1000);
    s.radius_min = s.radius_max = 1e-3;
    s.max_attempts = 200;
    struct wetdem_particle* p = calloc(s.n, sizeof *p);
    char msg[512] = "";
    CHECK_STATUS(wetdem_insert_particles(&s, p, msg, sizeof msg), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(msg, "random-insertion limit");
    CHECK_CONTAINS(msg, "lattice");
    CHECK_CONTAINS(msg, "of 1000 spheres (the largest first); the next, of radius 0.001 m");
    CHECK_CONTAINS(msg, "volume fraction 0.524"); /* 1000 x 4/3 pi (1 mm)^3 / (20 mm)^3 */
    free(p);
}

static void test_insert_sparse_region_gets_a_coarse_exact_grid(void** state)
{
    (void)state;
    /* Ten spheres of R = 50 um in a 1 m cube: cells of edge 2 R + gap = 0.2 mm would be
     * 1024^3 (8 GB of heads). The grid must stay within 8 cells a sphere (+ 27) with every
     * cell edge still >= 2 R + gap, which is what keeps the search exact. */
    struct wetdem_insert_spec s = base_spec(WETDEM_INSERT_RANDOM, 10);
    s.hi = vec3(1, 1, 1);
    s.radius_min = s.radius_max = 50e-6;
    double edge = 2 * s.radius_max + s.gap;
    int nc[3];
    size_t cells = wetdem_insert_grid_shape(&s, s.n, edge, nc);
    assert_true(cells <= INSERT_CELLS_PER_SPHERE * s.n + 27);
    assert_true(cells == (size_t)nc[0] * nc[1] * nc[2]);
    for (int k = 0; k < 3; k++)
        assert_true(nc[k] >= 1 && 1.0 / nc[k] >= edge);
    struct wetdem_particle p10[10];
    CHECK_OK(wetdem_insert_particles(&s, p10, NULL, 0));
    check_inside(&s, p10);

    /* 3000 spheres of R = 10 mm in a periodic 1 m cube: 49^3 cells of edge 2 R + gap =
     * 20.05 mm coarsened to 24^3 of 41.7 mm. The k-th sphere's trial lands within 2 R + gap
     * of an accepted one with probability k (4/3 pi (20.05 mm)^3) / 1 m^3, about 150 rejected
     * trials over the run, many in a neighbouring cell or through the wrap, so a grid that
     * missed a neighbour would let the brute-force check find an overlap. */
    s = base_spec(WETDEM_INSERT_RANDOM, 3000);
    s.hi = vec3(1, 1, 1);
    s.radius_min = s.radius_max = 10e-3;
    s.periodic[0] = s.periodic[1] = s.periodic[2] = true;
    cells = wetdem_insert_grid_shape(&s, s.n, 2 * s.radius_max + s.gap, nc);
    assert_true(nc[0] == 24 && nc[1] == 24 && nc[2] == 24);
    struct wetdem_particle* p = calloc(s.n, sizeof *p);
    CHECK_OK(wetdem_insert_particles(&s, p, NULL, 0));
    assert_true(worst_gap_excess(&s, p) >= 0);
    free(p);
}

/* Smallest gap between a sphere of a and one of b minus gap (>= 0: clear) [m]. */
static double worst_gap_between(const struct wetdem_insert_spec* s, const struct wetdem_particle* a,
                                size_t na, const struct wetdem_particle* b, size_t nb)
{
    double worst = INFINITY;
    for (size_t i = 0; i < na; i++)
        for (size_t j = 0; j < nb; j++)
            worst = fmin(worst, gap_excess(s, &a[i], &b[j]));
    return worst;
}

static void test_insert_random_keeps_clear_of_existing_spheres(void** state)
{
    (void)state;
    /* 40 spheres of R = 2 mm first, then 3000 of 0.2-0.3 mm in the same periodic 30 mm cube
     * (volume fractions 0.050 and 0.007). Drawn alone, about 3000 x 40 x 4/3 pi (2.35 mm)^3 /
     * (30 mm)^3 = 240 of the small spheres would land on a big one; none may. */
    struct wetdem_insert_spec big = base_spec(WETDEM_INSERT_RANDOM, 40);
    big.hi = vec3(30e-3, 30e-3, 30e-3);
    big.periodic[0] = big.periodic[1] = big.periodic[2] = true;
    big.radius_min = big.radius_max = 2e-3;
    struct wetdem_insert_spec small = big;
    small.n = 3000;
    small.radius_min = 0.2e-3;
    small.radius_max = 0.3e-3;
    small.seed = 43;
    struct wetdem_particle pb[40], *ps = calloc(small.n, sizeof *ps);
    CHECK_OK(wetdem_insert_particles(&big, pb, NULL, 0));
    CHECK_OK(wetdem_insert_particles(&small, ps, NULL, 0));
    assert_true(worst_gap_between(&small, ps, small.n, pb, 40) < 0); /* alone: they overlap */
    CHECK_OK(wetdem_insert_particles_among(&small, pb, 40, ps, NULL, 0));
    assert_true(worst_gap_between(&small, ps, small.n, pb, 40) >= 0);
    assert_true(worst_gap_excess(&small, ps) >= 0);

    /* the same through the simulation, which passes its spheres; the small ones first leave
     * no hole for a big one, and the message says to insert the larger spheres first */
    struct wetdem_sim* sim = wetdem_sim_create();
    struct wetdem_material m = {
        .density = 2500, .youngs_modulus = 1e7, .poisson_ratio = 0.3, .restitution = 0.6};
    assert_int_equal(wetdem_sim_add_material(sim, &m), 0);
    CHECK_OK(wetdem_sim_insert(sim, &big));
    CHECK_OK(wetdem_sim_insert(sim, &small));
    size_t n;
    const struct wetdem_particle* all = wetdem_sim_particles_const(sim, &n);
    assert_int_equal(n, 3040);
    assert_true(worst_gap_between(&small, all + 40, small.n, all, 40) >= 0);
    wetdem_sim_free(sim);
    sim = wetdem_sim_create();
    assert_int_equal(wetdem_sim_add_material(sim, &m), 0);
    /* 20000 of 0.3 mm: a big sphere's centre needs no small centre within 2.35 mm, where
     * 20000 x 4/3 pi (2.35 mm)^3 / (30 mm)^3 = 40 are expected (a chance of e^-40) */
    small.n = 20000;
    small.radius_min = small.radius_max = 0.3e-3;
    CHECK_OK(wetdem_sim_insert(sim, &small));
    big.max_attempts = 200;
    CHECK_STATUS(wetdem_sim_insert(sim, &big), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "the 20000 spheres already there");
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "insert the groups of larger spheres first");
    wetdem_sim_free(sim);
    free(ps);
}

struct progress_log {
    unsigned long long done[8], total[8];
    double elapsed[8];
    int calls;
    unsigned long long stop_at; /* non-zero: stop when this many are placed */
};

static int log_progress(unsigned long long done, unsigned long long total, double elapsed,
                        void* ctx)
{
    struct progress_log* log = ctx;
    if (log->calls < 8) {
        log->done[log->calls] = done;
        log->total[log->calls] = total;
        log->elapsed[log->calls] = elapsed;
    }
    log->calls++;
    return log->stop_at && done >= log->stop_at;
}

static void test_insert_random_reports_progress_and_can_stop(void** state)
{
    (void)state;
    /* 2500 spheres: calls after 1000, 2000 and 2500, with total 2500 and a clock that does
     * not run backwards; the callback leaves the spheres as they are without it. */
    struct wetdem_insert_spec s = base_spec(WETDEM_INSERT_RANDOM, 2500);
    s.hi = vec3(0.1, 0.1, 0.1);
    struct wetdem_particle* plain = calloc(s.n, sizeof *plain);
    struct wetdem_particle* seen = calloc(s.n, sizeof *seen);
    CHECK_OK(wetdem_insert_particles(&s, plain, NULL, 0));
    struct progress_log log = {.calls = 0};
    s.progress = log_progress;
    s.progress_ctx = &log;
    CHECK_OK(wetdem_insert_particles(&s, seen, NULL, 0));
    assert_int_equal(log.calls, 3);
    const unsigned long long want[3] = {1000, 2000, 2500};
    for (int k = 0; k < 3; k++) {
        assert_true(log.done[k] == want[k] && log.total[k] == 2500);
        assert_true(log.elapsed[k] >= (k ? log.elapsed[k - 1] : 0));
    }
    for (size_t i = 0; i < s.n; i++) /* field by field: padding bytes may differ */
        assert_true(plain[i].radius == seen[i].radius && plain[i].pos.x == seen[i].pos.x &&
                    plain[i].pos.y == seen[i].pos.y && plain[i].pos.z == seen[i].pos.z &&
                    plain[i].vel.x == seen[i].vel.x && plain[i].vel.z == seen[i].vel.z);

    /* a non-zero return stops it: WETDEM_EVENT, and the simulation gains no sphere */
    log = (struct progress_log){.stop_at = 2000};
    char msg[256] = "";
    CHECK_STATUS(wetdem_insert_particles(&s, seen, msg, sizeof msg), WETDEM_EVENT);
    CHECK_CONTAINS(msg, "insert: stopped after 2000 of 2500 spheres");
    assert_int_equal(log.calls, 2);
    struct wetdem_sim* sim = wetdem_sim_create();
    struct wetdem_material m = {.density = 2500,
                                .youngs_modulus = 1e7,
                                .poisson_ratio = 0.3,
                                .restitution = 0.6,
                                .friction_dry = 0.4};
    assert_int_equal(wetdem_sim_add_material(sim, &m), 0);
    log = (struct progress_log){.stop_at = 1000};
    CHECK_STATUS(wetdem_sim_insert(sim, &s), WETDEM_EVENT);
    assert_int_equal(wetdem_sim_n_particles(sim), 0);
    wetdem_sim_free(sim);
    free(plain);
    free(seen);
}

static void test_insert_given_radii_and_velocity_statistics(void** state)
{
    (void)state;
    size_t n = 4000;
    struct wetdem_insert_spec s = base_spec(WETDEM_INSERT_LATTICE, n);
    s.hi = vec3(0.2, 0.2, 0.2);
    s.velocity = vec3(0, 0, -1);
    double* radii = malloc(n * sizeof *radii);
    for (size_t i = 0; i < n; i++)
        radii[i] = (i % 2) ? 1e-3 : 0.6e-3;
    s.radii = radii;
    struct wetdem_particle* p = calloc(n, sizeof *p);
    CHECK_OK(wetdem_insert_particles(&s, p, NULL, 0));
    double mean = 0, var = 0;
    for (size_t i = 0; i < n; i++) {
        assert_true(p[i].radius == radii[i]);
        mean += p[i].vel.z / n;
    }
    for (size_t i = 0; i < n; i++)
        var += (p[i].vel.z - mean) * (p[i].vel.z - mean) / (n - 1);
    /* sample mean ~ N(-1, 0.1/sqrt(4000) = 1.6e-3): 5 standard errors is 7.9e-3 */
    CHECK_ABS(mean, -1.0, 7.9e-3);
    /* sample sd of 4000 Gaussians: relative standard error 1/sqrt(2 x 3999) = 1.1 %; 5 % */
    CHECK_REL(sqrt(var), 0.1, 0.05);
    free(p);
    free(radii);
}

static void test_insert_rejects_bad_spec(void** state)
{
    (void)state;
    struct wetdem_particle p[4];
    char msg[512] = "";
    struct wetdem_insert_spec s = base_spec(WETDEM_INSERT_RANDOM, 4);
    s.radius_min = 2e-3;
    CHECK_STATUS(wetdem_insert_particles(&s, p, msg, sizeof msg), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(msg, "radius_min <= radius_max");
    s = base_spec(WETDEM_INSERT_RANDOM, 4);
    s.hi.y = -1;
    CHECK_STATUS(wetdem_insert_particles(&s, p, msg, sizeof msg), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(msg, "y range");
    s = base_spec(WETDEM_INSERT_RANDOM, 4);
    s.gap = NAN;
    CHECK_STATUS(wetdem_insert_particles(&s, p, msg, sizeof msg), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(msg, "insert.gap");
    s = base_spec(WETDEM_INSERT_RANDOM, 4);
    s.hi.x = 1.5e-3; /* thinner than one sphere */
    CHECK_STATUS(wetdem_insert_particles(&s, p, msg, sizeof msg), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(msg, "does not fit in the region: it is 0.0015 m across in x, narrower than "
                        "2 r + 2 gap = ");
    /* the lattice names the axis too, not "holds at most 0 spheres"; across a periodic axis
     * a sphere needs one spacing, 2 r + gap */
    s = base_spec(WETDEM_INSERT_LATTICE, 4);
    s.radius_min = s.radius_max = 1e-3;
    s.hi.y = 2e-3;
    CHECK_STATUS(wetdem_insert_particles(&s, p, msg, sizeof msg), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(msg, "insert: the region is 0.002 m across in y, narrower than one sphere: "
                        "2 r + 2 gap = 0.0021 m (r = 0.001 m, the largest radius drawn; gap = "
                        "5e-05 m); enlarge the region in y or reduce radius_max or gap");
    s.periodic[1] = true;
    CHECK_STATUS(wetdem_insert_particles(&s, p, msg, sizeof msg), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(msg, "across in y, narrower than one sphere: 2 r + gap = 0.00205 m");

    /* 10^8 spheres of R >= 0.5 mm in a 20 mm cube: at least 10^8 x 4/3 pi (0.5 mm)^3 =
     * 0.0524 m^3, 6545 times the 8e-6 m^3 region. Refused before the 10^8 particles are
     * allocated: the simulation gives this message, not the random layout's "placed ..." */
    s = base_spec(WETDEM_INSERT_RANDOM, 100000000);
    CHECK_STATUS(wetdem_insert_check(&s, msg, sizeof msg), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(msg, "count = 100000000 spheres fill at least 0.0524 m^3, 6.54e+03 times");
    struct wetdem_sim* sim = wetdem_sim_create();
    struct wetdem_material m = {
        .density = 2500, .youngs_modulus = 1e7, .poisson_ratio = 0.3, .restitution = 0.6};
    assert_int_equal(wetdem_sim_add_material(sim, &m), 0);
    CHECK_STATUS(wetdem_sim_insert(sim, &s), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "times the region's 8e-06 m^3");
    wetdem_sim_free(sim);
    /* the lattice: for spheres of radius_min = 0.5 mm at 1.05 mm spacing an axis has
     * floor((20 - 2 x 0.05 - 2 x 0.5) / 1.05) + 1 = 19 sites, and 19^3 = 6859 is the most
     * any draw of radii in [0.5, 1] mm leaves */
    s = base_spec(WETDEM_INSERT_LATTICE, 100000000);
    CHECK_STATUS(wetdem_insert_check(&s, msg, sizeof msg), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(msg, "holds at most 6859 spheres (19 x 19 x 19)");
    CHECK_CONTAINS(msg, "radius_min, the least the largest radius drawn can be");
    /* given radii count exactly: 4 of 13 mm fill 3.68e-5 m^3 > 8e-6 m^3; 4 of 7 mm do not */
    double radii[4] = {13e-3, 13e-3, 13e-3, 13e-3};
    s = base_spec(WETDEM_INSERT_RANDOM, 4);
    s.radii = radii;
    CHECK_STATUS(wetdem_insert_check(&s, msg, sizeof msg), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(msg, "4.6 times");
    for (int k = 0; k < 4; k++)
        radii[k] = 7e-3;
    CHECK_OK(wetdem_insert_check(&s, msg, sizeof msg));
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_insert_same_seed_gives_identical_particles),
        cmocka_unit_test(test_insert_draws_in_a_stated_order),
        cmocka_unit_test(test_insert_random_has_no_overlap),
        cmocka_unit_test(test_insert_random_periodic_respects_images),
        cmocka_unit_test(test_insert_lattice_capacity_by_hand),
        cmocka_unit_test(test_insert_lattice_with_more_sites_than_a_size_t_holds),
        cmocka_unit_test(test_insert_lattice_polydisperse_no_overlap),
        cmocka_unit_test(test_insert_random_reports_jamming),
        cmocka_unit_test(test_insert_sparse_region_gets_a_coarse_exact_grid),
        cmocka_unit_test(test_insert_random_reports_progress_and_can_stop),
        cmocka_unit_test(test_insert_random_keeps_clear_of_existing_spheres),
        cmocka_unit_test(test_insert_given_radii_and_velocity_statistics),
        cmocka_unit_test(test_insert_rejects_bad_spec),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

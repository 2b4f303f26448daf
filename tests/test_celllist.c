/*
 * test_celllist.c — cell-list neighbour search (src/celllist.c) against brute force on random
 * polydisperse configurations, with and without periodic axes (including boxes of only 2 and
 * 3 cells, where neighbouring cells coincide), thread-count independence, the rebuild
 * guarantee for beyond-contact pairs (LAMMPS PR #4685), and history remapping.
 */
#include <gsl/gsl_rng.h>
#include <omp.h>
#include <stdlib.h>

#include "celllist.h"
#include "harness.h"
#include "vec3.h"

/* n spheres with radii uniform in [r_lo, r_hi] and centres uniform in [0, len]^3 (overlaps
 * allowed: the search must not care). */
static struct wetdem_particle* random_spheres(size_t n, double len, double r_lo, double r_hi,
                                              unsigned long seed)
{
    gsl_rng* rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, seed);
    struct wetdem_particle* p = calloc(n, sizeof *p);
    for (size_t i = 0; i < n; i++) {
        p[i].pos = vec3(len * gsl_rng_uniform(rng), len * gsl_rng_uniform(rng),
                        len * gsl_rng_uniform(rng));
        p[i].radius = r_lo + (r_hi - r_lo) * gsl_rng_uniform(rng);
    }
    gsl_rng_free(rng);
    return p;
}

static bool within(const struct wetdem_celllist_box* box, const struct wetdem_particle* p, size_t i,
                   size_t j, double gap_max)
{
    struct wetdem_vec3 d = celllist_delta(box, p[i].pos, p[j].pos);
    double lim = p[i].radius + p[j].radius + gap_max;
    return vec3_dot(d, d) < lim * lim;
}

/* Every brute-force pair with gap < reach + skin, not both fixed, is listed, in (i, j) order,
 * and nothing else. */
static void check_against_brute_force(const struct wetdem_celllist* cl,
                                      const struct wetdem_particle* p, size_t n)
{
    size_t k = 0;
    for (size_t i = 0; i < n; i++)
        for (size_t j = i + 1; j < n; j++) {
            if (!within(&cl->box, p, i, j, cl->reach + cl->skin) ||
                (p[i].is_fixed && p[j].is_fixed))
                continue;
            if (k >= cl->n_pairs || cl->pairs[k].i != i || cl->pairs[k].j != j)
                fail_msg("pair (%zu, %zu) missing or out of order at list position %zu", i, j, k);
            k++;
        }
    assert_int_equal(k, cl->n_pairs);
    assert_int_equal(cl->first_pair[0], 0);
    assert_int_equal(cl->first_pair[n], cl->n_pairs);
    for (size_t i = 0; i < n; i++)
        for (size_t q = cl->first_pair[i]; q < cl->first_pair[i + 1]; q++)
            assert_int_equal(cl->pairs[q].i, i);
}

/* Builds the list of p (n spheres) in `box` with the given reach and a 0.2 mm skin, with
 * `threads` threads, compares it with brute force and returns the number of pairs. */
static size_t build_and_check(const struct wetdem_celllist_box* box,
                              const struct wetdem_particle* p, size_t n, double reach, int threads,
                              int cells_x)
{
    struct wetdem_celllist cl;
    char msg[256];
    CHECK_OK(wetdem_celllist_init(&cl, box, reach, 0.2e-3, msg, sizeof msg));
    int saved = omp_get_max_threads();
    omp_set_num_threads(threads);
    CHECK_OK(wetdem_celllist_build(&cl, p, n, msg, sizeof msg));
    omp_set_num_threads(saved);
    if (cells_x > 0) /* the case meant to be exercised */
        assert_int_equal(cl.n_cells[0], cells_x);
    check_against_brute_force(&cl, p, n);
    size_t n_pairs = cl.n_pairs;
    wetdem_celllist_clear(&cl);
    return n_pairs;
}

static void run_case(const bool periodic[3], double len, size_t n, unsigned long seed)
{
    struct wetdem_particle* p = random_spheres(n, len, 0.5e-3, 1.5e-3, seed);
    struct wetdem_celllist_box box = {{0, 0, 0}, {len, len, len}, {0}};
    memcpy(box.periodic, periodic, sizeof box.periodic);
    assert_true(build_and_check(&box, p, n, 0.4e-3, 1, 0) > 0);
    free(p);
}

/* d_cut = 2 x 1.5 mm + 0.4 mm + 0.2 mm = 3.6 mm. A 30 mm box has 8 cells per axis; 600
 * spheres of mean radius 1 mm fill 8.4 % of it, so there are many pairs and empty cells. */
static void test_celllist_matches_brute_force_open_box(void** state)
{
    (void)state;
    run_case((bool[3]){false, false, false}, 30e-3, 600, 1);
}

/* A third of the spheres fixed (a rough base and obstacles): no pair of two of them is
 * listed, on 1 and 2 threads (the parallel build from 512 spheres), and every pair with a
 * free sphere still is. */
static void test_celllist_leaves_out_pairs_of_fixed_spheres(void** state)
{
    (void)state;
    struct wetdem_particle* p = random_spheres(600, 30e-3, 0.5e-3, 1.5e-3, 4);
    struct wetdem_celllist_box box = {{0, 0, 0}, {30e-3, 30e-3, 30e-3}, {true, false, true}};
    size_t all = build_and_check(&box, p, 600, 0.4e-3, 1, 0), fixed_pairs = 0;
    for (size_t i = 0; i < 600; i += 3)
        p[i].is_fixed = true;
    for (size_t i = 0; i < 600; i += 3)
        for (size_t j = i + 3; j < 600; j += 3)
            fixed_pairs += within(&box, p, i, j, 0.4e-3 + 0.2e-3);
    assert_true(fixed_pairs > 10); /* the case is exercised */
    for (int threads = 1; threads <= 2; threads++)
        assert_int_equal(build_and_check(&box, p, 600, 0.4e-3, threads, 0), all - fixed_pairs);
    free(p);
}

static void test_celllist_matches_brute_force_periodic(void** state)
{
    (void)state;
    run_case((bool[3]){true, false, true}, 30e-3, 600, 2);
    run_case((bool[3]){true, true, true}, 30e-3, 600, 3);
}

/* 7.5 mm / 3.6 mm -> 2 cells per axis: the -1 and +1 neighbours are the same cell and must
 * not yield the pair twice; 11 mm -> 3 cells, where -1 and +1 differ but wrap. */
static void test_celllist_small_periodic_boxes_have_no_duplicates(void** state)
{
    (void)state;
    run_case((bool[3]){true, true, true}, 7.5e-3, 40, 4);
    run_case((bool[3]){true, true, true}, 11e-3, 90, 5);
}

/* A single cell on a periodic axis: 7.5 mm periodic along x (2 cells of >= 3.6 mm), y and z
 * open over 100 mm (27 cells each); with 20 spheres the grid is coarsened to at most
 * 4 x 20 + 27 = 107 cells: 2 x 27 x 27 -> 1 x 13 x 13 -> 1 x 6 x 6, so x has one cell and
 * every pair along x is found through the minimum image within that cell. */
static void test_celllist_single_periodic_cell(void** state)
{
    (void)state;
    size_t n = 20;
    struct wetdem_particle* p = random_spheres(n, 100e-3, 0.5e-3, 1.5e-3, 11);
    for (size_t i = 0; i < n; i++) /* squeeze x into the periodic box */
        p[i].pos.x *= 7.5e-3 / 100e-3;
    for (size_t i = 0; i + 1 < n; i += 2) { /* the image of i + 1 is 2.5 mm from i along x */
        p[i + 1].pos = vec3(fmod(p[i].pos.x + 5e-3, 7.5e-3), p[i].pos.y + 0.5e-3, p[i].pos.z);
        p[i].radius = p[i + 1].radius = 1.2e-3; /* 2.55 mm apart < 2.4 + 0.4 + 0.2 = 3.0 mm */
    }
    struct wetdem_celllist_box box = {{0, 0, 0}, {7.5e-3, 0, 0}, {true, false, false}};
    assert_true(build_and_check(&box, p, n, 0.4e-3, 1, 1) >= n / 2);
    free(p);
}

/* Periodic along x with 1, 2 and 3 cells, the other axes open or periodic: each offset of
 * the half stencil must name a distinct cell or be de-duplicated. d_cut = 3.6 mm; 7.5 mm ->
 * 2 cells, 11 mm -> 3 cells (the rows that wrap), 30 mm -> 8. */
static void test_celllist_periodic_axes_of_few_cells(void** state)
{
    (void)state;
    const double len[3] = {7.5e-3, 11e-3, 30e-3};
    const int cells[3] = {2, 3, 8};
    for (int a = 0; a < 3; a++)
        for (int other = 0; other < 2; other++) {
            size_t n = 300;
            struct wetdem_particle* p = random_spheres(n, 30e-3, 0.5e-3, 1.5e-3, 20 + a);
            for (size_t i = 0; i < n; i++)
                p[i].pos.x *= len[a] / 30e-3;
            struct wetdem_celllist_box box = {
                {0, 0, 0}, {len[a], 30e-3, 30e-3}, {true, other == 1, other == 1}};
            assert_true(build_and_check(&box, p, n, 0.4e-3, 1, cells[a]) > 0);
            free(p);
        }
}

/* Particles outside the periodic box (an engine may hand over unwrapped positions): binned
 * modulo the box, paired through the minimum image; the list is that of brute force. */
static void test_celllist_unwrapped_positions(void** state)
{
    (void)state;
    size_t n = 600;
    struct wetdem_particle* p = random_spheres(n, 30e-3, 0.5e-3, 1.5e-3, 12);
    for (size_t i = 0; i < n; i += 3)
        p[i].pos = vec3_add(p[i].pos, vec3(i % 2 ? 30e-3 : -30e-3, 60e-3, 0));
    struct wetdem_celllist_box box = {{0, 0, 0}, {30e-3, 30e-3, 30e-3}, {true, true, false}};
    assert_true(build_and_check(&box, p, n, 0.4e-3, 1, 8) > 0);
    free(p);
}

/* Strong polydispersity (radii 0.05 .. 2 mm, a ratio of 40) and a long reach (3 mm, e.g. a
 * lubrication cut-off): cells of d_cut = 7.2 mm hold ~30 spheres, a sphere has tens of
 * candidates, and the list must still equal brute force for 1 and 2 threads. */
static void test_celllist_polydisperse_long_reach(void** state)
{
    (void)state;
    size_t n = 2000;
    struct wetdem_particle* p = random_spheres(n, 40e-3, 0.05e-3, 2e-3, 13);
    struct wetdem_celllist_box open = {{0, 0, 0}, {40e-3, 40e-3, 40e-3}, {0}};
    struct wetdem_celllist_box per = {{0, 0, 0}, {40e-3, 40e-3, 40e-3}, {true, false, true}};
    size_t a = build_and_check(&open, p, n, 3e-3, 1, 0),
           b = build_and_check(&open, p, n, 3e-3, 2, 0);
    assert_int_equal(a, b);
    /* mean pair range ~2 x 1 + 3.2 = 5.2 mm: ~0.031 spheres/mm^3 x 589 mm^3 / 2 ~ 9 pairs per
     * sphere in the bulk, fewer at the walls: long segments, so the per-i sort is exercised */
    assert_true(a > 5 * n);
    assert_int_equal(build_and_check(&per, p, n, 3e-3, 1, 0),
                     build_and_check(&per, p, n, 3e-3, 2, 0));
    free(p);
}

static void test_celllist_rejects_too_small_periodic_box(void** state)
{
    (void)state;
    /* 7.0 mm < 2 d_cut = 7.2 mm: a pair could interact through two images. */
    struct wetdem_particle* p = random_spheres(10, 7e-3, 1.5e-3, 1.5e-3, 6);
    struct wetdem_celllist_box box = {{0, 0, 0}, {7e-3, 7e-3, 7e-3}, {true, false, false}};
    struct wetdem_celllist cl;
    char msg[256] = "";
    CHECK_OK(wetdem_celllist_init(&cl, &box, 0.4e-3, 0.2e-3, msg, sizeof msg));
    CHECK_STATUS(wetdem_celllist_build(&cl, p, 10, msg, sizeof msg), WETDEM_ERR_INVALID);
    /* the axis and the least length are named (the message gave neither: which of a box's
       periodic edges was short, and by how much, was left to the reader) */
    CHECK_CONTAINS(msg, "periodic box length along x, 0.007 m, is below twice the interaction "
                        "distance 2 R_max + reach + skin = 0.0036 m (R_max 0.0015 m, reach "
                        "0.0004 m, skin 0.0002 m): it must be at least 0.0072 m");
    CHECK_STATUS(wetdem_celllist_init(&cl, &box, 0.4e-3, 0.0, msg, sizeof msg), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(msg, "skin");
    CHECK_STATUS(wetdem_celllist_init(&cl, &box, NAN, 1e-4, msg, sizeof msg), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(msg, "reach");
    wetdem_celllist_clear(&cl);
    free(p);
}

/* The check of the particles runs in parallel: the message names the first bad particle, and
 * the bounding box (and so the grid and the list) is the same, for any thread count. */
static void test_celllist_first_bad_particle_for_any_thread_count(void** state)
{
    (void)state;
    size_t n = 3000;
    struct wetdem_particle* p = random_spheres(n, 60e-3, 0.5e-3, 1.5e-3, 11);
    struct wetdem_celllist_box box = {{0, 0, 0}, {60e-3, 60e-3, 60e-3}, {false, false, false}};
    int saved = omp_get_max_threads();
    for (int threads = 1; threads <= 4; threads++) {
        omp_set_num_threads(threads);
        struct wetdem_celllist cl;
        char msg[256] = "";
        CHECK_OK(wetdem_celllist_init(&cl, &box, 0.4e-3, 0.2e-3, msg, sizeof msg));
        p[2900].radius = -1e-3; /* in the last thread's share */
        p[1700].pos.y = NAN;    /* the first bad one */
        CHECK_STATUS(wetdem_celllist_build(&cl, p, n, msg, sizeof msg), WETDEM_ERR_INVALID);
        CHECK_CONTAINS(msg, "particle 1700 has a non-finite position");
        p[1700].pos.y = 1e-3;
        CHECK_STATUS(wetdem_celllist_build(&cl, p, n, msg, sizeof msg), WETDEM_ERR_INVALID);
        CHECK_CONTAINS(msg, "particle 2900 has a non-finite position or a bad radius -0.001 m");
        p[2900].radius = 1e-3;
        CHECK_OK(wetdem_celllist_build(&cl, p, n, msg, sizeof msg));
        assert_int_equal(cl.n_cells[0], 16); /* the box of the spheres, 60 mm / d_cut 3.6 mm */
        check_against_brute_force(&cl, p, n);
        wetdem_celllist_clear(&cl);
    }
    omp_set_num_threads(saved);
    free(p);
}

static void test_celllist_same_list_for_any_thread_count(void** state)
{
    (void)state;
    size_t n = 3000;
    struct wetdem_particle* p = random_spheres(n, 60e-3, 0.5e-3, 1.5e-3, 7);
    struct wetdem_celllist_box box = {{0, 0, 0}, {60e-3, 60e-3, 60e-3}, {true, false, false}};
    struct wetdem_celllist a, b;
    CHECK_OK(wetdem_celllist_init(&a, &box, 0.4e-3, 0.2e-3, NULL, 0));
    CHECK_OK(wetdem_celllist_init(&b, &box, 0.4e-3, 0.2e-3, NULL, 0));
    int saved = omp_get_max_threads();
    omp_set_num_threads(1);
    CHECK_OK(wetdem_celllist_build(&a, p, n, NULL, 0));
    for (int threads = 2; threads <= 4; threads += 2) {
        omp_set_num_threads(threads);
        CHECK_OK(wetdem_celllist_build(&b, p, n, NULL, 0));
        assert_int_equal(a.n_pairs, b.n_pairs);
        assert_memory_equal(a.pairs, b.pairs, a.n_pairs * sizeof *a.pairs);
        assert_memory_equal(a.first_pair, b.first_pair, (n + 1) * sizeof *a.first_pair);
    }
    omp_set_num_threads(saved);
    check_against_brute_force(&a, p, n);
    wetdem_celllist_clear(&a);
    wetdem_celllist_clear(&b);
    free(p);
}

/* Moves particles with random velocities for `steps` steps of at most step_max each, wrapping
 * periodic coordinates into the box as an engine does, rebuilding only when the criterion
 * (or, for the negative control, a lax displacement `lax` > skin/2) asks for it. Returns the
 * number of (step, pair) occurrences with gap < reach that were absent from the list. */
static size_t count_missed_pairs(double reach, double lax, size_t* builds)
{
    size_t n = 400, missed = 0;
    double len = 24e-3, skin = 0.2e-3, step_max = 0.01e-3;
    struct wetdem_particle* p = random_spheres(n, len, 0.5e-3, 1.0e-3, 8);
    gsl_rng* rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 9);
    struct wetdem_vec3* v = calloc(n, sizeof *v);
    for (size_t i = 0; i < n; i++)
        v[i] = vec3(gsl_rng_uniform(rng) - 0.5, gsl_rng_uniform(rng) - 0.5,
                    gsl_rng_uniform(rng) - 0.5);
    struct wetdem_celllist_box box = {{0, 0, 0}, {len, len, len}, {true, true, false}};
    struct wetdem_celllist cl;
    CHECK_OK(wetdem_celllist_init(&cl, &box, reach, skin, NULL, 0));
    char* listed = calloc(n * n, 1);
    for (int s = 0; s < 300; s++) {
        bool rebuild = lax > 0 ? wetdem_celllist_max_displacement(&cl, p, n) > lax
                               : wetdem_celllist_needs_rebuild(&cl, p, n);
        if (rebuild) {
            CHECK_OK(wetdem_celllist_build(&cl, p, n, NULL, 0));
            memset(listed, 0, n * n);
            for (size_t q = 0; q < cl.n_pairs; q++)
                listed[cl.pairs[q].i * n + cl.pairs[q].j] = 1;
        }
        for (size_t i = 0; i < n; i++)
            for (size_t j = i + 1; j < n; j++)
                missed += within(&box, p, i, j, 0.4e-3) && !listed[i * n + j];
        for (size_t i = 0; i < n; i++) {
            /* |v| <= sqrt(3)/2, so one step moves a particle by <= 0.87 step_max */
            p[i].pos = vec3_axpy(p[i].pos, step_max, v[i]);
            p[i].pos.x -= len * floor(p[i].pos.x / len);
            p[i].pos.y -= len * floor(p[i].pos.y / len);
        }
    }
    *builds = (size_t)cl.n_builds;
    wetdem_celllist_clear(&cl);
    free(listed);
    free(v);
    free(p);
    gsl_rng_free(rng);
    return missed;
}

/* The interaction range is a 0.4 mm film beyond contact. With reach = 0.4 mm and the skin/2
 * criterion nothing is ever missed although the list is rebuilt only every ~12 steps
 * (0.1 mm / 0.0087 mm). Negative controls that must fail: a list built for contact only
 * (reach 0, the LAMMPS #4685 failure mode) and a lax criterion (rebuild after > skin). */
static void test_celllist_never_misses_beyond_contact_pairs(void** state)
{
    (void)state;
    size_t builds;
    assert_int_equal(count_missed_pairs(0.4e-3, 0, &builds), 0);
    assert_true(builds > 5 && builds < 100);
    assert_true(count_missed_pairs(0.0, 0, &builds) > 0);
    assert_true(count_missed_pairs(0.4e-3, 0.3e-3, &builds) > 0);
}

static void test_celllist_remap_history_keeps_common_pairs(void** state)
{
    (void)state;
    struct wetdem_celllist_pair old_pairs[] = {{0, 1}, {0, 5}, {2, 3}, {4, 7}};
    double old_hist[] = {1, 10, 2, 20, 3, 30, 4, 40};
    struct wetdem_celllist_pair new_pairs[] = {{0, 1}, {0, 2}, {2, 3}, {3, 4}, {4, 7}};
    double new_hist[10], fresh[2] = {-1, -2};
    assert_int_equal(
        wetdem_celllist_remap_history(old_pairs, old_hist, 4, new_pairs, new_hist, 5, 2, fresh), 3);
    double want[] = {1, 10, -1, -2, 3, 30, -1, -2, 4, 40};
    for (int k = 0; k < 10; k++)
        CHECK_ABS(new_hist[k], want[k], 0); /* copies: exact */
}

static void test_celllist_rebuild_criterion_is_half_skin(void** state)
{
    (void)state;
    struct wetdem_particle p[2] = {{.pos = {0, 0, 0}, .radius = 1e-3},
                                   {.pos = {5e-3, 0, 0}, .radius = 1e-3}};
    struct wetdem_celllist cl;
    CHECK_OK(wetdem_celllist_init(&cl, NULL, 0, 0.2e-3, NULL, 0));
    assert_true(wetdem_celllist_needs_rebuild(&cl, p, 2)); /* never built */
    CHECK_OK(wetdem_celllist_build(&cl, p, 2, NULL, 0));
    assert_int_equal(cl.n_pairs, 0); /* gap 3 mm > 0.2 mm */
    p[0].pos.y = 0.099e-3;           /* 0.099 mm < skin/2 = 0.1 mm */
    assert_false(wetdem_celllist_needs_rebuild(&cl, p, 2));
    /* the length of (0, 0.099 mm, 0): a square and a square root, an ulp or so: 1e-15
       (measured 0) */
    CHECK_REL(wetdem_celllist_max_displacement(&cl, p, 2), 0.099e-3, 1e-15);
    p[0].pos.y = 0.101e-3;
    assert_true(wetdem_celllist_needs_rebuild(&cl, p, 2));
    assert_true(wetdem_celllist_needs_rebuild(&cl, p, 1)); /* count changed */
    wetdem_celllist_clear(&cl);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_celllist_matches_brute_force_open_box),
        cmocka_unit_test(test_celllist_matches_brute_force_periodic),
        cmocka_unit_test(test_celllist_leaves_out_pairs_of_fixed_spheres),
        cmocka_unit_test(test_celllist_small_periodic_boxes_have_no_duplicates),
        cmocka_unit_test(test_celllist_single_periodic_cell),
        cmocka_unit_test(test_celllist_periodic_axes_of_few_cells),
        cmocka_unit_test(test_celllist_unwrapped_positions),
        cmocka_unit_test(test_celllist_polydisperse_long_reach),
        cmocka_unit_test(test_celllist_rejects_too_small_periodic_box),
        cmocka_unit_test(test_celllist_first_bad_particle_for_any_thread_count),
        cmocka_unit_test(test_celllist_same_list_for_any_thread_count),
        cmocka_unit_test(test_celllist_never_misses_beyond_contact_pairs),
        cmocka_unit_test(test_celllist_remap_history_keeps_common_pairs),
        cmocka_unit_test(test_celllist_rebuild_criterion_is_half_skin),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

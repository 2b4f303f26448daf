/*
 * test_many_force.c — the force evaluation of the many-particle mode (src/sim_many_force.c):
 * the contact built from the material-pair table equals the one contact.c builds, the fused
 * hertz/mindlin/sb/capillary kernel gives bit-identical forces, per-model forces and
 * histories to the generic model interface (wetdem_sim_eval_contact) over every branch of the
 * four models, the precomputed-coefficient damping kernels it calls equal the per-call ones,
 * whole runs with the fused kernel, and with the lean kernel that computes the same forces
 * without building contacts, equal runs through the generic interface bit for bit (also with
 * a min-separation record kept beyond the films), and all stay independent of the thread
 * count.
 *
 * Bit-identity is the right tolerance here: the fused kernel calls the same kernels with the
 * same arguments and adds the models in the same order, so any difference is a bug.
 */
#include <gsl/gsl_rng.h>
#include <omp.h>
#include <stdlib.h>

#include "harness.h"
#include "many.h"
#include "models.h"

/* The first material, or two that differ in every property the contact mixes, a fluid, and
 * the model set given (in that order). */
static struct wetdem_sim* materials_sim(const char* const* models, int n_models, bool two)
{
    struct wetdem_sim* sim = wetdem_sim_create();
    struct wetdem_material a = {.density = 2500,
                                .youngs_modulus = 1e7,
                                .poisson_ratio = 0.3,
                                .restitution = 0.6,
                                .friction_dry = 0.4,
                                .friction_lub = 0.1,
                                .roughness = 1e-7,
                                .film = 20e-6};
    struct wetdem_material b = {.density = 7800,
                                .youngs_modulus = 2e8,
                                .poisson_ratio = 0.25,
                                .restitution = 0.8,
                                .friction_dry = 0.3,
                                .friction_lub = 0.05,
                                .roughness = 3e-7,
                                .film = 10e-6};
    assert_int_equal(wetdem_sim_add_material(sim, &a), 0);
    if (two)
        assert_int_equal(wetdem_sim_add_material(sim, &b), 1);
    struct wetdem_fluid f = {.viscosity = 0.01, .surface_tension = 0.02, .density = 1000};
    CHECK_OK(wetdem_sim_set_fluid(sim, &f));
    for (int k = 0; k < n_models; k++)
        CHECK_OK(wetdem_sim_enable_model(sim, models[k]));
    return sim;
}

static struct wetdem_sim* two_material_sim(const char* const* models, int n_models)
{
    return materials_sim(models, n_models, true);
}

/* Random particles of both materials near one another, spinning, and a floor; the many
 * state set up (table, kernel choice) without running. */
static void add_particles(struct wetdem_sim* sim, size_t n, unsigned long seed)
{
    gsl_rng* rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, seed);
    for (size_t k = 0; k < n; k++) {
        struct wetdem_particle p = {
            .pos = {2e-3 * gsl_rng_uniform(rng), 2e-3 * gsl_rng_uniform(rng),
                    2e-3 * gsl_rng_uniform(rng)},
            .vel = {gsl_rng_uniform(rng) - 0.5, gsl_rng_uniform(rng) - 0.5,
                    gsl_rng_uniform(rng) - 0.5},
            .omega = {100 * (gsl_rng_uniform(rng) - 0.5), 100 * (gsl_rng_uniform(rng) - 0.5),
                      100 * (gsl_rng_uniform(rng) - 0.5)},
            .radius = 0.3e-3 + 0.2e-3 * gsl_rng_uniform(rng),
            .material = (int)(k % 2)};
        CHECK_OK(wetdem_sim_add_particle(sim, p));
    }
    gsl_rng_free(rng);
    CHECK_OK(wetdem_sim_add_wall(sim, (struct wetdem_vec3){0, 0, 0.2e-3},
                                 (struct wetdem_vec3){0, 0, 1}, 1));
    CHECK_OK(wetdem_sim_set_many(sim, &(struct wetdem_many_settings){.dt = 1e-7, .skin = 1e-4}));
    sim->many->reach = 1.0; /* larger than any range here; set by the first run otherwise */
    CHECK_OK(wetdem_sim_many_setup_kernel(sim));
}

static void check_same_contact(const struct wetdem_contact* a, const struct wetdem_contact* b)
{
    assert_int_equal(a->i, b->i);
    assert_int_equal(a->j, b->j);
    assert_int_equal(a->is_wall, b->is_wall);
    const double fa[] = {a->normal.x,     a->normal.y,        a->normal.z,  a->gap,
                         a->radius_i,     a->radius_j,        a->r_eff,     a->m_eff,
                         a->v_n,          a->v_t.x,           a->v_t.y,     a->v_t.z,
                         a->dt,           a->e_star,          a->g_star,    a->restitution,
                         a->friction_dry, a->friction_lub,    a->roughness, a->film,
                         a->viscosity,    a->surface_tension, a->h_min};
    const double fb[] = {b->normal.x,     b->normal.y,        b->normal.z,  b->gap,
                         b->radius_i,     b->radius_j,        b->r_eff,     b->m_eff,
                         b->v_n,          b->v_t.x,           b->v_t.y,     b->v_t.z,
                         b->dt,           b->e_star,          b->g_star,    b->restitution,
                         b->friction_dry, b->friction_lub,    b->roughness, b->film,
                         b->viscosity,    b->surface_tension, b->h_min};
    assert_memory_equal(fa, fb, sizeof fa);
}

/* The contact from the table equals contact.c's for every pair of particles and every
 * particle with the wall (both materials in every combination). */
static void test_many_contact_matches_contact_c(void** state)
{
    (void)state;
    const char* models[] = {"hertz"};
    struct wetdem_sim* sim = two_material_sim(models, 1);
    add_particles(sim, 12, 3);
    for (size_t i = 0; i < 12; i++) {
        for (size_t j = 0; j < 12; j++) {
            if (j == i)
                continue;
            struct wetdem_contact fast, ref;
            wetdem_sim_many_contact(sim, i, j, false, &fast);
            wetdem_sim_build_contact(sim, i, j, false, &ref);
            check_same_contact(&fast, &ref);
        }
        struct wetdem_contact fast, ref;
        wetdem_sim_many_contact(sim, i, 0, true, &fast);
        wetdem_sim_build_contact(sim, i, 0, true, &ref);
        check_same_contact(&fast, &ref);
    }
    wetdem_sim_free(sim);
}

/* Evaluates contact c with history h through both paths and requires identical bits. The
 * fused path must also leave identical histories. */
static void check_fused_equals_generic(struct wetdem_sim* sim, const struct wetdem_contact* c,
                                       const double* history)
{
    struct wetdem_contact cf = *c, cg = *c;
    double hf[64], hg[64];
    memcpy(hf, history, sim->history_len * sizeof(double));
    memcpy(hg, history, sim->history_len * sizeof(double));
    struct wetdem_pair_force of, og, pf[WETDEM_MAX_MODELS], pg[WETDEM_MAX_MODELS];
    memset(pf, 0, sizeof pf);
    memset(pg, 0, sizeof pg);
    int mb = c->is_wall ? sim->walls[c->j].material : sim->particles[c->j].material;
    const struct wetdem_many_mix* x = wetdem_sim_many_mix(sim, sim->particles[c->i].material, mb);
    int sf = wetdem_sim_many_eval_fused(sim, &cf, x, sim->history_len ? hf : NULL, &of, pf);
    int sg = wetdem_sim_eval_contact(sim, &cg, sim->history_len ? hg : NULL, &og, pg);
    assert_int_equal(sf, sg);
    assert_memory_equal(&of, &og, sizeof of);
    assert_memory_equal(pf, pg, sim->n_models * sizeof pf[0]);
    assert_memory_equal(hf, hg, sim->history_len * sizeof(double));
    assert_memory_equal(&cf.h_min, &cg.h_min, sizeof cf.h_min);
    /* without per-model output (the models add straight into the sum) */
    struct wetdem_contact cn = *c;
    double hn[64];
    memcpy(hn, history, sim->history_len * sizeof(double));
    struct wetdem_pair_force on;
    int sn = wetdem_sim_many_eval_fused(sim, &cn, x, sim->history_len ? hn : NULL, &on, NULL);
    assert_int_equal(sn, sg);
    assert_memory_equal(&on, &og, sizeof on);
    assert_memory_equal(hn, hg, sim->history_len * sizeof(double));
}

/* Gaps spanning every branch: deep and shallow overlap (sticking and sliding Mindlin springs,
 * clipped and unclipped Hertz damping), below h_min (c and nc), inside the film, at the film
 * edge and beyond; approaching and separating; for walls too. */
static void sweep_branches(struct wetdem_sim* sim, size_t* n_checked)
{
    const double gaps[] = {-20e-6, -2e-6,     -1e-9, 0.0,   0.5e-6, 1e-6,
                           5e-6,   29.999e-6, 30e-6, 40e-6, 41e-6};
    const double springs[] = {0.0, 1e-7, 5e-6}; /* fresh, sticking, sliding */
    for (size_t i = 0; i < 6; i++)
        for (size_t j = 0; j < 7; j++) {
            if (j == i)
                continue;
            bool wall = j == 6;
            struct wetdem_contact c;
            wetdem_sim_many_contact(sim, i, wall ? 0 : j, wall, &c);
            c.dt = 1e-6;
            for (size_t g = 0; g < sizeof gaps / sizeof gaps[0]; g++)
                for (size_t s = 0; s < 3; s++)
                    for (int sign = -1; sign <= 1; sign += 2) {
                        struct wetdem_contact cc = c;
                        cc.gap = gaps[g];
                        cc.v_n = sign * fabs(c.v_n);
                        double h[64] = {0};
                        for (size_t k = 0; k < sim->history_len; k++)
                            h[k] = springs[s] * (k % 3 == 0 ? 1.0 : 0.3);
                        check_fused_equals_generic(sim, &cc, h);
                        (*n_checked)++;
                    }
        }
}

static void test_many_fused_kernel_equals_generic(void** state)
{
    (void)state;
    /* every subset order and option the fused kernel distinguishes */
    const char* sets[][4] = {{"hertz", "mindlin", "sb", "capillary"},
                             {"capillary", "sb", "mindlin", "hertz"},
                             {"hertz", "mindlin", NULL, NULL},
                             {"sb", "capillary", NULL, NULL}};
    const int counts[] = {4, 4, 2, 2};
    size_t n_checked = 0;
    for (int s = 0; s < 4; s++)
        for (int option = 0; option < 2; option++) {
            struct wetdem_sim* sim = two_material_sim(sets[s], counts[s]);
            const char* hertz = option ? "tsuji" : "exact";
            const char* mindlin = option ? "lubricated" : "dry";
            const char* below = option ? "nc" : "c";
            for (int k = 0; k < counts[s]; k++) {
                if (!strcmp(sets[s][k], "hertz"))
                    CHECK_OK(wetdem_sim_set_param_str(sim, "hertz.damping", hertz));
                if (!strcmp(sets[s][k], "mindlin"))
                    CHECK_OK(wetdem_sim_set_param_str(sim, "mindlin.friction", mindlin));
                if (!strcmp(sets[s][k], "sb"))
                    CHECK_OK(wetdem_sim_set_param_str(sim, "sb.below_hmin", below));
            }
            add_particles(sim, 6, 11 + (unsigned long)s);
            assert_true(sim->many->fused);
            sweep_branches(sim, &n_checked);
            wetdem_sim_free(sim);
        }
    assert_true(n_checked > 10000); /* 8 set-ups x 36 pairs x 11 gaps x 3 springs x 2 signs */
}

/* The precomputed-coefficient kernels the fused path calls (wetdem_force_hertz_damping_with,
 * wetdem_force_mindlin_update_with) give the same bits as the kernels that compute the
 * coefficient per call, over restitutions spanning the exact table (1e-6 <= e < 1), the
 * strong-damping closed form below it, e = 1 (no damping), both Hertz forms, sticking and
 * sliding springs, and overlaps on both sides of zero. */
static void test_many_precomputed_damping_is_bit_identical(void** state)
{
    (void)state;
    const double es[] = {1e-9, 3e-7, 1e-6, 0.01, 0.3, 0.5, 0.77, 0.95, 0.999999, 1.0};
    const double overlaps[] = {-1e-6, 0.0, 1e-9, 2e-6, 5e-5};
    size_t n_checked = 0;
    for (size_t k = 0; k < sizeof es / sizeof es[0]; k++)
        for (size_t o = 0; o < sizeof overlaps / sizeof overlaps[0]; o++) {
            double e = es[k], d = overlaps[o];
            for (int form = 0; form < 2; form++) {
                double c = wetdem_force_hertz_damping_coefficient(e, form);
                double want = wetdem_force_hertz_damping(1e9, 4.7e-4, 3.1e-5, d, -0.37, e, form);
                double got = wetdem_force_hertz_damping_with(c, 1e9, 4.7e-4, 3.1e-5, d, -0.37);
                assert_memory_equal(&got, &want, sizeof got);
                n_checked++;
            }
            struct wetdem_contact c = {.normal = {0, 0.6, 0.8},
                                       .v_t = {0.3, 0.08, -0.06},
                                       .g_star = 4e8,
                                       .r_eff = 4.7e-4,
                                       .m_eff = 3.1e-5,
                                       .restitution = e,
                                       .dt = 1e-6};
            for (int slide = 0; slide < 2; slide++) {
                double mu = slide ? 0.01 : 10.0; /* 0.01: capped; 10: sticking */
                double s_ref[3] = {1e-7, -2e-8, 3e-8}, s_new[3] = {1e-7, -2e-8, 3e-8};
                struct wetdem_vec3 want = wetdem_force_mindlin_update(&c, d, 0.2, mu, s_ref, NULL);
                struct wetdem_vec3 got = wetdem_force_mindlin_update_with(
                    &c, d, 0.2, mu, wetdem_force_mindlin_damping_factor(e), s_new, NULL);
                assert_memory_equal(&got, &want, sizeof got);
                assert_memory_equal(s_new, s_ref, sizeof s_ref);
                n_checked++;
            }
        }
    assert_int_equal(n_checked, 10 * 5 * 4);
    /* invalid restitution: NAN, as the per-call kernel */
    assert_true(isnan(wetdem_force_hertz_damping_coefficient(0.0, 0)));
    assert_true(isnan(wetdem_force_hertz_damping_coefficient(1.5, 1)));
    assert_true(isnan(wetdem_force_hertz_damping_coefficient(0.5, 2)));
}

/* A set with a model outside the fused set (reynolds) takes the generic path. */
static void test_many_unfused_set_uses_generic_path(void** state)
{
    (void)state;
    const char* models[] = {"hertz", "reynolds"};
    struct wetdem_sim* sim = two_material_sim(models, 2);
    add_particles(sim, 4, 5);
    assert_false(sim->many->fused);
    wetdem_sim_free(sim);
}

/* A wet granular gas of two materials in a box periodic in x and y (floor and lid), with the
 * four models of the lean kernel in the order `models`. */
static struct wetdem_sim* wet_gas_of(const char* const models[4], bool generic_only, bool budget)
{
    struct wetdem_sim* sim = two_material_sim(models, 4);
    struct wetdem_insert_spec spec = {.layout = WETDEM_INSERT_RANDOM,
                                      .n = 150,
                                      .lo = {0, 0, 0},
                                      .hi = {6e-3, 6e-3, 8e-3},
                                      .periodic = {true, true, false},
                                      .radius_min = 0.4e-3,
                                      .radius_max = 0.5e-3,
                                      .velocity_sigma = 0.2,
                                      .seed = 9};
    CHECK_OK(wetdem_sim_insert(sim, &spec));
    size_t n;
    struct wetdem_particle* p = wetdem_sim_particles(sim, &n);
    for (size_t k = 0; k < n; k += 3) { /* a third of the other material: mixed pairs */
        p[k].material = 1;
        p[k].mass *= 7800.0 / 2500.0;
    }
    CHECK_OK(
        wetdem_sim_add_wall(sim, (struct wetdem_vec3){0, 0, 0}, (struct wetdem_vec3){0, 0, 1}, 1));
    CHECK_OK(wetdem_sim_add_wall(sim, (struct wetdem_vec3){0, 0, 8e-3},
                                 (struct wetdem_vec3){0, 0, -1}, 0));
    CHECK_OK(wetdem_sim_set_param(sim, "sim.gravity_z", -9.81));
    struct wetdem_many_settings s = {.periodic = {true, true, false},
                                     .box_lo = {0, 0, 0},
                                     .box_hi = {6e-3, 6e-3, 8e-3},
                                     .dt = 2e-6,
                                     .skin = 0.05e-3,
                                     .energy_budget = budget};
    CHECK_OK(wetdem_sim_set_many(sim, &s));
    sim->many->generic_only = generic_only;
    sim->many->parallel_min = 1; /* run the parallel loops even for this small system */
    return sim;
}

static struct wetdem_sim* wet_gas(bool generic_only, bool budget)
{
    const char* const models[] = {"hertz", "mindlin", "sb", "capillary"};
    return wet_gas_of(models, generic_only, budget);
}

/* Whole runs: the lean kernel against generic (with and without the energy budget, whose
 * per-model forces go through a separate branch), on 1 and 3 threads. */
static void test_many_fused_run_equals_generic_run(void** state)
{
    (void)state;
    int saved = omp_get_max_threads();
    for (int budget = 0; budget < 2; budget++) {
        struct wetdem_sim* fused = wet_gas(false, budget);
        struct wetdem_sim* generic = wet_gas(true, budget);
        struct wetdem_sim* fused3 = wet_gas(false, budget);
        omp_set_num_threads(1);
        CHECK_OK(wetdem_sim_integrate(fused, 0.6e-3));
        CHECK_OK(wetdem_sim_integrate(generic, 0.6e-3));
        omp_set_num_threads(3);
        CHECK_OK(wetdem_sim_integrate(fused3, 0.6e-3));
        omp_set_num_threads(saved);
        assert_true(fused->many->fused);
        assert_false(generic->many->fused);
        /* the lean kernel runs with and without the budget (sim_many_force.c): with it, each
           model's work from its terms must equal the generic interface's bit for bit */
        assert_true(fused->many->lean.on);
        assert_false(generic->many->lean.on);
        test_check_same_particles(fused, generic);
        test_check_same_particles(fused, fused3);
        struct wetdem_many_stats s;
        CHECK_OK(wetdem_sim_many_stats(fused, &s));
        assert_true(s.contacts > 0 && s.bridges > 0); /* contact and film branches were run */
        if (budget) {
            struct wetdem_energy_budget bf, bg, b3;
            CHECK_OK(wetdem_sim_energy_budget(fused, &bf));
            CHECK_OK(wetdem_sim_energy_budget(generic, &bg));
            CHECK_OK(wetdem_sim_energy_budget(fused3, &b3));
            assert_memory_equal(bf.work_pair, bg.work_pair, sizeof bf.work_pair);
            assert_memory_equal(bf.work_wall, bg.work_wall, sizeof bf.work_wall);
            /* (the work's sums do not depend on the blocks: the same on 3 threads) */
            assert_memory_equal(bf.work_pair, b3.work_pair, sizeof bf.work_pair);
            assert_memory_equal(bf.work_wall, b3.work_wall, sizeof bf.work_wall);
        }
        wetdem_sim_free(fused);
        wetdem_sim_free(generic);
        wetdem_sim_free(fused3);
    }
}

/* With a min-separation record (ehd, reset_ratio 1: up to R* ~ 0.22 mm, beyond the 20 um
 * films), the fused kernel evaluates a pair beyond the films from the part of its contact the
 * model reads (sim_many_force.c record_only), the generic path from the whole contact: whole
 * runs end bit-identical, the particles and every pair's history and flags, also on 3
 * threads. The lean kernel, which does not evaluate the model, is off; some pair apart beyond
 * the films (no bridge) holds a live record. */
static void test_many_record_beyond_the_films_equals_generic(void** state)
{
    (void)state;
    int saved = omp_get_max_threads();
    struct wetdem_sim* sims[3];
    for (int k = 0; k < 3; k++) {
        sims[k] = wet_gas(k == 1, false);
        CHECK_OK(wetdem_sim_enable_model(sims[k], "ehd"));
        omp_set_num_threads(k == 2 ? 3 : 1);
        CHECK_OK(wetdem_sim_integrate(sims[k], 0.6e-3));
    }
    omp_set_num_threads(saved);
    const struct wetdem_many *a = sims[0]->many, *b = sims[1]->many;
    assert_true(a->fused && a->record && !a->lean.on && !b->fused);
    size_t len = sims[0]->history_len, live = 0;
    for (int k = 1; k < 3; k++) {
        const struct wetdem_many* o = sims[k]->many;
        test_check_same_particles(sims[0], sims[k]);
        assert_int_equal(a->cl.n_pairs, o->cl.n_pairs);
        assert_memory_equal(a->cl.pairs, o->cl.pairs, a->cl.n_pairs * sizeof a->cl.pairs[0]);
        assert_memory_equal(a->history, o->history, a->cl.n_pairs * len * sizeof(double));
        assert_memory_equal(a->flags, o->flags, a->cl.n_pairs);
    }
    for (size_t q = 0; q < a->cl.n_pairs; q++)
        live += a->flags[q] == WETDEM_MANY_DIRTY && a->history[q * len] > 0;
    assert_true(live > 0);
    for (int k = 0; k < 3; k++)
        wetdem_sim_free(sims[k]);
}

/* A min-separation model of the user's own that keeps a record out to R* and reads the
 * reduced mass, which the partial contact of the fused kernel's record_only does not fill: the
 * largest approach momentum m* v_n of the encounter; h_min 1 um. */
static double momentum_min_separation(const void* params, const struct wetdem_contact* c,
                                      double* history)
{
    (void)params;
    double p = c->m_eff * c->v_n;
    history[0] = p > history[0] ? p : history[0];
    return 1e-6;
}

static double momentum_record_range(const void* params, const struct wetdem_contact* c)
{
    (void)params;
    return c->r_eff;
}

static const struct wetdem_param_desc no_params[] = {{0}};

static const struct wetdem_model momentum_model = {
    .name = "test_momentum",
    .kind = WETDEM_MODEL_MIN_SEPARATION,
    .summary = "h_min 1 um, a record of the largest m* v_n out to R*",
    .doc = "",
    .equations = "",
    .params = no_params,
    .history_len = 1,
    .min_separation = momentum_min_separation,
    .record_range = momentum_record_range,
};

/* With a min-separation model of the user's that keeps a record beyond the force range, the
 * fused kernel gives a pair there its whole contact, as the generic path does: the runs end
 * bit-identical, histories included (the part of the contact that suffices for wetdem's own
 * models left m* at 0, and with it this record). */
static void test_many_user_record_equals_generic(void** state)
{
    (void)state;
    struct wetdem_sim* sims[2];
    for (int k = 0; k < 2; k++) {
        sims[k] = wet_gas(k == 1, false);
        CHECK_OK(wetdem_sim_add_model(sims[k], &momentum_model, NULL));
        CHECK_OK(wetdem_sim_integrate(sims[k], 0.6e-3));
    }
    const struct wetdem_many *a = sims[0]->many, *b = sims[1]->many;
    assert_true(a->fused && a->record && !a->record_partial && !b->fused);
    test_check_same_particles(sims[0], sims[1]);
    assert_int_equal(a->cl.n_pairs, b->cl.n_pairs);
    size_t len = sims[0]->history_len;
    assert_memory_equal(a->history, b->history, a->cl.n_pairs * len * sizeof(double));
    for (int k = 0; k < 2; k++)
        wetdem_sim_free(sims[k]);
}

/* Runs the lean and the generic simulation to time t, checks that the first ran the lean
 * kernel and the second not, and that they end bit-identical; returns the lean run's stats. */
static struct wetdem_many_stats lean_equals_generic(struct wetdem_sim* lean,
                                                    struct wetdem_sim* generic, double t)
{
    CHECK_OK(wetdem_sim_integrate(lean, t));
    CHECK_OK(wetdem_sim_integrate(generic, t));
    assert_true(lean->many->lean.on);
    assert_false(generic->many->lean.on);
    test_check_same_particles(lean, generic);
    struct wetdem_many_stats s;
    CHECK_OK(wetdem_sim_many_stats(lean, &s));
    return s;
}

/* The lean kernel sums the two film terms of a pair apart directly, whatever the model order
 * (the Hertz term there is +0, and two terms commute), and adds no torques for it: whole runs
 * with the models in reverse order equal the generic interface's bit for bit. */
static void test_many_lean_run_any_model_order(void** state)
{
    (void)state;
    const char* const reverse[] = {"capillary", "sb", "mindlin", "hertz"};
    struct wetdem_sim* lean = wet_gas_of(reverse, false, false);
    struct wetdem_sim* generic = wet_gas_of(reverse, true, false);
    struct wetdem_many_stats s = lean_equals_generic(lean, generic, 0.6e-3);
    assert_true(s.contacts > 0 && s.bridges > 0); /* both paths of the lean kernel were run */
    wetdem_sim_free(lean);
    wetdem_sim_free(generic);
}

/* The lean kernel resets the tangential spring of a pair apart only when its flags say the
 * spring may be set (WETDEM_MANY_SPRING: set in contact, kept across list rebuilds); the
 * generic interface resets it always. A longer run, with many rebuilds and pairs that touch,
 * part and touch again, must still equal the generic one bit for bit (it would not if a spring
 * kept across a rebuild were left standing after its pair parted). */
static void test_many_lean_springs_across_rebuilds(void** state)
{
    (void)state;
    struct wetdem_sim* lean = wet_gas(false, false);
    struct wetdem_sim* generic = wet_gas(true, false);
    struct wetdem_many_stats s = lean_equals_generic(lean, generic, 4e-3);
    assert_true(s.list_builds >= 20);
    wetdem_sim_free(lean);
    wetdem_sim_free(generic);
}

/* The lean kernel's per-pair constants (R*, m*, Hertz stiffness and damping) come from a
 * table computed once per list build and kernel set-up: masses and radii changed between two
 * runs must reach it. The same change in a lean and a generic run keeps them bit-identical. */
static void test_many_lean_constants_follow_changed_particles(void** state)
{
    (void)state;
    struct wetdem_sim* lean = wet_gas(false, false);
    struct wetdem_sim* generic = wet_gas(true, false);
    CHECK_OK(wetdem_sim_integrate(lean, 0.3e-3));
    CHECK_OK(wetdem_sim_integrate(generic, 0.3e-3));
    struct wetdem_sim* sims[] = {lean, generic};
    for (int s = 0; s < 2; s++) {
        size_t n;
        struct wetdem_particle* p = wetdem_sim_particles(sims[s], &n);
        for (size_t k = 0; k < n; k += 2) { /* heavier and slightly smaller: new m*, R*, k */
            p[k].mass *= 3.0;
            p[k].radius *= 0.97;
        }
    }
    struct wetdem_many_stats st = lean_equals_generic(lean, generic, 0.6e-3);
    assert_true(st.contacts > 0); /* the changed constants were used in contacts */
    wetdem_sim_free(lean);
    wetdem_sim_free(generic);
}

/* The force pass's blocks and the kick-drift pass's ranges may be cut anywhere (both are
 * balanced by timing, which varies from run to run): the sum order of every particle does not
 * depend on the blocks, and each particle's kick and drift is its own, so runs with blocks cut
 * at random, re-cut at every list build, and ranges cut at random at every pass equal the run
 * on one thread bit for bit. */
static void test_many_block_and_kick_cuts_do_not_change_the_result(void** state)
{
    (void)state;
    int saved = omp_get_max_threads();
    struct wetdem_sim* one = wet_gas(false, false);
    omp_set_num_threads(1);
    CHECK_OK(wetdem_sim_integrate(one, 0.6e-3));
    for (int threads = 2; threads <= 4; threads++) {
        struct wetdem_sim* cut = wet_gas(false, false);
        cut->many->block_jitter = (uint64_t)threads * 977;
        cut->many->kick_jitter = (uint64_t)threads * 131;
        cut->many->no_drift_in_pass = true; /* (the kick-drift pass, cut anew, at every step) */
        omp_set_num_threads(threads);
        CHECK_OK(wetdem_sim_integrate(cut, 0.6e-3));
        assert_true(cut->many->n_blocks == (size_t)threads);
        assert_true(cut->many->kick_threads == (size_t)threads); /* (the ranges were used) */
        test_check_same_particles(one, cut);
        wetdem_sim_free(cut);
    }
    omp_set_num_threads(saved);
    wetdem_sim_free(one);
}

/* The kick-drift pass gives each thread a share of the particles in proportion to the speed at
 * which it updated its range before: with thread 1 measured three times as fast as thread 0,
 * the next pass cuts at a quarter of the particles; with a thread measured as stopped, no range
 * falls below an eighth of an equal share. */
static void test_many_kick_ranges_follow_the_threads_speed(void** state)
{
    (void)state;
    int saved = omp_get_max_threads();
    omp_set_num_threads(2);
    struct wetdem_sim* sim = wet_gas(false, false);
    CHECK_OK(wetdem_sim_integrate(sim, 2e-6)); /* (set-up and a first pass) */
    struct wetdem_many* m = sim->many;
    size_t n = sim->n_particles;
    assert_true(m->kick_threads == 2 && m->kick_n == n);
    m->kick_speed[0] = 1e6;
    m->kick_speed[1] = 3e6;
    CHECK_OK(wetdem_sim_integrate(sim, 4e-6));
    assert_int_equal(m->kick_cut[1], (size_t)((double)n * 0.25)); /* the speeds' share */
    m->kick_speed[0] = 1e-30;
    m->kick_speed[1] = 1e6;
    CHECK_OK(wetdem_sim_integrate(sim, 6e-6));
    assert_int_equal(m->kick_cut[1], n / 16); /* the least range */
    assert_int_equal(m->kick_cut[2], n);
    wetdem_sim_free(sim);
    omp_set_num_threads(saved);
}

/* The contacts, bridges and agglomerates sim reports (wetdem_sim_many_links) into *s, and each
 * particle's contacts (the VTK files') into a new array of n_particles entries. */
static uint32_t* reported_links(const struct wetdem_sim* sim, struct wetdem_many_stats* s)
{
    uint32_t* per_particle = malloc((sim->n_particles ? sim->n_particles : 1) * sizeof(uint32_t));
    assert_non_null(per_particle);
    *s = (struct wetdem_many_stats){0};
    CHECK_OK(wetdem_sim_many_links(
        sim, &(struct wetdem_many_per_particle){.contacts = per_particle}, s));
    return per_particle;
}

/* Runs a and b are bit-identical: particles, every candidate pair's flags over the same list
 * (what the next pass reads of the latest one), and what they report of the state: contacts,
 * bridges and agglomerates, and each particle's contacts. */
static void same_run(const struct wetdem_sim* a, const struct wetdem_sim* b)
{
    test_check_same_particles(a, b);
    assert_int_equal(a->many->cl.n_pairs, b->many->cl.n_pairs);
    assert_memory_equal(a->many->cl.pairs, b->many->cl.pairs,
                        a->many->cl.n_pairs * sizeof *a->many->cl.pairs);
    assert_memory_equal(a->many->flags, b->many->flags, a->many->cl.n_pairs);
    struct wetdem_many_stats sa, sb;
    uint32_t* ca = reported_links(a, &sa);
    uint32_t* cb = reported_links(b, &sb);
    assert_int_equal(sa.contacts, sb.contacts);
    assert_int_equal(sa.bridges, sb.bridges);
    assert_int_equal(sa.agglomerates, sb.agglomerates);
    CHECK_ABS(sa.mean_agglomerate, sb.mean_agglomerate, 0);
    assert_memory_equal(ca, cb, a->n_particles * sizeof *ca);
    free(ca);
    free(cb);
}

/* The gap test skips a candidate until the skip clock (the sum of every step's bound on the
 * displacements, many.h) says it may have come within reach; a skipped candidate would have
 * been rejected, so runs with and without skipping are bit-identical: in a flowing gas with
 * the skip times kept at every pass, with the default choice (here with the times dropped
 * unless half of the candidates are skipped, which drops them after the first passes of a
 * list, as too few candidates are), and the same spheres from rest; and with the candidates
 * whose time has come tested and evaluated in one loop (fused, where those within range keep
 * their old times, many.h) instead of a gap test and the kernels over its list. Between calls
 * the user may move particles: the run then tests every candidate at its first pass. Here the
 * first particle of the nearest skipped candidate is moved, between calls, to within its
 * reach (less than skin/2: no list rebuild); the runs with skipping must see it at once. Last,
 * the clock is restarted often. */
static void test_many_skipped_candidates_change_no_result(void** state)
{
    (void)state;
    int saved = omp_get_max_threads();
    omp_set_num_threads(2);
    struct wetdem_sim* skip = wet_gas(false, false);
    struct wetdem_sim* by_default = wet_gas(false, false);
    struct wetdem_sim* test_all = wet_gas(false, false);
    struct wetdem_sim* fused = wet_gas(false, false);
    skip->many->skip_always = true;
    skip->many->fuse_mode = 1;        /* the gap test, then the kernels over its list */
    by_default->many->skip_share = 2; /* dropped unless half are skipped: in this gas, often */
    test_all->many->no_skip = true;
    fused->many->skip_always = true;
    fused->many->fuse_mode = 2; /* tested and evaluated in one loop whenever the times are usable */
    struct wetdem_sim* sims[] = {skip, by_default, test_all, fused};
    enum { NS = 4 };
    for (int s = 0; s < NS; s++)
        CHECK_OK(wetdem_sim_integrate(sims[s], 1e-3));
    same_run(skip, test_all);
    same_run(by_default, test_all);
    same_run(fused, test_all);
    assert_int_equal(skip->many->fused_passes, 0);
    assert_true(fused->many->fused_passes > 0);
    /* short calls, the flags compared after each: a pair leaving its range in the last
       passes of a call loses them at once */
    double t_call = 1e-3;
    for (int call = 0; call < 40; call++) {
        t_call += 6 * 2e-6;
        for (int s = 0; s < NS; s++)
            CHECK_OK(wetdem_sim_integrate(sims[s], t_call));
        same_run(skip, test_all);
        same_run(fused, test_all);
    }
    struct wetdem_many* m = skip->many;
    assert_true(m->skipped_tests > by_default->many->skipped_tests);
    assert_true(by_default->many->skipped_tests > 0);
    for (int s = 0; s < NS; s++) { /* from rest */
        size_t n;
        struct wetdem_particle* ps = wetdem_sim_particles(sims[s], &n);
        for (size_t k = 0; k < n; k++)
            ps[k].vel = ps[k].omega = vec3(0, 0, 0);
    }
    double t = t_call + 20 * 2e-6;
    for (int s = 0; s < NS; s++)
        CHECK_OK(wetdem_sim_integrate(sims[s], t));
    same_run(skip, test_all);
    same_run(fused, test_all);
    assert_true(m->skip_on && m->skip_ready && m->pass_skipped > 0); /* the times are used */
    assert_int_equal(test_all->many->skipped_tests, 0);
    /* the skipped candidate closest to the gap test's reach */
    size_t n, best = SIZE_MAX;
    const struct wetdem_particle* p = wetdem_sim_particles_const(skip, &n);
    double best_beyond = INFINITY;
    for (size_t q = 0; q < m->cl.n_pairs; q++) {
        if (!(m->drift_clock < m->skip_until[q]))
            continue;
        struct wetdem_celllist_pair pq = m->cl.pairs[q];
        struct wetdem_vec3 d = celllist_delta(&m->cl.box, p[pq.i].pos, p[pq.j].pos);
        double beyond = vec3_norm(d) - sqrt(m->pair_lim2[q]);
        if (beyond < best_beyond) {
            best_beyond = beyond;
            best = q;
        }
    }
    assert_true(best != SIZE_MAX && best_beyond > 0 && best_beyond < 0.4 * m->cl.skin);
    struct wetdem_celllist_pair pb = m->cl.pairs[best];
    struct wetdem_vec3 d = celllist_delta(&m->cl.box, p[pb.i].pos, p[pb.j].pos);
    struct wetdem_vec3 move = vec3_scale(d, -(best_beyond + 1e-7) / vec3_norm(d)); /* i to j */
    uint64_t builds = m->cl.n_builds;
    for (int s = 0; s < NS; s++) {
        struct wetdem_particle* ps = wetdem_sim_particles(sims[s], &n);
        ps[pb.i].pos = vec3_add(ps[pb.i].pos, move);
    }
    t += 2e-6; /* one step: without a list build, the run must see the move */
    for (int s = 0; s < NS; s++)
        CHECK_OK(wetdem_sim_integrate(sims[s], t));
    assert_true(m->cl.n_builds == builds);
    assert_true(m->flags[best] & WETDEM_MANY_ACTIVE); /* the moved pair came within range */
    same_run(skip, test_all);
    same_run(fused, test_all);
    for (int call = 1; call <= 4; call++) /* and several calls */
        for (int s = 0; s < NS; s++)
            CHECK_OK(wetdem_sim_integrate(sims[s], t + call * 0.25e-3));
    same_run(skip, test_all);
    same_run(by_default, test_all);
    same_run(fused, test_all);
    /* the clock restarted often (its limit lowered from the skin): every restart makes the
       next pass test every candidate, and the run stays bit-identical */
    skip->many->clock_limit = 0.02 * m->cl.skin;
    uint64_t restarts = m->clock_restarts, skipped = m->skipped_tests;
    fused->many->clock_limit = skip->many->clock_limit;
    uint64_t fused_restarts = fused->many->clock_restarts, fused_passes = fused->many->fused_passes;
    for (int s = 0; s < NS; s++)
        if (sims[s] != by_default)
            CHECK_OK(wetdem_sim_integrate(sims[s], t + 1.5e-3));
    assert_true(m->clock_restarts > restarts + 10 && m->skipped_tests > skipped);
    assert_true(fused->many->clock_restarts > fused_restarts + 10 &&
                fused->many->fused_passes > fused_passes);
    same_run(skip, test_all);
    same_run(fused, test_all);
    omp_set_num_threads(saved);
    for (int s = 0; s < NS; s++)
        wetdem_sim_free(sims[s]);
}

/* A wet pile settling in a closed box, or with `periodic` in a box periodic in x and y with a
 * floor and a lid, one material (the case where the pass evaluates four pairs at a time,
 * many_bulk.h), with the skip times always kept, the pass
 * in one loop, two or as chosen (many.h fuse_mode 2, 1, 0), and the given choice of the
 * four-at-a-time version: never (`bulk_off`, the scalar kernel), or version `isa` (many.h
 * bulk_off, bulk_isa). */
static struct wetdem_sim* wet_pile_in(const char* const* models, int n_models, bool nc,
                                      int fuse_mode, bool bulk_off, enum wetdem_many_bulk_isa isa,
                                      bool periodic)
{
    struct wetdem_sim* sim = materials_sim(models, n_models, false);
    if (nc)
        CHECK_OK(wetdem_sim_set_param_str(sim, "sb.below_hmin", "nc"));
    double hi[3] = {5e-3, 5e-3, 10e-3};
    struct wetdem_insert_spec spec = {.layout = WETDEM_INSERT_RANDOM,
                                      .n = 200,
                                      .lo = {0, 0, 0},
                                      .hi = {hi[0], hi[1], hi[2]},
                                      .radius_min = 0.4e-3,
                                      .radius_max = 0.5e-3,
                                      .velocity_sigma = 0.2,
                                      .periodic = {periodic, periodic, false},
                                      .seed = 5};
    CHECK_OK(wetdem_sim_insert(sim, &spec));
    for (int w = periodic ? 4 : 0; w < 6; w++) {
        struct wetdem_vec3 point = {w == 1 ? hi[0] : 0, w == 3 ? hi[1] : 0, w == 5 ? hi[2] : 0};
        struct wetdem_vec3 normal = {w == 0   ? 1
                                     : w == 1 ? -1
                                              : 0,
                                     w == 2   ? 1
                                     : w == 3 ? -1
                                              : 0,
                                     w == 4   ? 1
                                     : w == 5 ? -1
                                              : 0};
        CHECK_OK(wetdem_sim_add_wall(sim, point, normal, 0));
    }
    CHECK_OK(wetdem_sim_set_param(sim, "sim.gravity_z", -9.81));
    struct wetdem_many_settings s = {.periodic = {periodic, periodic, false},
                                     .box_lo = {0, 0, 0},
                                     .box_hi = {hi[0], hi[1], hi[2]},
                                     .dt = 2e-6,
                                     .skin = 0.05e-3};
    CHECK_OK(wetdem_sim_set_many(sim, &s));
    sim->many->parallel_min = 1; /* run the parallel loops even for this small system */
    sim->many->skip_always = true;
    sim->many->fuse_mode = fuse_mode;
    sim->many->bulk_off = bulk_off;
    sim->many->bulk_isa = isa;
    return sim;
}

/* wet_pile_in in the closed box. */
static struct wetdem_sim* wet_pile(const char* const* models, int n_models, bool nc, int fuse_mode,
                                   bool bulk_off, enum wetdem_many_bulk_isa isa)
{
    return wet_pile_in(models, n_models, nc, fuse_mode, bulk_off, isa, false);
}

/* The next step's kicks and drifts applied by the force pass, block by block (many.h
 * WETDEM_MANY_END_STEP), are the kick-drift pass's arithmetic on complete forces: runs with
 * them and runs with the kick-drift pass at every step are bit-identical, on 1 to 3 threads,
 * in several calls (each ends with a step whose state is read, so without them), with a fixed
 * particle, in a periodic gas of two materials (the scalar kernel) and in a closed box of one
 * (four pairs at a time). */
static void test_many_drift_in_the_force_pass_changes_no_result(void** state)
{
    (void)state;
    static const char* const all[] = {"hertz", "mindlin", "sb", "capillary"};
    int saved = omp_get_max_threads();
    for (int fixture = 0; fixture < 2; fixture++)
        for (int threads = 1; threads <= 3; threads++) {
            omp_set_num_threads(threads);
            struct wetdem_sim* sims[2];
            for (int k = 0; k < 2; k++) {
                sims[k] = fixture ? wet_pile(all, 4, false, 0, false, WETDEM_MANY_BULK_BEST)
                                  : wet_gas(false, false);
                struct wetdem_particle* p3 = &wetdem_sim_particles(sims[k], NULL)[3];
                *p3 = (struct wetdem_particle){.pos = p3->pos,
                                               .radius = p3->radius,
                                               .mass = p3->mass,
                                               .material = p3->material,
                                               .is_fixed = true}; /* at rest */
                sims[k]->many->no_drift_in_pass = k == 1;
            }
            for (int call = 1; call <= 4; call++) {
                for (int k = 0; k < 2; k++)
                    CHECK_OK(wetdem_sim_integrate(sims[k], call * 0.15e-3));
                same_run(sims[0], sims[1]);
            }
            uint64_t steps = sims[0]->engine.stats.steps;
            assert_true(sims[0]->many->drift_passes == steps - 4); /* all but each call's last */
            assert_int_equal(sims[1]->many->drift_passes, 0);
            if (fixture)
                assert_true(sims[0]->many->bulk_passes > 0);
            for (int k = 0; k < 2; k++)
                wetdem_sim_free(sims[k]);
        }
    omp_set_num_threads(saved);
}

/* Four pairs at a time (many_bulk.h) in every version the processor runs (the baseline
 * instruction set, AVX2, its AVX-512 encoding, and the one chosen by default) give runs
 * bit-identical to the scalar kernel's, in one loop and in two, with
 * and without mindlin (whose springs are reset apart, and rotated, advanced and capped in
 * contact) and capillary, in either model order, with both treatments of sb below h_min',
 * without film models (dry: contacts only), with either hertz damping form and without hertz,
 * particle-wall pairs apart and in contact too,
 * on 1 and 2 threads (cross pairs, whose lanes are left out), several calls, each compared:
 * particles, pairs, flags and the contacts and bridges reported. */
static void test_many_four_at_a_time_change_no_result(void** state)
{
    (void)state;
    static const char* const all[] = {"hertz", "mindlin", "sb", "capillary"};
    static const char* const reordered[] = {"capillary", "hertz", "sb", "mindlin"};
    static const char* const sb_only[] = {"hertz", "sb"};
    static const char* const dry[] = {"mindlin", "hertz"};
    static const char* const hertz_only[] = {"hertz"};
    static const char* const no_hertz[] = {"sb", "capillary", "mindlin"};
    struct {
        const char* const* models;
        int n_models;
        bool nc;
        int fuse_mode;       /* 2 one loop, 1 two, 0 as chosen */
        const char* damping; /* hertz.damping, or NULL for the default */
        bool periodic;       /* x and y periodic (the minimum image in the vector kernel) */
    } cases[] = {{all, 4, false, 2, NULL, false},      {all, 4, false, 1, "exact", false},
                 {reordered, 4, true, 2, NULL, false}, {reordered, 4, true, 1, NULL, false},
                 {sb_only, 2, true, 0, NULL, false},   {dry, 2, false, 2, NULL, false},
                 {dry, 2, false, 1, "exact", false},   {hertz_only, 1, false, 0, "tsuji", false},
                 {no_hertz, 3, false, 0, NULL, false}, {all, 4, false, 2, NULL, true},
                 {all, 4, false, 1, NULL, true},       {dry, 2, false, 0, NULL, true}};
    int saved = omp_get_max_threads();
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++)
        for (int threads = 1; threads <= 2; threads++) {
            omp_set_num_threads(threads);
            /* the scalar kernel, then every version the processor runs (BEST: its default) */
            struct wetdem_sim* scalar = NULL;
            struct wetdem_sim* sims[WETDEM_MANY_BULK_AVX512 + 1] = {NULL};
            const int n_isa = WETDEM_MANY_BULK_AVX512 + 1;
            for (int v = -1; v < n_isa; v++) {
                enum wetdem_many_bulk_isa isa =
                    v < 0 ? WETDEM_MANY_BULK_BEST : (enum wetdem_many_bulk_isa)v;
                if (!wetdem_many_bulk_usable(isa))
                    continue;
                struct wetdem_sim* sim =
                    wet_pile_in(cases[c].models, cases[c].n_models, cases[c].nc, cases[c].fuse_mode,
                                v < 0, isa, cases[c].periodic);
                if (cases[c].damping)
                    CHECK_OK(wetdem_sim_set_param_str(sim, "hertz.damping", cases[c].damping));
                *(v < 0 ? &scalar : &sims[v]) = sim;
            }
            for (int call = 1; call <= 8; call++) {
                CHECK_OK(wetdem_sim_integrate(scalar, call * 1e-3));
                for (int v = 0; v < n_isa; v++)
                    if (sims[v]) {
                        CHECK_OK(wetdem_sim_integrate(sims[v], call * 1e-3));
                        same_run(sims[v], scalar);
                    }
            }
            const struct wetdem_many* m = sims[WETDEM_MANY_BULK_BEST]->many;
            uint64_t passes = sims[WETDEM_MANY_BULK_BEST]->engine.stats.force_evals;
            assert_true(m->bulk_passes == passes); /* every pass */
            if (cases[c].fuse_mode == 2)
                assert_true(m->fused_passes > passes / 2);
            if (cases[c].fuse_mode == 1)
                assert_int_equal(m->fused_passes, 0);
            assert_int_equal(scalar->many->bulk_passes, 0);
            assert_int_equal(scalar->many->bulk_contacts, 0);
            assert_int_equal(scalar->many->bulk_walls, 0);
            assert_true(m->bulk_contacts > 1000 && m->bulk_walls > 1000);
            for (int v = 0; v < n_isa; v++) {
                if (!sims[v])
                    continue;
                const struct wetdem_many* u = sims[v]->many;
                assert_true(u->bulk_passes == m->bulk_passes);
                /* contacts four at a time (counted in the blocks' passes, not in the cross
                   pairs'; on two threads the blocks follow measured times, so two runs may cut
                   them apart) */
                assert_true(u->bulk_contacts > 1000);
                if (threads == 1)
                    assert_true(u->bulk_contacts == m->bulk_contacts);
                /* and the particles' walls, on the box's six walls */
                assert_true(u->bulk_walls == m->bulk_walls);
            }
            /* both kinds were met at the end, as the run reports them: the particles'
               contacts sum to twice the pairs in contact plus the particle-wall contacts, which
               the total counts once; with a film model a pair in contact is bridged too, so the
               bridges less the pairs in contact are those apart (docs/many.md, Outputs) */
            struct wetdem_many_stats s;
            uint32_t* per_particle = reported_links(sims[WETDEM_MANY_BULK_BEST], &s);
            size_t ends = 0;
            for (size_t k = 0; k < sims[WETDEM_MANY_BULK_BEST]->n_particles; k++)
                ends += per_particle[k];
            free(per_particle);
            size_t contacts = ends - s.contacts;
            /* (without films the pile rebounds: 9 to 15 contacts remain at the end; those
               during the run are counted above) */
            bool films = cases[c].models != dry && cases[c].models != hertz_only;
            assert_true(contacts > (films ? 10u : 0u));
            assert_true(films ? s.bridges > contacts + 10 : s.bridges == 0);
            wetdem_sim_free(scalar);
            for (int v = 0; v < n_isa; v++)
                wetdem_sim_free(sims[v]);
        }
    omp_set_num_threads(saved);
}

/* With an energy budget the lean kernel gives each model's terms, four pairs at a time too:
 * their work from the vector kernel's film terms and, in solid contact, its hertz term,
 * tangential force and torques, for particle pairs and walls. Whole runs of the wet box, closed and periodic, 1 and 2 threads, through that
 * path, through the scalar kernel alone and through the generic interface: the same
 * particles, flags and work of every model bit for bit, and the same particles as without the
 * budget (the budget only reads the forces). The work is summed per particle in list order,
 * then in fixed chunks of particles (sim_many_force.c collect_pass_work), so it is also the
 * same on 1 and 2 threads, whose blocks are cut by measured times (it was not, with sums per
 * thread). */
static void test_many_budget_four_at_a_time_equals_generic(void** state)
{
    (void)state;
    static const char* const all[] = {"hertz", "mindlin", "sb", "capillary"};
    int saved = omp_get_max_threads();
    struct wetdem_energy_budget one_thread;
    for (int run = 0; run < 4; run++) { /* the closed box, then periodic in x and y */
        int threads = 1 + run % 2;
        bool periodic = run >= 2;
        omp_set_num_threads(threads);
        struct wetdem_sim* sims[4]; /* four at a time, scalar, generic: with the budget; none */
        for (int k = 0; k < 4; k++) {
            sims[k] = wet_pile_in(all, 4, false, 0, k == 1, WETDEM_MANY_BULK_BEST, periodic);
            sims[k]->many->set.energy_budget = k < 3;
            sims[k]->many->generic_only = k == 2;
        }
        for (int call = 1; call <= 4; call++)
            for (int k = 0; k < 4; k++)
                CHECK_OK(wetdem_sim_integrate(sims[k], call * 1e-3));
        const struct wetdem_many* bulk = sims[0]->many;
        assert_true(bulk->bulk_passes == sims[0]->engine.stats.force_evals);
        assert_true(bulk->bulk_contacts > 1000 && bulk->bulk_walls > 1000); /* four at a time */
        assert_true(bulk->lean.on && !sims[2]->many->lean.on);
        struct wetdem_energy_budget b[3];
        for (int k = 0; k < 3; k++) {
            if (k > 0)
                same_run(sims[0], sims[k]);
            CHECK_OK(wetdem_sim_energy_budget(sims[k], &b[k]));
        }
        test_check_same_particles(sims[0], sims[3]);
        if (threads == 1)
            one_thread = b[0];
        assert_memory_equal(b[0].work_pair, one_thread.work_pair, sizeof b[0].work_pair);
        assert_memory_equal(b[0].work_wall, one_thread.work_wall, sizeof b[0].work_wall);
        for (int k = 1; k < 3; k++) {
            assert_memory_equal(b[0].work_pair, b[k].work_pair, sizeof b[0].work_pair);
            assert_memory_equal(b[0].work_wall, b[k].work_wall, sizeof b[0].work_wall);
        }
        /* every model worked on pairs and walls (the films on the walls too) */
        for (int q = 0; q < 4; q++)
            assert_true(b[0].work_pair[q] != 0 && b[0].work_wall[q] != 0);
        for (int k = 0; k < 4; k++)
            wetdem_sim_free(sims[k]);
    }
    omp_set_num_threads(saved);
}

/* The choice of the four-at-a-time version (many.h): each version where the processor runs
 * it, else the baseline (never an instruction the processor lacks); by default the widest
 * usable one; AVX-512 usable only with AVX2. */
static void test_many_bulk_version_choice(void** state)
{
    (void)state;
    assert_true(wetdem_many_bulk_usable(WETDEM_MANY_BULK_BEST));
    assert_true(wetdem_many_bulk_usable(WETDEM_MANY_BULK_BASE));
    bool avx2 = wetdem_many_bulk_usable(WETDEM_MANY_BULK_AVX2),
         avx512 = wetdem_many_bulk_usable(WETDEM_MANY_BULK_AVX512);
    assert_true(!avx512 || avx2);
    assert_true(wetdem_many_bulk_choose(WETDEM_MANY_BULK_BASE) == wetdem_many_bulk_base);
    assert_true(wetdem_many_bulk_choose(WETDEM_MANY_BULK_AVX2) ==
                (avx2 ? wetdem_many_bulk_avx2 : wetdem_many_bulk_base));
    assert_true(wetdem_many_bulk_choose(WETDEM_MANY_BULK_AVX512) ==
                (avx512 ? wetdem_many_bulk_avx512 : wetdem_many_bulk_base));
    assert_true(wetdem_many_bulk_choose(WETDEM_MANY_BULK_BEST) == (avx512 ? wetdem_many_bulk_avx512
                                                                   : avx2 ? wetdem_many_bulk_avx2
                                                                          : wetdem_many_bulk_base));
    assert_true(wetdem_many_bulk_walls_choose(WETDEM_MANY_BULK_BASE) ==
                wetdem_many_bulk_base_walls);
    assert_true(wetdem_many_bulk_walls_choose(WETDEM_MANY_BULK_BEST) ==
                (avx512 ? wetdem_many_bulk_avx512_walls
                 : avx2 ? wetdem_many_bulk_avx2_walls
                        : wetdem_many_bulk_base_walls));
    assert_true(wetdem_many_bulk_walls_choose(WETDEM_MANY_BULK_AVX512) ==
                (avx512 ? wetdem_many_bulk_avx512_walls : wetdem_many_bulk_base_walls));
    /* what the processor says it has, for the record of the run */
    print_message("four-at-a-time versions usable here: baseline%s%s\n", avx2 ? ", AVX2" : "",
                  avx512 ? ", AVX-512" : "");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_many_contact_matches_contact_c),
        cmocka_unit_test(test_many_fused_kernel_equals_generic),
        cmocka_unit_test(test_many_precomputed_damping_is_bit_identical),
        cmocka_unit_test(test_many_unfused_set_uses_generic_path),
        cmocka_unit_test(test_many_fused_run_equals_generic_run),
        cmocka_unit_test(test_many_record_beyond_the_films_equals_generic),
        cmocka_unit_test(test_many_user_record_equals_generic),
        cmocka_unit_test(test_many_lean_run_any_model_order),
        cmocka_unit_test(test_many_lean_springs_across_rebuilds),
        cmocka_unit_test(test_many_lean_constants_follow_changed_particles),
        cmocka_unit_test(test_many_block_and_kick_cuts_do_not_change_the_result),
        cmocka_unit_test(test_many_drift_in_the_force_pass_changes_no_result),
        cmocka_unit_test(test_many_kick_ranges_follow_the_threads_speed),
        cmocka_unit_test(test_many_skipped_candidates_change_no_result),
        cmocka_unit_test(test_many_four_at_a_time_change_no_result),
        cmocka_unit_test(test_many_budget_four_at_a_time_equals_generic),
        cmocka_unit_test(test_many_bulk_version_choice),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

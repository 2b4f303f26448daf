/*
 * test_api_contract.c — the public API under misuse, against the contract of wetdem.h: a NULL
 * name, material, fluid or path is refused (WETDEM_ERR_INVALID with a message, or the "not
 * found" answer of a lookup), never dereferenced; an insertion is whole or nothing, also for
 * counts whose arrays no size_t can measure; a hard-sphere impulse that would give NaN or
 * infinite velocities is an error that leaves the bodies as they were; a fit refuses an
 * infinite scale or tolerance, and takes the defaults for NULL options; a NULL descriptor is
 * refused with a message; a value is formatted whatever the digits asked for, and the text
 * writers follow snprintf (NULL with 0 only counts, the length needed returned); the
 * reports of a many-particle run read particles edited since its latest call as that call
 * would, and refuse those it would refuse.
 */
#include <stdlib.h>
#include <unistd.h>

#include "harness.h"

/* A started many-particle run of one glass sphere (the state the file writers need). */
static struct wetdem_sim* started_many_run(void)
{
    struct wetdem_sim* sim = wetdem_sim_create();
    assert_non_null(sim);
    assert_int_equal(wetdem_sim_add_material_preset(sim, "glass"), 0);
    CHECK_OK(wetdem_sim_add_particle(
        sim, (struct wetdem_particle){.radius = 1e-3, .vel = {0.1, 0, 0}, .material = 0}));
    CHECK_OK(wetdem_sim_enable_model(sim, "hertz"));
    struct wetdem_many_settings ms = {.dt = 1e-6};
    CHECK_OK(wetdem_sim_set_many(sim, &ms));
    CHECK_OK(wetdem_sim_integrate(sim, 1e-5));
    return sim;
}

static void test_api_null_names_materials_fluids_and_paths_are_refused(void** state)
{
    (void)state;
    struct wetdem_fluid f;
    char msg[128] = "";
    assert_int_equal(wetdem_fluid_preset(NULL, &f), WETDEM_ERR_INVALID);
    assert_int_equal(wetdem_fluid_preset("water", NULL), WETDEM_ERR_INVALID);
    assert_int_equal(wetdem_material_validate(NULL, msg, sizeof msg), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(msg, "NULL");
    assert_int_equal(wetdem_fluid_validate(NULL, msg, sizeof msg), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(msg, "NULL");
    assert_true(isnan(wetdem_material_sphere_mass(NULL, 1e-3)));
    /* and the mass the library fills in is this function's, bit for bit */
    struct wetdem_material glass;
    assert_int_equal(wetdem_material_preset("glass", &glass), WETDEM_OK);
    assert_true(wetdem_material_sphere_mass(&glass, 1.1e-3) ==
                glass.density * 4.0 / 3.0 * M_PI * 1.1e-3 * 1.1e-3 * 1.1e-3);
    /* lookups answer as for a name they do not know */
    const struct wetdem_param_desc* settings = wetdem_sim_settings_params();
    assert_null(wetdem_param_find(settings, NULL));
    assert_int_equal(
        wetdem_param_choice_index(wetdem_param_find(settings, "stop_on_separation"), NULL), -1);
    assert_null(wetdem_param_suggest(NULL, wetdem_integrator_names()));
    assert_int_equal(wetdem_abi_sizeof(NULL), 0);

    struct wetdem_sim* sim = started_many_run();
    double v = 0;
    assert_int_equal(wetdem_sim_param(sim, NULL, &v), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "NULL name");
    assert_int_equal(wetdem_sim_param(sim, "sim.gravity_x", NULL), WETDEM_ERR_INVALID);
    assert_int_equal(wetdem_sim_set_integrator(sim, NULL), WETDEM_ERR_INVALID);
    assert_int_equal(wetdem_sim_write_vtk(sim, NULL, false), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "NULL path");
    assert_int_equal(wetdem_sim_write_vtk_links(sim, NULL, false), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "NULL path");
    assert_int_equal(wetdem_sim_write_checkpoint(sim, NULL), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "NULL path");
    assert_int_equal(wetdem_sim_read_checkpoint(sim, NULL), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "NULL path");
    assert_null(wetdem_sim_checkpoint_note(NULL));
    assert_null(wetdem_sim_checkpoint_note(sim)); /* (none restored) */
    double t = 0;
    assert_int_equal(wetdem_output_vtk_frame_time(NULL, &t), WETDEM_ERR_INVALID);
    assert_int_equal(wetdem_output_vtk_frame_time("frame.vtk", NULL), WETDEM_ERR_INVALID);
    CHECK_OK(wetdem_sim_param(sim, "sim.gravity_x", &v)); /* the sim is untouched */
    wetdem_sim_free(sim);
}

static void test_api_insert_is_whole_or_nothing(void** state)
{
    (void)state;
    struct wetdem_sim* sim = wetdem_sim_create();
    assert_int_equal(wetdem_sim_add_material_preset(sim, "glass"), 0);
    CHECK_OK(wetdem_sim_add_particle(sim, (struct wetdem_particle){.radius = 1e-3, .material = 0}));
    /* a count whose particle array wrapped size_t: refused, not written past a small block */
    struct wetdem_insert_spec sp = {
        .layout = WETDEM_INSERT_RANDOM,
        .n = (size_t)1 << 59,
        .lo = {1, 1, 1},
        .hi = {1e100, 1e100, 1e100},
        .radius_min = 1e-3,
        .radius_max = 1e-3,
    };
    assert_int_equal(wetdem_sim_insert(sim, &sp), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "insert.count");
    sp.layout = WETDEM_INSERT_LATTICE;
    assert_int_equal(wetdem_sim_insert(sim, &sp), WETDEM_ERR_INVALID);
    assert_int_equal(wetdem_sim_n_particles(sim), 1);
    /* velocities drawn beyond the doubles: the sphere that has one is refused, and none of
     * the spheres before it stays */
    sp.n = 1000;
    sp.hi = (struct wetdem_vec3){2, 2, 2};
    sp.velocity_sigma = 1e308;
    assert_int_equal(wetdem_sim_insert(sim, &sp), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "must be finite");
    assert_int_equal(wetdem_sim_n_particles(sim), 1);
    sp.velocity_sigma = 1;
    CHECK_OK(wetdem_sim_insert(sim, &sp));
    assert_int_equal(wetdem_sim_n_particles(sim), 1001);
    wetdem_sim_free(sim);
}

static void test_api_format_value_always_writes(void** state)
{
    (void)state;
    char buf[64];
    int digits[] = {-5, 0, 1, 17, 18, 100};
    for (size_t k = 0; k < sizeof digits / sizeof digits[0]; k++) {
        strcpy(buf, "stale");
        wetdem_param_format_value(1.5, digits[k], buf, sizeof buf);
        CHECK_ABS(strtod(buf, NULL), 1.5, 0.0);
    }
    wetdem_param_format_value(0.1, 100, buf, sizeof buf);
    assert_string_equal(buf, "0.10000000000000001");
}

static void test_api_hard_impulse_never_returns_nan_velocities(void** state)
{
    (void)state;
    const struct wetdem_impulse_body wall = {{0, 0, 0}, {0, 0, 0}, INFINITY, INFINITY, INFINITY};
    const struct wetdem_vec3 n = {-1, 0, 0}; /* from the wall (j) to the sphere (i) */
    struct {
        struct wetdem_impulse_body sphere;
        int status;
    } cases[] = {
        /* 1/m overflows: v += (1/m) J was inf x 0 = NaN */
        {{{1, 0, 0}, {0, 0, 0}, 1e-320, 1, 0.4}, WETDEM_ERR_INVALID},
        /* R^2/I overflows: the spin became NaN */
        {{{1, 0, 1}, {0, 0, 0}, 1, 1, 1e-320}, WETDEM_ERR_INVALID},
        /* (1 + e) v_n overflows: J_n and the velocities were infinite */
        {{{1e308, 0, 0}, {0, 0, 0}, 1, 1, 0.4}, WETDEM_ERR_NUMERIC},
        {{{1e308, 0, 1e308}, {0, 0, 0}, 1, 1, 0.4}, WETDEM_ERR_NUMERIC},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        struct wetdem_impulse_body bi = cases[k].sphere, bj = wall;
        struct wetdem_impulse_result r;
        CHECK_STATUS(wetdem_hard_impulse(&bi, &bj, n, 1.0, 0.5, &r), cases[k].status);
        assert_memory_equal(&bi, &cases[k].sphere, sizeof bi);
        assert_memory_equal(&bj, &wall, sizeof bj);
        CHECK_ABS(r.impulse_normal, 0.0, 0.0);
    }
    /* large but representable: applied as before */
    struct wetdem_impulse_body bi = {{1e300, 0, 0}, {0, 0, 0}, 1, 1, 0.4}, bj = wall;
    CHECK_OK(wetdem_hard_impulse(&bi, &bj, n, 0.5, 0.0, NULL));
    CHECK_REL(bi.vel.x, -0.5e300, 1e-15);
}

/* predicted_i = p0 i + p1 for i = 0..4 */
static int straight_line(const double* p, double* predicted, char* msg, size_t msg_size, void* ctx)
{
    (void)msg, (void)msg_size, (void)ctx;
    for (int i = 0; i < 5; i++)
        predicted[i] = p[0] * i + p[1];
    return WETDEM_OK;
}

/* The straight line's problem: the five points 1..5 from the start initial[2]. */
static struct wetdem_fit_problem line_problem(const double* initial)
{
    static const double observed[5] = {1, 2, 3, 4, 5};
    return (struct wetdem_fit_problem){.n_params = 2,
                                       .initial = initial,
                                       .n_data = 5,
                                       .observed = observed,
                                       .model = straight_line};
}

static void test_api_fit_refuses_infinite_scale_and_tolerances(void** state)
{
    (void)state;
    const double initial[2] = {1, 0.5};
    const double scale[5] = {1, 1, INFINITY, 1, 1};
    struct wetdem_fit_problem pb = line_problem(initial);
    struct wetdem_fit_options opt;
    struct wetdem_fit_result res;
    char msg[256] = "";
    wetdem_fit_options_init(&opt);
    CHECK_OK(wetdem_fit_run(&pb, &opt, &res, NULL, msg, sizeof msg));
    CHECK_REL(res.values[0], 1.0, 1e-6);
    pb.scale = scale; /* would drop data point 3 from the fit */
    assert_int_equal(wetdem_fit_run(&pb, &opt, &res, NULL, msg, sizeof msg), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(msg, "data point 3");
    CHECK_CONTAINS(msg, "scale inf");
    pb.scale = NULL;
    double* tolerances[3] = {&opt.xtol, &opt.gtol, &opt.ftol};
    for (int k = 0; k < 3; k++) { /* xtol inf stopped at the first iterate, "converged" */
        wetdem_fit_options_init(&opt);
        *tolerances[k] = INFINITY;
        assert_int_equal(wetdem_fit_run(&pb, &opt, &res, NULL, msg, sizeof msg),
                         WETDEM_ERR_INVALID);
        CHECK_CONTAINS(msg, "tol inf");
    }
}

/* The writers of text follow snprintf: buf NULL with n 0 only counts, a short buffer gets the
 * start of the text, and the return is the whole text's length; a value's digits do not
 * depend on the room given (a short buffer used to be read back and end the search at 17). */
static void test_api_text_writers_follow_snprintf(void** state)
{
    (void)state;
    char buf[64], small[4];
    size_t len = wetdem_param_format_value(0.1, 6, NULL, 0);
    assert_int_equal(len, 3); /* "0.1" */
    assert_int_equal(wetdem_param_format_value(0.1, 6, buf, sizeof buf), len);
    assert_string_equal(buf, "0.1");
    assert_int_equal(wetdem_param_format_value(1.000000000001, 6, small, sizeof small), 14);
    assert_string_equal(small, "1.0"); /* the start of 1.000000000001, cut to 3 + NUL */
    strcpy(small, "abc");
    assert_int_equal(wetdem_param_format_value(2.5, 1, small, 0), 3);
    assert_string_equal(small, "abc"); /* n 0: nothing written */

    const struct wetdem_param_desc* settings = wetdem_sim_settings_params();
    const struct wetdem_param_desc* choice = wetdem_param_find(settings, "stop_on_separation");
    assert_non_null(choice);
    for (size_t k = 0; settings[k].name; k++) { /* numbers and enumerations alike */
        size_t need = wetdem_param_range_text(&settings[k], NULL, 0);
        assert_int_equal(wetdem_param_range_text(&settings[k], buf, sizeof buf), need);
        assert_int_equal(strlen(buf), need);
        char cut[6];
        assert_int_equal(wetdem_param_range_text(&settings[k], cut, sizeof cut), need);
        assert_int_equal(strncmp(cut, buf, sizeof cut - 1), 0);
        assert_int_equal(strlen(cut), need < sizeof cut ? need : sizeof cut - 1);
    }
    assert_int_equal(wetdem_param_range_text(choice, NULL, 0), strlen("one of: no, yes"));
    strcpy(buf, "stale");
    assert_int_equal(wetdem_param_range_text(NULL, buf, sizeof buf), 0);
    assert_string_equal(buf, "");
}

/* A name wetdem_param_find does not know, chained into wetdem_param_validate, is an error
 * with a message, not a crash; a fit without options takes the defaults. */
static void test_api_null_descriptor_and_fit_options(void** state)
{
    (void)state;
    char msg[256] = "";
    const struct wetdem_param_desc* d =
        wetdem_param_find(wetdem_sim_settings_params(), "no_such_setting");
    assert_null(d);
    assert_int_equal(wetdem_param_validate(d, 1.0, msg, sizeof msg), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(msg, "NULL descriptor");
    assert_int_equal(wetdem_param_validate(NULL, 1.0, NULL, 0), WETDEM_ERR_INVALID);

    const double initial[2] = {1, 0.5};
    struct wetdem_fit_problem pb = line_problem(initial);
    struct wetdem_fit_options opt;
    struct wetdem_fit_result with_defaults, without;
    wetdem_fit_options_init(&opt);
    CHECK_OK(wetdem_fit_run(&pb, &opt, &with_defaults, NULL, msg, sizeof msg));
    CHECK_OK(wetdem_fit_run(&pb, NULL, &without, NULL, msg, sizeof msg));
    /* the same iterations: bit-identical values */
    assert_memory_equal(without.values, with_defaults.values, sizeof without.values);
    assert_int_equal(without.iterations, with_defaults.iterations);
    assert_int_equal(wetdem_fit_run(NULL, NULL, &without, NULL, msg, sizeof msg),
                     WETDEM_ERR_INVALID);
    CHECK_CONTAINS(msg, "NULL problem");
    assert_int_equal(wetdem_fit_run(&pb, NULL, NULL, NULL, msg, sizeof msg), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(msg, "NULL result");
}

/* A NaN start of an unbounded parameter is named as not finite; the message spoke of
 * ln(upper - p) and bounds it does not have. */
static void test_api_fit_names_a_start_that_is_not_finite(void** state)
{
    (void)state;
    const double initial[2] = {1, NAN};
    const char* names[2] = {"slope", "offset"};
    struct wetdem_fit_problem pb = line_problem(initial);
    struct wetdem_fit_result res;
    char msg[256] = "";
    assert_int_equal(wetdem_fit_run(&pb, NULL, &res, NULL, msg, sizeof msg), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(msg, "parameter 2 (initial[1]): initial value nan is not finite");
    assert_null(strstr(msg, "ln("));
    pb.names = names;
    assert_int_equal(wetdem_fit_run(&pb, NULL, &res, NULL, msg, sizeof msg), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(msg, "offset: initial value nan is not finite");
}

/* A wall's normal gives only its direction: (1, 1, 0) scaled by 1e-200 or 1e200 (whose
 * squared length under- or overflows) is the same wall, so a sphere pressed into it moves
 * bit for bit as with (1, 1, 0), along that normal; these were refused as "normal
 * non-zero". A zero normal is refused as zero. */
static void test_api_wall_normal_of_any_length(void** state)
{
    (void)state;
    const double scales[] = {1.0, 1e-200, 1e200, 5e-324};
    struct wetdem_particle ref = {0};
    for (size_t k = 0; k < sizeof scales / sizeof scales[0]; k++) {
        struct wetdem_sim* sim = wetdem_sim_create();
        assert_int_equal(wetdem_sim_add_material_preset(sim, "steel1"), 0);
        CHECK_OK(wetdem_sim_enable_model(sim, "hertz"));
        double c = scales[k];
        CHECK_OK(wetdem_sim_add_wall(sim, (struct wetdem_vec3){0, 0, 0},
                                     (struct wetdem_vec3){c, c, 0}, 0));
        /* centre 0.99 mm from the plane x + y = 0: 10 um overlap with a 1 mm sphere */
        double x = 0.99e-3 / sqrt(2.0);
        CHECK_OK(wetdem_sim_add_particle(
            sim, (struct wetdem_particle){.radius = 1e-3, .pos = {x, x, 0}, .material = 0}));
        CHECK_OK(wetdem_sim_integrate(sim, 1e-7));
        const struct wetdem_particle* p = wetdem_sim_particles(sim, NULL);
        assert_true(p->vel.x > 0 && p->vel.x == p->vel.y && p->vel.z == 0);
        if (k == 0)
            ref = *p;
        assert_memory_equal(&p->pos, &ref.pos, sizeof ref.pos);
        assert_memory_equal(&p->vel, &ref.vel, sizeof ref.vel);
        wetdem_sim_free(sim);
    }
    struct wetdem_sim* sim = wetdem_sim_create();
    assert_int_equal(wetdem_sim_add_material_preset(sim, "steel1"), 0);
    assert_int_equal(
        wetdem_sim_add_wall(sim, (struct wetdem_vec3){0, 0, 0}, (struct wetdem_vec3){0, 0, 0}, 0),
        WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "wall 0: normal (0, 0, 0) is zero");
    assert_int_equal(
        wetdem_sim_add_wall(sim, (struct wetdem_vec3){0, 0, 0}, (struct wetdem_vec3){NAN, 0, 1}, 0),
        WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "normal (nan, 0, 1) must be finite");
    assert_int_equal(wetdem_sim_n_walls(sim), 0);
    wetdem_sim_free(sim);
}

/* A collision's initial gap beyond what the geometry can square is refused naming the gap
 * and its range (it was "particle 0: position, velocity and spin must be finite"); the largest
 * allowed gap runs: the striker, 1e150 m away at 0.1 m/s, never reaches the target. */
static void test_api_collision_names_an_initial_gap_too_large(void** state)
{
    (void)state;
    struct wetdem_sim* sim = wetdem_sim_create();
    assert_int_equal(wetdem_sim_add_material_preset(sim, "steel1"), 0);
    CHECK_OK(wetdem_sim_enable_model(sim, "hertz"));
    struct wetdem_collision_spec s = {
        .radius_i = 1e-3, .radius_j = 1e-3, .speed = 0.1, .t_end = 1e-3, .initial_gap = 1e150};
    struct wetdem_collision_result r;
    for (int wall = 0; wall < 2; wall++) {
        s.target_is_wall = wall;
        s.initial_gap = 1e150;
        CHECK_OK(wetdem_collision_run(sim, &s, &r));
        assert_int_equal(r.outcome, WETDEM_OUTCOME_NONE);
        const double bad[] = {1e300, NAN, -INFINITY};
        for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
            s.initial_gap = bad[k];
            CHECK_STATUS(wetdem_collision_run(sim, &s, &r), WETDEM_ERR_INVALID);
            CHECK_CONTAINS(wetdem_sim_errmsg(sim), "collision: initial_gap = ");
            CHECK_CONTAINS(wetdem_sim_errmsg(sim), "valid finite and <= 1e+150 m");
        }
    }
    wetdem_sim_free(sim);
}

/* A force that overflows (a sphere 1e308 m behind a wall: Hertz's k delta^1.5) is reported as
 * a numerical failure, as the integrators report it, not returned as a result. */
static void test_api_pair_force_refuses_non_finite_force(void** state)
{
    (void)state;
    struct wetdem_sim* sim = wetdem_sim_create();
    assert_non_null(sim);
    assert_int_equal(wetdem_sim_add_material_preset(sim, "glass"), 0);
    CHECK_OK(wetdem_sim_add_particle(sim, (struct wetdem_particle){.radius = 1e-3, .material = 0}));
    CHECK_OK(wetdem_sim_add_wall(sim, (struct wetdem_vec3){0, 0, 1e308},
                                 (struct wetdem_vec3){0, 0, 1}, 0));
    CHECK_OK(wetdem_sim_enable_model(sim, "hertz"));
    struct wetdem_pair_force f;
    struct wetdem_contact c;
    assert_int_equal(wetdem_sim_pair_force(sim, 0, (size_t)-1, &c, &f), WETDEM_ERR_NUMERIC);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "non-finite force");
    wetdem_sim_free(sim);
}

/* The reports of a started many-particle run read the particles as they are now, edited
 * through wetdem_sim_particles() since the latest call as the next call will read them: a
 * material added since and given to a particle is mixed as that call mixes it (the table of
 * material pairs was made for the materials of the latest call, and the reports read past its
 * end), and a particle the next call would refuse (a material that does not exist, a NaN) is
 * refused by every report, naming it, and not read. */
static void test_api_many_reports_read_the_particles_edited_since_the_latest_call(void** state)
{
    (void)state;
    const double radius = 1e-3, overlap = 1e-6;
    struct wetdem_sim* sim = wetdem_sim_create();
    assert_non_null(sim);
    assert_int_equal(wetdem_sim_add_material_preset(sim, "glass"), 0);
    CHECK_OK(wetdem_sim_add_particle(sim, (struct wetdem_particle){.radius = radius}));
    CHECK_OK(wetdem_sim_add_particle(
        sim, (struct wetdem_particle){.pos = {2 * radius - overlap, 0, 0}, .radius = radius}));
    CHECK_OK(wetdem_sim_enable_model(sim, "hertz"));
    char dir[] = "/tmp/wetdem_test_api_reports_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char prefix[64], path[96];
    snprintf(prefix, sizeof prefix, "%s/run", dir);
    struct wetdem_many_settings ms = {.dt = 1e-9, .energy_budget = true, .output_prefix = prefix};
    CHECK_OK(wetdem_sim_set_many(sim, &ms));
    CHECK_OK(wetdem_sim_integrate(sim, 1e-9));
    snprintf(path, sizeof path, "%s/run.csv", dir);
    remove(path); /* (the header the run wrote) */

    /* steel given to sphere 1 after the call, the spheres put back at the overlap: the Hertz
     * energy (8/15) E* sqrt(R*) delta^(5/2) with the E* of glass on steel (closed form; the
     * same arithmetic up to rounding: 1e-12) */
    int steel = wetdem_sim_add_material_preset(sim, "steel1");
    assert_int_equal(steel, 1);
    struct wetdem_particle* p = wetdem_sim_particles(sim, NULL);
    p[0].pos = (struct wetdem_vec3){0, 0, 0};
    p[1].pos = (struct wetdem_vec3){2 * radius - overlap, 0, 0};
    p[1].material = steel;
    const struct wetdem_material *g = wetdem_sim_material(sim, 0), *s = wetdem_sim_material(sim, 1);
    double e_star = 1.0 / ((1 - g->poisson_ratio * g->poisson_ratio) / g->youngs_modulus +
                           (1 - s->poisson_ratio * s->poisson_ratio) / s->youngs_modulus);
    struct wetdem_energy_budget b;
    CHECK_OK(wetdem_sim_energy_budget(sim, &b));
    CHECK_REL(b.elastic, 8.0 / 15.0 * e_star * sqrt(radius / 2) * pow(overlap, 2.5), 1e-12);
    struct wetdem_many_stats st;
    CHECK_OK(wetdem_sim_many_stats(sim, &st));
    assert_int_equal(st.contacts, 1);

    /* a particle the next call refuses: so do the reports, and they write nothing */
    struct {
        int material;
        double mass;
        const char* why;
    } bad[] = {{7, p[1].mass, "material 7 does not exist"}, {steel, NAN, "mass must be"}};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        p[1].material = bad[k].material;
        double mass = p[1].mass;
        p[1].mass = bad[k].mass;
        assert_int_equal(wetdem_sim_energy_budget(sim, &b), WETDEM_ERR_INVALID);
        CHECK_CONTAINS(wetdem_sim_errmsg(sim), "particle 1");
        CHECK_CONTAINS(wetdem_sim_errmsg(sim), bad[k].why);
        assert_int_equal(wetdem_sim_many_stats(sim, &st), WETDEM_ERR_INVALID);
        CHECK_CONTAINS(wetdem_sim_errmsg(sim), bad[k].why);
        assert_int_equal(wetdem_sim_many_write_csv_row(sim), WETDEM_ERR_INVALID);
        snprintf(path, sizeof path, "%s/frame.vtk", dir);
        assert_int_equal(wetdem_sim_write_vtk(sim, path, false), WETDEM_ERR_INVALID);
        snprintf(path, sizeof path, "%s/links.vtk", dir);
        assert_int_equal(wetdem_sim_write_vtk_links(sim, path, false), WETDEM_ERR_INVALID);
        snprintf(path, sizeof path, "%s/run.ckpt", dir);
        assert_int_equal(wetdem_sim_write_checkpoint(sim, path), WETDEM_ERR_INVALID);
        CHECK_CONTAINS(wetdem_sim_errmsg(sim), "particle 1");
        p[1].mass = mass;
    }
    assert_int_equal(rmdir(dir), 0); /* empty: no report wrote a file */
    p[1].material = steel;
    CHECK_OK(wetdem_sim_energy_budget(sim, &b));
    wetdem_sim_free(sim);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_api_null_names_materials_fluids_and_paths_are_refused),
        cmocka_unit_test(test_api_insert_is_whole_or_nothing),
        cmocka_unit_test(test_api_hard_impulse_never_returns_nan_velocities),
        cmocka_unit_test(test_api_fit_refuses_infinite_scale_and_tolerances),
        cmocka_unit_test(test_api_format_value_always_writes),
        cmocka_unit_test(test_api_text_writers_follow_snprintf),
        cmocka_unit_test(test_api_null_descriptor_and_fit_options),
        cmocka_unit_test(test_api_fit_names_a_start_that_is_not_finite),
        cmocka_unit_test(test_api_wall_normal_of_any_length),
        cmocka_unit_test(test_api_collision_names_an_initial_gap_too_large),
        cmocka_unit_test(test_api_pair_force_refuses_non_finite_force),
        cmocka_unit_test(test_api_many_reports_read_the_particles_edited_since_the_latest_call),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/*
 * test_params.c — parameter validation through the public API: non-finite and out-of-range
 * values are rejected with a message naming the parameter, value and valid range; unknown
 * parameter and model names get a "did you mean" hint; enumerated parameters are set by
 * word; range text; material presets against the seed tables (Nijssen 2023 Table 1, Punch
 * 2023 Table 1); simulation lifecycle; particle mass from the material density; the public
 * descriptor tables of the simulation settings and of each integrator describe exactly what
 * wetdem_sim_param reads and wetdem_sim_set_param checks.
 */
#include <stdlib.h>

#include "harness.h"

/* A simulation with one steel1 material (index 0). */
static struct wetdem_sim* sim_with_steel(void)
{
    struct wetdem_sim* sim = wetdem_sim_create();
    assert_non_null(sim);
    assert_int_equal(wetdem_sim_add_material_preset(sim, "steel1"), 0);
    return sim;
}

static struct wetdem_particle sphere(double radius)
{
    return (struct wetdem_particle){.radius = radius, .material = 0};
}

static void test_params_lifecycle(void** state)
{
    (void)state;
    wetdem_sim_free(NULL); /* documented no-op: must not crash */
    struct wetdem_sim* sim = wetdem_sim_create();
    assert_non_null(sim);
    assert_string_equal(wetdem_sim_errmsg(sim), "");
    assert_int_equal(wetdem_sim_n_particles(sim), 0);
    assert_int_equal(wetdem_sim_n_materials(sim), 0);
    assert_int_equal(wetdem_sim_n_models(sim), 0);
    assert_string_equal(wetdem_sim_min_separation_model(sim)->name, "fixed");
    wetdem_sim_free(sim);
}

static void test_params_particle_rejects_bad_radius(void** state)
{
    (void)state;
    struct wetdem_sim* sim = sim_with_steel();
    const double bad[] = {NAN, INFINITY, -1e-3, 0.0};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        CHECK_STATUS(wetdem_sim_add_particle(sim, sphere(bad[k])), WETDEM_ERR_INVALID);
        CHECK_CONTAINS(wetdem_sim_errmsg(sim), "radius");
    }
    struct wetdem_particle p = sphere(1e-3);
    p.pos.y = NAN;
    CHECK_STATUS(wetdem_sim_add_particle(sim, p), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "finite");
    p = sphere(1e-3);
    p.vel.x = INFINITY;
    CHECK_STATUS(wetdem_sim_add_particle(sim, p), WETDEM_ERR_INVALID);
    p = sphere(1e-3);
    p.material = 1; /* only material 0 exists */
    CHECK_STATUS(wetdem_sim_add_particle(sim, p), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "material 1");
    p = sphere(1e-3);
    p.mass = -1.0;
    CHECK_STATUS(wetdem_sim_add_particle(sim, p), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "mass");
    /* a fixed sphere stands still: a velocity or a spin would act in its pair forces only */
    p = sphere(1e-3);
    p.is_fixed = true;
    p.vel.z = -0.5;
    CHECK_STATUS(wetdem_sim_add_particle(sim, p), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "fixed particle is held in place: its velocity and "
                                           "spin must be 0, got v = (0, 0, -0.5) m/s");
    p.vel.z = 0;
    p.omega.y = 1e-300;
    CHECK_STATUS(wetdem_sim_add_particle(sim, p), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "omega = (0, 1e-300, 0) rad/s");
    assert_int_equal(wetdem_sim_n_particles(sim), 0); /* nothing half-added */
    CHECK_OK(wetdem_sim_add_particle(sim, sphere(1e-3)));
    assert_int_equal(wetdem_sim_n_particles(sim), 1);
    p.omega.y = 0; /* at rest it is taken */
    CHECK_OK(wetdem_sim_add_particle(sim, p));
    assert_int_equal(wetdem_sim_n_particles(sim), 2);
    wetdem_sim_free(sim);
}

static void test_params_material_restitution_range(void** state)
{
    (void)state;
    struct wetdem_sim* sim = wetdem_sim_create();
    struct wetdem_material m;
    CHECK_OK(wetdem_material_preset("glass", &m));
    /* e_dry must lie in (0, 1]: 0 and 1 + 1e-9 and NaN are outside, 1 is inside. */
    const double bad[] = {0.0, -0.5, 1.0 + 1e-9, NAN, INFINITY};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        m.restitution = bad[k];
        CHECK_STATUS(wetdem_sim_add_material(sim, &m), WETDEM_ERR_INVALID);
        CHECK_CONTAINS(wetdem_sim_errmsg(sim), "restitution");
        CHECK_CONTAINS(wetdem_sim_errmsg(sim), "(0, 1]");
    }
    assert_int_equal(wetdem_sim_n_materials(sim), 0);
    m.restitution = 1.0;
    assert_int_equal(wetdem_sim_add_material(sim, &m), 0);
    m.poisson_ratio = 0.5; /* valid [-1, 0.5): 0.5 itself is excluded (incompressible) */
    CHECK_STATUS(wetdem_sim_add_material(sim, &m), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "poisson_ratio");
    wetdem_sim_free(sim);
}

static void test_params_fluid_rejects_nonfinite_and_negative(void** state)
{
    (void)state;
    struct wetdem_sim* sim = wetdem_sim_create();
    CHECK_OK(wetdem_sim_set_param(sim, "fluid.viscosity", 0.05));
    const double bad[] = {NAN, INFINITY, -INFINITY, -1e-3};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        CHECK_STATUS(wetdem_sim_set_param(sim, "fluid.viscosity", bad[k]), WETDEM_ERR_INVALID);
        CHECK_CONTAINS(wetdem_sim_errmsg(sim), "viscosity");
        CHECK_CONTAINS(wetdem_sim_errmsg(sim), "[0, 1e+06]");
    }
    double mu = 0;
    CHECK_OK(wetdem_sim_param(sim, "fluid.viscosity", &mu));
    CHECK_REL(mu, 0.05, 0.0); /* rejected values leave the old value untouched */
    CHECK_STATUS(wetdem_sim_set_param_str(sim, "fluid.viscosity", "1e-3x"), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "not a number");
    CHECK_OK(wetdem_sim_set_param_str(sim, "fluid.viscosity", "2.5e-2"));
    CHECK_OK(wetdem_sim_param(sim, "fluid.viscosity", &mu));
    CHECK_REL(mu, 0.025, 0.0); /* strtod of "2.5e-2" is the double nearest 0.025 */
    wetdem_sim_free(sim);
}

static void test_params_unknown_parameter_suggests(void** state)
{
    (void)state;
    struct wetdem_sim* sim = wetdem_sim_create();
    CHECK_STATUS(wetdem_sim_set_param(sim, "fluid.viscosty", 1.0), WETDEM_ERR_NOT_FOUND);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "did you mean 'fluid.viscosity'");
    CHECK_OK(wetdem_sim_enable_model(sim, "nijssen"));
    CHECK_STATUS(wetdem_sim_set_param(sim, "nijsen.cutoff_ratio", 2.0), WETDEM_ERR_NOT_FOUND);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "did you mean 'nijssen.cutoff_ratio'");
    /* A name far from every parameter gets no hint but says how names are formed. */
    CHECK_STATUS(wetdem_sim_set_param(sim, "zzzzzzzz.qqqqqqqq", 1.0), WETDEM_ERR_NOT_FOUND);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "<model>.<param>");
    /* A known model that is not enabled cannot be set. */
    CHECK_STATUS(wetdem_sim_set_param(sim, "reynolds.cutoff_ratio", 2.0), WETDEM_ERR_NOT_FOUND);
    CHECK_OK(wetdem_sim_set_param(sim, "nijssen.cutoff_ratio", 2.0));
    double v = 0;
    CHECK_OK(wetdem_sim_param(sim, "nijssen.cutoff_ratio", &v));
    CHECK_REL(v, 2.0, 0.0);
    wetdem_sim_free(sim);
}

static void test_params_unknown_model_suggests(void** state)
{
    (void)state;
    struct wetdem_sim* sim = wetdem_sim_create();
    CHECK_STATUS(wetdem_sim_enable_model(sim, "nijsen"), WETDEM_ERR_NOT_FOUND);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "did you mean 'nijssen'");
    CHECK_STATUS(wetdem_sim_enable_model(sim, "capilary"), WETDEM_ERR_NOT_FOUND);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "did you mean 'capillary'");
    assert_int_equal(wetdem_sim_n_models(sim), 0);
    /* Every registry model is found by its own name, and names are unique. */
    const struct wetdem_model* const* reg = wetdem_model_registry();
    for (size_t k = 0; reg[k]; k++) {
        assert_ptr_equal(wetdem_model_find(reg[k]->name), reg[k]);
        for (size_t j = 0; j < k; j++)
            assert_string_not_equal(reg[j]->name, reg[k]->name);
    }
    wetdem_sim_free(sim);
}

static void test_params_choice_by_word(void** state)
{
    (void)state;
    struct wetdem_sim* sim = wetdem_sim_create();
    CHECK_OK(wetdem_sim_enable_model(sim, "sb"));
    double v = -1;
    CHECK_OK(wetdem_sim_param(sim, "sb.below_hmin", &v));
    CHECK_REL(v, 0.0, 0.0); /* default "c" is index 0 of {c, nc} */
    CHECK_OK(wetdem_sim_set_param_str(sim, "sb.below_hmin", "nc"));
    CHECK_OK(wetdem_sim_param(sim, "sb.below_hmin", &v));
    CHECK_REL(v, 1.0, 0.0); /* "nc" is index 1 */
    CHECK_STATUS(wetdem_sim_set_param_str(sim, "sb.below_hmin", "ncc"), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "one of: c, nc");
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "did you mean 'nc'");
    /* As a number, only an exact index 0..count-1 is valid. */
    CHECK_STATUS(wetdem_sim_set_param(sim, "sb.below_hmin", 2.0), WETDEM_ERR_INVALID);
    CHECK_STATUS(wetdem_sim_set_param(sim, "sb.below_hmin", 0.5), WETDEM_ERR_INVALID);
    CHECK_STATUS(wetdem_sim_set_param(sim, "sb.below_hmin", NAN), WETDEM_ERR_INVALID);
    CHECK_OK(wetdem_sim_param(sim, "sb.below_hmin", &v));
    CHECK_REL(v, 1.0, 0.0); /* unchanged by the rejected values */
    wetdem_sim_free(sim);
}

static void test_params_range_text_and_message(void** state)
{
    (void)state;
    static const char* const words[] = {"c", "nc", NULL};
    const struct wetdem_param_desc d[] = {
        {"ratio", "-", "doc", 0, 0.5, 0, 1, true, false, NULL, false},
        {"speed", "m/s", "doc", 0, 0, -1, 1e6, false, true, NULL, false},
        {"mode", "-", "doc", 0, 0, 0, 1, false, false, words, false},
    };
    char buf[160];
    wetdem_param_range_text(&d[0], buf, sizeof buf);
    assert_string_equal(buf, "(0, 1]");
    wetdem_param_range_text(&d[1], buf, sizeof buf);
    assert_string_equal(buf, "[-1, 1e+06)");
    wetdem_param_range_text(&d[2], buf, sizeof buf);
    assert_string_equal(buf, "one of: c, nc");
    char msg[256];
    CHECK_STATUS(wetdem_param_validate(&d[0], 0.0, msg, sizeof msg), WETDEM_ERR_INVALID);
    assert_string_equal(msg, "ratio = 0 [-] is out of range: valid (0, 1]");
    CHECK_OK(wetdem_param_validate(&d[0], 1.0, msg, sizeof msg));
    /* just outside: as many digits as tell it from the end (%g printed "1 ... valid (0, 1]") */
    CHECK_STATUS(wetdem_param_validate(&d[0], 1.000000000001, msg, sizeof msg), WETDEM_ERR_INVALID);
    assert_string_equal(msg, "ratio = 1.000000000001 [-] is out of range: valid (0, 1]");
    CHECK_STATUS(wetdem_param_validate(&d[0], nextafter(1.0, 2.0), msg, sizeof msg),
                 WETDEM_ERR_INVALID);
    assert_string_equal(msg, "ratio = 1.0000000000000002 [-] is out of range: valid (0, 1]");
    /* the formatter both messages and the CLI's CSV use: fewest digits from the minimum up */
    wetdem_param_format_value(0.1, 15, buf, sizeof buf);
    assert_string_equal(buf, "0.1");
    wetdem_param_format_value(0.1 + 0.2, 15, buf, sizeof buf); /* 0.30000000000000004 */
    assert_true(strtod(buf, NULL) == 0.1 + 0.2 && strlen(buf) == 19);
    wetdem_param_format_value(2.5, 1, buf, sizeof buf);
    assert_string_equal(buf, "2.5");
    CHECK_STATUS(wetdem_param_validate(&d[1], 1e6, NULL, 0), WETDEM_ERR_INVALID);
    CHECK_OK(wetdem_param_validate(&d[1], -1.0, NULL, 0));
    assert_int_equal(wetdem_param_choice_index(&d[2], "nc"), 1);
    assert_int_equal(wetdem_param_choice_index(&d[2], "x"), -1);
}

/* A count (integer = true) takes whole numbers only: 100.5 steps is refused, not truncated to
 * 100; the value is printed in all its digits, and its range in full up to 10 digits. */
static void test_params_integer_counts(void** state)
{
    (void)state;
    const struct wetdem_param_desc seed = {"seed",       "-",   "doc", 0,    1,   0,
                                           4294967295.0, false, false, NULL, true};
    char buf[160], msg[256];
    wetdem_param_range_text(&seed, buf, sizeof buf);
    assert_string_equal(buf, "integer in [0, 4294967295]");
    CHECK_OK(wetdem_param_validate(&seed, 4294967295.0, msg, sizeof msg));
    CHECK_OK(wetdem_param_validate(&seed, 0.0, msg, sizeof msg));
    CHECK_STATUS(wetdem_param_validate(&seed, 1e6 + 0.5, msg, sizeof msg), WETDEM_ERR_INVALID);
    assert_string_equal(msg, "seed = 1000000.5 [-] is not a whole number: valid integer in "
                             "[0, 4294967295]");
    CHECK_STATUS(wetdem_param_validate(&seed, -1.0, msg, sizeof msg), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(msg, "seed = -1 [-] is out of range");
    /* the library's own counts: an integrator's step budget and order */
    struct wetdem_sim* sim = wetdem_sim_create();
    CHECK_OK(wetdem_sim_set_integrator(sim, "cvode"));
    CHECK_OK(wetdem_sim_set_param(sim, "cvode.max_order", 4));
    CHECK_STATUS(wetdem_sim_set_param(sim, "cvode.max_order", 2.5), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "max_order = 2.5 [-] is not a whole number");
    CHECK_STATUS(wetdem_sim_set_param(sim, "cvode.max_steps", 100.5), WETDEM_ERR_INVALID);
    double order = 0;
    CHECK_OK(wetdem_sim_param(sim, "cvode.max_order", &order));
    CHECK_REL(order, 4.0, 0.0); /* the refused value left the old one */
    wetdem_sim_free(sim);
}

static void test_params_suggest_threshold(void** state)
{
    (void)state;
    static const char* const names[] = {"viscosity", "surface_tension", "density", NULL};
    /* One substitution: distance 1 <= max(2, 9/3). */
    assert_string_equal(wetdem_param_suggest("viscosoty", names), "viscosity");
    /* Far from every name: no hint rather than a misleading one. */
    assert_null(wetdem_param_suggest("gravity_x", names));
    /* Two letters swapped count as one edit: "lgo2" is 1 from "log2" but 2 from "log", which
     * plain Levenshtein ties at 2 and so resolved to the first listed. */
    static const char* const flags[] = {"--log", "--log2", NULL};
    assert_string_equal(wetdem_param_suggest("--lgo2", flags), "--log2");
    assert_string_equal(wetdem_param_suggest("--lgo", flags), "--log");
    /* "dnesity": one swap (distance 1); "ytisned" reverses it and stays without a hint. */
    assert_string_equal(wetdem_param_suggest("dnesity", names), "density");
    assert_null(wetdem_param_suggest("ytisned", names));
}

/* One material preset checked field by field against a seed table row. */
struct preset_row {
    const char* name;
    double density, youngs, poisson, restitution, roughness, mu_dry, mu_lub, film;
};

static void test_params_presets_match_seed_tables(void** state)
{
    (void)state;
    /* Nijssen 2023 Table 1 (Yang & Hunt): rho [kg/m^3], gamma = E [GPa], nu, e_dry,
     * sigma [nm], mu_dry, mu_lub. Punch 2023 Table 1: rho 7960, E 2.0e11 Pa, nu 0.35,
     * e_dry 0.9; h_max = 270 um film on the coated sphere (Sec. 3.1); mu_f = 0.05 (Fig. 11). */
    const struct preset_row rows[] = {
        {"steel1", 7780, 190e9, 0.27, 0.97, 24e-9, 0.11, 0.02, 0},
        {"steel2", 7780, 190e9, 0.27, 0.97, 272e-9, 0.11, 0.02, 0},
        {"glass", 2540, 60e9, 0.23, 0.97, 134e-9, 0.40, 0.10, 0},
        {"delrin", 1400, 2.8e9, 0.35, 0.97, 796e-9, 0.20, 0.10, 0},
        {"punch_steel", 7960, 2.0e11, 0.35, 0.9, 0, 0.05, 0.05, 0},
        {"punch_steel_coated", 7960, 2.0e11, 0.35, 0.9, 0, 0.05, 0.05, 270e-6},
    };
    size_t n_rows = sizeof rows / sizeof rows[0];
    for (size_t k = 0; k < n_rows; k++) {
        struct wetdem_material m;
        CHECK_OK(wetdem_material_preset(rows[k].name, &m));
        /* Tolerance 0: the presets are the same decimal literals as the tables. */
        CHECK_REL(m.density, rows[k].density, 0.0);
        CHECK_REL(m.youngs_modulus, rows[k].youngs, 0.0);
        CHECK_REL(m.poisson_ratio, rows[k].poisson, 0.0);
        CHECK_REL(m.restitution, rows[k].restitution, 0.0);
        CHECK_REL(m.roughness, rows[k].roughness, 0.0);
        CHECK_REL(m.friction_dry, rows[k].mu_dry, 0.0);
        CHECK_REL(m.friction_lub, rows[k].mu_lub, 0.0);
        CHECK_REL(m.film, rows[k].film, 0.0);
        char msg[256];
        CHECK_OK(wetdem_material_validate(&m, msg, sizeof msg));
    }
    /* The name list has exactly these presets. */
    const char* const* names = wetdem_material_preset_names();
    size_t n = 0;
    while (names[n])
        n++;
    assert_int_equal(n, n_rows);
    struct wetdem_fluid f;
    CHECK_OK(wetdem_fluid_preset("silicone10", &f)); /* Punch Table 1: 10 Pa s, 0.0205 N/m */
    CHECK_REL(f.viscosity, 10.0, 0.0);
    CHECK_REL(f.surface_tension, 0.0205, 0.0);
    struct wetdem_material m;
    CHECK_STATUS(wetdem_material_preset("steal1", &m), WETDEM_ERR_NOT_FOUND);
    struct wetdem_sim* sim = wetdem_sim_create();
    CHECK_STATUS(wetdem_sim_add_material_preset(sim, "steal1"), WETDEM_ERR_NOT_FOUND);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "did you mean 'steel1'");
    wetdem_sim_free(sim);
}

static void test_params_mass_from_density(void** state)
{
    (void)state;
    struct wetdem_sim* sim = sim_with_steel();
    /* m = rho 4/3 pi R^3 with rho = 7780 kg/m^3, R = 6.35e-3 m:
     * R^3 = 2.56047875e-7 m^3, 4/3 pi R^3 = 1.07253083e-6 m^3, m = 8.34428986e-3 kg. */
    CHECK_OK(wetdem_sim_add_particle(sim, sphere(6.35e-3)));
    struct wetdem_particle p2 = sphere(6.35e-3);
    p2.mass = 0.5; /* an explicit mass is kept */
    CHECK_OK(wetdem_sim_add_particle(sim, p2));
    size_t n = 0;
    const struct wetdem_particle* p = wetdem_sim_particles(sim, &n);
    assert_int_equal(n, 2);
    /* 1e-8: the hand value above has 9 significant digits. */
    CHECK_REL(p[0].mass, 8.34428986e-3, 1e-8);
    CHECK_REL(p[1].mass, 0.5, 0.0);
    wetdem_sim_free(sim);
}

/* Every entry of `table` under "<prefix>.<name>": a new simulation reads its default, a value
 * just beyond a finite bound is rejected naming the parameter, and the bound itself is
 * accepted unless open. Returns the number of entries. */
static size_t check_table_against_sim(struct wetdem_sim* sim, const char* prefix,
                                      const struct wetdem_param_desc* table)
{
    size_t n = 0;
    for (; table[n].name; n++) {
        const struct wetdem_param_desc* d = &table[n];
        char full[128];
        snprintf(full, sizeof full, "%s.%s", prefix, d->name);
        double v = NAN;
        CHECK_OK(wetdem_sim_param(sim, full, &v));
        CHECK_REL(v, d->default_value, 0.0); /* the same double, not a copy of its text */
        if (d->choices)
            continue;
        /* 1e-3 of the bound's size (or 1e-3 absolute at 0) is well outside any rounding. */
        double above = d->max + fmax(fabs(d->max) * 1e-3, 1e-3);
        CHECK_STATUS(wetdem_sim_set_param(sim, full, above), WETDEM_ERR_INVALID);
        CHECK_CONTAINS(wetdem_sim_errmsg(sim), d->name);
        CHECK_STATUS(wetdem_sim_set_param(sim, full, d->max),
                     d->max_open ? WETDEM_ERR_INVALID : WETDEM_OK);
        CHECK_OK(wetdem_sim_set_param(sim, full, d->default_value));
    }
    return n;
}

static void test_params_public_settings_and_integrator_tables(void** state)
{
    (void)state;
    struct wetdem_sim* sim = wetdem_sim_create();
    assert_non_null(sim);
    const struct wetdem_param_desc* settings = wetdem_sim_settings_params();
    assert_non_null(settings);
    assert_true(check_table_against_sim(sim, "sim", settings) >= 6); /* gravity x3, stop, ... */
    assert_non_null(wetdem_param_find(settings, "speed_floor"));
    size_t n_integrators = 0;
    for (const char* const* name = wetdem_integrator_names(); *name; name++, n_integrators++) {
        const struct wetdem_param_desc* table = wetdem_integrator_params(*name);
        assert_non_null(table);
        assert_non_null(wetdem_integrator_summary(*name));
        /* Every integrator keeps its parameters on the simulation whichever one is chosen. */
        assert_true(check_table_against_sim(sim, *name, table) >= 3);
        CHECK_OK(wetdem_sim_set_integrator(sim, *name));
        check_table_against_sim(sim, *name, table);
    }
    assert_int_equal(n_integrators, 2); /* verlet and cvode */
    assert_non_null(wetdem_param_find(wetdem_integrator_params("cvode"), "rtol"));
    assert_non_null(wetdem_param_find(wetdem_integrator_params("verlet"), "dt_fraction"));
    assert_null(wetdem_integrator_params("cvod"));
    assert_null(wetdem_integrator_params(NULL));
    assert_null(wetdem_integrator_summary("rk45"));
    wetdem_sim_free(sim);
}

/* A NULL name, material, fluid or model is refused with a message (each crashed). */
static void test_params_null_arguments_are_refused(void** state)
{
    (void)state;
    struct wetdem_sim* s = wetdem_sim_create();
    struct wetdem_material m;
    assert_int_equal(wetdem_sim_enable_model(s, NULL), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(s), "NULL name");
    assert_int_equal(wetdem_sim_set_param(s, NULL, 1), WETDEM_ERR_INVALID);
    assert_int_equal(wetdem_sim_set_param_str(s, "sim.speed_floor", NULL), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(s), "NULL value");
    assert_null(wetdem_model_find(NULL));
    assert_int_equal(wetdem_material_preset(NULL, &m), WETDEM_ERR_INVALID);
    assert_int_equal(wetdem_sim_add_material_preset(s, NULL), WETDEM_ERR_INVALID);
    assert_int_equal(wetdem_sim_add_material(s, NULL), WETDEM_ERR_INVALID);
    assert_int_equal(wetdem_sim_set_fluid(s, NULL), WETDEM_ERR_INVALID);
    assert_int_equal(wetdem_sim_add_model(s, NULL, NULL), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(s), "a model needs a name");
    wetdem_sim_free(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_params_lifecycle),
        cmocka_unit_test(test_params_particle_rejects_bad_radius),
        cmocka_unit_test(test_params_material_restitution_range),
        cmocka_unit_test(test_params_fluid_rejects_nonfinite_and_negative),
        cmocka_unit_test(test_params_unknown_parameter_suggests),
        cmocka_unit_test(test_params_unknown_model_suggests),
        cmocka_unit_test(test_params_choice_by_word),
        cmocka_unit_test(test_params_range_text_and_message),
        cmocka_unit_test(test_params_suggest_threshold),
        cmocka_unit_test(test_params_integer_counts),
        cmocka_unit_test(test_params_presets_match_seed_tables),
        cmocka_unit_test(test_params_mass_from_density),
        cmocka_unit_test(test_params_public_settings_and_integrator_tables),
        cmocka_unit_test(test_params_null_arguments_are_refused),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/*
 * cmd_forces.c — `wetdem forces`: the pair force between two equal spheres as a function of
 * the gap, as CSV, evaluated through the public API only (wetdem_sim_create,
 * wetdem_sim_add_material_preset, wetdem_sim_add_particle, wetdem_sim_enable_model,
 * wetdem_sim_set_param_str, wetdem_sim_pair_force).
 *
 * Geometry: sphere j rests at the origin, sphere i sits on the +x axis at x = 2R + h, so the
 * normal (j to i) is +x. i moves with velocity (-speed, slip, 0): the normal approach speed
 * is v_n = speed (> 0 approaching) and i's surface slides past j's at `slip` along +y. Each
 * row is a fresh pair (no history), so history-dependent models see their initial state.
 *
 * Columns: gap [m] (h; < 0 overlap), f_normal [N] (on i along the normal, > 0 repulsive),
 * f_tangential [N] (on i along +y, the slip direction), h_min [m] (from the min-separation
 * model; composite models with their own minimum approach, e.g. nijssen, do not read it).
 */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cli_util.h"

#define MAX_ITEMS 32

struct forces_opts {
    const char* preset;    /* material preset of both spheres */
    const char* fluid;     /* fluid preset, NULL: library default */
    double radius;         /* [m] */
    double speed;          /* normal approach speed [m/s] */
    double slip;           /* tangential surface speed of i relative to j [m/s] */
    struct cli_range gaps; /* [m] */
    const char* gaps_text; /* as given, parsed after --log is known */
    bool is_log;
    const char* models[MAX_ITEMS];
    size_t n_models;
    const char* sets[MAX_ITEMS];
    size_t n_sets;
};

static void usage(FILE* f)
{
    fprintf(f,
            "usage: wetdem forces [--model NAME ...] [MODEL ...] [--preset NAME] [--fluid NAME]\n"
            "                     [--radius R] [--speed V] [--slip V] [--gaps A:B:N [--log]]\n"
            "                     [--set model.param=value ...]\n"
            "Pair force vs gap for two equal spheres, as CSV on stdout.\n"
            "  --model NAME    enable a model (repeatable; see 'wetdem models')\n"
            "  --preset NAME   material of both spheres (default steel1; 'wetdem describe "
            "presets')\n"
            "  --fluid NAME    fluid preset: water, glycerol80, silicone10 (default water)\n"
            "  --radius R      sphere radius [m] (default 0.00635)\n"
            "  --speed V       normal approach speed [m/s] (default 0.1; < 0: separating)\n"
            "  --slip V        tangential slip speed of the surfaces [m/s] (default 0)\n"
            "  --gaps A:B:N    gaps [m] (default 1e-7:1e-3:9 with --log)\n"
            "  --log           geometric spacing of the gaps\n"
            "  --set K=V       set a parameter by dotted name, e.g. fluid.viscosity=0.05\n"
            "A minimum-separation model (fixed, roughness, ehd, max, glass) gives only the\n"
            "h_min column: list a force model that reads h_min with it (reynolds, sb, db,\n"
            "davis, nase); alone, its force columns are 0 (with a warning).\n");
}

/* Takes the value of option argv[*k]; error if missing. */
static const char* option_value(int argc, char** argv, int* k)
{
    if (*k + 1 >= argc) {
        cli_error("forces: option %s needs a value (see 'wetdem forces --help')", argv[*k]);
        return NULL;
    }
    return argv[++*k];
}

/* Handles one option that takes a value; returns CLI_EXIT_OK or CLI_EXIT_USAGE. */
static int parse_valued(const char* opt, const char* val, struct forces_opts* o)
{
    if (strcmp(opt, "--preset") == 0)
        o->preset = val;
    else if (strcmp(opt, "--fluid") == 0)
        o->fluid = val;
    else if (strcmp(opt, "--radius") == 0)
        return cli_parse_double(val, "--radius", &o->radius);
    else if (strcmp(opt, "--speed") == 0)
        return cli_parse_double(val, "--speed", &o->speed);
    else if (strcmp(opt, "--slip") == 0)
        return cli_parse_double(val, "--slip", &o->slip);
    else if (strcmp(opt, "--gaps") == 0) {
        o->gaps_text = val;
    } else if (strcmp(opt, "--model") == 0 && o->n_models < MAX_ITEMS)
        o->models[o->n_models++] = val;
    else if (strcmp(opt, "--set") == 0 && o->n_sets < MAX_ITEMS)
        o->sets[o->n_sets++] = val;
    else {
        cli_error("forces: too many %s options (at most %d)", opt, MAX_ITEMS);
        return CLI_EXIT_USAGE;
    }
    return CLI_EXIT_OK;
}

static bool takes_value(const char* opt)
{
    static const char* const valued[] = {"--preset", "--fluid", "--radius", "--speed", "--slip",
                                         "--gaps",   "--model", "--set",    NULL};
    for (size_t k = 0; valued[k]; k++)
        if (strcmp(opt, valued[k]) == 0)
            return true;
    return false;
}

static int parse_args(int argc, char** argv, struct forces_opts* o)
{
    bool log_flag = false;
    static const char* const once[] = {"--preset", "--fluid", "--radius", "--speed",
                                       "--slip",   "--gaps",  NULL};
    unsigned seen = 0;
    for (int k = 1; k < argc; k++) {
        const char* a = argv[k];
        int rc = CLI_EXIT_OK;
        if (k + 1 < argc && cli_option_once("forces", a, once, &seen) != CLI_EXIT_OK)
            return CLI_EXIT_USAGE;
        if (strcmp(a, "--log") == 0) {
            log_flag = true;
        } else if (takes_value(a)) {
            const char* val = option_value(argc, argv, &k);
            rc = val ? parse_valued(a, val, o) : CLI_EXIT_USAGE;
        } else if (a[0] == '-' && a[1] == '-') {
            static const char* const options[] = {"--preset", "--fluid", "--radius", "--speed",
                                                  "--slip",   "--gaps",  "--model",  "--set",
                                                  "--log",    NULL};
            char hint[64];
            cli_error("forces: unknown option '%s'%s (see 'wetdem forces --help')", a,
                      cli_option_hint(a, options, hint, sizeof hint));
            rc = CLI_EXIT_USAGE;
        } else if (o->n_models < MAX_ITEMS) {
            o->models[o->n_models++] = a;
        }
        if (rc != CLI_EXIT_OK)
            return rc;
    }
    o->is_log = log_flag || !o->gaps_text;
    return cli_parse_range(o->gaps_text ? o->gaps_text : "1e-7:1e-3:9", o->is_log, "--gaps",
                           &o->gaps);
}

/* Checks the numbers that the library cannot check for us (it never sees them alone). */
static int check_opts(const struct forces_opts* o)
{
    /* the ranges of the scenario keys striker_radius and speed (docs/scenarios.md) */
    if (!(o->radius > 0 && o->radius <= 1)) {
        cli_error("forces: --radius = %g m is out of range: valid (0, 1]", o->radius);
        return CLI_EXIT_USAGE;
    }
    const double speeds[2] = {o->speed, o->slip};
    for (int k = 0; k < 2; k++)
        if (!(fabs(speeds[k]) <= 1e3)) {
            cli_error("forces: --%s = %g m/s is out of range: valid [-1000, 1000]",
                      k ? "slip" : "speed", speeds[k]);
            return CLI_EXIT_USAGE;
        }
    double lo = fmin(o->gaps.first, o->gaps.last);
    if (!(lo > -o->radius)) {
        cli_error("forces: --gaps: gap %g m is out of range: overlaps must stay below the "
                  "radius, valid (%g, inf)",
                  lo, -o->radius);
        return CLI_EXIT_USAGE;
    }
    /* the gap the library sees is |x_i - x_j| - 2 R, of centres 2 R + h apart: a gap below
       about R DBL_EPSILON x 1e6 (1.4e-12 m for R = 6.35 mm) loses more than 1e-6 of itself to
       the rounding of 2 R + h, and one below R DBL_EPSILON vanishes (its row would give the
       force at another gap, or at contact) */
    for (size_t k = 0; k < o->gaps.n; k++) {
        double h = cli_range_value(&o->gaps, k), seen = (2 * o->radius + h) - 2 * o->radius;
        if (fabs(seen - h) > 1e-6 * fabs(h)) {
            cli_error("forces: --gaps: gap %g m is not resolved beside centres %g m apart (the "
                      "pair would be evaluated at a gap of %g m): valid 0 or |gap| above about "
                      "%.2g m for --radius %g m (1e-6 of the gap; or a smaller --radius)",
                      h, 2 * o->radius + h, seen, 1e6 * o->radius * DBL_EPSILON, o->radius);
            return CLI_EXIT_USAGE;
        }
    }
    if (o->n_models == 0) {
        cli_error("forces: no model given: add --model NAME (see 'wetdem models')");
        return CLI_EXIT_USAGE;
    }
    return CLI_EXIT_OK;
}

/* Only min-separation models given (each replaces the default fixed): they give the h_min
 * column and no force, so both force columns are 0 at every gap. Said, not refused (h_min
 * against the gap is a use of its own). */
static void warn_no_force(const struct wetdem_sim* sim)
{
    if (wetdem_sim_n_models(sim) > 0)
        return;
    const char* ms = wetdem_sim_min_separation_model(sim)->name;
    cli_error("warning: forces: no force model given ('%s' is a minimum-separation model: it "
              "gives only the h_min column), so f_normal and f_tangential are 0 at every "
              "gap; add a force model that reads h_min, e.g. 'wetdem forces reynolds %s' "
              "(reynolds, sb, db, davis, nase; 'wetdem models' lists them)",
              ms, ms);
}

/* Materials, fluid, two particles, models and parameters; CLI_EXIT_OK or an exit code. */
static int build_sim(struct wetdem_sim* sim, const struct forces_opts* o)
{
    int mat = wetdem_sim_add_material_preset(sim, o->preset);
    if (mat < 0) {
        cli_error("forces: --preset: %s", wetdem_sim_errmsg(sim));
        return cli_setup_exit(mat);
    }
    if (o->fluid) {
        struct wetdem_fluid fl;
        if (wetdem_fluid_preset(o->fluid, &fl) != WETDEM_OK) {
            cli_error("forces: --fluid: unknown fluid preset '%s' (valid: water, glycerol80, "
                      "silicone10)",
                      o->fluid);
            return CLI_EXIT_USAGE;
        }
        wetdem_sim_set_fluid(sim, &fl);
    }
    struct wetdem_particle pi = {.pos = {2 * o->radius + o->gaps.first, 0, 0},
                                 .vel = {-o->speed, o->slip, 0},
                                 .radius = o->radius,
                                 .material = mat};
    struct wetdem_particle pj = {.radius = o->radius, .material = mat};
    int st = wetdem_sim_add_particle(sim, pi);
    if (st == WETDEM_OK)
        st = wetdem_sim_add_particle(sim, pj);
    if (st != WETDEM_OK) {
        cli_error("forces: %s", wetdem_sim_errmsg(sim));
        return cli_setup_exit(st);
    }
    for (size_t k = 0; k < o->n_models; k++)
        if ((st = wetdem_sim_enable_model(sim, o->models[k])) != WETDEM_OK) {
            cli_error("forces: --model %s: %s", o->models[k], wetdem_sim_errmsg(sim));
            return cli_setup_exit(st);
        }
    for (size_t k = 0; k < o->n_sets; k++) {
        int rc = cli_apply_set(sim, o->sets[k]);
        if (rc != CLI_EXIT_OK)
            return rc;
    }
    warn_no_force(sim);
    return CLI_EXIT_OK;
}

static void print_header(struct wetdem_sim* sim, const struct forces_opts* o, int argc, char** argv)
{
    struct wetdem_fluid fl = wetdem_sim_fluid(sim);
    cli_print_provenance(stdout, argc, argv);
    const char* motion = o->speed > 0   ? "approaching"
                         : o->speed < 0 ? "separating"
                                        : "no normal motion";
    printf("# pair: two '%s' spheres of radius %g m; v_n = %g m/s (%s), slip %g m/s; "
           "fluid viscosity %g Pa s, surface tension %g N/m\n",
           o->preset, o->radius, cli_plain_zero(o->speed), motion, cli_plain_zero(o->slip),
           fl.viscosity, fl.surface_tension);
    printf("# models:");
    for (size_t k = 0; k < wetdem_sim_n_models(sim); k++)
        printf(" %s", wetdem_sim_model(sim, k)->name);
    printf("; min-separation: %s\n", wetdem_sim_min_separation_model(sim)->name);
    printf("# f_normal: on i along the normal from j to i, > 0 repulsive; f_tangential: on i "
           "along the slip direction; h_min: from the min-separation model (models with their "
           "own h_min, e.g. nijssen, do not read it)\n");
    printf("gap [m],f_normal [N],f_tangential [N],h_min [m]\n");
}

int cmd_forces(int argc, char** argv)
{
    if (cli_wants_help(argc, argv)) {
        usage(stdout);
        return CLI_EXIT_OK;
    }
    struct forces_opts o = {.preset = "steel1", .radius = 6.35e-3, .speed = 0.1};
    int rc = parse_args(argc, argv, &o);
    if (rc == CLI_EXIT_OK)
        rc = check_opts(&o);
    if (rc != CLI_EXIT_OK)
        return rc;
    struct wetdem_sim* sim = wetdem_sim_create();
    if (!sim) {
        cli_error("forces: out of memory");
        return CLI_EXIT_RUNTIME;
    }
    rc = build_sim(sim, &o);
    if (rc == CLI_EXIT_OK)
        print_header(sim, &o, argc, argv);
    for (size_t k = 0; rc == CLI_EXIT_OK && k < o.gaps.n; k++) {
        double h = cli_range_value(&o.gaps, k);
        wetdem_sim_particles(sim, NULL)[0].pos.x = 2 * o.radius + h;
        struct wetdem_contact c;
        struct wetdem_pair_force f;
        if (wetdem_sim_pair_force(sim, 0, 1, &c, &f) != WETDEM_OK) {
            cli_error("forces: at gap %g m: %s", h, wetdem_sim_errmsg(sim));
            rc = CLI_EXIT_RUNTIME;
            break;
        }
        const double row[] = {h, f.f_normal, f.f_tan.y, c.h_min};
        for (size_t col = 0; col < 4; col++) {
            cli_print_double(stdout, row[col]);
            putchar(col + 1 < 4 ? ',' : '\n');
        }
    }
    wetdem_sim_free(sim);
    return rc;
}

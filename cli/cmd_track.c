/*
 * cmd_track.c — `wetdem track DOTS.csv --fps F --pixel-size S [options]`: translational and
 * rotational velocities, collision frame, impact angle (Eq. 16), St_n (Eq. 2) and e_n (Eq. 3)
 * from the tracked positions of three painted dots per sphere (Punch 2023 Sec. 3.2, Eq. 23;
 * library: wetdem_track_*). The summary goes to stdout as "key = value" lines (or JSON with
 * --json); --frames FILE writes the per-frame velocities as CSV, whole or not at all (under a
 * temporary name, renamed when written; cli_write_output). Standard uncertainties (u_ keys and
 * columns) and the estimated noise are appended after the values. docs/tracking.md.
 * Exit codes: 0 ok, 1 out of memory or a failed write (a full disk), 2 bad options, a --frames
 * that cannot be written there, or a malformed track.
 */
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli_util.h"

static const char usage[] =
    "usage: wetdem track DOTS.csv --fps F --pixel-size S [--window 7] [--order 2]\n"
    "                    [--threshold 0.05] [--offset 5] [--fit-frames N] [--striker ID]\n"
    "                    [--y-down] [--radius R --mass M --viscosity MU] [--frames FILE]\n"
    "                    [--json]\n"
    "Velocities, spin, collision time, impact angle, St_n and e_n of a Stokes-cradle\n"
    "collision from tracked dots, as Punch Sec. 3.2 (docs/tracking.md). Every value\n"
    "has a standard uncertainty (u_ keys and --frames columns, 1 sigma) from the\n"
    "tracking noise, which the dots give (striker_noise_px, target_noise_px).\n"
    "  DOTS.csv      rows frame,sphere,x1,y1,x2,y2,x3,y3 (pixels); dot 1 = centre dot\n"
    "  --fps         frame rate [1/s];  --pixel-size  image resolution [m/pixel]\n"
    "  --window/--order  Savitzky-Golay smoothing (odd frames > order; 1 = none)\n"
    "  --threshold   striker velocity change marking the collision [m/s]\n"
    "  --offset      frames before/after the collision where velocities are taken\n"
    "  --fit-frames  frame intervals in each straight-line fit (default all)\n"
    "  --striker     sphere id of the striker (default: the faster one at the start)\n"
    "  --y-down      the y pixel axis points down (image rows)\n"
    "  --radius, --mass, --viscosity  sphere radius [m], mass [kg], film viscosity [Pa s]\n"
    "                for the normal Stokes number (two equal spheres)\n"
    "  --frames FILE per-frame velocities as CSV;  --json  summary as JSON\n";

struct track_cli {
    const char* input;
    const char* frames_path;
    bool json;
    struct wetdem_track_options opt;
};

/* A whole number in decimal or exponent notation ("7", "7.0", "1e3"), as every count of the
 * command line (sweep's N, fit's --max-iter) is read. */
static int parse_int(const char* text, const char* what, int* out)
{
    double v;
    if (cli_number(text, &v) != 0 || v != floor(v) || v < INT_MIN || v > INT_MAX) {
        cli_error("%s: '%s' is not an integer", what, text);
        return CLI_EXIT_USAGE;
    }
    *out = (int)v;
    return CLI_EXIT_OK;
}

/* Options that take a number: name, where it goes (double or int). */
static int parse_option(struct track_cli* c, const char* name, const char* value)
{
    struct wetdem_track_options* o = &c->opt;
    static const char* const dnames[] = {"--fps",    "--pixel-size", "--threshold",
                                         "--radius", "--mass",       "--viscosity"};
    double* dvals[] = {&o->fps, &o->pixel_size, &o->threshold, &o->radius, &o->mass, &o->viscosity};
    for (size_t k = 0; k < sizeof dnames / sizeof dnames[0]; k++)
        if (strcmp(name, dnames[k]) == 0)
            return cli_parse_double(value, name, dvals[k]);
    static const char* const inames[] = {"--window", "--order", "--offset", "--fit-frames",
                                         "--striker"};
    int* ivals[] = {&o->window, &o->order, &o->offset, &o->fit_frames, &o->striker};
    for (size_t k = 0; k < sizeof inames / sizeof inames[0]; k++)
        if (strcmp(name, inames[k]) == 0)
            return parse_int(value, name, ivals[k]);
    if (strcmp(name, "--frames") == 0) {
        c->frames_path = value;
        return CLI_EXIT_OK;
    }
    static const char* const options[] = {"--fps",    "--pixel-size", "--threshold", "--radius",
                                          "--mass",   "--viscosity",  "--window",    "--order",
                                          "--offset", "--fit-frames", "--striker",   "--frames",
                                          "--json",   "--y-down",     NULL};
    char hint[64];
    cli_error("track: unknown option '%s'%s\n%s", name,
              cli_option_hint(name, options, hint, sizeof hint), usage);
    return CLI_EXIT_USAGE;
}

static int parse_args(int argc, char** argv, struct track_cli* c)
{
    memset(c, 0, sizeof *c);
    wetdem_track_options_init(&c->opt);
    c->opt.fps = c->opt.pixel_size = NAN; /* not given (0 given is the library's to refuse) */
    static const char* const once[] = {"--fps",    "--pixel-size", "--threshold", "--radius",
                                       "--mass",   "--viscosity",  "--window",    "--order",
                                       "--offset", "--fit-frames", "--striker",   "--frames",
                                       NULL};
    unsigned seen = 0;
    for (int k = 1; k < argc; k++) {
        const char* a = argv[k];
        if (k + 1 < argc && cli_option_once("track", a, once, &seen) != CLI_EXIT_OK)
            return CLI_EXIT_USAGE;
        if (strcmp(a, "--json") == 0) {
            c->json = true;
        } else if (strcmp(a, "--y-down") == 0) {
            c->opt.y_down = true;
        } else if (strncmp(a, "--", 2) == 0) {
            if (k + 1 >= argc) {
                static const char* const takes[] = {"--frames", "a file, FILE.csv", NULL};
                if (cli_needs_value("track", a, takes))
                    return CLI_EXIT_USAGE;
                if (cli_name_in(a, once)) /* (the options that take a value) */
                    cli_error("track: option %s needs a value", a);
                else /* unknown: parse_option names it, with a hint */
                    parse_option(c, a, "");
                return CLI_EXIT_USAGE;
            }
            int rc = parse_option(c, a, argv[++k]);
            if (rc != CLI_EXIT_OK)
                return rc;
        } else if (!c->input) {
            c->input = a;
        } else {
            cli_error("track: more than one input file ('%s' and '%s')", c->input, a);
            return CLI_EXIT_USAGE;
        }
    }
    const char* missing = !c->input                  ? "DOTS.csv"
                          : isnan(c->opt.fps)        ? "--fps"
                          : isnan(c->opt.pixel_size) ? "--pixel-size"
                                                     : NULL;
    if (missing) {
        cli_error("track: %s is missing (DOTS.csv, --fps and --pixel-size are required)\n%s",
                  missing, usage);
        return CLI_EXIT_USAGE;
    }
    const char* in[1] = {c->input};
    const char* names[1] = {"DOTS.csv"};
    int rc = cli_check_output_path("track", "--frames", c->frames_path, false);
    return rc != CLI_EXIT_OK
               ? rc
               : cli_check_not_input("track", "--frames", c->frames_path, in, names, 1);
}

/* What frames_table prints. */
struct frames_ctx {
    const struct wetdem_track* t;
    int argc;
    char** argv;
};

/* --frames: the per-frame velocities of every sphere. */
static void frames_table(FILE* f, const void* ctx)
{
    const struct frames_ctx* c = ctx;
    cli_print_provenance(f, c->argc, c->argv);
    fputs("sphere [index],frame [index],time [s],vx_raw [m/s],vy_raw [m/s],omega_raw [rad/s],"
          "vx [m/s],vy [m/s],omega [rad/s],residual [m],u_vx_raw [m/s],u_vy_raw [m/s],"
          "u_omega_raw [rad/s],u_vx [m/s],u_vy [m/s],u_omega [rad/s]\n",
          f);
    for (size_t k = 0; k < wetdem_track_n_spheres(c->t); k++) {
        size_t n;
        const struct wetdem_track_sample* q = wetdem_track_samples(c->t, k, &n);
        for (size_t i = 0; i < n; i++)
            fprintf(f,
                    "%d,%ld,%.15g,%.9g,%.9g,%.9g,%.9g,%.9g,%.9g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,"
                    "%.6g\n",
                    wetdem_track_sphere_id(c->t, k), q[i].frame, cli_plain_zero(q[i].time),
                    cli_plain_zero(q[i].vx_raw), cli_plain_zero(q[i].vy_raw),
                    cli_plain_zero(q[i].omega_raw), cli_plain_zero(q[i].vx),
                    cli_plain_zero(q[i].vy), cli_plain_zero(q[i].omega),
                    cli_plain_zero(q[i].residual), cli_plain_zero(q[i].u_vx_raw),
                    cli_plain_zero(q[i].u_vy_raw), cli_plain_zero(q[i].u_omega_raw),
                    cli_plain_zero(q[i].u_vx), cli_plain_zero(q[i].u_vy),
                    cli_plain_zero(q[i].u_omega));
    }
}

struct kv {
    const char* key;
    double value;
};

static void print_summary(const struct wetdem_track* t, const struct wetdem_track_summary* s,
                          bool json)
{
    const double deg = 180.0 / M_PI;
    size_t si = wetdem_track_sphere_id(t, 0) == s->striker_id ? 0 : 1; /* noise_px's order */
    const struct kv rows[] = {
        {"collision_time_s", s->collision_time},
        {"striker", s->striker_id},
        {"target", s->target_id},
        {"striker_before_vx_m_s", s->striker_before.vx},
        {"striker_before_vy_m_s", s->striker_before.vy},
        {"striker_before_omega_rad_s", s->striker_before.omega},
        {"target_before_vx_m_s", s->target_before.vx},
        {"target_before_vy_m_s", s->target_before.vy},
        {"target_before_omega_rad_s", s->target_before.omega},
        {"striker_after_vx_m_s", s->striker_after.vx},
        {"striker_after_vy_m_s", s->striker_after.vy},
        {"striker_after_omega_rad_s", s->striker_after.omega},
        {"target_after_vx_m_s", s->target_after.vx},
        {"target_after_vy_m_s", s->target_after.vy},
        {"target_after_omega_rad_s", s->target_after.omega},
        {"angle_centres_deg", s->angle_centres * deg},
        {"impact_angle_deg", s->impact_angle * deg},
        {"speed_n0_m_s", s->speed_n0},
        {"speed_nf_m_s", s->speed_nf},
        {"e_n", s->e_n},
        {"stokes_n", s->stokes_n},
        /* appended: the estimated noise and the standard uncertainties (1 sigma) */
        {"striker_noise_px", s->noise_px[si]},
        {"target_noise_px", s->noise_px[1 - si]},
        {"u_striker_before_vx_m_s", s->u_striker_before.vx},
        {"u_striker_before_vy_m_s", s->u_striker_before.vy},
        {"u_striker_before_omega_rad_s", s->u_striker_before.omega},
        {"u_target_before_vx_m_s", s->u_target_before.vx},
        {"u_target_before_vy_m_s", s->u_target_before.vy},
        {"u_target_before_omega_rad_s", s->u_target_before.omega},
        {"u_striker_after_vx_m_s", s->u_striker_after.vx},
        {"u_striker_after_vy_m_s", s->u_striker_after.vy},
        {"u_striker_after_omega_rad_s", s->u_striker_after.omega},
        {"u_target_after_vx_m_s", s->u_target_after.vx},
        {"u_target_after_vy_m_s", s->u_target_after.vy},
        {"u_target_after_omega_rad_s", s->u_target_after.omega},
        {"u_angle_centres_deg", s->u_angle_centres * deg},
        {"u_impact_angle_deg", s->u_impact_angle * deg},
        {"u_speed_n0_m_s", s->u_speed_n0},
        {"u_speed_nf_m_s", s->u_speed_nf},
        {"u_e_n", s->u_e_n},
        {"u_stokes_n", s->u_stokes_n},
    };
    size_t n = s->has_collision ? sizeof rows / sizeof rows[0] : 0;
    if (json)
        printf("{\n  \"spheres\": %zu,\n  \"has_collision\": %s%s\n", s->n_spheres,
               s->has_collision ? "true" : "false", n ? "," : "");
    else
        printf("spheres = %zu\nhas_collision = %s\n", s->n_spheres,
               s->has_collision ? "true" : "false");
    if (n) /* (a whole number, not rounded to 9 digits as a double: frames run to 1e12) */
        printf(json ? "  \"collision_frame\": %ld,\n" : "collision_frame = %ld\n",
               s->collision_frame);
    for (size_t k = 0; k < n; k++) {
        const char* sep = k + 1 < n ? "," : "";
        if (json && !isfinite(rows[k].value))
            printf("  \"%s\": null%s\n", rows[k].key, sep);
        else if (json)
            printf("  \"%s\": %.*g%s\n", rows[k].key, k == 0 ? 15 : 9,
                   cli_plain_zero(rows[k].value), sep);
        else if (!isfinite(rows[k].value)) /* (a comment, not "nan", for key = value readers) */
            printf("# %s not computed: %s\n", rows[k].key,
                   strstr(rows[k].key, "stokes_n") ? "give --radius, --mass and --viscosity"
                                                   : "not defined for this track");
        else
            printf("%s = %.*g\n", rows[k].key, k == 0 ? 15 : 9, cli_plain_zero(rows[k].value));
    }
    if (json)
        printf("}\n");
}

int cmd_track(int argc, char** argv)
{
    if (cli_wants_help(argc, argv)) {
        fputs(usage, stdout);
        return CLI_EXIT_OK;
    }
    struct track_cli c;
    int rc = parse_args(argc, argv, &c);
    if (rc != CLI_EXIT_OK)
        return rc;
    struct wetdem_track* t = wetdem_track_create();
    if (!t) {
        cli_error("track: out of memory");
        return CLI_EXIT_RUNTIME;
    }
    struct wetdem_track_summary s;
    int st = wetdem_track_read_csv(t, c.input);
    bool read = st == WETDEM_OK; /* (the reader's messages name the file and line already) */
    if (read)
        st = wetdem_track_analyse(t, &c.opt, &s);
    if (st != WETDEM_OK) {
        cli_error("track: %s%s%s", read ? c.input : "", read ? ": " : "", wetdem_track_errmsg(t));
        wetdem_track_free(t);
        return st == WETDEM_ERR_NOMEM ? CLI_EXIT_RUNTIME : CLI_EXIT_USAGE;
    }
    struct frames_ctx fc = {t, argc, argv};
    rc = cli_check_writable("track", "--frames", c.frames_path); /* (a place it cannot write) */
    if (rc == CLI_EXIT_OK && c.frames_path)
        rc = cli_write_output(c.frames_path, "track", frames_table, &fc);
    if (rc == CLI_EXIT_OK) {
        if (!c.json)
            cli_print_provenance(stdout, argc, argv);
        print_summary(t, &s, c.json);
    }
    wetdem_track_free(t);
    return rc;
}

/*
 * cmd_fit.c — `wetdem fit FILE --data CSV --fit KEY[,KEY...] [--init V,...]`: calibrates
 * scenario parameters (any scenario key or model parameter, e.g. glass.p_gt,
 * model.fixed.h_min, material.NAME.roughness, material.NAME.friction_dry,
 * material.NAME.restitution) against measured restitution, and optionally spin, by nonlinear
 * least squares (library: wetdem_fit_run; docs/calibration.md).
 *
 * Data CSV: a header naming the columns, then one row per measurement. Columns (a trailing
 * " [unit]" in a name is ignored; each column once, no other: a column the fit would not read
 * is refused rather than ignored): stokes_n (required), e_n (required), angle_deg (optional,
 * else the scenario's angle), omega_rad_s (optional; used with --omega-scale S). Every measurement is simulated as `wetdem run FILE --set
 * collision.stokes=St --set collision.angle_deg=angle --set KEY=value ...` would; the predicted
 * e_n is the result's e_n_observed when the scenario sets collision.observe_time (Punch
 * Fig. 9 window), its e_n otherwise, and the predicted spin is |omega_i| of the striker.
 * Residuals: e_n,sim - e_n,data, and (omega_sim - omega_data)/S. Keys the data set per point
 * (collision.stokes, collision.speed, collision.angle_deg with an angle column) cannot be
 * fitted. Each key is bounded by its valid range (the library varies the distance to the
 * bounds on a log scale); a start on a bound is refused.
 *
 * The runs of one evaluation are independent and run in parallel (OpenMP) on simulations
 * built serially beforehand, so results do not depend on the thread count.
 * Exit codes: 0 ok (also with a key at a bound of its range, reported as such), 1 runtime
 * error, no convergence, a key the data do not determine (its column of the Jacobian zero, or
 * numerically zero where the fit stopped, as at a start where its effect is cut off; the table
 * is printed with standard error inf, and no --out or --curve is written), or a collision
 * whose result cannot be trusted (energy growth, h_min not resolved); 2 bad options, data or
 * scenario, before any collision runs (every data point is built with the initial values
 * first).
 */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli_util.h"
#include "output_csv.h"
#include "scenario.h"

#define MAX_SETS 256
#define MAX_POINTS 10000

static void usage(FILE* f)
{
    fprintf(f,
            "usage: wetdem fit FILE --data CSV --fit KEY[,KEY...] [--init V,...]\n"
            "                  [--set section.key=value ...] [--out FIT.csv] [--curve CURVE.csv]\n"
            "                  [--curve-points N] [--omega-scale S] [--max-iter N] [--fd-step H]\n"
            "Fits scenario parameters to measured (stokes_n, e_n[, angle_deg, omega_rad_s]).\n"
            "  --fit KEYS     scenario keys or model parameters, e.g. glass.p_gt\n"
            "  --init VALUES  initial values (default: the scenario's values)\n"
            "  --out FILE     data vs fit, one row per measurement (CSV)\n"
            "  --curve FILE   the fitted model on N Stokes numbers per angle (CSV)\n"
            "  --omega-scale S  also fit the spin; an error of S [rad/s] weighs as 1 in e_n\n"
            "  --max-iter N   trust-region iterations (50); --fd-step H Jacobian step (0.01)\n"
            "Each key stays inside its valid range (varied as the log of its distance to the\n"
            "bounds); standard errors from the Jacobian scaled by the residual variance.\n"
            "Exit 1 when the fit does not converge or the data do not determine a key: the\n"
            "predictions do not move with it where the fit stopped (e.g. a start where its\n"
            "effect is cut off: start it elsewhere with --init, or leave it out of --fit).\n"
            "See docs/calibration.md.\n");
}

struct fit_args {
    const char *file, *data, *fit, *init, *out, *curve;
    const char* sets[MAX_SETS];
    int n_sets;
    int curve_points, max_iter;
    double omega_scale, fd_step;
};

/* One measurement (or curve point). */
struct point {
    double stokes, angle_deg, e_n, omega; /* omega: NAN when not measured */
    bool has_angle;
    long line; /* line in the data file (0: a curve point) */
};

/* Everything the model function needs. */
struct fit_ctx {
    const struct cli_scenario* base;
    char keys[WETDEM_FIT_MAX_PARAMS][2 * CLI_NAME_MAX];
    size_t n_keys;
    const struct point* pts;
    size_t n_pts;
    bool use_omega;
    const char* data; /* the data file, for messages */
};

static int parse_args(int argc, char** argv, struct fit_args* a)
{
    memset(a, 0, sizeof *a);
    a->curve_points = 40;
    a->max_iter = 50;
    a->fd_step = 1e-2;
    static const char* const once[] = {
        "--data",        "--fit",     "--init",     "--out",          "--curve",
        "--omega-scale", "--fd-step", "--max-iter", "--curve-points", NULL};
    unsigned seen = 0;
    for (int k = 1; k < argc; k++) {
        const char* s = argv[k];
        const char* v = k + 1 < argc ? argv[k + 1] : NULL;
        int rc = CLI_EXIT_OK;
        double x;
        if (v && cli_option_once("fit", s, once, &seen) != CLI_EXIT_OK)
            return CLI_EXIT_USAGE;
        if (s[0] != '-') {
            if (a->file) {
                cli_error("fit: more than one scenario file ('%s' and '%s')", a->file, s);
                return CLI_EXIT_USAGE;
            }
            a->file = s;
            continue;
        }
        static const char* const options[] = {
            "--data",        "--fit",     "--init",     "--out",          "--curve", "--set",
            "--omega-scale", "--fd-step", "--max-iter", "--curve-points", NULL};
        if (!v) {
            static const char* const takes[] = {
                "--data", "a CSV file", "--fit",  "KEYS",  "--init",    "VALUES", "--out",
                "a file", "--curve",    "a file", "--set", "KEY=VALUE", NULL};
            char hint[64];
            if (cli_needs_value("fit", s, takes))
                ;
            else if (cli_name_in(s, options))
                cli_error("fit: option '%s' needs a value", s);
            else /* (every option of fit takes a value: this one is none of them) */
                cli_error("fit: unknown option '%s'%s", s,
                          cli_option_hint(s, options, hint, sizeof hint));
            usage(stderr);
            return CLI_EXIT_USAGE;
        }
        k++;
        if (strcmp(s, "--data") == 0)
            a->data = v;
        else if (strcmp(s, "--fit") == 0)
            a->fit = v;
        else if (strcmp(s, "--init") == 0)
            a->init = v;
        else if (strcmp(s, "--out") == 0)
            a->out = v;
        else if (strcmp(s, "--curve") == 0)
            a->curve = v;
        else if (strcmp(s, "--set") == 0 && a->n_sets < MAX_SETS)
            a->sets[a->n_sets++] = v;
        else if (strcmp(s, "--omega-scale") == 0) {
            if ((rc = cli_parse_double(v, s, &a->omega_scale)) == CLI_EXIT_OK &&
                !(a->omega_scale > 0)) {
                cli_error("fit: --omega-scale %s: must be > 0 [rad/s]", v);
                rc = CLI_EXIT_USAGE;
            }
        } else if (strcmp(s, "--fd-step") == 0) {
            rc = cli_parse_double(v, s, &a->fd_step);
            if (rc == CLI_EXIT_OK && !(a->fd_step > 0 && a->fd_step < 1)) {
                cli_error("fit: --fd-step %s: must be in (0, 1) (a relative step)", v);
                rc = CLI_EXIT_USAGE;
            }
        } else if (strcmp(s, "--max-iter") == 0 || strcmp(s, "--curve-points") == 0) {
            if ((rc = cli_parse_double(v, s, &x)) == CLI_EXIT_OK &&
                (x != floor(x) || x < 1 || x > 100000)) {
                cli_error("fit: %s %s: must be an integer in [1, 100000]", s, v);
                rc = CLI_EXIT_USAGE;
            }
            if (rc == CLI_EXIT_OK)
                *(s[2] == 'm' ? &a->max_iter : &a->curve_points) = (int)x;
        } else if (strcmp(s, "--set") == 0) { /* (the only option refused with a value) */
            cli_error("fit: more than %d --set options", MAX_SETS);
            usage(stderr);
            return CLI_EXIT_USAGE;
        } else {
            char hint[64];
            cli_error("fit: unknown option '%s'%s", s,
                      cli_option_hint(s, options, hint, sizeof hint));
            usage(stderr);
            return CLI_EXIT_USAGE;
        }
        if (rc != CLI_EXIT_OK)
            return rc;
    }
    if (!a->file || !a->data || !a->fit) {
        cli_error("fit: FILE, --data CSV and --fit KEY[,KEY...] are required");
        usage(stderr);
        return CLI_EXIT_USAGE;
    }
    int rc = cli_check_output_path("fit", "--out", a->out, false);
    if (rc == CLI_EXIT_OK)
        rc = cli_check_output_path("fit", "--curve", a->curve, false);
    /* neither output may be an input, nor the other output (one would replace the other) */
    const char* in[3] = {a->file, a->data, a->out};
    const char* names[3] = {"FILE", "--data", "--out"};
    if (rc == CLI_EXIT_OK)
        rc = cli_check_not_input("fit", "--out", a->out, in, names, 2);
    if (rc == CLI_EXIT_OK)
        rc = cli_check_not_input("fit", "--curve", a->curve, in, names, 3);
    return rc;
}

/* ---- data file ---------------------------------------------------------------------------- */

enum { COL_STOKES, COL_EN, COL_ANGLE, COL_OMEGA, N_COLS };
static const char* const col_names[N_COLS + 1] = {"stokes_n", "e_n", "angle_deg", "omega_rad_s",
                                                  NULL};
static const char* const col_units[N_COLS] = {"-", "-", "deg", "rad/s"};

/* A hint for a line whose columns do not fit (text as read, before the split): "; ;-separated?
 * use commas" for a ';' in it, "; decimal comma? use a point (0.5, not 0,5)" for more columns
 * than the header's where a ',' stands between digits and no '.' is seen; else "". */
static const char* separator_hint(const char* text, int n, int n_header)
{
    if (strchr(text, ';'))
        return "; ;-separated? use commas";
    bool digit_comma_digit = false;
    for (const char* p = text; *p && !digit_comma_digit; p++)
        digit_comma_digit =
            p > text && *p == ',' && isdigit((unsigned char)p[-1]) && isdigit((unsigned char)p[1]);
    if (n > n_header && digit_comma_digit && !strchr(text, '.'))
        return "; decimal comma? use a point (0.5, not 0,5)";
    return "";
}

/* Maps the header's fields to the columns: each known column at most once, no other (a column
 * the fit would not read, e.g. per-point uncertainties, is refused rather than ignored). */
static int read_header(const char* path, long line, const char* text, char** f, int n,
                       int col[N_COLS])
{
    char why[300];
    int bad = 0, rc = cli_csv_columns(f, n, col_names, col_units, col, &bad, why, sizeof why);
    if (rc != 0) {
        if (rc == CLI_CSV_TWICE)
            cli_error("%s:%ld: %s", path, line, why);
        else
            cli_error("%s:%ld: column %d: %s%s; the columns are stokes_n and e_n (required), "
                      "angle_deg and omega_rad_s (per-point uncertainties are not read: the "
                      "scatter of the data about the fit sets the standard errors)",
                      path, line, bad + 1, why, separator_hint(text, n, n));
        return CLI_EXIT_USAGE;
    }
    if (col[COL_STOKES] < 0 || col[COL_EN] < 0) {
        cli_error("%s:%ld: the header must name columns stokes_n and e_n (optional: angle_deg, "
                  "omega_rad_s)",
                  path, line);
        return CLI_EXIT_USAGE;
    }
    return CLI_EXIT_OK;
}

/* Reads column c of a row (with the header's number of columns) into *v with its range
 * check. */
static int read_value(const char* path, long line, const char* hint, char** f,
                      const int col[N_COLS], int c, double* v)
{
    const char* t = f[col[c]];
    while (isspace((unsigned char)*t)) /* (a space after the comma) */
        t++;
    bool ok = cli_number(t, v) == 0;
    const char* why = "a finite number";
    char range[160];
    struct wetdem_param_desc st = {.max = INFINITY}; /* (the key's range: the speed follows) */
    cli_scenario_key_range("collision", "stokes", &st);
    snprintf(range, sizeof range, "a Stokes number in (0, %g] ([collision] stokes)", st.max);
    if (ok && c == COL_STOKES && !(*v > 0 && *v <= st.max))
        ok = false, why = range;
    if (ok && c == COL_ANGLE && !(*v >= 0 && *v < 90))
        ok = false, why = "an angle in [0, 90) deg";
    /* a coefficient of restitution: at most 1 for these models, above it by the scatter of a
       measurement only (Punch's repeated experiments scatter by about 0.02) */
    if (ok && c == COL_EN && !(*v >= 0 && *v < 1.5))
        ok = false, why = "a restitution coefficient in [0, 1.5)";
    if (ok && c == COL_OMEGA && !(*v >= 0))
        ok = false, why = "a spin magnitude >= 0 rad/s";
    if (!ok) {
        cli_error("%s:%ld: column %s: '%s' is not %s%s", path, line, col_names[c], t, why, hint);
        return CLI_EXIT_USAGE;
    }
    return CLI_EXIT_OK;
}

static int read_row(const char* path, long line, const char* text, char** f, int n, int n_header,
                    const int col[N_COLS], struct point* p)
{
    if (n != n_header) { /* (a value too many or too few: the columns would shift) */
        cli_error("%s:%ld: %d columns, but the header has %d%s", path, line, n, n_header,
                  separator_hint(text, n, n_header));
        return CLI_EXIT_USAGE;
    }
    const char* hint = separator_hint(text, n, n_header);
    int rc = read_value(path, line, hint, f, col, COL_STOKES, &p->stokes);
    if (rc == CLI_EXIT_OK)
        rc = read_value(path, line, hint, f, col, COL_EN, &p->e_n);
    p->has_angle = col[COL_ANGLE] >= 0;
    p->omega = NAN;
    p->line = line;
    if (rc == CLI_EXIT_OK && p->has_angle)
        rc = read_value(path, line, hint, f, col, COL_ANGLE, &p->angle_deg);
    if (rc == CLI_EXIT_OK && col[COL_OMEGA] >= 0)
        rc = read_value(path, line, hint, f, col, COL_OMEGA, &p->omega);
    return rc;
}

/* Reads one line of fp into buf (n bytes: at most n - 1 characters, the '\n' kept, NUL-terminated)
 * as fgets does, but tells a NUL byte, which fgets would take for the end of the line (a binary
 * file was read as lines cut short, or as one too long): 1 a line, 0 the end of the file, -1 a
 * line longer than n - 2 characters, -2 a NUL byte in the line. */
static int read_text_line(FILE* fp, char* buf, size_t n)
{
    size_t len = 0;
    int c;
    while ((c = getc(fp)) != EOF) {
        if (c == '\0')
            return -2;
        if (len + 1 >= n)
            return -1;
        buf[len++] = (char)c;
        if (c == '\n')
            break;
    }
    buf[len] = '\0';
    return len > 0 ? 1 : 0;
}

static int read_data(const char* path, struct point** out, size_t* n_out)
{
    FILE* fp = fopen(path, "r");
    if (!fp) {
        cli_error("fit: cannot open data file %s: %s", path, strerror(errno));
        return CLI_EXIT_USAGE;
    }
    struct point* pts = calloc(MAX_POINTS, sizeof *pts);
    char buf[4096], *f[64];
    int col[N_COLS], rc = pts ? CLI_EXIT_OK : CLI_EXIT_RUNTIME;
    if (!pts)
        cli_error("fit: out of memory for the data of %s", path);
    bool have_header = false;
    int n_header = 0;
    size_t n = 0;
    int got;
    for (long line = 1; rc == CLI_EXIT_OK && (got = read_text_line(fp, buf, sizeof buf)) != 0;
         line++) {
        if (got < 0) { /* (the rest of a long line would be read as another line) */
            if (got == -2)
                cli_error("%s:%ld: a NUL byte in the line: not a text (CSV) file", path, line);
            else
                cli_error("%s:%ld: line longer than %zu characters", path, line, sizeof buf - 2);
            rc = CLI_EXIT_USAGE;
            break;
        }
        char* s = buf;
        if (line == 1 && strncmp(s, "\xEF\xBB\xBF", 3) == 0) /* a UTF-8 byte-order mark */
            s += 3;
        s += strspn(s, " \t");
        if (*s == '#' || *s == '\n' || *s == '\r' || *s == '\0')
            continue;
        char text[sizeof buf];
        snprintf(text, sizeof text, "%s", s);
        int nf = cli_csv_split(s, f, 64);
        if (!have_header) {
            rc = read_header(path, line, text, f, nf, col);
            have_header = true;
            n_header = nf;
        } else if (n == MAX_POINTS) {
            cli_error("%s:%ld: more than %d data rows", path, line, MAX_POINTS);
            rc = CLI_EXIT_USAGE;
        } else {
            rc = read_row(path, line, text, f, nf, n_header, col, &pts[n++]);
        }
    }
    if (rc == CLI_EXIT_OK && ferror(fp)) { /* (e.g. a directory: it opens, but does not read) */
        cli_error("%s: cannot read data file: %s", path, strerror(errno));
        rc = CLI_EXIT_USAGE;
    }
    fclose(fp);
    if (rc == CLI_EXIT_OK && n == 0) {
        cli_error("%s: no data rows", path);
        rc = CLI_EXIT_USAGE;
    }
    if (rc != CLI_EXIT_OK) {
        free(pts);
        return rc;
    }
    *out = pts;
    *n_out = n;
    return CLI_EXIT_OK;
}

/* ---- simulation of the measurements ------------------------------------------------------- */

/* Builds the set-up of one point: the base scenario with the point's Stokes number and angle
 * and the parameter values. Returns an exit code (the builder prints its errors):
 * CLI_EXIT_USAGE when the scenario rejects the point, CLI_EXIT_RUNTIME when out of memory. */
static int build_point(const struct fit_ctx* c, const double* params, const struct point* p,
                       struct cli_setup* su)
{
    struct cli_scenario sc;
    int rc = cli_scenario_copy(c->base, &sc);
    if (rc != CLI_EXIT_OK)
        return rc;
    char set[2 * CLI_NAME_MAX + 64];
    snprintf(set, sizeof set, "collision.stokes=%.17g", p->stokes);
    rc = cli_scenario_override(&sc, set);
    if (rc == CLI_EXIT_OK && p->has_angle) {
        snprintf(set, sizeof set, "collision.angle_deg=%.17g", p->angle_deg);
        rc = cli_scenario_override(&sc, set);
    }
    for (size_t j = 0; rc == CLI_EXIT_OK && j < c->n_keys; j++) {
        snprintf(set, sizeof set, "%s=%.17g", c->keys[j], params[j]);
        rc = cli_scenario_override(&sc, set);
    }
    if (rc == CLI_EXIT_OK)
        rc = cli_scenario_build(&sc, su);
    cli_scenario_free(&sc);
    return rc;
}

/* e_n as Punch reports it: at observe_time when set (Fig. 9); 0 for a stick that never
 * separated (no outgoing normal velocity). */
static double reported_e_n(const struct cli_setup* su, const struct wetdem_collision_result* r)
{
    double e = su->spec.observe_time > 0 ? r->e_n_observed : r->e_n;
    return (!isfinite(e) && !r->separated) ? 0.0 : e;
}

/* "FILE:LINE (St_n = X, angle_deg = A)" of a data point, or "the point St_n = X, ..." of a
 * curve point, into buf. */
static void point_where(const struct fit_ctx* c, const struct point* p, char* buf, size_t n)
{
    char angle[64] = "";
    if (p->has_angle)
        snprintf(angle, sizeof angle, ", angle_deg = %g", p->angle_deg);
    if (p->line)
        snprintf(buf, n, "%s:%ld (St_n = %g%s)", c->data, p->line, p->stokes, angle);
    else
        snprintf(buf, n, "the point St_n = %g%s", p->stokes, angle);
}

/* "KEY = value, KEY2 = value2" of the fitted keys into buf. */
static void param_values(const struct fit_ctx* c, const double* params, char* buf, size_t n)
{
    size_t used = 0;
    buf[0] = '\0';
    for (size_t j = 0; j < c->n_keys && used < n; j++)
        used += (size_t)snprintf(buf + used, n - used, "%s%s = %.9g", j ? ", " : "", c->keys[j],
                                 params[j]);
}

/* The first collision, in input order, that failed or whose result cannot be trusted: its
 * message into msg and WETDEM_ERR_CALLBACK, or WETDEM_OK. */
static int first_failure(const struct fit_ctx* c, const struct point* pts, size_t n,
                         const struct cli_setup* su, const int* status,
                         const struct wetdem_collision_result* res, char* msg, size_t msg_size)
{
    for (size_t k = 0; k < n; k++) {
        char why[600], where[1200];
        point_where(c, &pts[k], where, sizeof where);
        if (status[k] < 0)
            snprintf(msg, msg_size, "the collision of %s failed: %s", where,
                     wetdem_sim_errmsg(su[k].sim));
        /* (as run and sweep report them; an unresolved h_min makes e_n a step function of
           the parameters, whose finite differences are 0 or huge) */
        else if (cli_energy_grew(res[k].energy_ratio, why, sizeof why) ||
                 cli_hmin_unresolved(&res[k], why, sizeof why))
            snprintf(msg, msg_size, "the collision of %s: %s", where, why);
        else
            continue;
        return WETDEM_ERR_CALLBACK;
    }
    return WETDEM_OK;
}

/* Simulates n points with the given parameters into e_n[] and omega[] (|omega_i|). A point
 * the scenario rejects (the builder printed why) gives WETDEM_ERR_INVALID; running out of
 * memory WETDEM_ERR_NOMEM, with the message in msg as for every failure. */
static int simulate(const struct fit_ctx* c, const double* params, const struct point* pts,
                    size_t n, double* e_n, double* omega, char* msg, size_t msg_size)
{
    struct cli_setup* su = calloc(n, sizeof *su);
    int* status = calloc(n, sizeof *status);
    struct wetdem_collision_result* res = calloc(n, sizeof *res);
    int st = (su && status && res) ? WETDEM_OK : WETDEM_ERR_NOMEM;
    if (st != WETDEM_OK)
        snprintf(msg, msg_size, "out of memory for %zu collisions", n);
    size_t built = 0;
    for (; st == WETDEM_OK && built < n; built++) {
        int rc = build_point(c, params, &pts[built], &su[built]);
        if (rc == CLI_EXIT_OK)
            continue;
        char where[1200], values[600];
        point_where(c, &pts[built], where, sizeof where);
        param_values(c, params, values, sizeof values);
        st = rc == CLI_EXIT_RUNTIME ? WETDEM_ERR_NOMEM : WETDEM_ERR_INVALID;
        if (st == WETDEM_ERR_NOMEM)
            snprintf(msg, msg_size, "out of memory setting up %s (the message above)", where);
        else
            snprintf(msg, msg_size, "the scenario rejects %s with %s (the message above)", where,
                     values);
    }
    if (st == WETDEM_OK) {
#pragma omp parallel for schedule(dynamic, 1)
        for (size_t k = 0; k < n; k++) {
            struct wetdem_collision_result* r = &res[k];
            status[k] = wetdem_collision_run(su[k].sim, &su[k].spec, r);
            e_n[k] = reported_e_n(&su[k], r);
            omega[k] = sqrt(r->omega_i.x * r->omega_i.x + r->omega_i.y * r->omega_i.y +
                            r->omega_i.z * r->omega_i.z);
        }
        st = first_failure(c, pts, n, su, status, res, msg, msg_size);
    }
    for (size_t k = 0; su && k < built; k++)
        cli_setup_free(&su[k]);
    free(su);
    free(status);
    free(res);
    return st;
}

/* Progress of the fit on stderr when it is a terminal (as sweep and map show theirs): the model
 * evaluations so far, each a collision per data point, at most every 0.2 s. One fit a process:
 * the solver calls fit_model serially. */
static struct {
    bool show, shown;
    size_t evals;
    double t0, last;
} progress;

static void progress_start(void)
{
    progress.show = isatty(STDERR_FILENO);
    progress.shown = false;
    progress.evals = 0;
    progress.t0 = progress.last = omp_get_wtime();
}

static void progress_show(const struct fit_ctx* c, double now)
{
    fprintf(stderr, "\rfit: %zu model evaluations (x %zu collisions), %.1f s elapsed   ",
            progress.evals, c->n_pts, now - progress.t0);
    progress.shown = true;
    progress.last = now;
}

static void progress_step(const struct fit_ctx* c)
{
    progress.evals++;
    double now = omp_get_wtime();
    if (progress.show && (!progress.shown || now - progress.last >= 0.2))
        progress_show(c, now);
}

/* The last count, and the line ended (the messages and the table start on their own). */
static void progress_end(const struct fit_ctx* c)
{
    if (progress.shown) {
        progress_show(c, omp_get_wtime());
        fputc('\n', stderr);
    }
    progress.shown = false;
}

/* wetdem_fit_model_fn: e_n of every point, then (with omega) |omega_i| of every point. A
 * point the scenario rejects is not bad input here: the data and the initial values were
 * checked before the fit (check_points), so the fit tried values the scenario does not accept
 * with that point (WETDEM_ERR_CALLBACK, exit 1). */
static int fit_model(const double* params, double* predicted, char* msg, size_t msg_size, void* ctx)
{
    const struct fit_ctx* c = ctx;
    double* omega = malloc(c->n_pts * sizeof *omega);
    if (!omega) {
        snprintf(msg, msg_size, "out of memory for %zu spins", c->n_pts);
        return WETDEM_ERR_NOMEM;
    }
    int st = simulate(c, params, c->pts, c->n_pts, predicted, omega, msg, msg_size);
    progress_step(c);
    if (st == WETDEM_OK && c->use_omega)
        memcpy(predicted + c->n_pts, omega, c->n_pts * sizeof *omega);
    free(omega);
    return st == WETDEM_ERR_INVALID ? WETDEM_ERR_CALLBACK : st;
}

/* ---- parameters --------------------------------------------------------------------------- */

/* Whether `key=value` is accepted as an override of the base scenario (the checker prints
 * why not). Returns its exit code. */
static int probe_override(const struct fit_ctx* c, const char* key, const char* value)
{
    struct cli_scenario probe;
    char set[2 * CLI_NAME_MAX + 64];
    snprintf(set, sizeof set, "%s=%s", key, value);
    if (cli_scenario_copy(c->base, &probe) != CLI_EXIT_OK)
        return CLI_EXIT_RUNTIME;
    int rc = cli_scenario_override(&probe, set);
    cli_scenario_free(&probe);
    return rc;
}

/* Whether the key (full name) is one the fit sets per data point, which a fit of it
 * (fitting: from --fit) or a --set of it (tok the whole override) would override: a message
 * and CLI_EXIT_USAGE, else CLI_EXIT_OK. */
static int check_not_per_point(bool fitting, const char* tok, const char* full,
                               const struct fit_ctx* c)
{
    const char* why = NULL;
    if (strcmp(full, "collision.stokes") == 0)
        why = fitting ? "every data row sets it (its stokes_n), so every point would "
                        "predict the same"
                      : "every data row sets it (its stokes_n)";
    else if (strcmp(full, "collision.speed") == 0)
        why = "every data row sets the Stokes number (stokes_n), from which the speed follows "
              "(speed and stokes exclude each other)";
    else if (strcmp(full, "collision.angle_deg") == 0 && c->n_pts && c->pts[0].has_angle)
        why = "every data row sets it (the angle_deg column)";
    if (!why)
        return CLI_EXIT_OK;
    cli_error("fit: %s %s: %s %s: %s", fitting ? "--fit" : "--set", tok, full,
              fitting ? "cannot be fitted" : "would never be used", why);
    return CLI_EXIT_USAGE;
}

/* Each --set of a key the data set per point is refused (check_not_per_point). */
static int check_sets(const struct fit_args* a, const struct fit_ctx* c)
{
    for (int k = 0; k < a->n_sets; k++) {
        char section[CLI_NAME_MAX], key[CLI_NAME_MAX], full[2 * CLI_NAME_MAX + 2];
        if (cli_override_split(a->sets[k], section, key, NULL) != 0)
            return CLI_EXIT_USAGE;
        snprintf(full, sizeof full, "%s.%s", section, key);
        if (check_not_per_point(false, a->sets[k], full, c) != CLI_EXIT_OK)
            return CLI_EXIT_USAGE;
    }
    return CLI_EXIT_OK;
}

/* Splits --fit into full "section.key" names and checks each: a known numeric key, not one
 * the data set per point, and not the same key twice under two names (glass.p_gt and
 * model.glass.p_gt: the second would override the first, whose column of the Jacobian would
 * be zero). */
static int parse_keys(const char* list, struct fit_ctx* c)
{
    char buf[1024];
    snprintf(buf, sizeof buf, "%s", list);
    size_t len = strlen(buf);
    if (!len || buf[0] == ',' || buf[len - 1] == ',' || strstr(buf, ",,")) {
        cli_error("fit: --fit '%s': an empty key (the keys are separated by single commas)", list);
        return CLI_EXIT_USAGE;
    }
    const char* given[WETDEM_FIT_MAX_PARAMS];
    c->n_keys = 0;
    for (char* tok = strtok(buf, ","); tok; tok = strtok(NULL, ",")) {
        if (c->n_keys == WETDEM_FIT_MAX_PARAMS) {
            cli_error("fit: --fit: at most %d parameters", WETDEM_FIT_MAX_PARAMS);
            return CLI_EXIT_USAGE;
        }
        char section[CLI_NAME_MAX], key[CLI_NAME_MAX];
        if (cli_key_split("--fit", tok, section, key) != 0 ||
            cli_check_numeric_key("fit", "--fit", tok, section, key, "fitted") != CLI_EXIT_OK)
            return CLI_EXIT_USAGE;
        char* full = c->keys[c->n_keys];
        snprintf(full, sizeof c->keys[0], "%s.%s", section, key);
        for (size_t j = 0; j < c->n_keys; j++)
            if (strcmp(c->keys[j], full) == 0) {
                cli_error("fit: --fit: %s is given twice (as '%s' and '%s'); each key once", full,
                          given[j], tok);
                return CLI_EXIT_USAGE;
            }
        if (check_not_per_point(true, tok, full, c) != CLI_EXIT_OK)
            return CLI_EXIT_USAGE;
        if (strncmp(section, "material.", 9) == 0 &&
            !cli_scenario_has_section(c->base, section)) { /* (the override says why) */
            int rc = probe_override(c, full, "0");
            cli_error("fit: --fit %s: not a key of this scenario (the message above)", tok);
            return rc == CLI_EXIT_OK ? CLI_EXIT_USAGE : rc;
        }
        given[c->n_keys] = tok; /* (in buf, split in place) */
        c->n_keys++;
    }
    if (c->n_keys == 0) {
        cli_error("fit: --fit: no parameter given");
        return CLI_EXIT_USAGE;
    }
    return CLI_EXIT_OK;
}

/* The residual variance needs a degree of freedom: more residuals than parameters. */
static int check_counts(const struct fit_args* a, const struct fit_ctx* c)
{
    size_t n = c->n_pts * (c->use_omega ? 2 : 1);
    if (n > c->n_keys)
        return CLI_EXIT_OK;
    cli_error("fit: %s has %zu data row%s (%zu residual%s%s) for %zu parameter%s: need more "
              "residuals than parameters, at least %zu rows (the standard errors use the "
              "residual variance cost/(n - p))",
              a->data, c->n_pts, c->n_pts == 1 ? "" : "s", n, n == 1 ? "" : "s",
              c->use_omega ? ": e_n and spin" : "", c->n_keys, c->n_keys == 1 ? "" : "s",
              c->use_omega ? c->n_keys / 2 + 1 : c->n_keys + 1);
    return CLI_EXIT_USAGE;
}

/* Unit of a fitted key as documented ("-" when dimensionless or unknown). */
static const char* key_unit(const char* full)
{
    const char* dot = strrchr(full, '.');
    char section[CLI_NAME_MAX];
    snprintf(section, sizeof section, "%.*s", (int)(dot - full), full);
    const char* u = cli_scenario_key_unit(section, dot + 1);
    return (u && *u) ? u : "-";
}

/* Value of a material or fluid field from the section's preset (material.NAME.KEY with
 * "preset = P", or fluid.KEY with the fluid preset, default water). */
static bool preset_value(const struct cli_scenario* sc, const char* section, const char* key,
                         double* v)
{
    bool is_fluid = strcmp(section, "fluid") == 0;
    if (!is_fluid && strncmp(section, "material.", 9) != 0)
        return false;
    const char* preset = cli_scenario_text(sc, section, "preset", is_fluid ? "water" : NULL);
    struct wetdem_material m;
    struct wetdem_fluid f;
    const void* base = is_fluid ? (const void*)&f : (const void*)&m;
    if (!preset ||
        (is_fluid ? wetdem_fluid_preset(preset, &f) : wetdem_material_preset(preset, &m)))
        return false;
    const struct wetdem_param_desc* d =
        wetdem_param_find(is_fluid ? wetdem_fluid_params() : wetdem_material_params(), key);
    if (!d)
        return false;
    memcpy(v, (const char*)base + d->offset, sizeof *v);
    return true;
}

/* The current value of a model parameter [model.NAME] KEY in the built simulation. */
static bool model_value(const struct cli_scenario* sc, const char* section, const char* key,
                        double* v)
{
    if (strncmp(section, "model.", 6) != 0)
        return false;
    struct cli_setup su;
    if (cli_scenario_build(sc, &su) != CLI_EXIT_OK)
        return false;
    char name[2 * CLI_NAME_MAX];
    snprintf(name, sizeof name, "%s.%s", section + 6, key);
    int st = wetdem_sim_param(su.sim, name, v);
    cli_setup_free(&su);
    return st == WETDEM_OK;
}

/* Initial value of key j: the scenario's value, its preset's, or the model's current value.
 * An unknown key gets the scenario checker's message (with a suggestion). */
static int initial_value(const struct fit_ctx* c, size_t j, double* v)
{
    const char* full = c->keys[j];
    const char* dot = strrchr(full, '.');
    char section[CLI_NAME_MAX];
    snprintf(section, sizeof section, "%.*s", (int)(dot - full), full);
    const struct cli_entry* e = cli_scenario_find(c->base, section, dot + 1);
    if (e && cli_number(e->value, v) == 0)
        return CLI_EXIT_OK;
    if (preset_value(c->base, section, dot + 1, v) || model_value(c->base, section, dot + 1, v))
        return CLI_EXIT_OK;
    struct cli_section_info info;
    if (cli_section_lookup(section, &info) == 0 && info.open_keys) {
        cli_error("fit: %s is not set in %s; give its initial value with --init", full,
                  c->base->file);
        return CLI_EXIT_USAGE;
    }
    /* Not settable here (e.g. a model the scenario does not enable): the checker says why. */
    int rc = probe_override(c, full, "1");
    if (rc == CLI_EXIT_RUNTIME)
        return rc;
    if (rc == CLI_EXIT_OK)
        cli_error("fit: %s has no numeric value in %s; give it with --init", full, c->base->file);
    return CLI_EXIT_USAGE;
}

/* The descriptor of a fitted key's valid range into *d ("material.striker.restitution": key
 * restitution of [material.striker]); false for a key of unknown range. */
static bool key_desc(const char* full, struct wetdem_param_desc* d)
{
    const char* dot = strrchr(full, '.');
    char section[CLI_NAME_MAX];
    snprintf(section, sizeof section, "%.*s", (int)(dot - full), full);
    return cli_scenario_key_range(section, dot + 1, d) == 0;
}

static int initial_values(const struct fit_args* a, const struct fit_ctx* c, double* init)
{
    if (!a->init) {
        for (size_t j = 0; j < c->n_keys; j++)
            if (initial_value(c, j, &init[j]) != CLI_EXIT_OK)
                return CLI_EXIT_USAGE;
        return CLI_EXIT_OK;
    }
    char buf[1024];
    snprintf(buf, sizeof buf, "%s", a->init);
    size_t len = strlen(buf), n = 0;
    if (!len || buf[0] == ',' || buf[len - 1] == ',' || strstr(buf, ",,")) {
        cli_error("fit: --init '%s': an empty value (the values are separated by single commas, "
                  "one for each --fit key)",
                  a->init);
        return CLI_EXIT_USAGE;
    }
    char* save = NULL;
    for (char* tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        if (n == c->n_keys) {
            cli_error("fit: --init has more values than --fit has keys (%zu)", c->n_keys);
            return CLI_EXIT_USAGE;
        }
        if (cli_parse_double(tok, "--init", &init[n]) != CLI_EXIT_OK)
            return CLI_EXIT_USAGE;
        /* the value as given, against its key's range, before the fit (which works on its
           logarithm and would report exp(log(v)) at the first collision instead): the range
           in the --init message, else the scenario checker's message of the override */
        struct wetdem_param_desc d;
        char why[256];
        if (key_desc(c->keys[n], &d) &&
            wetdem_param_validate(&d, init[n], why, sizeof why) != WETDEM_OK) {
            cli_error("fit: --init: %s is not a valid initial value of %s: %s", tok, c->keys[n],
                      why);
            return CLI_EXIT_USAGE;
        }
        int rc = probe_override(c, c->keys[n], tok);
        if (rc != CLI_EXIT_OK) {
            cli_error("fit: --init: %s is not a valid initial value of %s (the message above)", tok,
                      c->keys[n]);
            return rc;
        }
        n++;
    }
    if (n != c->n_keys) {
        cli_error("fit: --init has %zu values for %zu keys", n, c->n_keys);
        return CLI_EXIT_USAGE;
    }
    return CLI_EXIT_OK;
}

/* The fit's bounds of every key, its valid range [min, max] (the library varies the distance to
 * a bound on a log scale, so every evaluation stays inside; docs/calibration.md "Method").
 * Keys of an unknown range are unbounded, fitted in log form when their initial value is > 0.
 * A start on a bound of the range cannot be varied that way: refused (exit 2) with the range. */
static int key_bounds(const struct fit_ctx* c, const double* init, double* lower, double* upper,
                      bool* is_log)
{
    for (size_t j = 0; j < c->n_keys; j++) {
        const char* full = c->keys[j];
        struct wetdem_param_desc d;
        lower[j] = -INFINITY, upper[j] = INFINITY, is_log[j] = false;
        if (!key_desc(full, &d)) {
            is_log[j] = init[j] > 0;
            continue;
        }
        char range[128];
        wetdem_param_range_text(&d, range, sizeof range);
        if (d.integer) {
            cli_error("fit: --fit %s: takes whole numbers only (%s), which a least-squares fit "
                      "cannot vary",
                      full, range);
            return CLI_EXIT_USAGE;
        }
        lower[j] = d.min, upper[j] = d.max;
        if (init[j] > d.min && init[j] < d.max)
            continue;
        cli_error("fit: %s starts at %g, on the bound of its range %s: the fit varies the "
                  "distance to the bounds on a log scale (so it never leaves the range) and cannot "
                  "start on one; give --init a value inside the range, of the size you expect",
                  full, init[j], range);
        return CLI_EXIT_USAGE;
    }
    return CLI_EXIT_OK;
}

/* Builds every data point with the initial values, serially and before any collision runs:
 * a point the scenario rejects is bad input, named by its file and line (exit 2). */
static int check_points(const struct fit_ctx* c, const double* init)
{
    for (size_t k = 0; k < c->n_pts; k++) {
        struct cli_setup su;
        int rc = build_point(c, init, &c->pts[k], &su);
        if (rc == CLI_EXIT_OK) {
            cli_setup_free(&su);
            continue;
        }
        if (rc == CLI_EXIT_RUNTIME) /* (out of memory: the builder said so) */
            return rc;
        char where[1200], values[600];
        point_where(c, &c->pts[k], where, sizeof where);
        param_values(c, init, values, sizeof values);
        cli_error("fit: %s: the scenario rejects this data point with %s (the message above)",
                  where, values);
        return rc;
    }
    return CLI_EXIT_OK;
}

/* ---- output ------------------------------------------------------------------------------- */

static const char* const converged_words[] = {"no", "small step", "small gradient",
                                              "small cost change"};

/* The residual (fit - data) of point i: of e_n (part 0) or of the spin (part 1). */
static double residual(const struct fit_ctx* c, const double* pred, size_t part, size_t i)
{
    return part ? pred[c->n_pts + i] - c->pts[i].omega : pred[i] - c->pts[i].e_n;
}

/* Root mean square and largest magnitude of the residuals of a part, and the index of the
 * latter. */
static void residual_stats(const struct fit_ctx* c, const double* pred, size_t part, double* rms,
                           double* max, size_t* at)
{
    double s = 0;
    *max = 0, *at = 0;
    for (size_t i = 0; i < c->n_pts; i++) {
        double r = residual(c, pred, part, i);
        s += r * r;
        if (fabs(r) > *max)
            *max = fabs(r), *at = i;
    }
    *rms = c->n_pts ? sqrt(s / (double)c->n_pts) : 0;
}

static const char* const transform_words[] = {"linear", "log", "log-upper", "logistic"};

/* What key j ending at a bound (side -1 lower, +1 upper) of [lower, upper] means, with its
 * range open or closed at each end as its descriptor has it: "(0, 1]" for a restitution. */
static void print_at_bound(const struct fit_ctx* c, size_t j, int side, double lower, double upper)
{
    char range[128];
    struct wetdem_param_desc d;
    if (key_desc(c->keys[j], &d))
        wetdem_param_range_text(&d, range, sizeof range);
    else /* (not reached: a key of unknown range is fitted unbounded) */
        snprintf(range, sizeof range, "[%g, %g]", lower, upper);
    printf(": at the %s bound %g of its range %s: the data would take it further, or do not tell "
           "it from the bound (no standard error there%s)",
           side < 0 ? "lower" : "upper", side < 0 ? lower : upper, range,
           c->n_keys > 1 ? "; the others' are with it held there" : "");
}

/* "KEY = value +- error UNIT (relative %)" lines, and what an infinite or NAN error means. */
static void print_values(const struct fit_ctx* c, const struct wetdem_fit_result* r,
                         const double* lower, const double* upper)
{
    for (size_t j = 0; j < c->n_keys; j++) {
        const char* unit = key_unit(c->keys[j]);
        printf("# %s = %.6g +- %.3g %s (%.2g %%)", c->keys[j], cli_plain_zero(r->values[j]),
               r->std_errors[j], unit, 100 * r->std_errors[j] / fabs(r->values[j]));
        if (r->undetermined[j])
            printf(": not determined by the data");
        else if (r->at_bound[j])
            print_at_bound(c, j, r->at_bound[j], lower[j], upper[j]);
        else if (r->std_errors[j] > fabs(r->values[j]))
            printf(": hardly determined by the data here (a standard error above the value); a "
                   "start nearer the value you expect may find a better minimum");
        printf("\n");
    }
}

static void print_result(const struct fit_ctx* c, const double* init, const double* lower,
                         const double* upper, const struct wetdem_fit_result* r, int status,
                         const double* pred, double omega_scale, int argc, char** argv)
{
    cli_print_provenance(stdout, argc, argv);
    /* value, std_error and initial are in the unit the row's unit column names */
    printf("parameter [word],unit [word],value [unit],std_error [unit],initial [unit],"
           "fitted_as [word]\n");
    for (size_t j = 0; j < c->n_keys; j++) {
        int t = r->transform[j] >= 0 && r->transform[j] <= 3 ? r->transform[j] : 0;
        printf("%s,%s,%.9g,%.3g,%.9g,%s\n", c->keys[j], key_unit(c->keys[j]),
               cli_plain_zero(r->values[j]), r->std_errors[j], cli_plain_zero(init[j]),
               transform_words[t]);
    }
    print_values(c, r, lower, upper);
    int by = (r->converged_by >= 0 && r->converged_by <= 3) ? r->converged_by : 0;
    printf("# cost %.6g [-], residual std s = %.4g [-]%s over %zu dof, %zu iterations, %zu model "
           "evaluations (x %zu collisions), converged: %s%s\n",
           r->cost, r->residual_std,
           c->use_omega ? " (spin residuals in units of --omega-scale)" : " (e_n)", r->dof,
           r->iterations, r->model_evals, c->n_pts, converged_words[by],
           status == WETDEM_ERR_UNDETERMINED ? " (not a fit: a key is not determined)" : "");
    for (size_t part = 0; part < (c->use_omega ? 2u : 1u); part++) {
        double rms, max;
        size_t at;
        residual_stats(c, pred, part, &rms, &max, &at);
        const char* unit = part ? "rad/s" : "-";
        char angle[64] = ""; /* (rows of several angles may share a Stokes number) */
        if (c->pts[at].has_angle)
            snprintf(angle, sizeof angle, ", angle_deg = %g", c->pts[at].angle_deg);
        printf("# residuals %s (fit - data): rms %.3g [%s], largest %.3g [%s] at St_n = %g%s\n",
               part ? "omega" : "e_n", rms, unit, cli_plain_zero(residual(c, pred, part, at)), unit,
               c->pts[at].stokes, angle);
    }
    if (c->use_omega)
        printf("# spin residuals weighed as e_n residuals times %g rad/s (--omega-scale)\n",
               omega_scale);
    for (size_t j = 0; j < c->n_keys && c->n_keys > 1; j++) {
        printf("# correlation %s:", c->keys[j]);
        for (size_t k = 0; k < c->n_keys; k++) { /* (-0.0004 is "0.000", not "-0.000") */
            char text[32];
            snprintf(text, sizeof text, "%.3f", cli_plain_zero(r->correlation[j][k]));
            printf(" %s", strcmp(text, "-0.000") == 0 ? "0.000" : text);
        }
        printf("\n");
    }
}

static double point_angle(const struct fit_ctx* c, const struct point* p)
{
    return p->has_angle ? p->angle_deg : cli_scenario_number(c->base, "collision", "angle_deg", 0);
}

/* What the writers of --out and --curve print (cli_write_output). */
struct table_ctx {
    const struct fit_ctx* c;
    const struct point* pts; /* the curve's points (--curve) */
    const double* pred;      /* predictions: e_n [n], then omega [n] of --curve or with omega */
    size_t n;                /* curve points */
    int argc;
    char** argv;
};

/* --out: data vs fit, one row per measurement. */
static void fit_table(FILE* f, const void* ctx)
{
    const struct table_ctx* t = ctx;
    const struct fit_ctx* c = t->c;
    const double* pred = t->pred;
    cli_print_provenance(f, t->argc, t->argv);
    fprintf(f, "stokes_n [-],angle_deg [deg],e_n_data [-],e_n_fit [-],e_n_residual [-]%s\n",
            c->use_omega ? ",omega_data [rad/s],omega_fit [rad/s],omega_residual [rad/s]" : "");
    for (size_t i = 0; i < c->n_pts; i++) {
        const struct point* p = &c->pts[i];
        fprintf(f, "%.9g,%.9g,%.9g,%.9g,%.6g", p->stokes, cli_plain_zero(point_angle(c, p)),
                cli_plain_zero(p->e_n), cli_plain_zero(pred[i]), cli_plain_zero(pred[i] - p->e_n));
        if (c->use_omega)
            fprintf(f, ",%.9g,%.9g,%.6g", cli_plain_zero(p->omega),
                    cli_plain_zero(pred[c->n_pts + i]),
                    cli_plain_zero(pred[c->n_pts + i] - p->omega));
        fputc('\n', f);
    }
}

/* --curve: the fitted model at the curve's points. */
static void curve_table(FILE* f, const void* ctx)
{
    const struct table_ctx* t = ctx;
    cli_print_provenance(f, t->argc, t->argv);
    fprintf(f, "angle_deg [deg],stokes_n [-],e_n_fit [-],omega_fit [rad/s]\n");
    for (size_t k = 0; k < t->n; k++)
        fprintf(f, "%.9g,%.9g,%.9g,%.9g\n", cli_plain_zero(t->pts[k].angle_deg), t->pts[k].stokes,
                cli_plain_zero(t->pred[k]), cli_plain_zero(t->pred[t->n + k]));
}

/* The fitted model on `m` log-spaced Stokes numbers over the data range, per distinct angle
 * (--curve): t->pts and t->pred (freed by the caller) and t->n. Returns an exit code. */
static int compute_curve(const struct fit_ctx* c, const double* values, int m, struct table_ctx* t)
{
    double lo = INFINITY, hi = 0;
    double* angles = malloc((c->n_pts ? c->n_pts : 1) * sizeof *angles); /* every distinct one */
    size_t n_ang = 0;
    for (size_t i = 0; angles && i < c->n_pts; i++) {
        lo = fmin(lo, c->pts[i].stokes), hi = fmax(hi, c->pts[i].stokes);
        double a = point_angle(c, &c->pts[i]);
        size_t k = 0;
        while (k < n_ang && angles[k] != a)
            k++;
        if (k == n_ang)
            angles[n_ang++] = a;
    }
    size_t n = n_ang * (size_t)m;
    struct point* pts = calloc(n ? n : 1, sizeof *pts);
    double* e = calloc(2 * (n ? n : 1), sizeof *e);
    char msg[512] = "out of memory";
    int st = (angles && pts && e) ? WETDEM_OK : WETDEM_ERR_NOMEM;
    for (size_t k = 0; st == WETDEM_OK && k < n; k++) {
        double u = m > 1 ? (double)(k % (size_t)m) / (m - 1) : 0;
        pts[k] = (struct point){
            .stokes = lo * pow(hi / lo, u), .angle_deg = angles[k / (size_t)m], .has_angle = true};
    }
    if (st == WETDEM_OK)
        st = simulate(c, values, pts, n, e, e + n, msg, sizeof msg);
    free(angles);
    t->pts = pts;
    t->pred = e;
    t->n = n;
    if (st == WETDEM_OK)
        return CLI_EXIT_OK;
    cli_error("fit: curve: %s", msg);
    return CLI_EXIT_RUNTIME;
}

/* Writes --out and --curve as a set: both whole, or neither (the curve is computed first, so
 * a curve that cannot be computed or written leaves no --out either). Returns an exit code. */
static int write_outputs(const struct fit_args* a, const struct fit_ctx* c, const double* pred,
                         const double* values, int argc, char** argv)
{
    struct table_ctx fit = {.c = c, .pred = pred, .argc = argc, .argv = argv};
    struct table_ctx curve = {.c = c, .argc = argc, .argv = argv};
    int rc = a->curve ? compute_curve(c, values, a->curve_points, &curve) : CLI_EXIT_OK;
    if (rc == CLI_EXIT_OK) {
        const struct cli_output outs[2] = {{a->out, fit_table, &fit},
                                           {a->curve, curve_table, &curve}};
        rc = cli_write_outputs(outs, 2, "fit");
    }
    free((void*)curve.pts);
    free((void*)curve.pred);
    return rc;
}

/* ---- command ------------------------------------------------------------------------------ */

/* Problem set-up after the inputs are read: observations and scales. */
static int run_fit(const struct fit_args* a, struct fit_ctx* c, const double* init,
                   const double* lower, const double* upper, const bool* is_log, int argc,
                   char** argv)
{
    size_t n = c->n_pts * (c->use_omega ? 2 : 1);
    double* obs = malloc(n * sizeof *obs);
    double* scale = malloc(n * sizeof *scale);
    double* pred = calloc(n, sizeof *pred);
    if (!obs || !scale || !pred) {
        free(obs), free(scale), free(pred);
        cli_error("fit: out of memory");
        return CLI_EXIT_RUNTIME;
    }
    for (size_t i = 0; i < c->n_pts; i++) {
        obs[i] = c->pts[i].e_n, scale[i] = 1.0;
        if (c->use_omega)
            obs[c->n_pts + i] = c->pts[i].omega, scale[c->n_pts + i] = a->omega_scale;
    }
    const char* names[WETDEM_FIT_MAX_PARAMS];
    for (size_t j = 0; j < c->n_keys; j++)
        names[j] = c->keys[j];
    struct wetdem_fit_problem pb = {.n_params = c->n_keys,
                                    .names = names,
                                    .initial = init,
                                    .n_data = n,
                                    .observed = obs,
                                    .scale = scale,
                                    .model = fit_model,
                                    .ctx = c,
                                    .is_log = is_log,
                                    .lower = lower,
                                    .upper = upper};
    struct wetdem_fit_options o;
    wetdem_fit_options_init(&o);
    o.max_iter = a->max_iter;
    o.fd_step = a->fd_step;
    struct wetdem_fit_result r;
    char msg[512] = "";
    progress_start();
    int st = wetdem_fit_run(&pb, &o, &r, pred, msg, sizeof msg);
    progress_end(c);
    int rc = CLI_EXIT_OK;
    /* a result to show: converged, not converged, or not determining every parameter (dof 0:
       the fit stopped before it had one, e.g. at a zero column of the Jacobian) */
    bool has_result = st == WETDEM_OK || st == WETDEM_ERR_MAX_STEPS ||
                      (st == WETDEM_ERR_UNDETERMINED && r.dof > 0);
    if (has_result)
        print_result(c, init, lower, upper, &r, st, pred, a->omega_scale, argc, argv);
    if (st == WETDEM_OK || st == WETDEM_ERR_MAX_STEPS) {
        rc = write_outputs(a, c, pred, r.values, argc, argv);
    }
    if (st != WETDEM_OK) {
        cli_error("fit: %s", msg);
        rc = st == WETDEM_ERR_INVALID ? CLI_EXIT_USAGE : CLI_EXIT_RUNTIME;
    }
    if (st == WETDEM_ERR_UNDETERMINED)
        cli_error("fit: --init starts a key elsewhere; a key left out of --fit is held at the "
                  "scenario's value (or --set KEY=VALUE)");
    free(obs), free(scale), free(pred);
    return rc;
}

int cmd_fit(int argc, char** argv)
{
    if (cli_wants_help(argc, argv)) {
        usage(stdout);
        return CLI_EXIT_OK;
    }
    struct fit_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc != CLI_EXIT_OK)
        return rc;
    struct cli_scenario sc;
    memset(&sc, 0, sizeof sc);
    enum cli_engine engine = CLI_ENGINE_SOFT;
    struct fit_ctx c = {.base = &sc, .data = a.data};
    struct point* pts = NULL;
    double init[WETDEM_FIT_MAX_PARAMS];
    rc = cli_load_with_overrides(a.file, a.sets, a.n_sets, &sc);
    if (rc == CLI_EXIT_OK && (rc = cli_scenario_engine(&sc, &engine)) == CLI_EXIT_OK &&
        engine != CLI_ENGINE_SOFT) {
        cli_error("fit: %s: only the soft engine can be fitted ([engine] type = soft)", a.file);
        rc = CLI_EXIT_USAGE;
    }
    if (rc == CLI_EXIT_OK && cli_scenario_is_many && cli_scenario_is_many(&sc)) {
        cli_error("fit: %s is a many-particle scenario; fit calibrates binary collisions "
                  "([collision]: docs/calibration.md)",
                  a.file);
        rc = CLI_EXIT_USAGE;
    }
    if (rc == CLI_EXIT_OK)
        rc = read_data(a.data, &pts, &c.n_pts);
    c.pts = pts;
    c.use_omega = a.omega_scale > 0;
    for (size_t i = 0; rc == CLI_EXIT_OK && c.use_omega && i < c.n_pts; i++)
        if (isnan(pts[i].omega)) {
            cli_error("fit: --omega-scale needs an omega_rad_s column in %s", a.data);
            rc = CLI_EXIT_USAGE;
        }
    if (rc == CLI_EXIT_OK)
        rc = check_sets(&a, &c);
    if (rc == CLI_EXIT_OK)
        rc = parse_keys(a.fit, &c);
    if (rc == CLI_EXIT_OK)
        rc = check_counts(&a, &c);
    if (rc == CLI_EXIT_OK)
        rc = initial_values(&a, &c, init);
    double lower[WETDEM_FIT_MAX_PARAMS], upper[WETDEM_FIT_MAX_PARAMS];
    bool is_log[WETDEM_FIT_MAX_PARAMS];
    if (rc == CLI_EXIT_OK)
        rc = key_bounds(&c, init, lower, upper, is_log);
    if (rc == CLI_EXIT_OK)
        rc = check_points(&c, init);
    if (rc == CLI_EXIT_OK) /* (before the fit runs, not after it) */
        rc = cli_check_writable("fit", "--out", a.out);
    if (rc == CLI_EXIT_OK)
        rc = cli_check_writable("fit", "--curve", a.curve);
    if (rc == CLI_EXIT_OK)
        rc = run_fit(&a, &c, init, lower, upper, is_log, argc, argv);
    free(pts);
    cli_scenario_free(&sc);
    return rc;
}

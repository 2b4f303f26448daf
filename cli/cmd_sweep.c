/*
 * cmd_sweep.c — `wetdem sweep FILE --param KEY --values A:B:N [--log] [--out FILE.csv]
 * [--set section.key=value ...]`: one independent collision per value of KEY, run in parallel
 * with OpenMP, one CSV row per value in input order.
 *
 * KEY is any scenario key ("collision.stokes", "collision.angle_deg",
 * "material.soft.roughness", "fluid.viscosity") or a model parameter ("nijssen.cutoff_ratio",
 * read as [model.nijssen] cutoff_ratio). Value k is applied exactly as
 * `wetdem run FILE --set KEY=value_k` would (printed with %.17g, so the same bits), which keeps
 * coupled keys right: sweeping fluid.viscosity with a Stokes number given re-derives the speed.
 *
 * Determinism: every value gets its own simulation (soft engine) or scenario (pairwise engine),
 * built and checked serially before any run; the runs, of either engine, share nothing and
 * are distributed over the threads, and rows are written in input order after all finished,
 * so the data rows are bit-identical for any OMP_NUM_THREADS. The trailer '#' line (totals and
 * wall time) is the only line that varies between runs. The status column is the run's
 * status (the pairwise engine's for pairwise scenarios); a failed point makes the exit code 1.
 *
 * Progress with an estimate of the time left goes to stderr only when stderr is a terminal.
 */
#include <math.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli_util.h"
#include "output_csv.h"
#include "scenario.h"

#define MAX_SETS 256

struct sweep_args {
    const char* file;
    const char* key;
    const char* values;
    const char* out;
    bool is_log;
    const char* sets[MAX_SETS];
    int n_sets;
};

/* One sweep point: its set-up, and after the run its result or error. */
struct point {
    double value;
    struct cli_setup su;    /* soft engine: the built simulation */
    struct cli_scenario sc; /* pairwise engine: the point's scenario (checked, not run) */
    struct wetdem_collision_result res;
    int status;
    char errmsg[256];
    char* pairwise_row; /* pairwise engine: the row it wrote */
};

static void usage(FILE* f)
{
    fprintf(f, "usage: wetdem sweep FILE --param KEY --values A:B:N [--log] [--out FILE.csv]\n"
               "                    [--set section.key=value ...]\n"
               "Independent collisions, one per value of KEY (any scenario key, e.g.\n"
               "collision.stokes, or a model parameter), in parallel (OMP_NUM_THREADS).\n"
               "  --values A:B:N  N values from A to B (both included); --log: geometric\n"
               "  --out FILE.csv  write the table there (default: stdout)\n");
}

static int parse_args(int argc, char** argv, struct sweep_args* a)
{
    memset(a, 0, sizeof *a);
    for (int k = 1; k < argc; k++) {
        const char* s = argv[k];
        bool next = k + 1 < argc;
        if (strcmp(s, "--param") == 0 && next)
            a->key = argv[++k];
        else if (strcmp(s, "--values") == 0 && next)
            a->values = argv[++k];
        else if (strcmp(s, "--out") == 0 && next)
            a->out = argv[++k];
        else if (strcmp(s, "--set") == 0 && next && a->n_sets < MAX_SETS)
            a->sets[a->n_sets++] = argv[++k];
        else if (strcmp(s, "--log") == 0)
            a->is_log = true;
        else if (s[0] != '-' && !a->file)
            a->file = s;
        else {
            cli_error("sweep: unexpected argument '%s'", s);
            usage(stderr);
            return CLI_EXIT_USAGE;
        }
    }
    if (!a->file || !a->key || !a->values) {
        cli_error("sweep: FILE, --param KEY and --values A:B:N are required");
        usage(stderr);
        return CLI_EXIT_USAGE;
    }
    return CLI_EXIT_OK;
}

/* Builds point k: scenario copy with KEY = value, then the soft engine's set-up, or the
 * pairwise engine's configuration checked without running (the header mode builds and
 * validates it). Returns an exit code. */
static int build_point(const struct cli_scenario* base, const char* key, struct point* p,
                       enum cli_engine engine)
{
    int rc = cli_scenario_copy(base, &p->sc);
    if (rc != CLI_EXIT_OK)
        return rc;
    char set[512];
    snprintf(set, sizeof set, "%s=%.17g", key, p->value);
    rc = cli_scenario_override(&p->sc, set);
    if (rc == CLI_EXIT_OK && engine == CLI_ENGINE_SOFT)
        rc = cli_scenario_build(&p->sc, &p->su);
    if (rc == CLI_EXIT_OK && engine == CLI_ENGINE_PAIRWISE) {
        char* text = NULL;
        size_t len = 0;
        FILE* f = open_memstream(&text, &len);
        struct cli_run_options opt = {.sweep_row = f, .sweep_header = true};
        rc = f ? cli_run_pairwise(&p->sc, &opt) : CLI_EXIT_RUNTIME;
        if (f)
            fclose(f);
        free(text);
    }
    if (engine == CLI_ENGINE_SOFT)
        cli_scenario_free(&p->sc); /* the set-up holds everything the run needs */
    return rc;
}

/* Runs one built point: the soft engine's collision, or the pairwise engine's run writing
 * its row. Touches only *p, so points run concurrently. */
static void run_point(struct point* p, enum cli_engine engine)
{
    if (engine == CLI_ENGINE_PAIRWISE) {
        size_t len = 0;
        FILE* f = open_memstream(&p->pairwise_row, &len);
        struct cli_run_options opt = {.sweep_row = f,
                                      .status_out = &p->status,
                                      .errmsg_out = p->errmsg,
                                      .errmsg_size = sizeof p->errmsg};
        p->status = WETDEM_ERR_NOMEM; /* kept when the engine could not start */
        snprintf(p->errmsg, sizeof p->errmsg, "out of memory");
        if (f) {
            cli_run_pairwise(&p->sc, &opt);
            fclose(f);
        }
        cli_scenario_free(&p->sc);
        return;
    }
    p->status = wetdem_collision_run(p->su.sim, &p->su.spec, &p->res);
    if (p->status < 0)
        snprintf(p->errmsg, sizeof p->errmsg, "%s", wetdem_sim_errmsg(p->su.sim));
    else
        cli_setup_capture(&p->su);
    cli_setup_free(&p->su); /* the row needs only what su captured */
}

static void progress(size_t done, size_t n, double t0)
{
    double elapsed = omp_get_wtime() - t0;
    double left = done ? elapsed * (double)(n - done) / (double)done : 0;
    fprintf(stderr, "\rsweep: %zu/%zu done, %.1f s elapsed, ~%.1f s left   ", done, n, elapsed,
            left);
    if (done == n)
        fputc('\n', stderr);
}

/* The pairwise engine's column header (malloc'd), or NULL on failure. */
static char* pairwise_header(const struct cli_scenario* sc)
{
    char* text = NULL;
    size_t len = 0;
    FILE* f = open_memstream(&text, &len);
    if (!f)
        return NULL;
    struct cli_run_options opt = {.sweep_row = f, .sweep_header = true};
    int rc = cli_run_pairwise(sc, &opt);
    fclose(f);
    if (rc != CLI_EXIT_OK) {
        free(text);
        return NULL;
    }
    for (size_t k = strlen(text); k > 0 && text[k - 1] == '\n'; k--)
        text[k - 1] = '\0';
    return text;
}

/* Runs every point in parallel (dynamic scheduling: run times differ by orders of
 * magnitude across a sweep). */
static void run_points(struct point* pts, size_t n, enum cli_engine engine)
{
    bool show = isatty(STDERR_FILENO);
    double t0 = omp_get_wtime(), last = 0;
    size_t done = 0;
#pragma omp parallel for schedule(dynamic, 1)
    for (size_t k = 0; k < n; k++) {
        run_point(&pts[k], engine);
#pragma omp critical(sweep_progress)
        {
            done++;
            double now = omp_get_wtime();
            if (show && (now - last > 0.2 || done == n)) {
                progress(done, n, t0);
                last = now;
            }
        }
    }
}

static void write_table(FILE* f, const struct sweep_args* a, const struct point* pts, size_t n,
                        const char* pairwise_header, int argc, char** argv, double wall)
{
    char section[CLI_NAME_MAX], key[CLI_NAME_MAX], probe[CLI_VALUE_MAX];
    snprintf(probe, sizeof probe, "%s=0", a->key);
    const char* unit = cli_override_split(probe, section, key, NULL) == 0
                           ? cli_scenario_key_unit(section, key)
                           : "";
    cli_print_provenance(f, argc, argv);
    fprintf(f, "%s [%s],status [word],", a->key, unit[0] ? unit : "-");
    if (pairwise_header)
        fputs(pairwise_header, f);
    else
        cli_csv_result_header(f);
    fputc('\n', f);
    struct wetdem_stats tot = {0};
    for (size_t k = 0; k < n; k++) {
        fprintf(f, "%.12g,%s,", pts[k].value, wetdem_status_name(pts[k].status));
        if (!pairwise_header)
            cli_csv_result_row(f, &pts[k].su, &pts[k].res);
        else if (pts[k].pairwise_row)
            fputs(pts[k].pairwise_row, f);
        fputc('\n', f);
        tot.steps += pts[k].res.stats.steps;
        tot.force_evals += pts[k].res.stats.force_evals;
        tot.pair_evals += pts[k].res.stats.pair_evals;
        tot.root_evals += pts[k].res.stats.root_evals;
        tot.events += pts[k].res.stats.events;
    }
    if (pairwise_header) { /* the engine's counts are in the rows (events, steps) */
        fprintf(f, "# totals: runs=%zu wall_time_s=%.6f threads=%d\n", n, wall,
                omp_get_max_threads());
        return;
    }
    fprintf(f,
            "# totals: runs=%zu steps=%llu force_evals=%llu pair_evals=%llu root_evals=%llu "
            "events=%llu wall_time_s=%.6f threads=%d\n",
            n, tot.steps, tot.force_evals, tot.pair_evals, tot.root_evals, tot.events, wall,
            omp_get_max_threads());
}

/* Builds every point (serially: every input error is reported before anything runs). */
static int build_all(const struct cli_scenario* sc, const struct sweep_args* a,
                     const struct cli_range* r, struct point* pts, enum cli_engine engine)
{
    for (size_t k = 0; k < r->n; k++) {
        pts[k].value = cli_range_value(r, k);
        int rc = build_point(sc, a->key, &pts[k], engine);
        if (rc != CLI_EXIT_OK)
            return rc;
    }
    return CLI_EXIT_OK;
}

static void free_points(struct point* pts, size_t n)
{
    for (size_t k = 0; pts && k < n; k++) {
        cli_setup_free(&pts[k].su);
        cli_scenario_free(&pts[k].sc);
        free(pts[k].pairwise_row);
    }
    free(pts);
}

static int write_output(const struct sweep_args* a, const struct point* pts, size_t n,
                        const char* pairwise_header, int argc, char** argv, double wall)
{
    if (!a->out) {
        write_table(stdout, a, pts, n, pairwise_header, argc, argv, wall);
        return fflush(stdout) == 0 ? CLI_EXIT_OK : CLI_EXIT_RUNTIME;
    }
    char tmp[1100];
    snprintf(tmp, sizeof tmp, "%s.tmp%ld", a->out, (long)getpid());
    FILE* f = fopen(tmp, "w");
    if (!f) {
        cli_error("sweep: cannot write %s", tmp);
        return CLI_EXIT_RUNTIME;
    }
    write_table(f, a, pts, n, pairwise_header, argc, argv, wall);
    bool bad = ferror(f) != 0;
    bad = fclose(f) != 0 || bad;
    if (bad || rename(tmp, a->out) != 0) {
        remove(tmp);
        cli_error("sweep: cannot write %s", a->out);
        return CLI_EXIT_RUNTIME;
    }
    return CLI_EXIT_OK;
}

int cmd_sweep(int argc, char** argv)
{
    if (cli_wants_help(argc, argv)) {
        usage(stdout);
        return CLI_EXIT_OK;
    }
    struct sweep_args a;
    struct cli_range r;
    int rc = parse_args(argc, argv, &a);
    if (rc == CLI_EXIT_OK)
        rc = cli_parse_range(a.values, a.is_log, "--values", &r);
    if (rc != CLI_EXIT_OK)
        return rc;
    struct cli_scenario sc;
    rc = cli_load_with_overrides(a.file, a.sets, a.n_sets, &sc);
    enum cli_engine engine = CLI_ENGINE_SOFT;
    cli_scenario_engine(&sc, &engine);
    if (rc == CLI_EXIT_OK && engine == CLI_ENGINE_PAIRWISE && !cli_run_pairwise) {
        cli_error("sweep %s: engine 'pairwise' is not in this build", a.file);
        rc = CLI_EXIT_RUNTIME;
    }
    if (rc == CLI_EXIT_OK && cli_scenario_is_many && cli_scenario_is_many(&sc)) {
        cli_error("sweep %s: a many-particle scenario runs with 'wetdem run' (one run per "
                  "file); sweeps vary binary collisions",
                  a.file);
        rc = CLI_EXIT_USAGE;
    }
    struct point* pts = rc == CLI_EXIT_OK ? calloc(r.n, sizeof *pts) : NULL;
    if (rc == CLI_EXIT_OK && !pts) {
        cli_error("sweep: out of memory for %zu points", r.n);
        rc = CLI_EXIT_RUNTIME;
    }
    char* header = NULL;
    if (rc == CLI_EXIT_OK && engine == CLI_ENGINE_PAIRWISE && !(header = pairwise_header(&sc)))
        rc = CLI_EXIT_RUNTIME;
    double t0 = omp_get_wtime();
    if (rc == CLI_EXIT_OK)
        rc = build_all(&sc, &a, &r, pts, engine);
    if (rc == CLI_EXIT_OK) {
        run_points(pts, r.n, engine);
        double wall = omp_get_wtime() - t0;
        rc = write_output(&a, pts, r.n, header, argc, argv, wall);
        for (size_t k = 0; k < r.n; k++)
            if (pts[k].status < 0) {
                cli_error("sweep: %s = %.12g: %s (%s)", a.key, pts[k].value, pts[k].errmsg,
                          wetdem_status_name(pts[k].status));
                rc = CLI_EXIT_RUNTIME;
            }
    }
    free(header);
    free_points(pts, pts ? r.n : 0);
    cli_scenario_free(&sc);
    return rc;
}

/*
 * cmd_map.c — `wetdem map FILE --param KEY --values A:B:N --param2 KEY2 --values2 A:B:N
 * [--log] [--log2] [--out FILE.csv] [--set section.key=value ...]`: a two-parameter grid of
 * independent collisions (e.g. St_n x impact angle of three-sphere collisions, Davis 2023),
 * one CSV row per grid point, KEY varying slowest.
 *
 * Each point is the scenario with `--set KEY=a_i --set KEY2=b_j` (values printed with %.17g,
 * as `wetdem sweep` does), so coupled keys stay right. Every point is built and checked
 * serially first (all input errors are reported before anything runs); the runs are then
 * distributed over OpenMP threads with dynamic scheduling and share nothing; rows are written
 * in grid order after all finished, so the data rows are bit-identical for any thread count.
 * The trailer '#' line (runs, wall time, threads, collisions per second) is the only line
 * that varies. Engines: pairwise (the row of cli_run_pairwise) and soft (the collision row of
 * `wetdem sweep`); many-particle scenarios are refused (exit 2), as by `wetdem sweep`.
 */
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli_util.h"
#include "output_csv.h"
#include "scenario.h"

#define MAP_MAX_SETS 256

struct map_args {
    const char* file;
    const char* key[2];
    const char* values[2];
    bool is_log[2];
    const char* out;
    const char* sets[MAP_MAX_SETS];
    int n_sets;
};

/* One grid point: its scenario, and after the run its row or error. */
struct map_point {
    double value[2];
    struct cli_scenario sc; /* pairwise: the point's scenario */
    struct cli_setup su;    /* soft: the built simulation */
    struct wetdem_collision_result res;
    int status;
    char errmsg[256]; /* the engine's message of a failed run */
    char* row;        /* the engine's CSV fields (malloc'd) */
};

static void usage(FILE* f)
{
    fprintf(
        f, "usage: wetdem map FILE --param KEY --values A:B:N --param2 KEY2 --values2 A:B:N\n"
           "                  [--log] [--log2] [--out FILE.csv] [--set section.key=value ...]\n"
           "A grid of independent collisions over two scenario keys (KEY slowest), in\n"
           "parallel (OMP_NUM_THREADS); rows in grid order, bit-identical for any thread count.\n");
}

static int parse_args(int argc, char** argv, struct map_args* a)
{
    memset(a, 0, sizeof *a);
    for (int k = 1; k < argc; k++) {
        const char* s = argv[k];
        bool next = k + 1 < argc;
        if (strcmp(s, "--param") == 0 && next)
            a->key[0] = argv[++k];
        else if (strcmp(s, "--values") == 0 && next)
            a->values[0] = argv[++k];
        else if (strcmp(s, "--param2") == 0 && next)
            a->key[1] = argv[++k];
        else if (strcmp(s, "--values2") == 0 && next)
            a->values[1] = argv[++k];
        else if (strcmp(s, "--out") == 0 && next)
            a->out = argv[++k];
        else if (strcmp(s, "--set") == 0 && next && a->n_sets < MAP_MAX_SETS)
            a->sets[a->n_sets++] = argv[++k];
        else if (strcmp(s, "--log") == 0)
            a->is_log[0] = true;
        else if (strcmp(s, "--log2") == 0)
            a->is_log[1] = true;
        else if (s[0] != '-' && !a->file)
            a->file = s;
        else {
            cli_error("map: unexpected argument '%s'", s);
            usage(stderr);
            return CLI_EXIT_USAGE;
        }
    }
    if (!a->file || !a->key[0] || !a->values[0] || !a->key[1] || !a->values[1]) {
        cli_error("map: FILE, --param, --values, --param2 and --values2 are required");
        usage(stderr);
        return CLI_EXIT_USAGE;
    }
    if (strcmp(a->key[0], a->key[1]) == 0) {
        cli_error("map: --param and --param2 are both '%s'", a->key[0]);
        return CLI_EXIT_USAGE;
    }
    return CLI_EXIT_OK;
}

/* Scenario of one point: base with both keys set. Exit code. */
static int build_point(const struct cli_scenario* base, const struct map_args* a,
                       struct map_point* p, enum cli_engine engine)
{
    int rc = cli_scenario_copy(base, &p->sc);
    for (int d = 0; d < 2 && rc == CLI_EXIT_OK; d++) {
        char set[512];
        snprintf(set, sizeof set, "%s=%.17g", a->key[d], p->value[d]);
        rc = cli_scenario_override(&p->sc, set);
    }
    if (rc == CLI_EXIT_OK && engine == CLI_ENGINE_SOFT)
        rc = cli_scenario_build(&p->sc, &p->su);
    if (rc == CLI_EXIT_OK && engine == CLI_ENGINE_PAIRWISE) { /* check the build, no run */
        char* text = NULL;
        size_t len = 0;
        FILE* f = open_memstream(&text, &len);
        struct cli_run_options opt = {.sweep_row = f, .sweep_header = true};
        rc = f ? cli_run_pairwise(&p->sc, &opt) : CLI_EXIT_RUNTIME;
        if (f)
            fclose(f);
        free(text);
    }
    return rc;
}

/* Runs one built point and keeps its row. */
static void run_point(struct map_point* p, enum cli_engine engine)
{
    size_t len = 0;
    FILE* f = open_memstream(&p->row, &len);
    if (!f) {
        p->status = WETDEM_ERR_NOMEM;
        return;
    }
    if (engine == CLI_ENGINE_PAIRWISE) {
        struct cli_run_options opt = {.sweep_row = f,
                                      .status_out = &p->status,
                                      .errmsg_out = p->errmsg,
                                      .errmsg_size = sizeof p->errmsg};
        p->status = WETDEM_ERR_NOMEM; /* kept when the engine could not start */
        cli_run_pairwise(&p->sc, &opt);
    } else {
        p->status = wetdem_collision_run(p->su.sim, &p->su.spec, &p->res);
        if (p->status >= 0)
            cli_setup_capture(&p->su);
        else
            snprintf(p->errmsg, sizeof p->errmsg, "%s", wetdem_sim_errmsg(p->su.sim));
        cli_csv_result_row(f, &p->su, &p->res);
        cli_setup_free(&p->su);
    }
    fclose(f);
}

/* The engine's column header (malloc'd) or NULL. */
static char* engine_header(const struct cli_scenario* sc, enum cli_engine engine)
{
    char* text = NULL;
    size_t len = 0;
    FILE* f = open_memstream(&text, &len);
    if (!f)
        return NULL;
    if (engine == CLI_ENGINE_PAIRWISE) {
        struct cli_run_options opt = {.sweep_row = f, .sweep_header = true};
        if (cli_run_pairwise(sc, &opt) != CLI_EXIT_OK) {
            fclose(f);
            free(text);
            return NULL;
        }
    } else {
        cli_csv_result_header(f);
    }
    fclose(f);
    return text;
}

static const char* key_unit(const char* key)
{
    char section[CLI_NAME_MAX], name[CLI_NAME_MAX], probe[CLI_VALUE_MAX];
    snprintf(probe, sizeof probe, "%s=0", key);
    const char* u = cli_override_split(probe, section, name, NULL) == 0
                        ? cli_scenario_key_unit(section, name)
                        : "";
    return u[0] ? u : "-";
}

static void write_table(FILE* f, const struct map_args* a, const struct map_point* pts, size_t n,
                        const char* header, int argc, char** argv, double wall)
{
    cli_print_provenance(f, argc, argv);
    fprintf(f, "%s [%s],%s [%s],status [word],%s\n", a->key[0], key_unit(a->key[0]), a->key[1],
            key_unit(a->key[1]), header);
    for (size_t k = 0; k < n; k++)
        fprintf(f, "%.12g,%.12g,%s,%s\n", pts[k].value[0], pts[k].value[1],
                wetdem_status_name(pts[k].status), pts[k].row ? pts[k].row : "");
    fprintf(f, "# totals: runs=%zu wall_time_s=%.6f threads=%d collisions_per_s=%.3f\n", n, wall,
            omp_get_max_threads(), wall > 0 ? (double)n / wall : 0.0);
}

static int write_output(const struct map_args* a, const struct map_point* pts, size_t n,
                        const char* header, int argc, char** argv, double wall)
{
    if (!a->out) {
        write_table(stdout, a, pts, n, header, argc, argv, wall);
        return fflush(stdout) == 0 ? CLI_EXIT_OK : CLI_EXIT_RUNTIME;
    }
    char tmp[1100];
    snprintf(tmp, sizeof tmp, "%s.tmp%ld", a->out, (long)getpid());
    FILE* f = fopen(tmp, "w");
    if (!f) {
        cli_error("map: cannot write %s", tmp);
        return CLI_EXIT_RUNTIME;
    }
    write_table(f, a, pts, n, header, argc, argv, wall);
    bool bad = ferror(f) != 0;
    bad = fclose(f) != 0 || bad;
    if (bad || rename(tmp, a->out) != 0) {
        remove(tmp);
        cli_error("map: cannot write %s", a->out);
        return CLI_EXIT_RUNTIME;
    }
    return CLI_EXIT_OK;
}

/* Builds every point serially; exit code. */
static int build_all(const struct cli_scenario* sc, const struct map_args* a,
                     const struct cli_range* r, struct map_point* pts, enum cli_engine engine)
{
    for (size_t i = 0; i < r[0].n; i++)
        for (size_t j = 0; j < r[1].n; j++) {
            struct map_point* p = &pts[i * r[1].n + j];
            p->value[0] = cli_range_value(&r[0], i);
            p->value[1] = cli_range_value(&r[1], j);
            int rc = build_point(sc, a, p, engine);
            if (rc != CLI_EXIT_OK)
                return rc;
        }
    return CLI_EXIT_OK;
}

static void free_points(struct map_point* pts, size_t n)
{
    for (size_t k = 0; pts && k < n; k++) {
        cli_scenario_free(&pts[k].sc);
        cli_setup_free(&pts[k].su);
        free(pts[k].row);
    }
    free(pts);
}

int cmd_map(int argc, char** argv)
{
    if (cli_wants_help(argc, argv)) {
        usage(stdout);
        return CLI_EXIT_OK;
    }
    struct map_args a;
    struct cli_range r[2];
    int rc = parse_args(argc, argv, &a);
    for (int d = 0; d < 2 && rc == CLI_EXIT_OK; d++)
        rc = cli_parse_range(a.values[d], a.is_log[d], d ? "--values2" : "--values", &r[d]);
    if (rc != CLI_EXIT_OK)
        return rc;
    struct cli_scenario sc;
    rc = cli_load_with_overrides(a.file, a.sets, a.n_sets, &sc);
    enum cli_engine engine = CLI_ENGINE_SOFT;
    if (rc == CLI_EXIT_OK)
        rc = cli_scenario_engine(&sc, &engine);
    if (rc == CLI_EXIT_OK && engine == CLI_ENGINE_PAIRWISE && !cli_run_pairwise) {
        cli_error("map %s: engine 'pairwise' is not in this build", a.file);
        rc = CLI_EXIT_RUNTIME;
    }
    if (rc == CLI_EXIT_OK && cli_scenario_is_many && cli_scenario_is_many(&sc)) {
        cli_error("map %s: a many-particle scenario runs with 'wetdem run' (one run per "
                  "file); maps vary binary or three-sphere collisions",
                  a.file);
        rc = CLI_EXIT_USAGE;
    }
    size_t n = r[0].n * r[1].n;
    struct map_point* pts = rc == CLI_EXIT_OK ? calloc(n, sizeof *pts) : NULL;
    if (rc == CLI_EXIT_OK && !pts) {
        cli_error("map: out of memory for %zu points", n);
        rc = CLI_EXIT_RUNTIME;
    }
    char* header = rc == CLI_EXIT_OK ? engine_header(&sc, engine) : NULL;
    if (rc == CLI_EXIT_OK && !header)
        rc = CLI_EXIT_USAGE;
    double t0 = omp_get_wtime();
    if (rc == CLI_EXIT_OK)
        rc = build_all(&sc, &a, r, pts, engine);
    if (rc == CLI_EXIT_OK) {
#pragma omp parallel for schedule(dynamic, 1)
        for (size_t k = 0; k < n; k++)
            run_point(&pts[k], engine);
        rc = write_output(&a, pts, n, header, argc, argv, omp_get_wtime() - t0);
        for (size_t k = 0; k < n; k++)
            if (pts[k].status < 0) {
                cli_error("map: %s = %.12g, %s = %.12g: %s (%s)", a.key[0], pts[k].value[0],
                          a.key[1], pts[k].value[1], pts[k].errmsg,
                          wetdem_status_name(pts[k].status));
                rc = CLI_EXIT_RUNTIME;
            }
    }
    free(header);
    free_points(pts, pts ? n : 0);
    cli_scenario_free(&sc);
    return rc;
}

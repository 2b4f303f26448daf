/*
 * cmd_map.c — `wetdem map FILE --param KEY --values A:B:N --param2 KEY2 --values2 A:B:N
 * [--log] [--log2] [--out FILE.csv] [--set section.key=value ...]`: a two-parameter grid of
 * independent collisions (e.g. St_n x impact angle of three-sphere collisions, Davis 2023),
 * one CSV row per grid point, KEY varying slowest.
 *
 * Each point is the scenario with `--set KEY=a_i --set KEY2=b_j` (values printed with %.17g,
 * as `wetdem sweep` does), so coupled keys stay right. The batch machinery is the one of
 * `wetdem sweep` (cli/batch.c): every point is built and checked serially first (all input errors are reported before anything runs); the runs are then
 * distributed over OpenMP threads with dynamic scheduling and share nothing; rows are written
 * in grid order after all finished, so the data rows are bit-identical for any thread count.
 * The trailer '#' line (runs, wall time, threads, collisions per second) is the only line
 * that varies. Engines: pairwise (the row of cli_run_pairwise) and soft (the collision row of
 * `wetdem sweep`); many-particle scenarios are refused (exit 2), as by `wetdem sweep`, and
 * so are two names of one key, or speed with stokes (cli/batch.c). Progress goes to stderr
 * when it is a terminal; SIGINT writes the table of the points that ran (cli/batch.h).
 */
#include <omp.h>
#include <stdio.h>
#include <string.h>

#include "batch.h"

#define MAP_MAX_SETS 256

struct map_args {
    const char* file;
    const char* key[2];
    const char* values[2];
    bool is_log[2];
    const char* out;
    const char* resume;
    const char* save_every;
    const char* sets[MAP_MAX_SETS];
    int n_sets;
};

/* What the table writer needs. */
struct map_table {
    const struct cli_batch* batch;
    int argc;
    char** argv;
};

static void usage(FILE* f)
{
    fprintf(f,
            "usage: wetdem map FILE --param KEY --values A:B:N --param2 KEY2 --values2 A:B:N\n"
            "                  [--log] [--log2] [--out FILE.csv] [--resume FILE.csv]\n"
            "                  [--save-every S] [--set section.key=value ...]\n"
            "A grid of independent collisions over two scenario keys (KEY slowest), in\n"
            "parallel (OMP_NUM_THREADS); rows in grid order, bit-identical for any thread count.\n"
            "  --param KEY      first key (scenario key or model parameter, e.g. davis.stokes)\n"
            "  --values A:B:N   its N values from A to B (both included); --log: geometric\n"
            "  --param2 KEY2    second key, varied fastest\n"
            "  --values2 A:B:N  its N values; --log2: geometric\n"
            "  --out FILE.csv   write the grid there (default: stdout)\n"
            "  --resume T.csv   the grid of this map that Ctrl-C stopped: keep its rows that ran,\n"
            "                   run those NOT_RUN (T may be the --out file)\n"
            "  --save-every S   while it runs, save the grid of the points done to --out every\n"
            "                   S seconds (default 60; 0: never), for --resume after a crash\n"
            "  --set K=V        override a scenario key or model parameter (repeatable)\n");
}

static int parse_args(int argc, char** argv, struct map_args* a)
{
    memset(a, 0, sizeof *a);
    static const char* const once[] = {"--param", "--values", "--param2",     "--values2",
                                       "--out",   "--resume", "--save-every", NULL};
    unsigned seen = 0;
    for (int k = 1; k < argc; k++) {
        const char* s = argv[k];
        bool next = k + 1 < argc;
        if (next && cli_option_once("map", s, once, &seen) != CLI_EXIT_OK)
            return CLI_EXIT_USAGE;
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
        else if (strcmp(s, "--resume") == 0 && next)
            a->resume = argv[++k];
        else if (strcmp(s, "--save-every") == 0 && next)
            a->save_every = argv[++k];
        else if (strcmp(s, "--set") == 0 && next && a->n_sets < MAP_MAX_SETS)
            a->sets[a->n_sets++] = argv[++k];
        else if (strcmp(s, "--log") == 0)
            a->is_log[0] = true;
        else if (strcmp(s, "--log2") == 0)
            a->is_log[1] = true;
        else if (s[0] != '-' && !a->file)
            a->file = s;
        else {
            static const char* const options[] = {
                "--param",      "--values", "--param2", "--values2", "--out", "--resume",
                "--save-every", "--set",    "--log",    "--log2",    NULL};
            static const char* const takes[] = {"--param",
                                                "a scenario key or model parameter",
                                                "--values",
                                                "A:B:N",
                                                "--param2",
                                                "a scenario key or model parameter",
                                                "--values2",
                                                "A:B:N",
                                                "--out",
                                                "a file, FILE.csv",
                                                "--resume",
                                                "a grid, T.csv",
                                                "--set",
                                                "KEY=VALUE",
                                                "--save-every",
                                                "S seconds",
                                                NULL};
            char hint[64];
            if (strcmp(s, "--set") == 0 && next) /* (the only option refused with a value) */
                cli_error("map: more than %d --set options", MAP_MAX_SETS);
            else if (next || !cli_needs_value("map", s, takes))
                cli_error("map: unexpected argument '%s'%s", s,
                          cli_option_hint(s, options, hint, sizeof hint));
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
    const char* in[1] = {a->file};
    const char* names[1] = {"FILE"};
    int rc = cli_check_output_path("map", "--out", a->out, false);
    return rc == CLI_EXIT_OK ? cli_check_not_input("map", "--out", a->out, in, names, 1) : rc;
}

/* The table with the map's trailer. */
static void write_table(FILE* f, const void* ctx)
{
    const struct map_table* t = ctx;
    const struct cli_batch* b = t->batch;
    cli_batch_write_table(f, b, t->argc, t->argv);
    size_t runs = cli_batch_points_run(b) - b->n_kept; /* (run here, not kept) */
    fprintf(f, "# totals: runs=%zu wall_time_s=%.6f threads=%d collisions_per_s=%.3f\n", runs,
            b->wall, omp_get_max_threads(), b->wall > 0 ? (double)runs / b->wall : 0.0);
}

int cmd_map(int argc, char** argv)
{
    if (cli_wants_help(argc, argv)) {
        usage(stdout);
        return CLI_EXIT_OK;
    }
    struct map_args a;
    int rc = parse_args(argc, argv, &a);
    struct cli_batch b = {.cmd = "map",
                          .many_note = "maps vary binary or three-sphere collisions",
                          .file = a.file,
                          .sets = a.sets,
                          .n_sets = a.n_sets,
                          .n_keys = 2,
                          .key = {a.key[0], a.key[1]},
                          .progress = true,
                          .out = a.out,
                          .resume = a.resume,
                          .save_every = CLI_BATCH_SAVE_EVERY_S,
                          .write_table = write_table};
    struct map_table t = {&b, argc, argv};
    b.table_ctx = &t;
    for (int d = 0; d < 2 && rc == CLI_EXIT_OK; d++)
        rc = cli_parse_range(a.values[d], a.is_log[d], d ? "--values2" : "--values", &b.range[d]);
    if (rc == CLI_EXIT_OK && a.save_every)
        rc = cli_batch_parse_save_every("map", a.save_every, &b.save_every);
    if (rc == CLI_EXIT_OK && a.save_every && !a.out && b.save_every > 0)
        cli_error("warning: map: --save-every %s has no effect without --out: a table on "
                  "standard output is written once, at the end",
                  a.save_every);
    if (rc != CLI_EXIT_OK)
        return rc;
    double points = (double)b.range[0].n * (double)b.range[1].n;
    if (points > CLI_MAX_BATCH_POINTS) { /* as a sweep's N: some 0.8 kB of memory a point */
        cli_error("map: --values x --values2 = %zu x %zu = %.3g points, more than %.0f",
                  b.range[0].n, b.range[1].n, points, CLI_MAX_BATCH_POINTS);
        return CLI_EXIT_USAGE;
    }
    rc = cli_batch_run(&b);
    if (rc == CLI_EXIT_OK) { /* (also after an interruption: the points that ran) */
        rc = cli_write_output(a.out, "map", write_table, &t);
        rc = cli_batch_report_failures(&b, rc);
    }
    cli_batch_free(&b);
    return rc;
}

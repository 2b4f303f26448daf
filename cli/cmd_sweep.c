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
 * The batch machinery, shared with `wetdem map`, is cli/batch.c.
 * Determinism: every value gets its own simulation (soft engine) or scenario (pairwise engine),
 * built and checked serially before any run; the runs, of either engine, share nothing and
 * are distributed over the threads, and rows are written in input order after all finished,
 * so the data rows are bit-identical for any OMP_NUM_THREADS. The trailer '#' line (totals and
 * wall time) is the only line that varies between runs. The status column is the run's
 * status (the pairwise engine's for pairwise scenarios), ENERGY_GREW or NOT_RUN (cli/batch.h);
 * a failed point makes the exit code 1, an interruption (SIGINT, SIGTERM) 128 + the signal
 * after the table of the points that ran is written.
 *
 * Progress with an estimate of the time left goes to stderr only when stderr is a terminal.
 */
#include <omp.h>
#include <stdio.h>
#include <string.h>

#include "batch.h"

#define MAX_SETS 256

struct sweep_args {
    const char* file;
    const char* key;
    const char* values;
    const char* out;
    const char* resume;
    const char* save_every;
    bool is_log;
    const char* sets[MAX_SETS];
    int n_sets;
};

/* What the table writer needs. */
struct sweep_table {
    const struct cli_batch* batch;
    int argc;
    char** argv;
};

static void usage(FILE* f)
{
    fprintf(
        f,
        "usage: wetdem sweep FILE --param KEY --values A:B:N [--log] [--out FILE.csv]\n"
        "                    [--resume FILE.csv] [--save-every S] [--set section.key=value ...]\n"
        "Independent collisions, one per value of KEY (any scenario key, e.g.\n"
        "collision.stokes, or a model parameter), in parallel (OMP_NUM_THREADS).\n"
        "  --values A:B:N  N values from A to B (both included); --log: geometric\n"
        "  --out FILE.csv  write the table there (default: stdout)\n"
        "  --resume T.csv  the table of this sweep that Ctrl-C stopped: keep its rows that\n"
        "                  ran, run those NOT_RUN (T may be the --out file)\n"
        "  --save-every S  while it runs, save the table of the points done to --out every\n"
        "                  S seconds (default 60; 0: never), for --resume after a crash\n"
        "  --set K=V       override a scenario key or model parameter (repeatable)\n");
}

static int parse_args(int argc, char** argv, struct sweep_args* a)
{
    memset(a, 0, sizeof *a);
    static const char* const once[] = {"--param",  "--values",     "--out",
                                       "--resume", "--save-every", NULL};
    unsigned seen = 0;
    for (int k = 1; k < argc; k++) {
        const char* s = argv[k];
        bool next = k + 1 < argc;
        if (next && cli_option_once("sweep", s, once, &seen) != CLI_EXIT_OK)
            return CLI_EXIT_USAGE;
        if (strcmp(s, "--param") == 0 && next)
            a->key = argv[++k];
        else if (strcmp(s, "--values") == 0 && next)
            a->values = argv[++k];
        else if (strcmp(s, "--out") == 0 && next)
            a->out = argv[++k];
        else if (strcmp(s, "--resume") == 0 && next)
            a->resume = argv[++k];
        else if (strcmp(s, "--save-every") == 0 && next)
            a->save_every = argv[++k];
        else if (strcmp(s, "--set") == 0 && next && a->n_sets < MAX_SETS)
            a->sets[a->n_sets++] = argv[++k];
        else if (strcmp(s, "--log") == 0)
            a->is_log = true;
        else if (s[0] != '-' && !a->file)
            a->file = s;
        else {
            static const char* const options[] = {"--param",      "--values", "--out", "--resume",
                                                  "--save-every", "--set",    "--log", NULL};
            static const char* const takes[] = {"--param",
                                                "a scenario key or model parameter",
                                                "--values",
                                                "A:B:N",
                                                "--out",
                                                "a file, FILE.csv",
                                                "--resume",
                                                "a table, T.csv",
                                                "--set",
                                                "KEY=VALUE",
                                                "--save-every",
                                                "S seconds",
                                                NULL};
            char hint[64];
            if (strcmp(s, "--set") == 0 && next) /* (the only option refused with a value) */
                cli_error("sweep: more than %d --set options", MAX_SETS);
            else if (next || !cli_needs_value("sweep", s, takes))
                cli_error("sweep: unexpected argument '%s'%s", s,
                          cli_option_hint(s, options, hint, sizeof hint));
            usage(stderr);
            return CLI_EXIT_USAGE;
        }
    }
    if (!a->file || !a->key || !a->values) {
        cli_error("sweep: FILE, --param KEY and --values A:B:N are required");
        usage(stderr);
        return CLI_EXIT_USAGE;
    }
    const char* in[1] = {a->file};
    const char* names[1] = {"FILE"};
    int rc = cli_check_output_path("sweep", "--out", a->out, false);
    return rc == CLI_EXIT_OK ? cli_check_not_input("sweep", "--out", a->out, in, names, 1) : rc;
}

/* The table with the sweep's trailer: for the soft engine, the integrator counts summed over
 * all runs (the pairwise engine's counts are in its rows: events, steps). */
static void write_table(FILE* f, const void* ctx)
{
    const struct sweep_table* t = ctx;
    const struct cli_batch* b = t->batch;
    cli_batch_write_table(f, b, t->argc, t->argv);
    if (b->engine == CLI_ENGINE_PAIRWISE) {
        fprintf(f, "# totals: runs=%zu wall_time_s=%.6f threads=%d\n",
                cli_batch_points_run(b) - b->n_kept, b->wall, omp_get_max_threads());
        return;
    }
    struct wetdem_stats tot = {0};
    for (size_t k = 0; k < b->n_pts; k++) {
        if (!b->pts[k].done) /* (still running when the table is saved midway) */
            continue;
        const struct wetdem_stats* s = &b->pts[k].res.stats;
        tot.steps += s->steps;
        tot.force_evals += s->force_evals;
        tot.pair_evals += s->pair_evals;
        tot.root_evals += s->root_evals;
        tot.events += s->events;
    }
    fprintf(f,
            "# totals: runs=%zu steps=%llu force_evals=%llu pair_evals=%llu root_evals=%llu "
            "events=%llu wall_time_s=%.6f threads=%d\n",
            cli_batch_points_run(b) - b->n_kept, tot.steps, tot.force_evals, tot.pair_evals,
            tot.root_evals, tot.events, b->wall, omp_get_max_threads());
}

int cmd_sweep(int argc, char** argv)
{
    if (cli_wants_help(argc, argv)) {
        usage(stdout);
        return CLI_EXIT_OK;
    }
    struct sweep_args a;
    int rc = parse_args(argc, argv, &a);
    struct cli_batch b = {.cmd = "sweep",
                          .many_note = "sweeps vary binary collisions",
                          .file = a.file,
                          .sets = a.sets,
                          .n_sets = a.n_sets,
                          .n_keys = 1,
                          .key = {a.key},
                          .progress = true,
                          .out = a.out,
                          .resume = a.resume,
                          .save_every = CLI_BATCH_SAVE_EVERY_S,
                          .write_table = write_table};
    struct sweep_table t = {&b, argc, argv};
    b.table_ctx = &t;
    if (rc == CLI_EXIT_OK)
        rc = cli_parse_range(a.values, a.is_log, "--values", &b.range[0]);
    if (rc == CLI_EXIT_OK && a.save_every)
        rc = cli_batch_parse_save_every("sweep", a.save_every, &b.save_every);
    if (rc == CLI_EXIT_OK && a.save_every && !a.out && b.save_every > 0)
        cli_error("warning: sweep: --save-every %s has no effect without --out: a table on "
                  "standard output is written once, at the end",
                  a.save_every);
    if (rc != CLI_EXIT_OK)
        return rc;
    rc = cli_batch_run(&b);
    if (rc == CLI_EXIT_OK) { /* (also after an interruption: the points that ran) */
        rc = cli_write_output(a.out, "sweep", write_table, &t);
        rc = cli_batch_report_failures(&b, rc);
    }
    cli_batch_free(&b);
    return rc;
}

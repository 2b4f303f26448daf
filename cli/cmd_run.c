/*
 * cmd_run.c — `wetdem run FILE [--set section.key=value ...] [--out DIR] [--json] [--check]`:
 * runs the binary collision of a scenario file (docs/scenarios.md) and prints its summary
 * (every field of struct wetdem_collision_result with units; JSON with --json). With --out,
 * writes DIR/trajectory.csv, DIR/events.csv and DIR/summary.json (names from [output]).
 * --check only reads, checks and resolves the scenario (derived speed, times) and prints that.
 * Many-particle scenarios ([box], [insert], ...) go to cli_run_many (cli/run_many.c), which
 * also handles --restart CHECKPOINT.
 *
 * A long run shows its progress with the time left on stderr when that is a terminal.
 *
 * Nothing half-written: the scenario is checked and the simulation built (every input check)
 * before any file is opened; files are written under temporary names (cli_out_open) and
 * renamed only when the run succeeded and the file was written whole, removed otherwise.
 * Exit codes: 0 ok, 1 runtime error, 2 usage or input error.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli_util.h"
#include "output_csv.h"
#include "scenario.h"
#include "signals.h"

#define MAX_SETS 256

struct run_args {
    const char* file;
    const char* sets[MAX_SETS];
    int n_sets;
    const char* out_dir;
    const char* restart; /* many-particle runs: checkpoint to resume from */
    bool json, check;
};

static void usage(FILE* f)
{
    fprintf(f, "usage: wetdem run FILE [--set section.key=value ...] [--out DIR] [--json] "
               "[--check] [--restart CHECKPOINT]\n"
               "Runs the binary collision or the many-particle run of a scenario file "
               "(docs/scenarios.md, docs/many.md).\n"
               "  --set K=V   override a scenario key, e.g. --set collision.stokes=50\n"
               "  --out DIR   write DIR/trajectory.csv, DIR/events.csv, DIR/summary.json\n"
               "              (many-particle runs: VTK series, CSV, checkpoint, summary)\n"
               "  --json      print the summary as JSON\n"
               "  --check     check the scenario and print the resolved set-up; do not run\n"
               "  --restart C resume a many-particle run from checkpoint C (same scenario)\n"
               "The files of one collision are kept as a set, whole, or not at all. Ctrl-C or\n"
               "SIGTERM: exit 128 + N (a many-particle run writes its checkpoint first).\n"
               "A run longer than half a second shows its progress and the time left on\n"
               "stderr when that is a terminal (the estimate runs to t_end: a collision\n"
               "that separates, or a pairwise run that comes apart, ends sooner).\n");
}

static int parse_args(int argc, char** argv, struct run_args* a)
{
    memset(a, 0, sizeof *a);
    static const char* const once[] = {"--out", "--restart", NULL};
    unsigned seen = 0;
    for (int k = 1; k < argc; k++) {
        const char* s = argv[k];
        bool has_next = k + 1 < argc;
        if (has_next && cli_option_once("run", s, once, &seen) != CLI_EXIT_OK)
            return CLI_EXIT_USAGE;
        if (strcmp(s, "--set") == 0 && has_next && a->n_sets < MAX_SETS)
            a->sets[a->n_sets++] = argv[++k];
        else if (strcmp(s, "--out") == 0 && has_next)
            a->out_dir = argv[++k];
        else if (strcmp(s, "--restart") == 0 && has_next)
            a->restart = argv[++k];
        else if (strcmp(s, "--json") == 0)
            a->json = true;
        else if (strcmp(s, "--check") == 0)
            a->check = true;
        else if (s[0] != '-' && !a->file)
            a->file = s;
        else {
            static const char* const options[] = {"--set",  "--out",   "--restart",
                                                  "--json", "--check", NULL};
            static const char* const takes[] = {"--set",       "KEY=VALUE", "--out",
                                                "a directory", "--restart", "a checkpoint file",
                                                NULL};
            char hint[64];
            if (strcmp(s, "--set") == 0 && has_next) /* the only option refused with a value */
                cli_error("run: more than %d --set options", MAX_SETS);
            else if (has_next || !cli_needs_value("run", s, takes))
                cli_error("run: unexpected argument '%s'%s", s,
                          cli_option_hint(s, options, hint, sizeof hint));
            usage(stderr);
            return CLI_EXIT_USAGE;
        }
    }
    if (!a->file) {
        usage(stderr);
        return CLI_EXIT_USAGE;
    }
    /* before anything is built or written */
    return cli_check_output_path("run", "--out", a->out_dir, true);
}

static void print_check(const struct cli_scenario* sc, const struct cli_setup* su, bool json)
{
    const struct wetdem_collision_spec* s = &su->spec;
    if (json) {
        printf("{\"scenario\": ");
        cli_json_string(stdout, sc->file);
        printf(", \"integrator\": \"%s\", \"impact_speed\": ", wetdem_sim_integrator_name(su->sim));
        cli_json_number(stdout, su->impact_speed);
        printf(", \"stokes_n\": ");
        cli_json_number(stdout, su->stokes_n);
        printf(", \"m_eff\": %.17g, \"r_eff\": %.17g, \"t_end\": %.17g, \"angle\": %.17g, "
               "\"trajectory_interval\": %.17g, \"n_models\": %zu}\n",
               su->m_eff, su->r_eff, s->t_end,
               cli_plain_zero(s->angle * 180.0 / 3.14159265358979323846), su->trajectory_interval,
               wetdem_sim_n_models(su->sim));
        return;
    }
    printf("scenario %s is valid\n", sc->file);
    printf("  impact_speed  %.10g m/s\n  stokes_n      %.10g -\n  m_eff         %.10g kg\n"
           "  r_eff         %.10g m\n  t_end         %.10g s\n  integrator    %s\n  models       ",
           su->impact_speed, su->stokes_n, su->m_eff, su->r_eff, s->t_end,
           wetdem_sim_integrator_name(su->sim));
    for (size_t k = 0; k < wetdem_sim_n_models(su->sim); k++)
        printf(" %s", wetdem_sim_model(su->sim, k)->name);
    printf(" (h_min: %s)\n", wetdem_sim_min_separation_model(su->sim)->name);
}

/* Runs the collision with the files open; returns an exit code. */
static int run_soft(const struct cli_scenario* sc, struct cli_setup* su, const struct run_args* a,
                    int argc, char** argv)
{
    struct cli_out_file traj, events, summary;
    int rc = CLI_EXIT_OK;
    if (a->out_dir && su->trajectory_file[0] &&
        (rc = cli_scenario_check_trajectory(sc, "collision", su->spec.t_end,
                                            su->trajectory_interval)) != CLI_EXIT_OK)
        return rc; /* before the directory is made */
    const char* names[3] = {su->trajectory_file, su->events_file, su->summary_file};
    if ((rc = cli_check_out_dir("run", a->out_dir, names, 3)) != CLI_EXIT_OK)
        return rc; /* (before the run: an unwritable place is bad input) */
    if (cli_out_open(&traj, "run", a->out_dir, su->trajectory_file) != 0)
        return CLI_EXIT_RUNTIME;
    struct cli_trajectory t = {
        .f = traj.f, .target_is_wall = su->spec.target_is_wall, .argc = argc, .argv = argv};
    struct cli_saved_signals saved;
    bool guarded = traj.f != NULL; /* (a signal stops the run: cli_signals_install_run) */
    if (guarded) {
        wetdem_sim_set_observer(su->sim, su->trajectory_interval, cli_trajectory_observe, &t);
        cli_signals_install_run(traj.tmp, &saved);
    }
    struct wetdem_collision_result res;
    struct cli_progress line;
    cli_progress_start(&line, 0);
    if (line.tty)
        wetdem_sim_set_progress(su->sim, cli_progress_time, &line);
    errno = 0;
    int st = wetdem_collision_run(su->sim, &su->spec, &res);
    wetdem_sim_set_progress(su->sim, NULL, NULL); /* (line ends with this call) */
    cli_progress_clear(&line);                    /* (before any message) */
    if ((guarded && cli_stop_signal) || st < 0) {
        cli_out_close(&traj, "run", false);
        int stopped = guarded ? cli_signals_finish_run("run", &saved) : 0;
        if (stopped)
            return stopped;
        if (t.err) /* the observer stopped the run: the write failed, not the simulation */
            cli_error("run: cannot write %s: %s", traj.final, strerror(t.err));
        else
            cli_error("run %s: %s (%s)", sc->file, wetdem_sim_errmsg(su->sim),
                      wetdem_status_name(st));
        return t.err ? CLI_EXIT_RUNTIME : cli_run_exit(st);
    }
    cli_setup_capture(su, &res);
    struct cli_out_file* files[3] = {&traj, &events, &summary};
    if (cli_out_open(&events, "run", a->out_dir, su->events_file) != 0 ||
        cli_out_open(&summary, "run", a->out_dir, su->summary_file) != 0) {
        cli_out_close_all(files, 2, "run", false);
        int stopped = guarded ? cli_signals_finish_run("run", &saved) : 0;
        return stopped ? stopped : CLI_EXIT_RUNTIME;
    }
    if (events.f)
        cli_events_csv(events.f, su->sim, argc, argv);
    if (summary.f)
        cli_summary_json(summary.f, sc, su, &res, argc, argv);
    /* the three files as a set: all kept whole, or none (a signal until now keeps none) */
    sigset_t mask;
    cli_signals_block(&mask);
    int stopped = guarded ? cli_signals_finish_run("run", &saved) : 0;
    if (cli_out_close_all(files, 3, "run", !stopped) != 0)
        rc = CLI_EXIT_RUNTIME;
    cli_signals_unblock(&mask);
    if (stopped)
        return stopped;
    if (a->json)
        cli_summary_json(stdout, sc, su, &res, argc, argv);
    else
        cli_summary_text(stdout, sc, su, &res);
    if (a->out_dir && rc == CLI_EXIT_OK && !a->json)
        printf("files in %s/\n", a->out_dir);
    char why[600];
    if (rc == CLI_EXIT_OK && cli_energy_grew(res.energy_ratio, why, sizeof why)) {
        cli_error("run %s: the collision %s", sc->file, why);
        rc = CLI_EXIT_RUNTIME;
    }
    if (rc == CLI_EXIT_OK && cli_hmin_unresolved(&res, why, sizeof why))
        cli_error("warning: run %s: %s", sc->file, why);
    if (rc == CLI_EXIT_OK && cli_overlap_large(&res, su->r_eff, why, sizeof why))
        cli_error("warning: run %s: %s", sc->file, why);
    return rc;
}

int cmd_run(int argc, char** argv)
{
    if (cli_wants_help(argc, argv)) {
        usage(stdout);
        return CLI_EXIT_OK;
    }
    struct run_args a;
    int rc = parse_args(argc, argv, &a);
    if (rc != CLI_EXIT_OK)
        return rc;
    struct cli_scenario sc;
    rc = cli_load_with_overrides(a.file, a.sets, a.n_sets, &sc);
    enum cli_engine engine = CLI_ENGINE_SOFT;
    if (rc == CLI_EXIT_OK)
        cli_scenario_engine(&sc, &engine);
    if (rc == CLI_EXIT_OK && engine == CLI_ENGINE_PAIRWISE) {
        if (!cli_run_pairwise) {
            cli_error("run %s: engine 'pairwise' is not in this build", a.file);
            rc = CLI_EXIT_RUNTIME;
        } else {
            struct cli_run_options opt = {
                .out_dir = a.out_dir, .json = a.json, .argc = argc, .argv = argv, .check = a.check};
            rc = cli_run_pairwise(&sc, &opt);
        }
        cli_scenario_free(&sc);
        return rc;
    }
    bool many = rc == CLI_EXIT_OK && cli_scenario_is_many && cli_scenario_is_many(&sc);
    if (many || (rc == CLI_EXIT_OK && a.restart)) {
        struct cli_run_options opt = {.out_dir = a.out_dir,
                                      .json = a.json,
                                      .argc = argc,
                                      .argv = argv,
                                      .restart = a.restart,
                                      .check = a.check};
        if (!many || !cli_run_many) {
            cli_error("run %s: %s", a.file,
                      many ? "many-particle runs are not in this build"
                           : "--restart resumes many-particle runs only ([box], [insert], ...)");
            rc = many ? CLI_EXIT_RUNTIME : CLI_EXIT_USAGE;
        } else
            rc = cli_run_many(&sc, &opt);
        cli_scenario_free(&sc);
        return rc;
    }
    struct cli_setup su = {0};
    if (rc == CLI_EXIT_OK)
        rc = cli_scenario_build(&sc, &su);
    if (rc == CLI_EXIT_OK && a.check)
        print_check(&sc, &su, a.json);
    else if (rc == CLI_EXIT_OK)
        rc = run_soft(&sc, &su, &a, argc, argv);
    cli_setup_free(&su);
    cli_scenario_free(&sc);
    return rc;
}

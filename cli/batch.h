/*
 * batch.h — what `wetdem sweep` and `wetdem map` share: a batch of independent collisions, the
 * scenario of a file with one or two keys set to every combination of their values, built and
 * checked serially, run in parallel, written in input order.
 *
 * Each point is the scenario with `--set KEY=value` for each key (values printed with %.17g,
 * so the same bits as `wetdem run FILE --set KEY=value`, and coupled keys stay right). Every
 * point is built (soft engine) or its configuration checked (pairwise engine) before any runs,
 * so every input error is reported before anything runs, and built again when it runs (a
 * point keeps only its values and results: about 1 kB); the runs share nothing and are
 * distributed over OpenMP threads with dynamic scheduling (run times differ by orders of
 * magnitude across a batch); each keeps its engine's CSV fields, and the table is written
 * after all finished, so its data rows are bit-identical for any thread count.
 * Many-particle scenarios are refused (exit 2): they run with `wetdem run`.
 */
#ifndef WETDEM_CLI_BATCH_H
#define WETDEM_CLI_BATCH_H

#include <stdio.h>

#include "cli_util.h"
#include "scenario.h"

#define CLI_BATCH_MAX_KEYS 2

/* Status of a point that an interruption (SIGINT, SIGTERM) left out: no engine status. */
#define CLI_BATCH_NOT_RUN 1000
/* Status of a point kept from the table of --resume, whose run there succeeded or failed. */
#define CLI_BATCH_KEPT 1001
#define CLI_BATCH_KEPT_FAILED 1002

/* One point: its values, and after the run its status and CSV fields (its scenario and
 * set-up live only while it is checked and while it runs). */
struct cli_batch_point {
    double value[CLI_BATCH_MAX_KEYS];   /* the keys' values at this point [their units] */
    struct wetdem_collision_result res; /* soft engine: the run's result (zero for pairwise) */
    int status;       /* the run's status (the pairwise engine's own), or CLI_BATCH_NOT_RUN */
    bool energy_grew; /* soft engine: it ran but ended with more energy (cli_energy_grew) */
    double r_eff;     /* soft engine: R* of its set-up [m] (cli_overlap_large) */
    char errmsg[256]; /* the engine's message of a failed run */
    char* row;        /* the engine's CSV fields, no newline (malloc'd); of a point kept
                         from --resume, its status word and fields as that table has them */
    bool done;        /* it ran here (set under the batch's lock when it finished) or was
                         kept from --resume: only then are its status and row read while
                         the batch runs (the table saved meanwhile) */
};

/* The default of --save-every [s]: a batch of a minute or less is never saved midway. */
#define CLI_BATCH_SAVE_EVERY_S 60.0

/* Parses the value of `cmd`'s --save-every, seconds in [0, 1e9] (0: never). Returns
 * CLI_EXIT_OK and sets *out, or prints why and returns CLI_EXIT_USAGE. */
int cli_batch_parse_save_every(const char* cmd, const char* text, double* out);

/* A batch: the caller fills the first block, cli_batch_run() the second. */
struct cli_batch {
    const char* cmd;         /* "sweep", "map": names the command in messages */
    const char* many_note;   /* why a many-particle scenario is refused, e.g. "sweeps vary
                                binary collisions" */
    const char* file;        /* scenario file */
    const char* const* sets; /* "--set section.key=value" overrides of the file */
    int n_sets;
    int n_keys; /* 1 or 2 */
    const char* key[CLI_BATCH_MAX_KEYS];
    struct cli_range range[CLI_BATCH_MAX_KEYS];
    bool progress;      /* progress and time left on stderr when it is a terminal */
    const char* out;    /* the table's file (NULL: stdout): checked writable before the runs */
    const char* resume; /* a table this batch wrote, interrupted (NULL: none): its points that
                           ran are kept, only those NOT_RUN run */
    double save_every;  /* while the points run, the table of those done so far is written to
                           `out` every save_every seconds or more (never more than 2 % of the
                           time: at least 50 x the last write), the others NOT_RUN, so that a
                           run killed outright (SIGKILL, power) can be completed by --resume;
                           0, or out NULL (stdout): never */
    void (*write_table)(FILE* f, const void* ctx); /* the caller's writer of the table (with
                                                      its trailer), for those saves */
    const void* table_ctx;

    enum cli_engine engine;
    char* header;                /* the engine's CSV column header, no newline (malloc'd) */
    struct cli_batch_point* pts; /* n_pts points, the first key varying slowest */
    size_t n_pts;
    double wall;     /* build and run time [s] */
    int interrupted; /* the signal (SIGINT, SIGTERM) that stopped the batch early, or 0 */
    size_t n_kept;   /* points kept from the table of --resume */
    unsigned long long scenario_hash; /* of the file's bytes and the --set overrides (the table
                                         records it, --resume compares it) */
    bool saving;    /* the table is being saved while the batch runs (a '#' line says so) */
    size_t n_saves; /* saves so far */
    double t_start; /* omp_get_wtime() when the batch started building [s] */
};

/* Checks the keys (two names of one key, or speed and stokes, are refused), loads the file
 * with the overrides, checks the engine, builds every point serially, reads the table of
 * `resume` (its columns and every row's values must be this batch's, and each row kept one
 * the batch writes: exit 2 with the line that differs), checks that `out` can be written, and runs the points in parallel (those
 * kept from `resume` not again). Returns an exit code: an input error of the
 * file or of any point, or an output that cannot be written, stops before anything runs
 * (message printed, exit 2); a failed run is not an error here, its status is in its point
 * (see cli_batch_report_failures). SIGINT or SIGTERM while the points run stops starting new
 * ones: those that run finish, the others get CLI_BATCH_NOT_RUN and b->interrupted is set, so
 * the caller still writes the table (a repeat within CLI_SIGNAL_GRACE_S is the same request;
 * a later one, or a third, stops at once by the signal: signals.h). Free
 * with cli_batch_free() in every case. */
int cli_batch_run(struct cli_batch* b);

/* Writes the '#' provenance lines, the header "KEY [unit],...,status [word],<engine columns>"
 * (after a '#' line with the scenario's hash) and one row per point
 * "value,...,status,<engine fields>" (status: the engine's status name,
 * ENERGY_GREW, or NOT_RUN), and after an interruption, or when saved while the batch runs, a
 * '#' line saying so; the caller adds its trailer (reading only the points marked done). */
void cli_batch_write_table(FILE* f, const struct cli_batch* b, int argc, char** argv);

/* How many points ran, here or in the table of --resume (all unless interrupted; while the
 * table is saved, those done so far). */
size_t cli_batch_points_run(const struct cli_batch* b);

/* Prints "CMD: KEY = value, ...: message (status)" for every failed run (for those kept from
 * --resume, how many failed there). Returns rc (the table's write) when it is not
 * CLI_EXIT_OK, else 128 + the signal when the batch was interrupted, else CLI_EXIT_RUNTIME
 * when any run failed, else CLI_EXIT_OK. */
int cli_batch_report_failures(const struct cli_batch* b, int rc);

/* Frees the points, the header and the scenario. */
void cli_batch_free(struct cli_batch* b);

#endif

/*
 * batch.c — the batch of independent collisions behind `wetdem sweep` and `wetdem map` (see
 * batch.h): load and check the scenario, check every point serially by building it, build
 * and run the points in parallel, write the table in input order, report the failed runs.
 *
 * Engines: soft (a CSV row of every field of struct wetdem_collision_result, cli/output_csv.c;
 * nan and none for a failed run, status ENERGY_GREW for a run whose energy grew) and pairwise
 * (the row of cli_run_pairwise, whose status column is the engine's status). SIGINT or
 * SIGTERM stops starting points; the table of those that ran is still written. While the
 * points run, the table of those done is saved to the output file every save_every seconds
 * (the others NOT_RUN), so that a process killed outright can be resumed from it.
 */
#include <errno.h>
#include <math.h>
#include <omp.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "batch.h"
#include "output_csv.h"
#include "signals.h"

/* What a batch holds per point while it runs (with the row's text, about 1 kB): its set-up is
 * built when it runs, not kept, or maps of millions of collisions would not fit in memory. */
_Static_assert(sizeof(struct cli_batch_point) <= 1024, "a batch point holds only its results");

/* The scenario of point p into *sc: base with every key set; then, for the soft engine, its
 * set-up into *su, or for the pairwise engine its configuration checked without running (its
 * header mode builds and validates it). Touches only *sc and *su, so points are built
 * concurrently. Returns an exit code; free *sc and *su in every case. */
static int build_point(const struct cli_scenario* base, const struct cli_batch* b,
                       const struct cli_batch_point* p, struct cli_scenario* sc,
                       struct cli_setup* su)
{
    memset(su, 0, sizeof *su);
    int rc = cli_scenario_copy(base, sc);
    for (int d = 0; d < b->n_keys && rc == CLI_EXIT_OK; d++) {
        char set[512];
        snprintf(set, sizeof set, "%s=%.17g", b->key[d], cli_plain_zero(p->value[d]));
        rc = cli_scenario_override(sc, set);
    }
    if (rc == CLI_EXIT_OK && b->engine == CLI_ENGINE_SOFT)
        rc = cli_scenario_build(sc, su);
    if (rc == CLI_EXIT_OK && b->engine == CLI_ENGINE_PAIRWISE) {
        char* text = NULL;
        size_t len = 0;
        FILE* f = open_memstream(&text, &len);
        struct cli_run_options opt = {.sweep_row = f, .sweep_header = true};
        rc = f ? cli_run_pairwise(sc, &opt) : CLI_EXIT_RUNTIME;
        if (f)
            fclose(f);
        free(text);
    }
    return rc;
}

/* The values of point p into buf: for messages, "KEY = VALUE[, KEY2 = VALUE2]"; else as the
 * first fields of its row, "VALUE,[VALUE2,]". Each value is the one the point ran with: 12
 * digits, or up to 17 where 12 would read back as another number (0:0.4:5 gives
 * 0.30000000000000004, a log sweep most of its values), so that `wetdem run FILE --set
 * KEY=VALUE` with the text of a row runs that row's collision. */
static void format_values(const struct cli_batch* b, const struct cli_batch_point* p,
                          bool for_message, char* buf, size_t n)
{
    size_t used = 0;
    buf[0] = '\0';
    for (int d = 0; d < b->n_keys && used < n; d++) {
        char value[40];
        wetdem_param_format_value(cli_plain_zero(p->value[d]), 12, value, sizeof value);
        used += (size_t)(for_message ? snprintf(buf + used, n - used, "%s%s = %s", d ? ", " : "",
                                                b->key[d], value)
                                     : snprintf(buf + used, n - used, "%s,", value));
    }
}

/* "KEY = VALUE[, KEY2 = VALUE2]" of point p into buf. */
static void point_values(const struct cli_batch* b, const struct cli_batch_point* p, char* buf,
                         size_t n)
{
    format_values(b, p, true, buf, n);
}

/* Checks every point by building it (serially: every input error is reported before anything
 * runs), then releases it: a point holds only its values and results, and is built again when
 * it runs, so a batch of millions of collisions needs about 1 kB each rather than its set-up. */
static int build_all(const struct cli_scenario* base, struct cli_batch* b)
{
    for (size_t k = 0; k < b->n_pts; k++) {
        struct cli_batch_point* p = &b->pts[k];
        size_t rest = k; /* k in mixed radix, the last key fastest */
        for (int d = b->n_keys - 1; d >= 0; d--) {
            p->value[d] = cli_range_value(&b->range[d], rest % b->range[d].n);
            rest /= b->range[d].n;
        }
        struct cli_scenario sc;
        struct cli_setup su;
        int rc = build_point(base, b, p, &sc, &su);
        cli_scenario_free(&sc);
        cli_setup_free(&su);
        if (rc != CLI_EXIT_OK) { /* (the message above is about the file with these values) */
            char at[1024];
            point_values(b, p, at, sizeof at);
            cli_error("%s: at point %zu of %zu of the values: %s", b->cmd, k + 1, b->n_pts, at);
            return rc;
        }
    }
    return CLI_EXIT_OK;
}

/* Builds and runs one point (checked by build_all) and keeps its status and CSV fields.
 * Touches only *p, so points run concurrently. */
static void run_point(const struct cli_scenario* base, const struct cli_batch* b,
                      struct cli_batch_point* p)
{
    struct cli_scenario sc;
    struct cli_setup su;
    size_t len = 0;
    p->status = WETDEM_ERR_NOMEM; /* kept when the engine could not start */
    snprintf(p->errmsg, sizeof p->errmsg, "out of memory");
    bool built = build_point(base, b, p, &sc, &su) == CLI_EXIT_OK;
    FILE* f = built ? open_memstream(&p->row, &len) : NULL;
    if (f && b->engine == CLI_ENGINE_PAIRWISE) {
        struct cli_run_options opt = {.sweep_row = f,
                                      .status_out = &p->status,
                                      .errmsg_out = p->errmsg,
                                      .errmsg_size = sizeof p->errmsg};
        cli_run_pairwise(&sc, &opt);
    } else if (f) {
        p->status = wetdem_collision_run(su.sim, &su.spec, &p->res);
        if (p->status < 0) { /* (its result is all zeros: no number of it is known) */
            snprintf(p->errmsg, sizeof p->errmsg, "%s", wetdem_sim_errmsg(su.sim));
            cli_csv_failed_row(f, &su);
        } else {
            char why[300];
            p->energy_grew = cli_energy_grew(p->res.energy_ratio, why, sizeof why);
            p->r_eff = su.r_eff;
            cli_setup_capture(&su, &p->res);
            cli_csv_result_row(f, &su, &p->res);
        }
    }
    if (f)
        fclose(f);
    cli_scenario_free(&sc);
    cli_setup_free(&su); /* the row holds all that is reported */
}

/* Saves the table of the points done so far (called under the batch's lock, which every
 * point takes when it finishes, so those marked done are complete): written as the final
 * table is, whole or not at all, with the others NOT_RUN. The next save is save_every
 * seconds later, or 50 x this write's time if longer. A failed write is reported once and
 * the batch goes on without saving. */
static void save_partial(struct cli_batch* b, double* next_save)
{
    double w0 = omp_get_wtime();
    b->wall = w0 - b->t_start;
    b->saving = true;
    int rc = cli_write_output(b->out, b->cmd, b->write_table, b->table_ctx);
    b->saving = false;
    double now = omp_get_wtime();
    if (rc != CLI_EXIT_OK) {
        cli_error("warning: %s: the table of the points done so far could not be saved (above); "
                  "the points go on running, and no more saves are tried",
                  b->cmd);
        *next_save = INFINITY;
        return;
    }
    b->n_saves++;
    *next_save = now + fmax(b->save_every, 50.0 * (now - w0));
}

static void show_progress(const char* cmd, size_t done, size_t n, double t0)
{
    double elapsed = omp_get_wtime() - t0;
    double left = done ? elapsed * (double)(n - done) / (double)done : 0;
    fprintf(stderr, "\r%s: %zu/%zu done, %.1f s elapsed, ~%.1f s left   ", cmd, done, n, elapsed,
            left);
    if (done == n)
        fputc('\n', stderr);
}

/* Runs every point in parallel (dynamic scheduling: run times differ by orders of
 * magnitude across a batch). After SIGINT or SIGTERM the points not yet started are left
 * out (b->interrupted, their status CLI_BATCH_NOT_RUN). */
static void run_all(const struct cli_scenario* base, struct cli_batch* b)
{
    bool show = b->progress && isatty(STDERR_FILENO);
    double t0 = omp_get_wtime(), last = 0;
    double next_save =
        b->save_every > 0 && b->out && b->write_table ? t0 + b->save_every : INFINITY;
    size_t done = 0, n = b->n_pts - b->n_kept; /* (progress of the points that run here) */
    char notice[200];
    snprintf(notice, sizeof notice,
             "\nwetdem: interrupted: finishing the collisions that run, then writing the table "
             "of those done (a signal %g s or more after this one, or a third: stop at once)\n",
             CLI_SIGNAL_GRACE_S);
    struct cli_saved_signals saved;
    cli_signals_install(notice,
                        "\nwetdem: stopped at once by a repeated signal, without the table\n", NULL,
                        &saved);
#pragma omp parallel for schedule(dynamic, 1)
    for (size_t k = 0; k < b->n_pts; k++) {
        if (b->pts[k].status == CLI_BATCH_KEPT || b->pts[k].status == CLI_BATCH_KEPT_FAILED)
            continue;
        if (cli_stop_signal) {
            b->pts[k].status = CLI_BATCH_NOT_RUN;
            continue;
        }
        run_point(base, b, &b->pts[k]);
#pragma omp critical(batch_progress)
        {
            b->pts[k].done = true;
            done++;
            double now = omp_get_wtime();
            if (now >= next_save && done < n && !cli_stop_signal)
                save_partial(b, &next_save);
            if (show && !cli_stop_signal && (now - last > 0.2 || done == n)) {
                show_progress(b->cmd, done, n, t0);
                last = now;
            }
        }
    }
    b->interrupted = cli_stop_signal;
    if (!b->interrupted) /* (else kept, as run keeps them: see signals.h) */
        cli_signals_restore(&saved);
}

/* The engine's column header into b->header (malloc'd). Exit code. */
static int engine_header(const struct cli_scenario* sc, struct cli_batch* b)
{
    size_t len = 0;
    FILE* f = open_memstream(&b->header, &len);
    if (!f) {
        cli_error("%s: out of memory", b->cmd);
        return CLI_EXIT_RUNTIME;
    }
    int rc = CLI_EXIT_OK;
    if (b->engine == CLI_ENGINE_PAIRWISE) {
        struct cli_run_options opt = {.sweep_row = f, .sweep_header = true};
        rc = cli_run_pairwise(sc, &opt);
    } else {
        cli_csv_result_header(f);
    }
    fclose(f);
    return rc;
}

/* Whether the scenario's engine can run here; exit code, message printed. */
static int check_engine(const struct cli_scenario* sc, struct cli_batch* b)
{
    int rc = cli_scenario_engine(sc, &b->engine);
    if (rc == CLI_EXIT_OK && b->engine == CLI_ENGINE_PAIRWISE && !cli_run_pairwise) {
        cli_error("%s %s: engine 'pairwise' is not in this build", b->cmd, b->file);
        rc = CLI_EXIT_RUNTIME;
    }
    if (rc == CLI_EXIT_OK && b->engine == CLI_ENGINE_SOFT && cli_scenario_is_many &&
        cli_scenario_is_many(sc)) { /* (a pairwise scenario's stray [box] is its own error) */
        cli_error("%s %s: a many-particle scenario runs with 'wetdem run' (one run per "
                  "file); %s",
                  b->cmd, b->file, b->many_note);
        rc = CLI_EXIT_USAGE;
    }
    return rc;
}

/* The keys as the scenario names them ("glass.p_gt" is [model.glass] p_gt): two names of one
 * key, or collision.speed and collision.stokes (a --set of one replaces the other), would give
 * rows labelled with values never used; a --set of a key varied would never be used. An exit
 * code, the message printed. */
static int check_keys(const struct cli_batch* b)
{
    static const char* const options[CLI_BATCH_MAX_KEYS] = {"--param", "--param2"};
    char full[CLI_BATCH_MAX_KEYS][2 * CLI_NAME_MAX + 2];
    for (int d = 0; d < b->n_keys; d++) {
        char section[CLI_NAME_MAX], key[CLI_NAME_MAX];
        if (cli_key_split(options[d], b->key[d], section, key) != 0 ||
            cli_check_numeric_key(b->cmd, options[d], b->key[d], section, key, "varied") !=
                CLI_EXIT_OK)
            return CLI_EXIT_USAGE;
        snprintf(full[d], sizeof full[d], "%s.%s", section, key);
    }
    for (int k = 0; k < b->n_sets; k++) { /* each point's value would replace the --set */
        char section[CLI_NAME_MAX], key[CLI_NAME_MAX], set[2 * CLI_NAME_MAX + 2];
        const char* eq = strchr(b->sets[k], '=');
        if (eq && eq > b->sets[k] && !memchr(b->sets[k], '.', (size_t)(eq - b->sets[k])))
            continue; /* a key without its section: loading the file names its section */
        if (cli_override_split(b->sets[k], section, key, NULL) != 0)
            return CLI_EXIT_USAGE;
        snprintf(set, sizeof set, "%s.%s", section, key);
        for (int d = 0; d < b->n_keys; d++) {
            int clash = cli_keys_clash(set, full[d]);
            if (!clash)
                continue;
            cli_error("%s: --set %s sets %s, which %s %s varies%s: each point's value would "
                      "replace it; leave it out",
                      b->cmd, b->sets[k], set, options[d], b->key[d],
                      clash == 2 ? CLI_IMPACT_CLASH : "");
            return CLI_EXIT_USAGE;
        }
    }
    if (b->n_keys < 2)
        return CLI_EXIT_OK;
    int clash = cli_keys_clash(full[0], full[1]);
    if (clash == 1) {
        cli_error("%s: %s %s and %s %s name the same key, %s", b->cmd, options[0], b->key[0],
                  options[1], b->key[1], full[0]);
        return CLI_EXIT_USAGE;
    }
    if (clash == 2) {
        cli_error("%s: %s %s and %s %s: the impact is given by speed or by stokes, and setting "
                  "one replaces the other, so the first would never be used",
                  b->cmd, options[0], b->key[0], options[1], b->key[1]);
        return CLI_EXIT_USAGE;
    }
    return CLI_EXIT_OK;
}

/* The unit of a scenario key for the header, "-" when it has none or is unknown. */
static const char* key_unit(const char* key)
{
    char section[CLI_NAME_MAX], name[CLI_NAME_MAX], probe[CLI_VALUE_MAX];
    snprintf(probe, sizeof probe, "%s=0", key);
    const char* u = cli_override_split(probe, section, name, NULL) == 0
                        ? cli_scenario_key_unit(section, name)
                        : "";
    return u[0] ? u : "-";
}

/* The table's column header, "KEY [unit],...,status [word],<engine columns>" (malloc'd;
 * NULL when out of memory). */
static char* table_header(const struct cli_batch* b)
{
    char* text = NULL;
    size_t len = 0;
    FILE* f = open_memstream(&text, &len);
    if (!f)
        return NULL;
    for (int d = 0; d < b->n_keys; d++)
        fprintf(f, "%s [%s],", b->key[d], key_unit(b->key[d]));
    fprintf(f, "status [word],%s", b->header);
    fclose(f);
    return text;
}

/* The first fields of point p's row, its values "v1,[v2,]" as the table prints them. */
static void row_values(const struct cli_batch* b, const struct cli_batch_point* p, char* buf,
                       size_t n)
{
    format_values(b, p, false, buf, n);
}

/* Whether a status word of a table is a failed run's: an error status or ENERGY_GREW. */
static bool failed_word(const char* word, size_t len)
{
    return (len > 10 && strncmp(word, "WETDEM_ERR", 10) == 0) ||
           (len == 11 && strncmp(word, "ENERGY_GREW", 11) == 0);
}

/* Whether a status word is one a table of a batch writes: a status name or ENERGY_GREW. */
static bool known_status(const char* word, size_t len)
{
    if (len == 11 && strncmp(word, "ENERGY_GREW", 11) == 0)
        return true;
    for (int s = -64; s <= 64; s++) {
        const char* name = wetdem_status_name(s);
        if (strcmp(name, "WETDEM_UNKNOWN") != 0 && strlen(name) == len &&
            strncmp(word, name, len) == 0)
            return true;
    }
    return false;
}

/* Why `kept`, the status word and fields of a row that ran, is not a row this batch writes
 * (into why, returned), or NULL: a known status word, then one field per column of the
 * engine's header, a word in each [word] column and a number (nan and inf as the table
 * writes them) in the others. A kept row is copied as it stands, so an edited or damaged one
 * would pass into the completed table unnoticed. */
static const char* kept_row_problem(const struct cli_batch* b, const char* kept, char* why,
                                    size_t n)
{
    size_t len = strcspn(kept, ",");
    if (!known_status(kept, len)) {
        snprintf(why, n,
                 "status '%.*s' is none a run gives (WETDEM_OK, WETDEM_ERR_..., "
                 "ENERGY_GREW, NOT_RUN)",
                 (int)(len > 40 ? 40 : len), kept);
        return why;
    }
    const char* field = kept[len] == ',' ? kept + len + 1 : NULL;
    for (const char* col = b->header; col;) {
        size_t lc = strcspn(col, ",");
        if (!field) {
            snprintf(why, n, "it ends before column '%.*s'", (int)lc, col);
            return why;
        }
        size_t lf = strcspn(field, ",");
        bool word = lc >= 6 && strncmp(col + lc - 6, "[word]", 6) == 0;
        char text[64];
        snprintf(text, sizeof text, "%.*s", (int)(lf < sizeof text ? lf : sizeof text - 1), field);
        char* end = NULL;
        if (lf == 0 || lf >= sizeof text || (!word && (strtod(text, &end), *end != '\0'))) {
            snprintf(why, n, "column '%.*s': '%.*s' is not %s", (int)lc, col,
                     (int)(lf > 40 ? 40 : lf), field, word ? "a word" : "a number");
            return why;
        }
        col = col[lc] == ',' ? col + lc + 1 : NULL;
        field = field[lf] == ',' ? field + lf + 1 : NULL;
    }
    if (field) {
        snprintf(why, n, "it has more fields than the %s has columns", b->cmd);
        return why;
    }
    return NULL;
}

/* Row r (line `line` of the file) of the table of --resume, text without its newline: kept
 * into point r unless NOT_RUN. An exit code, the message printed. */
static int resume_row(struct cli_batch* b, size_t r, const char* text, size_t line)
{
    struct cli_batch_point* p = &b->pts[r];
    char want[128];
    row_values(b, p, want, sizeof want);
    size_t lw = strlen(want);
    if (strncmp(text, want, lw) != 0) {
        char at[1024];
        point_values(b, p, at, sizeof at);
        cli_error("%s: --resume %s:%zu: the row '%.60s' is not of point %zu of this %s (%s): "
                  "resume with the --values and --set of the run that wrote the table",
                  b->cmd, b->resume, line, text, r + 1, b->cmd, at);
        return CLI_EXIT_USAGE;
    }
    const char* status = text + lw;
    size_t ls = strcspn(status, ",");
    if (ls == 7 && strncmp(status, "NOT_RUN", 7) == 0)
        return CLI_EXIT_OK;
    char why[256];
    if (kept_row_problem(b, status, why, sizeof why)) {
        cli_error("%s: --resume %s:%zu: the row of point %zu is not one this %s writes: %s "
                  "(run the point again: write NOT_RUN in its status column)",
                  b->cmd, b->resume, line, r + 1, b->cmd, why);
        return CLI_EXIT_USAGE;
    }
    if (!(p->row = strdup(status))) {
        cli_error("%s: out of memory", b->cmd);
        return CLI_EXIT_RUNTIME;
    }
    p->status = failed_word(status, ls) ? CLI_BATCH_KEPT_FAILED : CLI_BATCH_KEPT;
    p->done = true;
    b->n_kept++;
    return CLI_EXIT_OK;
}

int cli_batch_parse_save_every(const char* cmd, const char* text, double* out)
{
    double v;
    const char* problem = cli_number(text, &v) == 0 ? NULL : cli_number_problem(text);
    if (problem || !(v >= 0.0 && v <= 1e9)) {
        cli_error("%s: --save-every '%s': %s; it is the time between saves of the table while "
                  "the points run, seconds in [0, 1e9] (0: never)",
                  cmd, text, problem ? problem : "out of range");
        return CLI_EXIT_USAGE;
    }
    *out = v;
    return CLI_EXIT_OK;
}

/* FNV-1a (64 bits) of n bytes, continuing from h. */
static unsigned long long fnv1a(unsigned long long h, const void* data, size_t n)
{
    const unsigned char* p = data;
    for (size_t k = 0; k < n; k++)
        h = (h ^ p[k]) * 0x100000001b3ULL;
    return h;
}

/* The hash of what the points' results depend on besides their values: the scenario file's
 * bytes and the --set overrides, in order. 0 when the file cannot be read (then loading it
 * failed first). */
static unsigned long long scenario_hash(const struct cli_batch* b)
{
    FILE* f = fopen(b->file, "rb");
    if (!f)
        return 0;
    unsigned long long h = 0xcbf29ce484222325ULL;
    char buf[4096];
    for (size_t n; (n = fread(buf, 1, sizeof buf, f)) > 0;)
        h = fnv1a(h, buf, n);
    fclose(f);
    for (int k = 0; k < b->n_sets; k++) {
        h = fnv1a(h, "\n--set ", 7);
        h = fnv1a(h, b->sets[k], strlen(b->sets[k]));
    }
    return h;
}

#define HASH_LINE "# scenario hash: "

/* Reads the table of b->resume, a table of this batch that an interruption left with rows
 * NOT_RUN: its column header and the values of every row must be this batch's; the rows that
 * ran are kept (verbatim: status word and fields), the others will run. '#' lines are passed
 * over; a NUL byte anywhere is refused (a text cut there would pass for a shorter line, a row
 * ending in one for a whole row). An exit code, the message printed (with the file and line
 * that differs). */
static int read_resume(struct cli_batch* b)
{
    FILE* f = fopen(b->resume, "r");
    if (!f) {
        cli_error("%s: --resume %s: cannot read it: %s", b->cmd, b->resume, strerror(errno));
        return CLI_EXIT_USAGE;
    }
    char* header = table_header(b);
    char* text = NULL;
    size_t cap = 0, line = 0, rows = 0;
    int rc = header ? CLI_EXIT_OK : CLI_EXIT_RUNTIME;
    if (!header)
        cli_error("%s: out of memory", b->cmd);
    bool seen_header = false;
    for (ssize_t len; rc == CLI_EXIT_OK && (len = getline(&text, &cap, f)) >= 0;) {
        line++;
        if (memchr(text, '\0', (size_t)len)) { /* (the string functions would stop there) */
            cli_error("%s: --resume %s:%zu: a NUL byte in the line: not a text (CSV) file", b->cmd,
                      b->resume, line);
            rc = CLI_EXIT_USAGE;
            break;
        }
        while (len > 0 && (text[len - 1] == '\n' || text[len - 1] == '\r'))
            text[--len] = '\0';
        if (line == 1 && strncmp(text, "\xEF\xBB\xBF", 3) == 0) /* a UTF-8 byte-order mark */
            memmove(text, text + 3, (size_t)(len -= 3) + 1);
        unsigned long long was;
        if (strncmp(text, HASH_LINE, strlen(HASH_LINE)) == 0 &&
            sscanf(text + strlen(HASH_LINE), "%llx", &was) == 1 && was != b->scenario_hash) {
            cli_error("%s: --resume %s:%zu: the table was written from another version of %s or "
                      "with other --set overrides (scenario hash %016llx, now %016llx): its rows "
                      "would not be those of this %s",
                      b->cmd, b->resume, line, b->file, was, b->scenario_hash, b->cmd);
            rc = CLI_EXIT_USAGE;
        }
        if (len == 0 || text[0] == '#')
            continue;
        if (!seen_header) {
            seen_header = true;
            if (strcmp(text, header) != 0) {
                cli_error("%s: --resume %s:%zu: its columns are not those of this %s (another "
                          "key, scenario or engine): '%.80s'",
                          b->cmd, b->resume, line, b->cmd, text);
                rc = CLI_EXIT_USAGE;
            }
        } else if (rows == b->n_pts) {
            cli_error("%s: --resume %s:%zu: more rows than the %zu points of this %s", b->cmd,
                      b->resume, line, b->n_pts, b->cmd);
            rc = CLI_EXIT_USAGE;
        } else {
            rc = resume_row(b, rows++, text, line);
        }
    }
    if (rc == CLI_EXIT_OK && ferror(f)) { /* (a directory: EISDIR) */
        cli_error("%s: --resume %s: cannot read it: %s", b->cmd, b->resume, strerror(errno));
        rc = CLI_EXIT_USAGE;
    }
    if (rc == CLI_EXIT_OK && rows != b->n_pts) {
        cli_error("%s: --resume %s: %zu rows, where this %s has %zu points (a table cut short "
                  "is not one an interruption writes)",
                  b->cmd, b->resume, rows, b->cmd, b->n_pts);
        rc = CLI_EXIT_USAGE;
    }
    free(text);
    free(header);
    fclose(f);
    return rc;
}

/* Above this estimate of the memory the points hold [bytes], a note says how much. */
#define NOTE_BYTES 1e9

/* The machine's physical memory [bytes] (sysconf), or the test hook WETDEM_TEST_MEMORY
 * (bytes), which stands in for it so that a test can exceed it with few points; 0: unknown. */
static double physical_memory(void)
{
    const char* hook = getenv("WETDEM_TEST_MEMORY");
    if (hook && hook[0])
        return strtod(hook, NULL);
    long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGESIZE);
    return pages > 0 && size > 0 ? (double)pages * (double)size : 0.0;
}

/* Before the points are allocated: the memory they hold until the table is written, each
 * its struct and its CSV row (the status and the header's engine columns at 16 bytes a field,
 * "0.123456789012," of %.12g, and 16 of the allocator's; a sweep of dry collisions measured
 * 0.83 kB a point, this estimate 1.22), against the machine's memory: a batch that cannot fit
 * is refused (exit 2) rather than swapping or killed by the system after its points were
 * built; above NOTE_BYTES a note says what it takes. */
static int check_memory(const struct cli_batch* b)
{
    size_t columns = 2; /* (the status, and the first engine column) */
    for (const char* c = b->header; (c = strchr(c, ',')); c++)
        columns++;
    double per_point = (double)sizeof *b->pts + 16.0 + 16.0 * (double)columns;
    double need = (double)b->n_pts * per_point, have = physical_memory();
    if (have > 0 && need > have) {
        cli_error("%s: %zu points need about %.3g GB of memory for their results (%.3g kB a "
                  "point: values, result and CSV row), more than this machine has, %.3g GB: run "
                  "fewer points, or the range in parts",
                  b->cmd, b->n_pts, need / 1e9, per_point / 1e3, have / 1e9);
        return CLI_EXIT_USAGE;
    }
    if (need > NOTE_BYTES)
        cli_error("%s: note: %zu points hold about %.3g GB of memory until the table is written "
                  "(%.3g kB a point; the machine has %.3g GB)",
                  b->cmd, b->n_pts, need / 1e9, per_point / 1e3, have / 1e9);
    return CLI_EXIT_OK;
}

int cli_batch_run(struct cli_batch* b)
{
    b->engine = CLI_ENGINE_SOFT;
    b->header = NULL;
    b->pts = NULL;
    b->n_pts = 1;
    b->wall = 0;
    b->interrupted = 0;
    b->n_kept = 0;
    b->saving = false;
    b->n_saves = 0;
    b->t_start = omp_get_wtime();
    for (int d = 0; d < b->n_keys; d++)
        b->n_pts *= b->range[d].n;
    struct cli_scenario sc;
    memset(&sc, 0, sizeof sc);
    int rc = check_keys(b);
    if (rc == CLI_EXIT_OK)
        rc = cli_load_with_overrides(b->file, b->sets, b->n_sets, &sc);
    b->scenario_hash = rc == CLI_EXIT_OK ? scenario_hash(b) : 0;
    if (rc == CLI_EXIT_OK)
        rc = check_engine(&sc, b);
    if (rc == CLI_EXIT_OK)
        rc = engine_header(&sc, b);
    if (rc == CLI_EXIT_OK)
        rc = check_memory(b);
    if (rc == CLI_EXIT_OK && !(b->pts = calloc(b->n_pts, sizeof *b->pts))) {
        cli_error("%s: out of memory for %zu points", b->cmd, b->n_pts);
        rc = CLI_EXIT_RUNTIME;
    }
    if (rc == CLI_EXIT_OK)
        rc = build_all(&sc, b);
    if (rc == CLI_EXIT_OK && b->resume)
        rc = read_resume(b);
    if (rc == CLI_EXIT_OK) /* (after the input checks, which write nothing; before the runs) */
        rc = cli_check_writable(b->cmd, "--out", b->out);
    if (rc == CLI_EXIT_OK) {
        run_all(&sc, b);
        b->wall = omp_get_wtime() - b->t_start;
    }
    cli_scenario_free(&sc);
    return rc;
}

/* The status word of a point: the engine's status, ENERGY_GREW for a run that succeeded with
 * more kinetic energy at the end than at the start (its numbers are those of an integration
 * too coarse for the contact), NOT_RUN for a point an interruption left out. */
static const char* point_status(const struct cli_batch_point* p)
{
    if (p->status == CLI_BATCH_NOT_RUN)
        return "NOT_RUN";
    if (p->status >= 0 && p->energy_grew)
        return "ENERGY_GREW";
    return wetdem_status_name(p->status);
}

/* The fields of a point that did not run: "none" for the header's words, "nan" otherwise. */
static void not_run_fields(FILE* f, const char* header)
{
    for (const char* col = header; col;) {
        const char* end = strchr(col, ',');
        size_t len = end ? (size_t)(end - col) : strlen(col);
        bool word = len >= 6 && strncmp(col + len - 6, "[word]", 6) == 0;
        fprintf(f, "%s%s", col == header ? "" : ",", word ? "none" : "nan");
        col = end ? end + 1 : NULL;
    }
}

size_t cli_batch_points_run(const struct cli_batch* b)
{
    size_t n = 0;
    for (size_t k = 0; k < b->n_pts; k++)
        n += b->pts[k].done;
    return n;
}

void cli_batch_write_table(FILE* f, const struct cli_batch* b, int argc, char** argv)
{
    cli_print_provenance(f, argc, argv);
    fprintf(f, HASH_LINE "%016llx (the scenario file's bytes and the --set overrides)\n",
            b->scenario_hash);
    char* header = table_header(b);
    fprintf(f, "%s\n", header ? header : "");
    free(header);
    for (size_t k = 0; k < b->n_pts; k++) {
        const struct cli_batch_point* p = &b->pts[k];
        char values[128];
        row_values(b, p, values, sizeof values);
        fputs(values, f);
        if (!p->done) { /* (left out by an interruption, or still to run) */
            fputs("NOT_RUN,", f);
            not_run_fields(f, b->header);
        } else {
            if (p->status != CLI_BATCH_KEPT && p->status != CLI_BATCH_KEPT_FAILED)
                fprintf(f, "%s,", point_status(p));
            fputs(p->row ? p->row : "", f);
        }
        fputc('\n', f);
    }
    if (b->n_kept)
        fprintf(f, "# resumed: %zu points kept from %s, %zu run now\n", b->n_kept, b->resume,
                cli_batch_points_run(b) - b->n_kept);
    if (b->interrupted)
        fprintf(f, "# interrupted by signal %d: %zu of %zu points ran (status %s: not run)\n",
                b->interrupted, cli_batch_points_run(b), b->n_pts, "NOT_RUN");
    if (b->saving)
        fprintf(f,
                "# saved while running: %zu of %zu points done after %.1f s (status NOT_RUN: "
                "not run yet; if the run is lost, the same command with --resume and this "
                "table runs the rest)\n",
                cli_batch_points_run(b), b->n_pts, b->wall);
}

/* What the points of a soft-engine batch are told about in one line (information): the
 * result column that shows it, what it is, whether a point has it (then why, into msg) and
 * how much (the worst point is named). */
struct point_notice {
    const char *column, *what;
    bool (*has)(const struct cli_batch_point* p, char* msg, size_t n);
    double (*size)(const struct cli_batch_point* p);
};

static bool hmin_unresolved(const struct cli_batch_point* p, char* msg, size_t n)
{
    return cli_hmin_unresolved(&p->res, msg, n);
}

static double hmin_ratio(const struct cli_batch_point* p)
{
    return p->res.stats.hmin_step_ratio;
}

static bool overlap_large(const struct cli_batch_point* p, char* msg, size_t n)
{
    return cli_overlap_large(&p->res, p->r_eff, msg, n);
}

static double overlap_ratio(const struct cli_batch_point* p)
{
    return -p->res.min_gap / p->r_eff;
}

/* One line for the points that ran and have notice c, with the worst and why. */
static void report_notice(const struct cli_batch* b, const struct point_notice* c)
{
    size_t n = 0, worst = 0;
    char why[600];
    for (size_t k = 0; b->engine == CLI_ENGINE_SOFT && k < b->n_pts; k++) {
        const struct cli_batch_point* p = &b->pts[k];
        if (p->status < 0 || p->status >= CLI_BATCH_NOT_RUN || !c->has(p, why, sizeof why))
            continue;
        if (n++ == 0 || c->size(p) > c->size(&b->pts[worst]))
            worst = k;
    }
    if (n == 0)
        return;
    char where[1100];
    point_values(b, &b->pts[worst], where, sizeof where);
    c->has(&b->pts[worst], why, sizeof why);
    cli_error("warning: %s: in %zu of %zu collisions (column %s) %s; the worst, at %s: %s", b->cmd,
              n, b->n_pts, c->column, c->what, where, why);
}

int cli_batch_report_failures(const struct cli_batch* b, int rc)
{
    static const struct point_notice notices[] = {
        {"hmin_step_ratio", "the step does not resolve h_min", hmin_unresolved, hmin_ratio},
        {"min_gap", "the spheres overlap beyond what the contact laws hold for", overlap_large,
         overlap_ratio},
    };
    for (size_t k = 0; k < sizeof notices / sizeof notices[0]; k++)
        report_notice(b, &notices[k]);
    if (b->interrupted)
        cli_error("%s: interrupted by signal %d: %zu of %zu points ran; the table has every "
                  "point, those left out with status NOT_RUN",
                  b->cmd, b->interrupted, cli_batch_points_run(b), b->n_pts);
    bool failed = false;
    size_t kept_failed = 0;
    for (size_t k = 0; k < b->n_pts; k++) {
        const struct cli_batch_point* p = &b->pts[k];
        char where[1100];
        size_t used = (size_t)snprintf(where, sizeof where, "%s: ", b->cmd);
        point_values(b, p, where + used, sizeof where - used);
        char why[300];
        kept_failed += p->status == CLI_BATCH_KEPT_FAILED;
        if (p->status >= CLI_BATCH_NOT_RUN) /* (not run, or kept: its message is not kept) */
            continue;
        if (p->status >= 0) { /* (a pairwise point's result is zero: no energy ratio) */
            if (p->energy_grew && cli_energy_grew(p->res.energy_ratio, why, sizeof why)) {
                cli_error("%s: the collision %s (status ENERGY_GREW)", where, why);
                failed = true;
            }
            continue;
        }
        cli_error("%s: %s (%s)", where, p->errmsg, wetdem_status_name(p->status));
        failed = true;
    }
    if (kept_failed) {
        cli_error("%s: %zu of the points kept from %s had failed there (their status column); "
                  "run them again without --resume for the messages",
                  b->cmd, kept_failed, b->resume);
        failed = true;
    }
    /* a table not written first, then the interruption (as a program stopped by the signal,
       but with the table), then failed points */
    if (rc != CLI_EXIT_OK)
        return rc;
    if (b->interrupted)
        return 128 + b->interrupted;
    return failed ? CLI_EXIT_RUNTIME : CLI_EXIT_OK;
}

void cli_batch_free(struct cli_batch* b)
{
    for (size_t k = 0; b->pts && k < b->n_pts; k++)
        free(b->pts[k].row);
    free(b->pts);
    free(b->header);
    b->pts = NULL;
    b->header = NULL;
}

/*
 * run_many.c — `wetdem run FILE [--out DIR] [--restart CHECKPOINT]` for many-particle
 * scenarios (cli/scenario_many.c; docs/many.md "From the command line").
 *
 * Order of work, so that bad input never leaves files behind: the scenario is built and the
 * run is started once without outputs (time step, neighbour lists, periodic-box checks,
 * the reach bound: every library check of the set-up), then the mode is set again with the
 * outputs, the --out directory is created and the run starts afresh or from the checkpoint.
 *
 * Outputs in DIR: PREFIX_NNNNNN.vtk frames every vtk_every steps (and the last step) with the
 * ParaView index PREFIX.vtk.series, the library's CSV of global quantities every csv_every
 * steps (and a row of the last step, added here), the checkpoint (atomic; every
 * checkpoint_every steps, on SIGINT/SIGTERM and at the end) and summary.json with the energy
 * budget. The VTK frames are written here, between integrate calls that each end at a frame
 * (run_steps), rather than by the library, so that the frame numbering and the series index
 * continue across restarts; between frames nothing reads the state, so the library lets each
 * force pass begin the next step (the settling example 1.06x faster on one and two threads,
 * 1.44x on two with OMP_WAIT_POLICY=passive: docs/performance.md; before, the frames were
 * written from a progress callback called at every step, which made the library write the
 * state back at every step). On --restart the existing index
 * is read back and the entries after the checkpoint time are dropped, as are CSV rows after
 * the checkpoint step (a run resumed from an older periodic checkpoint then rewrites them
 * identically), and the last frame and row of the run that wrote the checkpoint when they lie
 * off the output grid. A fresh run first removes the frames an earlier run left in DIR. Before
 * either, a directory (or a FIFO) under the name of an output is refused (outputs_usable).
 *
 * Interruption: the first SIGINT or SIGTERM sets a volatile flag that the library reads every
 * step as its stop flag; it writes the checkpoint and returns, and the run exits with 128 +
 * signal number (130, 143) after printing the command that resumes it. A repeat within
 * CLI_SIGNAL_GRACE_S of the first is the same request delivered twice (signals.c; GNU timeout signals the
 * process and then its process group; a terminal's Ctrl-C reaches the whole foreground group)
 * and is ignored, so it cannot lose the checkpoint being written. A second signal after the
 * grace period, or a third, stops the run at once by that signal, without a new checkpoint;
 * the previous one is intact (written atomically) and the partial temporary file is removed.
 *
 * Progress with an estimate of the time left goes to stderr, only when stderr is a terminal,
 * at most twice a second, from a progress callback every PROGRESS_EVERY steps or fewer.
 */
#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <omp.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli_util.h"
#include "output_csv.h"
#include "scenario_many.h"
#include "signals.h"

#define PATH_CHARS 2048

/* ------------------------------------------------------------------- VTK time series --- */

struct series {
    char dir[PATH_CHARS], prefix[CLI_VALUE_MAX];
    bool binary;
    bool links;        /* each frame also as PREFIX_links_NNNNNN.vtk, indexed by PREFIX_links */
    size_t links_from; /* the first frame with links (after a restart of a run without) */
    double* times;     /* time of frame k [s] */
    size_t n, cap;
    unsigned long long last_step; /* step of the latest frame (valid when n > 0) */
    /* why series_add failed (the checkpoint written on the stop that follows may replace the
       library's message) */
    char error[PATH_CHARS + CLI_VALUE_MAX + 200];
};

/* The name of frame k: PREFIX_NNNNNN.vtk, or of its links, PREFIX_links_NNNNNN.vtk. */
static void frame_name(const struct series* s, size_t k, bool links, char* buf, size_t n)
{
    snprintf(buf, n, "%s%s_%06zu.vtk", s->prefix, links ? WETDEM_LINKS_SUFFIX : "", k);
}

/* The summary, the global CSV and the checkpoint, in this order (outputs_clear removes the
 * summary first), as output_what names them. */
static const char* const output_files[3] = {"the summary", "the CSV", "the checkpoint"};

/* Which of the run's outputs the file `name` in --out is, or NULL: a frame or links frame of
 * s (NULL: none) or one of their indexes (series_clear), or names[k] (NULL: none), which is
 * output_files[k]. */
static const char* output_what(const char* name, const struct series* s, const char* const names[3])
{
    char links_prefix[CLI_VALUE_MAX + 8], links_index[CLI_VALUE_MAX + 24];
    char index[CLI_VALUE_MAX + 16];
    if (s) {
        snprintf(links_prefix, sizeof links_prefix, "%s" WETDEM_LINKS_SUFFIX, s->prefix);
        snprintf(links_index, sizeof links_index, "%s.vtk.series", links_prefix);
        snprintf(index, sizeof index, "%s.vtk.series", s->prefix);
        if (cli_is_frame_name(s->prefix, name))
            return "a VTK frame";
        if (cli_is_frame_name(links_prefix, name))
            return "a frame of the links";
        if (strcmp(name, index) == 0)
            return "the frames' index";
        if (strcmp(name, links_index) == 0)
            return "the links' index";
    }
    for (int k = 0; k < 3; k++)
        if (names[k] && strcmp(name, names[k]) == 0)
            return output_files[k];
    return NULL;
}

/* A fresh run replaces the run in its directory: removes the frames and links an earlier run
 * left there (the files output_what names as this series's frames and links, and no other
 * file), which the new index would not list and a shorter run would not overwrite; and both
 * indexes, which a run without links, or without frames, would leave behind describing the
 * earlier run. 0, or -1 with errno set. */
static int series_clear(const struct series* s)
{
    DIR* d = opendir(s->dir);
    if (!d)
        return -1;
    static const char* const none[3] = {NULL, NULL, NULL};
    int rc = 0;
    for (struct dirent* e = readdir(d); e && rc == 0; e = readdir(d)) {
        char path[PATH_CHARS + 300];
        snprintf(path, sizeof path, "%s/%s", s->dir, e->d_name);
        if (output_what(e->d_name, s, none) && unlink(path) != 0 && errno != ENOENT)
            rc = -1;
    }
    int err = errno;
    closedir(d);
    errno = err;
    return rc;
}

/* The names in --out of the summary, global CSV and checkpoint (output_files) that a fresh
 * run replaces: this run's names or, for an output it does not write, the default names. */
static void earlier_names(const struct cli_many_setup* su, const char* names[3])
{
    names[0] = su->summary_name[0] ? su->summary_name : "summary.json";
    names[1] = su->csv_name[0] ? su->csv_name : "global.csv";
    names[2] = su->checkpoint_name[0] ? su->checkpoint_name : "checkpoint.ckpt";
}

/* A fresh run replaces the run in its directory (as series_clear its frames): removes the
 * summary, global CSV and checkpoint an earlier run left there (earlier_names); the summary
 * first, so a run that fails or is killed before its end leaves no summary beside its files
 * that describes the earlier run. 0, or -1 with errno set. */
static int outputs_clear(const char* dir, const struct cli_many_setup* su)
{
    const char* names[3];
    earlier_names(su, names);
    for (size_t k = 0; k < 3; k++) {
        char path[PATH_CHARS + CLI_VALUE_MAX];
        snprintf(path, sizeof path, "%s/%s", dir, names[k]);
        if (unlink(path) != 0 && errno != ENOENT)
            return -1;
    }
    return 0;
}

/* Refuses an --out DIR that holds, under the name of one of the run's outputs (output_what,
 * with the frames s and the files `names`) or of its temporary NAME.tmp (every output is
 * written under it and renamed), a directory or a file that is not a regular one or a link
 * (a FIFO, a device): a fresh run failed to remove it, or the run to write there, after the
 * earlier run's frames and outputs were gone (or, resumed, after it had trimmed the CSV). The
 * message names the path. CLI exit code; nothing is touched. */
static int outputs_usable(const char* dir, const struct series* s, const char* const names[3])
{
    DIR* d = opendir(dir);
    if (!d) /* (none yet, which the run creates: a file there is refused with --out) */
        return CLI_EXIT_OK;
    int rc = CLI_EXIT_OK;
    for (struct dirent* e = readdir(d); e && rc == CLI_EXIT_OK; e = readdir(d)) {
        char name[sizeof e->d_name];
        snprintf(name, sizeof name, "%s", e->d_name);
        size_t n = strlen(name);
        const char* what = output_what(name, s, names);
        bool tmp = !what && n > 4 && strcmp(name + n - 4, ".tmp") == 0;
        if (tmp) {
            name[n - 4] = '\0';
            what = output_what(name, s, names);
        }
        char path[PATH_CHARS + 300];
        snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
        struct stat st;
        if (!what || lstat(path, &st) != 0 || S_ISREG(st.st_mode) || S_ISLNK(st.st_mode))
            continue;
        cli_error("run: %s is %s, named as %s%s, which the run replaces: move it elsewhere, or "
                  "give another --out (nothing was changed)",
                  path, S_ISDIR(st.st_mode) ? "a directory" : "not a regular file",
                  tmp ? "the temporary file of " : "", what);
        rc = CLI_EXIT_USAGE;
    }
    closedir(d);
    return rc;
}

/* Writes the .vtk.series index of the frames (links: of their links; temporary file, then
 * rename). 0, or -1 with errno set. */
static int series_write_one(const struct series* s, bool links)
{
    char path[PATH_CHARS + CLI_VALUE_MAX + 40], tmp[sizeof path + 8];
    snprintf(path, sizeof path, "%s/%s%s.vtk.series", s->dir, s->prefix,
             links ? WETDEM_LINKS_SUFFIX : "");
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    FILE* f = fopen(tmp, "w");
    if (!f)
        return -1;
    fputs("{\n  \"file-series-version\" : \"1.0\",\n  \"files\" : [\n", f);
    for (size_t k = links ? s->links_from : 0; k < s->n; k++) {
        char name[CLI_VALUE_MAX + 40];
        frame_name(s, k, links, name, sizeof name);
        fprintf(f, "    { \"name\" : \"%s\", \"time\" : %.17g }%s\n", name, s->times[k],
                k + 1 < s->n ? "," : "");
    }
    fputs("  ]\n}\n", f);
    bool ok = !ferror(f);
    ok = fclose(f) == 0 && ok;
    if (ok && rename(tmp, path) == 0)
        return 0;
    int err = errno ? errno : EIO;
    remove(tmp);
    errno = err;
    return -1;
}

/* Writes the index of the frames and, with links, that of their links. 0 or -1. */
static int series_write(const struct series* s)
{
    return series_write_one(s, false) == 0 && (!s->links || series_write_one(s, true) == 0) ? 0
                                                                                            : -1;
}

/* Appends a frame time to the index. 0 or -1 (out of memory). */
static int push_time(struct series* s, double time)
{
    if (s->n == s->cap) {
        size_t cap = s->cap ? 2 * s->cap : 64;
        double* t = realloc(s->times, cap * sizeof *t);
        if (!t)
            return -1;
        s->times = t;
        s->cap = cap;
    }
    s->times[s->n++] = time;
    return 0;
}

/* Removes frame k and its links after series_add failed to add it to the index: a frame on
 * disk that the index does not list makes a restart refuse the directory (series_resume). */
static void series_drop(const struct series* s, size_t k)
{
    char path[PATH_CHARS + CLI_VALUE_MAX + 40], name[CLI_VALUE_MAX + 40];
    for (int links = 0; links < 2; links++) {
        frame_name(s, k, links, name, sizeof name);
        snprintf(path, sizeof path, "%s/%s", s->dir, name);
        remove(path);
    }
}

/* Writes frame n at the current state and appends it to the index. WETDEM status; on failure
 * s->error says why, and a frame that could not be indexed is not left on disk. */
static int series_add(struct series* s, struct wetdem_sim* sim, unsigned long long step)
{
    char path[PATH_CHARS + CLI_VALUE_MAX + 40], name[CLI_VALUE_MAX + 40];
    frame_name(s, s->n, false, name, sizeof name);
    snprintf(path, sizeof path, "%s/%s", s->dir, name);
    int st = wetdem_sim_write_vtk(sim, path, s->binary);
    if (st == WETDEM_OK && s->links) {
        frame_name(s, s->n, true, name, sizeof name);
        snprintf(path, sizeof path, "%s/%s", s->dir, name);
        st = wetdem_sim_write_vtk_links(sim, path, s->binary);
    }
    if (st != WETDEM_OK) {
        snprintf(s->error, sizeof s->error, "%s", wetdem_sim_errmsg(sim));
        series_drop(s, s->n);
        return st;
    }
    if (push_time(s, wetdem_sim_time(sim)) != 0) {
        snprintf(s->error, sizeof s->error, "out of memory for the frames' index");
        series_drop(s, s->n);
        return WETDEM_ERR_NOMEM;
    }
    s->last_step = step;
    if (series_write(s) == 0)
        return WETDEM_OK;
    snprintf(s->error, sizeof s->error, "cannot write %s/%s.vtk.series: %s", s->dir, s->prefix,
             strerror(errno));
    return WETDEM_ERR_IO;
}

/* The step of frame k, from its time on the grid t = k dt, given the time t at step `step`. */
static unsigned long long frame_step(const struct series* s, size_t k, double t,
                                     unsigned long long step, double dt)
{
    return step - (unsigned long long)llround((t - s->times[k]) / dt);
}

/* Whether `time`, of a row or frame at `row` steps (or, row NULL, at some step), lies on the
 * time grid t0 + k dt of the checkpoint (at step `step`, time t) to within `rel` of it: the
 * outputs of another run (another scenario's step, given --out by mistake) do not. */
static bool on_time_grid(double time, const unsigned long long* row, double t,
                         unsigned long long step, double dt, double rel)
{
    double t0 = t - (double)step * dt;
    if (row) {
        double want = t0 + (double)*row * dt;
        return fabs(time - want) <= rel * fabs(want) + 1e-3 * dt;
    }
    double k = (time - t0) / dt;
    return fabs(k - nearbyint(k)) <= 1e-6 + rel * fabs(k);
}

/* On a restart with links: a links frame of the kept frames (number below s->n) that the
 * links index lists must still be there, as series_resume requires of the frames; one deleted
 * since would be dropped from the resumed run's links index without a word (the links start
 * after the last missing file), and the earlier ones still on disk with it. 0, or -1 after
 * the message. (A links index left by a run resumed without links lists frames that all
 * exist: the links then start again at the restart.) */
static int links_listed_missing(const struct series* s)
{
    char index[PATH_CHARS + CLI_VALUE_MAX + 48], prefix[CLI_VALUE_MAX + 8];
    snprintf(prefix, sizeof prefix, "%s" WETDEM_LINKS_SUFFIX, s->prefix);
    snprintf(index, sizeof index, "%s/%s.vtk.series", s->dir, prefix);
    FILE* f = fopen(index, "r");
    char line[1024];
    int missing = 0;
    while (f && !missing && fgets(line, sizeof line, f)) {
        char name[CLI_VALUE_MAX + 40], frame[PATH_CHARS + CLI_VALUE_MAX + 48];
        double time;
        if (wetdem_output_vtk_series_entry(line, name, sizeof name, &time) != WETDEM_OK ||
            !cli_is_frame_name(prefix, name))
            continue;
        unsigned long long k = strtoull(name + strlen(prefix) + 1, NULL, 10);
        snprintf(frame, sizeof frame, "%s/%s", s->dir, name);
        if (k < s->n && access(frame, F_OK) != 0) {
            cli_error("--restart: %s lists %s at t = %.9g s, but %s is missing: the resumed "
                      "run's links index would leave out the links before it; restore the "
                      "file, or start the run afresh without --restart",
                      index, name, time, frame);
            missing = -1;
        }
    }
    if (f)
        fclose(f);
    return missing;
}

/* On restart: the frames of the existing index up to time t, the checkpoint's (entries in
 * order, named as this run names them); the rest are dropped and will be written again. A
 * frame at t itself is kept only on the grid of `every`, the vtk_every of the run that wrote
 * the checkpoint (struct writer): off it, it is the last frame that run added at its end,
 * which the uninterrupted run does not have (the resumed run writes a frame there when t is
 * on its own grid). Frames on disk beyond those the index lists, at t or after it (the time
 * of their title, wetdem_output_vtk_frame_time), were written from the checkpoint on by a
 * run killed before it listed them (between a frame and its index, the frame of a periodic
 * checkpoint's step included, or while a resume from an older checkpoint wrote its frames
 * again over a longer series): they are dropped as the listed ones after t are. One before
 * t, or one whose time cannot be read, means the index is missing or cut short: numbering
 * from its end would overwrite frames the resumed run does not write again, so the restart
 * is refused (CLI exit code; nothing is touched); so is an entry up to t off the
 * checkpoint's time grid: another run's frames, and a frame the index keeps that is missing
 * (deleted since). */
static int series_resume(struct series* s, double t, unsigned long long step, double dt,
                         unsigned long long every)
{
    char path[PATH_CHARS + CLI_VALUE_MAX + 40];
    snprintf(path, sizeof path, "%s/%s.vtk.series", s->dir, s->prefix);
    FILE* f = fopen(path, "r");
    char line[1024];
    size_t listed = 0; /* entries in order, named as this run names them */
    bool later = false;
    while (f && fgets(line, sizeof line, f)) {
        char name[CLI_VALUE_MAX + 40], want[CLI_VALUE_MAX + 40];
        double time;
        if (wetdem_output_vtk_series_entry(line, name, sizeof name, &time) != WETDEM_OK)
            continue;
        frame_name(s, listed, false, want, sizeof want);
        if (strcmp(name, want) != 0)
            break;
        listed++;
        later = later || !(time <= t);
        if (!later && !on_time_grid(time, NULL, t, step, dt, 1e-12)) {
            fclose(f);
            cli_error("--restart: %s lists %s at t = %.17g s, off the time grid of the "
                      "checkpoint (dt = %.9g s, step %llu at t = %.9g s): the directory holds "
                      "the outputs of another run; give --out the directory of the run that "
                      "wrote the checkpoint",
                      path, name, time, dt, step, t);
            return CLI_EXIT_USAGE;
        }
        if (!later && push_time(s, time) != 0) {
            fclose(f);
            cli_error("--restart: out of memory reading %s", path);
            return CLI_EXIT_RUNTIME;
        }
    }
    bool indexed = f != NULL;
    if (f)
        fclose(f);
    char name[CLI_VALUE_MAX + 40], frame[sizeof path];
    double later_time = 0;
    for (;; listed++) { /* (frames a killed run wrote past the checkpoint, not yet listed) */
        frame_name(s, listed, false, name, sizeof name);
        snprintf(frame, sizeof frame, "%s/%s", s->dir, name);
        if (!(indexed && access(frame, F_OK) == 0 &&
              wetdem_output_vtk_frame_time(frame, &later_time) == WETDEM_OK && later_time >= t))
            break;
    }
    if (access(frame, F_OK) == 0) {
        cli_error("--restart: %s %s, but %s exists: the resumed run would number its frames "
                  "from %zu and overwrite frames it does not write again; restore the index, "
                  "or move the frames from %s on elsewhere",
                  path, indexed ? "lists fewer frames than the directory holds" : "is missing",
                  frame, listed, name);
        return CLI_EXIT_USAGE;
    }
    if (s->n && frame_step(s, s->n - 1, t, step, dt) == step && !(every && step % every == 0))
        s->n--;
    /* the frames kept stay listed: one deleted since the run that wrote them would leave the
       resumed run's index naming a file that is not there */
    for (size_t k = 0; k < s->n; k++) {
        frame_name(s, k, false, name, sizeof name);
        snprintf(frame, sizeof frame, "%s/%s", s->dir, name);
        if (access(frame, F_OK) != 0) {
            cli_error("--restart: %s lists %s at t = %.9g s, but %s is missing: the resumed run "
                      "would keep it in its index, naming a file that is not there; restore "
                      "the frame, or start the run afresh without --restart",
                      path, name, s->times[k], frame);
            return CLI_EXIT_USAGE;
        }
    }
    /* the links index lists the frames from the first after which each has its links file:
       a run written without links, resumed with them, has links from the restart on */
    for (s->links_from = s->n; s->links && s->links_from > 0; s->links_from--) {
        frame_name(s, s->links_from - 1, true, name, sizeof name);
        snprintf(path, sizeof path, "%s/%s", s->dir, name);
        if (access(path, F_OK) != 0)
            break;
    }
    if (s->links && links_listed_missing(s) != 0)
        return CLI_EXIT_USAGE;
    s->last_step = s->n ? frame_step(s, s->n - 1, t, step, dt) : 0;
    return CLI_EXIT_OK;
}

/* ------------------------------------------------- the run that wrote the checkpoint --- */

/* The output intervals of the run that wrote the checkpoint: its frames and rows up to the
 * checkpoint's step lie on their grid, except the frame and the row that run added at the
 * step it ended at. */
struct writer {
    unsigned long long vtk_every, csv_every;
    bool ended_here; /* that run ended (finished or was interrupted) at the checkpoint's step */
};

/* The value of "key": N in a JSON text, or false. */
static bool json_count(const char* text, const char* key, unsigned long long* value)
{
    char pattern[64];
    snprintf(pattern, sizeof pattern, "\"%s\": ", key);
    const char* p = strstr(text, pattern);
    if (!p || !(p[strlen(pattern)] >= '0' && p[strlen(pattern)] <= '9'))
        return false;
    *value = strtoull(p + strlen(pattern), NULL, 10);
    return true;
}

/* The first `size` - 1 bytes of a file as a string (into buf), or false. */
static bool read_head(const char* path, char* buf, size_t size)
{
    FILE* f = fopen(path, "r");
    if (!f)
        return false;
    size_t n = fread(buf, 1, size - 1, f);
    buf[n] = '\0';
    fclose(f);
    return true;
}

/* Finds the run that wrote the checkpoint at `step` from DIR/summary.json, which every run
 * writes where it ends, with its step and output intervals: when the summary's step is the
 * checkpoint's, its intervals; otherwise (no summary, or one of another step: a run that went
 * on from the checkpoint and crashed) this run's, as though unchanged. */
static struct writer find_writer(const char* dir, const struct cli_many_setup* su,
                                 unsigned long long step)
{
    struct writer w = {su->vtk_every, su->csv_every, false};
    char path[PATH_CHARS + CLI_VALUE_MAX];
    snprintf(path, sizeof path, "%s/%s", dir, su->summary_name);
    char text[8192]; /* (the step and the intervals come first) */
    unsigned long long at, vtk, csv;
    if (su->summary_name[0] && read_head(path, text, sizeof text) &&
        json_count(text, "step", &at) && at == step && json_count(text, "vtk_every", &vtk) &&
        json_count(text, "csv_every", &csv))
        w = (struct writer){vtk, csv, true};
    return w;
}

/* ----------------------------------------------------------- CSV: last row, restart --- */

/* Appends the state at the end of the run (finished or interrupted), at `step`, to the CSV
 * as its last row (wetdem_sim_many_write_csv_row), unless the library's rows, every csv_every
 * steps, ended there, so the CSV ends at the state summary.json reports. WETDEM status. */
static int csv_final_row(const char* csv_prefix, unsigned long long csv_every,
                         struct wetdem_sim* sim, unsigned long long step)
{
    if (!csv_prefix[0] || !csv_every || step % csv_every == 0)
        return WETDEM_OK;
    return wetdem_sim_many_write_csv_row(sim);
}

/* wetdem_sim_many_stats, which allocates (for the agglomerates): CLI_EXIT_OK, or
 * CLI_EXIT_RUNTIME after printing the library's message. */
static int many_stats(const struct cli_scenario* sc, struct wetdem_sim* sim,
                      struct wetdem_many_stats* s)
{
    if (wetdem_sim_many_stats(sim, s) == WETDEM_OK)
        return CLI_EXIT_OK;
    cli_error("run %s: %s", sc->file, wetdem_sim_errmsg(sim));
    return CLI_EXIT_RUNTIME;
}

/* Keeps the comment and header lines of the CSV and the rows up to `step` (second column),
 * rewriting the file atomically when rows are dropped. A row at `step` itself is kept only on
 * the grid of w->csv_every, that of the run which wrote the checkpoint: off it, it is the last
 * row that run added at its end (csv_final_row), which the uninterrupted run does not have. A
 * last line without its newline, a row cut short by a crash or a full disk, is dropped too
 * (the resumed run would append to it). *at_step says whether a row at `step` is kept. CLI
 * exit code; a missing file, one without its header line, and one whose rows end before those
 * the run that wrote the checkpoint had written (a file cut short or replaced) are input
 * errors, and leave the file as it was (the resumed run would append its rows after a gap);
 * so is a row up to `step` at a time off the checkpoint's grid (t, dt): another run's CSV. */
static int csv_resume(const char* path, double t, unsigned long long step, double dt,
                      const struct writer* w, const char* out_dir, bool* at_step)
{
    *at_step = false;
    FILE* f = fopen(path, "r");
    if (!f) {
        cli_error("--restart: %s is missing: give --out the directory of the interrupted run, "
                  "whose outputs the resumed run continues (now %s)",
                  path, out_dir);
        return CLI_EXIT_USAGE;
    }
    char tmp[PATH_CHARS + 16];
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    FILE* g = fopen(tmp, "w");
    char line[4096];
    bool dropped = false, header = false, rows = false, in_comment = false;
    unsigned long long every = w->csv_every, last = 0; /* the last whole row's step */
    unsigned long long off_grid = 0; /* 1 + the step of a row off the checkpoint's time grid */
    while (g && fgets(line, sizeof line, f)) {
        bool comment = in_comment || line[0] == '#'; /* (kept whole, however long) */
        in_comment = comment && !strchr(line, '\n');
        if (comment) {
            fputs(line, g);
            continue;
        }
        const char* comma = strchr(line, ',');
        bool data = line[0] >= '0' && line[0] <= '9' && comma;
        unsigned long long row = data ? strtoull(comma + 1, NULL, 10) : 0;
        bool whole = strchr(line, '\n') != NULL; /* (a row cut by a crash ends without) */
        header = header || strncmp(line, WETDEM_MANY_CSV_HEAD, strlen(WETDEM_MANY_CSV_HEAD)) == 0;
        if (data && whole) {
            last = rows && last > row ? last : row;
            rows = true;
        }
        if (data && whole && row <= step && !off_grid &&
            !on_time_grid(strtod(line, NULL), &row, t, step, dt, 1e-8))
            off_grid = row + 1; /* (+1: step 0 too) */
        if (!whole || (data && (row > step || (row == step && !(every && step % every == 0))))) {
            dropped = true;
            continue;
        }
        *at_step = *at_step || (data && row == step);
        fputs(line, g);
    }
    fclose(f);
    bool ok = g && !ferror(g);
    ok = g && fclose(g) == 0 && ok;
    /* the rows the run that wrote the checkpoint had written by then: one at the step it
       ended at, else those of its grid (this run's, as far as is known) */
    unsigned long long due = w->ended_here ? step : every ? step / every * every : 0;
    if (ok && (!header || !rows || last < due || off_grid)) {
        remove(tmp);
        if (off_grid)
            cli_error("--restart: %s has a row of step %llu at a time off the time grid of the "
                      "checkpoint (dt = %.9g s, step %llu at t = %.9g s): it holds the rows of "
                      "another run; give --out the directory of the run that wrote the "
                      "checkpoint (now %s)",
                      path, off_grid - 1, dt, step, t, out_dir);
        else if (!header)
            cli_error("--restart: %s has no header line (" WETDEM_MANY_CSV_HEAD "...): it was "
                      "emptied or cut at its start, and the rows up to the checkpoint are lost; "
                      "restore it, or start the run afresh without --restart",
                      path);
        else
            cli_error("--restart: %s %s%llu, before the checkpoint's step %llu: it was cut short "
                      "or replaced, and the resumed run would leave a gap; restore it, or start "
                      "the run afresh without --restart",
                      path, rows ? "ends at step " : "has no rows, expected up to step ",
                      rows ? last : due, step);
        return CLI_EXIT_USAGE;
    }
    if (ok && (!dropped || rename(tmp, path) == 0)) {
        remove(tmp);
        return CLI_EXIT_OK;
    }
    remove(tmp);
    cli_error("--restart: cannot rewrite %s", path);
    return CLI_EXIT_RUNTIME;
}

/* ----------------------------------------------------------------------- progress --- */

/* Progress of the stepping on a terminal. The run is stepped in integrate calls that end at
 * the frames (run_steps), so the callback reads nothing of the state but the time, and the
 * library may let each force pass begin the next step between them (sim_many.c one_step). */
struct progress {
    struct wetdem_sim* sim;
    struct series* vtk;           /* NULL: no frames */
    unsigned long long base_step; /* step count when this integrate call began */
    unsigned long long run_total; /* steps of the whole run */
    struct cli_progress line;     /* started when the stepping begins (line.tty before) */
    int status;                   /* first failure writing a frame (its message: vtk->error) */
};

/* Calls of the progress callback: every PROGRESS_PARTICLE_STEPS / N steps for N particles
 * (about 0.1 s of stepping at the benchmark's 20-60 million particle-steps a second, so that
 * the line moves on a large run too), at most every step and at least every PROGRESS_EVERY.
 * A call makes the library write the state back for the callback, which takes a step out of
 * the force pass that begins the next (sim_many.c); one step in 64 costs about a percent of
 * that. */
#define PROGRESS_EVERY 64
#define PROGRESS_PARTICLE_STEPS 2000000.0

/* Library progress callback, every PROGRESS_EVERY steps or fewer and at the end of a call: the
 * progress line on a terminal. */
static int on_progress(unsigned long long done, unsigned long long total, double elapsed, void* ctx)
{
    (void)total;
    (void)elapsed;
    struct progress* p = ctx;
    unsigned long long step = p->base_step + done;
    cli_progress_show(&p->line, (double)step / (double)p->run_total, "t = %.4g s, step %llu/%llu",
                      wetdem_sim_time(p->sim), step, p->run_total);
    return 0;
}

/* ------------------------------------------------------------------------ summary --- */

struct outcome {
    struct wetdem_many_stats stats;
    struct wetdem_energy_budget budget;
    bool has_budget;
    double wall; /* [s] */
    bool interrupted;
};

/* The closure error as a fraction of the larger of the input and the work, each model's work on
 * pairs and on walls counted by its size (0 when both are 0; not finite when the budget is
 * not). Their sum would let works of opposite signs cancel: capillary bridges that pull spheres
 * at rest together give the energy that the films and contacts take, and the run, which ends
 * at rest, has a net work of its own closure error, so its ratio was 1 at any step. */
static double closure_ratio(const struct wetdem_energy_budget* b)
{
    double work = 0;
    for (size_t k = 0; k < b->n_models && k < WETDEM_ENERGY_MAX_MODELS; k++)
        work += fabs(b->work_pair[k]) + fabs(b->work_wall[k]);
    double scale = fmax(fabs(b->input), work);
    if (!isfinite(b->balance_error) || !isfinite(scale))
        return NAN;
    return scale > 0 ? fabs(b->balance_error) / scale : 0.0;
}

/* Beyond this ratio the integration is not what the budget's O(dt^2) error allows: the step is
 * too long for the contacts (the example scenarios close to 5e-5 to 4e-4, dt_fraction 0.05;
 * the settling example gives 6e-4 at 6.6 us, 1.4e-3 at 9.7 us and 0.87 at 19 us, 0.12, 0.17
 * and 0.33 of its contact time). */
#define CLOSURE_LIMIT 0.05

/* Whether the budget of the run (has_budget) is beyond CLOSURE_LIMIT, also when its error is
 * not finite; *ratio is its closure_ratio (0 without a budget). The end of a run and a restart
 * judge by this one rule. */
static bool budget_open(const struct wetdem_energy_budget* b, bool has_budget, double* ratio)
{
    *ratio = has_budget ? closure_ratio(b) : 0.0;
    return !(*ratio <= CLOSURE_LIMIT);
}

/* Whether the run's step is the quarter of the viscous relaxation time the library holds a
 * derived step to (docs/many.md, Time step). */
static bool dt_held_by_relaxation(const struct wetdem_many_stats* s)
{
    return s->dt == 0.25 * s->relaxation_time;
}

/* verlet.many_hmin_fraction of the run (the library's default if it cannot be read). */
static double many_hmin_fraction(const struct wetdem_sim* sim)
{
    double f = 0.5;
    wetdem_sim_param(sim, "verlet.many_hmin_fraction", &f);
    return f;
}

/* Whether the run's step is the one a derived step is held to by the distance a pair at the
 * speed scale travels per step: many_hmin_fraction x the h_min crossing time (docs/many.md). */
static bool dt_held_by_gap(const struct wetdem_sim* sim, const struct wetdem_many_stats* s)
{
    return s->dt == many_hmin_fraction(sim) * s->hmin_crossing_time;
}

/* What a step does not resolve of the time scales at a speed scale (docs/many.md, Time step):
 * the two tests that warn_step makes at the start's speed scale and warn_speed at the one a
 * run reaches beyond it, each with its own message. */
struct unresolved {
    /* dt above WETDEM_MANY_CONTACT_FRACTION_MAX of the contact time, where velocity Verlet
       loses the contacts' restitution and then diverges */
    bool contacts;
    /* dt longer than the time a pair closing at the speed scale takes to cross the h_min where
       the force laws jump, so that the jump falls within one step (unless
       many_hmin_fraction = 0 turned that bound off) */
    bool h_min;
};

/* The tests of struct unresolved for step dt, contact time t_contact and h_min crossing time
 * t_cross [s] (INFINITY: nothing touches, nothing jumps) of sim. */
static struct unresolved step_unresolved(const struct wetdem_sim* sim, double dt, double t_contact,
                                         double t_cross)
{
    return (struct unresolved){
        .contacts = dt / t_contact > WETDEM_MANY_CONTACT_FRACTION_MAX,
        .h_min = dt > t_cross && many_hmin_fraction(sim) != 0,
    };
}

/* Warns on stderr when the step does not resolve what the run meets at the speed scale it
 * starts with (struct unresolved). (A step not below the viscous relaxation time is derived
 * below it, or refused by the library when given.) */
static void warn_step(const struct cli_scenario* sc, const struct cli_many_setup* su,
                      const struct wetdem_many_stats* s)
{
    struct unresolved u = step_unresolved(su->sim, s->dt, s->contact_time, s->hmin_crossing_time);
    double ratio = s->dt / s->contact_time;
    if (u.contacts)
        cli_error("warning: %s: the step dt = %.4g s is %.3g x the contact time %.4g s (the "
                  "shortest, normal or tangential, at the speed scale), above %g x: the "
                  "contacts are not resolved, and from about 0.5 x the motion diverges; lower "
                  "dt or dt_fraction (docs/many.md, Time step)",
                  sc->file, s->dt, ratio, s->contact_time, WETDEM_MANY_CONTACT_FRACTION_MAX);
    if (u.h_min)
        cli_error("warning: %s: in one step dt = %.4g s a pair closing at the speed scale "
                  "travels %.3g x the smallest h_min where the force laws jump (crossed in "
                  "%.4g s): the jump falls within a step, which can shift a collision's "
                  "restitution by 10 %% or more; lower dt (a derived step takes at most "
                  "[integrator] many_hmin_fraction of it: docs/many.md, Time step)",
                  sc->file, s->dt, s->dt / s->hmin_crossing_time, s->hmin_crossing_time);
}

/* What warn_speed judges: the run's step dt [s] and its speeds (wetdem_many_stats:
 * speed_scale, speed_bound, largest_speed [m/s]), from the stats where the run has them, else
 * from wetdem_sim_many_speeds, which counts no links. */
struct run_speeds {
    double dt, scale, bound, largest;
};

static struct run_speeds speeds_of(const struct wetdem_many_stats* s)
{
    return (struct run_speeds){s->dt, s->speed_scale, s->speed_bound, s->largest_speed};
}

/* Warns on stderr when a particle has moved faster than the speed scale of the step allows
 * (largest_speed above speed_bound: an incline, a chute, capillary attraction; docs/many.md,
 * "Speeds beyond the step's") and the step does not resolve, at the speed scale with that
 * speed in place of the bound, what warn_step checks at the start (struct unresolved), or is
 * not below the viscous relaxation time there; `tty`: after a newline, off the progress line.
 * Whether it warned. */
static bool warn_speed(const struct cli_scenario* sc, struct cli_many_setup* su,
                       const struct run_speeds* s, bool tty)
{
    if (!(s->largest > s->bound))
        return false;
    double v = s->scale + (s->largest - s->bound), t_c, tau, t_x, dt;
    char what[600] = "";
    bool ok = wetdem_sim_many_time_scales_at(su->sim, v, &t_c, &tau, &t_x, &dt) == WETDEM_OK;
    size_t n =
        ok ? (size_t)snprintf(what, sizeof what, "and there the step dt = %.4g s is ", s->dt) : 0;
    size_t head = n;
    if (!ok)
        snprintf(what, sizeof what, "where the time scales cannot be evaluated: %s",
                 wetdem_sim_errmsg(su->sim));
    else {
        struct unresolved u = step_unresolved(su->sim, s->dt, t_c, t_x);
        if (u.contacts)
            n += (size_t)snprintf(what + n, sizeof what - n,
                                  "%.3g x the contact time %.4g s (above %g x: the contacts are "
                                  "not resolved)",
                                  s->dt / t_c, t_c, WETDEM_MANY_CONTACT_FRACTION_MAX);
        if (u.h_min && n < sizeof what)
            n += (size_t)snprintf(what + n, sizeof what - n,
                                  "%slonger than the time %.4g s a pair takes to cross the "
                                  "smallest h_min where the force laws jump",
                                  n > head ? "; " : "", t_x);
        if (s->dt >= tau && n < sizeof what)
            n += (size_t)snprintf(what + n, sizeof what - n,
                                  "%snot below the viscous relaxation time %.4g s (velocity "
                                  "Verlet is unstable there)",
                                  n > head ? "; " : "", tau);
        if (n == head)
            return false;
        if (n < sizeof what) /* the step a start at that speed scale would derive */
            snprintf(what + n, sizeof what - n, ": [run] dt = %.4g s would resolve it", dt);
    }
    if (tty) /* (off the progress line) */
        fputc('\n', stderr);
    cli_error("warning: %s: by t = %.6g s a particle reached %.4g m/s, above the %.4g m/s the "
              "step's time scales allow a particle (an incline, a chute or capillary "
              "attraction: docs/many.md, Speeds beyond the step's); with it the speed scale, "
              "%.4g m/s at the start, becomes %.4g m/s, %s",
              sc->file, wetdem_sim_time(su->sim), s->largest, s->bound, s->scale, v, what);
    return true;
}

/* How many of the run's spheres are fixed (held in place). */
static size_t n_fixed(const struct cli_many_setup* su)
{
    size_t n, count = 0;
    const struct wetdem_particle* p = wetdem_sim_particles_const(su->sim, &n);
    for (size_t k = 0; k < n; k++)
        count += p[k].is_fixed;
    return count;
}

static void summary_text(FILE* f, const struct cli_many_setup* su, const struct outcome* o)
{
    const struct wetdem_many_stats* s = &o->stats;
    size_t fixed = n_fixed(su);
    fprintf(f, "particles          %zu  (", wetdem_sim_n_particles(su->sim));
    if (fixed)
        fprintf(f, "%zu fixed, ", fixed);
    fprintf(f, "walls %zu)\n", wetdem_sim_n_walls(su->sim));
    fprintf(f, "time               %.6g s  (step %llu, dt = %.4g s, %.3g s wall, %d thread%s)\n",
            wetdem_sim_time(su->sim), s->step, s->dt, o->wall, s->threads,
            s->threads == 1 ? "" : "s");
    if (dt_held_by_relaxation(s))
        fprintf(f,
                "                   (dt held at a quarter of the viscous relaxation time "
                "%.4g s: docs/many.md, Time step)\n",
                s->relaxation_time);
    else if (dt_held_by_gap(su->sim, s))
        fprintf(f,
                "                   (dt held at %g of the time %.4g s a pair at the speed "
                "scale takes to cross h_min: docs/many.md, Time step)\n",
                many_hmin_fraction(su->sim), s->hmin_crossing_time);
    fprintf(f, "largest speed      %.4g m/s  (the step's time scales allow ", s->largest_speed);
    if (isfinite(s->speed_bound))
        fprintf(f, "%.4g m/s: docs/many.md, Speeds beyond the step's)\n", s->speed_bound);
    else
        fprintf(f, "any: all falls together)\n");
    fprintf(f, "contacts           %zu\nliquid bridges     %zu\n", s->contacts, s->bridges);
    /* a mean of whole sizes: "2000", not %g's "2e+03"; below 1000 four digits at most */
    fprintf(f,
            s->mean_agglomerate < 999.5 ? "agglomerates       %zu  (mean size %.4g)\n"
                                        : "agglomerates       %zu  (mean size %.0f)\n",
            s->agglomerates, s->mean_agglomerate);
    double phase[4] = {s->seconds_kick, s->seconds_forces, s->seconds_lists, s->seconds_output};
    const char* name[4] = {"kick-drift", "forces", "neighbour lists", "output"};
    fprintf(f, "wall time by phase");
    for (int k = 0; k < 4; k++)
        fprintf(f, "%s %s %.3g s (%.0f %%)", k ? "," : "", name[k], phase[k],
                o->wall > 0 ? 100 * phase[k] / o->wall : 0.0);
    fprintf(f, "\n");
    if (!o->has_budget)
        return;
    const struct wetdem_energy_budget* b = &o->budget;
    fprintf(f, "energy budget [J]  input = kinetic + potential + elastic + dissipated\n");
    fprintf(f, "  input            %12.6g  (kinetic + potential + elastic at the start)\n",
            cli_plain_zero(b->input));
    fprintf(f,
            "  kinetic          %12.6g\n  potential        %12.6g\n  elastic          "
            "%12.6g\n  dissipated       %12.6g\n",
            cli_plain_zero(b->kinetic), cli_plain_zero(b->potential), cli_plain_zero(b->elastic),
            cli_plain_zero(b->dissipated));
    fprintf(f, "work by model [J]  %12s %12s %12s  (< 0: taken from the particles)\n", "pairs",
            "walls", "total");
    for (size_t k = 0; k < b->n_models && k < WETDEM_ENERGY_MAX_MODELS; k++)
        fprintf(f, "  %-16s %12.6g %12.6g %12.6g\n", wetdem_sim_model(su->sim, k)->name,
                cli_plain_zero(b->work_pair[k]), cli_plain_zero(b->work_wall[k]),
                cli_plain_zero(b->work_pair[k] + b->work_wall[k]));
    fprintf(f, "  %-16s %12s %12s %12.6g\n", "all", "", "", cli_plain_zero(b->work_total));
    fprintf(f,
            "closure error      %12.6g  (change of kinetic + potential minus the work; "
            "%.2g of the larger of input and work)\n",
            cli_plain_zero(b->balance_error), cli_plain_zero(closure_ratio(b)));
}

static void json_num(FILE* f, const char* key, double v, bool comma)
{
    fprintf(f, "\"%s\": ", key);
    if (isfinite(v))
        fprintf(f, "%.17g", cli_plain_zero(v));
    else
        fputs("null", f);
    if (comma)
        fputs(", ", f);
}

static void summary_json(FILE* f, const struct cli_scenario* sc, const struct cli_many_setup* su,
                         const struct cli_run_options* opt, const struct outcome* o)
{
    const struct wetdem_many_stats* s = &o->stats;
    fprintf(f, "{\"engine\": \"many\", \"version\": \"%s\", \"git\": \"%s\", \"scenario\": ",
            WETDEM_VERSION, WETDEM_GIT_HASH);
    cli_json_string(f, sc->file);
    fputs(", \"command\": ", f);
    cli_json_command(f, opt->argc, opt->argv);
    fprintf(f,
            ", \"interrupted\": %s, \"particles\": %zu, \"fixed\": %zu, \"walls\": %zu, "
            "\"step\": %llu, \"vtk_every\": %llu, \"csv_every\": %llu, ",
            o->interrupted ? "true" : "false", wetdem_sim_n_particles(su->sim), n_fixed(su),
            wetdem_sim_n_walls(su->sim), s->step, su->vtk_prefix[0] ? su->vtk_every : 0,
            su->csv_name[0] ? su->csv_every : 0);
    json_num(f, "time_s", wetdem_sim_time(su->sim), true);
    json_num(f, "dt_s", s->dt, true);
    json_num(f, "speed_scale_m_s", s->speed_scale, true);
    json_num(f, "speed_bound_m_s", s->speed_bound, true);
    json_num(f, "largest_speed_m_s", s->largest_speed, true);
    fprintf(f, "\"contacts\": %zu, \"bridges\": %zu, \"agglomerates\": %zu, ", s->contacts,
            s->bridges, s->agglomerates);
    json_num(f, "mean_agglomerate_size", s->mean_agglomerate, o->has_budget);
    if (o->has_budget) {
        const struct wetdem_energy_budget* b = &o->budget;
        fputs("\"energy_J\": {", f);
        json_num(f, "input", b->input, true);
        json_num(f, "kinetic", b->kinetic, true);
        json_num(f, "potential", b->potential, true);
        json_num(f, "elastic", b->elastic, true);
        json_num(f, "dissipated", b->dissipated, true);
        json_num(f, "work_total", b->work_total, true);
        json_num(f, "balance_error", b->balance_error, true);
        json_num(f, "balance_error_ratio", closure_ratio(b), true);
        fputs("\"work_by_model\": [", f);
        for (size_t k = 0; k < b->n_models && k < WETDEM_ENERGY_MAX_MODELS; k++) {
            fprintf(f, "%s{\"model\": \"%s\", ", k ? ", " : "", wetdem_sim_model(su->sim, k)->name);
            json_num(f, "pairs", b->work_pair[k], true);
            json_num(f, "walls", b->work_wall[k], false);
            fputs("}", f);
        }
        fputs("]}", f);
    }
    fputs("}\n", f);
}

/* Writes DIR/summary.json atomically. CLI exit code. */
static int write_summary(const char* dir, const struct cli_scenario* sc,
                         const struct cli_many_setup* su, const struct cli_run_options* opt,
                         const struct outcome* o)
{
    if (!dir || !su->summary_name[0])
        return CLI_EXIT_OK;
    char path[PATH_CHARS + CLI_VALUE_MAX], tmp[sizeof path + 8];
    snprintf(path, sizeof path, "%s/%s", dir, su->summary_name);
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    FILE* f = fopen(tmp, "w");
    if (f)
        summary_json(f, sc, su, opt, o);
    bool ok = f && !ferror(f);
    ok = f && fclose(f) == 0 && ok;
    if (ok && rename(tmp, path) == 0)
        return CLI_EXIT_OK;
    int err = errno ? errno : EIO;
    remove(tmp);
    cli_error("run: cannot write %s: %s", path, strerror(err));
    return CLI_EXIT_RUNTIME;
}

/* Prints " word" as a POSIX shell reads it back: in single quotes when it holds a character
 * the shell treats specially (or is empty), a quote inside as '\''. */
static void print_shell_word(FILE* f, const char* word)
{
    if (word[0] && !strpbrk(word, " \t\n'\"\\$`;&|<>()*?[]{}~#!")) {
        fprintf(f, " %s", word);
        return;
    }
    fputs(" '", f);
    for (const char* c = word; *c; c++)
        if (*c == '\'')
            fputs("'\\''", f);
        else
            fputc(*c, f);
    fputc('\'', f);
}

/* Prints the command that resumes an interrupted run: the original arguments with
 * --restart CHECKPOINT (replacing an earlier --restart), each quoted for the shell. */
static void print_resume(const struct cli_run_options* opt, const char* ckpt)
{
    fprintf(stderr, "wetdem: resume with: wetdem");
    for (int k = 0; k < opt->argc; k++) {
        if (strcmp(opt->argv[k], "--restart") == 0 && k + 1 < opt->argc) {
            k++;
            continue;
        }
        print_shell_word(stderr, opt->argv[k]);
    }
    fputs(" --restart", stderr);
    print_shell_word(stderr, ckpt);
    fputc('\n', stderr);
}

/* ------------------------------------------------------------------------ the run --- */

/* Everything resolved before any file is touched. */
struct plan {
    double t_end;                /* [s] */
    unsigned long long total;    /* steps of the whole run */
    double dt;                   /* [s] */
    char csv_prefix[PATH_CHARS]; /* DIR/<csv name without .csv>, "" for none */
    char checkpoint[PATH_CHARS]; /* DIR/<checkpoint>, "" for none */
};

/* Starts the run once without outputs: every library check of the set-up (time step, cell
 * lists, periodic box, reach). Fills the run length and the default output intervals. */
static int dry_start(const struct cli_scenario* sc, struct cli_many_setup* su, struct plan* pl)
{
    int st = wetdem_sim_integrate(su->sim, wetdem_sim_time(su->sim));
    if (st != WETDEM_OK)
        return cli_many_report_start(sc, st, wetdem_sim_errmsg(su->sim));
    struct wetdem_many_stats s;
    int rc = many_stats(sc, su->sim, &s);
    if (rc != CLI_EXIT_OK)
        return rc;
    warn_step(sc, su, &s);
    pl->dt = s.dt;
    /* the library takes ceil((t_end - t)/dt) steps on the grid t = k dt */
    pl->t_end = su->steps ? (double)su->steps * s.dt : su->t_end;
    double span = pl->t_end / s.dt;
    if (!su->steps && span > WETDEM_MANY_MAX_STEPS) {
        cli_scenario_error(sc, cli_scenario_find(sc, "run", "t_end"),
                           "takes %.3g steps of dt = %g s, more than %g: raise "
                           "[run] dt or lower t_end",
                           span, s.dt, WETDEM_MANY_MAX_STEPS);
        return CLI_EXIT_USAGE;
    }
    double max_steps = 1e8;
    wetdem_sim_param(su->sim, "verlet.max_steps", &max_steps);
    if ((pl->t_end - wetdem_sim_time(su->sim)) / s.dt > max_steps) {
        /* the library refuses such a call before its first step, saying what sets the step
           (the same test as its own, so that the call never runs the span) */
        st = wetdem_sim_integrate(su->sim, pl->t_end);
        if (st != WETDEM_OK)
            return cli_many_report_start(sc, st, wetdem_sim_errmsg(su->sim));
    }
    pl->total = su->steps ? su->steps : (unsigned long long)ceil(span - 1e-9);
    if (!su->vtk_every_given)
        su->vtk_every = pl->total / 50 > 0 ? pl->total / 50 : 1;
    if (!su->csv_every_given)
        su->csv_every = pl->total / 500 > 0 ? pl->total / 500 : 1;
    return CLI_EXIT_OK;
}

/* The resolved set-up of `run --check --json`: the fields of the text form, one object. */
static void print_check_json(const struct cli_scenario* sc, const struct cli_many_setup* su,
                             const struct plan* pl, const struct wetdem_many_stats* s)
{
    printf("{\"scenario\": ");
    cli_json_string(stdout, sc->file);
    printf(", \"engine\": \"many\", \"particles\": %zu, \"fixed\": %zu, \"walls\": %zu, "
           "\"box_m\": "
           "[%.17g, %.17g, %.17g], \"periodic\": [%s, %s, %s], \"dt_s\": %.17g, "
           "\"time_s\": %.17g, \"t_end_s\": %.17g, \"steps\": %llu, \"vtk_every\": %llu, "
           "\"vtk_links\": %s, "
           "\"csv_every\": %llu, \"contacts\": %zu, \"bridges\": %zu, \"models\": [",
           wetdem_sim_n_particles(su->sim), n_fixed(su), wetdem_sim_n_walls(su->sim), su->box[0],
           su->box[1], su->box[2], su->many.periodic[0] ? "true" : "false",
           su->many.periodic[1] ? "true" : "false", su->many.periodic[2] ? "true" : "false", pl->dt,
           wetdem_sim_time(su->sim), pl->t_end, pl->total, su->vtk_every,
           su->vtk_links ? "true" : "false", su->csv_every, s->contacts, s->bridges);
    for (size_t k = 0; k < wetdem_sim_n_models(su->sim); k++) {
        printf("%s", k ? ", " : "");
        cli_json_string(stdout, wetdem_sim_model(su->sim, k)->name);
    }
    printf("], \"materials\": [");
    for (int k = 0; k < wetdem_sim_n_materials(su->sim); k++) {
        printf("%s", k ? ", " : "");
        cli_json_string(stdout, su->material_names[k]);
    }
    printf("], ");
    const char* key[5] = {"relaxation_time_s", "contact_time_s", "hmin_crossing_time_s",
                          "speed_scale_m_s", "speed_bound_m_s"};
    double value[5] = {s->relaxation_time, s->contact_time, s->hmin_crossing_time, s->speed_scale,
                       s->speed_bound};
    /* (INFINITY: nothing damps, touches or crosses an h_min; no bound: all falls together) */
    for (int k = 0; k < 5; k++)
        if (isfinite(value[k]))
            printf("\"%s\": %.17g%s", key[k], value[k], k < 4 ? ", " : "}\n");
        else
            printf("\"%s\": null%s", key[k], k < 4 ? ", " : "}\n");
}

/* The resolved set-up of `run --check`. CLI exit code. */
static int print_check(const struct cli_scenario* sc, const struct cli_many_setup* su,
                       const struct plan* pl, const struct cli_run_options* opt)
{
    struct wetdem_many_stats s;
    if (many_stats(sc, su->sim, &s) != CLI_EXIT_OK)
        return CLI_EXIT_RUNTIME;
    bool opt_restart = opt->restart != NULL;
    if (opt->json) {
        print_check_json(sc, su, pl, &s);
        return CLI_EXIT_OK;
    }
    printf("scenario %s is valid (many-particle run)\n", sc->file);
    size_t fixed = n_fixed(su);
    printf("  particles     %zu", wetdem_sim_n_particles(su->sim));
    if (fixed)
        printf("  (%zu fixed)", fixed);
    printf("\n  walls         %zu\n  box           %g x %g x %g m, periodic %s%s%s%s\n",
           wetdem_sim_n_walls(su->sim), su->box[0], su->box[1], su->box[2],
           su->many.periodic[0] ? "x" : "", su->many.periodic[1] ? "y" : "",
           su->many.periodic[2] ? "z" : "",
           su->many.periodic[0] || su->many.periodic[1] || su->many.periodic[2] ? "" : "none");
    printf("  dt            %.6g s\n", pl->dt);
    printf("  speed scale   %.6g m/s  (", s.speed_scale);
    if (isfinite(s.speed_bound))
        printf("of the time scales below, which hold while no particle exceeds %.6g m/s)\n",
               s.speed_bound);
    else
        printf("of the time scales below; nothing stops a fall: no particle speed bound)\n");
    if (isfinite(s.contact_time))
        printf("  contact time  %.6g s  (shortest, normal or tangential, at the speed scale; "
               "dt is %.3g of it)\n",
               s.contact_time, pl->dt / s.contact_time);
    if (isfinite(s.relaxation_time))
        printf("  relaxation    %.6g s  (shortest viscous relaxation time; dt %s)\n",
               s.relaxation_time,
               dt_held_by_relaxation(&s) ? "held at a quarter of it" : "stays below it");
    if (isfinite(s.hmin_crossing_time))
        printf("  h_min crossed %.6g s  (by a pair at the speed scale; dt %s)\n",
               s.hmin_crossing_time,
               dt_held_by_gap(su->sim, &s)      ? "held at many_hmin_fraction of it"
               : pl->dt <= s.hmin_crossing_time ? "stays below it"
                                                : "exceeds it");
    printf("  t_end         %.6g s\n  steps         %llu\n", pl->t_end, pl->total);
    printf("  vtk_every     %llu%s\n  csv_every     %llu\n  contacts      %zu  (bridges %zu) at "
           "t = %.6g s%s\n  models       ",
           su->vtk_every, su->vtk_links ? "  (with links)" : "", su->csv_every, s.contacts,
           s.bridges, wetdem_sim_time(su->sim), opt_restart ? " (the checkpoint's)" : "");
    for (size_t k = 0; k < wetdem_sim_n_models(su->sim); k++)
        printf(" %s", wetdem_sim_model(su->sim, k)->name);
    printf("\n  materials    "); /* (their indices: frames' material array, [read.NAME]) */
    for (int k = 0; k < wetdem_sim_n_materials(su->sim); k++)
        printf(" %d %s%s", k, su->material_names[k],
               k + 1 < wetdem_sim_n_materials(su->sim) ? "," : "");
    printf("\n");
    return CLI_EXIT_OK;
}

/* What the checkpoints of a run record (checkpoint_note): the names its frames and CSV take
 * from [dump], "none" for one it does not write, a "key = value" line each, into buf[n]. */
static void output_note(const struct cli_many_setup* su, char* buf, size_t n)
{
    snprintf(buf, n, "vtk = %s\ncsv = %s",
             su->vtk_prefix[0] && su->vtk_every ? su->vtk_prefix : "none",
             su->csv_name[0] && su->csv_every ? su->csv_name : "none");
}

/* The value of `key` in a note of output_note into buf[n]; false when the note has none (a
 * checkpoint written without it, by another program or an earlier version). */
static bool note_value(const char* note, const char* key, char* buf, size_t n)
{
    size_t len = strlen(key);
    for (const char* p = note; p && *p; p = strchr(p, '\n') ? strchr(p, '\n') + 1 : NULL)
        if (strncmp(p, key, len) == 0 && strncmp(p + len, " = ", 3) == 0) {
            snprintf(buf, n, "%.*s", (int)strcspn(p + len + 3, "\n"), p + len + 3);
            return true;
        }
    return false;
}

/* Refuses a restart that names the frames or the CSV otherwise than the run that wrote the
 * checkpoint (its checkpoint_note): another VTK prefix would start a second series beside the
 * first, another CSV name find no rows before the checkpoint. Writing none of them, or
 * starting frames or a CSV that run did not write (from the checkpoint on), continues it. CLI
 * exit code; touches no file. */
static int check_output_names(const struct cli_many_setup* su, const struct cli_run_options* opt)
{
    const char* note = wetdem_sim_checkpoint_note(su->sim);
    char ours[2 * CLI_VALUE_MAX + 16];
    output_note(su, ours, sizeof ours);
    static const char* const keys[2] = {"vtk", "csv"};
    for (int k = 0; k < 2; k++) {
        char was[CLI_VALUE_MAX], now[CLI_VALUE_MAX];
        note_value(ours, keys[k], now, sizeof now);
        if (!note || !note_value(note, keys[k], was, sizeof was) || strcmp(was, "none") == 0 ||
            strcmp(now, "none") == 0 || strcmp(was, now) == 0)
            continue;
        cli_error("--restart %s: [dump] %s = %s, but the run that wrote the checkpoint wrote %s "
                  "%s%s: the resumed run would %s; resume with %s = %s (--set dump.%s=%s), or "
                  "start afresh without --restart (nothing was changed)",
                  opt->restart, keys[k], now, k ? "its CSV as" : "its frames as", was,
                  k ? "" : "_NNNNNN.vtk",
                  k ? "write a CSV that lacks the rows before the checkpoint"
                    : "start another series of frames beside them",
                  keys[k], was, keys[k], was);
        return CLI_EXIT_USAGE;
    }
    return CLI_EXIT_OK;
}

/* Sets the mode again with the outputs of --out DIR and the stop flag. */
static int set_outputs(struct cli_many_setup* su, const struct cli_run_options* opt,
                       struct plan* pl, struct progress* prog)
{
    struct wetdem_many_settings m = su->many;
    pl->csv_prefix[0] = pl->checkpoint[0] = '\0';
    if (opt->out_dir && su->csv_name[0] && su->csv_every)
        snprintf(pl->csv_prefix, sizeof pl->csv_prefix, "%s/%.*s", opt->out_dir,
                 (int)strlen(su->csv_name) - 4, su->csv_name);
    if (opt->out_dir && su->checkpoint_name[0])
        snprintf(pl->checkpoint, sizeof pl->checkpoint, "%s/%s", opt->out_dir, su->checkpoint_name);
    m.output_prefix = pl->csv_prefix[0] ? pl->csv_prefix : NULL;
    m.csv_every = su->csv_every;
    m.vtk_every = 0; /* frames are written by run_steps */
    m.checkpoint_path = pl->checkpoint[0] ? pl->checkpoint : NULL;
    m.checkpoint_every = su->checkpoint_every;
    m.stop_flag = &cli_stop_signal;
    m.progress = prog->line.tty ? on_progress : NULL;
    m.progress_ctx = prog;
    double every = PROGRESS_PARTICLE_STEPS / (double)(wetdem_sim_n_particles(su->sim) + 1);
    m.progress_every = every < 1                ? 1
                       : every > PROGRESS_EVERY ? PROGRESS_EVERY
                                                : (unsigned long long)every;
    char* comment = cli_provenance_text(opt->argc, opt->argv);
    if (!comment) {
        cli_error("run: out of memory");
        return CLI_EXIT_RUNTIME;
    }
    m.csv_comment = comment;
    char note[2 * CLI_VALUE_MAX + 16];
    output_note(su, note, sizeof note);
    m.checkpoint_note = note;
    int st = wetdem_sim_set_many(su->sim, &m);
    free(comment); /* (copied) */
    if (st == WETDEM_OK)
        return CLI_EXIT_OK;
    cli_error("run: %s", wetdem_sim_errmsg(su->sim));
    return CLI_EXIT_RUNTIME;
}

/* Restores the checkpoint and checks that this run can continue it, with the restored
 * state's statistics into *s; touches no file. */
static int restore(const struct cli_scenario* sc, const struct cli_many_setup* su,
                   const struct cli_run_options* opt, const struct plan* pl,
                   struct wetdem_many_stats* s)
{
    size_t n_scenario = wetdem_sim_n_particles(su->sim);
    if (wetdem_sim_read_checkpoint(su->sim, opt->restart) != WETDEM_OK) {
        cli_error("--restart %s: %s", opt->restart, wetdem_sim_errmsg(su->sim));
        return CLI_EXIT_USAGE;
    }
    /* The checkpoint's spheres replace the scenario's, so a changed [insert] count or a
       [particle.NAME] added or removed would otherwise go unnoticed. */
    if (wetdem_sim_n_particles(su->sim) != n_scenario) {
        cli_error("--restart %s: the checkpoint holds %zu spheres but the scenario places %zu "
                  "([insert] count, [particle.NAME]): resume with the scenario of the run that "
                  "wrote it",
                  opt->restart, wetdem_sim_n_particles(su->sim), n_scenario);
        return CLI_EXIT_USAGE;
    }
    if (check_output_names(su, opt) != CLI_EXIT_OK)
        return CLI_EXIT_USAGE;
    /* The budget restored closes at the checkpoint's step unless the state was edited or its
       run's step was too long for the contacts (which the end of that run judges too): either
       way the run is refused before any output is touched. */
    struct wetdem_energy_budget b;
    double ratio;
    if (budget_open(&b, wetdem_sim_energy_budget(su->sim, &b) == WETDEM_OK, &ratio)) {
        cli_error("--restart %s: its energy budget does not close (error %.2g of the larger of "
                  "input and work, above %g): the state was changed after its run wrote it, "
                  "or that run's step is too long for its contacts; resume from a checkpoint "
                  "whose budget closes, or start afresh",
                  opt->restart, ratio, CLOSURE_LIMIT);
        return CLI_EXIT_USAGE;
    }
    if (many_stats(sc, su->sim, s) != CLI_EXIT_OK)
        return CLI_EXIT_RUNTIME;
    /* the step is the checkpoint's; one the scenario now derives otherwise ([integrator]
       dt_fraction, a material's stiffness: not in the checkpoint's fingerprint, which holds
       the settings' dt) would misplace the run's end, its frames and its CSV rows */
    if (s->dt != pl->dt) {
        cli_error("--restart %s: the checkpoint's step is dt = %.9g s, this scenario's %.9g s "
                  "(run.dt, integrator.dt or dt_fraction, the materials): resume with the "
                  "scenario of the run that wrote it",
                  opt->restart, s->dt, pl->dt);
        return CLI_EXIT_USAGE;
    }
    if (s->step > pl->total) {
        cli_error("--restart %s: the checkpoint is at step %llu (t = %.9g s), after this run's "
                  "end at step %llu ([run] t_end = %.9g s, or steps): a run cannot go back in "
                  "time; give a t_end (--set run.t_end=...) or steps beyond the checkpoint's to "
                  "continue it, or start afresh without --restart",
                  opt->restart, (unsigned long long)s->step, wetdem_sim_time(su->sim), pl->total,
                  pl->t_end);
        return CLI_EXIT_USAGE;
    }
    if (s->step == pl->total) {
        cli_error("--restart %s: the checkpoint is at step %llu (t = %.9g s), and this run ends "
                  "at step %llu ([run] t_end = %.9g s): the run that wrote it had reached its "
                  "end; raise t_end (--set run.t_end=...) or steps to continue it",
                  opt->restart, (unsigned long long)s->step, wetdem_sim_time(su->sim), pl->total,
                  pl->t_end);
        return CLI_EXIT_USAGE;
    }
    return CLI_EXIT_OK;
}

/* Restores the checkpoint and trims the outputs after it. */
static int resume(const struct cli_scenario* sc, const struct cli_many_setup* su,
                  const struct cli_run_options* opt, const struct plan* pl, struct series* vtk)
{
    struct wetdem_many_stats s;
    int rc = restore(sc, su, opt, pl, &s);
    if (rc != CLI_EXIT_OK)
        return rc;
    struct writer w = find_writer(opt->out_dir, su, s.step);
    /* the index first: it refuses without touching a file, the CSV's trim rewrites one */
    rc = vtk ? series_resume(vtk, wetdem_sim_time(su->sim), s.step, pl->dt, w.vtk_every)
             : CLI_EXIT_OK;
    bool at_step = false;
    char path[PATH_CHARS + 8];
    snprintf(path, sizeof path, "%s.csv", pl->csv_prefix);
    /* a CSV the run that wrote the checkpoint did not write (csv = none there) starts here,
       as frames that run did not write do: the library writes it anew, header first (the
       checkpoint counts no rows), from the checkpoint's step on; there is nothing to trim */
    char was[CLI_VALUE_MAX];
    const char* note = wetdem_sim_checkpoint_note(su->sim);
    bool csv_starts = note && note_value(note, "csv", was, sizeof was) && strcmp(was, "none") == 0;
    if (rc == CLI_EXIT_OK && pl->csv_prefix[0] && !csv_starts)
        rc = csv_resume(path, wetdem_sim_time(su->sim), s.step, pl->dt, &w, opt->out_dir, &at_step);
    /* a row at the checkpoint's step on this run's grid that the CSV lacks (that run's grid
       was another): the uninterrupted run with this run's settings has it */
    if (rc == CLI_EXIT_OK && pl->csv_prefix[0] && !at_step && s.step % su->csv_every == 0 &&
        wetdem_sim_many_write_csv_row(su->sim) != WETDEM_OK) {
        cli_error("--restart: cannot append the row of step %llu to %s: %s", s.step, path,
                  wetdem_sim_errmsg(su->sim));
        rc = CLI_EXIT_RUNTIME;
    }
    return rc;
}

/* After the stepping: interrupted, failed or done (last frame, final checkpoint, summary). */
static int finish(const struct cli_scenario* sc, struct cli_many_setup* su,
                  const struct cli_run_options* opt, const struct plan* pl, struct progress* prog,
                  int st, double wall)
{
    if (prog->status != WETDEM_OK) {
        cli_error("run %s: writing a VTK frame: %s", sc->file, prog->vtk->error);
        return CLI_EXIT_RUNTIME;
    }
    if (st < 0) {
        cli_error("run %s: %s (%s)", sc->file, wetdem_sim_errmsg(su->sim), wetdem_status_name(st));
        return CLI_EXIT_RUNTIME;
    }
    /* (after the failures: a query refused, as the budget of a run without one, leaves its
       message in place of theirs) */
    struct outcome o = {.wall = wall, .interrupted = st == WETDEM_EVENT};
    if (many_stats(sc, su->sim, &o.stats) != CLI_EXIT_OK)
        return CLI_EXIT_RUNTIME;
    o.has_budget = wetdem_sim_energy_budget(su->sim, &o.budget) == WETDEM_OK;
    struct run_speeds v = speeds_of(&o.stats);
    warn_speed(sc, su, &v, prog->line.tty);
    if (csv_final_row(pl->csv_prefix, su->csv_every, su->sim, o.stats.step) != WETDEM_OK) {
        cli_error("run %s: cannot append the last row to %s.csv: %s", sc->file, pl->csv_prefix,
                  wetdem_sim_errmsg(su->sim));
        return CLI_EXIT_RUNTIME;
    }
    if (st == WETDEM_EVENT) {
        int sig = cli_stop_signal ? (int)cli_stop_signal : SIGINT;
        fprintf(stderr, "%swetdem: interrupted by %s at t = %.9g s (step %llu of %llu)",
                prog->line.tty ? "\n" : "", sig == SIGTERM ? "SIGTERM" : "SIGINT",
                wetdem_sim_time(su->sim), o.stats.step, pl->total);
        if (!pl->checkpoint[0])
            fprintf(stderr, "; no checkpoint (%s)\n",
                    opt->out_dir ? "[dump] checkpoint = none: the run cannot be resumed"
                                 : "run with --out DIR to keep one");
        else
            fprintf(stderr, "; checkpoint %s written\n", pl->checkpoint);
        write_summary(opt->out_dir, sc, su, opt, &o); /* ("interrupted": true) */
        if (opt->json)
            summary_json(stdout, sc, su, opt, &o);
        if (pl->checkpoint[0])
            print_resume(opt, pl->checkpoint);
        return 128 + sig;
    }
    if (prog->vtk && (prog->vtk->n == 0 || prog->vtk->last_step != o.stats.step) &&
        series_add(prog->vtk, su->sim, o.stats.step) != WETDEM_OK) {
        cli_error("run %s: writing the last VTK frame: %s", sc->file, prog->vtk->error);
        return CLI_EXIT_RUNTIME;
    }
    if (pl->checkpoint[0] && wetdem_sim_write_checkpoint(su->sim, pl->checkpoint) != WETDEM_OK) {
        cli_error("run %s: %s", sc->file, wetdem_sim_errmsg(su->sim));
        return CLI_EXIT_RUNTIME;
    }
    int rc = write_summary(opt->out_dir, sc, su, opt, &o);
    if (opt->json)
        summary_json(stdout, sc, su, opt, &o);
    else
        summary_text(stdout, su, &o);
    if (opt->out_dir && !opt->json && rc == CLI_EXIT_OK)
        printf("files in %s/\n", opt->out_dir);
    double ratio;
    if (budget_open(&o.budget, o.has_budget, &ratio) && rc == CLI_EXIT_OK) {
        cli_error("run %s: the energy budget does not close (error %.2g of the larger of input "
                  "and work, above %g): the step dt = %.4g s is too long for these contacts; "
                  "halve it ([integrator] dt_fraction, or dt in [run] or [integrator])",
                  sc->file, ratio, CLOSURE_LIMIT, o.stats.dt);
        rc = CLI_EXIT_RUNTIME;
    }
    return rc;
}

#define MAX_VTK_FRAMES 1e5 /* files in one directory, each N x 100 B or so */
#define MAX_CSV_ROWS 1e7   /* about 2 GB of global quantities */

/* Refuses output intervals that would flood --out: more than MAX_VTK_FRAMES VTK files or
 * MAX_CSV_ROWS CSV rows over the run (exit 2 at the interval's key). */
static int check_output_volume(const struct cli_scenario* sc, const struct cli_many_setup* su,
                               const struct plan* pl)
{
    const struct {
        bool on;
        unsigned long long every;
        double most;
        const char *key, *what, *off;
    } out[2] = {
        {su->vtk_prefix[0] && su->vtk_every, su->vtk_every, MAX_VTK_FRAMES, "vtk_every",
         "VTK files", "vtk = none"},
        {su->csv_name[0] && su->csv_every, su->csv_every, MAX_CSV_ROWS, "csv_every", "CSV rows",
         "csv = none"},
    };
    for (int k = 0; k < 2; k++) {
        double count = out[k].on ? (double)(pl->total / out[k].every) + 1 : 0;
        if (count <= out[k].most)
            continue;
        char text[300];
        snprintf(text, sizeof text,
                 "writes %.0f %s over the run's %llu steps, more than %.0f: raise %s, or set %s",
                 count, out[k].what, pl->total, out[k].most, out[k].key, out[k].off);
        const struct cli_entry* e = cli_scenario_find(sc, "dump", out[k].key);
        if (e)
            cli_scenario_error(sc, e, "%s", text);
        else /* (the default intervals give 51 frames and 501 rows) */
            cli_scenario_section_error(sc, "dump", "%s = %llu %s", out[k].key, out[k].every, text);
        return CLI_EXIT_USAGE;
    }
    return CLI_EXIT_OK;
}

/* The stepping from `step` to the run's end at pl->t_end (pl->total steps): an integrate call
 * up to each frame of the grid of vtk_every, the frame written when it returns (and the
 * speeds checked, warn_speed, until that warns once; the end checks them again), as it would
 * be at that step of one call (the library's outputs and checkpoints follow their own grid
 * of steps, and the motion is the same bit for bit over any calls: tests/test_many.c). A
 * call ends half a step before the frame's time, t + (n - 1/2) dt, which the library rounds
 * up to n steps. WETDEM status of the library; prog->status a frame's failure. */
static int run_steps(const struct cli_scenario* sc, struct cli_many_setup* su,
                     const struct plan* pl, struct series* vtk, struct progress* prog,
                     unsigned long long step)
{
    bool warned = false; /* about the speeds (warn_speed): at the first frame that shows it */
    cli_progress_start(&prog->line, (double)step / (double)pl->total);
    int st = WETDEM_OK;
    while (st == WETDEM_OK && prog->status == WETDEM_OK && step < pl->total) {
        unsigned long long next = pl->total;
        if (vtk && su->vtk_every && (step / su->vtk_every + 1) * su->vtk_every < pl->total)
            next = (step / su->vtk_every + 1) * su->vtk_every;
        double t_to = next == pl->total
                          ? pl->t_end
                          : wetdem_sim_time(su->sim) + ((double)(next - step) - 0.5) * pl->dt;
        prog->base_step = step;
        st = wetdem_sim_integrate(su->sim, t_to);
        if (st != WETDEM_OK)
            break;
        step = next;
        if (next < pl->total && series_add(vtk, su->sim, step) != WETDEM_OK) {
            prog->status = WETDEM_ERR_IO; /* the run stops there, resumable from its checkpoint */
            if (pl->checkpoint[0])
                st = wetdem_sim_write_checkpoint(su->sim, pl->checkpoint);
        }
        /* (pl->dt is the run's step, on whose grid these calls end: the start derives it
           again as the dry start did, and a restart refuses a checkpoint of another) */
        struct run_speeds v = {.dt = pl->dt};
        if (!warned && next < pl->total && prog->status == WETDEM_OK &&
            wetdem_sim_many_speeds(su->sim, &v.scale, &v.bound, &v.largest) == WETDEM_OK)
            warned = warn_speed(sc, su, &v, prog->line.tty);
    }
    return st;
}

/* Fresh start or restart, first frame, the stepping and the end. vtk: the frames this run
 * writes (NULL: none); named: the series named as its frames, or by the default name when it
 * writes none, whose files of an earlier run a fresh run removes (NULL without --out). */
static int run(const struct cli_scenario* sc, struct cli_many_setup* su,
               const struct cli_run_options* opt, struct plan* pl, struct series* vtk,
               const struct series* named)
{
    struct progress prog = {.sim = su->sim, .vtk = vtk, .run_total = pl->total};
    cli_progress_start(&prog.line, 0); /* (again when the stepping begins) */
    int rc = set_outputs(su, opt, pl, &prog);
    if (rc == CLI_EXIT_OK && opt->out_dir) {
        /* what a fresh run removes and writes (earlier_names, the frames as named), or what a
           restart writes: before any of it is touched, and before the restart trims the CSV */
        const char* names[3];
        earlier_names(su, names);
        if (opt->restart) {
            names[0] = su->summary_name[0] ? names[0] : NULL;
            names[1] = pl->csv_prefix[0] ? names[1] : NULL;
            names[2] = pl->checkpoint[0] ? names[2] : NULL;
        }
        rc = outputs_usable(opt->out_dir, opt->restart ? vtk : named, names);
    }
    if (rc == CLI_EXIT_OK && opt->restart)
        rc = resume(sc, su, opt, pl, vtk);
    if (rc != CLI_EXIT_OK)
        return rc;
    if (opt->out_dir && cli_make_dirs(opt->out_dir) != 0) {
        cli_error("run: cannot create directory %s: %s", opt->out_dir, strerror(errno));
        return CLI_EXIT_RUNTIME;
    }
    if (named && !opt->restart && series_clear(named) != 0) {
        cli_error("run: cannot remove the frames %s_NNNNNN.vtk of an earlier run in %s: %s",
                  named->prefix, named->dir, strerror(errno));
        return CLI_EXIT_RUNTIME;
    }
    if (opt->out_dir && !opt->restart && outputs_clear(opt->out_dir, su) != 0) {
        cli_error("run: cannot remove the summary, CSV or checkpoint of an earlier run in %s: %s",
                  opt->out_dir, strerror(errno));
        return CLI_EXIT_RUNTIME;
    }
    /* from the first output on, until every file is written: a signal asks for a stop */
    char notice[PATH_CHARS + 300], tmp[PATH_CHARS + 8] = "";
    if (pl->checkpoint[0])
        snprintf(tmp, sizeof tmp, "%s.tmp", pl->checkpoint);
    snprintf(notice, sizeof notice,
             "%swetdem: stopping after this step%s; a second signal %g s or more after this "
             "one, or a third, stops at once%s\n",
             prog.line.tty ? "\n" : "", pl->checkpoint[0] ? " to write the checkpoint" : "",
             CLI_SIGNAL_GRACE_S, pl->checkpoint[0] ? " without it" : "");
    struct cli_saved_signals saved;
    cli_signals_install(notice,
                        pl->checkpoint[0] ? "\nwetdem: stopped at once by a repeated signal, "
                                            "without a new checkpoint\n"
                                          : "\nwetdem: stopped at once by a repeated signal\n",
                        tmp, &saved);
    double t0 = omp_get_wtime();
    int st = opt->restart ? WETDEM_OK : wetdem_sim_integrate(su->sim, wetdem_sim_time(su->sim));
    struct wetdem_many_stats s = {0};
    if (st == WETDEM_OK) /* (a failed start keeps its message for finish) */
        st = wetdem_sim_many_stats(su->sim, &s);
    bool frame_due = vtk && su->vtk_every && s.step % su->vtk_every == 0 &&
                     !(vtk->n > 0 && vtk->last_step == s.step);
    if (st == WETDEM_OK && frame_due && series_add(vtk, su->sim, s.step) != WETDEM_OK)
        prog.status = WETDEM_ERR_IO;
    if (st == WETDEM_OK && prog.status == WETDEM_OK)
        st = run_steps(sc, su, pl, vtk, &prog, s.step);
    rc = finish(sc, su, opt, pl, &prog, st, omp_get_wtime() - t0);
    /* after a signal the handlers stay until the process exits: a duplicate arriving after the
       files are written would otherwise kill it, and turn exit 130 into death by signal */
    if (!cli_stop_signal)
        cli_signals_restore(&saved);
    return rc;
}

int cli_run_many(const struct cli_scenario* sc, const struct cli_run_options* opt)
{
    if (opt->sweep_row) {
        cli_error("%s: many-particle scenarios run with 'wetdem run', not sweeps", sc->file);
        return CLI_EXIT_USAGE;
    }
    struct cli_many_setup su;
    int rc = cli_many_build(sc, &su);
    if (rc != CLI_EXIT_OK)
        return rc;
    struct plan pl = {0};
    rc = dry_start(sc, &su, &pl);
    if (rc == CLI_EXIT_OK && opt->out_dir)
        rc = check_output_volume(sc, &su, &pl);
    if (rc == CLI_EXIT_OK && opt->check) { /* (with --restart: whether it can be continued) */
        struct wetdem_many_stats s;
        if (opt->restart)
            rc = restore(sc, &su, opt, &pl, &s);
        if (rc == CLI_EXIT_OK)
            rc = print_check(sc, &su, &pl, opt);
    } else if (rc == CLI_EXIT_OK) {
        struct series vtk = {.binary = su.vtk_binary, .links = su.vtk_links};
        bool has_vtk = opt->out_dir && su.vtk_prefix[0] && su.vtk_every;
        snprintf(vtk.dir, sizeof vtk.dir, "%s", opt->out_dir ? opt->out_dir : "");
        /* (without frames, those of an earlier run under the default name go too, as the
           summary, CSV and checkpoint do: outputs_clear) */
        snprintf(vtk.prefix, sizeof vtk.prefix, "%s",
                 su.vtk_prefix[0] ? su.vtk_prefix : "particles");
        rc = run(sc, &su, opt, &pl, has_vtk ? &vtk : NULL, opt->out_dir ? &vtk : NULL);
        free(vtk.times);
    }
    cli_many_setup_free(&su);
    return rc;
}

/*
 * harness.h — small helpers on top of cmocka for wetdem tests: relative/absolute comparisons
 * that print the test's numbers on failure, builders of two-sphere contacts, and running the
 * command-line tool end to end (its output read whole).
 */
#ifndef WETDEM_TEST_HARNESS_H
#define WETDEM_TEST_HARNESS_H

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <dirent.h>
#include <sys/types.h>
#include <sys/wait.h>

#include <cmocka.h>

#include "wetdem.h"

/* |a - b| <= tol * max(|a|, |b|), or both exactly zero. */
#define CHECK_REL(a, b, tol)                                                                       \
    do {                                                                                           \
        double a_ = (a), b_ = (b), t_ = (tol);                                                     \
        double s_ = fmax(fabs(a_), fabs(b_));                                                      \
        if (!(fabs(a_ - b_) <= t_ * s_) && !(a_ == b_))                                            \
            fail_msg("%s = %.17g vs %s = %.17g: relative difference %.3g > %.3g", #a, a_, #b, b_,  \
                     s_ > 0 ? fabs(a_ - b_) / s_ : 0.0, t_);                                       \
    } while (0)

#define CHECK_ABS(a, b, tol)                                                                       \
    do {                                                                                           \
        double a_ = (a), b_ = (b), t_ = (tol);                                                     \
        if (!(fabs(a_ - b_) <= t_))                                                                \
            fail_msg("%s = %.17g vs %s = %.17g: difference %.3g > %.3g", #a, a_, #b, b_,           \
                     fabs(a_ - b_), t_);                                                           \
    } while (0)

#define CHECK_STATUS(expr, want)                                                                   \
    do {                                                                                           \
        int st_ = (expr);                                                                          \
        if (st_ != (want))                                                                         \
            fail_msg("%s returned %s, expected %s", #expr, wetdem_status_name(st_),                \
                     wetdem_status_name(want));                                                    \
    } while (0)

#define CHECK_OK(expr) CHECK_STATUS(expr, WETDEM_OK)

/* Asserts that haystack contains needle. */
#define CHECK_CONTAINS(haystack, needle)                                                           \
    do {                                                                                           \
        const char* h_ = (haystack);                                                               \
        if (!h_ || !strstr(h_, (needle)))                                                          \
            fail_msg("'%s' does not contain '%s'", h_ ? h_ : "(null)", (needle));                  \
    } while (0)

/* Two spheres on the x axis: i at +x, j at the origin, so the normal (j to i) is +x.
 * gap [m], approach speed v_n [m/s] (> 0 approaching) given to i moving in -x. */
static inline struct wetdem_contact test_contact(double radius_i, double radius_j, double mass_i,
                                                 double mass_j, double gap, double v_n)
{
    struct wetdem_contact c;
    memset(&c, 0, sizeof c);
    c.i = 0;
    c.j = 1;
    c.normal = (struct wetdem_vec3){1, 0, 0};
    c.gap = gap;
    c.radius_i = radius_i;
    c.radius_j = radius_j;
    c.r_eff = radius_i * radius_j / (radius_i + radius_j);
    c.m_eff = mass_i * mass_j / (mass_i + mass_j);
    c.v_n = v_n;
    c.e_star = 100e9;
    c.g_star = 40e9;
    c.restitution = 0.9;
    c.friction_dry = 0.1;
    c.friction_lub = 0.02;
    c.roughness = 1e-6;
    c.film = 100e-6;
    c.viscosity = 1.0;
    c.surface_tension = 0.02;
    c.h_min = 1e-6;
    c.dt = 1e-7;
    return c;
}

/* A params block of `model` filled with its defaults (static storage, one per call site use). */
static inline void* test_default_params(const struct wetdem_model* model, void* storage)
{
    wetdem_param_init_defaults(model->params, storage);
    return storage;
}

/* Asserts that the particles of a and b have bit-identical positions, velocities and spins. */
static inline void test_check_same_particles(const struct wetdem_sim* a, const struct wetdem_sim* b)
{
    size_t na, nb;
    const struct wetdem_particle* pa = wetdem_sim_particles_const(a, &na);
    const struct wetdem_particle* pb = wetdem_sim_particles_const(b, &nb);
    assert_int_equal(na, nb);
    for (size_t k = 0; k < na; k++) {
        assert_memory_equal(&pa[k].pos, &pb[k].pos, sizeof pa[k].pos);
        assert_memory_equal(&pa[k].vel, &pb[k].vel, sizeof pa[k].vel);
        assert_memory_equal(&pa[k].omega, &pb[k].omega, sizeof pa[k].omega);
    }
}

/* ---- progress callbacks (wetdem_time_progress_fn) ---- */

/* What the progress calls of a run gave: their count, whether t and elapsed never decreased
 * (and elapsed was never negative), the t_end of every call (NAN when two differed) and the
 * last t. Call number stop_at (> 0) returns 1, which stops the run. */
struct test_progress_log {
    unsigned long calls, stop_at;
    bool monotone;
    double t_end, last_t, last_elapsed;
};

static inline int test_log_progress(double t, double t_end, double elapsed, void* ctx)
{
    struct test_progress_log* log = ctx;
    bool first = log->calls == 0;
    log->monotone =
        (first || (log->monotone && t >= log->last_t && elapsed >= log->last_elapsed)) &&
        elapsed >= 0;
    log->t_end = first || t_end == log->t_end ? t_end : NAN;
    log->last_t = t;
    log->last_elapsed = elapsed;
    log->calls++;
    return log->stop_at && log->calls == log->stop_at;
}

/* ---- the command-line tool ---- */

/* The soft glass-like material of the many-particle tests: 2500 kg/m^3, E = 10 MPa (a step of
 * microseconds), nu = 0.3, e_dry = 0.6, friction 0.4 dry and 0.1 lubricated, films `film` [m]. */
static inline struct wetdem_material test_soft_glass(double film)
{
    return (struct wetdem_material){.density = 2500,
                                    .youngs_modulus = 1e7,
                                    .poisson_ratio = 0.3,
                                    .restitution = 0.6,
                                    .friction_dry = 0.4,
                                    .friction_lub = 0.1,
                                    .film = film};
}

/* The small wet granular gas of several tests, set up in sim (the many-particle mode is the
 * caller's): n spheres of radius 0.4-0.5 mm at random (seed) in [0, side]^2 x [0, height], at
 * 0.2 m/s spread, periodic in x and y, a floor at z = 0, gravity; one material,
 * test_soft_glass(film), a fluid of 0.01 Pa s and 0.02 N/m, models hertz, mindlin, sb, capillary and `extra`
 * when not NULL. Returns the first status that is an error (the message in sim), or
 * WETDEM_OK. */
static inline int test_wet_gas(struct wetdem_sim* sim, size_t n, double side, double height,
                               double film, unsigned long seed, const char* extra)
{
    struct wetdem_material m = test_soft_glass(film);
    int st = wetdem_sim_add_material(sim, &m);
    struct wetdem_fluid f = {.viscosity = 0.01, .surface_tension = 0.02, .density = 1000};
    st = st < 0 ? st : wetdem_sim_set_fluid(sim, &f);
    const char* models[] = {"hertz", "mindlin", "sb", "capillary", extra};
    for (int k = 0; k < 5 && st >= 0 && models[k]; k++)
        st = wetdem_sim_enable_model(sim, models[k]);
    struct wetdem_insert_spec spec = {.layout = WETDEM_INSERT_RANDOM,
                                      .n = n,
                                      .lo = {0, 0, 0},
                                      .hi = {side, side, height},
                                      .periodic = {true, true, false},
                                      .radius_min = 0.4e-3,
                                      .radius_max = 0.5e-3,
                                      .velocity_sigma = 0.2,
                                      .seed = seed};
    st = st < 0 ? st : wetdem_sim_insert(sim, &spec);
    st = st < 0 ? st
                : wetdem_sim_add_wall(sim, (struct wetdem_vec3){0, 0, 0},
                                      (struct wetdem_vec3){0, 0, 1}, 0);
    st = st < 0 ? st : wetdem_sim_set_param(sim, "sim.gravity_z", -9.81);
    return st < 0 ? st : WETDEM_OK;
}

/* Path of the CLI: $WETDEM_CLI (set by `make test`), else build/wetdem relative to the
 * working directory (the repository root). */
static inline const char* test_cli_path(void)
{
    const char* p = getenv("WETDEM_CLI");
    return p && *p ? p : "build/wetdem";
}

/* Reads the rest of stream f into a NUL-terminated heap buffer (the caller frees it); *len,
 * if not NULL, receives its length in bytes. */
static inline char* test_slurp(FILE* f, size_t* len)
{
    size_t cap = 1 << 16, n = 0, got;
    char* buf = malloc(cap);
    assert_non_null(buf);
    while ((got = fread(buf + n, 1, cap - n - 1, f)) > 0) {
        n += got;
        if (n + 1 == cap) {
            cap *= 2;
            buf = realloc(buf, cap);
            assert_non_null(buf);
        }
    }
    buf[n] = '\0';
    if (len)
        *len = n;
    return buf;
}

/* Writes text to the file path (created or truncated). */
static inline void test_write_file(const char* path, const char* text)
{
    FILE* f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    assert_int_equal(fclose(f), 0);
}

/* The whole file at path as test_slurp gives it, or NULL (and *len 0) when it cannot be
 * opened. */
static inline char* test_read_file(const char* path, size_t* len)
{
    FILE* f = fopen(path, "rb");
    if (!f) {
        if (len)
            *len = 0;
        return NULL;
    }
    char* text = test_slurp(f, len);
    fclose(f);
    return text;
}

/* Output of one CLI run (heap buffer, the caller frees it) and its exit code (-1 if the
 * program did not exit normally). */
/* Whether bit sig of any of the masks named in `fields` ("SigPnd:", ...) of /proc/PID/status
 * is set. */
static inline bool test_proc_signal_bit(pid_t pid, const char* const* fields, int sig)
{
    char path[64], line[256];
    snprintf(path, sizeof path, "/proc/%d/status", (int)pid);
    FILE* f = fopen(path, "r");
    bool set = false;
    while (f && fgets(line, sizeof line, f))
        for (const char* const* field = fields; *field; field++) {
            size_t len = strlen(*field);
            unsigned long long mask;
            if (strncmp(line, *field, len) == 0 && sscanf(line + len, " %llx", &mask) == 1 &&
                (mask >> (sig - 1)) & 1u)
                set = true;
        }
    if (f)
        fclose(f);
    return set;
}

/* Whether signal sig is pending for process pid, not yet delivered (/proc/PID/status: SigPnd
 * for the thread, ShdPnd for the process): a second signal sent while the first is pending
 * merges with it, so a test of two signals waits for the first to be delivered. */
static inline bool test_signal_pending(pid_t pid, int sig)
{
    static const char* const fields[] = {"SigPnd:", "ShdPnd:", NULL};
    return test_proc_signal_bit(pid, fields, sig);
}

/* Whether process pid has a handler of signal sig installed (/proc/PID/status: SigCgt). A test
 * that interrupts a command waits for it: a signal sent before the handler is in place (a slow
 * start, as under the sanitizers) kills the process instead of testing the handler. */
static inline bool test_signal_caught(pid_t pid, int sig)
{
    static const char* const fields[] = {"SigCgt:", NULL};
    return test_proc_signal_bit(pid, fields, sig);
}

struct test_run {
    char* out;
    int code;
};

/* Runs the shell command line "ENV '<CLI>' ARGS" (env may be ""): stdout, and stderr merged
 * into it when with_stderr (discarded otherwise). */
static inline struct test_run test_run_cli(const char* env, const char* args, bool with_stderr)
{
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "%s '%s' %s %s", env, test_cli_path(), args,
             with_stderr ? "2>&1" : "2>/dev/null");
    FILE* p = popen(cmd, "r");
    if (!p)
        fail_msg("popen failed for: %s", cmd);
    char* out = test_slurp(p, NULL);
    int status = pclose(p);
    return (struct test_run){out, WIFEXITED(status) ? WEXITSTATUS(status) : -1};
}

/* What the shell command line "'<CLI>' ARGS" writes to a terminal, which script(1) gives it
 * (stdout and stderr both, unless ARGS redirects one: "... > /dev/null" leaves stderr alone).
 * A heap buffer, the caller frees it. */
static inline char* test_run_cli_on_terminal(const char* args)
{
    size_t n = strlen(test_cli_path()) + strlen(args) + 64;
    char* cmd = malloc(n);
    assert_non_null(cmd);
    snprintf(cmd, n, "script -qec \"'%s' %s\" /dev/null", test_cli_path(), args);
    FILE* p = popen(cmd, "r");
    assert_non_null(p);
    char* out = test_slurp(p, NULL);
    pclose(p);
    free(cmd);
    return out;
}

/* test_run_cli("", args, true) with the output copied into out (n bytes, truncated). Returns
 * the exit code. */
static inline int test_run_cli_into(const char* args, char* out, size_t n)
{
    struct test_run r = test_run_cli("", args, true);
    snprintf(out, n, "%s", r.out);
    free(r.out);
    return r.code;
}

/* Shell commands put before the CLI (test_run_cli's env) to make writing a file fail midway:
 * a file size limit of 1024 bytes (2 blocks of 512 for /bin/sh's ulimit; 2048 bytes with
 * bash's 1024-byte blocks), whose signal SIGXFSZ is ignored so that the write fails with
 * EFBIG instead of killing the program. Pipes (the output tests read) have no such limit. */
#define TEST_FILE_SIZE_LIMIT "trap '' XFSZ; ulimit -f 2;"

/* Takes the field "command": [...] (the command line, which differs between runs that are
 * otherwise the same) out of a summary's JSON text in place, with the separator before it;
 * true if there was one. The arguments must hold no ']'. */
static inline bool test_drop_json_command(char* json)
{
    char* at = strstr(json, "\"command\": [\"wetdem\"");
    char* end = at ? strchr(at, ']') : NULL;
    if (!end)
        return false;
    while (at > json && (at[-1] == ' ' || at[-1] == '\n'))
        at--;
    if (at > json && at[-1] == ',')
        at--;
    memmove(at, end + 1, strlen(end + 1) + 1);
    return true;
}

/* The names in directory dir, hidden ones included (not "." and ".."), each followed by a
 * newline, sorted, in a heap buffer (the caller frees it); "" for an empty directory and NULL
 * when dir cannot be opened (e.g. it does not exist). */
static inline char* test_list_dir(const char* dir)
{
    struct dirent** names = NULL;
    int n = scandir(dir, &names, NULL, alphasort);
    if (n < 0)
        return NULL;
    size_t len = 1;
    for (int k = 0; k < n; k++)
        len += strlen(names[k]->d_name) + 1;
    char* out = malloc(len);
    assert_non_null(out);
    out[0] = '\0';
    for (int k = 0; k < n; k++) {
        if (strcmp(names[k]->d_name, ".") && strcmp(names[k]->d_name, "..")) {
            strcat(out, names[k]->d_name);
            strcat(out, "\n");
        }
        free(names[k]);
    }
    free(names);
    return out;
}

/* Asserts that directory dir holds exactly the names in `want` ("a\nb\n": sorted, each
 * followed by a newline; "" for none): no half-written file, no temporary file left. */
static inline void test_check_dir(const char* dir, const char* want)
{
    char* got = test_list_dir(dir);
    if (!got || strcmp(got, want) != 0)
        fail_msg("directory %s holds\n%s\nexpected\n%s", dir, got ? got : "(no directory)\n", want);
    free(got);
}

/* Runs the CLI with ARGS under TEST_FILE_SIZE_LIMIT and asserts that it exits 1 with
 * "<cmd>: cannot write <path>: File too large" and that directory dir then holds exactly
 * `want` (test_check_dir): a write that fails midway leaves no cut-off or temporary file. */
static inline void test_check_write_fails(const char* args, const char* cmd, const char* path,
                                          const char* dir, const char* want)
{
    struct test_run r = test_run_cli(TEST_FILE_SIZE_LIMIT, args, true);
    if (r.code != 1)
        fail_msg("wetdem %s: exit %d, expected 1\n%s", args, r.code, r.out);
    char needle[1100];
    snprintf(needle, sizeof needle, "%s: cannot write %s: File too large", cmd, path);
    test_check_dir(dir, want);
    CHECK_CONTAINS(r.out, needle);
    free(r.out);
}

#endif

/*
 * test_concurrency.c — distinct objects used at once from several threads (the guarantee in
 * wetdem.h's top comment): soft collisions (CVODE and Verlet), pairwise runs, fits, tracks and
 * a small many-particle run (whose own OpenMP loops then run inside each thread) on four
 * pthreads give results bit-identical to the same runs done one after the other; and fits that
 * overlap in time keep GSL's process-wide error handler switched off until the last of them
 * ends, then give the caller's back.
 *
 * cmocka is not thread-safe: the worker threads only record statuses and results, and the main
 * thread checks them.
 */
#include <omp.h>
#include <pthread.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>

#include "harness.h"
#include "many.h"

#define N_THREADS 4
#define OUT_MAX 32768 /* bytes of one job's result */

enum job_kind {
    COLLISION_CVODE,
    COLLISION_VERLET,
    PAIRWISE,
    FIT,
    FIT_SIMULATED,
    TRACK,
    MANY,
    N_KINDS
};

static const char* const kind_names[N_KINDS] = {"collision (cvode)",
                                                "collision (verlet)",
                                                "pairwise",
                                                "fit",
                                                "fit (simulated)",
                                                "track",
                                                "many"};

struct job {
    enum job_kind kind;
    int variant; /* changes the inputs a little, so that jobs differ */
    int status;  /* WETDEM_OK, or what failed */
    size_t size; /* bytes of out used */
    unsigned char out[OUT_MAX];
};

static void put(struct job* j, const void* data, size_t n)
{
    if (j->size + n > OUT_MAX) {
        j->status = WETDEM_ERR_NOMEM;
        return;
    }
    memcpy(j->out + j->size, data, n);
    j->size += n;
}

/* ---- the runs (no cmocka calls: they run on the worker threads) ---- */

/* A Punch set-up (Hertz, DB, glass h_min) or, for Verlet, Hertz + Mindlin + SB + capillary;
 * NULL if a step failed. */
static struct wetdem_sim* collision_sim(const char* integrator)
{
    struct wetdem_sim* sim = wetdem_sim_create();
    struct wetdem_fluid f;
    int st = sim ? wetdem_fluid_preset("silicone10", &f) : WETDEM_ERR_NOMEM;
    st = st == WETDEM_OK ? wetdem_sim_set_fluid(sim, &f) : st;
    bool verlet = strcmp(integrator, "verlet") == 0;
    const char* models[] = {"hertz", verlet ? "mindlin" : "db", verlet ? "sb" : "glass",
                            verlet ? "capillary" : NULL};
    if (st == WETDEM_OK && wetdem_sim_add_material_preset(sim, "punch_steel") != 0)
        st = WETDEM_ERR_INVALID;
    if (st == WETDEM_OK && wetdem_sim_add_material_preset(sim, "punch_steel_coated") != 1)
        st = WETDEM_ERR_INVALID;
    for (int k = 0; k < 4 && st == WETDEM_OK && models[k]; k++)
        st = wetdem_sim_enable_model(sim, models[k]);
    if (st == WETDEM_OK && !verlet)
        st = wetdem_sim_set_param_str(sim, "db.below_hmin", "c");
    if (st == WETDEM_OK)
        st = wetdem_sim_set_integrator(sim, integrator);
    if (st != WETDEM_OK) {
        wetdem_sim_free(sim);
        return NULL;
    }
    return sim;
}

static struct wetdem_collision_spec collision_spec(double stokes, double angle)
{
    return (struct wetdem_collision_spec){.material_i = 0,
                                          .material_j = 1,
                                          .radius_i = 12.7e-3,
                                          .radius_j = 12.7e-3,
                                          .stokes = stokes,
                                          .angle = angle,
                                          .t_end = 0.05};
}

/* The set-ups of the collisions, built before the threads start; each run clones one (several
 * threads at once may clone a simulation that none changes). */
static struct wetdem_sim* templates[2]; /* cvode, verlet */

static void run_collision(struct job* j, const char* integrator)
{
    bool verlet = strcmp(integrator, "verlet") == 0;
    struct wetdem_sim* sim = wetdem_sim_clone(templates[verlet]);
    struct wetdem_collision_spec spec =
        collision_spec((verlet ? 30.0 : 3.0) + j->variant, verlet ? 0.3 : 0);
    struct wetdem_collision_result res;
    memset(&res, 0, sizeof res);
    j->status = sim ? wetdem_collision_run(sim, &spec, &res) : WETDEM_ERR_INVALID;
    put(j, &res, sizeof res);
    wetdem_sim_free(sim);
}

/* Three spheres of Davis Table I, with its impulses, films and capillary suction. */
static void run_pairwise(struct job* j)
{
    struct wetdem_pairwise_davis d;
    wetdem_pairwise_davis_init(&d);
    d.n_spheres = 3;
    d.stokes = 10 + 5 * j->variant;
    d.capillary = 1;
    d.angle_deg = 20;
    d.t_star_end = 2;
    struct wetdem_pairwise_config cfg;
    struct wetdem_pairwise* pw = wetdem_pairwise_create();
    int st = pw ? wetdem_pairwise_davis_config(&d, &cfg, NULL, 0) : WETDEM_ERR_NOMEM;
    struct wetdem_pairwise_result* res = calloc(1, sizeof *res);
    if (!res)
        st = WETDEM_ERR_NOMEM;
    if (st == WETDEM_OK)
        st = wetdem_pairwise_run(pw, &cfg, res);
    size_t n_ev = 0;
    const struct wetdem_pairwise_event* ev =
        st == WETDEM_OK ? wetdem_pairwise_events(pw, &n_ev) : NULL;
    if (res) {
        put(j, &res->final, sizeof res->final);
        put(j, &res->pairs, res->n_pairs * sizeof res->pairs[0]);
        put(j, &res->energy, sizeof res->energy);
        put(j, &res->time, sizeof res->time);
    }
    for (size_t k = 0; k < n_ev; k++)
        put(j, &ev[k].time, sizeof ev[k].time);
    j->status = j->status != WETDEM_OK ? j->status : st;
    free(res);
    wetdem_pairwise_free(pw);
}

/* e(St) = e_dry exp(-St_c/St) (test_fit.c) to fixed data, e_dry bounded by 1. */
struct curve {
    double stokes[10], obs[10];
};

static int curve_model(const double* p, double* out, char* msg, size_t n_msg, void* ctx)
{
    (void)msg;
    (void)n_msg;
    const struct curve* c = ctx;
    for (size_t i = 0; i < 10; i++)
        out[i] = p[0] * exp(-p[1] / c->stokes[i]);
    return WETDEM_OK;
}

static void run_fit(struct job* j)
{
    struct curve c;
    for (int i = 0; i < 10; i++) {
        c.stokes[i] = 1.5 + 3 * i;
        c.obs[i] = 0.9 * exp(-(2.0 + 0.1 * j->variant) / c.stokes[i]) + 0.01 * sin(7.0 * i);
    }
    const double init[2] = {0.5, 1.0}, lower[2] = {0, 0}, upper[2] = {1, INFINITY};
    struct wetdem_fit_problem pb = {.n_params = 2,
                                    .initial = init,
                                    .n_data = 10,
                                    .observed = c.obs,
                                    .model = curve_model,
                                    .ctx = &c,
                                    .lower = lower,
                                    .upper = upper};
    struct wetdem_fit_options o;
    wetdem_fit_options_init(&o);
    o.fd_step = 1e-5;
    struct wetdem_fit_result r;
    double pred[10];
    char msg[256];
    j->status = wetdem_fit_run(&pb, &o, &r, pred, msg, sizeof msg);
    put(j, &r, sizeof r);
    put(j, pred, sizeof pred);
}

/* The glass-transition pressure from restitutions the same set-up simulated (test_fit.c): a
 * fit whose model runs CVODE collisions. */
struct punch {
    struct wetdem_sim* sim;
    double stokes[4];
};

static int punch_model(const double* p, double* out, char* msg, size_t n, void* ctx)
{
    struct punch* d = ctx;
    int st = wetdem_sim_set_param(d->sim, "glass.p_gt", p[0]);
    for (size_t i = 0; st == WETDEM_OK && i < 4; i++) {
        struct wetdem_collision_spec spec = collision_spec(d->stokes[i], 0);
        struct wetdem_collision_result res;
        st = wetdem_collision_run(d->sim, &spec, &res);
        out[i] = res.e_n;
    }
    if (st != WETDEM_OK)
        snprintf(msg, n, "%s", wetdem_sim_errmsg(d->sim));
    return st;
}

static void run_fit_simulated(struct job* j)
{
    struct punch d = {collision_sim("cvode"), {2.0, 2.5, 3.0, 4.0}};
    const double obs[4] = {0.12, 0.33, 0.45 + 0.01 * j->variant, 0.6}, init[1] = {4e6};
    struct wetdem_fit_problem pb = {.n_params = 1,
                                    .initial = init,
                                    .n_data = 4,
                                    .observed = obs,
                                    .model = punch_model,
                                    .ctx = &d};
    struct wetdem_fit_options o;
    wetdem_fit_options_init(&o);
    struct wetdem_fit_result r;
    double pred[4];
    char msg[256];
    j->status = d.sim ? wetdem_fit_run(&pb, &o, &r, pred, msg, sizeof msg) : WETDEM_ERR_INVALID;
    put(j, &r, sizeof r);
    put(j, pred, sizeof pred);
    wetdem_sim_free(d.sim);
}

/* Two spheres, three dots each [pixel], the striker hitting the target at frame 60; a
 * deterministic ripple stands for the tracking noise. */
static void run_track(struct job* j)
{
    struct wetdem_track* t = wetdem_track_create();
    int st = t ? WETDEM_OK : WETDEM_ERR_NOMEM;
    for (int s = 0; s < 2 && st == WETDEM_OK; s++)
        for (long f = 0; f < 120 && st == WETDEM_OK; f++) {
            double after = f > 60 ? (double)(f - 60) : 0, before = (double)f - after;
            double x = s == 0 ? 2.0 * before + (0.6 + 0.1 * j->variant) * after : 200 + 1.3 * after;
            double y = 100 + (s == 0 ? 0.2 * after : -0.3 * after);
            double phi = s == 0 ? 0.01 * before + 0.05 * after : -0.04 * after;
            double xy[6] = {x, y, 0, 0, 0, 0};
            for (int d = 1; d < 3; d++) {
                xy[2 * d] = x + 30 * cos(phi + 0.8 * d) + 0.05 * sin(3.1 * (double)f + d + s);
                xy[2 * d + 1] = y + 30 * sin(phi + 0.8 * d) + 0.05 * cos(2.3 * (double)f + d);
            }
            st = wetdem_track_add_frame(t, s, f, xy);
        }
    struct wetdem_track_options o;
    wetdem_track_options_init(&o);
    o.fps = 5000;
    o.pixel_size = 175e-6;
    struct wetdem_track_summary sum;
    memset(&sum, 0, sizeof sum);
    if (st == WETDEM_OK)
        st = wetdem_track_analyse(t, &o, &sum);
    put(j, &sum, sizeof sum);
    for (size_t k = 0; st == WETDEM_OK && k < 2; k++) {
        size_t n;
        const struct wetdem_track_sample* smp = wetdem_track_samples(t, k, &n);
        put(j, smp, n * sizeof *smp);
    }
    j->status = j->status != WETDEM_OK ? j->status : st;
    wetdem_track_free(t);
}

/* 64 wet spheres in a box periodic in x and y, 300 steps, the parallel loops on even for so
 * few particles: the run's own OpenMP regions start inside the calling thread. */
static void run_many(struct job* j)
{
    struct wetdem_sim* sim = wetdem_sim_create();
    int st = sim ? test_wet_gas(sim, 64, 4e-3, 6e-3, 20e-6, 7 + (unsigned long)j->variant, NULL)
                 : WETDEM_ERR_NOMEM;
    struct wetdem_many_settings s = {.periodic = {true, true, false},
                                     .box_lo = {0, 0, 0},
                                     .box_hi = {4e-3, 4e-3, 6e-3},
                                     .dt = 2e-6,
                                     .skin = 0.05e-3,
                                     .energy_budget = true};
    if (st == WETDEM_OK)
        st = wetdem_sim_set_many(sim, &s);
    if (st == WETDEM_OK) {
        sim->many->parallel_min = 1;
        st = wetdem_sim_integrate(sim, 300 * 2e-6);
    }
    size_t n = 0;
    const struct wetdem_particle* p = st == WETDEM_OK ? wetdem_sim_particles_const(sim, &n) : NULL;
    for (size_t k = 0; k < n; k++) {
        put(j, &p[k].pos, sizeof p[k].pos);
        put(j, &p[k].vel, sizeof p[k].vel);
        put(j, &p[k].omega, sizeof p[k].omega);
    }
    struct wetdem_energy_budget e;
    memset(&e, 0, sizeof e);
    if (st == WETDEM_OK)
        st = wetdem_sim_energy_budget(sim, &e);
    put(j, &e, sizeof e);
    j->status = j->status != WETDEM_OK ? j->status : st;
    wetdem_sim_free(sim);
}

static void run_job(struct job* j)
{
    j->status = WETDEM_OK;
    j->size = 0;
    memset(j->out, 0, sizeof j->out);
    switch (j->kind) {
    case COLLISION_CVODE: run_collision(j, "cvode"); break;
    case COLLISION_VERLET: run_collision(j, "verlet"); break;
    case PAIRWISE: run_pairwise(j); break;
    case FIT: run_fit(j); break;
    case FIT_SIMULATED: run_fit_simulated(j); break;
    case TRACK: run_track(j); break;
    case MANY: run_many(j); break;
    default: j->status = WETDEM_ERR_INVALID;
    }
}

/* ---- every kind at once on four threads ---- */

#define N_JOBS (3 * N_KINDS)

struct worker {
    struct job* jobs;
    int first; /* runs jobs first, first + N_THREADS, ... */
};

static void* work(void* arg)
{
    struct worker* w = arg;
    /* One OpenMP thread for the library's loops in all but the first thread (whose jobs include
     * a many-particle run, on the default team): OpenMP teams in each of four threads would
     * oversubscribe the cores, and libgomp's spinning barriers then wait for threads the system
     * has put aside (runs many times slower). The setting is the calling thread's own
     * (docs/concepts.md). */
    if (w->first != 0)
        omp_set_num_threads(1);
    for (int k = w->first; k < N_JOBS; k += N_THREADS)
        run_job(&w->jobs[k]);
    return NULL;
}

static void test_concurrent_runs_match_serial_bit_for_bit(void** state)
{
    (void)state;
    templates[0] = collision_sim("cvode");
    templates[1] = collision_sim("verlet");
    assert_non_null(templates[0]);
    assert_non_null(templates[1]);
    struct job* serial = calloc(N_JOBS, sizeof *serial);
    struct job* parallel = calloc(N_JOBS, sizeof *parallel);
    assert_non_null(serial);
    assert_non_null(parallel);
    for (int k = 0; k < N_JOBS; k++) {
        serial[k].kind = parallel[k].kind = (enum job_kind)(k % N_KINDS);
        serial[k].variant = parallel[k].variant = k / N_KINDS;
        run_job(&serial[k]);
        if (serial[k].status != WETDEM_OK)
            fail_msg("%s (variant %d), serial: %s", kind_names[serial[k].kind], serial[k].variant,
                     wetdem_status_name(serial[k].status));
    }
    pthread_t tid[N_THREADS];
    struct worker w[N_THREADS];
    for (int t = 0; t < N_THREADS; t++) {
        w[t] = (struct worker){parallel, t};
        assert_int_equal(pthread_create(&tid[t], NULL, work, &w[t]), 0);
    }
    for (int t = 0; t < N_THREADS; t++)
        assert_int_equal(pthread_join(tid[t], NULL), 0);
    for (int k = 0; k < N_JOBS; k++) {
        const struct job *a = &serial[k], *b = &parallel[k];
        if (b->status != WETDEM_OK || a->size != b->size || memcmp(a->out, b->out, a->size) != 0)
            fail_msg("%s (variant %d) on a thread: status %s, %zu bytes, %s the serial run's",
                     kind_names[a->kind], a->variant, wetdem_status_name(b->status), b->size,
                     a->size == b->size && memcmp(a->out, b->out, a->size) == 0 ? "equal to"
                                                                                : "unlike");
    }
    free(serial);
    free(parallel);
    wetdem_sim_free(templates[0]);
    wetdem_sim_free(templates[1]);
}

/* ---- fits that overlap in time and GSL's error handler ----
 * Fit k starts while fits 0..k-1 are still running (each waits in its first model call), and
 * they end in the order they started, so the first fit to end is not the last. In each model
 * call a probe raises a GSL error: it must reach no handler while any fit runs, and the
 * caller's handler must be back after the last. */

static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t changed = PTHREAD_COND_INITIALIZER;
/* (under lock) fits that have made their first model call, fits let go on from it, fits
   returned, calls of the caller's handler */
static int entered, released, finished, caller_calls;

static void caller_handler(const char* reason, const char* file, int line, int gsl_errno)
{
    (void)reason;
    (void)file;
    (void)line;
    (void)gsl_errno;
    pthread_mutex_lock(&lock);
    caller_calls++;
    pthread_mutex_unlock(&lock);
}

struct gate_ctx {
    int index;
    bool first_call;
    int status; /* of the fit */
    struct curve c;
};

static int gated_model(const double* p, double* out, char* msg, size_t n_msg, void* ctx)
{
    struct gate_ctx* g = ctx;
    if (g->first_call) {
        g->first_call = false;
        pthread_mutex_lock(&lock);
        entered = g->index + 1;
        pthread_cond_broadcast(&changed);
        while (released <= g->index)
            pthread_cond_wait(&changed, &lock);
        pthread_mutex_unlock(&lock);
    }
    gsl_error("probe", __FILE__, __LINE__, GSL_EFAILED);
    return curve_model(p, out, msg, n_msg, &g->c);
}

static void* gated_fit(void* arg)
{
    struct gate_ctx* g = arg;
    for (int i = 0; i < 10; i++) {
        g->c.stokes[i] = 1.5 + 3 * i;
        g->c.obs[i] = 0.9 * exp(-2.0 / g->c.stokes[i]) + 0.01 * sin(7.0 * i);
    }
    const double init[2] = {0.5, 1.0};
    struct wetdem_fit_problem pb = {.n_params = 2,
                                    .initial = init,
                                    .n_data = 10,
                                    .observed = g->c.obs,
                                    .model = gated_model,
                                    .ctx = g};
    struct wetdem_fit_options o;
    wetdem_fit_options_init(&o);
    struct wetdem_fit_result r;
    g->status = wetdem_fit_run(&pb, &o, &r, NULL, NULL, 0);
    pthread_mutex_lock(&lock);
    finished++;
    pthread_cond_broadcast(&changed);
    pthread_mutex_unlock(&lock);
    return NULL;
}

static void test_overlapping_fits_keep_the_caller_gsl_handler(void** state)
{
    (void)state;
    gsl_error_handler_t* before = gsl_set_error_handler(&caller_handler);
    pthread_t tid[N_THREADS];
    struct gate_ctx g[N_THREADS];
    for (int t = 0; t < N_THREADS; t++) {
        g[t] = (struct gate_ctx){.index = t, .first_call = true};
        assert_int_equal(pthread_create(&tid[t], NULL, gated_fit, &g[t]), 0);
        pthread_mutex_lock(&lock);
        while (entered <= t)
            pthread_cond_wait(&changed, &lock);
        pthread_mutex_unlock(&lock);
    }
    for (int t = 0; t < N_THREADS; t++) {
        pthread_mutex_lock(&lock);
        released = t + 1;
        pthread_cond_broadcast(&changed);
        while (finished <= t)
            pthread_cond_wait(&changed, &lock);
        pthread_mutex_unlock(&lock);
        assert_int_equal(pthread_join(tid[t], NULL), 0);
    }
    gsl_error_handler_t* after = gsl_set_error_handler(before);
    for (int t = 0; t < N_THREADS; t++)
        if (g[t].status != WETDEM_OK)
            fail_msg("fit %d: %s", t, wetdem_status_name(g[t].status));
    if (caller_calls != 0)
        fail_msg("the caller's GSL handler was called %d times while fits ran", caller_calls);
    assert_ptr_equal(after, &caller_handler);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_concurrent_runs_match_serial_bit_for_bit),
        cmocka_unit_test(test_overlapping_fits_keep_the_caller_gsl_handler),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

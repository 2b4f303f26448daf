/*
 * test_alloc_failure.c — behaviour when memory runs out. The test is linked with --wrap for
 * malloc, calloc, realloc, strdup and free and for the constructors of SUNDIALS and GSL objects
 * the library calls (Makefile, ALLOC_WRAP), so every allocation the library makes passes
 * through the wrappers below, which fail the N-th one: an allocator returns NULL, a SUNDIALS
 * constructor NULL or its memory-failure flag, a GSL one NULL after calling GSL's error handler
 * as GSL does (its default handler aborts). Each path (sim set-up and pair force, soft
 * collisions with CVODE and Verlet, a pairwise run, a small many-particle run with outputs and
 * a checkpoint written and read back, a fit, a track analysis) runs for N = 1, 2, ... until it
 * makes fewer than N allocations; for every N where one failed the path must stop with
 * WETDEM_ERR_NOMEM (or NULL from a create function) and a message, every object must still be
 * freeable, and every block the library allocated must be freed again (the wrappers keep the
 * set of live blocks, so a leak shows without a leak checker). SUNDIALS and GSL are shared
 * libraries: the allocations inside them do not pass through the wrappers, only the library's
 * own and its calls of their constructors.
 */
#include <dirent.h>
#include <omp.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "alloc_fallible.h" /* the wrappers' declarations, the SUNDIALS and GSL ones */
#include "harness.h"

/* ---- the failing allocator ---------------------------------------------------------------- */

static atomic_bool alloc_tracking; /* record live blocks (between arm() and disarm()) */

/* Live blocks allocated while tracking: an open-addressing set of pointers (the runs here hold
 * a few thousand at most). */
#define LIVE_CAP (1u << 16)
static void* live[LIVE_CAP];
static size_t live_n;
static void* const live_tomb = &live_n; /* a deleted slot */

static size_t live_hash(const void* p)
{
    return (size_t)(((uintptr_t)p >> 4) * 0x9E3779B97F4A7C15ull) & (LIVE_CAP - 1);
}

static void live_add(void* p)
{
    if (!p || !atomic_load(&alloc_tracking))
        return;
    size_t k = live_hash(p);
    while (live[k] && live[k] != live_tomb)
        k = (k + 1) & (LIVE_CAP - 1);
    live[k] = p;
    if (++live_n > LIVE_CAP / 2)
        abort(); /* the set is full: not expected of these small runs */
}

static void live_remove(void* p)
{
    if (!p)
        return;
    for (size_t k = live_hash(p); live[k]; k = (k + 1) & (LIVE_CAP - 1))
        if (live[k] == p) {
            live[k] = live_tomb;
            live_n--;
            return;
        }
}

void* __wrap_malloc(size_t size)
{
    if (inject())
        return NULL;
    void* p = __real_malloc(size);
    live_add(p);
    return p;
}

void* __wrap_calloc(size_t n, size_t size)
{
    if (inject())
        return NULL;
    void* p = __real_calloc(n, size);
    live_add(p);
    return p;
}

void* __wrap_realloc(void* p, size_t size)
{
    if (inject())
        return NULL;
    void* q = __real_realloc(p, size);
    if (q) {
        live_remove(p);
        live_add(q);
    }
    return q;
}

char* __wrap_strdup(const char* s)
{
    if (inject())
        return NULL;
    char* p = __real_strdup(s);
    live_add(p);
    return p;
}

void __wrap_free(void* p)
{
    live_remove(p);
    __real_free(p);
}

/* Starts counting allocations and fails the n-th (none for n = 0). */
static void arm(long n)
{
    memset(live, 0, sizeof live);
    live_n = 0;
    atomic_store(&alloc_count, 0);
    atomic_store(&alloc_failed, false);
    alloc_fail_at = n;
    atomic_store(&alloc_tracking, true);
}

/* Stops failing and tracking; returns the blocks still live. */
static size_t disarm(void)
{
    alloc_fail_at = 0;
    atomic_store(&alloc_tracking, false);
    return live_n;
}

/* ---- the sweep ------------------------------------------------------------------------------ */

/* What a path reports: its status (WETDEM_OK when every step succeeded) and the message of the
 * step that failed. */
struct outcome {
    int status;
    char msg[512];
};

typedef void (*path_fn)(struct outcome* out);

/* Stops the path at a failing step: records status and message and jumps to its clean-up. */
#define STEP(out, expr, errmsg)                                                                    \
    do {                                                                                           \
        int st_ = (expr);                                                                          \
        if (st_ < 0) {                                                                             \
            (out)->status = st_;                                                                   \
            snprintf((out)->msg, sizeof(out)->msg, "%s: %s", #expr, (errmsg));                     \
            goto done;                                                                             \
        }                                                                                          \
    } while (0)

/* A create function that returned NULL: out of memory, the message is the function's name. */
#define CREATED(out, ptr)                                                                          \
    do {                                                                                           \
        if (!(ptr)) {                                                                              \
            (out)->status = WETDEM_ERR_NOMEM;                                                      \
            snprintf((out)->msg, sizeof(out)->msg, "%s: NULL from its create function", #ptr);     \
            goto done;                                                                             \
        }                                                                                          \
    } while (0)

/* Runs fn with the n-th allocation failed for n = 1, 2, ... until a run makes fewer than n
 * allocations, which must succeed; every run with a failed allocation must report
 * WETDEM_ERR_NOMEM with a message, and no run may leave a block allocated. Returns the number
 * of allocation points seen. */
static long sweep(const char* name, path_fn fn)
{
    struct outcome ref = {0};
    arm(0);
    fn(&ref);
    size_t leaked = disarm();
    if (ref.status < 0)
        fail_msg("%s without failures: %s (%s)", name, wetdem_status_name(ref.status), ref.msg);
    if (leaked)
        fail_msg("%s without failures: %zu blocks not freed", name, leaked);
    long total = atomic_load(&alloc_count);
    for (long n = 1;; n++) {
        struct outcome out = {0};
        arm(n);
        fn(&out);
        leaked = disarm();
        bool failed = atomic_load(&alloc_failed);
        if (leaked)
            fail_msg("%s, allocation %ld failed: %zu blocks not freed (%s: %s)", name, n, leaked,
                     wetdem_status_name(out.status), out.msg);
        if (!failed) {
            if (out.status < 0)
                fail_msg("%s: failed without a failed allocation: %s", name, out.msg);
            break;
        }
        if (out.status != WETDEM_ERR_NOMEM)
            fail_msg("%s, allocation %ld failed: status %s, expected WETDEM_ERR_NOMEM (%s)", name,
                     n, wetdem_status_name(out.status), out.msg);
        const char* colon = strstr(out.msg, ": ");
        if (!colon || !colon[2])
            fail_msg("%s, allocation %ld failed: no message (%s)", name, n, out.msg);
    }
    if (getenv("WETDEM_ALLOC_VERBOSE"))
        print_message("%s: %ld allocations\n", name, total);
    return total;
}

/* ---- the paths ------------------------------------------------------------------------------ */

/* A custom force model: a linear spring in the overlap. */
struct spring_params {
    double k;
};
static const struct wetdem_param_desc spring_desc[] = {{"k", "N/m", "stiffness",
                                                        offsetof(struct spring_params, k), 1e3, 0,
                                                        1e12, false, false, NULL, false},
                                                       {0}};
static double spring_range(const void* params, const struct wetdem_contact* c)
{
    (void)params;
    (void)c;
    return 0;
}
static int spring_pair(const void* params, const struct wetdem_contact* c, double* history,
                       struct wetdem_pair_force* out)
{
    (void)history;
    const struct spring_params* p = params;
    if (c->gap < 0)
        out->f_normal += -p->k * c->gap;
    return WETDEM_OK;
}
static const struct wetdem_model spring_model = {.name = "spring",
                                                 .kind = WETDEM_MODEL_CONTACT,
                                                 .summary = "linear spring",
                                                 .doc = "",
                                                 .equations = "",
                                                 .params = spring_desc,
                                                 .params_size = sizeof(struct spring_params),
                                                 .range = spring_range,
                                                 .pair = spring_pair};

/* Simulation set-up: materials, fluid, particles, walls, models, parameters, a pair force,
 * a clone and a reset. */
static void path_sim(struct outcome* out)
{
    struct wetdem_sim* sim = wetdem_sim_create();
    struct wetdem_sim* copy = NULL;
    CREATED(out, sim);
    struct wetdem_material m;
    CHECK_OK(wetdem_material_preset("glass", &m));
    STEP(out, wetdem_sim_add_material(sim, &m), wetdem_sim_errmsg(sim));
    STEP(out, wetdem_sim_add_material_preset(sim, "steel1"), wetdem_sim_errmsg(sim));
    STEP(out, wetdem_sim_add_material_preset(sim, "delrin"), wetdem_sim_errmsg(sim));
    struct wetdem_fluid f = {.viscosity = 0.01, .surface_tension = 0.02, .density = 1000};
    STEP(out, wetdem_sim_set_fluid(sim, &f), wetdem_sim_errmsg(sim));
    for (int k = 0; k < 20; k++) {
        struct wetdem_particle p = {.pos = {3e-3 * k, 0, 0}, .radius = 1e-3, .material = k % 2};
        STEP(out, wetdem_sim_add_particle(sim, p), wetdem_sim_errmsg(sim));
    }
    STEP(out,
         wetdem_sim_add_wall(sim, (struct wetdem_vec3){0, -2e-3, 0}, (struct wetdem_vec3){0, 1, 0},
                             2),
         wetdem_sim_errmsg(sim));
    const char* models[] = {"hertz", "mindlin", "reynolds", "capillary", "ehd"};
    for (size_t k = 0; k < sizeof models / sizeof models[0]; k++)
        STEP(out, wetdem_sim_enable_model(sim, models[k]), wetdem_sim_errmsg(sim));
    STEP(out, wetdem_sim_set_param(sim, "hertz.damping", 0), wetdem_sim_errmsg(sim));
    STEP(out, wetdem_sim_set_param(sim, "sim.gravity_z", -9.81), wetdem_sim_errmsg(sim));
    STEP(out, wetdem_sim_set_integrator(sim, "cvode"), wetdem_sim_errmsg(sim));
    struct wetdem_pair_force pf;
    struct wetdem_contact c;
    STEP(out, wetdem_sim_pair_force(sim, 0, 1, &c, &pf), wetdem_sim_errmsg(sim));
    STEP(out, wetdem_sim_pair_force(sim, 0, (size_t)-1, &c, &pf), wetdem_sim_errmsg(sim));
    copy = wetdem_sim_clone(sim);
    CREATED(out, copy);
    wetdem_sim_reset(copy);
    wetdem_sim_clear_models(copy);
    struct spring_params sp = {2e3};
    STEP(out, wetdem_sim_add_model(copy, &spring_model, &sp), wetdem_sim_errmsg(copy));
    STEP(out, wetdem_sim_enable_model(copy, "reynolds"), wetdem_sim_errmsg(copy));
done:
    wetdem_sim_free(copy);
    wetdem_sim_free(sim);
}

/* A wet head-on collision of two steel spheres (hertz + reynolds + capillary, films). */
static void collision(struct outcome* out, const char* integrator)
{
    struct wetdem_sim* sim = wetdem_sim_create();
    CREATED(out, sim);
    struct wetdem_material m;
    CHECK_OK(wetdem_material_preset("punch_steel_coated", &m));
    int mat = wetdem_sim_add_material(sim, &m);
    STEP(out, mat, wetdem_sim_errmsg(sim));
    STEP(out, wetdem_sim_add_material_preset(sim, "punch_steel"), wetdem_sim_errmsg(sim));
    struct wetdem_fluid f;
    CHECK_OK(wetdem_fluid_preset("silicone10", &f));
    f.viscosity = 0.1;
    STEP(out, wetdem_sim_set_fluid(sim, &f), wetdem_sim_errmsg(sim));
    const char* models[] = {"hertz", "mindlin", "db", "capillary", "ehd"};
    for (size_t k = 0; k < sizeof models / sizeof models[0]; k++)
        STEP(out, wetdem_sim_enable_model(sim, models[k]), wetdem_sim_errmsg(sim));
    STEP(out, wetdem_sim_set_integrator(sim, integrator), wetdem_sim_errmsg(sim));
    struct wetdem_collision_spec s = {.material_i = mat,
                                      .material_j = 1,
                                      .radius_i = 12.7e-3,
                                      .radius_j = 12.7e-3,
                                      .speed = 0.5,
                                      .angle = 0.5,
                                      .t_end = 1.0};
    struct wetdem_collision_result r;
    STEP(out, wetdem_collision_run(sim, &s, &r), wetdem_sim_errmsg(sim));
    if (!r.separated || !(r.e_n > 0 && r.e_n < 1))
        fail_msg("%s collision: separated %d, e_n = %g", integrator, r.separated, r.e_n);
    size_t n_events;
    wetdem_sim_events(sim, &n_events);
    if (n_events == 0)
        fail_msg("%s collision: no events", integrator);
done:
    wetdem_sim_free(sim);
}

static void path_collision_cvode(struct outcome* out)
{
    collision(out, "cvode");
}

static void path_collision_verlet(struct outcome* out)
{
    collision(out, "verlet");
}

/* A three-sphere pairwise run (Davis Table I set-up) with an observer. */
static int pairwise_observer(const struct wetdem_pairwise_frame* frame, void* ctx)
{
    (void)frame;
    ++*(int*)ctx;
    return 0;
}

static void path_pairwise(struct outcome* out)
{
    struct wetdem_pairwise* pw = wetdem_pairwise_create();
    CREATED(out, pw);
    struct wetdem_pairwise_davis d;
    wetdem_pairwise_davis_init(&d);
    d.n_spheres = 3;
    d.stokes = 10;
    d.capillary = 10;
    d.angle_deg = 20;
    d.t_star_end = 1;
    struct wetdem_pairwise_config c;
    char msg[256];
    CHECK_OK(wetdem_pairwise_davis_config(&d, &c, msg, sizeof msg));
    int frames = 0;
    wetdem_pairwise_set_observer(pw, 1e-4, pairwise_observer, &frames);
    struct wetdem_pairwise_result r;
    STEP(out, wetdem_pairwise_run(pw, &c, &r), wetdem_pairwise_errmsg(pw));
    size_t n_events;
    wetdem_pairwise_events(pw, &n_events);
    if (n_events == 0 || r.n_events != n_events || frames < 2)
        fail_msg("pairwise: %zu events, %zu in the result, %d frames", n_events, r.n_events,
                 frames);
done:
    wetdem_pairwise_free(pw);
}

/* A directory for the output files of the many-particle path, emptied between runs. */
static char out_dir[] = "/tmp/wetdem_test_alloc_XXXXXX";

/* Removes every file of out_dir; fails on a temporary file left behind (name with ".tmp"). */
static void clear_out_dir(bool check_tmp)
{
    DIR* d = opendir(out_dir);
    assert_non_null(d);
    struct dirent* e;
    char path[512];
    while ((e = readdir(d)))
        if (e->d_name[0] != '.') {
            if (check_tmp && strstr(e->d_name, "tmp"))
                fail_msg("temporary file left behind: %s", e->d_name);
            snprintf(path, sizeof path, "%s/%s", out_dir, e->d_name);
            unlink(path);
        }
    closedir(d);
}

/* A wet granular gas of 12 spheres in a box periodic in x and y with a floor, in the
 * many-particle mode with VTK (and links), CSV and checkpoint outputs under out_dir. */
static int many_box(struct wetdem_sim** out_sim, struct outcome* out)
{
    static char prefix[600], ck[600];
    snprintf(prefix, sizeof prefix, "%s/run", out_dir);
    snprintf(ck, sizeof ck, "%s/run.ck", out_dir);
    struct wetdem_sim* sim = *out_sim = wetdem_sim_create();
    CREATED(out, sim);
    STEP(out, test_wet_gas(sim, 12, 3e-3, 3e-3, 40e-6, 7, "ehd"), wetdem_sim_errmsg(sim));
    struct wetdem_many_settings s = {.periodic = {true, true, false},
                                     .box_lo = {0, 0, 0},
                                     .box_hi = {3e-3, 3e-3, 3e-3},
                                     .dt = 2e-6,
                                     .energy_budget = true,
                                     .output_prefix = prefix,
                                     .vtk_every = 2,
                                     .vtk_links = true,
                                     .csv_every = 1,
                                     .checkpoint_path = ck,
                                     .checkpoint_every = 3,
                                     .checkpoint_note = "csv = global.csv"};
    STEP(out, wetdem_sim_set_many(sim, &s), wetdem_sim_errmsg(sim));
    return WETDEM_OK;
done:
    return out->status;
}

static void path_many(struct outcome* out)
{
    struct wetdem_sim *sim = NULL, *resumed = NULL;
    char path[600];
    if (many_box(&sim, out) < 0)
        goto done;
    STEP(out, wetdem_sim_integrate(sim, 10e-6), wetdem_sim_errmsg(sim));
    struct wetdem_many_stats ms;
    STEP(out, wetdem_sim_many_stats(sim, &ms), wetdem_sim_errmsg(sim));
    STEP(out, wetdem_sim_many_write_csv_row(sim), wetdem_sim_errmsg(sim));
    snprintf(path, sizeof path, "%s/end.vtk", out_dir);
    STEP(out, wetdem_sim_write_vtk(sim, path, true), wetdem_sim_errmsg(sim));
    snprintf(path, sizeof path, "%s/end_links.vtk", out_dir);
    STEP(out, wetdem_sim_write_vtk_links(sim, path, false), wetdem_sim_errmsg(sim));
    snprintf(path, sizeof path, "%s/end.ck", out_dir);
    STEP(out, wetdem_sim_write_checkpoint(sim, path), wetdem_sim_errmsg(sim));
    if (many_box(&resumed, out) < 0)
        goto done;
    STEP(out, wetdem_sim_read_checkpoint(resumed, path), wetdem_sim_errmsg(resumed));
    if (strcmp(wetdem_sim_checkpoint_note(resumed), "csv = global.csv") != 0)
        fail_msg("the restored note is '%s'", wetdem_sim_checkpoint_note(resumed));
    STEP(out, wetdem_sim_integrate(resumed, 14e-6), wetdem_sim_errmsg(resumed));
    STEP(out, wetdem_sim_integrate(sim, 14e-6), wetdem_sim_errmsg(sim));
    test_check_same_particles(sim, resumed);
done:
    wetdem_sim_free(resumed);
    wetdem_sim_free(sim);
    clear_out_dir(true);
}

/* A two-parameter fit of e = a exp(-b / St) to ten points. */
static const double fit_stokes[10] = {1.5, 2, 3, 4, 6, 8, 12, 16, 24, 32};

static int fit_model(const double* p, double* pred, char* msg, size_t n_msg, void* ctx)
{
    (void)msg;
    (void)n_msg;
    (void)ctx;
    for (size_t i = 0; i < 10; i++)
        pred[i] = p[0] * exp(-p[1] / fit_stokes[i]);
    return WETDEM_OK;
}

static void path_fit(struct outcome* out)
{
    double obs[10];
    for (size_t i = 0; i < 10; i++)
        obs[i] = 0.9 * exp(-2.0 / fit_stokes[i]) * (1 + 0.01 * ((i % 3) - 1.0));
    const double init[2] = {0.5, 1.0}, lower[2] = {0, 0}, upper[2] = {1, INFINITY};
    struct wetdem_fit_problem pb = {.n_params = 2,
                                    .initial = init,
                                    .n_data = 10,
                                    .observed = obs,
                                    .model = fit_model,
                                    .lower = lower,
                                    .upper = upper};
    struct wetdem_fit_options o;
    wetdem_fit_options_init(&o);
    struct wetdem_fit_result r;
    double pred[10];
    char msg[256] = "";
    STEP(out, wetdem_fit_run(&pb, &o, &r, pred, msg, sizeof msg), msg);
    CHECK_REL(r.values[0], 0.9, 0.05);
done:;
}

/* Two spheres of a Stokes cradle: the striker (id 1) moves at 1 pixel/frame until frame 30,
 * then rests; the target (id 2) rests, then moves on. */
static void path_track(struct outcome* out)
{
    struct wetdem_track* t = wetdem_track_create();
    CREATED(out, t);
    for (long f = 0; f < 60; f++)
        for (int k = 0; k < 2; k++) {
            double x = k == 0 ? (f < 30 ? f : 30) : 100 + (f < 30 ? 0 : f - 30), y = 50;
            double xy[6] = {x, y, x - 10, y + 6, x + 10, y + 6};
            STEP(out, wetdem_track_add_frame(t, k + 1, f, xy), wetdem_track_errmsg(t));
        }
    struct wetdem_track_options o;
    wetdem_track_options_init(&o);
    o.fps = 5000;
    o.pixel_size = 175e-6;
    struct wetdem_track_summary s;
    STEP(out, wetdem_track_analyse(t, &o, &s), wetdem_track_errmsg(t));
    size_t n = 0;
    if (!s.has_collision || !wetdem_track_samples(t, 0, &n) || n != 59)
        fail_msg("track: collision %d, %zu samples", s.has_collision, n);
done:
    wetdem_track_free(t);
}

/* ---- tests ---------------------------------------------------------------------------------- */

static void test_alloc_failure_sim(void** state)
{
    (void)state;
    sweep("sim set-up", path_sim);
}

static void test_alloc_failure_collision_cvode(void** state)
{
    (void)state;
    sweep("collision (cvode)", path_collision_cvode);
}

static void test_alloc_failure_collision_verlet(void** state)
{
    (void)state;
    sweep("collision (verlet)", path_collision_verlet);
}

static void test_alloc_failure_pairwise(void** state)
{
    (void)state;
    sweep("pairwise", path_pairwise);
}

static void test_alloc_failure_many(void** state)
{
    (void)state;
    assert_non_null(mkdtemp(out_dir));
    sweep("many", path_many);
    clear_out_dir(false);
    rmdir(out_dir);
}

static void test_alloc_failure_fit(void** state)
{
    (void)state;
    sweep("fit", path_fit);
}

static void test_alloc_failure_track(void** state)
{
    (void)state;
    sweep("track", path_track);
}

int main(void)
{
    omp_set_num_threads(1); /* the wrappers' set of live blocks is not thread-safe */
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_alloc_failure_sim),
        cmocka_unit_test(test_alloc_failure_collision_cvode),
        cmocka_unit_test(test_alloc_failure_collision_verlet),
        cmocka_unit_test(test_alloc_failure_pairwise),
        cmocka_unit_test(test_alloc_failure_many),
        cmocka_unit_test(test_alloc_failure_fit),
        cmocka_unit_test(test_alloc_failure_track),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

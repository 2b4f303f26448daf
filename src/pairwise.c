/*
 * pairwise.c — the pairwise engine's driver and public API (Davis 2023, Secs. II, III, V and
 * Appendices A-B): configuration checks, adaptive integration with located events, the event
 * log, per-pair restitution (Eq. 40) and the FA / PA / FS outcome.
 *
 * Integration: SUNDIALS CVODE, BDF with a dense direct linear solver, one step at a time.
 * The film phase of a sticking pair is stiff: its normal velocity relaxes on the time
 * m* h / (6 pi mu a^2), far shorter near h_min than the time over which the pair creeps or
 * rotates (t_L = 4a / v_t0), so an implicit method takes steps of the slow scale.
 * Events are guards that stay >= 0 while the discrete mode is valid (docs/derivations):
 *     films apart:    h - delta_ij      films overlapping: delta_ij - h
 *     free:           h - h_min         held at h_min:     lambda (contact force, >= 0)
 * After every step the guards are evaluated; when one is negative its crossing is located
 * on CVODE's dense output (CVodeGetDky) by the Illinois variant of regula falsi to a relative
 * time tolerance of ~1e-13, the earliest crossing is processed (mode switch, impulse,
 * partner change) and CVODE is restarted there. Guards that touch zero at a restart (films
 * just touching at t = 0, h = h_min right after an impulse) need no special rule. The
 * progress callback is called between steps (every WETDEM_PROGRESS_STEPS) and never changes
 * CVODE's stops.
 * Validity: as pairwise_rhs.c; contact instantaneous (hard sphere), planar motion.
 */
#include <float.h>
#include <math.h>
#include <omp.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>

#include "pairwise.h"
#include "status.h"

enum { REV_NONE = 0, REV_IMPULSE = 1, REV_FILM = 2 };
enum { G_FILM = 0, G_CONTACT = 1, G_RELEASE = 2, G_KINDS = 3 };

#define PW_MAX_STEPS 20000000ULL
/* Steps in a row whose event lies at the step's start and logs nothing before the run is
 * stopped as stalled: a located event that changes nothing is met again by the next step. */
#define PW_MAX_STALLED 1000u

struct wetdem_pairwise {
    char errmsg[1024];
    struct wetdem_pairwise_config cfg;
    struct wetdem_pairwise_system sys;
    struct wetdem_pairwise_mode md;
    double y[PW_YMAX];
    double t;
    /* CVODE */
    SUNContext sunctx;
    void* cvode;
    N_Vector nv, atol, dky; /* dky: dense output (interpolate), made with the others */
    SUNMatrix mat;
    SUNLinearSolver ls;
    size_t cv_dim;
    /* log and observer */
    struct wetdem_pairwise_event* events;
    size_t n_events, events_cap;
    wetdem_pairwise_observer_fn obs;
    void* obs_ctx;
    double obs_interval;
    unsigned long long n_out;
    wetdem_time_progress_fn progress;
    void* progress_ctx;
    double progress_start; /* omp_get_wtime() at the start of the run [s] */
    /* per run */
    struct wetdem_pairwise_result* res;
    bool approaching[PW_PMAX];
    int reversal[PW_PMAX];
    double rest_speed, v_scale;
    unsigned stalled;     /* consecutive steps whose events came at their start, none logged */
    long conv_fails_seen; /* CVODE's nonlinear convergence failures since its restart */
    unsigned long window_steps; /* steps and convergence failures of the current window */
    unsigned long window_fails;
    double window_start; /* time of the window's first step [s] */
    double gravity_ref;  /* -sum m g . x at t = 0 [J]: gravity's potential is taken from it */
    bool done;
};

static int fail(struct wetdem_pairwise* pw, int status, const char* fmt, ...)
    __attribute__((format(printf, 3, 4)));

static int fail(struct wetdem_pairwise* pw, int status, const char* fmt, ...)
{
    char text[sizeof pw->errmsg]; /* the arguments may include the current message */
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    memcpy(pw->errmsg, text, sizeof text);
    return status;
}

/* ---------------------------------------------------------------- lifecycle and names -- */

struct wetdem_pairwise* wetdem_pairwise_create(void)
{
    return calloc(1, sizeof(struct wetdem_pairwise));
}

static void free_cvode(struct wetdem_pairwise* pw)
{
    if (pw->cvode)
        CVodeFree(&pw->cvode);
    if (pw->ls)
        SUNLinSolFree(pw->ls);
    if (pw->mat)
        SUNMatDestroy(pw->mat);
    if (pw->nv)
        N_VDestroy(pw->nv);
    if (pw->atol)
        N_VDestroy(pw->atol);
    if (pw->dky)
        N_VDestroy(pw->dky);
    if (pw->sunctx)
        SUNContext_Free(&pw->sunctx);
    pw->cvode = NULL;
    pw->ls = NULL;
    pw->mat = NULL;
    pw->nv = pw->atol = pw->dky = NULL;
    pw->sunctx = NULL;
    pw->cv_dim = 0;
}

void wetdem_pairwise_free(struct wetdem_pairwise* pw)
{
    if (!pw)
        return;
    free_cvode(pw);
    free(pw->events);
    free(pw);
}

const char* wetdem_pairwise_errmsg(const struct wetdem_pairwise* pw)
{
    return pw ? pw->errmsg : "";
}

void wetdem_pairwise_set_observer(struct wetdem_pairwise* pw, double interval,
                                  wetdem_pairwise_observer_fn fn, void* ctx)
{
    pw->obs = fn; /* (an interval it cannot use is refused by the next run) */
    pw->obs_ctx = ctx;
    pw->obs_interval = interval;
}

void wetdem_pairwise_set_progress(struct wetdem_pairwise* pw, wetdem_time_progress_fn fn, void* ctx)
{
    pw->progress = fn;
    pw->progress_ctx = ctx;
}

/* Calls the progress callback at pw->t; a non-zero return stops the run (can_stop) or, at its
 * end, is ignored. */
static int report_progress(struct wetdem_pairwise* pw, bool can_stop)
{
    int r =
        pw->progress(pw->t, pw->cfg.t_end, omp_get_wtime() - pw->progress_start, pw->progress_ctx);
    if (r != 0 && can_stop)
        return fail(pw, WETDEM_ERR_CALLBACK, "the progress callback returned %d at t = %g s", r,
                    pw->t);
    return WETDEM_OK;
}

const struct wetdem_pairwise_event* wetdem_pairwise_events(const struct wetdem_pairwise* pw,
                                                           size_t* n)
{
    *n = pw->n_events;
    return pw->events;
}

size_t wetdem_pairwise_pair_index(size_t n, size_t i, size_t j)
{
    if (i == j || i >= n || j >= n) /* (no pair: the formula gave another pair's index) */
        return SIZE_MAX;
    if (i > j) {
        size_t t = i;
        i = j;
        j = t;
    }
    return i * n - i * (i + 1) / 2 + (j - i - 1);
}

const char* wetdem_pairwise_event_name(enum wetdem_pairwise_event_kind kind)
{
    switch (kind) {
    case WETDEM_PAIRWISE_FILM_START: return "film_start";
    case WETDEM_PAIRWISE_CONTACT: return "contact";
    case WETDEM_PAIRWISE_REST_START: return "rest_start";
    case WETDEM_PAIRWISE_REST_END: return "rest_end";
    case WETDEM_PAIRWISE_FILM_END: return "film_end";
    case WETDEM_PAIRWISE_PARTNER_CHANGE: return "partner_change";
    }
    return "unknown";
}

const char* wetdem_pairwise_outcome_name(enum wetdem_pairwise_outcome outcome)
{
    switch (outcome) {
    case WETDEM_PAIRWISE_FA: return "FA";
    case WETDEM_PAIRWISE_PA: return "PA";
    case WETDEM_PAIRWISE_FS: return "FS";
    }
    return "unknown";
}

/* ---------------------------------------------------------------------- configuration -- */

void wetdem_pairwise_config_init(struct wetdem_pairwise_config* cfg)
{
    memset(cfg, 0, sizeof *cfg);
    cfg->restitution = 1.0;
    cfg->friction = 0.0;
    cfg->t_end = 1.0;
    cfg->rtol = 1e-9;
    cfg->rest_speed_ratio = 1e-3;
    cfg->stop_when_separated = true;
    cfg->energy_budget = true;
    cfg->ref_i = 0;
    cfg->ref_j = 1;
    cfg->max_events = 100000;
}

static int validate_sphere(const struct wetdem_pairwise_sphere* s, size_t i, char* msg, size_t n)
{
    if (!(s->radius > 0.0) || !isfinite(s->radius))
        return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID,
                                  "spheres[%zu].radius = %g m: must be in (0, inf)", i, s->radius);
    if (!(s->mass > 0.0) || !isfinite(s->mass))
        return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID,
                                  "spheres[%zu].mass = %g kg: must be in (0, inf)", i, s->mass);
    if (!(s->film >= 0.0) || !isfinite(s->film))
        return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID,
                                  "spheres[%zu].film = %g m: must be in [0, inf)", i, s->film);
    double v[5] = {s->x, s->y, s->vx, s->vy, s->omega};
    const char* names[5] = {"x", "y", "vx", "vy", "omega"};
    for (int k = 0; k < 5; k++)
        if (!isfinite(v[k]))
            return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID,
                                      "spheres[%zu].%s = %g: must be finite", i, names[k], v[k]);
    /* the spin equation divides by I, and the tolerances scale with the speeds: a radius or
     * mass near the least double, or a speed whose square underflows, leaves CVODE nothing
     * to work with (it failed at the first right-hand side) */
    double inertia = 0.4 * s->mass * s->radius * s->radius;
    if (!(inertia >= DBL_MIN && isfinite(inertia)))
        return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID,
                                  "spheres[%zu]: mass %g kg and radius %g m give a moment of "
                                  "inertia 2/5 m a^2 = %g kg m^2 outside the normal doubles",
                                  i, s->mass, s->radius, inertia);
    double speed = hypot(s->vx, s->vy), energy = 0.5 * s->mass * speed * speed;
    if (speed > 0.0 && !(energy >= DBL_MIN))
        return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID,
                                  "spheres[%zu]: speed %g m/s is too small: its kinetic energy "
                                  "1/2 m v^2 = %g J underflows; give 0 or a larger speed",
                                  i, speed, energy);
    return WETDEM_OK;
}

static int validate_scalars(const struct wetdem_pairwise_config* c, char* msg, size_t n)
{
    if (!(c->viscosity >= 0.0) || !isfinite(c->viscosity))
        return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID,
                                  "viscosity = %g Pa s: must be in [0, inf)", c->viscosity);
    if (!(c->surface_tension >= 0.0) || !isfinite(c->surface_tension))
        return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID,
                                  "surface_tension = %g N/m: must be in [0, inf)",
                                  c->surface_tension);
    if (!(c->h_min > 0.0) || !isfinite(c->h_min))
        return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID, "h_min = %g m: must be in (0, inf)",
                                  c->h_min);
    if (!(c->restitution > 0.0 && c->restitution <= 1.0))
        return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID, "restitution = %g: must be in (0, 1]",
                                  c->restitution);
    if (!(c->friction >= 0.0) || !isfinite(c->friction))
        return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID, "friction = %g: must be in [0, inf)",
                                  c->friction);
    if (!isfinite(c->gravity_x) || !isfinite(c->gravity_y))
        return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID,
                                  "gravity = (%g, %g) m/s^2: must be finite", c->gravity_x,
                                  c->gravity_y);
    /* (above 1e9 s CVODE's first step, scaled by the span, fails at t = 0 with repeated
       right-hand-side errors; 1e9 s is the CLI's bound too) */
    if (!(c->t_end >= WETDEM_MIN_SPAN && c->t_end <= 1e9))
        return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID,
                                  "t_end = %g s: must be in [%g, 1e9] (from the shortest span "
                                  "CVODE integrates)",
                                  c->t_end, WETDEM_MIN_SPAN);
    /* Above 1e-5 CVODE's tolerance on the speeds, rtol v_scale, comes within a factor 100 of
     * the rest speed (1e-3 v_n0) and contacts at h_min can chatter: at 1e-4 two of the 400
     * runs of a Davis St x angle map at Ca = 0.01 (spheres in a line) used up the event
     * budget; at 1e-5 none of the 800 of that map at Ca 0.01 and 1000 did. */
    if (!(c->rtol >= 1e-14 && c->rtol <= 1e-5))
        return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID, "rtol = %g: must be in [1e-14, 1e-5]",
                                  c->rtol);
    if (!(c->rest_speed_ratio >= 0.0 && c->rest_speed_ratio < 1.0))
        return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID,
                                  "rest_speed_ratio = %g: must be in [0, 1)", c->rest_speed_ratio);
    if (c->max_events < 1)
        return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID, "max_events = %zu: must be >= 1",
                                  c->max_events);
    return WETDEM_OK;
}

/* Messages about a pair count spheres from 1 (as the CLI, the scenario files and the output
 * columns x_1, e_w_12 do) and add the array index: "spheres 1 and 2 (spheres[0], spheres[1])". */
int wetdem_pairwise_config_validate(const struct wetdem_pairwise_config* c, char* msg, size_t n)
{
    if (c->n_spheres < 2 || c->n_spheres > WETDEM_PAIRWISE_MAX_SPHERES)
        return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID, "n_spheres = %zu: must be in [2, %d]",
                                  c->n_spheres, WETDEM_PAIRWISE_MAX_SPHERES);
    int st = validate_scalars(c, msg, n);
    for (size_t i = 0; i < c->n_spheres && st == WETDEM_OK; i++)
        st = validate_sphere(&c->spheres[i], i, msg, n);
    if (st != WETDEM_OK)
        return st;
    if (c->ref_i >= c->n_spheres || c->ref_j >= c->n_spheres || c->ref_i == c->ref_j)
        return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID,
                                  "reference pair: spheres %zu and %zu (ref_i = %zu, ref_j = %zu): "
                                  "must be two different spheres of 1..%zu",
                                  c->ref_i + 1, c->ref_j + 1, c->ref_i, c->ref_j, c->n_spheres);
    for (size_t i = 0; i < c->n_spheres; i++)
        for (size_t j = i + 1; j < c->n_spheres; j++) {
            const struct wetdem_pairwise_sphere *a = &c->spheres[i], *b = &c->spheres[j];
            double sum = a->radius + b->radius;
            if (!(c->h_min >= WETDEM_PAIRWISE_MIN_HMIN_RATIO * sum))
                return wetdem_status_fail(
                    msg, n, WETDEM_ERR_INVALID,
                    "h_min = %g m: must be >= %g (a_i + a_j) = %g m for spheres %zu and %zu "
                    "(spheres[%zu], spheres[%zu]): a smaller gap is not resolved beside "
                    "centre distances of %g m",
                    c->h_min, WETDEM_PAIRWISE_MIN_HMIN_RATIO, WETDEM_PAIRWISE_MIN_HMIN_RATIO * sum,
                    i + 1, j + 1, i, j, sum);
            double h = hypot(b->x - a->x, b->y - a->y) - a->radius - b->radius;
            /* The gap is a difference of lengths of the centres' size: spheres placed at
             * exactly h_min (a cradle's chain) come out a few ulps of those lengths short. */
            double rounding =
                8.0 * DBL_EPSILON *
                (fabs(a->x) + fabs(a->y) + fabs(b->x) + fabs(b->y) + a->radius + b->radius);
            if (!(h >= c->h_min - rounding))
                return wetdem_status_fail(
                    msg, n, WETDEM_ERR_INVALID,
                    "initial gap of spheres %zu and %zu (spheres[%zu], spheres[%zu]) = %.9g m: "
                    "must be >= h_min = %.9g m",
                    i + 1, j + 1, i, j, h, c->h_min);
        }
    return WETDEM_OK;
}

/* ---------------------------------------------------------------------------- CVODE -- */

static int cv_rhs(sunrealtype t, N_Vector y, N_Vector ydot, void* ud)
{
    (void)t;
    struct wetdem_pairwise* pw = ud;
    pw->res->rhs_evals++;
    return wetdem_pairwise_rhs_eval(&pw->sys, &pw->md, N_VGetArrayPointer(y),
                                    N_VGetArrayPointer(ydot))
               ? 0
               : 1; /* recoverable: CVODE retries with a smaller step */
}

/* Largest change of any gap, as a fraction of h_min, that the difference quotients of the
 * Jacobian may make by perturbing a tracked angle (cv_jac). */
#define JAC_GAP_FRACTION 0.02

/* Dense difference-quotient Jacobian: CVODE's own (cvLsDenseDQJac: increment
 * max(sqrt(eps) |y_j|, 1000 |h| eps N ||f||_wrms / ewt_j)), except that the increment of a
 * tracked angle theta_e is at most JAC_GAP_FRACTION h_min / r_e. Turning edge e by d theta
 * shifts every sphere beyond it by r_e d theta, and with it the gaps of the pairs that are not
 * tracked (a closed loop, Davis Appendix B), which are differences of lengths of the spheres'
 * size. CVODE's increment, 1.5e-8 |theta|, shifted them by ~6e-11 m |theta| for 2 mm spheres:
 * 1e-4 of h_min in Davis's Fig. 3 (h_a = h_m = 0.01), but the whole of it at h_a = 3e-6, where
 * a perturbed state had a gap <= 0, the right-hand side failed for every step size and CVODE
 * stopped with "the corrector convergence test failed repeatedly or with |h| = hmin". The
 * force laws change over a gap's own size (~1/h, ln h), so a quotient must move it by a small
 * part of h_min; rounding of a gap, ~1e-16 (a_i + a_j), stays below 1e-4 of that step while
 * h_min > 1e-10 (a_i + a_j). With |theta| < ANGLE_WRAP the cap does not bind in Davis's
 * Table-I range (h_a h_m >= 2e-6 at h_a = 0.002). */
static int cv_jac(sunrealtype t, N_Vector y, N_Vector fy, SUNMatrix jac, void* ud, N_Vector tmp1,
                  N_Vector tmp2, N_Vector tmp3)
{
    (void)tmp3;
    struct wetdem_pairwise* pw = ud;
    const struct wetdem_pairwise_system* sys = &pw->sys;
    size_t n = pw->cv_dim;
    sunrealtype h_step = 0.0;
    if (CVodeGetErrWeights(pw->cvode, tmp2) != CV_SUCCESS ||
        CVodeGetCurrentStep(pw->cvode, &h_step) != CV_SUCCESS)
        return -1;
    const double* ewt = N_VGetArrayPointer(tmp2);
    double* yd = N_VGetArrayPointer(y);
    const double* f0 = N_VGetArrayPointer(fy);
    const double* f1 = N_VGetArrayPointer(tmp1);
    double srur = sqrt(DBL_EPSILON), fnorm = N_VWrmsNorm(fy, tmp2);
    double min_inc = fnorm != 0.0 ? 1000.0 * fabs(h_step) * DBL_EPSILON * (double)n * fnorm : 1.0;
    for (size_t j = 0; j < n; j++) {
        double saved = yd[j], inc = fmax(srur * fabs(saved), min_inc / ewt[j]);
        if (j >= PW_ANCHOR_LEN && (j - PW_ANCHOR_LEN) % PW_EDGE_LEN == PW_THETA) {
            size_t e = (j - PW_ANCHOR_LEN) / PW_EDGE_LEN, p = pw->md.edge[e];
            double r = sys->a[sys->pi[p]] + sys->a[sys->pj[p]] + yd[j - PW_THETA + PW_H];
            inc = fmin(inc, JAC_GAP_FRACTION * sys->h_min / r);
        }
        yd[j] += inc;
        int st = cv_rhs(t, y, tmp1, ud);
        yd[j] = saved;
        if (st != 0)
            return st;
        double* col = SUNDenseMatrix_Column(jac, (sunindextype)j);
        double inv = 1.0 / inc;
        for (size_t i = 0; i < n; i++)
            col[i] = inv * (f1[i] - f0[i]);
    }
    return 0;
}

static void cv_err(int code, const char* module, const char* function, char* msg, void* ud)
{
    struct wetdem_pairwise* pw = ud;
    if (code < 0)
        snprintf(pw->errmsg, sizeof pw->errmsg, "%s %s: %s", module, function, msg);
}

/* Absolute tolerances: rtol times the scale of each component. */
static void set_atol(struct wetdem_pairwise* pw)
{
    const struct wetdem_pairwise_system* sys = &pw->sys;
    double* a = N_VGetArrayPointer(pw->atol);
    double amin = sys->a[0];
    for (size_t i = 1; i < sys->n; i++)
        amin = fmin(amin, sys->a[i]);
    double rt = pw->cfg.rtol, v = pw->v_scale;
    double anchor[5] = {amin, amin, v, v, v / amin};
    for (int c = 0; c < 5; c++)
        a[c] = rt * anchor[c];
    for (size_t e = 0; e + 1 < sys->n; e++) {
        double* b = a + PW_ANCHOR_LEN + PW_EDGE_LEN * e;
        b[PW_H] = rt * sys->h_min;
        b[PW_THETA] = rt;
        b[PW_VN] = rt * v;
        b[PW_OMEGA] = rt * v / amin;
        b[PW_VW] = rt * v;
    }
}

static int setup_cvode(struct wetdem_pairwise* pw)
{
    size_t dim = 5 * pw->sys.n;
    if (pw->cv_dim != dim) {
        free_cvode(pw);
        if (SUNContext_Create(NULL, &pw->sunctx) != 0)
            return fail(pw, WETDEM_ERR_NOMEM, "cannot create the SUNDIALS context");
        pw->nv = N_VNew_Serial((sunindextype)dim, pw->sunctx);
        pw->atol = N_VNew_Serial((sunindextype)dim, pw->sunctx);
        pw->dky = N_VNew_Serial((sunindextype)dim, pw->sunctx);
        pw->cvode = CVodeCreate(CV_BDF, pw->sunctx);
        if (!pw->nv || !pw->atol || !pw->dky || !pw->cvode)
            return fail(pw, WETDEM_ERR_NOMEM, "out of memory creating the integrator");
        CVodeSetErrHandlerFn(pw->cvode, cv_err, pw);
        memcpy(N_VGetArrayPointer(pw->nv), pw->y, dim * sizeof(double));
        if (CVodeInit(pw->cvode, cv_rhs, 0.0, pw->nv) != CV_SUCCESS)
            return fail(pw, WETDEM_ERR_NOMEM, "CVodeInit failed");
        pw->mat = SUNDenseMatrix((sunindextype)dim, (sunindextype)dim, pw->sunctx);
        pw->ls = pw->mat ? SUNLinSol_Dense(pw->nv, pw->mat, pw->sunctx) : NULL;
        if (!pw->ls || CVodeSetLinearSolver(pw->cvode, pw->ls, pw->mat) != 0)
            return fail(pw, WETDEM_ERR_NOMEM, "cannot attach the dense linear solver");
        CVodeSetMaxErrTestFails(pw->cvode, 20);
        CVodeSetMaxConvFails(pw->cvode, 50);
        CVodeSetJacFn(pw->cvode, cv_jac);
        pw->cv_dim = dim;
    }
    CVodeSetUserData(pw->cvode, pw);
    set_atol(pw);
    if (CVodeSVtolerances(pw->cvode, pw->cfg.rtol, pw->atol) != CV_SUCCESS)
        return fail(pw, WETDEM_ERR_INVALID, "CVodeSVtolerances failed");
    return WETDEM_OK;
}

static int restart(struct wetdem_pairwise* pw)
{
    pw->conv_fails_seen = 0; /* (CVodeReInit zeroes CVODE's counters) */
    memcpy(N_VGetArrayPointer(pw->nv), pw->y, pw->cv_dim * sizeof(double));
    if (CVodeReInit(pw->cvode, pw->t, pw->nv) != CV_SUCCESS)
        return fail(pw, WETDEM_ERR_STEP, "CVodeReInit failed at t = %g s", pw->t);
    CVodeSetStopTime(pw->cvode, pw->cfg.t_end);
    return WETDEM_OK;
}

/* y at time t inside the last step (dense output). */
static bool interpolate(struct wetdem_pairwise* pw, double t, double* y)
{
    if (CVodeGetDky(pw->cvode, t, 0, pw->dky) != CV_SUCCESS)
        return false;
    memcpy(y, N_VGetArrayPointer(pw->dky), pw->cv_dim * sizeof *y);
    return true;
}

/* ---------------------------------------------------------------------- event log ---- */

double wetdem_pairwise_t_hat(const struct wetdem_pairwise_result* res, double t)
{
    return (res->v_n0 > 0.0 && res->delta_ref > 0.0) ? res->v_n0 * t / res->delta_ref : NAN;
}

double wetdem_pairwise_t_star(const struct wetdem_pairwise_result* res, double t)
{
    return (res->v_10 > 0.0 && res->a_ref > 0.0) ? res->v_10 * t / (4.0 * res->a_ref) : NAN;
}

static int log_event(struct wetdem_pairwise* pw, enum wetdem_pairwise_event_kind kind, size_t p,
                     size_t p_old, double gap, double v_n)
{
    if (pw->n_events >= pw->cfg.max_events)
        return fail(pw, WETDEM_ERR_MAX_STEPS,
                    "event budget max_events = %zu exhausted at t = %g s, the next a %s of "
                    "spheres %zu and %zu at %g m/s (a pair bouncing in a deep capillary well, "
                    "or chattering: raise max_events, or lower the restitution)",
                    pw->cfg.max_events, pw->t, wetdem_pairwise_event_name(kind), pw->sys.pi[p] + 1,
                    pw->sys.pj[p] + 1, v_n);
    if (pw->n_events == pw->events_cap) {
        size_t cap = pw->events_cap ? 2 * pw->events_cap : 64;
        void* mem = realloc(pw->events, cap * sizeof *pw->events);
        if (!mem)
            return fail(pw, WETDEM_ERR_NOMEM, "out of memory growing the event log");
        pw->events = mem;
        pw->events_cap = cap;
    }
    pw->events[pw->n_events++] = (struct wetdem_pairwise_event){
        .kind = kind,
        .time = pw->t,
        .t_hat = wetdem_pairwise_t_hat(pw->res, pw->t),
        .t_star = wetdem_pairwise_t_star(pw->res, pw->t),
        .i = pw->sys.pi[p],
        .j = pw->sys.pj[p],
        .k = pw->sys.pi[p_old],
        .l = pw->sys.pj[p_old],
        .gap = gap,
        .v_n = v_n,
    };
    return WETDEM_OK;
}

/* ------------------------------------------------------------------ energy budget ---- */

/* Kinetic energy, capillary potential and -sum m g . x of state y in the current mode [J];
 * false if y is outside the domain. */
static bool energy_parts(const struct wetdem_pairwise* pw, const double* y, double* kinetic,
                         double* capillary, double* gravity)
{
    struct wetdem_pairwise_kin k;
    if (!wetdem_pairwise_state_kin(&pw->sys, &pw->md, y, &k))
        return false;
    wetdem_pairwise_rhs_energy(&pw->sys, &pw->md, &k, kinetic, capillary, gravity);
    return true;
}

/* Mechanical energy of state y [J] (NAN outside the domain), gravity's potential taken from
 * its value at t = 0: it then measures the work done alone, and a far origin of the positions
 * adds no large constant that would round the other terms away. */
static double mechanical_energy(const struct wetdem_pairwise* pw, const double* y)
{
    double ke, u_c, u_g;
    return energy_parts(pw, y, &ke, &u_c, &u_g) ? ke + u_c + (u_g - pw->gravity_ref) : NAN;
}

/* The film forces' dissipation over [t_lo, t_hi] inside the last step [J]: three-point
 * Gauss-Legendre on CVODE's dense output, exact for a power that is a polynomial of degree 5
 * in t, as accurate as the interpolant elsewhere. It reads the solution without changing
 * it, so the run's trajectory does not depend on the budget. */
static int step_dissipation(struct wetdem_pairwise* pw, double t_lo, double t_hi, double* normal,
                            double* tangential)
{
    static const double node[3] = {-0.77459666924148337704, 0.0, 0.77459666924148337704};
    static const double weight[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
    double half = 0.5 * (t_hi - t_lo), mid = 0.5 * (t_lo + t_hi);
    double e_n = 0.0, e_t = 0.0;
    *normal = *tangential = 0.0;
    if (!(half > 0.0))
        return WETDEM_OK;
    for (int g = 0; g < 3; g++) {
        double y[PW_YMAX], p_n, p_t, t = mid + half * node[g];
        struct wetdem_pairwise_kin k;
        if (!interpolate(pw, t, y) || !wetdem_pairwise_state_kin(&pw->sys, &pw->md, y, &k))
            return fail(pw, WETDEM_ERR_STEP, "dense output failed at t = %g s", t);
        wetdem_pairwise_rhs_dissipation(&pw->sys, &pw->md, &k, &p_n, &p_t);
        e_n += weight[g] * p_n;
        e_t += weight[g] * p_t;
    }
    *normal = half * e_n;
    *tangential = half * e_t;
    return WETDEM_OK;
}

/* Adds the dissipation over [t_lo, t_hi] of the last step to the run's budget. */
static int dissipate(struct wetdem_pairwise* pw, double t_lo, double t_hi)
{
    double e_n, e_t;
    int st = pw->cfg.energy_budget ? step_dissipation(pw, t_lo, t_hi, &e_n, &e_t) : WETDEM_OK;
    if (st == WETDEM_OK && pw->cfg.energy_budget) {
        pw->res->energy.viscous_normal += e_n;
        pw->res->energy.viscous_tangential += e_t;
    }
    return st;
}

double wetdem_pairwise_energy_scale(const struct wetdem_pairwise_energy* e)
{
    double terms[] = {e->initial, e->kinetic,        e->capillary,
                      e->gravity, e->viscous_normal, e->viscous_tangential,
                      e->contact};
    double s = DBL_MIN;
    for (size_t k = 0; k < sizeof terms / sizeof terms[0]; k++) {
        if (isnan(terms[k])) /* (fmax drops a NaN: a broken budget looked well scaled) */
            return NAN;
        s = fmax(s, fabs(terms[k]));
    }
    return s;
}

/* The budget at state k: the energies there and the residual, given the losses so far in e. */
static void close_budget(const struct wetdem_pairwise* pw, const struct wetdem_pairwise_kin* k,
                         struct wetdem_pairwise_energy* e)
{
    if (!pw->cfg.energy_budget) {
        *e = (struct wetdem_pairwise_energy){NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN};
        return;
    }
    wetdem_pairwise_rhs_energy(&pw->sys, &pw->md, k, &e->kinetic, &e->capillary, &e->gravity);
    e->gravity -= pw->gravity_ref;
    e->residual = e->initial - (e->kinetic + e->capillary + e->gravity + e->viscous_normal +
                                e->viscous_tangential + e->contact);
}

/* ------------------------------------------------------------------------- output ---- */

static void fill_frame(const struct wetdem_pairwise* pw, const struct wetdem_pairwise_kin* k,
                       double t, struct wetdem_pairwise_frame* fr)
{
    memset(fr, 0, sizeof *fr);
    fr->time = t;
    fr->t_hat = wetdem_pairwise_t_hat(pw->res, t);
    fr->t_star = wetdem_pairwise_t_star(pw->res, t);
    fr->n_spheres = pw->sys.n;
    fr->n_pairs = pw->sys.n_pairs;
    for (size_t i = 0; i < pw->sys.n; i++) {
        fr->spheres[i] = pw->cfg.spheres[i];
        fr->spheres[i].x = k->x[i];
        fr->spheres[i].y = k->y[i];
        fr->spheres[i].vx = k->vx[i];
        fr->spheres[i].vy = k->vy[i];
        fr->spheres[i].omega = k->w[i];
    }
    for (size_t p = 0; p < pw->sys.n_pairs; p++) {
        fr->gap[p] = k->h[p];
        fr->v_n[p] = k->v_n[p];
    }
}

/* Frame at time t, state y, inside the last step from pw->t (or at pw->t itself). Its
 * budget is the run's so far plus the dissipation from pw->t to t. */
static int emit(struct wetdem_pairwise* pw, double t, const double* y)
{
    struct wetdem_pairwise_kin k;
    struct wetdem_pairwise_frame fr;
    wetdem_pairwise_state_kin(&pw->sys, &pw->md, y, &k);
    fill_frame(pw, &k, t, &fr);
    fr.energy = pw->res->energy;
    if (pw->cfg.energy_budget && t > pw->t) {
        double e_n, e_t;
        int st = step_dissipation(pw, pw->t, t, &e_n, &e_t);
        if (st != WETDEM_OK)
            return st;
        fr.energy.viscous_normal += e_n;
        fr.energy.viscous_tangential += e_t;
    }
    close_budget(pw, &k, &fr.energy);
    if (pw->obs(&fr, pw->obs_ctx) != 0)
        return fail(pw, WETDEM_ERR_CALLBACK, "observer returned non-zero at t = %g s", t);
    return WETDEM_OK;
}

/* Frames at the output times in (t_lo, t_hi] of the last step (t_hi is the current pw->t
 * when `current`, else an interpolated time). */
static int emit_until(struct wetdem_pairwise* pw, double t_hi)
{
    if (!pw->obs)
        return WETDEM_OK;
    for (;;) {
        double t_out = (double)pw->n_out * pw->obs_interval;
        if (t_out > t_hi || t_out > pw->cfg.t_end)
            return WETDEM_OK;
        double y[PW_YMAX];
        if (!interpolate(pw, t_out, y))
            memcpy(y, pw->y, sizeof y);
        int st = emit(pw, t_out, y);
        if (st != WETDEM_OK)
            return st;
        pw->n_out++;
    }
}

/* --------------------------------------------------------------------------- guards ---- */

/* A contact is met at h = h_min (1 - CONTACT_SLACK), and then set to h_min, so that a pair
 * at h_min is not met again by the rounding of its gap (1e-16 of it): neither one the
 * contact problem leaves free there (it separates), nor one whose next step starts one
 * rounding below h_min. Without the slack, at Ca = 0.01 in Davis's set-up, where suction
 * turns a pair at h_min round within 1e-13 s, the default example stood still at
 * t = 3e-5 s at rtol 1e-5, and three spheres in a line met such a pair every 2e-16 s at
 * 1e-3. The slack is 4e-19 m at h_min = 4e-7 m, far below any of the model's lengths. */
#define CONTACT_SLACK 1e-12

/* The slowest contact that is not resting because of CONTACT_SLACK [m/s]: setting the gap
 * to h_min at a contact lifts a film-coated pair by CONTACT_SLACK h_min against its
 * capillary suction 8 pi a sigma, an energy dU it did not have; a contact whose kinetic
 * energy (1/2) m* v^2 is within REST_LIFT_ENERGY dU of that is resting. Without this floor
 * two wet spheres released at rest (the rest speed then 1e-3 of the 1 um/s fallback scale)
 * bounced with e_dry = 1 at ~1e-7 m/s, where the lift, 2.5e-22 J a bounce, gave back what
 * the viscous force took, until the event budget ran out. In Davis's set-ups (Ca >= 0.01) it
 * lies far below the rest speed (~4e-5 v_n0 against 1e-3). 0 without capillarity. */
#define REST_LIFT_ENERGY 1e4
static double lift_rest_speed(const struct wetdem_pairwise_system* sys)
{
    double v = 0.0;
    for (size_t p = 0; p < sys->n_pairs && sys->sigma > 0.0; p++)
        if (sys->delta[p] > sys->h_min) {
            double lift = 8.0 * M_PI * sys->a_eff[p] * sys->sigma * CONTACT_SLACK * sys->h_min;
            v = fmax(v, sqrt(2.0 * REST_LIFT_ENERGY * lift / sys->m_eff[p]));
        }
    return v;
}

/* Guard values of every pair at state y: g[G_KINDS * p + kind], >= 0 while the mode holds. */
static bool guards(struct wetdem_pairwise* pw, const double* y, double* g)
{
    const struct wetdem_pairwise_system* sys = &pw->sys;
    struct wetdem_pairwise_kin k;
    struct wetdem_pairwise_forces f;
    pw->res->guard_evals++;
    if (!wetdem_pairwise_state_kin(sys, &pw->md, y, &k))
        return false;
    bool any_rest = false;
    for (size_t p = 0; p < sys->n_pairs; p++) {
        double* gp = g + G_KINDS * p;
        bool has_film = sys->delta[p] > sys->h_min;
        gp[G_FILM] =
            !has_film ? 1.0 : (pw->md.film[p] ? sys->delta[p] - k.h[p] : k.h[p] - sys->delta[p]);
        gp[G_CONTACT] = pw->md.resting[p] ? 1.0 : k.h[p] - sys->h_min * (1.0 - CONTACT_SLACK);
        if (!(gp[G_CONTACT] > 0.0) && k.v_n[p] > 0.0) /* at h_min and approaching: now */
            gp[G_CONTACT] = fmin(gp[G_CONTACT], -DBL_MIN);
        gp[G_RELEASE] = 1.0;
        any_rest = any_rest || pw->md.resting[p];
    }
    if (!any_rest)
        return true;
    if (!wetdem_pairwise_rhs_forces(sys, &pw->md, &k, &f))
        return false;
    for (size_t p = 0; p < sys->n_pairs; p++)
        if (pw->md.resting[p])
            g[G_KINDS * p + G_RELEASE] = f.lambda[p];
    return true;
}

/* Value of guard `idx` at time t of the last step. */
static double guard_at(struct wetdem_pairwise* pw, size_t idx, double t)
{
    double y[PW_YMAX], g[G_KINDS * PW_PMAX];
    if (!interpolate(pw, t, y) || !guards(pw, y, g))
        return NAN;
    return g[idx];
}

/* Illinois regula falsi for the crossing of guard idx in [lo, hi], g(lo) >= 0 > g(hi).
 * Returns the end of the final bracket where the guard is negative. */
static double locate(struct wetdem_pairwise* pw, size_t idx, double lo, double hi, double g_hi)
{
    double g_lo = guard_at(pw, idx, lo);
    if (!(g_lo >= 0.0))
        return lo;
    double tol = 1e-13 * (hi - lo) + 4.0 * DBL_EPSILON * fabs(hi);
    int side = 0;
    for (int it = 0; it < 200 && hi - lo > tol; it++) {
        double t = (g_lo - g_hi != 0.0) ? hi - g_hi * (hi - lo) / (g_hi - g_lo) : 0.5 * (lo + hi);
        if (!(t > lo && t < hi))
            t = 0.5 * (lo + hi);
        double gt = guard_at(pw, idx, t);
        if (!isfinite(gt))
            gt = -1.0;
        if (gt < 0.0) {
            hi = t;
            g_hi = gt;
            if (side == -1)
                g_lo *= 0.5;
            side = -1;
        } else {
            lo = t;
            g_lo = gt;
            if (side == 1)
                g_hi *= 0.5;
            side = 1;
        }
    }
    return hi;
}

/* Normal approach speed of pair p at time t of the last step (NAN if the output fails). */
static double v_n_at(struct wetdem_pairwise* pw, size_t p, double t)
{
    double y[PW_YMAX];
    struct wetdem_pairwise_kin k;
    if (!interpolate(pw, t, y) || !wetdem_pairwise_state_kin(&pw->sys, &pw->md, y, &k))
        return NAN;
    return k.v_n[p];
}

/* Earliest crossing of a guard of pair p hidden inside the step [lo, hi]: the pair turned from
 * approach (v_lo > 0) to recession (v_hi <= 0), and its gap may have dipped below h_min or
 * delta_ij and be back above at both ends, a grazing contact or film overlap shorter than the
 * step (a sphere 1 um wide of h_min, 1 nm inside it, passed in 4 us between steps of 20 us
 * untouched). The smallest gap is where v_n = 0, found by bisection on the dense output; a
 * guard negative there is located between lo and that time. INFINITY if none. */
static double hidden_crossing(struct wetdem_pairwise* pw, size_t p, double lo, double hi)
{
    double a = lo, b = hi;
    for (int it = 0; it < 100 && a < b; it++) {
        double m = 0.5 * (a + b);
        if (m <= a || m >= b)
            break;
        double v = v_n_at(pw, p, m);
        if (!isfinite(v))
            return INFINITY;
        if (v > 0.0)
            a = m;
        else
            b = m;
    }
    double t_ev = INFINITY;
    for (size_t kind = G_FILM; kind <= G_CONTACT; kind++) {
        double g = guard_at(pw, G_KINDS * p + kind, b);
        if (g < 0.0)
            t_ev = fmin(t_ev, locate(pw, G_KINDS * p + kind, lo, b, g));
    }
    return t_ev;
}

/* ------------------------------------------------------------------ mode changes ---- */

/* Current kinematics from pw->y. */
static bool current_kin(struct wetdem_pairwise* pw, struct wetdem_pairwise_kin* k)
{
    if (wetdem_pairwise_state_kin(&pw->sys, &pw->md, pw->y, k))
        return true;
    fail(pw, WETDEM_ERR_NUMERIC, "state not finite at t = %g s", pw->t);
    return false;
}

/* Re-chooses the tracked tree (pair `force` must be tracked; PW_PMAX for none), converts the
 * state and logs a partner change for every pair that entered the tree. */
static int retree(struct wetdem_pairwise* pw, size_t force)
{
    struct wetdem_pairwise_kin k;
    if (!current_kin(pw, &k))
        return WETDEM_ERR_NUMERIC;
    struct wetdem_pairwise_mode md = pw->md;
    wetdem_pairwise_state_tree(&pw->sys, k.h, &pw->md, force, &md);
    size_t n_edges = pw->sys.n - 1, left[PW_NMAX], n_left = 0;
    for (size_t e = 0; e < n_edges; e++)
        if (md.edge_of_pair[pw->md.edge[e]] < 0)
            left[n_left++] = pw->md.edge[e];
    if (n_left == 0)
        return WETDEM_OK;
    const struct wetdem_pairwise_mode old = pw->md;
    pw->md = md;
    wetdem_pairwise_state_pack(&pw->sys, &pw->md, &k, pw->y);
    size_t a = 0;
    for (size_t e = 0; e < n_edges; e++) {
        size_t p = md.edge[e];
        if (old.edge_of_pair[p] >= 0)
            continue;
        int st = log_event(pw, WETDEM_PAIRWISE_PARTNER_CHANGE, p, left[a++], k.h[p], k.v_n[p]);
        if (st != WETDEM_OK)
            return st;
    }
    return WETDEM_OK;
}

static int on_film(struct wetdem_pairwise* pw, size_t p, const struct wetdem_pairwise_kin* k)
{
    struct wetdem_pairwise_pair_result* r = &pw->res->pairs[p];
    bool start = !pw->md.film[p];
    pw->md.film[p] = start;
    int st = log_event(pw, start ? WETDEM_PAIRWISE_FILM_START : WETDEM_PAIRWISE_FILM_END, p, p,
                       k->h[p], k->v_n[p]);
    if (st != WETDEM_OK)
        return st;
    if (start && !r->films_met) {
        r->films_met = true;
        r->v_n_in = k->v_n[p];
        r->t_start = pw->t;
    }
    if (!start) {
        r->v_n_out = -k->v_n[p];
        r->t_end = pw->t;
    }
    return retree(pw, PW_PMAX);
}

/* New held set `hold` (from the force-level contact problem): logs the pairs that start or
 * stop being held; pair `p`, if not PW_PMAX, is logged as the contact that caused it. */
static int set_held(struct wetdem_pairwise* pw, const bool* hold, size_t p,
                    const struct wetdem_pairwise_kin* k, double v_n)
{
    for (size_t q = 0; q < pw->sys.n_pairs; q++) {
        bool was = pw->md.resting[q];
        pw->md.resting[q] = hold[q];
        enum wetdem_pairwise_event_kind kind;
        if (q == p)
            kind = hold[q] ? WETDEM_PAIRWISE_REST_START : WETDEM_PAIRWISE_CONTACT;
        else if (was != hold[q])
            kind = hold[q] ? WETDEM_PAIRWISE_REST_START : WETDEM_PAIRWISE_REST_END;
        else
            continue;
        int st = log_event(pw, kind, q, q, k->h[q], q == p ? v_n : k->v_n[q]);
        if (st != WETDEM_OK)
            return st;
    }
    return WETDEM_OK;
}

/* Contact slower than the rest speed: the new pair and every slow pair touching at h_min stop
 * together (plastic), then the force-level contact problem decides which stay held. */
static int rest_contact(struct wetdem_pairwise* pw, size_t p, const struct wetdem_pairwise_kin* k,
                        double v_n)
{
    bool cand[PW_PMAX], hold[PW_PMAX];
    for (size_t q = 0; q < pw->sys.n_pairs; q++)
        cand[q] = pw->md.resting[q] || q == p ||
                  (k->h[q] <= pw->sys.h_min * (1.0 + 1e-9) && fabs(k->v_n[q]) < pw->rest_speed);
    struct wetdem_pairwise_kin k2;
    if (!wetdem_pairwise_jump_plastic(&pw->sys, &pw->md, k, cand, pw->y) || !current_kin(pw, &k2) ||
        !wetdem_pairwise_rhs_hold_set(&pw->sys, &pw->md, &k2, cand, hold))
        return fail(pw, WETDEM_ERR_NUMERIC, "singular resting-contact problem at t = %g s", pw->t);
    return set_held(pw, hold, p, &k2, v_n);
}

/* Sets the gap of tracked pair p to h_min: a contact is located within ~1e-13 of it
 * (CONTACT_SLACK). */
static void gap_to_hmin(struct wetdem_pairwise* pw, size_t p)
{
    pw->y[PW_ANCHOR_LEN + PW_EDGE_LEN * (size_t)pw->md.edge_of_pair[p] + PW_H] = pw->sys.h_min;
}

/* Bookkeeping of an impulse on pair p, met at approach speed v_n: counted and logged. */
static int note_impulse(struct wetdem_pairwise* pw, size_t p, double v_n)
{
    pw->approaching[p] = false;
    pw->reversal[p] = REV_IMPULSE;
    pw->res->pairs[p].n_contacts++;
    return log_event(pw, WETDEM_PAIRWISE_CONTACT, p, p, pw->sys.h_min, v_n);
}

/* After impulses (the kinematics before them in *before): a film pair they set receding, from
 * approaching, at rest, or receding without any reversal before (pushed through a neighbour's
 * film), was reversed by an impulse, its own or a neighbour's: a sphere knocked out of another's
 * films is a bounce, not stick-rotate-separate; and the held pairs whose normal velocity they
 * changed are let go (an approaching one is a contact of its own next). */
static int release_moved(struct wetdem_pairwise* pw, const struct wetdem_pairwise_kin* before)
{
    struct wetdem_pairwise_kin after;
    if (!current_kin(pw, &after))
        return WETDEM_ERR_NUMERIC;
    for (size_t q = 0; q < pw->sys.n_pairs; q++) {
        bool knocked = after.v_n[q] < 0.0 && after.v_n[q] < before->v_n[q] &&
                       (before->v_n[q] >= 0.0 || pw->reversal[q] == REV_NONE);
        if (pw->md.film[q] && knocked) {
            pw->approaching[q] = false;
            pw->reversal[q] = REV_IMPULSE;
        }
        if (!pw->md.resting[q] || after.v_n[q] == before->v_n[q])
            continue;
        pw->md.resting[q] = false;
        int st = log_event(pw, WETDEM_PAIRWISE_REST_END, q, q, after.h[q], after.v_n[q]);
        if (st != WETDEM_OK)
            return st;
    }
    return WETDEM_OK;
}

/* Contact at the rest speed or faster: the hard-sphere impulse of Appendix A, and the held
 * pairs it moves let go. */
static int hard_contact(struct wetdem_pairwise* pw, size_t p, struct wetdem_pairwise_kin* k,
                        double v_n)
{
    int st = wetdem_pairwise_jump_apply(&pw->sys, &pw->md, p, k, pw->y);
    if (st != WETDEM_OK)
        return fail(pw, st,
                    "hard-sphere impulse of spheres %zu and %zu (spheres[%zu], spheres[%zu]) "
                    "failed at t = %g s",
                    pw->sys.pi[p] + 1, pw->sys.pj[p] + 1, pw->sys.pi[p], pw->sys.pj[p], pw->t);
    st = note_impulse(pw, p, v_n);
    return st == WETDEM_OK ? release_moved(pw, k) : st;
}

/* Whether no pair of `set` slips at state k: |v_s| = |-r Omega + v_omega| within CVODE's
 * absolute tolerance on the speeds (rtol x the initial speed scale), below which the
 * integration does not resolve a slip. */
static bool set_does_not_slip(const struct wetdem_pairwise* pw, const bool* set,
                              const struct wetdem_pairwise_kin* k)
{
    double tol = pw->cfg.rtol * pw->v_scale;
    for (size_t q = 0; q < pw->sys.n_pairs; q++)
        if (set[q] && !(fabs(-k->r[q] * k->omega_lc[q] + k->v_w[q]) <= tol))
            return false;
    return true;
}

/* Contacts met at one instant at the rest speed or faster (`set`, two or more): their
 * impulses together, so that the result does not depend on the pairs' numbering, as one
 * impulse after the other did (a sphere meeting two touching ones symmetrically left off the
 * symmetry line). Without friction, or with friction when no pair of the set slips before or
 * after them (spheres in a line), the normal impulses of Newton's rule for each contact
 * (wetdem_pairwise_jump_simultaneous): no friction impulse is then called for, and the
 * frictionless result is the frictional one (one after the other, a sphere squeezed between two
 * at 1 m/s, e_dry = 0.8, mu_f = 0.3, left at 0.009 m/s instead of at rest). Otherwise, with
 * friction, compression and restitution with Coulomb friction at every contact of the set
 * (wetdem_pairwise_jump_simultaneous_friction). Returns WETDEM_EVENT, the velocities untouched,
 * when the joint solution would pull a pair (or could not be found: more than six frictional
 * contacts, energy that would grow); the caller then resolves them one by one. */
static int simultaneous_contacts(struct wetdem_pairwise* pw, const bool* set)
{
    struct wetdem_pairwise_kin k, after;
    bool friction = pw->sys.mu_f > 0.0;
    if (!current_kin(pw, &k))
        return WETDEM_ERR_NUMERIC;
    bool frictionless = !friction || set_does_not_slip(pw, set, &k);
    double y_met[PW_YMAX]; /* (a set resolved one by one starts from the state it was met at) */
    memcpy(y_met, pw->y, sizeof y_met);
    for (size_t q = 0; q < pw->sys.n_pairs; q++)
        if (set[q] && pw->md.edge_of_pair[q] >= 0)
            gap_to_hmin(pw, q);
    if (!current_kin(pw, &k))
        return WETDEM_ERR_NUMERIC;
    double y_before[PW_YMAX];
    memcpy(y_before, pw->y, sizeof y_before);
    bool done =
        frictionless && wetdem_pairwise_jump_simultaneous(&pw->sys, &pw->md, &k, set, pw->y);
    if (done && friction && (!current_kin(pw, &after) || !set_does_not_slip(pw, set, &after))) {
        memcpy(pw->y, y_before, sizeof y_before);
        done = false;
    }
    if (!done && friction)
        done = wetdem_pairwise_jump_simultaneous_friction(&pw->sys, &pw->md, &k, set, pw->y);
    if (!done && !frictionless)
        memcpy(pw->y, y_met, sizeof y_met);
    if (!done)
        return WETDEM_EVENT;
    for (size_t q = 0; q < pw->sys.n_pairs; q++) {
        int st = set[q] ? note_impulse(pw, q, k.v_n[q]) : WETDEM_OK;
        if (st != WETDEM_OK)
            return st;
    }
    return release_moved(pw, &k); /* (the set's own pairs are not held) */
}

/* The set of pairs whose contact guard is negative in g, or whose gap lies within the
 * integration's resolution of h_min, and that approach at the rest speed or faster, when there
 * are two or more of them; false otherwise. Contacts closer in time than the
 * integration can tell apart are one multiple collision: in a symmetric wet set-up the second
 * pair's gap was 2.9e-13 m above h_min (3e-7 of it) when the first was met. The resolution is
 * rtol (a_i + a_j), the error of a centre distance: a pair the tree does not track has its gap
 * from the tracked pairs' centre distances (Davis Appendix B), and two gaps that should be
 * equal differ by that much when one is tracked and the other not (a tracked gap alone is
 * integrated to atol = rtol h_min). Such a pair joins the set too: the impulses act on the
 * spheres. At rtol 1e-5 (the largest allowed) and 1 mm spheres the window is 2e-8 m; gaps
 * 5e-8 m apart are two collisions. */
static bool simultaneous_set(const struct wetdem_pairwise* pw, const double* g,
                             const struct wetdem_pairwise_kin* k, bool* set)
{
    size_t n = 0;
    for (size_t q = 0; q < pw->sys.n_pairs; q++) {
        double within = pw->cfg.rtol * (pw->sys.a[pw->sys.pi[q]] + pw->sys.a[pw->sys.pj[q]]);
        bool met = g[G_KINDS * q + G_CONTACT] < 0.0 || k->h[q] <= pw->sys.h_min + within;
        set[q] = met && !pw->md.resting[q] && k->v_n[q] >= pw->rest_speed && k->v_n[q] > 0.0;
        n += set[q];
    }
    return n >= 2;
}

static int on_contact(struct wetdem_pairwise* pw, size_t p)
{
    int st = pw->md.edge_of_pair[p] < 0 ? retree(pw, p) : WETDEM_OK;
    if (st != WETDEM_OK)
        return st;
    gap_to_hmin(pw, p);
    struct wetdem_pairwise_kin k;
    if (!current_kin(pw, &k))
        return WETDEM_ERR_NUMERIC;
    double v_n = k.v_n[p];
    if (!(v_n > 0.0))
        return WETDEM_OK; /* grazing: nothing to reverse */
    pw->approaching[p] = false;
    pw->reversal[p] = REV_IMPULSE;
    if (v_n < pw->rest_speed)
        return rest_contact(pw, p, &k, v_n);
    return hard_contact(pw, p, &k, v_n);
}

/* A held pair's contact force reached zero: the contact problem is solved again over the
 * held pairs (the pair itself is let go). */
static int on_release(struct wetdem_pairwise* pw, size_t p, const struct wetdem_pairwise_kin* k)
{
    bool cand[PW_PMAX], hold[PW_PMAX];
    for (size_t q = 0; q < pw->sys.n_pairs; q++)
        cand[q] = pw->md.resting[q];
    if (!wetdem_pairwise_rhs_hold_set(&pw->sys, &pw->md, k, cand, hold))
        return fail(pw, WETDEM_ERR_NUMERIC, "singular resting-contact problem at t = %g s", pw->t);
    hold[p] = false;
    pw->approaching[p] = false;
    /* the held pair had v_n = 0: what now pulls it apart is the film and centrifugal forces,
     * not an impulse (a later contact marks REV_IMPULSE again) */
    pw->reversal[p] = REV_FILM;
    return set_held(pw, hold, PW_PMAX, k, 0.0);
}

/* Whether every negative guard at the current state is the contact guard of a pair that does
 * not approach (v_n <= 0) and lies below its contact gap by rounding only (1e-9 h_min): the
 * state of three spheres touching in a closed loop, where only two pairs are tracked and the
 * third pair's gap, computed from theirs (Davis Appendix B), rounds a few 1e-19 below it. Each
 * such "contact" re-tracks that pair, which moves the rounding to the other, without end. */
static bool grazing_at_rounding(struct wetdem_pairwise* pw)
{
    double g[G_KINDS * PW_PMAX];
    struct wetdem_pairwise_kin k;
    if (!guards(pw, pw->y, g) || !current_kin(pw, &k))
        return false;
    for (size_t idx = 0; idx < G_KINDS * pw->sys.n_pairs; idx++) {
        size_t p = idx / G_KINDS;
        if (g[idx] < 0.0 &&
            !(idx % G_KINDS == G_CONTACT && !(k.v_n[p] > 0.0) && g[idx] > -1e-9 * pw->sys.h_min))
            return false;
    }
    return true;
}

/* Processes every negative guard at the current state, one at a time, until none is left. */
static int process_events(struct wetdem_pairwise* pw)
{
    double g[G_KINDS * PW_PMAX];
    for (int round = 0; round < 4 * G_KINDS * PW_PMAX; round++) {
        if (!guards(pw, pw->y, g))
            return fail(pw, WETDEM_ERR_NUMERIC, "state outside the domain at t = %g s", pw->t);
        size_t idx = 0;
        while (idx < G_KINDS * pw->sys.n_pairs && !(g[idx] < 0.0))
            idx++;
        if (idx == G_KINDS * pw->sys.n_pairs)
            return WETDEM_OK;
        size_t p = idx / G_KINDS;
        struct wetdem_pairwise_kin k;
        if (!current_kin(pw, &k))
            return WETDEM_ERR_NUMERIC;
        int st;
        bool set[PW_PMAX];
        switch (idx % G_KINDS) {
        case G_FILM: st = on_film(pw, p, &k); break;
        case G_CONTACT:
            /* (the pair tracked first, as on_contact does, so that its gap can be set to h_min
               with the others of the set) */
            st = pw->md.edge_of_pair[p] < 0 ? retree(pw, p) : WETDEM_OK;
            if (st == WETDEM_OK && (!guards(pw, pw->y, g) || !current_kin(pw, &k)))
                st = WETDEM_ERR_NUMERIC;
            if (st == WETDEM_OK)
                st = simultaneous_set(pw, g, &k, set) ? simultaneous_contacts(pw, set)
                                                      : WETDEM_EVENT;
            if (st == WETDEM_EVENT)
                st = on_contact(pw, p);
            break;
        default: st = on_release(pw, p, &k); break;
        }
        if (st != WETDEM_OK)
            return st;
    }
    if (grazing_at_rounding(pw))
        return WETDEM_OK;
    return fail(pw, WETDEM_ERR_STEP, "events do not settle at t = %g s", pw->t);
}

/* process_events, with the mechanical energy its impulses take counted as contact losses
 * (a film switching on or off at h = delta changes no energy; the tree's repacking only
 * rounds). */
static int process_events_counted(struct wetdem_pairwise* pw)
{
    if (!pw->cfg.energy_budget)
        return process_events(pw);
    double before = mechanical_energy(pw, pw->y);
    int st = process_events(pw);
    if (st == WETDEM_OK)
        pw->res->energy.contact += before - mechanical_energy(pw, pw->y);
    return st;
}

/* ------------------------------------------------------------------- bookkeeping ---- */

/* Turning points of film pairs and the smallest gaps, at an accepted state. */
static void track_pairs(struct wetdem_pairwise* pw, const struct wetdem_pairwise_kin* k)
{
    for (size_t p = 0; p < pw->sys.n_pairs; p++) {
        struct wetdem_pairwise_pair_result* r = &pw->res->pairs[p];
        r->min_gap = fmin(r->min_gap, k->h[p]);
        if (!pw->md.film[p] || pw->md.resting[p])
            continue;
        if (pw->approaching[p] && k->v_n[p] < 0.0) {
            pw->approaching[p] = false;
            pw->reversal[p] = REV_FILM;
        } else if (!pw->approaching[p] && k->v_n[p] > 0.0) {
            pw->approaching[p] = true;
        }
    }
}

/* True when no pair interacts and every pair recedes: nothing can change any more. */
static bool all_apart(const struct wetdem_pairwise* pw, const struct wetdem_pairwise_kin* k)
{
    for (size_t p = 0; p < pw->sys.n_pairs; p++)
        if (pw->md.film[p] || pw->md.resting[p] || k->v_n[p] > 0.0)
            return false;
    return true;
}

static size_t uf_root(size_t* parent, size_t i)
{
    while (parent[i] != i)
        i = parent[i];
    return i;
}

/* The label of pair p at the end (docs/derivations/pairwise.md Sec. 9), from what turned its
 * approach round. Bound: stick. A pair without films (delta_ij <= h_min) has nothing to hold
 * a doublet: bounce once a contact turned it (an impulse, or a slow contact held and let go,
 * so that the label does not depend on the rest speed), none if it never touched. A film pair:
 * none if the films never met; bounce or stick-rotate-separate by its last reversal; recede
 * when there was none: its films overlapped from the start and it never approached. */
static int pair_mechanism(const struct wetdem_pairwise* pw, size_t p)
{
    const struct wetdem_pairwise_pair_result* r = &pw->res->pairs[p];
    if (r->bound)
        return WETDEM_OUTCOME_STICK;
    if (!(pw->sys.delta[p] > pw->sys.h_min))
        return pw->reversal[p] == REV_NONE ? WETDEM_OUTCOME_NONE : WETDEM_OUTCOME_BOUNCE;
    if (!r->films_met)
        return WETDEM_OUTCOME_NONE;
    switch (pw->reversal[p]) {
    case REV_IMPULSE: return WETDEM_OUTCOME_BOUNCE;
    case REV_FILM: return WETDEM_OUTCOME_STICK_ROTATE_SEPARATE;
    default: return WETDEM_OUTCOME_RECEDE;
    }
}

/* Clusters of bound pairs at the end: FA, PA (which sphere left) or FS. */
static void classify(struct wetdem_pairwise* pw)
{
    struct wetdem_pairwise_result* res = pw->res;
    size_t parent[PW_NMAX], size[PW_NMAX] = {0};
    for (size_t i = 0; i < pw->sys.n; i++)
        parent[i] = i;
    for (size_t p = 0; p < pw->sys.n_pairs; p++) {
        struct wetdem_pairwise_pair_result* r = &res->pairs[p];
        r->bound = pw->md.film[p] || pw->md.resting[p];
        r->mechanism = pair_mechanism(pw, p);
        if (!r->films_met) {
            r->e_wet = r->e_wet_own = NAN;
            if (r->bound) /* (a pair without films held at h_min) */
                parent[uf_root(parent, pw->sys.pi[p])] = uf_root(parent, pw->sys.pj[p]);
            continue;
        }
        /* (without an approach of the reference pair at t = 0, e_ij,w has no scale) */
        r->e_wet = r->bound ? 0.0 : res->v_n0 > 0.0 ? r->v_n_out / res->v_n0 : NAN;
        r->e_wet_own = (r->bound ? 0.0 : r->v_n_out) / r->v_n_in;
        if (!(r->v_n_in > 0.0))
            r->e_wet_own = NAN;
        if (r->bound)
            parent[uf_root(parent, pw->sys.pi[p])] = uf_root(parent, pw->sys.pj[p]);
    }
    size_t n_single = 0, n_comp = 0;
    res->separated_sphere = -1;
    for (size_t i = 0; i < pw->sys.n; i++)
        size[uf_root(parent, i)]++;
    for (size_t i = 0; i < pw->sys.n; i++) {
        if (size[i] == 0)
            continue;
        n_comp++;
        if (size[i] == 1) {
            n_single++;
            res->separated_sphere = (int)i;
        }
    }
    if (n_single != 1)
        res->separated_sphere = -1;
    res->outcome = n_comp == 1 ? WETDEM_PAIRWISE_FA
                               : (n_single == pw->sys.n ? WETDEM_PAIRWISE_FS : WETDEM_PAIRWISE_PA);
}

/* ------------------------------------------------------------------------------ run ---- */

/* Rate of the hold of an untracked pair at h_min (struct wetdem_pairwise_system, hold_rate) in
 * units of rtol v_scale / h_min: fast enough to keep its drift near h_min / 100, slow beside
 * the integration step (docs/derivations/pairwise.md Sec. 7). */
#define HOLD_RATE_FACTOR 100.0

/* Reference quantities, initial modes, tree and state from the configuration. */
static void initial_state(struct wetdem_pairwise* pw)
{
    const struct wetdem_pairwise_config* cfg = &pw->cfg;
    struct wetdem_pairwise_system* sys = &pw->sys;
    struct wetdem_pairwise_result* res = pw->res;
    struct wetdem_pairwise_kin k;
    memset(&k, 0, sizeof k);
    wetdem_pairwise_state_system(cfg, sys);
    for (size_t i = 0; i < sys->n; i++) {
        k.x[i] = cfg->spheres[i].x;
        k.y[i] = cfg->spheres[i].y;
        k.vx[i] = cfg->spheres[i].vx;
        k.vy[i] = cfg->spheres[i].vy;
        k.w[i] = cfg->spheres[i].omega;
    }
    wetdem_pairwise_state_pairs_from_spheres(sys, &k);
    size_t ref = wetdem_pairwise_pair_index(sys->n, cfg->ref_i, cfg->ref_j);
    res->n_spheres = sys->n;
    res->n_pairs = sys->n_pairs;
    res->v_n0 = k.v_n[ref];
    res->delta_ref = sys->delta[ref];
    res->v_10 = hypot(k.vx[cfg->ref_i], k.vy[cfg->ref_i]);
    res->a_ref = sys->a_eff[ref];
    double v = 0.0;
    for (size_t i = 0; i < sys->n; i++)
        v = fmax(v, fmax(hypot(k.ux[i], k.uy[i]), hypot(k.vx[i], k.vy[i])));
    pw->v_scale = v > 0.0 ? v : 1e-6;
    sys->hold_rate = HOLD_RATE_FACTOR * cfg->rtol * pw->v_scale / sys->h_min;
    /* (without an approach of the reference pair, the largest initial speed: Sec. 7) */
    pw->rest_speed = cfg->rest_speed_ratio * (res->v_n0 > 0.0 ? res->v_n0 : pw->v_scale);
    if (cfg->rest_speed_ratio > 0.0) /* (0: no resting contact at all) */
        pw->rest_speed = fmax(pw->rest_speed, lift_rest_speed(sys));
    memset(&pw->md, 0, sizeof pw->md);
    for (size_t p = 0; p < sys->n_pairs; p++) {
        struct wetdem_pairwise_pair_result* r = &res->pairs[p];
        r->i = sys->pi[p];
        r->j = sys->pj[p];
        r->t_start = r->t_end = NAN;
        r->min_gap = k.h[p];
        r->mechanism = WETDEM_OUTCOME_NONE;
        bool has_film = sys->delta[p] > sys->h_min;
        /* films "just touching" (to rounding of the input positions) count as touching */
        if (has_film && fabs(k.h[p] - sys->delta[p]) <= 1e-12 * sys->delta[p] && k.v_n[p] >= 0.0)
            k.h[p] = sys->delta[p];
        pw->md.film[p] =
            has_film && k.h[p] <= sys->delta[p] && (k.h[p] < sys->delta[p] || k.v_n[p] >= 0.0);
        if (pw->md.film[p]) {
            r->films_met = true;
            r->v_n_in = k.v_n[p];
            r->t_start = 0.0;
        }
        pw->approaching[p] = k.v_n[p] > 0.0;
        pw->reversal[p] = REV_NONE;
    }
    struct wetdem_pairwise_mode md = pw->md;
    wetdem_pairwise_state_tree(sys, k.h, &pw->md, PW_PMAX, &md);
    pw->md = md;
    wetdem_pairwise_state_pack(sys, &pw->md, &k, pw->y);
}

/* One CVODE step and whatever events it contains. */
/* Angles of the line of centres are wrapped into (-pi, pi] once one passes ANGLE_WRAP [rad]:
 * they enter only through cos and sin, but CVODE's difference-quotient Jacobian perturbs a
 * component by about 1.5e-8 |y|, so an angle grown by a spinning cluster (7700 rad after
 * 100 s at 75 rad/s) moves a gap by a good part of h_min in the perturbed call and the
 * Newton iteration fails. At 32 pi the perturbation moves a 4 mm pair by 3 nm. */
#define ANGLE_WRAP (32.0 * M_PI)

/* Wraps the tracked angles of pw->y past ANGLE_WRAP; true if any was. */
static bool wrap_angles(struct wetdem_pairwise* pw)
{
    bool any = false;
    for (size_t e = 0; e + 1 < pw->sys.n; e++) {
        double* th = &pw->y[PW_ANCHOR_LEN + PW_EDGE_LEN * e + PW_THETA];
        if (fabs(*th) > ANGLE_WRAP) {
            *th -= 2.0 * M_PI * nearbyint(*th / (2.0 * M_PI));
            any = true;
        }
    }
    return any;
}

/* Stall of the Newton iteration, a run that would go on for hours: CVODE's steps are counted
 * in windows of PW_STALL_WINDOW, and the run stops when in one window the nonlinear iteration
 * failed to converge on at least every other accepted step and, at the window's pace, the rest
 * of the run would take more than PW_STALL_STEPS further steps (some 20 s at the ~25
 * right-hand sides such a step costs). That is the state of a film far stiffer than the motion
 * it carries: its normal velocity relaxes at the rate 6 pi mu a^2 / (m* h) (1 / (St_n h_m) in
 * units of v_n0 / delta_12), and as the step times that rate nears 1 / DBL_EPSILON the
 * Jacobian of the last step no longer converges in the next; the iteration fails, the step is
 * cut by 4 and the order falls to 1. Davis's set-up then advanced at Ca = 0.01, St_n = 1e-25 by
 * steps of 3e-14 s through a motion of 7e-2 s (1.5 failures a step, some 2e12 steps to go),
 * and at Ca = 1000, St_n = 1e-16 in 800 000 steps (46 s). Runs that thrash but finish are not
 * stopped: Ca = 1000 at 30 deg, St_n = 1e-15 (153 000 steps, at most 1.7e5 to go in any
 * window) and at 40 deg, St_n = 1e-14 (51 000). No run of the Davis validation
 * (scripts/validate.d/30-davis.sh) failed to converge in any window. */
#define PW_STALL_WINDOW 20000ul
#define PW_STALL_STEPS 3e5
static double film_relaxation_time(const struct wetdem_pairwise* pw)
{
    const struct wetdem_pairwise_system* sys = &pw->sys;
    double t = INFINITY;
    for (size_t p = 0; p < sys->n_pairs; p++)
        if (sys->delta[p] > sys->h_min && sys->mu > 0.0)
            t = fmin(t, sys->m_eff[p] * sys->h_min /
                            (6.0 * M_PI * sys->mu * sys->a_eff[p] * sys->a_eff[p]));
    return t;
}

static int newton_stall(struct wetdem_pairwise* pw, double t)
{
    long fails = 0;
    if (CVodeGetNumNonlinSolvConvFails(pw->cvode, &fails) == CV_SUCCESS) {
        pw->window_fails += (unsigned long)(fails - pw->conv_fails_seen);
        pw->conv_fails_seen = fails;
    }
    if (pw->window_steps++ == 0)
        pw->window_start = t;
    if (pw->window_steps < PW_STALL_WINDOW)
        return WETDEM_OK;
    double pace = (t - pw->window_start) / (double)(pw->window_steps - 1); /* [s/step] */
    double to_go = (pw->cfg.t_end - t) / pace;
    bool stalled = 2 * pw->window_fails >= pw->window_steps && !(to_go <= PW_STALL_STEPS);
    unsigned long n_fails = pw->window_fails;
    pw->window_steps = pw->window_fails = 0;
    if (!stalled)
        return WETDEM_OK;
    return fail(pw, WETDEM_ERR_STEP,
                "the integration stalls at t = %g s (t* = %g): CVODE's Newton iteration failed "
                "%lu times in the last %lu steps, which averaged %g s, and the run would need "
                "%.3g more. The films relax on m* h_min / (6 pi mu a^2) = %g s, too short "
                "beside the motion for double precision: the masses are too small for the "
                "viscosity (St_n = m* v / (6 pi mu a^2) this small is the inertia-free limit, "
                "which the engine does not resolve)",
                t, wetdem_pairwise_t_star(pw->res, t), n_fails, PW_STALL_WINDOW, pace, to_go,
                film_relaxation_time(pw));
}

static int advance(struct wetdem_pairwise* pw)
{
    double t_lo = pw->t, t;
    struct wetdem_pairwise_kin k_lo, k_hi;
    if (!current_kin(pw, &k_lo))
        return WETDEM_ERR_NUMERIC;
    int flag = CVode(pw->cvode, pw->cfg.t_end, pw->nv, &t, CV_ONE_STEP);
    if (flag < 0)
        return fail(pw, WETDEM_ERR_STEP, "integrator failed at t = %g s (%s)", t_lo, pw->errmsg);
    if (++pw->res->steps > PW_MAX_STEPS)
        return fail(pw, WETDEM_ERR_MAX_STEPS, "more than %llu steps", PW_MAX_STEPS);
    int st_conv = newton_stall(pw, t);
    if (st_conv != WETDEM_OK)
        return st_conv;
    double g[G_KINDS * PW_PMAX], y[PW_YMAX];
    memcpy(y, N_VGetArrayPointer(pw->nv), pw->cv_dim * sizeof(double));
    if (!guards(pw, y, g))
        return fail(pw, WETDEM_ERR_NUMERIC, "state not finite at t = %g s", t);
    double t_ev = INFINITY;
    for (size_t idx = 0; idx < G_KINDS * pw->sys.n_pairs; idx++)
        if (g[idx] < 0.0)
            t_ev = fmin(t_ev, locate(pw, idx, t_lo, t, g[idx]));
    if (!wetdem_pairwise_state_kin(&pw->sys, &pw->md, y, &k_hi))
        return fail(pw, WETDEM_ERR_NUMERIC, "state not finite at t = %g s", t);
    for (size_t p = 0; p < pw->sys.n_pairs; p++)
        if (!pw->md.resting[p] && k_lo.v_n[p] > 0.0 && !(k_hi.v_n[p] > 0.0) &&
            g[G_KINDS * p + G_FILM] >= 0.0 && g[G_KINDS * p + G_CONTACT] >= 0.0)
            t_ev = fmin(t_ev, hidden_crossing(pw, p, t_lo, t));
    if (isfinite(t_ev)) {
        int st = emit_until(pw, t_ev);
        if (st != WETDEM_OK || (st = dissipate(pw, t_lo, t_ev)) != WETDEM_OK)
            return st;
        pw->t = t_ev;
        if (!interpolate(pw, t_ev, pw->y))
            return fail(pw, WETDEM_ERR_STEP, "dense output failed at t = %g s", t_ev);
        size_t n_logged = pw->n_events;
        if ((st = process_events_counted(pw)) != WETDEM_OK || (st = restart(pw)) != WETDEM_OK)
            return st;
        pw->stalled = (t_ev == t_lo && pw->n_events == n_logged) ? pw->stalled + 1 : 0;
        if (pw->stalled >= PW_MAX_STALLED)
            return fail(pw, WETDEM_ERR_STEP,
                        "time stands still at t = %g s: %u steps in a row met an event at their "
                        "start that changed nothing (a pair grazing at h_min; with "
                        "rest_speed_ratio = %g, try a larger one or a smaller rtol)",
                        t_lo, pw->stalled, pw->cfg.rest_speed_ratio);
    } else {
        pw->stalled = 0;
        int st = emit_until(pw, t);
        if (st != WETDEM_OK || (st = dissipate(pw, t_lo, t)) != WETDEM_OK)
            return st;
        pw->t = t;
        memcpy(pw->y, y, pw->cv_dim * sizeof(double));
        if (wrap_angles(pw) && (st = restart(pw)) != WETDEM_OK)
            return st;
    }
    struct wetdem_pairwise_kin k;
    if (!current_kin(pw, &k))
        return WETDEM_ERR_NUMERIC;
    track_pairs(pw, &k);
    pw->done = pw->t >= pw->cfg.t_end || (pw->cfg.stop_when_separated && all_apart(pw, &k));
    return WETDEM_OK;
}

static void finish(struct wetdem_pairwise* pw)
{
    struct wetdem_pairwise_kin k;
    struct wetdem_pairwise_result* res = pw->res;
    wetdem_pairwise_state_kin(&pw->sys, &pw->md, pw->y, &k);
    for (size_t i = 0; i < pw->sys.n; i++) {
        res->final[i] = pw->cfg.spheres[i];
        res->final[i].x = k.x[i];
        res->final[i].y = k.y[i];
        res->final[i].vx = k.vx[i];
        res->final[i].vy = k.vy[i];
        res->final[i].omega = k.w[i];
    }
    res->time = pw->t;
    res->n_events = pw->n_events;
    close_budget(pw, &k, &res->energy);
    classify(pw);
}

int wetdem_pairwise_run(struct wetdem_pairwise* pw, const struct wetdem_pairwise_config* cfg,
                        struct wetdem_pairwise_result* res)
{
    pw->errmsg[0] = '\0';
    memset(res, 0, sizeof *res);
    pw->n_events = 0;
    int st = wetdem_pairwise_config_validate(cfg, pw->errmsg, sizeof pw->errmsg);
    if (st != WETDEM_OK)
        return st;
    if (pw->obs && !(pw->obs_interval > 0.0 && isfinite(pw->obs_interval))) {
        snprintf(pw->errmsg, sizeof pw->errmsg,
                 "observer interval = %g s must be finite and > 0 (set_observer with fn NULL "
                 "removes the observer)",
                 pw->obs_interval);
        return WETDEM_ERR_INVALID;
    }
    pw->cfg = *cfg;
    pw->res = res;
    pw->t = 0.0;
    pw->n_out = 0;
    pw->done = false;
    pw->stalled = 0;
    pw->conv_fails_seen = 0;
    pw->window_steps = pw->window_fails = 0;
    pw->progress_start = pw->progress ? omp_get_wtime() : 0.0;
    initial_state(pw);
    double ke0, u_c0;
    if (!energy_parts(pw, pw->y, &ke0, &u_c0, &pw->gravity_ref))
        pw->gravity_ref = NAN;
    res->energy.initial = mechanical_energy(pw, pw->y);
    if ((st = setup_cvode(pw)) != WETDEM_OK || (st = process_events_counted(pw)) != WETDEM_OK ||
        (st = restart(pw)) != WETDEM_OK)
        return st;
    if (pw->obs) {
        if ((st = emit(pw, 0.0, pw->y)) != WETDEM_OK)
            return st;
        pw->n_out = 1;
    }
    struct wetdem_pairwise_kin k;
    if (!current_kin(pw, &k))
        return WETDEM_ERR_NUMERIC;
    pw->done = pw->cfg.stop_when_separated && all_apart(pw, &k);
    while (!pw->done)
        if ((st = advance(pw)) != WETDEM_OK ||
            (pw->progress && res->steps % WETDEM_PROGRESS_STEPS == 0 &&
             (st = report_progress(pw, true)) != WETDEM_OK))
            return st;
    if (pw->obs && (st = emit(pw, pw->t, pw->y)) != WETDEM_OK)
        return st;
    finish(pw);
    if (pw->progress)
        report_progress(pw, false); /* (the run is over: nothing left to stop) */
    return WETDEM_OK;
}

/*
 * integrator_cvode.c — "cvode": adaptive integration of the soft engine's equations of motion
 * with SUNDIALS CVODE 6.4 (Hindmarsh et al. 2005), with every branch boundary of the force
 * laws located as a root (event.c) so that no step straddles a discontinuity.
 *
 * State: y = (x, v, w) of every free particle (9 doubles each). Method (cvode.method):
 *   adams: Adams-Moulton orders 1-12 with fixed-point (functional) iteration, no Jacobian;
 *     fastest while the pair moves, since the Hertz contact time must be resolved anyway;
 *   bdf: BDF orders 1-5 with Newton iteration and a dense difference-quotient Jacobian (each
 *     Jacobian costs 9 x n_free force evaluations); needed when a pair rests in a lubricated
 *     contact, a stiff state (contact stiffness against lubrication damping, time scales
 *     m* / c and c / k far apart) where Adams is held to tiny steps by stability;
 *   auto (default): adams, restarted as bdf for the rest of the run once cvode.stiff_steps
 *     steps shorter than max_step/2 pass without an event (a stiffness heuristic in the
 *     spirit of LSODA).
 * Orders are capped at cvode.max_order = 5: for the 9 n_free unknowns of a collision the
 * O(q^2) vector operations of the Nordsieck update, not the force evaluations, dominate.
 * Tolerances: rtol = cvode.rtol; absolute tolerances per component, scaled so that one
 * dimensionless cvode.atol serves all: positions atol L, velocities atol V, spins atol V/L,
 * with L the smallest free radius [m] and V the speed scale of wetdem_sim_speed_scale() [m/s]
 * at the start of the run. Largest step: cvode.max_step, or 0.1 L/V' when 0, V' the speed
 * scale without its floor (the pairs' own largest relative speed, gravity's addition included;
 * no bound when nothing moves), so that no step can carry a pair through its interaction range
 * unseen, and for a pair closing in the larger
 * of half the time to close its gap and 0.1 of its contact time (contact_step_bound), so that
 * no step carries it through a whole solid contact.
 *
 * Run loop: CVode(CV_ONE_STEP) up to the stop time t_end. After every accepted step (or
 * located root) the pair histories are committed at the returned time (RHS evaluations are
 * trials on scratch copies) and the events of every event function that changed side are
 * logged (wetdem_event_advance): at the root CVODE located (CVodeGetRootInfo), or, for a
 * function exactly zero where CVODE started or restarted, which it does not report (a pair
 * placed exactly touching), interpolated between the step ends. On a root the integrator is
 * restarted with CVodeReInit there, at order 1, so that it never steps across the
 * discontinuity.
 * History-carrying models are not part of CVODE's error control (docs/engines.md): the largest
 * approach speed is committed at step ends and starts at a located crossing (the range, or the
 * record range of the min-separation model, event.c), so where v_n falls from there on it is
 * v_n at the crossing; a peak of v_n between two step ends is missed by its flat top's fall to
 * the nearer end. The tangential spring advances from its committed value with the
 * trapezoidal mean of v_t at the commit and at the trial (.trapezoid_spring,
 * sim_integrate.c), second order in the step.
 */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#include "integrator.h"
#include "integrator_cvode_nvec.h"
#include "vec3.h"

static const char* const method_choices[] = {"auto", "adams", "bdf", NULL};
enum { METHOD_AUTO = 0, METHOD_ADAMS = 1, METHOD_BDF = 2 };

struct cvode_params {
    double rtol;        /* relative tolerance [-] */
    double atol;        /* absolute tolerance in units of the length/speed scales [-] */
    double max_steps;   /* most steps one integrate call may take [-] */
    double method;      /* index into method_choices */
    double max_step;    /* largest step [s]; 0: 0.1 L/V */
    double stiff_steps; /* auto: Adams steps without an event before switching to BDF [-] */
    double max_order;   /* largest method order (BDF: at most 5) [-] */
};

_Static_assert(sizeof(struct cvode_params) <= WETDEM_INTEGRATOR_PARAMS_MAX * sizeof(double),
               "cvode parameters exceed the engine's parameter block");

#define P(field) offsetof(struct cvode_params, field)
static const struct wetdem_param_desc cvode_params_desc[] = {
    /* Both end at 1e-4: over a map of nijssen_oblique.ini (40 Stokes numbers from 1 to 3000 by
     * 17 angles) rtol 1e-3 let two collisions end with 4.2 times their kinetic energy, and
     * atol 1e-2 one with 4.8 times (3e-3 and 1e-2 did so on the head-on sweep too, up to
     * 39 times); at 1e-4 none does, and e moves by 1e-5 (rtol) or 1e-2 (atol) of itself. */
    {"rtol", "-", "Relative tolerance of CVODE's local error test.", P(rtol), 1e-8, 1e-14, 1e-4,
     false, false, NULL, false},
    {"atol", "-",
     "Absolute tolerance in units of the length scale (positions), speed scale (velocities) "
     "and their ratio (spins).",
     P(atol), 1e-9, 1e-16, 1e-4, false, false, NULL, false},
    {"max_steps", "-", "Largest number of steps one integrate call may take.", P(max_steps), 1e7,
     1.0, 1e12, false, false, NULL, true},
    {"method", "-",
     "adams (non-stiff, functional iteration), bdf (stiff, dense Newton) or auto (adams, "
     "switching to bdf when a stretch without events takes stiff_steps steps).",
     P(method), 0, 0, 2, false, false, method_choices, false},
    {"max_step", "s",
     "Largest step; 0 uses 0.1 x smallest radius / the pairs' largest relative speed (gravity's "
     "addition included, no floor).",
     P(max_step), 0, 0, 1e6, false, false, NULL, false},
    {"stiff_steps", "-",
     "auto: Adams steps without an event after which the problem counts as stiff (e.g. a "
     "resting lubricated contact) and BDF takes over for the rest of the run.",
     P(stiff_steps), 500, 10, 1e9, false, false, NULL, true},
    {"max_order", "-",
     "Largest order of the method (BDF uses at most 5). 5 was measured fastest for binary "
     "collisions: higher Adams orders cost O(q^2) vector operations per step.",
     P(max_order), 5, 1, 12, false, false, NULL, true},
    {0},
};
#undef P

/* State shared with the CVODE callbacks. */
struct run {
    struct wetdem_sim* sim;
    size_t* free_index; /* particle index of each state block */
    size_t n_free;
    int status; /* first non-recoverable error raised in a callback */
};

static void unpack(struct run* r, const double* y)
{
    for (size_t b = 0; b < r->n_free; b++) {
        struct wetdem_particle* p = &r->sim->particles[r->free_index[b]];
        const double* s = y + 9 * b;
        p->pos = vec3(s[0], s[1], s[2]);
        p->vel = vec3(s[3], s[4], s[5]);
        p->omega = vec3(s[6], s[7], s[8]);
    }
}

static void put3(double* d, struct wetdem_vec3 a)
{
    d[0] = a.x;
    d[1] = a.y;
    d[2] = a.z;
}

static void pack(const struct run* r, double* y)
{
    for (size_t b = 0; b < r->n_free; b++) {
        const struct wetdem_particle* p = &r->sim->particles[r->free_index[b]];
        put3(y + 9 * b, p->pos);
        put3(y + 9 * b + 3, p->vel);
        put3(y + 9 * b + 6, p->omega);
    }
}

static int rhs(sunrealtype t, N_Vector yv, N_Vector ydot, void* data)
{
    struct run* r = data;
    unpack(r, N_VGetArrayPointer(yv));
    int st = wetdem_sim_compute_forces(r->sim, t, false);
    if (st == WETDEM_ERR_NUMERIC || st == WETDEM_RETRY)
        return 1; /* recoverable: CVODE retries with a smaller step */
    if (st < 0) {
        r->status = st;
        return -1;
    }
    double* d = N_VGetArrayPointer(ydot);
    for (size_t b = 0; b < r->n_free; b++) {
        size_t k = r->free_index[b];
        put3(d + 9 * b, r->sim->particles[k].vel);
        put3(d + 9 * b + 3, wetdem_sim_acceleration(r->sim, k));
        put3(d + 9 * b + 6, wetdem_sim_angular_acceleration(r->sim, k));
    }
    return 0;
}

static int roots(sunrealtype t, N_Vector yv, sunrealtype* g, void* data)
{
    (void)t;
    struct run* r = data;
    unpack(r, N_VGetArrayPointer(yv));
    wetdem_event_values(r->sim, g);
    return 0;
}

static void error_handler(int code, const char* module, const char* function, char* msg, void* data)
{
    if (code < 0)
        wetdem_sim_fail(data, WETDEM_ERR_STEP, "cvode: %s in %s (%s)", msg, function, module);
}

/* Status of a negative CVode() flag. */
static int map_flag(struct wetdem_sim* sim, const struct run* r, int flag, double t)
{
    if (r->status < 0)
        return r->status;
    switch (flag) {
    case CV_RHSFUNC_FAIL:
    case CV_REPTD_RHSFUNC_ERR:
    case CV_UNREC_RHSFUNC_ERR:
    case CV_FIRST_RHSFUNC_ERR:
        return wetdem_sim_fail(sim, WETDEM_ERR_NUMERIC,
                               "cvode: the forces stayed non-finite at t = %.9g s even with "
                               "smaller steps",
                               t);
    case CV_TOO_MUCH_WORK: return WETDEM_ERR_MAX_STEPS;
    default: return WETDEM_ERR_STEP; /* message already stored by error_handler */
    }
}

/* Adds CVODE's counters to the engine statistics (CVodeReInit resets them). */
static void add_counters(struct wetdem_sim* sim, void* mem)
{
    long nst = 0, netf = 0, nncf = 0;
    CVodeGetNumSteps(mem, &nst);
    CVodeGetNumErrTestFails(mem, &netf);
    CVodeGetNumNonlinSolvConvFails(mem, &nncf);
    sim->engine.stats.steps += (unsigned long long)nst;
    sim->engine.stats.rejected_steps += (unsigned long long)(netf + nncf);
}

/* Every SUNDIALS object of one run; one cleanup path. */
struct solver {
    SUNContext ctx;
    N_Vector y, abstol, ytmp;
    void* mem;
    SUNMatrix jac;
    SUNLinearSolver ls;
    SUNNonlinearSolver nls;
    int* rootsfound;
    double h_max;  /* largest step [s] */
    double h_cur;  /* the largest step in effect: h_max, or less by contact_step_bound */
    double t_end;  /* end of the integration [s] */
    double t_stop; /* CVODE's stop time in effect: t_end, or t + h_cur when that is sooner */
};

/* For two spheres closing in along straight lines (contact c), the bound of a step that
 * keeps the overlap of a grazing pass from falling between two step ends [s]: with centre
 * distance D, sum of radii S and relative velocity v = -v_n n + v_t (v_t the tangential part
 * of the centres' relative velocity), the closest distance is D |v_t| / |v|; when it is below
 * S the centres are closer than S for dur = 2 sqrt(S^2 - d_min^2) / |v|, starting at
 * t_in = D v_n / |v|^2 - dur / 2. The bound is the larger of half the time to t_in and a
 * quarter of dur. INFINITY for a wall, or a pass that misses. */
static double grazing_step_bound(const struct wetdem_sim* sim, const struct wetdem_contact* c)
{
    if (c->is_wall)
        return INFINITY;
    struct wetdem_vec3 dv = vec3_sub(sim->particles[c->i].vel, sim->particles[c->j].vel);
    struct wetdem_vec3 vt = vec3_reject(dv, c->normal);
    double sum = c->radius_i + c->radius_j, d = c->gap + sum;
    double v2 = c->v_n * c->v_n + vec3_dot(vt, vt);
    double d_min = d * sqrt(vec3_dot(vt, vt) / v2);
    if (!(d_min < sum))
        return INFINITY;
    double dur = 2 * sqrt((sum - d_min) * (sum + d_min) / v2);
    double t_in = d * c->v_n / v2 - 0.5 * dur;
    return fmax(0.5 * t_in, 0.25 * dur);
}

/* A bound on the next step [s] that keeps a solid contact from being stepped over: the root
 * finder sees a sign change of the gap between the ends of a step only, so a grazing pair
 * whose contact is shorter than a step passed through it unseen (e = 1, no contact force, at
 * 89 degrees). For each pair closing in (v_n > 0, gap > 0): the larger of half the time to
 * close its gap at v_n and 0.1 of its contact time at v_n (wetdem_sim_contact_time; a step
 * that long may cross gap 0, where the root is found, but cannot also leave the contact,
 * which lasts ten of them), and at most grazing_step_bound (nearer 90 degrees the contact is
 * the geometric pass of the surfaces, shorter than the contact time at v_n: at 89.99 degrees
 * and 0.5 m/s the surfaces overlap for 7 us, a tenth of the contact time is 24 us).
 * INFINITY without such a pair or a contact model. */
static double contact_step_bound(const struct wetdem_sim* sim)
{
    double bound = INFINITY;
    const struct wetdem_pairs* pl = &sim->engine.pairs;
    for (size_t k = 0; k < pl->n; k++) {
        const struct wetdem_pair* q = &pl->items[k];
        struct wetdem_contact c;
        wetdem_sim_build_contact(sim, q->i, q->j, q->is_wall, &c);
        if (!(c.v_n > 0 && c.gap > 0))
            continue;
        double t_c = wetdem_sim_contact_time(sim, &c);
        if (isfinite(t_c) && t_c > 0)
            bound = fmin(bound,
                         fmin(fmax(0.5 * c.gap / c.v_n, 0.1 * t_c), grazing_step_bound(sim, &c)));
    }
    return bound;
}

/* Sets CVODE's largest step at time t to h_max or the tighter contact_step_bound. A new
 * largest step applies from the step after next (CVODE chose the next step's size when it
 * completed the last one), so a bound also sets the stop time t + bound, which CVODE honours
 * on the next step: without it a bound that fell from half the time to contact to a tenth of
 * the contact time let one step of the old size run into a stiff Hertz contact, and CVODE
 * failed there (corrector convergence). 0 or -1. */
static int limit_step(const struct wetdem_sim* sim, struct solver* s, double t)
{
    double bound = contact_step_bound(sim);
    double h = fmin(s->h_max, bound);
    double stop = bound < s->h_max && t + bound < s->t_end ? t + bound : s->t_end;
    if (stop > t && stop != s->t_stop) {
        s->t_stop = stop;
        if (CVodeSetStopTime(s->mem, stop) != CV_SUCCESS)
            return -1;
    }
    if (h == s->h_cur)
        return 0;
    s->h_cur = h;
    return CVodeSetMaxStep(s->mem, h) == CV_SUCCESS ? 0 : -1;
}

static void solver_free(struct solver* s)
{
    if (s->mem)
        CVodeFree(&s->mem);
    if (s->nls)
        SUNNonlinSolFree(s->nls);
    if (s->ls)
        SUNLinSolFree(s->ls);
    if (s->jac)
        SUNMatDestroy(s->jac);
    if (s->y)
        N_VDestroy(s->y);
    if (s->abstol)
        N_VDestroy(s->abstol);
    if (s->ytmp)
        N_VDestroy(s->ytmp);
    free(s->rootsfound);
    if (s->ctx)
        SUNContext_Free(&s->ctx);
}

/* Absolute tolerances: positions atol L, velocities atol V, spins atol V/L. */
static void fill_abstol(const struct run* r, double atol, double len, double speed, double* a)
{
    for (size_t b = 0; b < r->n_free; b++)
        for (int q = 0; q < 3; q++) {
            a[9 * b + q] = atol * len;
            a[9 * b + 3 + q] = atol * speed;
            a[9 * b + 6 + q] = atol * speed / len;
        }
}

/* The method's iteration: Adams with fixed-point iteration or BDF with dense Newton. Returns
 * CV_SUCCESS, CV_MEM_FAIL (out of memory) or another CVODE flag. */
static int attach_solvers(struct solver* s, bool bdf, sunindextype n)
{
    if (!bdf) {
        s->nls = SUNNonlinSol_FixedPoint(s->y, 0, s->ctx);
        return s->nls ? CVodeSetNonlinearSolver(s->mem, s->nls) : CV_MEM_FAIL;
    }
    s->jac = SUNDenseMatrix(n, n, s->ctx);
    s->ls = s->jac ? SUNLinSol_Dense(s->y, s->jac, s->ctx) : NULL;
    if (!s->ls)
        return CV_MEM_FAIL;
    int flag = CVodeSetLinearSolver(s->mem, s->ls, s->jac);
    return flag == CVLS_MEM_FAIL ? CV_MEM_FAIL : flag;
}

static int solver_create(struct wetdem_sim* sim, struct run* r, const struct cvode_params* p,
                         double t_end, bool bdf, struct solver* s)
{
    sunindextype n = (sunindextype)(9 * r->n_free);
    double len = wetdem_sim_length_scale(sim), speed = wetdem_sim_speed_scale(sim, NULL);
    /* (the pairs' own speed, not the floored scale: beneath sim.speed_floor the floor held a
     * slow approach to steps floor / v times too short, and t_end grows as 1 / v) */
    double motion = wetdem_sim_motion_speed(sim);
    double h_max = p->max_step > 0 ? p->max_step : motion > 0 ? 0.1 * len / motion : INFINITY;
    s->h_max = h_max;
    s->h_cur = fmin(h_max, contact_step_bound(sim));
    s->t_end = s->t_stop = t_end;
    int ok = SUNContext_Create(NULL, &s->ctx) == 0;
    ok = ok && (s->y = N_VNew_Serial(n, s->ctx)) && (s->abstol = N_VNew_Serial(n, s->ctx)) &&
         (s->ytmp = N_VNew_Serial(n, s->ctx));
    ok = ok && (s->rootsfound = malloc((sim->engine.n_slots + 1) * sizeof(int)));
    ok = ok && (s->mem = CVodeCreate(bdf ? CV_BDF : CV_ADAMS, s->ctx));
    if (!ok)
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "cvode: out of memory");
    /* fused vector kernels: one call per Nordsieck update instead of q (measured 10 %);
     * the packaged kernels are unoptimised: ours, bit-identical (integrator_cvode_nvec.c) */
    N_VEnableFusedOps_Serial(s->y, SUNTRUE);
    wetdem_integrator_cvode_nvec_install(s->y);
    pack(r, N_VGetArrayPointer(s->y));
    fill_abstol(r, p->atol, len, speed, N_VGetArrayPointer(s->abstol));
    CVodeSetErrHandlerFn(s->mem, error_handler, sim);
    int flag = CVodeInit(s->mem, rhs, sim->engine.time, s->y);
    if (flag == CV_SUCCESS)
        flag = CVodeSVtolerances(s->mem, p->rtol, s->abstol);
    if (flag == CV_SUCCESS)
        flag = CVodeSetUserData(s->mem, r);
    if (flag == CV_SUCCESS)
        flag = CVodeSetStopTime(s->mem, t_end);
    if (flag == CV_SUCCESS)
        flag = CVodeSetMaxStep(s->mem, s->h_cur);
    if (flag == CV_SUCCESS)
        flag = CVodeRootInit(s->mem, (int)sim->engine.n_slots, roots);
    if (flag == CV_SUCCESS)
        flag = CVodeSetMaxOrd(s->mem, (int)fmin(p->max_order, bdf ? 5 : 12));
    if (flag == CV_SUCCESS)
        flag = attach_solvers(s, bdf, n);
    if (flag == CV_MEM_FAIL)
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "cvode: out of memory setting up");
    return flag == CV_SUCCESS
               ? WETDEM_OK
               : wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "cvode: set-up failed: %s", sim->errmsg);
}

/* Observer calls at the observer times in (previous time, t_new], on the interpolant. */
static int observe_between(struct wetdem_sim* sim, struct run* r, struct solver* s, double t_new)
{
    struct wetdem_engine* e = &sim->engine;
    if (!e->observer || !(e->observer_interval > 0))
        return WETDEM_OK;
    while (e->next_observe <= t_new) {
        double t = e->next_observe;
        if (CVodeGetDky(s->mem, t, 0, s->ytmp) != CV_SUCCESS)
            return wetdem_sim_fail(sim, WETDEM_ERR_STEP, "cvode: no interpolant at t = %g s", t);
        unpack(r, N_VGetArrayPointer(s->ytmp));
        e->time = t;
        int st = wetdem_sim_observe(sim); /* (which sets the next observer time) */
        if (st != WETDEM_OK)
            return st;
    }
    return WETDEM_OK;
}

/* Bookkeeping after CVode returned flag >= 0 at t: observer, commit, events, restart at a
 * root, stop check, monitor. *stop is set when the separation condition holds. */
static int after_return(struct wetdem_sim* sim, struct run* r, struct solver* s, int flag, double t,
                        bool* stop)
{
    struct wetdem_engine* e = &sim->engine;
    int st = observe_between(sim, r, s, t);
    if (st != WETDEM_OK) {
        /* stopped by the observer (or without an interpolant): the run stays at the state and
           time it last saw, engine.time <= t, committed there, and not at the step's end t, so
           that a further call goes on from there; no root lies before t, so no event is lost
           (the next call evaluates the event functions afresh) */
        int committed = wetdem_sim_commit_histories(sim, e->time);
        return committed != WETDEM_OK ? committed : st;
    }
    unpack(r, N_VGetArrayPointer(s->y));
    double t_prev = e->time;
    e->time = t;
    if (st == WETDEM_OK)
        st = wetdem_sim_commit_histories(sim, t);
    if (st != WETDEM_OK)
        return st;
    if (flag == CV_ROOT_RETURN)
        CVodeGetRootInfo(s->mem, s->rootsfound);
    else
        memset(s->rootsfound, 0, e->n_slots * sizeof *s->rootsfound);
    st = wetdem_event_advance(sim, t_prev, t, s->rootsfound);
    if (flag == CV_ROOT_RETURN) {
        add_counters(sim, s->mem);
        if (st == WETDEM_OK && CVodeReInit(s->mem, t, s->y) != CV_SUCCESS)
            st = WETDEM_ERR_STEP;
    }
    if (st == WETDEM_OK)
        *stop = wetdem_sim_separation_reached(sim);
    return st == WETDEM_OK ? wetdem_sim_step_done(sim) : st;
}

/* Restarts the integration with BDF at the current state (method auto, stiffness). */
static int switch_to_bdf(struct wetdem_sim* sim, struct run* r, struct solver* s,
                         const struct cvode_params* p, double t_end)
{
    add_counters(sim, s->mem);
    solver_free(s);
    *s = (struct solver){0};
    return solver_create(sim, r, p, t_end, true, s);
}

static int run_loop(struct wetdem_sim* sim, struct run* r, struct solver* s,
                    const struct cvode_params* p, double t_end)
{
    bool stop = false, bdf = p->method == METHOD_BDF;
    double quiet = 0; /* steps since the last root or restart */
    for (double steps = 1; sim->engine.time < t_end; steps++, quiet++) {
        if (steps > p->max_steps)
            return wetdem_sim_fail(sim, WETDEM_ERR_MAX_STEPS,
                                   "cvode: cvode.max_steps = %.3g steps taken before t = %.9g s "
                                   "(now at %.9g s); raise it, or for pairs slower than "
                                   "sim.speed_floor = %g m/s, whose time and length scales bound "
                                   "the steps, lower that",
                                   p->max_steps, t_end, sim->engine.time,
                                   sim->settings.speed_floor);
        if (!bdf && p->method == METHOD_AUTO && quiet > p->stiff_steps) {
            int st = switch_to_bdf(sim, r, s, p, t_end);
            if (st != WETDEM_OK)
                return st;
            bdf = true;
        }
        double t = sim->engine.time;
        int flag = CVode(s->mem, t_end, s->y, &t, CV_ONE_STEP);
        if (flag < 0)
            return map_flag(sim, r, flag, sim->engine.time);
        int st = after_return(sim, r, s, flag, t, &stop);
        if (st != WETDEM_OK)
            return st;
        if (stop)
            return WETDEM_EVENT;
        double h_last = 0;
        CVodeGetLastStep(s->mem, &h_last);
        if (flag == CV_ROOT_RETURN || h_last > 0.5 * s->h_cur)
            quiet = 0; /* an event, or a step limited by max_step rather than stability */
        if (flag == CV_TSTOP_RETURN && s->t_stop == t_end)
            sim->engine.time = t_end;
        if (limit_step(sim, s, sim->engine.time) != 0)
            return wetdem_sim_fail(sim, WETDEM_ERR_STEP, "cvode: cannot set the largest step");
    }
    return WETDEM_OK;
}

static int cvode_integrate(struct wetdem_sim* sim, const void* params, double t_end)
{
    const struct cvode_params* p = params;
    if (!(t_end > sim->engine.time))
        return WETDEM_OK;
    double t = sim->engine.time, span = t_end - t;
    /* CVODE's step selection fails below WETDEM_MIN_SPAN, and it starts no step to a t_end
       within two roundings of t ("tout too close to t0") */
    double shortest = fmax(WETDEM_MIN_SPAN, 2 * DBL_EPSILON * fmax(fabs(t), fabs(t_end)));
    if (span < shortest)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "cvode: t_end - t = %g s is shorter than the %g s that CVODE "
                               "integrates from t = %.17g s (1e-150 s, or 2 DBL_EPSILON t_end "
                               "if more); give a longer t_end",
                               span, shortest, t);
    struct run r = {.sim = sim};
    r.free_index = malloc((sim->n_particles ? sim->n_particles : 1) * sizeof *r.free_index);
    if (!r.free_index)
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "cvode: out of memory");
    for (size_t k = 0; k < sim->n_particles; k++)
        if (!sim->particles[k].is_fixed)
            r.free_index[r.n_free++] = k;
    int st = WETDEM_OK;
    if (r.n_free == 0) {
        sim->engine.time = t_end; /* nothing moves */
    } else {
        struct solver s = {0};
        st = solver_create(sim, &r, p, t_end, p->method == METHOD_BDF, &s);
        if (st == WETDEM_OK)
            st = run_loop(sim, &r, &s, p, t_end);
        if (s.mem)
            add_counters(sim, s.mem);
        solver_free(&s);
    }
    free(r.free_index);
    return st;
}

const struct wetdem_integrator wetdem_integrator_cvode = {
    .name = "cvode",
    .summary = "SUNDIALS CVODE (Adams or BDF), adaptive, events at every force-law branch",
    .params = cvode_params_desc,
    .params_size = sizeof(struct cvode_params),
    .integrate = cvode_integrate,
    .trapezoid_spring = true,
};

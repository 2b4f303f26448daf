/*
 * integrator_cvode.c — "cvode": adaptive integration of the soft engine's equations of motion
 * with SUNDIALS CVODE 6.4 (Hindmarsh et al. 2005), with every branch boundary of the force
 * laws located as a root (event.c) so that no step straddles a discontinuity.
 *
 * State: y = (x, v, w) of every free particle (9 doubles each), then, while some pair is within
 * its tangential spring's range (h < max(h_min, 0): entered and left at located events, where
 * the solver is created anew with or without them), q of every pair (3 doubles each): the
 * integral of the pair's v_t while its spring acts (sim_integrate.c), so that the spring,
 * which advances from its committed value by the increment of q, is under the local error
 * test (absolute tolerance atol L, as positions). Method (cvode.method):
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
 * Stick-slip transitions of the tangential springs (docs/engines.md): a trial from a sticking
 * commit is the spring itself, so where it starts to slide inside a step the force has only a
 * kink, under the error test; from a sliding commit (the spring capped there) the trial
 * differs from the spring once the pair sticks again, and the slip margin of the trial (|F_t|
 * before the cap minus the cap) peaks at the transition. So after every step each spring
 * that slid at the commit and whose trial margin falls at the step end has its transition
 * located at that peak on CVODE's interpolant, and each sticking spring whose margin turned
 * positive has its start of sliding located at the margin's root; the run is restarted at the
 * earliest such time inside the step (locate_transition), the rest of the step discarded (the
 * commit at the step's end, whose evaluation gives the margins there, is taken back).
 * The largest approach speed is not part of CVODE's error control: it is committed at step
 * ends and starts at a located crossing (the range, or the record range of the
 * min-separation model, event.c), so where v_n falls from there on it is v_n at the crossing;
 * a peak of v_n between two step ends is missed by its flat top's fall to the nearer end.
 */
#include <float.h>
#include <math.h>
#include <stdint.h>
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
    /* the pairs and their histories as committed before the latest commit (after_return
     * takes a commit back when a stick-slip transition fell inside the step), and the slip
     * margin of every pair's trial just before the step's end [N]; room for the latest commit
     * while the observer sees the one before (after_return) */
    struct wetdem_pair *pairs_before, *pairs_after;
    double *history_before, *history_after, *margin_before;
    double* at_end; /* per pair: its trial margin and |F_t| at the step's end, or NAN NAN when
                       no transition is possible there (may_transit) [N] */
    double* ydot;   /* the latest right-hand side (n_state doubles), evaluated at t_rhs */
    double t_rhs;
    bool with_q;    /* the state holds q of every pair (some pair within its spring's range) */
    size_t n_state; /* 9 n_free, and 3 per pair with_q */
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
    struct wetdem_pairs* pl = &r->sim->engine.pairs;
    const double* q = y + 9 * r->n_free;
    for (size_t k = 0; r->with_q && k < pl->n; k++)
        pl->items[k].q_trial = vec3(q[3 * k], q[3 * k + 1], q[3 * k + 2]);
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
    const struct wetdem_pairs* pl = &r->sim->engine.pairs;
    for (size_t k = 0; r->with_q && k < pl->n; k++)
        put3(y + 9 * r->n_free + 3 * k, pl->items[k].q_committed);
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
    const struct wetdem_pairs* pl = &r->sim->engine.pairs;
    for (size_t k = 0; r->with_q && k < pl->n; k++)
        put3(d + 9 * r->n_free + 3 * k, pl->items[k].q_rate);
    memcpy(r->ydot, d, r->n_state * sizeof *d);
    r->t_rhs = t;
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

/* Absolute tolerances: positions and the q of the pairs atol L, velocities atol V, spins
 * atol V/L. */
static void fill_abstol(const struct run* r, double atol, double len, double speed, double* a)
{
    for (size_t k = 9 * r->n_free; k < r->n_state; k++)
        a[k] = atol * len;
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

/* Whether some pair is within the range of its tangential spring (the state then holds q). */
static bool some_spring_acts(const struct wetdem_sim* sim)
{
    for (size_t k = 0; k < sim->engine.pairs.n; k++)
        if (sim->engine.pairs.items[k].spring_zone)
            return true;
    return false;
}

static int solver_create(struct wetdem_sim* sim, struct run* r, const struct cvode_params* p,
                         double t_end, bool bdf, struct solver* s)
{
    r->with_q = some_spring_acts(sim); /* q while some pair is within its spring's range */
    r->n_state = 9 * r->n_free + (r->with_q ? 3 * sim->engine.pairs.n : 0);
    r->t_rhs = NAN;
    sunindextype n = (sunindextype)r->n_state;
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

/* The slip margin of pair k's spring (a trial from the commit) at time t of the last step,
 * on CVODE's interpolant [N]. */
static double margin_at(struct wetdem_sim* sim, struct run* r, struct solver* s, size_t k, double t,
                        int* status)
{
    if (CVodeGetDky(s->mem, t, 0, s->ytmp) != CV_SUCCESS) {
        *status = wetdem_sim_fail(sim, WETDEM_ERR_STEP, "cvode: no interpolant at t = %g s", t);
        return 0.0;
    }
    unpack(r, N_VGetArrayPointer(s->ytmp));
    double f_t = 0.0;
    return wetdem_sim_slip_margin(sim, k, t, &f_t, status);
}

/* Time [s] at which pair k's spring changes between sticking and sliding inside the step
 * (t_prev, t], or t (none), from the commit at t_prev (restored) and the trial margin e_hi
 * at t. Sliding at the commit (the spring capped there), the trial margin e rises while the
 * pair slides and, once it sticks at t*, falls from its peak at t* (e' = d|F_t|/dt of the
 * sticking spring minus that of the cap, which changes sign there): when e falls at t
 * (may_transit), t* is its maximum, found by golden section to 1e-6 of the step (near the
 * peak e is flat: a spring capped that far from it is off by 1e-12 of the margin's change over
 * the step). Sticking at the commit, the trial is the spring: the start of sliding is the
 * root of e, found by regula falsi (Illinois) to 1e-12 of the step, at the end where e > 0,
 * so that the commit there caps the spring. A transition counts only inside the step, more
 * than 1e-6 of it (and 16 roundings of t) from its ends, and where the margin it corrects,
 * the peak's height above e(t) or e(t) > 0, exceeds 1e-12 |F_t|: a spring capped at the
 * wrong one of two times that close is off by less, and below it the margin is rounding
 * (|F_t| minus the cap, two numbers of size |F_t|): without this floor the steps of a few
 * 1e-11 s after the contact starts saw rounding as transitions and restarted at every one. */
static double locate_transition(struct wetdem_sim* sim, struct run* r, struct solver* s, size_t k,
                                double t_prev, double t, int* status)
{
    const double h = t - t_prev, g = 0.5 * (sqrt(5.0) - 1.0);
    const double tol = fmax(1e-6 * h, 16 * DBL_EPSILON * fabs(t));
    const struct wetdem_pair* before = &r->pairs_before[k];
    double e_hi = r->at_end[2 * k], floor = 1e-12 * r->at_end[2 * k + 1];
    double found = t;
    if (before->sliding) { /* Brent: parabolic steps, golden sections where they fail */
        double a = t_prev, b = t, x = a + (1 - g) * (b - a), w = x, v = x, d = 0, step = 0;
        double fx = -margin_at(sim, r, s, k, x, status), fw = fx, fv = fx;
        while (*status == WETDEM_OK) {
            double m = 0.5 * (a + b), tol2 = 2 * tol;
            if (fabs(x - m) <= tol2 - 0.5 * (b - a))
                break;
            bool golden = true;
            if (fabs(step) > tol) {
                double p1 = (x - w) * (fx - fv), q1 = (x - v) * (fx - fw);
                double p = (x - v) * q1 - (x - w) * p1, q = 2 * (q1 - p1);
                if (q > 0)
                    p = -p;
                q = fabs(q);
                if (fabs(p) < fabs(0.5 * q * step) && p > q * (a - x) && p < q * (b - x)) {
                    step = d, d = p / q, golden = false;
                    if ((x + d) - a < tol2 || b - (x + d) < tol2)
                        d = x < m ? tol : -tol;
                }
            }
            if (golden) {
                step = x >= m ? a - x : b - x;
                d = (1 - g) * step;
            }
            double u = fabs(d) >= tol ? x + d : x + (d > 0 ? tol : -tol);
            double fu = -margin_at(sim, r, s, k, u, status);
            if (fu <= fx) {
                if (u >= x)
                    a = x;
                else
                    b = x;
                v = w, fv = fw, w = x, fw = fx, x = u, fx = fu;
            } else {
                if (u < x)
                    a = u;
                else
                    b = u;
                if (fu <= fw || w == x)
                    v = w, fv = fw, w = u, fw = fu;
                else if (fu <= fv || v == x || v == w)
                    v = u, fv = fu;
            }
        }
        if (!(-fx - e_hi > floor))
            return t;
        found = x;
    } else {
        const double t_tol = fmax(1e-12 * h, 4 * DBL_EPSILON * fabs(t));
        double a = t_prev, b = t, fa = fmin(before->slip, 0.0), fb = e_hi;
        int side = 0; /* which end stayed last (Illinois: its value is halved) */
        for (int it = 0; *status == WETDEM_OK && b - a > t_tol && it < 200; it++) {
            double m = fb > fa ? (a * fb - b * fa) / (fb - fa) : 0.5 * (a + b);
            if (!(m > a && m < b) || it % 8 == 7)
                m = 0.5 * (a + b); /* (and now and then a bisection, which always shrinks) */
            double fm = margin_at(sim, r, s, k, m, status);
            if (fm > 0.0) {
                b = m, fb = fm;
                if (side == -1)
                    fa *= 0.5;
                side = -1;
            } else {
                a = m, fa = fm;
                if (side == 1)
                    fb *= 0.5;
                side = 1;
            }
        }
        found = b;
    }
    return found - t_prev > tol && t - found > tol ? found : t;
}

/* The offset before the step's end [s] at which a sliding spring's trial margin is compared
 * with the end's, to see whether it falls there: 1e-6 of the step (and 16 roundings of t). */
static double fall_offset(double t_prev, double t)
{
    return fmax(1e-6 * (t - t_prev), 16 * DBL_EPSILON * fabs(t));
}

/* Whether pair k (as committed before the step) may have changed between sticking and sliding
 * inside the step: its spring acted at the commit and either slid, and its trial margin falls
 * at the step's end (e_hi below the margin just before, r->margin_before), or stuck, and the
 * margin at the end is above the rounding floor 1e-12 |F_t| (locate_transition). */
static bool may_transit(const struct run* r, const struct wetdem_pairs* pl, size_t k)
{
    const struct wetdem_pair* before = &r->pairs_before[k];
    double e_hi = pl->items[k].slip;
    if (!before->acting || e_hi == 0.0) /* (a spring starts to act at a located event) */
        return false;
    return before->sliding ? e_hi < r->margin_before[k] : e_hi > 1e-12 * pl->items[k].f_t;
}

/* The trial margin of pair k at t - dt, just before the end t of the step [N]: at the state
 * y(t) - dt y'(t) when the latest right-hand side was evaluated at t (the corrector's last
 * iterate, within the tolerances of y(t): an error of order dt^2 and dt tol beside the
 * change dt e' the comparison looks for), else on the interpolant. */
static double margin_before_end(struct wetdem_sim* sim, struct run* r, struct solver* s, size_t k,
                                double t, double dt, int* status)
{
    if (r->t_rhs != t)
        return margin_at(sim, r, s, k, t - dt, status);
    const double* y = N_VGetArrayPointer(s->y);
    double* x = N_VGetArrayPointer(s->ytmp);
    for (size_t q = 0; q < r->n_state; q++)
        x[q] = y[q] - dt * r->ydot[q];
    unpack(r, x);
    double f_t = 0.0;
    return wetdem_sim_slip_margin(sim, k, t - dt, &f_t, status);
}

/* Commits the pair histories at t, the end of the step from e->time, keeping what they were
 * (r->pairs_before, r->history_before), after the trial margins of the springs that slid at
 * the commit just before t (r->margin_before, on the interpolant, for may_transit). */
static int commit_step(struct wetdem_sim* sim, struct run* r, struct solver* s, double t)
{
    struct wetdem_engine* e = &sim->engine;
    struct wetdem_pairs* pl = &e->pairs;
    for (size_t k = 0; k < pl->n; k++) {
        int st = WETDEM_OK;
        r->margin_before[k] = pl->items[k].acting && pl->items[k].sliding
                                  ? margin_before_end(sim, r, s, k, t, fall_offset(e->time, t), &st)
                                  : 0.0;
        if (st != WETDEM_OK)
            return st;
    }
    unpack(r, N_VGetArrayPointer(s->y));
    memcpy(r->pairs_before, pl->items, pl->n * sizeof *pl->items);
    if (sim->history_len > 0)
        memcpy(r->history_before, pl->history, pl->n * sim->history_len * sizeof(double));
    return wetdem_sim_commit_histories(sim, t);
}

/* Takes the latest commit back (commit_step). */
static void uncommit(struct wetdem_sim* sim, const struct run* r, double t_prev)
{
    struct wetdem_pairs* pl = &sim->engine.pairs;
    memcpy(pl->items, r->pairs_before, pl->n * sizeof *pl->items);
    if (sim->history_len > 0)
        memcpy(pl->history, r->history_before, pl->n * sim->history_len * sizeof(double));
    sim->engine.t_committed = t_prev;
}

/* observe_between up to t, the end of the step from t_prev whose commit at t stands: the
 * observer sees the histories committed at t_prev, as the trials inside the step did. */
static int observe_committed_step(struct wetdem_sim* sim, struct run* r, struct solver* s,
                                  double t_prev, double t)
{
    struct wetdem_engine* e = &sim->engine;
    struct wetdem_pairs* pl = &e->pairs;
    if (!e->observer || !(e->observer_interval > 0) || e->next_observe > t)
        return WETDEM_OK;
    size_t len = pl->n * sim->history_len * sizeof(double);
    memcpy(r->pairs_after, pl->items, pl->n * sizeof *pl->items);
    if (len)
        memcpy(r->history_after, pl->history, len);
    uncommit(sim, r, t_prev);
    int st = observe_between(sim, r, s, t);
    if (st != WETDEM_OK)
        return st; /* (stopped: the histories stay those of t_prev, for after_return) */
    memcpy(pl->items, r->pairs_after, pl->n * sizeof *pl->items);
    if (len)
        memcpy(pl->history, r->history_after, len);
    e->t_committed = t;
    return st;
}

/* Bookkeeping after CVode returned *flag >= 0 at t: commit, and where a stick-slip transition
 * fell inside the step the commit taken back and made at the transition instead (the state
 * moved back there, *flag CV_SUCCESS, the rest of the step discarded); observer, events,
 * restart at a root or transition, stop check, monitor. *stop is set when the separation
 * condition holds; *restarted when CVODE was restarted. */
static int after_return(struct wetdem_sim* sim, struct run* r, struct solver* s, int* flag,
                        double t, bool* stop, bool* restarted)
{
    struct wetdem_engine* e = &sim->engine;
    double t_prev = e->time, t_step = t;
    int st = commit_step(sim, r, s, t);
    if (st != WETDEM_OK)
        return st;
    size_t stuck = SIZE_MAX; /* the pair whose slip ended at t, if any */
    bool taken_back = false;
    for (size_t k = 0; k < e->pairs.n; k++) {
        bool may = may_transit(r, &e->pairs, k);
        r->at_end[2 * k] = may ? e->pairs.items[k].slip : NAN;
        r->at_end[2 * k + 1] = may ? e->pairs.items[k].f_t : NAN;
    }
    for (size_t k = 0; k < e->pairs.n; k++) {
        if (isnan(r->at_end[2 * k]))
            continue;
        if (!taken_back) {
            uncommit(sim, r, t_prev);
            taken_back = true;
        }
        double t_k = locate_transition(sim, r, s, k, t_prev, t_step, &st);
        if (st != WETDEM_OK)
            return st;
        if (t_k < t) {
            t = t_k;
            stuck = r->pairs_before[k].sliding ? k : SIZE_MAX;
        }
    }
    if (t < t_step) { /* back to the transition */
        if (CVodeGetDky(s->mem, t, 0, s->y) != CV_SUCCESS)
            return wetdem_sim_fail(sim, WETDEM_ERR_STEP, "cvode: no interpolant at t = %g s", t);
        *flag = CV_SUCCESS;
    }
    *restarted = t < t_step || *flag == CV_ROOT_RETURN;
    st = taken_back ? observe_between(sim, r, s, t) : observe_committed_step(sim, r, s, t_prev, t);
    if (st != WETDEM_OK) {
        /* stopped by the observer (or without an interpolant): the run stays at the state and
           time it last saw, engine.time <= t, committed there, and not at the step's end t, so
           that a further call goes on from there; no root lies before t, so no event is lost
           (the next call evaluates the event functions afresh) */
        int committed = wetdem_sim_commit_histories(sim, e->time);
        return committed != WETDEM_OK ? committed : st;
    }
    unpack(r, N_VGetArrayPointer(s->y));
    e->time = t;
    if (st == WETDEM_OK && taken_back)
        st = wetdem_sim_commit_histories(sim, t);
    if (st != WETDEM_OK)
        return st;
    if (stuck != SIZE_MAX) /* capped at its peak margin, from where it sticks */
        e->pairs.items[stuck].sliding = false;
    if (*flag == CV_ROOT_RETURN)
        CVodeGetRootInfo(s->mem, s->rootsfound);
    else
        memset(s->rootsfound, 0, e->n_slots * sizeof *s->rootsfound);
    st = wetdem_event_advance(sim, t_prev, t, s->rootsfound);
    if (*restarted) {
        add_counters(sim, s->mem);
        if (st == WETDEM_OK && CVodeReInit(s->mem, t, s->y) != CV_SUCCESS)
            st = WETDEM_ERR_STEP;
    }
    if (st == WETDEM_OK)
        *stop = wetdem_sim_separation_reached(sim);
    return st == WETDEM_OK ? wetdem_sim_step_done(sim) : st;
}

/* Restarts the integration at the current state: with BDF (method auto, stiffness), or
 * with or without the q of the pairs (whether some pair is within its spring's range:
 * solver_create). */
static int restart_solver(struct wetdem_sim* sim, struct run* r, struct solver* s,
                          const struct cvode_params* p, double t_end, bool bdf)
{
    add_counters(sim, s->mem);
    solver_free(s);
    *s = (struct solver){0};
    return solver_create(sim, r, p, t_end, bdf, s);
}

/* Whether the state must change to hold q (some pair is now within its spring's range, e.g.
 * past nijssen's h_min or in solid contact) or to drop it (none is): the range is entered and
 * left at located events, where CVODE restarts anyway. */
static bool q_change_due(const struct wetdem_sim* sim, const struct run* r)
{
    return some_spring_acts(sim) != r->with_q;
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
            int st = restart_solver(sim, r, s, p, t_end, true);
            if (st != WETDEM_OK)
                return st;
            bdf = true;
        }
        double t = sim->engine.time;
        int flag = CVode(s->mem, t_end, s->y, &t, CV_ONE_STEP);
        if (flag < 0)
            return map_flag(sim, r, flag, sim->engine.time);
        bool restarted = false;
        double h_last = 0;
        CVodeGetLastStep(s->mem, &h_last);
        int st = after_return(sim, r, s, &flag, t, &stop, &restarted);
        if (st != WETDEM_OK)
            return st;
        if (stop)
            return WETDEM_EVENT;
        if (restarted || h_last > 0.5 * s->h_cur)
            quiet = 0; /* an event, or a step limited by max_step rather than stability */
        if (flag == CV_TSTOP_RETURN && s->t_stop == t_end)
            sim->engine.time = t_end;
        /* (after that test: a new solver's stop time is t_end) */
        if (sim->engine.time < t_end && q_change_due(sim, r)) {
            st = restart_solver(sim, r, s, p, t_end, bdf);
            if (st != WETDEM_OK)
                return st;
        }
        if (limit_step(sim, s, sim->engine.time) != 0)
            return wetdem_sim_fail(sim, WETDEM_ERR_STEP, "cvode: cannot set the largest step");
    }
    return WETDEM_OK;
}

static void run_free(struct run* r)
{
    free(r->free_index);
    free(r->pairs_before);
    free(r->pairs_after);
    free(r->history_before);
    free(r->history_after);
    free(r->margin_before);
    free(r->ydot);
    free(r->at_end);
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
    size_t n_pairs = sim->engine.pairs.n ? sim->engine.pairs.n : 1;
    r.free_index = malloc((sim->n_particles ? sim->n_particles : 1) * sizeof *r.free_index);
    size_t n_history = n_pairs * (sim->history_len ? sim->history_len : 1);
    r.pairs_before = malloc(n_pairs * sizeof *r.pairs_before);
    r.pairs_after = malloc(n_pairs * sizeof *r.pairs_after);
    r.history_before = malloc(n_history * sizeof(double));
    r.history_after = malloc(n_history * sizeof(double));
    r.margin_before = malloc(n_pairs * sizeof *r.margin_before);
    r.at_end = malloc(2 * n_pairs * sizeof *r.at_end);
    r.ydot = malloc((9 * sim->n_particles + 3 * n_pairs) * sizeof *r.ydot); /* (at most) */
    r.t_rhs = NAN;
    if (!r.free_index || !r.pairs_before || !r.pairs_after || !r.history_before ||
        !r.history_after || !r.margin_before || !r.ydot || !r.at_end) {
        run_free(&r);
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "cvode: out of memory");
    }
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
    run_free(&r);
    return st;
}

const struct wetdem_integrator wetdem_integrator_cvode = {
    .name = "cvode",
    .summary = "SUNDIALS CVODE (Adams or BDF), adaptive, events at every force-law branch",
    .params = cvode_params_desc,
    .params_size = sizeof(struct cvode_params),
    .integrate = cvode_integrate,
    .spring_state = true,
};

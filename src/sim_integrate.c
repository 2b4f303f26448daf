/*
 * sim_integrate.c — the run loop of the soft engine (docs/engines.md): pair forces summed
 * over the pair list, the start and end of a run, the stop on separation, the observer, the
 * progress callback, integrator choice, statistics and the event log. Prefix: wetdem_sim_.
 *
 * Equations of motion of every free particle (fixed particles and walls do not move):
 *     dx/dt = v,   dv/dt = (sum of pair forces)/m + g,   dw/dt = (sum of pair torques)/I,
 *     I = (2/5) m R^2  (solid sphere).
 * For a pair with normal n (j to i) and model output f: F_i = f_normal n + f_tan,
 * F_j = -F_i; torques torque_i, torque_j as the models give them.
 *
 * History semantics: a pair's history (pairs.h) holds the committed state at time
 * engine.t_committed; a force evaluation at time t hands the models a scratch copy with
 * c->dt = t - t_committed and keeps the advanced copy only on commit. Pairs beyond their
 * interaction range are not evaluated, and their history is reset on commit, so each
 * encounter starts afresh. With engine.spring_state (cvode, whose evaluations are trials
 * anywhere in the step) the integrator carries per pair q, the integral of v_t while the
 * pair's tangential spring acts (dq/dt = q_rate, set here at every evaluation), and the
 * spring advances from its committed value by the increment of q, projected into the current
 * tangent plane,
 *     v_s (t - t_c) = (q(t) - q(t_c)) - ((q(t) - q(t_c)) . n) n   (c->dv_t_spring = v_s - v_t),
 * integrated under the integrator's error control (docs/engines.md); the pair's slip margin
 * (struct wetdem_pair_force slip) is kept for the location of the stick-slip transitions.
 * verlet, whose forces see the velocities predicted for the step's end, sets engine.half_vel
 * and half_omega during its evaluation instead, and the spring advances with the slip of the
 * half-step velocities at the current normal (midpoint rule, also second order).
 */
#include <float.h>
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "contact.h"
#include "integrator.h"
#include "models.h"
#include "vec3.h"

void wetdem_sim_engine_init(struct wetdem_sim* sim)
{
    struct wetdem_engine* e = &sim->engine;
    memset(e, 0, sizeof *e);
    const struct wetdem_integrator* const* reg = wetdem_integrator_registry();
    for (size_t k = 0; k < WETDEM_MAX_INTEGRATORS && reg[k]; k++)
        wetdem_param_init_defaults(reg[k]->params, e->integrator_params[k]);
    e->integrator = 0;
    e->last_observed = NAN;
}

void wetdem_sim_engine_free(struct wetdem_sim* sim)
{
    struct wetdem_engine* e = &sim->engine;
    wetdem_pairs_free(&e->pairs);
    free(e->pair_gap);
    free(e->pair_vn);
    free(e->pair_gap_prev);
    free(e->pair_vn_prev);
    free(e->pair_range);
    free(e->slots);
    free(e->g_prev);
    free(e->g_new);
    free(e->events);
    free(e->force);
    free(e->torque);
}

void wetdem_sim_engine_clear(struct wetdem_sim* sim)
{
    struct wetdem_engine* e = &sim->engine;
    wetdem_pairs_clear(&e->pairs);
    e->n_slots = 0;
    e->n_events = 0;
    e->stats = (struct wetdem_stats){0};
    e->time = 0.0;
    e->t_committed = 0.0;
    e->next_observe = 0.0;
    e->last_observed = NAN;
}

int wetdem_sim_engine_copy(struct wetdem_sim* dst, const struct wetdem_sim* src)
{
    const struct wetdem_engine* s = &src->engine;
    struct wetdem_engine* d = &dst->engine;
    wetdem_sim_engine_init(dst);
    memcpy(d->integrator_params, s->integrator_params, sizeof d->integrator_params);
    d->integrator = s->integrator;
    d->time = s->time;
    d->t_committed = s->t_committed;
    d->stats = s->stats;
    d->observer_interval = s->observer_interval;
    if (wetdem_pairs_copy(&d->pairs, &s->pairs) != WETDEM_OK)
        return WETDEM_ERR_NOMEM;
    if (s->n_events) {
        d->events = malloc(s->n_events * sizeof *d->events);
        if (!d->events)
            return WETDEM_ERR_NOMEM;
        memcpy(d->events, s->events, s->n_events * sizeof *d->events);
        d->n_events = d->events_cap = s->n_events;
    }
    return WETDEM_OK;
}

/* ---- integrator choice, queries ---- */

int wetdem_sim_set_integrator(struct wetdem_sim* sim, const char* name)
{
    if (!name)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "set_integrator: NULL name");
    int k = wetdem_integrator_index(name, strlen(name));
    if (k < 0) {
        const char* hint = wetdem_param_suggest(name, wetdem_integrator_names());
        return wetdem_sim_fail(sim, WETDEM_ERR_NOT_FOUND,
                               "unknown integrator '%s'%s%s%s (valid: verlet, cvode)", name,
                               hint ? " (did you mean '" : "", hint ? hint : "", hint ? "'?)" : "");
    }
    sim->engine.integrator = (size_t)k;
    return WETDEM_OK;
}

const char* wetdem_sim_integrator_name(const struct wetdem_sim* sim)
{
    return wetdem_integrator_registry()[sim->engine.integrator]->name;
}

double wetdem_sim_time(const struct wetdem_sim* sim)
{
    return sim->engine.time;
}

struct wetdem_stats wetdem_sim_stats(const struct wetdem_sim* sim)
{
    return sim->engine.stats;
}

const struct wetdem_event_record* wetdem_sim_events(const struct wetdem_sim* sim, size_t* n)
{
    if (n)
        *n = sim->engine.n_events;
    return sim->engine.events;
}

void wetdem_sim_set_observer(struct wetdem_sim* sim, double interval, wetdem_observer_fn fn,
                             void* ctx)
{
    sim->engine.observer = fn;
    sim->engine.observer_ctx = ctx;
    sim->engine.observer_interval = interval;
    sim->engine.next_observe = sim->engine.time;
    sim->engine.last_observed = NAN;
}

const struct wetdem_particle* wetdem_sim_particles_const(const struct wetdem_sim* sim, size_t* n)
{
    if (n)
        *n = sim->n_particles;
    return sim->particles;
}

/* ---- forces ---- */

/* Adds the force and torques of pair output f (contact c) to both bodies. */
static void apply_pair(struct wetdem_engine* e, const struct wetdem_contact* c,
                       const struct wetdem_pair_force* f)
{
    struct wetdem_vec3 fi = vec3_axpy(f->f_tan, f->f_normal, c->normal);
    e->force[c->i] = vec3_add(e->force[c->i], fi);
    e->torque[c->i] = vec3_add(e->torque[c->i], f->torque_i);
    if (!c->is_wall) {
        e->force[c->j] = vec3_sub(e->force[c->j], fi);
        e->torque[c->j] = vec3_add(e->torque[c->j], f->torque_j);
    }
}

/* Evaluates pair k at time t; applies the force when accumulate; keeps the history when
 * commit. */
static int eval_pair(struct wetdem_sim* sim, size_t k, double t, bool commit, bool accumulate)
{
    struct wetdem_engine* e = &sim->engine;
    struct wetdem_pair* p = &e->pairs.items[k];
    double* history = wetdem_pairs_history(&e->pairs, k);
    struct wetdem_contact c;
    wetdem_sim_build_contact(sim, p->i, p->j, p->is_wall, &c);
    struct wetdem_vec3 v_t = c.v_t;
    if (c.gap > wetdem_sim_contact_range(sim, &c)) {
        if (commit && history) /* (a min-separation record may outlive the force range) */
            wetdem_sim_history_beyond_range(sim, &c, wetdem_sim_record_range(sim, &c), history);
        p->q_rate = vec3(0, 0, 0);
        p->slip = p->f_t = 0.0;
        p->spring_zone = false;
        if (commit) {
            p->q_committed = p->q_trial;
            p->acting = p->sliding = false;
        }
        return WETDEM_OK;
    }
    double scratch[WETDEM_HISTORY_SCRATCH];
    if (history)
        memcpy(scratch, history, sim->history_len * sizeof *scratch);
    c.dt = t - e->t_committed;
    if (e->spring_state && c.dt > 0) { /* the increment of q, in the current tangent plane */
        struct wetdem_vec3 dq = vec3_sub(p->q_trial, p->q_committed);
        c.dv_t_spring = vec3_sub(vec3_scale(vec3_reject(dq, c.normal), 1.0 / c.dt), v_t);
    }
    if (e->half_vel) { /* verlet: the slip at the half step, at the current contact normal */
        size_t j = p->is_wall ? p->i : p->j; /* (a wall's unused) */
        c.dv_t_spring = contact_half_step_dv(&c, e->half_vel[p->i], e->half_omega[p->i],
                                             e->half_vel[j], e->half_omega[j]);
    }
    struct wetdem_pair_force f;
    int st = wetdem_sim_eval_contact(sim, &c, scratch, &f, NULL);
    e->stats.pair_evals++;
    if (st < 0)
        return wetdem_sim_fail(sim, st,
                               "pair (%zu, %s%zu) at t = %.9g s: a force model failed "
                               "(%s)",
                               p->i, p->is_wall ? "wall " : "", p->j, t, wetdem_status_name(st));
    if (!contact_force_is_finite(&f))
        return wetdem_sim_fail(sim, WETDEM_ERR_NUMERIC,
                               "pair (%zu, %s%zu) at t = %.9g s, gap %.6g m: non-finite force",
                               p->i, p->is_wall ? "wall " : "", p->j, t, c.gap);
    if (commit && history)
        memcpy(history, scratch, sim->history_len * sizeof *scratch);
    p->slip = f.slip;
    p->spring_zone = c.gap < fmax(c.h_min, 0.0); /* (mindlin: overlap; nijssen: below h_min) */
    p->f_t = vec3_norm(f.f_tan);
    p->q_rate = f.slip != 0.0 ? v_t : vec3(0, 0, 0); /* (0: no spring acts) */
    if (commit) {
        p->q_committed = p->q_trial;
        p->acting = f.slip != 0.0;
        p->sliding = f.slip > 0.0;
    }
    if (accumulate)
        apply_pair(e, &c, &f);
    return WETDEM_OK;
}

int wetdem_sim_compute_forces(struct wetdem_sim* sim, double t, bool commit)
{
    struct wetdem_engine* e = &sim->engine;
    for (size_t k = 0; k < sim->n_particles; k++)
        e->force[k] = e->torque[k] = vec3(0, 0, 0);
    e->stats.force_evals++;
    for (size_t k = 0; k < e->pairs.n; k++) {
        int st = eval_pair(sim, k, t, commit, true);
        if (st < 0)
            return st;
    }
    if (commit)
        e->t_committed = t;
    return WETDEM_OK;
}

double wetdem_sim_slip_margin(struct wetdem_sim* sim, size_t k, double t, double* f_t, int* status)
{
    *status = eval_pair(sim, k, t, false, false);
    *f_t = sim->engine.pairs.items[k].f_t;
    return sim->engine.pairs.items[k].slip;
}

int wetdem_sim_commit_histories(struct wetdem_sim* sim, double t)
{
    struct wetdem_engine* e = &sim->engine;
    for (size_t k = 0; sim->history_len > 0 && k < e->pairs.n; k++) {
        int st = eval_pair(sim, k, t, true, false);
        if (st < 0)
            return st;
    }
    e->t_committed = t;
    return WETDEM_OK;
}

struct wetdem_vec3 wetdem_sim_acceleration(const struct wetdem_sim* sim, size_t k)
{
    const struct wetdem_particle* p = &sim->particles[k];
    if (p->is_fixed)
        return vec3(0, 0, 0);
    struct wetdem_vec3 g =
        vec3(sim->settings.gravity_x, sim->settings.gravity_y, sim->settings.gravity_z);
    return vec3_axpy(g, 1.0 / p->mass, sim->engine.force[k]);
}

struct wetdem_vec3 wetdem_sim_angular_acceleration(const struct wetdem_sim* sim, size_t k)
{
    const struct wetdem_particle* p = &sim->particles[k];
    if (p->is_fixed)
        return vec3(0, 0, 0);
    double inertia = 0.4 * p->mass * p->radius * p->radius;
    return vec3_scale(sim->engine.torque[k], 1.0 / inertia);
}

/* ---- scales ---- */

/* The largest relative speed of any pair, gravity's addition over its gap included, each
 * floored by `floor` [m/s]; *t_contact as wetdem_sim_speed_scale's. */
static double pair_speed_scale(const struct wetdem_sim* sim, double floor, double* t_contact)
{
    const struct wetdem_engine* e = &sim->engine;
    double g = sqrt(sim->settings.gravity_x * sim->settings.gravity_x +
                    sim->settings.gravity_y * sim->settings.gravity_y +
                    sim->settings.gravity_z * sim->settings.gravity_z);
    double v_max = floor, t_min = INFINITY;
    for (size_t k = 0; k < e->pairs.n; k++) {
        const struct wetdem_pair* p = &e->pairs.items[k];
        struct wetdem_contact c;
        wetdem_sim_build_contact(sim, p->i, p->j, p->is_wall, &c);
        struct wetdem_vec3 dv = sim->particles[p->i].vel;
        if (!p->is_wall)
            dv = vec3_sub(dv, sim->particles[p->j].vel);
        /* speed the pair may reach when gravity closes its gap (energy bound) */
        double v = sqrt(vec3_dot(dv, dv) + 2.0 * g * fmax(c.gap, 0.0));
        v = fmax(v, floor);
        v_max = fmax(v_max, v);
        if (t_contact && v > 0) {
            c.v_n = v;
            t_min = fmin(t_min, wetdem_sim_contact_time(sim, &c));
        }
    }
    if (t_contact)
        *t_contact = t_min;
    return v_max;
}

double wetdem_sim_speed_scale(const struct wetdem_sim* sim, double* t_contact)
{
    return pair_speed_scale(sim, sim->settings.speed_floor, t_contact);
}

double wetdem_sim_motion_speed(const struct wetdem_sim* sim)
{
    return pair_speed_scale(sim, 0.0, NULL);
}

double wetdem_sim_length_scale(const struct wetdem_sim* sim)
{
    double r = INFINITY;
    for (size_t k = 0; k < sim->n_particles; k++)
        if (!sim->particles[k].is_fixed)
            r = fmin(r, sim->particles[k].radius);
    return isfinite(r) ? r : 1.0;
}

/* ---- stop condition, hooks ---- */

bool wetdem_sim_separation_reached(struct wetdem_sim* sim)
{
    struct wetdem_engine* e = &sim->engine;
    if (sim->settings.stop_on_separation == 0)
        return false;
    double factor = sim->settings.separation_factor;
    bool any = false;
    for (size_t k = 0; k < e->pairs.n; k++) {
        if (!e->pairs.items[k].has_interacted)
            continue;
        any = true;
        if (!(e->pair_gap[k] >= factor * e->pair_range[k] && e->pair_vn[k] < 0))
            return false;
    }
    if (!any)
        return false;
    for (size_t k = 0; k < e->pairs.n; k++)
        e->pairs.items[k].has_interacted = false;
    return true;
}

void wetdem_sim_set_progress(struct wetdem_sim* sim, wetdem_time_progress_fn fn, void* ctx)
{
    sim->engine.progress = fn;
    sim->engine.progress_ctx = ctx;
}

/* Calls the progress callback at engine.time; a non-zero return is WETDEM_ERR_CALLBACK when
 * the run can still stop (can_stop), ignored at its end. */
static int report_progress(struct wetdem_sim* sim, bool can_stop)
{
    struct wetdem_engine* e = &sim->engine;
    int r = e->progress(e->time, e->progress_t_end, omp_get_wtime() - e->progress_start,
                        e->progress_ctx);
    if (r != 0 && can_stop)
        return wetdem_sim_fail(sim, WETDEM_ERR_CALLBACK,
                               "the progress callback returned %d at t = %.9g s", r, e->time);
    return WETDEM_OK;
}

int wetdem_sim_step_done(struct wetdem_sim* sim)
{
    struct wetdem_engine* e = &sim->engine;
    int st = e->monitor ? e->monitor(sim, e->monitor_ctx) : WETDEM_OK;
    if (st == WETDEM_OK && e->progress && ++e->progress_steps % WETDEM_PROGRESS_STEPS == 0)
        st = report_progress(sim, true);
    return st;
}

/* The observer time after t: the least multiple k x interval above t, where a multiple that t
 * lies on, or a few roundings below, counts as t's own. Step ends summed from dt and multiples
 * computed as products or sums land either side of one another by a rounding: taken as the
 * multiple after them, it was observed a second time (1.3999999999999997e-06 s, then
 * 1.3999999999999999e-06 s for an interval of 1e-7 s). Every multiple is computed here as the
 * product of its index, so one multiple is one double. */
static double next_observe_after(double t, double interval)
{
    double k = floor(t / interval);
    if (interval * (k + 1.0) <= t + 4.0 * DBL_EPSILON * fabs(t))
        k += 1.0;
    double next = interval * (k + 1.0);
    return next > t ? next : interval * (k + 2.0);
}

int wetdem_sim_observe(struct wetdem_sim* sim)
{
    struct wetdem_engine* e = &sim->engine;
    if (!e->observer)
        return WETDEM_OK;
    if (e->observer_interval > 0) /* (every call: at the start, the multiples and the end) */
        e->next_observe = next_observe_after(e->time, e->observer_interval);
    e->last_observed = e->time;
    int r = e->observer(sim, e->observer_ctx);
    if (r != 0)
        return wetdem_sim_fail(sim, WETDEM_ERR_CALLBACK, "the observer returned %d at t = %.9g s",
                               r, e->time);
    return WETDEM_OK;
}

int wetdem_sim_observe_due(struct wetdem_sim* sim)
{
    struct wetdem_engine* e = &sim->engine;
    /* (a step end a few roundings below the multiple is at it: next_observe_after) */
    if (!e->observer || !(e->observer_interval > 0) ||
        e->time + 4.0 * DBL_EPSILON * fabs(e->time) < e->next_observe)
        return WETDEM_OK;
    return wetdem_sim_observe(sim);
}

/* ---- the run ---- */

/* Checks the arguments and the state before a run. */
static int check_run(struct wetdem_sim* sim, double t_end)
{
    const struct wetdem_engine* e = &sim->engine;
    double step = wetdem_sim_many_step(sim); /* 0 before a many-particle run */
    if (!isfinite(t_end) || (t_end < e->time && !((e->time - t_end) / step < 1 - 1e-9)))
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "integrate: t_end = %g s must be finite and >= the current time "
                               "%.9g s%s",
                               t_end, e->time,
                               step > 0 ? " less the step it passed (the many-particle mode "
                                          "takes whole steps)"
                                        : "");
    if (e->observer && !(isfinite(e->observer_interval) && e->observer_interval >= 0))
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "observer interval = %g s must be finite and >= 0",
                               e->observer_interval);
    if (sim->history_len > WETDEM_HISTORY_SCRATCH)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "the enabled models keep %zu doubles of pair history; at most %d",
                               sim->history_len, WETDEM_HISTORY_SCRATCH);
    char why[256];
    for (size_t k = 0; k < sim->n_particles; k++)
        if (!wetdem_sim_particle_valid(sim, &sim->particles[k], why, sizeof why))
            return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "particle %zu: %s", k, why);
    return WETDEM_OK;
}

/* q of every pair zero at the start of a run (engine.spring_state: only its increments are
 * read), and the slip state of the committed springs: the histories hold the state at
 * engine.time (t_committed). */
static int start_springs(struct wetdem_sim* sim)
{
    struct wetdem_engine* e = &sim->engine;
    for (size_t k = 0; k < e->pairs.n; k++) {
        struct wetdem_pair* p = &e->pairs.items[k];
        p->q_committed = p->q_trial = vec3(0, 0, 0);
        int st = eval_pair(sim, k, e->t_committed, false, false);
        if (st < 0)
            return st;
        p->acting = p->slip != 0.0;
        p->sliding = p->slip > 0.0;
    }
    return WETDEM_OK;
}

/* Pair list, event functions, per-particle arrays and the forces at the start state. */
static int begin_run(struct wetdem_sim* sim)
{
    struct wetdem_engine* e = &sim->engine;
    int st = wetdem_pairs_update(&e->pairs, sim);
    if (st == WETDEM_OK && e->spring_state)
        st = start_springs(sim);
    if (st == WETDEM_OK)
        st = wetdem_event_slots_build(sim);
    if (st == WETDEM_OK && sim->n_particles > e->force_cap) {
        struct wetdem_vec3* f = realloc(e->force, sim->n_particles * sizeof *f);
        if (f)
            e->force = f;
        struct wetdem_vec3* q = realloc(e->torque, sim->n_particles * sizeof *q);
        if (q)
            e->torque = q;
        if (!f || !q)
            return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory for %zu particles",
                                   sim->n_particles);
        e->force_cap = sim->n_particles;
    }
    if (st == WETDEM_OK)
        st = wetdem_sim_compute_forces(sim, e->time, false);
    if (st == WETDEM_OK)
        wetdem_event_start(sim);
    return st;
}

int wetdem_sim_integrate(struct wetdem_sim* sim, double t_end)
{
    struct wetdem_engine* e = &sim->engine;
    int st = check_run(sim, t_end);
    if (st == WETDEM_OK && sim->many) /* many-particle mode: cell lists, no events */
        return wetdem_sim_many_integrate(sim, t_end);
    e->spring_state = wetdem_integrator_registry()[e->integrator]->spring_state;
    e->progress_t_end = t_end;
    e->progress_start = e->progress ? omp_get_wtime() : 0.0;
    e->progress_steps = 0;
    if (st == WETDEM_OK)
        st = begin_run(sim);
    bool due = e->observer_interval > 0 ? e->time >= e->next_observe : true;
    if (st == WETDEM_OK && e->observer && due && !(e->last_observed == e->time))
        st = wetdem_sim_observe(sim);
    if (st != WETDEM_OK)
        return st;
    const struct wetdem_integrator* integ = wetdem_integrator_registry()[e->integrator];
    st = integ->integrate(sim, e->integrator_params[e->integrator], t_end);
    if (st >= 0 && e->observer && !(e->last_observed == e->time)) {
        int so = wetdem_sim_observe(sim);
        if (so != WETDEM_OK)
            return so;
    }
    if (st >= 0 && e->progress)
        report_progress(sim, false); /* (the run is over: nothing left to stop) */
    return st;
}

/*
 * integrator_verlet.c — "verlet": velocity Verlet with a fixed step (Nijssen 2023 Sec. 3: dt =
 * 2 % of the Hertz contact time), for translation and rotation:
 *
 *     v' = v + a(t) dt/2,  w' = w + alpha(t) dt/2            half kick
 *     x(t + dt) = x + v' dt                                  drift
 *     F, T at (x(t + dt), v* = v' + a(t) dt/2, w* = w' + alpha(t) dt/2)
 *     v(t + dt) = v' + a(t + dt) dt/2,  w(t + dt) = w' + alpha(t + dt) dt/2
 *
 * Velocity-dependent forces (damping, lubrication, friction) are evaluated with the predicted
 * velocities v* = v + a(t) dt, an explicit predictor of v(t + dt) with an O(dt^2) error, which
 * keeps the scheme second order for damped motion. (LIGGGHTS evaluates them with the half-step
 * velocities v', which is first order for damped motion.) Position-only forces see exactly the
 * symplectic, time-reversible velocity Verlet.
 *
 * Step: verlet.dt [s] when > 0; otherwise dt = dt_fraction x the shortest impact duration
 * over all pairs (the Hertz contact time, Johnson 1985 Sec. 11.4, or hooke's half period:
 * the enabled models' contact_time hooks) at the speed scale of wetdem_sim_speed_scale(): the
 * largest relative speed of any pair at the start of the run, raised by the speed gravity can
 * add over the pair's gap, floored by sim.speed_floor. dt is fixed for one
 * wetdem_sim_integrate() call; long runs with changing speeds are integrated in chunks.
 * With verlet.hmin_fraction > 0 the step is also held at or below hmin_fraction x h_min / v,
 * h_min the smallest gap inside their range at the start where the force laws jump (the
 * thin-film laws with below_hmin = c switch off there, docs/engines.md "Steps and h_min"; a
 * law continuous there, as nijssen's blend, sets no bound) and v that speed scale. Without
 * pairs the run is one step (exact for free flight and constant force). The last step is
 * shortened to land on t_end.
 *
 * Pair histories are committed at every step (c->dt = dt). Events: the event functions are
 * compared before and after every step and crossings are placed by linear interpolation of
 * g (time error O(dt^2) relative to the step, docs/engines.md). The forces are not: they are
 * sampled at the step ends only, so where a law switches at h_min the switch falls on a step
 * end, not where the gap crosses h_min; stats.hmin_step_ratio records how far such steps move
 * the gap, relative to h_min.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "integrator.h"
#include "vec3.h"

struct verlet_params {
    double dt;                 /* fixed step [s]; 0: from dt_fraction */
    double dt_fraction;        /* step as a fraction of the contact time [-] */
    double max_steps;          /* most steps one integrate call may take [-] */
    double hmin_fraction;      /* > 0: gap change per step at most this fraction of h_min [-] */
    double many_hmin_fraction; /* many-particle mode: the same, 0.5 by default [-] */
};

_Static_assert(sizeof(struct verlet_params) <= WETDEM_INTEGRATOR_PARAMS_MAX * sizeof(double),
               "verlet parameters exceed the engine's parameter block");

#define P(field) offsetof(struct verlet_params, field)
static const struct wetdem_param_desc verlet_params_desc[] = {
    {"dt", "s", "Fixed time step; 0 derives it from dt_fraction and the contact time.", P(dt), 0.0,
     0.0, 1.0, false, false, NULL, false},
    {"dt_fraction", "-",
     "Time step as a fraction of the contact time (Hertz, or hooke's half period; Nijssen: 0.02).",
     P(dt_fraction), 0.02, 0.0, 1.0, true, false, NULL, false},
    {"max_steps", "-", "Largest number of steps one integrate call may take.", P(max_steps), 1e8,
     1.0, 1e12, false, false, NULL, true},
    {"hmin_fraction", "-",
     "When > 0, the step is also held at or below hmin_fraction x h_min / v (h_min: the "
     "smallest gap inside the range of the force laws where they jump, v: the speed scale), "
     "so that the gap moves at most that fraction of h_min per step; 0: off (dt_fraction "
     "alone).",
     P(hmin_fraction), 0.0, 0.0, 1.0, false, false, NULL, false},
    {"many_hmin_fraction", "-",
     "Many-particle mode: the derived step is held at or below many_hmin_fraction x h_min / v "
     "(h_min: the smallest gap inside the range of the force laws where they jump, v: the speed "
     "scale; the two-body engine's hmin_fraction, on by default here); 0: off (docs/many.md, "
     "Time step).",
     P(many_hmin_fraction), 0.5, 0.0, 1.0, false, false, NULL, false},
    {0},
};
#undef P

/* Step size [s] for the run to t_end. */
static int choose_step(struct wetdem_sim* sim, const struct verlet_params* p, double t_end,
                       double* dt)
{
    double span = t_end - sim->engine.time, t_contact = INFINITY, v = 0.0;
    if (p->dt > 0) {
        *dt = p->dt;
    } else {
        v = wetdem_sim_speed_scale(sim, &t_contact);
        *dt = isfinite(t_contact) ? p->dt_fraction * t_contact : span;
    }
    bool held = false; /* by hmin_fraction */
    double h_min = p->hmin_fraction > 0 ? wetdem_event_smallest_branch_gap(sim) : INFINITY;
    if (isfinite(h_min)) {
        if (!(v > 0))
            v = wetdem_sim_speed_scale(sim, NULL);
        double hold = p->hmin_fraction * h_min / v;
        held = hold < *dt;
        *dt = held ? hold : *dt;
    }
    if (!(*dt > 0) || !isfinite(*dt)) {
        if (p->dt > 0 || !(t_contact > 0) || !isfinite(t_contact))
            return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "verlet: step %g s is not usable%s",
                                   *dt,
                                   p->dt > 0 ? ""
                                             : ": the contact time it derives from is not a "
                                               "positive finite number (check the materials' "
                                               "youngs_modulus and density, and the radii)");
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "verlet: step %g s is not usable: %g x the contact time %g s "
                               "(check the materials' youngs_modulus and density, and the radii)",
                               *dt, p->dt_fraction, t_contact);
    }
    if (span / *dt > p->max_steps) {
        char why[256] = "";
        if (held)
            snprintf(why, sizeof why, " (the step is held at hmin_fraction x h_min / v)");
        else if (!(p->dt > 0))
            snprintf(why, sizeof why,
                     " (the step is dt_fraction = %g x the contact time %.3g s at %.3g m/s: "
                     "check the materials' youngs_modulus and density, and the radii)",
                     p->dt_fraction, t_contact, v);
        return wetdem_sim_fail(sim, WETDEM_ERR_MAX_STEPS,
                               "verlet: %.3g steps of %.3g s to reach t = %.9g s exceed "
                               "verlet.max_steps = %.3g%s",
                               span / *dt, *dt, t_end, p->max_steps, why);
    }
    return WETDEM_OK;
}

/* Half kick with the current forces and drift; velocities become the predicted ones
 * (v + a dt), the half-step ones are kept in vh/wh (a fixed particle's own velocity and
 * spin). */
static void kick_drift(struct wetdem_sim* sim, double h, struct wetdem_vec3* vh,
                       struct wetdem_vec3* wh)
{
    for (size_t k = 0; k < sim->n_particles; k++) {
        struct wetdem_particle* p = &sim->particles[k];
        if (p->is_fixed) { /* (the springs read vh and wh of every particle) */
            vh[k] = p->vel;
            wh[k] = p->omega;
            continue;
        }
        struct wetdem_vec3 a = wetdem_sim_acceleration(sim, k);
        struct wetdem_vec3 alpha = wetdem_sim_angular_acceleration(sim, k);
        vh[k] = vec3_axpy(p->vel, 0.5 * h, a);
        wh[k] = vec3_axpy(p->omega, 0.5 * h, alpha);
        p->pos = vec3_axpy(p->pos, h, vh[k]);
        p->vel = vec3_axpy(vh[k], 0.5 * h, a);
        p->omega = vec3_axpy(wh[k], 0.5 * h, alpha);
    }
}

/* Second half kick with the forces at the new positions. */
static void kick(struct wetdem_sim* sim, double h, const struct wetdem_vec3* vh,
                 const struct wetdem_vec3* wh)
{
    for (size_t k = 0; k < sim->n_particles; k++) {
        struct wetdem_particle* p = &sim->particles[k];
        if (p->is_fixed)
            continue;
        p->vel = vec3_axpy(vh[k], 0.5 * h, wetdem_sim_acceleration(sim, k));
        p->omega = vec3_axpy(wh[k], 0.5 * h, wetdem_sim_angular_acceleration(sim, k));
    }
}

/* One step of size h from t0; then events, stop check, monitor, observer. */
static int step(struct wetdem_sim* sim, double t0, double h, struct wetdem_vec3* vh,
                struct wetdem_vec3* wh, bool* stop)
{
    struct wetdem_engine* e = &sim->engine;
    kick_drift(sim, h, vh, wh);
    double t1 = t0 + h;
    e->half_vel = vh; /* the springs advance with the half-step slip (midpoint rule) */
    e->half_omega = wh;
    int st = wetdem_sim_compute_forces(sim, t1, true);
    e->half_vel = e->half_omega = NULL;
    if (st != WETDEM_OK)
        return st;
    kick(sim, h, vh, wh);
    e->time = t1;
    e->stats.steps++;
    st = wetdem_event_advance(sim, t0, t1, NULL);
    if (st == WETDEM_OK)
        *stop = wetdem_sim_separation_reached(sim);
    if (st == WETDEM_OK)
        st = wetdem_sim_step_done(sim);
    if (st == WETDEM_OK)
        st = wetdem_sim_observe_due(sim);
    return st;
}

static int verlet_integrate(struct wetdem_sim* sim, const void* params, double t_end)
{
    struct wetdem_engine* e = &sim->engine;
    double dt;
    int st = choose_step(sim, params, t_end, &dt);
    if (st != WETDEM_OK)
        return st;
    size_t n = sim->n_particles ? sim->n_particles : 1;
    struct wetdem_vec3* vh = malloc(2 * n * sizeof *vh);
    if (!vh)
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "verlet: out of memory");
    double t_start = e->time;
    bool stop = false;
    for (unsigned long long k = 1; st == WETDEM_OK && !stop && e->time < t_end; k++) {
        double t1 = t_start + (double)k * dt; /* no accumulated round-off in the time */
        if (t1 > t_end || t_end - t1 < 1e-9 * dt)
            t1 = t_end;
        st = step(sim, e->time, t1 - e->time, vh, vh + n, &stop);
    }
    free(vh);
    if (st == WETDEM_OK && stop)
        return WETDEM_EVENT;
    return st;
}

const struct wetdem_integrator wetdem_integrator_verlet = {
    .name = "verlet",
    .summary = "velocity Verlet, fixed step = dt_fraction x contact time (Hertz, or hooke)",
    .params = verlet_params_desc,
    .params_size = sizeof(struct verlet_params),
    .integrate = verlet_integrate,
};

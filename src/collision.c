/*
 * collision.c — one binary collision on the soft engine and its analysis (SPEC §4,
 * docs/engines.md "Collision analysis"). Prefix override: wetdem_collision_* and
 * wetdem_outcome_*.
 *
 * Set-up: target j at rest at the origin (a sphere, or the wall x = 0 with normal +x); the
 * striker i moves with speed U at the impact angle theta, defined as in the experiments
 * (Yang & Hunt 2006; Nijssen Fig. 1c; Punch Eq. 16, "the moment before collision") and in
 * Davis's pairwise engine: the angle between the relative velocity and the line of centres
 * at contact of the undisturbed straight-line approach, sin(theta) = b / (R_i + R_j) with the
 * impact parameter b (for a wall: the angle to the wall normal). The striker starts on that
 * straight line, just outside the interaction range, and the line meets contact at +x
 * (centre distance R_i + R_j on the +x axis). U from the normal Stokes number when U = 0
 * (SPEC §2; Nijssen Eq. 2 with the normal speed, Punch Eq. 2):
 *   St_n = m* v_n0 / (6 pi mu R*^2),  v_n0 = U cos(theta).
 * Runs to separation (gap >= rebound_gap_factor x range, receding) or t_end.
 * With the relative velocity of centres dv = v_i - v_j, n0 = +x (the contact normal of the
 * straight-line approach, which defines theta and v_n0) and n_f the rebound normal, the line of
 * centres at the time of the final relative velocity (Punch Eq. 3): for a film-coated pair
 * where the films last part (the gap rises through delta_ij), whatever the outcome; for a pair
 * without films, whose lubrication reaches out to nijssen's cut-off R*, for a bounce at the
 * last local minimum of the gap (the middle of the contact) and for stick-rotate-separate where
 * the doublet leaves near contact (the gap rises through h_close, below); for a pair that has
 * not separated, the line at the end. The line of centres keeps turning after the spheres part
 * (by tens of degrees over the cut-off), and a normal taken at the end of the run made the
 * results depend on where the run stops (rebound_gap_factor) and gave e_n > 1 for an elastic
 * frictionless impact. One normal for every outcome of a film-coated pair keeps e_n continuous
 * where the outcome changes (a normal at the closest approach for a bounce dropped e_n by 0.1
 * where a thin-film collision turned from stick-rotate-separate to bounce). Velocities are
 * taken at the end (separation or t_end):
 *   e   = |dv_f| / |dv_0|                                   (Nijssen; Yang & Hunt)
 *   e_n = -(dv_f . n_f) / (dv_0 . n0)                        (Punch Eq. 3)
 *   (e and e_n are 0 when the pair has not separated by t_end: no rebound)
 *   e_t = -(u_f . t_f) / |u_0|,  u = tangential part of the contact-point velocity
 *         (v_i + w_i x (-R_i n)) - (v_j + w_j x (R_j n)), t_f = u_0/|u_0| projected on the
 *         final tangent plane; -1 smooth sliding, +1 full reversal (Walton's beta)
 *   angle_in = atan2(|dv_0,t|, -dv_0 . n0) = theta (the nominal impact angle: the initial
 *     relative velocity against the straight-line contact normal; lubrication slows the
 *     normal approach before contact, so the velocity at the actual first contact is more
 *     oblique than this, as in the experiments, which measure the approach before impact),
 *   angle_out = atan2(|dv_f,t|, dv_f . n_f),
 *   energy_ratio = E_f / E_0,  E = m* |dv|^2 / 2 + I_i |w_i|^2 / 2 + I_j |w_j|^2 / 2 + U (the
 *     kinetic energy of the two-body motion about its centre of mass, m* = m_i for a wall or
 *     a fixed target, and of the spins, I = 2/5 m R^2; U the energy the conservative forces
 *     store at the gap, stored_energy: 0 once the pair has left the range): at most 1 for the
 *     passive models of the catalogue, so a value above it measures the integration's error
 *     (NAN with gravity). Without U a pair held by a capillary bridge, its well's energy
 *     turned into motion, ended with up to 6 times its initial kinetic energy.
 * Outcome (docs/engines.md "Outcome"; Punch's definitions): none if the striker had not
 * reached the interaction range by t_end; stick if not separated by t_end; stick-rotate-
 * separate if separated after the pair orbited as a doublet by more than 5 degrees: the turn
 * that the line of centres and the relative velocity shared (per step the smaller, about the
 * line's axis), after the approach was first arrested (the first minimum of the gap), in steps
 * with the gap below h_close; else bounce. The line's turn alone is no measure: a bounce that
 * leaves a grazing contact turns it, in free flight, by up to sqrt(2 h_close / (R_i + R_j))
 * (8.4 degrees for Punch's films), while its velocity stays. h_close = spec close_gap when > 0,
 * else the pair's film thickness delta_ij when it has films (overlapping films are the bridge
 * that holds the doublet, Punch; Davis), else 0.01 R* (immersed pairs).
 */
#include <float.h>
#include <gsl/gsl_integration.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "gsl_guard.h"
#include "integrator.h"
#include "vec3.h"

#define SRS_ANGLE (5.0 * M_PI / 180.0) /* doublet turn that marks stick-rotate-separate [rad] */
#define CLOSE_GAP_RATIO 0.01           /* h_close / R* without films [-] */
#define START_MARGIN_RATIO 0.01        /* start gap beyond the range, / R* [-] */
/* Largest initial gap [m]: the pair geometry squares centre distances (contact.c, and
 * back_distance below), which overflows beyond sqrt(DBL_MAX) = 1.3e154 m; 1e150 leaves room
 * for the radii and the three components, and lies far beyond any gap a run can cross. */
#define INITIAL_GAP_MAX 1e150

const char* wetdem_outcome_name(enum wetdem_outcome outcome)
{
    switch (outcome) {
    case WETDEM_OUTCOME_STICK: return "stick";
    case WETDEM_OUTCOME_STICK_ROTATE_SEPARATE: return "stick-rotate-separate";
    case WETDEM_OUTCOME_BOUNCE: return "bounce";
    case WETDEM_OUTCOME_RECEDE: return "recede";
    case WETDEM_OUTCOME_NONE: return "none";
    }
    return "unknown";
}

/* Per-step record of the pair (0, 1) or (0, wall 0), kept by the monitor. */
struct tracker {
    double h_close; /* gap below which the pair counts as a doublet [m] */
    double film;    /* the pair's film thickness delta_ij [m], 0 without films */
    double t_prev, gap_prev, vn_prev;
    struct wetdem_vec3 n_prev, dv_prev;
    double min_gap;
    bool interacting; /* after the first interaction */
    double t_first;   /* time of the first interaction [s] */
    double rotation, rotation_close;
    double rotation_doublet; /* the part of rotation_close the relative velocity shared */
    bool arrested;           /* the approach has been arrested once (first minimum of
                                      the gap): rotation_close counts from there */
    size_t events_seen;
    double t_observe;    /* absolute observation time [s], INFINITY if none yet */
    double observe_span; /* spec->observe_time [s] */
    bool observed;
    struct wetdem_vec3 n_obs, dv_obs;
    bool turned;                /* the gap has had a local minimum */
    struct wetdem_vec3 n_turn;  /* the line of centres at the last one */
    bool left_close;            /* the gap has risen through h_close */
    struct wetdem_vec3 n_leave; /* the line of centres the last time it did */
    bool left_film;             /* the gap has risen through the film thickness */
    struct wetdem_vec3 n_film;  /* the line of centres the last time it did */
};

/* The rebound normal n_f, given the line of centres `now` (docs/engines.md, "Collision
 * analysis"): for a film-coated pair the line where the films last parted; without films,
 * where the pair last turned as a doublet in near contact (stick-rotate-separate), the line
 * where it left near contact, else the line at the last local minimum of the gap; `now` when
 * there was none of these. */
static struct wetdem_vec3 rebound_normal(const struct tracker* tr, struct wetdem_vec3 now)
{
    if (tr->film > 0)
        return tr->left_film ? tr->n_film : now;
    if (tr->rotation_doublet > SRS_ANGLE)
        return tr->left_close ? tr->n_leave : now;
    return tr->turned ? tr->n_turn : now;
}

/* The unit vector along (1 - s) a + s b. */
static struct wetdem_vec3 unit_between(struct wetdem_vec3 a, struct wetdem_vec3 b, double s)
{
    struct wetdem_vec3 n = vec3_add(vec3_scale(a, 1 - s), vec3_scale(b, s));
    return vec3_scale(n, 1.0 / vec3_norm(n));
}

/* The part of a step's turn of the line of centres, from n0 to n1 (turn [rad], > 0), that the
 * relative velocity shared, dv0 to dv1 turning about the same axis and the same way [rad]: a
 * doublet held in near contact orbits, its velocity turning with its line of centres; a pair
 * in free flight past the target turns its line while its velocity stays; an impact turns
 * the velocity while the line stays. */
static double shared_turn(struct wetdem_vec3 n0, struct wetdem_vec3 n1, double turn,
                          struct wetdem_vec3 dv0, struct wetdem_vec3 dv1)
{
    struct wetdem_vec3 axis = vec3_cross(n0, n1);
    double len = vec3_norm(axis);
    if (!(len > 0))
        return 0.0;
    axis = vec3_scale(axis, 1.0 / len);
    struct wetdem_vec3 p0 = vec3_reject(dv0, axis), p1 = vec3_reject(dv1, axis);
    double dv_turn = atan2(vec3_dot(axis, vec3_cross(p0, p1)), vec3_dot(p0, p1));
    return fmax(0.0, fmin(turn, dv_turn));
}

static struct wetdem_vec3 relative_velocity(const struct wetdem_sim* sim)
{
    struct wetdem_vec3 v = sim->particles[0].vel;
    return sim->n_walls ? v : vec3_sub(v, sim->particles[1].vel);
}

static void pair_contact(const struct wetdem_sim* sim, struct wetdem_contact* c)
{
    wetdem_sim_build_contact(sim, 0, 0 + (sim->n_walls ? 0 : 1), sim->n_walls > 0, c);
}

/* Smallest value of the cubic Hermite interpolant of the gap over a step in which the
 * approach speed changed sign (h' = -v_n at both ends) [m], and in *at where in the step it
 * lies (fraction of the step, 0 at its start). */
static double hermite_min(double dt, double h0, double vn0, double h1, double vn1, double* at)
{
    double m0 = -vn0 * dt, m1 = -vn1 * dt;
    double a = 6 * h0 + 3 * m0 - 6 * h1 + 3 * m1, b = -6 * h0 - 4 * m0 + 6 * h1 - 2 * m1;
    double roots[2] = {-1, -1}, best = fmin(h0, h1);
    *at = h1 <= h0 ? 1.0 : 0.0;
    if (fabs(a) > 1e-300) {
        double disc = b * b - 4 * a * m0;
        if (disc >= 0) {
            roots[0] = (-b + sqrt(disc)) / (2 * a);
            roots[1] = (-b - sqrt(disc)) / (2 * a);
        }
    } else if (fabs(b) > 1e-300) {
        roots[0] = -m0 / b;
    }
    for (int k = 0; k < 2; k++) {
        double s = roots[k];
        if (!(s > 0 && s < 1))
            continue;
        double p = (2 * s * s * s - 3 * s * s + 1) * h0 + (s * s * s - 2 * s * s + s) * m0 +
                   (-2 * s * s * s + 3 * s * s) * h1 + (s * s * s - s * s) * m1;
        if (p < best) {
            best = p;
            *at = s;
        }
    }
    return best;
}

/* Scans new log entries for the first interaction start. */
static void scan_events(const struct wetdem_sim* sim, struct tracker* tr)
{
    for (; tr->events_seen < sim->engine.n_events; tr->events_seen++) {
        const struct wetdem_event_record* ev = &sim->engine.events[tr->events_seen];
        if (ev->kind == WETDEM_EVENT_INTERACTION_START && !tr->interacting) {
            tr->interacting = true;
            tr->t_first = ev->time;
            tr->t_observe = tr->observe_span > 0 ? ev->time + tr->observe_span : INFINITY;
        }
    }
}

/* Linear interpolation of the normal and relative velocity at t_observe inside the step. */
static void observe_in_step(struct tracker* tr, double t, struct wetdem_vec3 n,
                            struct wetdem_vec3 dv)
{
    if (tr->observed || !(t >= tr->t_observe))
        return;
    double s = t > tr->t_prev ? (tr->t_observe - tr->t_prev) / (t - tr->t_prev) : 1.0;
    s = fmin(fmax(s, 0.0), 1.0);
    tr->n_obs = rebound_normal(tr, unit_between(tr->n_prev, n, s));
    tr->dv_obs = vec3_add(vec3_scale(tr->dv_prev, 1 - s), vec3_scale(dv, s));
    tr->observed = true;
}

static int monitor(struct wetdem_sim* sim, void* ctx)
{
    struct tracker* tr = ctx;
    struct wetdem_contact c;
    pair_contact(sim, &c);
    double t = sim->engine.time;
    struct wetdem_vec3 dv = relative_velocity(sim);
    scan_events(sim, tr);
    double low = c.gap;
    bool turned_back = tr->vn_prev > 0 && c.v_n <= 0; /* a local minimum of the gap */
    if (turned_back) {
        double at;
        low = fmin(low, hermite_min(t - tr->t_prev, tr->gap_prev, tr->vn_prev, c.gap, c.v_n, &at));
        tr->n_turn = unit_between(tr->n_prev, c.normal, at);
        tr->turned = true;
    }
    if (tr->gap_prev < tr->h_close && c.gap >= tr->h_close) {
        tr->n_leave = unit_between(tr->n_prev, c.normal,
                                   (tr->h_close - tr->gap_prev) / (c.gap - tr->gap_prev));
        tr->left_close = true;
    }
    if (tr->gap_prev < tr->film && c.gap >= tr->film) {
        tr->n_film =
            unit_between(tr->n_prev, c.normal, (tr->film - tr->gap_prev) / (c.gap - tr->gap_prev));
        tr->left_film = true;
    }
    tr->min_gap = fmin(tr->min_gap, low);
    if (tr->interacting) {
        double turn =
            atan2(vec3_norm(vec3_cross(tr->n_prev, c.normal)), vec3_dot(tr->n_prev, c.normal));
        tr->rotation += turn;
        if (tr->arrested && tr->gap_prev < tr->h_close && c.gap < tr->h_close) {
            tr->rotation_close += turn;
            tr->rotation_doublet += shared_turn(tr->n_prev, c.normal, turn, tr->dv_prev, dv);
        }
        tr->arrested = tr->arrested || turned_back;
    }
    observe_in_step(tr, t, c.normal, dv);
    tr->t_prev = t;
    tr->gap_prev = c.gap;
    tr->vn_prev = c.v_n;
    tr->n_prev = c.normal;
    tr->dv_prev = dv;
    return WETDEM_OK;
}

/* Checks every field of the spec; the message names the field, its value and the range. */
static int check_spec(struct wetdem_sim* sim, const struct wetdem_collision_spec* s)
{
    int nm = sim->n_materials;
    if (s->material_i < 0 || s->material_i >= nm || s->material_j < 0 || s->material_j >= nm)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "collision: material_i = %d, material_j = %d: valid 0..%d",
                               s->material_i, s->material_j, nm - 1);
    if (!(isfinite(s->radius_i) && s->radius_i > 0) ||
        (!s->target_is_wall && !(isfinite(s->radius_j) && s->radius_j > 0)))
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "collision: radius_i = %g m, radius_j = %g m: must be finite "
                               "and > 0",
                               s->radius_i, s->radius_j);
    if (!(isfinite(s->angle) && s->angle >= 0 && s->angle < M_PI / 2))
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "collision: angle = %g rad: valid [0, pi/2)", s->angle);
    if (!(isfinite(s->speed) && s->speed >= 0))
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "collision: speed = %g m/s: valid [0, inf), 0 = from stokes",
                               s->speed);
    if (s->speed == 0 &&
        !(isfinite(s->stokes) && s->stokes > 0 && s->angle < M_PI / 2 && sim->fluid.viscosity > 0))
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "collision: speed 0 asks for it from stokes = %g (valid > 0), "
                               "which needs angle < pi/2 (%g rad) and fluid.viscosity > 0 "
                               "(%g Pa s)",
                               s->stokes, s->angle, sim->fluid.viscosity);
    if (!vec3_is_finite(s->omega_i))
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "collision: omega_i = (%g, %g, %g) rad/s must be finite",
                               s->omega_i.x, s->omega_i.y, s->omega_i.z);
    if (!(isfinite(s->initial_gap) && s->initial_gap <= INITIAL_GAP_MAX))
        return wetdem_sim_fail(
            sim, WETDEM_ERR_INVALID,
            "collision: initial_gap = %g m: valid finite and <= %g m (<= 0: just "
            "outside the interaction range); the pair geometry squares "
            "centre distances, which overflow beyond %.2g m",
            s->initial_gap, INITIAL_GAP_MAX, sqrt(DBL_MAX));
    if (!(isfinite(s->t_end) && s->t_end > 0) ||
        !(isfinite(s->observe_time) && s->observe_time >= 0))
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "collision: t_end = %g s (valid > 0), observe_time = %g s "
                               "(valid >= 0)",
                               s->t_end, s->observe_time);
    if (!(isfinite(s->close_gap) && s->close_gap >= 0))
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "collision: close_gap = %g m: valid [0, inf), 0 = automatic",
                               s->close_gap);
    if (!(s->rebound_gap_factor == 0 ||
          (isfinite(s->rebound_gap_factor) && s->rebound_gap_factor >= 1)))
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "collision: rebound_gap_factor = %g: valid 0 (= 1) or >= 1",
                               s->rebound_gap_factor);
    return WETDEM_OK;
}

/* Geometry of the pair, known once both bodies exist. */
struct setup {
    double range, r_eff, m_eff; /* [m], [m], [kg] */
    double h_close;             /* doublet gap of the outcome rule [m] */
    double speed, speed_n0;     /* [m/s] */
};

/* Distance back along the approach line from the contact point of the straight path (centre
 * distance d on +x) to the point where the centre distance is s >= d, for impact angle theta
 * (|d x - D u| = s with u the direction of motion) [m]. */
static double back_distance(double d, double s, double theta)
{
    double c = cos(theta), sn = sin(theta);
    return -d * c + sqrt(fmax(s * s - d * d * sn * sn, 0.0));
}

/* Replaces the particles and walls by striker and target and sets the initial state: the
 * striker on the straight line with impact parameter b = (R_i + R_j) sin(theta) that reaches
 * contact at centre distance R_i + R_j on +x, started at the gap initial_gap (default: just
 * outside the interaction range). */
static int place_bodies(struct wetdem_sim* sim, const struct wetdem_collision_spec* s,
                        struct setup* out)
{
    wetdem_sim_reset(sim);
    struct wetdem_particle pi = {
        .radius = s->radius_i, .material = s->material_i, .omega = s->omega_i};
    int st = wetdem_sim_add_particle(sim, pi);
    if (st == WETDEM_OK && s->target_is_wall)
        st = wetdem_sim_add_wall(sim, vec3(0, 0, 0), vec3(1, 0, 0), s->material_j);
    struct wetdem_particle pj = {
        .radius = s->radius_j, .material = s->material_j, .is_fixed = s->target_is_fixed};
    if (st == WETDEM_OK && !s->target_is_wall)
        st = wetdem_sim_add_particle(sim, pj);
    if (st != WETDEM_OK)
        return st;
    double reach = s->radius_i + (s->target_is_wall ? 0.0 : s->radius_j);
    sim->particles[0].pos = vec3(reach + 1.0, 0, 0); /* provisional, for the pair geometry */
    struct wetdem_contact c;
    pair_contact(sim, &c);
    out->range = wetdem_sim_contact_range(sim, &c);
    out->r_eff = c.r_eff;
    out->m_eff = c.m_eff;
    out->h_close = s->close_gap > 0 ? s->close_gap
                   : c.film > 0     ? c.film
                                    : CLOSE_GAP_RATIO * c.r_eff;
    double cos_a = cos(s->angle);
    out->speed = s->speed > 0 ? s->speed
                              : s->stokes * 6 * M_PI * sim->fluid.viscosity * c.r_eff * c.r_eff /
                                    (c.m_eff * cos_a);
    out->speed_n0 = out->speed * cos_a;
    double gap0 = s->initial_gap > 0 ? s->initial_gap : out->range + START_MARGIN_RATIO * c.r_eff;
    struct wetdem_vec3 dir = vec3(-cos_a, -sin(s->angle), 0); /* direction of motion of i */
    double back = s->target_is_wall ? gap0 / cos_a : back_distance(reach, reach + gap0, s->angle);
    sim->particles[0].pos = vec3_axpy(vec3(reach, 0, 0), -back, dir);
    sim->particles[0].vel = vec3_scale(dir, out->speed);
    return WETDEM_OK;
}

/* Runs with the separation stop and the monitor, restoring the caller's settings. */
static int run(struct wetdem_sim* sim, const struct wetdem_collision_spec* s, struct tracker* tr)
{
    struct wetdem_sim_settings saved = sim->settings;
    sim->settings.stop_on_separation = 1;
    sim->settings.separation_factor = s->rebound_gap_factor > 1 ? s->rebound_gap_factor : 1;
    int (*saved_fn)(struct wetdem_sim*, void*) = sim->engine.monitor;
    void* saved_ctx = sim->engine.monitor_ctx;
    sim->engine.monitor = monitor;
    sim->engine.monitor_ctx = tr;
    int st = wetdem_sim_integrate(sim, s->t_end);
    sim->settings = saved;
    sim->engine.monitor = saved_fn;
    sim->engine.monitor_ctx = saved_ctx;
    return st;
}

/* Initial tracker state from the placed bodies. */
static void start_tracker(const struct wetdem_sim* sim, const struct setup* su,
                          const struct wetdem_collision_spec* s, struct tracker* tr)
{
    struct wetdem_contact c;
    pair_contact(sim, &c);
    *tr = (struct tracker){.h_close = su->h_close,
                           .film = c.film,
                           .t_prev = 0,
                           .gap_prev = c.gap,
                           .vn_prev = c.v_n,
                           .n_prev = c.normal,
                           .dv_prev = relative_velocity(sim),
                           .min_gap = c.gap,
                           .interacting = c.gap < su->range,
                           .t_first = 0,
                           .t_observe = INFINITY,
                           .observe_span = s->observe_time};
    if (tr->interacting && s->observe_time > 0)
        tr->t_observe = s->observe_time;
}

/* Tangential part of the velocity of i's surface relative to j's at the contact point on the
 * line of centres with normal n (contact.c convention) [m/s]. */
static struct wetdem_vec3 contact_slip(const struct wetdem_sim* sim, struct wetdem_vec3 n)
{
    const struct wetdem_particle* a = &sim->particles[0];
    struct wetdem_vec3 v = vec3_add(a->vel, vec3_cross(a->omega, vec3_scale(n, -a->radius)));
    if (!sim->n_walls) {
        const struct wetdem_particle* b = &sim->particles[1];
        v = vec3_sub(v, vec3_add(b->vel, vec3_cross(b->omega, vec3_scale(n, b->radius))));
    }
    return vec3_reject(v, n);
}

/* The initial state that the restitution coefficients refer to. */
struct initial {
    struct wetdem_vec3 dv, slip, n; /* relative velocity, contact slip [m/s], normal */
    double energy;                  /* kinetic energy of the relative motion and spins [J] */
    double stored;                  /* stored_energy at the start (0 beyond the range) [J] */
};

/* Kinetic energy of the relative motion, m* |dv|^2 / 2 (the two-body motion's in the frame
 * of the centre of mass; a wall or a fixed target has infinite mass), and of both spins,
 * I w^2 / 2 with I = 2/5 m R^2 (solid spheres, as the integrator's). */
static double collision_energy(const struct wetdem_sim* sim)
{
    const struct wetdem_particle* a = &sim->particles[0];
    bool other = !sim->n_walls && !sim->particles[1].is_fixed;
    double m_eff =
        other ? a->mass * sim->particles[1].mass / (a->mass + sim->particles[1].mass) : a->mass;
    struct wetdem_vec3 dv = relative_velocity(sim);
    double e = 0.5 * m_eff * vec3_dot(dv, dv) +
               0.2 * a->mass * a->radius * a->radius * vec3_dot(a->omega, a->omega);
    if (other) {
        const struct wetdem_particle* b = &sim->particles[1];
        e += 0.2 * b->mass * b->radius * b->radius * vec3_dot(b->omega, b->omega);
    }
    return e;
}

static int compare_doubles(const void* a, const void* b)
{
    double x = *(const double*)a, y = *(const double*)b;
    return (x > y) - (x < y);
}

/* Gauss-Legendre points per piece of stored_energy: exact for the capillary's constant force
 * and a linear spring, and for Hertz's delta^(3/2), whose derivative is singular at the
 * piece's end at contact, an error of about n^-5 of the energy (1e-9 at 64 points). */
#define STORED_ENERGY_POINTS 64

/* The energy the pair's forces store at its present gap [J]: the work their conservative part
 * (wetdem_sim_force_at_rest) does as the pair separates at rest from the gap to the end of its
 * interaction range, with its history (h_min records, tangential springs) held as it is now.
 * A Hertz overlap's (8/15) E* sqrt(R*) delta^(5/2) > 0; a capillary bridge's -F (delta - h)
 * < 0 (a well). 0 beyond the range; NAN if a model fails or the history is too long. The
 * integral is taken piecewise between the branch gaps of the force laws (their thresholds,
 * h_min and contact at 0), where a force may jump, by fixed Gauss-Legendre quadrature (GSL),
 * which needs no error handler and so is safe in parallel collisions. Into *energy (NAN when
 * the pair's history does not fit the scratch space); WETDEM_OK, or WETDEM_ERR_NOMEM with the
 * message set when the quadrature table cannot be allocated. */
static int stored_energy(struct wetdem_sim* sim, double* energy)
{
    *energy = NAN;
    if (sim->history_len > WETDEM_HISTORY_SCRATCH)
        return WETDEM_OK;
    /* the pair of particle 0 and its partner in the engine's list, which holds every pair
       once a run has begun; before, the pair is fresh */
    const struct wetdem_pairs* pl = &sim->engine.pairs;
    size_t k = 0;
    while (k < pl->n && !(pl->items[k].i == 0 && pl->items[k].j == (sim->n_walls ? 0u : 1u)))
        k++;
    const double* history = k < pl->n ? wetdem_pairs_history(pl, k) : NULL;
    struct wetdem_contact c;
    double range, scratch[WETDEM_HISTORY_SCRATCH];
    if (k < pl->n) {
        wetdem_event_pair_state(sim, k, &c, &range, scratch); /* (c.h_min: thresholds read it) */
    } else {
        pair_contact(sim, &c);
        range = wetdem_sim_contact_range(sim, &c);
        wetdem_sim_history_init(sim, scratch);
        c.h_min = sim->minsep.model->min_separation(sim->minsep.params, &c, scratch);
    }
    *energy = 0.0;
    if (!(c.gap < range))
        return WETDEM_OK;
    double cuts[WETDEM_MAX_MODELS * WETDEM_MAX_THRESHOLDS + 5], gaps[WETDEM_MAX_THRESHOLDS];
    size_t n = 0;
    cuts[n++] = c.gap;
    cuts[n++] = range;
    cuts[n++] = 0.0;
    cuts[n++] = c.film; /* (where a capillary bridge ends) */
    cuts[n++] = c.h_min;
    for (size_t m = 0; m < sim->n_models; m++) {
        const struct wetdem_model_slot* sl = &sim->models[m];
        size_t count =
            sl->model->thresholds
                ? sl->model->thresholds(sl->params, &c, scratch + sl->history_offset, gaps)
                : 0;
        for (size_t q = 0; q < count && q < WETDEM_MAX_THRESHOLDS; q++)
            cuts[n++] = gaps[q];
    }
    qsort(cuts, n, sizeof *cuts, compare_doubles);
    wetdem_gsl_guard_enter(); /* (out of memory, the allocation calls GSL's error handler) */
    gsl_integration_glfixed_table* table =
        gsl_integration_glfixed_table_alloc(STORED_ENERGY_POINTS);
    wetdem_gsl_guard_leave();
    if (!table)
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM,
                               "collision: out of memory for the quadrature of the stored energy");
    for (size_t q = 0; q + 1 < n; q++) {
        double a = cuts[q], b = cuts[q + 1];
        if (!(a >= c.gap && b <= range && b > a))
            continue;
        for (size_t p = 0; p < STORED_ENERGY_POINTS; p++) {
            double x, w;
            gsl_integration_glfixed_point(a, b, p, &x, &w, table);
            *energy += w * wetdem_sim_force_at_rest(sim, c, history, x); /* (NAN on failure) */
        }
    }
    gsl_integration_glfixed_table_free(table);
    return WETDEM_OK;
}

/* Contact time, contact/h_min flags and the last interaction end, from the event log. */
static void scan_log(const struct wetdem_sim* sim, bool in_contact,
                     struct wetdem_collision_result* r, double* t_last_end)
{
    double t_open = in_contact ? 0.0 : NAN, total = 0.0;
    *t_last_end = sim->engine.time;
    size_t n;
    const struct wetdem_event_record* ev = wetdem_sim_events(sim, &n);
    for (size_t k = 0; k < n; k++) {
        if (ev[k].kind == WETDEM_EVENT_CONTACT_START) {
            t_open = ev[k].time;
            r->solid_contact = true;
        } else if (ev[k].kind == WETDEM_EVENT_CONTACT_END && !isnan(t_open)) {
            total += ev[k].time - t_open;
            t_open = NAN;
        } else if (ev[k].kind == WETDEM_EVENT_HMIN_REACHED) {
            r->hmin_reached = true;
        } else if (ev[k].kind == WETDEM_EVENT_INTERACTION_END) {
            *t_last_end = ev[k].time;
        }
    }
    if (!isnan(t_open))
        total += sim->engine.time - t_open;
    r->contact_duration = total;
}

/* Restitution coefficients and angles from the initial and final states (a pair that has not
 * separated: the line of centres at the end). */
static void restitution(const struct wetdem_sim* sim, const struct initial* in,
                        const struct tracker* tr, bool separated, struct wetdem_collision_result* r)
{
    struct wetdem_contact c;
    pair_contact(sim, &c);
    struct wetdem_vec3 dvf = relative_velocity(sim);
    struct wetdem_vec3 nf = separated ? rebound_normal(tr, c.normal) : c.normal;
    double dn0 = vec3_dot(in->dv, in->n), dnf = vec3_dot(dvf, nf);
    /* no rebound by t_end (stick, or a run too short to reach the target): 0, as the papers
     * plot it; the ratios of the velocities at t_end would be those of a motion still under
     * way (e = 1 and e_n = -1 for a striker still on its way in) */
    r->e = separated ? vec3_norm(dvf) / vec3_norm(in->dv) : 0.0;
    r->e_n = dn0 < 0 ? (separated ? -dnf / dn0 : 0.0) : NAN;
    r->e_n_contact =
        dn0 < 0 && tr->turned ? (separated ? -vec3_dot(dvf, tr->n_turn) / dn0 : 0.0) : NAN;
    r->angle_in = atan2(vec3_norm(vec3_reject(in->dv, in->n)), -dn0);
    r->angle_out = atan2(vec3_norm(vec3_reject(dvf, nf)), dnf);
    r->normal_out = nf;
    double u0 = vec3_norm(in->slip);
    r->e_t = NAN;
    if (u0 > 1e-12 * vec3_norm(in->dv)) {
        struct wetdem_vec3 tf = vec3_reject(vec3_scale(in->slip, 1.0 / u0), nf);
        double len = vec3_norm(tf);
        if (len > 0)
            r->e_t = -vec3_dot(contact_slip(sim, nf), vec3_scale(tf, 1.0 / len)) / u0;
    }
    r->e_n_observed = NAN;
    if (tr->observe_span > 0) {
        struct wetdem_vec3 n = tr->observed ? tr->n_obs : nf, dv = tr->observed ? tr->dv_obs : dvf;
        double dn = vec3_dot(dv, n);
        r->e_n_observed = dn > 0 && dn0 < 0 ? -dn / dn0 : 0.0;
    }
}

/* The result of a run that ended (separated or at t_end). WETDEM_OK, or WETDEM_ERR_NOMEM
 * (stored_energy). */
static int analyse(struct wetdem_sim* sim, const struct setup* su, const struct initial* in,
                   const struct tracker* tr, bool separated, bool start_in_contact,
                   struct wetdem_collision_result* r)
{
    double mu = sim->fluid.viscosity;
    r->speed_n0 = su->speed_n0;
    r->stokes_n =
        mu > 0 ? su->m_eff * su->speed_n0 / (6 * M_PI * mu * su->r_eff * su->r_eff) : INFINITY;
    restitution(sim, in, tr, separated, r);
    r->omega_i = sim->particles[0].omega;
    r->omega_j = sim->n_walls ? vec3(0, 0, 0) : sim->particles[1].omega;
    double t_last_end;
    scan_log(sim, start_in_contact, r, &t_last_end);
    r->min_gap = tr->min_gap;
    r->solid_contact = r->solid_contact || tr->min_gap <= 0;
    r->hmin_reached = r->hmin_reached || r->solid_contact;
    r->separated = separated;
    r->t_first_interaction = tr->interacting ? tr->t_first : NAN;
    r->t_final = sim->engine.time;
    r->interaction_duration =
        tr->interacting ? (separated ? t_last_end : sim->engine.time) - tr->t_first : 0.0;
    double g = fabs(sim->settings.gravity_x) + fabs(sim->settings.gravity_y) +
               fabs(sim->settings.gravity_z);
    double e0 = in->energy + in->stored, stored = NAN;
    if (e0 > 0 && g == 0) {
        int st = stored_energy(sim, &stored);
        if (st != WETDEM_OK)
            return st;
    }
    r->energy_ratio = e0 > 0 && g == 0 ? (collision_energy(sim) + stored) / e0 : NAN;
    r->rotation_angle = tr->rotation;
    r->rotation_close = tr->rotation_close;
    r->rotation_doublet = tr->rotation_doublet;
    r->close_gap = su->h_close;
    if (!tr->interacting)
        r->outcome = WETDEM_OUTCOME_NONE;
    else if (!separated)
        r->outcome = WETDEM_OUTCOME_STICK;
    else if (tr->rotation_doublet > SRS_ANGLE)
        r->outcome = WETDEM_OUTCOME_STICK_ROTATE_SEPARATE;
    else
        r->outcome = WETDEM_OUTCOME_BOUNCE;
    r->stats = wetdem_sim_stats(sim);
    return WETDEM_OK;
}

int wetdem_collision_run(struct wetdem_sim* sim, const struct wetdem_collision_spec* spec,
                         struct wetdem_collision_result* result)
{
    if (!sim || !spec || !result)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "collision: NULL argument");
    memset(result, 0, sizeof *result);
    if (sim->many) /* (its steps feed no tracker: the result would be that of no collision) */
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "collision: the simulation is in the many-particle mode; a "
                               "collision is run and analysed by the two-body engine: call "
                               "wetdem_sim_set_many(sim, NULL) first");
    int st = check_spec(sim, spec);
    struct setup su;
    if (st == WETDEM_OK)
        st = place_bodies(sim, spec, &su);
    if (st != WETDEM_OK)
        return st;
    struct wetdem_contact c0;
    pair_contact(sim, &c0);
    c0.v_n = su.speed_n0;
    if ((st = wetdem_sim_check_range_edge(sim, &c0)) != WETDEM_OK)
        return st;
    struct tracker tr;
    start_tracker(sim, &su, spec, &tr);
    struct initial in = {
        .dv = relative_velocity(sim), .n = vec3(1, 0, 0), .energy = collision_energy(sim)};
    in.slip = contact_slip(sim, in.n);
    if (!(vec3_norm(in.dv) > 0 && in.energy >= DBL_MIN)) /* e and energy_ratio divide by them */
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "collision: the relative speed %g m/s is too small: |dv|^2 or the "
                               "kinetic energy %g J underflows, so e and energy_ratio would be "
                               "0/0; give a larger speed",
                               spec->speed, in.energy);
    if ((st = stored_energy(sim, &in.stored)) != WETDEM_OK)
        return st;
    bool in_contact = tr.gap_prev < 0;
    st = run(sim, spec, &tr);
    if (st < 0) {
        result->stats = wetdem_sim_stats(sim); /* (the work done up to the failure) */
        return st;
    }
    return analyse(sim, &su, &in, &tr, st == WETDEM_EVENT, in_contact, result);
}

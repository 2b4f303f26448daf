/*
 * sim_many.c — the many-particle mode of the soft engine (docs/many.md): velocity Verlet over
 * cell lists with a Verlet skin, plane walls, periodic boundaries, an OpenMP force loop whose
 * result does not depend on the thread count, and the energy budget. Prefix: wetdem_sim_.
 *
 * Step (the scheme of integrator_verlet.c, Nijssen 2023 Sec. 3, so both engines agree):
 *     v' = v + a(t) dt/2,  w' = w + alpha(t) dt/2,  x(t + dt) = x + v' dt
 *     F, T at x(t + dt) with the predicted velocities v* = v' + a(t) dt/2 (and w*)
 *     v(t + dt) = v' + a(t + dt) dt/2,  w(t + dt) = w' + alpha(t + dt) dt/2
 * with a = F/m + g, alpha = T/I, I = (2/5) m R^2. Between steps whose state nothing reads, the
 * force pass applies the last line and the next step's first one to each block of particles
 * once their forces are complete (one_step), with the same arithmetic. Steps are whole: a run
 * to t_end takes ceil((t_end - t)/dt) steps, so runs split into pieces (checkpoint and
 * restart) follow the same time grid t0 + k dt as one run and give bit-identical states.
 *
 * Pairs: the cell list (celllist.h, Eq. 1 there) lists every pair with gap < reach + skin,
 * where reach is the largest model range of any pair, bounded at start-up from the largest
 * radius and every material combination; a pair whose actual range exceeds the bound stops
 * the run with an error rather than being missed. Pair histories follow the pairs (i, j)
 * across rebuilds; pairs beyond their range get a fresh history (each encounter starts
 * afresh), except for the record of a min-separation model that keeps one beyond the force
 * range (ehd, max: up to reset_ratio R*), which ends where it ends in sim_integrate.c
 * (wetdem_sim_history_beyond_range); the list's reach covers that record range, so a live
 * record is never dropped by a rebuild (many.h, record). Particle-wall pairs are all
 * n x n_walls pairs.
 *
 * Determinism: every particle sums the forces on it in an order set by particle indices only
 * (sim_many_force.c), so positions and velocities are bit-identical for any number of
 * threads. So is the energy budget: its work is summed per particle in list order and then
 * over fixed chunks of particles (sim_many_force.c collect_pass_work).
 *
 * Energy budget: the work of model k on a pair over one step is W = dt P(t + dt) with the
 * power P = F_i.(v*_i - v*_j) + T_i.w*_i + T_j.w*_j of that model's force at the evaluated
 * state. In velocity Verlet the force F(t + dt) changes the kinetic energy through two half
 * kicks by exactly dt F.v(t + dt); v* differs from v(t + dt) by O(dt^2), so the sum of the
 * work of all models and of gravity equals the change of kinetic energy to second order.
 */
#include <float.h>
#include <omp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "integrator.h"
#include "contact.h"
#include "many.h"
#include "models.h"
#include "vec3.h"

#define HISTORY_MAX 64 /* doubles of per-pair history (as sim_integrate.c) */

/* ---- settings ---- */

static char* dup_string(const char* s)
{
    if (!s)
        return NULL;
    char* d = malloc(strlen(s) + 1);
    if (d)
        strcpy(d, s);
    return d;
}

static int check_settings(struct wetdem_sim* sim, const struct wetdem_many_settings* s)
{
    if (!(isfinite(s->skin) && s->skin >= 0))
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "many.skin = %g m must be finite and >= 0",
                               s->skin);
    if (!(isfinite(s->dt) && s->dt >= 0))
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "many.dt = %g s must be finite and >= 0",
                               s->dt);
    double lo[3] = {s->box_lo.x, s->box_lo.y, s->box_lo.z};
    double hi[3] = {s->box_hi.x, s->box_hi.y, s->box_hi.z};
    for (int k = 0; k < 3; k++)
        if (s->periodic[k] && !(isfinite(lo[k]) && isfinite(hi[k]) && hi[k] > lo[k]))
            return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                                   "many box: periodic axis %c needs finite box_lo < box_hi, got "
                                   "[%g, %g] m",
                                   "xyz"[k], lo[k], hi[k]);
    return WETDEM_OK;
}

void wetdem_sim_many_free(struct wetdem_sim* sim)
{
    struct wetdem_many* m = sim->many;
    if (!m)
        return;
    wetdem_celllist_clear(&m->cl);
    free(m->output_prefix);
    free(m->checkpoint_path);
    free(m->csv_comment);
    free(m->checkpoint_note);
    free(m->restored_note);
    free(m->history);
    free(m->wall_history);
    free(m->old_pairs);
    free(m->old_history);
    free(m->old_flags);
    free(m->pair_cache);
    free(m->flags);
    free(m->wall_mask);
    free(m->wall_dirty);
    free(m->wall_list);
    free(m->wall_entry_part);
    free(m->wall_entry_wall);
    free(m->force);
    free(m->torque);
    free(m->vwh);
    free(m->xr);
    free(m->inv);
    free(m->m_eff);
    free(m->vw);
    free(m->fixed);
    free(m->image);
    free(m->pair_work);
    free(m->wall_work);
    free(m->cross_work);
    free(m->chunk_work);
    free(m->mix);
    free(m->blk);
    free(m->cross_first);
    free(m->cross_q);
    free(m->cross_in);
    free(m->cross_out);
    free(m->hits);
    free(m->hit_near);
    free(m->pair_lim2);
    free(m->skip_until);
    free(m->work);
    for (size_t k = 0; k < m->n_series && m->vtk_names; k++)
        free(m->vtk_names[k]);
    free(m->vtk_names);
    free(m->vtk_times);
    free(m);
    sim->many = NULL;
}

int wetdem_sim_set_many(struct wetdem_sim* sim, const struct wetdem_many_settings* s)
{
    if (!s) {
        wetdem_sim_many_free(sim);
        return WETDEM_OK;
    }
    int st = check_settings(sim, s);
    if (st != WETDEM_OK)
        return st;
    wetdem_sim_many_free(sim);
    struct wetdem_many* m = calloc(1, sizeof *m);
    if (!m)
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory");
    m->set = *s;
    m->output_prefix = dup_string(s->output_prefix);
    m->checkpoint_path = dup_string(s->checkpoint_path);
    m->csv_comment = dup_string(s->csv_comment);
    m->checkpoint_note = dup_string(s->checkpoint_note);
    m->set.output_prefix = m->output_prefix;
    m->set.checkpoint_path = m->checkpoint_path;
    m->set.csv_comment = m->csv_comment;
    m->set.checkpoint_note = m->checkpoint_note;
    sim->many = m;
    if ((s->output_prefix && !m->output_prefix) || (s->checkpoint_path && !m->checkpoint_path) ||
        (s->csv_comment && !m->csv_comment) || (s->checkpoint_note && !m->checkpoint_note))
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory");
    return WETDEM_OK;
}

void wetdem_sim_many_reset(struct wetdem_sim* sim)
{
    if (!sim->many)
        return;
    /* set_many frees the state it replaces, the settings' strings with it: copies first */
    struct wetdem_many_settings s = sim->many->set;
    char* prefix = dup_string(s.output_prefix);
    char* checkpoint = dup_string(s.checkpoint_path);
    char* comment = dup_string(s.csv_comment);
    char* note = dup_string(s.checkpoint_note);
    s.output_prefix = prefix;
    s.checkpoint_path = checkpoint;
    s.csv_comment = comment;
    s.checkpoint_note = note;
    if ((s.output_prefix && !prefix) || (s.checkpoint_path && !checkpoint) ||
        (s.csv_comment && !comment) || (s.checkpoint_note && !note) ||
        wetdem_sim_set_many(sim, &s) != WETDEM_OK)
        wetdem_sim_many_free(sim); /* (out of memory: back to the two-body mode) */
    free(prefix);
    free(checkpoint);
    free(comment);
    free(note);
}

struct wetdem_vec3 wetdem_sim_many_nearest_image(const struct wetdem_sim* sim, struct wetdem_vec3 a,
                                                 struct wetdem_vec3 b)
{
    const struct wetdem_many_settings* s = &sim->many->set; /* (the cell list's box is set from
                                                               them when a run starts) */
    const struct wetdem_celllist_box box = {{s->box_lo.x, s->box_lo.y, s->box_lo.z},
                                            {s->box_hi.x, s->box_hi.y, s->box_hi.z},
                                            {s->periodic[0], s->periodic[1], s->periodic[2]}};
    return vec3_sub(a, celllist_delta(&box, a, b));
}

/* ---- start-up bounds ---- */

/* Contact of two copies of particle p (materials a, b) at gap `gap`, or of p with a wall. */
static void probe_contact(const struct wetdem_sim* sim, struct wetdem_particle p, int a, int b,
                          bool wall, double gap, struct wetdem_contact* c)
{
    const struct wetdem_material* mat = sim->materials;
    p.pos = vec3(0, 0, p.radius + gap);
    if (wall) {
        wetdem_contact_with_wall(c, &p, &mat[a], vec3(0, 0, 0), vec3(0, 0, 1), &mat[b],
                                 &sim->fluid);
        return;
    }
    struct wetdem_particle q = p;
    p.pos = vec3(0, 0, 0);
    q.pos = vec3(0, 0, 2 * p.radius + gap);
    wetdem_contact_from_particles(c, &q, &mat[a], &p, &mat[b], &sim->fluid);
}

/* The start-up bounds of the neighbour search over every material combination, for the pair
 * of the largest spheres and for a largest sphere and a wall [m]: *reach, the largest range
 * of the enabled models; *list_reach and *wall_reach, the larger of it and the largest record
 * range of the min-separation model (wetdem_sim_record_range, 0 without a record) of those
 * pairs of spheres and of those sphere-wall pairs (many.h). */
static void reach_bound(const struct wetdem_sim* sim, double* reach, double* list_reach,
                        double* wall_reach)
{
    struct wetdem_particle big = {.radius = 0, .mass = 1};
    for (size_t k = 0; k < sim->n_particles; k++)
        if (sim->particles[k].radius > big.radius)
            big = sim->particles[k];
    double range = 0, record[2] = {0, 0}; /* of two spheres, of a sphere and a wall */
    for (int a = 0; a < sim->n_materials; a++)
        for (int b = 0; b < sim->n_materials; b++)
            for (int wall = 0; wall < 2; wall++) {
                struct wetdem_contact c;
                probe_contact(sim, big, a, b, wall, 0.0, &c);
                range = fmax(range, wetdem_sim_contact_range(sim, &c));
                record[wall] = fmax(record[wall], wetdem_sim_record_range(sim, &c));
            }
    *reach = range;
    *list_reach = fmax(range, record[0]);
    *wall_reach = fmax(range, record[1]);
}

/* The pair of spheres p and q (materials a, b) at gap `gap`, p above q, at rest. */
static void probe_spheres(const struct wetdem_sim* sim, struct wetdem_particle p,
                          struct wetdem_particle q, int a, int b, double gap,
                          struct wetdem_contact* c)
{
    q.pos = vec3(0, 0, 0);
    p.pos = vec3(0, 0, q.radius + p.radius + gap);
    wetdem_contact_from_particles(c, &p, &sim->materials[a], &q, &sim->materials[b], &sim->fluid);
}

/* ---- the time step (docs/many.md, Time step) ---- */

/* The spheres the step is derived from: a smallest and a largest free sphere, a smallest and
 * a largest fixed one (is_fixed: infinite mass), how many of each, and the speed scale. */
struct step_spheres {
    struct wetdem_particle small, big, fixed_small, fixed_big;
    size_t n_free, n_fixed;
    double speed; /* [m/s] */
    double bound; /* the speed no particle exceeds under it (wetdem_many_stats) [m/s] */
};

/* The pairs that can occur, each probed with a smallest free sphere: with a smallest and with
 * a largest free sphere, with a smallest and a largest fixed one (the largest has the larger
 * R*, so the shorter contact and relaxation times; the smallest the smaller h_min), and with
 * a wall. A fixed sphere never meets a fixed one or a wall: it does not move. */
enum step_probe {
    PROBE_FREE_SMALL,
    PROBE_FREE_BIG,
    PROBE_FIXED_SMALL,
    PROBE_FIXED_BIG,
    PROBE_WALL,
    N_PROBES
};

static const char* const probe_names[N_PROBES] = {
    "two smallest free spheres", "a smallest and a largest free sphere",
    "a smallest free sphere and a smallest fixed one",
    "a smallest free sphere and a largest fixed one", "a smallest free sphere and a wall"};

/* Whether the pairs of `probe` can occur. When none can (a lone free sphere, or only fixed
 * ones), the step is that of two copies of a smallest sphere, as if another could come. */
static bool probe_occurs(const struct wetdem_sim* sim, const struct step_spheres* sp, int probe)
{
    bool free_pairs = sp->n_free >= 2, fixed = sp->n_free >= 1 && sp->n_fixed >= 1,
         wall = sp->n_free >= 1 && sim->n_walls >= 1;
    switch (probe) {
    case PROBE_FREE_SMALL: return free_pairs || !(fixed || wall);
    case PROBE_FREE_BIG: return free_pairs;
    case PROBE_FIXED_SMALL:
    case PROBE_FIXED_BIG: return fixed;
    default: return wall;
    }
}

/* The contact of `probe` (materials a, b) at first touch, at rest. */
static void probe_pair(const struct wetdem_sim* sim, const struct step_spheres* sp, int probe,
                       int a, int b, struct wetdem_contact* c)
{
    const struct wetdem_particle* partner[] = {&sp->small, &sp->big, &sp->fixed_small,
                                               &sp->fixed_big};
    if (probe == PROBE_WALL)
        probe_contact(sim, sp->small, a, b, true, 0.0, c);
    else
        probe_spheres(sim, sp->small, *partner[probe], a, b, 0.0, c);
}

/* The time scales of the step at the speed scale. */
struct step_scales {
    double t_contact;  /* shortest contact time, normal or tangential, over the pairs that can
                          occur and every material combination [s] */
    int contact_probe; /* the pair that sets it */
    double tau;        /* shortest viscous relaxation time over those pairs, for the materials
                          that the particles and walls carry (a material no sphere uses must
                          not refuse a step) [s] */
    const struct wetdem_model* damper; /* the model that sets tau */
    double h_at;                       /* the h_min where it does [m] */
    double gap; /* smallest gap where the force laws jump (h_min), same pairs and materials [m] */
};

/* The time scales of the pairs of sp at its speed scale (struct step_scales). Returns
 * WETDEM_OK, WETDEM_ERR_NOMEM, or WETDEM_ERR_INVALID when a model is in contact at
 * the edge of its range (wetdem_sim_check_range_edge; message in sim). */
static int step_scales(struct wetdem_sim* sim, const struct step_spheres* sp, struct step_scales* s)
{
    *s = (struct step_scales){.t_contact = INFINITY, .tau = INFINITY, .gap = INFINITY};
    /* bit 1: a particle's material, bit 2: a wall's */
    unsigned char* used = calloc((size_t)sim->n_materials + 1, 1);
    if (!used)
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "many: out of memory for %d materials",
                               sim->n_materials);
    for (size_t k = 0; k < sim->n_particles; k++)
        used[sim->particles[k].material] |= 1;
    for (size_t w = 0; w < sim->n_walls; w++)
        used[sim->walls[w].material] |= 2;
    bool first = true; /* (the first pair names the contact time even where it is not finite) */
    for (int a = 0; a < sim->n_materials; a++)
        for (int b = 0; b < sim->n_materials; b++)
            for (int probe = 0; probe < N_PROBES; probe++) {
                if (!probe_occurs(sim, sp, probe))
                    continue;
                struct wetdem_contact c;
                probe_pair(sim, sp, probe, a, b, &c);
                c.v_n = fmax(sp->speed, 1e-12);
                /* sliding at the speed scale too, whatever the spheres' own velocities, so
                 * that a tangential law's jump at h_min (davis, nase with below_hmin = c)
                 * bounds the step as a normal law's does */
                struct wetdem_vec3 slide = vec3_some_perpendicular(c.normal);
                c.v_t = vec3_scale(slide, c.v_n / vec3_norm(slide));
                double t_n = wetdem_sim_contact_time(sim, &c);
                double t = fmin(t_n, wetdem_sim_tangential_time(sim, &c, t_n));
                if (t < s->t_contact || first) {
                    s->t_contact = t;
                    s->contact_probe = probe;
                    first = false;
                }
                if (!((used[a] & 1) && (used[b] & (probe == PROBE_WALL ? 2 : 1))))
                    continue;
                int edge = wetdem_sim_check_range_edge(sim, &c);
                if (edge != WETDEM_OK) {
                    free(used);
                    return edge;
                }
                const struct wetdem_model* which;
                double tau = wetdem_sim_relaxation_time(sim, &c, &which);
                if (tau < s->tau) {
                    s->tau = tau;
                    s->damper = which;
                    s->h_at = c.h_min;
                }
                s->gap = fmin(s->gap, wetdem_sim_jump_gap(sim, &c));
            }
    free(used);
    return WETDEM_OK;
}

/* How far gravity can make a free sphere fall before something that does not fall with it stops
 * it [m] (docs/many.md, Time step, "What a fall adds"), along the unit direction gh of gravity,
 * with heights h = -gh.x: the largest of
 *   - over the walls that face up (a = -n.gh > 0), the fall of a free sphere p to the wall's
 *     plane along gh, (n.(x_p - q) - R_p) / a, bounded over the spheres in one pass: with t =
 *     n + a gh the part of n across gravity, it is (h_p - R_p) - R_p (1 - a)/a + (t.x_p -
 *     n.q)/a <= U - R_min (1 - a)/a + (max of t.x over the box of the free centres - n.q)/a,
 *     U the largest h_p - R_p (exact for a wall normal to gravity, and for one sphere);
 *   - the fall of the highest free centre to the lowest point a free centre can touch a fixed
 *     sphere at, min over fixed f of (h_f - R_f) less the largest free radius;
 *   - the extent of the free centres along gravity.
 * 0 without free spheres. O(particles + walls). */
static double fall_height(const struct wetdem_sim* sim, struct wetdem_vec3 gh)
{
    double top = -INFINITY, bot = INFINITY, u = -INFINITY, r_min = INFINITY, r_max = 0;
    double fixed_low = INFINITY;
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    for (size_t k = 0; k < sim->n_particles; k++) {
        const struct wetdem_particle* p = &sim->particles[k];
        double h = -vec3_dot(gh, p->pos);
        if (p->is_fixed) {
            fixed_low = fmin(fixed_low, h - p->radius);
            continue;
        }
        top = fmax(top, h);
        bot = fmin(bot, h);
        u = fmax(u, h - p->radius);
        r_min = fmin(r_min, p->radius);
        r_max = fmax(r_max, p->radius);
        const double x[3] = {p->pos.x, p->pos.y, p->pos.z};
        for (int a = 0; a < 3; a++) {
            lo[a] = fmin(lo[a], x[a]);
            hi[a] = fmax(hi[a], x[a]);
        }
    }
    if (!(top > -INFINITY))
        return 0; /* no free sphere */
    double fall = top - bot;
    if (fixed_low < INFINITY)
        fall = fmax(fall, top - (fixed_low - r_max));
    for (size_t w = 0; w < sim->n_walls; w++) {
        const struct wetdem_wall* W = &sim->walls[w];
        double a = -vec3_dot(W->normal, gh);
        if (!(a > 0))
            continue; /* a wall that does not face up stops no fall */
        const struct wetdem_vec3 t = vec3_add(W->normal, vec3_scale(gh, a));
        const double tc[3] = {t.x, t.y, t.z};
        double across = 0; /* the largest t.x over the box of the free centres */
        for (int c = 0; c < 3; c++)
            across += fmax(tc[c] * lo[c], tc[c] * hi[c]);
        fall = fmax(fall, u - r_min * (1 - a) / a + (across - vec3_dot(W->normal, W->point)) / a);
    }
    return fmax(fall, 0.0);
}

/* The spheres of struct step_spheres and the speed scale of the step [m/s]: twice the largest
 * particle speed plus what gravity adds over the fall of fall_height, floored by
 * sim.speed_floor. Without free spheres, small and big are copies of the smallest sphere,
 * taken as free. Needs at least one particle. */
static void start_speed(const struct wetdem_sim* sim, struct step_spheres* sp)
{
    const struct wetdem_particle *small = NULL, *big = NULL, *fs = NULL, *fb = NULL;
    const struct wetdem_particle* smallest = &sim->particles[0];
    double v = 0;
    sp->n_free = sp->n_fixed = 0;
    for (size_t k = 0; k < sim->n_particles; k++) {
        const struct wetdem_particle* p = &sim->particles[k];
        smallest = p->radius < smallest->radius ? p : smallest;
        if (p->is_fixed) {
            fs = !fs || p->radius < fs->radius ? p : fs;
            fb = !fb || p->radius > fb->radius ? p : fb;
            sp->n_fixed++;
        } else {
            small = !small || p->radius < small->radius ? p : small;
            big = !big || p->radius > big->radius ? p : big;
            sp->n_free++;
        }
        v = fmax(v, 2 * vec3_norm(p->vel));
    }
    sp->small = small ? *small : *smallest;
    sp->big = big ? *big : *smallest;
    sp->small.is_fixed = sp->big.is_fixed = false;
    sp->fixed_small = fs ? *fs : sp->small;
    sp->fixed_big = fb ? *fb : sp->small;
    const struct wetdem_sim_settings* s = &sim->settings;
    const struct wetdem_vec3 gv = vec3(s->gravity_x, s->gravity_y, s->gravity_z);
    double g = vec3_norm(gv);
    double fall = g > 0 ? fall_height(sim, vec3(gv.x / g, gv.y / g, gv.z / g)) : 0;
    sp->speed = fmax(s->speed_floor, v + sqrt(2 * g * fall));
    /* without walls or fixed spheres everything falls together: the speeds grow without
       bound, the relative speeds as little as without gravity */
    bool stops = sim->n_walls > 0 || sp->n_fixed > 0;
    sp->bound = g > 0 && !stops ? INFINITY : sp->speed - 0.5 * v;
}

/* The spheres and time scales of the step for the current particles, into the engine's
 * relaxation_time, contact_time and crossing_time too. Needs at least one particle. Returns
 * WETDEM_OK or the error of step_scales. */
static int time_scales(struct wetdem_sim* sim, struct step_spheres* sp, struct step_scales* s)
{
    struct wetdem_many* m = sim->many;
    start_speed(sim, sp);
    int st = step_scales(sim, sp, s);
    if (st != WETDEM_OK)
        return st;
    m->relaxation_time = s->tau;
    m->contact_time = s->t_contact;
    m->crossing_time = s->gap / sp->speed;
    m->speed_scale = sp->speed;
    m->speed_bound = sp->bound;
    m->v2_seen = 0;
    return WETDEM_OK;
}

/* The time scales and speeds of a run without particles: nothing touches, damps or moves. */
static void clear_time_scales(struct wetdem_many* m)
{
    m->relaxation_time = m->contact_time = m->crossing_time = INFINITY;
    m->speed_scale = m->speed_bound = m->v2_seen = 0;
}

/* The shortest contact, relaxation and h_min crossing times [s] over the pairs that can occur
 * in sim (n_particles > 0), at the speed scale speed [m/s] in place of the start's. */
static int scales_at_speed(struct wetdem_sim* sim, double speed, double* t_contact, double* tau,
                           double* crossing)
{
    struct step_spheres sp;
    struct step_scales s;
    start_speed(sim, &sp);
    sp.speed = speed;
    int st = step_scales(sim, &sp, &s);
    if (st != WETDEM_OK)
        return st;
    *t_contact = s.t_contact;
    *tau = s.tau;
    *crossing = s.gap / speed;
    return WETDEM_OK;
}

int wetdem_sim_many_time_scales_at_scale(struct wetdem_sim* sim)
{
    struct wetdem_many* m = sim->many;
    if (sim->n_particles == 0 || !(m->speed_scale > 0))
        return WETDEM_OK;
    return scales_at_speed(sim, m->speed_scale, &m->contact_time, &m->relaxation_time,
                           &m->crossing_time);
}

int wetdem_sim_many_time_scales(struct wetdem_sim* sim)
{
    clear_time_scales(sim->many);
    struct step_spheres sp;
    struct step_scales s;
    return sim->n_particles > 0 ? time_scales(sim, &sp, &s) : WETDEM_OK;
}

/* The derived step [s] (docs/many.md, Time step) from the shortest contact time t_contact,
 * relaxation time tau and h_min crossing time crossing [s]: the shortest of
 * verlet.dt_fraction x t_contact, tau / 4 and verlet.many_hmin_fraction x crossing (that bound
 * off at 0). */
static double derived_step(const struct wetdem_sim* sim, double t_contact, double tau,
                           double crossing)
{
    double fraction = 0.02, many_hmin_fraction = 0.5;
    wetdem_sim_param(sim, "verlet.dt_fraction", &fraction);
    wetdem_sim_param(sim, "verlet.many_hmin_fraction", &many_hmin_fraction);
    double by_gap = many_hmin_fraction > 0 ? many_hmin_fraction * crossing : INFINITY;
    return fmin(fmin(fraction * t_contact, 0.25 * tau), by_gap);
}

int wetdem_sim_many_time_scales_at(struct wetdem_sim* sim, double speed, double* contact_time,
                                   double* relaxation_time, double* hmin_crossing_time,
                                   double* step)
{
    if (!sim->many || !sim->many->started)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "many_time_scales_at: %s",
                               !sim->many ? "the simulation is not in the many-particle mode"
                                          : "the many-particle run has not started");
    if (!contact_time || !relaxation_time || !hmin_crossing_time || !step)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "many_time_scales_at: NULL output");
    if (!(isfinite(speed) && speed > 0))
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "many_time_scales_at: speed = %g m/s must be finite and > 0", speed);
    *contact_time = *relaxation_time = *hmin_crossing_time = *step = INFINITY;
    if (sim->n_particles == 0)
        return WETDEM_OK;
    int st = scales_at_speed(sim, speed, contact_time, relaxation_time, hmin_crossing_time);
    if (st == WETDEM_OK)
        *step = derived_step(sim, *contact_time, *relaxation_time, *hmin_crossing_time);
    return st;
}

/* Says in m->dt_origin which bound of choose_dt sets the derived step dt, and which
 * parameters set that bound, for a message that refuses the step or the run's length. */
static void describe_dt(struct wetdem_sim* sim, const struct step_spheres* sp,
                        const struct step_scales* s, double dt, double fraction,
                        double many_hmin_fraction)
{
    struct wetdem_many* m = sim->many;
    if (dt == 0.25 * s->tau)
        snprintf(m->dt_origin, sizeof m->dt_origin,
                 "the step is a quarter of the viscous relaxation time %g s that '%s' sets "
                 "(m/c_d of its damping, which grows as the materials' restitution e_dry falls "
                 "and with the fluid's viscosity)",
                 s->tau, s->damper->name);
    else if (dt == many_hmin_fraction * m->crossing_time)
        snprintf(m->dt_origin, sizeof m->dt_origin,
                 "the step is verlet.many_hmin_fraction = %g x the time %g s in which a pair "
                 "closing at the speed scale %g m/s crosses the smallest gap where the force "
                 "laws jump, %g m",
                 many_hmin_fraction, m->crossing_time, sp->speed, s->gap);
    else
        snprintf(m->dt_origin, sizeof m->dt_origin,
                 "the step is verlet.dt_fraction = %g x the contact time %g s of %s (the "
                 "smallest free one R = %g m, mass %g kg) at the speed scale %g m/s, which "
                 "scales as (m*^2/(E*^2 R* v))^(1/5): check the materials' youngs_modulus and "
                 "density, and the radii",
                 fraction, s->t_contact, probe_names[s->contact_probe], sp->small.radius,
                 sp->small.mass, sp->speed);
}

/* Step [s]: many.dt, else verlet.dt, else the shortest of verlet.dt_fraction x the shortest
 * contact time (normal or tangential) at the speed scale, a quarter of the shortest viscous
 * relaxation time tau, and verlet.many_hmin_fraction x the time a pair closing at the speed
 * scale takes to cross the smallest h_min where the force laws jump (step_scales). Velocity
 * Verlet with the damping evaluated at the predicted velocity is stable for dt < tau and
 * dissipates within 3 % of the exact rate for dt <= tau/4 (docs/many.md, Time step); a step
 * given at or above tau is refused. Without particles the step must be given. */
static int choose_dt(struct wetdem_sim* sim, double* dt)
{
    struct wetdem_many* m = sim->many;
    double fixed = 0, fraction = 0.02, many_hmin_fraction = 0.5;
    wetdem_sim_param(sim, "verlet.dt", &fixed);
    wetdem_sim_param(sim, "verlet.dt_fraction", &fraction);
    wetdem_sim_param(sim, "verlet.many_hmin_fraction", &many_hmin_fraction);
    double given = m->set.dt > 0 ? m->set.dt : fixed;
    clear_time_scales(m);
    if (sim->n_particles == 0) {
        *dt = given;
        return given > 0 ? WETDEM_OK
                         : wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                                           "many: no particles to derive the time step from: "
                                           "add particles, or set many.dt or verlet.dt");
    }
    struct step_spheres sp;
    struct step_scales s;
    int st = time_scales(sim, &sp, &s);
    if (st != WETDEM_OK)
        return st;
    double tau = s.tau;
    if (tau == 0 && s.h_at > 0) /* m/c_d underflowed to 0: a mass near the least double */
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "many: the viscous relaxation time m/c_d of '%s' at h_min = %g m "
                               "is 0 s, since the smallest free sphere's mass is %g kg: no step "
                               "is stable; check the material's density and the radii",
                               s.damper->name, s.h_at, sp.small.mass);
    if (tau == 0)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "many: the viscous damping of '%s' has no bound at h_min = %g m "
                               "(it grows as 1/h towards contact), so no step is stable: set a "
                               "minimum separation h_min > 0",
                               s.damper->name, s.h_at);
    if (given > 0) {
        if (given >= tau) {
            /* a fluid law damps most at h_min; the contact damping (hertz) at the overlap */
            char where[64] = "in contact";
            if (s.damper->kind != WETDEM_MODEL_CONTACT)
                snprintf(where, sizeof where, "at h_min = %g m", s.h_at);
            return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                                   "many: the step dt = %g s is not below the viscous "
                                   "relaxation time %g s that '%s' sets %s "
                                   "(m/c_d, shortest over the pairs that can occur): "
                                   "velocity Verlet is unstable there; use dt <= %g s (a "
                                   "quarter, dissipation within 3 %%), or 0 to derive it",
                                   given, tau, s.damper->name, where, 0.25 * tau);
        }
        *dt = given;
        snprintf(m->dt_origin, sizeof m->dt_origin, "the step is given (many.dt or verlet.dt)");
        return WETDEM_OK;
    }
    *dt = derived_step(sim, s.t_contact, tau, m->crossing_time);
    describe_dt(sim, &sp, &s, *dt, fraction, many_hmin_fraction);
    /* a contact time of 0 or inf (a density or modulus near the ends of the double range)
     * resolves no contact, even where the other bounds give a finite step */
    if (!(isfinite(*dt) && *dt > 0 && isfinite(s.t_contact) && s.t_contact > 0))
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "many: cannot derive a time step: the contact time of %s "
                               "(the smallest free one R = %g m, mass %g kg) is %g s at the "
                               "speed scale %g m/s, and the relaxation time %g s: check the "
                               "materials' density and youngs_modulus, or set many.dt or "
                               "verlet.dt",
                               probe_names[s.contact_probe], sp.small.radius, sp.small.mass,
                               s.t_contact, sp.speed, tau);
    return WETDEM_OK;
}

/* ---- storage ---- */

static int grow(void** a, size_t* cap, size_t need, size_t size)
{
    if (need <= *cap && *a)
        return WETDEM_OK;
    size_t c = need > 16 ? need + need / 2 : 16;
    void* p = realloc(*a, c * size);
    if (!p)
        return WETDEM_ERR_NOMEM;
    *a = p;
    *cap = c;
    return WETDEM_OK;
}

static int size_particle_arrays(struct wetdem_sim* sim)
{
    struct wetdem_many* m = sim->many;
    size_t n = sim->n_particles ? sim->n_particles : 1, cap = m->particle_cap;
    if (n <= cap && m->force)
        return WETDEM_OK;
    struct {
        void** a;
        size_t size;
    } arrays[] = {{(void**)&m->force, sizeof *m->force},
                  {(void**)&m->torque, sizeof *m->torque},
                  {(void**)&m->vwh, sizeof *m->vwh},
                  {(void**)&m->xr, sizeof *m->xr},
                  {(void**)&m->inv, sizeof *m->inv},
                  {(void**)&m->m_eff, sizeof *m->m_eff},
                  {(void**)&m->vw, sizeof *m->vw},
                  {(void**)&m->fixed, sizeof *m->fixed},
                  {(void**)&m->wall_dirty, sizeof *m->wall_dirty},
                  {(void**)&m->image, sizeof *m->image}};
    size_t c = cap;
    for (size_t k = 0; k < sizeof arrays / sizeof arrays[0]; k++) {
        c = cap;
        if (grow(arrays[k].a, &c, n, arrays[k].size))
            return WETDEM_ERR_NOMEM;
    }
    m->particle_cap = c;
    return WETDEM_OK;
}

/* Lays the particle-wall histories out for the current particles and walls: grown, each
 * particle's row widened where walls were added since (its histories kept, the new walls'
 * fresh), and every history of a particle added since fresh. Walls are only ever added to a
 * many-mode state (a reset starts a new one). Returns WETDEM_OK or WETDEM_ERR_NOMEM. */
static int layout_wall_history(struct wetdem_sim* sim)
{
    struct wetdem_many* m = sim->many;
    size_t len = sim->history_len, n = sim->n_particles, nw = sim->n_walls;
    size_t nw_old = m->wall_history_walls, kept = m->wall_history_n < n ? m->wall_history_n : n;
    size_t need = n * nw * len;
    if (m->wall_history && n == m->wall_history_n && nw == nw_old)
        return WETDEM_OK;
    if (grow((void**)&m->wall_history, &m->wall_history_cap, need > 0 ? need : 1, sizeof(double)))
        return WETDEM_ERR_NOMEM;
    double* h = m->wall_history;
    for (size_t i = kept; len && i-- > 0;) { /* from the last row: each moves up, if at all */
        memmove(h + i * nw * len, h + i * nw_old * len, nw_old * len * sizeof *h);
        for (size_t w = nw_old; w < nw; w++)
            wetdem_sim_history_init(sim, h + (i * nw + w) * len);
    }
    for (size_t k = kept * nw; len && k < n * nw; k++)
        wetdem_sim_history_init(sim, h + k * len);
    m->wall_history_n = n;
    m->wall_history_walls = nw;
    return WETDEM_OK;
}

double wetdem_sim_many_step(const struct wetdem_sim* sim)
{
    return sim->many && sim->many->started ? sim->many->dt : 0.0;
}

int wetdem_sim_many_walls_added(struct wetdem_sim* sim)
{
    return sim->many && sim->many->wall_history ? layout_wall_history(sim) : WETDEM_OK;
}

/* Exchanges the pair histories and flags with the old-list buffers. */
static void swap_pair_arrays(struct wetdem_many* m)
{
    double* h = m->old_history;
    m->old_history = m->history;
    m->history = h;
    size_t cap = m->old_history_cap;
    m->old_history_cap = m->history_cap;
    m->history_cap = cap;
    unsigned char* f = m->old_flags;
    m->old_flags = m->flags;
    m->flags = f;
    cap = m->old_flags_cap;
    m->old_flags_cap = m->flags_cap;
    m->flags_cap = cap;
}

/* Walls within wall_reach + skin of each particle at this build (Verlet criterion as for pairs),
 * none for a fixed particle (it never meets a wall: pairs.c alike); the histories of the other
 * particle-wall pairs are reset. */
static int update_wall_masks(struct wetdem_sim* sim)
{
    struct wetdem_many* m = sim->many;
    size_t n = sim->n_particles, nw = sim->n_walls, len = sim->history_len;
    if (grow((void**)&m->wall_mask, &m->wall_mask_cap, n ? n : 1, sizeof *m->wall_mask))
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory for %zu particles", n);
    double lim = m->wall_reach + m->cl.skin;
#pragma omp parallel for schedule(static) if (wetdem_many_parallel(m, n))
    for (size_t i = 0; i < n; i++) {
        uint64_t mask = 0;
        bool fixed = sim->particles[i].is_fixed;
        for (size_t w = 0; w < nw && w < 64; w++) {
            const struct wetdem_wall* wall = &sim->walls[w];
            double gap = vec3_dot(vec3_sub(sim->particles[i].pos, wall->point), wall->normal) -
                         sim->particles[i].radius;
            if (gap < lim && !fixed)
                mask |= (uint64_t)1 << w;
            else if (len && m->wall_dirty[i] >> w & 1) {
                wetdem_sim_history_init(sim, m->wall_history + (i * nw + w) * len);
                m->wall_dirty[i] &= ~((uint64_t)1 << w);
            }
        }
        m->wall_mask[i] = mask;
    }
    m->walls_masked = nw;
    if (grow((void**)&m->wall_list, &m->wall_list_cap, n ? n : 1, sizeof *m->wall_list))
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory for %zu particles", n);
    m->n_wall_list = 0;
    size_t n_entries = 0;
    for (size_t i = 0; i < n; i++) {
        if (m->wall_mask[i] || (nw > 64 && !sim->particles[i].is_fixed))
            m->wall_list[m->n_wall_list++] = (uint32_t)i;
        n_entries += (size_t)__builtin_popcountll(m->wall_mask[i]);
    }
    if (grow((void**)&m->wall_entry_part, &m->wall_entry_part_cap, n_entries ? n_entries : 1,
             sizeof *m->wall_entry_part) ||
        grow((void**)&m->wall_entry_wall, &m->wall_entry_wall_cap, n_entries ? n_entries : 1,
             sizeof *m->wall_entry_wall))
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory for %zu particle-wall pairs",
                               n_entries);
    m->n_wall_entries = 0;
    for (size_t s = 0; s < m->n_wall_list && nw <= 64; s++) {
        size_t i = m->wall_list[s];
        for (uint64_t mask = m->wall_mask[i]; mask; mask &= mask - 1) {
            m->wall_entry_part[m->n_wall_entries] = (uint32_t)i;
            m->wall_entry_wall[m->n_wall_entries++] = (unsigned char)__builtin_ctzll(mask);
        }
    }
    return WETDEM_OK;
}

/* Writes the engine state back to the particle records: positions, and with `motion` the
 * velocities and spins (many.h, struct wetdem_many: xr, vw). Returns the lowest index of a
 * particle whose state is not finite, or SIZE_MAX (with `motion`, where the records are read
 * next: outputs, observers, callbacks, the end of a call). Finite means a finite position and
 * finite |v|^2 + |w|^2, so that its kinetic energy is finite; checked in the same pass, on
 * values in registers. */
static size_t write_back(struct wetdem_sim* sim, bool motion)
{
    struct wetdem_many* m = sim->many;
    if (!m->records_stale)
        return SIZE_MAX;
    size_t bad = SIZE_MAX; /* min is exact: the same for any thread count */
#pragma omp parallel for schedule(static)                                                          \
    reduction(min                                                                                  \
              : bad) if (wetdem_many_parallel(m, sim->n_particles))
    for (size_t k = 0; k < sim->n_particles; k++) {
        struct wetdem_particle* p = &sim->particles[k];
        p->pos = vec3(m->xr[k].x, m->xr[k].y, m->xr[k].z);
        if (motion) {
            p->vel = m->vw[k][0];
            p->omega = m->vw[k][1];
            /* 0 x inf and 0 x NaN are NaN (no -ffast-math), so the position takes part */
            double q = vec3_dot(p->vel, p->vel) + vec3_dot(p->omega, p->omega) +
                       0.0 * (p->pos.x + p->pos.y + p->pos.z);
            bad = q <= DBL_MAX || k > bad ? bad : k;
        }
    }
    m->records_stale = !motion;
    return bad;
}

/* Writes the engine's positions back to the particle records (before a list build). */
static void sync_positions(struct wetdem_sim* sim)
{
    write_back(sim, false);
}

/* Writes the whole engine state back to the particle records (before anything reads them);
 * returns write_back's lowest index of a particle whose state is not finite, or SIZE_MAX. */
static size_t sync_records(struct wetdem_sim* sim)
{
    return write_back(sim, true);
}

/* The largest of m and the magnitudes of the components of x (comparisons: no call). */
static double abs_max(struct wetdem_vec3 x, double m)
{
    double a = fabs(x.x), b = fabs(x.y), c = fabs(x.z);
    m = a > m ? a : m;
    m = b > m ? b : m;
    return c > m ? c : m;
}

/* The largest magnitude of a coordinate at the last list build, and of a bound of a periodic
 * axis [m]. */
static double coordinate_max(const struct wetdem_sim* sim)
{
    const struct wetdem_many* m = sim->many;
    const struct wetdem_vec3* at_build = m->cl.pos_at_build;
    double x_max = 0; /* max is exact: the same for any thread count */
#pragma omp parallel for schedule(static)                                                          \
    reduction(max                                                                                  \
              : x_max) if (wetdem_many_parallel(m, sim->n_particles))
    for (size_t k = 0; k < sim->n_particles; k++)
        x_max = abs_max(at_build[k], x_max);
    for (int a = 0; a < 3; a++)
        if (m->cl.box.periodic[a])
            x_max = abs_max(vec3(m->cl.box.lo[a], m->cl.box.hi[a], 0), x_max);
    return x_max;
}

static double wall_seconds(void)
{
    return omp_get_wtime();
}

/* What a failed build of a cell list whose reach a min-separation record widened (many.h)
 * adds to its message: which model and parameter set the reach; "" otherwise. */
static const char* record_hint(const struct wetdem_sim* sim, char* buf, size_t size)
{
    const struct wetdem_many* m = sim->many;
    if (!(m->cl.reach > m->reach))
        return "";
    const struct wetdem_model* model = sim->minsep.model;
    bool ratio = wetdem_param_find(model->params, "reset_ratio") != NULL;
    snprintf(buf, size,
             " (the reach %g m is the record range of min-separation model '%s', where the "
             "force models reach %g m%s%s%s)",
             m->cl.reach, model->name, m->reach, ratio ? ": a smaller " : "",
             ratio ? model->name : "", ratio ? ".reset_ratio shortens it" : "");
    return buf;
}

/* Rebuilds the cell list and carries the histories of surviving pairs over. */
static int rebuild_lists(struct wetdem_sim* sim)
{
    struct wetdem_many* m = sim->many;
    size_t len = sim->history_len, n_old = m->cl.n_pairs;
    if (grow((void**)&m->old_pairs, &m->old_cap, n_old ? n_old : 1, sizeof *m->old_pairs))
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory for the pair list");
    if (n_old)
        memcpy(m->old_pairs, m->cl.pairs, n_old * sizeof *m->old_pairs);
    sync_positions(sim); /* the build and the wall masks read the records */
    char msg[512];
    int st = wetdem_celllist_build(&m->cl, sim->particles, sim->n_particles, msg, sizeof msg);
    if (st != WETDEM_OK) {
        char hint[256];
        return wetdem_sim_fail(sim, st, "%s%s", msg, record_hint(sim, hint, sizeof hint));
    }
    m->disp_bound = 0;  /* nothing has moved since the build (kick_drift) */
    m->drift_clock = 0; /* the gap test's skip clock starts again, its times kept anew */
    m->skip_on = !m->no_skip;
    m->skip_ready = false;
    m->skip_off_passes = 0;
    m->x_build_max = coordinate_max(sim);
    swap_pair_arrays(m); /* the current histories and flags become the old ones (no copy) */
    size_t n_new = m->cl.n_pairs;
    if (grow((void**)&m->history, &m->history_cap, n_new * len + 1, sizeof(double)) ||
        grow((void**)&m->flags, &m->flags_cap, n_new ? n_new : 1, 1))
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory for %zu pairs", n_new);
    double fresh[HISTORY_MAX];
    if (len)
        wetdem_sim_history_init(sim, fresh);
    /* surviving pairs keep their history and its DIRTY and SPRING flags */
    wetdem_celllist_remap(m->old_pairs, m->old_history, m->old_flags, n_old, m->cl.pairs,
                          m->history, m->flags, WETDEM_MANY_DIRTY | WETDEM_MANY_SPRING, n_new, len,
                          fresh);
    m->blocks_ready = false; /* the force pass indexes the new list */
    return update_wall_masks(sim);
}

/* rebuild_lists, its time added to the lists' phase. */
static int rebuild(struct wetdem_sim* sim)
{
    double t0 = wall_seconds();
    int st = rebuild_lists(sim);
    sim->many->seconds_lists += wall_seconds() - t0;
    return st;
}

int wetdem_sim_many_prepare(struct wetdem_sim* sim)
{
    struct wetdem_many* m = sim->many;
    if (sim->history_len > HISTORY_MAX)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "the enabled models keep %zu doubles of pair history; at most %d",
                               sim->history_len, HISTORY_MAX);
    /* a radius edited between calls changes gaps without a move, and the bounds of the reach
       and the cells: the lists are bounded and built anew, as for a new particle. Looked for
       when a call starts (kernel_ready cleared), not at every force pass of its steps, which
       cannot change a radius (over all particles at every step it cost 6 % of a step) */
    bool resized = false;
    for (size_t k = 0;
         m->started && !m->kernel_ready && k < sim->n_particles && k < m->cl.n_at_build; k++)
        resized = resized || sim->particles[k].radius != m->xr[k].r;
    bool fresh_set = !m->started || sim->n_particles != m->cl.n_at_build || resized;
    double r_min = INFINITY, skin = m->cl.skin;
    double reach = m->reach, list_reach = m->cl.reach, wall_reach = m->wall_reach;
    for (size_t k = 0; fresh_set && k < sim->n_particles; k++)
        r_min = fmin(r_min, sim->particles[k].radius);
    if (fresh_set) { /* the bounds are set at start-up and when particles are added */
        reach_bound(sim, &reach, &list_reach, &wall_reach);
        skin = m->set.skin > 0 ? m->set.skin : 0.1 * (isfinite(r_min) ? r_min : 1.0);
        m->reach = reach;
        m->wall_reach = wall_reach;
    }
    if (fresh_set && (!m->started || list_reach != m->cl.reach || skin != m->cl.skin)) {
        struct wetdem_celllist_box box = {
            {m->set.box_lo.x, m->set.box_lo.y, m->set.box_lo.z},
            {m->set.box_hi.x, m->set.box_hi.y, m->set.box_hi.z},
            {m->set.periodic[0], m->set.periodic[1], m->set.periodic[2]}};
        struct wetdem_celllist_pair* pairs = m->cl.pairs; /* keep the list for remapping */
        size_t n_pairs = m->cl.n_pairs, pairs_cap = m->cl.pairs_cap;
        m->cl.pairs = NULL;
        wetdem_celllist_clear(&m->cl);
        char msg[256];
        int st = wetdem_celllist_init(&m->cl, &box, list_reach, skin, msg, sizeof msg);
        m->cl.pairs = pairs;
        m->cl.n_pairs = n_pairs;
        m->cl.pairs_cap = pairs_cap;
        if (st != WETDEM_OK)
            return wetdem_sim_fail(sim, st, "%s", msg);
    }
    bool refresh = fresh_set || !m->kernel_ready;
    if (refresh) {
        const struct wetdem_model* ms = sim->minsep.model; /* (the model may have changed) */
        m->record = ms->record_range != NULL;
        m->record_partial = m->record && (ms == &wetdem_minsep_ehd || ms == &wetdem_minsep_max ||
                                          ms == &wetdem_minsep_glass);
        int st = wetdem_sim_many_setup_kernel(sim);
        if (st != WETDEM_OK)
            return st;
        m->kernel_ready = true;
    }
    size_t known = m->started ? m->cl.n_at_build : 0; /* particles the engine has forces of */
    if (size_particle_arrays(sim) != WETDEM_OK || layout_wall_history(sim) != WETDEM_OK)
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory for %zu particles",
                               sim->n_particles);
    /* particles added since: no pair force yet (their first half kick is gravity's alone; the
       first force pass of the call gives them theirs) */
    for (size_t k = known; k < sim->n_particles; k++) {
        m->force[k] = m->torque[k] = vec3(0, 0, 0);
        m->image[k][0] = m->image[k][1] = m->image[k][2] = 0;
    }
    if (refresh) {
        sync_records(sim);     /* (never stale here: a call ends with them written) */
        m->skip_ready = false; /* the positions are loaded anew: no skips at the next pass */
    }
    /* a particle fixed or freed since the lists were built for these particles (which leave
       out pairs of two fixed ones and a fixed one's walls): they are rebuilt */
    bool built = m->cl.n_builds > 0 && m->cl.n_at_build == sim->n_particles, refixed = false;
    for (size_t k = 0; refresh && k < sim->n_particles; k++) { /* the user may move particles */
        const struct wetdem_particle* p = &sim->particles[k];
        m->xr[k] = (struct wetdem_celllist_item){p->pos.x, p->pos.y, p->pos.z, p->radius};
        m->vw[k][0] = m->vwh[k][0] = p->vel; /* (a fixed particle's half-step velocity too) */
        m->vw[k][1] = m->vwh[k][1] = p->omega;
        refixed = refixed || (built && m->fixed[k] != p->is_fixed);
        m->fixed[k] = p->is_fixed;
        m->inv[k][0] = 1.0 / p->mass;
        m->inv[k][1] = 1.0 / (0.4 * p->mass * p->radius * p->radius);
        m->m_eff[k] = contact_effective_mass(p);
        m->wall_dirty[k] = ~(uint64_t)0; /* histories may have been restored or changed */
    }
    bool track = m->max_disp_valid && m->cl.n_builds > 0 && m->cl.n_at_build == sim->n_particles;
    if (!track)
        sync_positions(sim); /* needs_rebuild reads the records */
    bool moved = track ? m->max_disp2 > 0.25 * m->cl.skin * m->cl.skin
                       : wetdem_celllist_needs_rebuild(&m->cl, sim->particles, sim->n_particles);
    m->max_disp_valid = false;
    /* a wall added since the lists were built: the masks of the walls to evaluate are made
       anew, or the particles would not meet it until a move rebuilt them */
    bool rewalled = m->cl.n_builds > 0 && m->walls_masked != sim->n_walls;
    if (moved || refixed || rewalled || resized)
        return rebuild(sim);
    return WETDEM_OK;
}

/* ---- forces: sim_many_force.c ---- */

/* ---- integration ---- */

static struct wetdem_vec3 gravity(const struct wetdem_sim* sim)
{
    return vec3(sim->settings.gravity_x, sim->settings.gravity_y, sim->settings.gravity_z);
}

/* Wraps x into [lo, hi) on the periodic axes, counting the box lengths taken off in image
 * (a store only when a wrap happens). */
static struct wetdem_vec3 wrap(const struct wetdem_celllist_box* b, struct wetdem_vec3 x,
                               double image[3])
{
    double c[3] = {x.x, x.y, x.z};
    for (int k = 0; k < 3; k++)
        if (b->periodic[k]) {
            double len = b->hi[k] - b->lo[k], n = floor((c[k] - b->lo[k]) / len);
            c[k] -= len * n;
            if (n != 0)
                image[k] += n;
        }
    return vec3(c[0], c[1], c[2]);
}

/* The arrays the kick-drift pass reads and writes, none of them overlapping another: held in
 * registers across the stores of a particle, where the engine's fields would be loaded again
 * after each (14 fewer instructions per particle-step). */
struct kick_arrays {
    struct wetdem_vec3* restrict force;
    struct wetdem_vec3* restrict torque;
    struct wetdem_vec3 (*restrict vwh)[2];
    const double (*restrict inv)[2];
    struct wetdem_celllist_item* restrict xr;
    struct wetdem_vec3 (*restrict vw)[2];
    double (*restrict image)[3];
};

/* Half kick and drift of particle k; its velocities become the predicted ones v' + a dt/2,
 * and *v2_max the larger of itself and |v'|^2 of the half-step velocity (infinite for a NaN, which
 * a max would drop or keep depending on the order). Every value is formed
 * in a local and stored once. */
static inline __attribute__((always_inline)) void
kick_drift_one(const struct kick_arrays* A, const struct wetdem_celllist_box* box, size_t k,
               struct wetdem_vec3 g, double h, bool periodic, bool pending, double* v2_max)
{
    double half = 0.5 * h;
    struct wetdem_vec3 a = vec3_axpy(g, A->inv[k][0], A->force[k]);
    struct wetdem_vec3 alpha = vec3_scale(A->torque[k], A->inv[k][1]);
    struct wetdem_vec3 v = A->vw[k][0], w = A->vw[k][1];
    if (pending) { /* the previous step's closing half kick, with the same a and alpha */
        v = vec3_axpy(A->vwh[k][0], half, a);
        w = vec3_axpy(A->vwh[k][1], half, alpha);
    }
    struct wetdem_vec3 vh = vec3_axpy(v, half, a), wh = vec3_axpy(w, half, alpha);
    struct wetdem_vec3 x = vec3_axpy(vec3(A->xr[k].x, A->xr[k].y, A->xr[k].z), h, vh);
    double v2 = vec3_dot(vh, vh);
    v2 = v2 == v2 ? v2 : INFINITY; /* a NaN wins no max: count it as infinite */
    *v2_max = v2 > *v2_max ? v2 : *v2_max;
    x = periodic ? wrap(box, x, A->image[k]) : x;
    A->vwh[k][0] = vh;
    A->vwh[k][1] = wh;
    A->xr[k].x = x.x;
    A->xr[k].y = x.y;
    A->xr[k].z = x.z;
    A->vw[k][0] = vec3_axpy(vh, half, a);
    A->vw[k][1] = vec3_axpy(wh, half, alpha);
}

/* Particles lo .. hi - 1 of the engine's arrays: half kick and drift (kick_drift_one, after
 * the deferred closing half kick when `pending`) where not fixed, and force and torque zeroed
 * for the next force pass while their lines are in cache (that pass then starts only the sums
 * of the particles with walls); *v2_max as kick_drift_one's. */
static inline __attribute__((always_inline)) void kick_drift_range(struct wetdem_many* m, size_t lo,
                                                                   size_t hi, struct wetdem_vec3 g,
                                                                   bool pending, double* v2_max)
{
    const struct kick_arrays arrays = {.force = m->force,
                                       .torque = m->torque,
                                       .vwh = m->vwh,
                                       .inv = (const double(*)[2])m->inv,
                                       .xr = m->xr,
                                       .vw = m->vw,
                                       .image = m->image};
    const unsigned char* fixed = m->fixed;
    const struct wetdem_celllist_box* box = &m->cl.box;
    bool periodic = box->periodic[0] || box->periodic[1] || box->periodic[2];
    double h = m->dt, v2 = *v2_max;
    for (size_t k = lo; k < hi; k++) {
        const struct kick_arrays A = arrays; /* (the thread's own copy: in registers) */
        if (!fixed[k])
            kick_drift_one(&A, box, k, g, h, periodic, pending, &v2);
        A.force[k] = A.torque[k] = vec3(0, 0, 0);
    }
    *v2_max = v2;
}

double wetdem_sim_many_drift_range(struct wetdem_sim* sim, size_t lo, size_t hi)
{
    double v2 = 0;
    kick_drift_range(sim->many, lo, hi, gravity(sim), true, &v2);
    return v2;
}

/* Largest squared displacement of any particle since the last neighbour-list build [m^2]. */
static double max_displacement2(const struct wetdem_sim* sim)
{
    const struct wetdem_many* m = sim->many;
    bool periodic = m->cl.box.periodic[0] || m->cl.box.periodic[1] || m->cl.box.periodic[2];
    const struct wetdem_vec3* at_build = m->cl.pos_at_build;
    double worst = 0; /* max is exact: the same for any thread count */
#pragma omp parallel for schedule(static)                                                          \
    reduction(max                                                                                  \
              : worst) if (wetdem_many_parallel(m, sim->n_particles))
    for (size_t k = 0; k < sim->n_particles; k++) {
        struct wetdem_vec3 x = vec3(m->xr[k].x, m->xr[k].y, m->xr[k].z);
        struct wetdem_vec3 d =
            periodic ? celllist_delta(&m->cl.box, x, at_build[k]) : vec3_sub(x, at_build[k]);
        double d2 = vec3_dot(d, d);
        worst = d2 > worst ? d2 : worst;
    }
    return worst;
}

/* The ranges of the kick-drift pass on nt threads (1 <= nt <= WETDEM_MANY_MAX_BLOCKS):
 * contiguous, in proportion to the speed at which each was updated in the passes before
 * (kick_speeds), so that a thread the machine slows down (a virtual core shared with other
 * guests, which here ran the same work at half speed for whole runs) does less of the pass;
 * equal before the first measurement and when the thread count or the particles change; none
 * below an eighth of an equal share, so that every range keeps being measured. Each
 * particle's update is its own, so the cuts change no result (tests/test_many_force.c). */
static void kick_ranges(struct wetdem_many* m, size_t n, size_t nt)
{
    if (m->kick_threads != nt || m->kick_n != n) {
        m->kick_threads = nt;
        m->kick_n = n;
        for (size_t t = 0; t < nt; t++)
            m->kick_speed[t] = 0;
    }
    double total = 0;
    bool measured = true;
    for (size_t t = 0; t < nt; t++) {
        total += m->kick_speed[t];
        measured = measured && m->kick_speed[t] > 0;
    }
    size_t least = n / (8 * nt);
    double sum = 0;
    m->kick_cut[0] = 0;
    for (size_t t = 1; t < nt; t++) {
        sum += measured ? m->kick_speed[t - 1] / total : 1.0 / (double)nt;
        size_t cut = (size_t)((double)n * sum), lo = m->kick_cut[t - 1] + least,
               hi = n - (nt - t) * least;
        cut = cut < lo ? lo : cut;
        m->kick_cut[t] = cut > hi ? hi : cut;
    }
    m->kick_cut[nt] = n;
    if (m->kick_jitter) { /* tests: arbitrary increasing cuts, new at every pass */
        uint64_t r = m->kick_jitter = m->kick_jitter * 6364136223846793005u + 1442695040888963407u;
        for (size_t t = 1; t < nt; t++) {
            r = r * 6364136223846793005u + 1442695040888963407u;
            m->kick_cut[t] =
                m->kick_cut[t - 1] + (size_t)((r >> 33) % (n - m->kick_cut[t - 1] + 1));
        }
    }
}

/* Each range's speed [particles/s] from its time in the pass (seconds), smoothed over the
 * passes; one measurement moves it by at most a factor of two (a thread descheduled for one
 * step does not empty its range). */
static void kick_speeds(struct wetdem_many* m, size_t nt, const double* seconds)
{
    for (size_t t = 0; t < nt; t++) {
        size_t count = m->kick_cut[t + 1] - m->kick_cut[t];
        if (!count || !(seconds[t] > 0))
            continue;
        double speed = (double)count / seconds[t], old = m->kick_speed[t];
        if (old > 0)
            speed = 0.75 * old + 0.25 * fmin(fmax(speed, 0.5 * old), 2.0 * old);
        m->kick_speed[t] = speed;
    }
}

/* After the drift of every particle (by the kick-drift pass or inside the force pass), with
 * v2_max the largest |v'|^2 of the half-step velocities and h the step: the state of the
 * pass and the rebuild criterion. The criterion (largest displacement since the last
 * neighbour-list build > skin/2) is decided without reading the positions at the build at
 * every step: this step's displacement of every particle is bounded by h max|v'| plus the
 * round-off of the drift (16 eps max|x|, eps = DBL_EPSILON; the drift x + h v' and the
 * periodic wrap each round by at most eps|x| per component) and added to m->disp_bound, an
 * upper bound of the largest displacement since the build. Only when that bound exceeds
 * skin/2 (less a relative 1e-6 for the round-off of the sum) are the displacements measured,
 * and the bound reset to the measured one. Where the measurement is skipped, the true
 * displacement is below skin/2 and the measured one would not have triggered a rebuild
 * either: the lists are rebuilt at the same steps, so the results are those of a measurement
 * at every step. */
static void after_drift(struct wetdem_sim* sim, double h, double v2_max)
{
    struct wetdem_many* m = sim->many;
    bool track = m->cl.n_builds > 0 && m->cl.n_at_build == sim->n_particles;
    m->v2_drift = v2_max; /* (one_step stops the run where it is not finite) */
    m->sums_zeroed = sim->n_particles;
    m->records_stale = true;
    m->max_disp_valid = track;
    if (!track) {
        m->skip_ready = false;
        return;
    }
    /* |x| <= its value at the build + the displacement since, or within the periodic box */
    if (isfinite(m->disp_bound)) { /* else unknown (a new call): measured below */
        double step = h * sqrt(v2_max) * (1 + 16 * DBL_EPSILON) +
                      16 * DBL_EPSILON * (m->x_build_max + m->disp_bound);
        m->disp_bound += step;
        m->drift_clock += step; /* the gap test's skip clock (many.h) */
        double limit = m->clock_limit > 0 ? m->clock_limit : m->cl.skin;
        if (m->drift_clock > limit) { /* restarted while small against the coordinates, so */
            m->drift_clock = 0;       /* that its round-off stays below the 16 eps x_build_max */
            m->skip_ready = false;    /* each step adds */
            m->clock_restarts++;
        }
    } else
        m->skip_ready = false; /* the particles may have been moved since the last pass */
    m->max_disp2 = 0;
    if (!(m->disp_bound <= 0.5 * m->cl.skin * (1 - 1e-6))) {
        m->max_disp2 = max_displacement2(sim);
        m->disp_measures++;
        double d = sqrt(m->max_disp2);
        m->disp_bound = d * (1 + 16 * DBL_EPSILON) + 16 * DBL_EPSILON * (m->x_build_max + d);
    }
}

/* Half kick and drift of every particle (preceded by the previous step's closing half kick if
 * it was deferred), then after_drift. */
static void kick_drift(struct wetdem_sim* sim)
{
    struct wetdem_many* m = sim->many;
    bool pending = m->kick_pending;
    m->kick_pending = false;
    struct wetdem_vec3 g = gravity(sim);
    size_t n = sim->n_particles;
    double v2_max = 0; /* max is exact: the same for any thread count */
    size_t nt = wetdem_many_parallel(m, n) ? (size_t)omp_get_max_threads() : 1;
    nt = nt < WETDEM_MANY_MAX_BLOCKS ? nt : WETDEM_MANY_MAX_BLOCKS;
    kick_ranges(m, n, nt);
    double seconds[WETDEM_MANY_MAX_BLOCKS];
#pragma omp parallel num_threads((int)nt) reduction(max : v2_max) if (nt > 1)
    { /* (range r on thread r; on fewer threads than asked, each takes every got-th range) */
        size_t got = (size_t)omp_get_num_threads();
        for (size_t r = (size_t)omp_get_thread_num(); r < nt; r += got) {
            double t0 = omp_get_wtime();
            kick_drift_range(m, m->kick_cut[r], m->kick_cut[r + 1], g, pending, &v2_max);
            seconds[r] = omp_get_wtime() - t0;
        }
    }
    if (nt > 1)
        kick_speeds(m, nt, seconds);
    after_drift(sim, m->dt, v2_max);
}

/* The deferred closing half kick of every particle, before anything reads the state. */
static void finish_kick(struct wetdem_sim* sim)
{
    struct wetdem_many* m = sim->many;
    if (!m->kick_pending)
        return;
    m->kick_pending = false;
    struct wetdem_vec3 g = gravity(sim);
#pragma omp parallel for schedule(static) if (wetdem_many_parallel(m, sim->n_particles))
    for (size_t k = 0; k < sim->n_particles; k++)
        wetdem_many_close_kick(m, k, g);
}

/* Forces at the current state, then `end` for each particle (many.h), work collected (by the
 * force pass). */
static int forces_and_work(struct wetdem_sim* sim, enum wetdem_many_end end)
{
    struct wetdem_many* m = sim->many;
    double t0 = wall_seconds(), lists0 = m->seconds_lists; /* (a build may come first) */
    m->drift_seconds = 0;
    int st = wetdem_sim_many_forces(sim, end);
    /* (the next step's kicks and drifts, where the pass applied them, count as theirs) */
    m->seconds_forces += (wall_seconds() - t0) - (m->seconds_lists - lists0) - m->drift_seconds;
    m->seconds_kick += m->drift_seconds;
    return st;
}

void wetdem_sim_many_energies(const struct wetdem_sim* sim, double* kinetic, double* potential,
                              double* elastic)
{
    const struct wetdem_many* m = sim->many;
    struct wetdem_vec3 g = gravity(sim);
    double k = 0, u = 0, el = 0;
    for (size_t i = 0; i < sim->n_particles; i++) {
        const struct wetdem_particle* p = &sim->particles[i];
        if (p->is_fixed)
            continue;
        k += 0.5 * p->mass * vec3_dot(p->vel, p->vel) +
             0.2 * p->mass * p->radius * p->radius * vec3_dot(p->omega, p->omega);
        u -= p->mass * vec3_dot(g, p->pos);
        /* the box lengths its periodic wraps took off: the potential of the unwrapped
           position, continuous across a wrap (without it, gravity along a periodic axis put
           m g L into the closure error at every crossing) */
        const double* im = m && m->image && i < m->cl.n_at_build ? m->image[i] : NULL;
        if (im && (im[0] || im[1] || im[2])) {
            const struct wetdem_celllist_box* b = &m->cl.box;
            struct wetdem_vec3 shift =
                vec3(im[0] * (b->hi[0] - b->lo[0]), im[1] * (b->hi[1] - b->lo[1]),
                     im[2] * (b->hi[2] - b->lo[2]));
            u -= p->mass * vec3_dot(g, shift);
        }
    }
    /* the energy stored in the solid contacts, as the enabled models define it (their
     * elastic_energy hooks: the Hertz (8/15) E* sqrt(R*) delta^(5/2), hooke's k delta^2 / 2,
     * nijssen's blended contact; none for fluid forces), of every pair within the list (any
     * pair in range is in it) and every particle-wall pair */
    for (size_t q = 0; m && q < m->cl.n_pairs; q++) {
        struct wetdem_contact c;
        wetdem_sim_many_contact(sim, m->cl.pairs[q].i, m->cl.pairs[q].j, false, &c);
        el += wetdem_sim_contact_elastic_energy(sim, &c, wetdem_many_pair_history(sim, q));
    }
    for (size_t i = 0; m && i < sim->n_particles; i++)
        for (size_t w = 0; w < wetdem_many_walls_of(sim, i); w++) {
            struct wetdem_contact c;
            wetdem_sim_many_contact(sim, i, w, true, &c);
            el += wetdem_sim_contact_elastic_energy(sim, &c, wetdem_many_wall_history(sim, i, w));
        }
    *kinetic = k;
    *potential = u;
    *elastic = el;
}

/* The outputs due (wetdem_sim_many_outputs; `final`: those of a call's end), then with
 * `observe` the observer if due; their time added to the output phase. */
static int timed_outputs(struct wetdem_sim* sim, bool final, bool observe)
{
    double t0 = wall_seconds();
    int st = wetdem_sim_many_outputs(sim, final);
    if (st == WETDEM_OK && observe)
        st = wetdem_sim_observe_due(sim);
    sim->many->seconds_output += wall_seconds() - t0;
    return st;
}

void wetdem_sim_many_keep_models(struct wetdem_sim* sim)
{
    struct wetdem_many* m = sim->many;
    for (size_t k = 0; k < sim->n_models; k++)
        m->run_models[k] = sim->models[k].model;
    m->run_models[sim->n_models] = sim->minsep.model;
    m->run_n_models = sim->n_models + 1;
}

/* The names of models[0 .. n - 1] (the last the min-separation model) into buf. */
static void model_list(const struct wetdem_model* const* models, size_t n, char* buf, size_t size)
{
    size_t used = 0;
    buf[0] = '\0';
    for (size_t k = 0; k < n && used < size; k++)
        used += (size_t)snprintf(buf + used, size - used, "%s%s%s", k ? " " : "",
                                 k + 1 == n ? "min-separation " : "", models[k]->name);
}

int wetdem_sim_many_check_models(const struct wetdem_sim* sim, const char* what)
{
    const struct wetdem_many* m = sim->many;
    const struct wetdem_model* now[WETDEM_MAX_MODELS + 1];
    for (size_t k = 0; k < sim->n_models; k++)
        now[k] = sim->models[k].model;
    now[sim->n_models] = sim->minsep.model;
    size_t n = sim->n_models + 1;
    if (!m || !m->started ||
        (n == m->run_n_models && memcmp(now, m->run_models, n * sizeof *now) == 0))
        return WETDEM_OK;
    char was[512], is[512];
    model_list(m->run_models, m->run_n_models, was, sizeof was);
    model_list(now, n, is, sizeof is);
    /* the message buffer is the sim's one mutable part for a reader (a heap object) */
    return wetdem_sim_fail((struct wetdem_sim*)sim, WETDEM_ERR_INVALID,
                           "%s: the models of the many-particle run changed since it started "
                           "(%s; now %s): its pair histories and energy budget are kept per "
                           "model, so enable those again, or call wetdem_sim_set_many() to "
                           "start the mode afresh from the current state",
                           what, was, is);
}

int wetdem_sim_many_check_run(const struct wetdem_sim* sim, const char* what)
{
    const struct wetdem_many* m = sim->many;
    if (!m || !m->started) /* (the message buffer: as wetdem_sim_many_check_models) */
        return wetdem_sim_fail((struct wetdem_sim*)sim, WETDEM_ERR_INVALID, "%s: %s", what,
                               !m ? "the simulation is not in the many-particle mode"
                                  : "the many-particle run has not started");
    return wetdem_sim_many_check_models(sim, what);
}

int wetdem_sim_many_check_report(const struct wetdem_sim* sim, const char* what)
{
    int st = wetdem_sim_many_check_models(sim, what);
    if (st != WETDEM_OK || !sim->many || !sim->many->started)
        return st;
    char why[256];
    for (size_t k = 0; k < sim->n_particles; k++)
        if (!wetdem_sim_particle_valid(sim, &sim->particles[k], why, sizeof why))
            /* (the message buffer: as wetdem_sim_many_check_models) */
            return wetdem_sim_fail((struct wetdem_sim*)sim, WETDEM_ERR_INVALID,
                                   "%s: particle %zu: %s", what, k, why);
    return WETDEM_OK;
}

/* First call of a many run: step size, pair list, forces and the energy at t0. */
static int start(struct wetdem_sim* sim)
{
    struct wetdem_many* m = sim->many;
    int st = choose_dt(sim, &m->dt);
    if (st != WETDEM_OK)
        return st;
    m->t0 = sim->engine.time;
    m->step = 0;
    /* the first periodic checkpoint at step checkpoint_every (a restored run sets its own) */
    m->next_checkpoint_step = m->set.checkpoint_every;
    st = forces_and_work(sim, WETDEM_MANY_END_NONE);
    if (st != WETDEM_OK)
        return st;
    m->started = true;
    wetdem_sim_many_keep_models(sim);
    /* the forces at t0 give the first half kick only: half their dt P (trapezoid rule) */
    struct wetdem_many_energy first = m->energy;
    memset(&m->energy, 0, sizeof m->energy);
    for (size_t k = 0; k < WETDEM_MAX_MODELS; k++) {
        m->energy.work_pair[k] = 0.5 * first.last_pair[k];
        m->energy.work_wall[k] = 0.5 * first.last_wall[k];
        m->energy.last_pair[k] = first.last_pair[k];
        m->energy.last_wall[k] = first.last_wall[k];
    }
    wetdem_sim_many_energies(sim, &m->energy.k0, &m->energy.u0, &m->energy.el0);
    return timed_outputs(sim, false, false);
}

/* The lowest index of a free particle whose half-step velocity v' of the latest drift has a
 * |v'|^2 that is not finite (after_drift found one; a fixed particle does not drift). */
static size_t first_diverged_drift(const struct wetdem_sim* sim)
{
    const struct wetdem_many* m = sim->many;
    for (size_t k = 0; k < sim->n_particles; k++)
        if (!m->fixed[k] && !(vec3_dot(m->vwh[k][0], m->vwh[k][0]) <= DBL_MAX))
            return k;
    return 0;
}

/* Stops the run at particle k, the first whose motion is not finite: with `drift`, its
 * half-step velocity v' (the largest |v'|^2 of the drift overflowed), else its position, or
 * |v|^2 + |w|^2 (its kinetic energy would overflow). Returns WETDEM_ERR_NUMERIC with a message
 * naming the step, the time and the particle; no output of that step is written, and the
 * particle records hold the state reached. */
static int diverged(struct wetdem_sim* sim, size_t k, bool drift)
{
    const struct wetdem_many* m = sim->many;
    struct wetdem_vec3 v = drift ? m->vwh[k][0] : m->vw[k][0], w = m->vw[k][1];
    double ratio = m->dt / m->contact_time;
    char hint[200];
    if (ratio > WETDEM_MANY_CONTACT_FRACTION_MAX)
        snprintf(hint, sizeof hint,
                 "the step dt = %g s is %.3g x the contact time %g s, above %g x: lower it", m->dt,
                 ratio, m->contact_time, WETDEM_MANY_CONTACT_FRACTION_MAX);
    else
        snprintf(hint, sizeof hint, "lower the step dt = %g s, or check the forces", m->dt);
    return wetdem_sim_fail(sim, WETDEM_ERR_NUMERIC,
                           "many: the motion diverged in step %llu (t = %.9g s): particle %zu "
                           "has a %s that is not finite (x = (%g, %g, %g) m, v = (%g, %g, %g) "
                           "m/s, w = (%g, %g, %g) rad/s); %s",
                           (unsigned long long)m->step, sim->engine.time, k,
                           drift ? "velocity" : "position, velocity or spin", m->xr[k].x,
                           m->xr[k].y, m->xr[k].z, v.x, v.y, v.z, w.x, w.y, w.z, hint);
}

static int one_step(struct wetdem_sim* sim, bool defer);

/* Stop flag, progress callback. Returns WETDEM_EVENT to stop (checkpoint written). */
static int poll_stop(struct wetdem_sim* sim, unsigned long long done, unsigned long long total,
                     double t_start)
{
    struct wetdem_many* m = sim->many;
    bool stop = m->set.stop_flag && *m->set.stop_flag;
    unsigned long long every = m->set.progress_every ? m->set.progress_every : 1000;
    if (!stop && m->set.progress && (done % every == 0 || done == total))
        stop = m->set.progress(done, total, wall_seconds() - t_start, m->set.progress_ctx) != 0;
    if (!stop)
        return WETDEM_OK;
    if (m->drifted) { /* raised during a pass that began the next step: that step finished */
        int st = one_step(sim, false);
        if (st != WETDEM_OK)
            return st;
    }
    finish_kick(sim); /* a stop flag raised during a deferred step */
    size_t bad = sync_records(sim);
    if (bad != SIZE_MAX) /* (no checkpoint of a state no run can continue) */
        return diverged(sim, bad, false);
    if (m->checkpoint_path) {
        int st = wetdem_sim_write_checkpoint(sim, m->checkpoint_path);
        if (st != WETDEM_OK)
            return st;
    }
    wetdem_sim_fail(sim, WETDEM_EVENT, "stopped at t = %.9g s (step %llu)%s%s", sim->engine.time,
                    (unsigned long long)m->step, m->checkpoint_path ? "; checkpoint " : "",
                    m->checkpoint_path ? m->checkpoint_path : "");
    return WETDEM_EVENT;
}

/* Whether anything reads the state after step `step` (the k-th of `total` in this call): an
 * output, an observer, the progress callback, the end of the call. */
static bool state_read_after(const struct wetdem_sim* sim, uint64_t step, unsigned long long k,
                             unsigned long long total)
{
    const struct wetdem_many* m = sim->many;
    const struct wetdem_many_settings* s = &m->set;
    unsigned long long every = s->progress_every ? s->progress_every : 1000;
    return k >= total || sim->engine.observer || (s->progress && (k % every == 0 || k == total)) ||
           (m->output_prefix && s->vtk_every && step >= m->next_vtk_step) ||
           (m->output_prefix && s->csv_every && step >= m->next_csv_step) ||
           (m->checkpoint_path && s->checkpoint_every && step >= m->next_checkpoint_step);
}

/* The largest |v'|^2 of the drift the latest force pass applied (drift_v2 of its blocks; max
 * is exact, so the same for any blocks). */
static double drift_v2_max(const struct wetdem_many* m)
{
    double v2 = 0;
    for (size_t b = 0; b < m->n_blocks; b++)
        v2 = m->drift_v2[b] > v2 ? m->drift_v2[b] : v2;
    return v2;
}

/* One step. When nothing reads the state before the next step (`defer`), the force pass
 * begins the next step: each block, once the forces on its particles are complete, applies
 * the closing half kick, the next half kick and the drift to them (WETDEM_MANY_END_STEP), the
 * arithmetic of the kick-drift pass, so that the next step starts at its force pass. On two
 * threads this spares a parallel region and its wait per step, and each thread updates the
 * particles whose forces it summed. Not when a stop is already asked for, so that a stop
 * raised before a step ends the run at that step; one raised during the pass ends it after the
 * next (poll_stop). */
static int one_step(struct wetdem_sim* sim, bool defer)
{
    struct wetdem_many* m = sim->many;
    double t0 = wall_seconds();
    if (m->drifted) { /* begun by the previous pass */
        m->drifted = false;
        after_drift(sim, m->dt, drift_v2_max(m));
    } else
        kick_drift(sim);
    m->seconds_kick += wall_seconds() - t0;
    m->step++;
    sim->engine.time = m->t0 + (double)m->step * m->dt; /* no accumulated round-off */
    sim->engine.t_committed = sim->engine.time;
    if (!(m->v2_drift <= DBL_MAX)) /* the largest |v'|^2 of the drift: one test a step */
        return diverged(sim, first_diverged_drift(sim), true);
    m->v2_seen = m->v2_drift > m->v2_seen ? m->v2_drift : m->v2_seen;
    bool step = defer && !m->no_drift_in_pass && !(m->set.stop_flag && *m->set.stop_flag);
    int st = forces_and_work(sim, !defer ? WETDEM_MANY_END_KICK
                                  : step ? WETDEM_MANY_END_STEP
                                         : WETDEM_MANY_END_NONE);
    m->drifted = step;
    if (m->stop_during_step && m->step == m->stop_during_step && m->set.stop_flag)
        *m->set.stop_flag = 1; /* (tests) */
    if (st != WETDEM_OK)
        return st;
    m->kick_pending = defer && !m->drifted;
    size_t bad = defer ? SIZE_MAX : sync_records(sim); /* the state is read after this step */
    if (bad != SIZE_MAX)
        return diverged(sim, bad, false);
    sim->engine.stats.steps++;
    return timed_outputs(sim, false, true);
}

/* Largest component of a wall's unit normal along a periodic axis: a wall there is not the
 * same at the periodic images, so a sphere that crosses the periodic face jumps by the box
 * length times that component relative to the wall (into it, or off it). 1e-12 admits normals
 * whose zero components carry the round-off of a rotation (cos(pi/2) = 6e-17); the jump is
 * then below 1e-12 of the box length, under the margins of the gap tests. */
#define WALL_PERIODIC_NORMAL_MAX 1e-12

/* Refuses a wall that is not parallel to every periodic axis (walls may be added between
 * calls, so every call checks). */
static int check_walls(struct wetdem_sim* sim)
{
    const struct wetdem_many_settings* s = &sim->many->set;
    for (size_t w = 0; w < sim->n_walls; w++) {
        struct wetdem_vec3 n = sim->walls[w].normal;
        double c[3] = {n.x, n.y, n.z};
        for (int k = 0; k < 3; k++)
            if (s->periodic[k] && !(fabs(c[k]) <= WALL_PERIODIC_NORMAL_MAX))
                return wetdem_sim_fail(
                    sim, WETDEM_ERR_INVALID,
                    "wall %zu: its unit normal (%g, %g, %g) has the component %g along the "
                    "periodic axis %c, where |normal.%c| <= %g is needed: a wall must be parallel "
                    "to every periodic axis, or a sphere crossing the periodic face jumps into "
                    "the wall or off it",
                    w, n.x, n.y, n.z, c[k], "xyz"[k], "xyz"[k], WALL_PERIODIC_NORMAL_MAX);
    }
    return WETDEM_OK;
}

int wetdem_sim_many_integrate(struct wetdem_sim* sim, double t_end)
{
    struct wetdem_many* m = sim->many;
    int wall_st = check_walls(sim);
    if (wall_st == WETDEM_OK)
        wall_st = wetdem_sim_many_check_models(sim, "integrate");
    if (wall_st != WETDEM_OK)
        return wall_st;
    m->kernel_ready = false;  /* materials, models or parameters may have changed */
    m->disp_bound = INFINITY; /* particles may have been moved: measure at the first step */
    m->skip_ready = false;    /* and test every candidate at the first force pass */
    int st = m->started ? wetdem_sim_many_prepare(sim) : start(sim);
    if (st != WETDEM_OK)
        return st;
    double span = (t_end - sim->engine.time) / m->dt;
    if (span > WETDEM_MANY_MAX_STEPS) /* also keeps the step count below 2^64 */
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "reaching t_end = %g s from t = %g s takes %.3g steps of dt = %g s, "
                               "more than %g: raise dt or lower t_end",
                               t_end, sim->engine.time, span, m->dt, WETDEM_MANY_MAX_STEPS);
    double max_steps = 1e8;
    wetdem_sim_param(sim, "verlet.max_steps", &max_steps);
    if (span > max_steps)
        return wetdem_sim_fail(sim, WETDEM_ERR_MAX_STEPS,
                               "many: reaching t_end = %g s from t = %g s takes %.3g steps of "
                               "dt = %g s, more than verlet.max_steps = %.3g%s%s: raise "
                               "max_steps, lower t_end or integrate in shorter calls",
                               t_end, sim->engine.time, span, m->dt, max_steps,
                               m->dt_origin[0] ? "; " : "", m->dt_origin);
    if (sim->engine.observer && !(sim->engine.last_observed == sim->engine.time))
        st = wetdem_sim_observe(sim);
    unsigned long long total = span > 1e-9 ? (unsigned long long)ceil(span - 1e-9) : 0;
    double t_start = wall_seconds();
    for (unsigned long long k = 1; st == WETDEM_OK && k <= total; k++) {
        st = one_step(sim, !state_read_after(sim, m->step + 1, k, total));
        if (st == WETDEM_OK)
            st = poll_stop(sim, k, total, t_start);
    }
    sync_records(sim); /* done after the last step; here for a step that failed */
    if (st == WETDEM_OK)
        st = timed_outputs(sim, true, false);
    if (st >= 0 && sim->engine.observer && !(sim->engine.last_observed == sim->engine.time)) {
        int so = wetdem_sim_observe(sim);
        st = so != WETDEM_OK ? so : st;
    }
    return st;
}

int wetdem_sim_energy_budget(const struct wetdem_sim* sim, struct wetdem_energy_budget* b)
{
    memset(b, 0, sizeof *b);
    const struct wetdem_many* m = sim->many;
    if (!m || !m->started || !m->set.energy_budget) /* (without it, no work was summed) */
        /* the message buffer is the sim's one mutable part for a reader (a heap object) */
        return wetdem_sim_fail((struct wetdem_sim*)sim, WETDEM_ERR_INVALID, "energy_budget: %s",
                               !m            ? "the simulation is not in the many-particle mode"
                               : !m->started ? "the many-particle run has not started"
                                             : "the run's energy_budget setting is off");
    int st = wetdem_sim_many_check_report(sim, "energy_budget");
    if (st != WETDEM_OK)
        return st;
    wetdem_sim_many_energies(sim, &b->kinetic, &b->potential, &b->elastic);
    b->input = m->energy.k0 + m->energy.u0 + m->energy.el0;
    double work = 0;
    /* the latest forces have given their first half kick only (trapezoid rule, many.h) */
    for (size_t k = 0; k < sim->n_models && k < WETDEM_ENERGY_MAX_MODELS; k++) {
        b->work_pair[k] = m->energy.work_pair[k] - 0.5 * m->energy.last_pair[k];
        b->work_wall[k] = m->energy.work_wall[k] - 0.5 * m->energy.last_wall[k];
        work += b->work_pair[k] + b->work_wall[k];
    }
    b->n_models = sim->n_models;
    b->work_total = work;
    b->dissipated = b->input - (b->kinetic + b->potential + b->elastic);
    b->balance_error = (b->kinetic + b->potential) - (m->energy.k0 + m->energy.u0) - work;
    return WETDEM_OK;
}

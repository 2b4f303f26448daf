/*
 * sim_many_force.c — the force evaluation of the many-particle mode (docs/many.md,
 * docs/performance.md): candidate pairs from the cell list, a cheap gap test on positions,
 * mixed properties from a per-material-pair table, a lean kernel (and a fused one) for the
 * common model sets, and a block-parallel pass whose result does not depend on the thread
 * count. Prefix: wetdem_sim_.
 *
 * Per step, for the candidate list (celllist.h) of pairs (i < j) sorted by (i, j), with the
 * particles split into contiguous blocks (one per thread, of about equal estimated work):
 *   1. cross pairs (an equal share of them per thread): the pairs whose j lies in a later
 *      block than i are evaluated and their results stored; a barrier follows.
 *   2. block pass (parallel over blocks): every particle k of the block starts its sum with its
 *      wall forces (wall order) and the reactions -F of the cross pairs (i, k) from earlier
 *      blocks (increasing i). A flat loop gap-tests every in-block candidate,
 *      |x_i - x_j|^2 > (R_i + R_j + r_ab)^2 (1 + 1e-12) (r_ab the model range of the material
 *      pair, or the start-up reach for model sets without a fused kernel; the bound is kept
 *      per candidate from the list build), and lists those within range or with flags; a
 *      candidate it rejected is not tested again until the skip clock (many.h: the sum of the
 *      steps' displacement bounds) shows it may have come within reach. Then,
 *      for i in index order: its listed pairs (the exact test h > range decides), each
 *      reaction -F added to j at once; its cross pairs from step 1; the sum S_i of its own
 *      pairs in j order added last (a particle with no pairs adds nothing: +0 would change no
 *      sum); the closing half kick of velocity Verlet (sim_many.c). When nothing reads the
 *      state before the next step, the block then applies to its particles, whose forces are
 *      complete, the closing half kick, the next step's half kick and its drift instead
 *      (sim_many.c one_step, many.h WETDEM_MANY_END_STEP).
 * So particle k always sums walls, then -F of every pair (i, k) in increasing i, then S_k: an
 * order set by particle indices only, whatever the blocks, so states are bit-identical for any
 * number of threads and, because pairs out of range add nothing, for any time at which the
 * list was rebuilt (checkpoint + restart).
 *
 * The first pass of a run gives the forces at t0 of the state as given, as the two-body engine
 * evaluates its start (sim_integrate.c begin_run, nothing committed): the tangential springs
 * not advanced (many.h advance = 0) and the histories it writes put back after it, so that a
 * contact sliding at t0 starts its first step from its spring, not from the one mindlin.h
 * sets at the Coulomb limit (docs/derivations/contact.md Sec. 2, step 4).
 *
 * Mixed properties (contact.c, SPEC §2): 1/E* = (1-nu_a^2)/E_a + (1-nu_b^2)/E_b, 1/G* =
 * (2-nu_a)/G_a + (2-nu_b)/G_b, means of e, mu, sigma, sum of films; computed once per
 * material pair with the same code (wetdem_contact_from_particles on probe particles) so the
 * values are bit-identical to a contact built per pair.
 *
 * Fused kernel: when every enabled force model is one of hertz, mindlin, sb and capillary (any
 * subset, any order), a switch over the models replaces the calls through the model table. It
 * calls the same kernels (wetdem_force_hertz_elastic, wetdem_force_hertz_damping_with,
 * hertz_total (models.h), wetdem_force_mindlin_update_with, wetdem_pair_force_add_tangential,
 * thin_film_eval_gap), the damping coefficients of the restitution (the exact-table lookup,
 * log e) computed once per material pair in the table by the force files' own functions, and
 * writes the static-bridge force 6 pi mu a^2 v_n/h [1 - h/delta]^2
 * (Punch 2023 Eq. 7, corrected bracket; force_sb.c) and the capillary suction -8 pi a sigma
 * (Punch 2023 Eq. 15; force_capillary.c) with the same operations in the same order, and sums
 * the models as wetdem_sim_eval_contact does; the elastic Hertz force, which hertz and mindlin
 * both need, is computed once. tests/test_many_force.c checks the forces and histories are
 * bit-identical to the generic path. Without per-model output each model adds its terms
 * straight into the sum instead of into a zeroed record that is then added field by field:
 * the same bits, because the sum starts at +0 and so is never -0 (x + (+0) = x and
 * x + (0 + y) = x + y for every x other than -0), so the skipped additions of zero fields
 * and the dropped 0 + y change nothing. The range of these models is the film thickness delta_ab
 * (0 for the contact models), a property of the material pair. hooke is not among them: with
 * hooke (a linear normal law, whose k mindlin beside it reads as c->linear_stiffness) every
 * pair takes the generic path, wetdem_sim_eval_contact, which fills that field in; the fused,
 * lean and four-at-a-time kernels compute mindlin's Hertzian form only.
 *
 * Lean kernel: for the same model sets (with sb, only with a constant h_min), the force is
 * computed straight from the two particles (or particle and wall), without a contact record
 * or the switch, by the same definitions (models.h: Hertz stiffness, elastic and damping
 * parts; mindlin.h: the tangential spring) in the same order, so it is bit-identical to the
 * fused kernel and the generic path (tests/test_many_force.c). Pairs apart (gap >= 0, liquid
 * bridges) take a short path with the film terms only (lean_apart). With an energy budget it
 * (and four pairs at a time, many_bulk.h) also gives each model's terms (struct lean_terms),
 * whose work equals that of the fused kernel's per-model records bit for bit (add_lean_work).
 */
#include <omp.h>
#include <stdlib.h>
#include <string.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "many.h"
#include "mindlin.h"
#include "models.h"
#include "thin_film.h"
#include "contact.h"
#include "vec3.h"

/* Relative margin of the cheap gap test: its squared-distance bound must never reject a pair
 * that the exact test (gap = |d| - R_i - R_j <= range) accepts; both are within a few ulps. */
#define PREFILTER_MARGIN 1e-12

enum fused_kind { FUSED_NONE = 0, FUSED_HERTZ, FUSED_MINDLIN, FUSED_SB, FUSED_CAPILLARY };

/* ---- set-up: material-pair table and kernel choice ---- */

/* Value of the numeric parameter `name` of slot s (0 when absent). */
static double slot_param(const struct wetdem_model_slot* s, const char* name)
{
    const struct wetdem_param_desc* d = wetdem_param_find(s->model->params, name);
    if (!d || !s->params)
        return 0.0;
    double v;
    memcpy(&v, (const char*)s->params + d->offset, sizeof v);
    return v;
}

static enum fused_kind fused_kind_of(const struct wetdem_model* model)
{
    if (model == &wetdem_force_hertz)
        return FUSED_HERTZ;
    if (model == &wetdem_force_mindlin)
        return FUSED_MINDLIN;
    if (model == &wetdem_force_sb)
        return FUSED_SB;
    if (model == &wetdem_force_capillary)
        return FUSED_CAPILLARY;
    return FUSED_NONE;
}

/* Mixed properties of materials a and b, from contact.c itself. */
static void mix_pair(const struct wetdem_sim* sim, int a, int b, struct wetdem_many_mix* x)
{
    struct wetdem_particle p = {.radius = 1, .mass = 1, .material = a};
    struct wetdem_particle q = {.pos = {0, 0, 3}, .radius = 1, .mass = 1, .material = b};
    struct wetdem_contact c;
    wetdem_contact_from_particles(&c, &p, &sim->materials[a], &q, &sim->materials[b], &sim->fluid);
    *x = (struct wetdem_many_mix){.e_star = c.e_star,
                                  .g_star = c.g_star,
                                  .restitution = c.restitution,
                                  .friction_dry = c.friction_dry,
                                  .friction_lub = c.friction_lub,
                                  .roughness = c.roughness,
                                  .film = c.film,
                                  .viscosity = c.viscosity,
                                  .surface_tension = c.surface_tension};
    bool valid = c.restitution > 0.0 && c.restitution <= 1.0;
    x->hertz_damping[0] = wetdem_force_hertz_damping_coefficient(c.restitution, 0);
    x->hertz_damping[1] = wetdem_force_hertz_damping_coefficient(c.restitution, 1);
    x->mindlin_damping = valid ? wetdem_force_mindlin_damping_factor(c.restitution) : NAN;
}

/* The lean kernel's plan: on for fused model sets whose restitutions are all valid (else the
 * fused kernel runs and reports the bad one) and, with sb, a constant h_min (minsep "fixed").
 * Off with a min-separation record (many.h, record): the lean kernel does not evaluate the
 * min-separation model, whose record the engine keeps beyond the force range. */
static void plan_lean(struct wetdem_sim* sim)
{
    struct wetdem_many* m = sim->many;
    struct wetdem_many_lean* L = &m->lean;
    *L = (struct wetdem_many_lean){.on = m->fused && !m->record, .hertz_form = -1};
    bool contact_models = false;
    unsigned seen = 0;
    for (size_t k = 0; k < sim->n_models; k++) {
        L->on = L->on && !(seen >> m->kind[k] & 1u); /* a model twice: the fused kernel */
        seen |= 1u << m->kind[k];
        switch (m->kind[k]) {
        case FUSED_HERTZ:
            L->hertz_form = (int)m->kind_opt[k];
            L->normal[L->n_normal++] = 0;
            contact_models = true;
            break;
        case FUSED_MINDLIN:
            L->mindlin = true;
            L->mindlin_lub = m->kind_opt[k] != 0;
            L->mindlin_off = sim->models[k].history_offset;
            contact_models = true;
            break;
        case FUSED_SB:
            L->sb = true;
            L->sb_below = m->kind_opt[k];
            L->normal[L->n_normal++] = 1;
            break;
        case FUSED_CAPILLARY:
            L->capillary = true;
            L->normal[L->n_normal++] = 2;
            break;
        default: L->on = false;
        }
    }
    if (L->sb) { /* h_min must not depend on the pair */
        struct wetdem_contact probe = {0};
        double scratch[1] = {0.0};
        L->on = L->on && sim->minsep.model == &wetdem_minsep_fixed;
        if (L->on)
            L->h_min = sim->minsep.model->min_separation(sim->minsep.params, &probe, scratch);
    }
    for (size_t k = 0; L->on && k < (size_t)m->n_mix_materials * (size_t)m->n_mix_materials; k++) {
        struct wetdem_many_mix* x = &m->mix[k];
        bool valid = x->restitution > 0.0 && x->restitution <= 1.0;
        L->on = (valid || !contact_models) && x->range <= m->reach;
        x->film_h_min = thin_film_h_min(L->h_min, x->film);
    }
}

int wetdem_sim_many_setup_kernel(struct wetdem_sim* sim)
{
    struct wetdem_many* m = sim->many;
    size_t nm = sim->n_materials > 0 ? (size_t)sim->n_materials : 1;
    if (nm * nm > m->mix_cap) {
        free(m->mix);
        m->mix = malloc(nm * nm * sizeof *m->mix);
        m->mix_cap = m->mix ? nm * nm : 0;
        if (!m->mix)
            return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory");
    }
    bool fused = !m->generic_only, films = false;
    for (size_t k = 0; k < sim->n_models; k++) {
        const struct wetdem_model_slot* s = &sim->models[k];
        m->kind[k] = (unsigned char)fused_kind_of(s->model);
        films = films || m->kind[k] == FUSED_SB || m->kind[k] == FUSED_CAPILLARY;
        m->kind_opt[k] = m->kind[k] == FUSED_HERTZ     ? slot_param(s, "damping")
                         : m->kind[k] == FUSED_MINDLIN ? slot_param(s, "friction")
                         : m->kind[k] == FUSED_SB      ? slot_param(s, "below_hmin")
                                                       : 0.0;
        fused = fused && m->kind[k] != FUSED_NONE;
    }
    m->n_mix_materials = (int)nm;
    for (int a = 0; a < sim->n_materials; a++)
        for (int b = 0; b < sim->n_materials; b++) {
            struct wetdem_many_mix* x = &m->mix[(size_t)a * nm + (size_t)b];
            mix_pair(sim, a, b, x);
            /* the range of the fused models is the film thickness with a film model (sb,
               capillary), else 0 (hertz and mindlin act in contact only): a material-pair
               value */
            x->range = fused ? (films && x->film > 0.0 ? x->film : 0.0) : m->reach;
        }
    m->fused = fused;
    m->pair_consts_ready = false; /* the ranges, radii and masses may have changed */
    plan_lean(sim);
    m->periodic_any = m->cl.box.periodic[0] || m->cl.box.periodic[1] || m->cl.box.periodic[2];
    return WETDEM_OK;
}

/* ---- contacts ---- */

static void copy_mix(struct wetdem_contact* c, const struct wetdem_many_mix* x)
{
    c->e_star = x->e_star;
    c->g_star = x->g_star;
    c->restitution = x->restitution;
    c->friction_dry = x->friction_dry;
    c->friction_lub = x->friction_lub;
    c->roughness = x->roughness;
    c->film = x->film;
    c->viscosity = x->viscosity;
    c->surface_tension = x->surface_tension;
    c->h_min = 0.0;
    c->linear_stiffness = 0.0;
    c->dt = 0.0;
}

/* Contact of a with b where d = x_a - x_b (minimum image): the geometry of
 * wetdem_contact_from_particles (contact.h), mixed properties from the table. */
static void pair_contact_from(const struct wetdem_particle* a, const struct wetdem_particle* b,
                              struct wetdem_vec3 d, const struct wetdem_many_mix* x,
                              struct wetdem_contact* c)
{
    contact_pair_geometry(c, a, b, d);
    copy_mix(c, x);
}

/* Contact of particle a with a plane wall (wetdem_contact_with_wall, table properties). */
static void wall_contact_from(const struct wetdem_particle* a, const struct wetdem_wall* w,
                              const struct wetdem_many_mix* x, struct wetdem_contact* c)
{
    contact_wall_geometry(c, a, w->point, w->normal);
    copy_mix(c, x);
}

const struct wetdem_many_mix* wetdem_sim_many_mix(const struct wetdem_sim* sim, int a, int b)
{
    const struct wetdem_many* m = sim->many;
    return &m->mix[(size_t)a * (size_t)m->n_mix_materials + (size_t)b];
}

/* The mixed properties of materials a and b: the table's, or for a material added since the
 * table was made (at the latest call: a report between calls reads the particles as edited
 * since, wetdem_sim_many_check_report) mixed here as the next call will, with the fluid of
 * the table. */
static const struct wetdem_many_mix* mix_of(const struct wetdem_sim* sim, int a, int b,
                                            struct wetdem_many_mix* scratch)
{
    const struct wetdem_many* m = sim->many;
    if (a < m->n_mix_materials && b < m->n_mix_materials)
        return wetdem_sim_many_mix(sim, a, b);
    mix_pair(sim, a, b, scratch);
    scratch->viscosity = m->mix[0].viscosity;
    scratch->surface_tension = m->mix[0].surface_tension;
    return scratch;
}

void wetdem_sim_many_contact(const struct wetdem_sim* sim, size_t i, size_t j, bool is_wall,
                             struct wetdem_contact* c)
{
    const struct wetdem_particle* a = &sim->particles[i];
    struct wetdem_many_mix scratch;
    if (is_wall) {
        const struct wetdem_wall* w = &sim->walls[j];
        wall_contact_from(a, w, mix_of(sim, a->material, w->material, &scratch), c);
    } else {
        const struct wetdem_particle* b = &sim->particles[j];
        struct wetdem_vec3 d = celllist_delta(&sim->many->cl.box, a->pos, b->pos);
        pair_contact_from(a, b, d, mix_of(sim, a->material, b->material, &scratch), c);
    }
    c->i = i;
    c->j = j;
}

/* ---- the fused kernel ---- */

static void add_force(struct wetdem_pair_force* out, const struct wetdem_pair_force* f)
{
    out->f_normal += f->f_normal;
    out->f_tan = vec3_add(out->f_tan, f->f_tan);
    out->torque_i = vec3_add(out->torque_i, f->torque_i);
    out->torque_j = vec3_add(out->torque_j, f->torque_j);
    out->slip += f->slip;
}

/* One model's force, as its pair() function computes it. f_el: the Hertz elastic force at
 * this overlap. Returns WETDEM_OK or WETDEM_ERR_INVALID (restitution outside (0, 1]). */
static int fused_model(int kind, double opt, const struct wetdem_contact* c,
                       const struct wetdem_many_mix* x, double f_el, double* history,
                       struct wetdem_pair_force* f)
{
    double overlap = -c->gap;
    switch (kind) {
    case FUSED_HERTZ:
        if (!(c->restitution > 0.0 && c->restitution <= 1.0))
            return WETDEM_ERR_INVALID;
        if (overlap > 0.0)
            f->f_normal +=
                hertz_total(f_el,
                            wetdem_force_hertz_damping_with(x->hertz_damping[(int)opt], c->e_star,
                                                            c->r_eff, c->m_eff, overlap, c->v_n),
                            (int)opt);
        return WETDEM_OK;
    case FUSED_MINDLIN: {
        if (!(c->restitution > 0.0 && c->restitution <= 1.0))
            return WETDEM_ERR_INVALID;
        double mu = opt == 0 ? c->friction_dry : c->friction_lub;
        /* (the slip margin as the mindlin model gives it: the generic path's bits) */
        struct wetdem_vec3 ft = wetdem_force_mindlin_update_with(
            c, overlap, f_el, mu, x->mindlin_damping, history, &f->slip);
        if (overlap > 0.0)
            wetdem_pair_force_add_tangential(f, c, ft);
        return WETDEM_OK;
    }
    case FUSED_SB: {
        double h;
        if (thin_film_eval_gap(c->gap, c->h_min, c->film, opt, &h)) {
            double bracket = 1.0 - h / c->film;
            f->f_normal +=
                6.0 * M_PI * c->viscosity * c->r_eff * c->r_eff * c->v_n / h * bracket * bracket;
        }
        return WETDEM_OK;
    }
    default: /* FUSED_CAPILLARY */
        if (c->film > 0.0 && c->gap <= c->film)
            f->f_normal -= 8.0 * M_PI * c->r_eff * c->surface_tension;
        return WETDEM_OK;
    }
}

int wetdem_sim_many_eval_fused(const struct wetdem_sim* sim, struct wetdem_contact* c,
                               const struct wetdem_many_mix* x, double* history,
                               struct wetdem_pair_force* out, struct wetdem_pair_force* per_model)
{
    const struct wetdem_many* m = sim->many;
    double scratch[1] = {0.0};
    if (!history) /* only models without history are enabled */
        history = scratch;
    *out = (struct wetdem_pair_force){0};
    c->h_min = sim->minsep.model->min_separation(sim->minsep.params, c, history);
    c->linear_stiffness = 0.0; /* (no fused model is a linear law) */
    double f_el = wetdem_force_hertz_elastic(c->e_star, c->r_eff, -c->gap);
    if (!per_model) { /* each model adds into *out at once: see the file header */
        for (size_t k = 0; k < sim->n_models; k++) {
            int st = fused_model(m->kind[k], m->kind_opt[k], c, x, f_el,
                                 history + sim->models[k].history_offset, out);
            if (st < 0)
                return st;
        }
        return WETDEM_OK;
    }
    for (size_t k = 0; k < sim->n_models; k++) {
        struct wetdem_pair_force f = {0};
        int st = fused_model(m->kind[k], m->kind_opt[k], c, x, f_el,
                             history + sim->models[k].history_offset, &f);
        if (st < 0)
            return st;
        add_force(out, &f);
        if (per_model)
            per_model[k] = f;
    }
    return WETDEM_OK;
}

/* ---- the lean kernel ---- */

/* What the lean kernel reads of a pair or particle-wall pair (as struct wetdem_contact). */
struct lean_geometry {
    struct wetdem_vec3 n;   /* unit normal, j to i */
    double gap, r_i, r_j;   /* [m]; r_j unused for walls */
    double r_eff, m_eff;    /* R* [m], m* [kg] */
    double k, damping;      /* hertz_stiffness and hertz_damping_factor of the pair */
    double v_n;             /* [m/s] */
    struct wetdem_vec3 v_t; /* [m/s], set only when mindlin is enabled */
    struct wetdem_vec3 v_s; /* [m/s], what the spring advances with (spring_velocity); as v_t */
    bool wall;
};

/* What a tangential spring advances with over a step, from the slip v_t at the predicted
 * velocities and the slip `half` at the half-step ones (struct wetdem_many vwh): v_t +
 * (half - v_t), the operations of c->v_t + c->dv_t_spring in the models (mindlin.h), so the
 * generic and fused paths agree bit for bit; v_t where the pass advances nothing (its start,
 * whose half-step velocities are not yet those of a step). Midpoint rule: docs/many.md. */
static inline struct wetdem_vec3 spring_velocity(const struct wetdem_many* m,
                                                 struct wetdem_vec3 v_t, struct wetdem_vec3 half)
{
    return m->advance > 0.0 ? vec3_add(v_t, vec3_sub(half, v_t)) : v_t;
}

/* Each model's part of a lean result, for the energy budget: the normal terms of hertz, sb
 * and capillary (+0 where a model does not act), mindlin's tangential force and torques, and
 * the unit normal. */
struct lean_terms {
    double term[3]; /* hertz, sb, capillary [N] */
    struct wetdem_vec3 f_tan, t_i, t_j, n;
};

/* The normal forces of the film models at gap `gap` [m] (R* = r_eff [m], v_n [m/s]), as
 * force_sb.c and force_capillary.c compute them, into term[1] (sb) and term[2] (capillary);
 * the terms of models that do not act are left as they are (+0). */
static inline __attribute__((always_inline)) void film_terms(const struct wetdem_many_lean* L,
                                                             const struct wetdem_many_mix* x,
                                                             double gap, double r_eff, double v_n,
                                                             double term[3])
{
    double h;
    if (L->sb && thin_film_eval_gap_at(gap, x->film_h_min, x->film, L->sb_below, &h)) {
        double bracket = 1.0 - h / x->film;
        term[1] = 6.0 * M_PI * x->viscosity * r_eff * r_eff * v_n / h * bracket * bracket;
    }
    if (L->capillary && x->film > 0.0 && gap <= x->film)
        term[2] = -(8.0 * M_PI * r_eff * x->surface_tension);
}

/* Force of pair g with mixed properties x: the operations of wetdem_sim_many_eval_fused and
 * eval_pair in the same order on the quantities the enabled models read, so force, torques,
 * history and flags are bit-identical to theirs (tests/test_many_force.c). The film terms are
 * film_terms', or film[0] and film[1] when film is not NULL; each model's part into *terms
 * when terms is not NULL. The sum of the
 * normal forces starts at +0 and adds the models in model order; a model that does not act
 * adds +0, which changes no sum that is not -0 (and a sum from +0 never is). Needs
 * g->gap <= x->range. Returns WETDEM_OK or WETDEM_ERR_NUMERIC (non-finite force). */
static inline __attribute__((always_inline)) int
lean_force(const struct wetdem_many* m, const struct lean_geometry* g,
           const struct wetdem_many_mix* x, double* hist, unsigned char* flags,
           struct wetdem_many_pair_out* o, const double* film, struct lean_terms* terms)
{
    const struct wetdem_many_lean* L = &m->lean;
    double gap = g->gap, r_eff = g->r_eff, v_n = g->v_n, overlap = -gap;
    struct wetdem_vec3 n = g->n, zero = vec3(0, 0, 0), f_tan = zero, t_i = zero, t_j = zero;
    double term[3] = {0.0, 0.0, 0.0}; /* hertz, sb, capillary */
    if (overlap > 0.0) {              /* solid contact: hertz and mindlin act */
        double m_eff = g->m_eff, k = g->k;
        double f_el = hertz_elastic_k(k, overlap);
        if (L->hertz_form >= 0)
            term[0] =
                hertz_total(f_el, hertz_damping_from(g->damping, overlap, v_n), L->hertz_form);
        if (L->mindlin) { /* wetdem_pair_force_add_tangential onto a zero record */
            struct wetdem_vec3 ft =
                mindlin_spring(n, g->v_t, g->v_s, m->advance, x->g_star, r_eff, m_eff, overlap,
                               f_el, L->mindlin_lub ? x->friction_lub : x->friction_dry,
                               x->mindlin_damping, hist + L->mindlin_off, NULL);
            f_tan = vec3_add(zero, ft);
            struct wetdem_vec3 nxf = vec3_cross(n, ft);
            t_i = vec3_axpy(zero, -g->r_i, nxf);
            if (!g->wall)
                t_j = vec3_axpy(zero, -g->r_j, nxf);
        }
    } else if (L->mindlin) { /* apart: mindlin_spring resets the spring and gives no force */
        double* spring = hist + L->mindlin_off;
        spring[0] = spring[1] = spring[2] = 0.0;
    }
    if (film) { /* the film terms of four pairs at a time (many_bulk.h), the same bits */
        term[1] = film[0];
        term[2] = film[1];
    } else
        film_terms(L, x, gap, r_eff, v_n, term);
    double f_n = 0.0;
    for (int q = 0; q < L->n_normal; q++)
        f_n += term[L->normal[q]];
    o->force = vec3_axpy(f_tan, f_n, n);
    o->torque_i = t_i;
    o->torque_j = t_j;
    if (terms)
        *terms = (struct lean_terms){{term[0], term[1], term[2]}, f_tan, t_i, t_j, n};
    *flags = WETDEM_MANY_ACTIVE | WETDEM_MANY_DIRTY |
             (gap < 0 ? WETDEM_MANY_CONTACT | WETDEM_MANY_SPRING : 0);
    if (!(isfinite(f_n) && vec3_is_finite(o->force) && vec3_is_finite(t_i) && vec3_is_finite(t_j)))
        return WETDEM_ERR_NUMERIC;
    return WETDEM_OK;
}

/* Mindlin's spring of a pair apart reset (mindlin_spring does so apart), where the pair's
 * flags `was` before this evaluation say it may be set (else it is zero already). */
static inline __attribute__((always_inline)) void
reset_spring_apart(const struct wetdem_many_lean* L, unsigned char was, double* hist)
{
    if (L->mindlin && (was & WETDEM_MANY_SPRING)) {
        double* spring = hist + L->mindlin_off;
        spring[0] = spring[1] = spring[2] = 0.0;
    }
}

/* The result of a pair apart (gap >= 0) within its range, from its normal force f_n [N] and
 * force on i (lean_apart, or four pairs at a time: many_bulk.h): the spring reset, the flags,
 * the force; the torques are zero (left unset: the callers add none, see adds_torque). The
 * force is finite when f_n is (|n| = 1). */
static inline __attribute__((always_inline)) int
apart_result(const struct wetdem_many_lean* L, double f_n, struct wetdem_vec3 force,
             unsigned char was, double* hist, unsigned char* flags, struct wetdem_many_pair_out* o)
{
    reset_spring_apart(L, was, hist);
    o->force = force;
    *flags = WETDEM_MANY_ACTIVE | WETDEM_MANY_DIRTY;
    return isfinite(f_n) ? WETDEM_OK : WETDEM_ERR_NUMERIC;
}

/* Pair apart (gap >= 0) within its range: the operations of lean_force for that case, where
 * only the film models act, along the normal n. The normal sum is lean_force's: hertz adds +0
 * there, which changes no sum from +0, and the other two commute. *terms as lean_force's. */
static inline __attribute__((always_inline)) int
lean_apart(const struct wetdem_many_lean* L, const struct wetdem_many_mix* x, struct wetdem_vec3 n,
           double gap, double r_eff, double v_n, unsigned char was, double* hist,
           unsigned char* flags, struct wetdem_many_pair_out* o, struct lean_terms* terms)
{
    double term[3] = {0.0, 0.0, 0.0};
    film_terms(L, x, gap, r_eff, v_n, term);
    if (terms)
        *terms = (struct lean_terms){.term = {0.0, term[1], term[2]}, .n = n};
    double f_n = 0.0 + term[1] + term[2];
    return apart_result(L, f_n, vec3_axpy(vec3(0, 0, 0), f_n, n), was, hist, flags, o);
}

/* The start of pair (ia, ib)'s geometry with d = x_a - x_b (minimum image), from the engine
 * state (radii in xr, velocities in vw), as pair_contact_from computes it: the gap [m], and,
 * when it is within the range of x (returns true), the unit normal and the normal velocity
 * v_n [m/s]. */
static inline __attribute__((always_inline)) bool
lean_pair_start(const struct wetdem_many* m, size_t ia, size_t ib, struct wetdem_vec3 d,
                const struct wetdem_many_mix* x, double* gap, struct wetdem_vec3* n, double* v_n)
{
    double dist = vec3_norm(d);
    *gap = dist - m->xr[ia].r - m->xr[ib].r;
    if (*gap > x->range)
        return false;
    *n = dist > 0 ? vec3_scale(d, 1.0 / dist) : vec3(1, 0, 0);
    *v_n = -vec3_dot(vec3_sub(m->vw[ia][0], m->vw[ib][0]), *n);
    return true;
}

/* Pair (ia, ib) in solid contact (gap < 0) with the start of its geometry (lean_pair_start)
 * and its constants `cache` (pair_cache): the rest of the geometry, then lean_force (with the
 * film terms `film`, or NULL, and *terms). */
static inline __attribute__((always_inline)) int
lean_contact(const struct wetdem_many* m, size_t ia, size_t ib, struct wetdem_vec3 n, double gap,
             double v_n, const struct wetdem_many_mix* x, double* hist, const double* cache,
             unsigned char* flags, struct wetdem_many_pair_out* o, const double* film,
             struct lean_terms* terms)
{
    double r_a = m->xr[ia].r, r_b = m->xr[ib].r;
    const struct wetdem_vec3 *vw_a = m->vw[ia], *vw_b = m->vw[ib]; /* velocity, spin */
    struct lean_geometry g = {.n = n,
                              .gap = gap,
                              .r_i = r_a,
                              .r_j = r_b,
                              .r_eff = cache[0],
                              .m_eff = cache[1],
                              .k = cache[2],
                              .damping = cache[3],
                              .v_n = v_n,
                              .v_t = vec3(0, 0, 0), /* read in solid contact only */
                              .wall = false};
    if (m->lean.mindlin) {
        g.v_t = contact_pair_slip(n, r_a, vw_a[0], vw_a[1], r_b, vw_b[0], vw_b[1]);
        const struct wetdem_vec3 *h_a = m->vwh[ia], *h_b = m->vwh[ib];
        g.v_s = spring_velocity(m, g.v_t,
                                contact_pair_slip(n, r_a, h_a[0], h_a[1], r_b, h_b[0], h_b[1]));
    }
    return lean_force(m, &g, x, hist, flags, o, film, terms);
}

/* Pair (ia, ib) with d = x_a - x_b (minimum image): lean_pair_start, then lean_apart or
 * lean_contact; *flags = 0 beyond the range. With bulk results (bo, not NULL), the start of
 * the geometry and the force apart are candidate k's there (the same bits). Each model's part
 * into *terms when terms is not NULL. */
static inline __attribute__((always_inline)) int
lean_pair(const struct wetdem_many* m, size_t ia, size_t ib, struct wetdem_vec3 d,
          const struct wetdem_many_mix* x, double* hist, const double* cache, unsigned char* flags,
          struct wetdem_many_pair_out* o, const struct wetdem_many_bulk_out* bo, size_t k,
          struct lean_terms* terms)
{
    unsigned char was = *flags; /* of the previous evaluation */
    double gap, v_n, film[2];
    struct wetdem_vec3 n;
    *flags = 0;
    if (bo) {
        gap = bo->gap[k];
        if (gap > x->range)
            return WETDEM_OK;
        n = vec3(bo->n[0][k], bo->n[1][k], bo->n[2][k]);
        v_n = bo->v_n[k];
        if (!(gap < 0.0)) {
            if (terms)
                *terms = (struct lean_terms){.term = {0.0, bo->f_sb[k], bo->f_cap[k]}, .n = n};
            return apart_result(&m->lean, (0.0 + bo->f_sb[k]) + bo->f_cap[k],
                                vec3(bo->force[0][k], bo->force[1][k], bo->force[2][k]), was, hist,
                                flags, o);
        }
        film[0] = bo->f_sb[k];
        film[1] = bo->f_cap[k];
    } else {
        if (!lean_pair_start(m, ia, ib, d, x, &gap, &n, &v_n))
            return WETDEM_OK;
        if (!(gap < 0.0))
            return lean_apart(&m->lean, x, n, gap, cache[0], v_n, was, hist, flags, o, terms);
    }
    return lean_contact(m, ia, ib, n, gap, v_n, x, hist, cache, flags, o, bo ? film : NULL, terms);
}

/* Particle a and plane wall w: the geometry of wall_contact_from, then lean_force (walls
 * apart are too few for a path of their own to pay); *flags = 0 beyond the range. */
static int lean_wall(const struct wetdem_many* m, size_t ia, const struct wetdem_particle* a,
                     const struct wetdem_wall* w, const struct wetdem_many_mix* x, double* hist,
                     unsigned char* flags, struct wetdem_many_pair_out* o, struct lean_terms* terms)
    __attribute__((noinline));
static int lean_wall(const struct wetdem_many* m, size_t ia, const struct wetdem_particle* a,
                     const struct wetdem_wall* w, const struct wetdem_many_mix* x, double* hist,
                     unsigned char* flags, struct wetdem_many_pair_out* o, struct lean_terms* terms)
{
    double dist = vec3_dot(vec3_sub(a->pos, w->point), w->normal);
    struct lean_geometry g = {.n = w->normal,
                              .gap = dist - a->radius,
                              .r_i = a->radius,
                              .r_eff = a->radius,
                              .m_eff = contact_effective_mass(a),
                              .wall = true};
    *flags = 0;
    if (g.gap > x->range)
        return WETDEM_OK;
    g.v_n = -vec3_dot(a->vel, g.n);
    if (g.gap < 0.0) {
        g.k = hertz_stiffness(x->e_star, g.r_eff);
        g.damping = m->lean.hertz_form >= 0
                        ? hertz_damping_factor(x->hertz_damping[m->lean.hertz_form], g.k, g.m_eff)
                        : 0.0;
    }
    if (g.gap < 0.0 && m->lean.mindlin) {
        g.v_t = contact_wall_slip(g.n, a->radius, a->vel, a->omega);
        g.v_s = spring_velocity(m, g.v_t,
                                contact_wall_slip(g.n, a->radius, m->vwh[ia][0], m->vwh[ia][1]));
    }
    return lean_force(m, &g, x, hist, flags, o, NULL, terms);
}

/* ---- the pair pass ---- */

/* Whether the result of a particle pair with flags fl has torques to add (`lean`: the lean
 * kernel made it): lean_apart leaves them unset, as zero, for pairs apart; adding a zero
 * would change no sum (every sum starts from +0, and a sum from +0 is never -0). */
static bool adds_torque(bool lean, unsigned char fl)
{
    return !lean || (fl & WETDEM_MANY_CONTACT);
}

/* First failing pair (lowest index) of a parallel loop, for a deterministic message. */
struct failure {
    size_t index;
    int status;
    bool is_wall;
    double gap, range;
};

static void note_failure(struct failure* fail, size_t index, int st, bool is_wall,
                         const struct wetdem_contact* c, double range)
{
#pragma omp critical
    if (fail->status == WETDEM_OK || index < fail->index)
        *fail = (struct failure){index, st, is_wall, c->gap, range};
}

static int report_failure(struct wetdem_sim* sim, const struct failure* f)
{
    struct wetdem_many* m = sim->many;
    size_t i = f->is_wall ? f->index / sim->n_walls : m->cl.pairs[f->index].i;
    size_t j = f->is_wall ? f->index % sim->n_walls : m->cl.pairs[f->index].j;
    const char* what = f->is_wall ? "wall " : "";
    if (f->status == WETDEM_ERR_INVALID && m->record) { /* eval_pair's test of the record */
        struct wetdem_contact c;
        wetdem_sim_many_contact(sim, i, j, f->is_wall, &c);
        double record = wetdem_sim_record_range(sim, &c);
        double reach = f->is_wall ? m->wall_reach : m->cl.reach;
        if (record > reach)
            return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                                   "pair (%zu, %s%zu): record range %.6g m of min-separation "
                                   "model '%s' exceeds the neighbour reach %.6g m bounded at "
                                   "start-up",
                                   i, what, j, record, sim->minsep.model->name, reach);
    }
    if (f->status == WETDEM_ERR_INVALID && f->range > m->reach)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "pair (%zu, %s%zu): interaction range %.6g m exceeds the "
                               "neighbour reach %.6g m bounded at start-up",
                               i, what, j, f->range, m->reach);
    return wetdem_sim_fail(sim, f->status, "pair (%zu, %s%zu) at t = %.9g s, gap %.6g m: %s", i,
                           what, j, sim->engine.time, f->gap,
                           f->status == WETDEM_ERR_NUMERIC ? "non-finite force"
                                                           : wetdem_status_name(f->status));
}

/* The work accumulators (n_models doubles) of entry `index` of the pass's per-particle or
 * per-cross-pair work `base` (many.h; collect_pass_work), or NULL where base is (no energy
 * budget). */
static inline double* work_slot(double* base, size_t n_models, size_t index)
{
    return base ? base + index * n_models : NULL;
}

/* Adds dt x the power of each model's force on pair (i, j) (particle i and a wall when
 * `wall`; unit normal n, j to i) to work[model], from the models' records per_model[0..
 * n_models). */
static void add_model_work(const struct wetdem_many* m, size_t i, size_t j, bool wall,
                           struct wetdem_vec3 n, const struct wetdem_pair_force* per_model,
                           size_t n_models, double* work)
{
    struct wetdem_vec3 dv = m->vw[i][0], wi = m->vw[i][1], wj = vec3(0, 0, 0);
    if (!wall) {
        dv = vec3_sub(dv, m->vw[j][0]);
        wj = m->vw[j][1];
    }
    for (size_t k = 0; k < n_models; k++) {
        const struct wetdem_pair_force* f = &per_model[k];
        struct wetdem_vec3 fi = vec3_axpy(f->f_tan, f->f_normal, n);
        double p =
            vec3_dot(fi, dv) + vec3_dot(f->torque_i, wi) + (wall ? 0.0 : vec3_dot(f->torque_j, wj));
        work[k] += m->dt * p;
    }
}

/* The work of a lean result with terms t (lean_force): what add_model_work gives for the
 * records the fused kernel makes (fused_model: from zero, a normal model adds its term F,
 * mindlin its tangential force and torques), without them: such a record's force on i is
 * 0 + F n (axpy from zero), which is F n but for the sign of a zero component, and its zero
 * torques add +-0 to the power; neither changes a power that is not zero, and a zero power
 * changes no work sum (which starts at +0 and so is never -0). So the sums are the fused
 * kernel's bit for bit (tests/test_many_force.c compares whole runs' budgets), and a model that
 * does not act (its terms +0: mindlin and hertz apart) needs no test: it adds a zero power. */
static inline __attribute__((always_inline)) void add_lean_work(const struct wetdem_sim* sim,
                                                                size_t i, size_t j, bool wall,
                                                                const struct lean_terms* t,
                                                                double* work)
{
    const struct wetdem_many* m = sim->many;
    struct wetdem_vec3 dv = m->vw[i][0];
    if (!wall)
        dv = vec3_sub(dv, m->vw[j][0]);
    for (size_t k = 0; k < sim->n_models; k++) {
        double p;
        if (m->kind[k] == FUSED_MINDLIN) {
            p = vec3_dot(t->f_tan, dv) + vec3_dot(t->t_i, m->vw[i][1]);
            if (!wall)
                p += vec3_dot(t->t_j, m->vw[j][1]);
        } else {
            double f = t->term[m->kind[k] == FUSED_HERTZ ? 0 : m->kind[k] == FUSED_SB ? 1 : 2];
            p = vec3_dot(vec3_scale(t->n, f), dv);
        }
        work[k] += m->dt * p;
    }
}

/* Range of contact c: the table value for the fused models, else asked of every model. */
static double contact_range(const struct wetdem_sim* sim, const struct wetdem_contact* c,
                            const struct wetdem_many_mix* x)
{
    return sim->many->fused ? x->range : wetdem_sim_contact_range(sim, c);
}

/* Pair or particle-wall pair of contact c beyond its force range, with a min-separation record
 * (many.h, record): its history as wetdem_sim_history_beyond_range leaves it, and *flags
 * WETDEM_MANY_DIRTY while the record lives (not active: no force), else 0. Returns
 * WETDEM_ERR_INVALID when the record range exceeds the reach of the lists (report_failure
 * says so). Reads of c what the min-separation model reads: gap, R*, v_n, mixed properties. */
static int record_beyond_range(const struct wetdem_sim* sim, struct wetdem_contact* c, double* hist,
                               unsigned char* flags)
{
    const struct wetdem_many* m = sim->many;
    double record = wetdem_sim_record_range(sim, c);
    *flags = 0;
    if (record > (c->is_wall ? m->wall_reach : m->cl.reach))
        return WETDEM_ERR_INVALID;
    if (wetdem_sim_history_beyond_range(sim, c, record, hist))
        *flags = WETDEM_MANY_DIRTY;
    return WETDEM_OK;
}

/* Evaluates contact c (materials' mixed properties x, range `range`) with history hist, advanced in place (committed every
 * step). Returns the status; *out gets force and torques (when active), *flags the flags. */
static int eval_pair(const struct wetdem_sim* sim, struct wetdem_contact* c,
                     const struct wetdem_many_mix* x, double range, double* hist,
                     struct wetdem_many_pair_out* out, unsigned char* flags, double* work)
{
    const struct wetdem_many* m = sim->many;
    bool dirty = *flags & WETDEM_MANY_DIRTY;
    *flags = 0;
    if (range > m->reach)
        return WETDEM_ERR_INVALID; /* reported by the caller: the start-up bound failed */
    if (c->gap > range) {
        if (hist && m->record) /* the min-separation record may live on (many.h) */
            return record_beyond_range(sim, c, hist, flags);
        if (hist && dirty)
            wetdem_sim_history_init(sim, hist);
        return WETDEM_OK;
    }
    c->dt = m->advance;
    if (m->advance > 0.0) { /* the spring's slip at the half step (spring_velocity) */
        const struct wetdem_vec3 *h_i = m->vwh[c->i], *h_j = m->vwh[c->is_wall ? c->i : c->j];
        c->dv_t_spring = contact_half_step_dv(c, h_i[0], h_i[1], h_j[0], h_j[1]);
    }
    struct wetdem_pair_force f, per_model[WETDEM_MAX_MODELS];
    struct wetdem_pair_force* pm = m->set.energy_budget ? per_model : NULL;
    int st = m->fused ? wetdem_sim_many_eval_fused(sim, c, x, hist, &f, pm)
                      : wetdem_sim_eval_contact(sim, c, hist, &f, pm);
    if (st < 0)
        return st;
    out->force = vec3_axpy(f.f_tan, f.f_normal, c->normal);
    out->torque_i = f.torque_i;
    out->torque_j = f.torque_j;
    *flags = WETDEM_MANY_ACTIVE | WETDEM_MANY_DIRTY |
             (c->gap < 0 ? WETDEM_MANY_CONTACT | WETDEM_MANY_SPRING : 0);
    if (!(isfinite(f.f_normal) && vec3_is_finite(out->force) && vec3_is_finite(f.torque_i) &&
          vec3_is_finite(f.torque_j)))
        return WETDEM_ERR_NUMERIC;
    if (pm)
        add_model_work(m, c->i, c->j, c->is_wall, c->normal, per_model, sim->n_models, work);
    return WETDEM_OK;
}

/* Pair q = (i, j) within the cheap test's reach (d = x_i - x_j) with a record of one of
 * wetdem's own min-separation models (record_partial) and the fused kernel, whose range is the
 * table's: when it lies beyond that range, its record
 * (record_beyond_range) from only the part of the contact the min-separation model reads,
 * computed as contact_pair_geometry does (the same bits), and true; else false (eval_pair
 * then runs: its range check included). Most of these pairs are only within the record
 * range, and the full contact cost them as much again. */
static bool record_only(const struct wetdem_sim* sim, size_t q, struct wetdem_vec3 d,
                        const struct wetdem_many_mix* x, struct failure* fail)
{
    struct wetdem_many* m = sim->many;
    size_t i = m->cl.pairs[q].i, j = m->cl.pairs[q].j;
    double dist = vec3_norm(d), r_i = m->xr[i].r, r_j = m->xr[j].r;
    double gap = dist - r_i - r_j;
    if (!(gap > x->range) || x->range > m->reach)
        return false;
    struct wetdem_contact c = {.i = i, .j = j, .gap = gap, .radius_i = r_i, .radius_j = r_j};
    copy_mix(&c, x);
    c.normal = dist > 0 ? vec3_scale(d, 1.0 / dist) : vec3(1, 0, 0);
    c.r_eff = contact_reduced(r_i, r_j);
    c.v_n = -vec3_dot(vec3_sub(m->vw[i][0], m->vw[j][0]), c.normal);
    int st = record_beyond_range(sim, &c, m->history + q * sim->history_len, &m->flags[q]);
    if (st != WETDEM_OK)
        note_failure(fail, q, st, false, &c, x->range);
    return true;
}

/* Pair q within reach of the cheap test (d = x_i - x_j): its contact and force into *o, its
 * work into work[] (NULL: none). */
static void eval_near_pair(const struct wetdem_sim* sim, size_t q, struct wetdem_vec3 d,
                           const struct wetdem_many_mix* x, struct wetdem_many_pair_out* o,
                           struct failure* fail, double* work)
{
    const struct wetdem_many* m = sim->many;
    size_t i = m->cl.pairs[q].i, j = m->cl.pairs[q].j, len = sim->history_len;
    if (m->record_partial && m->fused && len && record_only(sim, q, d, x, fail))
        return;
    struct wetdem_contact c;
    struct wetdem_particle a = wetdem_many_particle(sim, i), b = wetdem_many_particle(sim, j);
    pair_contact_from(&a, &b, d, x, &c);
    c.i = i;
    c.j = j;
    double range = contact_range(sim, &c, x);
    double* hist = len ? m->history + q * len : NULL;
    int st = eval_pair(sim, &c, x, range, hist, o, &m->flags[q], work);
    if (st != WETDEM_OK)
        note_failure(fail, q, st, false, &c, range);
}

/* What every candidate evaluation of one force pass reads, gathered once. */
struct pass {
    const struct wetdem_sim* sim;
    struct wetdem_many* m;
    const struct wetdem_particle* p;
    const struct wetdem_celllist_item* xr;
    const struct wetdem_celllist_pair* pairs;
    unsigned char* flags;
    /* the sums the pairs add to (m's: here so that a block's copy of the pass holds them, not
       loaded from m again after every byte store to flags) */
    struct wetdem_vec3 *force, *torque;
    const double* lim2; /* pair_lim2 */
    float* skip_until;  /* many.h: the gap test's skip clock */
    double clock;       /* drift_clock */
    struct skip_bound bound;
    double* history;
    size_t len, nm;
    bool periodic, lean;
    bool skip;     /* the skip times are usable (else every candidate is tested) */
    bool fused;    /* skip, and the block's candidates are tested and evaluated in one loop */
    bool maintain; /* each tested candidate gets its skip time anew */
    bool zeroed;   /* the sums start from zero already (many.h sums_zeroed) */
    /* four pairs at a time (many_bulk.h) for the lean kernel's common case, or NULL; and the
       particle-wall pairs so (with at most 64 walls) */
    wetdem_many_bulk_fn* bulk;
    wetdem_many_bulk_walls_fn* bulk_walls;
    struct wetdem_many_bulk_in bulk_in;
    /* with an energy budget, the work entries of the particles and of the cross pairs (many.h),
       else NULL; n_models doubles each */
    double *pair_work, *cross_work;
    size_t n_models;
};

/* The force and torques of entry k of four-at-a-time results (those of a contact; a pair
 * apart has +0 for its torque on i there, and no torque on j). */
static inline struct wetdem_many_pair_out bulk_pair_out(const struct wetdem_many_bulk_out* bo,
                                                        size_t k)
{
    return (struct wetdem_many_pair_out){
        .force = vec3(bo->force[0][k], bo->force[1][k], bo->force[2][k]),
        .torque_i = vec3(bo->torque_i[0][k], bo->torque_i[1][k], bo->torque_i[2][k]),
        .torque_j = vec3(bo->torque_j[0][k], bo->torque_j[1][k], bo->torque_j[2][k])};
}

/* Candidate q = (i, j, d = x_i - x_j) that passed the gap test: its kernel, its work into
 * work[] (work_slot: NULL without a budget). Returns its flags.
 * Inlined into its two loops (cross pairs, pairs of a block): with the pairs apart on their
 * own short path (lean_apart), the call cost more than the spills it used to save. */
static unsigned char near_candidate(const struct pass* P, size_t q, size_t i, size_t j,
                                    struct wetdem_vec3 d, const struct wetdem_many_mix* x,
                                    struct wetdem_many_pair_out* o, struct failure* fail,
                                    const struct wetdem_many_bulk_out* bo, size_t k, double* work)
    __attribute__((always_inline));
static inline unsigned char near_candidate(const struct pass* P, size_t q, size_t i, size_t j,
                                           struct wetdem_vec3 d, const struct wetdem_many_mix* x,
                                           struct wetdem_many_pair_out* o, struct failure* fail,
                                           const struct wetdem_many_bulk_out* bo, size_t k,
                                           double* work)
{
    unsigned char* fl = &P->flags[q];
    if (!P->lean) {
        eval_near_pair(P->sim, q, d, x, o, fail, work);
        return *fl;
    }
    unsigned char was = *fl;
    double* hist = P->history + q * P->len;
    struct lean_terms terms, *budget = work ? &terms : NULL;
    int st = lean_pair(P->m, i, j, d, x, hist, P->m->pair_cache[q], fl, o, bo, k, budget);
    if (!*fl && (was & WETDEM_MANY_DIRTY) && P->len)
        wetdem_sim_history_init(P->sim, hist);
    if (budget && *fl && st == WETDEM_OK) /* (as eval_pair: a force within range, finite) */
        add_lean_work(P->sim, i, j, false, budget, work);
    if (st != WETDEM_OK) {
        struct wetdem_contact c = {.gap = bo ? bo->gap[k]
                                             : vec3_norm(d) - P->p[i].radius - P->p[j].radius};
        note_failure(fail, q, st, false, &c, x->range);
    }
    return *fl;
}

/* The terms of entry k of four-at-a-time results bo kept for a budget (in->budget), with unit
 * normal n: the contact terms are +0 apart, so no test on the class (which a wet packing's
 * results follow without a pattern); a wall has no torque on j. */
static inline __attribute__((always_inline)) struct lean_terms
bulk_terms(const struct wetdem_many_bulk_out* bo, size_t k, struct wetdem_vec3 n, bool wall)
{
    return (struct lean_terms){
        .term = {bo->hertz[k], bo->f_sb[k], bo->f_cap[k]},
        .f_tan = vec3(bo->f_tan[0][k], bo->f_tan[1][k], bo->f_tan[2][k]),
        .t_i = vec3(bo->torque_i[0][k], bo->torque_i[1][k], bo->torque_i[2][k]),
        .t_j =
            wall ? vec3(0, 0, 0) : vec3(bo->torque_j[0][k], bo->torque_j[1][k], bo->torque_j[2][k]),
        .n = n};
}

/* With an energy budget (work not NULL), the work of candidate k of four-at-a-time results bo,
 * pair (i, j), of class > 1, into work[]: the terms lean_pair gives with these results (apart:
 * the film terms; in solid contact also the hertz term, mindlin's force and the torques, which
 * the vector kernel computes as lean_force does). */
static inline __attribute__((always_inline)) void
bulk_result_work(const struct pass* P, const struct wetdem_many_bulk_out* bo, size_t k, size_t i,
                 size_t j, double* work)
{
    if (!work)
        return;
    struct lean_terms t = bulk_terms(bo, k, vec3(bo->n[0][k], bo->n[1][k], bo->n[2][k]), false);
    add_lean_work(P->sim, i, j, false, &t, work);
}

/* Pair q, which had flags, has left its range: fresh history, no flags. */
static void leave_range(const struct pass* P, size_t q) __attribute__((noinline));
static void leave_range(const struct pass* P, size_t q)
{
    if (P->flags[q] & WETDEM_MANY_DIRTY && P->len)
        wetdem_sim_history_init(P->sim, P->history + q * P->len);
    P->flags[q] = 0;
}

/* Candidate q's four-at-a-time result of class cls > 1 (its flags; many.h): the flags stored
 * where they change and, apart, Mindlin's spring reset from the flags before
 * (reset_spring_apart; in solid contact the vector kernel stored the spring). What
 * near_candidate does with the pair's state; its force and torques are the result's
 * (bulk_pair_out; apart, no torques). */
static inline __attribute__((always_inline)) void bulk_flags(const struct pass* P, size_t q,
                                                             long long cls)
{
    unsigned char was = P->flags[q];
    if (was == (unsigned char)cls) /* (most pairs keep their flags from step to step) */
        return;
    P->flags[q] = (unsigned char)cls;
    if (was & ~cls & WETDEM_MANY_SPRING) /* (apart now: cls has the bit in solid contact; one
                                            test, rarely true, for the two of before) */
        reset_spring_apart(&P->m->lean, was, P->history + q * P->len);
}

/* Pair (i, j): d = x_i - x_j (minimum image when `periodic`) into *d and the pair's mixed
 * properties into *x (the first when `single`: one material pair). */
static inline __attribute__((always_inline)) void pair_delta(const struct pass* P, size_t i,
                                                             size_t j, bool periodic, bool single,
                                                             struct wetdem_vec3* d,
                                                             const struct wetdem_many_mix** x)
{
    const struct wetdem_celllist_item* xr = P->xr;
    struct wetdem_vec3 xi = vec3(xr[i].x, xr[i].y, xr[i].z), xj = vec3(xr[j].x, xr[j].y, xr[j].z);
    *d = periodic ? celllist_delta(&P->m->cl.box, xi, xj) : vec3_sub(xi, xj);
    *x = single ? P->m->mix
                : &P->m->mix[(size_t)P->p[i].material * P->nm + (size_t)P->p[j].material];
}

/* Candidate q's skip time from its squared distance r2 [m^2] (within_reach). A candidate
 * that passes gets a time before the clock (beyond < 0): it is tested again. */
static inline __attribute__((always_inline)) float skip_time(const struct pass* P, size_t q,
                                                             double r2)
{
    const struct skip_bound* B = &P->bound;
    double beyond = (r2 - (P->lim2[q] * B->rel + B->abs)) * B->inv_2dmax; /* <= |d| - far */
    double until = P->clock + 0.5 * (beyond < B->cap ? beyond : B->cap);
    /* kept as a float rounded down (one float ulp off, then to nearest): never later */
    return (float)(until - fabs(until) * 1.2e-7);
}

static inline __attribute__((always_inline)) void set_skip_time(const struct pass* P, size_t q,
                                                                double r2)
{
    P->skip_until[q] = skip_time(P, q, r2);
}

/* The squared reach of the cheap gap test of pair (i, j) out to the gap `range` [m^2]: the
 * interaction range of its mixed properties (x->range), or a min-separation record's. */
static double reach2(const struct wetdem_celllist_item* xr, size_t i, size_t j, double range)
{
    double lim = xr[i].r + xr[j].r + range;
    return lim * lim * (1 + PREFILTER_MARGIN);
}

/* With a min-separation record (many.h, record), the gap test's bound of every candidate
 * (pair_lim2) for the larger of r_ab and the pair's record range (for its R* and the material
 * pair's films), up to which eval_pair still evaluates the min-separation model (the lean
 * kernel, which would not, is off then: plan_lean). */
static void record_limits(const struct wetdem_sim* sim)
{
    struct wetdem_many* m = sim->many;
    const struct wetdem_celllist_item* xr = m->xr;
    size_t nm = (size_t)m->n_mix_materials;
#pragma omp parallel for schedule(static) if (wetdem_many_parallel(m, sim->n_particles))
    for (size_t q = 0; q < m->cl.n_pairs; q++) {
        size_t i = m->cl.pairs[q].i, j = m->cl.pairs[q].j;
        const struct wetdem_many_mix* x =
            &m->mix[(size_t)sim->particles[i].material * nm + (size_t)sim->particles[j].material];
        struct wetdem_contact c = {.r_eff = contact_reduced(xr[i].r, xr[j].r)};
        copy_mix(&c, x);
        m->pair_lim2[q] = reach2(xr, i, j, fmax(x->range, wetdem_sim_record_range(sim, &c)));
    }
}

/* The cheap gap test of candidate q = (i, j): pair_delta, then true when
 * |d|^2 <= (R_i + R_j + r_ab)^2 (1 + PREFILTER_MARGIN), the bound kept per pair (pair_lim2).
 * With `maintain`, sets the candidate's skip time (many.h, set_skip_time): the skip clock
 * plus half of a lower bound of |d| - far_q (many.h, struct skip_bound), before the clock when
 * it passes. Until the clock gets there, its two particles cannot have come closer by that
 * much, and the test would reject it again: the margins of far_q, a relative 1e-9 and 1e-12 of
 * the largest coordinate, exceed the round-off of the distances, of the test and of the times
 * by orders of magnitude. */
static inline __attribute__((always_inline)) bool
within_reach(const struct pass* P, size_t q, size_t i, size_t j, bool periodic, bool single,
             bool maintain, struct wetdem_vec3* d, const struct wetdem_many_mix** x)
{
    pair_delta(P, i, j, periodic, single, d, x);
    double r2 = vec3_dot(*d, *d);
    bool near = r2 <= P->lim2[q];
    if (maintain) /* P->maintain */
        set_skip_time(P, q, r2);
    return near;
}

/* Whether candidate q's skip time has not come: its gap test would reject it. It then has no
 * flags (the test that set the time cleared them). */
static inline __attribute__((always_inline)) bool skipped(const struct pass* P, size_t q)
{
    return P->skip && P->clock < P->skip_until[q];
}

/* Candidate pair q = (i, j): the gap test on the positions first (most candidates are beyond
 * their range), the kernel only for the others. Returns the pair's new flags; *o holds the
 * force and torques where they include WETDEM_MANY_ACTIVE. */
static inline __attribute__((always_inline)) unsigned char
eval_candidate(const struct pass* P, size_t q, size_t i, size_t j, struct wetdem_many_pair_out* o,
               struct failure* fail, double* work)
{
    struct wetdem_vec3 d;
    const struct wetdem_many_mix* x;
    if (skipped(P, q))
        return 0;
    if (within_reach(P, q, i, j, P->periodic, P->nm == 1, P->maintain, &d, &x))
        return near_candidate(P, q, i, j, d, x, o, fail, NULL, 0, work);
    if (P->flags[q])
        leave_range(P, q);
    return 0;
}

/* Index of the lowest set bit of *mask, cleared; 64 (>= every wall count here) when none. */
static size_t next_wall(uint64_t* mask)
{
    if (!*mask)
        return 64;
    size_t w = (size_t)__builtin_ctzll(*mask);
    *mask &= *mask - 1;
    return w;
}

/* Wall w of particle i, within the start-up reach: its force into *o through the lean kernel
 * or eval_pair; returns its flags. The history is reset beyond the range (when it may have
 * been used: `dirty`). */
static unsigned char eval_wall(const struct wetdem_sim* sim, size_t i, size_t w, double* hist,
                               bool dirty, struct wetdem_many_pair_out* o, struct failure* fail)
{
    const struct wetdem_many* m = sim->many;
    struct wetdem_particle state = wetdem_many_particle(sim, i);
    const struct wetdem_particle* a = &state;
    const struct wetdem_wall* wall = &sim->walls[w];
    const struct wetdem_many_mix* x = wetdem_sim_many_mix(sim, a->material, wall->material);
    double* work = work_slot(m->set.energy_budget ? m->wall_work : NULL, sim->n_models, i);
    unsigned char flags;
    if (m->lean.on) {
        struct lean_terms terms, *budget = work ? &terms : NULL;
        int st = lean_wall(m, i, a, wall, x, hist, &flags, o, budget);
        if (!flags && hist && dirty) /* reset beyond the range, as eval_pair does */
            wetdem_sim_history_init(sim, hist);
        if (budget && flags && st == WETDEM_OK)
            add_lean_work(sim, i, w, true, budget, work);
        if (st != WETDEM_OK) {
            struct wetdem_contact c = {
                .gap = vec3_dot(vec3_sub(a->pos, wall->point), wall->normal) - a->radius};
            note_failure(fail, i * sim->n_walls + w, st, true, &c, x->range);
        }
        return flags;
    }
    struct wetdem_contact c;
    wall_contact_from(a, wall, x, &c);
    c.i = i;
    c.j = w;
    double range = contact_range(sim, &c, x);
    flags = WETDEM_MANY_DIRTY; /* eval_pair resets the history beyond the range */
    int st = eval_pair(sim, &c, x, range, hist, o, &flags, work);
    if (st != WETDEM_OK)
        note_failure(fail, i * sim->n_walls + w, st, true, &c, range);
    return flags;
}

/* Particle i's pair with wall w beyond its range: a fresh history where it may have been used
 * (its dirty bit; every wall past the 64th counts as used), no dirty bit. */
static void wall_beyond(const struct wetdem_sim* sim, size_t i, size_t w)
{
    struct wetdem_many* m = sim->many;
    size_t len = sim->history_len;
    uint64_t bit = w < 64 ? (uint64_t)1 << w : 0;
    if (len && (w >= 64 || (m->wall_dirty[i] & bit)))
        wetdem_sim_history_init(sim, m->wall_history + (i * sim->n_walls + w) * len);
    m->wall_dirty[i] &= ~bit;
}

/* Particle i's dirty bit of wall w after an evaluation with flags fl: set with any flags
 * (its history may differ from a fresh one), else cleared (walls past the 64th have none). */
static inline void set_wall_dirty(const struct wetdem_many* m, size_t i, size_t w, unsigned char fl)
{
    uint64_t bit = w < 64 ? (uint64_t)1 << w : 0;
    m->wall_dirty[i] = fl ? m->wall_dirty[i] | bit : m->wall_dirty[i] & ~bit;
}

/* Particle i's pair with wall w evaluated with flags fl and output o: its dirty bit, and when
 * active its force and torque into *f, *t. */
static inline void add_wall_result(const struct wetdem_many* m, size_t i, size_t w,
                                   unsigned char fl, const struct wetdem_many_pair_out* o,
                                   struct wetdem_vec3* f, struct wetdem_vec3* t)
{
    set_wall_dirty(m, i, w, fl);
    if (!(fl & WETDEM_MANY_ACTIVE))
        return;
    *f = vec3_add(*f, o->force);
    *t = vec3_add(*t, o->torque_i);
}

/* Wall forces on particle i, added to *f, *t in wall order. */
static void eval_walls_of(const struct wetdem_sim* sim, size_t i, struct wetdem_vec3* f,
                          struct wetdem_vec3* t, struct failure* fail)
{
    const struct wetdem_many* m = sim->many;
    size_t len = sim->history_len, nw = sim->n_walls;
    struct wetdem_vec3 pos = vec3(m->xr[i].x, m->xr[i].y, m->xr[i].z);
    double radius = m->xr[i].r;
    /* up to 64 walls: the set bits of the mask, in increasing w; beyond, every wall */
    uint64_t mask = nw <= 64 ? m->wall_mask[i] : 0;
    for (size_t w = nw <= 64 ? next_wall(&mask) : 0; w < nw;
         w = nw <= 64 ? next_wall(&mask) : w + 1) {
        if (w < 64 && !(m->wall_mask[i] >> w & 1))
            continue;
        const struct wetdem_wall* wall = &sim->walls[w];
        double gap = vec3_dot(vec3_sub(pos, wall->point), wall->normal) - radius;
        if (gap > m->wall_reach) {
            wall_beyond(sim, i, w);
            continue;
        }
        double* hist = len ? m->wall_history + (i * nw + w) * len : NULL;
        bool dirty = w >= 64 || (m->wall_dirty[i] >> w & 1);
        struct wetdem_many_pair_out o;
        unsigned char flags = eval_wall(sim, i, w, hist, dirty, &o, fail);
        add_wall_result(m, i, w, flags, &o, f, t);
    }
}

/* Grows *a to n elements of `size` bytes (contents not kept). */
static bool reserve(void** a, size_t* cap, size_t n, size_t size)
{
    if (n <= *cap && *a)
        return true;
    free(*a);
    *a = malloc((n ? n : 1) * size);
    *cap = *a ? n : 0;
    return *a != NULL;
}

/* ---- blocks and the cross-block index ---- */

/* Work of particle i in the force pass, in units of one candidate's gap test: the particle's
 * own steps (about 4.5), its candidates, and about 15 for each pair that was active (flags set
 * when the list was built; the kernel costs that much more than a rejected candidate). */
static double particle_work(const struct wetdem_many* m, size_t i)
{
    size_t q0 = m->cl.first_pair[i], q1 = m->cl.first_pair[i + 1], active = 0, walls = 0;
    for (size_t q = q0; q < q1; q++)
        active += m->flags[q] != 0;
    /* its walls within reach: a loop over the few set bits (__builtin_popcountll is a library
       call without -mpopcnt) */
    for (uint64_t w = m->wall_mask[i]; w; w &= w - 1)
        walls++;
    return 4.5 + (double)(q1 - q0) + 20.0 * (double)active + 12.0 * (double)walls;
}

/* Block of particle k (blk: nb + 1 starts). */
static size_t block_of(const size_t* blk, size_t nb, size_t k)
{
    size_t b = 0;
    while (b + 1 < nb && k >= blk[b + 1])
        b++;
    return b;
}

/* Chunks of the particles whose work sums place the block cuts (partition_blocks). */
#define PARTITION_CHUNKS 256

/* Block starts blk[0..nb]: contiguous blocks of about equal estimated work, so that the
 * threads finish together (the result does not depend on the boundaries). When the blocks of
 * the same count were timed, the estimate of each particle is scaled by its old block's time
 * per unit of estimate: a feedback on what the estimate misses (walls, sliding contacts).
 * One block is all particles, with nothing to estimate. */
static void partition_blocks(struct wetdem_many* m, size_t n, size_t nb)
{
    if (nb == 1) {
        m->blk[0] = 0;
        m->blk[1] = n;
        m->block_time[0] = 0; /* (one block is never re-cut for balance) */
        return;
    }
    double scale[WETDEM_MANY_MAX_BLOCKS] = {0}, mean = 0;
    size_t old_blk[WETDEM_MANY_MAX_BLOCKS + 1]; /* the timed blocks */
    bool timed = m->blocks_ready && m->n_blocks == nb && m->blocks_n == n && m->blocks_passes > 0;
    for (size_t b = 0; timed && b < nb; b++) {
        timed = m->block_est[b] > 0 && m->block_time[b] > 0;
        scale[b] = timed ? m->block_time[b] / m->block_est[b] : 0;
        mean += scale[b] / (double)nb;
    }
    if (timed)
        memcpy(old_blk, m->blk, (nb + 1) * sizeof *old_blk);
    double factor[WETDEM_MANY_MAX_BLOCKS]; /* of each timed block (a division once per block) */
    for (size_t b = 0; b < nb; b++)
        factor[b] = timed ? scale[b] / mean : 1.0;
    /* work[i], the unscaled estimate, and the scaled sums of PARTITION_CHUNKS chunks of the
       particles, in parallel (it reads every candidate's flags); then the cuts from the chunk
       sums, each found by a scan of its chunk. The chunks do not depend on the thread count,
       so neither do the cuts (which change no result anyway: only the balance). */
    size_t n_chunks = n < PARTITION_CHUNKS ? 1 : PARTITION_CHUNKS;
    double chunk_sum[PARTITION_CHUNKS + 1];
#pragma omp parallel for schedule(static) if (wetdem_many_parallel(m, n))
    for (size_t k = 0; k < n_chunks; k++) {
        size_t lo = n * k / n_chunks, hi = n * (k + 1) / n_chunks;
        size_t old = timed ? block_of(old_blk, nb, lo) : 0;
        double sum = 0;
        for (size_t i = lo; i < hi; i++) {
            while (timed && old + 1 < nb && i >= old_blk[old + 1])
                old++;
            m->work[i] = particle_work(m, i);
            sum += m->work[i] * factor[old];
        }
        chunk_sum[k + 1] = sum;
    }
    chunk_sum[0] = 0;
    for (size_t k = 0; k < n_chunks; k++)
        chunk_sum[k + 1] += chunk_sum[k];
    double total = chunk_sum[n_chunks];
    size_t b = 1, k = 0;
    m->blk[0] = 0;
    for (; b < nb; b++) { /* cut b: after the particle at which the sum reaches b/nb of it */
        double target = total * (double)b / (double)nb;
        while (k + 1 < n_chunks && chunk_sum[k + 1] < target)
            k++;
        size_t lo = n * k / n_chunks, hi = n * (k + 1) / n_chunks, i = lo;
        size_t old = timed ? block_of(old_blk, nb, lo) : 0;
        double sum = chunk_sum[k];
        for (; i < hi; i++) {
            while (timed && old + 1 < nb && i >= old_blk[old + 1])
                old++;
            sum += m->work[i] * factor[old];
            if (sum >= target)
                break;
        }
        size_t cut = i < hi ? i + 1 : hi;
        m->blk[b] = cut > m->blk[b - 1] ? cut : m->blk[b - 1];
    }
    m->blk[nb] = n;
    if (m->block_jitter) { /* tests: arbitrary increasing cuts, new at every re-cut */
        uint64_t r = m->block_jitter =
            m->block_jitter * 6364136223846793005u + 1442695040888963407u;
        for (b = 1; b < nb; b++) {
            r = r * 6364136223846793005u + 1442695040888963407u;
            size_t lo = m->blk[b - 1], hi = n;
            m->blk[b] = lo + (size_t)((r >> 33) % (hi - lo + 1));
        }
    }
#pragma omp parallel for schedule(static) if (wetdem_many_parallel(m, n))
    for (size_t c = 0; c < nb; c++) { /* the estimate of each new block, for the next feedback */
        double est = 0;
        for (size_t i = m->blk[c]; i < m->blk[c + 1]; i++)
            est += m->work[i];
        m->block_est[c] = est;
        m->block_time[c] = 0;
    }
}

/* Whether the timed blocks finished more than 10 % apart (after a few passes, so that one
 * slow step on a shared machine does not move them). */
static bool blocks_unbalanced(const struct wetdem_many* m)
{
    if (m->n_blocks < 2 || m->blocks_passes < 8)
        return false;
    double lo = INFINITY, hi = 0;
    for (size_t b = 0; b < m->n_blocks; b++) {
        lo = fmin(lo, m->block_time[b]);
        hi = fmax(hi, m->block_time[b]);
    }
    return hi > 1.1 * lo;
}

/* A cross entry e with its pair (i, j), for sorting by (j, i). */
struct cross_key {
    uint32_t j, i, e;
};

static int by_second(const void* a, const void* b)
{
    const struct cross_key *x = a, *y = b;
    if (x->j != y->j)
        return x->j < y->j ? -1 : 1;
    return x->i < y->i ? -1 : (x->i > y->i);
}

/* cross_in: the cross entries (n) ordered by their pair's second particle, then first. */
static int sort_cross_in(struct wetdem_many* m, size_t n)
{
    struct cross_key* k = malloc((n ? n : 1) * sizeof *k);
    if (!k)
        return WETDEM_ERR_NOMEM;
    for (size_t e = 0; e < n; e++) {
        struct wetdem_celllist_pair q = m->cl.pairs[m->cross_q[e]];
        k[e] = (struct cross_key){q.j, q.i, (uint32_t)e};
    }
    qsort(k, n, sizeof *k, by_second);
    for (size_t e = 0; e < n; e++)
        m->cross_in[e] = k[e].e;
    free(k);
    return WETDEM_OK;
}

/* Blocks for nb threads and the pairs that cross them (first particle in an earlier block
 * than the second), when the list, the particle count or nb changed. */
static int index_blocks(struct wetdem_sim* sim, size_t nb)
{
    struct wetdem_many* m = sim->many;
    size_t n = sim->n_particles, np = m->cl.n_pairs;
    /* kept until the next list build; but once more after the first pass: the work estimate
       counts the pairs with flags, which a run starting from fresh histories has only then */
    bool same_list = m->blocks_ready && m->blocks_build == m->cl.n_builds && m->blocks_n == n &&
                     m->n_blocks == nb;
    bool first_pass_done = same_list && !m->blocks_refined && m->blocks_passes >= 1;
    if (same_list && !first_pass_done && !blocks_unbalanced(m))
        return WETDEM_OK;
    m->blocks_refined = same_list; /* the re-index after the first pass is done */
    if (nb > WETDEM_MANY_MAX_BLOCKS)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "%zu threads: at most %d", nb,
                               WETDEM_MANY_MAX_BLOCKS);
    if (!reserve((void**)&m->blk, &m->blk_cap, nb + 1, sizeof *m->blk) ||
        !reserve((void**)&m->work, &m->work_cap, n, sizeof *m->work) ||
        !reserve((void**)&m->cross_first, &m->cross_first_cap, 2 * (nb + 1),
                 sizeof *m->cross_first))
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory for %zu threads", nb);
    if (np > UINT32_MAX) /* pair indices are stored in 32 bits (cross_q, hits) */
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "too many candidate pairs for the force pass: %zu (limit %u)", np,
                               UINT32_MAX);
    partition_blocks(m, n, nb);
    /* pairs (i, j > i) leave i's block when j is at or beyond its end: counted and listed by
       block, the blocks in parallel (each block's entries at its offset, in pair order) */
    size_t count[WETDEM_MANY_MAX_BLOCKS + 1] = {0};
    bool parallel = nb > 1 && wetdem_many_parallel(m, n);
    (void)parallel; /* (read by the pragmas only: unused in a build without OpenMP) */
#pragma omp parallel for schedule(static) if (parallel)
    for (size_t b = 0; b < (nb > 1 ? nb : 0); b++) {
        size_t c = 0; /* (stored once: neighbouring counts share a cache line) */
        for (size_t q = m->cl.first_pair[m->blk[b]]; q < m->cl.first_pair[m->blk[b + 1]]; q++)
            c += m->cl.pairs[q].j >= m->blk[b + 1];
        count[b + 1] = c;
    }
    for (size_t b = 0; b < nb; b++)
        count[b + 1] += count[b];
    size_t nc = count[nb];
    if (!reserve((void**)&m->cross_q, &m->cross_q_cap, nc, sizeof *m->cross_q) ||
        !reserve((void**)&m->cross_in, &m->cross_in_cap, nc, sizeof *m->cross_in) ||
        !reserve((void**)&m->cross_out, &m->cross_out_cap, nc, sizeof *m->cross_out) ||
        !reserve((void**)&m->hits, &m->hits_cap, np, sizeof *m->hits) ||
        !reserve((void**)&m->hit_near, &m->hit_near_cap, np, sizeof *m->hit_near))
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory for %zu pairs", nc);
    size_t* first_out = m->cross_first;         /* by block of the first particle */
    size_t* first_in = m->cross_first + nb + 1; /* by block of the second particle */
    memset(m->cross_first, 0, 2 * (nb + 1) * sizeof *m->cross_first);
#pragma omp parallel for schedule(static) if (parallel)
    for (size_t bi = 0; bi < (nb > 1 ? nb : 0); bi++) {
        size_t e = count[bi];
        for (size_t q = m->cl.first_pair[m->blk[bi]]; q < m->cl.first_pair[m->blk[bi + 1]]; q++)
            if (m->cl.pairs[q].j >= m->blk[bi + 1]) {
                m->cross_q[e] = (uint32_t)q;
                m->cross_in[e] = (uint32_t)e;
                e++;
            }
    }
    for (size_t e = 0; e < nc; e++)
        first_in[block_of(m->blk, nb, m->cl.pairs[m->cross_q[e]].j) + 1]++;
    for (size_t b = 0; b < nb; b++) {
        first_out[b + 1] = count[b + 1];
        first_in[b + 1] += first_in[b];
    }
    if (nc > 1 && sort_cross_in(m, nc) != WETDEM_OK)
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory for %zu pairs", nc);
    m->n_blocks = nb;
    m->blocks_n = n;
    m->blocks_build = m->cl.n_builds;
    m->blocks_ready = true;
    m->blocks_passes = 0;
    return WETDEM_OK;
}

/* ---- the force pass ---- */

/* Phase 1, thread t of nt: an equal share of the cross pairs (second particle in a later
 * block than the first) of all blocks, into cross_out. Each result is the pair's own, so the
 * shares change none; by block, all of them would fall to the threads of the first blocks
 * (the last block has none), and the others would wait. */
static void cross_pairs_share(const struct pass* P, size_t t, size_t nt, struct failure* fail)
{
    struct wetdem_many* m = P->m;
    size_t n = m->cross_first[m->n_blocks], e_begin = n * t / nt, e_end = n * (t + 1) / nt;
    if (P->bulk) { /* four at a time: what eval_candidate does with each result */
        uint32_t q_of[WETDEM_MANY_BULK_MAX], e_of[WETDEM_MANY_BULK_MAX];
        struct wetdem_many_bulk_out bo;
        for (size_t e = e_begin; e < e_end;) {
            size_t n_w = 0; /* the next candidates whose skip time has come */
            for (; e < e_end && n_w < WETDEM_MANY_BULK_MAX; e++) {
                q_of[n_w] = m->cross_q[e];
                e_of[n_w] = (uint32_t)e;
                n_w += !skipped(P, m->cross_q[e]);
            }
            if (!n_w)
                continue;
            P->bulk(&P->bulk_in, q_of, n_w, SIZE_MAX, &bo); /* (no particle is being updated) */
            for (size_t k = 0; k < n_w; k++) {
                size_t q = q_of[k];
                struct wetdem_many_pair_out* o = &m->cross_out[e_of[k]];
                long long cls = bo.cls[k];
                if (P->maintain) /* within_reach's */
                    set_skip_time(P, q, bo.r2[k]);
                if (!cls) {
                    if (P->flags[q])
                        leave_range(P, q);
                } else if (cls == 1)
                    near_candidate(P, q, P->pairs[q].i, P->pairs[q].j, vec3(0, 0, 0), m->mix, o,
                                   fail, &bo, k, work_slot(P->cross_work, P->n_models, e_of[k]));
                else {
                    bulk_flags(P, q, cls);
                    bulk_result_work(P, &bo, k, P->pairs[q].i, P->pairs[q].j,
                                     work_slot(P->cross_work, P->n_models, e_of[k]));
                    if (cls & WETDEM_MANY_CONTACT)
                        *o = bulk_pair_out(&bo, k);
                    else
                        o->force = vec3(bo.force[0][k], bo.force[1][k], bo.force[2][k]);
                }
            }
        }
        return;
    }
    for (size_t e = e_begin; e < e_end; e++) {
        size_t q = m->cross_q[e];
        eval_candidate(P, q, P->pairs[q].i, P->pairs[q].j, &m->cross_out[e], fail,
                       work_slot(P->cross_work, P->n_models, e));
    }
}

/* The running force and torque of a particle's listed pairs (or of its walls) in three pairs
 * of lanes, (f_x, f_y), (f_z, t_x), (t_y, t_z), each lane's addition the one of the vec3 sums;
 * the sums restarted from +0 without a branch (running_add); and what a batch
 * of four-at-a-time results keeps of each particle it reaches (consume_four_at_a_time): slot 0
 * the one carried from the batch before, slot s > 0 the s-th particle that begins in it. */
typedef double lanes2 __attribute__((vector_size(16)));
typedef unsigned long long mask2 __attribute__((vector_size(16)));
struct running_sums {
    lanes2 a, b, c;
};
struct batch_sums {
    struct running_sums s[WETDEM_MANY_BULK_MAX + 1];
    uint32_t particle[WETDEM_MANY_BULK_MAX + 1]; /* the slot's particle (slot 0: UINT32_MAX
                                                    before the first batch) */
};

static inline __attribute__((always_inline)) struct wetdem_vec3
running_force(const struct running_sums* r)
{
    return vec3(r->a[0], r->a[1], r->b[0]);
}
static inline __attribute__((always_inline)) struct wetdem_vec3
running_torque(const struct running_sums* r)
{
    return vec3(r->b[1], r->c[0], r->c[1]);
}

/* *r plus force (f_x, f_y, f_z) and torque (t_x, t_y, t_z) in ft[0..6), restarted from +0
 * first when `fresh` (a new particle): the lanes masked to +0, the sum +0 + ft as a fresh
 * vec3 sum's (and a sum from +0 is never -0, so the masked restart changes no bit). */
static inline __attribute__((always_inline)) void running_add(struct running_sums* r, bool fresh,
                                                              const double ft[6])
{
    unsigned long long keep = (unsigned long long)fresh - 1;
    mask2 keep2 = {keep, keep};
    r->a = (lanes2)((mask2)r->a & keep2) + (lanes2){ft[0], ft[1]};
    r->b = (lanes2)((mask2)r->b & keep2) + (lanes2){ft[2], ft[3]};
    r->c = (lanes2)((mask2)r->c & keep2) + (lanes2){ft[4], ft[5]};
}

/* The start of particle k's sum: its walls (wall order) when it has some within reach. */
static inline void start_sum(const struct wetdem_sim* sim, size_t k, bool walls,
                             struct failure* fail)
{
    struct wetdem_many* m = sim->many;
    struct wetdem_vec3 f = vec3(0, 0, 0), t = vec3(0, 0, 0);
    if (walls)
        eval_walls_of(sim, k, &f, &t, fail);
    m->force[k] = f;
    m->torque[k] = t;
}

/* The sums of the particles whose particle-wall pairs are the entries lo..hi of the flat list
 * (many.h wall_entry_part, wall_entry_wall; whole particles), started with their walls as
 * start_sum does: the pairs within the reach and the range evaluated four at a time
 * (many_bulk.h bulk_walls) in batches of whole particles, what eval_walls_of does with each
 * result (a class 1 pair through eval_wall, the scalar kernel). In flat loops over the entries
 * without branches on the outcome, whose patterns follow no rule in a packing (how many walls a
 * particle has, which of them are within range): every entry is written to the batch's list
 * and kept by its test; one beyond gets wall_beyond only where its history may have been used
 * (its dirty bit: otherwise wall_beyond changes nothing); the results are summed in entry
 * order into running sums restarted at each particle (running_add), which are stored after
 * every entry. The particles without a pair within range keep the zero sums the kick-drift
 * pass gave them (start_sums_of_block calls this only then), which is what start_sum gives
 * them. With `budget` (an energy budget), each result's work per model into the particle's
 * wall work, in entry order (eval_wall's for those it takes). */
static inline __attribute__((always_inline)) void start_sums_four_at_a_time_as(const struct pass* P,
                                                                               size_t lo, size_t hi,
                                                                               struct failure* fail,
                                                                               bool budget)
{
    struct wetdem_many* m = P->m;
    const struct wetdem_sim* sim = P->sim;
    const uint32_t* part_of = m->wall_entry_part;
    const unsigned char* wall_of = m->wall_entry_wall;
    size_t len = sim->history_len, nw = sim->n_walls;
    double range = P->bulk_in.range, reach = m->reach; /* (of the one material pair) */
    uint32_t part[WETDEM_MANY_BULK_MAX];
    unsigned char wall[WETDEM_MANY_BULK_MAX];
    double gap_of[WETDEM_MANY_BULK_MAX];
    struct wetdem_many_bulk_out bo;
    uint64_t n_within = 0;
    for (size_t s = lo; s < hi;) {
        /* a batch of whole particles: cut before the first entry of a particle that goes on
           past WETDEM_MANY_BULK_MAX entries (a particle has at most 64, one per wall) */
        size_t s_end = hi - s > WETDEM_MANY_BULK_MAX ? s + WETDEM_MANY_BULK_MAX : hi;
        while (s_end < hi && s_end - 1 > s && part_of[s_end] == part_of[s_end - 1])
            s_end--;
        size_t n = 0;
        for (size_t e = s; e < s_end; e++) {
            size_t i = part_of[e], w = wall_of[e];
            const struct wetdem_wall* wl = &sim->walls[w];
            struct wetdem_vec3 pos = vec3(m->xr[i].x, m->xr[i].y, m->xr[i].z);
            double gap = vec3_dot(vec3_sub(pos, wl->point), wl->normal) - m->xr[i].r;
            size_t within = (size_t)(gap <= reach) & (size_t) !(gap > range);
            part[n] = (uint32_t)i;
            gap_of[n] = gap;
            wall[n] = (unsigned char)w;
            n += within;
            if (!within && (m->wall_dirty[i] >> w & 1))
                wall_beyond(sim, i, w); /* (also within the reach: eval_wall's flags 0) */
        }
        if (n)
            P->bulk_walls(&P->bulk_in, part, wall, gap_of, n, &bo);
        struct running_sums r = {{0, 0}, {0, 0}, {0, 0}};
        uint32_t prev = UINT32_MAX;
        for (size_t e = 0; e < n; e++) {
            size_t i = part[e], w = wall[e];
            unsigned char flags = (unsigned char)bo.cls[e]; /* (within the range: never 0) */
            double ft[6] = {bo.force[0][e],    bo.force[1][e],    bo.force[2][e],
                            bo.torque_i[0][e], bo.torque_i[1][e], bo.torque_i[2][e]};
            if (bo.cls[e] == 1) { /* the scalar kernel; inactive, it adds +0 */
                struct wetdem_many_pair_out o;
                flags = eval_wall(sim, i, w, len ? m->wall_history + (i * nw + w) * len : NULL,
                                  m->wall_dirty[i] >> w & 1, &o, fail);
                bool active = flags & WETDEM_MANY_ACTIVE; /* (else o is not written) */
                ft[0] = active ? o.force.x : 0.0;
                ft[1] = active ? o.force.y : 0.0;
                ft[2] = active ? o.force.z : 0.0;
                ft[3] = active ? o.torque_i.x : 0.0;
                ft[4] = active ? o.torque_i.y : 0.0;
                ft[5] = active ? o.torque_i.z : 0.0;
            } else {
                n_within++;
                if (budget) { /* (the vector kernel's terms: lean_wall's) */
                    struct lean_terms t = bulk_terms(&bo, e, sim->walls[w].normal, true);
                    add_lean_work(sim, i, w, true, &t, work_slot(m->wall_work, sim->n_models, i));
                }
            }
            set_wall_dirty(m, i, w, flags);
            bool fresh = i != prev;
            prev = (uint32_t)i;
            running_add(&r, fresh, ft);
            m->force[i] = running_force(&r);
            m->torque[i] = running_torque(&r);
        }
        s = s_end;
    }
#pragma omp atomic
    m->bulk_walls += n_within;
}

/* start_sums_four_at_a_time_as, compiled apart with and without the energy budget (its work
 * of each entry). */
static void start_sums_four_at_a_time(const struct pass* P, size_t lo, size_t hi,
                                      struct failure* fail)
{
    if (P->m->set.energy_budget)
        start_sums_four_at_a_time_as(P, lo, hi, fail, true);
    else
        start_sums_four_at_a_time_as(P, lo, hi, fail, false);
}

/* The first index s < n with a[s] >= key in the sorted a[0..n), else n. */
static size_t first_not_below(const uint32_t* a, size_t n, size_t key)
{
    size_t lo = 0, hi = n;
    while (lo < hi) {
        size_t mid = lo + (hi - lo) / 2;
        if (a[mid] < key)
            lo = mid + 1;
        else
            hi = mid;
    }
    return lo;
}

/* Phase 2, start of block b: each particle's sum begins with its walls (wall order), then the
 * reactions of the cross pairs (k, i) from earlier blocks, in increasing k. */
static void start_sums_of_block(const struct pass* P, size_t b, struct failure* fail)
{
    struct wetdem_many* m = P->m;
    const struct wetdem_sim* sim = P->sim;
    const uint64_t* wall_mask = m->wall_mask;
    bool every_wall = sim->n_walls > 64;
    size_t begin = m->blk[b], end = m->blk[b + 1];
    if (P->zeroed) {       /* the others are zero already: the particles with walls */
        if (P->bulk_walls) /* their entries in the flat list */
            start_sums_four_at_a_time(
                P, first_not_below(m->wall_entry_part, m->n_wall_entries, begin),
                first_not_below(m->wall_entry_part, m->n_wall_entries, end), fail);
        else
            for (size_t s = first_not_below(m->wall_list, m->n_wall_list, begin);
                 s < m->n_wall_list && m->wall_list[s] < end; s++)
                start_sum(sim, m->wall_list[s], true, fail);
    } else
        for (size_t k = begin; k < end; k++)
            start_sum(sim, k, wall_mask[k] || (every_wall && !m->fixed[k]), fail);
    const size_t* first_in = m->cross_first + m->n_blocks + 1;
    for (size_t s = first_in[b]; s < first_in[b + 1]; s++) {
        size_t e = m->cross_in[s], q = m->cross_q[e], k = P->pairs[q].j;
        unsigned char fl = P->flags[q];
        if (!(fl & WETDEM_MANY_ACTIVE))
            continue;
        m->force[k] = vec3_sub(m->force[k], m->cross_out[e].force);
        if (adds_torque(P->lean, fl))
            m->torque[k] = vec3_add(m->torque[k], m->cross_out[e].torque_j);
    }
}

/* The gap test (within_reach) of n candidates, hits[k] when `listed` (the list of gap_test),
 * else q_begin + k, in one flat loop without branches on its outcome: those within range, and
 * those with flags, whose second particle is below end_block, are listed in hits in order
 * (over the list: each entry is written at or behind the one read); returns their number. */
static inline __attribute__((always_inline)) size_t
test_candidates(const struct pass* P, bool listed, size_t q_begin, size_t n, size_t end_block,
                uint32_t* restrict hits, unsigned char* restrict hit_near, bool periodic,
                bool single, bool maintain)
{
    const struct wetdem_celllist_pair* pairs = P->pairs;
    const unsigned char* flags = P->flags;
    size_t n_hits = 0;
    for (size_t k = 0; k < n; k++) {
        size_t q = listed ? hits[k] : q_begin + k, i = pairs[q].i, j = pairs[q].j;
        /* a pair crossing into a later block was tested, and given its skip time, before the
           barrier (cross_pairs_share), and that block's thread may be drifting j now: its test
           here reads i twice instead, is not used, and leaves the time as it is */
        bool own = j < end_block;
        struct wetdem_vec3 d;
        const struct wetdem_many_mix* x;
        bool near = within_reach(P, q, i, own ? j : i, periodic, single, false, &d, &x);
        if (maintain) /* (within_reach's) */
            P->skip_until[q] = own ? skip_time(P, q, vec3_dot(d, d)) : P->skip_until[q];
        hits[n_hits] = (uint32_t)q;
        hit_near[n_hits] = near;
        n_hits += ((size_t)near | (size_t)(flags[q] != 0)) & (size_t)own;
    }
    return n_hits;
}

/* The candidates q_begin .. q_end whose skip time has come (all of them to test), in order,
 * into list; returns their number. Branch-free: a branch per candidate on its time would be
 * mispredicted half of the time in a flowing system. With SSE2 (every x86-64), four
 * candidates a step: 5 instructions a candidate instead of 11 (9 and 10 fewer per
 * particle-step on the frozen configuration, dry and wet). */
static inline __attribute__((always_inline)) size_t
due_candidates(const struct pass* P, size_t q_begin, size_t q_end, uint32_t* restrict list)
{
    const float* restrict until = P->skip_until;
    double clock = P->clock;
    size_t n_test = 0, q = q_begin;
#if defined(__SSE2__)
    /* four at a time: their times widened to doubles (exact) and compared with the clock as
       below (not less: due, as is a NaN), the due lanes' offsets taken from a table by the
       4-bit mask and written as four indices, of which the first `count` are kept; the
       write stays within the candidates read so far plus three (n_test <= q - q_begin) */
    const uint32_t(*lanes)[4] = wetdem_many_mask_lanes;
    const unsigned char* count = wetdem_many_mask_count;
    __m128d c = _mm_set1_pd(clock);
    for (; q_end - q >= 4; q += 4) {
        __m128 u = _mm_loadu_ps(until + q);
        __m128d lo = _mm_cvtps_pd(u), hi = _mm_cvtps_pd(_mm_movehl_ps(u, u));
        int mask_lo = _mm_movemask_pd(_mm_cmpnlt_pd(c, lo));
        int mask = mask_lo | _mm_movemask_pd(_mm_cmpnlt_pd(c, hi)) << 2;
        __m128i idx = _mm_add_epi32(_mm_set1_epi32((int)(uint32_t)q), /* (mod 2^32, as list) */
                                    _mm_loadu_si128((const __m128i*)(const void*)lanes[mask]));
        _mm_storeu_si128((__m128i*)(void*)(list + n_test), idx);
        n_test += count[mask];
    }
#endif
    for (; q < q_end; q++) {
        list[n_test] = (uint32_t)q;
        n_test += !(clock < until[q]);
    }
    return n_test;
}

/* The gap test of candidates q_begin .. q_end in flat loops without branches on their outcome:
 * those within range, and those with flags (they may have just left it), whose second particle
 * is below end_block, are listed in hits in pair order; returns their number. With usable
 * skip times (many.h), a first loop lists the candidates whose time has come in hits
 * (due_candidates), and the test runs over that list, writing its result over it (never ahead
 * of its reading). The skipped ones have no flags. `periodic` and `single` (one material
 * pair) are constants at each call, so each case compiles to its own loop. The lists are
 * `restrict`: a store through the byte list could otherwise alias anything, and every read of
 * the pass would be repeated after it. */
static inline __attribute__((always_inline)) size_t
gap_test(const struct pass* P, size_t q_begin, size_t q_end, size_t end_block,
         uint32_t* restrict hits, unsigned char* restrict hit_near, bool periodic, bool single,
         uint64_t* n_skipped)
{
    if (!P->skip) {
        size_t n = q_end - q_begin;
        return P->maintain ? test_candidates(P, false, q_begin, n, end_block, hits, hit_near,
                                             periodic, single, true)
                           : test_candidates(P, false, q_begin, n, end_block, hits, hit_near,
                                             periodic, single, false);
    }
    size_t n_test = due_candidates(P, q_begin, q_end, hits);
    *n_skipped += (q_end - q_begin) - n_test;
    return test_candidates(P, true, q_begin, n_test, end_block, hits, hit_near, periodic, single,
                           true); /* (P->skip implies P->maintain) */
}

/* A pair's force on i into i's running sum f, and its reaction at once into j's force. */
static inline __attribute__((always_inline)) void
add_reaction_pair(const struct pass* P, size_t j, struct wetdem_vec3 force, struct wetdem_vec3* f)
{
    *f = vec3_add(*f, force);
    P->force[j] = vec3_sub(P->force[j], force);
}

/* Candidate q beyond the gap test's reach (squared distance r2 [m^2]): in one loop (`fused`)
 * its new skip time; the flags it may have, dropped (leave_range, out of line, gets P_out). */
static inline __attribute__((always_inline)) void
beyond_reach(const struct pass* P, const struct pass* P_out, size_t q, double r2, bool fused)
{
    if (fused)
        set_skip_time(P, q, r2);
    if (P->flags[q])
        leave_range(P_out, q);
}

/* Pair q = (i, j) of block b, with result o and flags fl: into particle i's running sums
 * (f, t), and its reaction at once into j's sums. */
static inline __attribute__((always_inline)) void
add_pair(const struct pass* P, size_t j, unsigned char fl, const struct wetdem_many_pair_out* o,
         struct wetdem_vec3* f, struct wetdem_vec3* t)
{
    if (!(fl & WETDEM_MANY_ACTIVE))
        return;
    add_reaction_pair(P, j, o->force, f);
    if (adds_torque(P->lean, fl)) {
        *t = vec3_add(*t, o->torque_i);
        P->torque[j] = vec3_add(P->torque[j], o->torque_j);
    }
}

/* Particle i of a block after its listed pairs (with running sums f and t): its cross pairs
 * from phase 1 (from *e, j order), then its own sums into the totals (the reactions of
 * earlier particles are there already) and the closing half kick. */
static inline __attribute__((always_inline)) void
close_particle(const struct pass* P, size_t i, size_t* e, size_t e_end, struct wetdem_vec3 f,
               struct wetdem_vec3 t, bool kick, struct wetdem_vec3 g)
{
    struct wetdem_many* m = P->m;
    for (; *e < e_end && P->pairs[m->cross_q[*e]].i == i; ++*e) { /* its cross pairs, j order */
        unsigned char fl = P->flags[m->cross_q[*e]];
        if (!(fl & WETDEM_MANY_ACTIVE))
            continue;
        f = vec3_add(f, m->cross_out[*e].force);
        if (adds_torque(P->lean, fl))
            t = vec3_add(t, m->cross_out[*e].torque_i);
    }
    P->force[i] = vec3_add(P->force[i], f);
    P->torque[i] = vec3_add(P->torque[i], t);
    if (kick)
        wetdem_many_close_kick(m, i, g);
}

/* Particle i of a block without listed pairs: close_particle from zero sums if it has cross
 * pairs, else only the closing half kick (nothing to add: adding +0 would change no sum). */
static inline __attribute__((always_inline)) void close_unlisted(const struct pass* P, size_t i,
                                                                 size_t* e, size_t e_end, bool kick,
                                                                 struct wetdem_vec3 g)
{
    if (*e < e_end && P->pairs[P->m->cross_q[*e]].i == i)
        close_particle(P, i, e, e_end, vec3(0, 0, 0), vec3(0, 0, 0), kick, g);
    else if (kick)
        wetdem_many_close_kick(P->m, i, g);
}

/* Closes the particles next .. stop - 1 of a batch (close_particle) with the sums of the
 * batch's slots from_slot .. to_slot - 1 (their particles in order among them, the others
 * without listed pairs). Without cross pairs among them (always on one thread), the slots'
 * sums are added, then every particle gets its kick: no branch on whether a particle has
 * pairs. */
static inline __attribute__((always_inline)) void
close_batch(const struct pass* P, const struct batch_sums* B, size_t from_slot, size_t to_slot,
            size_t next, size_t stop, size_t* e, size_t e_end, bool kick, struct wetdem_vec3 g)
{
    struct wetdem_many* m = P->m;
    if (*e < e_end && P->pairs[m->cross_q[*e]].i < stop) { /* cross pairs: particle by particle */
        for (size_t p = next, s = from_slot; p < stop; p++) {
            if (s < to_slot && B->particle[s] == p) {
                close_particle(P, p, e, e_end, running_force(&B->s[s]), running_torque(&B->s[s]),
                               kick, g);
                s++;
            } else
                close_unlisted(P, p, e, e_end, kick, g);
        }
        return;
    }
    for (size_t s = from_slot; s < to_slot; s++) { /* (their sums, then the kicks) */
        size_t p = B->particle[s];
        P->force[p] = vec3_add(P->force[p], running_force(&B->s[s]));
        P->torque[p] = vec3_add(P->torque[p], running_torque(&B->s[s]));
    }
    for (size_t p = next; kick && p < stop; p++)
        wetdem_many_close_kick(m, p, g);
}

/* Phase 2 of block b with four pairs at a time (pairs_of_block_as): the listed candidates
 * list[0..n_list) are evaluated WETDEM_MANY_BULK_MAX at a time (P->bulk) and their results
 * taken in list order, in one loop over the results rather than one per particle. Each result
 * adds to the running sums of its first particle (restarted from +0 at the first result of a
 * particle, without a branch: in a wet packing the particles' numbers of pairs follow no
 * pattern, and a branch there was mispredicted at about every other particle), which are kept
 * in the batch's slot of that particle; after the batch, the particles before the last one
 * (whose pairs may go on in the next batch) are closed (close_batch), the last ones after the
 * loop. The same operations in the same order as the loop per particle: each particle's pairs
 * in list order, then its cross pairs, its sums and its kick; the evaluation of a batch reads
 * only particles at or after its first pair's first particle, none of which has been closed,
 * and no reaction goes to a closed particle (j > i). Every result adds its torque on i to the
 * running sum (+0 apart: the vector kernel's, or +0 where it does not act); the torque on j
 * is added in solid contact only: with `defer` (a pass with films, where
 * contacts and bridges apart alternate without a pattern and a branch on which one a result
 * is was mispredicted often) after the batch's loop, in a loop over its contacts in list
 * order (the same sums: see there), else at once. `budget`: P->pair_work is set (an energy
 * budget), each result's work goes there.
 * Returns the number within range; *n_bulk_contacts gets those in solid contact evaluated
 * four at a time. */
static inline __attribute__((always_inline)) uint64_t
consume_four_at_a_time(const struct pass* P, const struct pass* P_out, size_t b,
                       const uint32_t* list, size_t n_list, bool kick, struct wetdem_vec3 g,
                       struct failure* fail, bool fused, bool defer, bool budget,
                       uint64_t* n_bulk_contacts)
{
    struct wetdem_many* m = P->m;
    size_t end_block = m->blk[b + 1];
    size_t e = m->cross_first[b], e_end = m->cross_first[b + 1]; /* the block's cross pairs */
    size_t next = m->blk[b];                                     /* the first particle not closed */
    uint32_t i = UINT32_MAX; /* the particle of the current results, once there is one */
    struct running_sums r = {{0, 0}, {0, 0}, {0, 0}};
    uint64_t n_near = 0, n_contact_results = 0;
    struct wetdem_many_bulk_out bo;
    struct batch_sums B;
    uint32_t torque_at[WETDEM_MANY_BULK_MAX];
    for (size_t h = 0; h < n_list;) {
        size_t n_w = n_list - h < WETDEM_MANY_BULK_MAX ? n_list - h : WETDEM_MANY_BULK_MAX;
        P->bulk(&P->bulk_in, list + h, n_w, end_block, &bo);
        /* in list order, each result's state and its reactions on j, then what it adds to i's
           force and torque (its entry's: the slower paths write it there, +0 for those that do
           not act) into the running sums of the first particles, restarted from +0 at a new
           particle without a branch (a sum from +0 is never -0) */
        size_t slot = 0; /* slot 0: the particle carried from the batch before (none at first) */
        B.particle[0] = i;
        B.s[0] = r;
        size_t n_torque = 0; /* with defer: the contacts, whose torque on j waits */
        for (size_t k = 0; k < n_w; k++) {
            size_t q = list[h + k], j = bo.j[k];
            long long cls = bo.cls[k];
            if (j < end_block && cls > 1) { /* evaluated four at a time: add_pair's j side */
                n_near++;
                bulk_flags(P, q, cls);
                bulk_result_work(P, &bo, k, bo.i[k], j,
                                 budget ? work_slot(P->pair_work, P->n_models, bo.i[k]) : NULL);
                P->force[j] =
                    vec3_sub(P->force[j], vec3(bo.force[0][k], bo.force[1][k], bo.force[2][k]));
                if (defer) { /* (apart: +0 torques) */
                    torque_at[n_torque] = (uint32_t)k;
                    n_torque += (size_t)((cls & WETDEM_MANY_CONTACT) != 0);
                } else if (cls & WETDEM_MANY_CONTACT) {
                    P->torque[j] = vec3_add(P->torque[j], vec3(bo.torque_j[0][k], bo.torque_j[1][k],
                                                               bo.torque_j[2][k]));
                    n_contact_results++;
                }
            } else {
                struct wetdem_vec3 f = vec3(0, 0, 0), t = vec3(0, 0, 0);
                if (j >= end_block) /* a cross pair: tested and evaluated in phase 1 */
                    ;
                else if (!cls) /* beyond (in two loops the test gave it its time and listed it
                                  for its flags) */
                    beyond_reach(P, P_out, q, bo.r2[k], fused);
                else {
                    n_near++;
                    struct wetdem_many_pair_out o;
                    unsigned char fl = near_candidate(
                        P, q, bo.i[k], j, vec3(0, 0, 0), m->mix, &o, fail, &bo, k,
                        budget ? work_slot(P->pair_work, P->n_models, bo.i[k]) : NULL);
                    add_pair(P, j, fl, &o, &f, &t);
                }
                bo.force[0][k] = f.x;
                bo.force[1][k] = f.y;
                bo.force[2][k] = f.z;
                bo.torque_i[0][k] = t.x;
                bo.torque_i[1][k] = t.y;
                bo.torque_i[2][k] = t.z;
            }
            uint32_t first = bo.i[k];
            size_t fresh = first != i;
            slot += fresh;
            i = first;
            const double ft[6] = {bo.force[0][k],    bo.force[1][k],    bo.force[2][k],
                                  bo.torque_i[0][k], bo.torque_i[1][k], bo.torque_i[2][k]};
            running_add(&r, fresh, ft);
            B.particle[slot] = i;
            B.s[slot] = r;
        }
        /* the torques on j of the contacts evaluated four at a time, in list order, apart
           from the loop over all results: in a wet packing, whether a result is a contact
           follows no pattern. The loop adds no other torque on j but that of a contact the
           scalar kernel takes over, whose result is not finite (bulk_contacts leaves it only
           those) and fails the pass: no run goes on with its sums. */
        for (size_t c = 0; c < n_torque; c++) {
            size_t k = torque_at[c], j = bo.j[k];
            P->torque[j] = vec3_add(P->torque[j],
                                    vec3(bo.torque_j[0][k], bo.torque_j[1][k], bo.torque_j[2][k]));
        }
        n_contact_results += n_torque;
        h += n_w;
        /* the particles before the last one, or at the end all of the block */
        size_t from = B.particle[0] == UINT32_MAX ? 1 : 0, stop = h < n_list ? i : end_block;
        close_batch(P, &B, from, h < n_list ? slot : slot + 1, next, stop, &e, e_end, kick, g);
        next = stop;
    }
    for (; next < end_block; next++) /* (no listed candidates) */
        close_unlisted(P, next, &e, e_end, kick, g);
    *n_bulk_contacts = n_contact_results;
    return n_near;
}

/* Phase 2 of block b: every particle i in index order; its pairs within the block are
 * evaluated and their reactions added to the second particle at once (so each particle
 * receives its reactions in increasing i), its cross pairs are read from phase 1; the sum of
 * its own pairs, in j order, is added last, and the closing half kick applied. Two loops
 * (`fused` false): the gap test of the block's candidates (gap_test), then the kernels over
 * the list of those within range; one loop (`fused`, with usable skip times only): the
 * candidates whose time has come, each tested and, within range, evaluated at once, with the
 * geometry of the test (many.h fuse_on). The same kernels run in the same order. `defer`: as
 * consume_four_at_a_time's (with `bulk`). */
static inline __attribute__((always_inline)) void
pairs_of_block_as(const struct pass* P, size_t b, bool kick, struct wetdem_vec3 g,
                  struct failure* fail, bool fused, bool common, bool bulk, bool defer)
{
    /* a private copy of the pass, whose fields no store of the loop can change (as those of
       *P could, through the byte stores of flags and hit lists): kept in registers, not
       loaded again after every store; leave_range, out of line, gets P */
    const struct pass own_copy = *P, *const P_out = P;
    P = &own_copy;
    struct wetdem_many* m = P->m;
    const struct wetdem_celllist_pair* pairs = P->pairs;
    size_t begin_block = m->blk[b], end_block = m->blk[b + 1];
    size_t e = m->cross_first[b], e_end = m->cross_first[b + 1]; /* the block's cross pairs */
    /* (common with bulk: periodic axes are the vector kernel's, known here only to the gap
       test of two loops, once per block) */
    bool single = common || P->nm == 1, periodic = common ? bulk && P->periodic : P->periodic;
    /* 1. the candidates to test (fused), or the gap test of every candidate of the block whose
          second particle is in the block, in one flat loop without branches on its outcome:
          the pairs within range, and those with flags (they may have just left it), are listed
          in pair order */
    size_t q_begin = m->cl.first_pair[begin_block], q_end = m->cl.first_pair[end_block];
    uint32_t* list = m->hits + q_begin;
    unsigned char* near = m->hit_near + q_begin;
    uint64_t n_skipped = 0, n_near = 0, n_bulk_contacts = 0;
    size_t n_list;
    if (fused) {
        n_list = due_candidates(P, q_begin, q_end, list);
        n_skipped = (q_end - q_begin) - n_list;
    } else
        n_list =
            single && !periodic /* the common case, in its own loop */
                ? gap_test(P, q_begin, q_end, end_block, list, near, false, true, &n_skipped)
                : gap_test(P, q_begin, q_end, end_block, list, near, periodic, false, &n_skipped);
    /* 2. every particle in index order: its listed pairs (reactions to the second particle at
          once), its cross pairs from phase 1, then its own sum and the closing half kick */
    if (bulk && P->pair_work) /* (the budget's code apart: none of it in the loop without) */
        n_near = consume_four_at_a_time(P, P_out, b, list, n_list, kick, g, fail, fused, defer,
                                        true, &n_bulk_contacts);
    else if (bulk)
        n_near = consume_four_at_a_time(P, P_out, b, list, n_list, kick, g, fail, fused, defer,
                                        false, &n_bulk_contacts);
    for (size_t i = begin_block, h = 0; !bulk && i < end_block; i++) {
        if (!(h < n_list && pairs[list[h]].i == i)) { /* no listed pairs */
            close_unlisted(P, i, &e, e_end, kick, g);
            continue;
        }
        struct wetdem_vec3 f = vec3(0, 0, 0), t = vec3(0, 0, 0);
        for (; h < n_list && pairs[list[h]].i == i; h++) {
            size_t q = list[h], j = pairs[q].j;
            struct wetdem_vec3 d;
            const struct wetdem_many_mix* x;
            if (fused) {
                if (j >= end_block) /* a cross pair: tested and evaluated in phase 1 */
                    continue;
                /* the skip time set only for those beyond: those within range (most here)
                   keep theirs, which came before this pass's clock and so before every later
                   one (until a restart, after which all are tested) */
                if (!within_reach(P, q, i, j, periodic, single, false, &d, &x)) {
                    beyond_reach(P, P_out, q, vec3_dot(d, d), true);
                    continue;
                }
                n_near++;
            } else {
                n_near += near[h];
                if (!near[h]) { /* listed for its flags */
                    leave_range(P_out, q);
                    continue;
                }
                pair_delta(P, i, j, periodic, single, &d, &x);
            }
            struct wetdem_many_pair_out o;
            unsigned char fl = near_candidate(P, q, i, j, d, x, &o, fail, NULL, 0,
                                              work_slot(P->pair_work, P->n_models, i));
            add_pair(P, j, fl, &o, &f, &t);
        }
        close_particle(P, i, &e, e_end, f, t, kick, g);
    }
#pragma omp atomic
    m->pass_skipped += n_skipped;
#pragma omp atomic
    m->pass_candidates += q_end - q_begin;
#pragma omp atomic
    m->pass_near += n_near;
    if (bulk) {
#pragma omp atomic
        m->bulk_contacts += n_bulk_contacts;
    }
}

/* Phase 2 of block b (pairs_of_block_as), compiled apart for the one-loop pass in the common
 * case (one material pair, and no periodic axis or four pairs at a time) with and without four
 * pairs at a time (with and without films), the one-loop pass in general, and two loops (in
 * the common case with and without four pairs at a time and films). */
static void pairs_of_block(const struct pass* P, size_t b, bool kick, struct wetdem_vec3 g,
                           struct failure* fail)
{
    /* one material pair, and no periodic axis or four pairs at a time (whose kernel takes the
       minimum image) */
    bool common = P->nm == 1 && (!P->periodic || P->bulk);
    /* films: contacts and bridges apart mixed in the results (consume_four_at_a_time) */
    bool films = wetdem_many_bulk_films(&P->bulk_in);
    if (P->fused && common && P->bulk && films)
        pairs_of_block_as(P, b, kick, g, fail, true, true, true, true);
    else if (P->fused && common && P->bulk)
        pairs_of_block_as(P, b, kick, g, fail, true, true, true, false);
    else if (P->fused && common)
        pairs_of_block_as(P, b, kick, g, fail, true, true, false, false);
    else if (P->fused)
        pairs_of_block_as(P, b, kick, g, fail, true, false, false, false);
    else if (common && P->bulk && films)
        pairs_of_block_as(P, b, kick, g, fail, false, true, true, true);
    else if (common && P->bulk)
        pairs_of_block_as(P, b, kick, g, fail, false, true, true, false);
    else
        pairs_of_block_as(P, b, kick, g, fail, false, false, false, false);
}

/* The constants of every candidate pair (many.h: pair_lim2, and pair_cache for the lean
 * kernel), once per list build and kernel set-up: radii, masses and ranges do not change in
 * between. The same expressions as per evaluation, so the same bits. */
static int pair_constants(struct wetdem_sim* sim)
{
    struct wetdem_many* m = sim->many;
    if (m->pair_consts_ready && m->pair_consts_build == m->cl.n_builds)
        return WETDEM_OK;
    size_t np = m->cl.n_pairs, nm = (size_t)m->n_mix_materials;
    bool lean = m->lean.on;
    int form = m->lean.hertz_form;
    if (!reserve((void**)&m->pair_lim2, &m->pair_lim2_cap, np, sizeof *m->pair_lim2) ||
        (lean && !reserve((void**)&m->pair_cache, &m->pair_cache_cap, np, sizeof *m->pair_cache)))
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory for %zu pairs", np);
#pragma omp parallel for schedule(static) if (wetdem_many_parallel(m, sim->n_particles))
    for (size_t q = 0; q < np; q++) { /* each pair on its own: the same for any thread count */
        size_t i = m->cl.pairs[q].i, j = m->cl.pairs[q].j;
        const struct wetdem_particle *a = &sim->particles[i], *b = &sim->particles[j];
        const struct wetdem_many_mix* x = &m->mix[(size_t)a->material * nm + (size_t)b->material];
        m->pair_lim2[q] = reach2(m->xr, i, j, x->range);
        if (!lean)
            continue;
        double* c = m->pair_cache[q];
        c[0] = contact_reduced(a->radius, b->radius);
        c[1] = contact_reduced(contact_effective_mass(a), contact_effective_mass(b));
        c[2] = hertz_stiffness(x->e_star, c[0]);
        c[3] = form >= 0 ? hertz_damping_factor(x->hertz_damping[form], c[2], c[1]) : 0.0;
    }
    if (m->record) /* (a loop of its own: the one above is the benchmark's) */
        record_limits(sim);
    double lim2_max = 0; /* max is exact: the same for any thread count */
#pragma omp parallel for schedule(static)                                                          \
    reduction(max                                                                                  \
              : lim2_max) if (wetdem_many_parallel(m, sim->n_particles))
    for (size_t q = 0; q < np; q++)
        lim2_max = m->pair_lim2[q] > lim2_max ? m->pair_lim2[q] : lim2_max;
    /* every coordinate stays below x_build_max + skin/2 until the next build: margin of a
       difference of coordinates (struct skip_bound) */
    double margin = 1e-12 * (m->x_build_max + m->cl.skin);
    double d_max = sqrt(lim2_max) * (1 + 1e-9) + margin + m->cl.skin;
    m->skip_bound = (struct skip_bound){.rel = 1 + 3e-9,
                                        .abs = 3 * d_max * margin,
                                        .inv_2dmax = 1 / (2 * d_max) * (1 - 1e-12),
                                        .cap = m->cl.skin};
    m->pair_consts_build = m->cl.n_builds;
    m->pair_consts_ready = true;
    return WETDEM_OK;
}

/* Particles per chunk of the work sums (collect_pass_work): a constant, so that the sums do not
 * depend on the thread count. */
#define WORK_CHUNK 1024

/* Grows *a to n doubles, zero where it grew (the pass's work entries are zero between passes:
 * collect_pass_work clears them). */
static bool reserve_zeroed(double** a, size_t* cap, size_t n)
{
    if (n <= *cap)
        return true;
    if (!reserve((void**)a, cap, n, sizeof **a))
        return false;
    memset(*a, 0, n * sizeof **a);
    return true;
}

/* With an energy budget: room for the pass's work entries (many.h). */
static int reserve_work(struct wetdem_sim* sim)
{
    struct wetdem_many* m = sim->many;
    size_t nm = sim->n_models, n = sim->n_particles, nc = m->cross_first[m->n_blocks];
    size_t chunks = (n + WORK_CHUNK - 1) / WORK_CHUNK;
    if (!reserve_zeroed(&m->pair_work, &m->pair_work_cap, n * nm) ||
        !reserve_zeroed(&m->wall_work, &m->wall_work_cap, n * nm) ||
        !reserve_zeroed(&m->cross_work, &m->cross_work_cap, nc * nm) ||
        !reserve_zeroed(&m->chunk_work, &m->chunk_work_cap, chunks * 2 * nm))
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory for the energy budget");
    return WETDEM_OK;
}

/* The work of the pass, model by model, added to the budget, its entries cleared. Each
 * particle's entry holds the work of its pairs (i, j) evaluated in its block, in list order;
 * its cross pairs (j in a later block: larger j, so later in the list) are added after them
 * in list order (cross_q is sorted); so every entry is the sum of the particle's pairs in list
 * order, whatever the blocks. The entries, pairs and walls, are then summed in particle order
 * in chunks of WORK_CHUNK, and the chunks in order: the work does not depend on the blocks or
 * the thread count (before, per-thread sums made it depend on the blocks, which follow
 * measured times). */
static void collect_pass_work(struct wetdem_sim* sim, bool parallel)
{
    (void)parallel; /* (read by the pragma only: unused in a build without OpenMP) */
    struct wetdem_many* m = sim->many;
    size_t nm = sim->n_models, n = sim->n_particles, nc = m->cross_first[m->n_blocks];
    for (size_t e = 0; e < nc; e++) {
        double *from = m->cross_work + e * nm,
               *to = m->pair_work + m->cl.pairs[m->cross_q[e]].i * nm;
        for (size_t k = 0; k < nm; k++) {
            to[k] += from[k];
            from[k] = 0.0;
        }
    }
    size_t chunks = (n + WORK_CHUNK - 1) / WORK_CHUNK;
#pragma omp parallel for schedule(static) if (parallel)
    for (size_t c = 0; c < chunks; c++) {
        double* s = m->chunk_work + c * 2 * nm; /* pairs, then walls */
        for (size_t k = 0; k < 2 * nm; k++)
            s[k] = 0.0;
        size_t end = (c + 1) * WORK_CHUNK < n ? (c + 1) * WORK_CHUNK : n;
        for (size_t i = c * WORK_CHUNK; i < end; i++)
            for (size_t k = 0; k < nm; k++) {
                s[k] += m->pair_work[i * nm + k];
                s[nm + k] += m->wall_work[i * nm + k];
                m->pair_work[i * nm + k] = m->wall_work[i * nm + k] = 0.0;
            }
    }
    double pairs[WETDEM_MAX_MODELS] = {0}, walls[WETDEM_MAX_MODELS] = {0};
    for (size_t c = 0; c < chunks; c++)
        for (size_t k = 0; k < nm; k++) {
            pairs[k] += m->chunk_work[c * 2 * nm + k];
            walls[k] += m->chunk_work[c * 2 * nm + nm + k];
        }
    for (size_t k = 0; k < nm; k++) {
        m->energy.work_pair[k] += pairs[k];
        m->energy.work_wall[k] += walls[k];
        m->energy.last_pair[k] = pairs[k];
        m->energy.last_wall[k] = walls[k];
    }
}

/* Whether a history of len doubles is all +0.0 bits (a fresh one, wetdem_sim_history_init). */
static bool history_is_fresh(const double* h, size_t len)
{
    static const double zero[64]; /* (history_len <= 64, sim_many.c HISTORY_MAX) */
    return memcmp(h, zero, len * sizeof *h) == 0;
}

/* The histories of the pairs and particle-wall pairs as the state gives them, kept in
 * m->old_history (unused between list builds, whose remap needs room for the pairs anyway)
 * for put_given_histories: the pairs' whole, then of the n_particles x n_walls wall histories
 * only those that are not fresh, each after its index (a double, exact below 2^53), so that
 * the buffer grows by no more than the pairs need (all wall histories would add ~160 bytes a
 * particle in a closed box). *kept: whether anything was kept. For the first pass of a run. */
static int keep_given_histories(struct wetdem_sim* sim, bool* kept)
{
    struct wetdem_many* m = sim->many;
    size_t len = sim->history_len, pairs = m->cl.n_pairs * len, rows = 0;
    size_t n_rows = sim->n_particles * sim->n_walls;
    *kept = false;
    if (len == 0)
        return WETDEM_OK;
    for (size_t r = 0; r < n_rows; r++)
        rows += !history_is_fresh(m->wall_history + r * len, len);
    size_t n = pairs + rows * (len + 1) + 1;
    if (!reserve((void**)&m->old_history, &m->old_history_cap, n, sizeof(double)))
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory for %zu pair histories",
                               m->cl.n_pairs + rows);
    double* o = m->old_history;
    if (pairs) /* (no memcpy from a NULL array, even of nothing) */
        memcpy(o, m->history, pairs * sizeof(double));
    o += pairs;
    *o++ = (double)rows;
    for (size_t r = 0; r < n_rows; r++)
        if (!history_is_fresh(m->wall_history + r * len, len)) {
            *o++ = (double)r;
            memcpy(o, m->wall_history + r * len, len * sizeof(double));
            o += len;
        }
    *kept = true;
    return WETDEM_OK;
}

/* Puts the histories kept by keep_given_histories back (kept = false: none kept, a pass after
 * the first or no histories): the pairs', and the wall histories fresh but for those kept. */
static void put_given_histories(struct wetdem_sim* sim, bool kept)
{
    struct wetdem_many* m = sim->many;
    size_t len = sim->history_len, pairs = m->cl.n_pairs * len;
    if (!kept)
        return;
    const double* o = m->old_history;
    if (pairs)
        memcpy(m->history, o, pairs * sizeof(double));
    o += pairs;
    size_t rows = (size_t)*o++;
    for (size_t r = 0; r < sim->n_particles * sim->n_walls; r++)
        wetdem_sim_history_init(sim, m->wall_history + r * len);
    for (size_t q = 0; q < rows; q++, o += len + 1)
        memcpy(m->wall_history + (size_t)o[0] * len, o + 1, len * sizeof(double));
}

int wetdem_sim_many_forces(struct wetdem_sim* sim, enum wetdem_many_end end)
{
    bool kick = end == WETDEM_MANY_END_KICK, drift = end == WETDEM_MANY_END_STEP;
    struct wetdem_many* m = sim->many;
    int st = wetdem_sim_many_prepare(sim);
    if (st != WETDEM_OK)
        return st;
    size_t n = sim->n_particles;
    bool parallel = wetdem_many_parallel(m, n);
    size_t nb = parallel ? (size_t)omp_get_max_threads() : 1;
    nb = nb < WETDEM_MANY_MAX_BLOCKS ? nb : WETDEM_MANY_MAX_BLOCKS;
    st = index_blocks(sim, nb);
    if (st != WETDEM_OK)
        return st;
    st = pair_constants(sim);
    /* the first pass of a run gives the forces at t0 of the state as given (the top of this
       file): springs not advanced, and nothing it writes into the histories kept (a spring set
       to the Coulomb limit, a min-separation record); a test per pass, none per pair */
    m->advance = m->started ? m->dt : 0.0;
    bool given = false;
    if (st == WETDEM_OK && !m->started)
        st = keep_given_histories(sim, &given);
    if (st == WETDEM_OK && m->set.energy_budget)
        st = reserve_work(sim);
    if (st != WETDEM_OK)
        return st;
    struct failure fail = {0};
    struct wetdem_vec3 g =
        vec3(sim->settings.gravity_x, sim->settings.gravity_y, sim->settings.gravity_z);
    if (!reserve((void**)&m->skip_until, &m->skip_until_cap, m->cl.n_pairs, sizeof *m->skip_until))
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory for %zu pairs", m->cl.n_pairs);
    if (!m->skip_on && ++m->skip_off_passes >= 32) { /* keep the times again (many.h) */
        m->skip_on = !m->no_skip;
        m->skip_off_passes = 0;
    }
    bool skip = m->skip_ready; /* (kept by the previous pass, so skip_on) */
    bool fused = skip && (m->fuse_mode == 2 || (m->fuse_mode == 0 && m->fuse_on));
    m->pass_candidates = m->pass_skipped = m->pass_near = 0;
    m->fused_passes += fused;
    struct pass P = {.sim = sim,
                     .m = m,
                     .force = m->force,
                     .torque = m->torque,
                     .p = sim->particles,
                     .xr = m->xr,
                     .pairs = m->cl.pairs,
                     .flags = m->flags,
                     .lim2 = m->pair_lim2,
                     .bound = m->skip_bound,
                     .skip_until = m->skip_until,
                     .clock = m->drift_clock,
                     .skip = skip,
                     .fused = fused,
                     .maintain = m->skip_on,
                     .history = m->history,
                     .len = sim->history_len,
                     .nm = (size_t)m->n_mix_materials,
                     .periodic = m->periodic_any,
                     .lean = m->lean.on,
                     .zeroed = m->sums_zeroed == n,
                     .pair_work = m->set.energy_budget ? m->pair_work : NULL,
                     .cross_work = m->set.energy_budget ? m->cross_work : NULL,
                     .n_models = sim->n_models};
    /* four pairs at a time for the lean kernel in the common case: the geometry and film
       terms of every listed candidate, then the solid contacts among them */
    if (P.lean && P.nm == 1 && !m->bulk_off) {
        const struct wetdem_many_mix* x = m->mix;
        const struct wetdem_many_lean* L = &m->lean;
        P.bulk = wetdem_many_bulk_choose(m->bulk_isa);
        P.bulk_in = (struct wetdem_many_bulk_in){
            .xr = m->xr,
            .vw = (const struct wetdem_vec3(*)[2])m->vw,
            .vwh = (const struct wetdem_vec3(*)[2])m->vwh,
            .pairs = m->cl.pairs,
            .lim2 = m->pair_lim2,
            .film = x->film,
            .film_h_min = x->film_h_min,
            .range = x->range,
            .axis_periodic = {m->cl.box.periodic[0], m->cl.box.periodic[1], m->cl.box.periodic[2]},
            .box_len = {m->cl.box.hi[0] - m->cl.box.lo[0], m->cl.box.hi[1] - m->cl.box.lo[1],
                        m->cl.box.hi[2] - m->cl.box.lo[2]},
            .sb_coef = 6.0 * M_PI * x->viscosity, /* the first product of film_terms' */
            .cap_coef = 8.0 * M_PI,
            .surface_tension = x->surface_tension,
            .sb = m->lean.sb,
            .sb_nc = (int)m->lean.sb_below == THIN_FILM_BELOW_NC,
            .capillary = m->lean.capillary,
            .hertz_form = L->hertz_form,
            .mindlin = L->mindlin,
            .n_normal = L->n_normal,
            .budget = m->set.energy_budget,
            .cache = (const double(*)[4])m->pair_cache,
            .history = m->history,
            .len = sim->history_len,
            .spring_off = L->mindlin_off,
            .dt = m->advance,
            .g_star = x->g_star,
            .mu = L->mindlin_lub ? x->friction_lub : x->friction_dry,
            .tangential_factor = x->mindlin_damping};
        memcpy(P.bulk_in.normal, L->normal, sizeof P.bulk_in.normal);
        if (sim->n_walls <= 64) { /* (the wall masks) */
            P.bulk_walls = wetdem_many_bulk_walls_choose(m->bulk_isa);
            P.bulk_in.walls = sim->walls;
            P.bulk_in.n_walls = sim->n_walls;
            P.bulk_in.wall_history = m->wall_history;
            P.bulk_in.m_eff = m->m_eff;
            P.bulk_in.e_star = x->e_star;
            P.bulk_in.hertz_coef = L->hertz_form >= 0 ? x->hertz_damping[L->hertz_form] : 0.0;
        }
    }
    m->bulk_passes += P.bulk != NULL;
    /* one region: cross pairs, a barrier, then each block on its own, and with `drift` the
       kicks and drifts of its particles, whose forces are then complete: the cross pairs were
       evaluated before the barrier, the block's own pairs and the reactions they give are
       summed, and no other block reads the block's particles after the barrier (its lanes of
       cross pairs read their first particle instead). Their time counts as the block's, so
       the blocks are balanced with them. */
#pragma omp parallel if (parallel)
    {
        size_t t = (size_t)omp_get_thread_num(), nt = (size_t)omp_get_num_threads();
        cross_pairs_share(&P, t, nt, &fail);
#pragma omp barrier
        for (size_t b = t; b < nb; b += nt) {
            double t0 = omp_get_wtime();
            start_sums_of_block(&P, b, &fail);
            pairs_of_block(&P, b, kick, g, &fail);
            if (drift) {
                double t1 = omp_get_wtime();
                m->drift_v2[b] = wetdem_sim_many_drift_range(sim, m->blk[b], m->blk[b + 1]);
                if (t == 0) /* (the phases' wall time, as the master thread sees it) */
                    m->drift_seconds += omp_get_wtime() - t1;
            }
            m->block_time[b] += omp_get_wtime() - t0;
        }
    }
    put_given_histories(sim, given); /* (also after a failure: the next call starts again) */
    if (m->set.energy_budget)
        collect_pass_work(sim, parallel);
    m->drift_passes += drift;
    m->blocks_passes++;
    m->sums_zeroed = 0;
    m->skipped_tests += m->pass_skipped;
    uint64_t share = m->skip_share ? m->skip_share : WETDEM_MANY_SKIP_SHARE;
    if (skip && share * m->pass_skipped < m->pass_candidates && !m->skip_always)
        m->skip_on = false; /* for 32 passes or until the next list build (many.h) */
    m->skip_ready = m->skip_on && fail.status == WETDEM_OK; /* every candidate has its time */
    m->fuse_on = 4 * m->pass_near >= 3 * (m->pass_candidates - m->pass_skipped); /* (many.h) */
    if (fail.status != WETDEM_OK)
        return report_failure(sim, &fail);
    sim->engine.stats.force_evals++;
    sim->engine.stats.pair_evals += m->cl.n_pairs + sim->n_particles * sim->n_walls;
    return WETDEM_OK;
}

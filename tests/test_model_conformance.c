/*
 * test_model_conformance.c — conformance matrix over EVERY model of wetdem_model_registry():
 * each force model, in every variant of its enumerated parameters (hertz/nijssen damping,
 * mindlin friction, thin-film below_hmin), for two fluids (the second makes nijssen's h_eps
 * exceed the roughness), two minimum separations (inside the film and above it, so the
 * Punch Eq. 14 cap acts), three motions (approaching with sliding and spins, separating,
 * spins only) and gaps from solid overlap to beyond every range, is checked for
 *   - i<->j swap symmetry with unequal radii, masses and materials, both contacts built from
 *     the particles by wetdem_contact_from_particles: equal normal force, opposite
 *     tangential force, exchanged torques, over two committed steps of history;
 *   - torque consistency: torque_i = -R_i n x F_t and torque_j = -R_j n x F_t, hence
 *     torque_j = (R_j/R_i) torque_i (the LAMMPS #1933 bug class: a torque on j computed with
 *     R_i), and F_t perpendicular to n;
 *   - zero force and torque beyond range(), even with a history taken in contact;
 *   - continuity at every gap thresholds() reports, except at the jumps the model's doc
 *     names (listed in documented_jump(), and checked to be real jumps);
 *   - no branch that thresholds() fails to report (a scan of the gap axis);
 * and min-separation models for swap invariance, and those with a record_range for the gap
 * at which their own record ends being that range. Then the pair geometry of src/contact.c
 * (mixing rules, kinematics with spin lever arms, walls, fixed particles) against hand
 * arithmetic, and the hard impulse against Davis Appendix A generalised to unequal spheres
 * at a finite gap (A1, A9-A11 with I_j, A30-A33, A36) plus its energy balance.
 */
#include <stdbool.h>
#include <stdlib.h>

#include "harness.h"
#include "test_vec.h"

#define MAX_PARAM_DOUBLES 16
#define MAX_HISTORY 16
#define MAX_VARIANTS 8

/* Pair: sphere a (i) of radius 2 mm and mass 0.07 kg, sphere b (j) of 5 mm and 1.2 kg.
 * R* = 2e-3 * 5e-3 / 7e-3 = 1.4285714e-3 m. */
#define RA 2e-3
#define RB 5e-3
#define MA 0.07
#define MB 1.2
#define DT 1e-6 /* [s] time since the history was committed */

static const struct wetdem_material mat_a = {.density = 7800,
                                             .youngs_modulus = 200e9,
                                             .poisson_ratio = 0.3,
                                             .restitution = 0.9,
                                             .friction_dry = 0.3,
                                             .friction_lub = 0.05,
                                             .roughness = 0.4e-6,
                                             .film = 60e-6};
static const struct wetdem_material mat_b = {.density = 2500,
                                             .youngs_modulus = 70e9,
                                             .poisson_ratio = 0.22,
                                             .restitution = 0.8,
                                             .friction_dry = 0.2,
                                             .friction_lub = 0.03,
                                             .roughness = 1.6e-6,
                                             .film = 40e-6};
/* delta = 100 um, h_sigma = 1 um. With mu = 200 Pa s and v_n = 0.3 m/s nijssen's
 * h_eps = 0.37 R* (mu v/(E* R*))^(2/5) = 1.9 um > h_sigma (E* = 5.51e10 Pa). */
static const struct wetdem_fluid fluids[] = {{0.5, 0.02, 1000}, {200.0, 0.03, 1200}};
static const double h_mins[] = {1e-6, 200e-6};

/* Motions: relative normal approach speed, tangential sliding of the centres, spins. */
struct motion {
    const char* name;
    double v_n;                 /* [m/s] > 0 approaching */
    double slide_1, slide_2;    /* centre sliding of i relative to j along t1, t2 [m/s] */
    struct wetdem_vec3 omega_a; /* [rad/s] */
    struct wetdem_vec3 omega_b;
};
static const struct motion motions[] = {
    {"approach+slide+spin", 0.3, 0.2, -0.07, {3, -8, 5}, {-6, 2, 4}},
    {"separate+slide+spin", -0.15, -0.1, 0.12, {-4, 1, 9}, {2, 7, -3}},
    {"spin only", 0.05, 0.0, 0.0, {40, -25, 10}, {-15, 30, 20}},
};
#define N_MOTIONS (sizeof motions / sizeof motions[0])

static const double scan_gaps[] = {-3e-6, -2e-7, 0.3e-6, 0.8e-6, 1.5e-6, 5e-6,
                                   50e-6, 99e-6, 0.5e-3, 1.3e-3, 2e-3};
#define N_GAPS (sizeof scan_gaps / sizeof scan_gaps[0])

/* ---- model variants: defaults, plus every other word of every enumerated parameter ---- */

struct variant {
    const struct wetdem_model* model;
    double params[MAX_PARAM_DOUBLES];
    char label[96];
};

static size_t model_variants(const struct wetdem_model* m, struct variant* out)
{
    if (m->params_size > sizeof out[0].params)
        fail_msg("%s: params struct of %zu bytes exceeds the test's storage", m->name,
                 m->params_size);
    size_t n = 0;
    out[n].model = m;
    memset(out[n].params, 0, sizeof out[n].params);
    wetdem_param_init_defaults(m->params, out[n].params);
    snprintf(out[n].label, sizeof out[n].label, "%s (defaults)", m->name);
    n++;
    for (const struct wetdem_param_desc* d = m->params; d && d->name; d++) {
        if (!d->choices)
            continue;
        for (size_t w = 0; d->choices[w]; w++) {
            if ((double)w == d->default_value)
                continue;
            if (n == MAX_VARIANTS)
                fail_msg("%s: more than %d variants", m->name, MAX_VARIANTS);
            out[n] = out[0];
            *(double*)((char*)out[n].params + d->offset) = (double)w;
            snprintf(out[n].label, sizeof out[n].label, "%s (%s = %s)", m->name, d->name,
                     d->choices[w]);
            n++;
        }
    }
    return n;
}

/* Value of the enumerated parameter `name` of a variant as its word, or "" if absent. */
static const char* variant_word(const struct variant* v, const char* name)
{
    const struct wetdem_param_desc* d = wetdem_param_find(v->model->params, name);
    if (!d || !d->choices)
        return "";
    return d->choices[(size_t) * (const double*)((const char*)v->params + d->offset)];
}

static bool is_force_model(const struct wetdem_model* m)
{
    return m->kind == WETDEM_MODEL_CONTACT || m->kind == WETDEM_MODEL_FLUID;
}

/* ---- pair configurations ---- */

struct config {
    const struct wetdem_fluid* fluid;
    double h_min;
    const struct motion* motion;
};

/* The unit normal from b to a: (2, -3, 6)/7, and two tangents completing a right-handed
 * frame. */
static void frame(struct wetdem_vec3* n, struct wetdem_vec3* t1, struct wetdem_vec3* t2)
{
    *n = v3(2.0 / 7.0, -3.0 / 7.0, 6.0 / 7.0);
    *t1 = v3(3.0 / sqrt(13.0), 2.0 / sqrt(13.0), 0.0);
    *t2 = cross(*n, *t1);
}

/* Particles a and b at surface gap `gap` [m] moving as cfg says. */
static void make_particles(const struct config* cfg, double gap, struct wetdem_particle* a,
                           struct wetdem_particle* b)
{
    struct wetdem_vec3 n, t1, t2;
    frame(&n, &t1, &t2);
    memset(a, 0, sizeof *a);
    memset(b, 0, sizeof *b);
    b->pos = v3(0.01, -0.02, 0.005);
    b->vel = v3(0.05, 0.02, -0.03);
    b->omega = cfg->motion->omega_b;
    b->radius = RB;
    b->mass = MB;
    b->material = 1;
    a->pos = add(b->pos, scale(n, RA + RB + gap));
    struct wetdem_vec3 rel = add(scale(n, -cfg->motion->v_n), add(scale(t1, cfg->motion->slide_1),
                                                                  scale(t2, cfg->motion->slide_2)));
    a->vel = add(b->vel, rel);
    a->omega = cfg->motion->omega_a;
    a->radius = RA;
    a->mass = MA;
}

/* The contact with a as i (swapped = false) or b as i (swapped = true). */
static struct wetdem_contact make_contact(const struct config* cfg, double gap, bool swapped)
{
    struct wetdem_particle a, b;
    make_particles(cfg, gap, &a, &b);
    struct wetdem_contact c;
    if (swapped)
        wetdem_contact_from_particles(&c, &b, &mat_b, &a, &mat_a, cfg->fluid);
    else
        wetdem_contact_from_particles(&c, &a, &mat_a, &b, &mat_b, cfg->fluid);
    /* the intended gap exactly (the placement rounds it by ~1e-18 m; contact.c's own gap
     * arithmetic is checked in test_conformance_contact_mixing_and_kinematics) */
    c.gap = gap;
    c.h_min = cfg->h_min;
    c.dt = DT;
    return c;
}

/* Force of a variant with the given history (updated in place). */
static struct wetdem_pair_force eval_force(const struct variant* v, const struct wetdem_contact* c,
                                           double* history)
{
    struct wetdem_pair_force f;
    memset(&f, 0, sizeof f);
    int st = v->model->pair(v->params, c, history, &f);
    if (st != WETDEM_OK)
        fail_msg("%s: pair() returned %s", v->label, wetdem_status_name(st));
    return f;
}

static struct wetdem_pair_force eval_fresh(const struct variant* v, const struct wetdem_contact* c)
{
    double history[MAX_HISTORY] = {0};
    return eval_force(v, c, history);
}

/* Largest absolute component of a force record, torques divided by their lever arms so that
 * every entry is a force [N]. */
static double force_scale(const struct wetdem_pair_force* f, double r_i, double r_j)
{
    double s = fabs(f->f_normal);
    const double* t = &f->f_tan.x;
    const double* ti = &f->torque_i.x;
    const double* tj = &f->torque_j.x;
    for (int k = 0; k < 3; k++) {
        s = fmax(s, fabs(t[k]));
        s = fmax(s, fabs(ti[k]) / r_i);
        s = fmax(s, fabs(tj[k]) / r_j);
    }
    return s;
}

static double force_difference(const struct wetdem_pair_force* f, const struct wetdem_pair_force* g,
                               double r_i, double r_j)
{
    struct wetdem_pair_force d;
    d.f_normal = f->f_normal - g->f_normal;
    d.f_tan = sub(f->f_tan, g->f_tan);
    d.torque_i = sub(f->torque_i, g->torque_i);
    d.torque_j = sub(f->torque_j, g->torque_j);
    return force_scale(&d, r_i, r_j);
}

static bool is_all_zero(const struct wetdem_pair_force* f)
{
    return force_scale(f, 1.0, 1.0) == 0.0;
}

static bool is_finite_force(const struct wetdem_pair_force* f)
{
    return isfinite(f->f_normal) && isfinite(norm(f->f_tan)) && isfinite(norm(f->torque_i)) &&
           isfinite(norm(f->torque_j));
}

/* Calls fn(variant, config) for every force model variant and every configuration. */
typedef void (*config_fn)(const struct variant* v, const struct config* cfg, void* ctx);

static size_t for_each_force_config(config_fn fn, void* ctx)
{
    size_t n_calls = 0;
    const struct wetdem_model* const* reg = wetdem_model_registry();
    for (size_t k = 0; reg[k]; k++) {
        if (!is_force_model(reg[k]))
            continue;
        if (!reg[k]->pair || !reg[k]->range || !reg[k]->thresholds)
            fail_msg("force model %s lacks pair(), range() or thresholds()", reg[k]->name);
        if (reg[k]->history_len > MAX_HISTORY)
            fail_msg("%s: history of %zu doubles exceeds the test's storage", reg[k]->name,
                     reg[k]->history_len);
        struct variant vars[MAX_VARIANTS];
        size_t nv = model_variants(reg[k], vars);
        for (size_t v = 0; v < nv; v++)
            for (size_t f = 0; f < 2; f++)
                for (size_t h = 0; h < 2; h++)
                    for (size_t m = 0; m < N_MOTIONS; m++) {
                        struct config cfg = {&fluids[f], h_mins[h], &motions[m]};
                        fn(&vars[v], &cfg, ctx);
                        n_calls++;
                    }
    }
    return n_calls;
}

/* ======================================================================================== */
/* i <-> j symmetry and torque consistency                                                   */
/* ======================================================================================== */

/* torque_i = -R_i n x F_t, torque_j = -R_j n x F_t and F_t . n = 0. Tolerance 1e-13 of R |F_t|:
 * the model computes the same cross product and scales it (a few roundings of 1.1e-16). */
static void check_contact_point_torques(const struct variant* v, const struct wetdem_contact* c,
                                        const struct wetdem_pair_force* f, const char* where)
{
    struct wetdem_vec3 nxf = cross(c->normal, f->f_tan);
    double ft = norm(f->f_tan);
    double ei = norm(sub(f->torque_i, scale(nxf, -c->radius_i)));
    double ej = norm(sub(f->torque_j, scale(nxf, -c->radius_j)));
    if (!(ei <= 1e-13 * c->radius_i * ft) || !(ej <= 1e-13 * c->radius_j * ft) ||
        !(fabs(dot(f->f_tan, c->normal)) <= 1e-13 * ft))
        fail_msg("%s %s: torques are not those of F_t at the contact point: |F_t| = %g N, "
                 "|T_i + R_i n x F_t| = %g, |T_j + R_j n x F_t| = %g N m, F_t.n = %g N",
                 v->label, where, ft, ei, ej, dot(f->f_tan, c->normal));
}

/* The swapped evaluation g must give the same normal force, the opposite tangential force and
 * the exchanged torques. Tolerance 1e-13 relative to the force scale: contact.c builds the two
 * contacts from negated operands, exact in IEEE arithmetic, so any difference beyond a few
 * roundings is an asymmetry of the model. */
static void check_swapped(const struct variant* v, const struct wetdem_pair_force* f,
                          const struct wetdem_pair_force* g, const char* where)
{
    struct wetdem_pair_force mirrored;
    mirrored.f_normal = g->f_normal;
    mirrored.f_tan = scale(g->f_tan, -1.0);
    mirrored.torque_i = g->torque_j;
    mirrored.torque_j = g->torque_i;
    double s = force_scale(f, RA, RB), d = force_difference(f, &mirrored, RA, RB);
    if (!(d <= 1e-13 * s))
        fail_msg("%s %s: i<->j swap breaks action-reaction: F_n %.17g vs %.17g, "
                 "F_t.x %.17g vs %.17g, difference %g of scale %g N",
                 v->label, where, f->f_normal, g->f_normal, f->f_tan.x, -g->f_tan.x, d, s);
}

static void swap_config(const struct variant* v, const struct config* cfg, void* ctx)
{
    size_t* n_nonzero = ctx;
    for (size_t g = 0; g < N_GAPS; g++) {
        char where[160];
        snprintf(where, sizeof where, "[mu %g, h_min %g, %s, gap %g]", cfg->fluid->viscosity,
                 cfg->h_min, cfg->motion->name, scan_gaps[g]);
        struct wetdem_contact c = make_contact(cfg, scan_gaps[g], false);
        struct wetdem_contact s = make_contact(cfg, scan_gaps[g], true);
        double hc[MAX_HISTORY] = {0}, hs[MAX_HISTORY] = {0};
        /* two steps: fresh history, then each orientation's own advanced history */
        for (int step = 0; step < 2; step++) {
            struct wetdem_pair_force f = eval_force(v, &c, hc);
            struct wetdem_pair_force b = eval_force(v, &s, hs);
            if (!is_finite_force(&f) || !is_finite_force(&b))
                fail_msg("%s %s: non-finite force", v->label, where);
            check_swapped(v, &f, &b, where);
            check_contact_point_torques(v, &c, &f, where);
            check_contact_point_torques(v, &s, &b, where);
            *n_nonzero += norm(f.f_tan) > 0.0;
        }
    }
}

/* Every force model of the registry, every variant and configuration, gaps from overlap to
 * beyond the ranges: action-reaction with unequal spheres and contact-point torques. */
static void test_conformance_swap_symmetry_and_torques(void** state)
{
    (void)state;
    size_t n_tangential = 0;
    size_t n = for_each_force_config(swap_config, &n_tangential);
    /* today 10 force models in 17 variants, 12 configurations each: 204 */
    assert_true(n >= 17 * 12);
    /* the torque checks must have seen tangential forces (mindlin, nijssen, davis, nase) */
    assert_true(n_tangential > 100);
}

/* The contact built with b as i is the mirror of the one with a as i
 * (wetdem_contact_swapped): geometry and mixing are symmetric, bit for bit. */
static void test_conformance_contact_swap_is_mirror(void** state)
{
    (void)state;
    for (size_t m = 0; m < N_MOTIONS; m++) {
        struct config cfg = {&fluids[0], 1e-6, &motions[m]};
        struct wetdem_contact c = make_contact(&cfg, 3e-6, false);
        struct wetdem_contact s = make_contact(&cfg, 3e-6, true);
        struct wetdem_contact w = wetdem_contact_swapped(&c);
        /* exact: negations and commutative operations only */
        CHECK_REL(s.gap, w.gap, 0);
        CHECK_REL(s.v_n, w.v_n, 0);
        CHECK_REL(s.r_eff, w.r_eff, 0);
        CHECK_REL(s.m_eff, w.m_eff, 0);
        CHECK_REL(s.e_star, w.e_star, 0);
        CHECK_REL(s.g_star, w.g_star, 0);
        CHECK_REL(s.radius_i, w.radius_i, 0);
        CHECK_REL(s.radius_j, w.radius_j, 0);
        CHECK_REL(s.normal.x, w.normal.x, 0);
        CHECK_REL(s.normal.z, w.normal.z, 0);
        CHECK_REL(s.v_t.x, w.v_t.x, 0);
        CHECK_REL(s.v_t.y, w.v_t.y, 0);
        CHECK_REL(s.v_t.z, w.v_t.z, 0);
        CHECK_REL(s.restitution, w.restitution, 0);
        CHECK_REL(s.friction_dry, w.friction_dry, 0);
        CHECK_REL(s.roughness, w.roughness, 0);
        CHECK_REL(s.film, w.film, 0);
    }
}

/* Min-separation models: h_min of a pair does not depend on which sphere is i, over two
 * committed steps of history. Exact: the inputs are identical. */
static void test_conformance_min_separation_swap_invariant(void** state)
{
    (void)state;
    const struct wetdem_model* const* reg = wetdem_model_registry();
    size_t n_models = 0;
    for (size_t k = 0; reg[k]; k++) {
        if (reg[k]->kind != WETDEM_MODEL_MIN_SEPARATION)
            continue;
        n_models++;
        assert_non_null(reg[k]->min_separation);
        struct variant vars[MAX_VARIANTS];
        size_t nv = model_variants(reg[k], vars);
        for (size_t v = 0; v < nv; v++)
            for (size_t m = 0; m < N_MOTIONS; m++)
                for (size_t g = 0; g < N_GAPS; g++) {
                    struct config cfg = {&fluids[1], 1e-6, &motions[m]};
                    struct wetdem_contact c = make_contact(&cfg, scan_gaps[g], false);
                    struct wetdem_contact s = make_contact(&cfg, scan_gaps[g], true);
                    double hc[MAX_HISTORY] = {0}, hs[MAX_HISTORY] = {0};
                    for (int step = 0; step < 2; step++) {
                        double a = reg[k]->min_separation(vars[v].params, &c, hc);
                        double b = reg[k]->min_separation(vars[v].params, &s, hs);
                        if (!(a == b) || !(a >= 0.0) || !isfinite(a))
                            fail_msg("%s: h_min %g vs swapped %g at gap %g", vars[v].label, a, b,
                                     scan_gaps[g]);
                    }
                }
    }
    assert_true(n_models == 5);
}

/* Min-separation models with a record of the encounter (record_range: ehd, max, glass): the
 * hook is theirs only; its gap is finite, >= 0 and the same for the swapped pair; and it is
 * where the model's own record ends, which the engines rely on (they evaluate the model up to
 * that gap beyond the force range, and give a fresh history beyond): a record of a fast
 * approach is still there after an evaluation at record_range, and gone (the history fresh,
 * h_min as for a fresh history) after one a relative 1e-12 beyond it. */
static void test_conformance_record_range_is_where_the_record_ends(void** state)
{
    (void)state;
    const struct wetdem_model* const* reg = wetdem_model_registry();
    size_t n_models = 0;
    for (size_t k = 0; reg[k]; k++) {
        if (reg[k]->kind != WETDEM_MODEL_MIN_SEPARATION) {
            assert_null(reg[k]->record_range);
            continue;
        }
        if (!reg[k]->record_range)
            continue;
        n_models++;
        struct variant vars[MAX_VARIANTS];
        size_t nv = model_variants(reg[k], vars);
        for (size_t v = 0; v < nv; v++) {
            struct config cfg = {&fluids[1], 1e-6, &motions[0]};
            struct wetdem_contact c = make_contact(&cfg, 1e-7, false);
            struct wetdem_contact s = make_contact(&cfg, 1e-7, true);
            double record = reg[k]->record_range(vars[v].params, &c);
            if (!(record >= 0.0 && isfinite(record)) ||
                !(record == reg[k]->record_range(vars[v].params, &s)))
                fail_msg("%s: record range %g, swapped %g", vars[v].label, record,
                         reg[k]->record_range(vars[v].params, &s));
            for (int beyond = 0; beyond < 2; beyond++) {
                double h[MAX_HISTORY] = {0}, fresh[MAX_HISTORY] = {0};
                c.v_n = 2.0; /* the record: a fast approach well inside */
                c.gap = 0.5 * record;
                reg[k]->min_separation(vars[v].params, &c, h);
                c.v_n = 0.1; /* then a slow one at the record range, or just beyond */
                c.gap = beyond ? record * (1 + 1e-12) + 1e-300 : record;
                double h_min = reg[k]->min_separation(vars[v].params, &c, h);
                double h_fresh = reg[k]->min_separation(vars[v].params, &c, fresh);
                bool is_fresh = !memcmp(h, fresh, reg[k]->history_len * sizeof h[0]);
                if (beyond ? !(is_fresh && h_min == h_fresh) : is_fresh)
                    fail_msg("%s: at %s record range %g m the record is %s", vars[v].label,
                             beyond ? "just beyond its" : "its", record, beyond ? "kept" : "gone");
            }
        }
    }
    assert_true(n_models == 3);
}

/* ======================================================================================== */
/* Zero beyond range()                                                                       */
/* ======================================================================================== */

static void beyond_range_config(const struct variant* v, const struct config* cfg, void* ctx)
{
    (void)ctx;
    /* a history taken in solid contact and inside every range: a stale spring or speed record
     * must not leak beyond the range */
    double dirty[MAX_HISTORY] = {0};
    struct wetdem_contact in = make_contact(cfg, -2e-7, false);
    eval_force(v, &in, dirty);
    eval_force(v, &in, dirty);
    double range = v->model->range(v->params, &in);
    if (!(range >= 0.0) || !isfinite(range))
        fail_msg("%s: range %g", v->label, range);
    const double probes[] = {nextafter(range, INFINITY), range * (1 + 1e-9) + 1e-15,
                             1.5 * range + 1e-9, range + 1e-3, range + 0.5};
    for (size_t p = 0; p < sizeof probes / sizeof probes[0]; p++) {
        struct wetdem_contact c = make_contact(cfg, probes[p], false);
        if (!(c.gap > range))
            continue; /* the placement rounded the gap back onto the range */
        double h[MAX_HISTORY];
        memcpy(h, dirty, sizeof h);
        struct wetdem_pair_force f = eval_force(v, &c, h);
        double fresh[MAX_HISTORY] = {0};
        struct wetdem_pair_force g = eval_force(v, &c, fresh);
        if (!is_all_zero(&f) || !is_all_zero(&g))
            fail_msg("%s [%s, h_min %g]: force beyond range %g m at gap %.17g m: F_n = %g N, "
                     "|F_t| = %g N (fresh: %g N)",
                     v->label, cfg->motion->name, cfg->h_min, range, c.gap, f.f_normal,
                     norm(f.f_tan), g.f_normal);
    }
}

static void test_conformance_zero_beyond_range(void** state)
{
    (void)state;
    assert_true(for_each_force_config(beyond_range_config, NULL) > 0);
}

/* ======================================================================================== */
/* Continuity at the reported thresholds; the documented jumps                                */
/* ======================================================================================== */

/* The jumps that the models' docs state, by model and the role of the threshold:
 *   nijssen    at h_co                 "the force jumps only at h_co" (Nijssen Eq. 9)
 *   reynolds   at h_co; at 0 if h_min > 0   "jumps at h = 0 (from its h_min value) and at
 *                                      the cut-off"
 *   hooke      at 0                    "jump by gamma v_n where the overlap begins and ends"
 *   sb, db, davis  at h_min' < delta with below_hmin = c   (Punch Eq. 12: zero below h_min)
 *   nase       at delta ("the force drops to zero there"); at h_min' < delta with c
 *   capillary  at delta                the bridge forms and breaks at the film edge
 * hertz and mindlin are continuous at 0 (force ~ delta^(3/2), damping ~ delta^(1/4)); the
 * thin films with nc and nijssen at h_min and 0 are continuous. Every jump needs a non-zero
 * force on one side, so the motion must have a normal (or, for tangential laws, a tangential)
 * relative velocity; all motions here have both. */
static bool documented_jump(const struct variant* v, const struct wetdem_contact* c, double g)
{
    const char* name = v->model->name;
    double range = v->model->range(v->params, c);
    double delta = c->film, hm = fmin(c->h_min, c->film);
    bool is_c = strcmp(variant_word(v, "below_hmin"), "c") == 0;
    if (strcmp(name, "nijssen") == 0)
        return g == range;
    if (strcmp(name, "reynolds") == 0)
        return g == range || (g == 0.0 && c->h_min > 0.0);
    if (strcmp(name, "hooke") == 0)
        return g == 0.0;
    if (strcmp(name, "sb") == 0 || strcmp(name, "db") == 0 || strcmp(name, "davis") == 0)
        return is_c && g == hm && hm < delta;
    if (strcmp(name, "nase") == 0) /* with c and h_min' = delta it is zero on both sides */
        return (g == delta && !(is_c && hm >= delta)) || (is_c && g == hm && hm < delta);
    if (strcmp(name, "capillary") == 0)
        return g == delta;
    return false;
}

/* Force jump across gap g at half-width eps [m], relative to the force scale there. */
static double jump_across(const struct variant* v, const struct config* cfg, double g, double eps,
                          double* scale_out)
{
    struct wetdem_contact above = make_contact(cfg, g + eps, false);
    struct wetdem_contact below = make_contact(cfg, g - eps, false);
    struct wetdem_pair_force fa = eval_fresh(v, &above), fb = eval_fresh(v, &below);
    double s = fmax(force_scale(&fa, RA, RB), force_scale(&fb, RA, RB));
    *scale_out = s;
    return force_difference(&fa, &fb, RA, RB);
}

static void threshold_config(const struct variant* v, const struct config* cfg, void* ctx)
{
    size_t* n_jumps = ctx;
    struct wetdem_contact c = make_contact(cfg, 0.5 * cfg->h_min, false);
    double gaps[WETDEM_MAX_THRESHOLDS];
    double history[MAX_HISTORY] = {0};
    size_t ng = v->model->thresholds(v->params, &c, history, gaps);
    assert_true(ng >= 1 && ng <= WETDEM_MAX_THRESHOLDS);
    for (size_t q = 0; q < ng; q++) {
        double g = gaps[q];
        if (!(g >= 0.0) || !isfinite(g))
            fail_msg("%s: threshold %zu = %g", v->label, q, g);
        /* half-widths relative to the threshold, or to 1 um at g = 0 */
        double len = g > 0.0 ? g : 1e-6;
        double s_wide, s_narrow;
        double j_wide = jump_across(v, cfg, g, 1e-4 * len, &s_wide);
        double j_narrow = jump_across(v, cfg, g, 1e-12 * len, &s_narrow);
        bool jumps = documented_jump(v, &c, g);
        if (jumps) {
            /* a real jump does not shrink with the half-width */
            if (!(j_narrow > 1e-3 * s_narrow && j_narrow >= 0.5 * j_wide))
                fail_msg("%s [mu %g, h_min %g, %s]: documented jump at %g m is absent: "
                         "%g N (half-width %g) and %g N (%g) of scale %g N",
                         v->label, cfg->fluid->viscosity, cfg->h_min, cfg->motion->name, g, j_wide,
                         1e-4 * len, j_narrow, 1e-12 * len, s_narrow);
            (*n_jumps)++;
        } else {
            /* Continuous: the jump shrinks at least as the weakest branch, the Hertz damping
             * ~ delta^(1/4): a half-width 1e8 times smaller leaves at most (1e-8)^(1/4) =
             * 1e-2 of it (0.05 allows for the constant of the next order), or it is already
             * at rounding level (1e-12 of the scale). */
            if (!(j_narrow <= 1e-12 * s_narrow || j_narrow <= 0.05 * j_wide))
                fail_msg("%s [mu %g, h_min %g, %s]: undocumented jump at threshold %g m: "
                         "%g N (half-width %g) and %g N (%g) of scale %g N",
                         v->label, cfg->fluid->viscosity, cfg->h_min, cfg->motion->name, g, j_wide,
                         1e-4 * len, j_narrow, 1e-12 * len, s_narrow);
        }
    }
}

static void test_conformance_continuity_at_thresholds(void** state)
{
    (void)state;
    size_t n_jumps = 0;
    assert_true(for_each_force_config(threshold_config, &n_jumps) > 0);
    assert_true(n_jumps > 0);
}

/* Force of a variant at gap h for cfg, fresh history, with Coulomb coefficients (1e30) so large
 * that a Mindlin spring (mindlin, nijssen) sticks at every gap probed: nijssen's limit
 * mu w_c F_el ~ delta^(5/2) against k_t |s| ~ delta^(1/2) needs mu > 3e17 at
 * delta = 1e-15 m. The stick/slip switch is a documented
 * discontinuity in the spring state, not in the gap: sliding drops the dashpot (LIGGGHTS
 * semantics, docs/derivations/contact.md Sec. 2), so |F_t| falls from k_t |s| + gamma_t |v_t|
 * to mu F_el where k_t |s| reaches mu F_el, at a gap that depends on the history. */
static struct wetdem_pair_force force_at(const struct variant* v, const struct config* cfg,
                                         double h)
{
    struct wetdem_contact c = make_contact(cfg, h, false);
    c.friction_dry = c.friction_lub = 1e30;
    return eval_fresh(v, &c);
}

/* Largest jump in [lo, hi]: bisects 64 times towards the half with the larger change. A law
 * that is continuous on [lo, hi] leaves a change of its slope times (hi - lo) 2^-64, about
 * 5e-20 (hi - lo) |dF/dh|; a jump stays. Returns the final change, *scale the force there. */
static double bisect_jump(const struct variant* v, const struct config* cfg, double lo, double hi,
                          double* scale_out, double* where)
{
    struct wetdem_pair_force flo = force_at(v, cfg, lo), fhi = force_at(v, cfg, hi);
    for (int it = 0; it < 64; it++) {
        double mid = 0.5 * (lo + hi);
        if (!(mid > lo && mid < hi))
            break;
        struct wetdem_pair_force fm = force_at(v, cfg, mid);
        if (force_difference(&flo, &fm, RA, RB) >= force_difference(&fm, &fhi, RA, RB)) {
            hi = mid;
            fhi = fm;
        } else {
            lo = mid;
            flo = fm;
        }
    }
    *scale_out = fmax(force_scale(&flo, RA, RB), force_scale(&fhi, RA, RB));
    *where = 0.5 * (lo + hi);
    return force_difference(&flo, &fhi, RA, RB);
}

static int compare_doubles(const void* a, const void* b)
{
    double x = *(const double*)a, y = *(const double*)b;
    return (x > y) - (x < y);
}

/* Between the gaps thresholds() reports a model must be continuous, or the event locator
 * would step over an unreported branch. The gap axis from -1e-5 m to twice the range (at
 * least 1e-5 m) is cut at every reported threshold and at a log grid (60 points per sign
 * and 0), each piece kept 1e-6 relative (1e-15 m at 0) away from the thresholds, and each
 * piece is searched for a jump by bisection. Tolerance: 1e-9 of the force there. The steepest
 * continuous laws here are the delta^(1/4) damping of hertz, mindlin and nijssen next to
 * their roots: at a distance d from the root a piece of width W <= |h| leaves
 * (1/4) 5e-20 W / d, below 1e-13 for d = 1e-6 |h| or 1e-15 m; the sb bracket near delta
 * (|d ln F/d ln h| < 1e7 at 1e-6 from it) leaves < 1e-12. */
static void scan_config(const struct variant* v, const struct config* cfg, void* ctx)
{
    (void)ctx;
    struct wetdem_contact c = make_contact(cfg, 0.5 * cfg->h_min, false);
    double thr[WETDEM_MAX_THRESHOLDS], history[MAX_HISTORY] = {0};
    size_t ng = v->model->thresholds(v->params, &c, history, thr);
    double top = fmax(2.0 * v->model->range(v->params, &c), 1e-5);
    double pts[160];
    size_t np = 0;
    for (int k = 0; k < 60; k++) {
        pts[np++] = 1e-9 * pow(top / 1e-9, k / 59.0);
        pts[np++] = -1e-9 * pow(1e4, k / 59.0);
    }
    pts[np++] = 0.0;
    for (size_t q = 0; q < ng; q++)
        pts[np++] = thr[q];
    qsort(pts, np, sizeof pts[0], compare_doubles);
    for (size_t k = 0; k + 1 < np; k++) {
        double lo = pts[k], hi = pts[k + 1];
        for (size_t q = 0; q < ng; q++) { /* stay off the reported thresholds */
            double pad = thr[q] != 0.0 ? 1e-6 * fabs(thr[q]) : 1e-15;
            if (lo == thr[q])
                lo += pad;
            if (hi == thr[q])
                hi -= pad;
        }
        if (!(hi > lo))
            continue;
        double s, at, j = bisect_jump(v, cfg, lo, hi, &s, &at);
        if (!(j <= 1e-9 * s))
            fail_msg("%s [mu %g, h_min %g, %s]: force jumps by %g of %g N at gap %.10g m, "
                     "which thresholds() does not report",
                     v->label, cfg->fluid->viscosity, cfg->h_min, cfg->motion->name, j, s, at);
    }
}

static void test_conformance_no_unreported_branch(void** state)
{
    (void)state;
    assert_true(for_each_force_config(scan_config, NULL) > 0);
}

/* ======================================================================================== */
/* Dissipation: viscous laws never do positive work                                          */
/* ======================================================================================== */

/* Power the pair's forces deliver to the two particles [W]: F on i and -F on j at their
 * centre velocities plus the torques on their spins. For forces applied at the contact points
 * it equals -F_n v_n + F_t . v_t (contact.c's v_t is the surface slip). */
static double pair_power(const struct config* cfg, double gap, const struct wetdem_contact* c,
                         const struct wetdem_pair_force* f)
{
    struct wetdem_particle a, b;
    make_particles(cfg, gap, &a, &b);
    struct wetdem_vec3 force = add(scale(c->normal, f->f_normal), f->f_tan);
    return dot(force, sub(a.vel, b.vel)) + dot(f->torque_i, a.omega) + dot(f->torque_j, b.omega);
}

static const char* const viscous_models[] = {"reynolds", "sb", "db", "davis", "nase", NULL};

static bool is_viscous(const struct wetdem_model* m)
{
    for (size_t k = 0; viscous_models[k]; k++)
        if (strcmp(m->name, viscous_models[k]) == 0)
            return true;
    return false;
}

/* Purely viscous laws (normal squeeze and tangential shear, spins included) dissipate: the
 * power is <= 0 in every configuration, and < 0 wherever they act. nijssen is purely viscous
 * in its lubrication branch h > h_min. Tolerance: the power is a sum of a few products of
 * size |F| |v|, so 1e-13 of that bounds the roundings. */
static void dissipation_config(const struct variant* v, const struct config* cfg, void* ctx)
{
    size_t* n_strict = ctx;
    bool viscous = is_viscous(v->model), nijssen = strcmp(v->model->name, "nijssen") == 0;
    if (!viscous && !nijssen)
        return;
    for (size_t g = 0; g < N_GAPS; g++) {
        if (nijssen && !(scan_gaps[g] > 2e-6)) /* above any h_min of these configurations */
            continue;
        struct wetdem_contact c = make_contact(cfg, scan_gaps[g], false);
        struct wetdem_pair_force f = eval_fresh(v, &c);
        double p = pair_power(cfg, scan_gaps[g], &c, &f);
        double bound = 1e-13 * force_scale(&f, RA, RB) * (fabs(c.v_n) + norm(c.v_t) + 1.0);
        if (!(p <= bound))
            fail_msg("%s [mu %g, h_min %g, %s, gap %g]: viscous force does work %g W > 0", v->label,
                     cfg->fluid->viscosity, cfg->h_min, cfg->motion->name, scan_gaps[g], p);
        *n_strict += p < -bound;
    }
}

static void test_conformance_viscous_laws_dissipate(void** state)
{
    (void)state;
    size_t n_strict = 0;
    assert_true(for_each_force_config(dissipation_config, &n_strict) > 0);
    assert_true(n_strict > 100); /* the laws did act */
}

/* ======================================================================================== */
/* What the engines report: stored energy, solid contact, liquid bridge                      */
/* ======================================================================================== */

/* At rest (no relative motion, no spins) and sliding only (no normal speed, no spins). */
static const struct motion rest = {"rest", 0.0, 0.0, 0.0, {0, 0, 0}, {0, 0, 0}};
static const struct motion slide = {"slide", 0.0, 0.2, -0.07, {0, 0, 0}, {0, 0, 0}};

/* Gaps probed: overlaps, the blend zone 0 < h < h_min of nijssen (h_min = h_sigma = 1 um, or
 * h_eps = 1.9 um for the viscous fluid) and beyond it, a film, beyond the films (100 um). */
static const double hook_gaps[] = {-3e-6, -2e-7, 0.3e-6, 0.8e-6, 1.5e-6, 5e-6, 99e-6, 0.5e-3};
#define N_HOOK_GAPS (sizeof hook_gaps / sizeof hook_gaps[0])

/* The contact at gap h with cfg's fluid and h_min, moving as mo says. */
static struct wetdem_contact contact_moving(const struct config* cfg, const struct motion* mo,
                                            double h)
{
    struct config at = *cfg;
    at.motion = mo;
    return make_contact(&at, h, false);
}

/* history[] after one evaluation at gap h approaching as cfg says (nijssen records its v0). */
static void record_history(const struct variant* v, const struct config* cfg, double h,
                           double* history)
{
    memset(history, 0, MAX_HISTORY * sizeof *history);
    struct wetdem_contact c = make_contact(cfg, h, false);
    eval_force(v, &c, history);
}

/* The force at rest of the pair at gap h with history (copied: pair() advances it). */
static struct wetdem_pair_force force_with(const struct variant* v, const struct wetdem_contact* c,
                                           const double* history)
{
    double copy[MAX_HISTORY];
    memcpy(copy, history, sizeof copy);
    return eval_force(v, c, copy);
}

/* elastic_energy is the potential of the force at rest (the damping and the lubrication
 * vanish there): -dE/dh by central differences equals F_n, with h_min as the evaluation
 * recorded it. Step 1e-4 |h|, at least 2e-7 / 1e-4 of the distance to the nearest kink of E
 * (0 and h_min, where dF/dh jumps), so the truncation, (eps/d)^2 times a constant below 1 for
 * powers d^(5/2) to d^(7/2), stays below 1e-7; the cancellation of E (about |h| F) over 2 eps
 * adds 1e-16 |h| / eps = 1e-12. Tolerance 1e-6 of F_n. */
static void elastic_config(const struct variant* v, const struct config* cfg, void* ctx)
{
    size_t* n_checked = ctx;
    if (!v->model->elastic_energy || cfg->motion != &motions[0])
        return;
    for (size_t g = 0; g < N_HOOK_GAPS; g++) {
        double h = hook_gaps[g], eps = 1e-4 * fabs(h), history[MAX_HISTORY];
        record_history(v, cfg, h, history);
        struct wetdem_contact at = contact_moving(cfg, &rest, h);
        struct wetdem_contact lo = contact_moving(cfg, &rest, h - eps);
        struct wetdem_contact hi = contact_moving(cfg, &rest, h + eps);
        double e = v->model->elastic_energy(v->params, &at, history);
        double slope = -(v->model->elastic_energy(v->params, &hi, history) -
                         v->model->elastic_energy(v->params, &lo, history)) /
                       (2.0 * eps);
        struct wetdem_pair_force f = force_with(v, &at, history);
        if (!(fabs(slope - f.f_normal) <= 1e-6 * fabs(f.f_normal)) || !(e >= 0.0) ||
            (e > 0.0) != (f.f_normal > 0.0))
            fail_msg("%s [mu %g, gap %g]: stored energy %g J, -dE/dh = %.12g N, force at rest "
                     "%.12g N",
                     v->label, cfg->fluid->viscosity, h, e, slope, f.f_normal);
        *n_checked += f.f_normal > 0.0;
    }
}

static void test_conformance_elastic_energy_is_the_potential_of_the_force(void** state)
{
    (void)state;
    size_t n_checked = 0;
    assert_true(for_each_force_config(elastic_config, &n_checked) > 0);
    /* hertz, hooke, nijssen in overlaps, nijssen in its blend zone too */
    assert_true(n_checked >= 20);
}

/* is_in_contact says where the model exerts a solid-contact force: an elastic force at rest or
 * a tangential one while sliding (nijssen's blend zone 0 < h < h_min included, its
 * lubrication at rest being zero); is_bridged where the films overlap, h <= delta_ij, and
 * nowhere without a film. Both are false beyond range(). */
static void contact_hook_config(const struct variant* v, const struct config* cfg, void* ctx)
{
    size_t* n_true = ctx;
    const struct wetdem_model* m = v->model;
    if (cfg->motion != &motions[0])
        return;
    for (size_t g = 0; g < N_HOOK_GAPS; g++) {
        double h = hook_gaps[g], history[MAX_HISTORY];
        record_history(v, cfg, h, history);
        struct wetdem_contact c = contact_moving(cfg, &rest, h);
        bool beyond = h > m->range(v->params, &c);
        if (m->is_in_contact) {
            struct wetdem_contact sl = contact_moving(cfg, &slide, h);
            struct wetdem_pair_force fr = force_with(v, &c, history);
            struct wetdem_pair_force fs = force_with(v, &sl, history);
            bool acts = fr.f_normal > 0.0 || norm(fs.f_tan) > 0.0;
            bool says = m->is_in_contact(v->params, &c, history);
            if (says != acts || (says && beyond))
                fail_msg("%s [mu %g, gap %g]: is_in_contact %d, but the force at rest is %g N "
                         "and sliding %g N",
                         v->label, cfg->fluid->viscosity, h, says, fr.f_normal, norm(fs.f_tan));
            *n_true += says;
        }
        if (m->is_bridged) {
            bool says = m->is_bridged(v->params, &c, history);
            if (says != (h <= c.film) || (says && beyond))
                fail_msg("%s: is_bridged %d at gap %g with films %g m", v->label, says, h, c.film);
            c.film = 0.0;
            if (m->is_bridged(v->params, &c, history))
                fail_msg("%s: bridged at gap %g without a film", v->label, h);
            *n_true += says;
        }
    }
}

static void test_conformance_contact_and_bridge_hooks(void** state)
{
    (void)state;
    size_t n_true = 0;
    assert_true(for_each_force_config(contact_hook_config, &n_true) > 0);
    assert_true(n_true > 50);
}

/* Which model has which reporting hook: a stored energy for the contacts whose elastic force
 * has a potential (hertz, hooke, nijssen's blended contact; mindlin's spring k_t |s|^2 / 2 is
 * none, k_t following the overlap), a solid contact for the contact models and nijssen, a
 * liquid bridge for the film models. Every force model of the registry is listed, so that a
 * new one decides. */
static void test_conformance_reporting_hooks_by_model(void** state)
{
    (void)state;
    static const struct {
        const char* name;
        bool energy, contact, bridge;
    } want[] = {
        {"hertz", true, true, false},      {"mindlin", false, true, false},
        {"hooke", true, true, false},      {"nijssen", true, true, false},
        {"reynolds", false, false, false}, {"sb", false, false, true},
        {"db", false, false, true},        {"davis", false, false, true},
        {"nase", false, false, true},      {"capillary", false, false, true},
    };
    size_t n_listed = sizeof want / sizeof want[0], n_force = 0;
    const struct wetdem_model* const* reg = wetdem_model_registry();
    for (size_t k = 0; reg[k]; k++) {
        const struct wetdem_model* m = reg[k];
        if (!is_force_model(m)) {
            if (m->elastic_energy || m->is_in_contact || m->is_bridged)
                fail_msg("%s: a reporting hook on a model that gives no force", m->name);
            continue;
        }
        n_force++;
        size_t w = 0;
        while (w < n_listed && strcmp(want[w].name, m->name) != 0)
            w++;
        if (w == n_listed)
            fail_msg("force model %s: say here which reporting hooks it has", m->name);
        if ((m->elastic_energy != NULL) != want[w].energy ||
            (m->is_in_contact != NULL) != want[w].contact ||
            (m->is_bridged != NULL) != want[w].bridge)
            fail_msg("%s: elastic_energy %d, is_in_contact %d, is_bridged %d; want %d %d %d",
                     m->name, m->elastic_energy != NULL, m->is_in_contact != NULL,
                     m->is_bridged != NULL, want[w].energy, want[w].contact, want[w].bridge);
    }
    assert_int_equal(n_force, n_listed);
}

/* ======================================================================================== */
/* src/contact.c: mixing rules and kinematics                                                */
/* ======================================================================================== */

/* Hand arithmetic (materials mat_a, mat_b):
 *   1/E* = (1 - 0.09)/200e9 + (1 - 0.0484)/70e9 = 4.55e-12 + 1.3594286e-11 = 1.8144286e-11
 *        -> E* = 5.51137e10 Pa;
 *   G_a = 200e9/2.6 = 7.6923e10, G_b = 70e9/2.44 = 2.8689e10;
 *   1/G* = 1.7/7.6923e10 + 1.78/2.8689e10 = 2.21e-11 + 6.204571e-11 -> G* = 1.188415e10 Pa;
 *   R* = 2e-3 * 5e-3 / 7e-3 = 1.4285714e-3 m; m* = 0.07 * 1.2 / 1.27 = 0.0661417 kg;
 *   e = 0.85, mu_dry = 0.25, mu_lub = 0.04, sigma_r = 1e-6 m, delta = 100e-6 m.
 * Kinematics: n = x, i at +x; v_i = (-0.3, 0.1, 0.02), v_j = (0, 0, 0.05),
 * w_i = (1, 0, 10), w_j = (0, 4, 20) rad/s. i's contact point is -R_i x:
 *   w_i x (-R_i x) = (1, 0, 10) x (-2e-3, 0, 0) = (0, -0.02, 0);
 * j's is +R_j x: w_j x (R_j x) = (0, 4, 20) x (5e-3, 0, 0) = (0, 0.1, -0.02).
 * Surface velocities: i (-0.3, 0.08, 0.02), j (0, 0.1, 0.03); relative (-0.3, -0.02, -0.01):
 *   v_n = 0.3 m/s, v_t = (0, -0.02, -0.01) m/s (spin about n, w_i.x, does not enter). */
static void test_conformance_contact_mixing_and_kinematics(void** state)
{
    (void)state;
    struct wetdem_particle a = {.pos = {7e-3 + 4e-6, 0, 0},
                                .vel = {-0.3, 0.1, 0.02},
                                .omega = {1, 0, 10},
                                .radius = RA,
                                .mass = MA};
    struct wetdem_particle b = {
        .pos = {0, 0, 0}, .vel = {0, 0, 0.05}, .omega = {0, 4, 20}, .radius = RB, .mass = MB};
    struct wetdem_contact c;
    wetdem_contact_from_particles(&c, &a, &mat_a, &b, &mat_b, &fluids[0]);
    /* 1e-14: a handful of roundings in the sums and quotients */
    CHECK_REL(c.e_star, 1.0 / (0.91 / 200e9 + (1 - 0.22 * 0.22) / 70e9), 1e-14);
    CHECK_REL(c.e_star, 5.51137e10, 1e-5); /* the hand values above, 6 and 7 digits */
    CHECK_REL(c.g_star, 1.0 / (1.7 * 2.6 / 200e9 + 1.78 * 2.44 / 70e9), 1e-14);
    CHECK_REL(c.g_star, 1.188415e10, 1e-6);
    CHECK_REL(c.r_eff, 1e-5 / 7e-3, 1e-15);
    CHECK_REL(c.m_eff, 0.084 / 1.27, 1e-15);
    CHECK_REL(c.gap, 4e-6, 1e-9); /* 7.004e-3 - 7e-3 loses 3 digits to cancellation */
    CHECK_REL(c.restitution, 0.85, 1e-15);
    CHECK_REL(c.friction_dry, 0.25, 1e-15);
    CHECK_REL(c.friction_lub, 0.04, 1e-15);
    CHECK_REL(c.roughness, 1e-6, 1e-15);
    CHECK_REL(c.film, 100e-6, 1e-15);
    CHECK_REL(c.viscosity, 0.5, 0);
    CHECK_REL(c.normal.x, 1.0, 1e-15); /* d * (1/|d|): one rounding */
    CHECK_REL(c.v_n, 0.3, 1e-15);
    CHECK_ABS(c.v_t.x, 0.0, 1e-15 * 0.3); /* the rounding of n.x times |v_n| */
    CHECK_REL(c.v_t.y, -0.02, 1e-14);
    CHECK_REL(c.v_t.z, -0.01, 1e-14);
    CHECK_REL(c.radius_i, RA, 0);
    CHECK_REL(c.radius_j, RB, 0);

    /* a fixed j has infinite mass: m* = m_i; R* unchanged */
    b.is_fixed = true;
    wetdem_contact_from_particles(&c, &a, &mat_a, &b, &mat_b, &fluids[0]);
    CHECK_REL(c.m_eff, MA, 0);
    wetdem_contact_from_particles(&c, &b, &mat_b, &a, &mat_a, &fluids[0]);
    CHECK_REL(c.m_eff, MA, 0);

    /* a wall through the origin with normal +x, of material b: R* = R_i, m* = m_i, the same
     * E*, G* and mixing; the wall surface is at rest, so v_t = i's surface velocity
     * (0.08, 0.02) in y, z */
    wetdem_contact_with_wall(&c, &a, &mat_a, v3(0, 0, 0), v3(1, 0, 0), &mat_b, &fluids[0]);
    CHECK_REL(c.r_eff, RA, 0);
    CHECK_REL(c.m_eff, MA, 0);
    assert_true(c.is_wall && isinf(c.radius_j));
    CHECK_REL(c.gap, 5e-3 + 4e-6, 1e-12);
    CHECK_REL(c.e_star, 1.0 / (0.91 / 200e9 + (1 - 0.22 * 0.22) / 70e9), 1e-14);
    CHECK_REL(c.v_n, 0.3, 1e-15);
    CHECK_REL(c.v_t.y, 0.08, 1e-14);
    CHECK_REL(c.v_t.z, 0.02, 1e-14);
}

/* A wall is the limit of a fixed sphere of huge radius: every force model gives the same force
 * and torque on i, and no torque on the wall. The sphere's R* differs from R_i by
 * R_i/R_j = 2e-9 relative and forces go as up to R*^2: tolerance 1e-8. The gap of the huge
 * sphere is set to the wall's (computing it would cancel 1e6 m against 1e6 m). */
static void test_conformance_wall_is_limit_of_large_fixed_sphere(void** state)
{
    (void)state;
    const double big = 1e6; /* [m] */
    const double gaps[] = {-2e-7, 0.5e-6, 30e-6};
    const struct wetdem_model* const* reg = wetdem_model_registry();
    for (size_t k = 0; reg[k]; k++) {
        if (!is_force_model(reg[k]))
            continue;
        struct variant vars[MAX_VARIANTS];
        size_t nv = model_variants(reg[k], vars);
        for (size_t v = 0; v < nv; v++)
            for (size_t g = 0; g < 3; g++) {
                struct wetdem_particle a = {.pos = {0, 0, RA + gaps[g]},
                                            .vel = {0.1, -0.05, -0.2},
                                            .omega = {5, 12, -3},
                                            .radius = RA,
                                            .mass = MA};
                struct wetdem_particle b = {
                    .pos = {0, 0, -big}, .radius = big, .mass = 1.0, .is_fixed = true};
                struct wetdem_contact cw, cs;
                wetdem_contact_with_wall(&cw, &a, &mat_a, v3(0, 0, 0), v3(0, 0, 1), &mat_b,
                                         &fluids[1]);
                wetdem_contact_from_particles(&cs, &a, &mat_a, &b, &mat_b, &fluids[1]);
                cs.gap = cw.gap;
                cw.h_min = cs.h_min = 1e-6;
                cw.dt = cs.dt = DT;
                struct wetdem_pair_force fw = eval_fresh(&vars[v], &cw);
                struct wetdem_pair_force fs = eval_fresh(&vars[v], &cs);
                double s = fmax(fabs(fw.f_normal), norm(fw.f_tan));
                double d = fmax(fabs(fw.f_normal - fs.f_normal), norm(sub(fw.f_tan, fs.f_tan)));
                double dt = norm(sub(fw.torque_i, fs.torque_i)) / RA;
                if (!(d <= 1e-8 * s) || !(dt <= 1e-8 * s) || norm(fw.torque_j) != 0.0)
                    fail_msg("%s at gap %g: wall F_n %.17g vs large sphere %.17g, torque "
                             "difference %g N m, wall torque %g N m",
                             vars[v].label, gaps[g], fw.f_normal, fs.f_normal, dt * RA,
                             norm(fw.torque_j));
            }
    }
}

/* ======================================================================================== */
/* Hard impulse against Davis Appendix A, generalised to unequal spheres at a finite gap      */
/* ======================================================================================== */

/* Davis's polar variables of a planar pair (x-y plane, spins about z): theta of x_j - x_i,
 * r, v_ij,n = (v_i - v_j).e_n (> 0 approaching), Omega = d theta/dt, v_w = a_i w_i + a_j w_j,
 * slip v^s = -r Omega + v_w (Eq. 4). */
struct davis_state {
    double r, v_n, omega_line, v_w, slip;
};

static struct davis_state davis_polar(struct wetdem_vec3 xi, struct wetdem_vec3 xj,
                                      const struct wetdem_impulse_body* bi,
                                      const struct wetdem_impulse_body* bj)
{
    struct davis_state d;
    struct wetdem_vec3 rij = sub(xj, xi), vij = sub(bj->vel, bi->vel);
    d.r = norm(rij);
    d.v_n = -dot(vij, rij) / d.r;
    d.omega_line = cross(rij, vij).z / (d.r * d.r);
    d.v_w = bi->radius * bi->omega.z + bj->radius * bj->omega.z;
    d.slip = -d.r * d.omega_line + d.v_w;
    return d;
}

static struct wetdem_impulse_body solid_sphere(double m, double a, struct wetdem_vec3 v, double wz)
{
    return (struct wetdem_impulse_body){v, v3(0, 0, wz), m, a, 0.4 * m * a * a};
}

/* Unequal spheres (m_i = 0.3, a_i = 0.02; m_j = 1.1, a_j = 0.035) whose surfaces are
 * h_min = 1e-4 m apart (Davis: r = a_i + a_j + h_min), line of centres at 30 degrees.
 * Generalising A31-A32 to I_i != I_j: m r dOmega = I_t, dv_w = -(a_i^2/I_i + a_j^2/I_j) I_t,
 * no slip after (A30) gives |I_t| = m_t |v_w - r Omega| with
 * 1/m_t = 1/m + a_i^2/I_i + a_j^2/I_j (A33; = 2m/7 for Davis's equal spheres), and the
 * sliding/sticking switch m_t |v^s| < mu (1 + e) m v_n (A36 generalised). */
static void test_conformance_hard_matches_davis_appendix_a_unequal(void** state)
{
    (void)state;
    const double e = 0.7, mi = 0.3, ai = 0.02, mj = 1.1, aj = 0.035, hmin = 1e-4;
    const double th = M_PI / 6, m = mi * mj / (mi + mj);
    const double mt = 1.0 / (1.0 / m + 2.5 / mi + 2.5 / mj); /* a^2/I = 5/(2 m) */
    struct wetdem_vec3 en = v3(cos(th), sin(th), 0), et = v3(-sin(th), cos(th), 0);
    struct wetdem_vec3 xi = v3(0, 0, 0), xj = scale(en, ai + aj + hmin);
    struct wetdem_vec3 n = scale(en, -1.0); /* wetdem: from j to i */
    /* approach 1.3 m/s along e_n; tangential centre velocity and spins set the slip */
    const double slips[] = {0.9, -0.4, 4.0, -6.0};
    int n_stick = 0;
    for (size_t k = 0; k < 4; k++) {
        struct wetdem_impulse_body bi =
            solid_sphere(mi, ai, add(scale(en, 1.3), scale(et, 0.3 * slips[k])), 15 * slips[k]);
        struct wetdem_impulse_body bj = solid_sphere(mj, aj, v3(0.1, -0.2, 0), -5 * slips[k]);
        struct davis_state b = davis_polar(xi, xj, &bi, &bj);
        const double mu = 0.25;
        double jn = m * (1 + e) * b.v_n;           /* A3 */
        bool stick = mt * fabs(b.slip) <= mu * jn; /* A36 generalised */
        double wi = bi.omega.z, wj = bj.omega.z;
        struct wetdem_impulse_result res;
        CHECK_OK(wetdem_hard_impulse(&bi, &bj, n, e, mu, &res));
        struct davis_state a = davis_polar(xi, xj, &bi, &bj);
        assert_int_equal(res.is_sticking, stick);
        n_stick += stick;
        /* tolerances 1e-13 absolute in m/s on O(1) quantities: a few roundings */
        CHECK_ABS(a.v_n, -e * b.v_n, 1e-13);      /* A1 */
        CHECK_REL(res.impulse_normal, jn, 1e-14); /* A3 */
        double sgn = b.slip > 0 ? 1.0 : -1.0;
        if (stick) {
            CHECK_ABS(a.slip, 0.0, 1e-13);                              /* A30 */
            CHECK_REL(norm(res.impulse_tan), mt * fabs(b.slip), 1e-13); /* A33 */
            /* A31: m r (Omega^a - Omega^b) = I_t, the tangential impulse on j along e_t */
            CHECK_ABS(m * a.r * (a.omega_line - b.omega_line), -dot(res.impulse_tan, et), 1e-13);
        } else {
            double jump = mu * (1 + e) * b.v_n; /* the v_t jump of A9 */
            CHECK_ABS(a.omega_line, b.omega_line + sgn * jump / b.r, 1e-12); /* A10 */
            CHECK_ABS(bi.omega.z, wi - sgn * jump * ai * m / (0.4 * mi * ai * ai), 1e-12);
            CHECK_ABS(bj.omega.z, wj - sgn * jump * aj * m / (0.4 * mj * aj * aj), 1e-12);
            /* A11 with I_j: the printed I_i would give a different omega_j for m_i != m_j */
            assert_true(fabs(jump * aj * m / (0.4 * mi * aj * aj) -
                             jump * aj * m / (0.4 * mj * aj * aj)) > 1.0);
            assert_true(a.slip * b.slip > 0.0); /* slides on, same direction */
        }
    }
    assert_true(n_stick >= 1 && n_stick <= 3); /* both branches were exercised */
}

/* Kinetic energy never grows and both momenta are kept, over random unequal pairs, walls and
 * fixed spheres, e in (0, 1] and mu from 0 to 10; with e = 1 and mu = 0 it is kept exactly.
 * dKE = J.(u^- + u^+)/2 <= 0 for the normal and the (sticking or sliding) tangential parts. */
static double kinetic_energy(const struct wetdem_impulse_body* b)
{
    if (isinf(b->mass))
        return 0.0;
    return 0.5 * b->mass * dot(b->vel, b->vel) + 0.5 * b->inertia * dot(b->omega, b->omega);
}

static double urand(unsigned* s, double lo, double hi)
{
    *s = *s * 1664525u + 1013904223u;
    return lo + (hi - lo) * (*s >> 8) / 16777216.0;
}

static void test_conformance_hard_energy_never_grows(void** state)
{
    (void)state;
    unsigned seed = 12345;
    for (int k = 0; k < 2000; k++) {
        struct wetdem_vec3 n = v3(urand(&seed, -1, 1), urand(&seed, -1, 1), urand(&seed, -1, 1));
        n = scale(n, 1.0 / norm(n));
        double mi = urand(&seed, 0.01, 2), mj = urand(&seed, 0.01, 2);
        double ai = urand(&seed, 1e-3, 0.05), aj = urand(&seed, 1e-3, 0.05);
        struct wetdem_impulse_body bi = {
            v3(urand(&seed, -2, 2), urand(&seed, -2, 2), urand(&seed, -2, 2)),
            v3(urand(&seed, -50, 50), urand(&seed, -50, 50), urand(&seed, -50, 50)), mi, ai,
            0.4 * mi * ai * ai};
        struct wetdem_impulse_body bj = {
            v3(urand(&seed, -2, 2), urand(&seed, -2, 2), urand(&seed, -2, 2)),
            v3(urand(&seed, -50, 50), urand(&seed, -50, 50), urand(&seed, -50, 50)), mj, aj,
            0.4 * mj * aj * aj};
        int kind = k % 4; /* 0, 1 free pair; 2 wall j; 3 fixed sphere j */
        if (kind == 2)
            bj = (struct wetdem_impulse_body){v3(0, 0, 0), v3(0, 0, 0), INFINITY, INFINITY, 0};
        if (kind == 3) { /* at rest: a moving support could feed energy in */
            bj.mass = INFINITY;
            bj.vel = v3(0, 0, 0);
            bj.omega = v3(0, 0, 0);
        }
        bool elastic = k % 7 == 0;
        double e = elastic ? 1.0 : urand(&seed, 0.05, 1.0);
        double mu = elastic ? 0.0 : urand(&seed, 0.0, 10.0);
        double ke0 = kinetic_energy(&bi) + kinetic_energy(&bj);
        CHECK_OK(wetdem_hard_impulse(&bi, &bj, n, e, mu, NULL));
        double ke1 = kinetic_energy(&bi) + kinetic_energy(&bj);
        /* 1e-12 relative: KE is a sum of ~10 products, the balance holds to rounding */
        if (elastic)
            CHECK_REL(ke1, ke0, 1e-12);
        else if (!(ke1 <= ke0 * (1 + 1e-12)))
            fail_msg("case %d: kinetic energy grew from %.17g to %.17g J (e %g, mu %g)", k, ke0,
                     ke1, e, mu);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_conformance_swap_symmetry_and_torques),
        cmocka_unit_test(test_conformance_contact_swap_is_mirror),
        cmocka_unit_test(test_conformance_min_separation_swap_invariant),
        cmocka_unit_test(test_conformance_record_range_is_where_the_record_ends),
        cmocka_unit_test(test_conformance_zero_beyond_range),
        cmocka_unit_test(test_conformance_continuity_at_thresholds),
        cmocka_unit_test(test_conformance_no_unreported_branch),
        cmocka_unit_test(test_conformance_viscous_laws_dissipate),
        cmocka_unit_test(test_conformance_elastic_energy_is_the_potential_of_the_force),
        cmocka_unit_test(test_conformance_contact_and_bridge_hooks),
        cmocka_unit_test(test_conformance_reporting_hooks_by_model),
        cmocka_unit_test(test_conformance_contact_mixing_and_kinematics),
        cmocka_unit_test(test_conformance_wall_is_limit_of_large_fixed_sphere),
        cmocka_unit_test(test_conformance_hard_matches_davis_appendix_a_unequal),
        cmocka_unit_test(test_conformance_hard_energy_never_grows),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

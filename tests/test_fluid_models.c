/*
 * test_fluid_models.c — thin-film viscous (sb, db, davis, nase), capillary and reynolds
 * force models: closed forms at hand-computed points, zero beyond range, continuity at the
 * film edge, c/nc below h_min, suction, direction of the tangential forces (pure spin
 * included), i<->j symmetry with unequal radii and masses, and parameter validation.
 *
 * Common pair (unless stated): R_i = 2 mm, R_j = 6 mm -> R* = a = 12e-6/8e-3 = 1.5e-3 m;
 * m_i = 0.1 kg, m_j = 0.3 kg; mu = 1 Pa s; delta = 100 um; h_min = 1 um; sigma = 0.02 N/m
 * (tests/harness.h test_contact). Relative tolerances of 1e-13 on closed forms allow a few
 * roundings (each <= 1.1e-16 relative) in the products, quotients and logs evaluated.
 */
#include "harness.h"
#include "models.h"

#define RI 2e-3
#define RJ 6e-3
#define MI 0.1
#define MJ 0.3
#define A_EFF 1.5e-3
#define DELTA 100e-6
#define TOL_CLOSED 1e-13

static double vec_norm_test(struct wetdem_vec3 a)
{
    return sqrt(a.x * a.x + a.y * a.y + a.z * a.z);
}

static const struct wetdem_model* const thin_film_models[] = {
    &wetdem_force_sb, &wetdem_force_db, &wetdem_force_davis, &wetdem_force_nase, NULL};

/* Params of `m` with its defaults and below_hmin set to `below` (0 = c, 1 = nc) if present. */
static void make_params(const struct wetdem_model* m, double below, double* storage)
{
    wetdem_param_init_defaults(m->params, storage);
    const struct wetdem_param_desc* d = wetdem_param_find(m->params, "below_hmin");
    if (d)
        *(double*)((char*)storage + d->offset) = below;
}

/* The force of model m for contact c with fresh history. */
static struct wetdem_pair_force eval(const struct wetdem_model* m, double below,
                                     struct wetdem_contact c)
{
    double params[8] = {0}, history[8] = {0};
    make_params(m, below, params);
    struct wetdem_pair_force f = {0};
    CHECK_OK(m->pair(params, &c, history, &f));
    return f;
}

static struct wetdem_contact pair_at(double gap, double v_n)
{
    return test_contact(RI, RJ, MI, MJ, gap, v_n);
}

static bool is_zero(struct wetdem_pair_force f)
{
    return f.f_normal == 0 && f.f_tan.x == 0 && f.f_tan.y == 0 && f.f_tan.z == 0 &&
           f.torque_i.x == 0 && f.torque_i.y == 0 && f.torque_i.z == 0 && f.torque_j.x == 0 &&
           f.torque_j.y == 0 && f.torque_j.z == 0;
}

/* sb at h = 50 um, v_n = 0.1 m/s: 6 pi * 1 * (1.5e-3)^2 * 0.1 / 50e-6 * (1 - 0.5)^2
 * = 6 pi * 4.5e-3 * 0.25 = 6 pi * 1.125e-3 = 0.0212057504117311 N (repulsive). */
static void test_sb_closed_form(void** state)
{
    (void)state;
    struct wetdem_pair_force f = eval(&wetdem_force_sb, 0, pair_at(50e-6, 0.1));
    CHECK_REL(f.f_normal, 0.021205750411731103, TOL_CLOSED);
}

/* db at h = 50 um: bracket 1 - 50/(200 - 50) = 2/3, squared 4/9:
 * 6 pi * 4.5e-3 * 4/9 = 6 pi * 2e-3 = 0.0376991118430775 N. */
static void test_db_closed_form(void** state)
{
    (void)state;
    struct wetdem_pair_force f = eval(&wetdem_force_db, 0, pair_at(50e-6, 0.1));
    CHECK_REL(f.f_normal, 0.03769911184307751, TOL_CLOSED);
}

/* Every thin-film and capillary force is zero just beyond delta and range() is delta. */
static void test_fluid_zero_beyond_range(void** state)
{
    (void)state;
    const struct wetdem_model* models[] = {&wetdem_force_sb,        &wetdem_force_db,
                                           &wetdem_force_davis,     &wetdem_force_nase,
                                           &wetdem_force_capillary, NULL};
    for (size_t k = 0; models[k]; k++) {
        struct wetdem_contact c = pair_at(0, 0.1);
        c.v_t = (struct wetdem_vec3){0, 0.1, 0};
        double params[8];
        make_params(models[k], 1, params);
        CHECK_REL(models[k]->range(params, &c), DELTA, 0); /* exact copy of c.film */
        c.gap = DELTA * (1 + 1e-12);
        if (!is_zero(eval(models[k], 1, c)))
            fail_msg("%s acts beyond its range", models[k]->name);
    }
    /* reynolds: range = cutoff_ratio R* = 1.5e-3 m by default */
    struct wetdem_contact c = pair_at(A_EFF * (1 + 1e-12), 0.1);
    if (!is_zero(eval(&wetdem_force_reynolds, 0, c)))
        fail_msg("reynolds acts beyond h_co");
}

/* sb, db and davis vanish at h = delta (sb: 1 - delta/delta = 0; db: 1 - delta/(2 delta -
 * delta) = 0; davis: ln(delta/delta) = 0) and are continuous there. Just inside, at
 * h = delta (1 - eps) with eps = 1e-6: sb and db fall as eps^2 (~4e-14 N against 0.02 N at
 * delta/2), davis as ln((1 + eps)/(1 - eps)) ~ 2 eps, i.e. 2e-6/ln 3 = 1.8e-6 of its value at
 * delta/2. The bound 1e-5 of the mid-film value holds for all three and fails for any law
 * that does not tend to zero at the edge. */
static void test_thin_film_continuous_at_film_edge(void** state)
{
    (void)state;
    for (size_t k = 0; k < 3; k++) {
        const struct wetdem_model* m = thin_film_models[k];
        struct wetdem_contact c = pair_at(DELTA, 0.1);
        c.v_t = (struct wetdem_vec3){0, 0.1, 0};
        struct wetdem_pair_force edge = eval(m, 0, c);
        CHECK_ABS(edge.f_normal, 0, 0);
        CHECK_ABS(vec_norm_test(edge.f_tan), 0, 0);
        c.gap = 0.5 * DELTA;
        struct wetdem_pair_force mid = eval(m, 0, c);
        c.gap = DELTA * (1 - 1e-6);
        struct wetdem_pair_force inside = eval(m, 0, c);
        double f_mid = fabs(mid.f_normal) + vec_norm_test(mid.f_tan);
        double f_in = fabs(inside.f_normal) + vec_norm_test(inside.f_tan);
        if (!(f_mid > 0) || !(f_in <= 1e-5 * f_mid))
            fail_msg("%s: |F| = %g just inside the film edge vs %g mid-film", m->name, f_in, f_mid);
    }
}

/* sb/db = (1 - x)^2 / (1 - x/(2 - x))^2 = ((2 - x)/2)^2 = (1 - x/2)^2 with x = h/delta, since
 * 1 - x/(2 - x) = 2(1 - x)/(2 - x). So the two agree as h -> 0 with relative difference ~x. */
static void test_sb_db_agree_as_gap_vanishes(void** state)
{
    (void)state;
    const double xs[] = {0.5, 1e-3, 1e-6};
    for (size_t k = 0; k < 3; k++) {
        struct wetdem_contact c = pair_at(xs[k] * DELTA, 0.1);
        c.h_min = 0;
        double sb = eval(&wetdem_force_sb, 0, c).f_normal;
        double db = eval(&wetdem_force_db, 0, c).f_normal;
        CHECK_REL(sb / db, (1 - xs[k] / 2) * (1 - xs[k] / 2), TOL_CLOSED);
    }
}

/* Below h_min (1 um): c gives zero (Punch Eq. 12); nc gives the law at h_min (Eq. 13), also at
 * solid overlap. Same arithmetic as at gap = h_min, so bit-identical. */
static void test_thin_film_c_vs_nc_below_hmin(void** state)
{
    (void)state;
    const double gaps[] = {0.5e-6, 0.0, -2e-6};
    for (size_t k = 0; thin_film_models[k]; k++) {
        const struct wetdem_model* m = thin_film_models[k];
        struct wetdem_contact c = pair_at(1e-6, 0.1);
        c.v_t = (struct wetdem_vec3){0.02, 0.1, 0};
        struct wetdem_pair_force at_hmin = eval(m, 0, c);
        if (is_zero(at_hmin))
            fail_msg("%s: zero at h = h_min", m->name);
        for (size_t g = 0; g < 3; g++) {
            c.gap = gaps[g];
            if (!is_zero(eval(m, 0, c)))
                fail_msg("%s: c form not zero at h = %g < h_min", m->name, gaps[g]);
            struct wetdem_pair_force nc = eval(m, 1, c);
            CHECK_REL(nc.f_normal, at_hmin.f_normal, 0);
            CHECK_REL(nc.f_tan.y, at_hmin.f_tan.y, 0);
            CHECK_REL(nc.torque_j.z, at_hmin.torque_j.z, 0);
        }
    }
}

/* With h_min >= delta the evaluation gap is delta (Punch Eq. 14 cap), where sb, db and
 * davis vanish: zero throughout for both c and nc. nase does not vanish at delta: its nc
 * form is the constant value at delta. */
static void test_thin_film_hmin_at_or_above_film(void** state)
{
    (void)state;
    const double gaps[] = {DELTA, 0.5 * DELTA, 0.0, -1e-6};
    for (size_t k = 0; k < 3; k++)
        for (size_t g = 0; g < 4; g++)
            for (int below = 0; below < 2; below++) {
                struct wetdem_contact c = pair_at(gaps[g], 0.1);
                c.v_t = (struct wetdem_vec3){0, 0.1, 0};
                c.h_min = 2 * DELTA;
                if (!is_zero(eval(thin_film_models[k], below, c)))
                    fail_msg("%s (below %d) acts at h = %g with h_min > delta",
                             thin_film_models[k]->name, below, gaps[g]);
            }
    struct wetdem_contact c = pair_at(DELTA, 0.1);
    c.v_t = (struct wetdem_vec3){0, 0.1, 0};
    c.h_min = 0;
    double at_delta = eval(&wetdem_force_nase, 0, c).f_tan.y;
    c.gap = 0.5 * DELTA;
    c.h_min = 2 * DELTA;
    CHECK_REL(eval(&wetdem_force_nase, 1, c).f_tan.y, at_delta, 0);
    CHECK_ABS(eval(&wetdem_force_nase, 0, c).f_tan.y, 0, 0);
}

/* Separating (v_n < 0) gives suction: the force is odd in v_n, exactly (sign flip). */
static void test_thin_film_suction_when_separating(void** state)
{
    (void)state;
    const struct wetdem_model* models[] = {&wetdem_force_sb, &wetdem_force_db,
                                           &wetdem_force_reynolds};
    for (size_t k = 0; k < 3; k++)
        for (int below = 0; below < 2; below++) {
            double gap = below ? 0.5e-6 : 30e-6; /* nc below h_min too */
            double f_in = eval(models[k], below, pair_at(gap, 0.1)).f_normal;
            double f_out = eval(models[k], below, pair_at(gap, -0.1)).f_normal;
            if (!(f_in > 0) || !(f_out < 0))
                fail_msg("%s: approach %g N, separation %g N", models[k]->name, f_in, f_out);
            CHECK_REL(f_out, -f_in, 0);
        }
}

/* davis at h = 50 um, v_t = (0, 0.2, 0) m/s: k = 2 pi * 1 * 1.5e-3 * ln(150/50)
 * = 9.42478e-3 * ln 3 = 0.0103541768856696 N s/m; F_t = -k v_t = (0, -2.0708354e-3, 0) N.
 * Torques: n = +x, n x F_t = (0, 0, F_y); torque_i = -R_i n x F_t = (0, 0, +4.1416707e-6),
 * torque_j = -R_j n x F_t = (0, 0, +1.2425012e-5) N m. */
static void test_davis_closed_form(void** state)
{
    (void)state;
    struct wetdem_contact c = pair_at(50e-6, 0.0);
    c.v_t = (struct wetdem_vec3){0, 0.2, 0};
    struct wetdem_pair_force f = eval(&wetdem_force_davis, 0, c);
    CHECK_ABS(f.f_normal, 0, 0);
    CHECK_REL(f.f_tan.y, -0.002070835377133922, TOL_CLOSED);
    CHECK_ABS(f.f_tan.x, 0, 0);
    CHECK_ABS(f.f_tan.z, 0, 0);
    CHECK_REL(f.torque_i.z, 2e-3 * 0.002070835377133922, TOL_CLOSED);
    CHECK_REL(f.torque_j.z, 6e-3 * 0.002070835377133922, TOL_CLOSED);
}

/* nase at h = 10 um, v_t = (0, 0, -0.3): factor 8/15 ln(1.5e-3/1e-5) + 0.9588
 * = 8/15 * 5.0106353 + 0.9588 = 3.6311388; k = 6 pi * 1.5e-3 * 3.6311388 = 0.1026680 N s/m;
 * F_t = -k v_t = (0, 0, +0.0308004094) N. */
static void test_nase_closed_form(void** state)
{
    (void)state;
    struct wetdem_contact c = pair_at(10e-6, 0.0);
    c.v_t = (struct wetdem_vec3){0, 0, -0.3};
    struct wetdem_pair_force f = eval(&wetdem_force_nase, 0, c);
    CHECK_REL(f.f_tan.z, 0.03080040944074787, TOL_CLOSED);
    CHECK_ABS(f.f_tan.y, 0, 0);
}

/* nase does not vanish at h = delta (factor 8/15 ln(15) + 0.9588 > 0) and drops to zero just
 * beyond: the jump Punch's model has. Its factor turns negative for h > a e^(15*0.9588/8)
 * = 6.04 a; there (a = 10 um, h = 80 um = 8 a, factor 8/15 ln(1/8) + 0.9588 = -0.150) the
 * force is floored to zero rather than pushing the sliding; at h = 5 a the factor is
 * 8/15 ln(0.2) + 0.9588 = 0.1005 > 0 and the force resists. */
static void test_nase_film_edge_and_validity_floor(void** state)
{
    (void)state;
    struct wetdem_contact c = pair_at(DELTA, 0.0);
    c.v_t = (struct wetdem_vec3){0, 0.1, 0};
    double k_edge = 6 * M_PI * A_EFF * (8.0 / 15.0 * log(A_EFF / DELTA) + 0.9588);
    CHECK_REL(eval(&wetdem_force_nase, 0, c).f_tan.y, -0.1 * k_edge, TOL_CLOSED);
    c.gap = DELTA * (1 + 1e-12);
    CHECK_ABS(eval(&wetdem_force_nase, 0, c).f_tan.y, 0, 0);

    struct wetdem_contact s = test_contact(2e-5, 2e-5, 1e-6, 1e-6, 80e-6, 0.0); /* a = 10 um */
    s.v_t = (struct wetdem_vec3){0, 0.1, 0};
    CHECK_ABS(eval(&wetdem_force_nase, 0, s).f_tan.y, 0, 0);
    s.gap = 50e-6;
    double k5 = 6 * M_PI * 1e-5 * (8.0 / 15.0 * log(0.2) + 0.9588);
    CHECK_REL(eval(&wetdem_force_nase, 0, s).f_tan.y, -0.1 * k5, TOL_CLOSED);
}

/* Tangential forces are antiparallel to v_t for any direction of v_t: F . v = -|F||v|.
 * Tolerance 1e-14: one dot product and two norms of three terms. */
static void test_tangential_opposes_surface_velocity(void** state)
{
    (void)state;
    const struct wetdem_vec3 dirs[] = {{0, 1, 0}, {0, -0.3, 0.7}, {0, 0, -2}};
    for (size_t k = 2; thin_film_models[k]; k++)
        for (size_t d = 0; d < 3; d++) {
            struct wetdem_contact c = pair_at(20e-6, 0.05);
            c.v_t = dirs[d];
            struct wetdem_vec3 f = eval(thin_film_models[k], 0, c).f_tan;
            double dot = f.x * c.v_t.x + f.y * c.v_t.y + f.z * c.v_t.z;
            CHECK_REL(dot, -vec_norm_test(f) * vec_norm_test(c.v_t), 1e-14);
            if (!(dot < 0))
                fail_msg("%s does not resist sliding", thin_film_models[k]->name);
        }
}

/* Pure spin: centres at rest, i (R_i = 2 mm at +x) spins with omega_i = (0, 0, 10) rad/s.
 * Its surface at the contact point -R_i n moves at omega x (-R_i x) = -R_i omega y
 * = (0, -0.02, 0) m/s. davis/nase push i's surface along +y, so the torque on i,
 * -R_i x x F = -R_i F_y z, opposes its spin, and j is driven the opposite way (as meshing
 * gears). Geometry from wetdem_contact_from_particles, so the spin enters through v_t. */
static void test_tangential_resists_pure_spin(void** state)
{
    (void)state;
    struct wetdem_material mat = {.density = 7800,
                                  .youngs_modulus = 200e9,
                                  .poisson_ratio = 0.3,
                                  .restitution = 0.9,
                                  .friction_dry = 0.1,
                                  .friction_lub = 0.02,
                                  .roughness = 1e-7,
                                  .film = 50e-6};
    struct wetdem_fluid fluid = {.viscosity = 1.0, .surface_tension = 0.02, .density = 1000};
    struct wetdem_particle pi_ = {
        .pos = {RI + RJ + 40e-6, 0, 0}, .omega = {0, 0, 10}, .radius = RI, .mass = MI};
    struct wetdem_particle pj = {.pos = {0, 0, 0}, .radius = RJ, .mass = MJ};
    struct wetdem_contact c;
    wetdem_contact_from_particles(&c, &pi_, &mat, &pj, &mat, &fluid);
    c.h_min = 1e-6;
    CHECK_REL(c.v_t.y, -0.02, 1e-15);
    CHECK_ABS(c.v_n, 0, 0);
    for (size_t k = 2; thin_film_models[k]; k++) {
        struct wetdem_pair_force f = eval(thin_film_models[k], 0, c);
        if (!(f.f_tan.y > 0) || !(f.torque_i.z < 0) || !(f.torque_j.z < 0))
            fail_msg("%s: F_y = %g, torque_i.z = %g, torque_j.z = %g", thin_film_models[k]->name,
                     f.f_tan.y, f.torque_i.z, f.torque_j.z);
        CHECK_REL(f.torque_i.z, -RI * f.f_tan.y, 1e-15);
        CHECK_ABS(f.f_normal, 0, 0); /* v_n = 0 */
    }
}

/* Capillary: -8 pi a sigma = -8 pi * 1.5e-3 * 0.02 = -7.5398223686155e-4 N for h <= delta,
 * including solid overlap; zero beyond delta and without a film. */
static void test_capillary_value_and_extent(void** state)
{
    (void)state;
    const double gaps[] = {DELTA, 0.3 * DELTA, 0.0, -1e-6};
    for (size_t g = 0; g < 4; g++) {
        struct wetdem_pair_force f = eval(&wetdem_force_capillary, 0, pair_at(gaps[g], 0.3));
        CHECK_REL(f.f_normal, -7.539822368615504e-4, TOL_CLOSED);
        CHECK_ABS(vec_norm_test(f.torque_i), 0, 0);
    }
    CHECK_ABS(eval(&wetdem_force_capillary, 0, pair_at(1.0001 * DELTA, 0.3)).f_normal, 0, 0);
    struct wetdem_contact dry = pair_at(-1e-6, 0.3);
    dry.film = 0;
    CHECK_ABS(eval(&wetdem_force_capillary, 0, dry).f_normal, 0, 0);
}

/* reynolds: 6 pi mu R*^2 v_n / max(h, h_min) for 0 < h <= R*:
 * h = 100 um: 6 pi * 2.25e-6 * 0.1 / 1e-4 = 0.0424115008234622 N;
 * h = 0.5 um < h_min = 1 um: 6 pi * 2.25e-7 / 1e-6 = 4.24115008234622 N; zero at h <= 0. */
static void test_reynolds_closed_form(void** state)
{
    (void)state;
    CHECK_REL(eval(&wetdem_force_reynolds, 0, pair_at(100e-6, 0.1)).f_normal, 0.042411500823462206,
              TOL_CLOSED);
    CHECK_REL(eval(&wetdem_force_reynolds, 0, pair_at(0.5e-6, 0.1)).f_normal, 4.241150082346221,
              TOL_CLOSED);
    CHECK_ABS(eval(&wetdem_force_reynolds, 0, pair_at(0.0, 0.1)).f_normal, 0, 0);
    CHECK_ABS(eval(&wetdem_force_reynolds, 0, pair_at(-1e-7, 0.1)).f_normal, 0, 0);
}

/* i<->j swap (R_i != R_j, m_i != m_j): equal normal force along the reversed normal, opposite
 * tangential force, torque_i and torque_j exchanged. The swap only flips signs and exchanges
 * operands, which is exact in IEEE arithmetic: tolerance 0. Angular momentum: the torques
 * about the centres sum to -(R_i + R_j) n x F_t (forces applied at each surface point). */
static void test_fluid_swap_symmetry(void** state)
{
    (void)state;
    const struct wetdem_model* models[] = {&wetdem_force_sb,
                                           &wetdem_force_db,
                                           &wetdem_force_davis,
                                           &wetdem_force_nase,
                                           &wetdem_force_capillary,
                                           &wetdem_force_reynolds,
                                           NULL};
    const double gaps[] = {30e-6, 0.4e-6, -0.5e-6};
    for (size_t k = 0; models[k]; k++)
        for (size_t g = 0; g < 3; g++)
            for (int below = 0; below < 2; below++) {
                struct wetdem_contact c = pair_at(gaps[g], 0.07);
                c.normal = (struct wetdem_vec3){0.6, 0.8, 0};
                c.v_t = (struct wetdem_vec3){-0.08, 0.06, 0.05}; /* perpendicular to n */
                struct wetdem_contact s = wetdem_contact_swapped(&c);
                struct wetdem_pair_force f = eval(models[k], below, c);
                struct wetdem_pair_force b = eval(models[k], below, s);
                CHECK_REL(b.f_normal, f.f_normal, 0);
                CHECK_REL(b.f_tan.x, -f.f_tan.x, 0);
                CHECK_REL(b.f_tan.z, -f.f_tan.z, 0);
                CHECK_REL(b.torque_i.z, f.torque_j.z, 0);
                CHECK_REL(b.torque_j.x, f.torque_i.x, 0);
                struct wetdem_vec3 nxf = {c.normal.y * f.f_tan.z - c.normal.z * f.f_tan.y,
                                          c.normal.z * f.f_tan.x - c.normal.x * f.f_tan.z,
                                          c.normal.x * f.f_tan.y - c.normal.y * f.f_tan.x};
                double tol = 1e-15 * (RI + RJ) * vec_norm_test(f.f_tan);
                CHECK_ABS(f.torque_i.x + f.torque_j.x, -(RI + RJ) * nxf.x, tol);
                CHECK_ABS(f.torque_i.y + f.torque_j.y, -(RI + RJ) * nxf.y, tol);
                CHECK_ABS(f.torque_i.z + f.torque_j.z, -(RI + RJ) * nxf.z, tol);
            }
}

/* Branch gaps for event location: thin films {delta, min(h_min, delta)}, capillary {delta},
 * reynolds {R*, h_min, 0}. */
static void test_fluid_thresholds(void** state)
{
    (void)state;
    struct wetdem_contact c = pair_at(10e-6, 0.1);
    double params[8], gaps[WETDEM_MAX_THRESHOLDS];
    make_params(&wetdem_force_sb, 0, params);
    CHECK_REL((double)wetdem_force_sb.thresholds(params, &c, NULL, gaps), 2, 0);
    CHECK_REL(gaps[0], DELTA, 0);
    CHECK_REL(gaps[1], 1e-6, 0);
    c.h_min = 3 * DELTA;
    wetdem_force_davis.thresholds(params, &c, NULL, gaps);
    CHECK_REL(gaps[1], DELTA, 0);
    CHECK_REL((double)wetdem_force_capillary.thresholds(params, &c, NULL, gaps), 1, 0);
    CHECK_REL(gaps[0], DELTA, 0);
    make_params(&wetdem_force_reynolds, 0, params);
    c.h_min = 1e-6;
    CHECK_REL((double)wetdem_force_reynolds.thresholds(params, &c, NULL, gaps), 3, 0);
    CHECK_REL(gaps[0], A_EFF, 0);
    CHECK_REL(gaps[1], 1e-6, 0);
}

/* below_hmin is an enumeration: set by word, rejected out of range, by number or by typo,
 * with a message naming the parameter and its valid choices. */
static void test_fluid_params_validated(void** state)
{
    (void)state;
    struct wetdem_sim* sim = wetdem_sim_create();
    CHECK_OK(wetdem_sim_enable_model(sim, "db"));
    CHECK_OK(wetdem_sim_enable_model(sim, "nase"));
    double v = -1;
    CHECK_OK(wetdem_sim_param(sim, "db.below_hmin", &v));
    CHECK_REL(v, 0, 0); /* default "c" */
    CHECK_OK(wetdem_sim_set_param_str(sim, "db.below_hmin", "nc"));
    CHECK_OK(wetdem_sim_param(sim, "db.below_hmin", &v));
    CHECK_REL(v, 1, 0);
    CHECK_STATUS(wetdem_sim_set_param_str(sim, "db.below_hmin", "ncc"), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "db.below_hmin");
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "one of: c, nc");
    CHECK_STATUS(wetdem_sim_set_param(sim, "db.below_hmin", 2), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_sim_errmsg(sim), "below_hmin");
    CHECK_STATUS(wetdem_sim_set_param(sim, "nase.below_hmin", 0.5), WETDEM_ERR_INVALID);
    CHECK_STATUS(wetdem_sim_set_param(sim, "nase.below_hmin", NAN), WETDEM_ERR_INVALID);
    CHECK_OK(wetdem_sim_param(sim, "db.below_hmin", &v));
    CHECK_REL(v, 1, 0); /* rejected values leave the parameter unchanged */
    wetdem_sim_free(sim);
}

/* relaxation_time, the many-particle engine's step bound (docs/many.md, Time step): m / c_d
 * at the gap that damps most. c_d is measured from each model's own force at unit speed
 * (normal: F_n at v_n = 1 m/s; tangential: |F_t| at |v_t| = 1 m/s) on gaps from the
 * stiffest one (h_min' = min(h_min, delta) for the thin films, h_min for reynolds, nijssen's
 * own h_min = max(h_sigma, h_eps) at v0 = 1 m/s) out to the film's edge or the cut-off: the
 * hook equals m / c_d there (m = m*, or 2/7 m* for the tangential laws) to TOL_CLOSED, and
 * no gap further out damps more; nijssen's also covers its contact branch's dashpots, whose
 * shorter time it returns here. With h_min = 0 the laws have no bound near contact (0);
 * capillary damps nothing viscously (no hook). */
static void test_fluid_relaxation_time_is_the_stiffest_damping(void** state)
{
    (void)state;
    const struct {
        const struct wetdem_model* model;
        bool tangential;
    } cases[] = {{&wetdem_force_sb, false},       {&wetdem_force_db, false},
                 {&wetdem_force_reynolds, false}, {&wetdem_force_nijssen, false},
                 {&wetdem_force_davis, true},     {&wetdem_force_nase, true}};
    const double m_eff = MI * MJ / (MI + MJ);
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        const struct wetdem_model* m = cases[k].model;
        double params[8] = {0};
        make_params(m, 0, params);
        struct wetdem_contact c = pair_at(DELTA, 1.0);
        assert_non_null(m->relaxation_time);
        double tau = m->relaxation_time(params, &c);
        double h_stiff = c.h_min; /* 1 um < delta */
        if (m == &wetdem_force_nijssen) {
            double h_eps = 0.37 * A_EFF * pow(c.viscosity * 1.0 / (c.e_star * A_EFF), 0.4);
            h_stiff = fmax(c.roughness, h_eps);
        }
        double mass = cases[k].tangential ? 2.0 / 7.0 * m_eff : m_eff;
        double range = m->range(params, &c);
        bool first = true;
        for (double g = h_stiff; g < range; g *= 1.7, first = false) {
            struct wetdem_contact at = pair_at(g, cases[k].tangential ? 0.0 : 1.0);
            if (cases[k].tangential)
                at.v_t = (struct wetdem_vec3){0, 1.0, 0};
            struct wetdem_pair_force f = eval(m, 0, at);
            double c_d = cases[k].tangential ? vec_norm_test(f.f_tan) : f.f_normal;
            if (first && m == &wetdem_force_nijssen) /* its contact dashpots: below */
                assert_true(tau <= mass / c_d * (1 + TOL_CLOSED));
            else if (first)
                CHECK_REL(tau, mass / c_d, TOL_CLOSED);
            else if (!(mass / c_d >= tau))
                fail_msg("%s: gap %g m damps more (m/c_d = %g s) than relaxation_time %g s",
                         m->name, g, mass / c_d, tau);
        }
        if (m == &wetdem_force_nijssen) {
            /* the contact branch's Hertz and Mindlin dashpots (Eqs. 7, 10) at the largest
               shifted overlap of an undamped approach at v0 = 1 m/s, d_max^(5/2) =
               (5/4) m* v0^2 / k + (2/7) h_min^(5/2) (force_nijssen.c) */
            double k_h = 4.0 / 3.0 * c.e_star * sqrt(c.r_eff);
            double d = pow(1.25 * m_eff / k_h + 2.0 / 7.0 * pow(h_stiff, 2.5), 0.4);
            double c_n =
                wetdem_force_hertz_damping(c.e_star, c.r_eff, m_eff, d, 1.0, c.restitution, 0);
            double c_t = wetdem_force_mindlin_damping_factor(c.restitution) *
                         sqrt(m_eff * 8.0 * c.g_star * sqrt(c.r_eff * d));
            double lub = m_eff / (6 * M_PI * c.viscosity * c.r_eff * c.r_eff / h_stiff);
            CHECK_REL(tau, fmin(lub, fmin(m_eff / c_n, 2.0 / 7.0 * m_eff / c_t)), TOL_CLOSED);
        } else { /* nijssen keeps its own h_min */
            c.h_min = 0;
            CHECK_ABS(m->relaxation_time(params, &c), 0, 0);
        }
    }
    assert_null(wetdem_force_capillary.relaxation_time);
    assert_non_null(wetdem_force_hertz.relaxation_time);   /* its dashpot (test_contact_models) */
    assert_non_null(wetdem_force_mindlin.relaxation_time); /* (test_contact_models) */
}

/* Every fluid model documents itself (docs/models.md is generated from these strings). */
static void test_fluid_models_documented(void** state)
{
    (void)state;
    const char* names[] = {"sb", "db", "davis", "nase", "capillary", "reynolds", "nijssen", NULL};
    for (size_t k = 0; names[k]; k++) {
        const struct wetdem_model* m = wetdem_model_find(names[k]);
        if (!m || m->kind != WETDEM_MODEL_FLUID || !m->summary || !m->doc || !m->equations ||
            strlen(m->doc) < 200 || !m->range || !m->pair || !m->thresholds)
            fail_msg("model %s is missing or incompletely documented", names[k]);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sb_closed_form),
        cmocka_unit_test(test_db_closed_form),
        cmocka_unit_test(test_fluid_zero_beyond_range),
        cmocka_unit_test(test_thin_film_continuous_at_film_edge),
        cmocka_unit_test(test_sb_db_agree_as_gap_vanishes),
        cmocka_unit_test(test_thin_film_c_vs_nc_below_hmin),
        cmocka_unit_test(test_thin_film_hmin_at_or_above_film),
        cmocka_unit_test(test_thin_film_suction_when_separating),
        cmocka_unit_test(test_davis_closed_form),
        cmocka_unit_test(test_nase_closed_form),
        cmocka_unit_test(test_nase_film_edge_and_validity_floor),
        cmocka_unit_test(test_tangential_opposes_surface_velocity),
        cmocka_unit_test(test_tangential_resists_pure_spin),
        cmocka_unit_test(test_capillary_value_and_extent),
        cmocka_unit_test(test_reynolds_closed_form),
        cmocka_unit_test(test_fluid_swap_symmetry),
        cmocka_unit_test(test_fluid_thresholds),
        cmocka_unit_test(test_fluid_params_validated),
        cmocka_unit_test(test_fluid_relaxation_time_is_the_stiffest_damping),
        cmocka_unit_test(test_fluid_models_documented),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

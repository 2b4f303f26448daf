/*
 * test_track.c — experiment tracking (src/track.c, Punch 2023 Sec. 3.2): Savitzky-Golay
 * weights against their closed forms, the exact small-angle bias of Eq. 23, recovery of
 * velocities, spin, impact angle, St_n and e_n from rendered dot tracks with sub-pixel noise,
 * and clear errors for malformed tracks (library and CLI).
 *
 * Rendered tracks: two spheres of Punch Table 1 (R = 12.7 mm), dot 1 at the bottom pole, dots
 * 2 and 3 at polar angle beta = 25 deg forming an equilateral triangle with dot 1, imaged
 * orthographically from below at 5000 frames/s and 175 um/pixel (Punch Sec. 3.1). The motion
 * is closed form: constant velocities and spins with a jump at a contact time between frames
 * (instantaneous collision with chosen e_n, tangential retention, momentum conserved for equal
 * masses), plus a common constant acceleration (the pendulum drift) so that the straight-line
 * fits have a slope to find. A second set renders a collision simulated by wetdem itself
 * (Punch set-up, soft engine, contact-bounce at 30 and 45 deg) and compares the tracked
 * values with the simulation's, within the propagated noise plus the method's biases.
 */
#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include <gsl/gsl_randist.h>
#include <gsl/gsl_rng.h>

#include "harness.h"
#include "track.h"

#define N_FRAMES 120

struct synth {
    double fps, pixel, radius, beta, dphi; /* [1/s], [m/pixel], [m], [rad], [rad] */
    double t_c;                            /* contact time [s] */
    double speed, theta, e_n, e_t;         /* impact speed [m/s], angle [rad], restitutions */
    double acc[2];                         /* common acceleration [m/s^2] */
    double omega_pre[2], omega_post[2];    /* spins of striker (0) and target (1) [rad/s] */
    double yaw[2];                         /* dot-2 azimuth at contact [rad] */
    double v_post[2][2];                   /* post-collision velocities, filled by synth_init */
};

static void synth_init_post(struct synth* y);

static void synth_init(struct synth* y, double theta)
{
    *y = (struct synth){.fps = 5000,
                        .pixel = 175e-6,
                        .radius = 12.7e-3,
                        .beta = 25 * M_PI / 180,
                        .t_c = 50.37 / 5000,
                        .speed = 0.3,
                        .theta = theta,
                        .e_n = 0.6,
                        .e_t = 0.8,
                        .acc = {-0.4, 0.1},
                        .omega_pre = {3, 0},
                        .omega_post = {-18, 25},
                        .yaw = {0.4, 2.1}};
    /* Equal chords |p1 p2| = |p2 p3|: 2R sin(beta/2) = 2R sin(beta) sin(dphi/2). */
    y->dphi = 2 * asin(sin(y->beta / 2) / sin(y->beta));
    synth_init_post(y);
}

/* The post-collision velocities from speed, theta, e_n and e_t. */
static void synth_init_post(struct synth* y)
{
    double theta = y->theta;
    double n[2] = {-cos(theta), -sin(theta)}; /* from target to striker at contact */
    double vn = y->speed * n[0];              /* v_rel . n (< 0: approaching) */
    double vrel_f[2];
    for (int c = 0; c < 2; c++) {
        double vrel = c == 0 ? y->speed : 0;
        vrel_f[c] = -y->e_n * vn * n[c] + y->e_t * (vrel - vn * n[c]);
    }
    for (int c = 0; c < 2; c++) {
        double total = c == 0 ? y->speed : 0; /* momentum of equal masses: v_s + v_g */
        y->v_post[0][c] = 0.5 * (total + vrel_f[c]);
        y->v_post[1][c] = 0.5 * (total - vrel_f[c]);
    }
}

/* True centre position [m], velocity [m/s], dot-2 azimuth [rad] and spin of a sphere. */
static void synth_state(const struct synth* y, int k, double t, double pos[2], double vel[2],
                        double* yaw, double* omega)
{
    double d = 2 * y->radius, tau = t - y->t_c;
    double at_contact[2] = {k == 0 ? -d * cos(y->theta) : 0, k == 0 ? -d * sin(y->theta) : 0};
    for (int c = 0; c < 2; c++) {
        double v = tau < 0 ? (k == 0 && c == 0 ? y->speed : 0) : y->v_post[k][c];
        pos[c] = at_contact[c] + v * tau + 0.5 * y->acc[c] * t * t;
        vel[c] = v + y->acc[c] * t;
    }
    *omega = tau < 0 ? y->omega_pre[k] : y->omega_post[k];
    *yaw = y->yaw[k] + *omega * tau;
}

/* The three dots of a sphere with centre pos [m] and dot-2 azimuth yaw [rad], in pixels, with
 * Gaussian noise of sigma_px on every coordinate (rng may be NULL). Dot 1 is the pole facing
 * the camera (projected onto the centre), dots 2 and 3 lie at polar angle beta from it, so
 * their images are at rho = R sin(beta) from dot 1. */
static void pose_dots(const struct synth* y, const double pos[2], double yaw, gsl_rng* rng,
                      double sigma_px, double xy[6])
{
    double rho = y->radius * sin(y->beta);
    double az[3] = {0, yaw, yaw + y->dphi};
    for (int j = 0; j < 3; j++) {
        double r = j == 0 ? 0 : rho;
        xy[2 * j] = (pos[0] + r * cos(az[j])) / y->pixel + 600;
        xy[2 * j + 1] = (pos[1] + r * sin(az[j])) / y->pixel + 400;
        for (int c = 0; c < 2 && rng; c++)
            xy[2 * j + c] += gsl_ran_gaussian(rng, sigma_px);
    }
}

/* Dots of sphere k at frame f in pixels, with Gaussian noise of sigma_px (rng may be NULL). */
static void synth_dots(const struct synth* y, int k, int f, gsl_rng* rng, double sigma_px,
                       double xy[6])
{
    double pos[2], vel[2], yaw, omega;
    synth_state(y, k, f / y->fps, pos, vel, &yaw, &omega);
    pose_dots(y, pos, yaw, rng, sigma_px, xy);
}

/* ---- Savitzky-Golay weights ---------------------------------------------------------------- */

static void test_track_savgol_matches_closed_form(void** state)
{
    (void)state;
    /* Quadratic least squares on u = -2..2: the centre value is
     * (-3 x_-2 + 12 x_-1 + 17 x_0 + 12 x_1 - 3 x_2)/35 (normal equations with sum u^2 = 10,
     * sum u^4 = 34); on u = -3..3 it is (-2, 3, 6, 7, 6, 3, -2)/21. */
    const double w5[5] = {-3, 12, 17, 12, -3}, w7[7] = {-2, 3, 6, 7, 6, 3, -2};
    double hat[49];
    CHECK_OK(wetdem_track_savgol_hat(5, 2, hat));
    for (int m = 0; m < 5; m++)
        CHECK_ABS(hat[2 * 5 + m], w5[m] / 35, 1e-14); /* QR round-off, entries O(1): 1.4e-16 */
    CHECK_OK(wetdem_track_savgol_hat(7, 2, hat));
    for (int m = 0; m < 7; m++)
        CHECK_ABS(hat[3 * 7 + m], w7[m] / 21, 1e-14);
    CHECK_STATUS(wetdem_track_savgol_hat(6, 2, hat), WETDEM_ERR_INVALID);
    CHECK_STATUS(wetdem_track_savgol_hat(5, 5, hat), WETDEM_ERR_INVALID);
}

static void test_track_savgol_keeps_quadratics_up_to_the_ends(void** state)
{
    (void)state;
    /* A least-squares polynomial of order 2 reproduces any quadratic exactly, including the
     * shifted (end) windows. Round-off: 7 terms of values up to 60 (ulp 7e-15) times
     * weights carrying 1e-16 of QR round-off, ~1e-13; 1e-12 (measured 1.4e-14). */
    double hat[49], x[20], out[20];
    CHECK_OK(wetdem_track_savgol_hat(7, 2, hat));
    for (int i = 0; i < 20; i++)
        x[i] = 1 + 2.5 * i - 0.3 * i * i;
    wetdem_track_savgol_apply(hat, 7, x, 20, out);
    for (int i = 0; i < 20; i++)
        CHECK_ABS(out[i], x[i], 1e-12);
}

/* ---- Eq. 23 and its small-angle bias ------------------------------------------------------- */

static void test_track_interval_small_angle_bias_is_exact(void** state)
{
    (void)state;
    /* Rigid step: translation v dt plus rotation by a about dot 1. The least squares gives
     * omega dt = sin(a) exactly and v dt + (cos a - 1)(D2 + D3)/3 (track.c header); checked at
     * a = 0.3 rad, far beyond the 6e-3 rad per frame of 30 rad/s at 5000 frames/s. */
    double dt = 2e-4, a = 0.3, v[2] = {0.4, -0.1};
    double d2[2] = {3e-3, 1e-3}, d3[2] = {-0.5e-3, 2.5e-3}, p0[6] = {0.01, 0.02}, p1[6], out[3];
    for (int k = 0; k < 2; k++) {
        const double* d = k == 0 ? d2 : d3;
        p0[2 + 2 * k] = p0[0] + d[0];
        p0[3 + 2 * k] = p0[1] + d[1];
        p1[2 + 2 * k] = p0[0] + v[0] * dt + cos(a) * d[0] - sin(a) * d[1];
        p1[3 + 2 * k] = p0[1] + v[1] * dt + sin(a) * d[0] + cos(a) * d[1];
    }
    p1[0] = p0[0] + v[0] * dt;
    p1[1] = p0[1] + v[1] * dt;
    double rms;
    CHECK_OK(wetdem_track_solve_interval(p0, p1, dt, out, &rms));
    /* round-off of a 6x3 QR on positions ~0.02 m whose differences (~3e-3 m) carry the
       rotation: ~10 ulp, 1e-13 (measured 3.4e-15) */
    CHECK_REL(out[2], sin(a) / dt, 1e-13);
    /* the translation v dt = 8e-5 m is a difference of positions ~0.01 m, which keeps only
       ~125 ulp of its digits (3e-14): 1e-12 (measured 1.6e-14) */
    for (int c = 0; c < 2; c++)
        CHECK_REL(out[c], v[c] + (cos(a) - 1) * (d2[c] + d3[c]) / (3 * dt), 1e-12);
    /* Degenerate dots: all three in one place. */
    double z[6] = {1, 1, 1, 1, 1, 1};
    CHECK_STATUS(wetdem_track_solve_interval(z, z, dt, out, NULL), WETDEM_ERR_NUMERIC);
}

/* ---- recovery from rendered tracks --------------------------------------------------------- */

#define N_OUT 11
/* Outputs compared: striker before vx, vy; striker after vx, vy, omega; target after vx, vy,
 * omega; e_n; impact angle; St_n. */
static int analyse_dots(const double* dots, const struct wetdem_track_options* o, double out[N_OUT],
                        struct wetdem_track_summary* sum)
{
    struct wetdem_track* t = wetdem_track_create();
    for (int f = 0; f < N_FRAMES; f++)
        for (int k = 0; k < 2; k++)
            assert_int_equal(wetdem_track_add_frame(t, k + 1, f, dots + 12 * f + 6 * k), 0);
    int st = wetdem_track_analyse(t, o, sum);
    if (st != WETDEM_OK)
        print_error("%s\n", wetdem_track_errmsg(t));
    wetdem_track_free(t);
    double v[N_OUT] = {sum->striker_before.vx,
                       sum->striker_before.vy,
                       sum->striker_after.vx,
                       sum->striker_after.vy,
                       sum->striker_after.omega,
                       sum->target_after.vx,
                       sum->target_after.vy,
                       sum->target_after.omega,
                       sum->e_n,
                       sum->impact_angle,
                       sum->stokes_n};
    memcpy(out, v, sizeof v);
    return st;
}

/* The same outputs from the true motion, using the tracker's definitions at its frames. */
static void true_outputs(const struct synth* y, const struct wetdem_track_options* o, long c,
                         double out[N_OUT])
{
    double ps0[2], pg0[2], psf[2], pgf[2], vs0[2], vg0[2], vsf[2], vgf[2], yaw, ws, wg, tmp[2];
    double tb = (double)(c - o->offset) / y->fps, ta = (double)(c + o->offset) / y->fps;
    synth_state(y, 0, tb, tmp, vs0, &yaw, &ws);
    synth_state(y, 1, tb, tmp, vg0, &yaw, &wg);
    synth_state(y, 0, ta, psf, vsf, &yaw, &ws);
    synth_state(y, 1, ta, pgf, vgf, &yaw, &wg);
    synth_state(y, 0, (double)c / y->fps, ps0, tmp, &yaw, tmp);
    synth_state(y, 1, (double)c / y->fps, pg0, tmp, &yaw, tmp);
    double n0[2] = {ps0[0] - pg0[0], ps0[1] - pg0[1]}, nf[2] = {psf[0] - pgf[0], psf[1] - pgf[1]};
    double l0 = hypot(n0[0], n0[1]), lf = hypot(nf[0], nf[1]);
    double vn0 = -((vs0[0] - vg0[0]) * n0[0] + (vs0[1] - vg0[1]) * n0[1]) / l0;
    double vnf = ((vsf[0] - vgf[0]) * nf[0] + (vsf[1] - vgf[1]) * nf[1]) / lf;
    double m = 7960 * 4.0 / 3.0 * M_PI * pow(y->radius, 3), r_eff = y->radius / 2;
    double v[N_OUT] = {vs0[0],
                       vs0[1],
                       vsf[0],
                       vsf[1],
                       ws,
                       vgf[0],
                       vgf[1],
                       wg,
                       vnf / vn0,
                       acos(vn0 / hypot(vs0[0] - vg0[0], vs0[1] - vg0[1])),
                       (m / 2) * vn0 / (6 * M_PI * 10.0 * r_eff * r_eff)};
    memcpy(out, v, sizeof v);
}

/* Method biases of the outputs (index as N_OUT), independent of the noise:
 * - small-angle approximation of Eq. 23 (track.c header): velocity bias
 *   omega^2 dt |D2 + D3|/6 with |D2 + D3| = 2 rho cos(dphi/2) = 2 * 5.37 mm * cos(30.8 deg)
 *   = 9.2 mm: at 25 rad/s, 625 * 2e-4 * 9.2e-3/6 = 1.9e-4 m/s (at 3 rad/s, 3e-6 m/s);
 *   relative spin bias (omega dt)^2/6 = (5e-3)^2/6 = 4e-6, i.e. 1e-4 rad/s;
 * - e_n: the velocity biases of both spheres over v_n0 >= 0.15 m/s (60 deg):
 *   (1.9e-4 + 1.0e-4)/0.15 = 2e-3; impact angle and St_n use pre-collision values (3 rad/s);
 * - the rotation of the outer dots within a 7-frame window departs from a quadratic by
 *   O((3 omega dt)^3 rho) ~ 2e-9 m, negligible. */
static const double method_bias[N_OUT] = {1e-5,   1e-5, 2.5e-4, 2.5e-4, 2e-4, 2.5e-4,
                                          2.5e-4, 2e-4, 3e-3,   1e-4,   1e-4};

static void track_options(struct wetdem_track_options* o, const struct synth* y)
{
    wetdem_track_options_init(o);
    o->fps = y->fps;
    o->pixel_size = y->pixel;
    o->radius = y->radius;
    o->mass = 7960 * 4.0 / 3.0 * M_PI * pow(y->radius, 3);
    o->viscosity = 10.0;
}

static void render(const struct synth* y, gsl_rng* rng, double sigma_px, double* dots)
{
    for (int f = 0; f < N_FRAMES; f++)
        for (int k = 0; k < 2; k++)
            synth_dots(y, k, f, rng, sigma_px, dots + 12 * f + 6 * k);
}

/* Standard deviation of each output for independent pixel noise sigma_px on every coordinate:
 * the analysis is linear in the dot positions once the collision frame is fixed, so
 * sigma_out^2 = sigma_px^2 sum_j (d out / d xy_j)^2, with the gains by finite differences. */
static void noise_sigma(double* dots, const struct wetdem_track_options* o, double sigma_px,
                        const double base[N_OUT], double sigma[N_OUT])
{
    const double eps = 1e-3; /* [pixel]: linear regime, far above round-off */
    double sum2[N_OUT] = {0}, out[N_OUT];
    struct wetdem_track_summary s;
    for (int j = 0; j < 12 * N_FRAMES; j++) {
        dots[j] += eps;
        CHECK_OK(analyse_dots(dots, o, out, &s));
        dots[j] -= eps;
        for (int q = 0; q < N_OUT; q++)
            sum2[q] += pow((out[q] - base[q]) / eps, 2);
    }
    for (int q = 0; q < N_OUT; q++)
        sigma[q] = sigma_px * sqrt(sum2[q]);
}

static void check_recovery(double theta, unsigned long seed)
{
    struct synth y;
    synth_init(&y, theta);
    struct wetdem_track_options o;
    track_options(&o, &y);
    /* 0.05 pixel: sub-pixel accuracy of correlation-based tracking (Punch Sec. 3.1 uses
     * feature correlation; 0.01-0.05 px is typical). It gives smoothed per-frame velocities
     * with sigma ~ 0.012 m/s, so the 0.05 m/s collision threshold is 4 sigma above noise. */
    const double sigma_px = 0.05;
    gsl_rng* rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, seed);
    double* dots = malloc(12 * N_FRAMES * sizeof *dots);
    render(&y, rng, sigma_px, dots);
    gsl_rng_free(rng);
    double got[N_OUT], want[N_OUT], sigma[N_OUT];
    struct wetdem_track_summary s;
    CHECK_OK(analyse_dots(dots, &o, got, &s));
    assert_int_equal(s.striker_id, 1);
    /* The jump is in interval 50 (t_c = 50.37 frames); the smoothing spreads it over
     * window/2 = 3 intervals, so the detected collision frame lies in [47, 50]. */
    assert_true(s.collision_frame >= 47 && s.collision_frame <= 50);
    true_outputs(&y, &o, s.collision_frame, want);
    noise_sigma(dots, &o, sigma_px, got, sigma);
    /* Tolerance: 4 sigma (two-sided false alarm 6e-5 per check) plus the method biases. */
    for (int q = 0; q < N_OUT; q++)
        if (!(fabs(got[q] - want[q]) <= 4 * sigma[q] + method_bias[q]))
            fail_msg("theta %.0f deg output %d: got %.6g, true %.6g, |diff| %.3g > 4 sigma %.3g "
                     "+ bias %.3g",
                     theta * 180 / M_PI, q, got[q], want[q], fabs(got[q] - want[q]), 4 * sigma[q],
                     method_bias[q]);
    /* The tolerance must stay meaningful: at 0.05 px, sigma(e_n) is 0.008 head-on and 0.018
     * at 60 deg (v_n0 = 0.15 m/s), sigma(omega) 0.4 rad/s; require 4 sigma(e_n) < 0.1. */
    assert_true(sigma[8] < 0.025);
    /* Eq. 3 with n_f taken `offset` frames after contact differs from the contact value e_n by
     * the rotation of the line of centres as the spheres fly apart, (e_t v_t)^2 tau/(d e v_n)
     * relative: tau <= 8 frames = 1.6 ms, 60 deg: (0.8 * 0.26)^2 * 1.6e-3/(25.4e-3 * 0.09)
     * = 3 %, so the physical e_n = 0.6 is met within 3 % + 4 sigma. */
    assert_true(fabs(got[8] - y.e_n) <= 0.03 * y.e_n + 4 * sigma[8]);
    free(dots);
}

static void test_track_recovers_collision_from_noisy_dots(void** state)
{
    (void)state;
    check_recovery(0.0, 11);
    check_recovery(45 * M_PI / 180, 12);
    check_recovery(60 * M_PI / 180, 13);
}

/* A pair that sticks (e_n = 0, head-on): the normal speed after is 0 up to the noise, which
 * makes it slightly negative about half the time. It is reported as measured (|e_n| within
 * 4 noise sigmas of 0.05 px, ~0.03), not refused as a change that is no collision, which
 * needs the spheres to approach after it faster than the threshold (50 mm/s). 20 seeds. */
static void test_track_sticking_pair_is_reported(void** state)
{
    (void)state;
    struct synth y;
    synth_init(&y, 0.0);
    y.e_n = 0.0;
    y.e_t = 0.0;
    synth_init_post(&y);
    struct wetdem_track_options o;
    track_options(&o, &y);
    static double dots[12 * N_FRAMES];
    gsl_rng* rng = gsl_rng_alloc(gsl_rng_mt19937);
    int negative = 0;
    for (unsigned long seed = 1; seed <= 20; seed++) {
        gsl_rng_set(rng, seed);
        render(&y, rng, 0.05, dots);
        double out[N_OUT];
        struct wetdem_track_summary sum;
        CHECK_OK(analyse_dots(dots, &o, out, &sum));
        assert_true(fabs(sum.e_n) < 0.03);
        negative += sum.e_n < 0;
    }
    assert_true(negative > 0); /* (the case the refusal had hit: measured 8 of 20) */
    gsl_rng_free(rng);
}

static void test_track_noise_free_recovery_is_tight(void** state)
{
    (void)state;
    /* Without noise only the small-angle and quadratic-window biases remain (see above). */
    struct synth y;
    synth_init(&y, 30 * M_PI / 180);
    struct wetdem_track_options o;
    track_options(&o, &y);
    double *dots = malloc(12 * N_FRAMES * sizeof *dots), got[N_OUT], want[N_OUT];
    render(&y, NULL, 0, dots);
    struct wetdem_track_summary s;
    CHECK_OK(analyse_dots(dots, &o, got, &s));
    true_outputs(&y, &o, s.collision_frame, want);
    for (int q = 0; q < N_OUT; q++)
        if (!(fabs(got[q] - want[q]) <= method_bias[q] * fmax(1, fabs(want[q]))))
            fail_msg("output %d: got %.9g, true %.9g, bias bound %.3g", q, got[q], want[q],
                     method_bias[q]);
    CHECK_ABS(s.angle_centres, 30 * M_PI / 180, 0.01); /* striker 0.2 mm short of contact */
    /* y_down negates y: the spin changes sign, the speeds do not. Negation is exact and
       commutes with rounding, so only libm's odd functions could differ, by an ulp or so:
       1e-14 (measured 0). */
    o.y_down = true;
    double flipped[N_OUT];
    CHECK_OK(analyse_dots(dots, &o, flipped, &s));
    CHECK_REL(flipped[4], -got[4], 1e-14);
    CHECK_REL(flipped[8], got[8], 1e-14);
    free(dots);
}

/* ---- recovery from a simulated collision --------------------------------------------------- */

/* A Punch collision simulated by wetdem (soft engine: Hertz-Mindlin, DB and Davis thin-film
 * forces with the c treatment, glass-transition h_min), recorded by an observer, rendered as
 * dots and tracked. The collision lies in the x-y plane with spins about z; z points up and
 * the camera looks up from below (Punch Sec. 3.1). Seen from below with the image columns
 * along +x the image rows run along +y, so the pixel frame (column, row) is the world's
 * (x, y) and the tracker's counter-clockwise omega is omega_z (no y_down). */

#define SIM_SUB 8  /* observer samples per frame: the spins are integrated into the azimuths */
#define SIM_PRE 50 /* frames before the simulation starts (free flight, extrapolated) */

struct sim_record {
    size_t n, cap;
    double* q; /* per sample SIM_COLS values: t [s], then per sphere x, y [m], vx, vy [m/s],
                  omega_z [rad/s], azimuth of dot 2 [rad] (filled after the run) */
};
#define SIM_COLS 13

static int record_state(const struct wetdem_sim* sim, void* ctx)
{
    struct sim_record* r = ctx;
    size_t n;
    const struct wetdem_particle* p = wetdem_sim_particles_const(sim, &n);
    if (r->n == r->cap) {
        r->cap = r->cap ? 2 * r->cap : 256;
        double* q = realloc(r->q, r->cap * SIM_COLS * sizeof *q);
        if (!q)
            return 1;
        r->q = q;
    }
    double* q = r->q + SIM_COLS * r->n++;
    q[0] = wetdem_sim_time(sim);
    for (size_t k = 0; k < 2 && k < n; k++) {
        double v[6] = {p[k].pos.x, p[k].pos.y, p[k].vel.x, p[k].vel.y, p[k].omega.z, 0};
        memcpy(q + 1 + 6 * k, v, sizeof v);
    }
    return 0;
}

/* Punch set-up (Table 1): dry punch_steel striker on a punch_steel_coated target (270 um of
 * 10 Pa s silicone oil), hertz + mindlin (mu_f = 0.05 of the presets) + db + davis, glass
 * h_min (P_gt = 11.6 MPa, instantaneous normal speed), CVODE. Records the state every
 * 1/(SIM_SUB fps) and integrates the spins into the dot azimuths by the trapezoidal rule.
 * Only the spin's integral matters between samples: an error there shifts the azimuth by a
 * constant after the collision, which Eq. 23 does not see. */
static void punch_collision(double stokes, double angle, double fps, const double yaw0[2],
                            struct sim_record* rec, struct wetdem_collision_result* res)
{
    struct wetdem_sim* sim = wetdem_sim_create();
    struct wetdem_fluid fluid;
    CHECK_OK(wetdem_fluid_preset("silicone10", &fluid));
    CHECK_OK(wetdem_sim_set_fluid(sim, &fluid));
    assert_int_equal(wetdem_sim_add_material_preset(sim, "punch_steel"), 0);
    assert_int_equal(wetdem_sim_add_material_preset(sim, "punch_steel_coated"), 1);
    static const char* const models[] = {"hertz", "mindlin", "db", "davis", "glass"};
    for (size_t k = 0; k < 5; k++)
        CHECK_OK(wetdem_sim_enable_model(sim, models[k]));
    CHECK_OK(wetdem_sim_set_param_str(sim, "glass.speed", "current"));
    CHECK_OK(wetdem_sim_set_integrator(sim, "cvode"));
    memset(rec, 0, sizeof *rec);
    wetdem_sim_set_observer(sim, 1.0 / (SIM_SUB * fps), record_state, rec);
    struct wetdem_collision_spec spec = {.material_i = 0,
                                         .material_j = 1,
                                         .radius_i = 12.7e-3,
                                         .radius_j = 12.7e-3,
                                         .stokes = stokes,
                                         .angle = angle,
                                         .t_end = 0.05};
    CHECK_OK(wetdem_collision_run(sim, &spec, res));
    wetdem_sim_free(sim);
    assert_true(rec->n >= 2 && res->separated);
    for (size_t k = 0; k < 2; k++) {
        rec->q[6 + 6 * k] = yaw0[k];
        for (size_t i = 1; i < rec->n; i++) {
            double *a = rec->q + SIM_COLS * (i - 1), *b = rec->q + SIM_COLS * i;
            b[6 + 6 * k] = a[6 + 6 * k] + 0.5 * (a[5 + 6 * k] + b[5 + 6 * k]) * (b[0] - a[0]);
        }
    }
}

/* Centre [m], velocity [m/s] and azimuth [rad] of sphere k at time t: a recorded sample on
 * the observer's grid, or free flight (no force acts beyond the interaction range) from the
 * first sample before the run and from the last one after it. */
static void sim_pose(const struct sim_record* r, double fps, int k, double t, double pos[2],
                     double vel[2], double* yaw)
{
    const double* first = r->q;
    const double* last = r->q + SIM_COLS * (r->n - 1);
    const double* q = t <= 0 ? first : last;
    if (t > 0 && t <= last[0]) {
        size_t i = (size_t)lround(t * SIM_SUB * fps);
        assert_true(i < r->n);
        q = r->q + SIM_COLS * i;
        /* on the observer's grid (spacing 25 us): the sample times carry round-off of ~1e-19 s
           (measured 1.1e-19), 1e-16 s is ~60 ulp of 10 ms */
        assert_true(fabs(q[0] - t) < 1e-16);
    }
    const double* s = q + 1 + 6 * k;
    double tau = t - q[0];
    pos[0] = s[0] + s[2] * tau;
    pos[1] = s[1] + s[3] * tau;
    vel[0] = s[2];
    vel[1] = s[3];
    *yaw = s[5] + s[4] * tau;
}

/* The simulation's own values of the outputs (index as N_OUT) and the method's biases against
 * them. Before the collision the spheres move in straight lines (no force acts beyond the
 * interaction range), after it they fly apart freely, so the before/after velocities and
 * spins are the first and last recorded states. The impact angle, v_n0 and St_n refer to the
 * line of centres n_c at contact of the undisturbed straight-line approach (Punch Eq. 16,
 * "the moment before collision"), e_n = (u_f . n_f)/v_n0 to the final, separated relative
 * velocity u_f and the rebound normal n_f (Punch Eq. 3 fully resolved; n_f the result's
 * normal_out, the line of centres at the closest approach).
 * The tracker takes the line of centres at its collision frame k (Eq. 16) and, for e_n, at
 * k + offset; meanwhile the line turns at v_t/d (tangential relative speed over the centre
 * distance), so the angle is off by delta_0 = (v_t0/d) |t_k - t_c| and v_n = |u| cos(angle)
 * by the relative tan(angle) delta: bias(e_n) = e_n (tan(theta_0) delta_0 + tan(theta_f)
 * delta_f) with delta_f the angle between n_f and the simulated line of centres at frame
 * k + offset, bias(St_n) = St_n tan(theta_0) delta_0 (first order; the path's deflection by
 * the film before k is ~10 um, 4e-4 rad).
 * Eq. 23's small-angle bias (track.c header): omega^2 dt |D2 + D3|/6 on the velocities and
 * omega (omega dt)^2/6 on the spin. */
static void simulated_truth(const struct sim_record* r, const struct synth* y,
                            const struct wetdem_track_options* o,
                            const struct wetdem_collision_result* res, long frame_k,
                            double want[N_OUT], double bias[N_OUT])
{
    const double* q0 = r->q + 1;
    const double* qf = r->q + SIM_COLS * (r->n - 1) + 1;
    double d = 2 * y->radius, u0[2] = {q0[2] - q0[8], q0[3] - q0[9]};
    double uf[2] = {qf[2] - qf[8], qf[3] - qf[9]}, nf[2] = {res->normal_out.x, res->normal_out.y};
    /* Straight-line contact: |x0 + u0 t| = d, the smaller root. */
    double x0[2] = {q0[0] - q0[6], q0[1] - q0[7]};
    double a = u0[0] * u0[0] + u0[1] * u0[1], b = x0[0] * u0[0] + x0[1] * u0[1];
    double c = x0[0] * x0[0] + x0[1] * x0[1] - d * d;
    double t_c = (-b - sqrt(b * b - a * c)) / a;
    double nc[2] = {(x0[0] + u0[0] * t_c) / d, (x0[1] + u0[1] * t_c) / d};
    double vn0 = -(u0[0] * nc[0] + u0[1] * nc[1]), vt0 = fabs(u0[0] * nc[1] - u0[1] * nc[0]);
    double vnf = uf[0] * nf[0] + uf[1] * nf[1], vtf = fabs(uf[0] * nf[1] - uf[1] * nf[0]);
    double mass = 7960 * 4.0 / 3.0 * M_PI * pow(y->radius, 3), r_eff = y->radius / 2;
    double v[N_OUT] = {q0[2],
                       q0[3],
                       qf[2],
                       qf[3],
                       qf[4],
                       qf[8],
                       qf[9],
                       qf[10],
                       vnf / vn0,
                       atan2(vt0, vn0),
                       (mass / 2) * vn0 / (6 * M_PI * 10.0 * r_eff * r_eff)};
    memcpy(want, v, sizeof v);
    double dt = 1 / y->fps, t_k = (double)(frame_k - SIM_PRE) * dt;
    double delta0 = vt0 / d * fabs(t_k - t_c);
    double pos_i[2], pos_j[2], vel[2], yaw;
    sim_pose(r, y->fps, 0, t_k + o->offset * dt, pos_i, vel, &yaw);
    sim_pose(r, y->fps, 1, t_k + o->offset * dt, pos_j, vel, &yaw);
    double lx = pos_i[0] - pos_j[0], ly = pos_i[1] - pos_j[1];
    double deltaf = fabs(atan2(lx * nf[1] - ly * nf[0], lx * nf[0] + ly * nf[1]));
    double sum_d = 2 * y->radius * sin(y->beta) * cos(y->dphi / 2); /* |D2 + D3| */
    for (int k = 0; k < 2; k++) {
        double w = k == 0 ? qf[4] : qf[10];
        bias[2 + 3 * k] = bias[3 + 3 * k] = w * w * dt * sum_d / 6;
        bias[4 + 3 * k] = fabs(w) * pow(w * dt, 2) / 6;
    }
    bias[0] = bias[1] = 0; /* no spin before: exact straight lines */
    bias[8] = want[8] * (vt0 / vn0 * delta0 + vtf / vnf * deltaf);
    bias[9] = delta0;
    bias[10] = want[10] * vt0 / vn0 * delta0;
}

static void render_simulated(const struct synth* y, const struct sim_record* rec, gsl_rng* rng,
                             double sigma_px, double* dots)
{
    for (int f = 0; f < N_FRAMES; f++)
        for (int k = 0; k < 2; k++) {
            double pos[2], vel[2], yaw;
            sim_pose(rec, y->fps, k, (f - SIM_PRE) / y->fps, pos, vel, &yaw);
            pose_dots(y, pos, yaw, rng, sigma_px, dots + 12 * f + 6 * k);
        }
}

/* Noise-free rendering of a simulated collision: only the method's biases remain, and the
 * bounds of simulated_truth() must hold (10 % margin for the line of centres turning slower
 * than v_t0/d farther from contact and the film's deflection of the path). */
static void check_noise_free(const struct synth* y, const struct wetdem_track_options* o,
                             const struct sim_record* rec,
                             const struct wetdem_collision_result* res, double* dots)
{
    double got[N_OUT], want[N_OUT], bias[N_OUT];
    struct wetdem_track_summary s;
    render_simulated(y, rec, NULL, 0, dots);
    CHECK_OK(analyse_dots(dots, o, got, &s));
    simulated_truth(rec, y, o, res, s.collision_frame, want, bias);
    /* The values taken from the record are the ones wetdem_collision_run reports (same
     * definitions of the same states: a few roundings in another order, 1e-14; measured 0). */
    CHECK_REL(want[8], res->e_n, 1e-14);
    CHECK_REL(want[9], res->angle_in, 1e-14);
    CHECK_REL(want[10], res->stokes_n, 1e-14);
    CHECK_REL(want[4], res->omega_i.z, 1e-14);
    CHECK_REL(want[7], res->omega_j.z, 1e-14);
    /* Floors: the film force sets in gradually at h = delta, so the velocity has begun to
     * change (below the threshold) by the collision frame and the smoothing window of the
     * last interval of the before-fit reaches it (2e-6 m/s here); round-off in the end
     * windows of the smoothing (1e-5 rad/s with positions of 0.1 m). */
    static const double floor_abs[N_OUT] = {1e-5, 1e-5, 1e-5, 1e-5, 1e-4, 1e-5,
                                            1e-5, 1e-4, 1e-5, 1e-5, 1e-4};
    for (int q = 0; q < N_OUT; q++)
        if (!(fabs(got[q] - want[q]) <= 1.1 * bias[q] + floor_abs[q]))
            fail_msg("noise-free, angle %.0f deg, output %d: got %.9g, simulated %.9g, bias "
                     "bound %.3g",
                     y->theta * 180 / M_PI, q, got[q], want[q], bias[q]);
}

static void check_simulated_recovery(double stokes, double angle, unsigned long seed)
{
    struct synth y; /* geometry of the dots and the camera only */
    synth_init(&y, angle);
    struct wetdem_track_options o;
    track_options(&o, &y);
    struct sim_record rec;
    struct wetdem_collision_result res;
    const double yaw0[2] = {0.4, 2.1};
    punch_collision(stokes, angle, y.fps, yaw0, &rec, &res);
    /* Contact-bounce (Punch Sec. 4.2): solid contact, prompt separation. */
    assert_true(res.solid_contact && res.outcome == WETDEM_OUTCOME_BOUNCE);
    double* dots = malloc(12 * N_FRAMES * sizeof *dots);
    double got[N_OUT], sigma[N_OUT], want[N_OUT], bias[N_OUT];
    struct wetdem_track_summary s;
    check_noise_free(&y, &o, &rec, &res, dots);
    /* With noise: 0.05 pixel as in check_recovery, seeded. */
    const double sigma_px = 0.05;
    gsl_rng* rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, seed);
    render_simulated(&y, &rec, rng, sigma_px, dots);
    gsl_rng_free(rng);
    CHECK_OK(analyse_dots(dots, &o, got, &s));
    noise_sigma(dots, &o, sigma_px, got, sigma);
    simulated_truth(&rec, &y, &o, &res, s.collision_frame, want, bias);
    /* The fit after the collision starts at the interval from frame k + window (k: the
     * collision frame); the bias bounds assume the simulated interaction has ended by then
     * (free flight): here it ends 1 ms (5 frames) after the first interaction. */
    double t_final = rec.q[SIM_COLS * (rec.n - 1)];
    assert_true((double)(s.collision_frame + o.window - SIM_PRE) / y.fps >= t_final);
    /* 4 sigma of the propagated pixel noise (two-sided 6e-5 per check) plus the biases. */
    for (int q = 0; q < N_OUT; q++)
        if (!(fabs(got[q] - want[q]) <= 4 * sigma[q] + bias[q]))
            fail_msg("angle %.0f deg, output %d: got %.6g, simulated %.6g, |diff| %.3g > 4 sigma "
                     "%.3g + bias %.3g",
                     angle * 180 / M_PI, q, got[q], want[q], fabs(got[q] - want[q]), 4 * sigma[q],
                     bias[q]);
    /* The tolerances stay meaningful: e_n within +-0.04 (4 sigma + bias) of the simulated
     * 0.70 (the bias, ~0.02, is the line of centres' turn of ~0.02 rad from the closest
     * approach, where the simulation takes n_f, to frame k + offset, where the tracker takes
     * it), the spins (-5.8 rad/s) to better than 2 rad/s, the angle to 1.5 degrees. */
    assert_true(4 * sigma[8] + bias[8] < 0.04);
    assert_true(4 * sigma[4] + bias[4] < 2 && 4 * sigma[7] + bias[7] < 2);
    assert_true(4 * sigma[9] + bias[9] < 1.5 * M_PI / 180);
    free(dots);
    free(rec.q);
}

static void test_track_recovers_simulated_punch_collision(void** state)
{
    (void)state;
    /* St_n = 3: contact-bounce for the DB-C model with P_gt = 11.6 MPa (Punch Fig. 8d),
     * e_n = 0.70 and spins of -5.8 rad/s with mu_f = 0.05 (Fig. 11); 45 and 30 degrees. */
    check_simulated_recovery(3.0, 45 * M_PI / 180, 21);
    check_simulated_recovery(3.0, 30 * M_PI / 180, 22);
}

/* ---- uncertainties ------------------------------------------------------------------------- */

/* Every value of the summary that carries an uncertainty: per state (striker before, striker
 * after, target before, target after) vx, vy, omega, x, y; then angle_centres, impact_angle,
 * speed_n0, speed_nf, e_n, stokes_n. */
#define N_ALL 26
static const char* const all_names[N_ALL] = {"striker_before_vx",
                                             "striker_before_vy",
                                             "striker_before_omega",
                                             "striker_before_x",
                                             "striker_before_y",
                                             "striker_after_vx",
                                             "striker_after_vy",
                                             "striker_after_omega",
                                             "striker_after_x",
                                             "striker_after_y",
                                             "target_before_vx",
                                             "target_before_vy",
                                             "target_before_omega",
                                             "target_before_x",
                                             "target_before_y",
                                             "target_after_vx",
                                             "target_after_vy",
                                             "target_after_omega",
                                             "target_after_x",
                                             "target_after_y",
                                             "angle_centres",
                                             "impact_angle",
                                             "speed_n0",
                                             "speed_nf",
                                             "e_n",
                                             "stokes_n"};

static void summary_values(const struct wetdem_track_summary* s, double v[N_ALL], double u[N_ALL])
{
    const struct wetdem_track_state* st[4] = {&s->striker_before, &s->striker_after,
                                              &s->target_before, &s->target_after};
    const struct wetdem_track_state* us[4] = {&s->u_striker_before, &s->u_striker_after,
                                              &s->u_target_before, &s->u_target_after};
    for (int k = 0; k < 4; k++) {
        const double a[5] = {st[k]->vx, st[k]->vy, st[k]->omega, st[k]->x, st[k]->y};
        const double b[5] = {us[k]->vx, us[k]->vy, us[k]->omega, us[k]->x, us[k]->y};
        memcpy(v + 5 * k, a, sizeof a);
        memcpy(u + 5 * k, b, sizeof b);
    }
    const double a[6] = {s->angle_centres, s->impact_angle, s->speed_n0,
                         s->speed_nf,      s->e_n,          s->stokes_n};
    const double b[6] = {s->u_angle_centres, s->u_impact_angle, s->u_speed_n0,
                         s->u_speed_nf,      s->u_e_n,          s->u_stokes_n};
    memcpy(v + 20, a, sizeof a);
    memcpy(u + 20, b, sizeof b);
}

static int analyse_all(const double* dots, const struct wetdem_track_options* o, double v[N_ALL],
                       double u[N_ALL], struct wetdem_track_summary* sum)
{
    double out[N_OUT];
    int st = analyse_dots(dots, o, out, sum);
    summary_values(sum, v, u);
    return st;
}

/* The true values of the synthetic collision by the tracker's definitions at its collision
 * frame c (true_outputs), with dot 1's position in the tracker's frame (pixel offsets). */
static void true_values(const struct synth* y, const struct wetdem_track_options* o, long c,
                        double v[N_ALL])
{
    double pos[4][2], vel[4][2], om[4], yaw, p0[2][2], pf[2][2], tmp[2];
    const double t[4] = {(double)(c - o->offset) / y->fps, (double)(c + o->offset) / y->fps,
                         (double)(c - o->offset) / y->fps, (double)(c + o->offset) / y->fps};
    for (int k = 0; k < 4; k++) {
        synth_state(y, k / 2, t[k], pos[k], vel[k], &yaw, &om[k]);
        const double a[5] = {vel[k][0], vel[k][1], om[k], pos[k][0] + 600 * y->pixel,
                             pos[k][1] + 400 * y->pixel};
        memcpy(v + 5 * k, a, sizeof a);
    }
    for (int k = 0; k < 2; k++) {
        synth_state(y, k, (double)c / y->fps, p0[k], tmp, &yaw, tmp);
        synth_state(y, k, t[1], pf[k], tmp, &yaw, tmp);
    }
    double d0[2] = {p0[0][0] - p0[1][0], p0[0][1] - p0[1][1]};
    double df[2] = {pf[0][0] - pf[1][0], pf[0][1] - pf[1][1]};
    double v0[2] = {vel[0][0] - vel[2][0], vel[0][1] - vel[2][1]};
    double vf[2] = {vel[1][0] - vel[3][0], vel[1][1] - vel[3][1]};
    double vn0 = -(v0[0] * d0[0] + v0[1] * d0[1]) / hypot(d0[0], d0[1]);
    double vnf = (vf[0] * df[0] + vf[1] * df[1]) / hypot(df[0], df[1]);
    double m = 7960 * 4.0 / 3.0 * M_PI * pow(y->radius, 3), r_eff = y->radius / 2;
    v[20] = atan(d0[1] / d0[0]);
    v[21] = acos(vn0 / hypot(v0[0], v0[1]));
    v[22] = vn0;
    v[23] = vnf;
    v[24] = vnf / vn0;
    v[25] = (m / 2) * vn0 / (6 * M_PI * 10.0 * r_eff * r_eff);
}

/* Standard deviation of every value for independent noise sigma_px[k] on each coordinate of
 * sphere k (the library's order: sphere id k + 1), from the gains by finite differences
 * (noise_sigma, per sphere). */
static void fd_sigma(double* dots, const struct wetdem_track_options* o, const double sigma_px[2],
                     const double base[N_ALL], double sigma[N_ALL])
{
    const double eps = 1e-3; /* [pixel] */
    double sum2[N_ALL] = {0}, v[N_ALL], u[N_ALL];
    struct wetdem_track_summary s;
    for (int j = 0; j < 12 * N_FRAMES; j++) {
        dots[j] += eps;
        CHECK_OK(analyse_all(dots, o, v, u, &s));
        dots[j] -= eps;
        double sp = sigma_px[(j % 12) / 6];
        for (int q = 0; q < N_ALL; q++)
            sum2[q] += pow(sp * (v[q] - base[q]) / eps, 2);
    }
    for (int q = 0; q < N_ALL; q++)
        sigma[q] = sqrt(sum2[q]);
}

/* The closed form of Eq. 23 that the uncertainties differentiate agrees with the QR solution,
 * and the residual they estimate the noise from vanishes for an exact rigid step however
 * large its rotation (the small-angle part removed) and averages 6 sigma^2 with noise sigma
 * on every coordinate (3 degrees of freedom of differences of variance 2 sigma^2). */
static void test_track_interval_gain_and_rigid_residual(void** state)
{
    (void)state;
    double dt = 2e-4, a = 0.3, v[2] = {0.4, -0.1};
    double d2[2] = {3e-3, 1e-3}, d3[2] = {-0.5e-3, 2.5e-3}, p0[6] = {0.01, 0.02}, p1[6];
    for (int k = 0; k < 2; k++) {
        const double* d = k == 0 ? d2 : d3;
        p0[2 + 2 * k] = p0[0] + d[0];
        p0[3 + 2 * k] = p0[1] + d[1];
        p1[2 + 2 * k] = p0[0] + v[0] * dt + cos(a) * d[0] - sin(a) * d[1];
        p1[3 + 2 * k] = p0[1] + v[1] * dt + sin(a) * d[0] + cos(a) * d[1];
    }
    p1[0] = p0[0] + v[0] * dt;
    p1[1] = p0[1] + v[1] * dt;
    double gain[18], out[3], rms, ss;
    CHECK_OK(wetdem_track_interval_gain(p0, dt, gain));
    CHECK_OK(wetdem_track_solve_interval(p0, p1, dt, out, &rms));
    /* the same least squares solved two ways: differences of positions ~0.01 m carry steps of
       1e-4 m, ~100 ulp of their digits each (2e-14 relative): 1e-12 */
    for (int c = 0; c < 3; c++) {
        double sum = 0;
        for (int j = 0; j < 6; j++)
            sum += gain[6 * c + j] * (p1[j] - p0[j]);
        CHECK_REL(sum, out[c], 1e-12);
    }
    /* Eq. 23's residual at a = 0.3 is (1 - cos a) |e| ~ 1e-4 m; less its small-angle part
       only round-off of the 0.02 m positions remains: 1e-16 m, 30 ulp (measured 1.5e-18) */
    CHECK_OK(wetdem_track_rigid_residual(p0, p1, &ss));
    assert_true(rms > 1e-5);
    assert_true(sqrt(ss) < 1e-16);
    /* 3000 noisy steps, sigma = 1e-5 m (1/300 of the dot offsets, so that the noise of the
       matrix, O(sigma/|D|) relative, is negligible): ss / (6 sigma^2) is chi^2_3/3, of variance
       2/3, so its mean has a standard error sqrt(2/(3 * 3000)) = 0.015; 4 of them: 0.06. */
    gsl_rng* rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 7);
    const double sigma = 1e-5;
    const int n = 3000;
    double mean = 0, q0[6], q1[6];
    for (int i = 0; i < n; i++) {
        for (int j = 0; j < 6; j++) {
            q0[j] = p0[j] + gsl_ran_gaussian(rng, sigma);
            q1[j] = p1[j] + gsl_ran_gaussian(rng, sigma);
        }
        CHECK_OK(wetdem_track_rigid_residual(q0, q1, &ss));
        mean += ss / (6 * sigma * sigma) / n;
    }
    gsl_rng_free(rng);
    CHECK_ABS(mean, 1.0, 0.06);
    double z[6] = {1, 1, 1, 1, 1, 1};
    CHECK_STATUS(wetdem_track_interval_gain(z, dt, gain), WETDEM_ERR_NUMERIC);
    CHECK_STATUS(wetdem_track_rigid_residual(z, z, &ss), WETDEM_ERR_NUMERIC);
}

/* The velocities of interval i of sphere k (raw, then smoothed) and their uncertainties. */
static void interval_values(const double* dots, const struct wetdem_track_options* o, size_t k,
                            size_t i, double v[6], double u[6], double* noise_px)
{
    struct wetdem_track* t = wetdem_track_create();
    for (int f = 0; f < N_FRAMES; f++)
        for (int s = 0; s < 2; s++)
            CHECK_OK(wetdem_track_add_frame(t, s + 1, f, dots + 12 * f + 6 * s));
    struct wetdem_track_summary sum;
    CHECK_OK(wetdem_track_analyse(t, o, &sum));
    size_t n;
    const struct wetdem_track_sample* q = wetdem_track_samples(t, k, &n);
    assert_true(i < n);
    const double a[6] = {q[i].vx_raw, q[i].vy_raw, q[i].omega_raw, q[i].vx, q[i].vy, q[i].omega};
    const double b[6] = {q[i].u_vx_raw, q[i].u_vy_raw, q[i].u_omega_raw,
                         q[i].u_vx,     q[i].u_vy,     q[i].u_omega};
    memcpy(v, a, sizeof a);
    memcpy(u, b, sizeof b);
    *noise_px = sum.noise_px[k];
    wetdem_track_free(t);
}

/* The per-interval uncertainties of sphere k, interval i against finite differences over the
 * frames that the interval's smoothing reaches. */
static void check_interval_uncertainty(double* dots, const struct wetdem_track_options* o, size_t k,
                                       size_t i)
{
    const double eps = 1e-3; /* [pixel] */
    double v[6], u[6], vp[6], up[6], noise, sum2[6] = {0};
    interval_values(dots, o, k, i, v, u, &noise);
    size_t lo = i >= 7 ? i - 7 : 0, hi = i + 9 < N_FRAMES ? i + 9 : N_FRAMES;
    for (size_t f = lo; f < hi; f++)
        for (size_t c = 0; c < 6; c++) {
            double* x = dots + 12 * f + 6 * k + c;
            *x += eps;
            interval_values(dots, o, k, i, vp, up, &noise);
            *x -= eps;
            for (int q = 0; q < 6; q++)
                sum2[q] += pow(noise * (vp[q] - v[q]) / eps, 2);
        }
    /* (tolerance as in test_track_uncertainties_are_the_propagated_noise; measured 2e-3 for
       the raw spin of the interval of the collision) */
    for (int q = 0; q < 6; q++)
        CHECK_REL(u[q], sqrt(sum2[q]), 5e-3);
}

/* The reported uncertainties are the estimated noise propagated through the whole analysis:
 * against the gains by finite differences (every pixel coordinate moved in turn) times each
 * sphere's reported noise, for every value of the summary and for per-interval velocities.
 * They agree to first order; the second-order terms left out (the noise of the matrix of
 * Eq. 23 times its residual) are O(noise / dot offset) = 0.05/31 px = 1.6e-3 relative:
 * 5e-3 (measured 8e-4). */
static void test_track_uncertainties_are_the_propagated_noise(void** state)
{
    (void)state;
    struct synth y;
    synth_init(&y, 45 * M_PI / 180);
    struct wetdem_track_options o;
    track_options(&o, &y);
    static double dots[12 * N_FRAMES];
    gsl_rng* rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 5);
    render(&y, rng, 0.05, dots);
    gsl_rng_free(rng);
    double v[N_ALL], u[N_ALL], fd[N_ALL];
    struct wetdem_track_summary s;
    CHECK_OK(analyse_all(dots, &o, v, u, &s));
    /* the rendered noise is 0.05 px; each sphere's estimate from its 119 intervals scatters
       by 4.6 % (measured over 1000 seeds: mean 0.0501): 4 of that, 0.18 */
    for (int k = 0; k < 2; k++)
        CHECK_REL(s.noise_px[k], 0.05, 0.18);
    fd_sigma(dots, &o, s.noise_px, v, fd);
    for (int q = 0; q < N_ALL; q++)
        if (!(fabs(u[q] / fd[q] - 1) <= 5e-3))
            fail_msg("%s: reported %.6g, propagated by finite differences %.6g", all_names[q], u[q],
                     fd[q]);
    /* intervals in the free flights and across the collision, both spheres */
    check_interval_uncertainty(dots, &o, 0, 20);
    check_interval_uncertainty(dots, &o, 1, 49);
    check_interval_uncertainty(dots, &o, 1, 118); /* (the end window) */
}

/* Monte Carlo: 1000 noise seeds of the 45-degree collision at 0.05 px. For every value, the
 * root mean square of the reported sigma must match the scatter of the estimates about the
 * truth (by the tracker's definitions at the collision frame it found): the relative
 * standard error of a standard deviation from N samples is 1/sqrt(2 (N - 1)) = 0.022, and 4
 * of them (two-sided 6e-5 per value) give 0.09. The coverage of |estimate - truth| <= k sigma,
 * k = 1 and 2, must be the Gaussian rate P_k (0.6827, 0.9545) within 4 binomial standard
 * errors sqrt(P_k (1 - P_k)/N) (0.059 and 0.026); from below, the truth may be off by the
 * method's bias bound (method_bias: the small-angle velocity and spin biases, e_n); the
 * biases of the smoothing across the contact (positions, angles) are below 0.15 sigma
 * (measured), which moves the coverage by less than 0.01. */
static void test_track_uncertainties_match_monte_carlo(void** state)
{
    (void)state;
    enum { N_SEEDS = 1000 };
    struct synth y;
    synth_init(&y, 45 * M_PI / 180);
    struct wetdem_track_options o;
    track_options(&o, &y);
    /* bias bounds per value (index as N_ALL) from method_bias: before (spins 3 and 0 rad/s)
       and after (-18 and 25 rad/s) velocities and spins, speed_nf from two after velocities,
       e_n; 0 where the bias is second order in the coverage (above) */
    static const double bias[N_ALL] = {1e-5, 1e-5, 2e-4, 0,    0,    2.5e-4, 2.5e-4, 2e-4,   0,
                                       0,    1e-5, 1e-5, 2e-4, 0,    0,      2.5e-4, 2.5e-4, 2e-4,
                                       0,    0,    0,    1e-4, 1e-5, 5e-4,   3e-3,   1e-4};
    static double dots[12 * N_FRAMES], err[N_SEEDS][N_ALL], us[N_SEEDS][N_ALL];
    gsl_rng* rng = gsl_rng_alloc(gsl_rng_mt19937);
    for (int k = 0; k < N_SEEDS; k++) {
        double v[N_ALL], want[N_ALL];
        struct wetdem_track_summary s;
        gsl_rng_set(rng, 1000 + (unsigned long)k);
        render(&y, rng, 0.05, dots);
        CHECK_OK(analyse_all(dots, &o, v, us[k], &s));
        true_values(&y, &o, s.collision_frame, want);
        for (int q = 0; q < N_ALL; q++)
            err[k][q] = v[q] - want[q];
    }
    gsl_rng_free(rng);
    const double n = N_SEEDS, tol_sd = 4 / sqrt(2 * (n - 1));
    const double p_k[2] = {0.682689, 0.954500};
    for (int q = 0; q < N_ALL; q++) {
        double mean = 0, var = 0, u2 = 0;
        int inside[2] = {0, 0}, inside_biased[2] = {0, 0};
        for (int k = 0; k < N_SEEDS; k++)
            mean += err[k][q] / n, u2 += us[k][q] * us[k][q] / n;
        for (int k = 0; k < N_SEEDS; k++) {
            var += pow(err[k][q] - mean, 2) / (n - 1);
            for (int m = 0; m < 2; m++) {
                inside[m] += fabs(err[k][q]) <= (m + 1) * us[k][q];
                inside_biased[m] += fabs(err[k][q]) <= (m + 1) * us[k][q] + bias[q];
            }
        }
        double ratio = sqrt(u2 / var);
        if (!(fabs(ratio - 1) <= tol_sd))
            fail_msg("%s: rms reported sigma %.4g, scatter %.4g (ratio %.3f, tolerance %.3f)",
                     all_names[q], sqrt(u2), sqrt(var), ratio, tol_sd);
        for (int m = 0; m < 2; m++) {
            double tol = 4 * sqrt(p_k[m] * (1 - p_k[m]) / n);
            if (!(inside_biased[m] / n >= p_k[m] - tol && inside[m] / n <= p_k[m] + tol))
                fail_msg("%s: |error| <= %d sigma in %d of %d seeds (%d with the bias bound); "
                         "Gaussian %.4f +- %.4f",
                         all_names[q], m + 1, inside[m], N_SEEDS, inside_biased[m], p_k[m], tol);
        }
    }
}

/* Noise-free dots give uncertainties at round-off: the residuals of the rigid steps are the
 * rounding of the pixel coordinates (up to 800 px, ulp 1.1e-13 px), so the noise estimate must
 * be below 1e-12 px (measured 3e-14) and every uncertainty below 1e-10 of its value at 0.05 px
 * (they scale with the noise: measured 6e-13). */
static void test_track_noise_free_uncertainties_vanish(void** state)
{
    (void)state;
    struct synth y;
    synth_init(&y, 45 * M_PI / 180);
    struct wetdem_track_options o;
    track_options(&o, &y);
    static double dots[12 * N_FRAMES];
    double v[N_ALL], u[N_ALL], u_noisy[N_ALL];
    struct wetdem_track_summary s;
    gsl_rng* rng = gsl_rng_alloc(gsl_rng_mt19937);
    gsl_rng_set(rng, 5);
    render(&y, rng, 0.05, dots);
    gsl_rng_free(rng);
    CHECK_OK(analyse_all(dots, &o, v, u_noisy, &s));
    render(&y, NULL, 0, dots);
    CHECK_OK(analyse_all(dots, &o, v, u, &s));
    assert_true(s.noise_px[0] < 1e-12 && s.noise_px[1] < 1e-12);
    for (int q = 0; q < N_ALL; q++)
        if (!(u[q] >= 0 && u[q] < 1e-10 * u_noisy[q]))
            fail_msg("%s: noise-free uncertainty %.3g (%.3g at 0.05 px)", all_names[q], u[q],
                     u_noisy[q]);
    size_t n;
    struct wetdem_track* t = wetdem_track_create();
    for (int f = 0; f < N_FRAMES; f++)
        for (int k = 0; k < 2; k++)
            CHECK_OK(wetdem_track_add_frame(t, k + 1, f, dots + 12 * f + 6 * k));
    CHECK_OK(wetdem_track_analyse(t, &o, &s));
    const struct wetdem_track_sample* q = wetdem_track_samples(t, 0, &n);
    for (size_t i = 0; i < n; i++) /* (0.05 px gives ~0.012 m/s and ~3 rad/s) */
        assert_true(q[i].u_vx < 1e-12 && q[i].u_vy_raw < 1e-12 && q[i].u_omega < 1e-9);
    wetdem_track_free(t);
}

/* Doubling the noise doubles the uncertainties: the same seed at 0.01 and 0.02 px (the
 * collision found at the same frame). The noise estimate and the states' uncertainties are
 * the noise times gains that depend on the noisy dots only through the dot offsets and the
 * spin, O(noise/offset) = 0.02/31 px = 7e-4 relative: 1e-3 (measured 3e-4). The derived
 * values' coefficients are evaluated at the estimates, which move by their own relative
 * uncertainty: 1e-3 plus twice the largest u/|value| among them, 0.018 (measured 4.6e-3, e_n).
 */
static void test_track_uncertainties_scale_with_noise(void** state)
{
    (void)state;
    struct synth y;
    synth_init(&y, 45 * M_PI / 180);
    struct wetdem_track_options o;
    track_options(&o, &y);
    static double dots[12 * N_FRAMES];
    double v[2][N_ALL], u[2][N_ALL];
    struct wetdem_track_summary s[2];
    gsl_rng* rng = gsl_rng_alloc(gsl_rng_mt19937);
    for (int m = 0; m < 2; m++) {
        gsl_rng_set(rng, 4);
        render(&y, rng, 0.01 * (m + 1), dots);
        CHECK_OK(analyse_all(dots, &o, v[m], u[m], &s[m]));
    }
    gsl_rng_free(rng);
    assert_int_equal(s[0].collision_frame, s[1].collision_frame);
    for (int k = 0; k < 2; k++)
        CHECK_REL(s[1].noise_px[k], 2 * s[0].noise_px[k], 1e-3);
    double rel = 0;
    for (int q = 20; q < N_ALL; q++)
        rel = fmax(rel, u[1][q] / fabs(v[1][q]));
    for (int q = 0; q < N_ALL; q++)
        if (!(fabs(u[1][q] / (2 * u[0][q]) - 1) <= (q < 20 ? 1e-3 : 1e-3 + 2 * rel)))
            fail_msg("%s: %.6g at 0.01 px, %.6g at 0.02 px", all_names[q], u[0][q], u[1][q]);
}

/* ---- malformed tracks ---------------------------------------------------------------------- */

static const char* write_temp(const char* text)
{
    static char path[64];
    snprintf(path, sizeof path, "/tmp/wetdem_track_%d.csv", (int)getpid());
    test_write_file(path, text);
    return path;
}

/* Reads `text` as a track file and expects `status` with `needle` in the message. */
static void expect_read_error(const char* text, int status, const char* needle)
{
    struct wetdem_track* t = wetdem_track_create();
    const char* path = write_temp(text);
    CHECK_STATUS(wetdem_track_read_csv(t, path), status);
    CHECK_CONTAINS(wetdem_track_errmsg(t), needle);
    wetdem_track_free(t);
    remove(path);
}

static void test_track_rejects_malformed_files(void** state)
{
    (void)state;
    { /* a directory opens, but does not read */
        struct wetdem_track* t = wetdem_track_create();
        CHECK_STATUS(wetdem_track_read_csv(t, "/tmp"), WETDEM_ERR_IO);
        CHECK_CONTAINS(wetdem_track_errmsg(t), "/tmp: cannot read: Is a directory");
        wetdem_track_free(t);
    }
    { /* a NUL byte (a binary file) is named: the row before it at the end of the file was
         read as the whole row, and one inside a line was "longer than 4094 characters" */
        static const char bin[] = "frame,sphere,x1,y1,x2,y2,x3,y3\n0,1,1,1,2,2,3,3\n"
                                  "1,1,1,1,2,2,3,3\0\x01\x02";
        const char* path = write_temp("");
        FILE* f = fopen(path, "wb");
        assert_non_null(f);
        assert_int_equal(fwrite(bin, 1, sizeof bin - 1, f), sizeof bin - 1);
        assert_int_equal(fclose(f), 0);
        struct wetdem_track* t = wetdem_track_create();
        CHECK_STATUS(wetdem_track_read_csv(t, path), WETDEM_ERR_PARSE);
        CHECK_CONTAINS(wetdem_track_errmsg(t), ":3: a NUL byte in the line: not a text (CSV) file");
        wetdem_track_free(t);
        remove(path);
    }
    const char* head = "frame,sphere,x1,y1,x2,y2,x3,y3\n";
    char buf[512];
    snprintf(buf, sizeof buf, "%s0,1,1,1,2,2,3,3\n1,1,1,1,2,2,3\n", head);
    expect_read_error(buf, WETDEM_ERR_PARSE, ":3: expected 8 columns");
    snprintf(buf, sizeof buf, "%s0,1,1,1,2,2,3,3\n1,1,1,nan,2,2,3,3\n", head);
    expect_read_error(buf, WETDEM_ERR_PARSE, ":3: column y1: 'nan' is not a finite number");
    snprintf(buf, sizeof buf, "%s# c\n0,1,1,1,2,2,3,3\n1,1,1,1,2,2,3,3\n3,1,1,1,2,2,3,3\n", head);
    expect_read_error(buf, WETDEM_ERR_PARSE,
                      ":5: sphere 1: frame 3 follows frame 1; frame 2 is missing");
    snprintf(buf, sizeof buf, "%s0,1,1,1,2,2,3,3\n1,1,1,1,2,2,3,3\n1,1,1,1,2,2,3,3\n", head);
    expect_read_error(buf, WETDEM_ERR_PARSE, ":4: sphere 1: frame 1 follows frame 1; frames must");
    expect_read_error("frame,ball,x1,y1,x2,y2,x3,y3\n", WETDEM_ERR_PARSE, ":1: header must be");
    expect_read_error("0,1,1,1,2,2,3,3\n0,2,1,1,2,2,3,3\n0,3,1,1,2,2,3,3\n", WETDEM_ERR_PARSE,
                      ":3: sphere 3: at most 2 spheres");
    expect_read_error("# nothing\n", WETDEM_ERR_PARSE, "no data rows");
    struct wetdem_track* t = wetdem_track_create();
    CHECK_STATUS(wetdem_track_read_csv(t, "/nonexistent/dots.csv"), WETDEM_ERR_IO);
    wetdem_track_free(t);
}

static void test_track_rejects_short_or_mismatched_tracks(void** state)
{
    (void)state;
    struct wetdem_track* t = wetdem_track_create();
    struct wetdem_track_options o;
    wetdem_track_options_init(&o);
    o.fps = 5000;
    o.pixel_size = 175e-6;
    struct wetdem_track_summary s;
    double xy[6] = {0, 0, 10, 0, 5, 8};
    for (int f = 0; f < 5; f++)
        CHECK_OK(wetdem_track_add_frame(t, 1, f, xy));
    CHECK_STATUS(wetdem_track_analyse(t, &o, &s), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_track_errmsg(t), "sphere 1 has 5 frames; at least 7");
    for (int f = 0; f < 6; f++)
        CHECK_OK(wetdem_track_add_frame(t, 2, f, xy));
    CHECK_STATUS(wetdem_track_analyse(t, &o, &s), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_track_errmsg(t), "covers frames 0 to 4 but sphere 2 covers 0 to 5");
    o.window = 4;
    CHECK_STATUS(wetdem_track_analyse(t, &o, &s), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_track_errmsg(t), "window = 4");
    /* a frame number near LONG_MAX overflowed first_frame + n (undefined behaviour) */
    CHECK_STATUS(wetdem_track_add_frame(t, 1, LONG_MAX, xy), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_track_errmsg(t), "is out of range [-1000000000000, 1000000000000]");
    o.window = 7;
    o.pixel_size = 1e300; /* (it made the first frames' speeds look like the collision) */
    CHECK_STATUS(wetdem_track_analyse(t, &o, &s), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_track_errmsg(t), "pixel_size = 1e+300: must be in (0, 1] [m/pixel]");
    o.pixel_size = 175e-6;
    /* St_n's inputs: within the scenario keys' ranges, and all three or none (two of them gave
       St_n = NaN without a word, a radius of 1e300 m gave St_n = 0) */
    o.radius = 1e300;
    o.mass = 0.068;
    o.viscosity = 10;
    CHECK_STATUS(wetdem_track_analyse(t, &o, &s), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_track_errmsg(t), "radius = 1e+300: must be in (0, 1] m, or 0");
    o.radius = 12.7e-3;
    o.viscosity = 0;
    CHECK_STATUS(wetdem_track_analyse(t, &o, &s), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_track_errmsg(t), "the Stokes number needs all three (or none)");
    o.viscosity = 10;
    /* a striker id below -1 (automatic) was taken as automatic */
    o.striker = -5;
    CHECK_STATUS(wetdem_track_analyse(t, &o, &s), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_track_errmsg(t), "striker = -5: must be a sphere id in [0, 1000000]");
    wetdem_track_free(t);
    /* a striker id that no sphere has: refused with one sphere too, where it was taken without
       a word (the per-frame velocities, has_collision = false) */
    t = wetdem_track_create();
    for (int f = 0; f < 10; f++)
        CHECK_OK(wetdem_track_add_frame(t, 1, f, xy));
    o.striker = 2;
    CHECK_STATUS(wetdem_track_analyse(t, &o, &s), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_track_errmsg(t), "striker = 2: no sphere with that id (found 1 only");
    o.striker = 1;
    CHECK_OK(wetdem_track_analyse(t, &o, &s));
    assert_int_equal(s.n_spheres, 1);
    o.striker = -1;
    wetdem_track_free(t);
    /* Two resting spheres: no collision, and the message says why. */
    t = wetdem_track_create();
    wetdem_track_options_init(&o);
    o.fps = 5000;
    o.pixel_size = 175e-6;
    for (int f = 0; f < 40; f++) {
        CHECK_OK(wetdem_track_add_frame(t, 1, f, xy));
        double other[6] = {200, 0, 210, 0, 205, 8};
        CHECK_OK(wetdem_track_add_frame(t, 2, f, other));
    }
    CHECK_STATUS(wetdem_track_analyse(t, &o, &s), WETDEM_ERR_INVALID);
    CHECK_CONTAINS(wetdem_track_errmsg(t), "no collision found");
    wetdem_track_free(t);
    /* Two spheres with frames enough for the smoothing (7) but not for the reference velocity
       (the mean of the first 7 intervals; a collision after them lasting 4 more): 7 to 11
       frames are refused with the count needed (7 frames read past the 6 velocities, found by
       make fuzz); 12 are enough to look for a collision. */
    for (int n = 7; n <= 12; n++) {
        t = wetdem_track_create();
        for (int f = 0; f < n; f++) {
            double moving[6] = {f, 0, 10 + f, 0, 5 + f, 8};
            CHECK_OK(wetdem_track_add_frame(t, 1, f, moving));
            double other[6] = {200, 0, 210, 0, 205, 8};
            CHECK_OK(wetdem_track_add_frame(t, 2, f, other));
        }
        CHECK_STATUS(wetdem_track_analyse(t, &o, &s), WETDEM_ERR_INVALID);
        CHECK_CONTAINS(wetdem_track_errmsg(t),
                       n < 12 ? "finding a collision needs at least 12" : "no collision found");
        wetdem_track_free(t);
    }
}

static void test_track_cli_exits_2_with_line_number(void** state)
{
    (void)state;
    const char* cli = getenv("WETDEM_CLI");
    if (!cli)
        skip();
    const char* path =
        write_temp("frame,sphere,x1,y1,x2,y2,x3,y3\n0,1,1,1,2,2,3,3\n2,1,1,1,2,2,3,3\n");
    char args[512], out[4096];
    snprintf(args, sizeof args, "track %s --fps 5000 --pixel-size 175e-6", path);
    int rc = test_run_cli_into(args, out, sizeof out);
    remove(path);
    assert_int_equal(rc, 2);
    CHECK_CONTAINS(out, ":3: sphere 1: frame 2 follows frame 0");
    /* a track that reads but cannot be analysed (sphere 2 one frame short): the file named */
    path = write_temp("frame,sphere,x1,y1,x2,y2,x3,y3\n0,1,1,1,2,2,3,3\n1,1,1,1,2,2,3,3\n"
                      "0,2,9,9,8,8,7,7\n");
    rc = test_run_cli_into(args, out, sizeof out);
    remove(path);
    assert_int_equal(rc, 2);
    char expect[600];
    snprintf(expect, sizeof expect, "track: %s: sphere 1 covers frames 0 to 1", path);
    CHECK_CONTAINS(out, expect);
    /* --help anywhere prints the usage and succeeds, also before the required options. */
    assert_int_equal(test_run_cli_into("track --help", out, sizeof out), 0);
    CHECK_CONTAINS(out, "usage: wetdem track DOTS.csv --fps F --pixel-size S");
    assert_int_equal(test_run_cli_into("track dots.csv --fps 5000 -h", out, sizeof out), 0);
    CHECK_CONTAINS(out, "--frames FILE");
    assert_int_equal(test_run_cli_into("track dots.csv --fps", out, sizeof out), 2);
    CHECK_CONTAINS(out, "option --fps needs a value");
    /* a missing option is named; a given but invalid one gets its own message (--fps 0 was
       reported as missing) */
    assert_int_equal(test_run_cli_into("track dots.csv --fps 5000", out, sizeof out), 2);
    CHECK_CONTAINS(out, "track: --pixel-size is missing");
    path = write_temp("frame,sphere,x1,y1,x2,y2,x3,y3\n0,1,1,1,2,2,3,3\n");
    snprintf(args, sizeof args, "track %s --fps 0 --pixel-size 175e-6", path);
    assert_int_equal(test_run_cli_into(args, out, sizeof out), 2);
    remove(path);
    CHECK_CONTAINS(out, "fps = 0: must be a frame rate in (0, 1e9] [1/s]");
}

/* A velocity change that is no collision: the example track with one frame of the striker's
 * dots (frame 20) moved 2 px along x, as a tracker glitch. The change was taken for the
 * collision and e_n reported as -0.98 (the spheres still approaching "after" it) with exit 0;
 * now it is an error naming the frame, exit 2. The unchanged file still gives e_n = 0.704. */
static void test_track_cli_refuses_a_change_that_is_no_collision(void** state)
{
    (void)state;
    if (!getenv("WETDEM_CLI"))
        skip();
    char* text = test_read_file("examples/tracks/punch_45deg.csv", NULL);
    assert_non_null(text);
    const char* old = "\n20,1,769.9066,424.7316,798.2607,436.7169,772.8269,455.3531\n";
    char* at = strstr(text, old);
    assert_non_null(at);
    memcpy(at, "\n20,1,771.9066,424.7316,800.2607,436.7169,774.8269,455.3531\n", strlen(old));
    const char* path = write_temp(text);
    free(text);
    char args[512], out[4096];
    snprintf(args, sizeof args, "track %s --fps 5000 --pixel-size 175e-6", path);
    int rc = test_run_cli_into(args, out, sizeof out);
    remove(path);
    assert_int_equal(rc, 2);
    CHECK_CONTAINS(out, "the spheres are still approaching after the velocity change found at "
                        "frame 16");
    rc = test_run_cli_into("track examples/tracks/punch_45deg.csv --fps 5000 --pixel-size 175e-6",
                           out, sizeof out);
    assert_int_equal(rc, 0);
    CHECK_CONTAINS(out, "e_n = 0.704");
    /* a UTF-8 byte order mark before the header (a spreadsheet's "CSV UTF-8") is skipped; it
       gave "header must be frame,sphere,... (got 'frame,sphere,...')" */
    text = test_read_file("examples/tracks/punch_45deg.csv", NULL);
    assert_non_null(text);
    size_t len = strlen(text);
    char* bom = malloc(len + 4);
    assert_non_null(bom);
    memcpy(bom, "\xef\xbb\xbf", 3);
    memcpy(bom + 3, text, len + 1);
    free(text);
    path = write_temp(bom);
    free(bom);
    rc = test_run_cli_into(args, out, sizeof out);
    remove(path);
    assert_int_equal(rc, 0);
    CHECK_CONTAINS(out, "e_n = 0.704");
}

/* The summary never prints "nan": without --radius, --mass and --viscosity the Stokes number
 * is a comment saying what it needs in the key = value text and null in JSON; with them it is
 * St_n = m* v_n0 / (6 pi mu R*^2) of two equal spheres (Eq. 2), here from its own speed_n0. */
static void test_track_cli_summary_has_no_nan(void** state)
{
    (void)state;
    if (!getenv("WETDEM_CLI"))
        skip();
    const char* track = "track examples/tracks/punch_45deg.csv --fps 5000 --pixel-size 175e-6";
    char args[512], out[8192];
    assert_int_equal(test_run_cli_into(track, out, sizeof out), 0);
    assert_null(strstr(out, "nan"));
    CHECK_CONTAINS(out, "# stokes_n not computed: give --radius, --mass and --viscosity\n");
    CHECK_CONTAINS(out, "# u_stokes_n not computed: give --radius, --mass and --viscosity\n");
    snprintf(args, sizeof args, "%s --json", track);
    assert_int_equal(test_run_cli_into(args, out, sizeof out), 0);
    assert_null(strstr(out, "nan"));
    CHECK_CONTAINS(out, "\"stokes_n\": null,\n"); /* (uncertainties follow) */
    CHECK_CONTAINS(out, "\"u_stokes_n\": null\n");
    const double radius = 6.35e-3, mass = 8.4e-3, viscosity = 0.02;
    snprintf(args, sizeof args, "%s --radius %g --mass %g --viscosity %g", track, radius, mass,
             viscosity);
    assert_int_equal(test_run_cli_into(args, out, sizeof out), 0);
    const char* v = strstr(out, "speed_n0_m_s = ");
    const char* st = strstr(out, "stokes_n = ");
    assert_non_null(v);
    assert_non_null(st);
    double speed = strtod(v + strlen("speed_n0_m_s = "), NULL);
    double stokes = strtod(st + strlen("stokes_n = "), NULL);
    /* (both printed to 9 digits: 1e-8 covers their rounding) */
    CHECK_REL(stokes, (mass / 2) * speed / (6 * M_PI * viscosity * (radius / 2) * (radius / 2)),
              1e-8);
}

/* The value after "KEY = " in key = value text, or NAN when the key is missing. */
static double text_value(const char* out, const char* key)
{
    char needle[96];
    snprintf(needle, sizeof needle, "\n%s = ", key);
    const char* at = strstr(out, needle);
    return at ? strtod(at + strlen(needle), NULL) : NAN;
}

/* The summary appends the noise estimate and an uncertainty per value after the keys it had
 * (text and JSON), equal to the library's (printed to 9 digits), the striker's and target's
 * noise in their roles; the same command prints the same bytes; --frames appends the
 * per-interval uncertainties to its columns. */
static void test_track_cli_reports_uncertainties(void** state)
{
    (void)state;
    if (!getenv("WETDEM_CLI"))
        skip();
    const char* file = "examples/tracks/punch_45deg.csv";
    char args[512], out[8192], again[8192];
    snprintf(args, sizeof args,
             "track %s --fps 5000 --pixel-size 175e-6 --radius 12.7e-3 --mass 0.06830 "
             "--viscosity 10",
             file);
    assert_int_equal(test_run_cli_into(args, out, sizeof out), 0);
    assert_int_equal(test_run_cli_into(args, again, sizeof again), 0);
    assert_string_equal(out, again);
    struct wetdem_track* t = wetdem_track_create();
    CHECK_OK(wetdem_track_read_csv(t, file));
    struct wetdem_track_options o;
    wetdem_track_options_init(&o);
    o.fps = 5000;
    o.pixel_size = 175e-6;
    o.radius = 12.7e-3;
    o.mass = 0.06830;
    o.viscosity = 10;
    struct wetdem_track_summary s;
    CHECK_OK(wetdem_track_analyse(t, &o, &s));
    size_t si = wetdem_track_sphere_id(t, 0) == s.striker_id ? 0 : 1;
    wetdem_track_free(t);
    const double deg = 180 / M_PI;
    const struct {
        const char* key;
        double value;
    } want[] = {{"striker_noise_px", s.noise_px[si]},
                {"target_noise_px", s.noise_px[1 - si]},
                {"u_striker_before_vx_m_s", s.u_striker_before.vx},
                {"u_target_before_omega_rad_s", s.u_target_before.omega},
                {"u_striker_after_vy_m_s", s.u_striker_after.vy},
                {"u_target_after_omega_rad_s", s.u_target_after.omega},
                {"u_angle_centres_deg", s.u_angle_centres * deg},
                {"u_impact_angle_deg", s.u_impact_angle * deg},
                {"u_speed_n0_m_s", s.u_speed_n0},
                {"u_speed_nf_m_s", s.u_speed_nf},
                {"u_e_n", s.u_e_n},
                {"u_stokes_n", s.u_stokes_n}};
    for (size_t k = 0; k < sizeof want / sizeof want[0]; k++)
        CHECK_REL(text_value(out, want[k].key), want[k].value, 1e-8);
    /* 0.05 px rendered; e_n 0.704 +- 0.004 */
    assert_true(s.noise_px[0] > 0.04 && s.noise_px[0] < 0.06 && s.u_e_n < 0.01);
    /* appended: every earlier key comes before the first new one */
    assert_true(strstr(out, "\nstokes_n = ") < strstr(out, "\nstriker_noise_px = "));
    snprintf(args + strlen(args), sizeof args - strlen(args), " --json");
    assert_int_equal(test_run_cli_into(args, out, sizeof out), 0);
    CHECK_CONTAINS(out, "\"stokes_n\": 3.02");
    CHECK_CONTAINS(out, "\"u_e_n\": 0.00");
    assert_true(strstr(out, "\"stokes_n\"") < strstr(out, "\"striker_noise_px\""));
    assert_true(strstr(out, "\"u_stokes_n\": 0.0") && strstr(out, "}\n"));
    char frames[96];
    snprintf(frames, sizeof frames, "/tmp/wetdem_track_u_%d.csv", (int)getpid());
    snprintf(args, sizeof args, "track %s --fps 5000 --pixel-size 175e-6 --frames %s", file,
             frames);
    assert_int_equal(test_run_cli_into(args, out, sizeof out), 0);
    char* text = test_read_file(frames, NULL);
    assert_non_null(text);
    CHECK_CONTAINS(text, "\nsphere [index],frame [index],time [s],vx_raw [m/s],vy_raw [m/s],"
                         "omega_raw [rad/s],vx [m/s],vy [m/s],omega [rad/s],residual [m],"
                         "u_vx_raw [m/s],u_vy_raw [m/s],u_omega_raw [rad/s],u_vx [m/s],"
                         "u_vy [m/s],u_omega [rad/s]\n");
    free(text);
    remove(frames);
}

/* --frames is written whole or not at all: it was written under its final name, so a write
 * that failed midway (a file size limit of 1 kB; the frames of the example track are some
 * 30 kB) left a cut-off file there, with exit 1. A track that succeeds leaves the whole file
 * and nothing else. */
static void test_track_cli_writes_frames_whole_or_not_at_all(void** state)
{
    (void)state;
    if (!getenv("WETDEM_CLI"))
        skip();
    char dir[96], frames[128], args[512];
    snprintf(dir, sizeof dir, "/tmp/wetdem_track_out_%d", (int)getpid());
    snprintf(frames, sizeof frames, "%s/frames.csv", dir);
    assert_int_equal(mkdir(dir, 0700), 0);
    snprintf(args, sizeof args,
             "track examples/tracks/punch_45deg.csv --fps 5000 --pixel-size 175e-6 --frames %s",
             frames);
    test_check_write_fails(args, "track", frames, dir, "");
    struct test_run r = test_run_cli("", args, true);
    if (r.code != 0)
        fail_msg("wetdem %s: exit %d\n%s", args, r.code, r.out);
    free(r.out);
    test_check_dir(dir, "frames.csv\n");
    size_t len;
    char* text = test_read_file(frames, &len);
    assert_non_null(text);
    size_t lines = 0;
    for (size_t i = 0; i < len; i++)
        lines += text[i] == '\n';
    /* provenance, header, and a row per interval of each sphere: 120 frames each */
    assert_int_equal(lines, 2 + 1 + 2 * 119);
    assert_true(len > 0 && text[len - 1] == '\n');
    free(text);
    remove(frames);
    rmdir(dir);
}

/* --frames naming a symbolic link writes the link's target and keeps the link; naming a
 * device (here through a link to /dev/null) writes it in place: the temporary file renamed over
 * the name replaced the link, and would have replaced a device node with a regular file. */
static void test_track_cli_frames_through_links_and_devices(void** state)
{
    (void)state;
    if (!getenv("WETDEM_CLI"))
        skip();
    char dir[96], target[128], link[128], null_link[128], args[512];
    snprintf(dir, sizeof dir, "/tmp/wetdem_track_links_%d", (int)getpid());
    snprintf(target, sizeof target, "%s/target.csv", dir);
    snprintf(link, sizeof link, "%s/link.csv", dir);
    snprintf(null_link, sizeof null_link, "%s/null.csv", dir);
    assert_int_equal(mkdir(dir, 0700), 0);
    FILE* f = fopen(target, "w");
    assert_non_null(f);
    fputs("old\n", f);
    fclose(f);
    assert_int_equal(symlink("target.csv", link), 0);
    assert_int_equal(symlink("/dev/null", null_link), 0);
    const char* track = "track examples/tracks/punch_45deg.csv --fps 5000 --pixel-size 175e-6";
    snprintf(args, sizeof args, "%s --frames %s", track, link);
    struct test_run r = test_run_cli("", args, true);
    if (r.code != 0)
        fail_msg("wetdem %s: exit %d\n%s", args, r.code, r.out);
    free(r.out);
    struct stat st;
    assert_int_equal(lstat(link, &st), 0);
    assert_true(S_ISLNK(st.st_mode));
    char* text = test_read_file(target, NULL);
    assert_non_null(text);
    CHECK_CONTAINS(text, "sphere [index],frame [index],time [s],");
    free(text);
    snprintf(args, sizeof args, "%s --frames %s", track, null_link);
    r = test_run_cli("", args, true);
    if (r.code != 0)
        fail_msg("wetdem %s: exit %d\n%s", args, r.code, r.out);
    free(r.out);
    assert_int_equal(lstat(null_link, &st), 0);
    assert_true(S_ISLNK(st.st_mode));
    assert_int_equal(stat("/dev/null", &st), 0);
    assert_true(S_ISCHR(st.st_mode));
    test_check_dir(dir, "link.csv\nnull.csv\ntarget.csv\n");
    remove(link);
    remove(null_link);
    remove(target);
    rmdir(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_track_savgol_matches_closed_form),
        cmocka_unit_test(test_track_savgol_keeps_quadratics_up_to_the_ends),
        cmocka_unit_test(test_track_interval_small_angle_bias_is_exact),
        cmocka_unit_test(test_track_recovers_collision_from_noisy_dots),
        cmocka_unit_test(test_track_noise_free_recovery_is_tight),
        cmocka_unit_test(test_track_sticking_pair_is_reported),
        cmocka_unit_test(test_track_recovers_simulated_punch_collision),
        cmocka_unit_test(test_track_interval_gain_and_rigid_residual),
        cmocka_unit_test(test_track_uncertainties_are_the_propagated_noise),
        cmocka_unit_test(test_track_uncertainties_match_monte_carlo),
        cmocka_unit_test(test_track_noise_free_uncertainties_vanish),
        cmocka_unit_test(test_track_uncertainties_scale_with_noise),
        cmocka_unit_test(test_track_rejects_malformed_files),
        cmocka_unit_test(test_track_rejects_short_or_mismatched_tracks),
        cmocka_unit_test(test_track_cli_exits_2_with_line_number),
        cmocka_unit_test(test_track_cli_refuses_a_change_that_is_no_collision),
        cmocka_unit_test(test_track_cli_summary_has_no_nan),
        cmocka_unit_test(test_track_cli_reports_uncertainties),
        cmocka_unit_test(test_track_cli_writes_frames_whole_or_not_at_all),
        cmocka_unit_test(test_track_cli_frames_through_links_and_devices),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

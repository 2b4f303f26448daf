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
 * fits have a slope to find.
 */
#include <stdlib.h>
#include <sys/wait.h>
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

static void synth_init(struct synth* y, double theta)
{
    *y = (struct synth){.fps = 5000, .pixel = 175e-6, .radius = 12.7e-3, .beta = 25 * M_PI / 180,
                        .t_c = 50.37 / 5000, .speed = 0.3, .theta = theta, .e_n = 0.6,
                        .e_t = 0.8, .acc = {-0.4, 0.1}, .omega_pre = {3, 0},
                        .omega_post = {-18, 25}, .yaw = {0.4, 2.1}};
    /* Equal chords |p1 p2| = |p2 p3|: 2R sin(beta/2) = 2R sin(beta) sin(dphi/2). */
    y->dphi = 2 * asin(sin(y->beta / 2) / sin(y->beta));
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

/* Dots of sphere k at frame f in pixels, with Gaussian noise of sigma_px (rng may be NULL). */
static void synth_dots(const struct synth* y, int k, int f, gsl_rng* rng, double sigma_px,
                       double xy[6])
{
    double pos[2], vel[2], yaw, omega;
    synth_state(y, k, f / y->fps, pos, vel, &yaw, &omega);
    double rho = y->radius * sin(y->beta); /* projected distance of dots 2, 3 from dot 1 */
    double az[3] = {0, yaw, yaw + y->dphi};
    for (int j = 0; j < 3; j++) {
        double r = j == 0 ? 0 : rho;
        xy[2 * j] = (pos[0] + r * cos(az[j])) / y->pixel + 600;
        xy[2 * j + 1] = (pos[1] + r * sin(az[j])) / y->pixel + 400;
        for (int c = 0; c < 2 && rng; c++)
            xy[2 * j + c] += gsl_ran_gaussian(rng, sigma_px);
    }
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
        CHECK_ABS(hat[2 * 5 + m], w5[m] / 35, 1e-14); /* QR round-off, entries O(1) */
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
     * shifted (end) windows; round-off on values O(100) is ~1e-12. */
    double hat[49], x[20], out[20];
    CHECK_OK(wetdem_track_savgol_hat(7, 2, hat));
    for (int i = 0; i < 20; i++)
        x[i] = 1 + 2.5 * i - 0.3 * i * i;
    wetdem_track_savgol_apply(hat, 7, x, 20, out);
    for (int i = 0; i < 20; i++)
        CHECK_ABS(out[i], x[i], 1e-11);
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
    CHECK_REL(out[2], sin(a) / dt, 1e-12); /* round-off of a 6x3 QR on O(1e-3) data */
    for (int c = 0; c < 2; c++)
        CHECK_REL(out[c], v[c] + (cos(a) - 1) * (d2[c] + d3[c]) / (3 * dt), 1e-10);
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
    double v[N_OUT] = {sum->striker_before.vx,  sum->striker_before.vy, sum->striker_after.vx,
                       sum->striker_after.vy,   sum->striker_after.omega, sum->target_after.vx,
                       sum->target_after.vy,    sum->target_after.omega, sum->e_n,
                       sum->impact_angle,       sum->stokes_n};
    memcpy(out, v, sizeof v);
    return st;
}

/* The same outputs from the true motion, using the tracker's definitions at its frames. */
static void true_outputs(const struct synth* y, const struct wetdem_track_options* o,
                         long c, double out[N_OUT])
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
    double v[N_OUT] = {vs0[0], vs0[1], vsf[0], vsf[1], ws, vgf[0], vgf[1], wg, vnf / vn0,
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
static const double method_bias[N_OUT] = {1e-5, 1e-5, 2.5e-4, 2.5e-4, 2e-4, 2.5e-4,
                                          2.5e-4, 2e-4, 3e-3, 1e-4, 1e-4};

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
                     "+ bias %.3g", theta * 180 / M_PI, q, got[q], want[q],
                     fabs(got[q] - want[q]), 4 * sigma[q], method_bias[q]);
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

static void test_track_noise_free_recovery_is_tight(void** state)
{
    (void)state;
    /* Without noise only the small-angle and quadratic-window biases remain (see above). */
    struct synth y;
    synth_init(&y, 30 * M_PI / 180);
    struct wetdem_track_options o;
    track_options(&o, &y);
    double* dots = malloc(12 * N_FRAMES * sizeof *dots), got[N_OUT], want[N_OUT];
    render(&y, NULL, 0, dots);
    struct wetdem_track_summary s;
    CHECK_OK(analyse_dots(dots, &o, got, &s));
    true_outputs(&y, &o, s.collision_frame, want);
    for (int q = 0; q < N_OUT; q++)
        if (!(fabs(got[q] - want[q]) <= method_bias[q] * fmax(1, fabs(want[q]))))
            fail_msg("output %d: got %.9g, true %.9g, bias bound %.3g", q, got[q], want[q],
                     method_bias[q]);
    CHECK_ABS(s.angle_centres, 30 * M_PI / 180, 0.01); /* striker 0.2 mm short of contact */
    /* y_down negates y: the spin changes sign, the speeds do not. */
    o.y_down = true;
    double flipped[N_OUT];
    CHECK_OK(analyse_dots(dots, &o, flipped, &s));
    CHECK_REL(flipped[4], -got[4], 1e-9);
    CHECK_REL(flipped[8], got[8], 1e-9);
    free(dots);
}

/* ---- malformed tracks ---------------------------------------------------------------------- */

static const char* write_temp(const char* text)
{
    static char path[64];
    snprintf(path, sizeof path, "/tmp/wetdem_track_%d.csv", (int)getpid());
    FILE* f = fopen(path, "w");
    assert_non_null(f);
    fputs(text, f);
    fclose(f);
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
    const char* head = "frame,sphere,x1,y1,x2,y2,x3,y3\n";
    char buf[512];
    snprintf(buf, sizeof buf, "%s0,1,1,1,2,2,3,3\n1,1,1,1,2,2,3\n", head);
    expect_read_error(buf, WETDEM_ERR_PARSE, ":3: expected 8 columns");
    snprintf(buf, sizeof buf, "%s0,1,1,1,2,2,3,3\n1,1,1,nan,2,2,3,3\n", head);
    expect_read_error(buf, WETDEM_ERR_PARSE, ":3: column y1: 'nan' is not a finite number");
    snprintf(buf, sizeof buf, "%s# c\n0,1,1,1,2,2,3,3\n1,1,1,1,2,2,3,3\n3,1,1,1,2,2,3,3\n", head);
    expect_read_error(buf, WETDEM_ERR_PARSE, ":5: sphere 1: frame 3 follows frame 1; frames 2 to 2");
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
}

static void test_track_cli_exits_2_with_line_number(void** state)
{
    (void)state;
    const char* cli = getenv("WETDEM_CLI");
    if (!cli)
        skip();
    const char* path = write_temp("frame,sphere,x1,y1,x2,y2,x3,y3\n0,1,1,1,2,2,3,3\n2,1,1,1,2,2,3,3\n");
    char cmd[512];
    snprintf(cmd, sizeof cmd, "%s track %s --fps 5000 --pixel-size 175e-6 2>&1", cli, path);
    FILE* p = popen(cmd, "r");
    char out[1024] = "";
    size_t len = fread(out, 1, sizeof out - 1, p);
    out[len] = '\0';
    int rc = pclose(p);
    remove(path);
    assert_true(WIFEXITED(rc));
    assert_int_equal(WEXITSTATUS(rc), 2);
    CHECK_CONTAINS(out, ":3: sphere 1: frame 2 follows frame 0");
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_track_savgol_matches_closed_form),
        cmocka_unit_test(test_track_savgol_keeps_quadratics_up_to_the_ends),
        cmocka_unit_test(test_track_interval_small_angle_bias_is_exact),
        cmocka_unit_test(test_track_recovers_collision_from_noisy_dots),
        cmocka_unit_test(test_track_noise_free_recovery_is_tight),
        cmocka_unit_test(test_track_rejects_malformed_files),
        cmocka_unit_test(test_track_rejects_short_or_mismatched_tracks),
        cmocka_unit_test(test_track_cli_exits_2_with_line_number),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/*
 * track.c — velocities, spin, impact angle, Stokes number and restitution of a Stokes-cradle
 * collision from the tracked positions of three painted dots per sphere (Punch et al. 2023,
 * Sec. 3.2, Eqs. 2, 3, 16-23 and Appendix A). docs/tracking.md describes the input and output.
 *
 * Pipeline (all lengths in m after multiplying pixels by the pixel size, times in s):
 *  1. Savitzky-Golay smoothing of every dot coordinate (order 2, 7 frames by default); the
 *     weights are the rows of the least-squares hat matrix H = V (V^T V)^-1 V^T of the window's
 *     Vandermonde matrix V, obtained by a QR factorisation (GSL), not from a table.
 *  2. For every frame interval i -> i+1 the rigid-motion equations of the three dots
 *         p1^{i+1} - p1^i = v dt                                   (Eqs. 17-18)
 *         pk^{i+1} - pk^i = v dt + omega dt J (pk^i - p1^i),  k = 2, 3
 *     with J (a, b) = (-b, a), solved by linear least squares (Eq. 23; GSL QR). Sign: omega is
 *     counter-clockwise in (x, y), as in Appendix A Eqs. 27-29; Eqs. 19-23 as printed carry
 *     the opposite sign of omega (they agree with App. A when the image y axis points down,
 *     which the y_down option handles). Eq. 21 as printed has p_y,2 - p_y,3 where the matrix
 *     of Eq. 23 (and the derivation) has p_y,1 - p_y,3.
 *     Small-angle bias: for an exact rotation by a = omega dt the solution is exactly
 *     omega_est = sin(a)/dt (the cos(a) - 1 part of the rotation is orthogonal to the omega
 *     column) and v_est = v + (cos(a) - 1)(D2 + D3)/(3 dt), Dk = pk - p1; i.e. a relative
 *     spin bias -a^2/6 (6e-6 at 30 rad/s and 5000 frames/s).
 *  3. Collision frame: the first interval from which the striker's smoothed velocity differs
 *     from its mean over the first `window` intervals by more than `threshold` (0.05 m/s) for
 *     window/2 + 1 consecutive intervals (a single noisy interval is not a collision).
 *  4. Straight lines fitted to vx, vy and omega of each sphere before (intervals ending
 *     window/2 + 1 before the collision frame) and after (from window + 1 after it, clear of
 *     the smoothing's spread of the jump), evaluated `offset` frames before/after.
 *  5. Impact angle of the centres (Eq. 16), normal relative speeds with the line of centres at
 *     the collision frame (n_0) and at `offset` frames after (n_f), e_n (Eq. 3) and
 *     St_n = m* v_n0 / (6 pi mu R*^2) (Eq. 2) for two equal spheres (m* = m/2, R* = R/2).
 *  6. Standard uncertainties (derivation in docs/tracking.md "Uncertainties"). The noise sigma
 *     of every pixel coordinate of a sphere, independent between coordinates and frames, is
 *     estimated from the residuals of Eq. 23 on the raw dots, less the small-angle part that
 *     the solution determines: E|r|^2 = 2 sigma^2 (6 - 3) per interval. With the collision
 *     frame fixed every value is, to first order, a linear function of the raw dots:
 *     smoothing s = S x, Eq. 23 per interval v_i = A_i+ (s_{i+1} - s_i)/dt (the closed form
 *     of its normal equations; A_i moves with s_i as dv = A+ (db - omega dt J dD)/dt), the
 *     straight lines sum_i w_i v_i. So the before/after values and the dot-1 positions have
 *     gradients g with respect to the raw dots and covariances sigma^2 g_a . g_b, which hold
 *     the correlations of values that share frames; the spheres, and the before and after
 *     fits, share none. The derived values (normal speeds, e_n, St_n, angles) follow by
 *     first-order propagation with those covariances.
 *
 * Validity: dot 1 on the spin axis (the painted centre dot), rotation about the camera axis,
 * orthographic imaging; at most two spheres; frames consecutive without gaps.
 */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include <gsl/gsl_linalg.h>
#include <gsl/gsl_matrix.h>
#include <gsl/gsl_vector.h>

#include "locale_guard.h"
#include "track.h"

#define TRACK_MAX_FRAME 1000000000000L /* |frame number| at most [-] */
#define TRACK_MAX_SPHERES 2
#define TRACK_ERRMSG_SIZE 512
#define TRACK_LINE_MAX 4096
#define TRACK_MIN_FIT 3 /* points of a straight-line fit: 2 parameters + 1 degree of freedom */

struct sphere_track {
    int id;
    long first_frame;
    size_t n, cap;                       /* frames stored */
    double* xy;                          /* 6 per frame: dots in pixels as given */
    double* raw;                         /* 6 per frame [m], y negated when y_down */
    double* smooth;                      /* 6 per frame [m], Savitzky-Golay smoothed */
    double noise;                        /* tracking noise per coordinate [m], after analysis */
    struct wetdem_track_sample* samples; /* n - 1 intervals, after analysis */
};

struct wetdem_track {
    char errmsg[TRACK_ERRMSG_SIZE];
    struct sphere_track s[TRACK_MAX_SPHERES];
    size_t n_spheres;
};

static int fail(struct wetdem_track* t, int status, const char* fmt, ...)
    __attribute__((format(printf, 3, 4)));

static int fail(struct wetdem_track* t, int status, const char* fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(t->errmsg, sizeof t->errmsg, fmt, ap);
    va_end(ap);
    return status;
}

struct wetdem_track* wetdem_track_create(void)
{
    return calloc(1, sizeof(struct wetdem_track));
}

static void free_results(struct sphere_track* s)
{
    free(s->raw);
    free(s->smooth);
    free(s->samples);
    s->raw = s->smooth = NULL;
    s->samples = NULL;
}

void wetdem_track_free(struct wetdem_track* track)
{
    if (!track)
        return;
    for (size_t k = 0; k < track->n_spheres; k++) {
        free_results(&track->s[k]);
        free(track->s[k].xy);
    }
    free(track);
}

const char* wetdem_track_errmsg(const struct wetdem_track* track)
{
    return track ? track->errmsg : "";
}

size_t wetdem_track_n_spheres(const struct wetdem_track* track)
{
    return track->n_spheres;
}

int wetdem_track_sphere_id(const struct wetdem_track* track, size_t k)
{
    return k < track->n_spheres ? track->s[k].id : -1;
}

const struct wetdem_track_sample* wetdem_track_samples(const struct wetdem_track* t, size_t k,
                                                       size_t* n)
{
    if (k >= t->n_spheres || !t->s[k].samples) {
        *n = 0;
        return NULL;
    }
    *n = t->s[k].n - 1;
    return t->s[k].samples;
}

/* ---- input ------------------------------------------------------------------------------ */

static const char* const coord_names[6] = {"x1", "y1", "x2", "y2", "x3", "y3"};

/* The stored sphere with this id, a new one, or NULL when two spheres exist already. */
static struct sphere_track* sphere_slot(struct wetdem_track* t, int id)
{
    for (size_t k = 0; k < t->n_spheres; k++)
        if (t->s[k].id == id)
            return &t->s[k];
    if (t->n_spheres == TRACK_MAX_SPHERES)
        return NULL;
    struct sphere_track* s = &t->s[t->n_spheres++];
    memset(s, 0, sizeof *s);
    s->id = id;
    return s;
}

int wetdem_track_add_frame(struct wetdem_track* track, int sphere_id, long frame,
                           const double xy[6])
{
    if (sphere_id < 0)
        return fail(track, WETDEM_ERR_INVALID, "sphere id %d must be >= 0", sphere_id);
    /* (a bound far beyond any video keeps first_frame + n, below, from overflowing) */
    if (frame < -TRACK_MAX_FRAME || frame > TRACK_MAX_FRAME)
        return fail(track, WETDEM_ERR_INVALID, "sphere %d: frame %ld is out of range [%ld, %ld]",
                    sphere_id, frame, -TRACK_MAX_FRAME, TRACK_MAX_FRAME);
    for (int c = 0; c < 6; c++)
        if (!isfinite(xy[c]))
            return fail(track, WETDEM_ERR_INVALID, "sphere %d frame %ld: %s is not finite (%g)",
                        sphere_id, frame, coord_names[c], xy[c]);
    struct sphere_track* s = sphere_slot(track, sphere_id);
    if (!s)
        return fail(track, WETDEM_ERR_INVALID,
                    "sphere %d: at most %d spheres per track (found %d and %d already)", sphere_id,
                    TRACK_MAX_SPHERES, track->s[0].id, track->s[1].id);
    if (s->n > 0) {
        long last = s->first_frame + (long)s->n - 1;
        if (frame <= last)
            return fail(track, WETDEM_ERR_INVALID,
                        "sphere %d: frame %ld follows frame %ld; frames must increase", sphere_id,
                        frame, last);
        if (frame == last + 2)
            return fail(track, WETDEM_ERR_INVALID,
                        "sphere %d: frame %ld follows frame %ld; frame %ld is missing (or comes "
                        "later: the rows of a sphere must be in frame order)",
                        sphere_id, frame, last, last + 1);
        if (frame > last + 1)
            return fail(track, WETDEM_ERR_INVALID,
                        "sphere %d: frame %ld follows frame %ld; frames %ld to %ld are missing "
                        "(or come later: the rows of a sphere must be in frame order)",
                        sphere_id, frame, last, last + 1, frame - 1);
    } else {
        s->first_frame = frame;
    }
    if (s->n == s->cap) {
        size_t cap = s->cap ? 2 * s->cap : 256;
        double* p = realloc(s->xy, cap * 6 * sizeof *p);
        if (!p)
            return fail(track, WETDEM_ERR_NOMEM, "out of memory storing frame %ld", frame);
        s->xy = p;
        s->cap = cap;
    }
    memcpy(s->xy + 6 * s->n, xy, 6 * sizeof *xy);
    s->n++;
    free_results(s);
    return WETDEM_OK;
}

/* Strips leading/trailing blanks in place; returns the start. */
static char* trim(char* f)
{
    while (*f == ' ' || *f == '\t')
        f++;
    size_t len = strlen(f);
    while (len > 0 &&
           (f[len - 1] == ' ' || f[len - 1] == '\t' || f[len - 1] == '\r' || f[len - 1] == '\n'))
        f[--len] = '\0';
    return f;
}

/* Splits a line at commas into at most `max` trimmed fields; returns the field count (max + 1
 * when there are more). */
static int split_fields(char* line, char** fields, int max)
{
    int n = 0;
    char* p = line;
    for (;;) {
        char* comma = strchr(p, ',');
        if (comma)
            *comma = '\0';
        if (n <= max - 1)
            fields[n] = trim(p);
        n++;
        if (!comma || n > max)
            return n;
        p = comma + 1;
    }
}

static bool parse_long(const char* text, long* out)
{
    char* end = NULL;
    errno = 0;
    long v = strtol(text, &end, 10);
    if (end == text || *end != '\0' || errno == ERANGE)
        return false;
    *out = v;
    return true;
}

static bool parse_number(const char* text, double* out)
{
    char* end = NULL;
    errno = 0;
    double v = strtod(text, &end);
    if (end == text || *end != '\0' || errno == ERANGE)
        return false;
    *out = v;
    return true;
}

/* True when fields are the expected header words frame,sphere,x1,...,y3 (any case). */
static bool is_expected_header(char** f)
{
    if (strcasecmp(f[0], "frame") != 0 || strcasecmp(f[1], "sphere") != 0)
        return false;
    for (int c = 0; c < 6; c++)
        if (strcasecmp(f[2 + c], coord_names[c]) != 0)
            return false;
    return true;
}

/* Parses and appends one data row; messages are prefixed by the caller. */
static int parse_row(struct wetdem_track* t, char** f)
{
    long frame, sphere;
    double xy[6];
    if (!parse_long(f[0], &frame))
        return fail(t, WETDEM_ERR_PARSE, "column frame: '%s' is not an integer", f[0]);
    if (!parse_long(f[1], &sphere) || sphere < 0 || sphere > 1000000)
        return fail(t, WETDEM_ERR_PARSE, "column sphere: '%s' is not an integer id in [0, 1000000]",
                    f[1]);
    for (int c = 0; c < 6; c++)
        if (!parse_number(f[2 + c], &xy[c]) || !isfinite(xy[c]))
            return fail(t, WETDEM_ERR_PARSE, "column %s: '%s' is not a finite number",
                        coord_names[c], f[2 + c]);
    int st = wetdem_track_add_frame(t, (int)sphere, frame, xy);
    return st == WETDEM_ERR_INVALID ? WETDEM_ERR_PARSE : st;
}

/* Prefixes the current message with "path:line: ". */
static int located(struct wetdem_track* t, int status, const char* path, long line)
{
    char msg[TRACK_ERRMSG_SIZE];
    snprintf(msg, sizeof msg, "%s", t->errmsg);
    return fail(t, status, "%s:%ld: %s", path, line, msg);
}

/* Handles one non-blank, non-comment line; *seen_data tells whether a row came before. */
static int read_line(struct wetdem_track* t, char* text, bool* seen_data)
{
    char* f[9];
    int n = split_fields(text, f, 9);
    if (n != 8)
        return fail(t, WETDEM_ERR_PARSE,
                    "expected 8 columns (frame,sphere,x1,y1,x2,y2,x3,y3), found %s%d",
                    n > 8 ? "more than " : "", n > 8 ? 8 : n);
    long dummy;
    if (!*seen_data && !parse_long(f[0], &dummy)) {
        *seen_data = true;
        if (!is_expected_header(f))
            return fail(t, WETDEM_ERR_PARSE,
                        "header must be frame,sphere,x1,y1,x2,y2,x3,y3 (got '%s,%s,...')", f[0],
                        f[1]);
        return WETDEM_OK;
    }
    *seen_data = true;
    return parse_row(t, f);
}

/* Reads one line of fp into buf (n bytes: at most n - 1 characters, the '\n' kept, NUL-terminated)
 * as fgets does, but tells a NUL byte, which fgets would take for the end of the line (a binary
 * file was read as lines cut short, or as one too long): 1 a line, 0 the end of the file, -1 a
 * line longer than n - 2 characters, -2 a NUL byte in the line. */
static int read_text_line(FILE* fp, char* buf, size_t n)
{
    size_t len = 0;
    int c;
    while ((c = getc(fp)) != EOF) {
        if (c == '\0')
            return -2;
        if (len + 1 >= n)
            return -1;
        buf[len++] = (char)c;
        if (c == '\n')
            break;
    }
    buf[len] = '\0';
    return len > 0 ? 1 : 0;
}

static int read_csv(struct wetdem_track* track, const char* path)
{
    if (!path)
        return fail(track, WETDEM_ERR_INVALID, "read_csv: NULL path");
    FILE* fp = fopen(path, "r");
    if (!fp)
        return fail(track, WETDEM_ERR_IO, "%s: cannot open: %s", path, strerror(errno));
    char buf[TRACK_LINE_MAX];
    long line = 0;
    bool seen_data = false;
    int st = WETDEM_OK;
    int got;
    while (st == WETDEM_OK && (got = read_text_line(fp, buf, sizeof buf)) != 0) {
        line++;
        if (got < 0) {
            st = located(track,
                         got == -2 ? fail(track, WETDEM_ERR_PARSE,
                                          "a NUL byte in the line: not a text (CSV) file")
                                   : fail(track, WETDEM_ERR_PARSE, "line longer than %d characters",
                                          TRACK_LINE_MAX - 2),
                         path, line);
            break;
        }
        char* text = buf;
        if (line == 1 && strncmp(text, "\xef\xbb\xbf", 3) == 0)
            text += 3; /* a UTF-8 byte order mark (spreadsheets' "CSV UTF-8") */
        text = trim(text);
        if (*text == '\0' || *text == '#')
            continue;
        st = read_line(track, text, &seen_data);
        if (st != WETDEM_OK)
            st = located(track, st, path, line);
    }
    if (st == WETDEM_OK && ferror(fp)) /* (e.g. a directory: it opens, but does not read) */
        st = fail(track, WETDEM_ERR_IO, "%s: cannot read: %s", path, strerror(errno));
    fclose(fp);
    if (st == WETDEM_OK && track->n_spheres == 0)
        st = fail(track, WETDEM_ERR_PARSE, "%s: no data rows", path);
    return st;
}

/* The numbers of the file in the C locale: "0.5", whatever LC_NUMERIC the host set. */
int wetdem_track_read_csv(struct wetdem_track* track, const char* path)
{
    struct wetdem_locale_guard g;
    if (wetdem_locale_guard_enter(&g) != WETDEM_OK)
        return fail(track, WETDEM_ERR_NOMEM, "read_csv: out of memory for the C locale");
    int st = read_csv(track, path);
    wetdem_locale_guard_leave(&g);
    return st;
}

/* ---- kernels ---------------------------------------------------------------------------- */

int wetdem_track_savgol_hat(int window, int order, double* hat)
{
    if (window < 1 || window % 2 == 0 || order < 0 || order >= window)
        return WETDEM_ERR_INVALID;
    size_t w = (size_t)window, p = (size_t)order + 1;
    /* views of one block of our own: GSL's allocators call its error handler, whose default
       aborts, when out of memory */
    double* block = malloc((2 * w * p + p + w * w) * sizeof *block);
    if (!block)
        return WETDEM_ERR_NOMEM;
    gsl_matrix_view vv = gsl_matrix_view_array(block, w, p);
    gsl_matrix_view rv = gsl_matrix_view_array(block + w * p, w, p);
    gsl_vector_view tv = gsl_vector_view_array(block + 2 * w * p, p);
    gsl_matrix_view qv = gsl_matrix_view_array(block + 2 * w * p + p, w, w);
    gsl_matrix *v = &vv.matrix, *r = &rv.matrix, *q = &qv.matrix;
    gsl_vector* tau = &tv.vector;
    /* Vandermonde matrix on the centred abscissa u = k - window/2 (better conditioned). */
    for (size_t k = 0; k < w; k++)
        for (size_t j = 0; j < p; j++)
            gsl_matrix_set(v, k, j, pow((double)k - (double)(w / 2), (double)j));
    gsl_linalg_QR_decomp(v, tau);
    gsl_linalg_QR_unpack(v, tau, q, r);
    /* V has full column rank, so H = Q1 Q1^T with Q1 the first p columns of Q. */
    for (size_t a = 0; a < w; a++)
        for (size_t b = 0; b < w; b++) {
            double sum = 0;
            for (size_t j = 0; j < p; j++)
                sum += gsl_matrix_get(q, a, j) * gsl_matrix_get(q, b, j);
            hat[a * w + b] = sum;
        }
    free(block);
    return WETDEM_OK;
}

/* First raw frame of the smoothing window of frame j: centred inside, the first/last
 * `window` frames at the ends. */
static size_t window_start(size_t j, size_t w, size_t n)
{
    size_t h = w / 2, start = j < h ? 0 : j - h;
    return start + w > n ? n - w : start;
}

void wetdem_track_savgol_apply(const double* hat, int window, const double* x, size_t n,
                               double* out)
{
    size_t w = (size_t)window;
    for (size_t j = 0; j < n; j++) {
        size_t start = window_start(j, w, n);
        const double* row = hat + (j - start) * w;
        double sum = 0;
        for (size_t m = 0; m < w; m++)
            sum += row[m] * x[start + m];
        out[j] = sum;
    }
}

int wetdem_track_solve_interval(const double p0[6], const double p1[6], double dt, double out[3],
                                double* rms)
{
    /* Unknowns scaled as (vx dt, vy dt, omega dt) so that the columns are comparable. */
    double a[18] = {0}, b[6], tau[3], x[3], res[6];
    for (int k = 0; k < 3; k++) {
        double dx = p0[2 * k] - p0[0], dy = p0[2 * k + 1] - p0[1];
        double* rx = a + 6 * k;
        double* ry = rx + 3;
        rx[0] = 1.0;
        rx[2] = -dy;
        ry[1] = 1.0;
        ry[2] = dx;
        b[2 * k] = p1[2 * k] - p0[2 * k];
        b[2 * k + 1] = p1[2 * k + 1] - p0[2 * k + 1];
    }
    gsl_matrix_view av = gsl_matrix_view_array(a, 6, 3);
    gsl_vector_view bv = gsl_vector_view_array(b, 6), tv = gsl_vector_view_array(tau, 3);
    gsl_vector_view xv = gsl_vector_view_array(x, 3), rv = gsl_vector_view_array(res, 6);
    gsl_linalg_QR_decomp(&av.matrix, &tv.vector);
    /* Degenerate when the outer dots coincide with the centre dot (R[2][2] = 0). */
    if (!(fabs(gsl_matrix_get(&av.matrix, 2, 2)) > 0))
        return WETDEM_ERR_NUMERIC;
    gsl_linalg_QR_lssolve(&av.matrix, &tv.vector, &bv.vector, &xv.vector, &rv.vector);
    for (int k = 0; k < 3; k++)
        out[k] = x[k] / dt;
    if (rms) {
        double s = 0;
        for (int k = 0; k < 6; k++)
            s += res[k] * res[k];
        *rms = sqrt(s / 6.0);
    }
    return isfinite(out[0] + out[1] + out[2]) ? WETDEM_OK : WETDEM_ERR_NUMERIC;
}

/* Eq. 23 in closed form (docs/tracking.md "Uncertainties"): with the dots' offsets
 * Dk = pk - p1 at the first frame (D1 = 0), their centroid c = (D2 + D3)/3, ek = Dk - c and
 * M = sum_k |ek|^2, the normal equations give
 *     omega dt = sum_k ek x bk / M,    v dt = mean_k(bk) - omega dt J c
 * (a x b = ax by - ay bx, J(a, b) = (-b, a)): the rotation about the dots' centroid and the
 * centroid's displacement. Fills e[6] = (e1, e2, e3), c[2] and *m; false when M is not > 0
 * (the outer dots on the centre dot, the QR's R[2][2] = 0). */
static bool interval_centroid(const double p0[6], double e[6], double c[2], double* m)
{
    c[0] = (p0[2] + p0[4] - 2 * p0[0]) / 3;
    c[1] = (p0[3] + p0[5] - 2 * p0[1]) / 3;
    *m = 0;
    for (int k = 0; k < 3; k++) {
        e[2 * k] = p0[2 * k] - p0[0] - c[0];
        e[2 * k + 1] = p0[2 * k + 1] - p0[1] - c[1];
        *m += e[2 * k] * e[2 * k] + e[2 * k + 1] * e[2 * k + 1];
    }
    return *m > 0 && isfinite(*m);
}

/* The residual used for the noise: with the solution's sin(a) = omega dt, the rigid step
 * about the centroid, bk - mean(b) = (R(a) - I) ek, leaves
 *     rk = bk - mean(b) - (cos a - 1) ek - sin a J ek,
 * the residual of Eq. 23 less its small-angle part (cos a - 1) ek (header, step 2):
 * cos a - 1 = -sin^2 a / (1 + cos a). */
int wetdem_track_rigid_residual(const double p0[6], const double p1[6], double* ss)
{
    double e[6], c[2], m, b[6], mean[2] = {0, 0}, w = 0;
    if (!interval_centroid(p0, e, c, &m))
        return WETDEM_ERR_NUMERIC;
    for (int j = 0; j < 6; j++) {
        b[j] = p1[j] - p0[j];
        mean[j % 2] += b[j] / 3;
    }
    for (int k = 0; k < 3; k++)
        w += (e[2 * k] * b[2 * k + 1] - e[2 * k + 1] * b[2 * k]) / m;
    double s2 = fmin(w * w, 1.0), cm1 = -s2 / (1 + sqrt(1 - s2)), sum = 0;
    for (int k = 0; k < 3; k++) {
        double rx = b[2 * k] - mean[0] - cm1 * e[2 * k] + w * e[2 * k + 1];
        double ry = b[2 * k + 1] - mean[1] - cm1 * e[2 * k + 1] - w * e[2 * k];
        sum += rx * rx + ry * ry;
    }
    *ss = sum;
    return isfinite(sum) ? WETDEM_OK : WETDEM_ERR_NUMERIC;
}

/* The derivatives of the closed form above with respect to bk = (bx, by):
 * d(omega dt) = (-eky, ekx)/M, d(vx dt) = (1/3, 0) + cy d(omega dt),
 * d(vy dt) = (0, 1/3) - cx d(omega dt). */
int wetdem_track_interval_gain(const double p0[6], double dt, double gain[18])
{
    double e[6], c[2], m;
    if (!interval_centroid(p0, e, c, &m))
        return WETDEM_ERR_NUMERIC;
    for (int k = 0; k < 3; k++) {
        double wx = -e[2 * k + 1] / m, wy = e[2 * k] / m;
        gain[2 * k] = (1.0 / 3 + c[1] * wx) / dt;
        gain[2 * k + 1] = c[1] * wy / dt;
        gain[6 + 2 * k] = -c[0] * wx / dt;
        gain[6 + 2 * k + 1] = (1.0 / 3 - c[0] * wy) / dt;
        gain[12 + 2 * k] = wx / dt;
        gain[12 + 2 * k + 1] = wy / dt;
    }
    return WETDEM_OK;
}

/* ---- analysis --------------------------------------------------------------------------- */

void wetdem_track_options_init(struct wetdem_track_options* opt)
{
    *opt = (struct wetdem_track_options){
        .fps = 0,
        .pixel_size = 0,
        .y_down = false,
        .window = 7,
        .order = 2,
        .threshold = 0.05,
        .offset = 5,
        .fit_frames = 0,
        .striker = -1,
        .radius = 0,
        .mass = 0,
        .viscosity = 0,
    };
}

static int check_options(struct wetdem_track* t, const struct wetdem_track_options* o)
{
    /* a camera's range, with room: 1e9 frames/s, 1 m a pixel (Punch: 5000, 175e-6) */
    if (!(o->fps > 0 && o->fps <= 1e9))
        return fail(t, WETDEM_ERR_INVALID, "fps = %g: must be a frame rate in (0, 1e9] [1/s]",
                    o->fps);
    if (!(o->pixel_size > 0 && o->pixel_size <= 1))
        return fail(t, WETDEM_ERR_INVALID, "pixel_size = %g: must be in (0, 1] [m/pixel]",
                    o->pixel_size);
    if (o->window < 1 || o->window % 2 == 0 || o->window > 1001)
        return fail(t, WETDEM_ERR_INVALID, "window = %d: must be odd, in [1, 1001] frames",
                    o->window);
    if (o->order < 0 || o->order >= o->window)
        return fail(t, WETDEM_ERR_INVALID, "order = %d: must be in [0, window - 1 = %d]", o->order,
                    o->window - 1);
    if (!(isfinite(o->threshold) && o->threshold > 0))
        return fail(t, WETDEM_ERR_INVALID, "threshold = %g: must be > 0 [m/s]", o->threshold);
    if (o->offset < 1 || o->offset > 100000)
        return fail(t, WETDEM_ERR_INVALID, "offset = %d: must be in [1, 100000] frames", o->offset);
    if (o->fit_frames != 0 && (o->fit_frames < TRACK_MIN_FIT || o->fit_frames > 1000000))
        return fail(t, WETDEM_ERR_INVALID, "fit_frames = %d: must be 0 (all) or in [%d, 1000000]",
                    o->fit_frames, TRACK_MIN_FIT);
    if (o->striker < -1 || o->striker > 1000000) /* (another negative id was taken as -1) */
        return fail(t, WETDEM_ERR_INVALID,
                    "striker = %d: must be a sphere id in [0, 1000000], or -1 (the faster sphere "
                    "at the start)",
                    o->striker);
    /* St_n's inputs, within the ranges of the scenario keys of a sphere (docs/scenarios.md) */
    const double phys[3] = {o->radius, o->mass, o->viscosity}, top[3] = {1, 1e6, 1e9};
    const char *names[3] = {"radius", "mass", "viscosity"}, *units[3] = {"m", "kg", "Pa s"};
    int given = 0;
    for (int k = 0; k < 3; k++) {
        if (!(isfinite(phys[k]) && phys[k] >= 0 && phys[k] <= top[k]))
            return fail(t, WETDEM_ERR_INVALID, "%s = %g: must be in (0, %g] %s, or 0: not given",
                        names[k], phys[k], top[k], units[k]);
        given += phys[k] > 0;
    }
    if (given == 1 || given == 2) /* St_n would be NaN without a word */
        return fail(t, WETDEM_ERR_INVALID,
                    "radius, mass and viscosity = %g m, %g kg, %g Pa s: the Stokes number needs "
                    "all three (or none)",
                    o->radius, o->mass, o->viscosity);
    return WETDEM_OK;
}

/* ---- uncertainties (docs/tracking.md "Uncertainties") ------------------------------------ */

/* Adds the gradient of weight * v[c], v = (vx, vy, omega) of Eq. 23 for one interval, with
 * respect to the dots of its first frame (to g0[6]) and of its last frame (to g1[6]); gain
 * from wetdem_track_interval_gain, x2 = omega dt of the solution. To first order
 * v dt = A+ (db - dA x): the matrix A holds the first frame's Dk = pk - p1, and dA x =
 * x2 J dDk in the rows of dot k (J(a, b) = (-b, a)). */
static void add_interval_gradient(const double gain[18], double x2, int c, double weight,
                                  double g0[6], double g1[6])
{
    const double* u = gain + 6 * c;
    const double rot[6] = {-(u[3] + u[5]), u[2] + u[4], u[3], -u[2], u[5], -u[4]};
    for (int j = 0; j < 6; j++) {
        g1[j] += weight * u[j];
        g0[j] -= weight * (u[j] + x2 * rot[j]);
    }
}

/* Adds the gradient gs[6] of a value with respect to the smoothed dots of frame j to its
 * gradient g with respect to the raw dots of frames lo, lo + 1, ...: the transpose of the
 * smoothing (wetdem_track_savgol_apply). */
static void unsmooth_gradient(const double* hat, size_t w, size_t n, size_t j, const double gs[6],
                              size_t lo, double* g)
{
    size_t start = window_start(j, w, n);
    const double* row = hat + (j - start) * w;
    for (size_t m = 0; m < w; m++)
        for (size_t c = 0; c < 6; c++)
            g[6 * (start + m - lo) + c] += row[m] * gs[c];
}

static double sum_squares(const double* g, size_t n)
{
    double sum = 0;
    for (size_t i = 0; i < n; i++)
        sum += g[i] * g[i];
    return sum;
}

/* The gain of Eq. 23 for the dots p0 (wetdem_track_interval_gain), NAN where it is not
 * defined (dots whose offsets overflow), so that the uncertainties are NAN there. */
static void interval_gain(const double p0[6], double dt, double gain[18])
{
    if (wetdem_track_interval_gain(p0, dt, gain) != WETDEM_OK)
        for (int j = 0; j < 18; j++)
            gain[j] = NAN;
}

/* Standard uncertainties of the velocities of interval i from the raw dots (u_raw[3]) and from
 * the smoothed dots (u[3]); g: room for 6 (window + 1) doubles. */
static void interval_uncertainties(const struct sphere_track* s, const double* hat, size_t w,
                                   double dt, size_t i, double* g, double u_raw[3], double u[3])
{
    double gain[18], gain_s[18];
    const struct wetdem_track_sample* q = &s->samples[i];
    interval_gain(s->raw + 6 * i, dt, gain);
    interval_gain(s->smooth + 6 * i, dt, gain_s);
    size_t lo = window_start(i, w, s->n), hi = window_start(i + 1, w, s->n) + w;
    for (int c = 0; c < 3; c++) {
        double g0[6] = {0}, g1[6] = {0};
        add_interval_gradient(gain, q->omega_raw * dt, c, 1.0, g0, g1);
        u_raw[c] = s->noise * sqrt(sum_squares(g0, 6) + sum_squares(g1, 6));
        memset(g0, 0, sizeof g0);
        memset(g1, 0, sizeof g1);
        add_interval_gradient(gain_s, q->omega * dt, c, 1.0, g0, g1);
        memset(g, 0, 6 * (hi - lo) * sizeof *g);
        unsmooth_gradient(hat, w, s->n, i, g0, lo, g);
        unsmooth_gradient(hat, w, s->n, i + 1, g1, lo, g);
        u[c] = s->noise * sqrt(sum_squares(g, 6 * (hi - lo)));
    }
}

static int sample_uncertainties(struct wetdem_track* t, struct sphere_track* s,
                                const struct wetdem_track_options* o, const double* hat)
{
    size_t w = (size_t)o->window;
    double* g = malloc(6 * (w + 1) * sizeof *g);
    if (!g)
        return fail(t, WETDEM_ERR_NOMEM, "out of memory analysing sphere %d", s->id);
    for (size_t i = 0; i + 1 < s->n; i++) {
        struct wetdem_track_sample* q = &s->samples[i];
        double u_raw[3], u[3];
        interval_uncertainties(s, hat, w, 1.0 / o->fps, i, g, u_raw, u);
        q->u_vx_raw = u_raw[0], q->u_vy_raw = u_raw[1], q->u_omega_raw = u_raw[2];
        q->u_vx = u[0], q->u_vy = u[1], q->u_omega = u[2];
    }
    free(g);
    return WETDEM_OK;
}

/* Positions in m (raw and smoothed) and the per-interval velocities of one sphere. */
static int sphere_velocities(struct wetdem_track* t, struct sphere_track* s,
                             const struct wetdem_track_options* o, const double* hat)
{
    size_t n = s->n;
    free_results(s);
    s->raw = malloc(6 * n * sizeof *s->raw);
    s->smooth = malloc(6 * n * sizeof *s->smooth);
    s->samples = malloc((n - 1) * sizeof *s->samples);
    double* col = malloc(2 * n * sizeof *col);
    if (!s->raw || !s->smooth || !s->samples || !col) {
        free(col);
        free_results(s);
        return fail(t, WETDEM_ERR_NOMEM, "out of memory analysing sphere %d", s->id);
    }
    for (size_t i = 0; i < 6 * n; i++)
        s->raw[i] = s->xy[i] * o->pixel_size * ((o->y_down && i % 2 == 1) ? -1.0 : 1.0);
    for (int c = 0; c < 6; c++) {
        for (size_t i = 0; i < n; i++)
            col[i] = s->raw[6 * i + (size_t)c];
        wetdem_track_savgol_apply(hat, o->window, col, n, col + n);
        for (size_t i = 0; i < n; i++)
            s->smooth[6 * i + (size_t)c] = col[n + i];
    }
    free(col);
    double dt = 1.0 / o->fps, v[3], ss_sum = 0, ss;
    for (size_t i = 0; i + 1 < n; i++) {
        struct wetdem_track_sample* q = &s->samples[i];
        q->frame = s->first_frame + (long)i;
        q->time = ((double)q->frame + 0.5) * dt;
        int st = wetdem_track_solve_interval(s->raw + 6 * i, s->raw + 6 * (i + 1), dt, v, NULL);
        q->vx_raw = v[0], q->vy_raw = v[1], q->omega_raw = v[2];
        if (wetdem_track_rigid_residual(s->raw + 6 * i, s->raw + 6 * (i + 1), &ss) != WETDEM_OK)
            ss = NAN; /* (offsets that overflow: the uncertainties are NAN) */
        if (st == WETDEM_OK)
            st = wetdem_track_solve_interval(s->smooth + 6 * i, s->smooth + 6 * (i + 1), dt, v,
                                             &q->residual);
        q->vx = v[0], q->vy = v[1], q->omega = v[2];
        if (st != WETDEM_OK)
            return fail(t, WETDEM_ERR_INVALID,
                        "sphere %d frame %ld: dots 2 and 3 coincide with dot 1 (or are not "
                        "finite); spin cannot be resolved",
                        s->id, q->frame);
        ss_sum += ss;
    }
    /* E[ss] = 6 sigma^2 per interval (docs/tracking.md "Uncertainties") */
    s->noise = sqrt(ss_sum / (6.0 * (double)(n - 1)));
    return sample_uncertainties(t, s, o, hat);
}

static double sample_component(const struct wetdem_track_sample* q, int c)
{
    return c == 0 ? q->vx : (c == 1 ? q->vy : q->omega);
}

/* Index of the striker among the two spheres. */
static int pick_striker(struct wetdem_track* t, const struct wetdem_track_options* o, size_t n_ref,
                        size_t* striker)
{
    if (o->striker >= 0) {
        for (size_t k = 0; k < t->n_spheres; k++)
            if (t->s[k].id == o->striker) {
                *striker = k;
                return WETDEM_OK;
            }
        return fail(t, WETDEM_ERR_INVALID, "striker = %d: no sphere with that id (found %d, %d)",
                    o->striker, t->s[0].id, t->s[1].id);
    }
    double speed[2];
    for (size_t k = 0; k < 2; k++) {
        double vx = 0, vy = 0;
        for (size_t i = 0; i < n_ref; i++)
            vx += t->s[k].samples[i].vx, vy += t->s[k].samples[i].vy;
        speed[k] = hypot(vx, vy) / (double)n_ref;
    }
    *striker = speed[1] > speed[0] ? 1 : 0;
    return WETDEM_OK;
}

/* First interval from which the striker's velocity differs from its initial mean by more
 * than the threshold for `persist` consecutive intervals; n_int on failure. */
static size_t find_collision(const struct sphere_track* s, size_t n_ref, size_t persist,
                             double threshold)
{
    size_t n_int = s->n - 1;
    double vx0 = 0, vy0 = 0;
    for (size_t i = 0; i < n_ref; i++)
        vx0 += s->samples[i].vx, vy0 += s->samples[i].vy;
    vx0 /= (double)n_ref, vy0 /= (double)n_ref;
    size_t run = 0;
    for (size_t i = 0; i < n_int; i++) {
        double dv = hypot(s->samples[i].vx - vx0, s->samples[i].vy - vy0);
        run = dv > threshold ? run + 1 : 0;
        if (run == persist)
            return i + 1 - persist;
    }
    return n_int;
}

/* Least-squares straight line through component c of samples [first, first + count)
 * against time, evaluated at t_eval (centred sums; count >= 2 distinct times). */
static double line_value(const struct wetdem_track_sample* q, size_t first, size_t count, int c,
                         double t_eval)
{
    double tm = 0, ym = 0;
    for (size_t i = first; i < first + count; i++)
        tm += q[i].time, ym += sample_component(&q[i], c);
    tm /= (double)count, ym /= (double)count;
    double sxx = 0, sxy = 0;
    for (size_t i = first; i < first + count; i++) {
        double dt = q[i].time - tm;
        sxx += dt * dt;
        sxy += dt * (sample_component(&q[i], c) - ym);
    }
    return ym + (sxy / sxx) * (t_eval - tm);
}

/* The fitted state of a sphere at frame index `at` (0-based) from intervals [first, +count). */
static struct wetdem_track_state fitted_state(const struct sphere_track* s, size_t first,
                                              size_t count, size_t at, double dt)
{
    double t_eval = (double)(s->first_frame + (long)at) * dt;
    struct wetdem_track_state st = {
        .vx = line_value(s->samples, first, count, 0, t_eval),
        .vy = line_value(s->samples, first, count, 1, t_eval),
        .omega = line_value(s->samples, first, count, 2, t_eval),
        .x = s->smooth[6 * at],
        .y = s->smooth[6 * at + 1],
    };
    return st;
}

/* Fitting windows of the collision at interval k (see the header comment, step 4). */
struct fit_windows {
    size_t before_first, before_count, after_first, after_count;
};

static int fit_windows(struct wetdem_track* t, const struct wetdem_track_options* o, size_t n_int,
                       size_t k, struct fit_windows* w)
{
    size_t h = (size_t)o->window / 2, fit = (size_t)o->fit_frames;
    size_t b_end = k > h ? k - h : 0, a_first = k + 2 * h + 1;
    w->before_first = (fit && b_end > fit) ? b_end - fit : 0;
    w->before_count = b_end - w->before_first;
    w->after_first = a_first;
    w->after_count = a_first < n_int ? n_int - a_first : 0;
    if (fit && w->after_count > fit)
        w->after_count = fit;
    long frame = t->s[0].first_frame + (long)k;
    if (w->before_count < TRACK_MIN_FIT)
        return fail(t, WETDEM_ERR_INVALID,
                    "collision at frame %ld leaves %zu frame intervals for the fit before it; "
                    "at least %d are needed (the track must start %zu frames earlier or more)",
                    frame, w->before_count, TRACK_MIN_FIT, (size_t)TRACK_MIN_FIT + h);
    if (w->after_count < TRACK_MIN_FIT)
        return fail(t, WETDEM_ERR_INVALID,
                    "collision at frame %ld leaves %zu frame intervals for the fit after it; "
                    "at least %d are needed (the track must go on %zu frames later or more)",
                    frame, w->after_count, TRACK_MIN_FIT, (size_t)TRACK_MIN_FIT + 2 * h + 1);
    if (k < (size_t)o->offset || k + (size_t)o->offset > n_int)
        return fail(t, WETDEM_ERR_INVALID,
                    "collision at frame %ld: frames %ld and %ld (offset %d) must both be tracked",
                    frame, frame - o->offset, frame + o->offset, o->offset);
    return WETDEM_OK;
}

/* Unit vector from the target's centre to the striker's at frame index `at`. */
static void centre_normal(const struct sphere_track* striker, const struct sphere_track* target,
                          size_t at, double n[2])
{
    double dx = striker->smooth[6 * at] - target->smooth[6 * at];
    double dy = striker->smooth[6 * at + 1] - target->smooth[6 * at + 1];
    double len = hypot(dx, dy);
    n[0] = dx / len;
    n[1] = dy / len;
}

/* Angles, normal speeds, e_n (Eq. 3) and St_n (Eq. 2) from the fitted states. */
static int restitution(struct wetdem_track* t, const struct wetdem_track_options* o,
                       const struct sphere_track* s, const struct sphere_track* g, size_t k,
                       struct wetdem_track_summary* sum)
{
    double n0[2], nf[2];
    centre_normal(s, g, k, n0);
    centre_normal(s, g, k + (size_t)o->offset, nf);
    if (!isfinite(n0[0] + n0[1] + nf[0] + nf[1]))
        return fail(t, WETDEM_ERR_INVALID, "the two spheres' centre dots coincide");
    double v0x = sum->striker_before.vx - sum->target_before.vx;
    double v0y = sum->striker_before.vy - sum->target_before.vy;
    double vfx = sum->striker_after.vx - sum->target_after.vx;
    double vfy = sum->striker_after.vy - sum->target_after.vy;
    sum->speed_n0 = -(v0x * n0[0] + v0y * n0[1]);
    sum->speed_nf = vfx * nf[0] + vfy * nf[1];
    if (!(sum->speed_n0 > 0))
        return fail(t, WETDEM_ERR_INVALID,
                    "the spheres are not approaching before the collision at frame %ld "
                    "(normal relative speed %g m/s)",
                    sum->collision_frame, -sum->speed_n0);
    /* a velocity change that is no collision (a tracker glitch, noise, a slow drift read as
       a change) leaves the spheres approaching "after" it, faster than the threshold that
       marks a change; a pair that sticks (e_n = 0) leaves at about 0, noise either way, and
       is reported as measured */
    if (-sum->speed_nf > o->threshold)
        return fail(t, WETDEM_ERR_INVALID,
                    "the spheres are still approaching after the velocity change found at frame "
                    "%ld (normal relative speed %g m/s after, %g before; more than the threshold "
                    "%g m/s): it is not a collision (a tracker glitch or noise?); raise "
                    "--threshold, or cut the recording to the collision",
                    sum->collision_frame, -sum->speed_nf, sum->speed_n0, o->threshold);
    sum->e_n = sum->speed_nf / sum->speed_n0;
    double cosine = sum->speed_n0 / hypot(v0x, v0y);
    sum->impact_angle = acos(cosine > 1 ? 1 : cosine);
    double dx = g->smooth[6 * k] - s->smooth[6 * k],
           dy = g->smooth[6 * k + 1] - s->smooth[6 * k + 1];
    sum->angle_centres = dx != 0 ? atan(dy / dx) : M_PI / 2;
    sum->stokes_n = NAN;
    if (o->radius > 0 && o->mass > 0 && o->viscosity > 0) {
        double m_eff = 0.5 * o->mass, r_eff = 0.5 * o->radius;
        sum->stokes_n = m_eff * sum->speed_n0 / (6 * M_PI * o->viscosity * r_eff * r_eff);
    }
    return WETDEM_OK;
}

/* ---- uncertainties of the summary (docs/tracking.md "Uncertainties") -------------------- */

/* The values of a sphere that the summary is made of, each a linear function of its raw dots
 * to first order: the before line's vx, vy, omega at k - offset, the after line's at
 * k + offset, and the smoothed dot 1 (x, y) at k - offset, k and k + offset. */
enum { L_BEFORE = 0, L_AFTER = 3, L_POS_BEFORE = 6, L_POS_K = 8, L_POS_AFTER = 10, N_LIN = 12 };

/* Gradient of one such value with respect to the raw dots of frames [lo, hi), 6 per frame. */
struct lin_fn {
    size_t lo, hi;
    double* g;
};

static int lin_alloc(struct lin_fn* f, size_t lo, size_t hi)
{
    f->lo = lo;
    f->hi = hi;
    f->g = calloc(6 * (hi - lo), sizeof *f->g);
    return f->g ? WETDEM_OK : WETDEM_ERR_NOMEM;
}

/* The gradients of a straight-line fit over intervals [first, first + count) evaluated at
 * t_eval, for vx, vy and omega (f[0..3)): the fit is sum_i w_i v_i with
 * w_i = 1/count + (t_i - t_mean)(t_eval - t_mean)/S_tt (line_value), each v_i is Eq. 23 on
 * the smoothed dots of frames i and i + 1 (add_interval_gradient), and those are the
 * smoothing of the raw dots (unsmooth_gradient). */
static int line_gradients(const struct sphere_track* s, const double* hat, size_t w, double dt,
                          size_t first, size_t count, double t_eval, struct lin_fn f[3])
{
    const struct wetdem_track_sample* q = s->samples;
    double tm = 0, stt = 0, gain[18];
    for (size_t i = first; i < first + count; i++)
        tm += q[i].time;
    tm /= (double)count;
    for (size_t i = first; i < first + count; i++)
        stt += (q[i].time - tm) * (q[i].time - tm);
    size_t m = count + 1; /* smoothed frames first .. first + count */
    double* gs = calloc(3 * 6 * m, sizeof *gs);
    if (!gs)
        return WETDEM_ERR_NOMEM;
    for (size_t i = first; i < first + count; i++) {
        double wi = 1.0 / (double)count + (q[i].time - tm) * (t_eval - tm) / stt;
        interval_gain(s->smooth + 6 * i, dt, gain);
        for (int c = 0; c < 3; c++)
            add_interval_gradient(gain, q[i].omega * dt, c, wi, gs + 6 * (c * m + i - first),
                                  gs + 6 * (c * m + i + 1 - first));
    }
    int st = WETDEM_OK;
    size_t lo = window_start(first, w, s->n), hi = window_start(first + count, w, s->n) + w;
    for (int c = 0; c < 3 && st == WETDEM_OK; c++) {
        st = lin_alloc(&f[c], lo, hi);
        for (size_t j = 0; j < m && st == WETDEM_OK; j++)
            unsmooth_gradient(hat, w, s->n, first + j, gs + 6 * (c * m + j), lo, f[c].g);
    }
    free(gs);
    return st;
}

/* The gradients of the smoothed dot 1 (x, y) of frame j (f[0..2)). */
static int position_gradients(const struct sphere_track* s, const double* hat, size_t w, size_t j,
                              struct lin_fn f[2])
{
    size_t lo = window_start(j, w, s->n);
    for (int c = 0; c < 2; c++) {
        if (lin_alloc(&f[c], lo, lo + w) != WETDEM_OK)
            return WETDEM_ERR_NOMEM;
        double gs[6] = {0};
        gs[c] = 1.0;
        unsmooth_gradient(hat, w, s->n, j, gs, lo, f[c].g);
    }
    return WETDEM_OK;
}

static double lin_dot(const struct lin_fn* a, const struct lin_fn* b)
{
    size_t lo = a->lo > b->lo ? a->lo : b->lo, hi = a->hi < b->hi ? a->hi : b->hi;
    double sum = 0;
    for (size_t i = 6 * lo; i < 6 * hi; i++)
        sum += a->g[i - 6 * a->lo] * b->g[i - 6 * b->lo];
    return sum;
}

/* Covariance matrix of the N_LIN values of one sphere: noise^2 times the dot products of their
 * gradients (the noise of different coordinates and frames independent, of equal variance). */
static int sphere_covariance(const struct sphere_track* s, const struct wetdem_track_options* o,
                             const double* hat, const struct fit_windows* fw, size_t k, double* cov)
{
    struct lin_fn f[N_LIN] = {{0}};
    size_t w = (size_t)o->window, off = (size_t)o->offset;
    double dt = 1.0 / o->fps;
    double t_before = (double)(s->first_frame + (long)(k - off)) * dt;
    double t_after = (double)(s->first_frame + (long)(k + off)) * dt;
    int st =
        line_gradients(s, hat, w, dt, fw->before_first, fw->before_count, t_before, f + L_BEFORE);
    if (st == WETDEM_OK)
        st = line_gradients(s, hat, w, dt, fw->after_first, fw->after_count, t_after, f + L_AFTER);
    if (st == WETDEM_OK)
        st = position_gradients(s, hat, w, k - off, f + L_POS_BEFORE);
    if (st == WETDEM_OK)
        st = position_gradients(s, hat, w, k, f + L_POS_K);
    if (st == WETDEM_OK)
        st = position_gradients(s, hat, w, k + off, f + L_POS_AFTER);
    for (int a = 0; a < N_LIN && st == WETDEM_OK; a++)
        for (int b = 0; b <= a; b++)
            cov[N_LIN * a + b] = cov[N_LIN * b + a] = s->noise * s->noise * lin_dot(&f[a], &f[b]);
    for (int a = 0; a < N_LIN; a++)
        free(f[a].g);
    return st;
}

/* Standard uncertainty of a function of the striker-minus-target differences of the N_LIN
 * values with gradient a: sqrt(a^T cov a), cov the sum of both spheres' covariances (the
 * spheres' dots are independent). */
static double propagate(const double* cov, const double a[N_LIN])
{
    double sum = 0;
    for (int i = 0; i < N_LIN; i++)
        for (int j = 0; j < N_LIN; j++)
            sum += a[i] * cov[N_LIN * i + j] * a[j];
    return sqrt(fmax(sum, 0.0));
}

static struct wetdem_track_state state_uncertainty(const double* cov, int line, int pos)
{
    struct wetdem_track_state u = {
        .vx = sqrt(cov[N_LIN * line + line]),
        .vy = sqrt(cov[N_LIN * (line + 1) + line + 1]),
        .omega = sqrt(cov[N_LIN * (line + 2) + line + 2]),
        .x = sqrt(cov[N_LIN * pos + pos]),
        .y = sqrt(cov[N_LIN * (pos + 1) + pos + 1]),
    };
    return u;
}

/* First-order propagation to the derived values (docs/tracking.md "Uncertainties"), with
 * v0, vf the relative velocities before and after, D0, Df the centres' differences at k and
 * k + offset, n = D/|D|, p = v - (v.n) n:
 *   speed_n0 = -v0.n0:        d = -n0 . dv0 - p0 . dD0/|D0|
 *   speed_nf = vf.nf:         d = nf . dvf + pf . dDf/|Df|
 *   e_n = speed_nf/speed_n0:  d = (d speed_nf - e_n d speed_n0)/speed_n0
 *   St_n = c speed_n0:        d = St_n d speed_n0/speed_n0
 *   angle_centres, the direction of D0:       d = (D0 x dD0)/|D0|^2
 *   impact_angle = |direction(D0) - direction(-v0)|: d = (D0 x dD0)/|D0|^2 - (v0 x dv0)/|v0|^2
 * with a x b = ax by - ay bx. */
static void summary_uncertainties(const double* cov, const double v0[2], const double vf[2],
                                  const double d0[2], const double df[2],
                                  struct wetdem_track_summary* sum)
{
    double l0 = hypot(d0[0], d0[1]), lf = hypot(df[0], df[1]), s0 = v0[0] * v0[0] + v0[1] * v0[1];
    double n0[2] = {d0[0] / l0, d0[1] / l0}, nf[2] = {df[0] / lf, df[1] / lf};
    double vn0 = v0[0] * n0[0] + v0[1] * n0[1], vnf = vf[0] * nf[0] + vf[1] * nf[1];
    double a_n0[N_LIN] = {0}, a_nf[N_LIN] = {0}, a_en[N_LIN], a_centres[N_LIN] = {0};
    double a_impact[N_LIN] = {0};
    for (int c = 0; c < 2; c++) {
        a_n0[L_BEFORE + c] = -n0[c];
        a_n0[L_POS_K + c] = -(v0[c] - vn0 * n0[c]) / l0;
        a_nf[L_AFTER + c] = nf[c];
        a_nf[L_POS_AFTER + c] = (vf[c] - vnf * nf[c]) / lf;
    }
    a_centres[L_POS_K] = -d0[1] / (l0 * l0);
    a_centres[L_POS_K + 1] = d0[0] / (l0 * l0);
    memcpy(a_impact, a_centres, sizeof a_impact);
    a_impact[L_BEFORE] = v0[1] / s0;
    a_impact[L_BEFORE + 1] = -v0[0] / s0;
    for (int i = 0; i < N_LIN; i++)
        a_en[i] = (a_nf[i] - sum->e_n * a_n0[i]) / sum->speed_n0;
    sum->u_speed_n0 = propagate(cov, a_n0);
    sum->u_speed_nf = propagate(cov, a_nf);
    sum->u_e_n = propagate(cov, a_en);
    sum->u_stokes_n = sum->stokes_n * sum->u_speed_n0 / sum->speed_n0; /* (NAN with it) */
    sum->u_angle_centres = propagate(cov, a_centres);
    sum->u_impact_angle = propagate(cov, a_impact);
}

/* The uncertainties of the summary of striker s and target g with the collision at k. */
static int collision_uncertainties(struct wetdem_track* t, const struct wetdem_track_options* o,
                                   const double* hat, const struct sphere_track* s,
                                   const struct sphere_track* g, const struct fit_windows* fw,
                                   size_t k, struct wetdem_track_summary* sum)
{
    double cs[N_LIN * N_LIN], cg[N_LIN * N_LIN], cov[N_LIN * N_LIN];
    int st = sphere_covariance(s, o, hat, fw, k, cs);
    if (st == WETDEM_OK)
        st = sphere_covariance(g, o, hat, fw, k, cg);
    if (st != WETDEM_OK)
        return fail(t, st, "out of memory for the uncertainties");
    sum->u_striker_before = state_uncertainty(cs, L_BEFORE, L_POS_BEFORE);
    sum->u_striker_after = state_uncertainty(cs, L_AFTER, L_POS_AFTER);
    sum->u_target_before = state_uncertainty(cg, L_BEFORE, L_POS_BEFORE);
    sum->u_target_after = state_uncertainty(cg, L_AFTER, L_POS_AFTER);
    for (int a = 0; a < N_LIN * N_LIN; a++)
        cov[a] = cs[a] + cg[a];
    size_t kf = k + (size_t)o->offset;
    double v0[2] = {sum->striker_before.vx - sum->target_before.vx,
                    sum->striker_before.vy - sum->target_before.vy};
    double vf[2] = {sum->striker_after.vx - sum->target_after.vx,
                    sum->striker_after.vy - sum->target_after.vy};
    double d0[2] = {s->smooth[6 * k] - g->smooth[6 * k],
                    s->smooth[6 * k + 1] - g->smooth[6 * k + 1]};
    double df[2] = {s->smooth[6 * kf] - g->smooth[6 * kf],
                    s->smooth[6 * kf + 1] - g->smooth[6 * kf + 1]};
    summary_uncertainties(cov, v0, vf, d0, df, sum);
    return WETDEM_OK;
}

/* Largest velocity change of the striker from its initial mean, for error messages. */
static double largest_change(const struct sphere_track* s, size_t n_ref)
{
    double vx0 = 0, vy0 = 0, best = 0;
    for (size_t i = 0; i < n_ref; i++)
        vx0 += s->samples[i].vx / (double)n_ref, vy0 += s->samples[i].vy / (double)n_ref;
    for (size_t i = 0; i + 1 < s->n; i++)
        best = fmax(best, hypot(s->samples[i].vx - vx0, s->samples[i].vy - vy0));
    return best;
}

static int collision_summary(struct wetdem_track* t, const struct wetdem_track_options* o,
                             const double* hat, struct wetdem_track_summary* sum)
{
    size_t n_int = t->s[0].n - 1, h = (size_t)o->window / 2;
    size_t n_ref = o->window > TRACK_MIN_FIT ? (size_t)o->window : TRACK_MIN_FIT, si = 0;
    /* the reference velocity is the mean of the first n_ref intervals, and a collision after
       them is a change that lasts h + 1 more */
    if (n_int < n_ref + h + 1)
        return fail(t, WETDEM_ERR_INVALID,
                    "sphere %d has %zu frames; finding a collision needs at least %zu (the first "
                    "%zu frame intervals set the reference velocity and a change must last %zu "
                    "more; window = %d)",
                    t->s[0].id, t->s[0].n, n_ref + h + 2, n_ref, h + 1, o->window);
    int st = pick_striker(t, o, n_ref, &si);
    if (st != WETDEM_OK)
        return st;
    const struct sphere_track *s = &t->s[si], *g = &t->s[1 - si];
    size_t k = find_collision(s, n_ref, h + 1, o->threshold);
    if (k == n_int)
        return fail(t, WETDEM_ERR_INVALID,
                    "no collision found: the velocity of the striker (sphere %d) never differs "
                    "from its initial value by more than threshold = %g m/s for %zu frames in a "
                    "row (largest change %.3g m/s)",
                    s->id, o->threshold, h + 1, largest_change(s, n_ref));
    if (k < n_ref)
        return fail(t, WETDEM_ERR_INVALID,
                    "collision at frame %ld is within the first %zu frames, which set the "
                    "reference velocity; the track must start earlier",
                    s->first_frame + (long)k, n_ref);
    struct fit_windows w;
    if ((st = fit_windows(t, o, n_int, k, &w)) != WETDEM_OK)
        return st;
    double dt = 1.0 / o->fps;
    size_t off = (size_t)o->offset;
    sum->has_collision = true;
    sum->striker_id = s->id;
    sum->target_id = g->id;
    sum->collision_frame = s->first_frame + (long)k;
    sum->collision_time = (double)sum->collision_frame * dt;
    sum->striker_before = fitted_state(s, w.before_first, w.before_count, k - off, dt);
    sum->striker_after = fitted_state(s, w.after_first, w.after_count, k + off, dt);
    sum->target_before = fitted_state(g, w.before_first, w.before_count, k - off, dt);
    sum->target_after = fitted_state(g, w.after_first, w.after_count, k + off, dt);
    if ((st = restitution(t, o, s, g, k, sum)) != WETDEM_OK)
        return st;
    return collision_uncertainties(t, o, hat, s, g, &w, k, sum);
}

int wetdem_track_analyse(struct wetdem_track* track, const struct wetdem_track_options* opt,
                         struct wetdem_track_summary* summary)
{
    if (!opt || !summary)
        return fail(track, WETDEM_ERR_INVALID, "analyse: NULL %s", opt ? "summary" : "options");
    memset(summary, 0, sizeof *summary);
    summary->e_n = summary->stokes_n = summary->u_e_n = summary->u_stokes_n = NAN;
    summary->noise_px[0] = summary->noise_px[1] = NAN;
    int st = check_options(track, opt);
    if (st != WETDEM_OK)
        return st;
    if (track->n_spheres == 0)
        return fail(track, WETDEM_ERR_INVALID, "the track has no frames");
    const struct sphere_track* a = &track->s[0];
    if (track->n_spheres == 2 &&
        (track->s[1].first_frame != a->first_frame || track->s[1].n != a->n))
        return fail(track, WETDEM_ERR_INVALID,
                    "sphere %d covers frames %ld to %ld but sphere %d covers %ld to %ld; both "
                    "spheres must be tracked over the same frames",
                    a->id, a->first_frame, a->first_frame + (long)a->n - 1, track->s[1].id,
                    track->s[1].first_frame, track->s[1].first_frame + (long)track->s[1].n - 1);
    if (track->n_spheres == 1 && opt->striker >= 0 &&
        a->id != opt->striker) /* (two: pick_striker) */
        return fail(track, WETDEM_ERR_INVALID,
                    "striker = %d: no sphere with that id (found %d only: one sphere, no "
                    "collision)",
                    opt->striker, a->id);
    size_t need = (size_t)(opt->window > 2 ? opt->window : 2);
    if (a->n < need)
        return fail(track, WETDEM_ERR_INVALID,
                    "sphere %d has %zu frames; at least %zu are needed (window = %d)", a->id, a->n,
                    need, opt->window);
    double* hat = malloc((size_t)opt->window * (size_t)opt->window * sizeof *hat);
    if (!hat)
        return fail(track, WETDEM_ERR_NOMEM, "out of memory");
    st = wetdem_track_savgol_hat(opt->window, opt->order, hat);
    if (st != WETDEM_OK) /* (the window and order were checked) */
        st = fail(track, st, "out of memory for the Savitzky-Golay weights");
    for (size_t k = 0; st == WETDEM_OK && k < track->n_spheres; k++) {
        st = sphere_velocities(track, &track->s[k], opt, hat);
        if (st == WETDEM_OK)
            summary->noise_px[k] = track->s[k].noise / opt->pixel_size;
    }
    if (st == WETDEM_OK) {
        summary->n_spheres = track->n_spheres;
        if (track->n_spheres == 2)
            st = collision_summary(track, opt, hat, summary);
    }
    free(hat);
    return st;
}

/*
 * fit.c — calibration of model parameters against measurements by nonlinear least squares:
 * minimise S(q) = sum_i r_i^2, r_i = (y_i(p) - y_i,obs)/s_i, over fitted variables q that keep
 * every parameter inside its range [a, b]:
 *     no bound        p = q
 *     a only          p = a + e^q              (q = ln(p - a): ln p for a = 0)
 *     b only          p = b - e^q
 *     a and b         p = a + (b - a)/(1 + e^-q) (the logistic; ~ a + (b - a) e^q near a)
 * so the solver's steps and the finite-difference probes never leave the range, and a
 * relative step is natural for quantities such as the glass-transition pressure P_gt of
 * Punch 2023 Eq. 14, a roughness or a minimum separation. A parameter can only approach a
 * bound: one that ends closer to it than its standard error and than 1e-3 of its initial
 * distance is reported at that bound (result.at_bound), not as an error.
 *
 * Solver: GSL gsl_multifit_nlinear, trust region with Levenberg-Marquardt steps, iterated
 * here (not by gsl_multifit_nlinear_driver, which carries on after a failed evaluation); a
 * step may change a bounded variable by at most ln 10 (a longer trial counts as not lowering
 * the cost, so the solver shortens it). The
 * Jacobian J_ij = dr_i/dq_j is taken by central differences with step h (fd_step):
 * predictions from a simulation carry integration noise of relative size ~1e-4, so the
 * default h = 1e-2 keeps the difference quotient's noise (~1e-4/h) below 1 % while its
 * truncation error is O(h^2). A column of J that is exactly zero means the predictions do not
 * change with that parameter: the fit stops with WETDEM_ERR_UNDETERMINED (GSL's QR would
 * otherwise fail on a Jacobian of rank 0). A flat start is WETDEM_ERR_UNDETERMINED too
 * (FLAT_FRACTION below): where a bounded parameter's effect is cut off, its difference
 * quotients are the predictions' noise and the solver stops at once, on a small step or
 * gradient, at or near the start, not fitted. It is told by evaluating the model a factor 1000
 * either way (in the distance to the bound, or in (p - a)/(b - p)), not by the size of the
 * column, which near a bound is small for a well-determined parameter too; an unbounded
 * parameter has no such scale, so only its exactly zero column is caught.
 *
 * Standard errors (Gauss-Newton linearisation at the solution): cov(q) = s^2 (J^T J)^-1 with
 * the residual variance s^2 = S/(n - p), i.e. the scatter of the data about the fit sets the
 * error scale (no measurement errors needed); sd(p) = |dp/dq| sd(q) (delta method). Valid when
 * the model is close to linear in q over +-2 sd and the residuals are independent with equal
 * variance (after division by s_i). (J^T J)^-1 comes from the singular values of J with unit
 * columns: a singular value below sqrt(DBL_EPSILON) of the largest marks columns that are
 * linearly dependent (parameters the data do not determine separately): those get an infinite
 * standard error, and the others' are computed with them held fixed.
 *
 * GSL reports errors through one process-wide handler whose default aborts; the library must
 * never abort its host, so the handler is switched off while any fit runs and the caller's is
 * restored when the last one ends (gsl_guard.c: fits may run at once in several threads, see
 * wetdem.h), and every GSL status is checked here.
 */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_blas.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_matrix.h>
#include <gsl/gsl_multifit_nlinear.h>
#include <gsl/gsl_vector.h>

#include "gsl_guard.h"
#include "status.h"
#include "wetdem.h"

#define NP_MAX WETDEM_FIT_MAX_PARAMS

/* Largest |q| of a bounded parameter: e^-700 ~ 1e-304 stays a normal double, so p never
 * rounds onto a bound of 0. */
#define Q_MAX 700.0

/* Largest change of a bounded parameter's variable in one step, ln 10: a factor 10 in its
 * distance to a bound. A Gauss-Newton step from where the predictions hardly change can be
 * enormous; the predictions that far away are not those the step was computed from. */
#define Q_STEP_MAX 2.302585092994046

/* A flat start: a bounded parameter whose predictions do not move with it where the fit
 * stopped, though its column of the Jacobian is not exactly zero (the difference quotients are
 * the model's noise, as at a start where its effect is cut off: the solver stops at once, on a
 * small step or gradient, at or near the start). It is WETDEM_ERR_UNDETERMINED when
 *  - it ended within Q_STEP_MAX (one step's reach, a factor 10) of its start in its variable:
 *    a parameter that travelled further followed the data, and is judged by its statistics;
 *  - the Jacobian says moving it by FLAT_PROBE in its variable changes the residuals by less
 *    than FLAT_FRACTION of their scatter s, ||J_j|| FLAT_PROBE < FLAT_FRACTION s (a screen:
 *    the probes below run only for such a column);
 *  - and the model, evaluated with the parameter at q_j - FLAT_PROBE and q_j + FLAT_PROBE (the
 *    others where they are), confirms it: each changes the residual vector by less than
 *    FLAT_FRACTION s (2-norm). A probe the model fails on counts as a change.
 * FLAT_PROBE = 3 ln 10 is a factor 1000 either way in the distance to a one-sided bound, and
 * in the odds (p - a)/(b - p) of a two-sided range (from its middle: 0.1 % to 99.9 % of it).
 * The probes, not the Jacobian, decide because near a bound the column of a log variable
 * vanishes with dp/dq = p - a: a well-determined parameter 0.002 from a bound with standard
 * error 0.05 has a column as small as a flat one, but a factor 1000 further from the bound
 * moves the residuals by far more than s. An unbounded (linear) parameter is never judged so:
 * no step is free of its units (a change of max(|p|, 1) misfires on data with a large scatter
 * in small units), so only its exactly zero column is caught. */
#define FLAT_FRACTION 0.1
#define FLAT_PROBE (3 * 2.302585092994046)

/* A bound is "hit" when the estimate is closer to it than this fraction of its standard
 * error (the data cannot tell it from the bound: within one standard error; near a bound the
 * error itself is the transform's, d x that of q, and says little more) and than
 * AT_BOUND_TRAVEL of its initial distance (the fit ran towards it: three decades of the
 * variable). Six decades and 1e-3 standard errors, as before, missed a restitution whose data
 * want e > 1: the solver stops on a small step 1e-7 to 1e-6 from the bound, and the value was
 * reported with a standard error that changed 17-fold with the start. */
#define AT_BOUND_SD 1.0
#define AT_BOUND_TRAVEL 1e-3

struct param_map {
    enum wetdem_fit_transform kind;
    double lo, hi;   /* bounds, -INFINITY/INFINITY when absent */
    double dist0[2]; /* initial distance to lo and to hi */
};

struct fit_ctx {
    const struct wetdem_fit_problem* pb;
    struct param_map map[NP_MAX];
    double fd_step;
    double* pred;    /* scratch predictions [n_data] */
    double* r_plus;  /* scratch residuals [n_data] */
    double* r_minus; /* scratch residuals [n_data] */
    gsl_matrix* jac; /* the last Jacobian computed, at q_jac */
    double q_jac[NP_MAX];
    size_t evals;
    int status;      /* first failure of the model (or an undetermined parameter) */
    int zero_column; /* 1 + index of a parameter whose column of J is zero, or 0 */
    char msg[512];
};

void wetdem_fit_options_init(struct wetdem_fit_options* opt)
{
    *opt = (struct wetdem_fit_options){
        .max_iter = 50, .xtol = 1e-6, .gtol = 1e-8, .ftol = 1e-10, .fd_step = 1e-2};
}

static const char* param_name(const struct wetdem_fit_problem* pb, size_t j)
{
    return (pb->names && pb->names[j]) ? pb->names[j] : "parameter";
}

/* ---- the fitted variables ---------------------------------------------------------------- */

static double to_param(const struct param_map* m, double q)
{
    if (m->kind == WETDEM_FIT_LINEAR)
        return q;
    q = fmax(-Q_MAX, fmin(Q_MAX, q));
    double p;
    if (m->kind == WETDEM_FIT_LOG_LOWER)
        p = m->lo + exp(q);
    else if (m->kind == WETDEM_FIT_LOG_UPPER)
        p = m->hi - exp(q);
    else if (q < 0) /* each form keeps the small distance to the nearer bound exact */
        p = m->lo + (m->hi - m->lo) * (exp(q) / (1 + exp(q)));
    else
        p = m->hi - (m->hi - m->lo) / (1 + exp(q));
    return fmax(m->lo, fmin(m->hi, p));
}

static double to_variable(const struct param_map* m, double p)
{
    switch (m->kind) {
    case WETDEM_FIT_LOG_LOWER: return log(p - m->lo);
    case WETDEM_FIT_LOG_UPPER: return log(m->hi - p);
    case WETDEM_FIT_LOGISTIC: return log(p - m->lo) - log(m->hi - p);
    default: return p;
    }
}

/* dp/dq at p (negative for an upper bound alone: p = hi - e^q). */
static double slope(const struct param_map* m, double p)
{
    switch (m->kind) {
    case WETDEM_FIT_LOG_LOWER: return p - m->lo;
    case WETDEM_FIT_LOG_UPPER: return -(m->hi - p);
    case WETDEM_FIT_LOGISTIC: return (p - m->lo) / (m->hi - m->lo) * (m->hi - p);
    default: return 1.0;
    }
}

/* The variable of parameter j from the bounds and the initial value. */
static int setup_map(const struct wetdem_fit_problem* pb, size_t j, struct param_map* m, char* msg,
                     size_t n)
{
    double p0 = pb->initial[j];
    m->lo = pb->lower ? pb->lower[j] : -INFINITY;
    m->hi = pb->upper ? pb->upper[j] : INFINITY;
    bool lg = pb->is_log ? pb->is_log[j] : (!pb->lower && !pb->upper && p0 > 0);
    if (lg && !(m->lo >= 0))
        m->lo = 0;
    if (isnan(m->lo) || isnan(m->hi) || !(m->lo < m->hi) || m->lo == INFINITY || m->hi == -INFINITY)
        return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID,
                                  "%s: bounds [%g, %g] do not make a range", param_name(pb, j),
                                  m->lo, m->hi);
    bool has_lo = isfinite(m->lo), has_hi = isfinite(m->hi);
    m->kind = has_lo && has_hi ? WETDEM_FIT_LOGISTIC
              : has_lo         ? WETDEM_FIT_LOG_LOWER
              : has_hi         ? WETDEM_FIT_LOG_UPPER
                               : WETDEM_FIT_LINEAR;
    if (!isfinite(p0)) {   /* (no bound to speak of: the start itself is no number) */
        char who[64] = ""; /* (room for two 20-digit counts) */
        if (!(pb->names && pb->names[j]))
            snprintf(who, sizeof who, " %zu (initial[%zu])", j + 1, j);
        return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID,
                                  "%s%s: initial value %g is not finite: the fit needs a finite "
                                  "start",
                                  param_name(pb, j), who, p0);
    }
    if ((has_lo && !(p0 > m->lo)) || (has_hi && !(p0 < m->hi))) {
        char range[96];
        snprintf(range, sizeof range, "%s%g, %g%s", has_lo ? "(" : "(-", has_lo ? m->lo : INFINITY,
                 m->hi, ")");
        return wetdem_status_fail(
            msg, n, WETDEM_ERR_INVALID,
            "%s: initial value %g must be inside %s%s: the fit varies %s, which "
            "cannot start on or beyond a bound",
            param_name(pb, j), p0, range, lg && m->lo == 0 ? ", i.e. > 0 (log fit)" : "",
            m->kind == WETDEM_FIT_LOGISTIC    ? "ln((p - lower)/(upper - p))"
            : m->kind == WETDEM_FIT_LOG_LOWER ? "ln(p - lower)"
                                              : "ln(upper - p)");
    }
    m->dist0[0] = p0 - m->lo;
    m->dist0[1] = m->hi - p0;
    return WETDEM_OK;
}

/* -1 or +1 when p (standard error sd) is at the lower or upper bound, else 0. */
static int at_bound(const struct param_map* m, double p, double sd)
{
    double d_lo = p - m->lo, d_hi = m->hi - p;
    if (isfinite(m->lo) && d_lo < AT_BOUND_SD * sd && d_lo < AT_BOUND_TRAVEL * m->dist0[0])
        return -1;
    if (isfinite(m->hi) && d_hi < AT_BOUND_SD * sd && d_hi < AT_BOUND_TRAVEL * m->dist0[1])
        return 1;
    return 0;
}

/* ---- residuals and Jacobian --------------------------------------------------------------- */

/* Scaled residuals r[0..n) at fitted variables q; a failure's message into msg. Counts the
 * evaluation. */
static int evaluate(struct fit_ctx* c, const double* q, double* r, char* msg, size_t n_msg)
{
    const struct wetdem_fit_problem* pb = c->pb;
    double p[NP_MAX];
    for (size_t j = 0; j < pb->n_params; j++)
        p[j] = to_param(&c->map[j], q[j]);
    c->evals++;
    int st = pb->model(p, c->pred, msg, n_msg, pb->ctx);
    if (st > 0) /* (a status of the success class would end the fit as if it had converged) */
        st = wetdem_status_fail(msg, n_msg, WETDEM_ERR_CALLBACK,
                                "the model returned %d, neither WETDEM_OK nor an error status", st);
    for (size_t i = 0; st == WETDEM_OK && i < pb->n_data; i++) {
        double s = pb->scale ? pb->scale[i] : 1.0;
        r[i] = (c->pred[i] - pb->observed[i]) / s;
        if (!isfinite(r[i]))
            st = wetdem_status_fail(msg, n_msg, WETDEM_ERR_NUMERIC,
                                    "the model gave a non-finite prediction %g for data point %zu",
                                    c->pred[i], i + 1);
    }
    return st;
}

/* evaluate(), keeping the first failure (c->status, c->msg): the fit stops on it. */
static int residuals_at(struct fit_ctx* c, const double* q, double* r)
{
    char msg[sizeof c->msg] = "";
    int st = evaluate(c, q, r, msg, sizeof msg);
    if (st != WETDEM_OK && c->status == WETDEM_OK) {
        c->status = st;
        snprintf(c->msg, sizeof c->msg, "%s", msg);
    }
    return st;
}

static int gsl_f(const gsl_vector* x, void* params, gsl_vector* f)
{
    struct fit_ctx* c = params;
    if (c->status != WETDEM_OK) /* (stopped: no further evaluation, no repeated message) */
        return GSL_EBADFUNC;
    for (size_t j = 0; j < c->pb->n_params; j++) /* (from the point of the last Jacobian) */
        if (c->map[j].kind != WETDEM_FIT_LINEAR && fabs(x->data[j] - c->q_jac[j]) > Q_STEP_MAX) {
            gsl_vector_set_all(f, 1e100); /* the solver rejects it and takes a shorter step */
            return GSL_SUCCESS;
        }
    return residuals_at(c, x->data, f->data) == WETDEM_OK ? GSL_SUCCESS : GSL_EBADFUNC;
}

/* Whether column j of jac is zero. */
static bool column_is_zero(const gsl_matrix* jac, size_t j)
{
    for (size_t i = 0; i < jac->size1; i++)
        if (gsl_matrix_get(jac, i, j) != 0)
            return false;
    return true;
}

/* A zero column j at q: the data do not depend on the parameter there. Returns a GSL
 * status. */
static int zero_column(struct fit_ctx* c, size_t j, double q, double h)
{
    const struct param_map* m = &c->map[j];
    double p = to_param(m, q), p0 = c->pb->initial[j];
    char from[160] = "";
    if (fabs(p - p0) > 1e-9 * fabs(p0))
        snprintf(from, sizeof from,
                 "; the fit came there from %g: start nearer the value you expect", p0);
    c->zero_column = (int)j + 1;
    c->status = wetdem_status_fail(
        c->msg, sizeof c->msg, WETDEM_ERR_UNDETERMINED,
        "the data do not depend on %s near %g (its column of the Jacobian is zero: %g and %g "
        "give the same predictions)%s",
        param_name(c->pb, j), p, to_param(m, q - h), to_param(m, q + h), from);
    return GSL_EBADFUNC;
}

/* Central-difference Jacobian dr_i/dq_j. */
static int gsl_df(const gsl_vector* x, void* params, gsl_matrix* jac)
{
    struct fit_ctx* c = params;
    size_t n = c->pb->n_data, np = c->pb->n_params;
    double q[NP_MAX];
    if (c->status != WETDEM_OK)
        return GSL_EBADFUNC;
    for (size_t j = 0; j < np; j++) {
        memcpy(q, x->data, np * sizeof *q);
        double h =
            c->map[j].kind != WETDEM_FIT_LINEAR ? c->fd_step : c->fd_step * fmax(fabs(q[j]), 1.0);
        q[j] = x->data[j] + h;
        if (residuals_at(c, q, c->r_plus) != WETDEM_OK)
            return GSL_EBADFUNC;
        q[j] = x->data[j] - h;
        if (residuals_at(c, q, c->r_minus) != WETDEM_OK)
            return GSL_EBADFUNC;
        for (size_t i = 0; i < n; i++)
            gsl_matrix_set(jac, i, j, (c->r_plus[i] - c->r_minus[i]) / (2 * h));
    }
    gsl_matrix_memcpy(c->jac, jac);
    memcpy(c->q_jac, x->data, np * sizeof *q);
    for (size_t j = 0; j < np; j++)
        if (column_is_zero(jac, j)) {
            double h = c->map[j].kind != WETDEM_FIT_LINEAR
                           ? c->fd_step
                           : c->fd_step * fmax(fabs(x->data[j]), 1.0);
            return zero_column(c, j, x->data[j], h);
        }
    return GSL_SUCCESS;
}

/* ---- checks ------------------------------------------------------------------------------- */

static int check_problem(const struct wetdem_fit_problem* pb, const struct wetdem_fit_options* o,
                         char* msg, size_t n)
{
    if (pb->n_params < 1 || pb->n_params > NP_MAX)
        return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID,
                                  "%zu parameters to fit: must be in [1, %d]", pb->n_params,
                                  NP_MAX);
    if (pb->n_data <= pb->n_params)
        return wetdem_status_fail(
            msg, n, WETDEM_ERR_INVALID,
            "%zu data points for %zu parameters: need more points than parameters (the "
            "standard errors use the residual variance)",
            pb->n_data, pb->n_params);
    if (!pb->model || !pb->initial || !pb->observed)
        return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID,
                                  "model, initial values and observations needed");
    /* (an infinite scale silenced its point; an infinite tolerance stopped the solver at its
       first iterate, reported as converged) */
    for (size_t i = 0; i < pb->n_data; i++)
        if (!isfinite(pb->observed[i]) ||
            (pb->scale && !(isfinite(pb->scale[i]) && pb->scale[i] > 0)))
            return wetdem_status_fail(
                msg, n, WETDEM_ERR_INVALID,
                "data point %zu: observation %g must be finite and its scale %g finite and > 0",
                i + 1, pb->observed[i], pb->scale ? pb->scale[i] : 1.0);
    if (o->max_iter < 1 || !(o->fd_step > 0 && o->fd_step < 1) ||
        !(isfinite(o->xtol) && o->xtol > 0) || !(isfinite(o->gtol) && o->gtol > 0) ||
        !(isfinite(o->ftol) && o->ftol > 0))
        return wetdem_status_fail(
            msg, n, WETDEM_ERR_INVALID,
            "fit options: max_iter >= 1, tolerances finite and > 0 and fd_step in (0, 1) needed "
            "(got max_iter %d, xtol %g, gtol %g, ftol %g, fd_step %g)",
            o->max_iter, o->xtol, o->gtol, o->ftol, o->fd_step);
    return WETDEM_OK;
}

/* ---- statistics --------------------------------------------------------------------------- */

/* (J^T J)^-1 over the columns j with use[j] (cov, np x np, zero elsewhere), from the SVD of J
 * with unit columns. Marks in *dependent the columns of singular directions (a singular value
 * below sqrt(DBL_EPSILON) of the largest) and returns their count (cov is then not filled),
 * or -1 when GSL fails (out of memory). */
static int inverse_normal_matrix(const gsl_matrix* jac, const bool* use, gsl_matrix* cov,
                                 bool* dependent)
{
    size_t n = jac->size1, np = jac->size2, m = 0, idx[NP_MAX];
    for (size_t j = 0; j < np; j++)
        if (use[j])
            idx[m++] = j;
    gsl_matrix_set_zero(cov);
    if (m == 0)
        return 0;
    gsl_matrix* a = gsl_matrix_alloc(n, m);
    gsl_matrix* v = gsl_matrix_alloc(m, m);
    gsl_vector* s = gsl_vector_alloc(m);
    gsl_vector* work = gsl_vector_alloc(m);
    double norm[NP_MAX];
    int found = -1;
    if (!a || !v || !s || !work)
        goto done;
    for (size_t k = 0; k < m; k++) {
        gsl_vector_const_view col = gsl_matrix_const_column(jac, idx[k]);
        norm[k] = gsl_blas_dnrm2(&col.vector);
        for (size_t i = 0; i < n; i++)
            gsl_matrix_set(a, i, k, gsl_vector_get(&col.vector, i) / norm[k]);
    }
    if (gsl_linalg_SV_decomp(a, v, s, work) != GSL_SUCCESS)
        goto done;
    found = 0;
    double tol = sqrt(DBL_EPSILON) * gsl_vector_get(s, 0);
    for (size_t l = 0; l < m; l++) {
        if (gsl_vector_get(s, l) > tol)
            continue;
        for (size_t k = 0; k < m; k++) /* the parameters of that direction */
            if (fabs(gsl_matrix_get(v, k, l)) > 1e-3 && !dependent[idx[k]]) {
                dependent[idx[k]] = true;
                found++;
            }
    }
    for (size_t k = 0; k < m && found == 0; k++)
        for (size_t l = 0; l < m; l++) {
            double sum = 0;
            for (size_t t = 0; t < m; t++)
                sum += gsl_matrix_get(v, k, t) * gsl_matrix_get(v, l, t) /
                       (gsl_vector_get(s, t) * gsl_vector_get(s, t));
            gsl_matrix_set(cov, idx[k], idx[l], sum / (norm[k] * norm[l]));
        }
done:
    gsl_matrix_free(a);
    gsl_matrix_free(v);
    gsl_vector_free(s);
    gsl_vector_free(work);
    return found;
}

/* Standard errors and correlations of the parameters with use[j] from cov, the covariance of
 * the fit variables q (delta method: dp = slope dq, so the correlation of p_j and p_k is that
 * of q_j and q_k times the signs of both slopes); the others get INFINITY (undetermined) or
 * NAN (at a bound) and NAN correlations. */
static void fill_errors(const struct fit_ctx* c, const gsl_matrix* cov, const bool* use,
                        const bool* undetermined, struct wetdem_fit_result* res)
{
    size_t np = c->pb->n_params;
    for (size_t j = 0; j < np; j++) {
        double sq = res->residual_std * sqrt(gsl_matrix_get(cov, j, j));
        res->std_errors[j] = use[j]            ? fabs(slope(&c->map[j], res->values[j])) * sq
                             : undetermined[j] ? INFINITY
                                               : NAN;
        for (size_t k = 0; k < np; k++) {
            double sign =
                (slope(&c->map[j], res->values[j]) < 0) != (slope(&c->map[k], res->values[k]) < 0)
                    ? -1.0
                    : 1.0;
            res->correlation[j][k] =
                use[j] && use[k] ? sign * gsl_matrix_get(cov, j, k) /
                                       sqrt(gsl_matrix_get(cov, j, j) * gsl_matrix_get(cov, k, k))
                                 : NAN;
        }
    }
}

/* What the flat-start test (FLAT_FRACTION) found for one parameter. */
struct flat_test {
    int state;     /* 0 not looked at, 1 flat, -1 not flat */
    double p[2];   /* the parameter at q_j - FLAT_PROBE and q_j + FLAT_PROBE */
    double change; /* the larger change of the residuals (2-norm) there */
};

/* Whether parameter j is flat where the fit stopped (q, residuals f, scatter s): see
 * FLAT_FRACTION. Evaluates the model (at most twice) only for a column that passes the
 * screens; a failed evaluation leaves no trace but its count. */
static bool is_flat(struct fit_ctx* c, const double* q, const gsl_vector* f, double s, size_t j,
                    struct flat_test* t)
{
    const struct param_map* m = &c->map[j];
    size_t np = c->pb->n_params, n = c->pb->n_data;
    gsl_vector_const_view col = gsl_matrix_const_column(c->jac, j);
    if (m->kind == WETDEM_FIT_LINEAR || !(s > 0) ||
        fabs(q[j] - to_variable(m, c->pb->initial[j])) >= Q_STEP_MAX ||
        !(gsl_blas_dnrm2(&col.vector) * FLAT_PROBE < FLAT_FRACTION * s))
        return false;
    double qp[NP_MAX];
    t->change = 0;
    for (int side = 0; side < 2; side++) {
        memcpy(qp, q, np * sizeof *qp);
        qp[j] = q[j] + (side ? FLAT_PROBE : -FLAT_PROBE);
        t->p[side] = to_param(m, qp[j]);
        char msg[sizeof c->msg];
        if (evaluate(c, qp, c->r_minus, msg, sizeof msg) != WETDEM_OK)
            return false;
        double sum = 0;
        for (size_t i = 0; i < n; i++)
            sum += pow(c->r_minus[i] - gsl_vector_get(f, i), 2);
        t->change = fmax(t->change, sqrt(sum));
        if (!(t->change < FLAT_FRACTION * s))
            return false;
    }
    return true;
}

/* Values, standard errors, correlations and bound flags from the Jacobian at the solution q;
 * returns how many parameters the data do not determine (-1: out of memory); flat[j].state is
 * 1 for those whose column is numerically zero (FLAT_FRACTION), not exactly zero or
 * dependent. */
static int fill_statistics(struct fit_ctx* c, const double* q, const gsl_vector* f, gsl_matrix* cov,
                           struct wetdem_fit_result* res, struct flat_test* flat)
{
    const struct wetdem_fit_problem* pb = c->pb;
    size_t np = pb->n_params;
    double cost;
    gsl_blas_ddot(f, f, &cost);
    res->cost = cost;
    res->dof = pb->n_data - np;
    res->residual_std = sqrt(cost / (double)res->dof);
    bool use[NP_MAX] = {false}, undetermined[NP_MAX] = {false};
    for (size_t j = 0; j < np; j++) {
        res->values[j] = to_param(&c->map[j], q[j]);
        res->transform[j] = (int)c->map[j].kind;
        undetermined[j] = column_is_zero(c->jac, j);
        use[j] = !undetermined[j];
    }
    /* undetermined combinations, then bounds hit (closer than AT_BOUND_SD sd), then flat
       starts (after the bounds: a parameter at a bound is a result): each pass removes
       parameters from the covariance, so at most 3 np passes; a parameter is probed for a
       flat start at most once */
    for (size_t pass = 0; pass < 3 * np; pass++) {
        int dep = inverse_normal_matrix(c->jac, use, cov, undetermined);
        if (dep < 0)
            return -1;
        for (size_t j = 0; j < np; j++)
            use[j] = use[j] && !undetermined[j];
        if (dep > 0)
            continue;
        fill_errors(c, cov, use, undetermined, res);
        bool changed = false;
        for (size_t j = 0; j < np; j++) {
            int side = use[j] ? at_bound(&c->map[j], res->values[j], res->std_errors[j]) : 0;
            if (side) {
                res->at_bound[j] = side;
                use[j] = false;
                changed = true;
            }
        }
        for (size_t j = 0; j < np && !changed; j++) {
            if (!use[j] || flat[j].state != 0)
                continue;
            flat[j].state = is_flat(c, q, f, res->residual_std, j, &flat[j]) ? 1 : -1;
            if (flat[j].state == 1) {
                undetermined[j] = true;
                use[j] = false;
                changed = true;
            }
        }
        if (!changed)
            break;
    }
    fill_errors(c, cov, use, undetermined, res);
    int n_undetermined = 0;
    for (size_t j = 0; j < np; j++) {
        res->undetermined[j] = undetermined[j];
        n_undetermined += undetermined[j];
    }
    return n_undetermined;
}

/* "A", "A and B", "A, B and C" of the undetermined parameters into buf. */
static void undetermined_names(const struct fit_ctx* c, const struct wetdem_fit_result* res,
                               char* buf, size_t n)
{
    size_t used = 0, count = 0, total = 0;
    for (size_t j = 0; j < c->pb->n_params; j++)
        total += res->undetermined[j];
    buf[0] = '\0';
    for (size_t j = 0; j < c->pb->n_params && used < n; j++)
        if (res->undetermined[j]) {
            count++;
            const char* sep = count == 1 ? "" : count == total ? " and " : ", ";
            used += (size_t)snprintf(buf + used, n - used, "%s%s", sep, param_name(c->pb, j));
        }
}

/* "A = a, B = b" of the parameters' initial values into buf. */
static void initial_values(const struct fit_ctx* c, char* buf, size_t n)
{
    size_t used = 0;
    buf[0] = '\0';
    for (size_t j = 0; j < c->pb->n_params && used < n; j++)
        used += (size_t)snprintf(buf + used, n - used, "%s%s = %g", j ? ", " : "",
                                 param_name(c->pb, j), c->pb->initial[j]);
}

/* ---- solver ------------------------------------------------------------------------------- */

/* Iterates the trust-region solver from x0; returns a wetdem status (WETDEM_OK: converged or
 * stopped at a bound). */
static int solve(struct fit_ctx* c, const struct wetdem_fit_options* o, const gsl_vector* x0,
                 gsl_multifit_nlinear_workspace* w, struct wetdem_fit_result* res)
{
    gsl_multifit_nlinear_fdf fdf = {.f = gsl_f,
                                    .df = gsl_df,
                                    .fvv = NULL,
                                    .n = c->pb->n_data,
                                    .p = c->pb->n_params,
                                    .params = c};
    int gst = gsl_multifit_nlinear_init(x0, &fdf, w);
    int info = 0;
    size_t iter = 0;
    while (gst == GSL_SUCCESS && iter < (size_t)o->max_iter) {
        gst = gsl_multifit_nlinear_iterate(w);
        if (gst == GSL_ENOPROG && iter > 0)
            gst = GSL_SUCCESS; /* (as GSL's driver: mu was reset; a good step came before) */
        if (gst != GSL_SUCCESS)
            break;
        iter++;
        int test = gsl_multifit_nlinear_test(o->xtol, o->gtol, o->ftol, &info, w);
        if (test == GSL_SUCCESS)
            break;
        info = 0;
        if (test != GSL_CONTINUE)
            gst = test;
    }
    res->iterations = iter;
    res->converged_by = info;
    if (c->status != WETDEM_OK)
        return c->status;
    if (gst == GSL_ENOPROG) {
        char start[300];
        initial_values(c, start, sizeof start);
        return wetdem_status_fail(c->msg, sizeof c->msg, WETDEM_ERR_STEP,
                                  "the trust-region solver found no step that lowers the cost "
                                  "from the initial values %s (the predictions are flat or "
                                  "noisy there: start nearer the value you expect, or hold "
                                  "the parameter fixed)",
                                  start);
    }
    if (gst != GSL_SUCCESS)
        return wetdem_status_fail(c->msg, sizeof c->msg, WETDEM_ERR_STEP,
                                  "the trust-region solver stopped: %s", gsl_strerror(gst));
    return info ? WETDEM_OK : WETDEM_ERR_MAX_STEPS;
}

/* The result after solve() returned st: statistics at the point of the last Jacobian (the
 * solution; GSL's position lags behind it when that Jacobian failed); the final status and
 * message. */
static int report(struct fit_ctx* c, int st, gsl_matrix* cov, const struct wetdem_fit_options* opt,
                  struct wetdem_fit_result* res, double* predicted, char* msg, size_t msg_size)
{
    size_t np = c->pb->n_params;
    if (c->zero_column) {
        size_t z = (size_t)c->zero_column - 1;
        for (size_t j = 0; j < np; j++) {
            res->values[j] = to_param(&c->map[j], c->q_jac[j]);
            res->transform[j] = (int)c->map[j].kind;
            res->std_errors[j] = j == z ? INFINITY : NAN;
            res->undetermined[j] = j == z;
            for (size_t k = 0; k < np; k++)
                res->correlation[j][k] = NAN;
        }
        return wetdem_status_fail(msg, msg_size, st, "%s", c->msg);
    }
    if (st != WETDEM_OK && st != WETDEM_ERR_MAX_STEPS)
        return wetdem_status_fail(msg, msg_size, st, "%s", c->msg);
    if (residuals_at(c, c->q_jac, c->r_plus) != WETDEM_OK) /* (it ran before: cannot fail) */
        return wetdem_status_fail(msg, msg_size, c->status, "%s", c->msg);
    if (predicted)
        memcpy(predicted, c->pred, c->pb->n_data * sizeof *predicted);
    gsl_vector_view f = gsl_vector_view_array(c->r_plus, c->pb->n_data);
    struct flat_test flat[NP_MAX] = {{0}};
    int n_und = fill_statistics(c, c->q_jac, &f.vector, cov, res, flat);
    if (n_und < 0)
        return wetdem_status_fail(msg, msg_size, WETDEM_ERR_NOMEM, "out of memory");
    char names[300];
    undetermined_names(c, res, names, sizeof names);
    size_t jf = 0;
    while (jf < np && flat[jf].state != 1)
        jf++;
    if (jf < np) { /* a flat start */
        const struct flat_test* t = &flat[jf];
        return wetdem_status_fail(
            msg, msg_size, WETDEM_ERR_UNDETERMINED,
            "the data do not determine %s: where the fit stopped, at %g (from the start %g), "
            "the predictions hardly depend on it: at %g and at %g (a factor 1000 either way in "
            "%s) the residuals change by at most %.2g, under %g of their scatter s = %.3g (its "
            "column of the Jacobian is numerically zero; standard error inf)%s%s%s; start it "
            "elsewhere, nearer the value you expect, or hold it fixed",
            param_name(c->pb, jf), res->values[jf], c->pb->initial[jf], t->p[0], t->p[1],
            c->map[jf].kind == WETDEM_FIT_LOGISTIC ? "the ratio (p - lower)/(upper - p)"
                                                   : "its distance to its bound",
            t->change, FLAT_FRACTION, res->residual_std, n_und > 1 ? "; not determined: " : "",
            n_und > 1 ? names : "",
            st == WETDEM_ERR_MAX_STEPS ? "; and no convergence in the iterations allowed" : "");
    }
    if (n_und > 0)
        return wetdem_status_fail(
            msg, msg_size, WETDEM_ERR_UNDETERMINED,
            "the data do not determine %s%s (%s of the Jacobian %s at the solution): "
            "standard error inf%s",
            names, n_und > 1 ? " separately" : "", n_und > 1 ? "their columns" : "its column",
            n_und > 1 ? "are linearly dependent" : "is zero",
            st == WETDEM_ERR_MAX_STEPS ? "; and no convergence in the iterations allowed" : "");
    if (st == WETDEM_ERR_MAX_STEPS)
        return wetdem_status_fail(msg, msg_size, st, "no convergence in %d iterations (cost %g)",
                                  opt->max_iter, res->cost);
    return WETDEM_OK;
}

int wetdem_fit_run(const struct wetdem_fit_problem* problem, const struct wetdem_fit_options* opt,
                   struct wetdem_fit_result* result, double* predicted, char* msg, size_t msg_size)
{
    if (!problem || !result)
        return wetdem_status_fail(msg, msg_size, WETDEM_ERR_INVALID, "NULL %s",
                                  problem ? "result" : "problem");
    memset(result, 0, sizeof *result);
    struct wetdem_fit_options defaults;
    if (!opt) { /* (the header's defaults, as wetdem_fit_options_init gives them) */
        wetdem_fit_options_init(&defaults);
        opt = &defaults;
    }
    int st = check_problem(problem, opt, msg, msg_size);
    if (st != WETDEM_OK)
        return st;
    size_t n = problem->n_data, np = problem->n_params;
    struct fit_ctx c = {.pb = problem, .fd_step = opt->fd_step, .status = WETDEM_OK};
    for (size_t j = 0; j < np && st == WETDEM_OK; j++)
        st = setup_map(problem, j, &c.map[j], msg, msg_size);
    if (st != WETDEM_OK)
        return st;
    wetdem_gsl_guard_enter();
    c.pred = malloc(n * sizeof *c.pred);
    c.r_plus = malloc(n * sizeof *c.r_plus);
    c.r_minus = malloc(n * sizeof *c.r_minus);
    c.jac = gsl_matrix_calloc(n, np);
    gsl_vector* x0 = gsl_vector_alloc(np);
    gsl_matrix* cov = gsl_matrix_alloc(np, np);
    gsl_multifit_nlinear_parameters fp = gsl_multifit_nlinear_default_parameters();
    gsl_multifit_nlinear_workspace* w =
        gsl_multifit_nlinear_alloc(gsl_multifit_nlinear_trust, &fp, n, np);
    if (!c.pred || !c.r_plus || !c.r_minus || !c.jac || !x0 || !cov || !w) {
        st = wetdem_status_fail(msg, msg_size, WETDEM_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t j = 0; j < np; j++) {
        c.q_jac[j] = to_variable(&c.map[j], problem->initial[j]);
        gsl_vector_set(x0, j, c.q_jac[j]);
    }
    st = solve(&c, opt, x0, w, result);
    st = report(&c, st, cov, opt, result, predicted, msg, msg_size);
    result->model_evals = c.evals; /* (report's own evaluation at the solution included) */
done:
    gsl_multifit_nlinear_free(w);
    gsl_matrix_free(cov);
    gsl_vector_free(x0);
    gsl_matrix_free(c.jac);
    free(c.pred);
    free(c.r_plus);
    free(c.r_minus);
    wetdem_gsl_guard_leave();
    return st;
}

/*
 * fit.c — calibration of model parameters against measurements by nonlinear least squares:
 * minimise S(q) = sum_i r_i^2, r_i = (y_i(p) - y_i,obs)/s_i, over the fitted variables q, with
 * q = ln p for positive parameters (so they stay positive and a relative step is natural for
 * quantities such as the glass-transition pressure P_gt of Punch 2023 Eq. 14, a roughness or a
 * minimum separation) and q = p otherwise.
 *
 * Solver: GSL gsl_multifit_nlinear, trust region with Levenberg-Marquardt steps. The Jacobian
 * J_ij = dr_i/dq_j is taken by central differences with step h (fd_step): predictions from a
 * simulation carry integration noise of relative size ~1e-4, so the default h = 1e-2 keeps
 * the difference quotient's noise (~1e-4/h) below 1 % while its truncation error is O(h^2).
 *
 * Standard errors (Gauss-Newton linearisation at the solution): cov(q) = s^2 (J^T J)^-1 with
 * the residual variance s^2 = S/(n - p), i.e. the scatter of the data about the fit sets the
 * error scale (no measurement errors needed); for log parameters sd(p) = p sd(q) (delta
 * method). Valid when the model is close to linear in q over +-2 sd and the residuals are
 * independent with equal variance (after division by s_i).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_blas.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_matrix.h>
#include <gsl/gsl_multifit_nlinear.h>
#include <gsl/gsl_vector.h>

#include "status.h"
#include "wetdem.h"

struct fit_ctx {
    const struct wetdem_fit_problem* pb;
    bool is_log[WETDEM_FIT_MAX_PARAMS];
    double fd_step;
    double* pred;   /* scratch predictions [n_data] */
    double* r_plus; /* scratch residuals [n_data] */
    size_t evals;
    int status; /* first failure of the model */
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

static double to_param(const struct fit_ctx* c, size_t j, double q)
{
    return c->is_log[j] ? exp(q) : q;
}

/* Scaled residuals r[0..n) at fitted variables q. */
static int residuals_at(struct fit_ctx* c, const double* q, double* r)
{
    const struct wetdem_fit_problem* pb = c->pb;
    double p[WETDEM_FIT_MAX_PARAMS];
    for (size_t j = 0; j < pb->n_params; j++)
        p[j] = to_param(c, j, q[j]);
    c->evals++;
    int st = pb->model(p, c->pred, c->msg, sizeof c->msg, pb->ctx);
    for (size_t i = 0; st == WETDEM_OK && i < pb->n_data; i++) {
        double s = pb->scale ? pb->scale[i] : 1.0;
        r[i] = (c->pred[i] - pb->observed[i]) / s;
        if (!isfinite(r[i]))
            st = wetdem_status_fail(c->msg, sizeof c->msg, WETDEM_ERR_NUMERIC,
                                    "the model gave a non-finite prediction %g for data point %zu",
                                    c->pred[i], i + 1);
    }
    if (st != WETDEM_OK && c->status == WETDEM_OK)
        c->status = st;
    return st;
}

static int gsl_f(const gsl_vector* x, void* params, gsl_vector* f)
{
    struct fit_ctx* c = params;
    return residuals_at(c, x->data, f->data) == WETDEM_OK ? GSL_SUCCESS : GSL_EBADFUNC;
}

/* Central-difference Jacobian dr_i/dq_j. */
static int gsl_df(const gsl_vector* x, void* params, gsl_matrix* jac)
{
    struct fit_ctx* c = params;
    size_t n = c->pb->n_data, np = c->pb->n_params;
    double q[WETDEM_FIT_MAX_PARAMS];
    double* r_minus = malloc(n * sizeof *r_minus);
    if (!r_minus)
        return GSL_ENOMEM;
    for (size_t j = 0; j < np; j++) {
        memcpy(q, x->data, np * sizeof *q);
        double h = c->is_log[j] ? c->fd_step : c->fd_step * fmax(fabs(q[j]), 1.0);
        q[j] = x->data[j] + h;
        if (residuals_at(c, q, c->r_plus) != WETDEM_OK)
            break;
        q[j] = x->data[j] - h;
        if (residuals_at(c, q, r_minus) != WETDEM_OK)
            break;
        for (size_t i = 0; i < n; i++)
            gsl_matrix_set(jac, i, j, (c->r_plus[i] - r_minus[i]) / (2 * h));
    }
    free(r_minus);
    return c->status == WETDEM_OK ? GSL_SUCCESS : GSL_EBADFUNC;
}

static int check_problem(const struct wetdem_fit_problem* pb, const struct wetdem_fit_options* o,
                         char* msg, size_t n)
{
    if (pb->n_params < 1 || pb->n_params > WETDEM_FIT_MAX_PARAMS)
        return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID,
                                  "%zu parameters to fit: must be in [1, %d]", pb->n_params,
                                  WETDEM_FIT_MAX_PARAMS);
    if (pb->n_data <= pb->n_params)
        return wetdem_status_fail(
            msg, n, WETDEM_ERR_INVALID,
            "%zu data points for %zu parameters: need more points than parameters (the "
            "standard errors use the residual variance)",
            pb->n_data, pb->n_params);
    if (!pb->model || !pb->initial || !pb->observed)
        return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID,
                                  "model, initial values and observations needed");
    for (size_t j = 0; j < pb->n_params; j++) {
        bool lg = pb->is_log ? pb->is_log[j] : pb->initial[j] > 0;
        if (!isfinite(pb->initial[j]) || (lg && !(pb->initial[j] > 0)))
            return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID,
                                      "%s: initial value %g must be finite%s", param_name(pb, j),
                                      pb->initial[j], lg ? " and > 0 (log fit)" : "");
    }
    for (size_t i = 0; i < pb->n_data; i++)
        if (!isfinite(pb->observed[i]) || (pb->scale && !(pb->scale[i] > 0)))
            return wetdem_status_fail(
                msg, n, WETDEM_ERR_INVALID,
                "data point %zu: observation %g must be finite and its scale > 0", i + 1,
                pb->observed[i]);
    if (o->max_iter < 1 || !(o->fd_step > 0 && o->fd_step < 1) || !(o->xtol > 0) ||
        !(o->gtol > 0) || !(o->ftol > 0))
        return wetdem_status_fail(
            msg, n, WETDEM_ERR_INVALID,
            "fit options: max_iter >= 1, tolerances > 0 and fd_step in (0, 1) needed "
            "(got %d, %g, %g, %g, %g)",
            o->max_iter, o->xtol, o->gtol, o->ftol, o->fd_step);
    return WETDEM_OK;
}

/* Values, standard errors and correlations from the Jacobian at the solution. */
static void fill_statistics(const struct fit_ctx* c, gsl_multifit_nlinear_workspace* w,
                            gsl_matrix* covar, struct wetdem_fit_result* res)
{
    const struct wetdem_fit_problem* pb = c->pb;
    size_t np = pb->n_params;
    const gsl_vector* x = gsl_multifit_nlinear_position(w);
    double cost;
    gsl_blas_ddot(gsl_multifit_nlinear_residual(w), gsl_multifit_nlinear_residual(w), &cost);
    gsl_multifit_nlinear_covar(gsl_multifit_nlinear_jac(w), 0.0, covar);
    res->cost = cost;
    res->dof = pb->n_data - np;
    res->residual_std = sqrt(cost / (double)res->dof);
    for (size_t j = 0; j < np; j++) {
        double q = gsl_vector_get(x, j), sq = res->residual_std * sqrt(gsl_matrix_get(covar, j, j));
        res->values[j] = to_param(c, j, q);
        res->std_errors[j] = c->is_log[j] ? res->values[j] * sq : sq;
        for (size_t k = 0; k < np; k++)
            res->correlation[j][k] =
                gsl_matrix_get(covar, j, k) /
                sqrt(gsl_matrix_get(covar, j, j) * gsl_matrix_get(covar, k, k));
    }
}

/* Runs the GSL driver; returns a wetdem status. */
static int solve(struct fit_ctx* c, const struct wetdem_fit_options* o, gsl_vector* x0,
                 gsl_multifit_nlinear_workspace* w, struct wetdem_fit_result* res)
{
    gsl_multifit_nlinear_fdf fdf = {.f = gsl_f,
                                    .df = gsl_df,
                                    .fvv = NULL,
                                    .n = c->pb->n_data,
                                    .p = c->pb->n_params,
                                    .params = c};
    int info = 0;
    int gst = gsl_multifit_nlinear_init(x0, &fdf, w);
    if (gst == GSL_SUCCESS)
        gst = gsl_multifit_nlinear_driver((size_t)o->max_iter, o->xtol, o->gtol, o->ftol, NULL,
                                          NULL, &info, w);
    res->iterations = gsl_multifit_nlinear_niter(w);
    res->converged_by = info;
    if (c->status != WETDEM_OK)
        return c->status;
    if (gst == GSL_EMAXITER)
        return WETDEM_ERR_MAX_STEPS;
    if (gst != GSL_SUCCESS)
        return wetdem_status_fail(c->msg, sizeof c->msg, WETDEM_ERR_STEP,
                                  "the trust-region solver stopped: %s", gsl_strerror(gst));
    return WETDEM_OK;
}

int wetdem_fit_run(const struct wetdem_fit_problem* problem, const struct wetdem_fit_options* opt,
                   struct wetdem_fit_result* result, double* predicted, char* msg, size_t msg_size)
{
    memset(result, 0, sizeof *result);
    int st = check_problem(problem, opt, msg, msg_size);
    if (st != WETDEM_OK)
        return st;
    size_t n = problem->n_data, np = problem->n_params;
    struct fit_ctx c = {.pb = problem, .fd_step = opt->fd_step, .status = WETDEM_OK};
    c.pred = malloc(n * sizeof *c.pred);
    c.r_plus = malloc(n * sizeof *c.r_plus);
    gsl_vector* x0 = gsl_vector_alloc(np);
    gsl_matrix* covar = gsl_matrix_alloc(np, np);
    gsl_multifit_nlinear_parameters fp = gsl_multifit_nlinear_default_parameters();
    gsl_multifit_nlinear_workspace* w =
        gsl_multifit_nlinear_alloc(gsl_multifit_nlinear_trust, &fp, n, np);
    if (!c.pred || !c.r_plus || !x0 || !covar || !w) {
        st = wetdem_status_fail(msg, msg_size, WETDEM_ERR_NOMEM, "out of memory");
        goto done;
    }
    for (size_t j = 0; j < np; j++) {
        c.is_log[j] = problem->is_log ? problem->is_log[j] : problem->initial[j] > 0;
        gsl_vector_set(x0, j, c.is_log[j] ? log(problem->initial[j]) : problem->initial[j]);
    }
    st = solve(&c, opt, x0, w, result);
    result->model_evals = c.evals;
    if (st == WETDEM_OK || st == WETDEM_ERR_MAX_STEPS) {
        fill_statistics(&c, w, covar, result);
        if (predicted &&
            residuals_at(&c, gsl_multifit_nlinear_position(w)->data, c.r_plus) == WETDEM_OK)
            memcpy(predicted, c.pred, n * sizeof *predicted);
    }
    if (st == WETDEM_ERR_MAX_STEPS)
        wetdem_status_fail(msg, msg_size, st, "no convergence in %d iterations (cost %g)",
                           opt->max_iter, result->cost);
    else if (st != WETDEM_OK)
        wetdem_status_fail(msg, msg_size, st, "%s", c.msg);
done:
    gsl_multifit_nlinear_free(w);
    gsl_matrix_free(covar);
    gsl_vector_free(x0);
    free(c.pred);
    free(c.r_plus);
    return st;
}

/*
 * integrator_cvode_nvec.c — vector kernels for CVODE's serial N_Vector, compiled with the
 * project's flags (docs/performance.md, "Where the CVODE time went").
 *
 * Why: the SUNDIALS 6.4.1 packages of the distribution (libsundials-nvecserial6,
 * libsundials-cvode6, Debian 6.4.1+dfsg1-3) are compiled without optimisation — their
 * N_V*_Serial kernels keep every loop variable on the stack (checked by disassembly) — and for
 * the 18 unknowns of a binary collision CVODE spends most of its time in these kernels:
 * ~60 % of all instructions of the Nijssen Fig. 3 sweep (callgrind). CVODE reaches them
 * through the function table of the vector (N_Vector ops), which every clone copies, so
 * installing these kernels on the template vector before CVodeInit serves the whole solver.
 *
 * Each kernel computes exactly what its N_V*_Serial counterpart computes, operation for
 * operation, so results stay bit-identical (tests/test_integrators.c compares every kernel
 * with the library's on random data for every special case): N_VLinearSum_Serial evaluates
 * a (x + y) when a == b and a (x - y) when a == -b (a, b not +-1), a x + b y otherwise (its
 * special cases for a or b = +-1 give the same bits as that general form); the fused and array
 * operations reduce to N_VLinearSum/N_VScale for one or two vectors as the library does.
 * Operations not listed here keep the library's kernels.
 */
#include <math.h>
#include <stdbool.h>

#include "integrator_cvode_nvec.h"

#define DATA(v) NV_DATA_S(v)
#define LEN(v) NV_LENGTH_S(v)

/* z = a x + b y with the library's rounding: a (x + y) when a == b and a (x - y) when
 * a == -b unless a or b is +-1 (then x +- y, y - x, x + b y, b y - x, ... are what the
 * library computes, the same bits as a x + b y, signed zeros included). */
static void linear_sum(sunrealtype a, N_Vector x, sunrealtype b, N_Vector y, N_Vector z)
{
    const sunrealtype* restrict xd = DATA(x), * restrict yd = DATA(y);
    sunrealtype* zd = DATA(z);
    sunindextype n = LEN(x);
    bool unit = a == 1.0 || a == -1.0 || b == 1.0 || b == -1.0; /* library: general form */
    if (!unit && a == b) {
        for (sunindextype i = 0; i < n; i++)
            zd[i] = a * (xd[i] + yd[i]);
    } else if (!unit && a == -b) {
        for (sunindextype i = 0; i < n; i++)
            zd[i] = a * (xd[i] - yd[i]);
    } else {
        for (sunindextype i = 0; i < n; i++)
            zd[i] = a * xd[i] + b * yd[i];
    }
}

static void set_const(sunrealtype c, N_Vector z)
{
    sunrealtype* zd = DATA(z);
    for (sunindextype i = 0, n = LEN(z); i < n; i++)
        zd[i] = c;
}

static void prod(N_Vector x, N_Vector y, N_Vector z)
{
    const sunrealtype *xd = DATA(x), *yd = DATA(y);
    sunrealtype* zd = DATA(z);
    for (sunindextype i = 0, n = LEN(x); i < n; i++)
        zd[i] = xd[i] * yd[i];
}

static void divide(N_Vector x, N_Vector y, N_Vector z)
{
    const sunrealtype *xd = DATA(x), *yd = DATA(y);
    sunrealtype* zd = DATA(z);
    for (sunindextype i = 0, n = LEN(x); i < n; i++)
        zd[i] = xd[i] / yd[i];
}

static void scale(sunrealtype c, N_Vector x, N_Vector z)
{
    const sunrealtype* xd = DATA(x);
    sunrealtype* zd = DATA(z);
    for (sunindextype i = 0, n = LEN(x); i < n; i++)
        zd[i] = c * xd[i];
}

static void absolute(N_Vector x, N_Vector z)
{
    const sunrealtype* xd = DATA(x);
    sunrealtype* zd = DATA(z);
    for (sunindextype i = 0, n = LEN(x); i < n; i++)
        zd[i] = fabs(xd[i]);
}

static void invert(N_Vector x, N_Vector z)
{
    const sunrealtype* xd = DATA(x);
    sunrealtype* zd = DATA(z);
    for (sunindextype i = 0, n = LEN(x); i < n; i++)
        zd[i] = 1.0 / xd[i];
}

static void add_const(N_Vector x, sunrealtype b, N_Vector z)
{
    const sunrealtype* xd = DATA(x);
    sunrealtype* zd = DATA(z);
    for (sunindextype i = 0, n = LEN(x); i < n; i++)
        zd[i] = xd[i] + b;
}

static sunrealtype max_norm(N_Vector x)
{
    const sunrealtype* xd = DATA(x);
    sunrealtype m = 0.0;
    for (sunindextype i = 0, n = LEN(x); i < n; i++)
        if (fabs(xd[i]) > m)
            m = fabs(xd[i]);
    return m;
}

/* Sum of (x_i w_i)^2 in index order. */
static sunrealtype wsqr_sum(N_Vector x, N_Vector w)
{
    const sunrealtype *xd = DATA(x), *wd = DATA(w);
    sunrealtype sum = 0.0;
    for (sunindextype i = 0, n = LEN(x); i < n; i++) {
        sunrealtype p = xd[i] * wd[i];
        sum += p * p;
    }
    return sum;
}

static sunrealtype wrms_norm(N_Vector x, N_Vector w)
{
    return sqrt(wsqr_sum(x, w) / (sunrealtype)LEN(x));
}

static int linear_combination(int nvec, sunrealtype* c, N_Vector* x, N_Vector z)
{
    if (nvec == 1) {
        scale(c[0], x[0], z);
        return 0;
    }
    if (nvec == 2) {
        linear_sum(c[0], x[0], c[1], x[1], z);
        return 0;
    }
    sunrealtype* zd = DATA(z);
    sunindextype n = LEN(z);
    if (x[0] != z || c[0] != 1.0) {
        const sunrealtype* x0 = DATA(x[0]);
        for (sunindextype j = 0; j < n; j++)
            zd[j] = c[0] * x0[j]; /* for x[0] == z this is the library's zd *= c[0] */
    }
    for (int i = 1; i < nvec; i++) {
        const sunrealtype* xd = DATA(x[i]);
        for (sunindextype j = 0; j < n; j++)
            zd[j] += c[i] * xd[j];
    }
    return 0;
}

static int scale_add_multi(int nvec, sunrealtype* a, N_Vector x, N_Vector* y, N_Vector* z)
{
    if (nvec == 1) {
        linear_sum(a[0], x, 1.0, y[0], z[0]);
        return 0;
    }
    const sunrealtype* xd = DATA(x);
    sunindextype n = LEN(x);
    for (int i = 0; i < nvec; i++) {
        const sunrealtype* yd = DATA(y[i]);
        sunrealtype* zd = DATA(z[i]);
        for (sunindextype j = 0; j < n; j++)
            zd[j] = a[i] * xd[j] + yd[j];
    }
    return 0;
}

static int linear_sum_array(int nvec, sunrealtype a, N_Vector* x, sunrealtype b, N_Vector* y,
                            N_Vector* z)
{
    for (int i = 0; i < nvec; i++)
        linear_sum(a, x[i], b, y[i], z[i]);
    return 0;
}

static int scale_array(int nvec, sunrealtype* c, N_Vector* x, N_Vector* z)
{
    for (int i = 0; i < nvec; i++)
        scale(c[i], x[i], z[i]);
    return 0;
}

static int const_array(int nvec, sunrealtype c, N_Vector* z)
{
    for (int i = 0; i < nvec; i++)
        set_const(c, z[i]);
    return 0;
}

static int wrms_norm_array(int nvec, N_Vector* x, N_Vector* w, sunrealtype* nrm)
{
    for (int i = 0; i < nvec; i++)
        nrm[i] = wrms_norm(x[i], w[i]);
    return 0;
}

void wetdem_integrator_cvode_nvec_install(N_Vector v)
{
    struct _generic_N_Vector_Ops* ops = v->ops;
    ops->nvlinearsum = linear_sum;
    ops->nvconst = set_const;
    ops->nvprod = prod;
    ops->nvdiv = divide;
    ops->nvscale = scale;
    ops->nvabs = absolute;
    ops->nvinv = invert;
    ops->nvaddconst = add_const;
    ops->nvmaxnorm = max_norm;
    ops->nvwrmsnorm = wrms_norm;
    ops->nvwsqrsumlocal = wsqr_sum;
    ops->nvmaxnormlocal = max_norm;
    if (ops->nvlinearcombination)
        ops->nvlinearcombination = linear_combination;
    if (ops->nvscaleaddmulti)
        ops->nvscaleaddmulti = scale_add_multi;
    if (ops->nvlinearsumvectorarray)
        ops->nvlinearsumvectorarray = linear_sum_array;
    if (ops->nvscalevectorarray)
        ops->nvscalevectorarray = scale_array;
    if (ops->nvconstvectorarray)
        ops->nvconstvectorarray = const_array;
    if (ops->nvwrmsnormvectorarray)
        ops->nvwrmsnormvectorarray = wrms_norm_array;
}

/*
 * alloc_fallible.h — the declarations of the C allocator's wrappers (each including file
 * defines them), and the SUNDIALS and GSL constructors the library calls, wrapped to fail when
 * inject() below says so (tests/test_alloc_failure.c, tests/cli_alloc_wrap.c;
 * the link flags are the Makefile's ALLOC_WRAP, which must name the same functions). A failed
 * SUNDIALS constructor returns NULL or its memory-failure flag; a failed GSL one calls GSL's
 * error handler first (whose default aborts), then returns NULL, as GSL does.
 *
 * Include once; the including file sets alloc_fail_at and reads alloc_count and alloc_failed.
 */
#ifndef WETDEM_TEST_ALLOC_FALLIBLE_H
#define WETDEM_TEST_ALLOC_FALLIBLE_H

#include <stdatomic.h>
#include <stdbool.h>
#include <stddef.h>

#include <cvode/cvode.h>
#include <cvode/cvode_ls.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_integration.h>
#include <gsl/gsl_matrix.h>
#include <gsl/gsl_multifit_nlinear.h>
#include <gsl/gsl_rng.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

/* the C allocator, as linked with --wrap (the including file defines the __wrap_ ones) */
void* __real_malloc(size_t size);
void* __real_calloc(size_t n, size_t size);
void* __real_realloc(void* p, size_t size);
char* __real_strdup(const char* s);
void __real_free(void* p);
void* __wrap_malloc(size_t size);
void* __wrap_calloc(size_t n, size_t size);
void* __wrap_realloc(void* p, size_t size);
char* __wrap_strdup(const char* s);
void __wrap_free(void* p);

static atomic_long alloc_count;  /* allocations counted (in the library's test: since arm()) */
static long alloc_fail_at;       /* the allocation to fail (1-based); 0: none */
static atomic_bool alloc_failed; /* the allocation alloc_fail_at was failed */

/* Counts an allocation; whether it is the one to fail. */
static bool inject(void)
{
    long k = atomic_fetch_add(&alloc_count, 1) + 1;
    if (alloc_fail_at > 0 && k == alloc_fail_at) {
        atomic_store(&alloc_failed, true);
        return true;
    }
    return false;
}

#define FALLIBLE(type, name, params, args, failed)                                                 \
    type __real_##name params;                                                                     \
    type __wrap_##name params;                                                                     \
    type __wrap_##name params                                                                      \
    {                                                                                              \
        if (inject())                                                                              \
            return failed;                                                                         \
        return __real_##name args;                                                                 \
    }
#define GSL_FAILED(type) (gsl_error("out of memory", __FILE__, __LINE__, GSL_ENOMEM), (type)NULL)

FALLIBLE(int, SUNContext_Create, (void* comm, SUNContext* ctx), (comm, ctx), -1)
FALLIBLE(N_Vector, N_VNew_Serial, (sunindextype n, SUNContext ctx), (n, ctx), NULL)
FALLIBLE(void*, CVodeCreate, (int lmm, SUNContext ctx), (lmm, ctx), NULL)
FALLIBLE(int, CVodeInit, (void* mem, CVRhsFn f, sunrealtype t0, N_Vector y0), (mem, f, t0, y0),
         CV_MEM_FAIL)
FALLIBLE(int, CVodeRootInit, (void* mem, int n, CVRootFn g), (mem, n, g), CV_MEM_FAIL)
FALLIBLE(SUNMatrix, SUNDenseMatrix, (sunindextype m, sunindextype n, SUNContext ctx), (m, n, ctx),
         NULL)
FALLIBLE(SUNLinearSolver, SUNLinSol_Dense, (N_Vector y, SUNMatrix a, SUNContext ctx), (y, a, ctx),
         NULL)
FALLIBLE(int, CVodeSetLinearSolver, (void* mem, SUNLinearSolver ls, SUNMatrix a), (mem, ls, a),
         CVLS_MEM_FAIL)
FALLIBLE(SUNNonlinearSolver, SUNNonlinSol_FixedPoint, (N_Vector y, int m, SUNContext ctx),
         (y, m, ctx), NULL)
FALLIBLE(gsl_rng*, gsl_rng_alloc, (const gsl_rng_type* t), (t), GSL_FAILED(gsl_rng*))
FALLIBLE(gsl_matrix*, gsl_matrix_alloc, (size_t n1, size_t n2), (n1, n2), GSL_FAILED(gsl_matrix*))
FALLIBLE(gsl_matrix*, gsl_matrix_calloc, (size_t n1, size_t n2), (n1, n2), GSL_FAILED(gsl_matrix*))
FALLIBLE(gsl_vector*, gsl_vector_alloc, (size_t n), (n), GSL_FAILED(gsl_vector*))
FALLIBLE(gsl_multifit_nlinear_workspace*, gsl_multifit_nlinear_alloc,
         (const gsl_multifit_nlinear_type* t, const gsl_multifit_nlinear_parameters* p, size_t n,
          size_t np),
         (t, p, n, np), GSL_FAILED(gsl_multifit_nlinear_workspace*))
FALLIBLE(gsl_integration_glfixed_table*, gsl_integration_glfixed_table_alloc, (size_t n), (n),
         GSL_FAILED(gsl_integration_glfixed_table*))

#endif

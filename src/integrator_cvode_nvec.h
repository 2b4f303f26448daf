/*
 * integrator_cvode_nvec.h — optimised kernels for CVODE's serial N_Vector
 * (integrator_cvode_nvec.c), used by integrator_cvode.c.
 */
#ifndef WETDEM_INTEGRATOR_CVODE_NVEC_H
#define WETDEM_INTEGRATOR_CVODE_NVEC_H

#include <nvector/nvector_serial.h>

/* Replaces the kernels of serial vector v (and of every vector later cloned from it) by
 * kernels compiled with the project's flags that give bit-identical results: linear sums,
 * scaling, constants, products, quotients, abs, inverse, WRMS and max norms, and the fused
 * and array forms CVODE uses. v must be an N_VNew_Serial vector. */
void wetdem_integrator_cvode_nvec_install(N_Vector v);

#endif

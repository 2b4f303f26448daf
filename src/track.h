/*
 * track.h — internal kernels of the experiment tracking (src/track.c), shared with its tests:
 * the Savitzky-Golay hat matrix derived by least squares, the per-interval solution of
 * Punch (2023) Eq. 23, and the residual and linear map of that solution that the
 * uncertainties use.
 */
#ifndef WETDEM_TRACK_H
#define WETDEM_TRACK_H

#include <stddef.h>

#include "wetdem.h"

/* Savitzky-Golay smoothing matrix of a window of `window` frames and polynomial `order`:
 * hat[q * window + m] is the weight of sample m in the value of the least-squares polynomial
 * at position q of the window (H = V (V^T V)^-1 V^T, V the Vandermonde matrix of the window).
 * Returns WETDEM_OK, or WETDEM_ERR_INVALID unless window >= 1 is odd and 0 <= order < window,
 * or WETDEM_ERR_NOMEM. */
int wetdem_track_savgol_hat(int window, int order, double* hat);

/* Smooths x[0..n) into out[0..n) with a hat matrix: centred windows inside, the first/last
 * `window` samples' polynomial at the ends. Requires n >= window. */
void wetdem_track_savgol_apply(const double* hat, int window, const double* x, size_t n,
                               double* out);

/* Punch Eq. 23 for one frame interval: dots p0 = x1,y1,x2,y2,x3,y3 at frame i and p1 at frame
 * i + 1 [m], frame time dt [s]. Least squares for (vx, vy, omega) with omega counter-clockwise
 * in (x, y) (Punch App. A, Eqs. 27-29). out[3] = vx [m/s], vy [m/s], omega [rad/s]; *rms
 * (may be NULL) = rms residual of the six equations [m]. Returns WETDEM_OK or
 * WETDEM_ERR_NUMERIC when the dots are degenerate. */
int wetdem_track_solve_interval(const double p0[6], const double p1[6], double dt, double out[3],
                                double* rms);

/* Sum of squares [m^2] of the residuals of Eq. 23 for dots p0 -> p1 [m] less their part due to
 * the small-angle approximation, which follows from the solution (track.c): zero up to
 * round-off for an exact rigid step of any rotation below pi/2 per frame, 6 sigma^2 on
 * average for independent noise sigma on every coordinate (docs/tracking.md "Uncertainties").
 * Returns WETDEM_OK or WETDEM_ERR_NUMERIC as wetdem_track_solve_interval. */
int wetdem_track_rigid_residual(const double p0[6], const double p1[6], double* ss);

/* The least-squares solution of Eq. 23 as a linear map of its right-hand side: gain[6 c + j]
 * = d (vx, vy, omega)[c] / d b[j] for b = p1 - p0 [1/s, 1/(m s)], the matrix (A^T A)^-1 A^T / dt
 * for the dots p0 [m]. Returns WETDEM_OK or WETDEM_ERR_NUMERIC when the dots are degenerate. */
int wetdem_track_interval_gain(const double p0[6], double dt, double gain[18]);

#endif

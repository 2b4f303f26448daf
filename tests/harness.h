/*
 * harness.h — small helpers on top of cmocka for wetdem tests: relative/absolute comparisons
 * that print the test's numbers on failure, and builders of two-sphere contacts.
 */
#ifndef WETDEM_TEST_HARNESS_H
#define WETDEM_TEST_HARNESS_H

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <cmocka.h>

#include "wetdem.h"

/* |a - b| <= tol * max(|a|, |b|), or both exactly zero. */
#define CHECK_REL(a, b, tol)                                                                       \
    do {                                                                                           \
        double a_ = (a), b_ = (b), t_ = (tol);                                                     \
        double s_ = fmax(fabs(a_), fabs(b_));                                                      \
        if (!(fabs(a_ - b_) <= t_ * s_) && !(a_ == b_))                                            \
            fail_msg("%s = %.17g vs %s = %.17g: relative difference %.3g > %.3g", #a, a_, #b, b_,  \
                     s_ > 0 ? fabs(a_ - b_) / s_ : 0.0, t_);                                       \
    } while (0)

#define CHECK_ABS(a, b, tol)                                                                       \
    do {                                                                                           \
        double a_ = (a), b_ = (b), t_ = (tol);                                                     \
        if (!(fabs(a_ - b_) <= t_))                                                                \
            fail_msg("%s = %.17g vs %s = %.17g: difference %.3g > %.3g", #a, a_, #b, b_,           \
                     fabs(a_ - b_), t_);                                                           \
    } while (0)

#define CHECK_STATUS(expr, want)                                                                   \
    do {                                                                                           \
        int st_ = (expr);                                                                          \
        if (st_ != (want))                                                                         \
            fail_msg("%s returned %s, expected %s", #expr, wetdem_status_name(st_),                \
                     wetdem_status_name(want));                                                    \
    } while (0)

#define CHECK_OK(expr) CHECK_STATUS(expr, WETDEM_OK)

/* Asserts that haystack contains needle. */
#define CHECK_CONTAINS(haystack, needle)                                                           \
    do {                                                                                           \
        const char* h_ = (haystack);                                                               \
        if (!h_ || !strstr(h_, (needle)))                                                          \
            fail_msg("'%s' does not contain '%s'", h_ ? h_ : "(null)", (needle));                  \
    } while (0)

/* Two spheres on the x axis: i at +x, j at the origin, so the normal (j to i) is +x.
 * gap [m], approach speed v_n [m/s] (> 0 approaching) given to i moving in -x. */
static inline struct wetdem_contact test_contact(double radius_i, double radius_j, double mass_i,
                                                 double mass_j, double gap, double v_n)
{
    struct wetdem_contact c;
    memset(&c, 0, sizeof c);
    c.i = 0;
    c.j = 1;
    c.normal = (struct wetdem_vec3){1, 0, 0};
    c.gap = gap;
    c.radius_i = radius_i;
    c.radius_j = radius_j;
    c.r_eff = radius_i * radius_j / (radius_i + radius_j);
    c.m_eff = mass_i * mass_j / (mass_i + mass_j);
    c.v_n = v_n;
    c.e_star = 100e9;
    c.g_star = 40e9;
    c.restitution = 0.9;
    c.friction_dry = 0.1;
    c.friction_lub = 0.02;
    c.roughness = 1e-6;
    c.film = 100e-6;
    c.viscosity = 1.0;
    c.surface_tension = 0.02;
    c.h_min = 1e-6;
    c.dt = 1e-7;
    return c;
}

/* A params block of `model` filled with its defaults (static storage, one per call site use). */
static inline void* test_default_params(const struct wetdem_model* model, void* storage)
{
    wetdem_param_init_defaults(model->params, storage);
    return storage;
}

#endif

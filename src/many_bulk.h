/*
 * many_bulk.h — four candidate pairs at a time in vector units (docs/many.md, "Four pairs at a
 * time"): the gap test, the geometry and the film forces of the lean kernel, for the one-loop
 * pass of a wet packing in the common case (one material pair, no periodic axis). Internal to
 * the many-particle engine.
 *
 * For candidate pair q = (i, j) with d = x_i - x_j, exactly the operations of
 * sim_many_force.c's within_reach, lean_pair_start, film_terms and lean_apart, lane by lane:
 *   r2 = (d_x d_x + d_y d_y) + d_z d_z (the gap test: r2 <= pair_lim2),  |d| = sqrt(r2),
 *   gap = (|d| - R_i) - R_j,  n = d (1/|d|) (or (1, 0, 0) when |d| = 0),
 *   v_n = -((v_i - v_j) . n),  R* = R_i R_j / (R_i + R_j) (contact.h contact_reduced),
 *   sb (force_sb.c; Punch 2023 Eq. 7 with the corrected bracket, SPEC §6):
 *     F_sb = 6 pi mu R*^2 v_n / h [1 - h/delta]^2, h = gap, or h_min' below it with "nc",
 *   capillary (force_capillary.c; Punch 2023 Eq. 15):  F_cap = -8 pi R* sigma,
 *   each for gap <= delta and +0 where it does not act;
 *   apart: f_n = (+0 + F_sb) + F_cap,  force = +0 + f_n n.
 * IEEE 754 addition, multiplication, division and square root are correctly rounded lane by
 * lane, and the build has no contraction into fused multiply-adds (-ffp-contract=off), so every
 * value is bit-identical to the scalar kernel's (tests/test_many_force.c compares whole runs
 * of both versions with the scalar kernel). The scalar loop takes a pair apart within range
 * with a finite force as it is (its class), and gives the others to the scalar kernel with this
 * geometry and, in solid contact, these film terms.
 *
 * Included by many_bulk.c (the baseline instruction set: SSE2 on x86-64, plain C elsewhere) and
 * many_bulk_avx2.c (AVX2, chosen at run time where the processor has it), each of which
 * defines WETDEM_MANY_BULK_NAME.
 */
#ifndef WETDEM_MANY_BULK_H
#define WETDEM_MANY_BULK_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#include "many.h"

#if defined(__SSE2__)
#include <immintrin.h>
#endif

typedef double wetdem_v4d __attribute__((vector_size(32)));
typedef long long wetdem_v4i __attribute__((vector_size(32)));

/* All ones in every lane where b, else zeros. */
#define BULK_UNIFORM(b)                                                                            \
    ((wetdem_v4i){-(long long)(b), -(long long)(b), -(long long)(b), -(long long)(b)})
/* a in every lane (not +0 + a, which would turn -0 into +0); a is evaluated four times. */
#define BULK_SPLAT(a) ((wetdem_v4d){(a), (a), (a), (a)})
/* Lane by lane a where mask is set (all ones), else b. */
#define BULK_SELECT(mask, a, b)                                                                    \
    ((wetdem_v4d)(((mask) & (wetdem_v4i)(a)) | (~(mask) & (wetdem_v4i)(b))))

/* *a = sqrt(*a) lane by lane (through a pointer: GCC warns about 32-byte vectors passed by
 * value without AVX). */
static inline __attribute__((always_inline)) void bulk_sqrt(wetdem_v4d* a)
{
#if defined(__AVX__)
    *a = (wetdem_v4d)_mm256_sqrt_pd((__m256d)*a);
#elif defined(__SSE2__)
    union {
        wetdem_v4d v;
        __m128d h[2];
    } u = {.v = *a};
    u.h[0] = _mm_sqrt_pd(u.h[0]);
    u.h[1] = _mm_sqrt_pd(u.h[1]);
    *a = u.v;
#else
    for (int l = 0; l < 4; l++)
        (*a)[l] = sqrt((*a)[l]);
#endif
}

/* The four doubles at p[0], p[1], p[2], p[3] (records of 4 or more doubles) as the columns
 * c[0..3] of their transpose: c[k] lane l = p[l][k]. */
static inline __attribute__((always_inline)) void bulk_columns(const double* p0, const double* p1,
                                                               const double* p2, const double* p3,
                                                               wetdem_v4d c[4])
{
#if defined(__AVX__)
    __m256d a0 = _mm256_loadu_pd(p0), a1 = _mm256_loadu_pd(p1), a2 = _mm256_loadu_pd(p2),
            a3 = _mm256_loadu_pd(p3);
    __m256d t0 = _mm256_unpacklo_pd(a0, a1), t1 = _mm256_unpackhi_pd(a0, a1); /* x y / z r */
    __m256d t2 = _mm256_unpacklo_pd(a2, a3), t3 = _mm256_unpackhi_pd(a2, a3);
    c[0] = (wetdem_v4d)_mm256_permute2f128_pd(t0, t2, 0x20);
    c[1] = (wetdem_v4d)_mm256_permute2f128_pd(t1, t3, 0x20);
    c[2] = (wetdem_v4d)_mm256_permute2f128_pd(t0, t2, 0x31);
    c[3] = (wetdem_v4d)_mm256_permute2f128_pd(t1, t3, 0x31);
#else
    for (int k = 0; k < 4; k++)
        c[k] = (wetdem_v4d){p0[k], p1[k], p2[k], p3[k]};
#endif
}

/* The constants of a call, in every lane. */
struct bulk_constants {
    wetdem_v4d zero, one, film, h_min, range, sb_coef, cap_coef, tension;
    /* the film models that act at all (the same for every pair of the pass), the "nc"
       treatment of sb, and whether gaps below the film are bridges */
    wetdem_v4i sb_on, nc, cap_on, bridge_on;
};

/* Candidates list[k..k+4) (with `tail`, those of them before n, the last one repeated). With
 * `both`, sb and capillary act within the films (film > 0) and sb is zero below h_min' (the
 * masks of C are then known to be all ones, all ones, zeros and all ones). */
static inline __attribute__((always_inline)) void
bulk_four(const struct wetdem_many_bulk_in* in, const struct bulk_constants* C,
          const uint32_t* list, size_t n, size_t j_end, struct wetdem_many_bulk_out* out, size_t k,
          bool tail, bool both)
{
    const wetdem_v4i all = {-1, -1, -1, -1}, none = {0, 0, 0, 0};
    const wetdem_v4i sb_on = both ? all : C->sb_on, nc = both ? none : C->nc,
                     cap_on = both ? all : C->cap_on, bridge_on = both ? all : C->bridge_on;
    const struct wetdem_celllist_item* xr = in->xr;
    const struct wetdem_vec3(*vw)[2] = in->vw;
    const wetdem_v4d zero = C->zero, one = C->one, film = C->film;
    uint32_t q[4], i[4], j[4];
    for (int l = 0; l < 4; l++) {
        q[l] = list[!tail || k + l < n ? k + l : n - 1];
        i[l] = in->pairs[q[l]].i;
        j[l] = in->pairs[q[l]].j;
        out->j[k + l] = j[l];
        /* a second particle at or past j_end belongs to another thread, which may be updating
           it: the lane reads its first particle instead (and is not used) */
        j[l] = j[l] < j_end ? j[l] : i[l];
    }
    wetdem_v4d pi[4], pj[4], vi[4], vj[4];
    bulk_columns(&xr[i[0]].x, &xr[i[1]].x, &xr[i[2]].x, &xr[i[3]].x, pi);
    bulk_columns(&xr[j[0]].x, &xr[j[1]].x, &xr[j[2]].x, &xr[j[3]].x, pj);
    /* velocity (x, y, z) and the spin's x, which is not used */
    bulk_columns(&vw[i[0]][0].x, &vw[i[1]][0].x, &vw[i[2]][0].x, &vw[i[3]][0].x, vi);
    bulk_columns(&vw[j[0]][0].x, &vw[j[1]][0].x, &vw[j[2]][0].x, &vw[j[3]][0].x, vj);
    wetdem_v4d lim2 = {in->lim2[q[0]], in->lim2[q[1]], in->lim2[q[2]], in->lim2[q[3]]};
    /* within_reach and lean_pair_start */
    wetdem_v4d dx = pi[0] - pj[0], dy = pi[1] - pj[1], dz = pi[2] - pj[2];
    wetdem_v4d r2 = dx * dx + dy * dy + dz * dz;
    wetdem_v4d dist = r2;
    bulk_sqrt(&dist);
    wetdem_v4d gap = dist - pi[3] - pj[3];
    wetdem_v4i positive = dist > zero;
    wetdem_v4d inv = one / BULK_SELECT(positive, dist, one);
    wetdem_v4d nx = BULK_SELECT(positive, dx * inv, one);
    wetdem_v4d ny = BULK_SELECT(positive, dy * inv, zero);
    wetdem_v4d nz = BULK_SELECT(positive, dz * inv, zero);
    wetdem_v4d v_n = -((vi[0] - vj[0]) * nx + (vi[1] - vj[1]) * ny + (vi[2] - vj[2]) * nz);
    /* film_terms (thin_film_eval_gap_at, then the two laws) and lean_apart's sums */
    wetdem_v4i in_film = ~(gap > film); /* also where gap is NaN, as the scalar test */
    wetdem_v4i at_gap = gap >= C->h_min;
    wetdem_v4d h = BULK_SELECT(at_gap, gap, C->h_min);
    wetdem_v4i sb_acts = sb_on & in_film & (at_gap | nc) & (h > zero);
    wetdem_v4d bracket = one - h / film;
    /* R* = R_i R_j / (R_i + R_j): contact_reduced of finite radii, the pair constants' */
    wetdem_v4d r_eff = pi[3] * pj[3] / (pi[3] + pj[3]);
    wetdem_v4d f_sb = C->sb_coef * r_eff * r_eff * v_n / h * bracket * bracket;
    wetdem_v4i cap_acts = cap_on & (gap <= film);
    wetdem_v4d f_cap = -(C->cap_coef * r_eff * C->tension);
    f_sb = BULK_SELECT(sb_acts, f_sb, zero); /* film_terms': +0 where a law does not act */
    f_cap = BULK_SELECT(cap_acts, f_cap, zero);
    wetdem_v4d f_n = (zero + f_sb) + f_cap;
    /* the class: 0 beyond the gap test's reach, else the flags of a pair apart within its range
       with a finite force (odd, >= 9), else 1 (the scalar kernel decides) */
    wetdem_v4i near = r2 <= lim2;
    wetdem_v4i fast = ~(gap < zero) & ~(gap > C->range) & ((f_n - f_n) == zero);
    wetdem_v4i apart_flags =
        (WETDEM_MANY_ACTIVE | WETDEM_MANY_DIRTY) | (bridge_on & (gap < film) & WETDEM_MANY_BRIDGE);
    *(wetdem_v4i*)&out->cls[k] = near & ((fast & (apart_flags - 1)) | 1);
    *(wetdem_v4d*)&out->r2[k] = r2; /* (out has room for the lanes past n) */
    *(wetdem_v4d*)&out->gap[k] = gap;
    *(wetdem_v4d*)&out->n[0][k] = nx;
    *(wetdem_v4d*)&out->n[1][k] = ny;
    *(wetdem_v4d*)&out->n[2][k] = nz;
    *(wetdem_v4d*)&out->v_n[k] = v_n;
    *(wetdem_v4d*)&out->f_sb[k] = f_sb;
    *(wetdem_v4d*)&out->f_cap[k] = f_cap;
    *(wetdem_v4d*)&out->force[0][k] = zero + f_n * nx;
    *(wetdem_v4d*)&out->force[1][k] = zero + f_n * ny;
    *(wetdem_v4d*)&out->force[2][k] = zero + f_n * nz;
}

/* Candidates list[0..n) (1 <= n <= WETDEM_MANY_BULK_MAX, in any particles): their geometry,
 * and the force apart of the film models, into out's entries 0..n); those whose second
 * particle is at or past j_end are left out (their entries but j are not used). */
void WETDEM_MANY_BULK_NAME(const struct wetdem_many_bulk_in* in, const uint32_t* list, size_t n,
                           size_t j_end, struct wetdem_many_bulk_out* out)
{
    const struct bulk_constants C = {.zero = BULK_SPLAT(0.0),
                                     .one = BULK_SPLAT(1.0),
                                     .film = BULK_SPLAT(in->film),
                                     .h_min = BULK_SPLAT(in->film_h_min),
                                     .range = BULK_SPLAT(in->range),
                                     .sb_coef = BULK_SPLAT(in->sb_coef),
                                     .cap_coef = BULK_SPLAT(in->cap_coef),
                                     .tension = BULK_SPLAT(in->surface_tension),
                                     .sb_on = BULK_UNIFORM(in->sb && in->film > 0),
                                     .nc = BULK_UNIFORM(in->sb_nc),
                                     .cap_on = BULK_UNIFORM(in->capillary && in->film > 0),
                                     .bridge_on = BULK_UNIFORM(in->film > 0)};
    bool both = in->sb && in->capillary && in->film > 0 && !in->sb_nc; /* the usual case */
    size_t k = 0;
    if (both)
        for (; k + 4 <= n; k += 4)
            bulk_four(in, &C, list, n, j_end, out, k, false, true);
    else
        for (; k + 4 <= n; k += 4)
            bulk_four(in, &C, list, n, j_end, out, k, false, false);
    if (k < n)
        bulk_four(in, &C, list, n, j_end, out, k, true, false);
}

#endif

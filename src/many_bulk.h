/*
 * many_bulk.h — four candidate pairs at a time in vector units (docs/many.md, "Four pairs at a
 * time"): the gap test, the geometry and the film forces of the lean kernel, for the one-loop
 * pass of a wet packing in the common case (one material pair, periodic axes or not). Internal
 * to the many-particle engine.
 *
 * For candidate pair q = (i, j) with d = x_i - x_j (on a periodic axis of length L its minimum
 * image d - L nearbyint(d / L), celllist.h celllist_delta), exactly the operations of
 * sim_many_force.c's within_reach, lean_pair_start, film_terms and lean_apart, lane by lane:
 *   r2 = (d_x d_x + d_y d_y) + d_z d_z (the gap test: r2 <= pair_lim2),  |d| = sqrt(r2),
 *   gap = (|d| - R_i) - R_j,  n = d (1/|d|) (or (1, 0, 0) when |d| = 0),
 *   v_n = -((v_i - v_j) . n),  R* = R_i R_j / (R_i + R_j) (contact.h contact_reduced),
 *   sb (force_sb.c; Punch 2023 Eq. 7 with the corrected bracket, SPEC §6):
 *     F_sb = 6 pi mu R*^2 v_n / h [1 - h/delta]^2, h = gap, or h_min' below it with "nc",
 *   capillary (force_capillary.c; Punch 2023 Eq. 15):  F_cap = -8 pi R* sigma,
 *   each for gap <= delta and +0 where it does not act;
 *   apart: f_n = (+0 + F_sb) + F_cap,  force = +0 + f_n n.
 * The candidates in solid contact (gap < 0) are then evaluated four at a time as well
 * (bulk_contacts): lean_contact and lean_force of sim_many_force.c for
 * hertz and mindlin, lane by lane, with R*, m*, k and the damping factor from the pair
 * constants (Hertz: Nijssen 2023 Eq. 2 and the Tsuji damping, force_hertz.c; Mindlin: the
 * spring of force_mindlin.c, mindlin.h):
 *   v_t = (v_i + w_i x (-R_i n)) - (v_j + w_j x (R_j n)), less its normal part,
 *   delta = -gap,  F_el = k delta sqrt(delta),  F_d = c sqrt(sqrt(delta)) v_n,
 *   F_hertz = F_el + F_d (tsuji) or max(F_el + F_d, 0) (exact),
 *   s = the spring rotated into the tangent plane (its length kept) + dt v_s, with v_s =
 *   v_t + (v_t' - v_t), v_t' the same slip from the half-step velocities and spins (vwh),
 *   or v_s = v_t where dt = 0 (sim_many_force.c spring_velocity),
 *   k_t = 8 G* sqrt(R* delta),  gamma_t = factor sqrt(m* k_t),  F_t = -k_t s - gamma_t v_t,
 *   where |F_t| > mu |F_el|: F_t scaled to mu |F_el|, s = -(F_t + gamma_t v_t) / k_t,
 *   torques -R_i n x F_t and -R_j n x F_t,  F = F_t + (the normal terms in model order) n.
 * A lane whose force or torques are not finite is left to the scalar kernel (class 1, spring
 * not stored), which reports it.
 * IEEE 754 addition, multiplication, division and square root are correctly rounded lane by
 * lane, and the build has no contraction into fused multiply-adds (-ffp-contract=off), so every
 * value is bit-identical to the scalar kernel's (tests/test_many_force.c compares whole runs
 * of every version the processor runs with the scalar kernel). The scalar loop takes a pair
 * apart within range with a finite force as it is (its class), and gives the others to the
 * scalar kernel with this geometry and, in solid contact, these film terms.
 *
 * Included by many_bulk.c (the baseline instruction set: SSE2 on x86-64, plain C elsewhere),
 * many_bulk_avx2.c (AVX2) and many_bulk_avx512.c (the same in the AVX-512 encoding), the last
 * two chosen at run time where the processor has them, each of which defines
 * WETDEM_MANY_BULK_NAME and WETDEM_MANY_BULK_WALLS_NAME.
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

/* The next loop over the four lanes written out (GCC would keep it a loop at -O2). */
#define BULK_UNROLL _Pragma("GCC unroll 4")
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

/* *d less len times the nearest integer (ties to even, the current rounding mode's, as
 * nearbyint) to *d / len, lane by lane: celllist_delta's minimum image on a periodic axis. */
static inline __attribute__((always_inline)) void bulk_minimum_image(wetdem_v4d* d, double len)
{
    wetdem_v4d l = BULK_SPLAT(len), r = *d / l;
#if defined(__AVX__)
    r = (wetdem_v4d)_mm256_round_pd((__m256d)r, _MM_FROUND_CUR_DIRECTION | _MM_FROUND_NO_EXC);
#else
    for (int k = 0; k < 4; k++)
        r[k] = nearbyint(r[k]);
#endif
    *d -= l * r;
}

/* The lanes of v at the entries idx[0..3] of the array a. */
#define BULK_GATHER(a, idx)                                                                        \
    ((wetdem_v4d){(a)[(idx)[0]], (a)[(idx)[1]], (a)[(idx)[2]], (a)[(idx)[3]]})

/* All ones in the lanes where a is finite (a - a is 0 there, NaN elsewhere); a is evaluated
 * twice. (A macro: GCC warns about 32-byte vectors returned by value without AVX.) */
#define BULK_FINITE(a) (((a) - (a)) == (wetdem_v4d){0, 0, 0, 0})

/* The constants of a call, in every lane. */
struct bulk_constants {
    wetdem_v4d zero, one, film, h_min, range, sb_coef, cap_coef, tension;
    /* the film models that act at all (the same for every pair of the pass) and the "nc"
       treatment of sb */
    wetdem_v4i sb_on, nc, cap_on;
};

/* The film models of a call, when known at compile time: BULK_BOTH, sb and capillary act within
 * the films (film > 0) and sb is zero below h_min' (the masks of C are then all ones, all ones,
 * zeros and all ones); BULK_DRY, neither acts (their terms are +0, as film_terms leaves
 * them). */
enum bulk_films { BULK_ANY, BULK_BOTH, BULK_DRY };

/* film_terms of sim_many_force.c lane by lane, at gap [m] with R* = r_eff [m] and v_n [m/s]
 * (thin_film_eval_gap_at, then the sb and capillary laws; force_sb.c, force_capillary.c):
 * *f_sb and *f_cap, +0 where a law does not act. */
static inline __attribute__((always_inline)) void
bulk_film_terms(const struct bulk_constants* C, enum bulk_films films, const wetdem_v4d* gap_in,
                const wetdem_v4d* r_eff_in, const wetdem_v4d* v_n_in, wetdem_v4d* f_sb,
                wetdem_v4d* f_cap)
{
    /* (through pointers: GCC notes an ABI change for 32-byte vectors passed by value) */
    const wetdem_v4d gap = *gap_in, r_eff = *r_eff_in, v_n = *v_n_in;
    const wetdem_v4i all = {-1, -1, -1, -1}, none = {0, 0, 0, 0};
    bool both = films == BULK_BOTH;
    const wetdem_v4i sb_on = both ? all : C->sb_on, nc = both ? none : C->nc,
                     cap_on = both ? all : C->cap_on;
    const wetdem_v4d zero = C->zero, film = C->film;
    wetdem_v4i in_film = ~(gap > film); /* also where gap is NaN, as the scalar test */
    wetdem_v4i at_gap = gap >= C->h_min;
    wetdem_v4d h = BULK_SELECT(at_gap, gap, C->h_min);
    wetdem_v4i sb_acts = sb_on & in_film & (at_gap | nc) & (h > zero);
    wetdem_v4d bracket = C->one - h / film;
    wetdem_v4d sb = C->sb_coef * r_eff * r_eff * v_n / h * bracket * bracket;
    wetdem_v4i cap_acts = cap_on & (gap <= film);
    wetdem_v4d cap = -(C->cap_coef * r_eff * C->tension);
    *f_sb = BULK_SELECT(sb_acts, sb, zero);
    *f_cap = BULK_SELECT(cap_acts, cap, zero);
}

/* Candidates list[k..k+4) (with `tail`, those of them before n, the last one repeated). */
static inline __attribute__((always_inline)) void
bulk_four(const struct wetdem_many_bulk_in* in, const struct bulk_constants* C,
          const uint32_t* list, size_t n, size_t j_end, struct wetdem_many_bulk_out* out, size_t k,
          bool tail, enum bulk_films films, bool periodic, uint32_t* at, size_t* n_at)
{
    bool dry = films == BULK_DRY;
    const struct wetdem_celllist_item* xr = in->xr;
    const struct wetdem_vec3(*vw)[2] = in->vw;
    const wetdem_v4d zero = C->zero, one = C->one;
    uint32_t q[4], i[4], j[4];
    wetdem_v4i own; /* all ones in the lanes of this thread's pairs (and, with tail, before n) */
    BULK_UNROLL
    for (int l = 0; l < 4; l++)
        q[l] = list[!tail || k + l < n ? k + l : n - 1];
#if defined(__SSE2__)
    if (!tail && j_end <= UINT32_MAX) { /* the same, four lanes at once */
        __m128i p01 = _mm_unpacklo_epi64(_mm_loadl_epi64((const __m128i*)&in->pairs[q[0]]),
                                         _mm_loadl_epi64((const __m128i*)&in->pairs[q[1]]));
        __m128i p23 = _mm_unpacklo_epi64(_mm_loadl_epi64((const __m128i*)&in->pairs[q[2]]),
                                         _mm_loadl_epi64((const __m128i*)&in->pairs[q[3]]));
        __m128i iv = _mm_castps_si128(
            _mm_shuffle_ps(_mm_castsi128_ps(p01), _mm_castsi128_ps(p23), _MM_SHUFFLE(2, 0, 2, 0)));
        __m128i jv = _mm_castps_si128(
            _mm_shuffle_ps(_mm_castsi128_ps(p01), _mm_castsi128_ps(p23), _MM_SHUFFLE(3, 1, 3, 1)));
        _mm_storeu_si128((__m128i*)(void*)&out->i[k], iv);
        _mm_storeu_si128((__m128i*)(void*)&out->j[k], jv);
        /* j < j_end unsigned: a signed comparison of both less 2^31 */
        const __m128i bias = _mm_set1_epi32(INT32_MIN);
        __m128i mine = _mm_cmplt_epi32(_mm_xor_si128(jv, bias),
                                       _mm_xor_si128(_mm_set1_epi32((int)(uint32_t)j_end), bias));
        __m128i js = _mm_or_si128(_mm_and_si128(mine, jv), _mm_andnot_si128(mine, iv));
        _mm_storeu_si128((__m128i*)(void*)i, iv);
        _mm_storeu_si128((__m128i*)(void*)j, js);
#if defined(__AVX2__) /* (sign-extended in a register: two halves stored and read back as
                          one vector would stall the load on its two stores) */
        own = (wetdem_v4i)_mm256_cvtepi32_epi64(mine);
#else
        union {
            wetdem_v4i v;
            __m128i h[2];
        } u = {.h = {_mm_unpacklo_epi32(mine, mine), _mm_unpackhi_epi32(mine, mine)}};
        own = u.v;
#endif
    } else
#endif
    {
        BULK_UNROLL
        for (int l = 0; l < 4; l++) {
            i[l] = in->pairs[q[l]].i;
            j[l] = in->pairs[q[l]].j;
            out->i[k + l] = i[l];
            out->j[k + l] = j[l];
            /* a second particle at or past j_end belongs to another thread, which may be
               updating it: the lane reads its first particle instead (and is not used) */
            own[l] = -(long long)(j[l] < j_end && (!tail || k + l < n));
            j[l] = j[l] < j_end ? j[l] : i[l];
        }
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
    if (periodic) { /* (some axis is: a constant of the loop) */
        if (in->axis_periodic[0])
            bulk_minimum_image(&dx, in->box_len[0]);
        if (in->axis_periodic[1])
            bulk_minimum_image(&dy, in->box_len[1]);
        if (in->axis_periodic[2])
            bulk_minimum_image(&dz, in->box_len[2]);
    }
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
    /* film_terms and lean_apart's sums */
    wetdem_v4d f_sb = zero, f_cap = zero;
    if (!dry) {
        /* R* = R_i R_j / (R_i + R_j): contact_reduced of finite radii, the pair constants' */
        wetdem_v4d r_eff = pi[3] * pj[3] / (pi[3] + pj[3]);
        bulk_film_terms(C, films, &gap, &r_eff, &v_n, &f_sb, &f_cap);
    }
    wetdem_v4d f_n = (zero + f_sb) + f_cap;
    /* the class: 0 beyond the gap test's reach, else the flags of a pair apart within its range
       with a finite force (ACTIVE | DIRTY, 9), else 1 (the scalar kernel decides) */
    wetdem_v4i near = r2 <= lim2;
    wetdem_v4i fast = ~(gap < zero) & ~(gap > C->range) & ((f_n - f_n) == zero);
    const long long apart_flags = WETDEM_MANY_ACTIVE | WETDEM_MANY_DIRTY;
    *(wetdem_v4i*)&out->cls[k] = near & ((fast & (apart_flags - 1)) | 1);
    /* this thread's lanes in solid contact (class 1 with gap < 0) onto the list for
       bulk_contacts, without a branch */
    wetdem_v4i contact = near & (gap < zero) & own;
#if defined(__AVX__)
    { /* their offsets from a table by the 4-bit mask, four written (within at's room: *n_at
         <= k), `count` of them kept */
        int mask = _mm256_movemask_pd((__m256d)contact);
        _mm_storeu_si128(
            (__m128i*)(void*)(at + *n_at),
            _mm_add_epi32(
                _mm_set1_epi32((int)k),
                _mm_loadu_si128((const __m128i*)(const void*)wetdem_many_mask_lanes[mask])));
        *n_at += wetdem_many_mask_count[mask];
    }
#else
    BULK_UNROLL
    for (int l = 0; l < 4; l++) {
        at[*n_at] = (uint32_t)(k + l);
        *n_at += (size_t)(contact[l] & 1);
    }
#endif
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
    for (int c = 0; c < 3; c++) /* (+0 apart: the results' sums add it without a test) */
        *(wetdem_v4d*)&out->torque_i[c][k] = zero;
    if (in->budget) { /* the contact terms +0 apart, so the budget reads them without a test */
        *(wetdem_v4d*)&out->hertz[k] = zero;
        for (int c = 0; c < 3; c++)
            *(wetdem_v4d*)&out->f_tan[c][k] = *(wetdem_v4d*)&out->torque_j[c][k] = zero;
    }
}

/* What the contact core (bulk_lean_force) reads of four lanes, and what it gives. */
struct bulk_lanes {
    wetdem_v4d n[3], gap, v_n; /* unit normal (into i), gap [m], normal velocity [m/s] */
    wetdem_v4d r_i, r_j;       /* radii [m] (r_j unused for a wall) */
    wetdem_v4d r_eff, m_eff;   /* R* [m], m* [kg] */
    wetdem_v4d k, damping;     /* Hertz stiffness factor, damping factor (models.h) */
    wetdem_v4d v_t[3];         /* tangential velocity [m/s] (with mindlin) */
    wetdem_v4d v_s[3];         /* what the spring advances with [m/s] (spring_velocity) */
    wetdem_v4d s[3];           /* the Mindlin spring [m] (with mindlin): in, then out */
    wetdem_v4d term[3];        /* sb and capillary terms in term[1], term[2] [N] */
    /* out: the force on i [N], the torques on i and j [N m], all ones where all are finite;
       mindlin's part of the force, f_tan [N] */
    wetdem_v4d force[3], ti[3], tj[3], f_tan[3];
    wetdem_v4i finite;
};

/* The tangential part of the contact points' relative velocity, contact.h contact_pair_slip
 * (or contact_wall_slip, `wall`: b0 and b1 unused) lane by lane, from the columns of the
 * velocity-and-spin records of i (a0: v_x v_y v_z w_x, a1: v_z w_x w_y w_z) and j (b0, b1). */
static inline __attribute__((always_inline)) void
bulk_slip(const wetdem_v4d a0[4], const wetdem_v4d a1[4], const wetdem_v4d b0[4],
          const wetdem_v4d b1[4], const wetdem_v4d n[3], const wetdem_v4d* r_i,
          const wetdem_v4d* r_j, bool wall, wetdem_v4d out[3])
{
    wetdem_v4d mra = -*r_i, a[3] = {n[0] * mra, n[1] * mra, n[2] * mra}; /* n (-R_i) */
    wetdem_v4d rel[3] = {a0[0] + (a1[2] * a[2] - a1[3] * a[1]),
                         a0[1] + (a1[3] * a[0] - a1[1] * a[2]),
                         a0[2] + (a1[1] * a[1] - a1[2] * a[0])};
    if (!wall) {
        wetdem_v4d b[3] = {n[0] * *r_j, n[1] * *r_j, n[2] * *r_j}; /* n R_j */
        rel[0] = rel[0] - (b0[0] + (b1[2] * b[2] - b1[3] * b[1]));
        rel[1] = rel[1] - (b0[1] + (b1[3] * b[0] - b1[1] * b[2]));
        rel[2] = rel[2] - (b0[2] + (b1[1] * b[1] - b1[2] * b[0]));
    }
    wetdem_v4d rn = -(rel[0] * n[0] + rel[1] * n[1] + rel[2] * n[2]);
    for (int c = 0; c < 3; c++)
        out[c] = rel[c] + rn * n[c];
}

/* The spring's velocity L->v_s from L->v_t and the slip at the half-step velocities (the
 * columns of struct wetdem_many vwh: a0, a1 of i, b0, b1 of j): sim_many_force.c
 * spring_velocity, v_t + (half - v_t), or v_t where the pass advances nothing (dt = 0). */
static inline __attribute__((always_inline)) void
bulk_spring_velocity(const struct wetdem_many_bulk_in* in, const wetdem_v4d a0[4],
                     const wetdem_v4d a1[4], const wetdem_v4d b0[4], const wetdem_v4d b1[4],
                     bool wall, struct bulk_lanes* L)
{
    if (!(in->dt > 0.0)) {
        for (int c = 0; c < 3; c++)
            L->v_s[c] = L->v_t[c];
        return;
    }
    wetdem_v4d half[3];
    bulk_slip(a0, a1, b0, b1, L->n, &L->r_i, &L->r_j, wall, half);
    for (int c = 0; c < 3; c++)
        L->v_s[c] = L->v_t[c] + (half[c] - L->v_t[c]);
}

/* The normal terms of L in model order into *f_n (chosen by value, not indexed: an indexed
 * member would keep all of L in memory). */
static inline __attribute__((always_inline)) void
bulk_normal_sum(const struct wetdem_many_bulk_in* in, const struct bulk_constants* C,
                const struct bulk_lanes* L, wetdem_v4d* f_n)
{
    wetdem_v4d sum = C->zero;
    for (int m = 0; m < in->n_normal; m++)
        sum += in->normal[m] == 0 ? L->term[0] : in->normal[m] == 1 ? L->term[1] : L->term[2];
    *f_n = sum;
}

/* lean_force of sim_many_force.c lane by lane (this file's header) for four lanes in solid
 * contact (gap < 0): hertz, mindlin and the normal terms. `wall`: no torque on j. (A wall
 * apart gets the film terms alone: bulk_walls_four.) */
static inline __attribute__((always_inline)) void
bulk_lean_force(const struct wetdem_many_bulk_in* in, const struct bulk_constants* C,
                struct bulk_lanes* L, bool wall)
{
    const wetdem_v4d zero = C->zero;
    wetdem_v4d overlap = -L->gap, root = overlap;
    bulk_sqrt(&root);
    wetdem_v4d f_el = L->k * overlap * root; /* hertz_elastic_k */
    L->term[0] = zero;
    if (in->hertz_form >= 0) { /* hertz_total of hertz_damping_from */
        wetdem_v4d quarter = root;
        bulk_sqrt(&quarter);
        wetdem_v4d sum = f_el + L->damping * quarter * L->v_n;
        L->term[0] = in->hertz_form == 1 ? sum : BULK_SELECT(sum > zero, sum, zero);
    }
    wetdem_v4d ft[3] = {zero, zero, zero};
    for (int c = 0; c < 3; c++)
        L->ti[c] = L->tj[c] = zero;
    if (in->mindlin) {
        const wetdem_v4d *n = L->n, *v_t = L->v_t;
        wetdem_v4d* s = L->s;
        /* mindlin_spring: the spring rotated into the plane (rotate_into_plane), advanced */
        wetdem_v4d len = s[0] * s[0] + s[1] * s[1] + s[2] * s[2];
        bulk_sqrt(&len);
        wetdem_v4d sn = -(s[0] * n[0] + s[1] * n[1] + s[2] * n[2]);
        wetdem_v4d p[3] = {s[0] + sn * n[0], s[1] + sn * n[1], s[2] + sn * n[2]};
        wetdem_v4d plen = p[0] * p[0] + p[1] * p[1] + p[2] * p[2];
        bulk_sqrt(&plen);
        wetdem_v4i some = plen > zero;
        wetdem_v4d ratio = len / BULK_SELECT(some, plen, C->one);
        const wetdem_v4d dt = BULK_SPLAT(in->dt);
        for (int c = 0; c < 3; c++)
            s[c] = BULK_SELECT(some, p[c] * ratio, zero) + dt * L->v_s[c];
        wetdem_v4d k_t = L->r_eff * overlap;
        bulk_sqrt(&k_t);
        k_t = BULK_SPLAT(8.0 * in->g_star) * k_t; /* tangential_stiffness */
        wetdem_v4d gamma_t = L->m_eff * k_t;
        bulk_sqrt(&gamma_t);
        gamma_t = BULK_SPLAT(in->tangential_factor) * gamma_t; /* tangential_damping */
        wetdem_v4d mk = -k_t, mg = -gamma_t;
        for (int c = 0; c < 3; c++)
            ft[c] = s[c] * mk + mg * v_t[c];
        wetdem_v4d f_total = ft[0] * ft[0] + ft[1] * ft[1] + ft[2] * ft[2];
        bulk_sqrt(&f_total);
        const wetdem_v4i magnitude = {INT64_MAX, INT64_MAX, INT64_MAX, INT64_MAX};
        wetdem_v4d f_max = BULK_SPLAT(in->mu) * (wetdem_v4d)((wetdem_v4i)f_el & magnitude);
        wetdem_v4i slide = f_total > f_max;
        if (slide[0] | slide[1] | slide[2] | slide[3]) { /* capped, the spring set to match */
            wetdem_v4d cap = f_max / BULK_SELECT(slide, f_total, C->one);
            wetdem_v4i stiff = k_t > zero;
            wetdem_v4d inv_k = BULK_SPLAT(-1.0) / BULK_SELECT(stiff, k_t, C->one);
            for (int c = 0; c < 3; c++) {
                wetdem_v4d capped = ft[c] * cap;
                wetdem_v4d back = BULK_SELECT(stiff, (capped + gamma_t * v_t[c]) * inv_k, zero);
                ft[c] = BULK_SELECT(slide, capped, ft[c]);
                s[c] = BULK_SELECT(slide, back, s[c]);
            }
        }
        /* the torques, -R n x F_t (lean_force: from zero, so +0 + ...) */
        wetdem_v4d cr[3] = {n[1] * ft[2] - n[2] * ft[1], n[2] * ft[0] - n[0] * ft[2],
                            n[0] * ft[1] - n[1] * ft[0]};
        wetdem_v4d mri = -L->r_i, mrj = -L->r_j;
        for (int c = 0; c < 3; c++) {
            L->ti[c] = zero + mri * cr[c];
            if (!wall)
                L->tj[c] = zero + mrj * cr[c];
            ft[c] = zero + ft[c];
        }
    }
    wetdem_v4d f_n;
    bulk_normal_sum(in, C, L, &f_n);
    wetdem_v4i finite = BULK_FINITE(f_n);
    if (in->budget) /* (only the budget reads it) */
        for (int c = 0; c < 3; c++)
            L->f_tan[c] = ft[c];
    for (int c = 0; c < 3; c++) {
        L->force[c] = ft[c] + f_n * L->n[c];
        finite &= BULK_FINITE(L->force[c]) & BULK_FINITE(L->ti[c]) & BULK_FINITE(L->tj[c]);
    }
    L->finite = finite;
}

/* The out entries at[0..4) (candidates list[at[l]]) in solid contact, with the geometry and
 * film terms bulk_four gave them: lean_contact, then lean_force (bulk_lean_force); each lane
 * with a finite result gets its force, torques and flags (cls) and its spring stored, the
 * others keep class 1. Lanes may repeat an entry (they compute and store the same). */
static inline __attribute__((always_inline)) void
bulk_contacts(const struct wetdem_many_bulk_in* in, const struct bulk_constants* C,
              const uint32_t* list, const uint32_t at[4], struct wetdem_many_bulk_out* out,
              bool films)
{
    const wetdem_v4d zero = C->zero;
    uint32_t q[4], i[4], j[4];
    BULK_UNROLL
    for (int l = 0; l < 4; l++) {
        q[l] = list[at[l]];
        i[l] = in->pairs[q[l]].i;
        j[l] = out->j[at[l]];
    }
    struct bulk_lanes L; /* (set field by field: an initializer would zero all of it first) */
    for (int c = 0; c < 3; c++)
        L.n[c] = BULK_GATHER(out->n[c], at);
    L.gap = BULK_GATHER(out->gap, at);
    L.v_n = BULK_GATHER(out->v_n, at);
    L.r_i = (wetdem_v4d){in->xr[i[0]].r, in->xr[i[1]].r, in->xr[i[2]].r, in->xr[i[3]].r};
    L.r_j = (wetdem_v4d){in->xr[j[0]].r, in->xr[j[1]].r, in->xr[j[2]].r, in->xr[j[3]].r};
    wetdem_v4d pc[4]; /* the pair constants: R*, m*, k, damping factor */
    bulk_columns(in->cache[q[0]], in->cache[q[1]], in->cache[q[2]], in->cache[q[3]], pc);
    L.r_eff = pc[0];
    L.m_eff = pc[1];
    L.k = pc[2];
    L.damping = pc[3];
    L.term[1] = films ? BULK_GATHER(out->f_sb, at) : zero;
    L.term[2] = films ? BULK_GATHER(out->f_cap, at) : zero;
    if (in->mindlin) {
        /* the contact points' velocities (velocity, spin: columns at the record's start and at
           its third double) and the tangential velocity, vec3_reject */
        const struct wetdem_vec3(*vw)[2] = in->vw;
        wetdem_v4d a0[4], a1[4], b0[4], b1[4]; /* v_x v_y v_z w_x, v_z w_x w_y w_z */
        bulk_columns(&vw[i[0]][0].x, &vw[i[1]][0].x, &vw[i[2]][0].x, &vw[i[3]][0].x, a0);
        bulk_columns(&vw[i[0]][0].z, &vw[i[1]][0].z, &vw[i[2]][0].z, &vw[i[3]][0].z, a1);
        bulk_columns(&vw[j[0]][0].x, &vw[j[1]][0].x, &vw[j[2]][0].x, &vw[j[3]][0].x, b0);
        bulk_columns(&vw[j[0]][0].z, &vw[j[1]][0].z, &vw[j[2]][0].z, &vw[j[3]][0].z, b1);
        bulk_slip(a0, a1, b0, b1, L.n, &L.r_i, &L.r_j, false, L.v_t);
        if (in->dt > 0.0) { /* the half-step records (struct wetdem_many vwh) */
            const struct wetdem_vec3(*h)[2] = in->vwh;
            bulk_columns(&h[i[0]][0].x, &h[i[1]][0].x, &h[i[2]][0].x, &h[i[3]][0].x, a0);
            bulk_columns(&h[i[0]][0].z, &h[i[1]][0].z, &h[i[2]][0].z, &h[i[3]][0].z, a1);
            bulk_columns(&h[j[0]][0].x, &h[j[1]][0].x, &h[j[2]][0].x, &h[j[3]][0].x, b0);
            bulk_columns(&h[j[0]][0].z, &h[j[1]][0].z, &h[j[2]][0].z, &h[j[3]][0].z, b1);
        }
        bulk_spring_velocity(in, a0, a1, b0, b1, false, &L);
        for (int c = 0; c < 3; c++) {
            L.s[c] = (wetdem_v4d){in->history[q[0] * in->len + in->spring_off + c],
                                  in->history[q[1] * in->len + in->spring_off + c],
                                  in->history[q[2] * in->len + in->spring_off + c],
                                  in->history[q[3] * in->len + in->spring_off + c]};
        }
    }
    bulk_lean_force(in, C, &L, false);
    const long long flags =
        WETDEM_MANY_ACTIVE | WETDEM_MANY_DIRTY | WETDEM_MANY_CONTACT | WETDEM_MANY_SPRING;
    for (int l = 0; l < 4; l++) {
        if (!L.finite[l])
            continue; /* the scalar kernel evaluates it again, from the unchanged spring */
        size_t k = at[l];
        out->cls[k] = flags;
        for (int c = 0; c < 3; c++) {
            out->force[c][k] = L.force[c][l];
            out->torque_i[c][k] = L.ti[c][l];
            out->torque_j[c][k] = L.tj[c][l];
            if (in->mindlin)
                in->history[q[l] * in->len + in->spring_off + c] = L.s[c][l];
        }
    }
    for (int l = 0; in->budget && l < 4; l++) /* (the test once for the group without one) */
        if (L.finite[l]) {
            out->hertz[at[l]] = L.term[0][l];
            for (int c = 0; c < 3; c++)
                out->f_tan[c][at[l]] = L.f_tan[c][l];
        }
}

/* The film models of a call's input (enum bulk_films). */
static inline enum bulk_films bulk_films_of(const struct wetdem_many_bulk_in* in)
{
    if (in->sb && in->capillary && in->film > 0 && !in->sb_nc) /* the usual case */
        return BULK_BOTH;
    return wetdem_many_bulk_films(in) ? BULK_ANY : BULK_DRY;
}

/* The constants of a call (struct bulk_constants). */
static inline __attribute__((always_inline)) struct bulk_constants
bulk_constants_of(const struct wetdem_many_bulk_in* in)
{
    return (struct bulk_constants){.zero = BULK_SPLAT(0.0),
                                   .one = BULK_SPLAT(1.0),
                                   .film = BULK_SPLAT(in->film),
                                   .h_min = BULK_SPLAT(in->film_h_min),
                                   .range = BULK_SPLAT(in->range),
                                   .sb_coef = BULK_SPLAT(in->sb_coef),
                                   .cap_coef = BULK_SPLAT(in->cap_coef),
                                   .tension = BULK_SPLAT(in->surface_tension),
                                   .sb_on = BULK_UNIFORM(in->sb && in->film > 0),
                                   .nc = BULK_UNIFORM(in->sb_nc),
                                   .cap_on = BULK_UNIFORM(in->capillary && in->film > 0)};
}

/* bulk_four over list[0..n), each kind of films in its own loop (its masks constants there),
 * `periodic` (some axis of in is) a constant of the loops. */
static inline __attribute__((always_inline)) void
bulk_groups(const struct wetdem_many_bulk_in* in, const struct bulk_constants* C,
            const uint32_t* list, size_t n, size_t j_end, struct wetdem_many_bulk_out* out,
            enum bulk_films films, bool periodic, uint32_t* at, size_t* n_at)
{
    size_t k = 0;
    if (films == BULK_BOTH)
        for (; k + 4 <= n; k += 4)
            bulk_four(in, C, list, n, j_end, out, k, false, BULK_BOTH, periodic, at, n_at);
    else if (films == BULK_DRY)
        for (; k + 4 <= n; k += 4)
            bulk_four(in, C, list, n, j_end, out, k, false, BULK_DRY, periodic, at, n_at);
    else
        for (; k + 4 <= n; k += 4)
            bulk_four(in, C, list, n, j_end, out, k, false, BULK_ANY, periodic, at, n_at);
    if (k < n)
        bulk_four(in, C, list, n, j_end, out, k, true, films == BULK_DRY ? BULK_DRY : BULK_ANY,
                  periodic, at, n_at);
}

/* Candidates list[0..n) (1 <= n <= WETDEM_MANY_BULK_MAX, in any particles): their geometry,
 * and the force apart of the film models, into out's entries 0..n); those whose second
 * particle is at or past j_end are left out (their entries but j are not used). Then those in
 * solid contact (bulk_contacts). */
void WETDEM_MANY_BULK_NAME(const struct wetdem_many_bulk_in* in, const uint32_t* list, size_t n,
                           size_t j_end, struct wetdem_many_bulk_out* out)
{
    const struct bulk_constants C = bulk_constants_of(in);
    enum bulk_films films = bulk_films_of(in);
    /* the entries in solid contact (class 1 with gap < 0, of this thread's particles), listed
       by bulk_four, for bulk_contacts four at a time, the last group filled up with its last
       entry */
    uint32_t at[WETDEM_MANY_BULK_MAX + 3];
    size_t n_at = 0;
    if (in->axis_periodic[0] || in->axis_periodic[1] || in->axis_periodic[2])
        bulk_groups(in, &C, list, n, j_end, out, films, true, at, &n_at);
    else
        bulk_groups(in, &C, list, n, j_end, out, films, false, at, &n_at);
    if (!n_at)
        return;
    for (size_t r = n_at; r % 4; r++)
        at[r] = at[n_at - 1];
    for (size_t g = 0; g < n_at; g += 4)
        if (films != BULK_DRY)
            bulk_contacts(in, &C, list, at + g, out, true);
        else
            bulk_contacts(in, &C, list, at + g, out, false);
}

/* Particle-wall entries e = idx[k..k+4) within the range at gap[e] (eval_walls_of's; with
 * `tail`, those before n, the last one repeated): lean_wall and lean_force lane by lane (walls
 * apart get the film terms only and a zero spring), with R* = R, m* = m_eff and the Hertz
 * constants of the particle's radius and mass; `touching`: all of them at gap < 0, else none
 * (then only what lean_force gives a pair apart: the film terms, +0 torques, a zero spring).
 * Lanes with a finite result get their flags (and their spring stored), the others class 1. */
static inline __attribute__((always_inline)) void
bulk_walls_four(const struct wetdem_many_bulk_in* in, const struct bulk_constants* C,
                const uint32_t* part, const unsigned char* wall, const double* gap,
                const uint32_t* idx, size_t n, struct wetdem_many_bulk_out* out, size_t k,
                bool tail, enum bulk_films films, bool touching)
{
    const wetdem_v4d zero = C->zero;
    uint32_t i[4], w[4], e[4];
    BULK_UNROLL
    for (int l = 0; l < 4; l++) {
        e[l] = idx[!tail || k + l < n ? k + l : n - 1];
        i[l] = part[e[l]];
        w[l] = wall[e[l]];
    }
    const struct wetdem_celllist_item* xr = in->xr;
    const struct wetdem_wall* W = in->walls;
    struct bulk_lanes L;
    L.n[0] = (wetdem_v4d){W[w[0]].normal.x, W[w[1]].normal.x, W[w[2]].normal.x, W[w[3]].normal.x};
    L.n[1] = (wetdem_v4d){W[w[0]].normal.y, W[w[1]].normal.y, W[w[2]].normal.y, W[w[3]].normal.y};
    L.n[2] = (wetdem_v4d){W[w[0]].normal.z, W[w[1]].normal.z, W[w[2]].normal.z, W[w[3]].normal.z};
    const wetdem_v4d* nv = L.n;
    L.gap = BULK_GATHER(gap, e);
    const wetdem_v4d radius = {xr[i[0]].r, xr[i[1]].r, xr[i[2]].r, xr[i[3]].r};
    const struct wetdem_vec3(*vw)[2] = in->vw;
    wetdem_v4d a0[4], a1[4]; /* v_x v_y v_z w_x, v_z w_x w_y w_z */
    bulk_columns(&vw[i[0]][0].x, &vw[i[1]][0].x, &vw[i[2]][0].x, &vw[i[3]][0].x, a0);
    L.v_n = -(a0[0] * nv[0] + a0[1] * nv[1] + a0[2] * nv[2]);
    L.r_i = L.r_eff = radius;
    L.r_j = zero;
    size_t spring[4];
    BULK_UNROLL
    for (int l = 0; l < 4; l++)
        spring[l] = (i[l] * in->n_walls + w[l]) * in->len + in->spring_off;
    L.term[1] = L.term[2] = zero;
    if (films != BULK_DRY)
        bulk_film_terms(C, films, &L.gap, &L.r_eff, &L.v_n, &L.term[1], &L.term[2]);
    if (touching) {
        L.m_eff = BULK_GATHER(in->m_eff, i);
        wetdem_v4d root = radius;
        bulk_sqrt(&root);
        L.k = BULK_SPLAT((4.0 / 3.0) * in->e_star) * root; /* hertz_stiffness */
        L.damping = zero;
        if (in->hertz_form >= 0) { /* hertz_damping_factor */
            wetdem_v4d mk = L.m_eff * L.k;
            bulk_sqrt(&mk);
            L.damping = BULK_SPLAT(in->hertz_coef) * mk;
        }
        if (in->mindlin) {
            bulk_columns(&vw[i[0]][0].z, &vw[i[1]][0].z, &vw[i[2]][0].z, &vw[i[3]][0].z, a1);
            bulk_slip(a0, a1, a0, a1, nv, &radius, &radius, true, L.v_t);
            if (in->dt > 0.0) { /* the half-step records (struct wetdem_many vwh) */
                const struct wetdem_vec3(*h)[2] = in->vwh;
                bulk_columns(&h[i[0]][0].x, &h[i[1]][0].x, &h[i[2]][0].x, &h[i[3]][0].x, a0);
                bulk_columns(&h[i[0]][0].z, &h[i[1]][0].z, &h[i[2]][0].z, &h[i[3]][0].z, a1);
            }
            bulk_spring_velocity(in, a0, a1, a0, a1, true, &L);
            for (int c = 0; c < 3; c++) {
                L.s[c] =
                    (wetdem_v4d){in->wall_history[spring[0] + c], in->wall_history[spring[1] + c],
                                 in->wall_history[spring[2] + c], in->wall_history[spring[3] + c]};
            }
        }
        bulk_lean_force(in, C, &L, true);
    } else { /* what lean_force gives a pair apart: no contact terms, +0 torques */
        L.term[0] = zero;
        wetdem_v4d f_n;
        bulk_normal_sum(in, C, &L, &f_n);
        L.finite = BULK_FINITE(f_n);
        for (int c = 0; c < 3; c++) {
            L.force[c] = zero + f_n * nv[c];
            L.ti[c] = L.s[c] = zero;
            L.finite &= BULK_FINITE(L.force[c]);
        }
    }
    const long long flags = (WETDEM_MANY_ACTIVE | WETDEM_MANY_DIRTY) |
                            (touching ? WETDEM_MANY_CONTACT | WETDEM_MANY_SPRING : 0);
    wetdem_v4i cls = (L.finite & (flags - 1)) | 1;
    BULK_UNROLL
    for (int l = 0; l < 4; l++) { /* (lanes that repeat an entry store the same) */
        out->cls[e[l]] = cls[l];
        for (int c = 0; c < 3; c++) {
            out->force[c][e[l]] = L.force[c][l];
            out->torque_i[c][e[l]] = L.ti[c][l];
        }
    }
    for (int l = 0; in->mindlin && l < 4; l++)
        if (L.finite[l])
            for (int c = 0; c < 3; c++)
                in->wall_history[spring[l] + c] = L.s[c][l];
    for (int l = 0; in->budget && l < 4; l++) { /* each model's terms (+0 where it does not act) */
        out->hertz[e[l]] = L.term[0][l];
        out->f_sb[e[l]] = L.term[1][l];
        out->f_cap[e[l]] = L.term[2][l];
        for (int c = 0; c < 3; c++)
            out->f_tan[c][e[l]] = touching ? L.f_tan[c][l] : 0.0;
    }
}

/* The entries idx[0..n) (touching or not) four at a time, each kind of films in its own loop
 * (its masks constants there), as for the pairs. */
static inline __attribute__((always_inline)) void
bulk_walls_of(const struct wetdem_many_bulk_in* in, const struct bulk_constants* C,
              const uint32_t* part, const unsigned char* wall, const double* gap,
              const uint32_t* idx, size_t n, struct wetdem_many_bulk_out* out, bool touching)
{
    enum bulk_films films = bulk_films_of(in);
    size_t k = 0;
    if (films == BULK_BOTH)
        for (; k + 4 <= n; k += 4)
            bulk_walls_four(in, C, part, wall, gap, idx, n, out, k, false, BULK_BOTH, touching);
    else if (films == BULK_DRY)
        for (; k + 4 <= n; k += 4)
            bulk_walls_four(in, C, part, wall, gap, idx, n, out, k, false, BULK_DRY, touching);
    else
        for (; k + 4 <= n; k += 4)
            bulk_walls_four(in, C, part, wall, gap, idx, n, out, k, false, BULK_ANY, touching);
    if (k < n)
        bulk_walls_four(in, C, part, wall, gap, idx, n, out, k, true, films, touching);
}

/* Particle-wall pairs (part[e], wall[e]) within the range at gap[e], e < n (1 <= n <=
 * WETDEM_MANY_BULK_MAX), into out's entries 0..n): those in solid contact (gap < 0) four at a
 * time, then the others (apart within the films, or a gap that is not a number: what
 * lean_force does with them), without the contact terms (bulk_walls_four). */
void WETDEM_MANY_BULK_WALLS_NAME(const struct wetdem_many_bulk_in* in, const uint32_t* part,
                                 const unsigned char* wall, const double* gap, size_t n,
                                 struct wetdem_many_bulk_out* out)
{
    const struct bulk_constants C = bulk_constants_of(in);
    uint32_t idx[2][WETDEM_MANY_BULK_MAX];
    size_t count[2] = {0, 0};        /* touching, apart */
    for (size_t e = 0; e < n; e++) { /* (without a branch on the gap) */
        size_t apart = !(gap[e] < 0);
        idx[0][count[0]] = idx[1][count[1]] = (uint32_t)e;
        count[0] += 1 - apart;
        count[1] += apart;
    }
    if (count[0])
        bulk_walls_of(in, &C, part, wall, gap, idx[0], count[0], out, true);
    if (count[1])
        bulk_walls_of(in, &C, part, wall, gap, idx[1], count[1], out, false);
}

#endif

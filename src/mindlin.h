/*
 * mindlin.h — the arithmetic of the Mindlin tangential spring (force_mindlin.c, whose header
 * gives the model: Mindlin 1949, Di Renzo & Di Maio 2004, docs/derivations/contact.md Sec. 2),
 * inline so that the model and the many-particle lean kernel (sim_many_force.c) share one
 * definition and compute bit-identical forces.
 */
#ifndef WETDEM_MINDLIN_H
#define WETDEM_MINDLIN_H

#include <math.h>

#include "vec3.h"

/* Mindlin tangential stiffness 8 G* sqrt(R* delta) [N/m]. */
static inline double tangential_stiffness(double g_star, double r_eff, double overlap)
{
    return 8.0 * g_star * sqrt(r_eff * overlap);
}

/* Tangential stiffness beside a linear normal spring k [N/m]: (4 G* / E*) k [N/m], the ratio
 * k_t / k_n = 8 G* a / (2 E* a) of Hertz-Mindlin (a the contact radius) applied to k. */
static inline double linear_tangential_stiffness(double g_star, double e_star, double k)
{
    return 4.0 * g_star / e_star * k;
}

/* Tsuji-form tangential damping coefficient -2 sqrt(5/6) beta sqrt(m* k_t) [kg/s], from the
 * factor -2 sqrt(5/6) beta (the product is formed in that order either way). */
static inline double tangential_damping(double k_t, double m_eff, double factor)
{
    return factor * sqrt(m_eff * k_t);
}

/* The spring s rotated rigidly into the plane normal to n, keeping its length. */
static inline struct wetdem_vec3 rotate_into_plane(struct wetdem_vec3 s, struct wetdem_vec3 n)
{
    double len = vec3_norm(s);
    struct wetdem_vec3 p = vec3_reject(s, n);
    double plen = vec3_norm(p);
    if (!(plen > 0.0))
        return vec3(0, 0, 0);
    return vec3_scale(p, len / plen);
}

static inline void store_spring(double* spring, struct wetdem_vec3 s)
{
    spring[0] = s.x;
    spring[1] = s.y;
    spring[2] = s.z;
}

/* The spring update and tangential force on i [N] with the tangential stiffness k_t [N/m]
 * given (mindlin_spring: the Hertzian one; force_mindlin.c: the linear one beside hooke), from
 * the contact quantities it reads: unit normal n, tangential velocity v_t [m/s] (the
 * dashpot's), the velocity v_s the spring advances with over dt [m/s] (the engines' mean of
 * the slip over dt: struct wetdem_contact dv_t_spring), dt [s], m* [kg],
 * overlap [m], f_limit [N], mu [-], the damping factor [-]; spring: the 3 doubles of history
 * [m]; slip (NULL: not wanted): |F_t| before the cap minus the cap [N] when overlap > 0 (struct
 * wetdem_pair_force slip), else left as it is. k_t is read only when overlap > 0. */
static inline __attribute__((always_inline)) struct wetdem_vec3
mindlin_spring_k(struct wetdem_vec3 n, struct wetdem_vec3 v_t, struct wetdem_vec3 v_s, double dt,
                 double k_t, double m_eff, double overlap, double f_limit, double mu,
                 double damping_factor, double* spring, double* slip)
{
    if (!(overlap > 0.0)) {
        store_spring(spring, vec3(0, 0, 0));
        return vec3(0, 0, 0);
    }
    struct wetdem_vec3 s = rotate_into_plane(vec3(spring[0], spring[1], spring[2]), n);
    s = vec3_axpy(s, dt, v_s);
    double gamma_t = tangential_damping(k_t, m_eff, damping_factor);
    struct wetdem_vec3 ft = vec3_axpy(vec3_scale(s, -k_t), -gamma_t, v_t);
    double f_total = vec3_norm(ft), f_max = mu * fabs(f_limit);
    if (slip)
        *slip = f_total - f_max;
    if (f_total > f_max) { /* sliding: total capped, spring set so that it gives the cap */
        ft = vec3_scale(ft, f_max / f_total);
        s = k_t > 0.0 ? vec3_scale(vec3_axpy(ft, gamma_t, v_t), -1.0 / k_t) : vec3(0, 0, 0);
    }
    store_spring(spring, s);
    return ft;
}

/* The spring update and tangential force on i [N] (wetdem_force_mindlin_update_with) with the
 * Hertzian k_t = 8 G* sqrt(R* delta) from G* [Pa] and R* [m]; the rest as mindlin_spring_k. */
static inline __attribute__((always_inline)) struct wetdem_vec3
mindlin_spring(struct wetdem_vec3 n, struct wetdem_vec3 v_t, struct wetdem_vec3 v_s, double dt,
               double g_star, double r_eff, double m_eff, double overlap, double f_limit, double mu,
               double damping_factor, double* spring, double* slip)
{
    double k_t = overlap > 0.0 ? tangential_stiffness(g_star, r_eff, overlap) : 0.0;
    return mindlin_spring_k(n, v_t, v_s, dt, k_t, m_eff, overlap, f_limit, mu, damping_factor,
                            spring, slip);
}

#endif

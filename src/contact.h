/*
 * contact.h — pair reductions and contact geometry shared by contact.c
 * (wetdem_contact_from_particles, wetdem_contact_with_wall) and the many-particle engine
 * (sim_many_force.c), so both build a contact with the same arithmetic:
 * R* = R_i R_j/(R_i + R_j) and m* = m_i m_j/(m_i + m_j), where an infinite radius or mass
 * (wall, fixed particle) leaves the other one.
 */
#ifndef WETDEM_CONTACT_H
#define WETDEM_CONTACT_H

#include <math.h>
#include <stdbool.h>

#include "vec3.h"
#include "wetdem.h"

/* a b/(a + b), with an infinite argument giving the other one. */
static inline double contact_reduced(double a, double b)
{
    if (isinf(a))
        return b;
    if (isinf(b))
        return a;
    return a * b / (a + b);
}

/* Whether every component of a pair force is finite. */
static inline bool contact_force_is_finite(const struct wetdem_pair_force* f)
{
    return isfinite(f->f_normal) && vec3_is_finite(f->f_tan) && vec3_is_finite(f->torque_i) &&
           vec3_is_finite(f->torque_j);
}

/* Mass of p as a pair sees it [kg]: infinite when the particle is held fixed. */
static inline double contact_effective_mass(const struct wetdem_particle* p)
{
    return p->is_fixed ? INFINITY : p->mass;
}

/* The geometry and kinematics of the contact of a with b, d = x_a - x_b (minimum image where
 * the caller needs it): normal (b to a), gap, radii, R*, m*, v_n, v_t; the mixed properties
 * are the caller's; dv_t_spring = 0. */
/* Tangential part of the surface velocity of sphere a (radius r_a, velocity v_a, spin w_a)
 * relative to sphere b at their contact, n the unit normal from b to a [m/s]:
 * (v_a + w_a x (-r_a n)) - (v_b + w_b x (r_b n)), less its part along n. */
static inline struct wetdem_vec3 contact_pair_slip(struct wetdem_vec3 n, double r_a,
                                                   struct wetdem_vec3 v_a, struct wetdem_vec3 w_a,
                                                   double r_b, struct wetdem_vec3 v_b,
                                                   struct wetdem_vec3 w_b)
{
    struct wetdem_vec3 va = vec3_add(v_a, vec3_cross(w_a, vec3_scale(n, -r_a)));
    struct wetdem_vec3 vb = vec3_add(v_b, vec3_cross(w_b, vec3_scale(n, r_b)));
    return vec3_reject(vec3_sub(va, vb), n);
}

/* The same against a wall that does not move (normal n into the side of a). */
static inline struct wetdem_vec3 contact_wall_slip(struct wetdem_vec3 n, double r_a,
                                                   struct wetdem_vec3 v_a, struct wetdem_vec3 w_a)
{
    return vec3_reject(vec3_add(v_a, vec3_cross(w_a, vec3_scale(n, -r_a))), n);
}

/* c->dv_t_spring of the fixed-step engines (midpoint rule, docs/engines.md): the slip of the
 * half-step velocities and spins v_i, w_i (and v_j, w_j of a sphere j) at c's normal, less
 * c->v_t [m/s]. */
static inline struct wetdem_vec3
contact_half_step_dv(const struct wetdem_contact* c, struct wetdem_vec3 v_i, struct wetdem_vec3 w_i,
                     struct wetdem_vec3 v_j, struct wetdem_vec3 w_j)
{
    struct wetdem_vec3 half =
        c->is_wall ? contact_wall_slip(c->normal, c->radius_i, v_i, w_i)
                   : contact_pair_slip(c->normal, c->radius_i, v_i, w_i, c->radius_j, v_j, w_j);
    return vec3_sub(half, c->v_t);
}

static inline void contact_pair_geometry(struct wetdem_contact* c, const struct wetdem_particle* a,
                                         const struct wetdem_particle* b, struct wetdem_vec3 d)
{
    double dist = vec3_norm(d);
    c->is_wall = false;
    c->normal = dist > 0 ? vec3_scale(d, 1.0 / dist) : vec3(1, 0, 0);
    c->gap = dist - a->radius - b->radius;
    c->radius_i = a->radius;
    c->radius_j = b->radius;
    c->r_eff = contact_reduced(a->radius, b->radius);
    c->m_eff = contact_reduced(contact_effective_mass(a), contact_effective_mass(b));
    struct wetdem_vec3 n = c->normal;
    c->v_n = -vec3_dot(vec3_sub(a->vel, b->vel), n);
    c->v_t = contact_pair_slip(n, a->radius, a->vel, a->omega, b->radius, b->vel, b->omega);
    c->dv_t_spring = vec3(0, 0, 0);
}

/* The same for particle a and the plane through `point` with unit `normal` (into the side of
 * a): R* = R_a, m* = m_a, a wall does not move. */
static inline void contact_wall_geometry(struct wetdem_contact* c, const struct wetdem_particle* a,
                                         struct wetdem_vec3 point, struct wetdem_vec3 normal)
{
    double dist = vec3_dot(vec3_sub(a->pos, point), normal);
    c->is_wall = true;
    c->normal = normal;
    c->gap = dist - a->radius;
    c->radius_i = a->radius;
    c->radius_j = INFINITY;
    c->r_eff = a->radius;
    c->m_eff = contact_effective_mass(a);
    c->v_n = -vec3_dot(a->vel, normal);
    c->v_t = contact_wall_slip(normal, a->radius, a->vel, a->omega);
    c->dv_t_spring = vec3(0, 0, 0);
}

#endif

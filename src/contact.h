/*
 * contact.h — pair reductions shared by contact.c (wetdem_contact_from_particles) and the
 * many-particle fast path (sim_many_force.c), so both build a contact with the same arithmetic:
 * R* = R_i R_j/(R_i + R_j) and m* = m_i m_j/(m_i + m_j), where an infinite radius or mass
 * (wall, fixed particle) leaves the other one.
 */
#ifndef WETDEM_CONTACT_H
#define WETDEM_CONTACT_H

#include <math.h>

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

/* Mass of p as a pair sees it [kg]: infinite when the particle is held fixed. */
static inline double contact_effective_mass(const struct wetdem_particle* p)
{
    return p->is_fixed ? INFINITY : p->mass;
}

#endif

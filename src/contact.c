/*
 * contact.c — builds struct wetdem_contact for a particle pair or a particle–wall pair:
 * geometry once per pair (SPEC §2), read-only for every model.
 * Prefix override: wetdem_contact_* and wetdem_pair_force_*.
 *
 *   n    = (x_i - x_j)/|x_i - x_j|           unit normal from j to i
 *   h    = |x_i - x_j| - R_i - R_j           gap [m], < 0 overlap
 *   v_n  = -(v_i - v_j) . n                  approach speed [m/s], > 0 approaching
 *   v_s  = (v_i + w_i x (-R_i n)) - (v_j + w_j x (R_j n))   surface velocity of i rel. to j
 *   v_t  = v_s - (v_s . n) n                 tangential part [m/s]
 * Mixed properties: 1/E* = (1-nu_i^2)/E_i + (1-nu_j^2)/E_j; 1/G* = (2-nu_i)/G_i +
 * (2-nu_j)/G_j with G = E/(2(1+nu)) (Di Renzo & Di Maio 2004); e_dry, mu and sigma are the
 * means of the two materials (Nijssen Eq. 3 for sigma); delta_ij = delta_i + delta_j.
 * A plane wall is a sphere of infinite radius and mass: R* = R_i, m* = m_i.
 * A fixed particle has infinite mass: m* = m of the other.
 * h_min, linear_stiffness and dt are left 0: the engines fill them in.
 */
#include <math.h>

#include "contact.h"
#include "vec3.h"
#include "wetdem.h"

static void mix_properties(struct wetdem_contact* c, const struct wetdem_material* a,
                           const struct wetdem_material* b, const struct wetdem_fluid* fluid)
{
    double ga = a->youngs_modulus / (2.0 * (1.0 + a->poisson_ratio));
    double gb = b->youngs_modulus / (2.0 * (1.0 + b->poisson_ratio));
    c->e_star = 1.0 / ((1.0 - a->poisson_ratio * a->poisson_ratio) / a->youngs_modulus +
                       (1.0 - b->poisson_ratio * b->poisson_ratio) / b->youngs_modulus);
    c->g_star = 1.0 / ((2.0 - a->poisson_ratio) / ga + (2.0 - b->poisson_ratio) / gb);
    c->restitution = 0.5 * (a->restitution + b->restitution);
    c->friction_dry = 0.5 * (a->friction_dry + b->friction_dry);
    c->friction_lub = 0.5 * (a->friction_lub + b->friction_lub);
    c->roughness = 0.5 * (a->roughness + b->roughness);
    c->film = a->film + b->film;
    c->viscosity = fluid ? fluid->viscosity : 0.0;
    c->surface_tension = fluid ? fluid->surface_tension : 0.0;
    c->h_min = 0.0;
    c->linear_stiffness = 0.0;
    c->dt = 0.0;
}

void wetdem_contact_from_particles(struct wetdem_contact* c, const struct wetdem_particle* a,
                                   const struct wetdem_material* ma,
                                   const struct wetdem_particle* b,
                                   const struct wetdem_material* mb,
                                   const struct wetdem_fluid* fluid)
{
    contact_pair_geometry(c, a, b, vec3_sub(a->pos, b->pos));
    mix_properties(c, ma, mb, fluid);
}

void wetdem_contact_with_wall(struct wetdem_contact* c, const struct wetdem_particle* a,
                              const struct wetdem_material* ma, struct wetdem_vec3 point,
                              struct wetdem_vec3 normal, const struct wetdem_material* mw,
                              const struct wetdem_fluid* fluid)
{
    contact_wall_geometry(c, a, point, normal);
    mix_properties(c, ma, mw, fluid);
}

struct wetdem_contact wetdem_contact_swapped(const struct wetdem_contact* c)
{
    struct wetdem_contact s = *c;
    s.i = c->j;
    s.j = c->i;
    s.normal = vec3_neg(c->normal);
    s.v_t = vec3_neg(c->v_t);
    s.dv_t_spring = vec3_neg(c->dv_t_spring);
    s.radius_i = c->radius_j;
    s.radius_j = c->radius_i;
    return s;
}

void wetdem_pair_force_add_tangential(struct wetdem_pair_force* out, const struct wetdem_contact* c,
                                      struct wetdem_vec3 ft)
{
    out->f_tan = vec3_add(out->f_tan, ft);
    struct wetdem_vec3 nxf = vec3_cross(c->normal, ft);
    out->torque_i = vec3_axpy(out->torque_i, -c->radius_i, nxf);
    if (!c->is_wall)
        out->torque_j = vec3_axpy(out->torque_j, -c->radius_j, nxf);
}

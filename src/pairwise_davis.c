/*
 * pairwise_davis.c — the three-sphere configuration of Davis (2023) Sec. III, Fig. 3 and
 * Table I, built from its dimensionless groups (and the two-sphere oblique collision as the
 * same set-up without sphere 3).
 *
 * Equal spheres of radius 2a (a = reduced radius), mass 2m (m = reduced mass),
 * I = 16 m a^2 / 5. Sphere 0 (Davis's sphere 1) moves along +x (alpha = 0) with speed
 * v_10 = v_n0 / cos(beta) and its films just touch those of sphere 1 (Davis's 2):
 * h_12,0 = delta_12, theta_12,0 = alpha - beta = -beta. Sphere 2 (Davis's 3) rests at gap
 * h_23,0 and angle theta_23,0 from sphere 1. Spheres 1 and 2 are at rest and nothing spins.
 *     St_n = m v_n0 / (6 pi mu a^2)      ->  m = 6 pi mu a^2 St_n / v_n0
 *     Ca   = 3 mu a v_n0 / (sigma delta_12)  ->  sigma = 3 mu a v_n0 / (delta_12 Ca)
 *            (Table I prints 3 mu v_n0 / (sigma delta_12), which is not dimensionless; the
 *            text below Eq. 33 has the factor a, and 4/Ca is then the capillary term of
 *            Eq. 28.)
 *     h_a  = delta_12 / 4a,  h_m = h_min / delta_12,  d_23 = delta_23 / delta_12,
 *     d_13 = delta_13 / delta_12,  h_23,0 / delta_12.
 * The single films follow from the three pair sums: delta_1 = delta_12 (1 + d_13 - d_23)/2,
 * delta_2 = delta_12 (1 + d_23 - d_13)/2, delta_3 = delta_12 (d_23 + d_13 - 1)/2, all >= 0.
 * The scales a, mu and v_n0 only fix the units: every result in t-hat, t* or e_ij,w depends
 * on the groups alone.
 */
#include <math.h>
#include <stddef.h>
#include <stdio.h>

#include "pairwise.h"
#include "status.h"

#define DEG (M_PI / 180.0)

static const struct wetdem_param_desc davis_desc[] = {
    {"n_spheres", "-", "2: striker and target only (oblique two-sphere collision); 3: Fig. 3.",
     offsetof(struct wetdem_pairwise_davis, n_spheres), 3, 2, 3, false, false, NULL, true},
    {"stokes", "-", "Normal Stokes number St_n = m v_n0 / (6 pi mu a^2).",
     offsetof(struct wetdem_pairwise_davis, stokes), 2, 0, INFINITY, true, true, NULL, false},
    {"capillary", "-",
     "Capillary number Ca = 3 mu a v_n0 / (sigma delta_12); 0 (or inf in "
     "the C API) means no capillary force (Ca -> infinity).",
     offsetof(struct wetdem_pairwise_davis, capillary), 1000, 0, INFINITY, false, true, NULL,
     false},
    {"film_ratio", "-", "Film thickness h_a = delta_12 / 4a (film over sphere diameter).",
     offsetof(struct wetdem_pairwise_davis, film_ratio), 0.01, 0, 0.5, true, true, NULL, false},
    {"hmin_ratio", "-", "Minimum separation h_m = h_min / delta_12.",
     offsetof(struct wetdem_pairwise_davis, hmin_ratio), 0.01, 0, 1, true, true, NULL, false},
    {"angle_deg", "deg",
     "Impact angle beta between the striker's velocity and the line of "
     "centres (0 = head-on).",
     offsetof(struct wetdem_pairwise_davis, angle_deg), 30, 0, 90, false, true, NULL, false},
    {"d23", "-", "delta_23 / delta_12.", offsetof(struct wetdem_pairwise_davis, d23), 1, 0,
     INFINITY, true, true, NULL, false},
    {"d13", "-", "delta_13 / delta_12.", offsetof(struct wetdem_pairwise_davis, d13), 1, 0,
     INFINITY, true, true, NULL, false},
    {"h23", "-", "Initial gap of the target doublet h_23,0 / delta_12 (>= hmin_ratio).",
     offsetof(struct wetdem_pairwise_davis, h23), 1, 0, INFINITY, true, true, NULL, false},
    {"theta23_deg", "deg", "Angle of the target doublet's line of centres from the x axis.",
     offsetof(struct wetdem_pairwise_davis, theta23_deg), 0, -180, 180, false, false, NULL, false},
    {"restitution", "-", "Dry coefficient of restitution e_dry.",
     offsetof(struct wetdem_pairwise_davis, restitution), 1, 0, 1, true, false, NULL, false},
    {"friction", "-", "Friction coefficient mu_f of the contact impulse.",
     offsetof(struct wetdem_pairwise_davis, friction), 0, 0, INFINITY, false, true, NULL, false},
    {"t_star_end", "-", "Run length in t* = v_10 t / 4a.",
     offsetof(struct wetdem_pairwise_davis, t_star_end), 20, 0, INFINITY, true, true, NULL, false},
    {"a", "m", "Reduced radius a (sphere radius 2a); a unit only.",
     offsetof(struct wetdem_pairwise_davis, a), 1e-3, 0, INFINITY, true, true, NULL, false},
    {"viscosity", "Pa s", "Film viscosity mu; a unit only.",
     offsetof(struct wetdem_pairwise_davis, viscosity), 1, 0, INFINITY, true, true, NULL, false},
    {"speed_n0", "m/s", "Normal impact speed v_n0; a unit only.",
     offsetof(struct wetdem_pairwise_davis, speed_n0), 1, 0, INFINITY, true, true, NULL, false},
    {0},
};

const struct wetdem_param_desc* wetdem_pairwise_davis_params(void)
{
    return davis_desc;
}

void wetdem_pairwise_davis_init(struct wetdem_pairwise_davis* d)
{
    wetdem_param_init_defaults(davis_desc, d);
}

/* Range checks of every field, then the cross-field rules. */
static int davis_validate(const struct wetdem_pairwise_davis* d, char* msg, size_t n)
{
    for (const struct wetdem_param_desc* p = davis_desc; p->name; p++) {
        double v = *(const double*)((const char*)d + p->offset);
        if (p->offset == offsetof(struct wetdem_pairwise_davis, capillary) && v == INFINITY)
            continue;
        if (wetdem_param_validate(p, v, msg, n) != WETDEM_OK)
            return WETDEM_ERR_INVALID;
    }
    /* h_min / (a_i + a_j) = h_m delta_12 / 4a = h_m h_a for the equal spheres */
    if (!(d->film_ratio * d->hmin_ratio >= WETDEM_PAIRWISE_MIN_HMIN_RATIO))
        return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID,
                                  "film_ratio = %g with hmin_ratio = %g: h_min is %g of the "
                                  "spheres' diameter sum; need film_ratio x hmin_ratio >= %g "
                                  "(film_ratio >= %g at this hmin_ratio)",
                                  d->film_ratio, d->hmin_ratio, d->film_ratio * d->hmin_ratio,
                                  WETDEM_PAIRWISE_MIN_HMIN_RATIO,
                                  WETDEM_PAIRWISE_MIN_HMIN_RATIO / d->hmin_ratio);
    if (d->n_spheres == 3) {
        if (d->d23 + d->d13 < 1.0 || d->d13 - d->d23 < -1.0 || d->d23 - d->d13 < -1.0)
            return wetdem_status_fail(
                msg, n, WETDEM_ERR_INVALID,
                "d23 = %g, d13 = %g: the single films would be negative; need "
                "d23 + d13 >= 1 and |d23 - d13| <= 1",
                d->d23, d->d13);
        if (d->h23 < d->hmin_ratio)
            return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID,
                                      "h23 = %g: must be >= hmin_ratio = %g", d->h23,
                                      d->hmin_ratio);
    }
    return WETDEM_OK;
}

int wetdem_pairwise_davis_config(const struct wetdem_pairwise_davis* d,
                                 struct wetdem_pairwise_config* cfg, char* msg, size_t msg_size)
{
    int st = davis_validate(d, msg, msg_size);
    if (st != WETDEM_OK)
        return st;
    double a = d->a, mu = d->viscosity, vn0 = d->speed_n0, beta = d->angle_deg * DEG;
    double m = 6.0 * M_PI * mu * a * a * d->stokes / vn0;
    double delta12 = 4.0 * a * d->film_ratio;
    double v10 = vn0 / cos(beta);
    wetdem_pairwise_config_init(cfg);
    cfg->n_spheres = (size_t)d->n_spheres;
    cfg->viscosity = mu;
    bool no_cap = isinf(d->capillary) || d->capillary == 0.0;
    cfg->surface_tension = no_cap ? 0.0 : 3.0 * mu * a * vn0 / (delta12 * d->capillary);
    cfg->h_min = d->hmin_ratio * delta12;
    cfg->restitution = d->restitution;
    cfg->friction = d->friction;
    cfg->t_end = d->t_star_end * 4.0 * a / v10;
    bool three = cfg->n_spheres == 3;
    double film[3] = {0.5 * delta12, 0.5 * delta12, 0.0};
    if (three) {
        film[0] = 0.5 * delta12 * (1.0 + d->d13 - d->d23);
        film[1] = 0.5 * delta12 * (1.0 + d->d23 - d->d13);
        film[2] = 0.5 * delta12 * (d->d23 + d->d13 - 1.0);
    }
    for (size_t i = 0; i < cfg->n_spheres; i++)
        cfg->spheres[i] =
            (struct wetdem_pairwise_sphere){.radius = 2.0 * a, .mass = 2.0 * m, .film = film[i]};
    double r12 = 4.0 * a + delta12, th12 = -beta;
    cfg->spheres[0].vx = v10;
    cfg->spheres[1].x = r12 * cos(th12);
    cfg->spheres[1].y = r12 * sin(th12);
    if (three) {
        double r23 = 4.0 * a + d->h23 * delta12, th23 = d->theta23_deg * DEG;
        cfg->spheres[2].x = cfg->spheres[1].x + r23 * cos(th23);
        cfg->spheres[2].y = cfg->spheres[1].y + r23 * sin(th23);
    }
    return wetdem_pairwise_config_validate(cfg, msg, msg_size);
}

/*
 * pairwise_state.c — the tracked-pair tree of the pairwise engine and the conversion between
 * its state vector and the spheres (Davis 2023 Eqs. 34-38 and Appendix B, generalised from
 * three spheres to a tree over n <= WETDEM_PAIRWISE_MAX_SPHERES spheres).
 *
 * Tracked pairs form a spanning tree of the spheres (n - 1 pairs). Sphere 0 is followed in
 * fixed coordinates (Eqs. 34-36, 39); walking the tree from it gives every other sphere:
 *     x_j = x_i + r_ij e_ij,  e_ij = (cos theta_ij, sin theta_ij),  r_ij = a_i + a_j + h_ij
 *                                                                     (Eqs. 37-38)
 *     v_j = v_i - (v_ij,n e_ij + v_ij,t t_ij),  t_ij = (-sin theta_ij, cos theta_ij),
 *     v_ij,t = -r_ij Omega_ij                                        (below Eq. 9)
 *     w_j = (v_ij,omega - a_i w_i) / a_j                             (below Eq. 39)
 * A pair not in the tree is computed from geometry: r_ik = sum of the tree vectors on the path
 * from i to k, v_ik = v_i - v_k (Appendix B, Eqs. B1-B9; B6 corrected to use v_13,y).
 * Positions and velocities are formed relative to sphere 0 first so that differences of
 * neighbouring spheres do not lose digits to the absolute position.
 *
 * Tree choice (Sec. V, partner changes): Kruskal over all pairs ordered by (a pair that must
 * be tracked now, e.g. the one in contact; pairs held at h_min; pairs whose films overlap;
 * pairs tracked before; smallest gap; pair index), so the tree changes only when a pair that
 * interacts is not tracked, e.g. when sphere 1 leaves sphere 2 while its films overlap those
 * of sphere 3.
 */
#include <math.h>
#include <string.h>

#include "pairwise.h"

void wetdem_pairwise_state_system(const struct wetdem_pairwise_config* cfg,
                                  struct wetdem_pairwise_system* sys)
{
    memset(sys, 0, sizeof *sys);
    sys->n = cfg->n_spheres;
    for (size_t i = 0; i < sys->n; i++) {
        const struct wetdem_pairwise_sphere* s = &cfg->spheres[i];
        sys->a[i] = s->radius;
        sys->m[i] = s->mass;
        sys->inertia[i] = 0.4 * s->mass * s->radius * s->radius;
    }
    size_t p = 0;
    for (size_t i = 0; i < sys->n; i++)
        for (size_t j = i + 1; j < sys->n; j++, p++) {
            sys->pi[p] = i;
            sys->pj[p] = j;
            sys->a_eff[p] = sys->a[i] * sys->a[j] / (sys->a[i] + sys->a[j]);
            sys->m_eff[p] = sys->m[i] * sys->m[j] / (sys->m[i] + sys->m[j]);
            sys->delta[p] = cfg->spheres[i].film + cfg->spheres[j].film;
        }
    sys->n_pairs = p;
    sys->mu = cfg->viscosity;
    sys->sigma = cfg->surface_tension;
    sys->h_min = cfg->h_min;
    sys->e_dry = cfg->restitution;
    sys->mu_f = cfg->friction;
    sys->gx = cfg->gravity_x;
    sys->gy = cfg->gravity_y;
}

/* Sort key of pair p for the tree: smaller is preferred. */
static void tree_key(const struct wetdem_pairwise_mode* old, size_t force, size_t p,
                     const double* gaps, int* cls, int* was, double* gap)
{
    if (p == force)
        *cls = 0;
    else if (old && old->resting[p])
        *cls = 1;
    else if (old && old->film[p])
        *cls = 2;
    else
        *cls = 3;
    *was = (old && old->edge_of_pair[p] >= 0) ? 0 : 1;
    *gap = gaps[p];
}

static bool key_less(const struct wetdem_pairwise_mode* old, size_t force, const double* gaps,
                     size_t p, size_t q)
{
    int cp, cq, wp, wq;
    double gp, gq;
    tree_key(old, force, p, gaps, &cp, &wp, &gp);
    tree_key(old, force, q, gaps, &cq, &wq, &gq);
    if (cp != cq)
        return cp < cq;
    if (wp != wq)
        return wp < wq;
    if (gp != gq)
        return gp < gq;
    return p < q;
}

static size_t uf_find(size_t* parent, size_t i)
{
    while (parent[i] != i)
        i = parent[i] = parent[parent[i]];
    return i;
}

/* Breadth-first order of the spheres from sphere 0 along the tree edges. */
static void tree_order(const struct wetdem_pairwise_system* sys, struct wetdem_pairwise_mode* md)
{
    bool seen[PW_NMAX] = {false};
    size_t head = 0, tail = 1;
    md->order[0] = 0;
    seen[0] = true;
    while (head < tail) {
        size_t s = md->order[head++];
        for (size_t e = 0; e + 1 < sys->n; e++) {
            size_t p = md->edge[e];
            size_t other = sys->pi[p] == s ? sys->pj[p] : (sys->pj[p] == s ? sys->pi[p] : s);
            if (other == s || seen[other])
                continue;
            seen[other] = true;
            md->via[tail] = e;
            md->order[tail++] = other;
        }
    }
}

void wetdem_pairwise_state_tree(const struct wetdem_pairwise_system* sys, const double* gaps,
                                const struct wetdem_pairwise_mode* old, size_t force,
                                struct wetdem_pairwise_mode* md)
{
    size_t idx[PW_PMAX], parent[PW_NMAX];
    for (size_t p = 0; p < sys->n_pairs; p++) {
        idx[p] = p;
        md->edge_of_pair[p] = -1;
    }
    for (size_t a = 1; a < sys->n_pairs; a++) /* insertion sort: at most 28 pairs */
        for (size_t b = a; b > 0 && key_less(old, force, gaps, idx[b], idx[b - 1]); b--) {
            size_t t = idx[b];
            idx[b] = idx[b - 1];
            idx[b - 1] = t;
        }
    for (size_t i = 0; i < sys->n; i++)
        parent[i] = i;
    size_t n_edges = 0;
    for (size_t a = 0; a < sys->n_pairs && n_edges + 1 < sys->n; a++) {
        size_t p = idx[a];
        size_t ri = uf_find(parent, sys->pi[p]), rj = uf_find(parent, sys->pj[p]);
        if (ri == rj)
            continue;
        parent[ri] = rj;
        md->edge[n_edges] = p;
        n_edges++;
    }
    /* edges in pair order, so the state layout does not depend on the sort */
    for (size_t a = 1; a < n_edges; a++)
        for (size_t b = a; b > 0 && md->edge[b] < md->edge[b - 1]; b--) {
            size_t t = md->edge[b];
            md->edge[b] = md->edge[b - 1];
            md->edge[b - 1] = t;
        }
    for (size_t e = 0; e < n_edges; e++)
        md->edge_of_pair[md->edge[e]] = (int)e;
    tree_order(sys, md);
}

/* Sphere `to` from sphere `from` across tracked pair p with its five variables v. */
static void walk_edge(const struct wetdem_pairwise_system* sys, size_t p, const double* v,
                      size_t from, size_t to, struct wetdem_pairwise_kin* k)
{
    size_t i = sys->pi[p], j = sys->pj[p];
    double r = sys->a[i] + sys->a[j] + v[PW_H];
    double c = cos(v[PW_THETA]), s = sin(v[PW_THETA]);
    double v_t = -r * v[PW_OMEGA];
    /* v_i - v_j = v_n e + v_t t */
    double rel_x = v[PW_VN] * c - v_t * s, rel_y = v[PW_VN] * s + v_t * c;
    double sign = (from == i) ? 1.0 : -1.0; /* x_j - x_i = +r e */
    k->dx[to] = k->dx[from] + sign * r * c;
    k->dy[to] = k->dy[from] + sign * r * s;
    k->ux[to] = k->ux[from] - sign * rel_x;
    k->uy[to] = k->uy[from] - sign * rel_y;
    k->w[to] = (v[PW_VW] - sys->a[from] * k->w[from]) / sys->a[to];
}

/* Pair p of k from the relative sphere fields (Appendix B). */
static void pair_from_spheres(const struct wetdem_pairwise_system* sys, size_t p,
                              struct wetdem_pairwise_kin* k)
{
    size_t i = sys->pi[p], j = sys->pj[p];
    double rx = k->dx[j] - k->dx[i], ry = k->dy[j] - k->dy[i];
    double r = hypot(rx, ry);
    double c = rx / r, s = ry / r;
    double vx = k->ux[i] - k->ux[j], vy = k->uy[i] - k->uy[j];
    k->r[p] = r;
    k->h[p] = r - sys->a[i] - sys->a[j]; /* B3 */
    k->theta[p] = atan2(ry, rx);         /* B2 */
    k->c[p] = c;
    k->s[p] = s;
    k->v_n[p] = vx * c + vy * s;                           /* B6 */
    k->omega_lc[p] = -(-vx * s + vy * c) / r;              /* B7-B8 */
    k->v_w[p] = sys->a[i] * k->w[i] + sys->a[j] * k->w[j]; /* B9 */
}

bool wetdem_pairwise_state_kin(const struct wetdem_pairwise_system* sys,
                               const struct wetdem_pairwise_mode* md, const double* y,
                               struct wetdem_pairwise_kin* k)
{
    k->dx[0] = k->dy[0] = k->ux[0] = k->uy[0] = 0.0;
    k->w[0] = y[4];
    for (size_t a = 1; a < sys->n; a++) {
        size_t s = md->order[a], e = md->via[a], p = md->edge[e];
        const double* v = y + PW_ANCHOR_LEN + PW_EDGE_LEN * e;
        size_t from = (sys->pi[p] == s) ? sys->pj[p] : sys->pi[p];
        walk_edge(sys, p, v, from, s, k);
    }
    for (size_t i = 0; i < sys->n; i++) {
        k->x[i] = y[0] + k->dx[i];
        k->y[i] = y[1] + k->dy[i];
        k->vx[i] = y[2] + k->ux[i];
        k->vy[i] = y[3] + k->uy[i];
    }
    for (size_t p = 0; p < sys->n_pairs; p++) {
        int e = md->edge_of_pair[p];
        if (e < 0) {
            pair_from_spheres(sys, p, k);
            continue;
        }
        const double* v = y + PW_ANCHOR_LEN + PW_EDGE_LEN * (size_t)e;
        k->h[p] = v[PW_H];
        k->r[p] = sys->a[sys->pi[p]] + sys->a[sys->pj[p]] + v[PW_H];
        k->theta[p] = v[PW_THETA];
        k->c[p] = cos(v[PW_THETA]);
        k->s[p] = sin(v[PW_THETA]);
        k->v_n[p] = v[PW_VN];
        k->omega_lc[p] = v[PW_OMEGA];
        k->v_w[p] = v[PW_VW];
    }
    for (size_t p = 0; p < sys->n_pairs; p++)
        if (!isfinite(k->h[p]) || !isfinite(k->v_n[p]) || !(k->r[p] > 0.0))
            return false;
    return true;
}

void wetdem_pairwise_state_pack(const struct wetdem_pairwise_system* sys,
                                const struct wetdem_pairwise_mode* md,
                                const struct wetdem_pairwise_kin* k, double* y)
{
    y[0] = k->x[0];
    y[1] = k->y[0];
    y[2] = k->vx[0];
    y[3] = k->vy[0];
    y[4] = k->w[0];
    for (size_t e = 0; e + 1 < sys->n; e++) {
        size_t p = md->edge[e];
        double* v = y + PW_ANCHOR_LEN + PW_EDGE_LEN * e;
        v[PW_H] = k->h[p];
        v[PW_THETA] = k->theta[p];
        v[PW_VN] = k->v_n[p];
        v[PW_OMEGA] = k->omega_lc[p];
        v[PW_VW] = k->v_w[p];
    }
}

void wetdem_pairwise_state_pairs_from_spheres(const struct wetdem_pairwise_system* sys,
                                              struct wetdem_pairwise_kin* k)
{
    for (size_t i = 0; i < sys->n; i++) {
        k->dx[i] = k->x[i] - k->x[0];
        k->dy[i] = k->y[i] - k->y[0];
        k->ux[i] = k->vx[i] - k->vx[0];
        k->uy[i] = k->vy[i] - k->vy[0];
    }
    for (size_t p = 0; p < sys->n_pairs; p++)
        pair_from_spheres(sys, p, k);
}

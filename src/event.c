/*
 * event.c — event functions of the soft engine: for every pair, g = h - h_k with h the gap
 * and h_k each branch boundary of the force laws (docs/engines.md, "Events"):
 *   - the interaction range (largest model range(), e.g. h_co = R* for nijssen),
 *   - every threshold a model lists in thresholds() strictly between 0 and the range, logged
 *     as h_min when it equals the min-separation model's h_min or is the only such threshold
 *     of its model (nijssen's own h_min), otherwise as "branch",
 *   - 0 (solid contact),
 *   - separation_factor x range when the stop on separation needs it (not logged),
 *   - the record range of the min-separation model (record_range(): ehd and max, reset_ratio
 *     R*; glass, the films) when it is > 0 and differs from the range (not logged): the
 *     record of the largest approach speed starts there, so the adaptive integrator commits
 *     at the located crossing and the record begins with v_n at that gap, not at the first
 *     step end past it (an error of first order in the step where v_n falls).
 * g falling through 0 starts a phase (interaction, h_min, contact), rising ends it.
 * The adaptive integrator hands these functions to its root finder; fixed-step integrators
 * compare them between steps and interpolate the crossing linearly (wetdem_event_advance).
 * Prefix: wetdem_event_.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "integrator.h"

const char* wetdem_event_kind_name(enum wetdem_event_kind kind)
{
    switch (kind) {
    case WETDEM_EVENT_INTERACTION_START: return "interaction_start";
    case WETDEM_EVENT_HMIN_REACHED: return "hmin_reached";
    case WETDEM_EVENT_CONTACT_START: return "contact_start";
    case WETDEM_EVENT_CONTACT_END: return "contact_end";
    case WETDEM_EVENT_HMIN_LEFT: return "hmin_left";
    case WETDEM_EVENT_INTERACTION_END: return "interaction_end";
    case WETDEM_EVENT_HARD_CONTACT: return "hard_contact";
    case WETDEM_EVENT_PARTNER_CHANGE: return "partner_change";
    case WETDEM_EVENT_BRANCH: return "branch";
    }
    return "unknown";
}

/* Geometry of pair k at the current state: contact (with h_min from the min-separation model
 * evaluated on a scratch copy of the committed history) and range [m]. */
void wetdem_event_pair_state(const struct wetdem_sim* sim, size_t k, struct wetdem_contact* c,
                             double* range, double* scratch)
{
    const struct wetdem_pair* p = &sim->engine.pairs.items[k];
    const double* history = wetdem_pairs_history(&sim->engine.pairs, k);
    wetdem_sim_build_contact(sim, p->i, p->j, p->is_wall, c);
    *range = wetdem_sim_contact_range(sim, c);
    if (history)
        memcpy(scratch, history, sim->history_len * sizeof *scratch);
    else
        wetdem_sim_history_init(sim, scratch);
    c->h_min = sim->minsep.model->min_separation(sim->minsep.params, c, scratch);
}

static int append_slot(struct wetdem_engine* e, struct wetdem_event_slot slot)
{
    if (e->n_slots == e->slots_cap) {
        size_t cap = e->slots_cap ? 2 * e->slots_cap : 16;
        struct wetdem_event_slot* s = realloc(e->slots, cap * sizeof *s);
        if (!s)
            return WETDEM_ERR_NOMEM;
        e->slots = s;
        e->slots_cap = cap;
    }
    e->slots[e->n_slots++] = slot;
    return WETDEM_OK;
}

/* Appends slot to the interior thresholds of a pair unless an equal value is there; keeps
 * them in decreasing order of value. */
static void add_interior(struct wetdem_event_slot* list, double* values, size_t* n,
                         struct wetdem_event_slot slot, double value)
{
    size_t k = 0;
    while (k < *n && values[k] > value)
        k++;
    if (k < *n && values[k] == value) {
        list[k].as_hmin = list[k].as_hmin || slot.as_hmin;
        return;
    }
    for (size_t q = *n; q > k; q--) {
        list[q] = list[q - 1];
        values[q] = values[q - 1];
    }
    list[k] = slot;
    values[k] = value;
    (*n)++;
}

/* Collects the interior thresholds (0 < h_k < range) the models of pair k list. A threshold
 * is logged as h_min when it equals the min-separation model's h_min or is the only interior
 * threshold of its model (e.g. nijssen's own h_min = max(h_sigma, h_eps)); else as a branch. */
static size_t interior_thresholds(const struct wetdem_sim* sim, size_t k,
                                  const struct wetdem_contact* c, double range,
                                  const double* scratch, struct wetdem_event_slot* list)
{
    double values[WETDEM_MAX_MODELS * WETDEM_MAX_THRESHOLDS], gaps[WETDEM_MAX_THRESHOLDS];
    size_t n = 0;
    for (size_t m = 0; m < sim->n_models; m++) {
        const struct wetdem_model_slot* s = &sim->models[m];
        if (!s->model->thresholds)
            continue;
        size_t ng = s->model->thresholds(s->params, c, scratch + s->history_offset, gaps);
        size_t n_inner = 0;
        for (size_t q = 0; q < ng && q < WETDEM_MAX_THRESHOLDS; q++)
            n_inner += gaps[q] > 0.0 && gaps[q] < range;
        for (size_t q = 0; q < ng && q < WETDEM_MAX_THRESHOLDS; q++) {
            if (!(gaps[q] > 0.0 && gaps[q] < range))
                continue;
            bool as_hmin = gaps[q] == c->h_min || n_inner == 1;
            struct wetdem_event_slot slot = {k, WETDEM_EVENT_SOURCE_MODEL, m, q, as_hmin};
            add_interior(list, values, &n, slot, gaps[q]);
        }
    }
    return n;
}

/* Appends the event functions of pair k in decreasing threshold order: range, interior
 * thresholds, 0, then separation, and last the record range where it is another gap. Marks the
 * pair as interacting when it starts within range. */
static int build_pair_slots(struct wetdem_sim* sim, size_t k)
{
    struct wetdem_engine* e = &sim->engine;
    struct wetdem_contact c;
    double range, scratch[WETDEM_HISTORY_SCRATCH];
    wetdem_event_pair_state(sim, k, &c, &range, scratch);
    if (c.gap < range) /* strictly inside: a run stopped exactly at separation stays done */
        e->pairs.items[k].has_interacted = true;
    struct wetdem_event_slot inner[WETDEM_MAX_MODELS * WETDEM_MAX_THRESHOLDS];
    size_t n_inner = interior_thresholds(sim, k, &c, range, scratch, inner);
    int st = append_slot(e, (struct wetdem_event_slot){k, WETDEM_EVENT_SOURCE_RANGE, 0, 0, 0});
    for (size_t q = 0; q < n_inner && st == WETDEM_OK; q++)
        st = append_slot(e, inner[q]);
    if (st == WETDEM_OK)
        st = append_slot(e, (struct wetdem_event_slot){k, WETDEM_EVENT_SOURCE_ZERO, 0, 0, 0});
    if (st == WETDEM_OK && sim->settings.stop_on_separation != 0 &&
        sim->settings.separation_factor > 1)
        st = append_slot(e, (struct wetdem_event_slot){k, WETDEM_EVENT_SOURCE_SEPARATION, 0, 0, 0});
    double record = wetdem_sim_record_range(sim, &c);
    if (st == WETDEM_OK && record > 0.0 && record != range)
        st = append_slot(e, (struct wetdem_event_slot){k, WETDEM_EVENT_SOURCE_RECORD, 0, 0, 0});
    return st;
}

/* Grows a double array to n entries. */
static int grow_doubles(double** a, size_t n)
{
    double* p = realloc(*a, (n ? n : 1) * sizeof *p);
    if (!p)
        return WETDEM_ERR_NOMEM;
    *a = p;
    return WETDEM_OK;
}

int wetdem_event_slots_build(struct wetdem_sim* sim)
{
    struct wetdem_engine* e = &sim->engine;
    e->n_slots = 0;
    int st = WETDEM_OK;
    for (size_t k = 0; k < e->pairs.n && st == WETDEM_OK; k++)
        st = build_pair_slots(sim, k);
    size_t np = e->pairs.n;
    if (st == WETDEM_OK && np > e->pair_scratch_cap) {
        double** arrays[] = {&e->pair_gap, &e->pair_vn, &e->pair_gap_prev, &e->pair_vn_prev,
                             &e->pair_range};
        for (size_t q = 0; q < 5 && st == WETDEM_OK; q++)
            st = grow_doubles(arrays[q], np);
        if (st == WETDEM_OK)
            e->pair_scratch_cap = np;
    }
    if (st == WETDEM_OK)
        st = grow_doubles(&e->g_prev, e->slots_cap);
    if (st == WETDEM_OK)
        st = grow_doubles(&e->g_new, e->slots_cap);
    if (st != WETDEM_OK)
        return wetdem_sim_fail(sim, st, "out of memory building the event functions");
    return WETDEM_OK;
}

/* Threshold [m] of slot s for a pair in state c (h_min filled) with history scratch. */
static double slot_threshold(const struct wetdem_sim* sim, const struct wetdem_event_slot* s,
                             const struct wetdem_contact* c, double range, const double* scratch)
{
    switch (s->source) {
    case WETDEM_EVENT_SOURCE_RANGE: return range;
    case WETDEM_EVENT_SOURCE_ZERO: return 0.0;
    case WETDEM_EVENT_SOURCE_SEPARATION: return sim->settings.separation_factor * range;
    case WETDEM_EVENT_SOURCE_RECORD: return wetdem_sim_record_range(sim, c);
    case WETDEM_EVENT_SOURCE_MODEL: break;
    }
    const struct wetdem_model_slot* m = &sim->models[s->model];
    double gaps[WETDEM_MAX_THRESHOLDS];
    size_t n = m->model->thresholds(m->params, c, scratch + m->history_offset, gaps);
    return s->index < n ? gaps[s->index] : range;
}

void wetdem_event_values(struct wetdem_sim* sim, double* g)
{
    struct wetdem_engine* e = &sim->engine;
    struct wetdem_contact c;
    double range = 0.0, scratch[WETDEM_HISTORY_SCRATCH];
    size_t current = (size_t)-1;
    e->stats.root_evals++;
    for (size_t q = 0; q < e->n_slots; q++) {
        const struct wetdem_event_slot* s = &e->slots[q];
        if (s->pair != current) {
            current = s->pair;
            wetdem_event_pair_state(sim, current, &c, &range, scratch);
            e->pair_gap[current] = c.gap;
            e->pair_vn[current] = c.v_n;
            e->pair_range[current] = range;
        }
        g[q] = c.gap - slot_threshold(sim, s, &c, range, scratch);
    }
}

/* Kind logged when slot s is crossed in direction dir; 0 for none. */
static int kind_of(const struct wetdem_event_slot* s, int dir)
{
    switch (s->source) {
    case WETDEM_EVENT_SOURCE_RANGE:
        return dir < 0 ? WETDEM_EVENT_INTERACTION_START : WETDEM_EVENT_INTERACTION_END;
    case WETDEM_EVENT_SOURCE_ZERO:
        return dir < 0 ? WETDEM_EVENT_CONTACT_START : WETDEM_EVENT_CONTACT_END;
    case WETDEM_EVENT_SOURCE_MODEL:
        if (!s->as_hmin)
            return WETDEM_EVENT_BRANCH;
        return dir < 0 ? WETDEM_EVENT_HMIN_REACHED : WETDEM_EVENT_HMIN_LEFT;
    case WETDEM_EVENT_SOURCE_SEPARATION:
    case WETDEM_EVENT_SOURCE_RECORD: break;
    }
    return 0;
}

int wetdem_event_record(struct wetdem_sim* sim, size_t k, int dir, double t, double gap, double v_n)
{
    struct wetdem_engine* e = &sim->engine;
    const struct wetdem_event_slot* s = &e->slots[k];
    struct wetdem_pair* p = &e->pairs.items[s->pair];
    if (s->source == WETDEM_EVENT_SOURCE_RANGE && dir < 0)
        p->has_interacted = true;
    int kind = kind_of(s, dir);
    if (!kind)
        return WETDEM_OK;
    if (e->n_events == e->events_cap) {
        size_t cap = e->events_cap ? 2 * e->events_cap : 32;
        struct wetdem_event_record* r = realloc(e->events, cap * sizeof *r);
        if (!r)
            return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory logging events");
        e->events = r;
        e->events_cap = cap;
    }
    e->events[e->n_events++] = (struct wetdem_event_record){.time = t,
                                                            .kind = (enum wetdem_event_kind)kind,
                                                            .i = p->i,
                                                            .j = p->j,
                                                            .is_wall = p->is_wall,
                                                            .gap = gap,
                                                            .v_n = v_n};
    e->stats.events++;
    return WETDEM_OK;
}

/* A crossing found between two steps. */
struct crossing {
    double t;     /* interpolated time [s] */
    double theta; /* fraction of the step [-] */
    size_t slot;
    int dir;
};

/* Time order; at equal times starts (falling) before ends, starts in slot order (range,
 * h_min, contact) and ends in reverse slot order (contact, h_min, range). */
static bool crossing_before(const struct crossing* a, const struct crossing* b)
{
    if (a->t != b->t)
        return a->t < b->t;
    if (a->dir != b->dir)
        return a->dir < b->dir;
    return a->dir < 0 ? a->slot < b->slot : a->slot > b->slot;
}

static void sort_crossings(struct crossing* x, size_t n)
{
    for (size_t a = 1; a < n; a++) {
        struct crossing key = x[a];
        size_t b = a;
        for (; b > 0 && crossing_before(&key, &x[b - 1]); b--)
            x[b] = x[b - 1];
        x[b] = key;
    }
}

double wetdem_event_smallest_branch_gap(const struct wetdem_sim* sim)
{
    const struct wetdem_engine* e = &sim->engine;
    double h_min = INFINITY;
    for (size_t q = 0; q < e->n_slots; q++) {
        if (e->slots[q].source != WETDEM_EVENT_SOURCE_MODEL)
            continue;
        size_t p = e->slots[q].pair;
        double h_k = e->pair_gap[p] - e->g_prev[q];
        if (!(h_k > 0.0 && h_k < h_min))
            continue;
        struct wetdem_contact c;
        double range, scratch[WETDEM_HISTORY_SCRATCH];
        wetdem_event_pair_state(sim, p, &c, &range, scratch);
        if (wetdem_sim_laws_resolve_at(sim, &c, scratch, h_k))
            h_min = h_k;
    }
    return h_min;
}

/* Keeps in stats.hmin_step_ratio the gap change of the step just taken, as a multiple of
 * the branch gap h_k of model slot q that it crossed (h_k = gap - g at the step's end), where
 * the force laws jump at h_k, or peak there and fall steeply below it
 * (wetdem_sim_laws_resolve_at). A fixed step samples the force law only at its ends: with a
 * change of the order of h_k it puts the switch (c: to zero) at a step end, not where the gap
 * crosses h_k, or steps over the peak. Where the laws are continuous and flat at h_k (nc;
 * nijssen's lever blend in water, where the contact force takes over) the step's error there
 * is of second order and is not counted. */
static void note_branch_step(struct wetdem_sim* sim, size_t q)
{
    struct wetdem_engine* e = &sim->engine;
    size_t p = e->slots[q].pair;
    double h_k = e->pair_gap[p] - e->g_new[q];
    if (!(h_k > 0.0))
        return;
    double ratio = fabs(e->pair_gap[p] - e->pair_gap_prev[p]) / h_k;
    if (!(ratio > e->stats.hmin_step_ratio))
        return;
    struct wetdem_contact c;
    double range, scratch[WETDEM_HISTORY_SCRATCH];
    wetdem_event_pair_state(sim, p, &c, &range, scratch);
    if (wetdem_sim_laws_resolve_at(sim, &c, scratch, h_k))
        e->stats.hmin_step_ratio = ratio;
}

/* Whether a value g = h - h_k of an event function puts its pair inside the threshold h_k.
 * Exactly at it counts as outside: the interaction and the contact begin only below their
 * thresholds (the laws vanish at the edge of their range and at gap 0), as has_interacted and
 * the stop on separation count them, so a pair placed exactly touching, or exactly at the edge
 * of its range, crosses when it moves inward. */
static bool is_inside(double g)
{
    return g < 0;
}

/* Copies engine.pair_gap and pair_vn (the latest wetdem_event_values) to pair_gap_prev and
 * pair_vn_prev, the state detect() interpolates from. */
static void keep_pair_state(struct wetdem_sim* sim)
{
    struct wetdem_engine* e = &sim->engine;
    if (e->pairs.n == 0) /* (a lone particle: the arrays were never allocated, memcpy of NULL) */
        return;
    memcpy(e->pair_gap_prev, e->pair_gap, e->pairs.n * sizeof *e->pair_gap);
    memcpy(e->pair_vn_prev, e->pair_vn, e->pairs.n * sizeof *e->pair_vn);
}

/* Detection between two evaluated states, g_prev at t0 and g_new at t1 (wetdem_event_advance). */
static int detect(struct wetdem_sim* sim, double t0, double t1, const int* roots)
{
    struct wetdem_engine* e = &sim->engine;
    size_t n = 0;
    for (size_t q = 0; q < e->n_slots; q++)
        n += is_inside(e->g_prev[q]) != is_inside(e->g_new[q]);
    if (n == 0)
        return WETDEM_OK;
    struct crossing* x = malloc(n * sizeof *x);
    if (!x)
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory locating events");
    n = 0;
    for (size_t q = 0; q < e->n_slots; q++) {
        double a = e->g_prev[q], b = e->g_new[q];
        if (is_inside(a) == is_inside(b))
            continue;
        double theta = roots && roots[q] ? 1.0 : a / (a - b);
        x[n++] = (struct crossing){theta < 1.0 ? t0 + theta * (t1 - t0) : t1, theta, q,
                                   is_inside(b) ? -1 : 1};
        if (!roots && e->slots[q].source == WETDEM_EVENT_SOURCE_MODEL)
            note_branch_step(sim, q);
    }
    sort_crossings(x, n);
    int st = WETDEM_OK;
    for (size_t k = 0; k < n && st == WETDEM_OK; k++) {
        size_t p = e->slots[x[k].slot].pair;
        double th = x[k].theta;
        double gap = e->pair_gap_prev[p] + th * (e->pair_gap[p] - e->pair_gap_prev[p]);
        double v_n = e->pair_vn_prev[p] + th * (e->pair_vn[p] - e->pair_vn_prev[p]);
        st = wetdem_event_record(sim, x[k].slot, x[k].dir, x[k].t, gap, v_n);
    }
    free(x);
    return st;
}

void wetdem_event_start(struct wetdem_sim* sim)
{
    wetdem_event_values(sim, sim->engine.g_prev);
    keep_pair_state(sim);
}

int wetdem_event_advance(struct wetdem_sim* sim, double t0, double t1, const int* roots)
{
    struct wetdem_engine* e = &sim->engine;
    wetdem_event_values(sim, e->g_new);
    int st = detect(sim, t0, t1, roots);
    double* g = e->g_prev; /* g_new becomes the previous state of the next step */
    e->g_prev = e->g_new;
    e->g_new = g;
    keep_pair_state(sim);
    return st;
}

/*
 * sim_models.c — enabling models on a simulation, dotted-name parameters with validation and
 * "did you mean" hints, and the evaluation of all enabled force models for one pair.
 * Prefix: wetdem_sim_.
 *
 * Per-pair history layout: [min-separation model | force model 0 | force model 1 | ...].
 * Forces of enabled models add up (STYLE §6.4); the min-separation model runs first and
 * writes c->h_min, which thin-film models read.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "contact.h"
#include "integrator.h"
#include "locale_guard.h"
#include "models.h"
#include "sim.h"
#include "vec3.h"

static const char* const yes_no[] = {"no", "yes", NULL};

#define SET(field) offsetof(struct wetdem_sim_settings, field)
static const struct wetdem_param_desc settings_params[] = {
    {"gravity_x", "m/s^2", "Gravitational acceleration, x component.", SET(gravity_x), 0, -1e4, 1e4,
     false, false, NULL, false},
    {"gravity_y", "m/s^2", "Gravitational acceleration, y component.", SET(gravity_y), 0, -1e4, 1e4,
     false, false, NULL, false},
    {"gravity_z", "m/s^2", "Gravitational acceleration, z component.", SET(gravity_z), 0, -1e4, 1e4,
     false, false, NULL, false},
    {"stop_on_separation", "-",
     "Stop integrating (status WETDEM_EVENT) once every pair that interacted has left its "
     "interaction range and recedes.",
     SET(stop_on_separation), 0, 0, 1, false, false, yes_no, false},
    {"separation_factor", "-",
     "A pair counts as separated when its gap exceeds this multiple of its interaction range.",
     SET(separation_factor), 1, 1, 1e3, false, false, NULL, false},
    {"speed_floor", "m/s",
     "Smallest relative speed used to derive the Verlet step and the CVODE tolerance scales.",
     SET(speed_floor), 1e-3, 0, 1e3, true, false, NULL, false},
    {0},
};
#undef SET

const struct wetdem_param_desc* wetdem_sim_settings_params(void)
{
    return settings_params;
}

static void recompute_history_layout(struct wetdem_sim* sim)
{
    size_t off = sim->minsep.model->history_len;
    for (size_t k = 0; k < sim->n_models; k++) {
        sim->models[k].history_offset = off;
        off += sim->models[k].model->history_len;
    }
    sim->history_len = off;
}

size_t wetdem_sim_slot_size(const struct wetdem_model* model)
{
    size_t size = model->params_size ? model->params_size : 1;
    if (model->kind == WETDEM_MODEL_MIN_SEPARATION && size < wetdem_minsep_fixed.params_size)
        size = wetdem_minsep_fixed.params_size;
    return size;
}

static int make_slot(struct wetdem_sim* sim, struct wetdem_model_slot* slot,
                     const struct wetdem_model* model, const void* params)
{
    void* p = calloc(1, wetdem_sim_slot_size(model));
    if (!p)
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory enabling %s", model->name);
    if (params)
        memcpy(p, params, model->params_size);
    else
        wetdem_param_init_defaults(model->params, p);
    slot->model = model;
    slot->params = p;
    slot->history_offset = 0;
    return WETDEM_OK;
}

/* Whether a force model carries a normal solid-contact law: it stores elastic energy (hertz,
 * hooke, and nijssen's own Hertz contact). */
static bool has_normal_contact(const struct wetdem_model* m)
{
    return m->elastic_energy != NULL;
}

/* Whether a force model carries a tangential contact law: a contact model without a normal
 * one (mindlin's spring), or a fluid model with its own contact (nijssen's Hertz-Mindlin). */
static bool has_tangential_contact(const struct wetdem_model* m)
{
    return m->kind == WETDEM_MODEL_CONTACT ? !has_normal_contact(m)
                                           : m->kind == WETDEM_MODEL_FLUID && has_normal_contact(m);
}

/* The enabled model that would count one of the contact forces twice beside `model`: a second
 * normal contact law, or a second tangential one; NULL when none. */
static const struct wetdem_model* contact_twice(const struct wetdem_sim* sim,
                                                const struct wetdem_model* model)
{
    for (size_t k = 0; k < sim->n_models; k++) {
        const struct wetdem_model* m = sim->models[k].model;
        if ((has_normal_contact(m) && has_normal_contact(model)) ||
            (has_tangential_contact(m) && has_tangential_contact(model)))
            return m;
    }
    return NULL;
}

/* Whether `model` is one the engines can call, and params (NULL: the defaults) within its
 * descriptors' ranges; the message goes to sim. */
static int check_model(struct wetdem_sim* sim, const struct wetdem_model* model, const void* params)
{
    if (!model || !model->name || !model->name[0])
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "add_model: a model needs a name");
    if (model->kind < WETDEM_MODEL_CONTACT || model->kind > WETDEM_MODEL_IMPULSE)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "model '%s': kind %d is none of contact, fluid, min-separation "
                               "and impulse",
                               model->name, (int)model->kind);
    if (model->kind == WETDEM_MODEL_MIN_SEPARATION && !model->min_separation)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "model '%s': a min-separation model needs its min_separation hook",
                               model->name);
    if (!model->params)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "model '%s': params must be a {0}-terminated descriptor table (an "
                               "empty one for a model without parameters)",
                               model->name);
    for (const struct wetdem_param_desc* d = model->params; d->name; d++) {
        if (d->offset + sizeof(double) > model->params_size)
            return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                                   "model '%s': parameter %s at offset %zu lies beyond params_size "
                                   "%zu",
                                   model->name, d->name, d->offset, model->params_size);
        if (!params)
            continue;
        double value;
        memcpy(&value, (const char*)params + d->offset, sizeof value);
        char msg[256];
        if (wetdem_param_validate(d, value, msg, sizeof msg) != WETDEM_OK)
            return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "model '%s': %s", model->name, msg);
    }
    return WETDEM_OK;
}

int wetdem_sim_add_model(struct wetdem_sim* sim, const struct wetdem_model* model,
                         const void* params)
{
    int checked = check_model(sim, model, params);
    if (checked != WETDEM_OK)
        return checked;
    if (model->kind == WETDEM_MODEL_MIN_SEPARATION) {
        struct wetdem_model_slot slot;
        int st = make_slot(sim, &slot, model, params);
        if (st != WETDEM_OK)
            return st;
        free(sim->minsep.params);
        sim->minsep = slot;
        recompute_history_layout(sim);
        return WETDEM_OK;
    }
    if (model->kind == WETDEM_MODEL_IMPULSE || !model->pair)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "model '%s' is an impulse model: it is used by the pairwise "
                               "engine, not summed as a force",
                               model->name);
    for (size_t k = 0; k < sim->n_models; k++)
        if (strcmp(sim->models[k].model->name, model->name) == 0)
            return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "model '%s' is already enabled",
                                   model->name);
    const struct wetdem_model* twice = contact_twice(sim, model);
    if (twice)
        return wetdem_sim_fail(
            sim, WETDEM_ERR_INVALID,
            "model '%s' and model '%s' both give the %s contact force, which would be counted "
            "twice; enable one of them%s",
            model->name, twice->name,
            has_normal_contact(model) && has_normal_contact(twice) ? "normal" : "tangential",
            model->kind == WETDEM_MODEL_FLUID || twice->kind == WETDEM_MODEL_FLUID
                ? " (a fluid model with its own contact replaces hertz and mindlin)"
                : "");
    if (sim->n_models >= WETDEM_MAX_MODELS)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "at most %d force models",
                               WETDEM_MAX_MODELS);
    int st = make_slot(sim, &sim->models[sim->n_models], model, params);
    if (st != WETDEM_OK)
        return st;
    sim->n_models++;
    recompute_history_layout(sim);
    return WETDEM_OK;
}

/* NULL-terminated list of every built-in model name, for suggestions. */
static void model_names(const char** names, size_t cap)
{
    const struct wetdem_model* const* reg = wetdem_model_registry();
    size_t n = 0;
    for (; reg[n] && n + 1 < cap; n++)
        names[n] = reg[n]->name;
    names[n] = NULL;
}

int wetdem_sim_enable_model(struct wetdem_sim* sim, const char* name)
{
    if (!name)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "enable_model: NULL name");
    const struct wetdem_model* m = wetdem_model_find(name);
    if (!m) {
        const char* names[64];
        model_names(names, 64);
        const char* hint = wetdem_param_suggest(name, names);
        return wetdem_sim_fail(sim, WETDEM_ERR_NOT_FOUND,
                               "unknown model '%s'%s%s%s (see 'wetdem models')", name,
                               hint ? " (did you mean '" : "", hint ? hint : "", hint ? "'?)" : "");
    }
    return wetdem_sim_add_model(sim, m, NULL);
}

void wetdem_sim_clear_models(struct wetdem_sim* sim)
{
    for (size_t k = 0; k < sim->n_models; k++)
        free(sim->models[k].params);
    sim->n_models = 0;
    if (sim->minsep.model != &wetdem_minsep_fixed) { /* in place (wetdem_sim_slot_size) */
        memset(sim->minsep.params, 0, wetdem_sim_slot_size(&wetdem_minsep_fixed));
        wetdem_param_init_defaults(wetdem_minsep_fixed.params, sim->minsep.params);
        sim->minsep.model = &wetdem_minsep_fixed;
        sim->minsep.history_offset = 0;
    }
    recompute_history_layout(sim);
}

size_t wetdem_sim_n_models(const struct wetdem_sim* sim)
{
    return sim->n_models;
}

const struct wetdem_model* wetdem_sim_model(const struct wetdem_sim* sim, size_t k)
{
    return k < sim->n_models ? sim->models[k].model : NULL;
}

const struct wetdem_model* wetdem_sim_min_separation_model(const struct wetdem_sim* sim)
{
    return sim->minsep.model;
}

/* ---- dotted parameter names ---- */

struct param_target {
    const struct wetdem_param_desc* desc;
    double* field;
};

/* Collects every settable dotted name into names (for suggestions). */
static size_t all_param_names(const struct wetdem_sim* sim, char (*buf)[96], const char** names,
                              size_t cap)
{
    size_t n = 0;
    const struct {
        const char* prefix;
        const struct wetdem_param_desc* table;
    } groups[] = {{"fluid", wetdem_fluid_params()}, {"sim", settings_params}};
    for (size_t g = 0; g < 2; g++)
        for (size_t k = 0; groups[g].table[k].name && n + 1 < cap; k++, n++)
            snprintf(buf[n], 96, "%s.%s", groups[g].prefix, groups[g].table[k].name);
    const struct wetdem_integrator* const* integ = wetdem_integrator_registry();
    for (size_t m = 0; integ[m]; m++)
        for (size_t k = 0; integ[m]->params[k].name && n + 1 < cap; k++, n++)
            snprintf(buf[n], 96, "%s.%s", integ[m]->name, integ[m]->params[k].name);
    for (size_t m = 0; m <= sim->n_models; m++) {
        const struct wetdem_model* model =
            m < sim->n_models ? sim->models[m].model : sim->minsep.model;
        for (size_t k = 0; model->params[k].name && n + 1 < cap; k++, n++)
            snprintf(buf[n], 96, "%s.%s", model->name, model->params[k].name);
    }
    for (size_t k = 0; k < n; k++)
        names[k] = buf[k];
    names[n] = NULL;
    return n;
}

static int not_found(const struct wetdem_sim* sim_c, const char* name)
{
    struct wetdem_sim* sim = (struct wetdem_sim*)sim_c;
    static const size_t cap = 256;
    char(*buf)[96] = malloc(cap * sizeof *buf);
    const char** names = malloc(cap * sizeof *names);
    const char* hint = NULL;
    char hint_copy[96] = "";
    if (buf && names) {
        all_param_names(sim, buf, names, cap);
        hint = wetdem_param_suggest(name, names);
        if (hint)
            snprintf(hint_copy, sizeof hint_copy, "%s", hint);
    }
    free(buf);
    free(names);
    if (hint_copy[0])
        return wetdem_sim_fail(sim, WETDEM_ERR_NOT_FOUND,
                               "unknown parameter '%s' (did you mean '%s'?)", name, hint_copy);
    return wetdem_sim_fail(sim, WETDEM_ERR_NOT_FOUND,
                           "unknown parameter '%s': names are <model>.<param> for an enabled "
                           "model, fluid.<field>, sim.<setting>, verlet.<param> or "
                           "cvode.<param>",
                           name);
}

static int find_target(const struct wetdem_sim* sim, const char* name, struct param_target* t)
{
    const char* dot = strchr(name, '.');
    if (!dot)
        return not_found(sim, name);
    size_t plen = (size_t)(dot - name);
    const char* key = dot + 1;
    const struct wetdem_param_desc* table = NULL;
    void* base = NULL;
    if (plen == 5 && strncmp(name, "fluid", 5) == 0) {
        table = wetdem_fluid_params();
        base = (void*)&sim->fluid;
    } else if (plen == 3 && strncmp(name, "sim", 3) == 0) {
        table = settings_params;
        base = (void*)&sim->settings;
    } else if (wetdem_integrator_index(name, plen) >= 0) {
        int k = wetdem_integrator_index(name, plen);
        table = wetdem_integrator_registry()[k]->params;
        base = (void*)sim->engine.integrator_params[k];
    } else {
        for (size_t m = 0; m <= sim->n_models; m++) {
            const struct wetdem_model_slot* s = m < sim->n_models ? &sim->models[m] : &sim->minsep;
            if (strlen(s->model->name) == plen && strncmp(s->model->name, name, plen) == 0) {
                table = s->model->params;
                base = s->params;
            }
        }
    }
    const struct wetdem_param_desc* d = table ? wetdem_param_find(table, key) : NULL;
    if (!d)
        return not_found(sim, name);
    t->desc = d;
    t->field = (double*)((char*)base + d->offset);
    return WETDEM_OK;
}

int wetdem_sim_set_param(struct wetdem_sim* sim, const char* name, double value)
{
    if (!name)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "set_param: NULL name");
    struct param_target t;
    int st = find_target(sim, name, &t);
    if (st != WETDEM_OK)
        return st;
    char msg[512];
    if (wetdem_param_validate(t.desc, value, msg, sizeof msg) != WETDEM_OK)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "%.*s.%s", (int)(strchr(name, '.') - name),
                               name, msg);
    *t.field = value;
    return WETDEM_OK;
}

static int set_param_str(struct wetdem_sim* sim, const char* name, const char* value)
{
    if (!name || !value)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "set_param_str: NULL %s",
                               name ? "value" : "name");
    struct param_target t;
    int st = find_target(sim, name, &t);
    if (st != WETDEM_OK)
        return st;
    if (t.desc->choices) {
        int idx = wetdem_param_choice_index(t.desc, value);
        if (idx < 0) {
            char range[160];
            wetdem_param_range_text(t.desc, range, sizeof range);
            const char* hint = wetdem_param_suggest(value, t.desc->choices);
            return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "%s = '%s' is not valid: %s%s%s%s",
                                   name, value, range, hint ? " (did you mean '" : "",
                                   hint ? hint : "", hint ? "'?)" : "");
        }
        *t.field = idx;
        return WETDEM_OK;
    }
    char* end = NULL;
    double v = strtod(value, &end);
    if (end == value || *end != '\0')
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "%s = '%s' is not a number [%s]", name,
                               value, t.desc->unit);
    return wetdem_sim_set_param(sim, name, v);
}

/* The number in the C locale: "0.5", whatever LC_NUMERIC the host set (locale_guard.h). */
int wetdem_sim_set_param_str(struct wetdem_sim* sim, const char* name, const char* value)
{
    struct wetdem_locale_guard g;
    if (wetdem_locale_guard_enter(&g) != WETDEM_OK)
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM,
                               "set_param_str: out of memory for the C "
                               "locale of the numbers");
    int st = set_param_str(sim, name, value);
    wetdem_locale_guard_leave(&g);
    return st;
}

int wetdem_sim_param(const struct wetdem_sim* sim, const char* name, double* value)
{
    if (!name || !value) /* (the message buffer: as wetdem_sim_energy_budget) */
        return wetdem_sim_fail((struct wetdem_sim*)sim, WETDEM_ERR_INVALID, "param: NULL %s",
                               name ? "value" : "name");
    struct param_target t;
    int st = find_target(sim, name, &t);
    if (st == WETDEM_OK)
        *value = *t.field;
    return st;
}

/* ---- evaluation ---- */

void wetdem_sim_history_init(const struct wetdem_sim* sim, double* history)
{
    for (size_t k = 0; k < sim->history_len; k++)
        history[k] = 0.0;
}

double wetdem_sim_record_range(const struct wetdem_sim* sim, const struct wetdem_contact* c)
{
    const struct wetdem_model_slot* s = &sim->minsep;
    return s->model->record_range ? s->model->record_range(s->params, c) : 0.0;
}

bool wetdem_sim_history_beyond_range(const struct wetdem_sim* sim, struct wetdem_contact* c,
                                     double record_range, double* history)
{
    const struct wetdem_model_slot* s = &sim->minsep;
    size_t kept = 0;
    if (s->model->record_range && c->gap <= record_range) {
        c->h_min = s->model->min_separation(s->params, c, history); /* updates the record */
        kept = s->model->history_len;
    }
    for (size_t k = kept; k < sim->history_len; k++) /* the force models': fresh */
        history[k] = 0.0;
    return kept > 0;
}

double wetdem_sim_contact_range(const struct wetdem_sim* sim, const struct wetdem_contact* c)
{
    double r = 0.0;
    for (size_t k = 0; k < sim->n_models; k++) {
        const struct wetdem_model_slot* s = &sim->models[k];
        double rk = s->model->range ? s->model->range(s->params, c) : 0.0;
        if (rk > r)
            r = rk;
    }
    return r;
}

double wetdem_sim_contact_time(const struct wetdem_sim* sim, const struct wetdem_contact* c)
{
    double t = INFINITY;
    for (size_t k = 0; k < sim->n_models; k++) {
        const struct wetdem_model_slot* s = &sim->models[k];
        if (s->model->contact_time)
            t = fmin(t, s->model->contact_time(s->params, c));
    }
    if (t < INFINITY)
        return t;
    return hertz_contact_time_hook(NULL, c); /* fluid forces only: the materials' */
}

double wetdem_sim_relaxation_time(const struct wetdem_sim* sim, struct wetdem_contact* c,
                                  const struct wetdem_model** which)
{
    double history[WETDEM_HISTORY_SCRATCH] = {
        0}; /* a fresh pair's min-separation record (offset 0) */
    c->h_min = sim->minsep.model->history_len <= WETDEM_HISTORY_SCRATCH
                   ? sim->minsep.model->min_separation(sim->minsep.params, c, history)
                   : 0.0;
    c->linear_stiffness = wetdem_sim_linear_stiffness(sim, c); /* (mindlin beside hooke) */
    double t = INFINITY;
    if (which)
        *which = NULL;
    for (size_t k = 0; k < sim->n_models; k++) {
        const struct wetdem_model_slot* s = &sim->models[k];
        double tk = s->model->relaxation_time ? s->model->relaxation_time(s->params, c) : INFINITY;
        if (tk < t) {
            t = tk;
            if (which)
                *which = s->model;
        }
    }
    return t;
}

/* The history slice of the model in slot s, or NULL for a model without one. */
static const double* slot_history(const struct wetdem_model_slot* s, const double* history)
{
    return s->model->history_len ? history + s->history_offset : NULL;
}

double wetdem_sim_contact_elastic_energy(const struct wetdem_sim* sim,
                                         const struct wetdem_contact* c, const double* history)
{
    double e = 0.0;
    for (size_t k = 0; k < sim->n_models; k++) {
        const struct wetdem_model_slot* s = &sim->models[k];
        if (s->model->elastic_energy)
            e += s->model->elastic_energy(s->params, c, slot_history(s, history));
    }
    return e;
}

bool wetdem_sim_contact_is_in_contact(const struct wetdem_sim* sim, const struct wetdem_contact* c,
                                      const double* history)
{
    for (size_t k = 0; k < sim->n_models; k++) {
        const struct wetdem_model_slot* s = &sim->models[k];
        if (s->model->is_in_contact &&
            s->model->is_in_contact(s->params, c, slot_history(s, history)))
            return true;
    }
    return false;
}

bool wetdem_sim_contact_is_bridged(const struct wetdem_sim* sim, const struct wetdem_contact* c,
                                   const double* history)
{
    for (size_t k = 0; k < sim->n_models; k++) {
        const struct wetdem_model_slot* s = &sim->models[k];
        if (s->model->is_bridged && s->model->is_bridged(s->params, c, slot_history(s, history)))
            return true;
    }
    return false;
}

/* The enabled models' forces on contact c moved to gap `gap`, with a scratch copy of the
 * committed history `history` (NULL: a fresh pair; at most WETDEM_HISTORY_SCRATCH doubles)
 * and no time elapsed, into *f. WETDEM status. */
static int force_at_gap(const struct wetdem_sim* sim, struct wetdem_contact c,
                        const double* history, double gap, struct wetdem_pair_force* f)
{
    double scratch[WETDEM_HISTORY_SCRATCH];
    if (history)
        memcpy(scratch, history, sim->history_len * sizeof *scratch);
    c.gap = gap;
    c.dt = 0.0;
    return wetdem_sim_eval_contact(sim, &c, history ? scratch : NULL, f, NULL);
}

/* Change of the enabled models' forces on contact c (committed history `history`, NULL: a
 * fresh pair) across the gap h, between h (1 + eps) and h (1 - eps): of the summed normal
 * force plus that of the size of the summed tangential force [N]; NAN if a model fails. */
static double change_across(const struct wetdem_sim* sim, const struct wetdem_contact* c,
                            const double* history, double h, double eps)
{
    struct wetdem_pair_force f[2];
    for (int side = 0; side < 2; side++)
        if (force_at_gap(sim, *c, history, h * (side ? 1 - eps : 1 + eps), &f[side]) != WETDEM_OK)
            return NAN;
    return fabs(f[0].f_normal - f[1].f_normal) +
           fabs(vec3_norm(f[0].f_tan) - vec3_norm(f[1].f_tan));
}

bool wetdem_sim_laws_jump_at(const struct wetdem_sim* sim, const struct wetdem_contact* c,
                             const double* history, double h)
{
    if (sim->history_len > WETDEM_HISTORY_SCRATCH)
        return false;
    double wide = change_across(sim, c, history, h, 1e-6);
    return wide > 0.0 && change_across(sim, c, history, h, 1e-9) >= 0.5 * wide;
}

/* The summed normal force of the enabled models on contact c at gap h [N]; NAN if a model
 * fails. */
static double normal_force_at(const struct wetdem_sim* sim, const struct wetdem_contact* c,
                              const double* history, double h)
{
    struct wetdem_pair_force f;
    return force_at_gap(sim, *c, history, h, &f) == WETDEM_OK ? f.f_normal : NAN;
}

#define PEAK_FALL 0.75 /* force at h/2 over that at h below which h is a peak to resolve */

bool wetdem_sim_laws_resolve_at(const struct wetdem_sim* sim, const struct wetdem_contact* c,
                                const double* history, double h)
{
    if (wetdem_sim_laws_jump_at(sim, c, history, h))
        return true;
    if (sim->history_len > WETDEM_HISTORY_SCRATCH)
        return false;
    double at = normal_force_at(sim, c, history, h);
    return at > 0.0 && normal_force_at(sim, c, history, 0.5 * h) < PEAK_FALL * at;
}

double wetdem_sim_jump_gap(const struct wetdem_sim* sim, const struct wetdem_contact* c)
{
    if (sim->history_len > WETDEM_HISTORY_SCRATCH ||
        sim->minsep.model->history_len > WETDEM_HISTORY_SCRATCH)
        return INFINITY;
    struct wetdem_contact p = *c;
    double history[WETDEM_HISTORY_SCRATCH] = {0}, gaps[WETDEM_MAX_THRESHOLDS], gap = INFINITY;
    p.h_min = sim->minsep.model->min_separation(sim->minsep.params, &p, history);
    double range = wetdem_sim_contact_range(sim, &p);
    for (size_t k = 0; k < sim->n_models; k++) {
        const struct wetdem_model_slot* s = &sim->models[k];
        size_t n = s->model->thresholds
                       ? s->model->thresholds(s->params, &p, history + s->history_offset, gaps)
                       : 0;
        for (size_t q = 0; q < n && q < WETDEM_MAX_THRESHOLDS; q++) {
            double h = gaps[q];
            if (!(h > 0.0 && h < range && h < gap))
                continue;
            if (wetdem_sim_laws_jump_at(sim, &p, NULL, h))
                gap = h;
        }
    }
    return gap;
}

double wetdem_sim_force_at_rest(const struct wetdem_sim* sim, struct wetdem_contact c,
                                const double* history, double gap)
{
    if (history && sim->history_len > WETDEM_HISTORY_SCRATCH)
        return NAN;
    struct wetdem_pair_force f;
    c.v_n = 0.0;
    c.v_t = c.dv_t_spring = vec3(0, 0, 0);
    return force_at_gap(sim, c, history, gap, &f) == WETDEM_OK && isfinite(f.f_normal) ? f.f_normal
                                                                                       : NAN;
}

/* The tangential force along t of the enabled models at overlap `overlap` when a fresh
 * tangential spring has been stretched by sliding at v_t = u t for a time dt [N], or NAN. */
static double tangential_after(const struct wetdem_sim* sim, struct wetdem_contact c,
                               double overlap, struct wetdem_vec3 t, double u, double dt)
{
    struct wetdem_pair_force f;
    c.gap = -overlap;
    c.v_n = 0.0;
    c.v_t = vec3_scale(t, u);
    c.dv_t_spring = vec3(0, 0, 0);
    c.dt = dt;
    return wetdem_sim_eval_contact(sim, &c, NULL, &f, NULL) == WETDEM_OK ? vec3_dot(f.f_tan, t)
                                                                         : NAN;
}

double wetdem_sim_tangential_time(const struct wetdem_sim* sim, const struct wetdem_contact* c,
                                  double t_contact)
{
    if (!(isfinite(t_contact) && t_contact > 0.0 && c->v_n > 0.0) ||
        sim->history_len > WETDEM_HISTORY_SCRATCH)
        return INFINITY;
    /* The largest overlap of the impact: Hertz's t_c = 2.94 delta_max / v (Johnson 1985
     * Eq. 11.25). A linear spring's is v t_c / pi, 7 % smaller, so there the stiffnesses are
     * taken at a slightly larger overlap than reached: conservative where they grow with it. */
    double overlap = c->v_n * t_contact / 2.94, eps = 1e-4;
    /* k_n = dF_n/d(delta) by a central difference: F_n ~ delta^(3/2) (hertz) or ~ delta
     * (hooke), so the truncation error is ~eps^2 and the rounding ~1e-16/eps, both far below
     * the accuracy a time scale needs */
    double k_n = (wetdem_sim_force_at_rest(sim, *c, NULL, -overlap * (1 + eps)) -
                  wetdem_sim_force_at_rest(sim, *c, NULL, -overlap * (1 - eps))) /
                 (2 * eps * overlap);
    /* k_t from a spring stretched by u dt and by 2 u dt at the same sliding speed u: the
     * difference removes the dashpots (mindlin's, and any viscous tangential law), which
     * depend on the speed only. u dt = 1e-6 delta keeps the spring force ~1e-6 k_t delta far
     * below the Coulomb limit mu F_n ~ mu k_n delta for any mu above 1e-5 (below it the
     * tangential force is negligible, and so is this bound). */
    struct wetdem_vec3 n = c->normal;
    struct wetdem_vec3 t = vec3_some_perpendicular(n);
    t = vec3_scale(t, 1.0 / vec3_norm(t));
    double u = 1e-6 * overlap;
    double k_t = (tangential_after(sim, *c, overlap, t, u, 1.0) -
                  tangential_after(sim, *c, overlap, t, u, 2.0)) /
                 u;
    if (!(k_t > 0.0 && isfinite(k_t)))
        return INFINITY;
    /* A tangential force F at the contact point also spins both spheres (I = 2/5 m R^2):
     * d(v_t)/dt = F (1/m* + R_i^2/I_i + R_j^2/I_j) = (7/2) F/m*, so the tangential mass is
     * (2/7) m* for sphere pairs, fixed spheres and walls alike. */
    double ratio = 2.0 / 7.0 / k_t; /* 1/omega_t^2 = m_t/k_t, per kg of m* */
    if (k_n > 0.0 && isfinite(k_n)) /* omega_n/omega_t = sqrt(k_n m_t / (k_t m*)) */
        return t_contact * sqrt(ratio * k_n);
    return M_PI * sqrt(ratio * c->m_eff); /* no normal spring: the tangential half period */
}

double wetdem_sim_linear_stiffness(const struct wetdem_sim* sim, const struct wetdem_contact* c)
{
    double k = 0.0; /* (at most one normal contact law is enabled: contact_twice) */
    for (size_t m = 0; m < sim->n_models; m++) {
        const struct wetdem_model_slot* s = &sim->models[m];
        if (s->model->linear_stiffness)
            k += s->model->linear_stiffness(s->params, c);
    }
    return k;
}

int wetdem_sim_eval_contact(const struct wetdem_sim* sim, struct wetdem_contact* c, double* history,
                            struct wetdem_pair_force* out, struct wetdem_pair_force* per_model)
{
    double scratch[WETDEM_HISTORY_SCRATCH];
    if (!history) {
        if (sim->history_len > WETDEM_HISTORY_SCRATCH)
            return WETDEM_ERR_INVALID;
        wetdem_sim_history_init(sim, scratch);
        history = scratch;
    }
    *out = (struct wetdem_pair_force){0};
    c->h_min = sim->minsep.model->min_separation(sim->minsep.params, c, history);
    c->linear_stiffness = wetdem_sim_linear_stiffness(sim, c);
    for (size_t k = 0; k < sim->n_models; k++) {
        const struct wetdem_model_slot* s = &sim->models[k];
        struct wetdem_pair_force f = {0};
        int st = s->model->pair(s->params, c, history + s->history_offset, &f);
        if (st < 0)
            return st;
        out->f_normal += f.f_normal;
        out->f_tan = vec3_add(out->f_tan, f.f_tan);
        out->torque_i = vec3_add(out->torque_i, f.torque_i);
        out->torque_j = vec3_add(out->torque_j, f.torque_j);
        out->slip += f.slip;
        if (per_model)
            per_model[k] = f;
    }
    return WETDEM_OK;
}

int wetdem_sim_check_range_edge(struct wetdem_sim* sim, const struct wetdem_contact* c)
{
    if (sim->history_len > WETDEM_HISTORY_SCRATCH)
        return WETDEM_OK;
    for (size_t k = 0; k < sim->n_models; k++) {
        const struct wetdem_model_slot* s = &sim->models[k];
        if (!s->model->range || !s->model->is_in_contact)
            continue;
        struct wetdem_contact p = *c;
        p.gap = s->model->range(s->params, &p);
        if (!(p.gap > 0.0 && isfinite(p.gap)))
            continue;
        /* one evaluation there records what the pair's history keeps (nijssen: v0) */
        double history[WETDEM_HISTORY_SCRATCH];
        struct wetdem_pair_force f;
        wetdem_sim_history_init(sim, history);
        if (wetdem_sim_eval_contact(sim, &p, history, &f, NULL) != WETDEM_OK)
            continue; /* (the run reports what the models refuse) */
        if (!s->model->is_in_contact(s->params, &p, history + s->history_offset))
            continue;
        return wetdem_sim_fail(
            sim, WETDEM_ERR_INVALID,
            "model '%s' is in solid contact already at the edge of its range, gap %g m "
            "(R* = %g m, approach speed %g m/s): its minimum approach (nijssen: h_min = "
            "max(h_sigma, h_eps), the mean roughness (sigma_i + sigma_j)/2 = %g m or the "
            "elastohydrodynamic gap 0.37 R* (mu v/(E* R*))^(2/5)) is not below its cut-off "
            "(nijssen: h_co = cutoff_ratio R*), so the solid force would switch on with a jump "
            "there; lower the materials' roughness, raise their youngs_modulus or the "
            "model's cutoff_ratio",
            s->model->name, p.gap, p.r_eff, p.v_n, p.roughness);
    }
    return WETDEM_OK;
}

int wetdem_sim_pair_force(struct wetdem_sim* sim, size_t i, size_t j, struct wetdem_contact* c,
                          struct wetdem_pair_force* out)
{
    bool is_wall = j >= sim->n_particles && j != i && (size_t)-1 - j < sim->n_walls;
    if (i >= sim->n_particles || (!is_wall && (j >= sim->n_particles || j == i)))
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "pair (%zu, %zu): indices must address two different particles "
                               "(0..%zu) or a wall",
                               i, j, sim->n_particles);
    /* the particles may have been edited through wetdem_sim_particles() since they were added */
    char why[256];
    for (int side = 0; side < 2 - is_wall; side++)
        if (!wetdem_sim_particle_valid(sim, &sim->particles[side ? j : i], why, sizeof why))
            return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "particle %zu: %s", side ? j : i, why);
    if (!out)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "pair_force: out is NULL");
    struct wetdem_contact local;
    struct wetdem_contact* cc = c ? c : &local;
    wetdem_sim_build_contact(sim, i, is_wall ? (size_t)-1 - j : j, is_wall, cc);
    int st = wetdem_sim_eval_contact(sim, cc, NULL, out, NULL);
    if (st == WETDEM_OK && !contact_force_is_finite(out))
        return wetdem_sim_fail(sim, WETDEM_ERR_NUMERIC,
                               "pair (%zu, %s%zu), gap %.6g m: non-finite force", i,
                               is_wall ? "wall " : "", is_wall ? (size_t)-1 - j : j, cc->gap);
    return st;
}

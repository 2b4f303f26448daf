/*
 * scenario_build.c — turns a checked scenario into a simulation and a collision spec:
 * fluid, materials, models and their parameters, integrator, settings, and the derived
 * quantities of the collision. Every library check runs here, so a scenario that builds
 * runs without input errors; each failure names the file, the line and the key. [fluid],
 * [material.NAME] sections, [model.NAME] parameters and library errors are read the same way
 * by the many-particle builder (scenario_many.c), through the cli_scenario_* functions here.
 *
 * Derived quantities (SPEC §2, Nijssen 2023 Eq. 2 with the normal speed):
 *   m_i = rho_i (4/3) pi R_i^3;  m* = m_i m_j / (m_i + m_j) for a free target sphere, m* = m_i
 *   for a fixed sphere or a wall;  R* = R_i R_j / (R_i + R_j), R* = R_i for a wall;
 *   St_n = m* v cos(angle) / (6 pi mu R*^2)  =>  v = St_n 6 pi mu R*^2 / (m* cos(angle)).
 *   Automatic end time: t_end = N max(R*, initial_gap) / v_n, N = t_end_crossings (20: the
 *   cut-off h_co = R* of Nijssen crossed twenty times over); trajectory interval
 *   max(R*, initial_gap) / (500 v_n).
 */
#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli_util.h"
#include "scenario.h"

#define PI 3.14159265358979323846

double cli_stokes_speed(double stokes_n, double viscosity, double m_eff, double r_eff, double angle)
{
    return stokes_n * 6.0 * PI * viscosity * r_eff * r_eff / (m_eff * cos(angle));
}

int cli_scenario_lib_error(const struct cli_scenario* sc, const struct cli_entry* e,
                           const char* section, const struct wetdem_sim* sim, int status)
{
    char home[400];
    if (e && status == WETDEM_ERR_NOT_FOUND &&
        (strcmp(e->section, "sim") == 0 || strcmp(e->section, "integrator") == 0) &&
        cli_key_home(sc, e, home, sizeof home) == 1)
        cli_scenario_error(sc, e, "unknown key '%s' in [%s]: %s", e->key, e->section, home);
    else if (e)
        cli_scenario_error(sc, e, "%s", wetdem_sim_errmsg(sim));
    else
        cli_scenario_section_error(sc, section, "%s", wetdem_sim_errmsg(sim));
    return cli_setup_exit(status);
}

int cli_scenario_build_fluid(const struct cli_scenario* sc, struct wetdem_sim* sim)
{
    struct wetdem_fluid f;
    const char* preset = cli_scenario_text(sc, "fluid", "preset", "water");
    if (wetdem_fluid_preset(preset, &f) != WETDEM_OK) {
        cli_scenario_error(sc, cli_scenario_find(sc, "fluid", "preset"), "unknown fluid preset");
        return CLI_EXIT_USAGE;
    }
    const struct wetdem_param_desc* d = wetdem_fluid_params();
    for (size_t k = 0; d[k].name; k++) {
        const struct cli_entry* e = cli_scenario_find(sc, "fluid", d[k].name);
        if (e)
            *(double*)((char*)&f + d[k].offset) = strtod(e->value, NULL);
    }
    int st = wetdem_sim_set_fluid(sim, &f);
    if (st != WETDEM_OK)
        return cli_scenario_lib_error(sc, NULL, "fluid", sim, st);
    return CLI_EXIT_OK;
}

int cli_scenario_material_section(const struct cli_scenario* sc, const char* section,
                                  struct wetdem_material* m)
{
    const struct cli_entry* p = cli_scenario_find(sc, section, "preset");
    wetdem_param_init_defaults(wetdem_material_params(), m);
    if (p && wetdem_material_preset(p->value, m) != WETDEM_OK) {
        const char* const* names = wetdem_material_preset_names();
        const char* hint = wetdem_param_suggest(p->value, names);
        char list[512] = "";
        for (size_t k = 0, used = 0; !hint && names[k] && used < sizeof list; k++)
            used +=
                (size_t)snprintf(list + used, sizeof list - used, "%s%s", k ? ", " : "", names[k]);
        if (hint)
            cli_scenario_error(sc, p, "unknown material preset (did you mean '%s'?)", hint);
        else
            cli_scenario_error(sc, p, "unknown material preset; the presets are %s", list);
        return CLI_EXIT_USAGE;
    }
    const struct wetdem_param_desc* d = wetdem_material_params();
    for (size_t k = 0; d[k].name; k++) {
        const struct cli_entry* e = cli_scenario_find(sc, section, d[k].name);
        if (e)
            *(double*)((char*)m + d[k].offset) = strtod(e->value, NULL);
    }
    char msg[512];
    if (wetdem_material_validate(m, msg, sizeof msg) != WETDEM_OK) {
        cli_scenario_section_error(sc, section, "%s", msg);
        return CLI_EXIT_USAGE;
    }
    return CLI_EXIT_OK;
}

int cli_scenario_check_materials(const struct cli_scenario* sc)
{
    for (size_t k = 0; k < sc->n_sections; k++) {
        struct wetdem_material m;
        int rc = strncmp(sc->sections[k].name, "material.", 9) == 0
                     ? cli_scenario_material_section(sc, sc->sections[k].name, &m)
                     : CLI_EXIT_OK;
        if (rc != CLI_EXIT_OK)
            return rc;
    }
    return CLI_EXIT_OK;
}

/* Whether [models] force or min_separation was given by --set (line 0). */
static bool models_chosen_by_set(const struct cli_scenario* sc)
{
    const struct cli_entry* force = cli_scenario_find(sc, "models", "force");
    const struct cli_entry* ms = cli_scenario_find(sc, "models", "min_separation");
    return (force && force->line == 0) || (ms && ms->line == 0);
}

int cli_scenario_set_model_params(const struct cli_scenario* sc, struct wetdem_sim* sim)
{
    bool switched = models_chosen_by_set(sc);
    for (size_t k = 0; k < sc->n_entries; k++) {
        const struct cli_entry* p = &sc->entries[k];
        if (strncmp(p->section, "model.", 6) != 0)
            continue;
        char name[2 * CLI_NAME_MAX];
        snprintf(name, sizeof name, "%s.%s", p->section + 6, p->key);
        double v;
        bool enabled = wetdem_sim_param(sim, name, &v) == WETDEM_OK;
        if (!enabled && switched && p->line > 0)
            continue; /* the file's section of a model that a --set of [models] left out */
        if (!enabled) {
            cli_scenario_error(sc, p,
                               "model '%s' is not enabled by [models] force or "
                               "min_separation, so it has no parameters to set",
                               p->section + 6);
            return CLI_EXIT_USAGE;
        }
        int st = wetdem_sim_set_param_str(sim, name, p->value);
        if (st != WETDEM_OK)
            return cli_scenario_lib_error(sc, p, p->section, sim, st);
    }
    return CLI_EXIT_OK;
}

/* Names a material can have: presets and [material.NAME] sections (for suggestions). */
static void material_names(const struct cli_scenario* sc, const char** names, size_t cap)
{
    size_t n = 0;
    const char* const* presets = wetdem_material_preset_names();
    for (size_t k = 0; presets[k] && n + 1 < cap; k++)
        names[n++] = presets[k];
    for (size_t k = 0; k < sc->n_sections && n + 1 < cap; k++)
        if (strncmp(sc->sections[k].name, "material.", 9) == 0)
            names[n++] = sc->sections[k].name + 9;
    names[n] = NULL;
}

/* Resolves a material name (section first, then preset) into *m. */
static int resolve_material(const struct cli_scenario* sc, const struct cli_entry* use,
                            const char* name, struct wetdem_material* m)
{
    char section[CLI_NAME_MAX];
    snprintf(section, sizeof section, "material.%s", name);
    if (!cli_scenario_has_section(sc, section)) {
        if (wetdem_material_preset(name, m) == WETDEM_OK)
            return CLI_EXIT_OK;
        const char* names[64];
        material_names(sc, names, 64);
        const char* hint = wetdem_param_suggest(name, names);
        cli_scenario_error(sc, use,
                           "unknown material '%s'%s%s%s: use a preset (wetdem docs-models lists "
                           "them) or define a [material.%s] section",
                           name, hint ? " (did you mean '" : "", hint ? hint : "",
                           hint ? "'?)" : "", name);
        return CLI_EXIT_USAGE;
    }
    return cli_scenario_material_section(sc, section, m);
}

/* Adds striker and target materials; sets spec material indices. */
static int build_materials(const struct cli_scenario* sc, struct cli_setup* su,
                           struct wetdem_material* mi, struct wetdem_material* mj)
{
    const char* si = cli_scenario_text(sc, "collision", "striker", "steel1");
    const char* sj = cli_scenario_text(sc, "collision", "target_material", si);
    const struct cli_entry* ei = cli_scenario_find(sc, "collision", "striker");
    const struct cli_entry* ej = cli_scenario_find(sc, "collision", "target_material");
    struct cli_entry dflt = {
        .section = "collision", .key = "striker", .value = "steel1", .line = 1};
    int rc;
    if ((rc = resolve_material(sc, ei ? ei : &dflt, si, mi)) != CLI_EXIT_OK ||
        (rc = resolve_material(sc, ej ? ej : (ei ? ei : &dflt), sj, mj)) != CLI_EXIT_OK)
        return rc;
    int ki = wetdem_sim_add_material(su->sim, mi);
    if (ki < 0)
        return cli_scenario_lib_error(sc, ei, "collision", su->sim, ki);
    int kj = ki;
    if (strcmp(si, sj) != 0 && (kj = wetdem_sim_add_material(su->sim, mj)) < 0)
        return cli_scenario_lib_error(sc, ej, "collision", su->sim, kj);
    su->spec.material_i = ki;
    su->spec.material_j = kj;
    return CLI_EXIT_OK;
}

static int enable_forces(const struct cli_scenario* sc, struct wetdem_sim* sim)
{
    const struct cli_entry* e = cli_scenario_find(sc, "models", "force");
    char buf[CLI_VALUE_MAX];
    snprintf(buf, sizeof buf, "%s", e ? e->value : "hertz");
    char* save = NULL;
    for (char* tok = strtok_r(buf, " ,\t", &save); tok; tok = strtok_r(NULL, " ,\t", &save)) {
        const struct wetdem_model* m = wetdem_model_find(tok);
        if (m && m->kind == WETDEM_MODEL_MIN_SEPARATION) {
            cli_scenario_error(sc, e,
                               "'%s' is a minimum-separation model: write "
                               "'min_separation = %s'",
                               tok, tok);
            return CLI_EXIT_USAGE;
        }
        int st = wetdem_sim_enable_model(sim, tok);
        if (st != WETDEM_OK)
            return cli_scenario_lib_error(sc, e, "models", sim, st);
    }
    return CLI_EXIT_OK;
}

int cli_scenario_enable_min_separation(const struct cli_scenario* sc, struct wetdem_sim* sim)
{
    const struct cli_entry* e = cli_scenario_find(sc, "models", "min_separation");
    if (!e)
        return CLI_EXIT_OK;
    const struct wetdem_model* m = wetdem_model_find(e->value);
    if (m && m->kind != WETDEM_MODEL_MIN_SEPARATION) {
        const char* kind = wetdem_model_kind_name(m->kind);
        cli_scenario_error(sc, e, "'%s' is %s %s model, not a minimum-separation model", e->value,
                           cli_article(kind), kind);
        return CLI_EXIT_USAGE;
    }
    int st = wetdem_sim_enable_model(sim, e->value);
    if (st != WETDEM_OK)
        return cli_scenario_lib_error(sc, e, "models", sim, st);
    return CLI_EXIT_OK;
}

static int build_models(const struct cli_scenario* sc, struct wetdem_sim* sim)
{
    wetdem_sim_clear_models(sim);
    int rc = enable_forces(sc, sim);
    if (rc == CLI_EXIT_OK)
        rc = cli_scenario_enable_min_separation(sc, sim);
    return rc == CLI_EXIT_OK ? cli_scenario_set_model_params(sc, sim) : rc;
}

/* Whether an integrator other than `chosen` has the parameter `key` (cvode's rtol, say, where
 * verlet is chosen). */
static bool other_integrator_has(const char* chosen, const char* key)
{
    struct wetdem_sim* probe = wetdem_sim_create();
    const char* const* names = wetdem_integrator_names();
    bool found = false;
    for (size_t k = 0; probe && names[k] && !found; k++) {
        char full[CLI_VALUE_MAX + CLI_NAME_MAX + 2];
        snprintf(full, sizeof full, "%s.%s", names[k], key);
        double v;
        found = strcmp(names[k], chosen) != 0 &&
                wetdem_sim_set_integrator(probe, names[k]) == WETDEM_OK &&
                wetdem_sim_param(probe, full, &v) == WETDEM_OK;
    }
    wetdem_sim_free(probe);
    return found;
}

/* The parameter of any integrator closest to `key` (wetdem_param_suggest), those of `chosen`
 * first, so that it has a tie; *owner is the integrator it belongs to. NULL: none is close. */
static const char* integrator_key_suggest(const char* chosen, const char* key, const char** owner)
{
    const char* const* names = wetdem_integrator_names();
    const char* keys[128];
    const char* of[128];
    size_t n = 0;
    for (int pass = 0; pass < 2; pass++) /* (the chosen integrator's first) */
        for (size_t k = 0; names[k]; k++) {
            const struct wetdem_param_desc* d = wetdem_integrator_params(names[k]);
            if ((strcmp(names[k], chosen) == 0) != (pass == 0) || !d)
                continue;
            for (size_t j = 0; d[j].name && n + 1 < sizeof keys / sizeof keys[0]; j++) {
                of[n] = names[k];
                keys[n++] = d[j].name;
            }
        }
    keys[n] = NULL;
    const char* hint = wetdem_param_suggest(key, keys);
    for (size_t k = 0; hint && k < n; k++)
        if (keys[k] == hint)
            *owner = of[k];
    return hint;
}

/* Reports the [integrator] or [sim] key p that the library refused with `status`
 * (cli_scenario_set_integrator_keys). Returns the exit code. */
static int integrator_error(const struct cli_scenario* sc, const struct cli_entry* p,
                            const char* chosen, bool many, const struct wetdem_sim* sim, int status)
{
    static const char* const name_key[] = {"name", NULL};
    bool integrator = strcmp(p->section, "integrator") == 0;
    if (integrator && wetdem_param_suggest(p->key, name_key)) {
        cli_scenario_error(sc, p, "unknown key '%s' in [integrator] (did you mean 'name'?)",
                           p->key);
        return CLI_EXIT_USAGE;
    }
    /* the library suggests among the chosen integrator's parameters (and the other dotted
       names): a typo of the other's (rtoll, where verlet steps) is named with its owner */
    const char* owner = NULL;
    const char* hint = integrator && status == WETDEM_ERR_NOT_FOUND
                           ? integrator_key_suggest(chosen, p->key, &owner)
                           : NULL;
    char home[400];
    if (!hint || strcmp(owner, chosen) == 0 || cli_key_home(sc, p, home, sizeof home) == 1)
        return cli_scenario_lib_error(sc, p, p->section, sim, status);
    cli_scenario_error(sc, p,
                       "unknown parameter '%s.%s' (did you mean '%s', a parameter of the %s "
                       "integrator? %s %s%s)",
                       chosen, p->key, hint, owner,
                       many ? "a many-particle run steps with" : "the scenario uses", chosen,
                       many ? "" : ": [integrator] name");
    return CLI_EXIT_USAGE;
}

int cli_scenario_set_integrator_keys(const struct cli_scenario* sc, struct wetdem_sim* sim,
                                     const char* chosen, bool many)
{
    for (size_t k = 0; k < sc->n_entries; k++) {
        const struct cli_entry* p = &sc->entries[k];
        bool is_integrator = strcmp(p->section, "integrator") == 0 && strcmp(p->key, "name");
        if (!is_integrator && strcmp(p->section, "sim") != 0)
            continue;
        char full[CLI_VALUE_MAX + CLI_NAME_MAX + 2];
        snprintf(full, sizeof full, "%s.%s", is_integrator ? chosen : "sim", p->key);
        double current;
        if (is_integrator && wetdem_sim_param(sim, full, &current) == WETDEM_ERR_NOT_FOUND &&
            other_integrator_has(chosen, p->key))
            continue; /* a parameter of the integrator not chosen (e.g. --set name=verlet) */
        int st = wetdem_sim_set_param_str(sim, full, p->value);
        if (st != WETDEM_OK)
            return integrator_error(sc, p, chosen, many, sim, st);
    }
    return CLI_EXIT_OK;
}

/* [integrator] name and parameters ("<name>.<key>"), [sim] settings ("sim.<key>").
 * Parameters of an integrator other than the chosen one are skipped, so a file tuned for
 * cvode also runs with --set integrator.name=verlet; a key no integrator has is an error. */
static int build_integrator(const struct cli_scenario* sc, struct wetdem_sim* sim)
{
    const struct cli_entry* e = cli_scenario_find(sc, "integrator", "name");
    const char* name = e ? e->value : "verlet";
    if (wetdem_sim_set_integrator(sim, name) != WETDEM_OK) {
        struct cli_entry d = {.section = "integrator", .key = "name", .line = 1};
        snprintf(d.value, sizeof d.value, "%s", name);
        cli_scenario_error(sc, e ? e : &d, "%s", wetdem_sim_errmsg(sim));
        return CLI_EXIT_USAGE;
    }
    return cli_scenario_set_integrator_keys(sc, sim, name, false);
}

/* Radii, masses, R*, m*, the impact speed and the times of the collision. */
static int build_kinematics(const struct cli_scenario* sc, struct cli_setup* su,
                            const struct wetdem_material* mi, const struct wetdem_material* mj)
{
    struct wetdem_collision_spec* s = &su->spec;
    const char* target = cli_scenario_text(sc, "collision", "target", "sphere");
    s->target_is_wall = strcmp(target, "wall") == 0;
    s->target_is_fixed = strcmp(target, "fixed") == 0;
    s->radius_i = cli_scenario_number(sc, "collision", "striker_radius", 6.35e-3);
    s->radius_j = cli_scenario_number(sc, "collision", "target_radius", s->radius_i);
    double m_i = wetdem_material_sphere_mass(mi, s->radius_i);
    double m_j = wetdem_material_sphere_mass(mj, s->radius_j);
    bool free_target = !s->target_is_wall && !s->target_is_fixed;
    bool striker_ok = isfinite(m_i) && m_i > 0, target_ok = isfinite(m_j) && m_j > 0;
    /* a radius or density near the ends of the double range */
    if (!striker_ok || (free_target && !target_ok)) {
        const char* who = striker_ok ? "target" : "striker";
        const struct cli_entry* e =
            cli_scenario_find(sc, "collision", striker_ok ? "target_radius" : "striker_radius");
        double m = striker_ok ? m_j : m_i;
        if (e)
            cli_scenario_error(sc, e,
                               "gives a mass density x 4/3 pi R^3 = %g kg, not a positive finite "
                               "number: check the radius and the material's density",
                               m);
        else
            cli_scenario_section_error(sc, "collision",
                                       "the %s's mass density x 4/3 pi R^3 = %g kg is not a "
                                       "positive finite number: check its radius and density",
                                       who, m);
        return CLI_EXIT_USAGE;
    }
    su->m_eff = free_target ? m_i * m_j / (m_i + m_j) : m_i;
    su->r_eff =
        s->target_is_wall ? s->radius_i : s->radius_i * s->radius_j / (s->radius_i + s->radius_j);
    s->angle = cli_scenario_number(sc, "collision", "angle_deg", 0) * PI / 180.0;
    const struct cli_entry* ev = cli_scenario_find(sc, "collision", "speed");
    const struct cli_entry* es = cli_scenario_find(sc, "collision", "stokes");
    double speed = ev ? strtod(ev->value, NULL) : 0, stokes = es ? strtod(es->value, NULL) : 0;
    double mu = wetdem_sim_fluid(su->sim).viscosity;
    if (speed > 0 && stokes > 0) {
        cli_scenario_error(sc, (ev->line == 0 || (es->line != 0 && ev->line > es->line)) ? ev : es,
                           "give either speed or stokes, not both (speed is derived from stokes)");
        return CLI_EXIT_USAGE;
    }
    if (!(speed > 0) && !(stokes > 0)) {
        cli_scenario_section_error(sc, "collision", "needs speed > 0 [m/s] or stokes > 0 [-]");
        return CLI_EXIT_USAGE;
    }
    if (stokes > 0 && !(mu > 0)) {
        cli_scenario_error(sc, es, "a Stokes number needs a fluid viscosity > 0, got %g Pa s", mu);
        return CLI_EXIT_USAGE;
    }
    if (stokes > 0)
        speed = cli_stokes_speed(stokes, mu, su->m_eff, su->r_eff, s->angle);
    if (!(speed > 0 && speed <= 1e3)) {
        cli_scenario_error(sc, es, "the derived impact speed %g m/s is outside (0, 1e3] m/s",
                           speed);
        return CLI_EXIT_USAGE;
    }
    if (!(0.5 * su->m_eff * speed * speed >= DBL_MIN)) { /* e = |dv_f|/|dv_0| would be 0/0 */
        cli_scenario_error(sc, ev ? ev : es,
                           "gives an impact speed of %g m/s, whose kinetic energy m* v^2 / 2 "
                           "= %g J underflows a double: e and energy_ratio would be 0/0",
                           speed, 0.5 * su->m_eff * speed * speed);
        return CLI_EXIT_USAGE;
    }
    su->impact_speed = speed;
    s->speed = speed;
    double v_n = speed * cos(s->angle);
    su->stokes_n = mu > 0 ? su->m_eff * v_n / (6.0 * PI * mu * su->r_eff * su->r_eff) : INFINITY;
    s->stokes = mu > 0 ? su->stokes_n : 0;
    s->omega_i = (struct wetdem_vec3){cli_scenario_number(sc, "collision", "spin_x", 0),
                                      cli_scenario_number(sc, "collision", "spin_y", 0),
                                      cli_scenario_number(sc, "collision", "spin_z", 0)};
    s->initial_gap = cli_scenario_number(sc, "collision", "initial_gap", 0);
    double t_cross = fmax(su->r_eff, s->initial_gap) / v_n;
    s->t_end = cli_scenario_number(sc, "collision", "t_end", 0);
    bool t_end_auto = s->t_end == 0;
    if (t_end_auto)
        s->t_end = cli_scenario_number(sc, "collision", "t_end_crossings", 20) * t_cross;
    if (!(s->t_end >= WETDEM_MIN_SPAN)) { /* a radius near the least double, say */
        if (t_end_auto)
            cli_scenario_section_error(sc, "collision",
                                       "the automatic t_end = %g s (t_end_crossings x "
                                       "max(R*, initial_gap) / v_n) is below %g s, the "
                                       "shortest run CVODE integrates: give t_end",
                                       s->t_end, WETDEM_MIN_SPAN);
        else
            cli_scenario_error(sc, cli_scenario_find(sc, "collision", "t_end"),
                               "is below %g s, the shortest run CVODE integrates: give 0 "
                               "(automatic) or a longer time",
                               WETDEM_MIN_SPAN);
        return CLI_EXIT_USAGE;
    }
    s->observe_time = cli_scenario_number(sc, "collision", "observe_time", 0);
    s->rebound_gap_factor = cli_scenario_number(sc, "collision", "rebound_gap_factor", 1);
    s->close_gap = cli_scenario_number(sc, "collision", "close_gap", 0);
    su->trajectory_interval = cli_scenario_number(sc, "output", "trajectory_interval", 0);
    if (su->trajectory_interval == 0)
        su->trajectory_interval = t_cross / 500.0;
    return CLI_EXIT_OK;
}

int cli_scenario_out_name(const struct cli_scenario* sc, const char* section, const char* key,
                          const char* def, char* out)
{
    const struct cli_entry* e = cli_scenario_find(sc, section, key);
    const char* v = e ? e->value : def;
    snprintf(out, CLI_VALUE_MAX, "%s", strcmp(v, "none") == 0 ? "" : v);
    if (e && (strchr(v, '/') || !v[0] || v[0] == '.')) {
        cli_scenario_error(sc, e,
                           "a file name in the --out directory (no '/', not starting with '.'), "
                           "or none");
        return CLI_EXIT_USAGE;
    }
    return CLI_EXIT_OK;
}

int cli_scenario_check_outputs(const struct cli_scenario* sc)
{
    static const char* const key[3] = {"trajectory", "events", "summary"};
    static const char* const def[3] = {"trajectory.csv", "events.csv", "summary.json"};
    char name[3][CLI_VALUE_MAX];
    for (int k = 0; k < 3; k++)
        if (cli_scenario_out_name(sc, "output", key[k], def[k], name[k]) != CLI_EXIT_OK)
            return CLI_EXIT_USAGE;
    for (int k = 1; k < 3; k++)
        for (int j = 0; j < k; j++)
            if (name[k][0] && strcmp(name[k], name[j]) == 0) {
                const struct cli_entry* e = cli_scenario_find(sc, "output", key[k]);
                cli_scenario_error(sc, e ? e : cli_scenario_find(sc, "output", key[j]),
                                   "%s would name both the %s and the %s: give the outputs of "
                                   "--out distinct names",
                                   name[k], key[j], key[k]);
                return CLI_EXIT_USAGE;
            }
    return CLI_EXIT_OK;
}

int cli_scenario_check_trajectory(const struct cli_scenario* sc, const char* run_section,
                                  double t_end, double interval)
{
    double rows = t_end / interval;
    if (rows <= CLI_MAX_TRAJECTORY_ROWS)
        return CLI_EXIT_OK;
    const struct cli_entry* e = cli_scenario_find(sc, "output", "trajectory_interval");
    const char* fmt = "a trajectory row every %g s over t_end = %g s makes %.3g rows, more than "
                      "%g: raise trajectory_interval, or set trajectory = none";
    if (e && strtod(e->value, NULL) > 0)
        cli_scenario_error(sc, e, fmt, interval, t_end, rows, CLI_MAX_TRAJECTORY_ROWS);
    else
        cli_scenario_section_error(sc,
                                   cli_scenario_has_section(sc, "output") ? "output" : run_section,
                                   fmt, interval, t_end, rows, CLI_MAX_TRAJECTORY_ROWS);
    return CLI_EXIT_USAGE;
}

/* The thin-film models: they act only where the pair's films overlap (h <= delta); all but
 * capillary read h_min, capped at delta (docs/models.md). */
static bool is_thin_film_model(const char* name, bool* reads_h_min)
{
    static const char* const names[] = {"sb", "db", "davis", "nase", "capillary", NULL};
    for (size_t k = 0; names[k]; k++)
        if (strcmp(name, names[k]) == 0) {
            *reads_h_min = strcmp(name, "capillary") != 0;
            return true;
        }
    return false;
}

void cli_scenario_warning(const struct cli_scenario* sc, const struct cli_entry* e, const char* fmt,
                          ...)
{
    va_list ap;
    va_start(ap, fmt);
    if (e->line > 0)
        fprintf(stderr, "wetdem: warning: %s:%d: [%s] %s = %s: ", sc->file, e->line, e->section,
                e->key, e->value);
    else
        fprintf(stderr, "wetdem: warning: %s: --set %s.%s=%s: ", sc->file, e->section, e->key,
                e->value);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
}

void cli_scenario_warn_films(const struct cli_scenario* sc, const struct wetdem_sim* sim,
                             double delta, const char* films, double roughness, const char* roughs)
{
    static atomic_flag warned = ATOMIC_FLAG_INIT;
    char all[256] = "", reading[256] = "";
    size_t n_all = 0, n_reading = 0;
    for (size_t k = 0; k < wetdem_sim_n_models(sim); k++) {
        const char* name = wetdem_sim_model(sim, k)->name;
        bool reads_h_min = false;
        if (!is_thin_film_model(name, &reads_h_min))
            continue;
        n_all += (size_t)snprintf(all + n_all, sizeof all - n_all, "%s%s", n_all ? ", " : "", name);
        if (reads_h_min)
            n_reading += (size_t)snprintf(reading + n_reading, sizeof reading - n_reading, "%s%s",
                                          n_reading ? ", " : "", name);
        if (n_all >= sizeof all || n_reading >= sizeof reading)
            break;
    }
    const struct wetdem_model* ms = wetdem_sim_min_separation_model(sim);
    double h_min = 0;
    bool fixed = ms && strcmp(ms->name, "fixed") == 0 &&
                 wetdem_sim_param(sim, "fixed.h_min", &h_min) == WETDEM_OK;
    /* roughness: h_min = (sigma_i + sigma_j)/2; max: at least that */
    bool rough = ms && (strcmp(ms->name, "roughness") == 0 || strcmp(ms->name, "max") == 0);
    bool dry = n_all > 0 && !(delta > 0);
    bool capped =
        !dry && n_reading > 0 && ((fixed && h_min >= delta) || (rough && roughness >= delta));
    if ((!dry && !capped) || atomic_flag_test_and_set(&warned))
        return;
    const struct cli_entry* force = cli_scenario_find(sc, "models", "force");
    if (dry) {
        bool plural = strchr(all, ',') != NULL;
        if (force)
            cli_scenario_warning(
                sc, force,
                "the thin-film model%s %s act%s only within the pair's liquid film, but "
                "the film thickness delta = 0 m (%s): the run is dry for %s; give the "
                "materials a film > 0 [m] ([material.NAME] film = ...) or leave %s out",
                plural ? "s" : "", all, plural ? "" : "s", films, plural ? "them" : "it",
                plural ? "them" : "it");
        return;
    }
    const char* takes = strchr(reading, ',') ? "" : "s";
    if (rough) {
        const struct cli_entry* e = cli_scenario_find(sc, "models", "min_separation");
        bool is_max = strcmp(ms->name, "max") == 0;
        if (e)
            cli_scenario_warning(
                sc, e,
                "h_min %s the mean roughness (sigma_i + sigma_j)/2 = %g m (%s), which is at "
                "or above the pair's film thickness delta = %g m (%s): %s take%s h_min "
                "capped at delta, so the film has no range left above h_min; give the "
                "materials a roughness below %g m or thicker films",
                is_max ? "is at least" : "is", roughness, roughs, delta, films, reading, takes,
                delta);
        return;
    }
    const struct cli_entry* e = cli_scenario_find(sc, "model.fixed", "h_min");
    const char* whose = e ? "" : " (fixed's default)";
    if (!e && !(e = cli_scenario_find(sc, "models", "min_separation")) && !(e = force))
        return;
    cli_scenario_warning(
        sc, e,
        "h_min = %g m%s is at or above the pair's film thickness delta = %g m (%s): %s "
        "take%s h_min capped at delta, so the film has no range left above h_min; set "
        "[model.fixed] h_min below %g m or give the materials thicker films",
        h_min, whose, delta, films, reading, takes, delta);
}

/* Whether section k of sc is a [material.NAME] that none of used[0 .. n_used) names. */
static bool unused_material(const struct cli_scenario* sc, size_t k, const char* const* used,
                            size_t n_used)
{
    const char* name = sc->sections[k].name;
    if (strncmp(name, "material.", 9) != 0)
        return false;
    for (size_t j = 0; j < n_used; j++)
        if (strcmp(used[j], name + 9) == 0)
            return false;
    return true;
}

void cli_scenario_warn_unused_materials(const struct cli_scenario* sc, const char* const* used,
                                        size_t n_used, const char* how)
{
    static atomic_flag warned = ATOMIC_FLAG_INIT;
    bool any = false;
    for (size_t k = 0; k < sc->n_sections && !any; k++)
        any = unused_material(sc, k, used, n_used);
    if (!any || atomic_flag_test_and_set(&warned))
        return;
    for (size_t k = 0; k < sc->n_sections; k++)
        if (unused_material(sc, k, used, n_used))
            cli_error("warning: %s:%d: [%s] is not used: %s", sc->file, sc->sections[k].line,
                      sc->sections[k].name, how);
}

/* The force models that read the min-separation model's h_min (docs/models.md); nijssen
 * takes its own h_min = max(h_sigma, h_eps), the others none. */
static bool reads_min_separation(const char* name)
{
    static const char* const names[] = {"reynolds", "sb", "db", "davis", "nase", NULL};
    for (size_t k = 0; names[k]; k++)
        if (strcmp(name, names[k]) == 0)
            return true;
    return false;
}

/* Whether entry e of the file is one that a --set of `by`, the key that leaves it unread,
 * set aside (a file tuned for cvode run with --set integrator.name=verlet, say). */
static bool set_aside(const struct cli_entry* e, const struct cli_entry* by)
{
    return e->line > 0 && by && by->line == 0;
}

/* A key the run does not read, and why (for cli_scenario_warn_ignored). */
struct ignored_key {
    const struct cli_entry* e;
    char why[480];
};

#define MAX_IGNORED 32

/* [integrator] keys that the engine's step does not read: the other integrator's parameters,
 * the other engine's step bound, and the step's derivation when a step is given. */
static size_t ignored_integrator_keys(const struct cli_scenario* sc, const struct wetdem_sim* sim,
                                      bool many, struct ignored_key* out)
{
    const char* name = many ? "verlet" : wetdem_sim_integrator_name(sim);
    const struct cli_entry* ne = cli_scenario_find(sc, "integrator", "name");
    const struct cli_entry* run_dt = many ? cli_scenario_find(sc, "run", "dt") : NULL;
    const struct cli_entry* dt = cli_scenario_find(sc, "integrator", "dt");
    if (run_dt && !(strtod(run_dt->value, NULL) > 0))
        run_dt = NULL;
    if (dt && !(strtod(dt->value, NULL) > 0))
        dt = NULL;
    size_t n = 0;
    for (size_t k = 0; k < sc->n_entries && n < MAX_IGNORED; k++) {
        const struct cli_entry* e = &sc->entries[k];
        if (strcmp(e->section, "integrator") != 0 || strcmp(e->key, "name") == 0)
            continue;
        char full[2 * CLI_NAME_MAX];
        snprintf(full, sizeof full, "%s.%s", name, e->key);
        double v;
        char* why = out[n].why;
        size_t size = sizeof out[n].why;
        /* (many_hmin_fraction is read with a step given: 0 turns off the warning about a
           step that crosses h_min, cli/run_many.c) */
        bool derives = strcmp(e->key, "dt_fraction") == 0;
        const struct cli_entry* given = run_dt ? run_dt : dt;
        if (!many && strcmp(e->key, "many_hmin_fraction") == 0)
            snprintf(why, size,
                     "only many-particle runs hold their step with it; a binary collision's "
                     "verlet step reads hmin_fraction (0, off, by default), so it has no "
                     "effect here: use hmin_fraction");
        else if (many && strcmp(e->key, "hmin_fraction") == 0)
            snprintf(why, size,
                     "only a binary collision's verlet step reads it; a many-particle run "
                     "holds its step with many_hmin_fraction (0.5 by default), so it has no "
                     "effect here: use many_hmin_fraction");
        else if (many && wetdem_sim_param(sim, full, &v) != WETDEM_OK)
            snprintf(why, size,
                     "a parameter of the cvode integrator, which a many-particle run does not "
                     "use (it steps with velocity Verlet), so it has no effect: remove it");
        else if (!many && wetdem_sim_param(sim, full, &v) != WETDEM_OK) {
            if (set_aside(e, ne))
                continue;
            const char* other = strcmp(name, "verlet") == 0 ? "cvode" : "verlet";
            snprintf(why, size,
                     "a parameter of the %s integrator, and [integrator] name = %s%s does not "
                     "read it, so it has no effect: remove it, or set name = %s",
                     other, name, ne ? "" : " (the default)", other);
        } else if ((derives && given && !set_aside(e, given)) ||
                   (many && run_dt && strcmp(e->key, "dt") == 0 && !set_aside(e, run_dt)))
            snprintf(why, size,
                     "the step is given ([%s] dt = %s s), so %s has no effect: remove one of "
                     "them",
                     given->section, given->value, e->key);
        else
            continue;
        out[n++].e = e;
    }
    return n;
}

/* [model.NAME] parameters of the min-separation model when no force model reads its h_min:
 * they move only the run's h_min events (hmin_reached, hmin_left), not the spheres. */
static size_t ignored_min_separation_keys(const struct cli_scenario* sc,
                                          const struct wetdem_sim* sim, struct ignored_key* out)
{
    char forces[256] = "";
    size_t used = 0;
    for (size_t k = 0; k < wetdem_sim_n_models(sim); k++) {
        const char* name = wetdem_sim_model(sim, k)->name;
        if (reads_min_separation(name))
            return 0;
        if (used < sizeof forces)
            used +=
                (size_t)snprintf(forces + used, sizeof forces - used, "%s%s", k ? ", " : "", name);
    }
    const char* ms = wetdem_sim_min_separation_model(sim)->name;
    char section[CLI_NAME_MAX];
    snprintf(section, sizeof section, "model.%s", ms);
    const struct cli_entry* force = cli_scenario_find(sc, "models", "force");
    size_t n = 0;
    for (size_t k = 0; k < sc->n_entries && n < MAX_IGNORED; k++) {
        const struct cli_entry* e = &sc->entries[k];
        if (strcmp(e->section, section) != 0 || set_aside(e, force))
            continue;
        snprintf(out[n].why, sizeof out[n].why,
                 "none of the force models (%s) reads the h_min of '%s', so this parameter "
                 "moves only the run's h_min events, not the spheres: reynolds, sb, db, davis "
                 "and nase read h_min (nijssen takes its own)",
                 used ? forces : "none", ms);
        out[n++].e = e;
    }
    return n;
}

/* [material.NAME] roughness when no model reads it: the min-separation models roughness and
 * max (h_min from it) and the force model nijssen (h_sigma) do, and nothing else. */
static size_t ignored_roughness_keys(const struct cli_scenario* sc, const struct wetdem_sim* sim,
                                     struct ignored_key* out)
{
    const char* ms = wetdem_sim_min_separation_model(sim)->name;
    if (strcmp(ms, "roughness") == 0 || strcmp(ms, "max") == 0)
        return 0;
    char forces[256] = "";
    size_t used = 0;
    for (size_t k = 0; k < wetdem_sim_n_models(sim); k++) {
        const char* name = wetdem_sim_model(sim, k)->name;
        if (strcmp(name, "nijssen") == 0)
            return 0;
        if (used < sizeof forces)
            used +=
                (size_t)snprintf(forces + used, sizeof forces - used, "%s%s", k ? ", " : "", name);
    }
    const struct cli_entry* by[] = {cli_scenario_find(sc, "models", "min_separation"),
                                    cli_scenario_find(sc, "models", "force")};
    size_t n = 0;
    for (size_t k = 0; k < sc->n_entries && n < MAX_IGNORED; k++) {
        const struct cli_entry* e = &sc->entries[k];
        if (strncmp(e->section, "material.", 9) != 0 || strcmp(e->key, "roughness") != 0 ||
            set_aside(e, by[0]) || set_aside(e, by[1]))
            continue;
        snprintf(out[n].why, sizeof out[n].why,
                 "no model of this run reads a roughness (min_separation = %s, force models: "
                 "%s), so it has no effect: min_separation = roughness or max takes h_min from "
                 "it, and the force model nijssen its h_sigma",
                 ms, used ? forces : "none");
        out[n++].e = e;
    }
    return n;
}

/* [sim] stop_on_separation and separation_factor where the run does not read them: a
 * many-particle run does not stop on separation, and a binary collision sets both itself
 * (src/collision.c: it always stops, beyond [collision] rebound_gap_factor x the range). */
static size_t ignored_sim_keys(const struct cli_scenario* sc, bool many, struct ignored_key* out)
{
    bool collision = !many && cli_scenario_has_section(sc, "collision");
    if (!many && !collision)
        return 0;
    const char* const names[] = {"stop_on_separation", "separation_factor"};
    size_t n = 0;
    for (int k = 0; k < 2; k++) {
        const struct cli_entry* e = cli_scenario_find(sc, "sim", names[k]);
        if (!e)
            continue;
        if (many)
            snprintf(out[n].why, sizeof out[n].why,
                     "a many-particle run does not stop on separation: it runs to [run] t_end "
                     "or steps, so it has no effect here: remove it");
        else if (k == 0)
            snprintf(out[n].why, sizeof out[n].why,
                     "a binary collision always stops once its spheres have separated, so it "
                     "has no effect here: remove it");
        else
            snprintf(out[n].why, sizeof out[n].why,
                     "a binary collision counts its spheres as separated beyond [collision] "
                     "rebound_gap_factor x their range, so it has no effect here: use "
                     "rebound_gap_factor");
        out[n++].e = e;
    }
    return n;
}

void cli_scenario_warn_ignored(const struct cli_scenario* sc, const struct wetdem_sim* sim,
                               bool many)
{
    static atomic_flag warned = ATOMIC_FLAG_INIT;
    struct ignored_key keys[3 * MAX_IGNORED + 3];
    size_t n = ignored_integrator_keys(sc, sim, many, keys);
    n += ignored_min_separation_keys(sc, sim, keys + n);
    n += ignored_roughness_keys(sc, sim, keys + n);
    n += ignored_sim_keys(sc, many, keys + n);
    const struct cli_entry* target = cli_scenario_find(sc, "collision", "target");
    const struct cli_entry* radius = cli_scenario_find(sc, "collision", "target_radius");
    if (!many && target && strcmp(target->value, "wall") == 0 && radius &&
        !set_aside(radius, target)) {
        snprintf(keys[n].why, sizeof keys[n].why,
                 "a wall has no radius (with target = wall, R* = striker_radius and m* the "
                 "striker's mass), so it has no effect: remove it, or set target = sphere or "
                 "fixed");
        keys[n++].e = radius;
    }
    if (n == 0 || atomic_flag_test_and_set(&warned))
        return;
    for (size_t k = 0; k < n; k++)
        cli_scenario_warning(sc, keys[k].e, "%s", keys[k].why);
}

void cli_scenario_warn_no_contact(const struct cli_scenario* sc, const struct wetdem_sim* sim)
{
    static atomic_flag warned = ATOMIC_FLAG_INIT;
    char forces[256] = "", contact[256] = "";
    size_t n_forces = 0, n_contact = 0;
    for (size_t k = 0; k < wetdem_sim_n_models(sim); k++) {
        const struct wetdem_model* m = wetdem_sim_model(sim, k);
        if (m->contact_time)
            return;
        if (n_forces < sizeof forces)
            n_forces += (size_t)snprintf(forces + n_forces, sizeof forces - n_forces, "%s%s",
                                         k ? ", " : "", m->name);
    }
    const struct cli_entry* force = cli_scenario_find(sc, "models", "force");
    if (!force || atomic_flag_test_and_set(&warned))
        return;
    /* the models with a solid contact (a contact time); the impulse model hard is the
       pairwise engine's */
    for (const struct wetdem_model* const* r = wetdem_model_registry(); *r; r++)
        if ((*r)->contact_time && n_contact < sizeof contact)
            n_contact += (size_t)snprintf(contact + n_contact, sizeof contact - n_contact, "%s%s",
                                          n_contact ? ", " : "", (*r)->name);
    cli_scenario_warning(sc, force,
                         "%s%s%s no contact model, so nothing holds the surfaces apart where "
                         "they touch: only the fluid forces slow the approach, and the spheres "
                         "overlap as far as those let them; add a contact model: %s (nijssen "
                         "includes its Hertz-Mindlin contact)",
                         n_forces ? "the force models (" : "", n_forces ? forces : "it enables",
                         n_forces ? ") include" : "", contact);
}

int cli_scenario_engine(const struct cli_scenario* sc, enum cli_engine* engine)
{
    const char* t = cli_scenario_text(sc, "engine", "type", "soft");
    *engine = strcmp(t, "pairwise") == 0 ? CLI_ENGINE_PAIRWISE : CLI_ENGINE_SOFT;
    return CLI_EXIT_OK;
}

int cli_scenario_build(const struct cli_scenario* sc, struct cli_setup* su)
{
    static const char* const reads[] = {"engine",  "collision",  "material.*", "fluid",  "models",
                                        "model.*", "integrator", "sim",        "output", NULL};
    memset(su, 0, sizeof *su);
    cli_scenario_engine(sc, &su->engine);
    if (cli_scenario_check_read(sc, "a binary collision", reads) != CLI_EXIT_OK)
        return CLI_EXIT_USAGE;
    su->sim = wetdem_sim_create();
    if (!su->sim) {
        cli_error("out of memory creating a simulation");
        return CLI_EXIT_RUNTIME;
    }
    struct wetdem_material mi, mj;
    int rc;
    if ((rc = cli_scenario_build_fluid(sc, su->sim)) != CLI_EXIT_OK ||
        (rc = cli_scenario_check_materials(sc)) != CLI_EXIT_OK ||
        (rc = build_materials(sc, su, &mi, &mj)) != CLI_EXIT_OK ||
        (rc = build_models(sc, su->sim)) != CLI_EXIT_OK ||
        (rc = build_integrator(sc, su->sim)) != CLI_EXIT_OK ||
        (rc = build_kinematics(sc, su, &mi, &mj)) != CLI_EXIT_OK ||
        (rc = cli_scenario_check_outputs(sc)) != CLI_EXIT_OK) {
        cli_setup_free(su);
        return rc;
    }
    const char* si = cli_scenario_text(sc, "collision", "striker", "steel1");
    char films[2 * CLI_VALUE_MAX + 64];
    snprintf(films, sizeof films, "film of striker %s %g m + target %s %g m", si, mi.film,
             cli_scenario_text(sc, "collision", "target_material", si), mj.film);
    char roughs[2 * CLI_VALUE_MAX + 64];
    snprintf(roughs, sizeof roughs, "roughness of striker %s %g m, target %s %g m", si,
             mi.roughness, cli_scenario_text(sc, "collision", "target_material", si), mj.roughness);
    cli_scenario_warn_films(sc, su->sim, mi.film + mj.film, films,
                            0.5 * (mi.roughness + mj.roughness), roughs);
    cli_scenario_warn_ignored(sc, su->sim, false);
    cli_scenario_warn_no_contact(sc, su->sim);
    const struct cli_entry* ei = cli_scenario_find(sc, "collision", "striker");
    const struct cli_entry* ej = cli_scenario_find(sc, "collision", "target_material");
    if (!(ei && ei->line == 0) && !(ej && ej->line == 0)) { /* (not switched by --set) */
        const char* used[2] = {si, cli_scenario_text(sc, "collision", "target_material", si)};
        char how[2 * CLI_VALUE_MAX + 160];
        snprintf(how, sizeof how,
                 "neither [collision] striker (%s) nor target_material (%s) names it; name it "
                 "there (striker = NAME), or leave it out",
                 used[0], used[1]);
        cli_scenario_warn_unused_materials(sc, used, 2, how);
    }
    /* (checked by cli_scenario_check_outputs above) */
    cli_scenario_out_name(sc, "output", "trajectory", "trajectory.csv", su->trajectory_file);
    cli_scenario_out_name(sc, "output", "events", "events.csv", su->events_file);
    cli_scenario_out_name(sc, "output", "summary", "summary.json", su->summary_file);
    return CLI_EXIT_OK;
}

void cli_setup_free(struct cli_setup* su)
{
    wetdem_sim_free(su->sim);
    su->sim = NULL;
}

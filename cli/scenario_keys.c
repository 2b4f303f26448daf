/*
 * scenario_keys.c — the one table of scenario sections and keys (unit, default, range, doc),
 * section lookup with "did you mean" hints, and `wetdem docs-scenarios`, which writes the
 * key tables of docs/scenarios.md from this table and from the library's descriptor tables
 * (materials, fluid, every model's parameters), so the documentation cannot drift.
 *
 * Ranges of collision keys: radii in (0, 1] m and speeds up to 1e3 m/s cover every seed
 * set-up with margin (spheres of 12.7 mm diameter, impact speeds below 1 m/s); the angle is
 * that of the straight-line approach at contact (sin = b / (R_i + R_j), impact parameter b),
 * so a grazing 90 deg would never collide.
 */
#include <stdio.h>
#include <string.h>

#include "cli_util.h"
#include "scenario.h"

static const char* const target_choices[] = {"sphere", "wall", "fixed", NULL};
static const char* const fluid_choices[] = {"water", "glycerol80", "silicone10", NULL};
static const char* const engine_choices[] = {"soft", "pairwise", NULL};

#define NUM CLI_KEY_NUMBER
#define COUNT CLI_KEY_COUNT
#define WORD CLI_KEY_WORD

static const struct cli_key_desc collision_keys[] = {
    WORD("striker", CLI_VALUE_NAME, "steel1", NULL,
         "Material of the moving sphere i: a preset (steel1, steel2, glass, delrin, "
         "punch_steel, punch_steel_coated) or NAME of a [material.NAME] section."),
    WORD("target_material", CLI_VALUE_NAME, "same as striker", NULL,
         "Material of the target j (sphere or wall), as for striker."),
    NUM("striker_radius", "m", "6.35e-3", 0, 1, true, false, "Radius R_i of the striker."),
    NUM("target_radius", "m", "same as striker_radius", 0, 1, true, false,
        "Radius R_j of a target sphere; ignored for a wall."),
    WORD("target", CLI_VALUE_CHOICE, "sphere", target_choices,
         "sphere: free target at rest; fixed: target sphere held in place (infinite mass); "
         "wall: plane wall."),
    NUM("speed", "m/s", "0 (derive from stokes)", 0, 1e3, false, false,
        "Impact speed |v_i| of the striker. Give speed or stokes, not both."),
    NUM("stokes", "-", "0", 0, 1e9, false, false,
        "Normal Stokes number St_n = m* v cos(angle) / (6 pi mu R*^2); the speed is derived "
        "as v = St_n 6 pi mu R*^2 / (m* cos(angle)). Needs fluid viscosity > 0."),
    NUM("angle_deg", "deg", "0", 0, 90, false, true,
        "Impact angle: between the striker's velocity and the line of centres at contact of "
        "the undisturbed straight-line approach, sin(angle) = b / (R_i + R_j) with the impact "
        "parameter b (Yang & Hunt; Nijssen Fig. 1c; Punch Eq. 16; wall: to its normal); the "
        "striker starts on that line just outside the interaction range; 0 = head-on."),
    NUM("spin_x", "rad/s", "0", -1e6, 1e6, false, false, "Initial spin of the striker, x."),
    NUM("spin_y", "rad/s", "0", -1e6, 1e6, false, false, "Initial spin of the striker, y."),
    NUM("spin_z", "rad/s", "0", -1e6, 1e6, false, false, "Initial spin of the striker, z."),
    NUM("t_end", "s", "0 (auto)", 0, 1e6, false, false,
        "Longest simulated time. 0: t_end_crossings x max(R*, initial_gap) / v_n, i.e. that "
        "many times the time to cross the lubrication cut-off h_co = R* at the impact speed."),
    NUM("t_end_crossings", "-", "20", 1, 1e6, false, false,
        "Automatic t_end in units of the crossing time max(R*, initial_gap) / v_n."),
    NUM("initial_gap", "m", "0 (auto)", 0, 1, false, false,
        "Gap at t = 0; 0: just outside the interaction range of the enabled models."),
    NUM("observe_time", "s", "0 (off)", 0, 1e6, false, false,
        "Also report e_n at this time after the start (Punch Fig. 9 window)."),
    NUM("rebound_gap_factor", "-", "1", 1, 1e3, false, false,
        "Separation is declared when the gap exceeds this multiple of the interaction range."),
    NUM("close_gap", "m", "0 (auto)", 0, 1, false, false,
        "Outcome rule: a pair that separates after its line of centres turned, together with "
        "its relative velocity, by more than 5 deg with the gap below close_gap (after the "
        "approach was first arrested) is stick-rotate-separate. 0: the film thickness delta_ij "
        "when the pair has films (the overlapping films hold the doublet), else 0.01 R*."),
    {0},
};

static const struct cli_key_desc material_keys[] = {
    WORD("preset", CLI_VALUE_NAME, "none (the field defaults below)", NULL,
         "Preset the other keys start from: steel1, steel2, glass, delrin, punch_steel, "
         "punch_steel_coated."),
    {0},
};

static const struct cli_key_desc fluid_keys[] = {
    WORD("preset", CLI_VALUE_CHOICE, "water", fluid_choices,
         "Fluid the other keys start from: water (1e-3 Pa s), glycerol80 (80 w% glycerol), "
         "silicone10 (10 Pa s silicone oil of Punch)."),
    {0},
};

static const struct cli_key_desc models_keys[] = {
    WORD("force", CLI_VALUE_NAME_LIST, "hertz", NULL,
         "Force models summed for every pair, separated by spaces or commas, e.g. "
         "'nijssen' (its own Hertz-Mindlin contact) or 'hertz mindlin db davis capillary' "
         "(wetdem models); two laws of one contact force (hertz and hooke, nijssen and "
         "hertz or mindlin) are refused."),
    WORD("min_separation", CLI_VALUE_NAME, "fixed", NULL,
         "Minimum-separation model giving h_min: fixed, roughness, ehd, max or glass."),
    {0},
};

const char* const cli_yes_no[] = {"no", "yes", NULL};
static const char* const cvode_methods[] = {"auto", "adams", "bdf", NULL};

/* Keys after "name" are the integrators' parameters ("<name>.<key>" in the library); their
 * defaults are read from the library's descriptor tables when the docs are generated
 * (default_text NULL), and generation fails if the library does not know a key listed here
 * or gives it another range. */
static const struct cli_key_desc integrator_keys[] = {
    WORD("name", CLI_VALUE_NAME, "verlet", NULL,
         "verlet (fixed step, a fraction of the contact time) or cvode (adaptive, "
         "with located events). The other keys are integrator parameters, checked by the library "
         "when the scenario is built; those of an integrator not chosen are ignored."),
    NUM("dt_fraction", "-", NULL, 0, 1, true, false,
        "verlet: time step as a fraction of the contact time (Hertz, or hooke's half period; "
        "Nijssen: 0.02)."),
    NUM("dt", "s", NULL, 0, 1, false, false,
        "verlet: fixed time step; 0 derives it from dt_fraction."),
    NUM("hmin_fraction", "-", NULL, 0, 1, false, false,
        "verlet: when > 0, the step is also held at or below hmin_fraction x h_min / v, so that "
        "the gap moves at most that fraction of h_min per step (0.1 resolves it; "
        "docs/engines.md); 0: off."),
    NUM("many_hmin_fraction", "-", NULL, 0, 1, false, false,
        "verlet, many-particle runs: a derived step is held at or below many_hmin_fraction x "
        "h_min / v, so that a pair closing at the speed scale moves at most that fraction of "
        "h_min per step; 0: off, with no warning about h_min (docs/many.md, Time step)."),
    COUNT("max_steps", NULL, 1, 1e12, "verlet and cvode: most steps one integration may take."),
    NUM("rtol", "-", NULL, 1e-14, 1e-4, false, false, "cvode: relative tolerance."),
    NUM("atol", "-", NULL, 1e-16, 1e-4, false, false,
        "cvode: absolute tolerance in units of the length, speed and spin scales."),
    WORD("method", CLI_VALUE_CHOICE, NULL, cvode_methods,
         "cvode: auto (Adams, switching to BDF for the rest of the run once a stretch without "
         "events turns stiff, e.g. a resting lubricated contact), adams (non-stiff) or bdf "
         "(stiff, dense Newton)."),
    COUNT("stiff_steps", NULL, 10, 1e9,
          "cvode, method auto: Adams steps without an event after which BDF takes over."),
    COUNT("max_order", NULL, 1, 12, "cvode: largest order of the method (BDF uses at most 5)."),
    NUM("max_step", "s", NULL, 0, 1e6, false, false,
        "cvode: largest step; 0 uses 0.1 x smallest radius / the pairs' largest relative speed "
        "(gravity's addition included, no floor)."),
    {0},
};

static const struct cli_key_desc sim_keys[] = {
    NUM("gravity_x", "m/s^2", NULL, -1e4, 1e4, false, false, "Gravity, x component."),
    NUM("gravity_y", "m/s^2", NULL, -1e4, 1e4, false, false, "Gravity, y component."),
    NUM("gravity_z", "m/s^2", NULL, -1e4, 1e4, false, false, "Gravity, z component."),
    WORD("stop_on_separation", CLI_VALUE_CHOICE, NULL, cli_yes_no,
         "Stop once every pair that interacted has left its range and recedes (a collision "
         "run sets this itself; a many-particle run does not stop on separation: both warn "
         "that it has no effect)."),
    NUM("separation_factor", "-", NULL, 1, 1e3, false, false,
        "A pair counts as separated beyond this multiple of its interaction range (a "
        "collision run takes [collision] rebound_gap_factor; a many-particle run does not "
        "read it: both warn)."),
    NUM("speed_floor", "m/s", NULL, 0, 1e3, true, false,
        "Smallest relative speed used for the Verlet step and the CVODE tolerance scales."),
    {0},
};

static const struct cli_key_desc output_keys[] = {
    WORD("trajectory", CLI_VALUE_TEXT, "trajectory.csv", NULL,
         "Trajectory file in the --out directory; 'none' disables it."),
    WORD("events", CLI_VALUE_TEXT, "events.csv", NULL,
         "Event log file in the --out directory; 'none' disables it."),
    WORD("summary", CLI_VALUE_TEXT, "summary.json", NULL,
         "Summary file (JSON) in the --out directory; 'none' disables it."),
    NUM("trajectory_interval", "s", "0 (auto)", 0, 1e6, false, false,
        "Time between trajectory rows; 0: max(R*, initial_gap) / (500 v_n), or t_end / 2000 "
        "for the pairwise engine. At most 1e7 rows (t_end / interval)."),
    {0},
};

static const struct cli_key_desc engine_keys[] = {
    WORD("type", CLI_VALUE_CHOICE, "soft", engine_choices,
         "soft: Cartesian soft-sphere DEM; pairwise: Davis relative-motion engine with hard "
         "contact (when the build has it)."),
    {0},
};

static const struct cli_section_desc sections[] = {
    {"collision", "The binary collision: striker i moving towards target j at rest.",
     collision_keys},
    {"material.*",
     "A material NAME usable as striker or target_material: a preset and/or every field of "
     "struct wetdem_material.",
     material_keys},
    {"fluid", "The liquid: a preset and/or every field of struct wetdem_fluid.", fluid_keys},
    {"models", "Which models act on every pair.", models_keys},
    {"model.*",
     "Parameters of model NAME, which [models] must enable; each key is set as 'NAME.key'. "
     "The keys are the model's parameters, listed with unit, default and range in "
     "docs/models.md (generated from the same descriptor tables the library checks values "
     "against), e.g. [model.nijssen] cutoff_ratio = 1, [model.glass] p_gt = 11.6e6. When "
     "--set chooses [models] force or min_separation, the file's sections of the models it "
     "leaves out are ignored (so --set models.min_separation=ehd works on a file with "
     "[model.fixed]); a --set of a parameter of a model not enabled is still an error.",
     NULL},
    {"integrator", "Time integrator and its parameters.", integrator_keys},
    {"sim", "Simulation settings, set as 'sim.<key>'; other keys are checked by the library.",
     sim_keys},
    {"output", "Files `wetdem run --out DIR` writes.", output_keys},
    {"engine", "Which engine runs the scenario.", engine_keys},
    {0},
};

const struct cli_section_desc* cli_scenario_sections(void)
{
    return sections;
}

/* Finds name in a section table: exact, or as a "family.*" with a valid NAME. */
static const struct cli_section_desc* find_in(const struct cli_section_desc* table,
                                              const char* name, const char** member)
{
    for (size_t k = 0; table && table[k].name; k++) {
        const char* star = strstr(table[k].name, ".*");
        if (!star) {
            if (strcmp(table[k].name, name) == 0)
                return &table[k];
            continue;
        }
        size_t plen = (size_t)(star - table[k].name) + 1; /* "material." */
        if (strncmp(table[k].name, name, plen) == 0 && cli_is_name(name + plen)) {
            *member = name + plen;
            return &table[k];
        }
    }
    return NULL;
}

int cli_section_lookup(const char* name, struct cli_section_info* info)
{
    memset(info, 0, sizeof *info);
    const char* member = NULL;
    const struct cli_section_desc* d = find_in(sections, name, &member);
    if (!d && cli_pairwise_sections)
        d = find_in(cli_pairwise_sections, name, &member);
    if (!d && cli_many_sections)
        d = find_in(cli_many_sections, name, &member);
    if (!d)
        return -1;
    info->desc = d;
    if (strcmp(d->name, "material.*") == 0)
        info->lib_keys = wetdem_material_params();
    else if (strcmp(d->name, "fluid") == 0)
        info->lib_keys = wetdem_fluid_params();
    else if (strcmp(d->name, "model.*") == 0) {
        info->model = wetdem_model_find(member);
        if (!info->model)
            return -1;
        info->lib_keys = info->model->params;
    } else if (strcmp(d->name, "integrator") == 0 || strcmp(d->name, "sim") == 0)
        info->open_keys = true;
    return 0;
}

const char* cli_model_suggestion(const char* word)
{
    const struct wetdem_model* const* reg = wetdem_model_registry();
    const char* names[64];
    size_t k = 0;
    for (; reg[k] && k + 1 < 64; k++)
        names[k] = reg[k]->name;
    names[k] = NULL;
    return wetdem_param_suggest(word, names);
}

void cli_section_suggestion(const char* name, char* msg, size_t n)
{
    if (strncmp(name, "model.", 6) == 0) {
        const char* hint = cli_model_suggestion(name + 6);
        snprintf(msg, n, ": '%s' is not a model%s%s%s (see 'wetdem models')", name + 6,
                 hint ? "; did you mean [model." : "", hint ? hint : "", hint ? "]?" : "");
        return;
    }
    /* the fixed sections, and the families NAME.* (shown as [NAME.NAME]) */
    const char* names[40];
    const char* fam[13]; /* -> families[], NULL-terminated */
    char families[12][32];
    size_t m = 0, nf = 0;
    const struct cli_section_desc* tables[3] = {sections, cli_pairwise_sections, cli_many_sections};
    for (int t = 0; t < 3; t++)
        for (size_t k = 0; tables[t] && tables[t][k].name && m + 1 < 40; k++) {
            const char* star = strstr(tables[t][k].name, ".*");
            if (!star)
                names[m++] = tables[t][k].name;
            else if (nf < 12) {
                snprintf(families[nf], sizeof families[0], "%.*s", (int)(star - tables[t][k].name),
                         tables[t][k].name);
                fam[nf] = families[nf];
                nf++;
            }
        }
    names[m] = NULL;
    fam[nf] = NULL;
    const char* dot = strchr(name, '.');
    if (dot) { /* a misspelt family: [reed.bed] -> [read.bed] */
        char prefix[64];
        snprintf(prefix, sizeof prefix, "%.*s", (int)(dot - name), name);
        const char* hint = wetdem_param_suggest(prefix, fam);
        if (hint && strcmp(hint, prefix) == 0) { /* the family is right: its NAME is not */
            snprintf(msg, n, ": '%s' is not a NAME (letters, digits, '_' and '-')", dot + 1);
            return;
        }
        if (hint) {
            snprintf(msg, n, " (did you mean [%s%s]?)", hint, dot);
            return;
        }
    }
    const char* hint = wetdem_param_suggest(name, names);
    if (hint) {
        snprintf(msg, n, " (did you mean [%s]?)", hint);
        return;
    }
    size_t used = (size_t)snprintf(msg, n, "; valid sections:");
    for (size_t k = 0; names[k] && used < n; k++)
        used += (size_t)snprintf(msg + used, n - used, " [%s]", names[k]);
    for (size_t k = 0; k < nf && used < n; k++)
        used += (size_t)snprintf(msg + used, n - used, " [%s.NAME]", families[k]);
}

const char* cli_scenario_key_unit(const char* section, const char* key)
{
    struct cli_section_info info;
    if (cli_section_lookup(section, &info) != 0)
        return "";
    for (size_t k = 0; info.desc->keys && info.desc->keys[k].key; k++)
        if (strcmp(info.desc->keys[k].key, key) == 0)
            return info.desc->keys[k].unit;
    const struct wetdem_param_desc* d = wetdem_param_find(info.lib_keys, key);
    return d ? d->unit : "";
}

int cli_scenario_key_range(const char* section, const char* key, struct wetdem_param_desc* out)
{
    struct cli_section_info info;
    if (cli_section_lookup(section, &info) != 0)
        return -1;
    for (size_t k = 0; info.desc->keys && info.desc->keys[k].key; k++)
        if (strcmp(info.desc->keys[k].key, key) == 0) {
            if (info.desc->keys[k].kind != CLI_VALUE_NUMBER)
                return -1;
            *out = cli_key_as_param(&info.desc->keys[k]);
            return 0;
        }
    const struct wetdem_param_desc* d = wetdem_param_find(info.lib_keys, key);
    if (!d || d->choices)
        return -1;
    *out = *d;
    return 0;
}

/* ---- documentation ---- */

/* Writes a Markdown table cell, '|' escaped. */
static void cell(FILE* f, const char* text)
{
    for (const char* p = text; *p; p++) {
        if (*p == '|')
            fputc('\\', f);
        fputc(*p, f);
    }
}

/* Whether a key's documented range is the library descriptor's (the library checks values
 * against its own table when the scenario is built; the docs must say the same). */
static bool same_range(const struct cli_key_desc* k, const struct wetdem_param_desc* d)
{
    if (k->kind == CLI_VALUE_CHOICE)
        return d->choices != NULL;
    return k->min == d->min && k->max == d->max && k->min_open == d->min_open &&
           k->max_open == d->max_open && !d->choices;
}

/* Default of an integrator or sim key from the library's descriptor tables
 * (wetdem_sim_settings_params, wetdem_integrator_params): "<value>" or, for integrator keys,
 * "<value> (<integrator>)" per integrator that has it. Returns 0, or -1 (message printed) if
 * the library knows the key for none or documents another range. */
static int library_default(const char* section, const struct cli_key_desc* k, char* out, size_t n)
{
    bool is_sim = strcmp(section, "sim") == 0;
    const char* const* names = wetdem_integrator_names();
    size_t used = 0;
    out[0] = '\0';
    for (size_t m = 0; is_sim ? m < 1 : names[m] != NULL; m++) {
        const struct wetdem_param_desc* d = wetdem_param_find(
            is_sim ? wetdem_sim_settings_params() : wetdem_integrator_params(names[m]), k->key);
        if (!d)
            continue;
        if (!same_range(k, d)) {
            char range[160];
            wetdem_param_range_text(d, range, sizeof range);
            fprintf(stderr, "wetdem: docs-scenarios: [%s] %s: the library's range is %s\n", section,
                    k->key, range);
            return -1;
        }
        char value[64];
        cli_param_default_text(d, value, sizeof value);
        used +=
            (size_t)snprintf(out + used, used < n ? n - used : 0, "%s%s%s%s%s", used ? ", " : "",
                             value, is_sim ? "" : " (", is_sim ? "" : names[m], is_sim ? "" : ")");
    }
    if (!out[0])
        fprintf(stderr, "wetdem: docs-scenarios: the library has no parameter '%s' for [%s]\n",
                k->key, section);
    return out[0] ? 0 : -1;
}

static int key_row(FILE* f, const char* section, const struct cli_key_desc* k)
{
    char dflt[256];
    if (k->default_text)
        snprintf(dflt, sizeof dflt, "%s", k->default_text);
    else if (library_default(section, k, dflt, sizeof dflt) != 0)
        return -1;
    char range[256] = "name";
    if (k->kind == CLI_VALUE_NUMBER || k->kind == CLI_VALUE_CHOICE) {
        struct wetdem_param_desc d = cli_key_as_param(k);
        wetdem_param_range_text(&d, range, sizeof range);
    } else if (k->kind == CLI_VALUE_NAME_LIST)
        snprintf(range, sizeof range, "list of names, each once");
    else if (k->kind == CLI_VALUE_TEXT)
        snprintf(range, sizeof range, "text");
    fprintf(f, "| `%s` | %s | ", k->key, k->unit[0] ? k->unit : "");
    cell(f, dflt);
    fputs(" | ", f);
    cell(f, range);
    fputs(" | ", f);
    cell(f, k->doc);
    fputs(" |\n", f);
    return 0;
}

static void lib_row(FILE* f, const struct wetdem_param_desc* d)
{
    char range[256], dflt[64];
    wetdem_param_range_text(d, range, sizeof range);
    cli_param_default_text(d, dflt, sizeof dflt);
    fprintf(f, "| `%s` | %s | %s | ", d->name, d->unit, dflt);
    cell(f, range);
    fputs(" | ", f);
    cell(f, d->doc);
    fputs(" |\n", f);
}

static void table_head(FILE* f)
{
    fputs("| key | unit | default | range | meaning |\n|---|---|---|---|---|\n", f);
}

static int section_doc(FILE* f, const struct cli_section_desc* s)
{
    struct cli_section_info info;
    char probe[CLI_NAME_MAX];
    snprintf(probe, sizeof probe, "%s", s->name);
    char* star = strstr(probe, "*");
    if (star)
        snprintf(star, sizeof probe - (size_t)(star - probe), "%s",
                 strcmp(s->name, "model.*") == 0 ? "hertz" : "NAME");
    cli_section_lookup(probe, &info);
    if (star)
        snprintf(star, sizeof probe - (size_t)(star - probe), "NAME"); /* "sphere.NAME" */
    fprintf(f, "\n### `[%s]`\n\n", probe);
    cell(f, s->doc);
    fputs("\n", f);
    if (strcmp(s->name, "model.*") == 0)
        return 0; /* the models' parameter tables are docs/models.md (wetdem docs-models) */
    fputs("\n", f);
    table_head(f);
    int rc = 0;
    for (size_t k = 0; s->keys && s->keys[k].key; k++)
        if (key_row(f, s->name, &s->keys[k]) != 0)
            rc = -1;
    for (size_t k = 0; info.lib_keys && info.lib_keys[k].name; k++)
        lib_row(f, &info.lib_keys[k]);
    return rc;
}

int cli_scenario_print_docs(FILE* f)
{
    int rc = 0;
    fputs("<!-- generated by `wetdem docs-scenarios` from cli/scenario_keys.c and the "
          "library's descriptor tables; do not edit by hand -->\n",
          f);
    for (size_t k = 0; sections[k].name; k++)
        rc |= section_doc(f, &sections[k]);
    for (size_t k = 0; cli_pairwise_sections && cli_pairwise_sections[k].name; k++)
        rc |= section_doc(f, &cli_pairwise_sections[k]);
    for (size_t k = 0; cli_many_sections && cli_many_sections[k].name; k++)
        rc |= section_doc(f, &cli_many_sections[k]);
    fputs("\n<!-- end of generated tables -->\n", f);
    return rc;
}

int cmd_docs_scenarios(int argc, char** argv)
{
    if (cli_wants_help(argc, argv)) {
        printf("usage: wetdem docs-scenarios\n"
               "Writes the key tables of every scenario section (Markdown) to stdout: the\n"
               "generated part of docs/scenarios.md.\n");
        return CLI_EXIT_OK;
    }
    if (argc > 1) {
        cli_error("docs-scenarios: unexpected argument '%s' (usage: wetdem docs-scenarios)",
                  argv[1]);
        return CLI_EXIT_USAGE;
    }
    return cli_scenario_print_docs(stdout) == 0 ? CLI_EXIT_OK : CLI_EXIT_RUNTIME;
}

/* ------------------------------------------------------------ a key in another section -- */

enum { ENGINE_BINARY = 1, ENGINE_MANY = 2, ENGINE_PAIRWISE = 4 };

/* The engines that read section (table entry) d of table t (0 the common table, 1 the
 * pairwise engine's, 2 the many-particle run's). */
static unsigned section_engines(int t, const struct cli_section_desc* d)
{
    if (t == 1)
        return ENGINE_PAIRWISE;
    if (t == 2)
        return ENGINE_MANY;
    if (strcmp(d->name, "collision") == 0)
        return ENGINE_BINARY;
    if (strcmp(d->name, "output") == 0)
        return ENGINE_BINARY | ENGINE_PAIRWISE;
    if (strcmp(d->name, "engine") == 0)
        return ENGINE_BINARY | ENGINE_MANY | ENGINE_PAIRWISE;
    return ENGINE_BINARY | ENGINE_MANY;
}

static unsigned scenario_engine(const struct cli_scenario* sc)
{
    if (strcmp(cli_scenario_text(sc, "engine", "type", "soft"), "pairwise") == 0)
        return ENGINE_PAIRWISE;
    if (cli_scenario_is_many && cli_scenario_is_many(sc))
        return ENGINE_MANY;
    return ENGINE_BINARY;
}

/* Whether value is of the kind a library parameter takes (a number, or one of its words). */
static bool lib_takes(const struct wetdem_param_desc* d, const char* value)
{
    double v;
    if (!d)
        return false;
    if (!d->choices)
        return cli_number(value, &v) == 0;
    for (size_t k = 0; d->choices[k]; k++)
        if (strcmp(d->choices[k], value) == 0)
            return true;
    return false;
}

/* Whether section d of the table has key and takes value there as its kind (a number for a
 * number, one of the words of a choice): its own table, or the library's for materials, the
 * fluid and the simulation settings. A key whose value is of another kind (a particle's
 * speed = 1 and the glass model's speed = max) belongs elsewhere only in name. */
static bool desc_has_key(const struct cli_section_desc* d, const char* key, const char* value)
{
    double v;
    for (size_t k = 0; d->keys && d->keys[k].key; k++)
        if (strcmp(d->keys[k].key, key) == 0) {
            if (d->keys[k].kind == CLI_VALUE_NUMBER)
                return cli_number(value, &v) == 0;
            if (d->keys[k].kind == CLI_VALUE_CHOICE) {
                for (size_t c = 0; d->keys[k].choices[c]; c++)
                    if (strcmp(d->keys[k].choices[c], value) == 0)
                        return true;
                return false;
            }
            return true;
        }
    if (strcmp(d->name, "material.*") == 0)
        return lib_takes(wetdem_param_find(wetdem_material_params(), key), value);
    if (strcmp(d->name, "fluid") == 0)
        return lib_takes(wetdem_param_find(wetdem_fluid_params(), key), value);
    if (strcmp(d->name, "sim") == 0)
        return lib_takes(wetdem_param_find(wetdem_sim_settings_params(), key), value);
    return false;
}

/* Appends "[name]" (a family as [family.NAME]) to a list of at most 4 in buf. */
static void add_home(char* buf, size_t n, int* count, const char* name)
{
    if (*count == 4)
        return;
    size_t used = strlen(buf);
    const char* star = strstr(name, ".*");
    snprintf(buf + used, n - used, "%s[%.*s%s]", *count ? ", " : "",
             star ? (int)(star - name) : (int)strlen(name), name, star ? ".NAME" : "");
    (*count)++;
}

/* Lists into buf the sections other than `section` that have `key` and that the engines in
 * `engines` read, with the models whose parameter it is as [model.NAME]. Returns how many;
 * *first (when not NULL) is the name of the first, as its table has it ("collision",
 * "material.*", "model.nijssen" in a static buffer). */
static int key_homes_first(const char* section, const char* key, const char* value,
                           unsigned engines, char* buf, size_t n, const char** first)
{
    static _Thread_local char model_section[CLI_NAME_MAX];
    buf[0] = '\0';
    int count = 0;
    const struct cli_section_desc* tables[3] = {sections, cli_pairwise_sections, cli_many_sections};
    for (int t = 0; t < 3; t++)
        for (size_t k = 0; tables[t] && tables[t][k].name; k++) {
            const struct cli_section_desc* d = &tables[t][k];
            if ((section_engines(t, d) & engines) && !cli_section_matches(section, d->name) &&
                desc_has_key(d, key, value)) {
                if (first && count == 0)
                    *first = d->name;
                add_home(buf, n, &count, d->name);
            }
        }
    if (engines & (ENGINE_BINARY | ENGINE_MANY)) {
        const struct wetdem_model* const* reg = wetdem_model_registry();
        for (size_t k = 0; reg[k]; k++) {
            char name[CLI_NAME_MAX];
            snprintf(name, sizeof name, "model.%s", reg[k]->name);
            if (strcmp(name, section) != 0 &&
                lib_takes(wetdem_param_find(reg[k]->params, key), value)) {
                if (first && count == 0) {
                    snprintf(model_section, sizeof model_section, "%s", name);
                    *first = model_section;
                }
                add_home(buf, n, &count, name);
            }
        }
    }
    char* last = strrchr(buf, ',');
    if (count > 1 && last) { /* "[a], [b], [c]" -> "[a], [b] and [c]" */
        char tail[256];
        snprintf(tail, sizeof tail, " and%s", last + 1);
        snprintf(last, n - (size_t)(last - buf), "%s", tail);
    }
    return count;
}

static int key_homes(const char* section, const char* key, const char* value, unsigned engines,
                     char* buf, size_t n)
{
    return key_homes_first(section, key, value, engines, buf, n, NULL);
}

int cli_key_only_home(const struct cli_scenario* sc, const char* key, const char* value,
                      char* section, size_t n)
{
    char homes[320];
    const char* first = NULL;
    if (key_homes_first("", key, value, scenario_engine(sc), homes, sizeof homes, &first) != 1 ||
        !first || strchr(first, '*'))
        return 0;
    snprintf(section, n, "%s", first);
    return 1;
}

int cli_key_home(const struct cli_scenario* sc, const struct cli_entry* e, char* buf, size_t n)
{
    unsigned engine = scenario_engine(sc);
    char homes[320];
    if (key_homes(e->section, e->key, e->value, engine, homes, sizeof homes) > 0) {
        snprintf(buf, n, "it is a key of %s: move it there", homes);
        return 1;
    }
    static const struct {
        unsigned engine;
        const char* what;
    } others[] = {{ENGINE_BINARY, "a binary collision"},
                  {ENGINE_MANY, "a many-particle run"},
                  {ENGINE_PAIRWISE, "the pairwise engine"}};
    for (size_t k = 0; k < 3; k++)
        if (others[k].engine != engine &&
            key_homes(e->section, e->key, e->value, others[k].engine, homes, sizeof homes) > 0) {
            snprintf(buf, n, "'%s' is a key of %s of %s, which this scenario is not", e->key, homes,
                     others[k].what);
            return 2;
        }
    buf[0] = '\0';
    return 0;
}

/*
 * cmd_describe.c — `wetdem describe NAME`: a model's summary, doc paragraph and equation
 * references, then every parameter with unit, default (the word for enumerations), valid
 * range and one-line doc. NAME may also be an integrator ("verlet", "cvode": its summary and
 * parameters), "material", "fluid" or "sim" (the descriptor tables of materials, the fluid and
 * simulation settings) or "presets" (the material presets and their values). An unknown NAME gets a "did you mean" hint and exit code 2.
 * Everything printed comes from the library's descriptor tables.
 */
#include <ctype.h>
#include <stdio.h>
#include <string.h>

#include "cli_util.h"

#define WRAP_COLUMNS 78

/* Prints text word-wrapped at WRAP_COLUMNS with `indent` spaces before every line. */
static void print_wrapped(const char* text, int indent)
{
    int col = 0;
    const char* p = text;
    while (*p) {
        while (*p == ' ')
            p++;
        size_t len = strcspn(p, " ");
        if (len == 0)
            break;
        if (col > 0 && col + 1 + (int)len > WRAP_COLUMNS) {
            putchar('\n');
            col = 0;
        }
        if (col == 0)
            col = printf("%*s", indent, "");
        else
            col += printf(" ");
        col += printf("%.*s", (int)len, p);
        p += len;
    }
    if (col > 0)
        putchar('\n');
}

/* One parameter: "  name [unit]  default D, valid R" then its doc, indented. */
static void print_param(const struct wetdem_param_desc* d)
{
    char def[64], range[160];
    cli_param_default_text(d, def, sizeof def);
    wetdem_param_range_text(d, range, sizeof range);
    printf("  %s [%s]  default %s, valid %s\n", d->name, d->unit, def, range);
    print_wrapped(d->doc, 6);
}

static void print_table(const struct wetdem_param_desc* table)
{
    if (wetdem_param_count(table) == 0) {
        printf("  (none)\n");
        return;
    }
    for (size_t k = 0; table[k].name; k++)
        print_param(&table[k]);
}

static void describe_model(const struct wetdem_model* m)
{
    printf("%s (%s model): %s\n\n", m->name, wetdem_model_kind_name(m->kind), m->summary);
    print_wrapped(m->doc, 0);
    printf("\nequations: %s\n", m->equations ? m->equations : "-");
    if (m->history_len > 0)
        printf("per-pair history: %zu value%s\n", m->history_len, m->history_len == 1 ? "" : "s");
    printf("\nparameters (set as %s.NAME=VALUE, e.g. with --set):\n", m->name);
    print_table(m->params);
}

static void describe_presets(void)
{
    const char* const* names = wetdem_material_preset_names();
    const struct wetdem_param_desc* table = wetdem_material_params();
    printf("material presets (wetdem_sim_add_material_preset, --preset NAME):\n");
    for (size_t p = 0; names[p]; p++) {
        struct wetdem_material m;
        if (wetdem_material_preset(names[p], &m) != WETDEM_OK)
            continue;
        printf("\n%s:\n", names[p]);
        for (size_t k = 0; table[k].name; k++) {
            double v = *(const double*)((const char*)&m + table[k].offset);
            printf("  %-16s %-12g %s\n", table[k].name, v, table[k].unit);
        }
    }
}

/* The names `describe` accepts besides model and integrator names. */
static const char* const special_names[] = {"material", "fluid", "sim", "presets", NULL};

static void describe_integrator(const char* name)
{
    printf("%s (integrator): %s\n\n", name, wetdem_integrator_summary(name));
    printf("parameters ([integrator] keys of a scenario, --set integrator.NAME=VALUE or "
           "%s.NAME=VALUE; %s.NAME in the library):\n",
           name, name);
    print_table(wetdem_integrator_params(name));
}

/* What describe takes, for its messages. */
static const char valid_names[] = "a model name (see 'wetdem models'), an integrator (verlet, "
                                  "cvode), material, fluid, sim or presets";

static int unknown_name(const char* name)
{
    if (!name[0]) { /* (every short name is "near" the empty one) */
        cli_error("describe: an empty name; valid: %s", valid_names);
        return CLI_EXIT_USAGE;
    }
    const char* names[96];
    size_t n = 0;
    const struct wetdem_model* const* reg = wetdem_model_registry();
    for (size_t k = 0; reg[k] && n < 80; k++)
        names[n++] = reg[k]->name;
    for (const char* const* in = wetdem_integrator_names(); *in && n < 88; in++)
        names[n++] = *in;
    for (size_t k = 0; special_names[k]; k++)
        names[n++] = special_names[k];
    names[n] = NULL;
    char lower[64]; /* the names are lower case: NIJSSEN is nijssen */
    size_t len = 0;
    for (; name[len] && len + 1 < sizeof lower; len++)
        lower[len] = (char)tolower((unsigned char)name[len]);
    lower[len] = '\0';
    const char* hint = wetdem_param_suggest(lower, names);
    cli_error("describe: unknown name '%s'%s%s%s; valid: %s", name, hint ? " (did you mean '" : "",
              hint ? hint : "", hint ? "'?)" : "", valid_names);
    return CLI_EXIT_USAGE;
}

int cmd_describe(int argc, char** argv)
{
    bool help = cli_wants_help(argc, argv);
    if (argc != 2 || help) {
        FILE* f = help ? stdout : stderr;
        fprintf(f, "usage: wetdem describe NAME\n"
                   "NAME: a model (see 'wetdem models'), an integrator (verlet, cvode),\n"
                   "      material, fluid, sim or presets\n");
        return help ? CLI_EXIT_OK : CLI_EXIT_USAGE;
    }
    const char* name = argv[1];
    const struct wetdem_model* m = wetdem_model_find(name);
    if (m) {
        describe_model(m);
    } else if (wetdem_integrator_params(name)) {
        describe_integrator(name);
    } else if (strcmp(name, "material") == 0) {
        printf("material fields (struct wetdem_material, one per sphere or wall; pairs mix "
               "them):\n");
        print_table(wetdem_material_params());
    } else if (strcmp(name, "fluid") == 0) {
        printf("fluid (set as fluid.NAME=VALUE):\n");
        print_table(wetdem_fluid_params());
    } else if (strcmp(name, "sim") == 0) {
        printf("simulation settings (set as sim.NAME=VALUE):\n");
        print_table(wetdem_sim_settings_params());
    } else if (strcmp(name, "presets") == 0) {
        describe_presets();
    } else {
        return unknown_name(name);
    }
    return CLI_EXIT_OK;
}

/*
 * cmd_models.c — `wetdem models`: the catalogue of built-in models, one line per model
 * (name, kind, one-line summary), grouped by kind in the order contact, impulse, fluid,
 * min-separation. Everything comes from the model registry (wetdem_model_registry()).
 */
#include <stdio.h>
#include <string.h>

#include "cli_util.h"

/* Kinds in the order a user builds a collision: solid contact, then fluid, then h_min. */
static const enum wetdem_model_kind kind_order[] = {
    WETDEM_MODEL_CONTACT,
    WETDEM_MODEL_IMPULSE,
    WETDEM_MODEL_FLUID,
    WETDEM_MODEL_MIN_SEPARATION,
};

int cmd_models(int argc, char** argv)
{
    if (cli_wants_help(argc, argv)) {
        printf("usage: wetdem models\nLists every built-in model: name, kind, summary.\n"
               "Details of one model: wetdem describe NAME\n");
        return CLI_EXIT_OK;
    }
    if (argc > 1) {
        cli_error("models: unexpected argument '%s' (usage: wetdem models)", argv[1]);
        return CLI_EXIT_USAGE;
    }
    const struct wetdem_model* const* reg = wetdem_model_registry();
    size_t n_kinds = sizeof kind_order / sizeof kind_order[0];
    bool printed_any = false;
    for (size_t g = 0; g < n_kinds; g++) {
        bool first = true;
        for (size_t k = 0; reg[k]; k++) {
            if (reg[k]->kind != kind_order[g])
                continue;
            if (first && printed_any)
                putchar('\n');
            first = false;
            printed_any = true;
            printf("%-12s %-15s %s\n", reg[k]->name, wetdem_model_kind_name(reg[k]->kind),
                   reg[k]->summary);
        }
    }
    return CLI_EXIT_OK;
}

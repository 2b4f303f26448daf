/*
 * model_registry.c — the one table of built-in models (contact, fluid, minimum separation,
 * impulse). Adding a model: write src/<family>_<name>.c exporting one const struct
 * wetdem_model, add its row here and in models.h, regenerate docs/models.md
 * (docs/add_model.md).
 */
#include <string.h>

#include "models.h"
#include "wetdem.h"

/* One row a model, grouped by kind as in models.h (the comments keep clang-format from packing
 * the rows into columns, which a new row would reflow). */
static const struct wetdem_model* const registry[] = {
    /* contact */
    &wetdem_force_hertz,
    &wetdem_force_mindlin,
    &wetdem_force_hooke,
    /* impulse */
    &wetdem_hard_model,
    /* fluid */
    &wetdem_force_nijssen,
    &wetdem_force_reynolds,
    &wetdem_force_sb,
    &wetdem_force_db,
    &wetdem_force_davis,
    &wetdem_force_nase,
    &wetdem_force_capillary,
    /* minimum separation */
    &wetdem_minsep_fixed,
    &wetdem_minsep_roughness,
    &wetdem_minsep_ehd,
    &wetdem_minsep_max,
    &wetdem_minsep_glass,
    NULL,
};

const struct wetdem_model* const* wetdem_model_registry(void)
{
    return registry;
}

const struct wetdem_model* wetdem_model_find(const char* name)
{
    if (!name)
        return NULL;
    for (size_t k = 0; registry[k]; k++)
        if (strcmp(registry[k]->name, name) == 0)
            return registry[k];
    return NULL;
}

const char* wetdem_model_kind_name(enum wetdem_model_kind kind)
{
    switch (kind) {
    case WETDEM_MODEL_CONTACT: return "contact";
    case WETDEM_MODEL_FLUID: return "fluid";
    case WETDEM_MODEL_MIN_SEPARATION: return "min-separation";
    case WETDEM_MODEL_IMPULSE: return "impulse";
    }
    return "unknown";
}

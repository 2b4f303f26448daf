/*
 * integrator.c — the table of the soft engine's integrators and their names. Each integrator
 * keeps its parameter block inside the simulation (engine.integrator_params), addressed by
 * dotted names "<integrator>.<param>" (sim_models.c), so that a scenario may set the
 * parameters of both integrators and choose one. Their descriptor tables and summaries are
 * public (wetdem_integrator_params, wetdem_integrator_summary) for `wetdem describe` and the
 * generated docs. Prefix: wetdem_integrator_.
 */
#include <string.h>

#include "integrator.h"

static const struct wetdem_integrator* const registry[] = {
    &wetdem_integrator_verlet,
    &wetdem_integrator_cvode,
    NULL,
};

static const char* const names[] = {"verlet", "cvode", NULL};

const struct wetdem_integrator* const* wetdem_integrator_registry(void)
{
    return registry;
}

const char* const* wetdem_integrator_names(void)
{
    return names;
}

const struct wetdem_param_desc* wetdem_integrator_params(const char* name)
{
    int k = name ? wetdem_integrator_index(name, strlen(name)) : -1;
    return k >= 0 ? registry[k]->params : NULL;
}

const char* wetdem_integrator_summary(const char* name)
{
    int k = name ? wetdem_integrator_index(name, strlen(name)) : -1;
    return k >= 0 ? registry[k]->summary : NULL;
}

int wetdem_integrator_index(const char* name, size_t len)
{
    for (int k = 0; registry[k]; k++)
        if (strlen(registry[k]->name) == len && strncmp(registry[k]->name, name, len) == 0)
            return k;
    return -1;
}

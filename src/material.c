/*
 * material.c — material and fluid presets, their descriptors and validation.
 * Prefix override: wetdem_material_* and wetdem_fluid_*.
 *
 * Presets:
 *   Nijssen et al. (2023) Table 1 (from Yang & Hunt 2006), spheres of d = 12.7 mm:
 *     steel1, steel2, glass, delrin. The table's "gamma" row is Young's modulus E (SPEC §6).
 *   Punch et al. (2023) Table 1: stainless-steel spheres, r = 12.7 mm, rho = 7960 kg/m^3,
 *     E = 2.0e11 Pa, nu = 0.35, e_dry = 0.9; the target carries a 270 um film of 10 Pa s
 *     silicone oil with surface tension 0.0205 N/m (the table's N/m^2 is a typo, SPEC §6).
 *     Roughness < 1 um is reported; h_min there comes from the glass transition, so the preset
 *     sets roughness 0. Friction 0.05 is the value Punch Fig. 11 finds in fair agreement.
 */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "status.h"
#include "wetdem.h"

struct named_material {
    const char* name;
    struct wetdem_material m;
};

static const struct named_material material_presets[] = {
    {"steel1",
     {.density = 7780,
      .youngs_modulus = 190e9,
      .poisson_ratio = 0.27,
      .restitution = 0.97,
      .friction_dry = 0.11,
      .friction_lub = 0.02,
      .roughness = 24e-9,
      .film = 0}},
    {"steel2",
     {.density = 7780,
      .youngs_modulus = 190e9,
      .poisson_ratio = 0.27,
      .restitution = 0.97,
      .friction_dry = 0.11,
      .friction_lub = 0.02,
      .roughness = 272e-9,
      .film = 0}},
    {"glass",
     {.density = 2540,
      .youngs_modulus = 60e9,
      .poisson_ratio = 0.23,
      .restitution = 0.97,
      .friction_dry = 0.40,
      .friction_lub = 0.10,
      .roughness = 134e-9,
      .film = 0}},
    {"delrin",
     {.density = 1400,
      .youngs_modulus = 2.8e9,
      .poisson_ratio = 0.35,
      .restitution = 0.97,
      .friction_dry = 0.20,
      .friction_lub = 0.10,
      .roughness = 796e-9,
      .film = 0}},
    {"punch_steel",
     {.density = 7960,
      .youngs_modulus = 2.0e11,
      .poisson_ratio = 0.35,
      .restitution = 0.9,
      .friction_dry = 0.05,
      .friction_lub = 0.05,
      .roughness = 0,
      .film = 0}},
    {"punch_steel_coated",
     {.density = 7960,
      .youngs_modulus = 2.0e11,
      .poisson_ratio = 0.35,
      .restitution = 0.9,
      .friction_dry = 0.05,
      .friction_lub = 0.05,
      .roughness = 0,
      .film = 270e-6}},
};

static const char* const material_names[] = {
    "steel1", "steel2", "glass", "delrin", "punch_steel", "punch_steel_coated", NULL};

struct named_fluid {
    const char* name;
    struct wetdem_fluid f;
};

static const struct named_fluid fluid_presets[] = {
    {"water", {.viscosity = 1.0e-3, .surface_tension = 0.072, .density = 998}},
    {"glycerol80", {.viscosity = 0.060, .surface_tension = 0.065, .density = 1209}},
    {"silicone10", {.viscosity = 10.0, .surface_tension = 0.0205, .density = 970}},
};

int wetdem_material_preset(const char* name, struct wetdem_material* m)
{
    if (!name || !m)
        return WETDEM_ERR_INVALID;
    for (size_t k = 0; k < sizeof material_presets / sizeof material_presets[0]; k++)
        if (strcmp(material_presets[k].name, name) == 0) {
            *m = material_presets[k].m;
            return WETDEM_OK;
        }
    return WETDEM_ERR_NOT_FOUND;
}

const char* const* wetdem_material_preset_names(void)
{
    return material_names;
}

int wetdem_fluid_preset(const char* name, struct wetdem_fluid* f)
{
    if (!name || !f)
        return WETDEM_ERR_INVALID;
    for (size_t k = 0; k < sizeof fluid_presets / sizeof fluid_presets[0]; k++)
        if (strcmp(fluid_presets[k].name, name) == 0) {
            *f = fluid_presets[k].f;
            return WETDEM_OK;
        }
    return WETDEM_ERR_NOT_FOUND;
}

#define MAT(field) offsetof(struct wetdem_material, field)
static const struct wetdem_param_desc material_params[] = {
    {"density", "kg/m^3", "Solid density.", MAT(density), 7780, 0, INFINITY, true, true, NULL,
     false},
    {"youngs_modulus", "Pa", "Young's modulus E.", MAT(youngs_modulus), 190e9, 0, INFINITY, true,
     true, NULL, false},
    {"poisson_ratio", "-", "Poisson's ratio nu.", MAT(poisson_ratio), 0.27, -1, 0.5, true, true,
     NULL, false},
    {"restitution", "-", "Dry coefficient of restitution e_dry.", MAT(restitution), 0.97, 0, 1,
     true, false, NULL, false},
    {"friction_dry", "-", "Coulomb friction coefficient of dry contact.", MAT(friction_dry), 0.11,
     0, 10, false, false, NULL, false},
    {"friction_lub", "-", "Coulomb friction coefficient of lubricated contact.", MAT(friction_lub),
     0.02, 0, 10, false, false, NULL, false},
    {"roughness", "m", "Mean asperity height sigma (Nijssen Eq. 3).", MAT(roughness), 0, 0, 1e-2,
     false, false, NULL, false},
    {"film", "m", "Liquid film thickness on this sphere (delta_i).", MAT(film), 0, 0, 1, false,
     false, NULL, false},
    {0},
};
#undef MAT

#define FLU(field) offsetof(struct wetdem_fluid, field)
static const struct wetdem_param_desc fluid_params[] = {
    {"viscosity", "Pa s", "Dynamic viscosity mu of the liquid.", FLU(viscosity), 1e-3, 0, 1e6,
     false, false, NULL, false},
    {"surface_tension", "N/m", "Surface tension sigma of the liquid.", FLU(surface_tension), 0.072,
     0, 10, false, false, NULL, false},
    {"density", "kg/m^3", "Liquid density.", FLU(density), 998, 0, 1e5, false, false, NULL, false},
    {0},
};
#undef FLU

const struct wetdem_param_desc* wetdem_material_params(void)
{
    return material_params;
}

const struct wetdem_param_desc* wetdem_fluid_params(void)
{
    return fluid_params;
}

/* Validates every double field of `obj` described by `table`. */
static int validate_struct(const struct wetdem_param_desc* table, const void* obj, const char* what,
                           char* msg, size_t n)
{
    for (size_t k = 0; table[k].name; k++) {
        double v = *(const double*)((const char*)obj + table[k].offset);
        char inner[256];
        if (wetdem_param_validate(&table[k], v, inner, sizeof inner) != WETDEM_OK) {
            if (msg && n)
                snprintf(msg, n, "%s.%s", what, inner);
            return WETDEM_ERR_INVALID;
        }
    }
    return WETDEM_OK;
}

double wetdem_material_sphere_mass(const struct wetdem_material* m, double radius)
{
    return m ? m->density * 4.0 / 3.0 * M_PI * radius * radius * radius : NAN;
}

int wetdem_material_validate(const struct wetdem_material* m, char* msg, size_t n)
{
    if (!m)
        return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID, "material: NULL");
    return validate_struct(material_params, m, "material", msg, n);
}

int wetdem_fluid_validate(const struct wetdem_fluid* f, char* msg, size_t n)
{
    if (!f)
        return wetdem_status_fail(msg, n, WETDEM_ERR_INVALID, "fluid: NULL");
    return validate_struct(fluid_params, f, "fluid", msg, n);
}

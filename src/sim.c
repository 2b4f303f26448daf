/*
 * sim.c — lifecycle of struct wetdem_sim, materials, fluid, particles and walls, and the
 * per-simulation error message. Prefix: wetdem_sim_.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "models.h"
#include "sim.h"
#include "vec3.h"

int wetdem_sim_fail(struct wetdem_sim* sim, int status, const char* fmt, ...)
{
    if (!sim)
        return status;
    char text[sizeof sim->errmsg]; /* the arguments may include the current message */
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    memcpy(sim->errmsg, text, sizeof text);
    return status;
}

const char* wetdem_sim_errmsg(const struct wetdem_sim* sim)
{
    return sim ? sim->errmsg : "";
}

struct wetdem_sim* wetdem_sim_create(void)
{
    struct wetdem_sim* sim = calloc(1, sizeof *sim);
    if (!sim)
        return NULL;
    wetdem_fluid_preset("water", &sim->fluid);
    sim->minsep.model = &wetdem_minsep_fixed;
    sim->minsep.params = calloc(1, wetdem_sim_slot_size(&wetdem_minsep_fixed));
    if (!sim->minsep.params) {
        free(sim);
        return NULL;
    }
    wetdem_param_init_defaults(wetdem_minsep_fixed.params, sim->minsep.params);
    sim->history_len = wetdem_minsep_fixed.history_len;
    wetdem_param_init_defaults(wetdem_sim_settings_params(), &sim->settings);
    wetdem_sim_engine_init(sim);
    return sim;
}

void wetdem_sim_free(struct wetdem_sim* sim)
{
    if (!sim)
        return;
    for (size_t k = 0; k < sim->n_models; k++)
        free(sim->models[k].params);
    wetdem_sim_engine_free(sim);
    wetdem_sim_many_free(sim);
    free(sim->minsep.params);
    free(sim->particles);
    free(sim->materials);
    free(sim->walls);
    free(sim);
}

/* Grows *array (element size `size`) to hold at least `need` elements. */
static int grow(void** array, size_t* cap, size_t need, size_t size)
{
    if (need <= *cap)
        return WETDEM_OK;
    size_t new_cap = *cap ? 2 * *cap : 8;
    while (new_cap < need)
        new_cap *= 2;
    void* p = realloc(*array, new_cap * size);
    if (!p)
        return WETDEM_ERR_NOMEM;
    *array = p;
    *cap = new_cap;
    return WETDEM_OK;
}

int wetdem_sim_add_material(struct wetdem_sim* sim, const struct wetdem_material* m)
{
    if (!m)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "add_material: NULL material");
    char msg[512];
    if (wetdem_material_validate(m, msg, sizeof msg) != WETDEM_OK)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "%s", msg);
    size_t cap = (size_t)sim->materials_cap;
    if (grow((void**)&sim->materials, &cap, (size_t)sim->n_materials + 1, sizeof *m) != WETDEM_OK)
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory adding a material");
    sim->materials_cap = (int)cap;
    sim->materials[sim->n_materials] = *m;
    return sim->n_materials++;
}

int wetdem_sim_add_material_preset(struct wetdem_sim* sim, const char* name)
{
    if (!name)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "add_material_preset: NULL name");
    struct wetdem_material m;
    if (wetdem_material_preset(name, &m) != WETDEM_OK) {
        const char* hint = wetdem_param_suggest(name, wetdem_material_preset_names());
        return wetdem_sim_fail(sim, WETDEM_ERR_NOT_FOUND, "unknown material preset '%s'%s%s%s",
                               name, hint ? " (did you mean '" : "", hint ? hint : "",
                               hint ? "'?)" : "");
    }
    return wetdem_sim_add_material(sim, &m);
}

const struct wetdem_material* wetdem_sim_material(const struct wetdem_sim* sim, int k)
{
    return (k >= 0 && k < sim->n_materials) ? &sim->materials[k] : NULL;
}

int wetdem_sim_n_materials(const struct wetdem_sim* sim)
{
    return sim->n_materials;
}

int wetdem_sim_set_fluid(struct wetdem_sim* sim, const struct wetdem_fluid* f)
{
    if (!f)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "set_fluid: NULL fluid");
    char msg[512];
    if (wetdem_fluid_validate(f, msg, sizeof msg) != WETDEM_OK)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "%s", msg);
    sim->fluid = *f;
    return WETDEM_OK;
}

struct wetdem_fluid wetdem_sim_fluid(const struct wetdem_sim* sim)
{
    return sim->fluid;
}

bool wetdem_sim_particle_valid(const struct wetdem_sim* sim, const struct wetdem_particle* p,
                               char* why, size_t n)
{
    if (p->material < 0 || p->material >= sim->n_materials)
        snprintf(why, n, "material %d does not exist (valid 0..%d)", p->material,
                 sim->n_materials - 1);
    else if (!vec3_is_finite(p->pos) || !vec3_is_finite(p->vel) || !vec3_is_finite(p->omega))
        snprintf(why, n, "position, velocity and spin must be finite");
    else if (!(isfinite(p->radius) && p->radius > 0))
        snprintf(why, n, "radius must be > 0 and finite, got %g m", p->radius);
    else if (!(isfinite(p->mass) && p->mass > 0))
        snprintf(why, n, "mass must be > 0 and finite, got %g kg", p->mass);
    else if (p->is_fixed && !(p->vel.x == 0 && p->vel.y == 0 && p->vel.z == 0 && p->omega.x == 0 &&
                              p->omega.y == 0 && p->omega.z == 0))
        /* the engines neither move it nor count its energy: a velocity would enter the pair
         * forces as the surface speed of a sphere that stands still */
        snprintf(why, n,
                 "a fixed particle is held in place: its velocity and spin must be 0, got v = "
                 "(%g, %g, %g) m/s, omega = (%g, %g, %g) rad/s",
                 p->vel.x, p->vel.y, p->vel.z, p->omega.x, p->omega.y, p->omega.z);
    else
        return true;
    return false;
}

int wetdem_sim_add_particle(struct wetdem_sim* sim, struct wetdem_particle p)
{
    size_t k = sim->n_particles;
    if (p.material < 0 || p.material >= sim->n_materials)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "particle %zu: material %d does not exist (valid 0..%d)", k,
                               p.material, sim->n_materials - 1);
    double density = sim->materials[p.material].density;
    if (p.mass == 0) {
        p.mass = wetdem_material_sphere_mass(&sim->materials[p.material], p.radius);
        if (isfinite(p.radius) && p.radius > 0 && !(isfinite(p.mass) && p.mass > 0))
            return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                                   "particle %zu: its mass density x 4/3 pi R^3 = %g kg (density "
                                   "%g kg/m^3, R = %g m) is not a positive finite number",
                                   k, p.mass, density, p.radius);
    }
    char why[256];
    if (!wetdem_sim_particle_valid(sim, &p, why, sizeof why))
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID, "particle %zu: %s", k, why);
    if (grow((void**)&sim->particles, &sim->particles_cap, k + 1, sizeof p) != WETDEM_OK)
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory adding particle %zu", k);
    sim->particles[k] = p;
    sim->n_particles++;
    return WETDEM_OK;
}

struct wetdem_particle* wetdem_sim_particles(struct wetdem_sim* sim, size_t* n)
{
    if (n)
        *n = sim->n_particles;
    return sim->particles;
}

size_t wetdem_sim_n_particles(const struct wetdem_sim* sim)
{
    return sim->n_particles;
}

int wetdem_sim_add_wall(struct wetdem_sim* sim, struct wetdem_vec3 point, struct wetdem_vec3 normal,
                        int material)
{
    if (!vec3_is_finite(point) || !vec3_is_finite(normal))
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "wall %zu: point (%g, %g, %g) m and normal (%g, %g, %g) must be "
                               "finite",
                               sim->n_walls, point.x, point.y, point.z, normal.x, normal.y,
                               normal.z);
    double big = fmax(fabs(normal.x), fmax(fabs(normal.y), fabs(normal.z)));
    if (!(big > 0))
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "wall %zu: normal (0, 0, 0) is zero: it gives no direction",
                               sim->n_walls);
    /* |normal| squares the components, which underflows to 0 (or loses digits) below 1e-150
     * and overflows above 1.3e154: such a normal is first scaled by its largest component
     * (others as they are: their unit normal unchanged to the last bit) */
    double len = vec3_norm(normal);
    if (!(len >= 1e-150 && len <= 1e150)) {
        normal = (struct wetdem_vec3){normal.x / big, normal.y / big, normal.z / big};
        /* (divided: 1 / big overflows for a subnormal big) */
        len = vec3_norm(normal); /* in [1, sqrt(3)] */
    }
    if (material < 0 || material >= sim->n_materials)
        return wetdem_sim_fail(sim, WETDEM_ERR_INVALID,
                               "wall %zu: material %d does not exist (valid 0..%d)", sim->n_walls,
                               material, sim->n_materials - 1);
    if (grow((void**)&sim->walls, &sim->walls_cap, sim->n_walls + 1, sizeof *sim->walls) !=
        WETDEM_OK)
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory adding a wall");
    sim->walls[sim->n_walls++] = (struct wetdem_wall){
        .point = point, .normal = vec3_scale(normal, 1.0 / len), .material = material};
    if (wetdem_sim_many_walls_added(sim) != WETDEM_OK) { /* (a many-particle run under way) */
        sim->n_walls--;
        return wetdem_sim_fail(sim, WETDEM_ERR_NOMEM, "out of memory adding a wall");
    }
    return WETDEM_OK;
}

size_t wetdem_sim_n_walls(const struct wetdem_sim* sim)
{
    return sim->n_walls;
}

void wetdem_sim_build_contact(const struct wetdem_sim* sim, size_t i, size_t j, bool is_wall,
                              struct wetdem_contact* c)
{
    const struct wetdem_particle* a = &sim->particles[i];
    if (is_wall) {
        const struct wetdem_wall* w = &sim->walls[j];
        wetdem_contact_with_wall(c, a, &sim->materials[a->material], w->point, w->normal,
                                 &sim->materials[w->material], &sim->fluid);
    } else {
        const struct wetdem_particle* b = &sim->particles[j];
        struct wetdem_particle image;
        if (sim->many) { /* across a periodic face: the image of j that the engine pairs */
            image = *b;
            image.pos = wetdem_sim_many_nearest_image(sim, a->pos, b->pos);
            b = &image;
        }
        wetdem_contact_from_particles(c, a, &sim->materials[a->material], b,
                                      &sim->materials[b->material], &sim->fluid);
    }
    c->i = i;
    c->j = j;
}

void wetdem_sim_reset(struct wetdem_sim* sim)
{
    sim->n_particles = 0;
    sim->n_walls = 0;
    sim->errmsg[0] = '\0';
    wetdem_sim_engine_clear(sim);
    wetdem_sim_many_reset(sim);
}

/* Copies n elements of size `size` into a fresh allocation (*dst); NULL source gives NULL. */
static int copy_array(void** dst, const void* src, size_t n, size_t size)
{
    *dst = NULL;
    if (!src || n == 0)
        return WETDEM_OK;
    *dst = malloc(n * size);
    if (!*dst)
        return WETDEM_ERR_NOMEM;
    memcpy(*dst, src, n * size);
    return WETDEM_OK;
}

/* Deep copy of a model slot's parameter block. */
static int copy_slot(struct wetdem_model_slot* dst, const struct wetdem_model_slot* src)
{
    *dst = *src;
    size_t size = wetdem_sim_slot_size(src->model);
    dst->params = malloc(size);
    if (!dst->params)
        return WETDEM_ERR_NOMEM;
    memcpy(dst->params, src->params, size);
    return WETDEM_OK;
}

/* Copies everything but the engine from src into the zeroed sim. */
static int copy_setup(struct wetdem_sim* sim, const struct wetdem_sim* src)
{
    sim->fluid = src->fluid;
    sim->settings = src->settings;
    sim->history_len = src->history_len;
    int st = copy_array((void**)&sim->particles, src->particles, src->n_particles,
                        sizeof *src->particles);
    if (st != WETDEM_OK)
        return st;
    sim->n_particles = sim->particles_cap = src->n_particles;
    st = copy_array((void**)&sim->materials, src->materials, (size_t)src->n_materials,
                    sizeof *src->materials);
    if (st != WETDEM_OK)
        return st;
    sim->n_materials = sim->materials_cap = src->n_materials;
    st = copy_array((void**)&sim->walls, src->walls, src->n_walls, sizeof *src->walls);
    if (st != WETDEM_OK)
        return st;
    sim->n_walls = sim->walls_cap = src->n_walls;
    st = copy_slot(&sim->minsep, &src->minsep);
    for (size_t k = 0; k < src->n_models && st == WETDEM_OK; k++) {
        st = copy_slot(&sim->models[k], &src->models[k]);
        if (st == WETDEM_OK)
            sim->n_models = k + 1;
    }
    return st;
}

struct wetdem_sim* wetdem_sim_clone(const struct wetdem_sim* src)
{
    struct wetdem_sim* sim = calloc(1, sizeof *sim);
    if (!sim)
        return NULL;
    wetdem_sim_engine_init(sim);
    int st = copy_setup(sim, src);
    if (st == WETDEM_OK)
        st = wetdem_sim_engine_copy(sim, src);
    if (st != WETDEM_OK) {
        wetdem_sim_free(sim);
        return NULL;
    }
    return sim;
}

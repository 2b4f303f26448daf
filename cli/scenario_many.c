/*
 * scenario_many.c — the sections of many-particle scenarios (cli_many_sections: [box],
 * [walls], [insert], [insert.NAME], [particle.NAME], [run], [dump]) and building a
 * simulation from them together with the shared [fluid], [material.NAME], [models],
 * [model.NAME], [integrator] and [sim] sections. docs/many.md ("From the command line") and
 * the generated tables of docs/scenarios.md describe every key.
 *
 * Spheres read from a file ([read.NAME]: a CSV or a frame of a wetdem run, sphere_file.c)
 * are taken as they are: they may overlap each other and the walls, as a settled packing does
 * (their contacts start without tangential history); only their centres must lie in the box,
 * and they must not overlap the groups before them.
 *
 * Geometry: the box is [0, size_x] x [0, size_y] x [0, size_z] [m]. A periodic axis wraps
 * (minimum image); on the other axes [walls] puts plane walls on the faces (by default on
 * every face of a non-periodic axis), with normals into the box. A wall on a periodic axis
 * would cut the periodic images and is refused. Insertion groups ([insert], [insert.NAME])
 * and single spheres ([particle.NAME]) are added in file order; each group is free of
 * overlaps by construction (src/insert.c; a random group also keeps clear of the spheres
 * added before it) and the groups are checked against each other here
 * (|x_i - x_j| >= R_i + R_j with the minimum image on periodic axes), as is every centre being
 * inside the box and every free sphere of [insert] or [particle] inside the walls.
 *
 * Every check runs before anything is written; each failure names the file, the line and the
 * key (scenario.h error convention).
 */
#include <ctype.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli_util.h"
#include "scenario_many.h"
#include "sphere_file.h"

#define NUM CLI_KEY_NUMBER
#define COUNT CLI_KEY_COUNT
#define WORD CLI_KEY_WORD
#define MAX_MATERIALS CLI_MANY_MAX_MATERIALS

static const char* const layouts[] = {"lattice", "random", NULL};
static const char* const face_names[] = {"x_min", "x_max", "y_min", "y_max",
                                         "z_min", "z_max", NULL};

static const struct cli_key_desc box_keys[] = {
    NUM("size_x", "m", "required", 0, 1e3, true, false, "Edge of the box along x: [0, size_x]."),
    NUM("size_y", "m", "required", 0, 1e3, true, false, "Edge of the box along y: [0, size_y]."),
    NUM("size_z", "m", "required", 0, 1e3, true, false, "Edge of the box along z: [0, size_z]."),
    WORD("periodic", CLI_VALUE_NAME_LIST, "none", NULL,
         "Periodic axes: any of x, y, z (e.g. 'x y'), or none. A periodic edge must be at least "
         "twice the cell edge 2 R_max + reach + skin."),
    {0},
};

static const struct cli_key_desc walls_keys[] = {
    WORD("faces", CLI_VALUE_NAME_LIST, "all", NULL,
         "Plane walls on faces of the box, normals inwards: any of x_min, x_max, y_min, y_max, "
         "z_min, z_max; all (every face of a non-periodic axis) or none. A face of a periodic "
         "axis is an error."),
    WORD("material", CLI_VALUE_NAME, "material of the first sphere group", NULL,
         "Material of the walls: a preset or NAME of a [material.NAME] section."),
    {0},
};

static const struct cli_key_desc insert_keys[] = {
    WORD("layout", CLI_VALUE_CHOICE, "random", layouts,
         "lattice: simple cubic lattice of spacing 2 radius_max + gap, bottom layers first; "
         "random: random sequential addition without overlap (jams near a volume fraction of "
         "0.38)."),
    COUNT("count", "required", 1, 1e8, "Number of spheres."),
    NUM("radius", "m", "required unless radius_min/max", 0, 1, true, false,
        "Radius of equal spheres."),
    NUM("radius_min", "m", "none", 0, 1, true, false,
        "Polydisperse: radii uniform in [radius_min, radius_max] (give both, not radius)."),
    NUM("radius_max", "m", "none", 0, 1, true, false, "Polydisperse: largest radius."),
    NUM("gap", "m", "0", 0, 1, false, false,
        "Least surface gap between spheres and to the region's faces."),
    COUNT("seed", "1", 0, 4294967295.0,
          "Seed of the generator (mt19937): the same seed gives the same spheres."),
    WORD("material", CLI_VALUE_NAME, "steel1", NULL,
         "Material: a preset (steel1, steel2, glass, delrin, punch_steel, punch_steel_coated) "
         "or NAME of a [material.NAME] section."),
    NUM("velocity_x", "m/s", "0", -1e3, 1e3, false, false, "Mean initial velocity, x."),
    NUM("velocity_y", "m/s", "0", -1e3, 1e3, false, false, "Mean initial velocity, y."),
    NUM("velocity_z", "m/s", "0", -1e3, 1e3, false, false, "Mean initial velocity, z."),
    NUM("velocity_sigma", "m/s", "0", 0, 1e3, false, false,
        "Standard deviation of each velocity component (Gaussian)."),
    NUM("x_min", "m", "0", -1e3, 1e3, false, false, "Insertion region: lower x (box by default)."),
    NUM("x_max", "m", "size_x", -1e3, 1e3, false, false, "Insertion region: upper x."),
    NUM("y_min", "m", "0", -1e3, 1e3, false, false, "Insertion region: lower y."),
    NUM("y_max", "m", "size_y", -1e3, 1e3, false, false, "Insertion region: upper y."),
    NUM("z_min", "m", "0", -1e3, 1e3, false, false, "Insertion region: lower z."),
    NUM("z_max", "m", "size_z", -1e3, 1e3, false, false, "Insertion region: upper z."),
    {0},
};

static const struct cli_key_desc particle_keys[] = {
    NUM("radius", "m", "required", 0, 1, true, false, "Radius."),
    NUM("x", "m", "required", -1e3, 1e3, false, false,
        "Centre, x (inside the box; a free sphere wholly inside the walls, a fixed one may cut "
        "them)."),
    NUM("y", "m", "required", -1e3, 1e3, false, false, "Centre, y."),
    NUM("z", "m", "required", -1e3, 1e3, false, false, "Centre, z."),
    NUM("vx", "m/s", "0", -1e3, 1e3, false, false, "Velocity, x."),
    NUM("vy", "m/s", "0", -1e3, 1e3, false, false, "Velocity, y."),
    NUM("vz", "m/s", "0", -1e3, 1e3, false, false, "Velocity, z."),
    NUM("spin_x", "rad/s", "0", -1e6, 1e6, false, false, "Spin, x."),
    NUM("spin_y", "rad/s", "0", -1e6, 1e6, false, false, "Spin, y."),
    NUM("spin_z", "rad/s", "0", -1e6, 1e6, false, false, "Spin, z."),
    WORD("material", CLI_VALUE_NAME, "steel1", NULL, "Material, as in [insert]."),
    WORD("fixed", CLI_VALUE_CHOICE, "no", cli_yes_no,
         "yes: held in place (infinite mass), at rest: vx ... spin_z must then be 0. Fixed "
         "spheres meet neither each other nor the walls."),
    {0},
};

static const char* const read_fixed_choices[] = {"file", "yes", "no", NULL};

static const struct cli_key_desc read_keys[] = {
    WORD("file", CLI_VALUE_TEXT, "required", NULL,
         "The spheres' file, relative to the scenario file's directory unless absolute: a frame "
         "of a wetdem run (PREFIX_NNNNNN.vtk: centres, radius, velocity, spin, fixed, material; "
         "a run's "
         "PREFIX.vtk.series stands for its last frame), or a CSV whose "
         "header names the columns x, y, z, radius [m] and optionally vx, vy, vz [m/s], spin_x, "
         "spin_y, spin_z [rad/s], fixed (0 or 1), material (an index: see materials) (a name "
         "may carry its unit, 'x [m]'; '#' lines are skipped). "
         "Values are checked as the keys of [particle.NAME]. The spheres may overlap each other "
         "and the walls (a settled packing does), but no two share a centre (0 and the length of a "
         "periodic axis are one place); their centres must "
         "lie in the box."),
    WORD("material", CLI_VALUE_NAME, "steel1", NULL, "Material of every sphere, as in [insert]."),
    WORD("materials", CLI_VALUE_TEXT, "none (material)", NULL,
         "Instead of material: the materials of the file's material indices 0, 1, ..., e.g. "
         "'glass steel1' (a CSV's material column; a frame's material array, the index of each "
         "sphere's material in the run that wrote it, as `wetdem run --check` lists them)."),
    WORD("fixed", CLI_VALUE_CHOICE, "file", read_fixed_choices,
         "Which spheres are held in place (infinite mass, at rest): file, those the file marks "
         "(a frame's fixed array, a CSV's fixed column of 0 and 1; none if it has neither); "
         "yes, every sphere (a rough base of glued spheres, a settled bed as an obstacle: the "
         "file's velocities and spins are then not used); no, none (the file's fixed column or "
         "array is then not read)."),
    {0},
};

static const struct cli_key_desc run_keys[] = {
    NUM("t_end", "s", "give t_end or steps", 0, 1e6, true, false,
        "Simulated time of the run, at most 1e15 steps of dt."),
    COUNT("steps", "give t_end or steps", 1, 1e15, "Number of time steps."),
    NUM("dt", "s", "0 ([integrator] dt, else dt_fraction)", 0, 1, false, false,
        "Time step; 0: [integrator] dt, else dt_fraction x the shortest contact time, normal or "
        "tangential, of the pairs that can occur (free spheres with the smallest free sphere, "
        "fixed spheres, walls) at twice the largest speed plus the speed gravity adds over the "
        "packing height, at most a quarter of the viscous relaxation time and the time to "
        "travel many_hmin_fraction x h_min at that speed (docs/many.md). A step at or above the "
        "relaxation time is refused; one above 0.1 x the contact time is warned about. Fixed "
        "for the run."),
    NUM("skin", "m", "0 (0.1 x smallest radius)", 0, 1, false, false,
        "Verlet skin of the neighbour lists."),
    WORD("energy_budget", CLI_VALUE_CHOICE, "yes", cli_yes_no,
         "Accumulate the work of every model on particle pairs and walls, and check that the "
         "budget closes (about 25-50 % slower: docs/many.md)."),
    {0},
};

static const struct cli_key_desc dump_keys[] = {
    WORD("vtk", CLI_VALUE_TEXT, "particles", NULL,
         "Prefix of the VTK files PREFIX_NNNNNN.vtk and of the ParaView index PREFIX.vtk.series "
         "in --out DIR; none disables them. A fresh run (no --restart) first removes the "
         "PREFIX_NNNNNN.vtk files and index of an earlier run from DIR (with none, or "
         "vtk_every = 0, those named particles)."),
    COUNT("vtk_every", "run steps / 50", 0, 1e15,
          "Steps between VTK frames (the last step is always written); 0: none. At most 1e5 "
          "files a run."),
    WORD("vtk_binary", CLI_VALUE_CHOICE, "yes", cli_yes_no,
         "yes: binary legacy VTK (exact, compact); no: ASCII with 17 digits."),
    WORD("vtk_links", CLI_VALUE_CHOICE, "no", cli_yes_no,
         "yes: with each frame, PREFIX_links_NNNNNN.vtk (index PREFIX_links.vtk.series): every "
         "contact and liquid bridge, and every pair apart that lubrication acts on, as a line, "
         "with its gap and normal and tangential force (force chains, bridge networks: "
         "docs/many.md)."),
    WORD("csv", CLI_VALUE_TEXT, "global.csv", NULL,
         "CSV of global quantities (energies, contacts, liquid bridges, agglomerates, work per "
         "model) in --out DIR, ending in .csv; none disables it."),
    COUNT("csv_every", "run steps / 500", 0, 1e15,
          "Steps between CSV rows (the last step is always written); 0: none. At most 1e7 "
          "rows a run."),
    WORD("checkpoint", CLI_VALUE_TEXT, "checkpoint.ckpt", NULL,
         "Checkpoint in --out DIR, written atomically every checkpoint_every steps, when "
         "interrupted (SIGINT, SIGTERM) and at the end; none disables it."),
    COUNT("checkpoint_every", "0 (interruption and end only)", 0, 1e15,
          "Steps between periodic checkpoints."),
    WORD("summary", CLI_VALUE_TEXT, "summary.json", NULL,
         "Summary and energy budget (JSON) in --out DIR; none disables it."),
    {0},
};

const struct cli_section_desc cli_many_sections[] = {
    {"box", "Many-particle run: the box [0, size] on each axis and its periodic axes.", box_keys},
    {"walls", "Many-particle run: plane walls on faces of the box.", walls_keys},
    {"insert", "Many-particle run: spheres inserted on a lattice or at random (seeded).",
     insert_keys},
    {"insert.*",
     "Many-particle run: another insertion group NAME with the keys of [insert]; groups and "
     "particles are added in file order and must not overlap (a random group keeps clear of "
     "the spheres before it: put larger spheres first).",
     insert_keys},
    {"particle.*", "Many-particle run: one sphere NAME placed explicitly.", particle_keys},
    {"read.*",
     "Many-particle run: spheres read from a file, a frame of an earlier run or a CSV table (a "
     "packing settled dry and then wetted, a state from another code); added in file order "
     "with the other groups.",
     read_keys},
    {"run", "Many-particle run: length, time step, neighbour-list skin, energy budget.", run_keys},
    {"dump", "Many-particle run: files written in `wetdem run --out DIR`.", dump_keys},
    {0},
};

/* Whether a section name belongs to the many-particle sections. */
static bool is_many_section(const char* name)
{
    for (size_t k = 0; cli_many_sections[k].name; k++)
        if (cli_section_matches(name, cli_many_sections[k].name))
            return true;
    return false;
}

bool cli_scenario_is_many(const struct cli_scenario* sc)
{
    bool collision = false;
    for (size_t k = 0; k < sc->n_sections; k++) {
        if (is_many_section(sc->sections[k].name))
            return true;
        collision = collision || strcmp(sc->sections[k].name, "collision") == 0;
    }
    /* a file of a binary collision stays one: a --set of a many-particle section ([box]) is
       refused at that --set as a section it does not read, not at the file's [collision] */
    for (size_t k = 0; k < sc->n_entries && !collision; k++)
        if (is_many_section(sc->entries[k].section))
            return true;
    return false;
}

/* ------------------------------------------------- fluid, models, integrator, settings --- */

static int build_models(const struct cli_scenario* sc, struct wetdem_sim* sim)
{
    wetdem_sim_clear_models(sim);
    const struct cli_entry* e = cli_scenario_find(sc, "models", "force");
    char buf[CLI_VALUE_MAX];
    snprintf(buf, sizeof buf, "%s", e ? e->value : "hertz");
    char* save = NULL;
    for (char* tok = strtok_r(buf, " ,\t", &save); tok; tok = strtok_r(NULL, " ,\t", &save)) {
        const struct wetdem_model* m = wetdem_model_find(tok);
        if (m && m->kind != WETDEM_MODEL_CONTACT && m->kind != WETDEM_MODEL_FLUID) {
            const char* kind = wetdem_model_kind_name(m->kind);
            cli_scenario_error(sc, e,
                               "'%s' is %s %s model: the many-particle mode sums force "
                               "models (contact and fluid) only",
                               tok, cli_article(kind), kind);
            return CLI_EXIT_USAGE;
        }
        int st = wetdem_sim_enable_model(sim, tok);
        if (st != WETDEM_OK)
            return cli_scenario_lib_error(sc, e, "models", sim, st);
    }
    int rc = cli_scenario_enable_min_separation(sc, sim);
    return rc == CLI_EXIT_OK ? cli_scenario_set_model_params(sc, sim) : rc;
}

/* [integrator] (the many mode steps with velocity Verlet: verlet.dt and verlet.dt_fraction
 * choose the step) and [sim] settings (gravity). */
static int build_settings(const struct cli_scenario* sc, struct wetdem_sim* sim)
{
    const struct cli_entry* n = cli_scenario_find(sc, "integrator", "name");
    if (n && strcmp(n->value, "verlet") != 0) {
        cli_scenario_error(sc, n,
                           "the many-particle mode steps with velocity Verlet: use "
                           "name = verlet (or leave it out)");
        return CLI_EXIT_USAGE;
    }
    /* (cvode's keys, rtol say, are not read: warned about by warn_ignored) */
    return cli_scenario_set_integrator_keys(sc, sim, "verlet", true);
}

/* ------------------------------------------------------------------------- materials --- */

/* Index of material `name` in su->sim, added on first use ([material.NAME] first, then a
 * preset) with its name in su->material_names (every material of the run comes through here,
 * so the table's k-th name is material k). `use` is the entry naming it (NULL: the default,
 * reported at `section`). */
static int material_index_at(const struct cli_scenario* sc, struct cli_many_setup* su,
                             const char* section, const struct cli_entry* use, const char* name,
                             int* index)
{
    int n = wetdem_sim_n_materials(su->sim);
    for (int k = 0; k < n; k++)
        if (strcmp(su->material_names[k], name) == 0) {
            *index = k;
            return CLI_EXIT_OK;
        }
    char msec[CLI_NAME_MAX];
    snprintf(msec, sizeof msec, "material.%s", name);
    struct wetdem_material m;
    if (cli_scenario_has_section(sc, msec)) {
        int rc = cli_scenario_material_section(sc, msec, &m);
        if (rc != CLI_EXIT_OK)
            return rc;
    } else if (wetdem_material_preset(name, &m) != WETDEM_OK) {
        const char* hint = wetdem_param_suggest(name, wetdem_material_preset_names());
        const char* fmt = "unknown material '%s'%s%s%s: use a preset or define a [material.%s] "
                          "section";
        if (use)
            cli_scenario_error(sc, use, fmt, name, hint ? " (did you mean '" : "", hint ? hint : "",
                               hint ? "'?)" : "", name);
        else
            cli_scenario_section_error(sc, section, fmt, name, hint ? " (did you mean '" : "",
                                       hint ? hint : "", hint ? "'?)" : "", name);
        return CLI_EXIT_USAGE;
    }
    if (n == MAX_MATERIALS) {
        cli_scenario_section_error(sc, section, "more than %d materials", MAX_MATERIALS);
        return CLI_EXIT_USAGE;
    }
    *index = wetdem_sim_add_material(su->sim, &m);
    if (*index < 0)
        return cli_scenario_lib_error(sc, use, section, su->sim, *index);
    snprintf(su->material_names[*index], sizeof su->material_names[0], "%s", name);
    return CLI_EXIT_OK;
}

/* material_index_at for the `material` key of `section`. */
static int material_index(const struct cli_scenario* sc, struct cli_many_setup* su,
                          const char* section, const char* name, int* index)
{
    return material_index_at(sc, su, section, cli_scenario_find(sc, section, "material"), name,
                             index);
}

/* ------------------------------------------------------------------------------- box --- */

static int build_box(const struct cli_scenario* sc, struct cli_many_setup* su)
{
    static const char* const size_keys[] = {"size_x", "size_y", "size_z"};
    for (int k = 0; k < 3; k++) {
        if (!cli_scenario_find(sc, "box", size_keys[k])) {
            cli_scenario_section_error(sc, "box",
                                       "[box] needs size_x, size_y and size_z [m] "
                                       "(the box is [0, size] on each axis)");
            return CLI_EXIT_USAGE;
        }
        su->box[k] = cli_scenario_number(sc, "box", size_keys[k], 0);
    }
    su->many.box_lo = (struct wetdem_vec3){0, 0, 0};
    su->many.box_hi = (struct wetdem_vec3){su->box[0], su->box[1], su->box[2]};
    const struct cli_entry* e = cli_scenario_find(sc, "box", "periodic");
    char buf[CLI_VALUE_MAX];
    snprintf(buf, sizeof buf, "%s", e ? e->value : "none");
    char* save = NULL;
    for (char* tok = strtok_r(buf, " ,\t", &save); tok; tok = strtok_r(NULL, " ,\t", &save)) {
        if (strcmp(tok, "none") == 0)
            continue;
        if (strlen(tok) != 1 || !strchr("xyz", tok[0])) {
            cli_scenario_error(sc, e, "'%s' is not an axis: list any of x, y, z, or none", tok);
            return CLI_EXIT_USAGE;
        }
        su->many.periodic[tok[0] - 'x'] = true;
    }
    return CLI_EXIT_OK;
}

/* Which faces get walls: bit f (order of face_names) set. */
static int wall_faces(const struct cli_scenario* sc, const struct cli_many_setup* su,
                      unsigned* faces)
{
    const struct cli_entry* e = cli_scenario_find(sc, "walls", "faces");
    char buf[CLI_VALUE_MAX];
    snprintf(buf, sizeof buf, "%s", e ? e->value : "all");
    *faces = 0;
    char* save = NULL;
    for (char* tok = strtok_r(buf, " ,\t", &save); tok; tok = strtok_r(NULL, " ,\t", &save)) {
        if (strcmp(tok, "none") == 0)
            continue;
        if (strcmp(tok, "all") == 0) {
            for (int k = 0; k < 3; k++)
                *faces |= su->many.periodic[k] ? 0u : 3u << (2 * k);
            continue;
        }
        int f = 0;
        while (face_names[f] && strcmp(face_names[f], tok) != 0)
            f++;
        if (!face_names[f]) {
            const char* hint = wetdem_param_suggest(tok, face_names);
            cli_scenario_error(sc, e,
                               "'%s' is not a face%s%s%s; faces: x_min, x_max, y_min, "
                               "y_max, z_min, z_max, all or none",
                               tok, hint ? " (did you mean '" : "", hint ? hint : "",
                               hint ? "'?)" : "");
            return CLI_EXIT_USAGE;
        }
        if (su->many.periodic[f / 2]) {
            cli_scenario_error(sc, e,
                               "wall %s lies on axis %c, which [box] periodic makes "
                               "periodic: remove the wall or the periodic axis",
                               tok, "xyz"[f / 2]);
            return CLI_EXIT_USAGE;
        }
        *faces |= 1u << f;
    }
    return CLI_EXIT_OK;
}

static int build_walls(const struct cli_scenario* sc, struct cli_many_setup* su,
                       const char* first_material)
{
    unsigned faces;
    int rc = wall_faces(sc, su, &faces);
    if (rc != CLI_EXIT_OK || !faces)
        return rc;
    int mat;
    const char* name = cli_scenario_text(sc, "walls", "material", first_material);
    if ((rc = material_index(sc, su, "walls", name, &mat)) != CLI_EXIT_OK)
        return rc;
    for (int f = 0; f < 6; f++) {
        if (!(faces & (1u << f)))
            continue;
        double point[3] = {0, 0, 0}, normal[3] = {0, 0, 0};
        point[f / 2] = (f % 2) ? su->box[f / 2] : 0.0;
        normal[f / 2] = (f % 2) ? -1.0 : 1.0;
        int st = wetdem_sim_add_wall(su->sim, (struct wetdem_vec3){point[0], point[1], point[2]},
                                     (struct wetdem_vec3){normal[0], normal[1], normal[2]}, mat);
        if (st != WETDEM_OK)
            return cli_scenario_lib_error(sc, cli_scenario_find(sc, "walls", "faces"), "walls",
                                          su->sim, st);
    }
    return CLI_EXIT_OK;
}

/* --------------------------------------------------------------------------- spheres --- */

/* Reports an insertion failure at the key the library message names ("insert.gap ...",
 * "insert radii ...", "insert: ... count ..."), else at the section. */
static int insert_error(const struct cli_scenario* sc, const char* section, const char* msg)
{
    const char* key = NULL;
    char k[CLI_NAME_MAX];
    if (strncmp(msg, "insert.", 7) == 0) {
        size_t n = strcspn(msg + 7, " ");
        snprintf(k, sizeof k, "%.*s", (int)(n < sizeof k ? n : sizeof k - 1), msg + 7);
        key = k;
    } else if (strncmp(msg, "insert radii", 12) == 0)
        key = cli_scenario_find(sc, section, "radius") ? "radius" : "radius_max";
    else if (strncmp(msg, "insert:", 7) == 0)
        key = "count";
    const struct cli_entry* e = key ? cli_scenario_find(sc, section, key) : NULL;
    if (e)
        cli_scenario_error(sc, e, "%s", msg);
    else
        cli_scenario_section_error(sc, section, "%s", msg);
    return CLI_EXIT_USAGE;
}

static int insert_radii(const struct cli_scenario* sc, const char* section,
                        struct wetdem_insert_spec* s)
{
    const struct cli_entry* r = cli_scenario_find(sc, section, "radius");
    const struct cli_entry* lo = cli_scenario_find(sc, section, "radius_min");
    const struct cli_entry* hi = cli_scenario_find(sc, section, "radius_max");
    if (r && (lo || hi)) {
        cli_scenario_error(sc, lo ? lo : hi,
                           "give radius (equal spheres) or radius_min and "
                           "radius_max (polydisperse), not both");
        return CLI_EXIT_USAGE;
    }
    if (!r && !(lo && hi)) {
        cli_scenario_section_error(sc, section,
                                   "[%s] needs radius, or radius_min and "
                                   "radius_max [m]",
                                   section);
        return CLI_EXIT_USAGE;
    }
    s->radius_min = strtod(r ? r->value : lo->value, NULL);
    s->radius_max = strtod(r ? r->value : hi->value, NULL);
    if (s->radius_max < s->radius_min) {
        cli_scenario_error(sc, hi, "radius_max must be >= radius_min = %g m", s->radius_min);
        return CLI_EXIT_USAGE;
    }
    return CLI_EXIT_OK;
}

/* Progress of a random insertion, on stderr when it is a terminal: near the random-insertion
 * limit a million spheres take some 20 s. The line is redrawn at most twice a second and
 * cleared at the end. No time left is shown: the trials per sphere grow as the region fills. */
struct insert_progress {
    const char* section;
    double last_print; /* [s] of wall time */
    bool shown;        /* a line is on the terminal */
};

static void clear_insert_progress(struct insert_progress* p)
{
    if (p->shown)
        fprintf(stderr, "\r%100s\r", "");
    p->shown = false;
}

static int on_insert_progress(unsigned long long done, unsigned long long total, double elapsed,
                              void* ctx)
{
    struct insert_progress* p = ctx;
    if (!(elapsed - p->last_print >= 0.5 || done == total))
        return 0;
    p->last_print = elapsed;
    fprintf(stderr, "\rwetdem: [%s] %llu/%llu spheres placed (%5.1f %%), %.0f s elapsed   ",
            p->section, done, total, 100.0 * (double)done / (double)total, elapsed);
    p->shown = true;
    if (done == total)
        clear_insert_progress(p);
    fflush(stderr);
    return 0;
}

static int build_insert(const struct cli_scenario* sc, struct cli_many_setup* su,
                        const char* section)
{
    if (!cli_scenario_find(sc, section, "count")) {
        cli_scenario_section_error(sc, section, "[%s] needs count", section);
        return CLI_EXIT_USAGE;
    }
    struct wetdem_insert_spec s = {0};
    int rc = insert_radii(sc, section, &s);
    if (rc != CLI_EXIT_OK)
        return rc;
    const char* layout = cli_scenario_text(sc, section, "layout", "random");
    s.layout = strcmp(layout, "lattice") == 0 ? WETDEM_INSERT_LATTICE : WETDEM_INSERT_RANDOM;
    s.n = (size_t)cli_scenario_number(sc, section, "count", 1);
    s.gap = cli_scenario_number(sc, section, "gap", 0);
    s.seed = (unsigned long)cli_scenario_number(sc, section, "seed", 1);
    s.velocity = (struct wetdem_vec3){cli_scenario_number(sc, section, "velocity_x", 0),
                                      cli_scenario_number(sc, section, "velocity_y", 0),
                                      cli_scenario_number(sc, section, "velocity_z", 0)};
    s.velocity_sigma = cli_scenario_number(sc, section, "velocity_sigma", 0);
    static const char* const lo_keys[] = {"x_min", "y_min", "z_min"};
    static const char* const hi_keys[] = {"x_max", "y_max", "z_max"};
    double lo[3], hi[3];
    for (int k = 0; k < 3; k++) {
        lo[k] = cli_scenario_number(sc, section, lo_keys[k], 0);
        hi[k] = cli_scenario_number(sc, section, hi_keys[k], su->box[k]);
        /* the region wraps only where it spans the whole periodic edge */
        s.periodic[k] = su->many.periodic[k] && lo[k] == 0 && hi[k] == su->box[k];
    }
    s.lo = (struct wetdem_vec3){lo[0], lo[1], lo[2]};
    s.hi = (struct wetdem_vec3){hi[0], hi[1], hi[2]};
    rc = material_index(sc, su, section, cli_scenario_text(sc, section, "material", "steel1"),
                        &s.material);
    if (rc != CLI_EXIT_OK)
        return rc;
    struct insert_progress prog = {.section = section};
    if (isatty(STDERR_FILENO)) {
        s.progress = on_insert_progress;
        s.progress_ctx = &prog;
    }
    int st = wetdem_sim_insert(su->sim, &s);
    clear_insert_progress(&prog); /* before a message: the insertion may fail part way */
    if (st == WETDEM_ERR_NOMEM) {
        cli_error("%s: out of memory inserting %zu spheres", sc->file, s.n);
        return CLI_EXIT_RUNTIME;
    }
    return st == WETDEM_OK ? CLI_EXIT_OK : insert_error(sc, section, wetdem_sim_errmsg(su->sim));
}

static int build_particle(const struct cli_scenario* sc, struct cli_many_setup* su,
                          const char* section)
{
    static const char* const req[] = {"radius", "x", "y", "z"};
    for (int k = 0; k < 4; k++)
        if (!cli_scenario_find(sc, section, req[k])) {
            cli_scenario_section_error(sc, section, "[%s] needs radius, x, y and z", section);
            return CLI_EXIT_USAGE;
        }
#define N(key) cli_scenario_number(sc, section, key, 0)
    struct wetdem_particle p = {
        .pos = {N("x"), N("y"), N("z")},
        .vel = {N("vx"), N("vy"), N("vz")},
        .omega = {N("spin_x"), N("spin_y"), N("spin_z")},
        .radius = N("radius"),
        .is_fixed = strcmp(cli_scenario_text(sc, section, "fixed", "no"), "yes") == 0};
#undef N
    int rc = material_index(sc, su, section, cli_scenario_text(sc, section, "material", "steel1"),
                            &p.material);
    if (rc != CLI_EXIT_OK)
        return rc;
    int st = wetdem_sim_add_particle(su->sim, p);
    if (st != WETDEM_OK)
        return cli_scenario_lib_error(sc, NULL, section, su->sim, st);
    return CLI_EXIT_OK;
}

/* The [read.NAME] file: its value, relative to the scenario file's directory unless it is
 * absolute, into path. */
static void sphere_file_path(const struct cli_scenario* sc, const char* value, char* path, size_t n)
{
    const char* slash = strrchr(sc->file, '/');
    if (value[0] == '/' || !slash)
        snprintf(path, n, "%s", value);
    else
        snprintf(path, n, "%.*s/%s", (int)(slash - sc->file), sc->file, value);
}

/* The [read.NAME] materials list (materials = A B ...: the materials of the file's indices 0, 1,
 * ...) resolved into index[0 .. *n), sim's materials. */
static int read_materials(const struct cli_scenario* sc, struct cli_many_setup* su,
                          const char* section, const struct cli_entry* list, int* index, size_t* n)
{
    const char* empty = cli_list_empty_name(list->value);
    /* "glass,,steel1": an index left out, which strtok would skip unseen ("," alone: below) */
    if (empty && strncmp(empty, "only", 4) != 0) {
        cli_scenario_error(sc, list,
                           "%s: separate the names by one comma or by blanks ('glass, steel1' "
                           "or 'glass steel1')",
                           empty);
        return CLI_EXIT_USAGE;
    }
    char buf[CLI_VALUE_MAX], *save = NULL;
    snprintf(buf, sizeof buf, "%s", list->value);
    *n = 0;
    for (char* tok = strtok_r(buf, " ,\t", &save); tok; tok = strtok_r(NULL, " ,\t", &save)) {
        if (*n == MAX_MATERIALS) {
            cli_scenario_error(sc, list, "more than %d materials", MAX_MATERIALS);
            return CLI_EXIT_USAGE;
        }
        int rc = material_index_at(sc, su, section, list, tok, &index[(*n)++]);
        if (rc != CLI_EXIT_OK)
            return rc;
    }
    if (*n == 0) {
        cli_scenario_error(sc, list,
                           "materials names none: give the materials of the file's "
                           "indices 0, 1, ... (e.g. 'glass steel1')");
        return CLI_EXIT_USAGE;
    }
    return CLI_EXIT_OK;
}

/* Each sphere's material: with `materials`, the one its index in the file (p[k].material, -1
 * when the file has none) names; without, `material` for all, with a warning when the file's
 * spheres have several indices (their materials are then not kept apart). */
static int assign_materials(const struct cli_scenario* sc, struct cli_many_setup* su,
                            const char* section, const char* path, struct wetdem_particle* p,
                            size_t n)
{
    const struct cli_entry* list = cli_scenario_find(sc, section, "materials");
    const struct cli_entry* one = cli_scenario_find(sc, section, "material");
    if (list && one) {
        cli_scenario_error(sc, list,
                           "give material (every sphere) or materials (by the file's "
                           "material column), not both");
        return CLI_EXIT_USAGE;
    }
    int index[MAX_MATERIALS], material;
    size_t n_list = 0;
    int rc = list ? read_materials(sc, su, section, list, index, &n_list)
                  : material_index(sc, su, section,
                                   cli_scenario_text(sc, section, "material", "steel1"), &material);
    if (rc != CLI_EXIT_OK)
        return rc;
    int lo = INT_MAX, hi = -1;
    for (size_t k = 0; k < n; k++) {
        int m = p[k].material;
        if (list && (m < 0 || (size_t)m >= n_list)) {
            if (m < 0)
                cli_scenario_error(sc, list,
                                   "%s has no material column (a CSV) or array (a frame) for "
                                   "materials to map",
                                   path);
            else
                cli_scenario_error(sc, list,
                                   "sphere %zu of %s has material %d; materials names %zu "
                                   "(indices 0 to %zu)",
                                   k + 1, path, m, n_list, n_list - 1);
            return CLI_EXIT_USAGE;
        }
        lo = m < lo ? m : lo;
        hi = m > hi ? m : hi;
        p[k].material = list ? index[m] : material;
    }
    if (!list && lo >= 0 && hi > lo)
        cli_error("warning: %s: [%s]: the spheres of %s have material indices %d to %d; every one "
                  "takes material = %s (materials = ... keeps them apart)",
                  sc->file, section, path, lo, hi,
                  cli_scenario_text(sc, section, "material", "steel1"));
    return CLI_EXIT_OK;
}

static int build_sphere_file(const struct cli_scenario* sc, struct cli_many_setup* su,
                             const char* section)
{
    const struct cli_entry* e = cli_scenario_find(sc, section, "file");
    if (!e || !e->value[0]) {
        cli_scenario_section_error(sc, section, "[%s] needs file (a CSV or a frame .vtk)", section);
        return CLI_EXIT_USAGE;
    }
    char path[2200], why[512];
    sphere_file_path(sc, e->value, path, sizeof path);
    struct wetdem_particle* p = NULL;
    size_t n = 0;
    const char* fixed = cli_scenario_text(sc, section, "fixed", "file");
    double period[3];
    for (int k = 0; k < 3; k++)
        period[k] = su->many.periodic[k] ? su->box[k] : 0;
    int rc =
        cli_read_sphere_file(path, strcmp(fixed, "file") == 0, period, &p, &n, why, sizeof why);
    if (rc != CLI_EXIT_OK) {
        /* "PATH:LINE: why" for a CSV (why starts with its line), "PATH: why" otherwise */
        cli_scenario_error(sc, e, "%s:%s%s", path, isdigit((unsigned char)why[0]) ? "" : " ", why);
        return rc;
    }
    rc = assign_materials(sc, su, section, path, p, n);
    for (size_t k = 0; k < n && rc == CLI_EXIT_OK; k++) {
        if (strcmp(fixed, "yes") == 0) /* at rest */
            p[k] = (struct wetdem_particle){.pos = p[k].pos,
                                            .radius = p[k].radius,
                                            .material = p[k].material,
                                            .is_fixed = true};
        int st = wetdem_sim_add_particle(su->sim, p[k]);
        if (st != WETDEM_OK)
            rc = cli_scenario_lib_error(sc, e, section, su->sim, st);
    }
    free(p);
    return rc;
}

/* Separation of a and b along axis k, minimum image on periodic axes [m]. */
static double axis_delta(const struct cli_many_setup* su, int k, double a, double b)
{
    double d = a - b;
    if (su->many.periodic[k])
        d -= su->box[k] * round(d / su->box[k]);
    return d;
}

/* A group of spheres: its section, the index of its first sphere, and whether it was read from
 * a file (then its spheres may overlap the walls). */
struct group {
    const char* section;
    size_t from;
    bool from_file;
};

/* The spheres [0, from) binned in a grid over the box, so that a later sphere is tested
 * against those in its cell and the neighbouring ones only (two groups of 40,000 spheres took
 * 22 s when each was tested against every earlier one). Cells are at least the largest
 * diameter 2 R_max of any sphere (slightly more, against rounding) on each axis, so two
 * spheres that overlap lie in neighbouring cells (across the face of a periodic axis too), and
 * there are at most about 2 from + 27 of them. Every centre lies in the box (check_group). */
struct bins {
    size_t n[3];
    double edge[3];
    size_t* start; /* the spheres of cell c: index[start[c] .. start[c + 1]) */
    size_t* index;
};

/* The cell of centre x along axis k. */
static size_t bin_of(const struct bins* b, int k, double x)
{
    double c = floor(x / b->edge[k]);
    return c < 0 ? 0 : c >= (double)b->n[k] ? b->n[k] - 1 : (size_t)c;
}

static size_t bin_cell(const struct bins* b, const struct wetdem_particle* p)
{
    return (bin_of(b, 2, p->pos.z) * b->n[1] + bin_of(b, 1, p->pos.y)) * b->n[0] +
           bin_of(b, 0, p->pos.x);
}

/* Bins spheres [0, from) of p[0 .. n). 0, or -1 when out of memory. */
static int bins_build(struct bins* b, const struct cli_many_setup* su,
                      const struct wetdem_particle* p, size_t n, size_t from)
{
    double r_max = 0;
    for (size_t i = 0; i < n; i++)
        r_max = fmax(r_max, p[i].radius);
    double reach = 2 * r_max * (1 + 1e-9), cells = 1;
    for (int k = 0; k < 3; k++) {
        double m = floor(su->box[k] / reach);
        b->n[k] = m < 1 ? 1 : m > 1e6 ? 1000000 : (size_t)m;
        cells *= (double)b->n[k];
    }
    while (cells > 2.0 * (double)from + 27) { /* coarser along the axis of the most cells */
        int k = b->n[0] >= b->n[1] && b->n[0] >= b->n[2] ? 0 : b->n[1] >= b->n[2] ? 1 : 2;
        cells = cells / (double)b->n[k] * (double)((b->n[k] + 1) / 2);
        b->n[k] = (b->n[k] + 1) / 2;
    }
    for (int k = 0; k < 3; k++)
        b->edge[k] = su->box[k] / (double)b->n[k];
    size_t nc = b->n[0] * b->n[1] * b->n[2];
    b->start = calloc(nc + 1, sizeof *b->start);
    b->index = malloc((from ? from : 1) * sizeof *b->index);
    if (!b->start || !b->index)
        return -1;
    for (size_t j = 0; j < from; j++)
        b->start[bin_cell(b, &p[j]) + 1]++;
    for (size_t c = 0; c < nc; c++)
        b->start[c + 1] += b->start[c];
    for (size_t j = 0; j < from; j++) /* (start[c] counts up to start[c + 1]: restored below) */
        b->index[b->start[bin_cell(b, &p[j])]++] = j;
    for (size_t c = nc; c > 0; c--)
        b->start[c] = b->start[c - 1];
    b->start[0] = 0;
    return 0;
}

/* The cells next to cell a along axis k (a itself included), each once, into out: those
 * across the face of a periodic axis too. Their number. */
static int bin_neighbours(const struct bins* b, const struct cli_many_setup* su, int k, size_t a,
                          size_t out[3])
{
    size_t n = b->n[k];
    bool periodic = su->many.periodic[k];
    /* a - 1, a, a + 1, wrapped on a periodic axis, within [0, n) on another */
    const size_t below = a > 0 ? a - 1 : periodic ? n - 1 : a;
    const size_t above = a + 1 < n ? a + 1 : periodic ? 0 : a;
    const size_t cand[3] = {below, a, above};
    int m = 0;
    for (int d = 0; d < 3; d++) {
        size_t c = cand[d];
        bool seen = false;
        for (int q = 0; q < m; q++)
            seen = seen || out[q] == c;
        if (!seen)
            out[m++] = c;
    }
    return m;
}

/* The first sphere j < from (by index) that sphere i overlaps, with its gap in *gap; from if
 * none. */
static size_t first_overlap(const struct bins* b, const struct cli_many_setup* su,
                            const struct wetdem_particle* p, size_t i, size_t from, double* gap)
{
    size_t cx[3], cy[3], cz[3], found = from;
    int nx = bin_neighbours(b, su, 0, bin_of(b, 0, p[i].pos.x), cx);
    int ny = bin_neighbours(b, su, 1, bin_of(b, 1, p[i].pos.y), cy);
    int nz = bin_neighbours(b, su, 2, bin_of(b, 2, p[i].pos.z), cz);
    for (int a = 0; a < nz; a++)
        for (int c = 0; c < ny; c++)
            for (int e = 0; e < nx; e++) {
                size_t cell = (cz[a] * b->n[1] + cy[c]) * b->n[0] + cx[e];
                for (size_t q = b->start[cell]; q < b->start[cell + 1]; q++) {
                    size_t j = b->index[q];
                    if (j >= found)
                        continue;
                    double d[3] = {axis_delta(su, 0, p[i].pos.x, p[j].pos.x),
                                   axis_delta(su, 1, p[i].pos.y, p[j].pos.y),
                                   axis_delta(su, 2, p[i].pos.z, p[j].pos.z)};
                    double g =
                        sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) - p[i].radius - p[j].radius;
                    if (g < 0) {
                        found = j;
                        *gap = g;
                    }
                }
            }
    return found;
}

/* Spheres [from, n) of the latest of groups[0 .. n_groups) against the spheres of the groups
 * before it, and each inside the box: its centre in [0, size], and the whole sphere inside on
 * an axis with walls unless it was read from a file or is fixed (fixed spheres meet no wall:
 * a base sunk into the floor). */
static int check_group(const struct cli_scenario* sc, const struct cli_many_setup* su,
                       const struct group* groups, size_t n_groups, unsigned faces)
{
    const char* section = groups[n_groups - 1].section;
    size_t from = groups[n_groups - 1].from;
    bool inside_walls = !groups[n_groups - 1].from_file; /* else the centre inside the box */
    size_t n;
    const struct wetdem_particle* p = wetdem_sim_particles_const(su->sim, &n);
    struct bins b = {.start = NULL, .index = NULL};
    if (from > 0 && bins_build(&b, su, p, n, from) != 0) {
        free(b.start);
        free(b.index);
        cli_error("out of memory");
        return CLI_EXIT_RUNTIME;
    }
    int rc = CLI_EXIT_OK;
    for (size_t i = from; i < n && rc == CLI_EXIT_OK; i++) {
        double x[3] = {p[i].pos.x, p[i].pos.y, p[i].pos.z};
        for (int k = 0; k < 3; k++) {
            bool walls = inside_walls && !p[i].is_fixed;
            double lo = walls && (faces >> (2 * k)) & 1u ? p[i].radius : 0.0;
            double hi = walls && (faces >> (2 * k + 1)) & 1u ? p[i].radius : 0.0;
            if (!(x[k] >= lo && x[k] <= su->box[k] - hi)) {
                cli_scenario_section_error(sc, section,
                                           "sphere %zu of [%s] (centre %c = %.15g m, "
                                           "radius %g m) is outside the box [0, %.15g] m%s",
                                           i - from + 1, section, "xyz"[k], x[k], p[i].radius,
                                           su->box[k], (lo > 0 || hi > 0) ? " or cuts a wall" : "");
                rc = CLI_EXIT_USAGE;
                break;
            }
        }
        double gap = 0;
        size_t j = rc == CLI_EXIT_OK && from > 0 ? first_overlap(&b, su, p, i, from, &gap) : from;
        if (j < from) {
            size_t g = n_groups - 1;
            while (g > 0 && groups[g].from > j)
                g--;
            cli_scenario_section_error(sc, section,
                                       "sphere %zu of [%s] overlaps sphere %zu of [%s] by %g "
                                       "m: move or shrink one of the groups (they are "
                                       "inserted in file order)",
                                       i - from + 1, section, j - groups[g].from + 1,
                                       groups[g].section, -gap);
            rc = CLI_EXIT_USAGE;
        }
    }
    free(b.start);
    free(b.index);
    return rc;
}

/* Every [insert], [insert.NAME], [particle.NAME] and [read.NAME] in file order. *first:
 * material name of the first group (default of [walls] material). */
static int build_spheres(const struct cli_scenario* sc, struct cli_many_setup* su, unsigned faces,
                         const char** first)
{
    *first = NULL;
    struct group* groups = malloc((sc->n_sections ? sc->n_sections : 1) * sizeof *groups);
    if (!groups) {
        cli_error("out of memory");
        return CLI_EXIT_RUNTIME;
    }
    size_t n_groups = 0;
    for (size_t s = 0; s < sc->n_sections; s++) {
        const char* name = sc->sections[s].name;
        bool ins = strcmp(name, "insert") == 0 || strncmp(name, "insert.", 7) == 0;
        bool file = strncmp(name, "read.", 5) == 0;
        if (!ins && !file && strncmp(name, "particle.", 9) != 0)
            continue;
        groups[n_groups++] = (struct group){name, wetdem_sim_n_particles(su->sim), file};
        int rc = ins    ? build_insert(sc, su, name)
                 : file ? build_sphere_file(sc, su, name)
                        : build_particle(sc, su, name);
        if (rc == CLI_EXIT_OK)
            rc = check_group(sc, su, groups, n_groups, faces);
        if (rc != CLI_EXIT_OK) {
            free(groups);
            return rc;
        }
        if (!*first) { /* the material of the group's first sphere */
            int m = wetdem_sim_particles_const(su->sim, NULL)[groups[n_groups - 1].from].material;
            *first = su->material_names[m];
        }
    }
    free(groups);
    if (!*first) {
        cli_scenario_section_error(sc, "box",
                                   "no spheres: add an [insert] section (or "
                                   "[insert.NAME], [particle.NAME], [read.NAME])");
        return CLI_EXIT_USAGE;
    }
    return CLI_EXIT_OK;
}

/* --------------------------------------------------------------------- run and dump --- */

/* The files of --out DIR must not share a name (the one written last would replace the
 * other, and a fresh run removes whatever is named as its frames): the CSV, the checkpoint,
 * the summary, the frames' index and their links' index (each also as its temporary
 * NAME.tmp), none named as a frame or a links frame. The message stands at the key of the
 * first of the two in that order that the scenario gives. */
static int dump_names_distinct(const struct cli_scenario* sc, const struct cli_many_setup* su)
{
    char index[CLI_VALUE_MAX + 16] = "", links_index[CLI_VALUE_MAX + 24] = "",
                               links_prefix[CLI_VALUE_MAX + 8] = "";
    if (su->vtk_prefix[0]) {
        snprintf(index, sizeof index, "%s.vtk.series", su->vtk_prefix);
        snprintf(links_prefix, sizeof links_prefix, "%s" WETDEM_LINKS_SUFFIX, su->vtk_prefix);
        snprintf(links_index, sizeof links_index, "%s.vtk.series", links_prefix);
    }
    const struct {
        const char *key, *name, *what;
    } file[5] = {{"vtk", index, "the frames' index"},
                 {"vtk", links_index, "the links' index"},
                 {"csv", su->csv_name, "the CSV"},
                 {"checkpoint", su->checkpoint_name, "the checkpoint"},
                 {"summary", su->summary_name, "the summary"}};
    for (int a = 0; a < 5; a++) {
        char clash[80] = "";
        const char* clash_key = "vtk";
        if (a >= 2 && file[a].name[0] && su->vtk_prefix[0] &&
            (cli_is_frame_name(su->vtk_prefix, file[a].name) ||
             cli_is_frame_name(links_prefix, file[a].name)))
            snprintf(clash, sizeof clash, "a VTK frame");
        for (int b = 0; file[a].name[0] && !clash[0] && b < 5; b++) {
            size_t lb = strlen(file[b].name);
            bool same = strcmp(file[a].name, file[b].name) == 0,
                 tmp = strncmp(file[a].name, file[b].name, lb) == 0 &&
                       strcmp(file[a].name + lb, ".tmp") == 0;
            if (b != a && lb && (same || tmp)) {
                snprintf(clash, sizeof clash, "%s%s", same ? "" : "the temporary file of ",
                         file[b].what);
                clash_key = file[b].key;
            }
        }
        if (!clash[0])
            continue;
        const struct cli_entry* e = cli_scenario_find(sc, "dump", file[a].key);
        if (!e)
            e = cli_scenario_find(sc, "dump", clash_key);
        const char* text = "%s would name both %s and %s: give the outputs of --out distinct "
                           "names";
        if (e)
            cli_scenario_error(sc, e, text, file[a].name, file[a].what, clash);
        else
            cli_scenario_section_error(sc, "dump", text, file[a].name, file[a].what, clash);
        return CLI_EXIT_USAGE;
    }
    return CLI_EXIT_OK;
}

static int build_run(const struct cli_scenario* sc, struct cli_many_setup* su)
{
    const struct cli_entry* te = cli_scenario_find(sc, "run", "t_end");
    const struct cli_entry* se = cli_scenario_find(sc, "run", "steps");
    if (te && se && (te->line == 0) != (se->line == 0)) { /* --set of one replaces the other */
        if (te->line == 0)
            se = NULL;
        else
            te = NULL;
    }
    if (te && se) {
        cli_scenario_error(sc, se, "give t_end or steps, not both");
        return CLI_EXIT_USAGE;
    }
    if (!te && !se) {
        cli_scenario_section_error(sc, "run", "[run] needs t_end [s] or steps");
        return CLI_EXIT_USAGE;
    }
    su->t_end = te ? strtod(te->value, NULL) : 0;
    su->steps = se ? (unsigned long long)strtod(se->value, NULL) : 0;
    su->many.dt = cli_scenario_number(sc, "run", "dt", 0);
    su->many.skin = cli_scenario_number(sc, "run", "skin", 0);
    su->many.energy_budget =
        strcmp(cli_scenario_text(sc, "run", "energy_budget", "yes"), "yes") == 0;
    su->vtk_every_given = cli_scenario_find(sc, "dump", "vtk_every") != NULL;
    su->csv_every_given = cli_scenario_find(sc, "dump", "csv_every") != NULL;
    su->vtk_every = (unsigned long long)cli_scenario_number(sc, "dump", "vtk_every", 0);
    su->csv_every = (unsigned long long)cli_scenario_number(sc, "dump", "csv_every", 0);
    su->checkpoint_every =
        (unsigned long long)cli_scenario_number(sc, "dump", "checkpoint_every", 0);
    su->vtk_binary = strcmp(cli_scenario_text(sc, "dump", "vtk_binary", "yes"), "yes") == 0;
    su->vtk_links = strcmp(cli_scenario_text(sc, "dump", "vtk_links", "no"), "yes") == 0;
    int rc;
    if ((rc = cli_scenario_out_name(sc, "dump", "vtk", "particles", su->vtk_prefix)) !=
            CLI_EXIT_OK ||
        (rc = cli_scenario_out_name(sc, "dump", "csv", "global.csv", su->csv_name)) !=
            CLI_EXIT_OK ||
        (rc = cli_scenario_out_name(sc, "dump", "checkpoint", "checkpoint.ckpt",
                                    su->checkpoint_name)) != CLI_EXIT_OK ||
        (rc = cli_scenario_out_name(sc, "dump", "summary", "summary.json", su->summary_name)) !=
            CLI_EXIT_OK)
        return rc;
    size_t len = strlen(su->csv_name);
    if (len && (len < 5 || strcmp(su->csv_name + len - 4, ".csv") != 0)) {
        cli_scenario_error(sc, cli_scenario_find(sc, "dump", "csv"),
                           "the CSV name must end in "
                           ".csv");
        return CLI_EXIT_USAGE;
    }
    return dump_names_distinct(sc, su);
}

/* The entry of a key the library's start-up message names (reset_ratio or h_min of a
 * [model.NAME], [run] skin), when the scenario gives it; NULL otherwise. */
static const struct cli_entry* named_entry(const struct cli_scenario* sc, const char* msg)
{
    static const char* const keys[] = {"reset_ratio", "h_min", "skin"};
    for (int k = 0; k < 3; k++) {
        if (!strstr(msg, keys[k]))
            continue;
        for (size_t q = 0; q < sc->n_entries; q++) {
            const struct cli_entry* e = &sc->entries[q];
            bool section =
                k == 2 ? strcmp(e->section, "run") == 0 : strncmp(e->section, "model.", 6) == 0;
            if (section && strcmp(e->key, keys[k]) == 0)
                return e;
        }
    }
    return NULL;
}

int cli_many_report_start(const struct cli_scenario* sc, int status, const char* msg)
{
    if (status == WETDEM_ERR_NOMEM) { /* (no fault of the set-up: no key to point at) */
        cli_error("%s: %s", sc->file, msg);
        return CLI_EXIT_RUNTIME;
    }
    const struct cli_entry* e = named_entry(sc, msg);
    if (e) {
        cli_scenario_error(sc, e, "%s", msg);
        return CLI_EXIT_USAGE;
    }
    bool box = strstr(msg, "periodic") || strstr(msg, "box") || strstr(msg, "cell");
    cli_scenario_section_error(sc, box ? "box" : "run", "%s", msg);
    return CLI_EXIT_USAGE;
}

int cli_many_build(const struct cli_scenario* sc, struct cli_many_setup* su)
{
    memset(su, 0, sizeof *su);
    if (cli_scenario_has_section(sc, "collision")) {
        cli_scenario_section_error(sc, "collision",
                                   "a scenario is a binary collision "
                                   "([collision]) or a many-particle run ([box], [insert], "
                                   "[run], ...), not both");
        return CLI_EXIT_USAGE;
    }
    static const char* const reads[] = {
        "engine", "box",        "walls", "insert", "insert.*", "particle.*", "read.*", "run",
        "dump",   "material.*", "fluid", "models", "model.*",  "integrator", "sim",    NULL};
    if (cli_scenario_check_read(sc, "a many-particle run", reads) != CLI_EXIT_OK)
        return CLI_EXIT_USAGE;
    su->sim = wetdem_sim_create();
    if (!su->sim) {
        cli_error("out of memory creating a simulation");
        return CLI_EXIT_RUNTIME;
    }
    const char* first = NULL;
    unsigned faces = 0;
    int rc;
    if ((rc = cli_scenario_build_fluid(sc, su->sim)) != CLI_EXIT_OK ||
        (rc = cli_scenario_check_materials(sc)) != CLI_EXIT_OK ||
        (rc = build_models(sc, su->sim)) != CLI_EXIT_OK ||
        (rc = build_settings(sc, su->sim)) != CLI_EXIT_OK ||
        (rc = build_box(sc, su)) != CLI_EXIT_OK ||
        (rc = wall_faces(sc, su, &faces)) != CLI_EXIT_OK ||
        (rc = build_spheres(sc, su, faces, &first)) != CLI_EXIT_OK ||
        (rc = build_walls(sc, su, first)) != CLI_EXIT_OK ||
        (rc = build_run(sc, su)) != CLI_EXIT_OK) {
        cli_many_setup_free(su);
        return rc;
    }
    int st = wetdem_sim_set_many(su->sim, &su->many);
    if (st != WETDEM_OK) {
        rc = cli_many_report_start(sc, st, wetdem_sim_errmsg(su->sim));
        cli_many_setup_free(su);
        return rc;
    }
    double film = 0, roughness = INFINITY;
    for (int k = 0; k < wetdem_sim_n_materials(su->sim); k++) {
        film = fmax(film, wetdem_sim_material(su->sim, k)->film);
        roughness = fmin(roughness, wetdem_sim_material(su->sim, k)->roughness);
    }
    const char* used[MAX_MATERIALS];
    int n_used = wetdem_sim_n_materials(su->sim);
    for (int k = 0; k < n_used; k++)
        used[k] = su->material_names[k];
    cli_scenario_warn_unused_materials(sc, used, (size_t)n_used,
                                       "no material or materials key of [insert], [particle.*], "
                                       "[read.*] or [walls] names it; name it there, or leave "
                                       "it out");
    cli_scenario_warn_films(sc, su->sim, 2 * film,
                            "at most: twice the thickest film of the materials", roughness,
                            "at least: the least roughness of the materials");
    cli_scenario_warn_ignored(sc, su->sim, true);
    cli_scenario_warn_no_contact(sc, su->sim);
    return rc;
}

void cli_many_setup_free(struct cli_many_setup* su)
{
    wetdem_sim_free(su->sim);
    su->sim = NULL;
}

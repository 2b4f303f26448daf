/*
 * run_pairwise.c — `[engine] type = pairwise` scenarios: the sections the pairwise engine reads
 * (cli_pairwise_sections), building a struct wetdem_pairwise_config from them, running it
 * (wetdem_pairwise_run, Davis 2023) and reporting: a text or JSON summary, trajectory and
 * event CSVs in --out DIR, or one CSV row for `wetdem sweep` / `wetdem map`; with
 * `run --check`, the resolved configuration (text or JSON) without running. A run (not a
 * sweep's row) shows its progress on stderr when that is a terminal (cli_progress).
 *
 * Two ways to give the spheres:
 *   [davis]      Davis's Table I groups (St_n, Ca, h_a, h_m, beta, d_23, d_13, h_23,0,
 *                theta_23,0, e_dry, mu_f, t*_end) for two or three equal spheres, built by
 *                wetdem_pairwise_davis_config();
 *   [sphere.NAME] one section per sphere (in file order) with [pairwise] holding the fluid,
 *                h_min, e_dry, mu_f and t_end.
 * [pairwise] also holds the run settings (rtol, rest speed, stop rule, reference pair) and may
 * override the [davis] run length. Spheres are numbered from 1 in every output (Davis's
 * numbering: sphere 1 is the striker); the library counts from 0.
 */
#include <errno.h>
#include <float.h>
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli_util.h"
#include "output_csv.h"
#include "scenario.h"
#include "signals.h"

#define NUM CLI_KEY_NUMBER
#define COUNT CLI_KEY_COUNT

static const struct cli_key_desc davis_keys[] = {
    COUNT("n_spheres", "3", 2, 3,
          "2: striker and target only (oblique two-sphere collision); 3: Davis Fig. 3."),
    NUM("stokes", "-", "2", 0, 1e9, true, false,
        "Normal Stokes number St_n = m v_n0/(6 pi mu a^2)."),
    NUM("capillary", "-", "1000", 0, 1e12, false, false,
        "Capillary number Ca = 3 mu a v_n0/(sigma delta_12); 0 = no capillary force."),
    NUM("film_ratio", "-", "0.01", 0, 0.5, true, true, "h_a = delta_12/4a (film over diameter)."),
    NUM("hmin_ratio", "-", "0.01", 0, 1, true, true, "h_m = h_min/delta_12."),
    NUM("angle_deg", "deg", "30", 0, 90, false, true,
        "Impact angle beta between the striker's velocity and the 1-2 line of centres."),
    NUM("d23", "-", "1", 0, 1e6, true, false, "delta_23/delta_12."),
    NUM("d13", "-", "1", 0, 1e6, true, false, "delta_13/delta_12."),
    NUM("h23", "-", "1", 0, 1e6, true, false, "Initial 2-3 gap h_23,0/delta_12 (>= hmin_ratio)."),
    NUM("theta23_deg", "deg", "0", -180, 180, false, false,
        "Angle of the 2-3 line of centres from the x axis."),
    NUM("restitution", "-", "1", 0, 1, true, false, "Dry coefficient of restitution e_dry."),
    NUM("friction", "-", "0", 0, 10, false, false, "Friction coefficient mu_f of the impulse."),
    NUM("t_star_end", "-", "20", 0, 1e9, true, false, "Run length in t* = v_10 t/4a."),
    NUM("a", "m", "1e-3", 1e-6, 1, false, false,
        "Reduced radius a (sphere radius 2a); a unit only (the range keeps the dimensional run "
        "within CVODE's reach)."),
    NUM("viscosity", "Pa s", "1", 1e-6, 1e9, false, false, "Film viscosity mu; a unit only."),
    NUM("speed_n0", "m/s", "1", 1e-6, 1e3, false, false, "Normal impact speed v_n0; a unit only."),
    {0},
};

static const struct cli_key_desc pairwise_keys[] = {
    NUM("viscosity", "Pa s", "0", 0, 1e9, false, false, "Film viscosity mu ([sphere.*] runs)."),
    NUM("surface_tension", "N/m", "0", 0, 10, false, false,
        "Surface tension sigma: capillary suction 8 pi a_ij sigma ([sphere.*] runs)."),
    NUM("h_min", "m", "required with [sphere.*]", 0, 1, true, false,
        "Minimum separation: hard-sphere contact when a gap reaches it."),
    NUM("restitution", "-", "1", 0, 1, true, false, "Dry restitution e_dry ([sphere.*] runs)."),
    NUM("friction", "-", "0", 0, 10, false, false,
        "Friction mu_f of the impulse ([sphere.*] runs)."),
    NUM("gravity_x", "m/s^2", "0", -1e3, 1e3, false, false, "Gravity, x."),
    NUM("gravity_y", "m/s^2", "0", -1e3, 1e3, false, false, "Gravity, y."),
    NUM("t_end", "s", "from [davis] t_star_end, else required", 0, 1e9, true, false,
        "Longest simulated time."),
    NUM("rtol", "-", "1e-9", 1e-14, 1e-5, false, false,
        "Relative tolerance of CVODE (above 1e-5 its speeds are too coarse for the rest speed)."),
    NUM("rest_speed_ratio", "-", "1e-3", 0, 1, false, true,
        "Contacts slower than this times v_n0 are held at h_min (resting contact); without "
        "v_n0 > 0, times the largest initial sphere speed. When > 0, so is at least every "
        "contact whose kinetic energy is within 1e4 x the energy the reset of its gap to "
        "h_min adds against the suction (docs/derivations/pairwise.md); 0: no contact is "
        "held."),
    COUNT("stop_when_separated", "1", 0, 1,
          "1: stop once every pair is apart and receding; 0: run to t_end."),
    COUNT("ref_i", "1", 1, 8, "Reference pair (v_n0, delta_12, t-hat, t*): first."),
    COUNT("ref_j", "2", 1, 8, "Reference pair: second sphere."),
    COUNT("max_events", "100000", 1, 1e9, "Event budget of one run."),
    {0},
};

static const struct cli_key_desc sphere_keys[] = {
    NUM("radius", "m", "required", 0, 1, true, false, "Radius a_i."),
    NUM("mass", "kg", "required", 0, 1e6, true, false, "Mass m_i."),
    NUM("film", "m", "0", 0, 1, false, false, "Liquid film thickness delta_i."),
    NUM("x", "m", "0", -1e3, 1e3, false, false, "Centre, x."),
    NUM("y", "m", "0", -1e3, 1e3, false, false, "Centre, y."),
    NUM("vx", "m/s", "0", -1e3, 1e3, false, false, "Velocity, x."),
    NUM("vy", "m/s", "0", -1e3, 1e3, false, false, "Velocity, y."),
    NUM("omega", "rad/s", "0", -1e6, 1e6, false, false, "Spin about z (counter-clockwise)."),
    {0},
};

const struct cli_section_desc cli_pairwise_sections[] = {
    {"davis", "Pairwise engine: Davis (2023) Table I groups for two or three equal spheres.",
     davis_keys},
    {"pairwise", "Pairwise engine: fluid and contact for [sphere.*] runs, and run settings.",
     pairwise_keys},
    {"sphere.*", "Pairwise engine: one sphere NAME (file order gives the numbering 1, 2, ...).",
     sphere_keys},
    {0},
};

/* ----------------------------------------------------------------- building the config -- */

/* Reports a library message about `key` at its line in `section` (or at the section). */
static int report(const struct cli_scenario* sc, const char* section, const char* msg)
{
    for (size_t k = 0; k < sc->n_entries; k++) {
        const struct cli_entry* e = &sc->entries[k];
        size_t n = strlen(e->key);
        if (strcmp(e->section, section) == 0 && strncmp(msg, e->key, n) == 0 && msg[n] == ' ') {
            cli_scenario_error(sc, e, "%s", msg);
            return CLI_EXIT_USAGE;
        }
    }
    cli_scenario_section_error(sc, section, "%s", msg);
    return CLI_EXIT_USAGE;
}

/* With [davis] the spheres, their films, h_min and the contact come from its groups: a
 * [sphere.NAME] section, a [pairwise] key of [sphere.NAME] runs, and with n_spheres = 2 a key
 * that places sphere 3 would be ignored, so each is an error (all are reported). A key of
 * sphere 3 in the file is ignored when a --set makes n_spheres 2, as the file's [model.NAME]
 * sections are when a --set chooses the models. */
static int check_davis_keys(const struct cli_scenario* sc)
{
    static const char* const sphere_run_keys[][2] = {
        {"viscosity", "[davis] viscosity (a unit only; the film's effect is [davis] stokes)"},
        {"surface_tension", "[davis] capillary (Ca)"},
        {"h_min", "[davis] hmin_ratio"},
        {"restitution", "[davis] restitution"},
        {"friction", "[davis] friction"},
    };
    static const char* const third_sphere_keys[] = {"d23", "d13", "h23", "theta23_deg"};
    int rc = CLI_EXIT_OK;
    for (size_t s = 0; s < sc->n_sections; s++)
        if (strncmp(sc->sections[s].name, "sphere.", 7) == 0) {
            fprintf(stderr,
                    "%s:%d: [%s]: a scenario with [davis] takes its spheres from the [davis] "
                    "groups, so this section would be ignored: remove it, or remove [davis] "
                    "and give every sphere a [sphere.NAME] section\n",
                    sc->file, sc->sections[s].line, sc->sections[s].name);
            rc = CLI_EXIT_USAGE;
        }
    const struct cli_entry* n = cli_scenario_find(sc, "davis", "n_spheres");
    bool two = n && strtod(n->value, NULL) == 2;
    for (size_t m = 0; m < sc->n_entries; m++) { /* (in file order) */
        const struct cli_entry* e = &sc->entries[m];
        for (size_t k = 0; k < sizeof sphere_run_keys / sizeof sphere_run_keys[0]; k++)
            if (strcmp(e->section, "pairwise") == 0 && strcmp(e->key, sphere_run_keys[k][0]) == 0) {
                cli_scenario_error(sc, e,
                                   "[pairwise] %s is read only without [davis] (runs of "
                                   "[sphere.NAME] sections); with [davis] it would be ignored: "
                                   "set %s instead",
                                   e->key, sphere_run_keys[k][1]);
                rc = CLI_EXIT_USAGE;
            }
        for (size_t k = 0; two && k < sizeof third_sphere_keys / sizeof third_sphere_keys[0]; k++)
            if (strcmp(e->section, "davis") == 0 && strcmp(e->key, third_sphere_keys[k]) == 0 &&
                !(n->line == 0 && e->line > 0)) {
                cli_scenario_error(sc, e,
                                   "%s places sphere 3, which n_spheres = 2 leaves out, so it "
                                   "would be ignored: remove it, or set n_spheres = 3",
                                   e->key);
                rc = CLI_EXIT_USAGE;
            }
    }
    return rc;
}

static int from_davis(const struct cli_scenario* sc, struct wetdem_pairwise_config* cfg)
{
    if (check_davis_keys(sc) != CLI_EXIT_OK)
        return CLI_EXIT_USAGE;
    struct wetdem_pairwise_davis d;
    wetdem_pairwise_davis_init(&d);
    for (const struct wetdem_param_desc* p = wetdem_pairwise_davis_params(); p->name; p++) {
        double* field = (double*)((char*)&d + p->offset);
        *field = cli_scenario_number(sc, "davis", p->name, *field);
    }
    char msg[512];
    if (wetdem_pairwise_davis_config(&d, cfg, msg, sizeof msg) != WETDEM_OK)
        return report(sc, "davis", msg);
    return CLI_EXIT_OK;
}

/* The film forces of [sphere.*] spheres act while a pair's films overlap above its contact at
 * h_min: with no film on any two spheres, or h_min at or above the thickest pair's films
 * delta, they never act. Warned once a process (a sweep checks each point). */
static void warn_films(const struct cli_scenario* sc, const struct wetdem_pairwise_config* cfg)
{
    static atomic_flag warned = ATOMIC_FLAG_INIT;
    double first = 0, second = 0; /* the two thickest films */
    for (size_t k = 0; k < cfg->n_spheres; k++) {
        double f = cfg->spheres[k].film;
        second = f > first ? first : fmax(second, f);
        first = fmax(first, f);
    }
    double delta = first + second;
    if (delta > 0 && cfg->h_min < delta)
        return;
    if (atomic_flag_test_and_set(&warned))
        return;
    if (!(delta > 0))
        cli_error("warning: %s: no two [sphere.NAME] have a film (film = 0 m): the film forces "
                  "(viscous and capillary) never act and the spheres collide dry at h_min; give "
                  "the spheres a film > 0 [m]",
                  sc->file);
    else
        cli_scenario_warning(sc, cli_scenario_find(sc, "pairwise", "h_min"),
                             "h_min is at or above the film thickness delta = %g m of the "
                             "thickest pair of spheres: they touch before their films overlap, "
                             "so the film forces never act; set h_min below %g m or give the "
                             "spheres thicker films",
                             delta, delta);
}

static int from_spheres(const struct cli_scenario* sc, struct wetdem_pairwise_config* cfg)
{
    wetdem_pairwise_config_init(cfg);
    for (size_t s = 0; s < sc->n_sections; s++) {
        const char* name = sc->sections[s].name;
        if (strncmp(name, "sphere.", 7) != 0)
            continue;
        if (cfg->n_spheres == WETDEM_PAIRWISE_MAX_SPHERES) {
            cli_scenario_section_error(sc, name, "more than %d spheres",
                                       WETDEM_PAIRWISE_MAX_SPHERES);
            return CLI_EXIT_USAGE;
        }
        struct wetdem_pairwise_sphere* q = &cfg->spheres[cfg->n_spheres++];
        const char* keys[] = {"radius", "mass", "film", "x", "y", "vx", "vy", "omega"};
        double* fields[] = {&q->radius, &q->mass, &q->film, &q->x,
                            &q->y,      &q->vx,   &q->vy,   &q->omega};
        for (int k = 0; k < 8; k++) {
            if (k < 2 && !cli_scenario_find(sc, name, keys[k])) {
                cli_scenario_section_error(sc, name, "[%s] needs %s", name, keys[k]);
                return CLI_EXIT_USAGE;
            }
            *fields[k] = cli_scenario_number(sc, name, keys[k], 0.0);
        }
    }
    if (cfg->n_spheres < 2) {
        cli_scenario_section_error(sc, "pairwise",
                                   "the pairwise engine needs [davis] or at least two "
                                   "[sphere.NAME] sections");
        return CLI_EXIT_USAGE;
    }
    const char* req[] = {"h_min", "t_end"};
    for (int k = 0; k < 2; k++)
        if (!cli_scenario_find(sc, "pairwise", req[k])) {
            cli_scenario_section_error(sc, "pairwise", "[pairwise] needs %s with [sphere.*]",
                                       req[k]);
            return CLI_EXIT_USAGE;
        }
    cfg->viscosity = cli_scenario_number(sc, "pairwise", "viscosity", 0.0);
    cfg->surface_tension = cli_scenario_number(sc, "pairwise", "surface_tension", 0.0);
    cfg->h_min = cli_scenario_number(sc, "pairwise", "h_min", 0.0);
    cfg->restitution = cli_scenario_number(sc, "pairwise", "restitution", 1.0);
    cfg->friction = cli_scenario_number(sc, "pairwise", "friction", 0.0);
    warn_films(sc, cfg);
    return CLI_EXIT_OK;
}

/* Run settings of [pairwise] on top of either way of giving the spheres. */
static void run_settings(const struct cli_scenario* sc, struct wetdem_pairwise_config* cfg)
{
    cfg->gravity_x = cli_scenario_number(sc, "pairwise", "gravity_x", cfg->gravity_x);
    cfg->gravity_y = cli_scenario_number(sc, "pairwise", "gravity_y", cfg->gravity_y);
    cfg->t_end = cli_scenario_number(sc, "pairwise", "t_end", cfg->t_end);
    cfg->rtol = cli_scenario_number(sc, "pairwise", "rtol", cfg->rtol);
    cfg->rest_speed_ratio =
        cli_scenario_number(sc, "pairwise", "rest_speed_ratio", cfg->rest_speed_ratio);
    cfg->stop_when_separated =
        cli_scenario_number(sc, "pairwise", "stop_when_separated", 1.0) != 0.0;
    cfg->ref_i = (size_t)cli_scenario_number(sc, "pairwise", "ref_i", 1.0) - 1;
    cfg->ref_j = (size_t)cli_scenario_number(sc, "pairwise", "ref_j", 2.0) - 1;
    cfg->max_events = (size_t)cli_scenario_number(sc, "pairwise", "max_events", 100000.0);
}

/* A library message about the initial gap of spheres I and J (counted from 1, file order of the
 * [sphere.*] sections) is reported at the section of sphere J and names both sections. */
static int report_gap(const struct cli_scenario* sc, const char* msg)
{
    size_t want[2], k = 0;
    const char* names[2] = {NULL, NULL};
    if (sscanf(msg, "initial gap of spheres %zu and %zu", &want[0], &want[1]) != 2)
        return report(sc, "pairwise", msg);
    for (size_t s = 0; s < sc->n_sections; s++)
        if (strncmp(sc->sections[s].name, "sphere.", 7) == 0) {
            k++;
            for (int w = 0; w < 2; w++)
                if (k == want[w])
                    names[w] = sc->sections[s].name;
        }
    if (!names[0] || !names[1])
        return report(sc, "pairwise", msg);
    cli_scenario_section_error(sc, names[1], "%s: sphere %zu is [%s], sphere %zu [%s]", msg,
                               want[0], names[0], want[1], names[1]);
    return CLI_EXIT_USAGE;
}

/* Densities m / (4/3 pi a^3) a [sphere.NAME] may have [kg/m^3]: every solid sphere of matter
 * lies inside, from aerogels (0.16) to osmium (22 590), with a margin of about 10 below and 4
 * above. Outside, the scales of the run part beyond what double precision resolves long before
 * anything physical is reached: a radius of 1e-150 m under a mass of 1e-4 kg (a spin equation
 * with 1/I ~ 1e300), or a mass of 1e-300 kg pulled by a capillary force of 0.1 N (1e299 m/s^2
 * when the films meet) failed at or soon after t = 0 with WETDEM_ERR_STEP. Davis's
 * dimensionless runs, whose masses follow from St_n and carry no density, are [davis]'s. */
#define SPHERE_DENSITY_MIN 1e-2
#define SPHERE_DENSITY_MAX 1e5

/* Checks of [sphere.NAME] runs beyond the library's (which also serves [davis] and programs):
 * a density of matter (above), and a speed that moves its sphere by more than the rounding of
 * its position within t_end (a slower one cannot be told from rest, and CVODE's weights on the
 * speeds, 1 / (rtol v), overflow below ~1e-146 m/s: it failed at t = 0). The message is at the
 * sphere's section. Exit code. */
static int check_spheres(const struct cli_scenario* sc, const struct wetdem_pairwise_config* cfg)
{
    size_t i = 0;
    for (size_t s = 0; s < sc->n_sections && i < cfg->n_spheres; s++) {
        const char* name = sc->sections[s].name;
        if (strncmp(name, "sphere.", 7) != 0)
            continue;
        const struct wetdem_pairwise_sphere* q = &cfg->spheres[i++];
        double rho = q->mass / (4.0 / 3.0 * M_PI * q->radius * q->radius * q->radius);
        if (!(rho >= SPHERE_DENSITY_MIN && rho <= SPHERE_DENSITY_MAX)) {
            cli_scenario_section_error(
                sc, name,
                "mass = %g kg and radius = %g m give a density m / (4/3 pi a^3) = %g "
                "kg/m^3: valid [%g, %g] (solids span 0.16 to 22 590 kg/m^3; beyond, the run's "
                "time scales are not resolved in double precision); for dimensionless limits "
                "use [davis]",
                q->mass, q->radius, rho, SPHERE_DENSITY_MIN, SPHERE_DENSITY_MAX);
            return CLI_EXIT_USAGE;
        }
        double v = hypot(q->vx, q->vy);
        double rounding = DBL_EPSILON * (fabs(q->x) + fabs(q->y) + q->radius);
        if (v > 0 && !(v * cfg->t_end >= rounding)) {
            cli_scenario_section_error(
                sc, name,
                "speed |(vx, vy)| = %g m/s moves the sphere %g m in t_end = %g s, less than "
                "the rounding of its position (%g m): it cannot be told from rest; give 0, or at "
                "least %g m/s",
                v, v * cfg->t_end, cfg->t_end, rounding, rounding / cfg->t_end);
            return CLI_EXIT_USAGE;
        }
    }
    return CLI_EXIT_OK;
}

/* Builds and checks the configuration; exit code. */
static int build_config(const struct cli_scenario* sc, struct wetdem_pairwise_config* cfg)
{
    static const char* const reads[] = {"engine", "davis", "pairwise", "sphere.*", "output", NULL};
    int rc = cli_scenario_check_read(sc, "the pairwise engine", reads);
    if (rc == CLI_EXIT_OK)
        rc = cli_scenario_check_outputs(sc);
    if (rc != CLI_EXIT_OK)
        return rc;
    bool davis = cli_scenario_has_section(sc, "davis");
    rc = davis ? from_davis(sc, cfg) : from_spheres(sc, cfg);
    if (rc != CLI_EXIT_OK)
        return rc;
    run_settings(sc, cfg);
    char msg[512];
    if (wetdem_pairwise_config_validate(cfg, msg, sizeof msg) != WETDEM_OK) {
        if (!davis && strncmp(msg, "initial gap", 11) == 0)
            return report_gap(sc, msg);
        return report(sc, strncmp(msg, "spheres[", 8) == 0 && davis ? "davis" : "pairwise", msg);
    }
    return davis ? CLI_EXIT_OK : check_spheres(sc, cfg);
}

/* ----------------------------------------------------------------------- reporting ---- */

/* The pair's label: "none" (WETDEM_OUTCOME_NONE) for a pair that never interacted. */
static const char* mechanism_name(int m)
{
    return wetdem_outcome_name((enum wetdem_outcome)m);
}

static void sweep_header(FILE* f, const struct wetdem_pairwise_config* cfg)
{
    fputs("pairwise_status [word],outcome [word],separated_sphere [index],time [s],"
          "t_star_end [-],events [count],steps [count]",
          f);
    for (size_t i = 0; i < cfg->n_spheres; i++)
        for (size_t j = i + 1; j < cfg->n_spheres; j++)
            fprintf(f,
                    ",e_w_%zu%zu [-],e_own_%zu%zu [-],contacts_%zu%zu [count],"
                    "mechanism_%zu%zu [word],t_sep_star_%zu%zu [-]",
                    i + 1, j + 1, i + 1, j + 1, i + 1, j + 1, i + 1, j + 1, i + 1, j + 1);
}

/* One sweep row. A failed run writes its status, the steps and events it took, and "nan" or
 * "none" for every result (the row keeps the header's columns). */
static void sweep_row(FILE* f, int status, const struct wetdem_pairwise_config* cfg,
                      const struct wetdem_pairwise* pw, const struct wetdem_pairwise_result* r)
{
    size_t n_events = 0;
    wetdem_pairwise_events(pw, &n_events);
    if (status != WETDEM_OK) {
        fprintf(f, "%s,none,nan,nan,nan,%zu,%llu", wetdem_status_name(status), n_events, r->steps);
        for (size_t i = 0; i < cfg->n_spheres; i++)
            for (size_t j = i + 1; j < cfg->n_spheres; j++)
                fputs(",nan,nan,0,none,nan", f);
        return;
    }
    /* separated_sphere: 1-based, -1 for none, as in the JSON summary */
    fprintf(f, "%s,%s,%d,%.12g,%.12g,%zu,%llu", wetdem_status_name(status),
            wetdem_pairwise_outcome_name(r->outcome),
            r->separated_sphere >= 0 ? r->separated_sphere + 1 : -1, cli_plain_zero(r->time),
            cli_plain_zero(wetdem_pairwise_t_star(r, r->time)), r->n_events, r->steps);
    for (size_t p = 0; p < r->n_pairs; p++) {
        const struct wetdem_pairwise_pair_result* q = &r->pairs[p];
        fprintf(f, ",%.12g,%.12g,%u,%s,%.12g", cli_plain_zero(q->e_wet),
                cli_plain_zero(q->e_wet_own), q->n_contacts, mechanism_name(q->mechanism),
                cli_plain_zero(wetdem_pairwise_t_star(r, q->t_end)));
    }
}

/* %g of v, or "n/a" for a coefficient that is undefined (NaN) */
static void format_or_na(double v, char* buf, size_t n)
{
    if (isfinite(v))
        snprintf(buf, n, "%.6g", cli_plain_zero(v));
    else
        snprintf(buf, n, "n/a");
}

static void summary_text(FILE* f, const struct wetdem_pairwise_result* r)
{
    fprintf(f, "outcome            %s", wetdem_pairwise_outcome_name(r->outcome));
    if (r->separated_sphere >= 0)
        fprintf(f, " (sphere %d left)", r->separated_sphere + 1);
    char t_star[32], t_hat[32];
    format_or_na(wetdem_pairwise_t_star(r, r->time), t_star, sizeof t_star);
    format_or_na(wetdem_pairwise_t_hat(r, r->time), t_hat, sizeof t_hat);
    fprintf(f, "\ntime               %.6g s  (t* = %s, t-hat = %s)\n", cli_plain_zero(r->time),
            t_star, t_hat);
    fprintf(f, "v_n0               %.6g m/s  (delta_12 = %.6g m)%s\n", cli_plain_zero(r->v_n0),
            cli_plain_zero(r->delta_ref),
            r->v_n0 > 0.0 ? ""
                          : "; the reference pair does not approach at t = 0, so t-hat and e_w "
                            "have no scale (n/a)");
    fprintf(f, "events             %zu  (steps %llu, rhs %llu)\n", r->n_events, r->steps,
            r->rhs_evals);
    fprintf(f, "pair  e_w[-]     e_own[-]   contacts  mechanism\n");
    bool undefined = false;
    for (size_t p = 0; p < r->n_pairs; p++) {
        const struct wetdem_pairwise_pair_result* q = &r->pairs[p];
        char e_w[32], e_own[32];
        format_or_na(q->e_wet, e_w, sizeof e_w);
        format_or_na(q->e_wet_own, e_own, sizeof e_own);
        undefined = undefined || !isfinite(q->e_wet) || !isfinite(q->e_wet_own);
        fprintf(f, "%zu-%zu   %-10s %-10s %-9u %s\n", q->i + 1, q->j + 1, e_w, e_own, q->n_contacts,
                mechanism_name(q->mechanism));
    }
    if (undefined) /* (NaN in the CSV and null in the JSON) */
        fprintf(f, "n/a: the pair's films never met, or it did not approach when they did\n");
    const struct wetdem_pairwise_energy* e = &r->energy;
    if (!isfinite(e->residual))
        return; /* (not computed: energy_budget = false) */
    fprintf(f, "energy [J]         initial %.6g\n", cli_plain_zero(e->initial));
    fprintf(f, "  kinetic          %-13.6g at the end\n", cli_plain_zero(e->kinetic));
    fprintf(f, "  capillary        %-13.6g potential at the end\n", cli_plain_zero(e->capillary));
    fprintf(f, "  gravity          %-13.6g potential at the end, from the start\n",
            cli_plain_zero(e->gravity));
    fprintf(f, "  viscous normal   %-13.6g dissipated\n", cli_plain_zero(e->viscous_normal));
    fprintf(f, "  viscous tangent  %-13.6g dissipated\n", cli_plain_zero(e->viscous_tangential));
    fprintf(f, "  contact          %-13.6g lost in impulses\n", cli_plain_zero(e->contact));
    fprintf(f, "  residual         %-13.3g %.2g of the largest term (integration error)\n",
            cli_plain_zero(e->residual),
            cli_plain_zero(e->residual / wetdem_pairwise_energy_scale(e)));
}

static void json_number(FILE* f, double v)
{
    if (isfinite(v))
        fprintf(f, "%.12g", cli_plain_zero(v));
    else
        fputs("null", f);
}

static void summary_json(FILE* f, const struct cli_scenario* sc, const struct cli_run_options* opt,
                         const struct wetdem_pairwise_result* r)
{
    fprintf(f, "{\"engine\": \"pairwise\", \"version\": \"%s\", \"git\": \"%s\", \"scenario\": ",
            WETDEM_VERSION, WETDEM_GIT_HASH);
    cli_json_string(f, sc->file);
    fputs(", \"command\": ", f);
    cli_json_command(f, opt->argc, opt->argv);
    fprintf(f, ", \"outcome\": \"%s\", \"separated_sphere\": %d, \"time_s\": ",
            wetdem_pairwise_outcome_name(r->outcome),
            r->separated_sphere >= 0 ? r->separated_sphere + 1 : -1);
    json_number(f, r->time);
    fputs(", \"v_n0_m_s\": ", f);
    json_number(f, r->v_n0);
    fprintf(f, ", \"events\": %zu, \"steps\": %llu, \"pairs\": [", r->n_events, r->steps);
    for (size_t p = 0; p < r->n_pairs; p++) {
        const struct wetdem_pairwise_pair_result* q = &r->pairs[p];
        fprintf(f,
                "%s{\"i\": %zu, \"j\": %zu, \"films_met\": %s, \"bound\": %s, \"contacts\": %u, "
                "\"mechanism\": \"%s\", \"e_w\": ",
                p ? ", " : "", q->i + 1, q->j + 1, q->films_met ? "true" : "false",
                q->bound ? "true" : "false", q->n_contacts, mechanism_name(q->mechanism));
        json_number(f, q->e_wet);
        fputs(", \"e_own\": ", f);
        json_number(f, q->e_wet_own);
        fputs("}", f);
    }
    const struct wetdem_pairwise_energy* e = &r->energy;
    const struct {
        const char* key;
        double value;
    } energy[] = {{"initial", e->initial},
                  {"kinetic", e->kinetic},
                  {"capillary", e->capillary},
                  {"gravity", e->gravity},
                  {"viscous_normal", e->viscous_normal},
                  {"viscous_tangential", e->viscous_tangential},
                  {"contact", e->contact},
                  {"residual", e->residual}};
    fputs("], \"energy_J\": {", f);
    for (size_t k = 0; k < sizeof energy / sizeof energy[0]; k++) {
        fprintf(f, "%s\"%s\": ", k ? ", " : "", energy[k].key);
        json_number(f, energy[k].value);
    }
    fputs("}}\n", f);
}

/* `run --check`: the resolved configuration, without running. */
static void print_check(const struct cli_scenario* sc, const struct wetdem_pairwise_config* c,
                        bool json)
{
    if (json) {
        printf("{\"scenario\": ");
        cli_json_string(stdout, sc->file);
        printf(", \"engine\": \"pairwise\", \"viscosity\": %.17g, \"surface_tension\": %.17g, "
               "\"h_min\": %.17g, \"restitution\": %.17g, \"friction\": %.17g, "
               "\"t_end\": %.17g, \"rtol\": %.17g, \"spheres\": [",
               cli_plain_zero(c->viscosity), cli_plain_zero(c->surface_tension),
               cli_plain_zero(c->h_min), cli_plain_zero(c->restitution),
               cli_plain_zero(c->friction), cli_plain_zero(c->t_end), cli_plain_zero(c->rtol));
        for (size_t i = 0; i < c->n_spheres; i++) {
            const struct wetdem_pairwise_sphere* s = &c->spheres[i];
            printf("%s{\"radius\": %.17g, \"mass\": %.17g, \"film\": %.17g, \"x\": %.17g, "
                   "\"y\": %.17g, \"vx\": %.17g, \"vy\": %.17g, \"omega\": %.17g}",
                   i ? ", " : "", cli_plain_zero(s->radius), cli_plain_zero(s->mass),
                   cli_plain_zero(s->film), cli_plain_zero(s->x), cli_plain_zero(s->y),
                   cli_plain_zero(s->vx), cli_plain_zero(s->vy), cli_plain_zero(s->omega));
        }
        printf("]}\n");
        return;
    }
    printf("scenario %s is valid (pairwise engine)\n", sc->file);
    printf("  viscosity        %.10g Pa s\n  surface_tension  %.10g N/m\n  h_min            "
           "%.10g m\n  restitution      %.10g -\n  friction         %.10g -\n  t_end            "
           "%.10g s\n  rtol             %.10g -\n",
           cli_plain_zero(c->viscosity), cli_plain_zero(c->surface_tension),
           cli_plain_zero(c->h_min), cli_plain_zero(c->restitution), cli_plain_zero(c->friction),
           cli_plain_zero(c->t_end), cli_plain_zero(c->rtol));
    printf("  sphere  radius [m]    mass [kg]     film [m]      x [m]         y [m]         "
           "vx [m/s]      vy [m/s]      omega [rad/s]\n");
    for (size_t i = 0; i < c->n_spheres; i++) {
        const struct wetdem_pairwise_sphere* s = &c->spheres[i];
        printf("  %-6zu  %-12.6g  %-12.6g  %-12.6g  %-12.6g  %-12.6g  %-12.6g  %-12.6g  %.6g\n",
               i + 1, cli_plain_zero(s->radius), cli_plain_zero(s->mass), cli_plain_zero(s->film),
               cli_plain_zero(s->x), cli_plain_zero(s->y), cli_plain_zero(s->vx),
               cli_plain_zero(s->vy), cli_plain_zero(s->omega));
    }
}

/* Observer writing one trajectory row per frame. */
struct traj {
    FILE* f;
    int err; /* errno of the first write that failed (EIO if none was set), 0 */
};

static int write_frame(const struct wetdem_pairwise_frame* fr, void* ctx)
{
    struct traj* t = ctx;
    fprintf(t->f, "%.12g,%.12g,%.12g", cli_plain_zero(fr->time), cli_plain_zero(fr->t_hat),
            cli_plain_zero(fr->t_star));
    for (size_t i = 0; i < fr->n_spheres; i++) {
        const struct wetdem_pairwise_sphere* s = &fr->spheres[i];
        fprintf(t->f, ",%.12g,%.12g,%.12g,%.12g,%.12g", cli_plain_zero(s->x), cli_plain_zero(s->y),
                cli_plain_zero(s->vx), cli_plain_zero(s->vy), cli_plain_zero(s->omega));
    }
    for (size_t p = 0; p < fr->n_pairs; p++)
        fprintf(t->f, ",%.12g,%.12g", cli_plain_zero(fr->gap[p]), cli_plain_zero(fr->v_n[p]));
    const struct wetdem_pairwise_energy* e = &fr->energy;
    fprintf(t->f, ",%.12g,%.12g,%.12g,%.12g,%.12g,%.12g,%.12g", cli_plain_zero(e->kinetic),
            cli_plain_zero(e->capillary), cli_plain_zero(e->gravity),
            cli_plain_zero(e->viscous_normal), cli_plain_zero(e->viscous_tangential),
            cli_plain_zero(e->contact), cli_plain_zero(e->residual));
    fputc('\n', t->f);
    if (!ferror(t->f))
        return cli_stop_signal ? -1 : 0; /* (a signal asked the command to stop) */
    t->err = errno ? errno : EIO;
    return -1;
}

static void trajectory_header(FILE* f, size_t n)
{
    fputs("time [s],t_hat [-],t_star [-]", f);
    for (size_t i = 1; i <= n; i++)
        fprintf(f, ",x_%zu [m],y_%zu [m],vx_%zu [m/s],vy_%zu [m/s],omega_%zu [rad/s]", i, i, i, i,
                i);
    for (size_t i = 1; i <= n; i++)
        for (size_t j = i + 1; j <= n; j++)
            fprintf(f, ",h_%zu%zu [m],v_n_%zu%zu [m/s]", i, j, i, j);
    fputs(",kinetic [J],capillary [J],gravity [J],viscous_normal [J],viscous_tangential [J],"
          "contact [J],energy_residual [J]",
          f);
    fputc('\n', f);
}

static void events_csv(FILE* f, const struct wetdem_pairwise* pw)
{
    size_t n;
    const struct wetdem_pairwise_event* ev = wetdem_pairwise_events(pw, &n);
    fputs("time [s],t_hat [-],t_star [-],event [word],i [index],j [index],k [index],l [index],"
          "gap [m],v_n [m/s]\n",
          f);
    for (size_t e = 0; e < n; e++)
        fprintf(f, "%.12g,%.12g,%.12g,%s,%zu,%zu,%zu,%zu,%.12g,%.12g\n", cli_plain_zero(ev[e].time),
                cli_plain_zero(ev[e].t_hat), cli_plain_zero(ev[e].t_star),
                wetdem_pairwise_event_name(ev[e].kind), ev[e].i + 1, ev[e].j + 1, ev[e].k + 1,
                ev[e].l + 1, cli_plain_zero(ev[e].gap), cli_plain_zero(ev[e].v_n));
}

/* The run with files in opt->out_dir: the trajectory written during the run, events and
 * summary after it, each under a temporary name renamed only when the run succeeded and the
 * file was written whole (a failed or interrupted run leaves nothing under the final names).
 * *ran: whether the run took place (not when the trajectory is refused or no directory). */
/* wetdem_pairwise_run, with the progress line on a terminal when `show` (not for a sweep's
 * rows), cleared when it returns. */
static int run_shown(struct wetdem_pairwise* pw, const struct wetdem_pairwise_config* cfg,
                     struct wetdem_pairwise_result* r, bool show)
{
    struct cli_progress line;
    cli_progress_start(&line, 0);
    wetdem_pairwise_set_progress(pw, show && line.tty ? cli_progress_time : NULL, &line);
    int st = wetdem_pairwise_run(pw, cfg, r);
    wetdem_pairwise_set_progress(pw, NULL, NULL); /* (line ends with this call) */
    cli_progress_clear(&line);
    return st;
}

static int run_with_files(const struct cli_scenario* sc, const struct cli_run_options* opt,
                          const struct wetdem_pairwise_config* cfg, struct wetdem_pairwise* pw,
                          struct wetdem_pairwise_result* r, int* status, bool* ran)
{
    struct cli_out_file ft, fe, fs;
    double dt = cli_scenario_number(sc, "output", "trajectory_interval", 0.0);
    dt = dt > 0.0 ? dt : cfg->t_end / 2000.0;
    char traj_name[CLI_VALUE_MAX], events_name[CLI_VALUE_MAX], summary_name[CLI_VALUE_MAX];
    /* (checked by build_config: cli_scenario_check_outputs) */
    cli_scenario_out_name(sc, "output", "trajectory", "trajectory.csv", traj_name);
    cli_scenario_out_name(sc, "output", "events", "events.csv", events_name);
    cli_scenario_out_name(sc, "output", "summary", "summary.json", summary_name);
    int rc = traj_name[0] ? cli_scenario_check_trajectory(
                                sc, cli_scenario_has_section(sc, "davis") ? "davis" : "pairwise",
                                cfg->t_end, dt)
                          : CLI_EXIT_OK;
    if (rc != CLI_EXIT_OK)
        return rc; /* before the directory is made */
    const char* names[3] = {traj_name, events_name, summary_name};
    if ((rc = cli_check_out_dir("run", opt->out_dir, names, 3)) != CLI_EXIT_OK)
        return rc; /* (before the run: an unwritable place is bad input) */
    if (cli_out_open(&ft, "run", opt->out_dir, traj_name) != 0)
        return CLI_EXIT_RUNTIME;
    struct traj t = {ft.f, 0};
    struct cli_saved_signals saved;
    bool guarded = ft.f != NULL; /* (a signal stops the run: cli_signals_install_run) */
    if (guarded) {
        cli_print_provenance(ft.f, opt->argc, opt->argv);
        trajectory_header(ft.f, cfg->n_spheres);
        wetdem_pairwise_set_observer(pw, dt, write_frame, &t);
        cli_signals_install_run(ft.tmp, &saved);
    }
    errno = 0;
    *status = run_shown(pw, cfg, r, !opt->sweep_row);
    *ran = true;
    if ((guarded && cli_stop_signal) || *status != WETDEM_OK) {
        cli_out_close(&ft, "run", false);
        int stopped = guarded ? cli_signals_finish_run("run", &saved) : 0;
        if (stopped) {
            if (*status == WETDEM_OK)
                *status = WETDEM_ERR_CALLBACK; /* (the caller reports nothing more) */
            return stopped;
        }
        if (!t.err)
            return CLI_EXIT_OK; /* (the caller reports the status) */
        /* the observer stopped the run: the write is what failed, not the simulation */
        cli_error("run: cannot write %s: %s", ft.final, strerror(t.err));
        return CLI_EXIT_RUNTIME;
    }
    struct cli_out_file* files[3] = {&ft, &fe, &fs};
    if (cli_out_open(&fe, "run", opt->out_dir, events_name) != 0 ||
        cli_out_open(&fs, "run", opt->out_dir, summary_name) != 0) {
        cli_out_close_all(files, 2, "run", false);
        int stopped = guarded ? cli_signals_finish_run("run", &saved) : 0;
        return stopped ? stopped : CLI_EXIT_RUNTIME;
    }
    if (fe.f) {
        cli_print_provenance(fe.f, opt->argc, opt->argv);
        events_csv(fe.f, pw);
    }
    if (fs.f)
        summary_json(fs.f, sc, opt, r);
    /* the three files as a set: all kept whole, or none (a signal until now keeps none) */
    sigset_t mask;
    cli_signals_block(&mask);
    int stopped = guarded ? cli_signals_finish_run("run", &saved) : 0;
    rc = cli_out_close_all(files, 3, "run", !stopped) == 0 ? CLI_EXIT_OK : CLI_EXIT_RUNTIME;
    cli_signals_unblock(&mask);
    if (stopped && *status == WETDEM_OK)
        *status = WETDEM_ERR_CALLBACK; /* (the caller reports nothing more) */
    return stopped ? stopped : rc;
}

int cli_run_pairwise(const struct cli_scenario* sc, const struct cli_run_options* opt)
{
    struct wetdem_pairwise_config cfg;
    int rc = build_config(sc, &cfg);
    if (rc != CLI_EXIT_OK)
        return rc;
    if (opt->sweep_row && opt->sweep_header) {
        sweep_header(opt->sweep_row, &cfg);
        return CLI_EXIT_OK;
    }
    if (opt->check) {
        print_check(sc, &cfg, opt->json);
        return CLI_EXIT_OK;
    }
    struct wetdem_pairwise* pw = wetdem_pairwise_create();
    struct wetdem_pairwise_result r;
    if (!pw) {
        cli_error("run: out of memory");
        return CLI_EXIT_RUNTIME;
    }
    int status = WETDEM_OK;
    cfg.energy_budget = !opt->sweep_row; /* (a sweep's rows carry no energies) */
    if (opt->out_dir) {
        bool ran = false;
        rc = run_with_files(sc, opt, &cfg, pw, &r, &status, &ran);
        /* refused, no directory, or a failed run whose failure was reported (its trajectory
           could not be written): no result to report */
        if (!ran || (rc != CLI_EXIT_OK && status != WETDEM_OK)) {
            wetdem_pairwise_free(pw);
            return rc;
        }
    } else {
        status = run_shown(pw, &cfg, &r, !opt->sweep_row);
    }
    if (opt->status_out)
        *opt->status_out = status;
    if (opt->errmsg_out && opt->errmsg_size > 0)
        snprintf(opt->errmsg_out, opt->errmsg_size, "%s",
                 status != WETDEM_OK ? wetdem_pairwise_errmsg(pw) : "");
    if (opt->sweep_row) {
        sweep_row(opt->sweep_row, status, &cfg, pw, &r);
    } else if (status != WETDEM_OK) {
        cli_error("run %s: %s (%s)", sc->file, wetdem_pairwise_errmsg(pw),
                  wetdem_status_name(status));
        rc = CLI_EXIT_RUNTIME;
    } else if (opt->json) {
        summary_json(stdout, sc, opt, &r);
    } else {
        summary_text(stdout, &r);
    }
    wetdem_pairwise_free(pw);
    return rc;
}

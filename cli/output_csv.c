/*
 * output_csv.c — CSV and JSON writers for `wetdem run` and `wetdem sweep` (see output_csv.h):
 * collision summary, trajectory rows from the observer, event log.
 *
 * Trajectory gap: for two spheres h = |x_i - x_j| - R_i - R_j from the positions; for a wall
 * the library's contact geometry (wetdem_sim_pair_force) gives it. Forces are not written:
 * the models' forces depend on per-pair history (tangential spring, largest approach speed
 * for h_eps) that an observer cannot see, so a recomputed force would be wrong.
 */
#include <errno.h>
#include <math.h>
#include <string.h>

#include "cli_util.h"
#include "output_csv.h"
#include "signals.h"

#define RAD2DEG (180.0 / 3.14159265358979323846)

static struct cli_field num(const char* name, const char* unit, const char* doc, double v)
{
    return (struct cli_field){.name = name,
                              .unit = unit,
                              .doc = doc,
                              .kind = CLI_FIELD_NUMBER,
                              .number = cli_plain_zero(v)};
}

static struct cli_field flag(const char* name, const char* doc, bool v)
{
    return (struct cli_field){
        .name = name, .unit = "", .doc = doc, .kind = CLI_FIELD_BOOL, .flag = v};
}

static struct cli_field count(const char* name, const char* doc, unsigned long long v)
{
    return (struct cli_field){
        .name = name, .unit = "", .doc = doc, .kind = CLI_FIELD_COUNT, .count = v};
}

size_t cli_result_fields(const struct cli_setup* su, const struct wetdem_collision_result* r,
                         struct cli_field* out)
{
    size_t n = 0;
    out[n++] = num("impact_speed", "m/s", "speed U of the striker at t = 0", su->impact_speed);
    out[n++] = num("stokes_n", "-", "normal Stokes number m* v_n0 / (6 pi mu R*^2)", r->stokes_n);
    out[n++] =
        num("speed_n0", "m/s",
            "normal impact speed v_n0 = U cos(angle) of the straight-line approach", r->speed_n0);
    out[n++] = num("e", "-", "Nijssen restitution |dv_f|/|dv_0|", r->e);
    out[n++] = num("e_n", "-",
                   "normal restitution dv_f.n_f / v_n0: separation over impact speed (Punch "
                   "Eq. 3)",
                   r->e_n);
    out[n++] = num("e_t", "-",
                   "tangential restitution of the contact point (-1 smooth, +1 reversed; nan "
                   "without initial slip)",
                   r->e_t);
    out[n++] = num("e_n_observed", "-", "e_n at observe_time after the first interaction",
                   r->e_n_observed);
    out[n++] = num("e_n_contact", "-",
                   "e_n referred to the line of centres at the closest approach (the middle of "
                   "the last contact; nan without one)",
                   r->e_n_contact);
    out[n++] = num("energy_ratio", "-",
                   "energy of the relative motion and spins plus that the conservative forces "
                   "store at the gap (elastic overlap, capillary well), at the end over that at "
                   "t = 0 (at most 1, < 0 bound in a capillary well; nan with gravity)",
                   r->energy_ratio);
    out[n++] = num("angle_in", "deg",
                   "impact angle to the line of centres at contact of the straight-line approach",
                   r->angle_in * RAD2DEG);
    out[n++] = num("angle_out", "deg", "rebound angle of the relative velocity to the normal",
                   r->angle_out * RAD2DEG);
    out[n++] = num("striker_angle_out", "deg",
                   "rebound angle of the striker's own velocity to the line of centres",
                   su->striker_angle_out * RAD2DEG);
    out[n++] = num("striker_speed_out", "m/s", "final speed of the striker", su->striker_speed_out);
    out[n++] = num("omega_i_x", "rad/s", "final spin of the striker, x", r->omega_i.x);
    out[n++] = num("omega_i_y", "rad/s", "final spin of the striker, y", r->omega_i.y);
    out[n++] = num("omega_i_z", "rad/s", "final spin of the striker, z", r->omega_i.z);
    out[n++] = num("omega_j_x", "rad/s", "final spin of the target, x", r->omega_j.x);
    out[n++] = num("omega_j_y", "rad/s", "final spin of the target, y", r->omega_j.y);
    out[n++] = num("omega_j_z", "rad/s", "final spin of the target, z", r->omega_j.z);
    out[n++] = num("contact_duration", "s", "total time with gap < 0", r->contact_duration);
    out[n++] = num("interaction_duration", "s",
                   "first interaction start to last interaction end (to t_end if not separated)",
                   r->interaction_duration);
    out[n++] = num("min_gap", "m", "smallest gap reached", r->min_gap);
    out[n++] = flag("solid_contact", "the gap reached 0", r->solid_contact);
    out[n++] = flag("hmin_reached", "the gap reached h_min (or 0)", r->hmin_reached);
    out[n++] = flag("separated", "receding beyond the separation gap by t_end", r->separated);
    out[n++] = num("rotation_angle", "deg", "turn of the line of centres during interaction",
                   r->rotation_angle * RAD2DEG);
    out[n++] = num("rotation_close", "deg",
                   "part of rotation_angle turned below close_gap after the approach was "
                   "arrested",
                   r->rotation_close * RAD2DEG);
    out[n++] = num("rotation_doublet", "deg",
                   "part of rotation_close the relative velocity turned with (> 5 deg and "
                   "separated: stick-rotate-separate)",
                   r->rotation_doublet * RAD2DEG);
    out[n++] = num("close_gap", "m", "doublet gap of the outcome rule", r->close_gap);
    out[n] = (struct cli_field){
        .name = "outcome",
        .unit = "",
        .kind = CLI_FIELD_TEXT,
        .doc = "stick, stick-rotate-separate, bounce or none (never reached the target)",
        .text = wetdem_outcome_name(r->outcome)};
    n++;
    out[n++] = count("steps", "accepted integrator steps", r->stats.steps);
    out[n++] = count("rejected_steps", "rejected step attempts", r->stats.rejected_steps);
    out[n++] = count("force_evals", "evaluations of all forces (RHS)", r->stats.force_evals);
    out[n++] = count("pair_evals", "evaluations of one pair's models", r->stats.pair_evals);
    out[n++] = count("root_evals", "evaluations of the event functions", r->stats.root_evals);
    out[n++] = count("events", "events located", r->stats.events);
    out[n++] = num("hmin_step_ratio", "-",
                   "verlet: largest gap change of a step that crossed h_min (or another branch "
                   "gap of the force laws), over that gap; above 0.1 h_min is not resolved "
                   "(0 with cvode)",
                   r->stats.hmin_step_ratio);
    return n;
}

bool cli_energy_grew(double energy_ratio, char* msg, size_t n)
{
    if (!(isfinite(energy_ratio) && energy_ratio > 1.01))
        return false;
    snprintf(msg, n,
             "ends with %.4g times the energy it began with, which the models cannot "
             "give: the integration is too coarse for the contact; with [integrator] name = "
             "verlet halve dt_fraction (or dt), or use name = cvode; with cvode lower rtol and "
             "atol",
             energy_ratio);
    return true;
}

bool cli_overlap_large(const struct wetdem_collision_result* r, double r_eff, char* msg, size_t n)
{
    double ratio = -r->min_gap / r_eff;
    if (!(ratio > CLI_OVERLAP_RATIO_MAX))
        return false;
    snprintf(msg, n,
             "the spheres overlapped by %.3g m, %.3g R*: the contact laws hold for overlaps "
             "small against R* (Hertz's below about %g R*), so this result extrapolates them; "
             "the impact is too fast or the solid too soft for them",
             -r->min_gap, ratio, CLI_OVERLAP_RATIO_MAX);
    return true;
}

bool cli_hmin_unresolved(const struct wetdem_collision_result* r, char* msg, size_t n)
{
    double ratio = r->stats.hmin_step_ratio;
    if (!(ratio > WETDEM_HMIN_STEP_RATIO_MAX))
        return false;
    int used = snprintf(msg, n,
                        "the verlet step moved the gap by %.3g h_min in a step that crossed "
                        "h_min (it is resolved at %g or less), so the result changes in jumps, "
                        "not smoothly, with h_min",
                        ratio, WETDEM_HMIN_STEP_RATIO_MAX);
    double bound = ratio / r->stokes_n;
    if (used > 0 && (size_t)used < n && isfinite(bound))
        used += snprintf(msg + used, n - (size_t)used,
                         "; where a law switches there (below_hmin = c) e_n can be off by up "
                         "to about %.2g (hmin_step_ratio / St_n), where it peaks there (nijssen "
                         "in a viscous liquid) by more",
                         bound);
    if (used > 0 && (size_t)used < n)
        snprintf(msg + used, n - (size_t)used,
                 "; set [integrator] hmin_fraction = 0.1 (or a lower dt_fraction), or use "
                 "name = cvode (docs/engines.md, \"Steps and h_min\")");
    return true;
}

void cli_setup_capture(struct cli_setup* su, const struct wetdem_collision_result* r)
{
    size_t n = 0;
    const struct wetdem_particle* p = wetdem_sim_particles_const(su->sim, &n);
    su->striker_speed_out = NAN;
    su->striker_angle_out = NAN;
    if (n < 1)
        return;
    const struct wetdem_vec3 v = p[0].vel, nf = r->normal_out;
    double vn = v.x * nf.x + v.y * nf.y + v.z * nf.z;
    double tx = v.x - vn * nf.x, ty = v.y - vn * nf.y, tz = v.z - vn * nf.z;
    su->striker_speed_out = sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
    su->striker_angle_out = atan2(sqrt(tx * tx + ty * ty + tz * tz), fabs(vn));
}

void cli_csv_result_header(FILE* f)
{
    struct cli_setup su = {0};
    struct wetdem_collision_result r = {0};
    struct cli_field fields[CLI_MAX_FIELDS];
    size_t n = cli_result_fields(&su, &r, fields);
    for (size_t k = 0; k < n; k++) {
        const char* unit = fields[k].kind == CLI_FIELD_BOOL    ? "0/1"
                           : fields[k].kind == CLI_FIELD_TEXT  ? "word"
                           : fields[k].kind == CLI_FIELD_COUNT ? "count"
                                                               : fields[k].unit;
        fprintf(f, "%s%s [%s]", k ? "," : "", fields[k].name, unit);
    }
}

static void csv_value(FILE* f, const struct cli_field* x)
{
    switch (x->kind) {
    case CLI_FIELD_NUMBER: fprintf(f, "%.12g", x->number); break;
    case CLI_FIELD_BOOL: fputc(x->flag ? '1' : '0', f); break;
    case CLI_FIELD_TEXT: fputs(x->text, f); break;
    case CLI_FIELD_COUNT: fprintf(f, "%llu", x->count); break;
    }
}

void cli_csv_result_row(FILE* f, const struct cli_setup* su,
                        const struct wetdem_collision_result* r)
{
    struct cli_field fields[CLI_MAX_FIELDS];
    size_t n = cli_result_fields(su, r, fields);
    for (size_t k = 0; k < n; k++) {
        if (k)
            fputc(',', f);
        csv_value(f, &fields[k]);
    }
}

void cli_csv_failed_row(FILE* f, const struct cli_setup* su)
{
    struct wetdem_collision_result r = {0};
    struct cli_field fields[CLI_MAX_FIELDS];
    size_t n = cli_result_fields(su, &r, fields);
    for (size_t k = 0; k < n; k++) {
        if (k)
            fputc(',', f);
        if (strcmp(fields[k].name, "impact_speed") == 0) /* (the set-up's, not a result) */
            csv_value(f, &fields[k]);
        else
            fputs(fields[k].kind == CLI_FIELD_TEXT ? "none" : "nan", f);
    }
}

void cli_summary_text(FILE* f, const struct cli_scenario* sc, const struct cli_setup* su,
                      const struct wetdem_collision_result* r)
{
    fprintf(f, "scenario %s: %s integrator, St_n = %.6g, impact speed %.6g m/s\n", sc->file,
            wetdem_sim_integrator_name(su->sim), cli_plain_zero(su->stokes_n),
            cli_plain_zero(su->impact_speed));
    struct cli_field fields[CLI_MAX_FIELDS];
    size_t n = cli_result_fields(su, r, fields);
    for (size_t k = 0; k < n; k++) {
        fprintf(f, "  %-22s ", fields[k].name);
        if (fields[k].kind == CLI_FIELD_NUMBER)
            fprintf(f, "%-14.8g", fields[k].number);
        else if (fields[k].kind == CLI_FIELD_BOOL)
            fprintf(f, "%-14s", fields[k].flag ? "yes" : "no");
        else if (fields[k].kind == CLI_FIELD_TEXT)
            fprintf(f, "%-14s", fields[k].text);
        else
            fprintf(f, "%-14llu", fields[k].count);
        fprintf(f, " %-6s %s\n", fields[k].unit, fields[k].doc);
    }
}

void cli_json_number(FILE* f, double v)
{
    if (isfinite(v))
        fprintf(f, "%.17g", cli_plain_zero(v));
    else
        fputs("null", f);
}

void cli_json_string(FILE* f, const char* s)
{
    fputc('"', f);
    for (const char* p = s; *p; p++) {
        if (*p == '"' || *p == '\\')
            fputc('\\', f);
        if ((unsigned char)*p < 0x20)
            fprintf(f, "\\u%04x", (unsigned)(unsigned char)*p);
        else
            fputc(*p, f);
    }
    fputc('"', f);
}

void cli_json_command(FILE* f, int argc, char** argv)
{
    fputs("[\"wetdem\"", f);
    for (int k = 0; k < argc; k++) {
        fputs(", ", f);
        cli_json_string(f, argv[k]);
    }
    fputc(']', f);
}

static void json_fields(FILE* f, const struct cli_field* fields, size_t n, bool units)
{
    for (size_t k = 0; k < n; k++) {
        fprintf(f, "%s\n    \"%s\": ", k ? "," : "", fields[k].name);
        if (units)
            cli_json_string(f, fields[k].unit);
        else if (fields[k].kind == CLI_FIELD_NUMBER)
            cli_json_number(f, fields[k].number);
        else if (fields[k].kind == CLI_FIELD_BOOL)
            fputs(fields[k].flag ? "true" : "false", f);
        else if (fields[k].kind == CLI_FIELD_TEXT)
            cli_json_string(f, fields[k].text);
        else
            fprintf(f, "%llu", fields[k].count);
    }
}

void cli_summary_json(FILE* f, const struct cli_scenario* sc, const struct cli_setup* su,
                      const struct wetdem_collision_result* r, int argc, char** argv)
{
    fprintf(f, "{\n  \"wetdem\": \"%s\",\n  \"git\": \"%s\",\n  \"scenario\": ", WETDEM_VERSION,
            WETDEM_GIT_HASH);
    cli_json_string(f, sc->file);
    fputs(",\n  \"command\": ", f);
    cli_json_command(f, argc, argv);
    fputs(",\n  \"integrator\": ", f);
    cli_json_string(f, wetdem_sim_integrator_name(su->sim));
    fputs(",\n  \"setup\": {\n    \"m_eff\": ", f);
    cli_json_number(f, su->m_eff);
    fputs(",\n    \"r_eff\": ", f);
    cli_json_number(f, su->r_eff);
    fputs(",\n    \"t_end\": ", f);
    cli_json_number(f, su->spec.t_end);
    fputs(",\n    \"angle\": ", f);
    cli_json_number(f, su->spec.angle * RAD2DEG);
    fputs("\n  },\n  \"setup_units\": {\"m_eff\": \"kg\", \"r_eff\": \"m\", \"t_end\": \"s\", "
          "\"angle\": \"deg\"},\n  \"result\": {",
          f);
    struct cli_field fields[CLI_MAX_FIELDS];
    size_t n = cli_result_fields(su, r, fields);
    json_fields(f, fields, n, false);
    fputs("\n  },\n  \"units\": {", f);
    json_fields(f, fields, n, true);
    fputs("\n  }\n}\n", f);
}

void cli_events_csv(FILE* f, const struct wetdem_sim* sim, int argc, char** argv)
{
    cli_print_provenance(f, argc, argv);
    fputs("time [s],event [word],i [index],j [index],is_wall [0/1],gap [m],v_n [m/s]\n", f);
    size_t n = 0;
    const struct wetdem_event_record* ev = wetdem_sim_events(sim, &n);
    for (size_t k = 0; k < n; k++)
        fprintf(f, "%.12g,%s,%zu,%zu,%d,%.12g,%.12g\n", cli_plain_zero(ev[k].time),
                wetdem_event_kind_name(ev[k].kind), ev[k].i, ev[k].j, ev[k].is_wall ? 1 : 0,
                cli_plain_zero(ev[k].gap), cli_plain_zero(ev[k].v_n));
}

static void trajectory_header(struct cli_trajectory* t, size_t n)
{
    cli_print_provenance(t->f, t->argc, t->argv);
    fputs("time [s]", t->f);
    static const char* const names[] = {"x", "y", "z", "vx", "vy", "vz", "wx", "wy", "wz"};
    static const char* const units[] = {"m",   "m",     "m",     "m/s",  "m/s",
                                        "m/s", "rad/s", "rad/s", "rad/s"};
    for (size_t p = 0; p < n; p++)
        for (size_t k = 0; k < 9; k++)
            fprintf(t->f, ",%s_%c [%s]", names[k], p == 0 ? 'i' : 'j', units[k]);
    fputs(",gap [m],v_n [m/s]\n", t->f);
    t->header_done = true;
}

/* Gap [m] and normal approach speed [m/s] of the striker and the target. */
static void pair_gap(const struct wetdem_sim* sim, const struct cli_trajectory* t, double* gap,
                     double* v_n)
{
    size_t n = 0;
    const struct wetdem_particle* p = wetdem_sim_particles_const(sim, &n);
    *gap = NAN;
    *v_n = NAN;
    if (t->target_is_wall) {
        /* wetdem_sim_pair_force writes to sim only on failure (its message buffer). */
        struct wetdem_contact c;
        struct wetdem_pair_force f;
        if (n >= 1 &&
            wetdem_sim_pair_force((struct wetdem_sim*)sim, 0, (size_t)-1, &c, &f) == WETDEM_OK) {
            *gap = c.gap;
            *v_n = c.v_n;
        }
        return;
    }
    if (n < 2)
        return;
    double dx = p[0].pos.x - p[1].pos.x, dy = p[0].pos.y - p[1].pos.y, dz = p[0].pos.z - p[1].pos.z;
    double d = sqrt(dx * dx + dy * dy + dz * dz);
    *gap = d - p[0].radius - p[1].radius;
    double dvx = p[0].vel.x - p[1].vel.x, dvy = p[0].vel.y - p[1].vel.y,
           dvz = p[0].vel.z - p[1].vel.z;
    *v_n = -(dx * dvx + dy * dvy + dz * dvz) / d;
}

int cli_trajectory_observe(const struct wetdem_sim* sim, void* ctx)
{
    struct cli_trajectory* t = ctx;
    size_t n = 0;
    const struct wetdem_particle* p = wetdem_sim_particles_const(sim, &n);
    if (n > 2)
        n = 2;
    if (!t->header_done)
        trajectory_header(t, n);
    fprintf(t->f, "%.12g", cli_plain_zero(wetdem_sim_time(sim)));
    for (size_t k = 0; k < n; k++) {
        const double v[9] = {p[k].pos.x, p[k].pos.y,   p[k].pos.z,   p[k].vel.x,  p[k].vel.y,
                             p[k].vel.z, p[k].omega.x, p[k].omega.y, p[k].omega.z};
        for (size_t m = 0; m < 9; m++)
            fprintf(t->f, ",%.12g", cli_plain_zero(v[m]));
    }
    double gap, v_n;
    pair_gap(sim, t, &gap, &v_n);
    fprintf(t->f, ",%.12g,%.12g\n", cli_plain_zero(gap), cli_plain_zero(v_n));
    if (ferror(t->f)) {
        t->err = errno ? errno : EIO;
        return 1;
    }
    return cli_stop_signal ? 1 : 0;
}

/*
 * output_csv.h — writers of what `wetdem run` and `wetdem sweep` report: the collision summary
 * (text, JSON, or one CSV row), the trajectory CSV (an observer) and the event-log CSV.
 *
 * Every CSV starts with '#' provenance lines (version, git hash, command) and a header whose
 * columns name the quantity and its unit, "name [unit]". Numbers are printed with %.12g (12
 * significant digits: well below every tolerance the validation uses, and the same bits
 * for the same input); NaN is "nan" in CSV and null in JSON; booleans are 0/1 in CSV.
 */
#ifndef WETDEM_CLI_OUTPUT_CSV_H
#define WETDEM_CLI_OUTPUT_CSV_H

#include <stdio.h>

#include "scenario.h"

enum cli_field_kind { CLI_FIELD_NUMBER, CLI_FIELD_BOOL, CLI_FIELD_TEXT, CLI_FIELD_COUNT };

/* One reported quantity. */
struct cli_field {
    const char* name;
    const char* unit; /* "-" for dimensionless, "" for words, flags and counts */
    const char* doc;
    enum cli_field_kind kind;
    double number;
    bool flag;
    const char* text;
    unsigned long long count;
};

#define CLI_MAX_FIELDS 48

/* Fills out (CLI_MAX_FIELDS entries) with every field of a collision result, in a fixed
 * order, plus the impact speed of the setup; returns the count. Angles are in degrees. */
size_t cli_result_fields(const struct cli_setup* su, const struct wetdem_collision_result* r,
                         struct cli_field* out);

/* Whether a collision ended with more kinetic energy than it began with, beyond what the
 * integration's error allows (its energy_ratio above 1.01; the passive models give at most 1,
 * Verlet at its default step 1 - 8e-5 for an elastic impact): its step was too long for the
 * contact. Then writes into msg[n] which ratio and what to change ("ends with ..."). */
bool cli_energy_grew(double energy_ratio, char* msg, size_t n);

/* Whether a collision's fixed step did not resolve h_min (its stats.hmin_step_ratio above
 * WETDEM_HMIN_STEP_RATIO_MAX): information, not an error. Then writes into msg[n] how far the
 * step moved the gap, the e_n error it can cause and what to change ("the verlet step ..."). */
bool cli_hmin_unresolved(const struct wetdem_collision_result* r, char* msg, size_t n);

/* Overlap over R* above which the contact laws are extrapolated: Hertz's law holds while the
 * contact radius sqrt(delta R*) is small against R* (at 0.1 R* it is already 0.3 R*). */
#define CLI_OVERLAP_RATIO_MAX 0.1
/* Whether a collision's spheres overlapped by more than CLI_OVERLAP_RATIO_MAX R* (r_eff [m]):
 * information, not an error. Then writes into msg[n] the overlap and what it means ("the
 * spheres overlapped by ..."). */
bool cli_overlap_large(const struct wetdem_collision_result* r, double r_eff, char* msg, size_t n);

/* Records what the result struct lacks from the final state of su->sim: the striker's own
 * speed and the angle of its velocity to the line of centres, theta_i,1 of Nijssen Fig. 1c,
 * atan2(|v_t|, |v . n|) in [0, pi/2] (n: the rebound normal r->normal_out, the line of
 * centres at the start of the final separation; the wall normal against a wall). */
void cli_setup_capture(struct cli_setup* su, const struct wetdem_collision_result* r);

/* CSV header "name [unit],..." of the result fields (no newline). */
void cli_csv_result_header(FILE* f);
/* CSV row of the result fields (no newline). */
void cli_csv_result_row(FILE* f, const struct cli_setup* su,
                        const struct wetdem_collision_result* r);
/* CSV row of a collision that failed (no newline): the impact speed of the set-up, then "nan"
 * for every number, flag and count of the result and "none" for every word (the result of a
 * failed run holds no values, and 0 or "stick" would read as results). */
void cli_csv_failed_row(FILE* f, const struct cli_setup* su);
/* The result as aligned "name  value  unit  meaning" lines. */
void cli_summary_text(FILE* f, const struct cli_scenario* sc, const struct cli_setup* su,
                      const struct wetdem_collision_result* r);
/* The result as one JSON object (version, scenario, command, integrator, result, units). */
void cli_summary_json(FILE* f, const struct cli_scenario* sc, const struct cli_setup* su,
                      const struct wetdem_collision_result* r, int argc, char** argv);
/* The event log of sim as CSV, with provenance lines. */
void cli_events_csv(FILE* f, const struct wetdem_sim* sim, int argc, char** argv);

/* Trajectory writer: pass as the observer context of wetdem_sim_set_observer(). */
struct cli_trajectory {
    FILE* f;
    int err; /* errno of the first write that failed (EIO if none was set), 0 */
    bool header_done;
    bool target_is_wall;
    int argc;
    char** argv;
};
/* Observer writing one row: time, position, velocity and spin of each particle, the gap and
 * the normal approach speed of the pair. Returns 0, or 1 to stop the run: the file cannot be
 * written (t->err), or a signal asked the command to stop (cli_stop_signal). */
int cli_trajectory_observe(const struct wetdem_sim* sim, void* ctx);

/* A number as JSON (null for NaN or infinity). */
void cli_json_number(FILE* f, double v);
/* A string as JSON (quotes and backslashes escaped). */
void cli_json_string(FILE* f, const char* s);
/* The command line as a JSON array of strings, "wetdem" and then the subcommand's arguments
 * (argc, argv from "run" on), as the CSV files' "# command:" line gives it. */
void cli_json_command(FILE* f, int argc, char** argv);

#endif

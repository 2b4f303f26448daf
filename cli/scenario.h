/*
 * scenario.h — scenario files (INI, read with inih) for `wetdem run` and `wetdem sweep`.
 *
 * A scenario is kept as a generic list of (section, key, value, file, line) entries, so that
 * every engine or command can read its own sections with the typed accessors below, and so
 * that `--set section.key=value` overrides work for every key. The keys a section accepts are
 * described by descriptor tables (unit, default, range, doc); docs/scenarios.md is generated
 * from them by `wetdem docs-scenarios`, and tests/test_scenario.c checks it is current.
 *
 * Error convention (as cli_util.h): functions that reject input print one message to stderr,
 * "FILE:LINE: [section] key = value: why" (or "--set section.key=value: why" for overrides),
 * and return CLI_EXIT_USAGE (2); CLI_EXIT_OK (0) on success.
 */
#ifndef WETDEM_CLI_SCENARIO_H
#define WETDEM_CLI_SCENARIO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdio.h>

#include "cli.h"

#define CLI_NAME_MAX 64   /* longest section or key name + 1 */
#define CLI_VALUE_MAX 256 /* longest value + 1 */

/* One "key = value" line of a scenario, or one --set override (line 0). */
struct cli_entry {
    char section[CLI_NAME_MAX]; /* "collision", "material.delrin", "model.nijssen" */
    char key[CLI_NAME_MAX];
    char value[CLI_VALUE_MAX];
    int line; /* 1-based line in the file; 0 for a --set override */
};

/* A "[section]" header line. */
struct cli_section_mark {
    char name[CLI_NAME_MAX];
    int line;
};

struct cli_scenario {
    char file[1024]; /* the path as given, for messages */
    struct cli_entry* entries;
    size_t n_entries, entries_cap;
    struct cli_section_mark* sections;
    size_t n_sections, sections_cap;
};

/* Kinds of values a key accepts. */
enum cli_value_kind {
    CLI_VALUE_NUMBER = 0, /* a finite number in [min, max] */
    CLI_VALUE_CHOICE,     /* one word of `choices` */
    CLI_VALUE_NAME,       /* a name checked when the scenario is built (material, model) */
    CLI_VALUE_NAME_LIST,  /* space- or comma-separated names, checked when built */
    CLI_VALUE_TEXT,       /* free text, e.g. a file name */
};

/* Descriptor of one scenario key (tables end with {0}). */
struct cli_key_desc {
    const char* key;
    enum cli_value_kind kind;
    const char* unit;           /* "m", "-", ... ("" for words) */
    const char* default_text;   /* as documented, e.g. "0 (derive from stokes)"; NULL: read
                                 from the library ([integrator], [sim] parameters) */
    double min, max;            /* numbers: valid range */
    bool min_open, max_open;    /* exclude the bound */
    const char* const* choices; /* CLI_VALUE_CHOICE: NULL-terminated words */
    const char* doc;            /* one or two sentences */
    bool integer;               /* numbers: whole numbers only (counts, steps, indices) */
};

/* Initialisers of key descriptors for the tables of cli/scenario_keys.c, cli/scenario_many.c
 * and cli/run_pairwise.c: a number with its unit and valid range, or a word of a kind. */
#define CLI_KEY_NUMBER(k, u, dflt, lo, hi, lo_open, hi_open, doc)                                  \
    {                                                                                              \
        k, CLI_VALUE_NUMBER, u, dflt, lo, hi, lo_open, hi_open, NULL, doc, false                   \
    }
/* A whole number in [lo, hi] without a unit: a count, a number of steps, an index. */
#define CLI_KEY_COUNT(k, dflt, lo, hi, doc)                                                        \
    {                                                                                              \
        k, CLI_VALUE_NUMBER, "-", dflt, lo, hi, false, false, NULL, doc, true                      \
    }
#define CLI_KEY_WORD(k, kind, dflt, choices, doc)                                                  \
    {                                                                                              \
        k, kind, "", dflt, 0, 0, false, false, choices, doc, false                                 \
    }

/* The choices of a yes/no key. */
extern const char* const cli_yes_no[];

/* Descriptor of one section. A name ending in ".*" (e.g. "material.*") is a family of
 * sections "material.NAME". keys == NULL means the keys are checked when the scenario is
 * built (e.g. [model.NAME] keys are the parameters of model NAME). */
struct cli_section_desc {
    const char* name;
    const char* doc;
    const struct cli_key_desc* keys;
};

/* Optional (weak): sections another engine reads, e.g. the pairwise engine's, as a
 * {0}-terminated table; they are accepted, validated and documented like the built-in ones. */
extern const struct cli_section_desc cli_pairwise_sections[] __attribute__((weak));
/* Optional (weak): the many-particle sections ([box], [walls], [insert], [particle.NAME],
 * [run], [dump]; cli/scenario_many.c), accepted, validated and documented the same way. */
extern const struct cli_section_desc cli_many_sections[] __attribute__((weak));

/* ---- loading and overriding ---- */

/* Reads and checks a scenario file: syntax, known sections and keys ("did you mean"),
 * duplicates, numbers finite and in range, words among their choices. Returns CLI_EXIT_OK or
 * prints every error found and returns CLI_EXIT_USAGE. sc is left valid for free() either way. */
int cli_scenario_load(const char* path, struct cli_scenario* sc);
/* Applies "section.key=value" (e.g. "collision.stokes=50", "material.delrin.roughness=1e-7",
 * "model.nijssen.cutoff_ratio=2"; a dotted model parameter "nijssen.cutoff_ratio" is taken as
 * [model.nijssen]). The key must be one the section accepts. Returns an exit code. */
int cli_scenario_override(struct cli_scenario* sc, const char* key_value);
/* Deep copy of src into dst (dst is overwritten). CLI_EXIT_OK or CLI_EXIT_RUNTIME (memory). */
int cli_scenario_copy(const struct cli_scenario* src, struct cli_scenario* dst);
/* Frees what sc owns; sc may then be loaded again. */
void cli_scenario_free(struct cli_scenario* sc);

/* ---- typed accessors ---- */

/* The entry for section.key, or NULL when absent. */
const struct cli_entry* cli_scenario_find(const struct cli_scenario* sc, const char* section,
                                          const char* key);
/* Whether the scenario has a [section] header or any key in it. */
bool cli_scenario_has_section(const struct cli_scenario* sc, const char* section);
/* Whether section `name` is `pattern`, or of its family when pattern is "family.*". */
bool cli_section_matches(const char* name, const char* pattern);
/* Checks that every section of sc (in the file or from --set) is one of `reads`, the
 * NULL-terminated sections that `reader` (e.g. "the pairwise engine") reads, a "family.*"
 * standing for every [family.NAME]: a section no engine of the scenario reads would be
 * ignored without a word. Prints the first other one at its line, with the list, and returns
 * CLI_EXIT_USAGE; CLI_EXIT_OK when there is none. */
int cli_scenario_check_read(const struct cli_scenario* sc, const char* reader,
                            const char* const* reads);
/* Reads a number (default `def` when absent). The value was checked when loaded; this only
 * converts. */
double cli_scenario_number(const struct cli_scenario* sc, const char* section, const char* key,
                           double def);
/* Reads a word or text (default `def` when absent). Borrowed pointer. */
const char* cli_scenario_text(const struct cli_scenario* sc, const char* section, const char* key,
                              const char* def);
/* Prints "FILE:LINE: [section] key = value: <message>" (or the --set form) to stderr. */
void cli_scenario_error(const struct cli_scenario* sc, const struct cli_entry* e, const char* fmt,
                        ...) __attribute__((format(printf, 3, 4)));
/* "wetdem: warning: FILE:LINE: [section] key = value: ..." ("FILE: --set section.key=value:"
 * for an entry of --set), placed as cli_scenario_error places an error. */
void cli_scenario_warning(const struct cli_scenario* sc, const struct cli_entry* e, const char* fmt,
                          ...) __attribute__((format(printf, 3, 4)));
/* Prints "FILE:LINE: [section]: <message>" for a whole section (its header line, or that of its
 * first key); "FILE: no [section] section: " when the file lacks it, "FILE: [section] of
 * --set: " when only --set gave its keys. */
void cli_scenario_section_error(const struct cli_scenario* sc, const char* section, const char* fmt,
                                ...) __attribute__((format(printf, 3, 4)));

/* ---- building a soft-engine collision ---- */

enum cli_engine { CLI_ENGINE_SOFT = 0, CLI_ENGINE_PAIRWISE = 1 };

/* Everything a soft-engine run needs, resolved from a scenario. */
struct cli_setup {
    struct wetdem_sim* sim;            /* owned; materials, fluid, models, integrator set */
    struct wetdem_collision_spec spec; /* speed always explicit (derived from stokes) */
    enum cli_engine engine;
    double impact_speed;                 /* |v_i| at t = 0 [m/s] */
    double stokes_n;                     /* normal Stokes number of the impact [-] */
    double m_eff, r_eff;                 /* m* [kg], R* [m] used for the Stokes number */
    double trajectory_interval;          /* [s], resolved from auto */
    char trajectory_file[CLI_VALUE_MAX]; /* "" = not written */
    char events_file[CLI_VALUE_MAX];
    char summary_file[CLI_VALUE_MAX];
    /* filled by cli_setup_capture() after the run: */
    double striker_speed_out; /* |v_i| at the end [m/s] */
    double striker_angle_out; /* angle of v_i to the rebound normal n_f [rad] */
};

/* Reads [engine] type only. CLI_EXIT_OK or CLI_EXIT_USAGE. */
int cli_scenario_engine(const struct cli_scenario* sc, enum cli_engine* engine);
/* Builds the simulation and the collision spec. Every library check runs here, so a
 * scenario that builds runs without input errors. Returns CLI_EXIT_OK, CLI_EXIT_USAGE
 * (message printed, nothing allocated) or CLI_EXIT_RUNTIME (out of memory). */
int cli_scenario_build(const struct cli_scenario* sc, struct cli_setup* setup);
/* Frees the simulation of a setup. */
void cli_setup_free(struct cli_setup* setup);

/* Impact speed [m/s] that gives the normal Stokes number St_n = m* v cos(angle) /
 * (6 pi mu R*^2): v = St_n 6 pi mu R*^2 / (m* cos(angle)). */
double cli_stokes_speed(double stokes_n, double viscosity, double m_eff, double r_eff,
                        double angle);

/* ---- internal: building blocks of the soft-engine and many-particle builders
 * (scenario_build.c, used by scenario_many.c) ---- */

/* Sets the [integrator] keys (but name) as parameters of the integrator `chosen`
 * ("<chosen>.<key>") and the [sim] keys as settings ("sim.<key>"). A parameter of another
 * integrator is skipped (a file tuned for cvode also runs with --set integrator.name=verlet;
 * many: a many-particle run, which steps with verlet, warns about it elsewhere). A key the
 * library refuses is reported: one close to `name` (as "nam") with that hint; one closer to a
 * parameter of another integrator than to any of the chosen one's (rtoll, where verlet steps:
 * cvode's rtol) with that parameter and its integrator; else as cli_scenario_lib_error.
 * Returns the exit code. */
int cli_scenario_set_integrator_keys(const struct cli_scenario* sc, struct wetdem_sim* sim,
                                     const char* chosen, bool many);

/* Most rows a trajectory file may get: about 2 GB of CSV. */
#define CLI_MAX_TRAJECTORY_ROWS 1e7

/* A trajectory of t_end / interval rows [s / s]: CLI_EXIT_OK if at most
 * CLI_MAX_TRAJECTORY_ROWS, else the message at [output] trajectory_interval (or at [output],
 * else at [run_section], when the interval is automatic) and CLI_EXIT_USAGE. */
/* The file name that `key` of [section] gives in the --out directory (def when not given), ""
 * for "none", into out (CLI_VALUE_MAX chars). A given name must be a plain file name: not
 * empty, no '/', not starting with '.'. Returns an exit code (the message at the key). */
int cli_scenario_out_name(const struct cli_scenario* sc, const char* section, const char* key,
                          const char* def, char* out);

/* Checks the [output] names of a collision run: each a plain file name in the --out
 * directory (no '/', not starting with '.') or none, and no two the same (the one written
 * last would replace the other). Returns an exit code (message printed). */
int cli_scenario_check_outputs(const struct cli_scenario* sc);

int cli_scenario_check_trajectory(const struct cli_scenario* sc, const char* run_section,
                                  double t_end, double interval);

/* Prints the library's message of sim against entry e (or against [section] when e is NULL)
 * and returns the exit code of the library's status: CLI_EXIT_RUNTIME for WETDEM_ERR_NOMEM
 * (running out of memory is no fault of the input), CLI_EXIT_USAGE otherwise. */
int cli_scenario_lib_error(const struct cli_scenario* sc, const struct cli_entry* e,
                           const char* section, const struct wetdem_sim* sim, int status);
/* [fluid]: the preset, then every field given, set on sim. Returns an exit code. */
int cli_scenario_build_fluid(const struct cli_scenario* sc, struct wetdem_sim* sim);
/* A [material.NAME] section into *m: the library defaults, then its preset, then every field
 * given; checked with wetdem_material_validate. Returns an exit code. */
int cli_scenario_material_section(const struct cli_scenario* sc, const char* section,
                                  struct wetdem_material* m);
/* Every [material.NAME] section checked as cli_scenario_material_section does, also those no
 * sphere uses (a mistake there is one too): an exit code, the message printed. */
int cli_scenario_check_materials(const struct cli_scenario* sc);
/* [models] min_separation, when given: enables that model, which must be a minimum-separation
 * one (a force model named there would otherwise be summed as a force). Returns an exit
 * code. */
int cli_scenario_enable_min_separation(const struct cli_scenario* sc, struct wetdem_sim* sim);
/* Every [model.NAME] key as the parameter NAME.key of sim's enabled model NAME. A key of a
 * model that is not enabled is an error (it would be ignored without a word), except a key of
 * the file when [models] force or min_separation came from --set: the file may hold the
 * parameters of the model the --set switched away from. Returns an exit code. */
int cli_scenario_set_model_params(const struct cli_scenario* sc, struct wetdem_sim* sim);
/* Warns (once a process) when sim's thin-film models (sb, db, davis, nase, capillary) can do
 * nothing: the pair has no film (delta = 0), or [model.fixed] h_min >= delta, or the
 * roughness (min_separation roughness or max, whose h_min is at least the mean roughness)
 * >= delta, where they take h_min capped at delta. delta: the pair's film thickness (the
 * largest a pair can have); films: where it comes from, for the message; roughness: the
 * pair's mean roughness (sigma_i + sigma_j)/2 (the smallest a pair can have) [m]; roughs:
 * where it comes from. */
void cli_scenario_warn_films(const struct cli_scenario* sc, const struct wetdem_sim* sim,
                             double delta, const char* films, double roughness, const char* roughs);
/* Warns (once a process) about each [material.NAME] section that none of used[0 .. n_used)
 * names (it would be read by no sphere): "FILE:LINE: [material.NAME] is not used: <how>". */
void cli_scenario_warn_unused_materials(const struct cli_scenario* sc, const char* const* used,
                                        size_t n_used, const char* how);
/* Warns (once a process) about each key given that the run does not read, at its line with
 * why: [integrator] parameters of the integrator not chosen, the other engine's step bound
 * (hmin_fraction of binary collisions, many_hmin_fraction of many-particle runs), dt_fraction
 * (and [integrator] dt, in a many-particle run with [run] dt) when the step is given;
 * [collision] target_radius with target = wall; [model.NAME] parameters of the
 * min-separation model when no force model reads h_min. A key of the file that a --set of the
 * key making it unread (integrator.name, say) set aside is not warned about. many: a
 * many-particle run. */
void cli_scenario_warn_ignored(const struct cli_scenario* sc, const struct wetdem_sim* sim,
                               bool many);
/* Warns (once a process), at [models] force, when none of sim's force models holds the
 * surfaces apart at contact (a solid contact, with a contact time: hertz, hooke, nijssen),
 * naming those that do. */
void cli_scenario_warn_no_contact(const struct cli_scenario* sc, const struct wetdem_sim* sim);

/* ---- internal: section lookup (scenario_keys.c), shared by scenario*.c ---- */

/* What a section accepts: its descriptor, keys from a library table, or any key. */
struct cli_section_info {
    const struct cli_section_desc* desc;      /* never NULL on success */
    const struct wetdem_param_desc* lib_keys; /* e.g. wetdem_material_params(), or NULL */
    const struct wetdem_model* model;         /* [model.NAME]: the model */
    bool open_keys;                           /* keys checked when built ([integrator], [sim]) */
};
/* Looks a section name up ("collision", "material.delrin", "model.nijssen"). 0 or -1. */
int cli_section_lookup(const char* name, struct cli_section_info* info);
/* The name of a built-in model close to `word` (e.g. "nijsen" -> "nijssen"), or NULL. */
const char* cli_model_suggestion(const char* word);
/* Writes " (did you mean [x]?)" or a list of valid sections for an unknown name into msg. */
void cli_section_suggestion(const char* name, char* msg, size_t n);
/* Where the key of entry e, which its section lacks, belongs, taking e's value as its kind
 * there (a number, or a word of its choices): writes "it is a key of [collision]: move it
 * there" into buf and returns 1 when sections (or [model.NAME] sections) the scenario's
 * engine reads have it; "'count' is a key of [insert] ... of a many-particle run, which this
 * scenario is not" and 2 when only another engine's have it; "" and 0 otherwise. */
int cli_key_home(const struct cli_scenario* sc, const struct cli_entry* e, char* buf, size_t n);
/* The one section that the scenario's engine reads and that has `key` (taking value as its
 * kind there), a named family ([material.NAME]) excepted: written into section (e.g.
 * "collision", "model.nijssen"), returns 1; 0 when none or several have it. */
int cli_key_only_home(const struct cli_scenario* sc, const char* key, const char* value,
                      char* section, size_t n);
/* Whether s is a non-empty name of letters, digits, '_' and '-'. */
bool cli_is_name(const char* s);
/* What is wrong with the commas of a list of names (names separated by commas or blanks):
 * "only commas, no name", "a comma with no name before it" (",hertz"), "two commas with no
 * name between them" ("hertz,,db") or "a comma with no name after it" ("hertz,"), the first
 * found; NULL when every comma stands between two names (or there is none). */
const char* cli_list_empty_name(const char* list);
/* A numeric or choice key descriptor as a library parameter descriptor (for range text). */
struct wetdem_param_desc cli_key_as_param(const struct cli_key_desc* k);

/* The valid range of a numeric key (min, max, open flags, integer) as a descriptor, from the
 * section's key table or the library's table (material, fluid, model parameters). 0, or -1
 * when the key is unknown or not a number. */
int cli_scenario_key_range(const char* section, const char* key, struct wetdem_param_desc* out);
/* Unit of a key as documented ("" if unknown or a word). */
const char* cli_scenario_key_unit(const char* section, const char* key);
/* Splits an override "a.b.key=value" into section and key (a model name "nijssen" becomes
 * "model.nijssen"). 0, or -1 with a message printed. value may be NULL. */
int cli_override_split(const char* text, char* section, char* key, char* value);
/* The same for a key given alone by `option` ("--param", "--fit"): "a.b.c" into section and
 * key; the message names the option. Returns 0 or -1 (message printed). */
int cli_key_split(const char* option, const char* name, char* section, char* key);
/* Checks that key `key` of section `section`, named `tok` by `option` of command `cmd` (fit
 * --fit, sweep --param), is a numeric key: the section must exist, the key must be one of
 * its keys (with a suggestion otherwise) and take a number ("only numeric keys can be
 * <verb>"). Sections whose keys are only known when built ([integrator], [sim]) pass here.
 * CLI_EXIT_OK, or the message printed and CLI_EXIT_USAGE. */
int cli_check_numeric_key(const char* cmd, const char* option, const char* tok, const char* section,
                          const char* key, const char* verb);
/* Whether two keys "section.key" (as those splits resolve them) set one thing: 1 the same
 * key, 2 collision.speed and collision.stokes (the impact: setting one replaces the other),
 * else 0. */
int cli_keys_clash(const char* a, const char* b);
/* What a clash 2 of cli_keys_clash means, for messages. */
#define CLI_IMPACT_CLASH " (the impact, by speed or by stokes: setting one replaces the other)"

/* ---- shared by run, sweep and fit ---- */

/* cli_scenario_load() then cli_scenario_override() for each of sets. Returns an exit code. */
int cli_load_with_overrides(const char* file, const char* const* sets, int n_sets,
                            struct cli_scenario* sc);

/* ---- documentation ---- */

/* Built-in section table ({0}-terminated). */
const struct cli_section_desc* cli_scenario_sections(void);
/* Writes the Markdown key tables of every section (the generated part of docs/scenarios.md).
 * Returns 0, or -1 if a documented integrator or sim key is unknown to the library. */
int cli_scenario_print_docs(FILE* f);
/* `wetdem docs-scenarios`: the key tables to stdout. */
int cmd_docs_scenarios(int argc, char** argv);

/* ---- other engines ---- */

/* Options of `wetdem run` handed to an engine. */
struct cli_run_options {
    const char* out_dir; /* NULL: no files */
    bool json;           /* summary as JSON on stdout */
    int argc;            /* the subcommand's arguments, for provenance lines */
    char** argv;
    FILE* sweep_row;     /* non-NULL (sweep): write only one CSV row of results (no newline
                            handling by the caller: end it with '\n'), or the header */
    bool sweep_header;   /* with sweep_row: write the CSV column header line instead */
    const char* restart; /* many-particle runs: checkpoint to resume from, or NULL */
    bool check;          /* only check the scenario and print the resolved set-up */
    int* status_out;     /* non-NULL: receives the engine's run status (WETDEM_OK, or < 0 when
                            the run failed; a sweep row is still written then) */
    char* errmsg_out;    /* non-NULL: receives the engine's message of a failed run */
    size_t errmsg_size;  /* bytes at errmsg_out */
};

/* Runs a scenario whose [engine] type is "pairwise" (cli/run_pairwise.c). Weak: when the
 * build has no pairwise engine, run and sweep report "engine 'pairwise' is not in this
 * build" and exit 1. Returns an exit code. */
int cli_run_pairwise(const struct cli_scenario* sc, const struct cli_run_options* opt)
    __attribute__((weak));

/* Whether the scenario describes a many-particle run (it has one of cli_many_sections and no
 * [collision]); cli/scenario_many.c. Weak: absent when the build has no many-particle CLI. */
bool cli_scenario_is_many(const struct cli_scenario* sc) __attribute__((weak));
/* Runs a many-particle scenario (cli/run_many.c): outputs in opt->out_dir, --restart from
 * opt->restart, SIGINT/SIGTERM write a checkpoint. Returns an exit code (130/143 when
 * interrupted by SIGINT/SIGTERM with a checkpoint written). Weak. */
int cli_run_many(const struct cli_scenario* sc, const struct cli_run_options* opt)
    __attribute__((weak));

#endif

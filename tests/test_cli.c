/*
 * test_cli.c — the wetdem command-line tool end to end: --version, --help, `models` (every
 * registry model listed), `describe` (parameters with units and ranges of every model, the
 * simulation settings and both integrators; unknown names give a hint and exit 2), `forces` (CSV provenance and columns; one value checked against the closed
 * form of the reynolds model, F = 6 pi mu R*^2 v_n / h), bad input (exit 2, message), and
 * `--help`/`-h` of every subcommand listed by `wetdem --help` (usage on stdout, exit 0), and
 * the choice of models: a model of the wrong kind named with its kind, and [model.NAME]
 * sections of models that a --set of [models] left out; the inputs `make fuzz` found
 * (tests/fuzz/regressions/), each answered as any other file; the shape of every CSV the tool
 * writes (provenance lines, then columns "name [unit]" whose rows fit their units).
 *
 * The CLI path comes from the environment variable WETDEM_CLI (set by `make test`), falling
 * back to build/wetdem relative to the working directory (the repository root).
 */
#include <pty.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "harness.h"

/* Runs "$WETDEM_CLI args"; stderr is merged into out when with_stderr, discarded otherwise. */
static struct test_run run_cli(const char* args, bool with_stderr)
{
    return test_run_cli("", args, with_stderr);
}

/* True if some line of text starts with `word` followed by a space. */
static bool has_line_starting_with(const char* text, const char* word)
{
    size_t n = strlen(word);
    const char* line = text;
    while (line) {
        if (strncmp(line, word, n) == 0 && line[n] == ' ')
            return true;
        line = strchr(line, '\n');
        if (line)
            line++;
    }
    return false;
}

static void test_cli_version_and_help(void** state)
{
    (void)state;
    struct test_run r = run_cli("--version", true);
    assert_int_equal(r.code, 0);
    CHECK_CONTAINS(r.out, "wetdem " WETDEM_VERSION " (git ");
    free(r.out);
    r = run_cli("--help", true);
    assert_int_equal(r.code, 0);
    CHECK_CONTAINS(r.out, "wetdem models");
    CHECK_CONTAINS(r.out, "wetdem describe NAME");
    CHECK_CONTAINS(r.out, "wetdem forces");
    CHECK_CONTAINS(r.out, "exit codes");
    free(r.out);
    r = run_cli("modles", true);
    assert_int_equal(r.code, 2);
    CHECK_CONTAINS(r.out, "did you mean 'models'");
    free(r.out);
}

/* Every subcommand that `wetdem --help` lists ("  wetdem NAME ..." lines) answers --help and
 * -h, alone or after other arguments, with its usage on stdout and exit code 0. */
static void test_cli_every_subcommand_help(void** state)
{
    (void)state;
    struct test_run help = run_cli("--help", false);
    assert_int_equal(help.code, 0);
    size_t n_commands = 0;
    for (const char* line = strstr(help.out, "\n  wetdem "); line;
         line = strstr(line + 1, "\n  wetdem ")) {
        char name[64];
        if (sscanf(line + 10, "%63[a-z-]", name) != 1)
            fail_msg("cannot read a command name at '%.40s'", line + 1);
        n_commands++;
        const char* forms[] = {"--help", "-h", "extra-argument --help", "--bogus -h"};
        for (size_t f = 0; f < sizeof forms / sizeof forms[0]; f++) {
            char args[160], want[96];
            snprintf(args, sizeof args, "%s %s", name, forms[f]);
            snprintf(want, sizeof want, "usage: wetdem %s", name);
            struct test_run r = run_cli(args, false);
            if (r.code != 0 || strncmp(r.out, want, strlen(want)) != 0)
                fail_msg("'wetdem %s' exited %d with stdout:\n%s\n(expected exit 0 and '%s')", args,
                         r.code, r.out, want);
            free(r.out);
        }
    }
    /* models, describe, forces, run, sweep, map, fit, track, docs-models, docs-scenarios,
     * docs-cli */
    if (n_commands < 11)
        fail_msg("only %zu commands found in 'wetdem --help':\n%s", n_commands, help.out);
    free(help.out);
}

static void test_cli_models_lists_every_model(void** state)
{
    (void)state;
    struct test_run r = run_cli("models", false);
    assert_int_equal(r.code, 0);
    const struct wetdem_model* const* reg = wetdem_model_registry();
    size_t n = 0;
    for (; reg[n]; n++)
        if (!has_line_starting_with(r.out, reg[n]->name))
            fail_msg("'wetdem models' has no line for '%s':\n%s", reg[n]->name, r.out);
    assert_true(n >= 2); /* the registry is never empty: at least reynolds and fixed */
    CHECK_CONTAINS(r.out, "min-separation");
    free(r.out);
}

static void test_cli_describe_lists_parameters_with_units(void** state)
{
    (void)state;
    struct test_run r = run_cli("describe reynolds", false);
    assert_int_equal(r.code, 0);
    CHECK_CONTAINS(r.out, "cutoff_ratio [-]  default 1, valid (0, 100]");
    CHECK_CONTAINS(r.out, "Nijssen 2023 Eq. 1");
    free(r.out);
    /* Every parameter of every model appears as "name [unit]". */
    const struct wetdem_model* const* reg = wetdem_model_registry();
    for (size_t k = 0; reg[k]; k++) {
        char args[128], want[160];
        snprintf(args, sizeof args, "describe %s", reg[k]->name);
        r = run_cli(args, false);
        assert_int_equal(r.code, 0);
        for (size_t q = 0; reg[k]->params[q].name; q++) {
            snprintf(want, sizeof want, "  %s [%s]", reg[k]->params[q].name,
                     reg[k]->params[q].unit);
            CHECK_CONTAINS(r.out, want);
        }
        free(r.out);
    }
    r = run_cli("describe fluid", false);
    assert_int_equal(r.code, 0);
    CHECK_CONTAINS(r.out, "viscosity [Pa s]  default 0.001, valid [0, 1e+06]");
    free(r.out);
    /* the simulation settings and both integrators, from the public descriptor tables */
    const struct {
        const char* name;
        const struct wetdem_param_desc* table;
    } tables[] = {{"sim", wetdem_sim_settings_params()},
                  {"verlet", wetdem_integrator_params("verlet")},
                  {"cvode", wetdem_integrator_params("cvode")}};
    for (size_t t = 0; t < sizeof tables / sizeof tables[0]; t++) {
        char args[64], want[160];
        snprintf(args, sizeof args, "describe %s", tables[t].name);
        r = run_cli(args, false);
        assert_int_equal(r.code, 0);
        assert_non_null(tables[t].table);
        for (size_t q = 0; tables[t].table[q].name; q++) {
            snprintf(want, sizeof want, "  %s [%s]  default ", tables[t].table[q].name,
                     tables[t].table[q].unit);
            CHECK_CONTAINS(r.out, want);
        }
        free(r.out);
    }
    r = run_cli("describe cvode", false);
    CHECK_CONTAINS(r.out, "rtol [-]  default 1e-08, valid [1e-14, 0.0001]");
    CHECK_CONTAINS(r.out, "method [-]  default auto, valid one of: auto, adams, bdf");
    free(r.out);
    r = run_cli("describe presets", false);
    assert_int_equal(r.code, 0);
    CHECK_CONTAINS(r.out, "delrin:");
    CHECK_CONTAINS(r.out, "7.96e-07"); /* delrin roughness 796 nm, Nijssen Table 1 */
    free(r.out);
}

static void test_cli_describe_unknown_name(void** state)
{
    (void)state;
    struct test_run r = run_cli("describe nijsen", true);
    assert_int_equal(r.code, 2);
    CHECK_CONTAINS(r.out, "unknown name 'nijsen'");
    CHECK_CONTAINS(r.out, "did you mean 'nijssen'");
    free(r.out);
    r = run_cli("describe", true);
    assert_int_equal(r.code, 2);
    CHECK_CONTAINS(r.out, "usage: wetdem describe NAME");
    free(r.out);
    /* an empty name is said to be one, with no hint (it was "did you mean 'sb'?") */
    r = run_cli("describe ''", true);
    assert_int_equal(r.code, 2);
    CHECK_CONTAINS(r.out, "describe: an empty name; valid: a model name");
    assert_null(strstr(r.out, "did you mean"));
    free(r.out);
}

/* Parses the first data row of a forces CSV into cols[4]; checks the provenance lines and the
 * column header on the way. */
static void parse_forces_csv(const char* csv, double cols[4])
{
    CHECK_CONTAINS(csv, "# wetdem " WETDEM_VERSION " (git ");
    CHECK_CONTAINS(csv, "# command: wetdem forces");
    const char* header = strstr(csv, "\ngap [m],f_normal [N],f_tangential [N],h_min [m]\n");
    if (!header)
        fail_msg("no column header line in:\n%s", csv);
    const char* row = strchr(header + 1, '\n') + 1;
    if (sscanf(row, "%lf,%lf,%lf,%lf", &cols[0], &cols[1], &cols[2], &cols[3]) != 4)
        fail_msg("cannot parse the row '%.80s'", row);
}

static void test_cli_forces_matches_reynolds_closed_form(void** state)
{
    (void)state;
    struct test_run r = run_cli("forces --model reynolds --preset steel1 --radius 6.35e-3 "
                                "--speed 0.1 --gaps 1e-5:1e-5:1 --set fluid.viscosity=0.5",
                                false);
    assert_int_equal(r.code, 0);
    double c[4];
    parse_forces_csv(r.out, c);
    free(r.out);
    /* F = 6 pi mu R*^2 v_n / h with mu = 0.5 Pa s, R* = 6.35e-3/2 = 3.175e-3 m,
     * v_n = 0.1 m/s, h = 1e-5 m: R*^2 = 1.00806e-5 m^2, F = 18.8496 * 0.5 * 1.00806e-5
     * * 0.1 / 1e-5 = 0.950077 N (h > h_min = 1e-6 m of the default fixed model). */
    double r_eff = 6.35e-3 / 2, want = 6 * M_PI * 0.5 * r_eff * r_eff * 0.1 / 1e-5;
    CHECK_REL(want, 0.950077, 1e-6); /* the hand value above has 6 significant digits */
    CHECK_REL(c[0], 1e-5, 0.0);      /* the gap column is the requested gap */
    /* 1e-12: the library recovers h = |x_i - x_j| - 2R from centres ~1e-2 m apart, which
     * costs ~1e-18 m of rounding, i.e. ~1e-13 relative on h = 1e-5 m (measured 4.1e-14). */
    CHECK_REL(c[1], want, 1e-12);
    CHECK_REL(c[2], 0.0, 0.0);  /* reynolds has no tangential part */
    CHECK_REL(c[3], 1e-6, 0.0); /* h_min of the default "fixed" model */
    /* separating at the same speed: the same force, as suction (F is odd in v_n), and the
       header says so (it said "approaching" for every speed) */
    r = run_cli("forces --model reynolds --preset steel1 --radius 6.35e-3 --speed -0.1 "
                "--gaps 1e-5:1e-5:1 --set fluid.viscosity=0.5",
                false);
    assert_int_equal(r.code, 0);
    CHECK_CONTAINS(r.out, "v_n = -0.1 m/s (separating)");
    parse_forces_csv(r.out, c);
    free(r.out);
    CHECK_REL(c[1], -want, 1e-12); /* (the same rounding of h as above) */
}

/* Only a min-separation model: no force, so both force columns are 0 at every gap; a warning
 * says so and names the force models that read h_min, and with one of them none is given. */
static void test_cli_forces_min_separation_only_is_explained(void** state)
{
    (void)state;
    struct test_run r = run_cli("forces roughness --gaps 1e-6:1e-5:2", true);
    assert_int_equal(r.code, 0);
    CHECK_CONTAINS(r.out, "wetdem: warning: forces: no force model given ('roughness' is a "
                          "minimum-separation model: it gives only the h_min column), so "
                          "f_normal and f_tangential are 0 at every gap; add a force model "
                          "that reads h_min, e.g. 'wetdem forces reynolds roughness'");
    free(r.out);
    r = run_cli("forces reynolds roughness --gaps 1e-6:1e-5:2", true);
    assert_int_equal(r.code, 0);
    assert_null(strstr(r.out, "warning"));
    free(r.out);
}

static void test_cli_forces_log_gaps_are_decades(void** state)
{
    (void)state;
    struct test_run r = run_cli("forces --model reynolds --gaps 1e-7:1e-3:5 --log", false);
    assert_int_equal(r.code, 0);
    const char* row = strstr(r.out, "h_min [m]\n");
    assert_non_null(row);
    /* Five geometric points from 1e-7 to 1e-3 m are the decades 1e-7 ... 1e-3, printed as
     * such (the text must read back as the double nearest the decimal). */
    const char* want[] = {"1e-07,", "1e-06,", "1e-05,", "0.0001,", "0.001,"};
    for (size_t k = 0; k < 5; k++) {
        row = strchr(row, '\n') + 1;
        if (strncmp(row, want[k], strlen(want[k])) != 0)
            fail_msg("row %zu is '%.40s', expected it to start with '%s'", k, row, want[k]);
    }
    free(r.out);
}

static void test_cli_forces_bad_input(void** state)
{
    (void)state;
    const struct {
        const char* args;
        const char* message;
    } cases[] = {
        {"forces --model reynolds --gaps 1:2", "A:B:N"},
        {"forces --model reynolds --gaps 1e-6:1e-3:0", "count N"},
        {"forces --model reynolds --gaps -1e-6:1e-3:3 --log", "--log needs A > 0"},
        {"forces --model reynolds --gaps 1e-6:1e-3:1", "has N = 1 but A != B"},
        {"forces --model reynolds --gaps 1e-6:1e-6:4",
         "'1e-6:1e-6:4' gives 4 identical values (A = B)"},
        {"forces --model reynolds --set fluid.viscosty=1", "did you mean 'fluid.viscosity'"},
        {"forces --model reynolds --set reynolds.cutoff_ratio=-1", "valid (0, 100]"},
        {"forces --model reynolds --speed nan", "--speed: 'nan' is not a finite number"},
        {"forces --model reynolds --speed 1m/s",
         "--speed: '1m/s' is not a finite number: write the number alone, without a unit"},
        {"forces --model reynolds --radius 0", "--radius = 0 m is out of range"},
        {"forces --model reynolds --radius 1e300",
         "--radius = 1e+300 m is out of range: valid (0, 1]"},
        {"forces --model reynolds --speed 1e300", "--speed = 1e+300 m/s is out of range"},
        {"forces --model reynolds --slip -2e3", "--slip = -2000 m/s is out of range"},
        {"forces --model reynolds --preset steal1", "did you mean 'steel1'"},
        {"forces --model reynols", "did you mean 'reynolds'"},
        {"forces --model reynolds --bogus", "unknown option '--bogus'"},
        {"forces", "no model given"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        struct test_run r = run_cli(cases[k].args, true);
        if (r.code != 2)
            fail_msg("'%s' exited %d, expected 2:\n%s", cases[k].args, r.code, r.out);
        CHECK_CONTAINS(r.out, "wetdem: ");
        CHECK_CONTAINS(r.out, cases[k].message);
        free(r.out);
    }
}

/* A command line, the text its output must contain and its exit code. */
struct cli_case {
    const char *args, *message;
    int code;
};

/* Runs every case and checks its exit code and message. */
static void check_cli_cases(const struct cli_case* cases, size_t n)
{
    for (size_t k = 0; k < n; k++) {
        struct test_run r = run_cli(cases[k].args, true);
        if (r.code != cases[k].code)
            fail_msg("'%s' exited %d, expected %d:\n%s", cases[k].args, r.code, cases[k].code,
                     r.out);
        CHECK_CONTAINS(r.out, cases[k].message);
        free(r.out);
    }
}

/* Every command rejects a bad option before it reads a file: exit code 2, the option named,
 * a hint for a near-miss spelling (one or two letters off, as wetdem_param_suggest measures
 * it), none for a word far from every option, and a note for an option left without its
 * value (an unknown option given last is unknown: fit and track said it "needs a value"). */
static void test_cli_bad_options_get_hints(void** state)
{
    (void)state;
    static const struct cli_case cases[] = {
        {"run none.ini --otu d", "run: unexpected argument '--otu' (did you mean '--out'?)", 2},
        {"run none.ini --jsno", "(did you mean '--json'?)", 2},
        {"run none.ini --restrat c.ckpt", "(did you mean '--restart'?)", 2},
        {"run none.ini --out", "run: --out needs a value (a directory)\nusage: wetdem run", 2},
        {"run none.ini --set", "run: --set needs a value (KEY=VALUE)\n", 2},
        {"sweep none.ini --set", "sweep: --set needs a value (KEY=VALUE)\n", 2},
        {"sweep none.ini --out", "sweep: --out needs a value (a file, FILE.csv)\n", 2},
        {"map none.ini --set", "map: --set needs a value (KEY=VALUE)\n", 2},
        {"map none.ini --out", "map: --out needs a value (a file, FILE.csv)\n", 2},
        {"fit none.ini --set", "fit: --set needs a value (KEY=VALUE)\n", 2},
        {"fit none.ini --out", "fit: --out needs a value (a file)\n", 2},
        {"track dots.csv --frames", "track: --frames needs a value (a file, FILE.csv)\n", 2},
        {"run none.ini --zzzzzzzz", "unexpected argument '--zzzzzzzz'\nusage: wetdem run", 2},
        {"sweep none.ini --parma a",
         "sweep: unexpected argument '--parma' (did you mean '--param'?)", 2},
        {"map none.ini --lgo2", "map: unexpected argument '--lgo2' (did you mean '--log2'?)", 2},
        {"sweep none.ini --values 1:2:3 --param",
         "sweep: --param needs a value (a scenario key or model parameter)", 2},
        {"map none.ini --param2", "map: --param2 needs a value (a scenario key or model parameter)",
         2},
        {"fit none.ini --dat d.csv", "fit: unknown option '--dat' (did you mean '--data'?)", 2},
        {"fit none.ini --zzzzzzzz 1", "fit: unknown option '--zzzzzzzz'\n", 2},
        {"forces --model reynolds --radus 1", "unknown option '--radus' (did you mean '--radius'?)",
         2},
        {"track dots.csv --fsp 30", "track: unknown option '--fsp' (did you mean '--fps'?)", 2},
        /* an unknown option given last is unknown, not one whose value is missing */
        {"fit none.ini --jsno", "fit: unknown option '--jsno'\n", 2},
        {"fit none.ini --outt", "fit: unknown option '--outt' (did you mean '--out'?)", 2},
        {"fit none.ini --max-iter", "fit: option '--max-iter' needs a value", 2},
        {"track dots.csv --fps=5000", "track: unknown option '--fps=5000'\n", 2},
        {"track dots.csv --framse", "track: unknown option '--framse' (did you mean '--frames'?)",
         2},
        {"track dots.csv --window", "track: option --window needs a value", 2},
    };
    check_cli_cases(cases, sizeof cases / sizeof cases[0]);
}

/* More --set options than a command keeps (256) are refused as such by run, sweep, map and fit;
 * sweep, map and fit called the 257th "unexpected argument '--set'" (or unknown option). */
static void test_cli_too_many_set_options(void** state)
{
    (void)state;
    static const char* const cmds[] = {"run none.ini", "sweep none.ini", "map none.ini",
                                       "fit none.ini"};
    static char args[257 * 12 + 64]; /* (within test_run_cli's command of 4 kB) */
    for (size_t c = 0; c < sizeof cmds / sizeof cmds[0]; c++) {
        size_t used = (size_t)snprintf(args, sizeof args, "%s", cmds[c]);
        for (int k = 0; k < 257; k++)
            used += (size_t)snprintf(args + used, sizeof args - used, " --set x.y=1");
        struct test_run r = run_cli(args, true);
        assert_int_equal(r.code, 2);
        CHECK_CONTAINS(r.out, "more than 256 --set options");
        free(r.out);
    }
}

/* An option that takes one value, given twice, is refused by every command: the later value
 * replaced the earlier unseen (`fit --fit A --fit B` fitted B alone, `sweep --param A --param
 * B` swept B, `track --fps 5000 --fps 4000` ran at 4000). Repeatable options (--set, --model)
 * and flags without a value stay as they were. */
static void test_cli_single_options_given_twice(void** state)
{
    (void)state;
    static const struct cli_case cases[] = {
        {"run none.ini --out a --out b", "run: --out is given twice: give it once", 2},
        {"run none.ini --restart a --restart b", "run: --restart is given twice", 2},
        {"sweep none.ini --param collision.stokes --param collision.angle_deg --values 1:2:2",
         "sweep: --param is given twice: give it once", 2},
        {"sweep none.ini --param a.b --values 1:2:2 --values 1:3:2", "--values is given twice", 2},
        {"map none.ini --values2 1:2:2 --values2 1:3:2", "map: --values2 is given twice", 2},
        {"map none.ini --out a.csv --out b.csv", "map: --out is given twice", 2},
        {"fit none.ini --data d.csv --fit glass.p_gt --fit fluid.viscosity",
         "fit: --fit is given twice: give it once", 2},
        {"fit none.ini --max-iter 5 --max-iter 6", "fit: --max-iter is given twice", 2},
        {"forces --model reynolds --radius 1e-3 --radius 2e-3", "forces: --radius is given twice",
         2},
        {"track dots.csv --fps 5000 --fps 4000 --pixel-size 1e-4",
         "track: --fps is given twice: give it once", 2},
        {"track dots.csv --fps 5000 --pixel-size 1e-4 --frames a.csv --frames b.csv",
         "track: --frames is given twice", 2},
        {"forces --model reynolds --model hertz --set fluid.viscosity=0.1 --set sim.gravity_z=0 "
         "--log --log",
         "gap [m],f_normal [N]", 0},
    };
    check_cli_cases(cases, sizeof cases / sizeof cases[0]);
}

/* A --set that would never be used is refused with exit 2: a second --set of one key (also
 * under its other name, or speed after stokes) replaced the first unseen, a --set of the key
 * a sweep or map varies was replaced by every point's value, and one of the Stokes number or
 * an angle given per data row of a fit by every row. */
static void test_cli_set_overrides_never_used(void** state)
{
    (void)state;
    static const struct cli_case cases[] = {
        {"run examples/scenarios/dry_hertz.ini --check --set collision.speed=0.3 "
         "--set collision.speed=0.4",
         "--set collision.speed=0.3 and --set collision.speed=0.4 set one key: give it once", 2},
        {"run examples/scenarios/nijssen_head_on.ini --check --set nijssen.cutoff_ratio=2 "
         "--set model.nijssen.cutoff_ratio=3",
         "set one key: give it once", 2},
        {"run examples/scenarios/nijssen_head_on.ini --check --set collision.stokes=4 "
         "--set collision.speed=0.3",
         "set one key (the impact, by speed or by stokes", 2},
        {"run examples/scenarios/nijssen_head_on.ini --check --set collision.stokes=4 "
         "--set collision.angle_deg=30",
         "is valid", 0},
        {"sweep examples/scenarios/dry_hertz.ini --param collision.speed --values 0.1:0.2:2 "
         "--set collision.speed=0.5",
         "sweep: --set collision.speed=0.5 sets collision.speed, which --param collision.speed "
         "varies: each point's value would replace it",
         2},
        {"sweep examples/scenarios/nijssen_head_on.ini --param collision.stokes --values 1:2:2 "
         "--set collision.speed=0.5",
         "which --param collision.stokes varies (the impact", 2},
        {"map examples/scenarios/dry_hertz.ini --param collision.speed --values 0.1:0.2:2 "
         "--param2 collision.angle_deg --values2 0:10:2 --set collision.angle_deg=5",
         "map: --set collision.angle_deg=5 sets collision.angle_deg, which --param2", 2},
        {"fit examples/fit/punch_db_c.ini --data examples/fit/punch_0deg.csv --fit glass.p_gt "
         "--set collision.stokes=2",
         "fit: --set collision.stokes=2: collision.stokes would never be used: every data row "
         "sets it",
         2},
    };
    check_cli_cases(cases, sizeof cases / sizeof cases[0]);
}

/* A --set KEY=VALUE without its section suggests the one section of the scenario's engine
 * that has KEY ([collision] stokes of a binary collision, [davis] stokes of the pairwise
 * engine); with none or several (film: every [material.NAME]) the example stays. */
static void test_cli_set_without_section_suggests_it(void** state)
{
    (void)state;
    static const struct cli_case cases[] = {
        {"run examples/scenarios/nijssen_head_on.ini --check --set stokes=3",
         "wetdem: --set 'stokes=3': expected section.key=value (did you mean "
         "'collision.stokes=3'?)\n",
         2},
        {"sweep examples/scenarios/nijssen_head_on.ini --param collision.speed --values 1:2:2 "
         "--set angle_deg=30",
         "(did you mean 'collision.angle_deg=30'?)", 2},
        {"run examples/scenarios/davis_three.ini --check --set stokes=5",
         "(did you mean 'davis.stokes=5'?)", 2},
        {"run examples/scenarios/nijssen_head_on.ini --check --set film=1e-5",
         "--set 'film=1e-5': expected section.key=value, e.g. --set collision.stokes=50", 2},
    };
    check_cli_cases(cases, sizeof cases / sizeof cases[0]);
}

/* Messages that named the wrong thing: a --param without its section called "--set 'stokes=0'"
 * (an option the user never typed, a value from nowhere), --log2 called --log, a NAME with a
 * dot was suggested as itself, an upper-case model got no hint, --fd-step 0 came back as the
 * library's list of five options, an empty --fit key was skipped, a many-particle scenario
 * fitted blamed a data point, a contact counted twice ran, a preset's name on a section
 * without its preset ran at the field defaults unsaid. */
static void test_cli_messages_name_what_is_wrong(void** state)
{
    (void)state;
    const char* head = "examples/scenarios/nijssen_head_on.ini";
    char args[10][400];
    snprintf(args[0], 400, "sweep %s --param stokes --values 10:20:2", head);
    snprintf(args[1], 400,
             "map %s --param collision.stokes --values 10:20:2 --param2 collision.angle_deg "
             "--values2 0:80:2 --log2",
             head);
    snprintf(args[2], 400, "fit %s --data examples/fit/punch_0deg.csv --fit glass.p_gt --fd-step 0",
             "examples/fit/punch_db_c.ini");
    snprintf(args[3], 400, "fit %s --data examples/fit/punch_0deg.csv --fit glass.p_gt,",
             "examples/fit/punch_db_c.ini");
    snprintf(args[4], 400,
             "fit examples/scenarios/many_settling.ini --data examples/fit/punch_0deg.csv --fit "
             "glass.p_gt");
    snprintf(args[5], 400, "run %s --check --set 'models.force=nijssen hertz'", head);
    /* refused by the library when the run starts (WETDEM_ERR_INVALID: nijssen's h_min at
       its cut-off): input, exit 2 */
    snprintf(args[6], 400,
             "run examples/scenarios/nijssen_roughness.ini --set material.rough.roughness=0.01");
    const struct cli_case cases[] = {
        {args[0], "--param 'stokes': expected section.key, e.g. --param collision.stokes", 2},
        {args[1], "'0:80:2' with --log2 needs A > 0", 2},
        {args[2], "fit: --fd-step 0: must be in (0, 1)", 2},
        {args[3], "--fit 'glass.p_gt,': an empty key", 2},
        {args[4], "is a many-particle scenario; fit calibrates binary collisions", 2},
        {args[5], "model 'hertz' and model 'nijssen' both give the normal contact force", 2},
        {"describe NIJSSEN", "(did you mean 'nijssen'?)", 2},
        {args[6], "is in solid contact already at the edge of its range", 2},
    };
    check_cli_cases(cases, sizeof cases / sizeof cases[0]);
    const char* dir = getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp";
    char path[300], cmd[400];
    snprintf(path, sizeof path, "%s/wetdem_cli_names_%d.ini", dir, (int)getpid());
    const char* text[2] = {"[collision]\nstriker = delrin\nspeed = 0.5\n[material.delrin]\n"
                           "roughness = 1e-7\n[models]\nforce = hertz\n",
                           "[collision]\nstriker = a\nspeed = 0.5\n[material.a.b]\n"
                           "preset = glass\n[models]\nforce = hertz\n"};
    const char* want[2] = {"[material.delrin] has the name of a preset but no 'preset = delrin'",
                           "unknown section [material.a.b]: 'a.b' is not a NAME"};
    for (int k = 0; k < 2; k++) {
        FILE* f = fopen(path, "w");
        assert_non_null(f);
        fputs(text[k], f);
        fclose(f);
        snprintf(cmd, sizeof cmd, "run %s --check", path);
        struct test_run r = run_cli(cmd, true);
        assert_int_equal(r.code, k ? 2 : 0); /* (the first a warning) */
        CHECK_CONTAINS(r.out, want[k]);
        free(r.out);
    }
    remove(path);
}

/* Models chosen where they do not belong are named with their kind ("an impulse model"); a
 * minimum-separation slot holding a force model is refused in both engines (the many-particle
 * one summed it as a force). */
static void test_cli_model_of_the_wrong_kind(void** state)
{
    (void)state;
    static const struct cli_case cases[] = {
        {"run examples/scenarios/nijssen_head_on.ini --set models.min_separation=hard --check",
         "'hard' is an impulse model, not a minimum-separation model", 2},
        {"run examples/scenarios/many_settling.ini --set models.force=hard --check",
         "'hard' is an impulse model: the many-particle mode sums force models", 2},
        /* (the many-particle engine summed nijssen as a force, the run valid) */
        {"run examples/scenarios/many_settling.ini --set models.min_separation=nijssen --check",
         "'nijssen' is a fluid model, not a minimum-separation model", 2},
    };
    check_cli_cases(cases, sizeof cases / sizeof cases[0]);
}

/* Integrator parameters by the library's names, cvode.rtol, are the [integrator] keys, as
 * `wetdem describe cvode` says (they were refused as an unknown section [cvode]). */
static void test_cli_integrator_names_in_set(void** state)
{
    (void)state;
    static const struct cli_case cases[] = {
        {"run examples/scenarios/nijssen_head_on.ini --set cvode.rtol=1e-9 --check", "is valid", 0},
        {"run examples/scenarios/nijssen_head_on.ini --set verlet.dt_fraction=0.01 --check",
         "is valid", 0},
        {"run examples/scenarios/nijssen_head_on.ini --set cvode.rtol=1 --check",
         "--set integrator.rtol=1: rtol = 1 [-] is out of range", 2},
    };
    check_cli_cases(cases, sizeof cases / sizeof cases[0]);
}

/* Writes text to a new temporary file; returns its path (static buffer). */
static const char* temp_scenario(const char* text)
{
    static char path[64];
    snprintf(path, sizeof path, "/tmp/wetdem_test_cli_XXXXXX");
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    test_write_file(path, text);
    return path;
}

/* Runs "'<CLI>' args" with stderr to the pipe read and stdout where args send it; the exit
 * code, stderr in *err (caller frees). */
static int run_cli_stderr(const char* args, char** err)
{
    char cmd[1024];
    snprintf(cmd, sizeof cmd, "'%s' %s", test_cli_path(), args);
    FILE* p = popen(cmd, "r");
    assert_non_null(p);
    *err = test_slurp(p, NULL);
    int status = pclose(p);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/* The last percentage of a progress line in text ("( 24.5 %)"), -1 if there is none. */
static double last_percent(const char* text)
{
    double pct = -1;
    for (const char* at = strstr(text, " s ("); at; at = strstr(at + 1, " s ("))
        pct = strtod(at + 4, NULL);
    return pct;
}

/* Progress of a binary collision and of a pairwise run on a terminal: a line "wetdem: t = T
 * of T_END s (P %), E s elapsed, about L s left" on stderr, redrawn at most twice a second and
 * first after half a second, the last one, at t_end, drawn and then cleared; nothing on
 * stdout, nothing when stderr is not a terminal, nothing for a short run that ends before
 * t_end (a collision that separated). Such runs told nothing until they ended. */
static void test_cli_run_progress_on_a_terminal(void** state)
{
    (void)state;
    if (!getenv("WETDEM_CLI"))
        skip();
    /* dry_hertz.ini separates at 2.46e-4 s; with t_end = 2e-4 s both integrators run to t_end */
    static const char* const runs[] = {
        "run examples/scenarios/dry_hertz.ini --set collision.t_end=2e-4",
        ("run examples/scenarios/dry_hertz.ini --set collision.t_end=2e-4 --set "
         "integrator.name=cvode"),
        "run examples/scenarios/davis_three.ini", /* (FA: runs to t_end) */
    };
    for (size_t k = 0; k < sizeof runs / sizeof runs[0]; k++) {
        char args[512], *err;
        snprintf(args, sizeof args, "%s 2>&1 > /dev/null", runs[k]);
        assert_int_equal(run_cli_stderr(args, &err), 0);
        assert_string_equal(err, ""); /* (not a terminal) */
        free(err);
        snprintf(args, sizeof args, "%s > /dev/null", runs[k]);
        char* tty = test_run_cli_on_terminal(args);
        CHECK_CONTAINS(tty, k < 2 ? "\rwetdem: t = 0.0002 of 0.0002 s (100.0 %), "
                                  : "\rwetdem: t = 0.06928 of 0.06928 s (100.0 %), ");
        CHECK_CONTAINS(tty, " s left   \r      "); /* (cleared) */
        free(tty);
    }
    /* stdout to a file: the summary there, and no progress */
    char out[64] = "/tmp/wetdem_test_progress_XXXXXX", args[512];
    int fd = mkstemp(out);
    assert_true(fd >= 0);
    close(fd);
    snprintf(args, sizeof args, "%s > %s", runs[0], out);
    free(test_run_cli_on_terminal(args));
    char* text = test_read_file(out, NULL);
    assert_non_null(text);
    CHECK_CONTAINS(text, "scenario examples/scenarios/dry_hertz.ini: verlet integrator");
    assert_null(strstr(text, "wetdem: t = "));
    free(text);
    remove(out);
    /* a short run that separates: nothing (its few ms are below the first half second) */
    char* tty = test_run_cli_on_terminal("run examples/scenarios/dry_hertz.ini > /dev/null");
    assert_string_equal(tty, "");
    free(tty);
    /* a long one (4e6 steps, some 2 s): lines before the last, whose estimate comes down */
    tty =
        test_run_cli_on_terminal("run examples/scenarios/dry_hertz.ini --set collision.t_end=2e-4 "
                                 "--set integrator.dt=5e-11 > /dev/null");
    const char* first = strstr(tty, "\rwetdem: t = ");
    assert_non_null(first);
    double pct = last_percent(first);
    CHECK_CONTAINS(first, " s elapsed, about ");
    if (!(strtod(first + strlen("\rwetdem: t = "), NULL) < 2e-4 && pct == 100))
        fail_msg("expected lines before the last:\n%s", tty);
    free(tty);
}

/* Ctrl-C over a run's progress line (a pairwise run with --out, on a terminal): the notice
 * erases the line ("\r\033[K") and starts where it stood; it started on the next line, the
 * progress line left above it. No progress line is drawn after it. */
static void test_cli_signal_notice_starts_on_a_clean_line(void** state)
{
    (void)state;
    char dir[] = "/tmp/wetdem_test_cli_signal_XXXXXX";
    assert_non_null(mkdtemp(dir));
    int master;
    pid_t pid = forkpty(&master, NULL, NULL, NULL);
    assert_true(pid >= 0);
    if (pid == 0) {
        char cmd[2048]; /* (some 4 s without the signal) */
        snprintf(cmd, sizeof cmd,
                 "exec env OMP_NUM_THREADS=1 '%s' run examples/scenarios/davis_three.ini --set "
                 "davis.t_star_end=1e5 --out %s/out > /dev/null",
                 test_cli_path(), dir);
        execl("/bin/sh", "sh", "-c", cmd, (char*)NULL);
        _exit(127);
    }
    char buf[16384];
    size_t n = 0;
    ssize_t got;
    bool sent = false;
    while (n + 1 < sizeof buf && (got = read(master, buf + n, sizeof buf - n - 1)) > 0) {
        n += (size_t)got;
        buf[n] = '\0';
        if (!sent && strstr(buf, " s left") && test_signal_caught(pid, SIGINT)) {
            kill(pid, SIGINT); /* (a progress line stands: the first comes after 0.5 s) */
            sent = true;
        }
    }
    buf[n] = '\0';
    int status;
    waitpid(pid, &status, 0);
    close(master);
    if (!sent)
        fail_msg("no progress line to interrupt:\n%s", buf);
    assert_true(WIFEXITED(status) && WEXITSTATUS(status) == 128 + SIGINT);
    const char* notice = strstr(buf, "wetdem: run: stopping");
    assert_non_null(notice);
    assert_true(notice - buf >= 4 && memcmp(notice - 4, "\r\033[K", 4) == 0);
    assert_null(strstr(notice, " s left")); /* nothing drawn after it */
    CHECK_CONTAINS(notice, "wetdem: run: interrupted by signal 2");
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    assert_int_equal(system(cmd), 0);
}

/* A table that cannot be written to standard output (a full disk, a closed descriptor) is an
 * error with the reason, exit 1: it was exit 0 with a truncated table, and a redirected
 * `wetdem docs-models > docs/models.md` on a full disk left half a file. A command that
 * writes nothing there is not affected by a closed stdout. */
static void test_cli_stdout_write_failures(void** state)
{
    (void)state;
    static const struct {
        const char* args;
        int code;
        const char* message;
    } cases[] = {
        {"forces hertz 2>&1 >/dev/full", 1, "cannot write standard output: No space left"},
        {"models 2>&1 >/dev/full", 1, "cannot write standard output: No space left"},
        {"describe hertz 2>&1 >&-", 1, "cannot write standard output: Bad file descriptor"},
        {"--version 2>&1 >/dev/full", 1, "cannot write standard output"},
        {"sweep examples/scenarios/dry_hertz.ini --param collision.speed --values 0.1:0.5:3 "
         "2>&1 >/dev/full",
         1, "cannot write standard output: No space left"},
        {"describe hertz 2>&1 >/dev/null", 0, ""},
        {"run examples/scenarios/dry_hertz.ini --check --json 2>&1 >/dev/null", 0, ""},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        char* err;
        int code = run_cli_stderr(cases[k].args, &err);
        if (code != cases[k].code)
            fail_msg("'%s' exited %d, expected %d:\n%s", cases[k].args, code, cases[k].code, err);
        CHECK_CONTAINS(err, cases[k].message);
        free(err);
    }
}

/* The text after `"key": ` in a JSON line, up to the next comma or brace. */
static void json_token(const char* json, const char* key, char* out, size_t n)
{
    char pattern[64];
    snprintf(pattern, sizeof pattern, "\"%s\": ", key);
    const char* at = strstr(json, pattern);
    assert_non_null(at);
    at += strlen(pattern);
    size_t len = strcspn(at, ",}");
    assert_true(len < n);
    memcpy(out, at, len);
    out[len] = '\0';
}

/* `run --check` reports the St_n the run then uses, bit for bit: both take the spheres'
 * masses from wetdem_material_sphere_mass. Before, the check computed them with pow(R, 3) and the run
 * with R R R, and a scenario asking for stokes = 100 was checked as 99.999999999999986 and run
 * as 99.999999999999972. */
static void test_cli_check_reports_the_stokes_number_run(void** state)
{
    (void)state;
    char dir[] = "/tmp/wetdem_test_cli_check_st_XXXXXX";
    assert_non_null(mkdtemp(dir));
    static const char* const scenarios[] = {"nijssen_head_on.ini", "nijssen_oblique.ini",
                                            "punch_oblique.ini", "wall_collision.ini"};
    for (size_t k = 0; k < sizeof scenarios / sizeof scenarios[0]; k++) {
        char args[400], checked[64], run[64];
        snprintf(args, sizeof args, "run examples/scenarios/%s --check --json", scenarios[k]);
        struct test_run r = run_cli(args, false);
        assert_int_equal(r.code, 0);
        json_token(r.out, "stokes_n", checked, sizeof checked);
        free(r.out);
        snprintf(args, sizeof args, "run examples/scenarios/%s --json --out %s/%zu", scenarios[k],
                 dir, k);
        r = run_cli(args, false);
        assert_int_equal(r.code, 0);
        json_token(r.out, "stokes_n", run, sizeof run);
        free(r.out);
        if (strcmp(checked, run) != 0)
            fail_msg("%s: --check St_n %s, the run's %s", scenarios[k], checked, run);
        snprintf(args, sizeof args, "rm -r %s/%zu", dir, k);
        assert_int_equal(system(args), 0);
    }
    assert_int_equal(rmdir(dir), 0);
}

/* Every engine's summary.json (and --json) names the command that made it, --set included,
 * as the CSV files' "# command:" line does: the overrides were in no file of a many-particle
 * or pairwise run, and a pairwise summary named neither the scenario nor the git version. */
static void test_cli_summary_names_its_command(void** state)
{
    (void)state;
    char dir[] = "/tmp/wetdem_test_cli_command_XXXXXX";
    assert_non_null(mkdtemp(dir));
    static const struct {
        const char* scenario;
        const char* set;
    } cases[] = {
        {"dry_hertz.ini", "collision.speed=0.2"},
        {"davis_three.ini", "davis.stokes=3"},
        {"many_stokes_cradle.ini", "run.steps=2"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        char args[400], want[600], path[300];
        snprintf(args, sizeof args, "run examples/scenarios/%s --set '%s' --out %s/%zu",
                 cases[k].scenario, cases[k].set, dir, k);
        struct test_run r = run_cli(args, false);
        assert_int_equal(r.code, 0);
        free(r.out);
        snprintf(path, sizeof path, "%s/%zu/summary.json", dir, k);
        char* json = test_read_file(path, NULL);
        assert_non_null(json);
        snprintf(want, sizeof want,
                 "\"scenario\": \"examples/scenarios/%s\", \"command\": [\"wetdem\", \"run\", "
                 "\"examples/scenarios/%s\", \"--set\", \"%s\", \"--out\", \"%s/%zu\"]",
                 cases[k].scenario, cases[k].scenario, cases[k].set, dir, k);
        if (k == 0) /* the two-body summary puts a field on each line */
            snprintf(want, sizeof want,
                     "\"scenario\": \"examples/scenarios/%s\",\n  \"command\": [\"wetdem\", "
                     "\"run\", \"examples/scenarios/%s\", \"--set\", \"%s\", \"--out\", "
                     "\"%s/%zu\"]",
                     cases[k].scenario, cases[k].scenario, cases[k].set, dir, k);
        CHECK_CONTAINS(json, want);
        CHECK_CONTAINS(json, "\"git\": \"");
        free(json);
    }
    /* and the many-particle run's global.csv, which the library writes, as its first lines */
    char path[300], want[600];
    snprintf(path, sizeof path, "%s/2/global.csv", dir);
    char* csv = test_read_file(path, NULL);
    assert_non_null(csv);
    const char* git = "# wetdem " WETDEM_VERSION " (git ";
    assert_memory_equal(csv, git, strlen(git));
    const char* command = strstr(csv, "\n# command: ");
    assert_non_null(command);
    snprintf(want, sizeof want,
             "\n# command: wetdem run examples/scenarios/many_stokes_cradle.ini --set run.steps=2 "
             "--out %s/2\n# many-particle run: global quantities\ntime [s],step [count],",
             dir);
    assert_memory_equal(command, want, strlen(want));
    free(csv);
    char cmd[200];
    snprintf(cmd, sizeof cmd, "rm -r %s", dir);
    assert_int_equal(system(cmd), 0);
}

/* Whether text[0..n) is one number as the CSVs write them (nan and inf included). */
static bool csv_number(const char* text, size_t n)
{
    char buf[64], *end;
    if (n == 0 || n >= sizeof buf)
        return false;
    memcpy(buf, text, n);
    buf[n] = '\0';
    strtod(buf, &end);
    return *end == '\0';
}

/* Whether text[0..n) is a whole number (a leading '-' allowed: separated_sphere -1 for none). */
static bool csv_integer(const char* text, size_t n)
{
    size_t k = n > 1 && text[0] == '-';
    if (k == n)
        return false;
    for (; k < n; k++)
        if (text[k] < '0' || text[k] > '9')
            return false;
    return true;
}

/* The shape every CSV wetdem writes has (docs/concepts.md, "CSV files"): the provenance lines
 * "# wetdem VERSION (git HASH)" and "# command: wetdem ...", any '#' lines, then a header
 * whose every column is "name [unit]" (a name of letters, digits, '_' and '.'; a unit with no
 * bracket, comma or outer blank), then at least one row of as many fields, '#' lines allowed
 * between and after the rows. A row's field must fit its column's unit: a number but in a
 * [word] column, a whole number in a [count] or [index] column, 0 or 1 in a [0/1] column;
 * a zero is "0", never "-0" (docs/concepts.md). `what` names the file in a failure. */
static void check_csv_shape(const char* what, const char* text)
{
    const char* first = "# wetdem " WETDEM_VERSION " (git ";
    if (strncmp(text, first, strlen(first)) != 0)
        fail_msg("%s: the first line is not '%s...)': '%.80s'", what, first, text);
    const char* line = strchr(text, '\n');
    if (!line || strncmp(line + 1, "# command: wetdem ", 18) != 0)
        fail_msg("%s: the second line is not '# command: wetdem ...'", what);
    while (line && line[1] == '#')
        line = strchr(line + 1, '\n');
    if (!line || !line[1])
        fail_msg("%s: no header line after the '#' lines", what);
    line++;
    enum { MAX_COLS = 128 };
    char units[MAX_COLS][32];
    size_t n_cols = 0, len = strcspn(line, "\n");
    for (const char* f = line; f < line + len; n_cols++) {
        const char* end = memchr(f, ',', (size_t)(line + len - f));
        end = end ? end : line + len;
        size_t n = (size_t)(end - f);
        const char* open = memchr(f, '[', n);
        size_t name = open ? (size_t)(open - f) : 0;
        bool ok = open && name >= 2 && open[-1] == ' ' && end[-1] == ']' && n_cols < MAX_COLS;
        for (size_t k = 0; ok && k + 1 < name; k++)
            ok = (f[k] >= 'a' && f[k] <= 'z') || (f[k] >= 'A' && f[k] <= 'Z') ||
                 (f[k] >= '0' && f[k] <= '9') || f[k] == '_' || f[k] == '.';
        size_t unit = ok ? n - name - 2 : 0; /* between the brackets */
        ok = ok && unit > 0 && unit < sizeof units[0] && open[1] != ' ' && end[-2] != ' ' &&
             !memchr(open + 1, '[', unit) && !memchr(open + 1, ']', unit);
        if (!ok)
            fail_msg("%s: column %zu '%.*s' is not 'name [unit]' in the header '%.*s'", what,
                     n_cols + 1, (int)n, f, (int)len, line);
        snprintf(units[n_cols], sizeof units[0], "%.*s", (int)unit, open + 1);
        f = end + (end < line + len);
    }
    size_t rows = 0;
    for (const char* row = line + len; *row && row[1]; row += len) {
        row++;
        len = strcspn(row, "\n");
        if (row[0] == '#')
            continue;
        rows++;
        size_t c = 0;
        for (const char* f = row; c < MAX_COLS; c++) {
            const char* end = memchr(f, ',', (size_t)(row + len - f));
            end = end ? end : row + len;
            size_t n = (size_t)(end - f);
            const char* u = c < n_cols ? units[c] : "";
            bool ok = c < n_cols &&
                      (strcmp(u, "word") == 0 ||
                       (strcmp(u, "0/1") == 0 ? n == 1 && (*f == '0' || *f == '1')
                        : strcmp(u, "count") == 0 || strcmp(u, "index") == 0 ? csv_integer(f, n)
                                                                             : csv_number(f, n)));
            if (!ok)
                fail_msg("%s: row %zu, column %zu: '%.*s' %s", what, rows, c + 1, (int)n, f,
                         c < n_cols ? "does not fit its unit" : "is beyond the header's columns");
            if (strcmp(u, "word") != 0 && n > 1 && f[0] == '-' && strtod(f, NULL) == 0.0)
                fail_msg("%s: row %zu, column %zu: '%.*s' is a zero with a sign", what, rows, c + 1,
                         (int)n, f);
            if (end == row + len)
                break;
            f = end + 1;
        }
        if (c + 1 != n_cols)
            fail_msg("%s: row %zu has %zu fields, the header %zu columns", what, rows, c + 1,
                     n_cols);
    }
    if (rows == 0)
        fail_msg("%s: no rows", what);
}

/* Every CSV wetdem writes has the shape of check_csv_shape: forces, the trajectory and events
 * of a run of each engine, the tables of sweep (both engines) and map, the three of fit (its
 * standard output, --out, --curve), track --frames and the library's global CSV of a
 * many-particle run. Three of them had columns "name_unit" (gap_m, time_s, kinetic_J) and no
 * brackets, global.csv put its version line before the provenance, and a line break in an
 * argument ended the command's comment line. Zeros that came with a sign were written "-0":
 * the y velocity -U sin 0 of a head-on run's first trajectory row, the smoothed vy and spin
 * of track --frames for dots that move along x without turning, a sweep's value -0. */
static void test_cli_every_csv_has_provenance_and_name_unit_columns(void** state)
{
    (void)state;
    char dir[] = "/tmp/wetdem_test_cli_csv_XXXXXX";
    assert_non_null(mkdtemp(dir));
    { /* dots of two spheres on the line y = 300 px that do not turn: the striker at 2 px a
         frame strikes the resting target at frame 50 and goes on at 0.5, the target at 1.5 */
        char path[400];
        snprintf(path, sizeof path, "%s/still.csv", dir);
        FILE* f = fopen(path, "w");
        assert_non_null(f);
        fputs("frame,sphere,x1,y1,x2,y2,x3,y3\n", f);
        for (int k = 0; k < 100; k++)
            for (int s = 1; s <= 2; s++) {
                double x = s == 1 ? (k < 50 ? 400 + 2.0 * (k - 50) : 400 + 0.5 * (k - 50))
                                  : (k < 50 ? 544 : 544 + 1.5 * (k - 50));
                fprintf(f, "%d,%d,%.4f,300,%.4f,300,%.4f,330\n", k, s, x, x + 30, x);
            }
        assert_int_equal(fclose(f), 0);
    }
    static const struct {
        const char* args;     /* %s: the directory */
        const char* files[3]; /* in the directory; none: standard output */
    } cases[] = {
        {"forces --model reynolds mindlin --slip 0.01 --gaps 1e-6:1e-5:3", {NULL}},
        {"run examples/scenarios/nijssen_oblique.ini --out %s/soft",
         {"soft/trajectory.csv", "soft/events.csv"}},
        {"run examples/scenarios/davis_three.ini --out %s/pairwise",
         {"pairwise/trajectory.csv", "pairwise/events.csv"}},
        {"sweep examples/scenarios/nijssen_head_on.ini --param collision.stokes --values 10:30:2",
         {NULL}},
        {"sweep examples/scenarios/davis_three.ini --param davis.stokes --values 4:6:2", {NULL}},
        {"map examples/scenarios/dry_hertz.ini --param collision.speed --values 0.1:0.2:2 "
         "--param2 collision.angle_deg --values2 0:30:2",
         {NULL}},
        {"fit examples/fit/punch_db_c.ini --data examples/fit/punch_0deg.csv --fit glass.p_gt "
         "--init 4e6 --out %s/fit.csv --curve %s/curve.csv --curve-points 3",
         {NULL, "fit.csv", "curve.csv"}},
        {"track examples/tracks/punch_45deg.csv --fps 5000 --pixel-size 175e-6 --frames "
         "%s/frames.csv",
         {"frames.csv"}},
        /* a line break in an argument (here the file name) continues the command's comment */
        {"track examples/tracks/punch_45deg.csv --fps 5000 --pixel-size 175e-6 --frames "
         "\"%s/two\nlines.csv\"",
         {"two\nlines.csv"}},
        {"run examples/scenarios/many_stokes_cradle.ini --set run.steps=2 --out %s/many",
         {"many/global.csv"}},
        {"run examples/scenarios/dry_hertz.ini --out %s/head_on", {"head_on/trajectory.csv"}},
        {"track %s/still.csv --fps 5000 --pixel-size 1e-4 --frames %s/still_frames.csv",
         {"still_frames.csv"}},
        {"sweep examples/scenarios/nijssen_head_on.ini --param collision.spin_z --values -0:1:2",
         {NULL}},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        char args[600];
        snprintf(args, sizeof args, cases[k].args, dir, dir, dir);
        struct test_run r = run_cli(args, false);
        if (r.code != 0)
            fail_msg("wetdem %s: exit %d", args, r.code);
        for (size_t f = 0; f == 0 || (f < 3 && cases[k].files[f]); f++) {
            char what[800], path[400];
            if (!cases[k].files[f]) {
                snprintf(what, sizeof what, "the output of wetdem %s", args);
                check_csv_shape(what, r.out);
                continue;
            }
            snprintf(path, sizeof path, "%s/%s", dir, cases[k].files[f]);
            snprintf(what, sizeof what, "%s of wetdem %s", cases[k].files[f], args);
            char* text = test_read_file(path, NULL);
            if (!text)
                fail_msg("%s is missing", what);
            check_csv_shape(what, text);
            free(text);
        }
        free(r.out);
    }
    char cmd[200];
    snprintf(cmd, sizeof cmd, "rm -r %s", dir);
    assert_int_equal(system(cmd), 0);
}

/* Output named /dev/stdout goes through standard output in place, also when that is a
 * regular file (`> FILE`): the CSV of fit --out and track --frames and the summary printed
 * beside it all reach the file. Before, /dev/stdout led to that file, which was replaced by a
 * temporary one renamed over it, and the summary went to the unlinked file and was lost. */
static void test_cli_dev_stdout_output_to_a_redirected_file(void** state)
{
    (void)state;
    char dir[] = "/tmp/wetdem_test_cli_stdout_XXXXXX";
    assert_non_null(mkdtemp(dir));
    static const struct {
        const char* args;
        const char* summary;
        const char* table;
    } cases[] = {
        {"fit examples/fit/punch_db_c.ini --data examples/fit/punch_0deg.csv --fit glass.p_gt "
         "--init 4e6 --out /dev/stdout",
         "parameter [word],unit [word],value [unit],std_error [unit],initial [unit],fitted_as "
         "[word]\nmodel.glass.p_gt,Pa,",
         "\nstokes_n [-],angle_deg [deg],e_n_data [-],e_n_fit [-],e_n_residual [-]\n1.6,0,"},
        {"track examples/tracks/punch_45deg.csv --fps 5000 --pixel-size 175e-6 --frames "
         "/dev/stdout",
         "\ne_n = 0.70", "\nsphere [index],frame [index],time [s],vx_raw [m/s],"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        char args[600], path[300];
        snprintf(path, sizeof path, "%s/out.txt", dir);
        snprintf(args, sizeof args, "%s > %s", cases[k].args, path);
        struct test_run r = run_cli(args, false);
        if (r.code != 0)
            fail_msg("'%s' exited %d", args, r.code);
        free(r.out);
        char* text = test_read_file(path, NULL);
        assert_non_null(text);
        CHECK_CONTAINS(text, cases[k].summary);
        CHECK_CONTAINS(text, cases[k].table);
        free(text);
        test_check_dir(dir, "out.txt\n");
        assert_int_equal(remove(path), 0);
    }
    assert_int_equal(rmdir(dir), 0);
}

/* Numbers a double cannot hold are named as such (they were "not a finite number"), and a
 * file with classic Mac OS line endings (CR only), which inih read as one line, is named as
 * that (it was "no [section] in the file"). */
static void test_cli_numbers_out_of_range_and_cr_lines(void** state)
{
    (void)state;
    static const struct cli_case cases[] = {
        {"run examples/scenarios/dry_hertz.ini --check --set collision.speed=4.9e-324",
         "collision.speed=4.9e-324: below the smallest normal double", 2},
        {"run examples/scenarios/dry_hertz.ini --check --set collision.speed=-1e999",
         "collision.speed=-1e999: beyond the range of a double", 2},
        {"forces --model reynolds --radius 1e-400", "'1e-400' is below the smallest normal double",
         2},
    };
    check_cli_cases(cases, sizeof cases / sizeof cases[0]);
    /* track's counts are read as every count of the command line (sweep's N, fit's
       --max-iter): a whole number, in exponent notation too; 7.5 is none */
    const char* head =
        "track examples/tracks/punch_45deg.csv --fps 5000 --pixel-size 175e-6 --json";
    char cmd[200];
    snprintf(cmd, sizeof cmd, "%s --window 7", head);
    struct test_run seven = run_cli(cmd, false);
    assert_int_equal(seven.code, 0);
    const char* spellings[2] = {"7.0", "0.7e1"};
    for (int k = 0; k < 2; k++) {
        snprintf(cmd, sizeof cmd, "%s --window %s", head, spellings[k]);
        struct test_run same = run_cli(cmd, false);
        assert_int_equal(same.code, 0);
        assert_string_equal(same.out, seven.out);
        free(same.out);
    }
    free(seven.out);
    snprintf(cmd, sizeof cmd, "%s --window 7.5", head);
    struct test_run half = run_cli(cmd, true);
    assert_int_equal(half.code, 2);
    CHECK_CONTAINS(half.out, "--window: '7.5' is not an integer");
    free(half.out);
    const char* path = temp_scenario("[collision]\rspeed = 0.1\r[models]\rforce = hertz\r");
    char args[128];
    snprintf(args, sizeof args, "run %s --check", path);
    struct test_run r = run_cli(args, true);
    assert_int_equal(r.code, 2);
    CHECK_CONTAINS(r.out, ":1: a carriage return inside the line");
    free(r.out);
    remove(path);
}

/* The files of one run are replaced as a set, whole or not at all: when one target cannot be
 * replaced (here events.csv is a directory) the others keep the earlier run's contents, and
 * no temporary or backup file is left. Before, the files renamed ahead of it were the new
 * run's and the rest the old run's. */
static void test_cli_run_outputs_replaced_whole_or_not_at_all(void** state)
{
    (void)state;
    char dir[] = "/tmp/wetdem_test_cli_set_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char args[256], path[300];
    snprintf(args, sizeof args, "run examples/scenarios/dry_hertz.ini --out %s", dir);
    struct test_run r = run_cli(args, true);
    assert_int_equal(r.code, 0);
    free(r.out);
    snprintf(path, sizeof path, "%s/trajectory.csv", dir);
    test_write_file(path, "OLD\n");
    snprintf(path, sizeof path, "%s/events.csv", dir);
    assert_int_equal(remove(path), 0);
    assert_int_equal(mkdir(path, 0755), 0);
    r = run_cli(args, true);
    assert_int_equal(r.code, 1);
    CHECK_CONTAINS(r.out, "events.csv: Is a directory");
    free(r.out);
    snprintf(path, sizeof path, "%s/trajectory.csv", dir);
    char* text = test_read_file(path, NULL);
    assert_non_null(text);
    assert_string_equal(text, "OLD\n");
    free(text);
    snprintf(args, sizeof args, "ls -A %s", dir);
    FILE* p = popen(args, "r");
    char* names = test_slurp(p, NULL);
    pclose(p);
    assert_string_equal(names, "events.csv\nsummary.json\ntrajectory.csv\n");
    free(names);
    snprintf(args, sizeof args, "rm -rf '%s'", dir);
    assert_int_equal(system(args), 0);
}

/* A process killed (SIGKILL) while it replaces the files of a run leaves them in order for the
 * next: killed after one of three files was renamed, or after every target was moved aside
 * (to .NAME.tmpPID.old, the target then missing), its set is completed by the next run that
 * writes there, which says so; a backup of a dead process whose target is missing is put back
 * (even when that run then fails), its cut temporary files are removed, and the files of a
 * live process are left alone. WETDEM_TEST_KILL_AT_RENAME=k kills a run after k renames. */
static void test_cli_run_outputs_recovered_after_a_kill(void** state)
{
    (void)state;
    char dir[] = "/tmp/wetdem_test_cli_kill_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char args[400], b_args[400], path[400], path2[400];
    const char* names[3] = {"trajectory.csv", "events.csv", "summary.json"};
    snprintf(args, sizeof args, "run examples/scenarios/dry_hertz.ini --out %s/d", dir);
    snprintf(b_args, sizeof b_args,
             "run examples/scenarios/dry_hertz.ini --set collision.speed=0.2 --out %s/d", dir);
    struct test_run r = run_cli(args, true);
    assert_int_equal(r.code, 0);
    free(r.out);
    char* first[3]; /* the files of the first run */
    for (int k = 0; k < 3; k++) {
        snprintf(path, sizeof path, "%s/d/%s", dir, names[k]);
        first[k] = test_read_file(path, NULL);
        assert_non_null(first[k]);
    }
    /* killed after its first rename: trajectory.csv is new, the others aside or not placed */
    r = test_run_cli("WETDEM_TEST_KILL_AT_RENAME=1", b_args, true);
    if (r.code != 137 && r.code != -1)
        fail_msg("a run with WETDEM_TEST_KILL_AT_RENAME=1: exit %d, expected a kill\n%s", r.code,
                 r.out);
    free(r.out);
    snprintf(path, sizeof path, "%s/d", dir);
    char* listing = test_list_dir(path);
    CHECK_CONTAINS(listing, ".wetdem-set.");
    CHECK_CONTAINS(listing, ".events.csv.tmp");
    free(listing);
    /* the next, killed in turn after moving every target aside: it completed the first set */
    r = test_run_cli("WETDEM_TEST_KILL_AT_RENAME=0", args, true);
    if (r.code != 137 && r.code != -1)
        fail_msg("a run with WETDEM_TEST_KILL_AT_RENAME=0: exit %d, expected a kill\n%s", r.code,
                 r.out);
    CHECK_CONTAINS(r.out, "events.csv: completed from a set of files that process");
    CHECK_CONTAINS(r.out, "summary.json: completed from a set of files that process");
    free(r.out);
    /* and the next, not killed, completes that one (no target was left under the backup
       name) and writes its own: the first run's files, nothing else */
    r = run_cli(args, true);
    assert_int_equal(r.code, 0);
    CHECK_CONTAINS(r.out, "trajectory.csv: completed from a set of files that process");
    free(r.out);
    snprintf(path, sizeof path, "%s/d", dir);
    listing = test_list_dir(path);
    assert_string_equal(listing, "events.csv\nsummary.json\ntrajectory.csv\n");
    free(listing);
    for (int k = 0; k < 3; k++) {
        snprintf(path, sizeof path, "%s/d/%s", dir, names[k]);
        char* text = test_read_file(path, NULL);
        assert_string_equal(text, first[k]);
        free(text);
    }
    /* by hand, as an earlier version left them: summary.json under the backup name of a dead
       process, a cut temporary file of events.csv; and a temporary file of a live process
       (this one). The run fails (a full disk), but the backup is put back. */
    pid_t child = fork();
    assert_true(child >= 0);
    if (child == 0)
        _exit(0);
    assert_int_equal(waitpid(child, NULL, 0), child);
    snprintf(path, sizeof path, "%s/d/summary.json", dir);
    snprintf(path2, sizeof path2, "%s/d/.summary.json.tmp%ld.old", dir, (long)child);
    assert_int_equal(rename(path, path2), 0);
    snprintf(path, sizeof path, "%s/d/events.csv.tmp%ld", dir, (long)child);
    test_write_file(path, "time [s],");
    snprintf(path, sizeof path, "%s/d/.trajectory.csv.tmp%ld", dir, (long)getpid());
    test_write_file(path, "a live process's\n");
    r = test_run_cli(TEST_FILE_SIZE_LIMIT, args, true); /* (trajectory.csv: too large) */
    assert_int_equal(r.code, 1);
    CHECK_CONTAINS(r.out, "summary.json: put back from");
    CHECK_CONTAINS(r.out, "which had not finished writing it");
    free(r.out);
    snprintf(path, sizeof path, "%s/d/summary.json", dir);
    char* text = test_read_file(path, NULL);
    assert_non_null(text);
    assert_string_equal(text, first[2]);
    free(text);
    snprintf(path, sizeof path, "%s/d", dir);
    listing = test_list_dir(path);
    snprintf(path2, sizeof path2,
             ".trajectory.csv.tmp%ld\nevents.csv\nsummary.json\ntrajectory.csv\n", (long)getpid());
    assert_string_equal(listing, path2);
    free(listing);
    for (int k = 0; k < 3; k++)
        free(first[k]);
    snprintf(args, sizeof args, "rm -rf '%s'", dir);
    assert_int_equal(system(args), 0);
}

/* The journal of a set holds any name: a directory whose name has a tab in it, written by a
 * run killed after its first rename, is completed by the next run from its journal, and a
 * user's files whose names are the parts of that name before the tab ("a", "a.old") are left
 * as they are (a journal split at the tab named them). */
static void test_cli_run_outputs_journal_names_with_tabs(void** state)
{
    (void)state;
    char dir[] = "/tmp/wetdem_test_cli_tab_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char args[600], b_args[600], path[600];
    snprintf(args, sizeof args, "run examples/scenarios/dry_hertz.ini --out '%s/a\tb'", dir);
    snprintf(b_args, sizeof b_args,
             "run examples/scenarios/dry_hertz.ini --set collision.speed=0.2 --out '%s/a\tb'", dir);
    snprintf(path, sizeof path, "%s/a", dir);
    test_write_file(path, "the user's a\n");
    snprintf(path, sizeof path, "%s/a.old", dir);
    test_write_file(path, "the user's a.old\n");
    struct test_run r = run_cli(args, true);
    assert_int_equal(r.code, 0);
    free(r.out);
    r = test_run_cli("WETDEM_TEST_KILL_AT_RENAME=1", b_args, true);
    if (r.code != 137 && r.code != -1)
        fail_msg("a run with WETDEM_TEST_KILL_AT_RENAME=1: exit %d, expected a kill\n%s", r.code,
                 r.out);
    free(r.out);
    r = run_cli(args, true);
    assert_int_equal(r.code, 0);
    CHECK_CONTAINS(r.out, "events.csv: completed from a set of files that process");
    CHECK_CONTAINS(r.out, "summary.json: completed from a set of files that process");
    free(r.out);
    char* listing = test_list_dir(dir);
    assert_string_equal(listing, "a\na\tb\na.old\n");
    free(listing);
    snprintf(path, sizeof path, "%s/a.old", dir);
    char* text = test_read_file(path, NULL);
    assert_non_null(text);
    assert_string_equal(text, "the user's a.old\n");
    free(text);
    snprintf(path, sizeof path, "%s/a\tb", dir);
    listing = test_list_dir(path);
    assert_string_equal(listing, "events.csv\nsummary.json\ntrajectory.csv\n");
    free(listing);
    snprintf(args, sizeof args, "rm -rf '%s'", dir);
    assert_int_equal(system(args), 0);
}

/* A journal of a dead process that names files which are not a set's temporary files and
 * targets (another user's in a shared directory, or one damaged) moves nothing: the user's
 * notes.txt is neither renamed over other.txt nor its notes.txt.old removed. */
static void test_cli_run_outputs_foreign_journal_left_alone(void** state)
{
    (void)state;
    char dir[] = "/tmp/wetdem_test_cli_foreign_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char real[PATH_MAX], args[600], path[600], text[3 * PATH_MAX + 100];
    assert_non_null(realpath(dir, real));
    pid_t child = fork();
    assert_true(child >= 0);
    if (child == 0)
        _exit(0);
    assert_int_equal(waitpid(child, NULL, 0), child);
    snprintf(path, sizeof path, "%s/notes.txt", dir);
    test_write_file(path, "notes\n");
    snprintf(path, sizeof path, "%s/notes.txt.old", dir);
    test_write_file(path, "older notes\n");
    snprintf(text, sizeof text,
             "wetdem output set\ndir\t%s\nfile\t%s/notes.txt\t%s/other.txt\nend\n", real, real,
             real);
    snprintf(path, sizeof path, "%s/.wetdem-set.%ld", dir, (long)child);
    test_write_file(path, text);
    snprintf(args, sizeof args, "run examples/scenarios/dry_hertz.ini --out %s", dir);
    struct test_run r = run_cli(args, true);
    assert_int_equal(r.code, 0);
    CHECK_CONTAINS(r.out, "not a journal of a set of files that wetdem can put in order");
    free(r.out);
    char* listing = test_list_dir(dir);
    snprintf(text, sizeof text,
             ".wetdem-set.%ld\nevents.csv\nnotes.txt\nnotes.txt.old\nsummary.json\n"
             "trajectory.csv\n",
             (long)child);
    assert_string_equal(listing, text);
    free(listing);
    snprintf(args, sizeof args, "rm -rf '%s'", dir);
    assert_int_equal(system(args), 0);
}

/* A set written through a short name of a directory whose real path is long (a symbolic
 * link to it; or a relative --out from a deep working directory) is written: its journal
 * holds real paths of up to PATH_MAX characters. */
static void test_cli_run_outputs_into_a_deep_directory(void** state)
{
    (void)state;
    char dir[] = "/tmp/wetdem_test_cli_deep_XXXXXX";
    assert_non_null(mkdtemp(dir));
    char deep[2000], args[800], link[200];
    size_t len = (size_t)snprintf(deep, sizeof deep, "%s", dir);
    while (len < 1480) {
        len += (size_t)snprintf(deep + len, sizeof deep - len, "/%.*s", 100,
                                "dddddddddddddddddddddddddddddddddddddddddddddddddd"
                                "dddddddddddddddddddddddddddddddddddddddddddddddddd");
        assert_int_equal(mkdir(deep, 0777), 0);
    }
    snprintf(link, sizeof link, "%s/short", dir);
    assert_int_equal(symlink(deep, link), 0);
    snprintf(args, sizeof args, "run examples/scenarios/dry_hertz.ini --out %s/d", link);
    struct test_run r = run_cli(args, true);
    if (r.code != 0)
        fail_msg("a run into %s/d: exit %d\n%s", link, r.code, r.out);
    free(r.out);
    snprintf(args, sizeof args, "%s/d", link);
    char* listing = test_list_dir(args);
    assert_string_equal(listing, "events.csv\nsummary.json\ntrajectory.csv\n");
    free(listing);
    snprintf(args, sizeof args, "rm -rf '%s'", dir);
    assert_int_equal(system(args), 0);
}

/* A [model.NAME] section of the file for a model that a --set of [models] switched away from
 * is ignored, so one file serves both choices (the files below hold [model.fixed] and
 * [model.glass], for the models they choose); a --set of such a parameter, a section the
 * file's own choice leaves unused, and a section of no model at all remain errors. */
static void test_cli_unused_model_sections(void** state)
{
    (void)state;
    static const struct cli_case cases[] = {
        {"run examples/scenarios/many_settling.ini --set models.min_separation=ehd --check",
         "is valid (many-particle run)", 0},
        {"run examples/scenarios/punch_oblique.ini --set models.min_separation=roughness --check",
         "is valid", 0},
        {"run examples/scenarios/many_settling.ini --set models.min_separation=ehd "
         "--set model.fixed.h_min=2e-6 --check",
         "--set model.fixed.h_min=2e-6: model 'fixed' is not enabled", 2},
    };
    check_cli_cases(cases, sizeof cases / sizeof cases[0]);
    char args[256];
    const char* unused = temp_scenario("[collision]\nstokes = 50\n[models]\nmin_separation = ehd\n"
                                       "[model.fixed]\nh_min = 1e-6\n");
    snprintf(args, sizeof args, "run %s --check", unused);
    struct test_run r = run_cli(args, true);
    assert_int_equal(r.code, 2);
    CHECK_CONTAINS(r.out, ":6: [model.fixed] h_min = 1e-6: model 'fixed' is not enabled");
    free(r.out);
    remove(unused);
    const char* stray = temp_scenario("[collision]\nstokes = 50\n[model.fixd]\nh_min = 1e-6\n");
    snprintf(args, sizeof args, "run %s --set models.min_separation=ehd --check", stray);
    r = run_cli(args, true);
    assert_int_equal(r.code, 2);
    CHECK_CONTAINS(r.out, ":3: unknown section [model.fixd]: 'fixd' is not a model; did you mean "
                          "[model.fixed]?");
    free(r.out);
    remove(stray);
}

/* Inputs found by `make fuzz` (tests/fuzz/regressions/), each once a memory error, undefined
 * behaviour or a silent loss: the answer now is that of any other file. Under `make test-san`
 * AddressSanitizer checks the track's way; the cell list's zero offset of a NULL pointer only
 * clang's UBSan reports (`make fuzz`: the file is in its corpus), GCC's does not look. */
static void test_cli_fuzz_regressions(void** state)
{
    (void)state;
    static const struct {
        const char* args;
        int code;
        const char* needle;
    } cases[] = {
        /* 7 frames of two spheres: the striker's pick read past the 6 velocities */
        {"track tests/fuzz/regressions/track_too_short.csv --fps 5000 --pixel-size 0.000175", 2,
         "sphere 1 has 7 frames; finding a collision needs at least 12"},
        /* two spheres 0.13 m apart: a cell of one sphere without neighbours offset a NULL list */
        {"run tests/fuzz/regressions/cell_without_pairs.ini --check", 0,
         "is valid (many-particle run)"},
        /* "[particle.s4] coated": inih kept the header and dropped the rest without a word */
        {"run tests/fuzz/regressions/header_with_text.ini --check", 2,
         "header_with_text.ini:35: text after the section header [particle.s4]: 'coated'"},
    };
    for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
        struct test_run r = run_cli(cases[k].args, true);
        if (r.code != cases[k].code || !strstr(r.out, cases[k].needle))
            fail_msg("wetdem %s: exit %d (want %d), output:\n%s", cases[k].args, r.code,
                     cases[k].code, r.out);
        free(r.out);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_cli_version_and_help),
        cmocka_unit_test(test_cli_every_subcommand_help),
        cmocka_unit_test(test_cli_models_lists_every_model),
        cmocka_unit_test(test_cli_describe_lists_parameters_with_units),
        cmocka_unit_test(test_cli_describe_unknown_name),
        cmocka_unit_test(test_cli_forces_matches_reynolds_closed_form),
        cmocka_unit_test(test_cli_forces_min_separation_only_is_explained),
        cmocka_unit_test(test_cli_forces_log_gaps_are_decades),
        cmocka_unit_test(test_cli_forces_bad_input),
        cmocka_unit_test(test_cli_bad_options_get_hints),
        cmocka_unit_test(test_cli_single_options_given_twice),
        cmocka_unit_test(test_cli_too_many_set_options),
        cmocka_unit_test(test_cli_set_overrides_never_used),
        cmocka_unit_test(test_cli_model_of_the_wrong_kind),
        cmocka_unit_test(test_cli_messages_name_what_is_wrong),
        cmocka_unit_test(test_cli_set_without_section_suggests_it),
        cmocka_unit_test(test_cli_unused_model_sections),
        cmocka_unit_test(test_cli_integrator_names_in_set),
        cmocka_unit_test(test_cli_fuzz_regressions),
        cmocka_unit_test(test_cli_stdout_write_failures),
        cmocka_unit_test(test_cli_run_outputs_replaced_whole_or_not_at_all),
        cmocka_unit_test(test_cli_run_outputs_recovered_after_a_kill),
        cmocka_unit_test(test_cli_run_outputs_journal_names_with_tabs),
        cmocka_unit_test(test_cli_run_outputs_foreign_journal_left_alone),
        cmocka_unit_test(test_cli_run_outputs_into_a_deep_directory),
        cmocka_unit_test(test_cli_check_reports_the_stokes_number_run),
        cmocka_unit_test(test_cli_summary_names_its_command),
        cmocka_unit_test(test_cli_every_csv_has_provenance_and_name_unit_columns),
        cmocka_unit_test(test_cli_dev_stdout_output_to_a_redirected_file),
        cmocka_unit_test(test_cli_numbers_out_of_range_and_cr_lines),
        cmocka_unit_test(test_cli_run_progress_on_a_terminal),
        cmocka_unit_test(test_cli_signal_notice_starts_on_a_clean_line),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

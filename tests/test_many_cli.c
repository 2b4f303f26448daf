/*
 * test_many_cli.c — many-particle runs through the command line (cli/run_many.c,
 * cli/scenario_many.c):
 *   - bad scenarios (box too small for the count, negative radius, unknown key, a wall on a
 *     periodic axis, a name listed twice or 'none' beside other names, overlapping groups,
 *     t_end and steps both, a periodic edge too short for the neighbour cells, a foreign
 *     checkpoint) exit 2 with "FILE:LINE:" at the right line
 *     and write nothing, not even the --out directory;
 *   - a run split by --restart (at a step on the output grid and off it), and a run resumed
 *     from an older checkpoint after its outputs went further (listed in the index or, after
 *     a kill, not yet), give byte-identical VTK frames, series index, CSV and summary to the
 *     uninterrupted run;
 *   - SIGINT sent to a running CLI, once or twice back to back, writes a checkpoint, exits 130
 *     and prints the command that resumes it; resuming gives the uninterrupted run's files
 *     byte for byte; a third stops it at once, the earlier checkpoint intact;
 *   - the CSV ends with a row of the last step, in the library's format;
 *   - a fresh run into a used --out removes the earlier run's frames and links (vtk_links),
 *     and no other file; a restart continues both, bit-identical to an uninterrupted run;
 *   - a directory named as one of the run's outputs (or their temporary files) in --out is
 *     refused, exit 2, naming it, with every file as it was;
 *   - the summary prints a large mean agglomerate size as a whole number;
 *   - progress goes to stderr only when it is a terminal, with an estimate of the time left;
 *   - [read.NAME] starts a run from a frame of another (ASCII or binary) bit for bit, or from a
 *     CSV at its values; bad files exit 2 with the scenario's line and the file's line;
 *   - the example scenarios check, and the summary's energy budget adds up; a run whose budget
 *     does not close (a step too long for the contacts) says so and exits 1, and a restart
 *     from an edited checkpoint whose budget does not close is refused with exit 2; a run
 *     whose models' works cancel (wet spheres at rest pulled together by their bridge) is
 *     judged against the size of each model's work, and closes.
 *
 * The runs use one OpenMP thread (results are bit-identical for a given thread count, and one
 * thread is the fastest for 150 spheres on a shared machine) and the passive wait policy.
 */
#include <fcntl.h>
#include <math.h>
#include <pty.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "checkpoint.h"
#include "harness.h"

#define ENV "OMP_NUM_THREADS=1 OMP_WAIT_POLICY=passive"

static char tmpdir[256];

/* tmpdir/name */
static const char* tpath(const char* name)
{
    static char paths[8][600];
    static int next = 0;
    char* p = paths[next++ % 8];
    snprintf(p, 600, "%s/%s", tmpdir, name);
    return p;
}

static void write_text(const char* name, const char* text)
{
    test_write_file(tpath(name), text);
}

static bool exists(const char* name)
{
    struct stat st;
    return stat(tpath(name), &st) == 0;
}

/* Runs "cd tmpdir && ENV wetdem ARGS > out.txt 2> err.txt"; returns the exit code. */
static int run_cli(const char* args)
{
    char cmd[4096];
    snprintf(cmd, sizeof cmd, "cd '%s' && " ENV " '%s' %s > out.txt 2> err.txt", tmpdir,
             test_cli_path(), args);
    int status = system(cmd);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

static char* stderr_text(void)
{
    char* s = test_read_file(tpath("err.txt"), NULL);
    assert_non_null(s);
    return s;
}

/* Runs args, expects exit `code` and `needle` on stderr; returns stderr (caller frees). */
static char* expect_exit(const char* args, int code, const char* needle)
{
    int got = run_cli(args);
    char* err = stderr_text();
    if (got != code)
        fail_msg("%s: exit %d, expected %d\n%s", args, got, code, err);
    CHECK_CONTAINS(err, needle);
    return err;
}

/* Runs args, expects exit 0 and `needle` in the file `name` of tmpdir (out.txt: stdout). */
static void expect_output(const char* args, const char* name, const char* needle)
{
    int got = run_cli(args);
    if (got != 0) {
        char* err = stderr_text();
        fail_msg("%s: exit %d, expected 0\n%s", args, got, err);
    }
    char* text = test_read_file(tpath(name), NULL);
    assert_non_null(text);
    CHECK_CONTAINS(text, needle);
    free(text);
}

/* A wet granular box, periodic in x and y, floor and lid, gravity (21 lines)... */
#define WET_BOX                                                                                    \
    "[box]\nsize_x = 6e-3\nsize_y = 6e-3\nsize_z = 8e-3\nperiodic = x y\n"                         \
    "[material.wet]\ndensity = 2500\nyoungs_modulus = 1e7\npoisson_ratio = 0.3\n"                  \
    "restitution = 0.6\nfriction_dry = 0.4\nfriction_lub = 0.1\nfilm = 20e-6\n"                    \
    "[fluid]\nviscosity = 0.01\nsurface_tension = 0.02\n"                                          \
    "[models]\nforce = hertz mindlin sb capillary\nmin_separation = fixed\n"                       \
    "[sim]\ngravity_z = -9.81\n"

/* ... with 150 spheres. */
static const char* const base =
    WET_BOX "[insert]\ncount = 150\nradius_min = 0.4e-3\nradius_max = 0.5e-3\nmaterial = wet\n"
            "velocity_sigma = 0.2\nseed = 7\n"
            "[run]\ndt = 2e-6\n";

/* base + extra lines, into tmpdir/name. */
static void scenario(const char* name, const char* extra)
{
    char text[4096];
    snprintf(text, sizeof text, "%s%s", base, extra);
    write_text(name, text);
}

/* Runs a bad scenario: exit 2, "NAME:LINE:" and `what` in the message, no --out directory. */
static void expect_bad(const char* name, const char* text, int line, const char* what)
{
    write_text(name, text);
    char args[600], where[128];
    snprintf(args, sizeof args, "run %s --out %s.out", name, name);
    int code = run_cli(args);
    char* err = stderr_text();
    if (code != 2)
        fail_msg("%s: exit %d, expected 2\n%s", name, code, err);
    snprintf(where, sizeof where, "%s:%d:", name, line);
    CHECK_CONTAINS(err, where);
    CHECK_CONTAINS(err, what);
    char out[200];
    snprintf(out, sizeof out, "%s.out", name);
    if (exists(out))
        fail_msg("%s: the --out directory was created for a bad scenario", name);
    free(err);
}

static void test_many_cli_bad_inputs_exit_2_with_file_and_line(void** state)
{
    (void)state;
    /* lattice of spacing 2 x 0.5 mm in a 2 mm cube: 2 x 2 x 2 = 8 sites < 150 (line 2: count) */
    expect_bad("small.ini",
               "[insert]\ncount = 150\nradius = 0.5e-3\nlayout = lattice\n[box]\nsize_x = 2e-3\n"
               "size_y = 2e-3\nsize_z = 2e-3\n[run]\nsteps = 10\n",
               2, "holds at most 8 spheres");
    /* a box thinner than one sphere names its size against the diameter, not "0 spheres" */
    expect_bad("thin.ini",
               "[insert]\ncount = 5\nradius = 1e-3\nlayout = lattice\n[box]\nsize_x = 1e-3\n"
               "size_y = 1e-2\nsize_z = 1e-2\n[run]\nsteps = 10\n",
               2, "the region is 0.001 m across in x, narrower than one sphere: 2 r + 2 gap = ");
    expect_bad("negative.ini",
               "[box]\nsize_x = 1e-2\nsize_y = 1e-2\nsize_z = 1e-2\n[insert]\ncount = 5\n"
               "radius = -1e-3\n[run]\nsteps = 10\n",
               7, "radius");
    /* a count given as 5.5 is refused, not truncated to 5 (line 6: count) */
    expect_bad("fraction.ini",
               "[box]\nsize_x = 1e-2\nsize_y = 1e-2\nsize_z = 1e-2\n[insert]\ncount = 5.5\n"
               "radius = 1e-3\n[run]\nsteps = 10\n",
               6, "count = 5.5 [-] is not a whole number: valid integer in [1, 100000000]");
    expect_bad("typo.ini",
               "[box]\nsize_x = 1e-2\nsize_y = 1e-2\nsize_z = 1e-2\n[insert]\ncuont = 5\n"
               "radius = 1e-3\n[run]\nsteps = 10\n",
               6, "did you mean 'count'");
    /* a typo of cvode's rtol: named as cvode's, not 'verlet.dt', the closest of verlet's */
    expect_bad("rtoll.ini",
               "[box]\nsize_x = 1e-2\nsize_y = 1e-2\nsize_z = 1e-2\n[insert]\ncount = 5\n"
               "radius = 1e-3\n[run]\nsteps = 10\n[integrator]\nrtoll = 1e-8\n",
               11,
               "unknown parameter 'verlet.rtoll' (did you mean 'rtol', a parameter of the cvode "
               "integrator? a many-particle run steps with verlet)");
    expect_bad("periodic_wall.ini",
               "[box]\nsize_x = 1e-2\nsize_y = 1e-2\nsize_z = 1e-2\nperiodic = x\n[walls]\n"
               "faces = x_min z_min\n[insert]\ncount = 5\nradius = 1e-3\n[run]\nsteps = 10\n",
               7, "wall x_min lies on axis x");
    /* a name listed twice is a slip (meant 'x y'), and 'none' or 'all' stand alone */
    expect_bad("twice.ini",
               "[box]\nsize_x = 1e-2\nsize_y = 1e-2\nsize_z = 1e-2\nperiodic = x x\n"
               "[insert]\ncount = 5\nradius = 1e-3\n[run]\nsteps = 10\n",
               5, "'x' is listed twice");
    expect_bad("face_twice.ini",
               "[box]\nsize_x = 1e-2\nsize_y = 1e-2\nsize_z = 1e-2\n[walls]\n"
               "faces = z_min, z_max z_min\n[insert]\ncount = 5\nradius = 1e-3\n[run]\n"
               "steps = 10\n",
               6, "'z_min' is listed twice");
    expect_bad("none_and.ini",
               "[box]\nsize_x = 1e-2\nsize_y = 1e-2\nsize_z = 1e-2\nperiodic = none z\n"
               "[insert]\ncount = 5\nradius = 1e-3\n[run]\nsteps = 10\n",
               5, "'none' stands for the whole list");
    expect_bad("overlap.ini",
               "[box]\nsize_x = 1e-2\nsize_y = 1e-2\nsize_z = 1e-2\n[particle.a]\nradius = 1e-3\n"
               "x = 5e-3\ny = 5e-3\nz = 5e-3\n[particle.b]\nradius = 1e-3\nx = 6e-3\ny = 5e-3\n"
               "z = 5e-3\n[run]\nsteps = 10\n",
               10, "sphere 1 of [particle.b] overlaps sphere 1 of [particle.a] by 0.001 m");
    /* the group overlapped is named, not counted over all the groups before */
    expect_bad("overlap3.ini",
               "[box]\nsize_x = 1e-2\nsize_y = 1e-2\nsize_z = 1e-2\n[particle.a]\nradius = 1e-3\n"
               "x = 2e-3\ny = 5e-3\nz = 5e-3\n[particle.b]\nradius = 1e-3\nx = 5e-3\ny = 5e-3\n"
               "z = 5e-3\n[particle.c]\nradius = 1e-3\nx = 6e-3\ny = 5e-3\nz = 5e-3\n[run]\n"
               "steps = 10\n",
               15, "sphere 1 of [particle.c] overlaps sphere 1 of [particle.b] by 0.001 m");
    /* across the face of a periodic axis (the minimum image: 0.5 mm apart, 1.5 mm of radii),
       and of the earlier spheres it overlaps, the first by index is named (here the third,
       also in the cell across the face, and the second) */
    expect_bad("overlap_periodic.ini",
               "[box]\nsize_x = 1e-2\nsize_y = 1e-2\nsize_z = 1e-2\nperiodic = x\n"
               "[particle.a]\nradius = 1e-3\nx = 9.8e-3\ny = 5e-3\nz = 5e-3\n"
               "[particle.b]\nradius = 0.5e-3\nx = 0.3e-3\ny = 5e-3\nz = 5e-3\n[run]\n"
               "steps = 10\n",
               11, "sphere 1 of [particle.b] overlaps sphere 1 of [particle.a] by 0.001 m");
    write_text("row.csv", "x,y,z,radius\n5e-3,1e-3,5e-3,1e-4\n9.9e-3,5e-3,5e-3,1e-4\n"
                          "0.1e-3,5.15e-3,5e-3,1e-4\n");
    expect_bad("overlap_first.ini",
               "[box]\nsize_x = 1e-2\nsize_y = 1e-2\nsize_z = 1e-2\nperiodic = x\n"
               "[read.row]\nfile = row.csv\n[particle.b]\nradius = 1e-4\nx = 0\ny = 5.1e-3\n"
               "z = 5e-3\n[run]\nsteps = 10\n",
               8, "sphere 1 of [particle.b] overlaps sphere 2 of [read.row]");
    expect_bad("both.ini",
               "[box]\nsize_x = 1e-2\nsize_y = 1e-2\nsize_z = 1e-2\n[insert]\ncount = 5\n"
               "radius = 1e-3\n[run]\nt_end = 1e-3\nsteps = 10\n",
               10, "not both");
    /* periodic edge 3 mm < 2 x (2 R_max + reach + skin) = 2 x (2 mm + 40 um + 0.1 mm) */
    expect_bad("short_periodic.ini",
               "[box]\nsize_x = 3e-3\nsize_y = 1e-2\nsize_z = 1e-2\nperiodic = x\n"
               "[insert]\ncount = 1\nradius = 1e-3\n[material.steel1]\npreset = steel1\n"
               "film = 20e-6\n[models]\nforce = hertz sb\n[run]\nsteps = 10\n",
               1, "[box]");
    /* 1e6 s in steps of 1e-20 s: 1e26 steps is refused at t_end, not cast to a wrong count */
    expect_bad("too_long.ini",
               "[box]\nsize_x = 1e-2\nsize_y = 1e-2\nsize_z = 1e-2\n[insert]\ncount = 5\n"
               "radius = 1e-3\n[run]\nt_end = 1e6\ndt = 1e-20\n",
               9, "t_end = 1e6: takes 1e+26 steps of dt = 1e-20 s, more than 1e+15");
    /* a VTK file every step of 2e5, a CSV row every step of 2e7: refused before --out */
    expect_bad("vtk_flood.ini",
               "[box]\nsize_x = 1e-2\nsize_y = 1e-2\nsize_z = 1e-2\n[insert]\ncount = 5\n"
               "radius = 1e-3\n[run]\nsteps = 200000\n[dump]\nvtk_every = 1\n",
               11, "writes 200001 VTK files over the run's 200000 steps, more than 100000");
    expect_bad("csv_flood.ini",
               "[box]\nsize_x = 1e-2\nsize_y = 1e-2\nsize_z = 1e-2\n[insert]\ncount = 5\n"
               "radius = 1e-3\n[run]\nsteps = 20000000\n[dump]\ncsv_every = 1\n",
               11, "writes 20000001 CSV rows over the run's 20000000 steps, more than 10000000");
    /* --check says so too (it said "valid") */
    free(expect_exit("run vtk_flood.ini --check --out flood", 2, "writes 200001 VTK files"));
    /* two outputs of one name: the one written last replaced the other */
    expect_bad("clash.ini",
               "[box]\nsize_x = 1e-2\nsize_y = 1e-2\nsize_z = 1e-2\n[insert]\ncount = 5\n"
               "radius = 1e-3\n[run]\nsteps = 10\n[dump]\ncheckpoint = global.csv\n",
               11, "global.csv would name both the CSV and the checkpoint");
    expect_bad("clash_frame.ini",
               "[box]\nsize_x = 1e-2\nsize_y = 1e-2\nsize_z = 1e-2\n[insert]\ncount = 5\n"
               "radius = 1e-3\n[run]\nsteps = 10\n[dump]\nsummary = particles_000003.vtk\n",
               11, "particles_000003.vtk would name both the summary and a VTK frame");
    /* a density of 1e-300 kg/m^3 makes m/c_d underflow to 0 though h_min > 0: the message
     * names the mass, not a missing h_min; 1e300 makes the Hertz contact time infinite, and
     * a step of a quarter of the relaxation time (2e291 s) would send the spheres to inf: the
     * message names the pair that sets it (with the floor and the lid here) and the sphere */
    scenario("light.ini", "steps = 5\n");
    char* msg = expect_exit("run light.ini --set material.wet.density=1e-300", 2,
                            "is 0 s, since the smallest free sphere's mass is");
    CHECK_CONTAINS(msg, "check the material's density and the radii");
    free(msg);
    msg = expect_exit("run light.ini --set material.wet.density=1e300 --set run.dt=0", 2,
                      "cannot derive a time step: the contact time of two smallest free "
                      "spheres (the smallest free one R = 0.0004");
    CHECK_CONTAINS(msg, ") is inf s at the speed scale ");
    CHECK_CONTAINS(msg, "check the materials' density and youngs_modulus");
    free(msg);
    expect_bad("mixed.ini",
               "[collision]\nspeed = 1\n[box]\nsize_x = 1e-2\nsize_y = 1e-2\nsize_z = 1e-2\n"
               "[insert]\ncount = 1\nradius = 1e-3\n[run]\nsteps = 10\n",
               1, "not both");
    /* sweeps vary binary collisions; a many-particle file is refused, not misread */
    scenario("sweep.ini", "");
    free(expect_exit("sweep sweep.ini --param run.dt --values 1e-6:2e-6:2", 2,
                     "runs with 'wetdem run'"));
    /* a --set of a sphere, an insertion or a file read the file does not define was an entry
       no section read: the run went on without it */
    free(expect_exit("run overlap3.ini --check --set particle.aa.x=1e-3", 2,
                     "--set particle.aa.x=1e-3: the file has no section [particle.aa] (did you "
                     "mean [particle.a]?); --set changes a sphere the file defines"));
    free(expect_exit("run sweep.ini --check --set insert.big.count=3", 2,
                     "the file has no section [insert.big]; --set changes an insertion"));
    /* nor did a --set of [insert] in a file without one: its spheres were never inserted,
       and the run went on with the file's [particle.NAME] spheres alone */
    free(expect_exit("run overlap3.ini --check --set insert.count=3", 2,
                     "--set insert.count=3: the file has no section [insert]; --set changes an "
                     "insertion the file defines"));
}

/* Removes field `col` (0-based) from every comma-separated line of text, in place. */
static void drop_column(char* text, int col)
{
    char* w = text;
    const char* r = text;
    while (*r) {
        for (int field = 0;; field++) {
            const char* end = r + strcspn(r, ",\n");
            if (field != col) {
                if (field > 0 && !(col == 0 && field == 1))
                    *w++ = ',';
                memmove(w, r, (size_t)(end - r)); /* w <= r: copying leftwards */
                w += end - r;
            }
            r = end;
            if (*r != ',')
                break;
            r++;
        }
        if (*r == '\n')
            *w++ = *r++;
    }
    *w = '\0';
}

/* The last line of tmpdir/name (caller frees), without its newline. */
static char* last_line(const char* name)
{
    char* t = test_read_file(tpath(name), NULL);
    if (!t)
        fail_msg("%s is missing", name);
    size_t n = strlen(t);
    while (n > 0 && t[n - 1] == '\n')
        t[--n] = '\0';
    const char* nl = strrchr(t, '\n');
    char* line = strdup(nl ? nl + 1 : t);
    free(t);
    return line;
}

/* The step (second column) of the last row of the CSV tmpdir/name. */
static unsigned long long csv_last_step(const char* name)
{
    char* line = last_line(name);
    const char* comma = strchr(line, ',');
    if (!comma)
        fail_msg("%s: last line '%s' is not a row", name, line);
    unsigned long long step = strtoull(comma + 1, NULL, 10);
    free(line);
    return step;
}

/* Takes the line that starts with `prefix` out of text (it must have one). */
static void drop_line(char* text, const char* prefix)
{
    char* at = strstr(text, prefix);
    assert_true(at && (at == text || at[-1] == '\n'));
    const char* end = strchr(at, '\n');
    end = end ? end + 1 : at + strlen(at);
    memmove(at, end, strlen(end) + 1);
}

/* The files of two --out directories are byte-identical, except the CSV column
 * candidate_pairs: the size of the neighbour list depends on when the list was last built,
 * and a restart builds it afresh (the forces do not depend on it: every pair within range is
 * in any valid list), and the command in the summary and the CSV's "# command:" line: the
 * summary names the run's own (a resumed one's with --restart), the CSV the command of the
 * run that wrote its first rows. The checkpoint holds such counters too and is not compared. When a has links
 * (vtk_links), so must b, the same. */
static void check_same_outputs(const char* a, const char* b, size_t frames)
{
    char names[64][64];
    size_t n = 0;
    snprintf(names[n++], 64, "global.csv");
    snprintf(names[n++], 64, "particles.vtk.series");
    snprintf(names[n++], 64, "summary.json");
    for (size_t k = 0; k < frames && n < 64; k++)
        snprintf(names[n++], 64, "particles_%06zu.vtk", k);
    char links_index[200];
    snprintf(links_index, sizeof links_index, "%.100s/particles_links.vtk.series", a);
    if (exists(links_index)) {
        snprintf(names[n++], 64, "particles_links.vtk.series");
        for (size_t k = 0; k < frames && n < 64; k++)
            snprintf(names[n++], 64, "particles_links_%06zu.vtk", k);
    }
    for (size_t k = 0; k < n; k++) {
        char pa[300], pb[300];
        snprintf(pa, sizeof pa, "%.100s/%.63s", a, names[k]);
        snprintf(pb, sizeof pb, "%.100s/%.63s", b, names[k]);
        size_t la, lb;
        char* ta = test_read_file(tpath(pa), &la);
        char* tb = test_read_file(tpath(pb), &lb);
        if (!ta || !tb)
            fail_msg("%s missing in %s", names[k], ta ? b : a);
        if (k == 0) { /* global.csv: column 9 is candidate_pairs */
            CHECK_CONTAINS(ta, ",mean_agglomerate_size [-],candidate_pairs [count],");
            drop_line(ta, "# command: wetdem run ");
            drop_line(tb, "# command: wetdem run ");
            drop_column(ta, 9);
            drop_column(tb, 9);
            la = strlen(ta);
            lb = strlen(tb);
        }
        if (k == 2) { /* summary.json */
            assert_true(test_drop_json_command(ta));
            assert_true(test_drop_json_command(tb));
            la = strlen(ta);
            lb = strlen(tb);
        }
        if (la != lb || memcmp(ta, tb, la) != 0)
            fail_msg("%s differs between %s and %s", names[k], a, b);
        free(ta);
        free(tb);
    }
    char extra[300];
    snprintf(extra, sizeof extra, "%.100s/particles_%06zu.vtk", b, frames);
    if (exists(extra))
        fail_msg("%s has a frame more than %s", b, a);
}

static void test_many_cli_restart_is_bit_identical(void** state)
{
    (void)state;
    scenario("box.ini", "[dump]\nvtk_every = 100\ncsv_every = 20\n");
    /* 600 steps of 2 us: frames at 0, 100, ..., 600 -> 7 files */
    assert_int_equal(run_cli("run box.ini --set run.steps=600 --out whole"), 0);
    /* 300 steps, then extended to 600 from its final checkpoint */
    assert_int_equal(run_cli("run box.ini --set run.steps=300 --out split"), 0);
    int code =
        run_cli("run box.ini --set run.steps=600 --out split --restart split/checkpoint.ckpt");
    if (code != 0)
        fail_msg("restart: exit %d\n%s", code, stderr_text());
    check_same_outputs("whole", "split", 7);
    /* split off the CSV grid: the first run's CSV ends with a row of its last step, 305, which
       the uninterrupted run does not have; the resumed run drops it (and keeps the row of 300) */
    assert_int_equal(run_cli("run box.ini --set run.steps=305 --out split305"), 0);
    assert_int_equal(csv_last_step("split305/global.csv"), 305);
    code = run_cli("run box.ini --set run.steps=600 --out split305 --restart "
                   "split305/checkpoint.ckpt");
    if (code != 0)
        fail_msg("restart at 305: exit %d\n%s", code, stderr_text());
    check_same_outputs("whole", "split305", 7);
    /* a crash after step 300: the outputs went on to 600, the checkpoint is the older one */
    assert_int_equal(run_cli("run box.ini --set run.steps=300 --out crash"), 0);
    char cmd[1200];
    snprintf(cmd, sizeof cmd, "cp '%s/crash/checkpoint.ckpt' '%s/old.ckpt'", tmpdir, tmpdir);
    assert_int_equal(system(cmd), 0);
    assert_int_equal(run_cli("run box.ini --set run.steps=600 --out crash"), 0);
    assert_int_equal(run_cli("run box.ini --set run.steps=600 --out crash --restart old.ckpt"), 0);
    check_same_outputs("whole", "crash", 7);
    /* a run killed (SIGKILL) after writing frames past the checkpoint but before listing them:
       between a frame and its index, or while a resume from an older checkpoint wrote its
       frames again over a longer series. The index lists the frames up to step 300, the
       directory holds those up to 600; the frames after the checkpoint are written again */
    assert_int_equal(run_cli("run box.ini --set run.steps=300 --out killed"), 0);
    snprintf(cmd, sizeof cmd,
             "cd '%s/killed' && cp checkpoint.ckpt ../killed.ckpt && "
             "cp particles.vtk.series ../killed.series",
             tmpdir);
    assert_int_equal(system(cmd), 0);
    assert_int_equal(run_cli("run box.ini --set run.steps=600 --out killed"), 0);
    assert_int_equal(rename(tpath("killed.series"), tpath("killed/particles.vtk.series")), 0);
    code = run_cli("run box.ini --set run.steps=600 --out killed --restart killed.ckpt");
    if (code != 0)
        fail_msg("restart after a kill before the index: exit %d\n%s", code, stderr_text());
    check_same_outputs("whole", "killed", 7);
    /* killed between the frame of a periodic checkpoint's step and its index: the frame at
       the checkpoint's time is not listed; it is written again */
    assert_int_equal(run_cli("run box.ini --set run.steps=300 --out killed300"), 0);
    char* index = test_read_file(tpath("killed300/particles.vtk.series"), NULL);
    assert_non_null(index);
    char* last = strstr(index, ",\n    { \"name\" : \"particles_000003.vtk\"");
    assert_non_null(last);
    snprintf(last, 10, "\n  ]\n}\n");
    write_text("killed300/particles.vtk.series", index);
    free(index);
    code = run_cli("run box.ini --set run.steps=600 --out killed300 --restart "
                   "killed300/checkpoint.ckpt");
    if (code != 0)
        fail_msg("restart after a kill at the checkpoint's frame: exit %d\n%s", code,
                 stderr_text());
    check_same_outputs("whole", "killed300", 7);
    /* a crash in the middle of a CSV row: the cut row (no newline) is dropped, not joined to
       the first row the resumed run appends */
    assert_int_equal(run_cli("run box.ini --set run.steps=300 --out cut"), 0);
    FILE* f = fopen(tpath("cut/global.csv"), "a");
    assert_non_null(f);
    fputs("0.00061570,30", f);
    fclose(f);
    assert_int_equal(run_cli("run box.ini --set run.steps=600 --out cut --restart "
                             "cut/checkpoint.ckpt"),
                     0);
    check_same_outputs("whole", "cut", 7);
    /* a missing index (or one cut short) beside the frames: numbering from its end overwrote
       them; refused, exit 2, nothing touched */
    assert_int_equal(run_cli("run box.ini --set run.steps=300 --out noindex"), 0);
    assert_int_equal(rename(tpath("noindex/particles.vtk.series"), tpath("index.keep")), 0);
    char* before = test_read_file(tpath("noindex/global.csv"), NULL);
    free(expect_exit("run box.ini --set run.steps=600 --out noindex --restart "
                     "noindex/checkpoint.ckpt",
                     2,
                     "noindex/particles.vtk.series is missing, but "
                     "noindex/particles_000000.vtk exists"));
    char* after = test_read_file(tpath("noindex/global.csv"), NULL);
    assert_string_equal(before, after);
    free(before);
    free(after);
    write_text("noindex/particles.vtk.series",
               "{\n  \"file-series-version\" : \"1.0\",\n  \"files\" : [\n    { \"name\" : "
               "\"particles_000000.vtk\", \"time\" : 0 }\n  ]\n}\n");
    free(expect_exit("run box.ini --set run.steps=600 --out noindex --restart "
                     "noindex/checkpoint.ckpt",
                     2,
                     "lists fewer frames than the directory holds, but "
                     "noindex/particles_000001.vtk exists"));
    assert_int_equal(rename(tpath("index.keep"), tpath("noindex/particles.vtk.series")), 0);
    assert_int_equal(run_cli("run box.ini --set run.steps=600 --out noindex --restart "
                             "noindex/checkpoint.ckpt"),
                     0);
    check_same_outputs("whole", "noindex", 7);
    /* a checkpoint of another set-up is refused: exit 2, and the outputs stay as they were */
    code = run_cli("run box.ini --set run.steps=600 --set material.wet.film=30e-6 --out split "
                   "--restart split/checkpoint.ckpt");
    char* err = stderr_text();
    assert_int_equal(code, 2);
    CHECK_CONTAINS(err, "different materials");
    free(err);
    check_same_outputs("whole", "split", 7);
    /* --out naming the directory of another run, as long but with a step of 1.23456 us, not
       2 us: its frames and rows are not the checkpoint's run's, and the resumed run appended
       to them (exit 0); refused, exit 2, by the index or, without frames, by the CSV, nothing
       touched */
    assert_int_equal(run_cli("run box.ini --set run.steps=900 --set run.dt=1.23456e-6 --out other"),
                     0);
    before = test_read_file(tpath("other/global.csv"), NULL);
    char* index_before = test_read_file(tpath("other/particles.vtk.series"), NULL);
    free(expect_exit("run box.ini --set run.steps=1000 --out other --restart split/checkpoint.ckpt",
                     2,
                     "other/particles.vtk.series lists particles_000001.vtk at t = "
                     "0.000123456"));
    err = stderr_text();
    CHECK_CONTAINS(err, "off the time grid of the checkpoint (dt = 2e-06 s, step 600");
    CHECK_CONTAINS(err, "the directory holds the outputs of another run");
    free(err);
    free(expect_exit("run box.ini --set run.steps=1000 --set dump.vtk=none --out other --restart "
                     "split/checkpoint.ckpt",
                     2,
                     "other/global.csv has a row of step 20 at a time off the time grid of the "
                     "checkpoint"));
    after = test_read_file(tpath("other/global.csv"), NULL);
    assert_string_equal(before, after);
    free(before);
    free(after);
    after = test_read_file(tpath("other/particles.vtk.series"), NULL);
    assert_string_equal(index_before, after);
    free(index_before);
    free(after);
    /* so is one written without the energy budget when the budget is on (it would count the
       work since the restart against the energies since the start), with the key to set */
    code = run_cli("run box.ini --set run.steps=600 --set run.energy_budget=no --out split "
                   "--restart split/checkpoint.ckpt");
    err = stderr_text();
    assert_int_equal(code, 2);
    CHECK_CONTAINS(err, "was written with the energy budget on: resume with it on too "
                        "(energy_budget = yes)");
    free(err);
    check_same_outputs("whole", "split", 7);
    /* so are other names of the frames or the CSV than the checkpoint's run wrote, both
       alike: another VTK prefix started a second series beside the first (exit 0), another
       CSV name was "missing"; --check --restart says the same */
    const struct {
        const char *set, *what;
    } renamed[] = {
        {"dump.vtk=other",
         "--restart split/checkpoint.ckpt: [dump] vtk = other, but the run that wrote the "
         "checkpoint wrote its frames as particles_NNNNNN.vtk: the resumed run would start "
         "another series of frames beside them; resume with vtk = particles (--set "
         "dump.vtk=particles), or start afresh without --restart (nothing was changed)"},
        {"dump.csv=other.csv",
         "--restart split/checkpoint.ckpt: [dump] csv = other.csv, but the run that wrote the "
         "checkpoint wrote its CSV as global.csv: the resumed run would write a CSV that lacks "
         "the rows before the checkpoint; resume with csv = global.csv (--set "
         "dump.csv=global.csv)"},
    };
    for (size_t k = 0; k < sizeof renamed / sizeof renamed[0]; k++) {
        char args[300];
        snprintf(args, sizeof args,
                 "run box.ini --set run.steps=900 --set %s --out split --restart "
                 "split/checkpoint.ckpt",
                 renamed[k].set);
        free(expect_exit(args, 2, renamed[k].what));
        check_same_outputs("whole", "split", 7);
        assert_int_equal(access(tpath("split/other.vtk.series"), F_OK), -1);
        assert_int_equal(access(tpath("split/other_000000.vtk"), F_OK), -1);
        assert_int_equal(access(tpath("split/other.csv"), F_OK), -1);
        snprintf(args, sizeof args,
                 "run box.ini --check --set run.steps=900 --set %s --restart "
                 "split/checkpoint.ckpt",
                 renamed[k].set);
        free(expect_exit(args, 2, renamed[k].what));
    }
    /* a CSV the checkpoint's run did not write (csv = none) starts at the restart, as frames
       do: its header and the rows from the checkpoint's step on, those of the uninterrupted
       run (it was refused as a "missing" CSV) */
    assert_int_equal(run_cli("run box.ini --set run.steps=300 --set dump.csv=none --out nocsv"), 0);
    assert_int_equal(access(tpath("nocsv/global.csv"), F_OK), -1);
    code = run_cli("run box.ini --set run.steps=600 --out nocsv --restart nocsv/checkpoint.ckpt");
    if (code != 0)
        fail_msg("restart starting a CSV: exit %d\n%s", code, stderr_text());
    char* started = test_read_file(tpath("nocsv/global.csv"), NULL);
    char* full = test_read_file(tpath("whole/global.csv"), NULL);
    assert_non_null(started);
    assert_non_null(full);
    drop_column(started, 9); /* (candidate pairs: the restart builds its list afresh) */
    drop_column(full, 9);
    char* header = strstr(full, "\ntime [s],"); /* the header, then rows from step 300 on */
    char* from300 = strstr(full, "\n0.0006,300,");
    assert_non_null(header);
    assert_non_null(from300);
    size_t header_len = (size_t)(strchr(header + 1, '\n') - header);
    char* own_header = strstr(started, "\ntime [s],");
    assert_non_null(own_header);
    assert_memory_equal(own_header, header, header_len + 1);
    assert_string_equal(own_header + header_len, from300);
    free(started);
    free(full);
    /* one holding another number of spheres than the scenario places (the checkpoint's would
       replace them unnoticed), and the final checkpoint of a run resumed with the same end
       (nothing to run: the message says how to extend it); both exit 2 before any output is
       touched */
    code = run_cli("run box.ini --set run.steps=900 --set insert.count=151 --out split "
                   "--restart split/checkpoint.ckpt");
    err = stderr_text();
    assert_int_equal(code, 2);
    CHECK_CONTAINS(err, "the checkpoint holds 150 spheres but the scenario places 151");
    free(err);
    /* --check --restart makes the same checks, and says "valid" only when the run would go */
    free(expect_exit("run box.ini --check --set run.steps=900 --set insert.count=151 --restart "
                     "split/checkpoint.ckpt",
                     2, "the checkpoint holds 150 spheres but the scenario places 151"));
    expect_output("run box.ini --check --set run.steps=900 --restart split/checkpoint.ckpt",
                  "out.txt", "contacts      ");
    expect_output("run box.ini --check --set run.steps=900 --restart split/checkpoint.ckpt",
                  "out.txt", "at t = 0.0012 s (the checkpoint's)");
    code = run_cli("run box.ini --set run.steps=600 --out split --restart split/checkpoint.ckpt");
    err = stderr_text();
    assert_int_equal(code, 2);
    CHECK_CONTAINS(err, "the checkpoint is at step 600 (t = 0.0012 s), and this run ends at step "
                        "600");
    CHECK_CONTAINS(err, "raise t_end (--set run.t_end=...) or steps to continue it");
    free(err);
    check_same_outputs("whole", "split", 7);
    /* a checkpoint edited after it was written (every velocity tripled, CRC rewritten): its
       state is whole and finite, but the kinetic energy it holds is not one its budget's work
       accounts for; it is refused, exit 2, and the outputs it would continue stay as they were */
    struct wetdem_checkpoint ck;
    char msg[256];
    CHECK_OK(wetdem_checkpoint_read(tpath("split/checkpoint.ckpt"), &ck, msg, sizeof msg));
    for (size_t k = 0; k < ck.n_particles; k++) {
        ck.particles[k].vel.x *= 3;
        ck.particles[k].vel.y *= 3;
        ck.particles[k].vel.z *= 3;
    }
    CHECK_OK(wetdem_checkpoint_write(tpath("edited.ckpt"), &ck, msg, sizeof msg));
    wetdem_checkpoint_clear(&ck);
    snprintf(cmd, sizeof cmd, "cp -r '%s/split' '%s/edited'", tmpdir, tmpdir);
    assert_int_equal(system(cmd), 0);
    code = run_cli("run box.ini --set run.steps=700 --out edited --restart edited.ckpt");
    err = stderr_text();
    assert_int_equal(code, 2);
    CHECK_CONTAINS(err, "--restart edited.ckpt: its energy budget does not close (error 2.");
    CHECK_CONTAINS(err, "the state was changed after its run wrote it");
    free(err);
    check_same_outputs("split", "edited", 7);
}

/* The frames of a series index in order: their times into t[] (at most max); the count. Fails
 * when a name is not the next number or a time does not increase. */
static size_t series_times(const char* dir, double* t, size_t max)
{
    char path[300];
    snprintf(path, sizeof path, "%s/particles.vtk.series", dir);
    char* text = test_read_file(tpath(path), NULL);
    if (!text)
        fail_msg("%s is missing", path);
    size_t n = 0;
    for (const char* p = strstr(text, "\"name\" : \""); p && n < max;
         p = strstr(p + 1, "\"name\" : \"")) {
        size_t k;
        double time;
        if (sscanf(p, "\"name\" : \"particles_%zu.vtk\", \"time\" : %lf", &k, &time) != 2 || k != n)
            fail_msg("%s: entry %zu is not particles_%06zu.vtk", path, n, n);
        if (n > 0 && !(time > t[n - 1]))
            fail_msg("%s: the time of entry %zu, %.17g, does not increase", path, n, time);
        t[n++] = time;
    }
    free(text);
    return n;
}

/* Whether frame `k` of dir a and frame `l` of dir b are byte-identical. */
static bool same_frame(const char* a, size_t k, const char* b, size_t l)
{
    char pa[300], pb[300];
    snprintf(pa, sizeof pa, "%s/particles_%06zu.vtk", a, k);
    snprintf(pb, sizeof pb, "%s/particles_%06zu.vtk", b, l);
    size_t la, lb;
    char* ta = test_read_file(tpath(pa), &la);
    char* tb = test_read_file(tpath(pb), &lb);
    bool same = ta && tb && la == lb && memcmp(ta, tb, la) == 0;
    free(ta);
    free(tb);
    return same;
}

/* The row of `step` in a CSV without its column candidate_pairs (caller frees), or NULL. */
static char* csv_row(const char* name, unsigned long long step)
{
    char* text = test_read_file(tpath(name), NULL);
    if (!text)
        fail_msg("%s is missing", name);
    char* found = NULL;
    for (char* line = strtok(text, "\n"); line && !found; line = strtok(NULL, "\n")) {
        const char* comma = strchr(line, ',');
        if (line[0] >= '0' && line[0] <= '9' && comma && strtoull(comma + 1, NULL, 10) == step) {
            size_t n = strlen(line);
            found = malloc(n + 2);
            snprintf(found, n + 2, "%s\n", line);
            drop_column(found, 9);
        }
    }
    free(text);
    return found;
}

/* The steps of the data rows of a CSV, in order, into steps[] (at most max); the count. */
static size_t csv_steps(const char* name, unsigned long long* steps, size_t max)
{
    char* text = test_read_file(tpath(name), NULL);
    if (!text)
        fail_msg("%s is missing", name);
    size_t n = 0;
    for (char* line = strtok(text, "\n"); line && n < max; line = strtok(NULL, "\n")) {
        const char* comma = strchr(line, ',');
        if (line[0] >= '0' && line[0] <= '9' && comma)
            steps[n++] = strtoull(comma + 1, NULL, 10);
    }
    free(text);
    return n;
}

/* A restart with other output intervals (vtk_every, csv_every; the defaults derive them from
 * the run's length, so a longer t_end changes them too): the frames and rows up to the
 * checkpoint's step are those of the run that wrote it, on its grid, those after it on the
 * resumed run's grid; the frame and the row of the checkpoint's step are kept when they lie on
 * the first grid (they were dropped when off the second), and written when on the second. No
 * frame is lost or doubled, the index's times increase, and each frame and row is the
 * uninterrupted run's of its step, byte for byte. */
static void test_many_cli_restart_with_other_intervals(void** state)
{
    (void)state;
    scenario("grid.ini", "");
    const char* old_grid = "--set dump.vtk_every=100 --set dump.csv_every=20";
    const char* new_grid = "--set dump.vtk_every=70 --set dump.csv_every=35";
    char args[600];
    snprintf(args, sizeof args, "run grid.ini --set run.steps=600 %s --out ref_old", old_grid);
    assert_int_equal(run_cli(args), 0);
    snprintf(args, sizeof args, "run grid.ini --set run.steps=600 %s --out ref_new", new_grid);
    assert_int_equal(run_cli(args), 0);
    /* split at 300 (on the first grids, off the second), at 305 (off both: its last frame and
       row are dropped) and at 350 (off the first, on the second: written again) */
    const unsigned long long split[3] = {300, 305, 350};
    for (int c = 0; c < 3; c++) {
        char dir[32], csv[64];
        snprintf(dir, sizeof dir, "grid%llu", split[c]);
        snprintf(csv, sizeof csv, "%s/global.csv", dir);
        snprintf(args, sizeof args, "run grid.ini --set run.steps=%llu %s --out %s", split[c],
                 old_grid, dir);
        assert_int_equal(run_cli(args), 0);
        snprintf(args, sizeof args,
                 "run grid.ini --set run.steps=600 %s --out %s --restart %s/checkpoint.ckpt",
                 new_grid, dir, dir);
        int code = run_cli(args);
        if (code != 0)
            fail_msg("%s: exit %d\n%s", args, code, stderr_text());
        /* the frames: 0, 100, 200, 300 of the first grid up to the split, then 350, 420,
           490, 560 and the last, 600 */
        unsigned long long want[16];
        size_t n_want = 0;
        for (unsigned long long k = 0; k <= split[c]; k += 100)
            want[n_want++] = k;
        for (unsigned long long k = 70; k < 600; k += 70)
            if (k >= split[c] && !(k == split[c] && split[c] % 100 == 0))
                want[n_want++] = k;
        want[n_want++] = 600;
        double t[32];
        size_t n = series_times(dir, t, 32);
        if (n != n_want)
            fail_msg("split at %llu: %zu frames, expected %zu", split[c], n, n_want);
        for (size_t k = 0; k < n; k++) {
            /* the uninterrupted run's frame of that step */
            bool first = want[k] % 100 == 0 && want[k] <= split[c];
            size_t ref_k = first ? want[k] / 100 : want[k] == 600 ? 9 : want[k] / 70;
            CHECK_ABS(t[k], 2e-6 * (double)want[k], 1e-15);
            if (!same_frame(first ? "ref_old" : "ref_new", ref_k, dir, k))
                fail_msg("split at %llu: frame %zu (step %llu) differs from the uninterrupted "
                         "run's",
                         split[c], k, want[k]);
        }
        /* the rows: every 20 up to the split, then every 35 after it, and the last */
        unsigned long long rows[64], want_rows[64];
        size_t n_rows = csv_steps(csv, rows, 64), n_want_rows = 0;
        for (unsigned long long k = 0; k <= split[c]; k += 20)
            want_rows[n_want_rows++] = k;
        for (unsigned long long k = 35; k < 600; k += 35)
            if (k > split[c] || (k == split[c] && split[c] % 20 != 0))
                want_rows[n_want_rows++] = k;
        want_rows[n_want_rows++] = 600;
        if (n_rows != n_want_rows)
            fail_msg("split at %llu: %zu CSV rows, expected %zu", split[c], n_rows, n_want_rows);
        for (size_t k = 0; k < n_rows; k++) {
            if (rows[k] != want_rows[k])
                fail_msg("split at %llu: CSV row %zu is of step %llu, expected %llu", split[c], k,
                         rows[k], want_rows[k]);
            char* a = csv_row(csv, rows[k]);
            char* b = csv_row(rows[k] % 20 == 0 && rows[k] <= split[c] ? "ref_old/global.csv"
                                                                       : "ref_new/global.csv",
                              rows[k]);
            if (!a || !b || strcmp(a, b) != 0)
                fail_msg("split at %llu: the CSV row of step %llu differs from the "
                         "uninterrupted run's",
                         split[c], rows[k]);
            free(a);
            free(b);
        }
    }
}

/* Number of data rows in a CSV (lines starting with a digit). */
static size_t csv_rows(const char* path)
{
    char* t = test_read_file(path, NULL);
    size_t n = 0;
    for (const char* p = t; p && *p; p = strchr(p, '\n') ? strchr(p, '\n') + 1 : p + strlen(p))
        n += (*p >= '0' && *p <= '9');
    free(t);
    return n;
}

/* Starts the CLI in the background (stderr to err.txt); returns its pid. */
static pid_t spawn_cli(const char* args)
{
    char cmd[2048];
    snprintf(cmd, sizeof cmd, "cd '%s' && exec env " ENV " '%s' %s > out.txt 2> err.txt", tmpdir,
             test_cli_path(), args);
    pid_t pid = fork();
    assert_true(pid >= 0);
    if (pid == 0) {
        execl("/bin/sh", "sh", "-c", cmd, (char*)NULL);
        _exit(127);
    }
    return pid;
}

/* Starts `args`, waits until it is stepping (5 rows in tmpdir/csv), then sends it `count`
 * SIGINTs back to back, each as soon as the one before has been delivered (two sent while
 * neither is delivered would merge into one). Returns its wait status. */
static int interrupt_cli(const char* args, const char* csv, int count)
{
    pid_t pid = spawn_cli(args);
    struct timespec nap = {0, 1000000}, blink = {0, 20000};
    for (int k = 0; k < 60000 && csv_rows(tpath(csv)) < 5; k++)
        nanosleep(&nap, NULL);
    for (int n = 0; n < count; n++) {
        for (int k = 0; n > 0 && k < 50000 && test_signal_pending(pid, SIGINT); k++)
            nanosleep(&blink, NULL);
        kill(pid, SIGINT);
    }
    int status;
    assert_int_equal(waitpid(pid, &status, 0), pid);
    return status;
}

/* The step "(step N of" of the interruption message on stderr. */
static unsigned long long interrupted_step(const char* err)
{
    const char* p = strstr(err, "(step ");
    if (!p)
        fail_msg("no step in the interruption message:\n%s", err);
    return strtoull(p + 6, NULL, 10);
}

/* Copies tmpdir/a to tmpdir/b (a directory). */
static void copy_dir(const char* a, const char* b)
{
    char cmd[1400];
    snprintf(cmd, sizeof cmd, "rm -rf '%s/%s' && cp -r '%s/%s' '%s/%s'", tmpdir, b, tmpdir, a,
             tmpdir, b);
    assert_int_equal(system(cmd), 0);
}

/* Restarts as a demanding user tries them: a t_end before the checkpoint's time (exit 2, said
 * so, nothing touched); a CSV deleted, emptied or cut short at a row's end (exit 2, the file
 * as it was: the resumed run appended its rows after a gap); a frame the index lists deleted
 * (exit 2, nothing touched: the resumed index named it); two restarts in a row, and one
 * with another number of threads (bit-identical frames, index and summary), and one from a
 * checkpoint written at a signal in the first step. */
static void test_many_cli_restart_probes(void** state)
{
    (void)state;
    scenario("probe.ini", "[dump]\nvtk_every = 100\ncsv_every = 20\n");
    assert_int_equal(run_cli("run probe.ini --set run.steps=600 --out pwhole"), 0);
    assert_int_equal(run_cli("run probe.ini --set run.steps=300 --out p300"), 0);
    /* t_end before the checkpoint: refused, and not as "had reached its end" */
    copy_dir("p300", "pshort");
    char* err = expect_exit("run probe.ini --set run.t_end=4e-4 --out pshort --restart "
                            "pshort/checkpoint.ckpt",
                            2, "after this run's end at step 200");
    CHECK_CONTAINS(err, "a run cannot go back in time");
    assert_null(strstr(err, "had reached its end"));
    free(err);
    check_same_outputs("p300", "pshort", 4);
    /* the CSV deleted, emptied, or cut short at the end of a row (rows 0..240 of 300) */
    copy_dir("p300", "pcsv");
    assert_int_equal(rename(tpath("pcsv/global.csv"), tpath("global.keep")), 0);
    free(expect_exit("run probe.ini --set run.steps=600 --out pcsv --restart pcsv/checkpoint.ckpt",
                     2, "pcsv/global.csv is missing"));
    write_text("pcsv/global.csv", "");
    free(expect_exit("run probe.ini --set run.steps=600 --out pcsv --restart pcsv/checkpoint.ckpt",
                     2, "pcsv/global.csv has no header line"));
    char* whole = test_read_file(tpath("global.keep"), NULL);
    assert_non_null(whole);
    char* cut = strstr(whole, "\n0.00052,260,"); /* the row of step 260 */
    assert_non_null(cut);
    cut[1] = '\0';
    write_text("pcsv/global.csv", whole);
    free(whole);
    err = expect_exit("run probe.ini --set run.steps=600 --out pcsv --restart pcsv/checkpoint.ckpt",
                      2, "pcsv/global.csv ends at step 240, before the checkpoint's step 300");
    free(err);
    char* kept = test_read_file(tpath("pcsv/global.csv"), NULL);
    assert_non_null(strstr(kept, ",240,"));
    assert_null(strstr(kept, ",260,"));
    free(kept);
    /* a frame the index lists deleted (it stayed listed, the index naming a missing file),
       also the one at the checkpoint's step: refused, every file as it was */
    const char* gone[2] = {"particles_000001.vtk", "particles_000003.vtk"};
    for (int k = 0; k < 2; k++) {
        copy_dir("p300", "pframe");
        char name[64], needle[200], cmd[1400];
        snprintf(name, sizeof name, "pframe/%s", gone[k]);
        assert_int_equal(unlink(tpath(name)), 0);
        snprintf(needle, sizeof needle, "pframe/particles.vtk.series lists %s at t = ", gone[k]);
        err = expect_exit("run probe.ini --set run.steps=600 --out pframe --restart "
                          "pframe/checkpoint.ckpt",
                          2, needle);
        snprintf(needle, sizeof needle, "but pframe/%s is missing", gone[k]);
        CHECK_CONTAINS(err, needle);
        free(err);
        snprintf(cmd, sizeof cmd, "cd '%s' && cp p300/%s pframe/ && diff -r p300 pframe", tmpdir,
                 gone[k]);
        if (system(cmd) != 0)
            fail_msg("a restart refused for a missing %s changed the files of --out", gone[k]);
    }
    /* two restarts in a row */
    copy_dir("p300", "ptwice");
    assert_int_equal(run_cli("run probe.ini --set run.steps=450 --out ptwice --restart "
                             "ptwice/checkpoint.ckpt"),
                     0);
    assert_int_equal(run_cli("run probe.ini --set run.steps=600 --out ptwice --restart "
                             "ptwice/checkpoint.ckpt"),
                     0);
    check_same_outputs("pwhole", "ptwice", 7);
    /* another thread count: 600 spheres, so that the run's loops use the threads (from 512) */
    write_text("many.ini", WET_BOX "[insert]\ncount = 600\nradius_min = 0.2e-3\nradius_max = "
                                   "0.25e-3\nmaterial = wet\nvelocity_sigma = 0.2\nseed = 7\n"
                                   "[run]\ndt = 1e-6\n[dump]\nvtk_every = 50\ncsv_every = 10\n");
    char cmd[1400];
    snprintf(cmd, sizeof cmd,
             "cd '%s' && OMP_NUM_THREADS=2 OMP_WAIT_POLICY=passive '%s' run many.ini --set "
             "run.steps=200 --out %s > /dev/null 2> err.txt",
             tmpdir, test_cli_path(), "pthr2");
    assert_int_equal(system(cmd), 0);
    snprintf(cmd, sizeof cmd,
             "cd '%s' && OMP_NUM_THREADS=2 OMP_WAIT_POLICY=passive '%s' run many.ini --set "
             "run.steps=100 --out %s > /dev/null 2> err.txt",
             tmpdir, test_cli_path(), "pthr");
    assert_int_equal(system(cmd), 0);
    char* js = test_read_file(tpath("pthr/summary.json"), NULL);
    assert_non_null(js);
    free(js);
    assert_int_equal(run_cli("run many.ini --set run.steps=200 --out pthr --restart "
                             "pthr/checkpoint.ckpt"),
                     0); /* (one thread) */
    const char* same[3] = {"particles.vtk.series", "summary.json", "particles_000004.vtk"};
    for (int k = 0; k < 3; k++) {
        char pa[64], pb[64];
        snprintf(pa, sizeof pa, "pthr2/%s", same[k]);
        snprintf(pb, sizeof pb, "pthr/%s", same[k]);
        size_t la, lb;
        char* ta = test_read_file(tpath(pa), &la);
        char* tb = test_read_file(tpath(pb), &lb);
        if (ta && tb && k == 1) { /* (the commands differ by --restart) */
            assert_true(test_drop_json_command(ta));
            assert_true(test_drop_json_command(tb));
            la = strlen(ta);
            lb = strlen(tb);
        }
        if (!ta || !tb || la != lb || memcmp(ta, tb, la) != 0)
            fail_msg("%s differs after a restart on one thread of a run on two", same[k]);
        free(ta);
        free(tb);
    }
    for (size_t k = 0; k <= 4; k++)
        if (!same_frame("pthr2", k, "pthr", k))
            fail_msg("frame %zu differs after a restart on one thread of a run on two", k);
    /* a signal during the first step: 20000 spheres, a step takes milliseconds; the signal
       goes as soon as the first frame is indexed */
    write_text("first.ini",
               "[box]\nsize_x = 28e-3\nsize_y = 28e-3\nsize_z = 28e-3\n[material.wet]\n"
               "density = 2500\nyoungs_modulus = 1e7\nfilm = 20e-6\n[fluid]\nviscosity = 0.01\n"
               "surface_tension = 0.02\n[models]\nforce = hertz sb capillary\n[insert]\n"
               "layout = lattice\ncount = 20000\nradius = 0.45e-3\ngap = 10e-6\nmaterial = wet\n"
               "velocity_sigma = 0.01\n[run]\nsteps = 40\n[dump]\nvtk_every = 10\n"
               "csv_every = 5\n");
    assert_int_equal(run_cli("run first.ini --out fwhole"), 0);
    pid_t pid = spawn_cli("run first.ini --out first");
    struct timespec nap = {0, 200000};
    for (int k = 0; k < 100000 && !exists("first/particles.vtk.series"); k++)
        nanosleep(&nap, NULL);
    kill(pid, SIGINT);
    int status;
    assert_int_equal(waitpid(pid, &status, 0), pid);
    err = stderr_text();
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 130)
        fail_msg("SIGINT in the first step: status %d, expected exit 130\n%s", status, err);
    assert_true(interrupted_step(err) < 40);
    free(err);
    int code = run_cli("run first.ini --out first --restart first/checkpoint.ckpt");
    if (code != 0)
        fail_msg("resume after a SIGINT in the first step: exit %d\n%s", code, stderr_text());
    check_same_outputs("fwhole", "first", 5);
}

/* SIGINT: the checkpoint, exit 130, the command that resumes, and the CSV ending at the step
 * of the checkpoint; resuming gives the files of the uninterrupted run (the CSV without that
 * last row, off its grid of 10 steps unless the stop fell on it). Two SIGINTs back to back,
 * as GNU timeout sends them (to the process, then to its group), are one request: the run
 * still writes its checkpoint and exits 130 (the second killed it at once). */
static void test_many_cli_sigint_writes_a_checkpoint_and_resumes(void** state)
{
    (void)state;
    scenario("long.ini", "[dump]\nvtk_every = 2000\ncsv_every = 10\n");
    assert_int_equal(run_cli("run long.ini --set run.steps=12000 --out ref"), 0);
    /* the second directory's name needs quoting: the printed command must run as printed */
    const char* dirs[2] = {"sig", "it's 2"};
    const char* quoted[2] = {"sig", "'it'\\''s 2'"};
    const char* quoted_ckpt[2] = {"sig/checkpoint.ckpt", "'it'\\''s 2/checkpoint.ckpt'"};
    for (int k = 0; k < 2; k++) {
        char args[200], csv[64], resume[300];
        snprintf(args, sizeof args, "run long.ini --set run.steps=12000 --out %s", quoted[k]);
        snprintf(csv, sizeof csv, "%s/global.csv", dirs[k]);
        int status = interrupt_cli(args, csv, k + 1);
        char* err = stderr_text();
        if (!WIFEXITED(status) || WEXITSTATUS(status) != 130)
            fail_msg("%d SIGINT: status %d, expected exit 130 (the run must outlast the wait "
                     "for 5 CSV rows)\n%s",
                     k + 1, status, err);
        CHECK_CONTAINS(err, "stopping after this step to write the checkpoint");
        CHECK_CONTAINS(err, "interrupted by SIGINT");
        snprintf(resume, sizeof resume,
                 "resume with: wetdem run long.ini --set run.steps=12000 --out %s --restart %s",
                 quoted[k], quoted_ckpt[k]);
        CHECK_CONTAINS(err, resume);
        assert_int_equal(csv_last_step(csv), interrupted_step(err));
        snprintf(args, sizeof args, "%s/checkpoint.ckpt", dirs[k]);
        assert_true(exists(args));
        /* the command as printed, after "resume with: wetdem " */
        const char* printed = strstr(err, "resume with: wetdem ") + strlen("resume with: wetdem ");
        snprintf(args, sizeof args, "%.*s", (int)strcspn(printed, "\n"), printed);
        free(err);
        assert_int_equal(run_cli(args), 0);
        check_same_outputs("ref", dirs[k], 7); /* frames at 0, 2000, ..., 12000 */
    }
    /* without a checkpoint there is nothing to resume from: said so (it said "run with --out"
       though --out was given), and the summary is written all the same */
    int status = interrupt_cli("run long.ini --set run.steps=12000 --set dump.checkpoint=none "
                               "--out nock",
                               "nock/global.csv", 1);
    char* err = stderr_text();
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 130)
        fail_msg("SIGINT without a checkpoint: status %d, expected exit 130\n%s", status, err);
    CHECK_CONTAINS(err, "no checkpoint ([dump] checkpoint = none: the run cannot be resumed)");
    if (strstr(err, "resume with"))
        fail_msg("a resume command without a checkpoint:\n%s", err);
    free(err);
    char* summary = test_read_file(tpath("nock/summary.json"), NULL);
    assert_non_null(summary);
    CHECK_CONTAINS(summary, "\"interrupted\": true");
    free(summary);
}

/* A third SIGINT, sent while the run is still stopping after the first (20000 spheres: a step
 * and a checkpoint take milliseconds, the signals microseconds), stops it at once by the
 * signal: no new checkpoint, the periodic one before intact, no temporary file left. On a
 * loaded machine this process may be descheduled for longer than the run takes to stop; the
 * run then ends as after one request (exit 130, "interrupted by SIGINT"), which is tried
 * again, up to three times in all: any other end fails at once. */
static void test_many_cli_third_signal_stops_at_once(void** state)
{
    (void)state;
    write_text("slow.ini",
               "[box]\nsize_x = 28e-3\nsize_y = 28e-3\nsize_z = 28e-3\n[material.wet]\n"
               "density = 2500\nyoungs_modulus = 1e7\nfilm = 20e-6\n[fluid]\nviscosity = 0.01\n"
               "surface_tension = 0.02\n[models]\nforce = hertz sb capillary\n[insert]\n"
               "layout = lattice\ncount = 20000\nradius = 0.45e-3\ngap = 10e-6\nmaterial = wet\n"
               "velocity_sigma = 0.01\n[run]\nsteps = 100000\n[dump]\nvtk_every = 100000\n"
               "csv_every = 1\ncheckpoint_every = 2\n");
    char dir[32], args[64], csv[64], path[64];
    int status = 0;
    char* err = NULL;
    for (int attempt = 0; attempt < 3; attempt++) {
        snprintf(dir, sizeof dir, "slow%d", attempt);
        snprintf(args, sizeof args, "run slow.ini --out %s", dir);
        snprintf(csv, sizeof csv, "%s/global.csv", dir);
        free(err);
        status = interrupt_cli(args, csv, 3);
        err = stderr_text();
        if (!(WIFEXITED(status) && WEXITSTATUS(status) == 130 &&
              strstr(err, "interrupted by SIGINT")))
            break; /* not a run that stopped before the signals came */
    }
    if (!WIFSIGNALED(status) || WTERMSIG(status) != SIGINT)
        fail_msg("3 SIGINT: status %d, expected death by SIGINT\n%s", status, err);
    CHECK_CONTAINS(err, "stopped at once by a repeated signal, without a new checkpoint");
    assert_null(strstr(err, "interrupted by SIGINT"));
    free(err);
    snprintf(path, sizeof path, "%s/checkpoint.ckpt.tmp", dir);
    assert_false(exists(path));
    struct wetdem_checkpoint ck;
    char msg[256];
    snprintf(path, sizeof path, "%s/checkpoint.ckpt", dir);
    CHECK_OK(wetdem_checkpoint_read(tpath(path), &ck, msg, sizeof msg));
    assert_int_equal(ck.n_particles, 20000);
    assert_int_equal(ck.step % 2, 0); /* a periodic one */
    wetdem_checkpoint_clear(&ck);
}

/* global.csv starts with the git version and the command, as the other CSVs do (it named the
 * version alone), then says what it holds, and a restart keeps those lines whole however long:
 * the resume read the file in pieces of 4096 bytes and dropped a piece without a newline as a
 * row cut by a crash. Here the command is over 5000 characters (19 keys set to values padded with
 * zeros to 250 characters), and the resumed file is the uninterrupted run's. */
static void test_many_cli_csv_names_its_command(void** state)
{
    (void)state;
    scenario("cmd.ini", "[dump]\nvtk_every = 100\ncsv_every = 20\ncheckpoint = c.ckpt\n");
    static const char* const keys[] = {"material.wet.density=2500.",
                                       "material.wet.youngs_modulus=10000000.",
                                       "material.wet.poisson_ratio=0.3",
                                       "material.wet.restitution=0.6",
                                       "material.wet.friction_dry=0.4",
                                       "material.wet.friction_lub=0.1",
                                       "material.wet.film=0.00002",
                                       "fluid.viscosity=0.01",
                                       "fluid.surface_tension=0.02",
                                       "sim.gravity_x=0.",
                                       "sim.gravity_y=0.",
                                       "sim.gravity_z=-9.81",
                                       "box.size_x=0.006",
                                       "box.size_y=0.006",
                                       "box.size_z=0.008",
                                       "insert.radius_min=0.0004",
                                       "insert.radius_max=0.0005",
                                       "insert.velocity_sigma=0.2",
                                       "run.dt=0.000002"};
    size_t n_keys = sizeof keys / sizeof keys[0];
    char* sets = malloc(n_keys * 300);
    assert_non_null(sets);
    size_t at = 0;
    for (size_t k = 0; k < n_keys; k++) {
        const char* value = strchr(keys[k], '=') + 1;
        at += (size_t)sprintf(sets + at, " --set %s", keys[k]);
        for (size_t z = strlen(value); z < 250; z++)
            sets[at++] = '0';
    }
    sets[at] = '\0';
    assert_true(at > 5000);
    static const char* const runs[3] = {"--set run.steps=200 --out cmd_a",
                                        "--set run.steps=100 --out cmd_b",
                                        "--set run.steps=200 --out cmd_b --restart cmd_b/c.ckpt"};
    char* script = malloc(at + 400);
    assert_non_null(script);
    for (int r = 0; r < 3; r++) {
        snprintf(script, at + 400, ENV " '%s' run cmd.ini%s %s > out.txt 2> err.txt\n",
                 test_cli_path(), sets, runs[r]);
        write_text("cmd.sh", script);
        char cmd[600];
        snprintf(cmd, sizeof cmd, "cd '%s' && sh cmd.sh", tmpdir);
        if (system(cmd) != 0)
            fail_msg("run %d failed:\n%s", r, stderr_text());
    }
    char* csv = test_read_file(tpath("cmd_b/global.csv"), NULL);
    assert_non_null(csv);
    const char* head = "# wetdem " WETDEM_VERSION " (git ";
    assert_memory_equal(csv, head, strlen(head));
    const char* command = strchr(csv + strlen(head), '\n');
    assert_non_null(command);
    command++;
    char* want = malloc(at + 400);
    assert_non_null(want);
    snprintf(
        want, at + 400,
        "# command: wetdem run cmd.ini%s --set run.steps=100 --out cmd_b\n# many-particle run: "
        "global quantities\ntime [s],step [count],",
        sets);
    assert_memory_equal(command, want, strlen(want));
    free(csv);
    free(want);
    free(script);
    free(sets);
    check_same_outputs("cmd_a", "cmd_b", 3);
}

/* The CSV ends with the state of the last step, also off its grid of csv_every steps, and that
 * row agrees with summary.json; it is the row the library writes on its grid, byte for byte. */
static void test_many_cli_csv_ends_at_the_last_step(void** state)
{
    (void)state;
    scenario("tail.ini", "[dump]\nvtk_every = 100\ncsv_every = 20\n");
    assert_int_equal(run_cli("run tail.ini --set run.steps=610 --out tail"), 0);
    assert_int_equal(csv_last_step("tail/global.csv"), 610);
    char* row = last_line("tail/global.csv");
    double t, kinetic, potential, elastic;
    unsigned long long step;
    assert_int_equal(sscanf(row, "%lf,%llu,%lf,%lf,%lf", &t, &step, &kinetic, &potential, &elastic),
                     5);
    free(row);
    char* js = test_read_file(tpath("tail/summary.json"), NULL);
    CHECK_CONTAINS(js, "\"step\": 610, ");
    const char* keys[4] = {"\"time_s\": ", "\"kinetic\": ", "\"potential\": ", "\"elastic\": "};
    double csv_values[4] = {t, kinetic, potential, elastic};
    for (int k = 0; k < 4; k++) {
        const char* p = strstr(js, keys[k]);
        if (!p)
            fail_msg("%s missing in %s", keys[k], js);
        double v = strtod(p + strlen(keys[k]), NULL);
        CHECK_ABS(csv_values[k], v, 1e-8 * fabs(v)); /* the CSV has 9 digits */
    }
    free(js);
    /* 600 steps: the library's row of step 600 (every 20), and the CLI's (every 7: 595, 600) */
    assert_int_equal(run_cli("run tail.ini --set run.steps=600 --out grid"), 0);
    assert_int_equal(run_cli("run tail.ini --set run.steps=600 --set dump.csv_every=7 --out off"),
                     0);
    char* a = last_line("grid/global.csv");
    char* b = last_line("off/global.csv");
    assert_string_equal(a, b);
    free(a);
    free(b);
    assert_int_equal(csv_rows(tpath("off/global.csv")), 600 / 7 + 2); /* 0, 7, ..., 595, 600 */
    /* without the energy budget too (the row's energies then come from the state alone) */
    assert_int_equal(run_cli("run tail.ini --set run.steps=610 --set run.energy_budget=no "
                             "--out nobudget"),
                     0);
    assert_int_equal(csv_last_step("nobudget/global.csv"), 610);
}

/* A fresh run into a used --out replaces the earlier run's frames: none of a longer run is
 * left beside the new index, and files not named as frames stay; a resumed run keeps the
 * frames it continues. */
static void test_many_cli_fresh_run_replaces_earlier_frames(void** state)
{
    (void)state;
    scenario("frames.ini", "[dump]\nvtk_every = 100\ncsv_every = 20\nvtk_links = yes\n");
    assert_int_equal(run_cli("run frames.ini --set run.steps=600 --out reuse"), 0);
    for (int k = 0; k <= 6; k++) { /* each frame with its links */
        char name[64];
        snprintf(name, sizeof name, "reuse/particles_links_%06d.vtk", k);
        if (!exists(name))
            fail_msg("%s is missing", name);
    }
    const char* keep[] = {"reuse/particles_notes.vtk", "reuse/other_000005.vtk",
                          "reuse/particles_000005.vtk.bak", "reuse/particles_00005.vtk"};
    for (size_t k = 0; k < 4; k++)
        write_text(keep[k], "not a frame of this run\n");
    assert_int_equal(run_cli("run frames.ini --set run.steps=200 --out reuse"), 0);
    for (int k = 0; k <= 6; k++)
        for (int links = 0; links < 2; links++) {
            char name[64];
            snprintf(name, sizeof name, "reuse/particles%s_%06d.vtk", links ? "_links" : "", k);
            if (exists(name) != (k <= 2))
                fail_msg("%s %s", name, k <= 2 ? "is missing" : "of the earlier run is left");
        }
    for (size_t k = 0; k < 4; k++)
        if (!exists(keep[k]))
            fail_msg("%s, not a frame, was removed", keep[k]);
    /* a links frame the links index lists, deleted: refused, every file as it was (the
       resumed links index started after it, leaving out the links before it) */
    copy_dir("reuse", "links_gone");
    assert_int_equal(unlink(tpath("links_gone/particles_links_000001.vtk")), 0);
    char* err = expect_exit("run frames.ini --set run.steps=400 --out links_gone --restart "
                            "links_gone/checkpoint.ckpt",
                            2,
                            "links_gone/particles_links.vtk.series lists "
                            "particles_links_000001.vtk at t = ");
    CHECK_CONTAINS(err, "but links_gone/particles_links_000001.vtk is missing");
    free(err);
    char diff[600];
    snprintf(diff, sizeof diff,
             "cd '%s' && cp reuse/particles_links_000001.vtk links_gone/ && "
             "diff -r reuse links_gone",
             tmpdir);
    if (system(diff) != 0)
        fail_msg("a restart refused for a missing links frame changed the files of --out");
    assert_int_equal(run_cli("run frames.ini --set run.steps=400 --out reuse --restart "
                             "reuse/checkpoint.ckpt"),
                     0);
    assert_int_equal(run_cli("run frames.ini --set run.steps=400 --out whole400"), 0);
    check_same_outputs("whole400", "reuse", 5);
    /* a fresh run without links leaves none of the earlier run's, nor their index */
    assert_int_equal(run_cli("run frames.ini --set run.steps=200 --set dump.vtk_links=no "
                             "--out reuse"),
                     0);
    assert_false(exists("reuse/particles_links_000000.vtk"));
    assert_false(exists("reuse/particles_links.vtk.series"));
    assert_true(exists("reuse/particles_000002.vtk"));
    /* resumed with links, it has them from the restart on, and their index lists only those */
    assert_int_equal(run_cli("run frames.ini --set run.steps=400 --out reuse --restart "
                             "reuse/checkpoint.ckpt"),
                     0);
    char* index = test_read_file(tpath("reuse/particles_links.vtk.series"), NULL);
    assert_non_null(index);
    CHECK_CONTAINS(index, "\"particles_links_000003.vtk\"");
    CHECK_CONTAINS(index, "\"particles_links_000004.vtk\"");
    assert_null(strstr(index, "particles_links_000002.vtk"));
    free(index);
    assert_true(exists("reuse/particles_links_000004.vtk"));
    assert_false(exists("reuse/particles_links_000002.vtk"));
    /* a fresh run killed before its end leaves no summary of the earlier run beside its own
       files (killed once its CSV, which names its command, is there: past the removal) */
    assert_true(exists("reuse/summary.json"));
    pid_t pid = spawn_cli("run frames.ini --set run.steps=1000000 --out reuse");
    struct timespec nap = {0, 1000000};
    for (int k = 0; k < 60000; k++) {
        char* csv = test_read_file(tpath("reuse/global.csv"), NULL);
        bool started = csv && strstr(csv, "run.steps=1000000");
        free(csv);
        if (started)
            break;
        nanosleep(&nap, NULL);
    }
    kill(pid, SIGKILL);
    int status;
    assert_int_equal(waitpid(pid, &status, 0), pid);
    if (!WIFSIGNALED(status) || WTERMSIG(status) != SIGKILL)
        fail_msg("the long run was not killed: status %d\n%s", status, stderr_text());
    assert_false(exists("reuse/summary.json"));
    /* nor, when it writes neither, the earlier run's CSV and checkpoint */
    assert_int_equal(run_cli("run frames.ini --set run.steps=200 --out reuse"), 0);
    assert_int_equal(run_cli("run frames.ini --set run.steps=200 --set dump.csv=none "
                             "--set dump.checkpoint=none --out reuse"),
                     0);
    assert_true(exists("reuse/summary.json"));
    assert_false(exists("reuse/global.csv"));
    assert_false(exists("reuse/checkpoint.ckpt"));
    /* nor the earlier run's frames and index when it writes no frames (vtk_every = 0, or vtk =
       none: those under the default name): the index described the earlier run beside this
       run's summary */
    const char* no_frames[] = {"--set dump.vtk_every=0", "--set dump.vtk=none"};
    for (int k = 0; k < 2; k++) {
        assert_int_equal(run_cli("run frames.ini --set run.steps=200 --out reuse"), 0);
        assert_true(exists("reuse/particles.vtk.series"));
        assert_true(exists("reuse/particles_links_000002.vtk"));
        char cmd[200];
        snprintf(cmd, sizeof cmd, "run frames.ini --set run.steps=200 %s --out reuse",
                 no_frames[k]);
        assert_int_equal(run_cli(cmd), 0);
        assert_true(exists("reuse/summary.json"));
        assert_false(exists("reuse/particles.vtk.series"));
        assert_false(exists("reuse/particles_links.vtk.series"));
        for (int f = 0; f <= 2; f++) {
            char name[64];
            snprintf(name, sizeof name, "reuse/particles_%06d.vtk", f);
            if (exists(name))
                fail_msg("%s of the earlier run is left by a run with %s", name, no_frames[k]);
            snprintf(name, sizeof name, "reuse/particles_links_%06d.vtk", f);
            if (exists(name))
                fail_msg("%s of the earlier run is left by a run with %s", name, no_frames[k]);
        }
    }
}

/* A directory in --out named as one of the run's outputs, or as the temporary file one is
 * written to, is refused (exit 2, the path named) before any file is touched: a fresh run
 * removed the earlier run's frames, CSV and checkpoint, then failed on it with exit 1, and a
 * restart trimmed the CSV and ran to its end before it failed to write its summary there. */
static void test_many_cli_refuses_a_directory_named_as_an_output(void** state)
{
    (void)state;
    scenario("named.ini", "[dump]\nvtk_every = 100\ncsv_every = 20\nvtk_links = yes\n");
    assert_int_equal(run_cli("run named.ini --set run.steps=300 --out named"), 0);
    copy_dir("named", "named_before");
    const char* taken[] = {"global.csv",           "summary.json",
                           "checkpoint.ckpt",      "checkpoint.ckpt.tmp",
                           "particles_000002.vtk", "particles_links_000007.vtk.tmp",
                           "particles.vtk.series", "particles_links.vtk.series.tmp"};
    char cmd[1400], name[128], args[256];
    for (size_t k = 0; k < sizeof taken / sizeof taken[0]; k++)
        for (int restart = 0; restart < 2; restart++) {
            snprintf(name, sizeof name, "named/%s", taken[k]);
            bool was = exists(name);
            if (was)
                assert_int_equal(rename(tpath(name), tpath("taken.keep")), 0);
            assert_int_equal(mkdir(tpath(name), 0755), 0);
            snprintf(args, sizeof args, "run named.ini --set run.steps=500 --out named%s",
                     restart ? " --restart named/checkpoint.ckpt" : "");
            char needle[200];
            snprintf(needle, sizeof needle, "run: %s is a directory, named as ", name);
            free(expect_exit(args, 2, needle));
            assert_int_equal(rmdir(tpath(name)), 0);
            if (was)
                assert_int_equal(rename(tpath("taken.keep"), tpath(name)), 0);
            snprintf(cmd, sizeof cmd, "diff -r '%s/named_before' '%s/named' > /dev/null", tmpdir,
                     tmpdir);
            if (system(cmd) != 0)
                fail_msg("a %s with %s as a directory changed the files of --out",
                         restart ? "restart" : "fresh run", taken[k]);
        }
    /* a FIFO where the CSV is trimmed (the restart opened it and waited for a writer) */
    assert_int_equal(mkfifo(tpath("named/global.csv.tmp"), 0644), 0);
    free(expect_exit("run named.ini --set run.steps=500 --out named --restart "
                     "named/checkpoint.ckpt",
                     2, "run: named/global.csv.tmp is not a regular file"));
    assert_int_equal(unlink(tpath("named/global.csv.tmp")), 0);
    /* a fresh run that writes no CSV still removes the earlier one's: a directory there too */
    assert_int_equal(rename(tpath("named/global.csv"), tpath("taken.keep")), 0);
    assert_int_equal(mkdir(tpath("named/global.csv"), 0755), 0);
    free(expect_exit("run named.ini --set run.steps=500 --set dump.csv=none --out named", 2,
                     "run: named/global.csv is a directory, named as the CSV"));
    assert_true(exists("named/particles_000003.vtk"));
    assert_true(exists("named/summary.json"));
}

/* A restart whose scenario derives another step (here [integrator] dt_fraction, which the
 * checkpoint's fingerprint does not hold: it holds the settings' dt, 0 = derived) is refused
 * before any file is touched: it ran on with the checkpoint's step, its end and its outputs
 * placed by the other, and a restart it then found past its end had cut the CSV's last row. */
static void test_many_cli_restart_refuses_another_step(void** state)
{
    (void)state;
    write_text("derived.ini",
               WET_BOX "[insert]\ncount = 60\nradius_min = 0.4e-3\nradius_max = 0.5e-3\n"
                       "material = wet\nseed = 7\n[dump]\ncsv_every = 10\n");
    assert_int_equal(run_cli("run derived.ini --set run.steps=40 --out der"), 0);
    char* before = test_read_file(tpath("der/global.csv"), NULL);
    assert_non_null(before);
    const char* other = "--set integrator.dt_fraction=0.01 --restart der/checkpoint.ckpt";
    char args[512];
    snprintf(args, sizeof args, "run derived.ini --set run.steps=80 %s --out der", other);
    free(expect_exit(args, 2, "the checkpoint's step is dt = "));
    snprintf(args, sizeof args, "run derived.ini --set run.steps=20 %s --out der", other);
    free(expect_exit(args, 2, "the checkpoint's step is dt = "));
    snprintf(args, sizeof args, "run derived.ini --check --set run.steps=80 %s", other);
    free(expect_exit(args, 2, "the checkpoint's step is dt = "));
    char* after = test_read_file(tpath("der/global.csv"), NULL);
    assert_non_null(after);
    assert_string_equal(before, after);
    free(before);
    free(after);
    assert_int_equal(run_cli("run derived.ini --set run.steps=80 --out der --restart "
                             "der/checkpoint.ckpt"),
                     0);
}

/* The summary gives a large mean agglomerate size as a whole number: 1000 wet spheres on a
 * lattice 10 um apart, every neighbour held by a bridge, are one agglomerate of 1000 (%.3g
 * printed 1e+03). */
static void test_many_cli_summary_mean_size_readable(void** state)
{
    (void)state;
    write_text("agglomerate.ini",
               "[box]\nsize_x = 9.2e-3\nsize_y = 9.2e-3\nsize_z = 9.2e-3\n[material.wet]\n"
               "density = 2500\nyoungs_modulus = 1e7\nfilm = 20e-6\n[fluid]\nviscosity = 0.01\n"
               "surface_tension = 0.02\n[models]\nforce = hertz sb capillary\n[insert]\n"
               "layout = lattice\ncount = 1000\nradius = 0.45e-3\ngap = 10e-6\nmaterial = wet\n"
               "[run]\nsteps = 1\n");
    expect_output("run agglomerate.ini", "out.txt", "agglomerates       1  (mean size 1000)\n");
}

/* Progress: nothing on stderr when it is a file; on a terminal, the spheres placed by the
 * random insertion and then a line with the time left. */
static void test_many_cli_progress_only_on_a_terminal(void** state)
{
    (void)state;
    /* (many_hmin_fraction = 0: the given step lets pairs cross h_min within a step, which the
       run would warn about on stderr, test_many_cli_warns_about_the_step) */
    scenario("progress.ini", "[integrator]\nmany_hmin_fraction = 0\n");
    assert_int_equal(run_cli("run progress.ini --set run.steps=200"), 0);
    char* err = stderr_text();
    assert_string_equal(err, "");
    free(err);
    int master;
    pid_t pid = forkpty(&master, NULL, NULL, NULL);
    assert_true(pid >= 0);
    if (pid == 0) {
        char cmd[2048];
        snprintf(cmd, sizeof cmd,
                 "cd '%s' && exec env " ENV " '%s' run progress.ini "
                 "--set run.steps=200 > /dev/null",
                 tmpdir, test_cli_path());
        execl("/bin/sh", "sh", "-c", cmd, (char*)NULL);
        _exit(127);
    }
    char buf[8192];
    size_t n = 0;
    ssize_t got;
    while (n + 1 < sizeof buf && (got = read(master, buf + n, sizeof buf - n - 1)) > 0)
        n += (size_t)got;
    buf[n] = '\0';
    int status;
    waitpid(pid, &status, 0);
    close(master);
    assert_true(WIFEXITED(status) && WEXITSTATUS(status) == 0);
    CHECK_CONTAINS(buf, "step 200/200 (100.0 %)");
    CHECK_CONTAINS(buf, "s left");
    /* the random insertion's count, before the steps (and not on a file, above) */
    CHECK_CONTAINS(buf, "wetdem: [insert] 150/150 spheres placed (100.0 %)");
    assert_true(strstr(buf, "spheres placed") < strstr(buf, "step 200/200"));
}

/* Two random groups in one box: the later one keeps clear of the earlier (else the CLI's own
 * check between groups, tested above, refuses the file); smaller spheres first leave no room
 * for larger ones, and the message says so. */
static void test_many_cli_random_groups_share_the_box(void** state)
{
    (void)state;
    const char* box = "[box]\nsize_x = 10e-3\nsize_y = 10e-3\nsize_z = 10e-3\nperiodic = x y z\n"
                      "[run]\nsteps = 10\n";
    /* 8 of R = 1.5 mm (volume fraction 0.11), then 400 of 0.3 mm (0.045): drawn alone, some
     * 400 x 8 x 4/3 pi (1.8 mm)^3 / (10 mm)^3 = 78 small spheres would land on a big one */
    char text[1024];
    snprintf(text, sizeof text,
             "%s[insert.big]\ncount = 8\nradius = 1.5e-3\nseed = 1\n"
             "[insert.small]\ncount = 400\nradius = 0.3e-3\nseed = 2\n",
             box);
    write_text("groups.ini", text);
    expect_output("run groups.ini --check", "out.txt", "particles     408");
    /* 1500 of 0.3 mm first (0.17): a big sphere's centre needs none of theirs within 1.8 mm,
     * where 1500 x 4/3 pi (1.8 mm)^3 / (10 mm)^3 = 37 are expected (a chance of e^-37) */
    snprintf(text, sizeof text,
             "%s[insert.small]\ncount = 1500\nradius = 0.3e-3\nseed = 2\n"
             "[insert.big]\ncount = 8\nradius = 1.5e-3\nseed = 1\n",
             box);
    expect_bad("groups_bad.ini", text, 13, "insert the groups of larger spheres first");
}

/* The text of file `name` in tmpdir from its line starting with "POINTS" on (a frame's
 * spheres and their arrays, without the title and TIME that carry the time); NULL if none. */
static char* frame_from_points(const char* name, size_t* len)
{
    size_t n = 0;
    char* text = test_read_file(tpath(name), &n);
    assert_non_null(text);
    for (size_t k = 0; k + 7 < n; k++)
        if ((k == 0 || text[k - 1] == '\n') && memcmp(text + k, "POINTS ", 7) == 0) {
            *len = n - k;
            memmove(text, text + k, n - k);
            return text;
        }
    free(text);
    return NULL;
}

/* Runs `args` (exit 0) and requires frame `dst` of tmpdir to hold the spheres and arrays of
 * frame `src` bit for bit (frame_from_points: the time may differ). */
static void run_gives_frame(const char* args, const char* dst, const char* src)
{
    assert_int_equal(run_cli(args), 0);
    size_t la = 0, lb = 0;
    char* a = frame_from_points(src, &la);
    char* b = frame_from_points(dst, &lb);
    assert_non_null(a);
    assert_non_null(b);
    if (la != lb || memcmp(a, b, la) != 0)
        fail_msg("%s: %s, the frame written, differs from %s, the frame read", args, dst, src);
    free(a);
    free(b);
}

/* [read.NAME]: spheres from a frame of an earlier run (ASCII and binary) start the run at that
 * frame's state bit for bit; from a CSV at the parsed values; bad files exit 2 naming the
 * scenario line, the file and its line or array, and write nothing. */
static void test_many_cli_read_spheres_from_a_file(void** state)
{
    (void)state;
    for (int binary = 0; binary < 2; binary++) {
        char extra[200], text[2048];
        snprintf(extra, sizeof extra, "steps = 40\n[dump]\nvtk_every = 40\nvtk_binary = %s\n",
                 binary ? "yes" : "no");
        scenario("src.ini", extra);
        assert_int_equal(run_cli("run src.ini --out src"), 0);
        /* the state at step 40, read into a run of its own: its frame 0 is that state, and its
           counts of contacts, bridges and agglomerates are those of the frame read */
        snprintf(text, sizeof text,
                 WET_BOX "[read.bed]\nfile = src/particles_000001.vtk\nmaterial = wet\n"
                         "[run]\ndt = 2e-6\nsteps = 1\n[dump]\nvtk_every = 1\nvtk_binary = %s\n",
                 binary ? "yes" : "no");
        write_text("dst.ini", text);
        run_gives_frame("run dst.ini --out dst", "dst/particles_000000.vtk",
                        "src/particles_000001.vtk");
    }
    /* a run's .vtk.series index stands for its last frame (step 40 of the binary run) */
    write_text("series.ini", WET_BOX "[read.bed]\nfile = src/particles.vtk.series\nmaterial = wet\n"
                                     "[run]\ndt = 2e-6\nsteps = 1\n[dump]\nvtk_every = 1\n");
    run_gives_frame("run series.ini --out series", "series/particles_000000.vtk",
                    "src/particles_000001.vtk");
    /* a CSV: the spheres at the values parsed (the ASCII frame's %.17g gives them back),
       overlapping each other and the floor as a settled packing does; blank and '#' lines
       skipped, units in the header */
    static const char* const row[3][6] = {
        {"1.0000000000000001e-3", "3e-3", "0.49999999999999994e-3", "5e-4", "0.1", "2"},
        {"1.9e-3", "3e-3", "0.5e-3", "0.5e-3", "-0.10000000000000001", "0"},
        {"4.2e-3", "3e-3", "3.3333333333333335e-3", "4e-4", "0", "-7.5"}};
    char csv[1024] = "# three spheres\nx [m], y [m], z [m], radius [m], vx, spin_y\n";
    for (int i = 0; i < 3; i++) {
        size_t at = strlen(csv);
        snprintf(csv + at, sizeof csv - at, "%s%s, %s, %s, %s, %s, %s\n", i == 2 ? "\n" : "",
                 row[i][0], row[i][1], row[i][2], row[i][3], row[i][4], row[i][5]);
    }
    write_text("bed.csv", csv);
    write_text("csv.ini", WET_BOX "[read.bed]\nfile = bed.csv\nmaterial = wet\n[run]\ndt = 2e-6\n"
                                  "steps = 1\n[dump]\nvtk_every = 1\nvtk_binary = no\n");
    assert_int_equal(run_cli("run csv.ini --out csv"), 0);
    char* frame = test_read_file(tpath("csv/particles_000000.vtk"), NULL);
    assert_non_null(frame);
    for (int i = 0; i < 3; i++) {
        double v[6];
        for (int k = 0; k < 6; k++)
            v[k] = strtod(row[i][k], NULL);
        char want[3][200];
        snprintf(want[0], sizeof want[0], "\n%.17g %.17g %.17g\n", v[0], v[1], v[2]);
        snprintf(want[1], sizeof want[1], "\n%.17g\n", v[3]);
        snprintf(want[2], sizeof want[2], "\n%.17g 0 0\n", v[4]);
        for (int k = 0; k < 3; k++)
            CHECK_CONTAINS(frame, want[k]);
    }
    CHECK_CONTAINS(frame, "spin 3 3 double\n0 2 0\n0 0 0\n0 -7.5 0\n");
    free(frame);
    /* the same spheres as a fixed base: at rest whatever the file's velocities and spins, and
       where the file put them after 200 steps, while a free sphere falls */
    write_text("fixed.ini", WET_BOX "[read.bed]\nfile = bed.csv\nmaterial = wet\nfixed = yes\n"
                                    "[particle.drop]\nradius = 4e-4\nx = 3e-3\ny = 3e-3\nz = "
                                    "2.5e-3\nmaterial = wet\n[run]\ndt = 2e-6\nsteps = 200\n"
                                    "[dump]\nvtk_every = 200\nvtk_binary = no\n");
    expect_output("run fixed.ini --out fixed", "out.txt",
                  "particles          4  (3 fixed, walls 2)");
    char* said = test_read_file(tpath("fixed/summary.json"), NULL);
    CHECK_CONTAINS(said, "\"particles\": 4, \"fixed\": 3, \"walls\": 2,");
    free(said);
    expect_output("run fixed.ini --check", "out.txt", "  particles     4  (3 fixed)\n");
    for (int f = 0; f < 2; f++) {
        frame = test_read_file(
            tpath(f ? "fixed/particles_000001.vtk" : "fixed/particles_000000.vtk"), NULL);
        assert_non_null(frame);
        char want[600] = "POINTS 4 double\n";
        for (int i = 0; i < 3; i++) {
            size_t at = strlen(want);
            snprintf(want + at, sizeof want - at, "%.17g %.17g %.17g\n", strtod(row[i][0], NULL),
                     strtod(row[i][1], NULL), strtod(row[i][2], NULL));
        }
        CHECK_CONTAINS(frame, want);
        CHECK_CONTAINS(frame, "velocity 3 4 double\n0 0 0\n0 0 0\n0 0 0\n");
        CHECK_CONTAINS(frame, "spin 3 4 double\n0 0 0\n0 0 0\n0 0 0\n");
        /* fixed spheres meet neither each other (the first two overlap by 0.1 mm) nor a wall
           (the first cuts the floor by 1e-19 m): no contact, and no infinite-mass force */
        CHECK_CONTAINS(frame, "contacts 1 4 int\n0\n0\n0\n0\n");
        if (f) { /* the free sphere has fallen by g t^2 / 2 (0.78 um: velocity Verlet is exact
                    under a constant force but for rounding, a few ulp of z over 200 steps) */
            const char* line = strstr(frame, want) + strlen(want);
            double x, y, z, t = 200 * 2e-6;
            assert_int_equal(sscanf(line, "%lf %lf %lf", &x, &y, &z), 3);
            CHECK_ABS(z, 2.5e-3 - 0.5 * 9.81 * t * t, 1e-17);
            CHECK_REL(x, 3e-3, 0);
        }
        CHECK_CONTAINS(frame, "fixed 1 4 int\n1\n1\n1\n0\n");
        free(frame);
    }
    /* that frame read back as it is (fixed = file, the default) starts a run at its state bit
       for bit, the base still fixed; with fixed = no every sphere is free */
    const char* again = WET_BOX "[read.all]\nfile = fixed/particles_000001.vtk\nmaterial = wet\n"
                                "%s[run]\ndt = 2e-6\nsteps = 1\n[dump]\nvtk_every = 1\n"
                                "vtk_binary = no\n";
    char ini[2048];
    snprintf(ini, sizeof ini, again, "");
    write_text("again.ini", ini);
    run_gives_frame("run again.ini --out again", "again/particles_000000.vtk",
                    "fixed/particles_000001.vtk");
    snprintf(ini, sizeof ini, again, "fixed = no\n");
    write_text("again.ini", ini);
    assert_int_equal(run_cli("run again.ini --out free"), 0);
    frame = test_read_file(tpath("free/particles_000000.vtk"), NULL);
    assert_non_null(frame);
    CHECK_CONTAINS(frame, "fixed 1 4 int\n0\n0\n0\n0\n");
    free(frame);
    /* a fixed [particle] may cut a wall, as a fixed sphere read from a file may: it meets
       none (it was refused as "outside the box ... or cuts a wall"); a free one may not */
    const char* sunk = WET_BOX "[particle.base]\nradius = 4e-4\nx = 3e-3\ny = 3e-3\nz = 1e-4\n"
                               "material = wet\nfixed = %s\n[run]\ndt = 2e-6\nsteps = 1\n";
    snprintf(ini, sizeof ini, sunk, "yes");
    write_text("sunk.ini", ini);
    expect_output("run sunk.ini --check", "out.txt", "  particles     1  (1 fixed)\n");
    snprintf(ini, sizeof ini, sunk, "no");
    write_text("sunk.ini", ini);
    free(expect_exit("run sunk.ini --check", 2,
                     "sphere 1 of [particle.base] (centre z = 0.0001 m, radius 0.0004 m) is "
                     "outside the box [0, 0.008] m or cuts a wall"));
    /* a CSV's fixed column */
    write_text("fixed.csv", "x,y,z,radius,vx,fixed\n1e-3,3e-3,1e-3,4e-4,0,1\n"
                            "3e-3,3e-3,3e-3,4e-4,0.1,0\n");
    write_text("fixed_csv.ini", WET_BOX "[read.bed]\nfile = fixed.csv\nmaterial = wet\n[run]\n"
                                        "dt = 2e-6\nsteps = 1\n[dump]\nvtk_every = 1\n"
                                        "vtk_binary = no\n");
    assert_int_equal(run_cli("run fixed_csv.ini --out fixed_csv"), 0);
    frame = test_read_file(tpath("fixed_csv/particles_000000.vtk"), NULL);
    assert_non_null(frame);
    CHECK_CONTAINS(frame, "fixed 1 2 int\n1\n0\n");
    CHECK_CONTAINS(frame, "velocity 3 2 double\n0 0 0\n0.10000000000000001 0 0\n");
    free(frame);
    /* with fixed = no the column is not read, so a sphere it marks fixed may move (it was
       refused as "a fixed sphere ... at rest"); with fixed = yes the velocities are not used */
    write_text("moving.csv", "x,y,z,radius,vx,fixed\n1e-3,3e-3,1e-3,4e-4,0.1,1\n");
    write_text("moving.ini", WET_BOX "[read.bed]\nfile = moving.csv\nmaterial = wet\n[run]\n"
                                     "dt = 2e-6\nsteps = 1\n[dump]\nvtk_every = 1\n"
                                     "vtk_binary = no\n");
    free(expect_exit("run moving.ini --check", 2, "must be 0"));
    const char* fixed_as[2] = {"no", "yes"};
    const char* want[2] = {"fixed 1 1 int\n0\n", "fixed 1 1 int\n1\n"};
    for (int k = 0; k < 2; k++) {
        char args[200];
        snprintf(args, sizeof args, "run moving.ini --out moving --set read.bed.fixed=%s",
                 fixed_as[k]);
        assert_int_equal(run_cli(args), 0);
        frame = test_read_file(tpath("moving/particles_000000.vtk"), NULL);
        assert_non_null(frame);
        CHECK_CONTAINS(frame, want[k]);
        CHECK_CONTAINS(frame, k ? "velocity 3 1 double\n0 0 0\n"
                                : "velocity 3 1 double\n0.10000000000000001 0 0\n");
        free(frame);
    }
    /* two materials by a CSV's material column; the frame of that run (material array 0 1 1
       as the scenario's materials list them) read back with the same list starts at its state
       bit for bit; without the list every sphere takes `material`, with a warning */
    write_text("two.csv", "x,y,z,radius,material\n1e-3,3e-3,1e-3,4e-4,0\n3e-3,3e-3,3e-3,4e-4,1\n"
                          "5e-3,3e-3,3e-3,4e-4,1\n");
    const char* two = WET_BOX "[read.bed]\nfile = %s\n%s\n[run]\ndt = 2e-6\nsteps = 1\n"
                              "[dump]\nvtk_every = 1\nvtk_binary = no\n";
    snprintf(ini, sizeof ini, two, "two.csv", "materials = wet glass");
    write_text("two.ini", ini);
    expect_output("run two.ini --check", "out.txt", "  materials     0 wet, 1 glass\n");
    assert_int_equal(run_cli("run two.ini --out two"), 0);
    frame = test_read_file(tpath("two/particles_000000.vtk"), NULL);
    assert_non_null(frame);
    CHECK_CONTAINS(frame, "material 1 3 int\n0\n1\n1\n");
    free(frame);
    snprintf(ini, sizeof ini, two, "two/particles_000000.vtk", "materials = wet, glass");
    write_text("two_again.ini", ini);
    run_gives_frame("run two_again.ini --out two_again", "two_again/particles_000000.vtk",
                    "two/particles_000000.vtk");
    snprintf(ini, sizeof ini, two, "two/particles_000000.vtk", "material = wet");
    write_text("two_one.ini", ini);
    assert_int_equal(run_cli("run two_one.ini --out two_one"), 0);
    char* warned = stderr_text();
    CHECK_CONTAINS(warned, "two_one.ini: [read.bed]: the spheres of two/particles_000000.vtk have "
                           "material indices 0 to 1; every one takes material = wet (materials = "
                           "... keeps them apart)");
    free(warned);
    frame = test_read_file(tpath("two_one/particles_000000.vtk"), NULL);
    CHECK_CONTAINS(frame, "material 1 3 int\n0\n0\n0\n");
    free(frame);
    /* and what materials refuses: the scenario's line of the key (24) */
    const struct {
        const char *file, *keys, *what;
    } refused[] = {
        {"two.csv", "materials = wet",
         "sphere 2 of two.csv has material 1; materials names 1 "
         "(indices 0 to 0)"},
        {"bed.csv", "materials = wet glass", "bed.csv has no material column (a CSV) or array"},
        {"two.csv", "materials = wet glas", "unknown material 'glas' (did you mean 'glass'?)"},
        {"two.csv", "materials = wet glass\nmaterial = wet",
         "give material (every sphere) or materials (by the file's material column), not both"},
        {"two.csv", "materials = ,", "materials names none"},
        /* an empty name would be skipped: glass would take index 1, meant for another */
        {"two.csv", "materials = wet,,glass",
         "materials = wet,,glass: two commas with no name between them"},
    };
    for (size_t k = 0; k < sizeof refused / sizeof refused[0]; k++) {
        snprintf(ini, sizeof ini, two, refused[k].file, refused[k].keys);
        expect_bad("refused.ini", ini, 24, refused[k].what);
    }

    /* bad files: the scenario's file line (22), the file's own line or array */
    const char* head = WET_BOX "[read.bed]\nfile = ";
    const char* tail = "\nmaterial = wet\n[run]\ndt = 2e-6\nsteps = 1\n";
    struct {
        const char *csv, *what;
    } bad[] = {
        {"x,y,z,radus\n1e-3,1e-3,1e-3,1e-4\n", "bad.csv:1: unknown column 'radus' (did you "
                                               "mean 'radius'?)"},
        {"x,y,z\n1e-3,1e-3,1e-3\n", "bad.csv:1: the header has no column 'radius'"},
        /* a unit label is checked, not dropped: vx [mm/s] read as m/s was 1000 x too fast */
        {"x,y,z,radius,vx [mm/s]\n1e-3,1e-3,1e-3,1e-4,5\n",
         "bad.csv:1: column 'vx [mm/s]': vx is read in m/s, not mm/s"},
        {"x [m] extra,y,z,radius\n1e-3,1e-3,1e-3,1e-4\n",
         "bad.csv:1: column 'x [m] extra': a unit is written as 'name [unit]'"},
        {"# c\nx,y,z,radius\n1e-3,1e-3,1e-3,1e-4\n2e-3,1e-3,nan,1e-4\n",
         "bad.csv:4: z = 'nan' is not a finite number"},
        {"x,y,z,radius\n1e-3,1e-3,1e-3,-1e-4\n",
         "bad.csv:2: radius = -0.0001 m is not in (0, 1] m"},
        {"x,y,z,radius\n1e-3,1e-3,1e-3\n", "bad.csv:2: 3 fields, the header has 4 columns"},
        {"x,y,z,radius,fixed\n1e-3,1e-3,1e-3,1e-4,0.5\n",
         "bad.csv:2: fixed = 0.5 is not 0 (free) or 1 (held in place)"},
        {"x,y,z,radius,fixed,spin_z\n1e-3,1e-3,1e-3,1e-4,1,-3\n",
         "bad.csv:2: a fixed sphere (fixed = 1) is held in place, at rest: spin_z = -3 must be 0"},
        {"x,y,z,radius,material\n1e-3,1e-3,1e-3,1e-4,1.5\n",
         "bad.csv:2: material = 1.5 is not a whole number in [0, 1000]"},
        {"x,y,z,radius\n", "bad.csv:1: no spheres after the header"},
        {"", "bad.csv: the file is empty"},
        /* a row given twice: two spheres at one centre, pushed apart along an arbitrary axis */
        {"x,y,z,radius\n1e-3,1e-3,1e-3,1e-4\n2e-3,1e-3,1e-3,1e-4\n1e-3,1e-3,1e-3,1e-4\n",
         "bad.csv:4: centre (0.001, 0.001, 0.001) m, that of line 2: two spheres at one centre"},
        /* and one centre through the periodic face x (WET_BOX: x and y periodic, 6 mm) */
        {"x,y,z,radius\n0,1e-3,1e-3,1e-4\n6e-3,1e-3,1e-3,1e-4\n",
         "bad.csv:3: centre (0.006, 0.001, 0.001) m, that of line 2: two spheres at one centre "
         "(on a periodic axis, 0 and the box length are one place)"},
        {"x,y,z,radius\n1e-3,1e-3,9e-3,1e-4\n", "sphere 1 of [read.bed] (centre z = 0.009 m"},
        /* just outside: the centre with the digits that tell it from the box's edge (it read
           "centre z = 0.008 m ... outside the box [0, 0.008] m") */
        {"x,y,z,radius\n1e-3,1e-3,8.000000001e-3,1e-4\n",
         "sphere 1 of [read.bed] (centre z = 0.008000000001 m, radius 0.0001 m) is outside the "
         "box [0, 0.008] m"},
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        write_text("bad.csv", bad[k].csv);
        char text[2048];
        snprintf(text, sizeof text, "%s%s%s", head, "bad.csv", tail);
        /* the spheres outside the box (the last two cases) are a fault of the group: its
           section's line, 22 */
        expect_bad("badread.ini", text, 22 + (k + 2 < sizeof bad / sizeof bad[0]), bad[k].what);
    }
    char text[2048];
    snprintf(text, sizeof text, "%s%s%s", head, "missing.csv", tail);
    expect_bad("missing.ini", text, 23, "missing.csv: cannot read it: No such file or directory");
    snprintf(text, sizeof text, "%s%s%s", head, "/dev/zero", tail); /* not read for ever */
    expect_bad("device.ini", text, 23, "/dev/zero: cannot read it: not a regular file");
    /* a links file is not a frame; a binary frame cut short is refused, not read past its end */
    scenario("links.ini", "steps = 4\n[dump]\nvtk_every = 4\nvtk_links = yes\n");
    assert_int_equal(run_cli("run links.ini --out lk"), 0);
    snprintf(text, sizeof text, "%s%s%s", head, "lk/particles_links_000001.vtk", tail);
    expect_bad("links_read.ini", text, 23, "a links file (LINES), not a particle frame");
    size_t n = 0;
    char* whole = test_read_file(tpath("lk/particles_000001.vtk"), &n);
    assert_non_null(whole);
    FILE* f = fopen(tpath("cut.vtk"), "wb");
    assert_non_null(f);
    fwrite(whole, 1, n / 2, f);
    fclose(f);
    free(whole);
    snprintf(text, sizeof text, "%s%s%s", head, "cut.vtk", tail);
    expect_bad("cut_read.ini", text, 23, "the file ends within");
    write_text("empty.vtk.series",
               "{\n  \"file-series-version\" : \"1.0\",\n  \"files\" : [\n  ]\n}\n");
    snprintf(text, sizeof text, "%s%s%s", head, "empty.vtk.series", tail);
    expect_bad("series_read.ini", text, 23, "empty.vtk.series: the index lists no frame");
    /* and none of them to overlap a group before it */
    snprintf(text, sizeof text,
             WET_BOX "[particle.a]\nradius = 1e-3\nx = 1e-3\ny = 3e-3\nz = 1e-3\n"
                     "[read.bed]\nfile = bed.csv\n[run]\ndt = 2e-6\nsteps = 1\n");
    expect_bad("overlap_read.ini", text, 27,
               "sphere 1 of [read.bed] overlaps sphere 1 of "
               "[particle.a]");
}

/* Groups of many spheres are checked against the groups before them in time linear in their
 * numbers: two lattice groups of 150,000 spheres, one above the other, are checked in well
 * under 30 s. Each sphere was tested against every earlier one, 2.25e10 pairs at some 14 ns
 * (two groups of 40,000 took 22 s on this machine): about five minutes. The binned check
 * takes about 2 s, so 30 s leaves room for a loaded machine. */
static void test_many_cli_groups_checked_in_linear_time(void** state)
{
    (void)state;
    write_text("layers.ini",
               "[box]\nsize_x = 2e-2\nsize_y = 2e-2\nsize_z = 8e-3\nperiodic = x y\n"
               "[insert.low]\nlayout = lattice\ncount = 150000\nradius = 1e-4\nz_max = 4e-3\n"
               "[insert.high]\nlayout = lattice\ncount = 150000\nradius = 1e-4\n"
               "z_min = 4e-3\n[run]\nsteps = 10\n");
    struct timespec a, b;
    clock_gettime(CLOCK_MONOTONIC, &a);
    int code = run_cli("run layers.ini --check");
    clock_gettime(CLOCK_MONOTONIC, &b);
    double seconds = (double)(b.tv_sec - a.tv_sec) + 1e-9 * (double)(b.tv_nsec - a.tv_nsec);
    if (code != 0)
        fail_msg("exit %d", code);
    char* out = test_read_file(tpath("out.txt"), NULL);
    CHECK_CONTAINS(out, "particles     300000");
    free(out);
    if (seconds > 30)
        fail_msg("checking two groups of 150,000 spheres took %.1f s", seconds);
}

/* The shipped examples check; the summary's budget: input = kinetic + potential + elastic +
 * dissipated exactly as defined, and the closure error small against the energies. */
static void test_many_cli_examples_and_budget(void** state)
{
    (void)state;
    const char* files[] = {"many_stokes_cradle", "many_settling", "many_agglomeration",
                           "many_rough_base", "many_chute"};
    for (size_t k = 0; k < 5; k++) {
        char args[1400], cwd[1024];
        assert_non_null(getcwd(cwd, sizeof cwd)); /* the repository root */
        snprintf(args, sizeof args, "run '%s/examples/scenarios/%s.ini' --check", cwd, files[k]);
        int code = run_cli(args);
        char* out = test_read_file(tpath("out.txt"), NULL);
        if (code != 0)
            fail_msg("%s: exit %d", files[k], code);
        CHECK_CONTAINS(out, "is valid (many-particle run)");
        /* the settling example writes its links, the others do not */
        if ((strstr(out, "(with links)") != NULL) != (k == 1))
            fail_msg("%s: --check says %s links:\n%s", files[k], k == 1 ? "no" : "", out);
        free(out);
    }
    scenario("budget.ini", "");
    assert_int_equal(run_cli("run budget.ini --set run.steps=500 --json"), 0);
    char* js = test_read_file(tpath("out.txt"), NULL);
    double v[7];
    const char* keys[] = {
        "\"input\": ",      "\"kinetic\": ",    "\"potential\": ",    "\"elastic\": ",
        "\"dissipated\": ", "\"work_total\": ", "\"balance_error\": "};
    for (int k = 0; k < 7; k++) {
        const char* p = strstr(js, keys[k]);
        if (!p)
            fail_msg("%s missing in %s", keys[k], js);
        v[k] = strtod(p + strlen(keys[k]), NULL);
    }
    /* dissipated = input - (kinetic + potential + elastic), printed with 17 digits: five
       roundings of terms all smaller than the input, 1e-14 of it (measured 0) */
    CHECK_ABS(v[0], v[1] + v[2] + v[3] + v[4], 1e-14 * fabs(v[0]));
    /* closure: 500 steps of 2 us, about 1/60 of the contact time, close to 1e-3 of the energy
       moved (tests/test_many.c); 1e-2 leaves room for the film forces' jumps at h = delta */
    assert_true(fabs(v[6]) < 1e-2 * fmax(fabs(v[5]), fabs(v[1] - v[0])));
    assert_true(v[4] > 0);                              /* damping and films took energy */
    CHECK_CONTAINS(js, ", \"energy_J\": {\"input\": "); /* fields separated as JSON wants */
    free(js);
    /* a step too long for the contacts (20 us, 0.47 of the contact time, tangential; e_dry 0.9
       so that it stays below mindlin's relaxation time, at or above which a step is
       refused): the budget closes to only 0.13 (2e-4 at 2 us), the run says so and exits 1,
       its files written */
    assert_int_equal(run_cli("run budget.ini --set run.steps=300 --set run.dt=2e-5 "
                             "--set material.wet.restitution=0.9 --out long"),
                     1);
    char* err = stderr_text();
    CHECK_CONTAINS(err, "the energy budget does not close (error 0.13");
    CHECK_CONTAINS(err, "the step dt = 2e-05 s is too long for these contacts; halve it");
    free(err);
    assert_true(exists("long/summary.json") && exists("long/global.csv"));
    /* without the budget no work is summed: the same run prints no budget and does not judge
       one (it gave every model's work as 0 and failed on the change of kinetic energy) */
    assert_int_equal(run_cli("run budget.ini --set run.steps=300 --set run.dt=2e-5 "
                             "--set material.wet.restitution=0.9 --set run.energy_budget=no "
                             "--out off"),
                     0);
    char* off = test_read_file(tpath("out.txt"), NULL);
    CHECK_CONTAINS(off, "contacts");
    assert_null(strstr(off, "energy budget"));
    assert_null(strstr(off, "closure error"));
    free(off);
    char* off_json = test_read_file(tpath("off/summary.json"), NULL);
    assert_null(strstr(off_json, "balance_error"));
    free(off_json);
}

/* The budget of a run whose models' works cancel: two wet spheres at rest, 10 um apart within
 * their 20 um films. The bridge pulls them together (capillary work > 0) and the films and the
 * contact bring them to rest (< 0); the run starts with no input and ends with a net work the
 * size of its own closure error. That error is the integration's, 2e-13 J against 2.8e-9 J
 * of the models' work at 2 us (9e-13 J at 4 us, 5e-14 J at 1 us: second order); judged
 * against the net work the run failed at any step with "error 1" and advice to halve it, and
 * --restart refused its checkpoint. */
static void test_many_cli_budget_of_works_that_cancel(void** state)
{
    (void)state;
    write_text("rest.ini",
               "[box]\nsize_x = 4e-3\nsize_y = 4e-3\nsize_z = 4e-3\n[walls]\nfaces = none\n"
               "[material.wet]\ndensity = 2500\nyoungs_modulus = 1e7\npoisson_ratio = 0.3\n"
               "restitution = 0.6\nfriction_dry = 0.4\nfriction_lub = 0.1\nfilm = 20e-6\n"
               "[fluid]\nviscosity = 0.01\nsurface_tension = 0.02\n"
               "[models]\nforce = hertz mindlin sb capillary\nmin_separation = fixed\n"
               "[particle.a]\nmaterial = wet\nradius = 0.5e-3\nx = 1.5e-3\ny = 2e-3\nz = 2e-3\n"
               "[particle.b]\nmaterial = wet\nradius = 0.5e-3\nx = 2.51e-3\ny = 2e-3\nz = 2e-3\n"
               "[run]\ndt = 2e-6\nsteps = 2000\n");
    int code = run_cli("run rest.ini --out rest");
    char* err = stderr_text();
    if (code != 0)
        fail_msg("exit %d, expected 0\n%s", code, err);
    assert_null(strstr(err, "does not close"));
    free(err);
    char* js = test_read_file(tpath("rest/summary.json"), NULL);
    assert_non_null(js);
    const char* keys[] = {"\"input\": ", "\"work_total\": ", "\"balance_error\": ",
                          "\"balance_error_ratio\": ", "\"capillary\", \"pairs\": "};
    double v[5];
    for (int k = 0; k < 5; k++) {
        const char* p = strstr(js, keys[k]);
        if (!p)
            fail_msg("%s missing in %s", keys[k], js);
        v[k] = strtod(p + strlen(keys[k]), NULL);
    }
    free(js);
    assert_true(v[0] == 0);                /* at rest: no input */
    assert_true(v[4] > 1e-9);              /* the bridge's work, 1.4e-9 J */
    assert_true(fabs(v[1]) < 1e-2 * v[4]); /* the works cancel (net 2e-13 J) */
    /* the error, second order (2e-13 J), against the models' work: 7.5e-5 */
    assert_true(fabs(v[2]) < 1e-3 * v[4]);
    assert_true(v[3] > 0 && v[3] < 1e-3);
    /* and the run goes on from its checkpoint */
    code = run_cli("run rest.ini --set run.steps=2500 --out rest --restart rest/checkpoint.ckpt");
    err = stderr_text();
    if (code != 0)
        fail_msg("restart: exit %d, expected 0\n%s", code, err);
    free(err);
}

/* Counts the lines of a file that start with a digit (the rows of a CSV); *finite: whether
 * every field of those rows is a finite number. */
static size_t count_rows_finite(const char* name, bool* finite)
{
    char* text = test_read_file(tpath(name), NULL);
    assert_non_null(text);
    size_t rows = 0;
    *finite = true;
    for (char* line = strtok(text, "\n"); line; line = strtok(NULL, "\n")) {
        if (!(line[0] >= '0' && line[0] <= '9'))
            continue;
        rows++;
        for (char *p = line, *end; *p; p = *end ? end + 1 : end) {
            double v = strtod(p, &end);
            *finite = *finite && isfinite(v) && end != p;
        }
    }
    free(text);
    return rows;
}

/* A run whose derived step is absurdly short for its length (a Young's modulus of 1e30 Pa,
 * inside the material's range: 4e4 steps became 5e13; e_dry = 1e-12: the hertz dashpot's
 * relaxation time holds the step at 5e-12 s) is refused at once, exit 2, with the number of
 * steps, the step, what sets it and the parameters to check, and no --out directory. Before,
 * [integrator] max_steps did not apply to the many-particle mode: the run started and ground
 * at some 300 steps a second (interrupted, it resumed from its checkpoint). A given step is
 * held to max_steps the same way. */
static void test_many_cli_refuses_a_run_with_too_many_steps(void** state)
{
    (void)state;
    scenario("long.ini", "t_end = 0.05\n");
    char* err = expect_exit("run long.ini --set run.dt=0 --set material.wet.youngs_modulus=1e30 "
                            "--out long.out",
                            2, "long.ini:");
    CHECK_CONTAINS(err, "steps of dt = ");
    CHECK_CONTAINS(err, "more than verlet.max_steps = 1e+08; the step is verlet.dt_fraction = "
                        "0.02 x the contact time ");
    CHECK_CONTAINS(err, "check the materials' youngs_modulus and density, and the radii");
    assert_false(exists("long.out"));
    free(err);
    err = expect_exit("run long.ini --set run.dt=0 --set material.wet.restitution=1e-12 --check", 2,
                      "the step is a quarter of the viscous relaxation time ");
    CHECK_CONTAINS(err, "that 'hertz' sets");
    free(err);
    err = expect_exit("run long.ini --set integrator.max_steps=1000 --check", 2,
                      "takes 2.5e+04 steps of dt = 2e-06 s, more than verlet.max_steps = 1e+03; "
                      "the step is given");
    free(err);
}

/* A step that does not resolve what the run meets is warned about on stderr (the library
 * gives the time scales in wetdem_many_stats): the base scenario's given 2 us lets a pair at
 * its speed scale (2 m/s) travel several times h_min = 1 um in a step; many_hmin_fraction = 0 turns
 * that bound and its warning off, and the derived step keeps to the bound. A step of 0.3 ms,
 * some 8 x the contact time of the dry spheres, is refused up front (exit 2) where it is not
 * below the relaxation time of the damped contact (mindlin's dashpot), with the step to use; with undamped
 * contacts (e_dry = 1) it is warned about and diverges: the run stops
 * at the first step whose motion is not finite with exit 1, naming the step, the time and
 * the particle, and every CSV row and VTK frame written before is of a finite state (one of
 * each for the start and every step done; no summary). Before, it ran to its end with an
 * infinite kinetic energy. */
static void test_many_cli_warns_about_the_step(void** state)
{
    (void)state;
    scenario("warn.ini", "steps = 300\n");
    char* err = expect_exit("run warn.ini --check", 0, "wetdem: warning: warn.ini: in one step");
    CHECK_CONTAINS(err, "x the smallest h_min where the force laws jump");
    assert_null(strstr(err, "contact time"));
    free(err);
    const char* quiet[] = {"--set integrator.many_hmin_fraction=0", "--set run.dt=0"};
    for (int k = 0; k < 2; k++) {
        char args[200];
        snprintf(args, sizeof args, "run warn.ini --check %s", quiet[k]);
        assert_int_equal(run_cli(args), 0);
        err = stderr_text();
        assert_string_equal(err, "");
        free(err);
    }

    err = expect_exit("run warn.ini --set 'models.force=hertz mindlin' --set run.dt=3e-4", 2,
                      "many: the step dt = 0.0003 s is not below the viscous relaxation time ");
    CHECK_CONTAINS(err, "that 'mindlin' sets in contact"); /* (its dashpot: 0.3 of hertz's) */
    free(err);
    err = expect_exit("run warn.ini --set 'models.force=hertz mindlin' --set run.dt=3e-4 "
                      "--set material.wet.restitution=1 "
                      "--set dump.vtk_every=1 --set dump.csv_every=1 "
                      "--out div",
                      1, "wetdem: warning: warn.ini: the step dt = 0.0003 s is ");
    CHECK_CONTAINS(err, "x the contact time");
    CHECK_CONTAINS(err, "many: the motion diverged in step ");
    const char* at = strstr(err, "diverged in step ");
    unsigned long long step = strtoull(at + strlen("diverged in step "), NULL, 10);
    char where[80];
    snprintf(where, sizeof where, "in step %llu (t = %.9g s): particle ", step, 3e-4 * step);
    CHECK_CONTAINS(err, where);
    free(err);
    assert_true(step > 1 && step < 300);
    bool finite;
    assert_int_equal(count_rows_finite("div/global.csv", &finite), step);
    assert_true(finite);
    char frame[64];
    snprintf(frame, sizeof frame, "div/particles_%06llu.vtk", step - 1);
    assert_true(exists(frame));
    snprintf(frame, sizeof frame, "div/particles_%06llu.vtk", step);
    assert_false(exists(frame));
    assert_false(exists("div/summary.json"));
}

/* A sphere rolling down a chute (a floor under gravity tilted by 30 deg, periodic along x)
 * outgrows the speed scale its step was derived at (docs/many.md, Speeds beyond the step's):
 * at rest on the floor it has nothing to fall, so the speed scale and the bound are the
 * floor's 1e-3 m/s; after 0.05 s it rolls at (5/7) g sin(30 deg) t = 0.175 m/s, and at that
 * speed scale the step, 0.05 of the contact time at 1e-3 m/s, is 0.05 x 175^(1/5) = 0.14 of
 * the contact time, above 0.1: the run warns (exit 0) at the first frame that shows it and
 * at its end, with the step that would resolve it, and summary.json holds the three speeds. Run again at that step, the same
 * speed is reached (the motion does not depend on the step to 1e-4) and nothing is warned. */
static void test_many_cli_warns_when_speeds_outgrow_the_step(void** state)
{
    (void)state;
    write_text("chute.ini", "[box]\nsize_x = 4e-3\nsize_y = 4e-3\nsize_z = 4e-3\nperiodic = x y\n"
                            "[walls]\nfaces = z_min\n"
                            "[material.soft]\ndensity = 2500\nyoungs_modulus = 1e7\n"
                            "poisson_ratio = 0.3\nrestitution = 0.6\nfriction_dry = 0.4\n"
                            "[models]\nforce = hertz mindlin\n"
                            "[sim]\ngravity_x = 4.905\ngravity_z = -8.49571\n"
                            "[particle.a]\nx = 2e-3\ny = 2e-3\nz = 0.5e-3\nradius = 0.5e-3\n"
                            "material = soft\n"
                            "[integrator]\ndt_fraction = 0.05\n[run]\nt_end = 0.05\n");
    expect_output("run chute.ini --check", "out.txt",
                  "  speed scale   0.001 m/s  (of the time scales below, which hold while no "
                  "particle exceeds 0.001 m/s)\n");
    char* err = expect_exit("run chute.ini --out o", 0, "s a particle reached 0.175");
    CHECK_CONTAINS(err, "above the 0.001 m/s the step's time scales allow a particle");
    /* and once before, at the first frame where the step no longer resolves the contacts: at
       0.1 = 0.05 x (V'/V)^(1/5), V' = 32 x 1e-3 m/s, reached at t = 0.032 / ((5/7) g sin 30
       deg) = 9.1 ms; frames every 72 steps of 13.7 us, 0.99 ms */
    const char* first = strstr(err, "warning: chute.ini: by t = ");
    assert_non_null(first);
    double t_first = strtod(first + strlen("warning: chute.ini: by t = "), NULL);
    assert_true(t_first > 9.1e-3 && t_first < 9.1e-3 + 1e-3);
    CHECK_CONTAINS(first + 1, "warning: chute.ini: by t = 0.050011 s"); /* the last step */
    CHECK_CONTAINS(err, "x the contact time");
    const char* at = strstr(err, "[run] dt = ");
    assert_non_null(at);
    double dt = strtod(at + strlen("[run] dt = "), NULL);
    assert_true(dt > 0 && dt < 1.373e-5 / 2);
    free(err);
    char* js = test_read_file(tpath("o/summary.json"), NULL);
    assert_non_null(js);
    CHECK_CONTAINS(js, "\"speed_scale_m_s\": 0.001, \"speed_bound_m_s\": 0.001, "
                       "\"largest_speed_m_s\": 0.175");
    free(js);
    char* out = test_read_file(tpath("out.txt"), NULL);
    assert_non_null(out);
    CHECK_CONTAINS(out, "largest speed      0.175"); /* (the text summary) */
    CHECK_CONTAINS(out, " m/s  (the step's time scales allow 0.001 m/s: docs/many.md");
    free(out);
    char args[200];
    snprintf(args, sizeof args, "run chute.ini --set run.dt=%.4g", dt);
    assert_int_equal(run_cli(args), 0);
    err = stderr_text();
    assert_string_equal(err, "");
    free(err);
    /* wet, sb cut off below h_min = 1 um: the step (0.05 of the contact time at 1e-3 m/s,
       13.7 us) is far below the 0.5 ms to cross h_min at the start's speed scale, but a pair
       closing at V' = 0.176 m/s crosses it in 5.7 us, so the end's warning names the h_min
       crossing beside the contact time (it outgrows it from V' = 1 um / 13.7 us = 0.073 m/s,
       reached at 21 ms, after the contacts' first warning at 9.1 ms) */
    assert_int_equal(run_cli("run chute.ini --out w --set models.force=\"hertz mindlin sb\" "
                             "--set material.soft.film=20e-6 --set model.fixed.h_min=1e-6"),
                     0);
    err = stderr_text();
    const char* last = strstr(err, "by t = 0.050011 s");
    assert_non_null(last);
    CHECK_CONTAINS(last, "x the contact time");
    CHECK_CONTAINS(last, "; longer than the time 5.7");
    CHECK_CONTAINS(last, " s a pair takes to cross the smallest h_min where the force laws jump");
    /* the first warning, at the contacts' frame, does not name the h_min crossing yet */
    const char* early = strstr(err, "warning: chute.ini: by t = ");
    assert_true(early != NULL && early < last);
    assert_true(strtod(early + strlen("warning: chute.ini: by t = "), NULL) < 0.021);
    const char* h_min = strstr(early, "cross the smallest h_min");
    assert_true(h_min > last);
    free(err);
}

static int setup(void** state)
{
    (void)state;
    snprintf(tmpdir, sizeof tmpdir, "/tmp/wetdem_test_many_cli_XXXXXX");
    return mkdtemp(tmpdir) ? 0 : -1;
}

static int teardown(void** state)
{
    (void)state;
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    return system(cmd) == 0 ? 0 : -1;
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_many_cli_bad_inputs_exit_2_with_file_and_line),
        cmocka_unit_test(test_many_cli_restart_is_bit_identical),
        cmocka_unit_test(test_many_cli_groups_checked_in_linear_time),
        cmocka_unit_test(test_many_cli_restart_with_other_intervals),
        cmocka_unit_test(test_many_cli_restart_probes),
        cmocka_unit_test(test_many_cli_sigint_writes_a_checkpoint_and_resumes),
        cmocka_unit_test(test_many_cli_third_signal_stops_at_once),
        cmocka_unit_test(test_many_cli_csv_names_its_command),
        cmocka_unit_test(test_many_cli_csv_ends_at_the_last_step),
        cmocka_unit_test(test_many_cli_fresh_run_replaces_earlier_frames),
        cmocka_unit_test(test_many_cli_refuses_a_directory_named_as_an_output),
        cmocka_unit_test(test_many_cli_restart_refuses_another_step),
        cmocka_unit_test(test_many_cli_summary_mean_size_readable),
        cmocka_unit_test(test_many_cli_progress_only_on_a_terminal),
        cmocka_unit_test(test_many_cli_random_groups_share_the_box),
        cmocka_unit_test(test_many_cli_read_spheres_from_a_file),
        cmocka_unit_test(test_many_cli_examples_and_budget),
        cmocka_unit_test(test_many_cli_warns_when_speeds_outgrow_the_step),
        cmocka_unit_test(test_many_cli_budget_of_works_that_cancel),
        cmocka_unit_test(test_many_cli_warns_about_the_step),
        cmocka_unit_test(test_many_cli_refuses_a_run_with_too_many_steps),
    };
    return cmocka_run_group_tests(tests, setup, getenv("WETDEM_KEEP_TMP") ? NULL : teardown);
}

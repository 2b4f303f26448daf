/*
 * test_locale.c — the library's text is the same whatever locale its host set: a program that
 * called setlocale(LC_ALL, "") in a German locale, whose decimal separator is a comma, gets
 * the same bytes in its VTK files (particles, links), .vtk.series indexes, global CSV and
 * checkpoints as in the C locale, restarts from a .vtk.series file with the same times, and
 * has "0.5" read as 0.5 in parameter strings and track files, and written as 0.5 by the
 * parameter formatters, and a frame's time read back from its title; and the host's locale is
 * left as it was.
 *
 * The German locale is built at run time into a temporary directory (localedef, from the
 * sources of Debian's `locales` package; LOCPATH points glibc there), and the test first
 * checks that printf gives "0,5" in it, so that a passing test means the library ignored it.
 */
#include <locale.h>
#include <sys/stat.h>
#include <unistd.h>

#include "harness.h"

#define N_TRACK_FRAMES 15

static char locale_dir[64]; /* holds de_DE.UTF-8, built by setup */
/* the outputs of the library in the C locale and in the German one (removed by teardown) */
static char c_dir[] = "/tmp/wetdem_locale_c_XXXXXX", de_dir[] = "/tmp/wetdem_locale_de_XXXXXX";

static int teardown(void** state)
{
    (void)state;
    setlocale(LC_ALL, "C");
    char cmd[256];
    snprintf(cmd, sizeof cmd, "rm -rf %s %s %s", locale_dir, c_dir, de_dir);
    return system(cmd) == 0 ? 0 : -1;
}

static int setup(void** state)
{
    (void)state;
    snprintf(locale_dir, sizeof locale_dir, "/tmp/wetdem_locale_XXXXXX");
    if (!mkdtemp(locale_dir) || !mkdtemp(c_dir) || !mkdtemp(de_dir))
        return -1;
    char cmd[256];
    snprintf(cmd, sizeof cmd, "localedef -i de_DE -f UTF-8 %s/de_DE.UTF-8 >/dev/null 2>&1",
             locale_dir);
    if (system(cmd) != 0) {
        fprintf(stderr, "test_locale: localedef could not build de_DE.UTF-8 (the locale sources "
                        "come with the Debian package `locales`: scripts/install-deps)\n");
        teardown(state);
        return -1;
    }
    return setenv("LOCPATH", locale_dir, 1);
}

/* What the library gave back, besides its files. */
struct outcome {
    int param_status;
    double param_value;
    int track_status;
    size_t n_samples;
    struct wetdem_track_sample samples[N_TRACK_FRAMES];
    char formatted[64], range[64];
    int frame_status;  /* of reading the time of a frame (wetdem_output_vtk_frame_time) */
    double frame_time; /* what it read */
    double sim_time;   /* the time the frame was written at */
};

/* A wet granular gas of 20 spheres in a box periodic in x and y with a floor, and the
 * many-particle mode writing every output into dir (prefix "run", checkpoint "run.ck"). */
static struct wetdem_sim* wet_box(const char* dir, char* prefix, char* ck, size_t n)
{
    snprintf(prefix, n, "%s/run", dir);
    snprintf(ck, n, "%s/run.ck", dir);
    struct wetdem_sim* sim = wetdem_sim_create();
    assert_non_null(sim);
    CHECK_OK(test_wet_gas(sim, 20, 4e-3, 4e-3, 20e-6, 7, NULL));
    struct wetdem_many_settings s = {.periodic = {true, true, false},
                                     .box_hi = {4e-3, 4e-3, 4e-3},
                                     .dt = 2e-6,
                                     .skin = 0.05e-3,
                                     .energy_budget = true,
                                     .output_prefix = prefix,
                                     .vtk_every = 25,
                                     .vtk_links = true,
                                     .csv_every = 10,
                                     .checkpoint_path = ck,
                                     .checkpoint_every = 50};
    CHECK_OK(wetdem_sim_set_many(sim, &s));
    return sim;
}

/* A track file of one sphere moving and turning, its numbers with decimal points. */
static void write_track(const char* path)
{
    FILE* f = fopen(path, "w");
    assert_non_null(f);
    fputs("frame,sphere,x1,y1,x2,y2,x3,y3\n", f);
    for (int k = 0; k < N_TRACK_FRAMES + 1; k++) /* (integers only: any locale writes them) */
        fprintf(f, "%d,0,%d.5,200.25,%d.75,21%d.5,%d.25,190.5\n", k, 100 + 3 * k, 110 + 3 * k,
                k % 10, 90 + 3 * k);
    assert_int_equal(fclose(f), 0);
}

/* Every text reader and writer of the library, in the calling thread's locale, with its files
 * in dir. */
static void exercise(const char* dir, struct outcome* out)
{
    char prefix[256], ck[256], path[256];
    struct wetdem_sim* sim = wet_box(dir, prefix, ck, sizeof prefix);
    /* the run's own outputs: VTK frames with links, their indexes, CSV rows, checkpoints */
    CHECK_OK(wetdem_sim_integrate(sim, 2e-4));
    snprintf(path, sizeof path, "%s/extra.vtk", dir);
    CHECK_OK(wetdem_sim_write_vtk(sim, path, false));
    out->frame_time = NAN;
    out->frame_status = wetdem_output_vtk_frame_time(path, &out->frame_time);
    out->sim_time = wetdem_sim_time(sim);
    snprintf(path, sizeof path, "%s/extra_links.vtk", dir);
    CHECK_OK(wetdem_sim_write_vtk_links(sim, path, false));
    CHECK_OK(wetdem_sim_many_write_csv_row(sim));
    snprintf(path, sizeof path, "%s/extra.ck", dir);
    CHECK_OK(wetdem_sim_write_checkpoint(sim, path));
    /* a restart: the checkpoint, and the times of the frames before it from run.vtk.series */
    struct wetdem_sim* resumed = wet_box(dir, prefix, ck, sizeof prefix);
    CHECK_OK(wetdem_sim_read_checkpoint(resumed, ck));
    CHECK_OK(wetdem_sim_integrate(resumed, 3e-4));
    wetdem_sim_free(resumed);

    out->param_status = wetdem_sim_set_param_str(sim, "sim.gravity_z", "0.5");
    out->param_value = NAN;
    CHECK_OK(wetdem_sim_param(sim, "sim.gravity_z", &out->param_value));
    wetdem_sim_free(sim);

    snprintf(path, sizeof path, "%s/track.csv", dir);
    write_track(path);
    struct wetdem_track* t = wetdem_track_create();
    assert_non_null(t);
    out->track_status = wetdem_track_read_csv(t, path);
    out->n_samples = 0;
    if (out->track_status == WETDEM_OK) {
        struct wetdem_track_options opt;
        wetdem_track_options_init(&opt);
        opt.fps = 5000;
        opt.pixel_size = 175e-6;
        struct wetdem_track_summary summary;
        CHECK_OK(wetdem_track_analyse(t, &opt, &summary));
        const struct wetdem_track_sample* s = wetdem_track_samples(t, 0, &out->n_samples);
        assert_int_equal(out->n_samples, N_TRACK_FRAMES);
        memcpy(out->samples, s, out->n_samples * sizeof *s);
    }
    wetdem_track_free(t);

    wetdem_param_format_value(0.5, 1, out->formatted, sizeof out->formatted);
    struct wetdem_param_desc d = {.name = "x", .unit = "-", .min = 0.25, .max = 1.5};
    wetdem_param_range_text(&d, out->range, sizeof out->range);
}

/* Asserts that the files of dir `got` are those of `want`, byte for byte. */
static void check_same_files(const char* want, const char* got)
{
    char* names = test_list_dir(want);
    char* names_got = test_list_dir(got);
    assert_non_null(names);
    assert_non_null(names_got);
    assert_string_equal(names_got, names);
    int files = 0;
    for (char *name = names, *end; (end = strchr(name, '\n')); name = end + 1, files++) {
        *end = '\0';
        char a[256], b[256];
        snprintf(a, sizeof a, "%s/%s", want, name);
        snprintf(b, sizeof b, "%s/%s", got, name);
        size_t na, nb;
        char* ta = test_read_file(a, &na);
        char* tb = test_read_file(b, &nb);
        assert_non_null(ta);
        assert_non_null(tb);
        size_t k = 0;
        while (k < na && k < nb && ta[k] == tb[k])
            k++;
        if (na != nb || k < na) {
            size_t line = k; /* the line where they part */
            while (line > 0 && ta[line - 1] != '\n')
                line--;
            fail_msg("%s differs in the German locale from byte %zu on: '%.60s' vs '%.60s'", name,
                     k, tb + line, ta + line);
        }
        free(ta);
        free(tb);
    }
    assert_true(files >= 15); /* frames, links, indexes, CSV, checkpoints, the track */
    free(names);
    free(names_got);
}

static void test_locale_text_io_ignores_the_hosts_decimal_comma(void** state)
{
    (void)state;
    struct outcome c, de;
    memset(&c, 0, sizeof c);
    memset(&de, 0, sizeof de);

    assert_non_null(setlocale(LC_ALL, "C"));
    exercise(c_dir, &c);
    CHECK_OK(c.param_status);
    assert_true(c.param_value == 0.5);
    CHECK_OK(c.track_status);
    assert_string_equal(c.formatted, "0.5");
    assert_string_equal(c.range, "[0.25, 1.5]");
    CHECK_OK(c.frame_status);
    assert_memory_equal(&c.frame_time, &c.sim_time, sizeof c.sim_time);

    /* the host's locale, as after setlocale(LC_ALL, "") with LANG=de_DE.UTF-8 */
    if (!setlocale(LC_ALL, "de_DE.UTF-8"))
        fail_msg("setlocale(LC_ALL, \"de_DE.UTF-8\") failed with LOCPATH=%s", locale_dir);
    char text[16];
    snprintf(text, sizeof text, "%g", 0.5);
    assert_string_equal(text, "0,5"); /* the locale is in force: printf writes a comma */
    exercise(de_dir, &de);
    snprintf(text, sizeof text, "%g", 0.5);
    assert_string_equal(text, "0,5"); /* and the library left it so */
    setlocale(LC_ALL, "C");

    check_same_files(c_dir, de_dir);
    if (de.param_status != WETDEM_OK)
        fail_msg("set_param_str(\"0.5\") gave %s in the German locale",
                 wetdem_status_name(de.param_status));
    assert_true(de.param_value == 0.5);
    if (de.track_status != WETDEM_OK)
        fail_msg("track_read_csv gave %s in the German locale",
                 wetdem_status_name(de.track_status));
    assert_int_equal(de.n_samples, c.n_samples);
    assert_memory_equal(de.samples, c.samples, c.n_samples * sizeof c.samples[0]);
    assert_string_equal(de.formatted, c.formatted);
    assert_string_equal(de.range, c.range);
    if (de.frame_status != WETDEM_OK)
        fail_msg("output_vtk_frame_time gave %s in the German locale",
                 wetdem_status_name(de.frame_status));
    assert_memory_equal(&de.frame_time, &de.sim_time, sizeof de.sim_time);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_locale_text_io_ignores_the_hosts_decimal_comma),
    };
    return cmocka_run_group_tests(tests, setup, teardown);
}

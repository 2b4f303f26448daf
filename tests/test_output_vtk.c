/*
 * test_output_vtk.c — legacy VTK particle files (src/output_vtk.c): what is written is parsed
 * back here, keyword by keyword, and must equal the input bit for bit (ASCII with 17 digits
 * and big-endian binary are both exact); when the VTK Python module is installed the files
 * are also read with VTK's own legacy reader. Also: the links file (lines and cell data), atomic
 * write, series file, bad path; the time of a particle file read back from its title
 * (wetdem_output_vtk_frame_time) and the entries of a series index
 * (wetdem_output_vtk_series_entry), bit for bit, and everything else refused.
 */
#include <float.h>
#include <stdlib.h>
#include <unistd.h>

#include "harness.h"
#include "output_vtk.h"
#include "vec3.h"

#define N 37

/* Each particle's links, as the arrays of struct wetdem_output_vtk_counts. */
struct counts_data {
    uint32_t contacts[N], bridges[N], agglomerate[N];
};

static struct wetdem_output_vtk_counts counts_of(const struct counts_data* d)
{
    return (struct wetdem_output_vtk_counts){d->contacts, d->bridges, d->agglomerate};
}

static void make_particles(struct wetdem_particle* p, struct counts_data* links)
{
    for (size_t k = 0; k < N; k++) {
        double t = (double)k;
        p[k] = (struct wetdem_particle){.pos = vec3(t * 1e-3 / 3, -t / 7, 1.0 / (t + 1)),
                                        .vel = vec3(sin(t), cos(t), -t * 1e-9),
                                        .omega = vec3(1e5 / (t + 3), 0, -0.1 * t),
                                        .radius = 1e-3 * (1 + t / 97),
                                        .material = (int)(k % 3)};
        if (k % 4 == 1) /* a fixed sphere, at rest */
            p[k] = (struct wetdem_particle){.pos = p[k].pos,
                                            .radius = p[k].radius,
                                            .material = p[k].material,
                                            .is_fixed = true};
        links->contacts[k] = (uint32_t)(k * 7 % 5);
        links->bridges[k] = (uint32_t)(k * 3 % 4);
        links->agglomerate[k] = (uint32_t)(k / 5);
    }
}

/* Reads the next whitespace-delimited token and checks it. */
static void expect(FILE* f, const char* want)
{
    char tok[128];
    if (fscanf(f, "%127s", tok) != 1 || strcmp(tok, want) != 0)
        fail_msg("expected '%s' in the VTK file, got '%s'", want, tok);
}

static void skip_line(FILE* f)
{
    int c;
    while ((c = fgetc(f)) != EOF && c != '\n') {
    }
}

static void get_be(FILE* f, void* out, size_t size)
{
    unsigned char b[8];
    assert_int_equal(fread(b, 1, size, f), size);
    const uint16_t probe = 1;
    bool little = *(const unsigned char*)&probe == 1;
    unsigned char* o = out;
    for (size_t k = 0; k < size; k++)
        o[k] = little ? b[size - 1 - k] : b[k];
}

static double get_double(FILE* f, bool binary)
{
    double x = NAN;
    if (binary)
        get_be(f, &x, sizeof x);
    else
        assert_int_equal(fscanf(f, "%lf", &x), 1);
    return x;
}

static int32_t get_int(FILE* f, bool binary)
{
    int32_t x = -1;
    int v = -1;
    if (binary)
        get_be(f, &x, sizeof x);
    else if (fscanf(f, "%d", &v) == 1)
        x = v;
    return x;
}

/* After a keyword line, binary data starts right after its newline. */
static void begin_data(FILE* f, bool binary)
{
    if (binary)
        skip_line(f);
}

static void check_vectors(FILE* f, const char* name, const struct wetdem_particle* p, int which,
                          bool binary)
{
    char count[32];
    snprintf(count, sizeof count, "%d", N);
    expect(f, name);
    expect(f, "3");
    expect(f, count);
    expect(f, "double");
    begin_data(f, binary);
    for (size_t k = 0; k < N; k++) {
        struct wetdem_vec3 v = which == 1 ? p[k].vel : p[k].omega;
        double a = get_double(f, binary), b = get_double(f, binary), c = get_double(f, binary);
        assert_true(a == v.x && b == v.y && c == v.z); /* exact round trip */
    }
}

static void check_ints(FILE* f, const char* name, const int32_t* want, bool binary)
{
    char count[32];
    snprintf(count, sizeof count, "%d", N);
    expect(f, name);
    expect(f, "1");
    expect(f, count);
    expect(f, "int");
    begin_data(f, binary);
    for (size_t k = 0; k < N; k++)
        assert_int_equal(get_int(f, binary), want[k]);
}

static void check_header(FILE* f, double time, bool binary)
{
    char line[256];
    assert_non_null(fgets(line, sizeof line, f));
    assert_string_equal(line, "# vtk DataFile Version 3.0\n");
    assert_non_null(fgets(line, sizeof line, f)); /* title */
    expect(f, binary ? "BINARY" : "ASCII");
    expect(f, "DATASET");
    expect(f, "POLYDATA");
    expect(f, "FIELD");
    expect(f, "FieldData");
    expect(f, "1");
    expect(f, "TIME");
    expect(f, "1");
    expect(f, "1");
    expect(f, "double");
    begin_data(f, binary);
    assert_true(get_double(f, binary) == time);
}

static void parse_back(const char* path, const struct wetdem_particle* p,
                       const struct counts_data* links, double time, bool binary)
{
    FILE* f = fopen(path, "rb");
    assert_non_null(f);
    check_header(f, time, binary);
    char count[32];
    snprintf(count, sizeof count, "%d", N);
    expect(f, "POINTS");
    expect(f, count);
    expect(f, "double");
    begin_data(f, binary);
    for (size_t k = 0; k < N; k++) {
        double a = get_double(f, binary), b = get_double(f, binary), c = get_double(f, binary);
        assert_true(a == p[k].pos.x && b == p[k].pos.y && c == p[k].pos.z);
    }
    expect(f, "VERTICES");
    expect(f, count);
    begin_data(f, binary);
    if (!binary)
        skip_line(f);
    for (int32_t k = 0; k < N; k++) {
        assert_int_equal(get_int(f, binary), 1);
        assert_int_equal(get_int(f, binary), k);
    }
    expect(f, "POINT_DATA");
    expect(f, count);
    expect(f, "FIELD");
    expect(f, "FieldData");
    expect(f, "9");
    expect(f, "radius");
    expect(f, "1");
    expect(f, count);
    expect(f, "double");
    begin_data(f, binary);
    for (size_t k = 0; k < N; k++)
        assert_true(get_double(f, binary) == p[k].radius);
    check_vectors(f, "velocity", p, 1, binary);
    check_vectors(f, "spin", p, 2, binary);
    int32_t want[6][N];
    for (int32_t k = 0; k < N; k++) {
        want[0][k] = (int32_t)links->contacts[k];
        want[1][k] = (int32_t)links->bridges[k];
        want[2][k] = (int32_t)links->agglomerate[k];
        want[3][k] = p[k].material;
        want[4][k] = k;
        want[5][k] = p[k].is_fixed;
    }
    check_ints(f, "contacts", want[0], binary);
    check_ints(f, "bridges", want[1], binary);
    check_ints(f, "agglomerate", want[2], binary);
    check_ints(f, "material", want[3], binary);
    check_ints(f, "id", want[4], binary);
    check_ints(f, "fixed", want[5], binary);
    char tail[8];
    assert_int_equal(fscanf(f, "%7s", tail), EOF); /* nothing else in the file */
    fclose(f);
}

/* Reads the file with VTK's legacy reader if the vtk module is importable; returns false if
 * not. The script prints the number of points, the sum of contacts, and radius/velocity of
 * point 5 with 17 digits, which must equal what was written. */
static bool read_with_vtk(const char* path, const struct wetdem_particle* p,
                          const struct counts_data* links)
{
    if (system("/usr/bin/python3 -c 'import vtk' >/dev/null 2>&1") != 0)
        return false;
    char cmd[1024];
    snprintf(cmd, sizeof cmd,
             "/usr/bin/python3 -c \"import vtk; r = vtk.vtkPolyDataReader(); "
             "r.SetFileName('%s'); r.Update(); d = r.GetOutput(); pd = d.GetPointData(); "
             "c = pd.GetArray('contacts'); "
             "print(d.GetNumberOfPoints(), d.GetNumberOfVerts(), "
             "sum(int(c.GetValue(k)) for k in range(c.GetNumberOfTuples())), "
             "'%%.17g %%.17g' %% (pd.GetArray('radius').GetValue(5), "
             "pd.GetArray('velocity').GetTuple3(5)[1]))\"",
             path);
    FILE* f = popen(cmd, "r");
    assert_non_null(f);
    long n_points = -1, n_verts = -1, sum = -1;
    double r5 = NAN, vy5 = NAN;
    int got = fscanf(f, "%ld %ld %ld %lf %lf", &n_points, &n_verts, &sum, &r5, &vy5);
    pclose(f);
    assert_int_equal(got, 5);
    long want_sum = 0;
    for (size_t k = 0; k < N; k++)
        want_sum += links->contacts[k];
    assert_int_equal(n_points, N);
    assert_int_equal(n_verts, N);
    assert_int_equal(sum, want_sum);
    assert_true(r5 == p[5].radius && vy5 == p[5].vel.y);
    return true;
}

static void round_trip(bool binary)
{
    struct wetdem_particle p[N];
    struct counts_data links;
    make_particles(p, &links);
    struct wetdem_output_vtk_counts arrays = counts_of(&links);
    char path[] = "/tmp/wetdem_test_vtk_XXXXXX";
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    close(fd);
    char msg[256] = "";
    double time = 0.123456789012345678;
    CHECK_OK(wetdem_output_vtk_write(path, p, N, &arrays, time, binary, msg, sizeof msg));
    parse_back(path, p, &links, time, binary);
    if (!read_with_vtk(path, p, &links))
        print_message("python3 vtk not available: checked the format structurally only\n");
    /* without links (a run not started) the counts and labels are zeros */
    CHECK_OK(wetdem_output_vtk_write(path, p, N, NULL, time, binary, msg, sizeof msg));
    static const struct counts_data zeros;
    parse_back(path, p, &zeros, time, binary);
    char tmp[64];
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    assert_int_equal(access(tmp, F_OK), -1); /* the temporary was renamed away */
    remove(path);
}

static void test_output_vtk_ascii_round_trip(void** state)
{
    (void)state;
    round_trip(false);
}

static void test_output_vtk_binary_round_trip(void** state)
{
    (void)state;
    round_trip(true);
}

/* A links file: lines of two points each, and the cell arrays, read back bit for bit. */
static void links_round_trip(bool binary)
{
    enum { NL = 5 };
    struct wetdem_output_vtk_link l[NL];
    for (int k = 0; k < NL; k++) {
        double t = k + 1;
        l[k] = (struct wetdem_output_vtk_link){.a = vec3(t / 3, -t, 1e-3 * t),
                                               .b = vec3(t / 7, t * t, -1e-4 / t),
                                               .i = k,
                                               .j = k == 4 ? -1 : k + 1,
                                               .contact = k % 2 == 0,
                                               .bridge = k != 4,
                                               .gap = -1e-6 / t,
                                               .f_normal = sqrt(t) * 1e-3,
                                               .f_tangential = 1e-5 / t,
                                               .force = vec3(-t, 1 / t, sin(t))};
    }
    char path[] = "/tmp/wetdem_test_vtk_links_XXXXXX";
    close(mkstemp(path));
    char msg[256] = "";
    double time = 1.0 / 3.0;
    CHECK_OK(wetdem_output_vtk_links_write(path, l, NL, time, binary, msg, sizeof msg));
    FILE* f = fopen(path, "rb");
    assert_non_null(f);
    check_header(f, time, binary);
    expect(f, "POINTS");
    expect(f, "10");
    expect(f, "double");
    begin_data(f, binary);
    for (int k = 0; k < NL; k++)
        for (int e = 0; e < 2; e++) {
            struct wetdem_vec3 v = e ? l[k].b : l[k].a;
            assert_true(get_double(f, binary) == v.x && get_double(f, binary) == v.y &&
                        get_double(f, binary) == v.z);
        }
    expect(f, "LINES");
    expect(f, "5");
    expect(f, "15");
    begin_data(f, binary);
    for (int k = 0; k < NL; k++) {
        assert_int_equal(get_int(f, binary), 2);
        assert_int_equal(get_int(f, binary), 2 * k);
        assert_int_equal(get_int(f, binary), 2 * k + 1);
    }
    expect(f, "CELL_DATA");
    expect(f, "5");
    expect(f, "FIELD");
    expect(f, "FieldData");
    expect(f, "8");
    static const char* const names[] = {
        "i", "j", "contact", "bridge", "gap", "force_normal", "force_tangential", "force"};
    for (int w = 0; w < 8; w++) {
        expect(f, names[w]);
        expect(f, w == 7 ? "3" : "1");
        expect(f, "5");
        expect(f, w < 4 ? "int" : "double");
        begin_data(f, binary);
        for (int k = 0; k < NL; k++) {
            const int32_t ints[4] = {l[k].i, l[k].j, l[k].contact, l[k].bridge};
            const double dbl[3] = {l[k].gap, l[k].f_normal, l[k].f_tangential};
            if (w < 4)
                assert_int_equal(get_int(f, binary), ints[w]);
            else if (w < 7)
                assert_true(get_double(f, binary) == dbl[w - 4]);
            else
                assert_true(get_double(f, binary) == l[k].force.x &&
                            get_double(f, binary) == l[k].force.y &&
                            get_double(f, binary) == l[k].force.z);
        }
    }
    char tail[8];
    assert_int_equal(fscanf(f, "%7s", tail), EOF);
    fclose(f);
    remove(path);
}

static void test_output_vtk_links_round_trip(void** state)
{
    (void)state;
    links_round_trip(false);
    links_round_trip(true);
    /* no links (a frame before any contact): a links file of none, not a particle file */
    char path[] = "/tmp/wetdem_test_vtk_links_XXXXXX";
    close(mkstemp(path));
    char msg[256] = "";
    CHECK_OK(wetdem_output_vtk_links_write(path, NULL, 0, 0.5, false, msg, sizeof msg));
    char* text = test_read_file(path, NULL);
    CHECK_CONTAINS(text, "wetdem links t = 0.5 s\n");
    CHECK_CONTAINS(text, "POINTS 0 double\nLINES 0 0\nCELL_DATA 0\nFIELD FieldData 8\n");
    free(text);
    remove(path);
}

static void test_output_vtk_bad_path_is_an_io_error(void** state)
{
    (void)state;
    struct wetdem_particle p[N];
    struct counts_data links;
    make_particles(p, &links);
    char msg[256] = "";
    CHECK_STATUS(
        wetdem_output_vtk_write("/nonexistent-dir/x.vtk", p, N, NULL, 0, false, msg, sizeof msg),
        WETDEM_ERR_IO);
    CHECK_CONTAINS(msg, "/nonexistent-dir/x.vtk");
}

static void test_output_vtk_series_and_names(void** state)
{
    (void)state;
    char name[64];
    wetdem_output_vtk_path(name, sizeof name, "out/run", 42);
    assert_string_equal(name, "out/run_000042.vtk");
    const char* files[] = {"run_000000.vtk", "run_000001.vtk"};
    double times[] = {0, 2.5e-3};
    char path[] = "/tmp/wetdem_test_series_XXXXXX";
    int fd = mkstemp(path);
    close(fd);
    CHECK_OK(wetdem_output_vtk_series_write(path, files, times, 2, NULL, 0));
    FILE* f = fopen(path, "r");
    char text[512] = "";
    size_t len = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[len] = 0;
    CHECK_CONTAINS(text, "\"file-series-version\" : \"1.0\"");
    CHECK_CONTAINS(text, "{ \"name\" : \"run_000001.vtk\", \"time\" : 0.0025000000000000001 }\n");
    remove(path);
}

/* The entries of a series index read back as written, line by line: names (with the JSON
 * escapes the writer adds) and times bit for bit; the index's other lines and broken entries
 * refused, the outputs untouched. */
static void test_output_vtk_series_entries_read_back(void** state)
{
    (void)state;
    const char* files[] = {"run_000000.vtk", "a \"quoted\" \\ name.vtk", "run_000002.vtk"};
    double times[] = {-0.0, 0.1 + 0.2, DBL_MAX};
    char path[] = "/tmp/wetdem_test_series_read_XXXXXX";
    int fd = mkstemp(path);
    close(fd);
    CHECK_OK(wetdem_output_vtk_series_write(path, files, times, 3, NULL, 0));
    FILE* f = fopen(path, "r");
    char line[256], name[64];
    size_t k = 0;
    while (fgets(line, sizeof line, f)) {
        double t = 42;
        int st = wetdem_output_vtk_series_entry(line, name, sizeof name, &t);
        if (st != WETDEM_OK) {
            CHECK_STATUS(st, WETDEM_ERR_PARSE);
            assert_true(t == 42);
            continue;
        }
        assert_true(k < 3);
        assert_string_equal(name, files[k]);
        assert_memory_equal(&t, &times[k], sizeof t); /* (-0 too) */
        k++;
    }
    fclose(f);
    remove(path);
    assert_int_equal(k, 3);
    const char* bad[] = {
        "{ \"name\" : \"\", \"time\" : 1 }",        /* empty name */
        "{ \"name\" : \"x.vtk, \"time\" : 1 }",     /* unterminated */
        "{ \"name\" : \"x.vtk\" }",                 /* no time */
        "{ \"name\" : \"x.vtk\", \"time\" : }",     /* no number */
        "{ \"name\" : \"x.vtk\", \"time\" : nan }", /* not finite */
        "{ \"name\" : \"x.vtk\", \"time\" : 1e999 }",
        "{ \"time\" : 1, \"name\" : \"x.vtk\" }", /* not as the writer orders it */
        "  \"files\" : [",
    };
    for (size_t b = 0; b < sizeof bad / sizeof *bad; b++) {
        double t = 42;
        strcpy(name, "untouched");
        CHECK_STATUS(wetdem_output_vtk_series_entry(bad[b], name, sizeof name, &t),
                     WETDEM_ERR_PARSE);
        assert_true(t == 42);
        assert_string_equal(name, "untouched");
    }
    double t = 0;
    const char* fits = "{ \"name\" : \"abcd\", \"time\" : 1 }";
    CHECK_STATUS(wetdem_output_vtk_series_entry(fits, name, 4, &t), WETDEM_ERR_PARSE);
    CHECK_OK(wetdem_output_vtk_series_entry(fits, name, 5, &t));
    assert_string_equal(name, "abcd");
    CHECK_STATUS(wetdem_output_vtk_series_entry(fits, name, 0, &t), WETDEM_ERR_INVALID);
    CHECK_STATUS(wetdem_output_vtk_series_entry(NULL, name, 5, &t), WETDEM_ERR_INVALID);
    CHECK_STATUS(wetdem_output_vtk_series_entry(fits, NULL, 5, &t), WETDEM_ERR_INVALID);
    CHECK_STATUS(wetdem_output_vtk_series_entry(fits, name, 5, NULL), WETDEM_ERR_INVALID);
}

/* A temporary file holding the `len` bytes of text. */
static void temp_file_with(char* path, const char* text, size_t len)
{
    int fd = mkstemp(path);
    assert_true(fd >= 0);
    assert_int_equal(write(fd, text, len), (ssize_t)len);
    close(fd);
}

/* Writes N particles at `time` and reads the time back from the file's title. */
static double time_written_and_read(double time, bool binary)
{
    struct wetdem_particle p[N];
    struct counts_data links;
    make_particles(p, &links);
    char path[] = "/tmp/wetdem_test_vtk_time_XXXXXX";
    temp_file_with(path, "", 0);
    char msg[256] = "";
    CHECK_OK(wetdem_output_vtk_write(path, p, N, NULL, time, binary, msg, sizeof msg));
    double got = NAN;
    CHECK_OK(wetdem_output_vtk_frame_time(path, &got));
    remove(path);
    return got;
}

/* Times whose text is awkward: zero of both signs, the smallest subnormal and normal numbers,
 * sums and quotients that 15 digits do not round-trip, the largest double. */
static void test_output_vtk_frame_time_reads_back_every_bit(void** state)
{
    (void)state;
    const double times[] = {0.0,        -0.0,      5e-324,  DBL_MIN,    1e-300,
                            1.0 / 3.0,  0.1 + 0.2, 0.1,     2.5e-3,     1.0 + DBL_EPSILON,
                            123456.789, 1e300,     DBL_MAX, -1.0 / 3.0, 4503599627370497.0,
                            -DBL_MAX};
    for (size_t k = 0; k < sizeof times / sizeof times[0]; k++)
        for (int binary = 0; binary < 2; binary++) {
            double got = time_written_and_read(times[k], binary);
            if (memcmp(&got, &times[k], sizeof got) != 0)
                fail_msg("time %.17g (%s) read back as %.17g", times[k],
                         binary ? "binary" : "ASCII", got);
        }
}

/* The status of reading the time of a file holding `text`; *t must be left as it was unless
 * the read succeeds. */
static int frame_time_of_text(const char* text, size_t len)
{
    char path[] = "/tmp/wetdem_test_vtk_title_XXXXXX";
    temp_file_with(path, text, len);
    double t = 42;
    int st = wetdem_output_vtk_frame_time(path, &t);
    remove(path);
    if (st != WETDEM_OK && t != 42)
        fail_msg("a failed read (%s) changed *t to %.17g: '%s'", wetdem_status_name(st), t, text);
    return st;
}

/* A title that is not exactly the one the writer gives a particle file is refused as
 * WETDEM_ERR_PARSE: missing, altered, cut short, with anything after " s", or with a time that
 * is not a finite number; so is a links file. */
static void test_output_vtk_frame_time_refuses_other_titles(void** state)
{
    (void)state;
    static const char* const bad[] = {
        "",
        "# vtk DataFile Version 3.0\n",
        "# vtk DataFile Version 3.0\nASCII\nDATASET POLYDATA\n",
        "# vtk DataFile Version 2.0\nwetdem particles t = 0.5 s\nASCII\n",
        "wetdem particles t = 0.5 s\nASCII\n",
        "# vtk DataFile Version 3.0\nwetdem links t = 0.5 s\nASCII\n",
        "# vtk DataFile Version 3.0\nwetdem particle t = 0.5 s\nASCII\n",
        "# vtk DataFile Version 3.0\nWetdem particles t = 0.5 s\nASCII\n",
        "# vtk DataFile Version 3.0\n wetdem particles t = 0.5 s\nASCII\n",
        "# vtk DataFile Version 3.0\nwetdem particles t= 0.5 s\nASCII\n",
        "# vtk DataFile Version 3.0\nwetdem particles t = 0.5 ms\nASCII\n",
        "# vtk DataFile Version 3.0\nwetdem particles t = 0.50 s\nASCII\n",
        "# vtk DataFile Version 3.0\nwetdem particles t = +0.5 s\nASCII\n",
        "# vtk DataFile Version 3.0\nwetdem particles t = 0x1p-1 s\nASCII\n",
        "# vtk DataFile Version 3.0\nwetdem particles t =  0.5 s\nASCII\n",
        "# vtk DataFile Version 3.0\nwetdem particles t = s\nASCII\n",
        "# vtk DataFile Version 3.0\nwetdem particles t = ",
        "# vtk DataFile Version 3.0\nwetdem particles t = 0.5",
        "# vtk DataFile Version 3.0\nwetdem particles t = 0.5 s",
        "# vtk DataFile Version 3.0\nwetdem particles t = 0.5 s \nASCII\n",
        "# vtk DataFile Version 3.0\nwetdem particles t = 0.5 s\r\nASCII\n",
        "# vtk DataFile Version 3.0\nwetdem particles t = 0.5 s extra\nASCII\n",
        "# vtk DataFile Version 3.0\nwetdem particles t = 0.5abc s\nASCII\n",
        "# vtk DataFile Version 3.0\nwetdem particles t = 0.5 s0.5 s\nASCII\n",
        "# vtk DataFile Version 3.0\nwetdem particles t = nan s\nASCII\n",
        "# vtk DataFile Version 3.0\nwetdem particles t = -nan s\nASCII\n",
        "# vtk DataFile Version 3.0\nwetdem particles t = inf s\nASCII\n",
        "# vtk DataFile Version 3.0\nwetdem particles t = -inf s\nASCII\n",
        "# vtk DataFile Version 3.0\nwetdem particles t = infinity s\nASCII\n",
        "# vtk DataFile Version 3.0\nwetdem particles t = 1e999 s\nASCII\n",
    };
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        int st = frame_time_of_text(bad[k], strlen(bad[k]));
        if (st != WETDEM_ERR_PARSE)
            fail_msg("'%s' gave %s, expected WETDEM_ERR_PARSE", bad[k], wetdem_status_name(st));
    }
    /* the good title itself, as the control of the cases above */
    static const char good[] = "# vtk DataFile Version 3.0\nwetdem particles t = 0.5 s\nASCII\n";
    CHECK_OK(frame_time_of_text(good, strlen(good)));
    /* a NUL inside the title */
    static const char nul[] = "# vtk DataFile Version 3.0\nwetdem particles t = 0.5 s\0\nASCII\n";
    CHECK_STATUS(frame_time_of_text(nul, sizeof nul - 1), WETDEM_ERR_PARSE);
    /* a title line longer than any the writer gives */
    char long_title[400];
    snprintf(long_title, sizeof long_title,
             "# vtk DataFile Version 3.0\nwetdem particles t = 0.5 s%*s\n", 300, "");
    CHECK_STATUS(frame_time_of_text(long_title, strlen(long_title)), WETDEM_ERR_PARSE);
    /* a links file, as the links writer gives it */
    char path[] = "/tmp/wetdem_test_vtk_title_XXXXXX";
    temp_file_with(path, "", 0);
    char msg[256] = "";
    double t = 42;
    CHECK_OK(wetdem_output_vtk_links_write(path, NULL, 0, 0.5, false, msg, sizeof msg));
    CHECK_STATUS(wetdem_output_vtk_frame_time(path, &t), WETDEM_ERR_PARSE);
    assert_true(t == 42);
    remove(path);
}

/* A file that cannot be read is WETDEM_ERR_IO, a NULL argument WETDEM_ERR_INVALID. */
static void test_output_vtk_frame_time_refuses_what_it_cannot_read(void** state)
{
    (void)state;
    double t = 42;
    CHECK_STATUS(wetdem_output_vtk_frame_time("/nonexistent-dir/x.vtk", &t), WETDEM_ERR_IO);
    CHECK_STATUS(wetdem_output_vtk_frame_time("/tmp", &t), WETDEM_ERR_IO); /* a directory */
    CHECK_STATUS(wetdem_output_vtk_frame_time(NULL, &t), WETDEM_ERR_INVALID);
    assert_true(t == 42);
    char path[] = "/tmp/wetdem_test_vtk_title_XXXXXX";
    temp_file_with(path, "", 0);
    CHECK_STATUS(wetdem_output_vtk_frame_time(path, NULL), WETDEM_ERR_INVALID);
    remove(path);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_output_vtk_ascii_round_trip),
        cmocka_unit_test(test_output_vtk_binary_round_trip),
        cmocka_unit_test(test_output_vtk_links_round_trip),
        cmocka_unit_test(test_output_vtk_bad_path_is_an_io_error),
        cmocka_unit_test(test_output_vtk_series_and_names),
        cmocka_unit_test(test_output_vtk_series_entries_read_back),
        cmocka_unit_test(test_output_vtk_frame_time_reads_back_every_bit),
        cmocka_unit_test(test_output_vtk_frame_time_refuses_other_titles),
        cmocka_unit_test(test_output_vtk_frame_time_refuses_what_it_cannot_read),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

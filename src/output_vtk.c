/*
 * output_vtk.c — legacy VTK (version 3.0) POLYDATA files of the particles and of their links
 * (contacts and liquid bridges as lines), ASCII or binary, and ParaView ".vtk.series"
 * time-series files; and what the readers of those files need back: the time of a particle
 * file from its title, an entry of a series index (the one definition of each format,
 * TITLE_FORMAT and SERIES_NAME / SERIES_TIME, serves writer and reader). Prefix:
 * wetdem_output_vtk.
 *
 * Layout (VTK User's Guide, "VTK File Formats", legacy format):
 *   # vtk DataFile Version 3.0 / title / ASCII|BINARY / DATASET POLYDATA
 *   (title: "wetdem particles t = T s" or "wetdem links t = T s", T the time [s] in %.17g)
 *   FIELD FieldData 1, TIME 1 1 double      simulated time [s] (ParaView shows it)
 *   POINTS n double                         centres [m]
 *   VERTICES n 2n                           one vertex cell per sphere ("1 i")
 *   POINT_DATA n, FIELD FieldData 9: radius [m], velocity [m/s], spin [rad/s], contacts,
 *                                    bridges, agglomerate, material, id, fixed (1: held in
 *                                    place)
 * Links: POINTS 2n (the ends of each line), LINES n 3n ("2 2k 2k+1"), CELL_DATA n with FIELD
 * FieldData 8: i, j, contact, bridge (int), gap [m], force_normal [N], force_tangential [N],
 * force (3 components, on i) [N].
 * The point arrays form a FIELD rather than SCALARS/VECTORS attributes because VTK's legacy
 * reader loads only the first SCALARS and VECTORS unless told otherwise; field arrays are all
 * read.
 * Binary arrays are big-endian (the legacy format's byte order); 32-bit ints and 64-bit
 * doubles. Render spheres in ParaView with the Glyph filter (sphere, scale by "radius", factor 2).
 * Files are written to "<path>.tmp" and renamed into place (atomic on POSIX file systems).
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "locale_guard.h"
#include "output_vtk.h"
#include "status.h"

/* The first two lines of every file: the legacy format's version, and the title, which names
 * the content ("particles" or "links") and gives the time [s] with 17 significant digits (an
 * exact round trip). write_head writes them; wetdem_output_vtk_frame_time reads them back. */
#define VERSION_LINE "# vtk DataFile Version 3.0\n"
#define TITLE_HEAD "wetdem %s t = "
#define TITLE_FORMAT TITLE_HEAD "%.17g s\n"
#define PARTICLES "particles"
/* The keys of an entry of a ".vtk.series" index, one line each ({ "name" : "F", "time" : T }):
 * wetdem_output_vtk_series_write writes them, wetdem_output_vtk_series_entry reads them. */
#define SERIES_NAME "\"name\" : "
#define SERIES_TIME "\"time\" : "

static bool host_is_little_endian(void)
{
    const uint16_t probe = 1;
    unsigned char b;
    memcpy(&b, &probe, 1);
    return b == 1;
}

/* Writes `count` elements of `size` bytes in big-endian order. */
static void put_be(FILE* f, const void* data, size_t size, size_t count)
{
    const unsigned char* s = data;
    if (!host_is_little_endian()) {
        fwrite(s, size, count, f);
        return;
    }
    unsigned char buf[8];
    for (size_t e = 0; e < count; e++) {
        for (size_t b = 0; b < size; b++)
            buf[b] = s[e * size + size - 1 - b];
        fwrite(buf, size, 1, f);
    }
}

static void put_double(FILE* f, double x, bool binary)
{
    if (binary)
        put_be(f, &x, sizeof x, 1);
    else
        fprintf(f, "%.17g\n", x);
}

static void put_vec(FILE* f, struct wetdem_vec3 v, bool binary)
{
    if (binary) {
        double a[3] = {v.x, v.y, v.z};
        put_be(f, a, sizeof a[0], 3);
    } else {
        fprintf(f, "%.17g %.17g %.17g\n", v.x, v.y, v.z);
    }
}

static void put_int(FILE* f, int32_t x, bool binary)
{
    if (binary)
        put_be(f, &x, sizeof x, 1);
    else
        fprintf(f, "%d\n", (int)x);
}

/* The vec3 member of particle k selected by `which`: 0 position, 1 velocity, 2 spin. */
static struct wetdem_vec3 member(const struct wetdem_particle* p, int which)
{
    return which == 0 ? p->pos : (which == 1 ? p->vel : p->omega);
}

static void write_vectors(FILE* f, const char* head, const struct wetdem_particle* p, size_t n,
                          int which, bool binary)
{
    fprintf(f, head, n);
    for (size_t k = 0; k < n; k++)
        put_vec(f, member(&p[k], which), binary);
    if (binary)
        fputc('\n', f);
}

enum int_data { INT_COUNT, INT_MATERIAL, INT_ID, INT_FIXED };

/* Integer point data: a count or label (`count`, NULL for zeros), material, id or fixed. */
static void write_ints(FILE* f, const char* name, const struct wetdem_particle* p, size_t n,
                       const uint32_t* count, enum int_data which, bool binary)
{
    fprintf(f, "%s 1 %zu int\n", name, n);
    for (size_t k = 0; k < n; k++) {
        int32_t v = which == INT_COUNT      ? (count ? (int32_t)count[k] : 0)
                    : which == INT_MATERIAL ? (int32_t)p[k].material
                    : which == INT_FIXED    ? (int32_t)p[k].is_fixed
                                            : (int32_t)k;
        put_int(f, v, binary);
    }
    if (binary)
        fputc('\n', f);
}

/* The title, format and TIME field data of a file. */
static void write_head(FILE* f, const char* what, double time, bool binary)
{
    fprintf(f, VERSION_LINE TITLE_FORMAT, what, time);
    fprintf(f, "%s\nDATASET POLYDATA\nFIELD FieldData 1\nTIME 1 1 double\n",
            binary ? "BINARY" : "ASCII");
    put_double(f, time, binary);
    if (binary)
        fputc('\n', f);
}

static void write_body(FILE* f, const struct wetdem_particle* p, size_t n,
                       const struct wetdem_output_vtk_counts* counts, double time, bool binary)
{
    write_head(f, PARTICLES, time, binary);
    write_vectors(f, "POINTS %zu double\n", p, n, 0, binary);
    fprintf(f, "VERTICES %zu %zu\n", n, 2 * n);
    for (size_t k = 0; k < n; k++) {
        int32_t cell[2] = {1, (int32_t)k};
        if (binary)
            put_be(f, cell, sizeof cell[0], 2);
        else
            fprintf(f, "1 %zu\n", k);
    }
    if (binary)
        fputc('\n', f);
    fprintf(f, "POINT_DATA %zu\nFIELD FieldData 9\nradius 1 %zu double\n", n, n);
    for (size_t k = 0; k < n; k++)
        put_double(f, p[k].radius, binary);
    if (binary)
        fputc('\n', f);
    write_vectors(f, "velocity 3 %zu double\n", p, n, 1, binary);
    write_vectors(f, "spin 3 %zu double\n", p, n, 2, binary);
    const struct wetdem_output_vtk_counts none = {0};
    const struct wetdem_output_vtk_counts* c = counts ? counts : &none;
    write_ints(f, "contacts", p, n, c->contacts, INT_COUNT, binary);
    write_ints(f, "bridges", p, n, c->bridges, INT_COUNT, binary);
    write_ints(f, "agglomerate", p, n, c->agglomerate, INT_COUNT, binary);
    write_ints(f, "material", p, n, NULL, INT_MATERIAL, binary);
    write_ints(f, "id", p, n, NULL, INT_ID, binary);
    write_ints(f, "fixed", p, n, NULL, INT_FIXED, binary);
}

/* A cell array of the links: member `which` of each, 0 i, 1 j, 2 contact, 3 bridge (int), 4
 * gap, 5 force_normal, 6 force_tangential (double), 7 force (3 doubles). */
static void write_link_array(FILE* f, const char* name, const struct wetdem_output_vtk_link* l,
                             size_t n, int which, bool binary)
{
    fprintf(f, "%s %d %zu %s\n", name, which == 7 ? 3 : 1, n, which < 4 ? "int" : "double");
    for (size_t k = 0; k < n; k++) {
        switch (which) {
        case 0: put_int(f, l[k].i, binary); break;
        case 1: put_int(f, l[k].j, binary); break;
        case 2: put_int(f, l[k].contact, binary); break;
        case 3: put_int(f, l[k].bridge, binary); break;
        case 4: put_double(f, l[k].gap, binary); break;
        case 5: put_double(f, l[k].f_normal, binary); break;
        case 6: put_double(f, l[k].f_tangential, binary); break;
        default: put_vec(f, l[k].force, binary); break;
        }
    }
    if (binary)
        fputc('\n', f);
}

static void write_links_body(FILE* f, const struct wetdem_output_vtk_link* l, size_t n, double time,
                             bool binary)
{
    write_head(f, "links", time, binary);
    fprintf(f, "POINTS %zu double\n", 2 * n);
    for (size_t k = 0; k < n; k++) {
        put_vec(f, l[k].a, binary);
        put_vec(f, l[k].b, binary);
    }
    if (binary)
        fputc('\n', f);
    fprintf(f, "LINES %zu %zu\n", n, 3 * n);
    for (size_t k = 0; k < n; k++) {
        int32_t cell[3] = {2, (int32_t)(2 * k), (int32_t)(2 * k + 1)};
        if (binary)
            put_be(f, cell, sizeof cell[0], 3);
        else
            fprintf(f, "2 %zu %zu\n", 2 * k, 2 * k + 1);
    }
    if (binary)
        fputc('\n', f);
    fprintf(f, "CELL_DATA %zu\nFIELD FieldData 8\n", n);
    static const char* const names[] = {
        "i", "j", "contact", "bridge", "gap", "force_normal", "force_tangential", "force"};
    for (int w = 0; w < 8; w++)
        write_link_array(f, names[w], l, n, w, binary);
}

/* Closes f (opened on tmp) and renames tmp to path; cleans up on failure. */
static int finish_atomic(FILE* f, const char* tmp, const char* path, char* msg, size_t n)
{
    bool ok = !ferror(f);
    ok = (fclose(f) == 0) && ok;
    if (!ok || rename(tmp, path) != 0) {
        int err = errno;
        remove(tmp);
        return wetdem_status_fail(msg, n, WETDEM_ERR_IO, "cannot write '%s': %s", path,
                                  strerror(err));
    }
    return WETDEM_OK;
}

static FILE* open_tmp(const char* path, char* tmp, size_t tmp_size, char* msg, size_t n)
{
    if ((size_t)snprintf(tmp, tmp_size, "%s.tmp", path) >= tmp_size) {
        wetdem_status_fail(msg, n, WETDEM_ERR_IO, "output path too long: '%s'", path);
        return NULL;
    }
    FILE* f = fopen(tmp, "wb");
    if (!f)
        wetdem_status_fail(msg, n, WETDEM_ERR_IO, "cannot open '%s' for writing: %s", tmp,
                           strerror(errno));
    return f;
}

/* What a VTK file holds: particles (p, counts) or, is_links, links (l), n of them. */
struct vtk_content {
    bool is_links;
    const struct wetdem_particle* p;
    const struct wetdem_output_vtk_counts* counts;
    const struct wetdem_output_vtk_link* l;
    size_t n;
    double time;
    bool binary;
};

/* Writes the content to path, atomically. */
static int write_vtk_file(const char* path, const struct vtk_content* c, char* msg, size_t n)
{
    if (c->n > (c->is_links ? INT32_MAX / 3 : INT32_MAX))
        return wetdem_status_fail(msg, n, WETDEM_ERR_IO, "too many %s for a legacy VTK file: %zu",
                                  c->is_links ? "links" : "particles", c->n);
    char tmp[4096];
    FILE* f = open_tmp(path, tmp, sizeof tmp, msg, n);
    if (!f)
        return WETDEM_ERR_IO;
    if (c->is_links)
        write_links_body(f, c->l, c->n, c->time, c->binary);
    else
        write_body(f, c->p, c->n, c->counts, c->time, c->binary);
    return finish_atomic(f, tmp, path, msg, n);
}

int wetdem_output_vtk_write(const char* path, const struct wetdem_particle* p, size_t n,
                            const struct wetdem_output_vtk_counts* counts, double time, bool binary,
                            char* msg, size_t msg_size)
{
    const struct vtk_content c = {.p = p, .counts = counts, .n = n, .time = time, .binary = binary};
    return write_vtk_file(path, &c, msg, msg_size);
}

int wetdem_output_vtk_links_write(const char* path, const struct wetdem_output_vtk_link* links,
                                  size_t n, double time, bool binary, char* msg, size_t msg_size)
{
    const struct vtk_content c = {
        .is_links = true, .l = links, .n = n, .time = time, .binary = binary};
    return write_vtk_file(path, &c, msg, msg_size);
}

/* The time in `title` if it is the title write_head gives a particle file: after the head, a
 * finite number that TITLE_FORMAT prints as the line has it (nothing else after " s", no other
 * spelling of the number). */
static int title_time(const char* title, double* t)
{
    char head[64], want[128];
    int n = snprintf(head, sizeof head, TITLE_HEAD, PARTICLES);
    if (strncmp(title, head, (size_t)n) != 0)
        return WETDEM_ERR_PARSE;
    double x = strtod(title + n, NULL);
    snprintf(want, sizeof want, TITLE_FORMAT, PARTICLES, x);
    if (!isfinite(x) || strcmp(title, want) != 0)
        return WETDEM_ERR_PARSE;
    *t = x;
    return WETDEM_OK;
}

/* The time of a particle file from its first two lines, the version and the title. */
static int read_frame_time(FILE* f, double* t)
{
    char version[64], title[128]; /* (a longer line is cut, and so not a title) */
    bool got = fgets(version, sizeof version, f) && fgets(title, sizeof title, f);
    if (ferror(f))
        return WETDEM_ERR_IO;
    if (!got || strcmp(version, VERSION_LINE) != 0)
        return WETDEM_ERR_PARSE;
    return title_time(title, t);
}

int wetdem_output_vtk_frame_time(const char* path, double* t)
{
    if (!path || !t)
        return WETDEM_ERR_INVALID;
    struct wetdem_locale_guard g; /* (strtod reads a decimal point in the C locale only) */
    if (wetdem_locale_guard_enter(&g) != WETDEM_OK)
        return WETDEM_ERR_NOMEM;
    FILE* f = fopen(path, "rb");
    int st = f ? read_frame_time(f, t) : WETDEM_ERR_IO;
    if (f)
        fclose(f);
    wetdem_locale_guard_leave(&g);
    return st;
}

int wetdem_output_vtk_path(char* buf, size_t size, const char* prefix, uint64_t index)
{
    return snprintf(buf, size, "%s_%06llu.vtk", prefix, (unsigned long long)index);
}

/* Writes s as a JSON string literal (quotes and backslashes escaped). */
static void put_json_string(FILE* f, const char* s)
{
    fputc('"', f);
    for (; *s; s++) {
        if (*s == '"' || *s == '\\')
            fputc('\\', f);
        fputc(*s, f);
    }
    fputc('"', f);
}

int wetdem_output_vtk_series_write(const char* path, const char* const* files, const double* times,
                                   size_t n, char* msg, size_t msg_size)
{
    char tmp[4096];
    FILE* f = open_tmp(path, tmp, sizeof tmp, msg, msg_size);
    if (!f)
        return WETDEM_ERR_IO;
    fputs("{\n  \"file-series-version\" : \"1.0\",\n  \"files\" : [\n", f);
    for (size_t k = 0; k < n; k++) {
        fputs("    { " SERIES_NAME, f);
        put_json_string(f, files[k]);
        fprintf(f, ", " SERIES_TIME "%.17g }%s\n", times[k], k + 1 < n ? "," : "");
    }
    fputs("  ]\n}\n", f);
    return finish_atomic(f, tmp, path, msg, msg_size);
}

/* The JSON string at s (after its opening quote) with the escapes put_json_string writes
 * (\" and \\) undone, into name unless it is NULL (n bytes); its length, or n when it is
 * unterminated or does not fit in n bytes. *end: after the closing quote. */
static size_t json_string(const char* s, char* name, size_t n, const char** end)
{
    size_t len = 0;
    for (; *s && *s != '"'; s++, len++) {
        if (*s == '\\' && (s[1] == '"' || s[1] == '\\'))
            s++;
        if (len + 1 >= n)
            return n;
        if (name)
            name[len] = *s;
    }
    if (*s != '"')
        return n;
    if (name)
        name[len] = '\0';
    *end = s + 1;
    return len;
}

int wetdem_output_vtk_series_entry(const char* line, char* name, size_t n, double* time)
{
    if (!line || !name || n == 0 || !time)
        return WETDEM_ERR_INVALID;
    const char *p = strstr(line, SERIES_NAME "\""), *end = NULL;
    p = p ? p + strlen(SERIES_NAME "\"") : NULL;
    size_t len = p ? json_string(p, NULL, n, &end) : 0;
    const char* q = len > 0 && len < n ? strstr(end, SERIES_TIME) : NULL;
    if (!q)
        return WETDEM_ERR_PARSE;
    struct wetdem_locale_guard g; /* (strtod reads a decimal point in the C locale only) */
    if (wetdem_locale_guard_enter(&g) != WETDEM_OK)
        return WETDEM_ERR_NOMEM;
    char* after;
    double t = strtod(q + strlen(SERIES_TIME), &after);
    wetdem_locale_guard_leave(&g);
    if (after == q + strlen(SERIES_TIME) || !isfinite(t))
        return WETDEM_ERR_PARSE;
    json_string(p, name, n, &end);
    *time = t;
    return WETDEM_OK;
}

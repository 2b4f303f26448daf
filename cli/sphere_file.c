/*
 * sphere_file.c — spheres read from a file ([read.NAME] of a many-particle scenario; see
 * sphere_file.h): a CSV table with a header naming its columns, or a particle frame written by
 * a wetdem run (src/output_vtk.c: legacy VTK POLYDATA, ASCII with 17 digits or big-endian
 * binary, the spheres' centres as POINTS and radius, velocity, spin and fixed among the point
 * field arrays), so that a run can start from the state where another one ended: a packing settled
 * dry and then wetted, a state from another code, a measured packing. A run's .vtk.series index
 * stands for the last frame it lists.
 *
 * Every value is checked as the scenario keys of [particle.NAME] are (finite, and within the
 * same ranges; fixed 0 or 1, and a fixed sphere at rest), with the line of the CSV or the
 * sphere of the frame in the message. The values
 * of a frame are its bits (binary) or its 17 digits (ASCII), so a run started from a frame
 * starts from the state that wrote it.
 */
#include "sphere_file.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "cli_util.h"

#define MAX_SPHERES 100000000 /* as [insert] count */
#define MAX_FIELDS 64         /* fields of a CSV line read (more: a count error) */

/* The columns a CSV may have (the [particle.NAME] keys), with their ranges and units. */
enum column { X, Y, Z, RADIUS, VX, VY, VZ, SPIN_X, SPIN_Y, SPIN_Z, FIXED, MATERIAL, N_COLUMNS };
static const char* const column_names[] = {"x",     "y",        "z",      "radius", "vx",
                                           "vy",    "vz",       "spin_x", "spin_y", "spin_z",
                                           "fixed", "material", NULL};
static const char* const column_units[N_COLUMNS] = {"m",   "m",     "m",     "m",     "m/s", "m/s",
                                                    "m/s", "rad/s", "rad/s", "rad/s", "-",   "-"};
static const struct {
    double lo, hi;
    bool lo_open;
} column_range[N_COLUMNS] = {
    {-1e3, 1e3, false}, {-1e3, 1e3, false}, {-1e3, 1e3, false}, {0, 1, true},
    {-1e3, 1e3, false}, {-1e3, 1e3, false}, {-1e3, 1e3, false}, {-1e6, 1e6, false},
    {-1e6, 1e6, false}, {-1e6, 1e6, false}, {0, 1, false},      {0, 1000, false},
};

static int fail(char* err, size_t err_len, const char* fmt, ...)
    __attribute__((format(printf, 3, 4)));

/* Writes why into err; returns CLI_EXIT_USAGE (bad input). */
static int fail(char* err, size_t err_len, const char* fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, err_len, fmt, ap);
    va_end(ap);
    return CLI_EXIT_USAGE;
}

static int no_memory(char* err, size_t err_len)
{
    snprintf(err, err_len, "out of memory");
    return CLI_EXIT_RUNTIME;
}

/* Whether value v lies in column c's range (fixed: 0 or 1; material: a whole number);
 * otherwise writes why into err. */
static bool in_range(enum column c, double v, char* err, size_t err_len, const char* where)
{
    bool ok = column_range[c].lo_open ? v > column_range[c].lo : v >= column_range[c].lo;
    if (ok && v <= column_range[c].hi && (c != FIXED || v == 0 || v == 1) &&
        (c != MATERIAL || v == floor(v)))
        return true;
    if (c == FIXED) {
        fail(err, err_len, "%sfixed = %g is not 0 (free) or 1 (held in place)", where, v);
        return false;
    }
    if (c == MATERIAL) {
        fail(err, err_len,
             "%smaterial = %g is not a whole number in [0, 1000] (the index of the sphere's "
             "material in [read.NAME] materials)",
             where, v);
        return false;
    }
    fail(err, err_len, "%s%s = %g %s is not in %c%g, %g] %s", where, column_names[c], v,
         column_units[c], column_range[c].lo_open ? '(' : '[', column_range[c].lo,
         column_range[c].hi, column_units[c]);
    return false;
}

/* The sphere of values v (indexed by column; absent columns 0, material -1), checked: a fixed
 * one must be at rest (else why, after `where`, into err and false). Without marks_fixed the
 * fixed column is not used: the sphere is free. */
static bool sphere_of(const double v[N_COLUMNS], bool marks_fixed, struct wetdem_particle* p,
                      char* err, size_t err_len, const char* where)
{
    *p = (struct wetdem_particle){.pos = {v[X], v[Y], v[Z]},
                                  .vel = {v[VX], v[VY], v[VZ]},
                                  .omega = {v[SPIN_X], v[SPIN_Y], v[SPIN_Z]},
                                  .radius = v[RADIUS],
                                  .material = (int)v[MATERIAL],
                                  .is_fixed = marks_fixed && v[FIXED] == 1};
    for (int c = VX; p->is_fixed && c <= SPIN_Z; c++)
        if (v[c] != 0) {
            fail(err, err_len,
                 "%sa fixed sphere (fixed = 1) is held in place, at rest: %s = %g must be 0", where,
                 column_names[c], v[c]);
            return false;
        }
    return true;
}

/* Appends p to the growing array *a (count *n, capacity *cap). */
static bool push(struct wetdem_particle** a, size_t* n, size_t* cap, struct wetdem_particle p)
{
    if (*n == *cap) {
        size_t c = *cap ? 2 * *cap : 256;
        struct wetdem_particle* grown = realloc(*a, c * sizeof *grown);
        if (!grown)
            return false;
        *a = grown;
        *cap = c;
    }
    (*a)[(*n)++] = p;
    return true;
}

/* A sphere's centre and its place in the file, for finding two at one centre. */
struct centre {
    double x, y, z;
    size_t index;
};

static int by_centre(const void* a, const void* b)
{
    const struct centre *p = a, *q = b;
    int c = (p->x > q->x) - (p->x < q->x);
    c = c ? c : (p->y > q->y) - (p->y < q->y);
    c = c ? c : (p->z > q->z) - (p->z < q->z);
    return c ? c : (p->index > q->index) - (p->index < q->index);
}

/* Two of the n spheres at one centre (a row given twice) cannot be a packing: every pair
 * force acts along the line of centres, which they do not have, so the pair was pushed apart
 * along an arbitrary axis from an overlap of a whole diameter. On a periodic axis of length
 * period[k] > 0 (period may be NULL) the centre at period[k] is the one at 0. The first such
 * pair, by its CSV lines (lines[i] of sphere i) or, without lines, by its place in the frame,
 * into err: CLI_EXIT_USAGE; CLI_EXIT_OK when every centre is distinct. Sorting: O(n log n). */
static int check_distinct_centres(const struct wetdem_particle* p, size_t n, const size_t* lines,
                                  const double* period, char* err, size_t err_len)
{
    struct centre* c = malloc((n ? n : 1) * sizeof *c);
    if (!c)
        return no_memory(err, err_len);
    for (size_t i = 0; i < n; i++) {
        double x[3] = {p[i].pos.x, p[i].pos.y, p[i].pos.z};
        for (int k = 0; k < 3 && period; k++)
            if (period[k] > 0 && x[k] == period[k])
                x[k] = 0;
        c[i] = (struct centre){x[0], x[1], x[2], i};
    }
    qsort(c, n, sizeof *c, by_centre);
    int rc = CLI_EXIT_OK;
    for (size_t k = 1; k < n && rc == CLI_EXIT_OK; k++) {
        if (c[k].x != c[k - 1].x || c[k].y != c[k - 1].y || c[k].z != c[k - 1].z)
            continue;
        size_t i = c[k - 1].index, j = c[k].index; /* i < j: the earlier in the file first */
        const struct wetdem_vec3 a = p[i].pos, b = p[j].pos;
        const char* why = a.x == b.x && a.y == b.y && a.z == b.z
                              ? "two spheres at one centre have no line of centres for their "
                                "contact; give each sphere once"
                              : "two spheres at one centre (on a periodic axis, 0 and the box "
                                "length are one place) have no line of centres for their "
                                "contact; give each sphere once";
        if (lines)
            rc = fail(err, err_len, "%zu: centre (%g, %g, %g) m, that of line %zu: %s", lines[j],
                      b.x, b.y, b.z, lines[i], why);
        else
            rc = fail(err, err_len, "sphere %zu: centre (%g, %g, %g) m, that of sphere %zu: %s",
                      j + 1, b.x, b.y, b.z, i + 1, why);
    }
    free(c);
    return rc;
}

/* The whole file, NUL-terminated, malloc'd; *len its length. NULL with errno set. */
static char* read_all(const char* path, size_t* len)
{
    FILE* f = fopen(path, "rb");
    if (!f)
        return NULL;
    struct stat st;
    if (fstat(fileno(f), &st) != 0 || !S_ISREG(st.st_mode)) { /* not /dev/zero, a FIFO, ... */
        fclose(f);
        errno = S_ISDIR(st.st_mode) ? EISDIR : EINVAL;
        return NULL;
    }
    size_t cap = 1 << 16, n = 0;
    char* buf = malloc(cap);
    while (buf) {
        n += fread(buf + n, 1, cap - n - 1, f);
        if (ferror(f) || n < cap - 1)
            break;
        char* grown = realloc(buf, 2 * cap);
        if (!grown) {
            free(buf);
            buf = NULL;
            errno = ENOMEM;
            break;
        }
        buf = grown;
        cap *= 2;
    }
    bool bad = !buf || ferror(f);
    fclose(f);
    if (bad) {
        free(buf);
        if (!errno)
            errno = EIO;
        return NULL;
    }
    buf[n] = '\0';
    *len = n;
    return buf;
}

/* ---------------------------------------------------------------------------- CSV --- */

/* Cuts s at the end of its line (\n, and a \r before it); returns the next line or NULL. */
static char* cut_line(char* s)
{
    char* nl = strchr(s, '\n');
    if (nl)
        *nl = '\0';
    size_t len = strlen(s);
    if (len && s[len - 1] == '\r')
        s[len - 1] = '\0';
    return nl ? nl + 1 : NULL;
}

static bool is_blank_or_comment(const char* s)
{
    while (isspace((unsigned char)*s))
        s++;
    return *s == '\0' || *s == '#';
}

/* The header's fields (*n_fields of them) mapped to the columns: col[c] is the field of column
 * c, or -1. */
static int read_header(char* line, size_t line_no, int col[N_COLUMNS], int* n_fields, char* err,
                       size_t err_len)
{
    char* f[MAX_FIELDS];
    *n_fields = cli_csv_split(line, f, MAX_FIELDS);
    char why[300];
    int bad;
    if (cli_csv_columns(f, *n_fields, column_names, column_units, col, &bad, why, sizeof why) != 0)
        return fail(err, err_len,
                    "%zu: %s (columns: x, y, z, radius; optional vx, vy, vz, spin_x, spin_y, "
                    "spin_z, fixed, material)",
                    line_no, why);
    for (int c = X; c <= RADIUS; c++)
        if (col[c] < 0)
            return fail(err, err_len,
                        "%zu: the header has no column '%s' (x, y, z and radius are "
                        "required)",
                        line_no, column_names[c]);
    return CLI_EXIT_OK;
}

static int read_csv(char* text, bool marks_fixed, struct wetdem_particle** out, size_t* n,
                    size_t** lines, char* err, size_t err_len)
{
    int col[N_COLUMNS + 1], n_fields = 0;
    size_t cap = 0, line_no = 0, lines_cap = 0;
    bool have_header = false;
    if (strncmp(text, "\xEF\xBB\xBF", 3) == 0) /* a byte-order mark */
        text += 3;
    for (char *line = text, *next; line; line = next) {
        next = cut_line(line);
        if (!next && !*line)
            break; /* (the end of a file that ends with a newline) */
        line_no++;
        if (is_blank_or_comment(line))
            continue;
        if (!have_header) {
            int rc = read_header(line, line_no, col, &n_fields, err, err_len);
            if (rc != CLI_EXIT_OK)
                return rc;
            have_header = true;
            continue;
        }
        char* f[MAX_FIELDS];
        int nf = cli_csv_split(line, f, MAX_FIELDS);
        if (nf != n_fields)
            return fail(err, err_len, "%zu: %d fields, the header has %d columns", line_no, nf,
                        n_fields);
        double v[N_COLUMNS] = {0};
        v[MATERIAL] = -1; /* none given */
        char where[64];
        snprintf(where, sizeof where, "%zu: ", line_no);
        for (int c = 0; c < N_COLUMNS; c++) {
            if (col[c] < 0)
                continue;
            if (cli_number(f[col[c]], &v[c]) != 0)
                return fail(err, err_len, "%zu: %s = '%s' is %s", line_no, column_names[c],
                            f[col[c]], cli_number_problem(f[col[c]]));
            if (!in_range(c, v[c], err, err_len, where))
                return CLI_EXIT_USAGE;
        }
        if (*n == MAX_SPHERES)
            return fail(err, err_len, "%zu: more than %d spheres", line_no, MAX_SPHERES);
        struct wetdem_particle p;
        if (!sphere_of(v, marks_fixed, &p, err, err_len, where))
            return CLI_EXIT_USAGE;
        if (*n == lines_cap) { /* (the line of each sphere, for messages) */
            size_t* grown =
                realloc(*lines, (lines_cap = lines_cap ? 2 * lines_cap : 256) * sizeof *grown);
            if (!grown)
                return no_memory(err, err_len);
            *lines = grown;
        }
        (*lines)[*n] = line_no;
        if (!push(out, n, &cap, p))
            return no_memory(err, err_len);
    }
    if (line_no == 0)
        return fail(err, err_len, "the file is empty (a CSV needs a header and a row a sphere)");
    if (!have_header)
        return fail(err, err_len,
                    "%zu: no header (a line naming the columns: x, y, z, radius, "
                    "...)",
                    line_no);
    if (*n == 0)
        return fail(err, err_len, "%zu: no spheres after the header", line_no);
    return 0;
}

/* ---------------------------------------------------------------------------- VTK --- */

struct vtk_cursor {
    const char* data;
    size_t len, at;
    bool binary;
};

/* The next line's words into w (at most 8, of at most 63 bytes); their number, -1 at the end. */
static int vtk_line(struct vtk_cursor* c, char w[8][64])
{
    if (c->at >= c->len)
        return -1;
    const char* s = c->data + c->at;
    const char* nl = memchr(s, '\n', c->len - c->at);
    size_t len = nl ? (size_t)(nl - s) : c->len - c->at;
    c->at += len + (nl != NULL);
    int n = 0;
    for (size_t k = 0; k < len && n < 8;) {
        while (k < len && isspace((unsigned char)s[k]))
            k++;
        size_t b = k;
        while (k < len && !isspace((unsigned char)s[k]))
            k++;
        if (k > b) {
            size_t m = k - b < 63 ? k - b : 63;
            memcpy(w[n], s + b, m);
            w[n++][m] = '\0';
        }
    }
    return n;
}

/* Whether count values of `size` bytes (binary) or of at least two characters (ASCII, a digit
 * and a separator) can follow: checked before an array is allocated for them. */
static bool vtk_fits(const struct vtk_cursor* c, size_t count, size_t size)
{
    return count <= (c->len - c->at) / (c->binary ? size : 2) + (c->binary ? 0 : 1);
}

/* count values of `type` (double, float or int) into out (NULL: skipped). */
static int vtk_values(struct vtk_cursor* c, size_t count, const char* type, double* out,
                      const char* what, char* err, size_t err_len)
{
    size_t size = strcmp(type, "double") == 0 ? 8 : 4;
    bool is_int = strcmp(type, "int") == 0;
    if (!is_int && size == 4 && strcmp(type, "float") != 0)
        return fail(err, err_len, "%s: values of type '%s' (wetdem writes double and int)", what,
                    type);
    if (c->binary) {
        if (count > (c->len - c->at) / size)
            return fail(err, err_len, "%s: the file ends within its %zu values", what, count);
        const unsigned char* p = (const unsigned char*)c->data + c->at;
        for (size_t k = 0; out && k < count; k++, p += size) {
            uint64_t u = 0;
            for (size_t b = 0; b < size; b++)
                u = u << 8 | p[b];
            if (size == 8) {
                memcpy(&out[k], &u, 8);
            } else if (is_int) {
                out[k] = (double)(int32_t)(uint32_t)u;
            } else {
                uint32_t u32 = (uint32_t)u;
                float f;
                memcpy(&f, &u32, 4);
                out[k] = f;
            }
        }
        c->at += count * size;
        if (c->at < c->len && c->data[c->at] == '\n')
            c->at++;
        return 0;
    }
    for (size_t k = 0; k < count; k++) {
        while (c->at < c->len && isspace((unsigned char)c->data[c->at]))
            c->at++;
        size_t b = c->at;
        while (c->at < c->len && !isspace((unsigned char)c->data[c->at]))
            c->at++;
        char word[64];
        size_t m = c->at - b;
        if (m == 0)
            return fail(err, err_len, "%s: the file ends within its %zu values", what, count);
        if (m > 63)
            return fail(err, err_len, "%s: value %zu is not a number", what, k + 1);
        memcpy(word, c->data + b, m);
        word[m] = '\0';
        double v;
        if (cli_number(word, &v) != 0)
            return fail(err, err_len, "%s: value %zu, '%s', is %s", what, k + 1, word,
                        cli_number_problem(word));
        if (out)
            out[k] = v;
    }
    if (c->at < c->len && c->data[c->at] == '\n')
        c->at++;
    return 0;
}

/* A count from a header word: a whole number up to MAX_SPHERES x 3, or -1. */
static long long vtk_count(const char* w)
{
    char* end;
    errno = 0;
    long long v = strtoll(w, &end, 10);
    return errno || *end || v < 0 || v > 3LL * MAX_SPHERES ? -1 : v;
}

static int read_vtk(const char* data, size_t len, bool marks_fixed, struct wetdem_particle** out,
                    size_t* n, char* err, size_t err_len)
{
    struct vtk_cursor c = {.data = data, .len = len};
    char w[8][64];
    int nw = vtk_line(&c, w);
    if (nw < 2 || strcmp(w[0], "#") != 0 || strcmp(w[1], "vtk") != 0)
        return fail(err, err_len, "not a legacy VTK file (no '# vtk DataFile' first line)");
    vtk_line(&c, w); /* the title */
    nw = vtk_line(&c, w);
    if (nw != 1 || (strcmp(w[0], "ASCII") != 0 && strcmp(w[0], "BINARY") != 0))
        return fail(err, err_len, "line 3 is not ASCII or BINARY");
    c.binary = strcmp(w[0], "BINARY") == 0;
    nw = vtk_line(&c, w);
    if (nw != 2 || strcmp(w[0], "DATASET") != 0 || strcmp(w[1], "POLYDATA") != 0)
        return fail(err, err_len, "not a wetdem frame: line 4 is not DATASET POLYDATA");
    double *pos = NULL, *arrays[5] = {NULL, NULL, NULL, NULL, NULL}; /* as wanted[] */
    static const char* const wanted[] = {"radius", "velocity", "spin", "fixed", "material"};
    static const int comps[] = {1, 3, 3, 1, 1};
    long long n_points = -1;
    int rc = 0;
    while (rc == 0 && (nw = vtk_line(&c, w)) >= 0) {
        if (nw == 0)
            continue;
        if (strcmp(w[0], "POINTS") == 0 && nw == 3 && n_points < 0 &&
            (n_points = vtk_count(w[1])) >= 0) {
            if (n_points > MAX_SPHERES)
                rc = fail(err, err_len, "POINTS %lld: more than %d spheres", n_points, MAX_SPHERES);
            else if (!vtk_fits(&c, (size_t)(3 * n_points), 8))
                rc = fail(err, err_len, "POINTS: the file ends within its %lld values",
                          3 * n_points);
            else if (!(pos = malloc((size_t)(3 * n_points + 1) * sizeof *pos)))
                rc = no_memory(err, err_len);
            else
                rc = vtk_values(&c, (size_t)(3 * n_points), w[2], pos, "POINTS", err, err_len);
        } else if (strcmp(w[0], "VERTICES") == 0 && nw == 3 && vtk_count(w[2]) >= 0) {
            rc = vtk_values(&c, (size_t)vtk_count(w[2]), "int", NULL, "VERTICES", err, err_len);
        } else if (strcmp(w[0], "LINES") == 0) {
            rc = fail(err, err_len,
                      "a links file (LINES), not a particle frame: give the frame "
                      "PREFIX_NNNNNN.vtk beside it");
        } else if (strcmp(w[0], "POINT_DATA") == 0 && nw == 2) {
            if (vtk_count(w[1]) != n_points)
                rc = fail(err, err_len, "POINT_DATA %s for %lld points", w[1], n_points);
        } else if (strcmp(w[0], "FIELD") == 0 && nw == 3 && vtk_count(w[2]) >= 0) {
            long long k_arrays = vtk_count(w[2]);
            for (long long k = 0; rc == 0 && k < k_arrays; k++) {
                nw = vtk_line(&c, w);
                long long nc = nw == 4 ? vtk_count(w[1]) : -1, nt = nw == 4 ? vtk_count(w[2]) : -1;
                if (nc <= 0 || nt < 0 || nc > 9) {
                    rc = fail(err, err_len, "FIELD array %lld: not 'NAME COMPONENTS TUPLES TYPE'",
                              k + 1);
                    break;
                }
                int a = 0;
                while (a < 5 && strcmp(w[0], wanted[a]) != 0)
                    a++;
                double* dest = NULL;
                if (a < 5 && !arrays[a]) {
                    if (nc != comps[a] || nt != n_points) {
                        rc = fail(err, err_len, "array %s: %lld x %lld values, expected %d x %lld",
                                  wanted[a], nt, nc, comps[a], n_points);
                        break;
                    }
                    if (!vtk_fits(&c, (size_t)(nc * nt), strcmp(w[3], "double") == 0 ? 8 : 4)) {
                        rc = fail(err, err_len, "array %s: the file ends within its values",
                                  wanted[a]);
                        break;
                    }
                    dest = arrays[a] = malloc((size_t)(nc * nt + 1) * sizeof *dest);
                    if (!dest) {
                        rc = no_memory(err, err_len);
                        break;
                    }
                }
                char what[80];
                snprintf(what, sizeof what, "array %s", w[0]);
                rc = vtk_values(&c, (size_t)(nc * nt), w[3], dest, what, err, err_len);
            }
        } else {
            rc = fail(err, err_len, "not a wetdem frame: unexpected '%s'", w[0]);
        }
    }
    if (rc == 0 && n_points <= 0)
        rc = fail(err, err_len, "no POINTS (or none)");
    if (rc == 0 && !arrays[0])
        rc = fail(err, err_len, "no point array 'radius' (a frame of a wetdem run has one)");
    size_t cap = 0;
    for (long long i = 0; rc == 0 && i < n_points; i++) {
        double v[N_COLUMNS] = {0};
        for (int k = 0; k < 3; k++) {
            v[X + k] = pos[3 * i + k];
            v[VX + k] = arrays[1] ? arrays[1][3 * i + k] : 0;
            v[SPIN_X + k] = arrays[2] ? arrays[2][3 * i + k] : 0;
        }
        v[RADIUS] = arrays[0][i];
        v[FIXED] = arrays[3] ? arrays[3][i] : 0;
        v[MATERIAL] = arrays[4] ? arrays[4][i] : -1;
        char where[64];
        snprintf(where, sizeof where, "sphere %lld: ", i + 1);
        for (int k = 0; rc == 0 && k < N_COLUMNS; k++)
            if (k == MATERIAL && !arrays[4])
                continue; /* (none given: -1) */
            else if (!isfinite(v[k]))
                rc = fail(err, err_len, "%s%s is not a finite number", where, column_names[k]);
            else if (!in_range(k, v[k], err, err_len, where))
                rc = CLI_EXIT_USAGE;
        struct wetdem_particle p;
        if (rc == 0 && !sphere_of(v, marks_fixed, &p, err, err_len, where))
            rc = CLI_EXIT_USAGE;
        if (rc == 0 && !push(out, n, &cap, p))
            rc = no_memory(err, err_len);
    }
    free(pos);
    for (int a = 0; a < 5; a++)
        free(arrays[a]);
    return rc;
}

/* The path of the last frame a .vtk.series index lists (the text of the index, cut into lines
 * here), beside the index. */
static int last_frame(const char* index, char* text, char* path, size_t n, char* err,
                      size_t err_len)
{
    char name[1024] = "", entry[sizeof name];
    double time;
    for (char *line = text, *next; line; line = next) {
        next = cut_line(line);
        if (wetdem_output_vtk_series_entry(line, entry, sizeof entry, &time) == WETDEM_OK)
            memcpy(name, entry, sizeof name);
    }
    if (!name[0])
        return fail(err, err_len, "the index lists no frame (a .vtk.series of a wetdem run)");
    const char* slash = strrchr(index, '/');
    int dir = slash ? (int)(slash - index + 1) : 0;
    if ((size_t)snprintf(path, n, "%.*s%s", dir, index, name) >= n)
        return fail(err, err_len, "the path of its last frame is too long");
    size_t len = strlen(path);
    if (len < 5 || strcmp(path + len - 4, ".vtk") != 0)
        return fail(err, err_len, "its last frame, %s, is not a .vtk file", name);
    return CLI_EXIT_OK;
}

int cli_read_sphere_file(const char* path, bool marks_fixed, const double* period,
                         struct wetdem_particle** out, size_t* n, char* err, size_t err_len)
{
    *out = NULL;
    *n = 0;
    size_t len = 0;
    errno = 0;
    char* text = read_all(path, &len);
    if (!text && errno == ENOMEM)
        return no_memory(err, err_len);
    if (!text)
        return fail(err, err_len, "cannot read it: %s",
                    errno == EINVAL ? "not a regular file" : strerror(errno));
    size_t plen = strlen(path);
    if (plen > 11 && strcmp(path + plen - 11, ".vtk.series") == 0) {
        char frame[4200];
        int rc = last_frame(path, text, frame, sizeof frame, err, err_len);
        free(text);
        char why[400];
        if (rc == CLI_EXIT_OK &&
            (rc = cli_read_sphere_file(frame, marks_fixed, period, out, n, why, sizeof why)) != 0)
            snprintf(err, err_len, "its last frame %s: %s", frame, why);
        return rc;
    }
    size_t* lines = NULL; /* (a CSV's) */
    int rc =
        plen > 4 && strcmp(path + plen - 4, ".vtk") == 0
            ? read_vtk(text, len, marks_fixed, out, n, err, err_len)
            : (memchr(text, '\0', len) ? fail(err, err_len, "a CSV with a NUL byte")
                                       : read_csv(text, marks_fixed, out, n, &lines, err, err_len));
    free(text);
    if (rc == 0)
        rc = check_distinct_centres(*out, *n, lines, period, err, err_len);
    free(lines);
    if (rc != 0) {
        free(*out);
        *out = NULL;
        *n = 0;
    }
    return rc;
}

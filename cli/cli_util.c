/*
 * cli_util.c — helpers shared by the CLI subcommands (see cli_util.h): messages, strict
 * parsing of numbers and "A:B:N" ranges, "--set KEY=VALUE", CSV provenance lines, tables
 * and --out files written whole (temporary file, then rename) or not at all, the progress line
 * of a long run.
 *
 * Range values: linear x_k = A + (B - A) k/(N - 1); geometric x_k = A (B/A)^(k/(N - 1)),
 * computed as 10^(log10 A + (log10 B - log10 A) k/(N - 1)) so that decades come out as the
 * round numbers they are; k = 0..N-1, with x_0 = A and x_{N-1} = B returned exactly.
 */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <omp.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli_util.h"
#include "output_journal.h"
#include "signals.h"

void cli_error(const char* fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fputs("wetdem: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
}

/* The length of the longest prefix of text in the number syntax
 * [+-] digits [. digits] [(e|E) [+-] digits], with at least one digit before the exponent
 * (an exponent without digits is not part of it); 0 when text does not start with one. */
static size_t number_syntax(const char* text)
{
    const char* p = text;
    size_t mantissa = 0;
    p += *p == '+' || *p == '-';
    for (; isdigit((unsigned char)*p); p++)
        mantissa++;
    if (*p == '.')
        for (p++; isdigit((unsigned char)*p); p++)
            mantissa++;
    if (!mantissa)
        return 0;
    if (*p == 'e' || *p == 'E') {
        const char* q = p + 1;
        q += *q == '+' || *q == '-';
        if (isdigit((unsigned char)*q)) {
            while (isdigit((unsigned char)*q))
                q++;
            p = q;
        }
    }
    return (size_t)(p - text);
}

int cli_number(const char* text, double* out)
{
    size_t n = number_syntax(text);
    const char* p = text + n;
    if (n == 0 || *p != '\0')
        return -1;
    char* end = NULL;
    errno = 0;
    double v = strtod(text, &end);
    if (end != p)
        return -1;
    if (errno == ERANGE) /* (strtod's ERANGE: overflow to inf, or an underflow below DBL_MIN) */
        return fabs(v) >= 1 ? -2 : -3;
    if (!isfinite(v))
        return -1;
    *out = v;
    return 0;
}

const char* cli_number_problem(const char* text)
{
    double v;
    switch (cli_number(text, &v)) {
    case 0: return NULL;
    case -2: return "beyond the range of a double (magnitude up to 1.8e308)";
    case -3:
        return "below the smallest normal double (magnitude 2.2e-308): write 0 or a larger "
               "value";
    default: return "not a finite number";
    }
}

/* The length of the longest prefix of text in cli_number's syntax (0: none), its value in *v. */
static size_t number_prefix(const char* text, double* v)
{
    char buf[64];
    size_t len = number_syntax(text);
    if (len == 0 || len >= sizeof buf)
        return 0;
    memcpy(buf, text, len);
    buf[len] = '\0';
    *v = strtod(buf, NULL);
    return isfinite(*v) ? len : 0;
}

/* Copies s to out without blanks. */
static void squeeze(const char* s, char* out, size_t n)
{
    size_t k = 0;
    for (; *s && k + 1 < n; s++)
        if (!isspace((unsigned char)*s))
            out[k++] = *s;
    out[k] = '\0';
}

/* The factor of an SI prefix at the start of s ("m", "u", "µ", "k", ...), its length in *len;
 * 0 when there is none. */
static double si_prefix(const char* s, size_t* len)
{
    static const struct {
        const char* p;
        double f;
    } prefixes[] = {{"G", 1e9},  {"M", 1e6},  {"k", 1e3},         {"c", 1e-2},       {"m", 1e-3},
                    {"u", 1e-6}, {"n", 1e-9}, {"\xc2\xb5", 1e-6}, {"\xce\xbc", 1e-6}};
    for (size_t k = 0; k < sizeof prefixes / sizeof prefixes[0]; k++) {
        size_t n = strlen(prefixes[k].p);
        if (strncmp(s, prefixes[k].p, n) == 0) {
            *len = n;
            return prefixes[k].f;
        }
    }
    return 0;
}

/* v with the fewest digits that read back as v (a converted value to paste), into num[32]. */
static const char* shortest(double v, char* num)
{
    wetdem_param_format_value(v, 1, num, 32);
    return num;
}

const char* cli_number_hint(const char* text, const char* unit, char* buf, size_t n)
{
    buf[0] = '\0';
    char num[32]; /* a converted value */
    double v;
    size_t len = strlen(text);
    if (len >= 2 && (text[0] == '"' || text[0] == '\'') && text[len - 1] == text[0]) {
        char inner[128];
        if (len - 2 < sizeof inner) {
            memcpy(inner, text + 1, len - 2);
            inner[len - 2] = '\0';
            if (cli_number(inner, &v) == 0)
                snprintf(buf, n, ": write it without quotes, %s", inner);
        }
        return buf;
    }
    size_t k = number_prefix(text, &v);
    if (k == 0 || cli_number(text, &v) == 0)
        return buf;
    const char* rest = text + k;
    if (strchr("eExX", *rest)) /* a broken exponent (5e), hexadecimal (0x10): no unit */
        return buf;
    while (isspace((unsigned char)*rest))
        rest++;
    bool dimensionless = !unit || !unit[0] || strcmp(unit, "-") == 0;
    if (*rest == ';' || *rest == '#') {
        snprintf(buf, n, ": an inline comment needs a blank before its '%c' (%.*s %s)", *rest,
                 (int)(rest - text), text, rest);
    } else if (*rest == ',' && rest == text + k && isdigit((unsigned char)rest[1])) {
        /* a decimal comma ("0,5"), or a thousands separator ("1,000") */
        const char* d = rest + 1;
        while (isdigit((unsigned char)*d))
            d++;
        if (*d == '\0' && d - rest - 1 != 3)
            snprintf(buf, n, ": write a decimal point, not a comma: %.*s.%s", (int)k, text,
                     rest + 1);
        else
            snprintf(buf, n, ": write a decimal point, not a comma, and no thousands separator");
    } else if (strcmp(rest, "%") == 0 && dimensionless) {
        snprintf(buf, n, ": write a fraction, not a percentage: %s = %s", text,
                 shortest(v / 100, num));
    } else if (isalpha((unsigned char)*rest) || (unsigned char)*rest >= 0x80 || *rest == '%') {
        /* a unit: the key's own (written out), one with an SI prefix (converted), or another */
        char given[64], want[64];
        squeeze(rest, given, sizeof given);
        squeeze(unit && !dimensionless ? unit : "", want, sizeof want);
        size_t plen = 0;
        double f = want[0] ? si_prefix(given, &plen) : 0;
        if (want[0] && strcmp(given, want) == 0)
            snprintf(buf, n, ": write the number alone, %.*s (the unit is %s)", (int)k, text, unit);
        else if (f != 0 && strcmp(given + plen, want) == 0)
            snprintf(buf, n, ": write the number alone, in %s: %s = %s %s", unit, text,
                     shortest(v * f, num), unit);
        else if (want[0] && strcmp(want, "Pas") == 0 && strcmp(given, "cP") == 0)
            snprintf(buf, n, ": write the number alone, in %s: %s = %s %s", unit, text,
                     shortest(v * 1e-3, num), unit);
        else if (want[0] && strcmp(want, "deg") == 0 && strcmp(given, "rad") == 0)
            snprintf(buf, n, ": write the number alone, in deg: %s = %s deg", text,
                     shortest(v * 57.295779513082321, num));
        else if (want[0] && strcmp(want, "deg") == 0)
            snprintf(buf, n, ": write the number alone, in degrees");
        else if (want[0])
            snprintf(buf, n, ": write the number alone, in %s (SI units throughout)", unit);
        else
            snprintf(buf, n, ": write the number alone, without a unit");
    }
    return buf;
}

int cli_parse_double(const char* text, const char* what, double* out)
{
    if (cli_number(text, out) != 0) {
        char hint[160];
        cli_error("%s: '%s' is %s%s", what, text, cli_number_problem(text),
                  cli_number_hint(text, NULL, hint, sizeof hint));
        return CLI_EXIT_USAGE;
    }
    return CLI_EXIT_OK;
}

/* Parses the count field of a range: a whole number in [1, 10^7], in decimal or exponent
 * notation ("1e7", as every number of the command line). */
static int parse_count(const char* text, const char* what, size_t* n)
{
    double v;
    if (cli_number(text, &v) != 0 || v != floor(v) || v < 1 || v > CLI_MAX_BATCH_POINTS) {
        cli_error("%s: count N = '%s' must be an integer in [1, %.0f]", what, text,
                  CLI_MAX_BATCH_POINTS);
        return CLI_EXIT_USAGE;
    }
    *n = (size_t)v;
    return CLI_EXIT_OK;
}

int cli_parse_range(const char* text, bool is_log, const char* what, struct cli_range* r)
{
    char buf[256];
    if (strlen(text) >= sizeof buf) {
        cli_error("%s: '%.40s...' is too long for A:B:N", what, text);
        return CLI_EXIT_USAGE;
    }
    strcpy(buf, text);
    char* c1 = strchr(buf, ':');
    char* c2 = c1 ? strchr(c1 + 1, ':') : NULL;
    if (!c1 || !c2 || strchr(c2 + 1, ':')) {
        cli_error("%s: '%s' is not of the form A:B:N (first:last:count)", what, text);
        return CLI_EXIT_USAGE;
    }
    *c1 = '\0';
    *c2 = '\0';
    int rc;
    if ((rc = cli_parse_double(buf, what, &r->first)) != CLI_EXIT_OK ||
        (rc = cli_parse_double(c1 + 1, what, &r->last)) != CLI_EXIT_OK ||
        (rc = parse_count(c2 + 1, what, &r->n)) != CLI_EXIT_OK)
        return rc;
    r->is_log = is_log;
    if (r->n == 1 && r->first != r->last) {
        cli_error("%s: '%s' has N = 1 but A != B; use A:A:1 for a single value", what, text);
        return CLI_EXIT_USAGE;
    }
    if (r->n > 1 && r->first == r->last) {
        cli_error("%s: '%s' gives %zu identical values (A = B); use A:A:1 for a single value", what,
                  text, r->n);
        return CLI_EXIT_USAGE;
    }
    if (is_log && !(r->first > 0 && r->last > 0)) {
        cli_error("%s: '%s' with %s needs A > 0 and B > 0", what, text,
                  strcmp(what, "--values2") == 0 ? "--log2" : "--log");
        return CLI_EXIT_USAGE;
    }
    return CLI_EXIT_OK;
}

double cli_range_value(const struct cli_range* r, size_t k)
{
    if (k == 0 || r->n < 2)
        return r->first;
    if (k + 1 >= r->n)
        return r->last;
    double s = (double)k / (double)(r->n - 1);
    if (r->is_log) /* in decades, so that 1e-7:1e-3:5 gives exactly 1e-7, 1e-6, ... */
        return pow(10.0, log10(r->first) + s * (log10(r->last) - log10(r->first)));
    return r->first + (r->last - r->first) * s;
}

int cli_setup_exit(int status)
{
    return status == WETDEM_ERR_NOMEM ? CLI_EXIT_RUNTIME : CLI_EXIT_USAGE;
}

int cli_run_exit(int status)
{
    return status == WETDEM_ERR_INVALID ? CLI_EXIT_USAGE : CLI_EXIT_RUNTIME;
}

int cli_apply_set(struct wetdem_sim* sim, const char* key_value)
{
    const char* eq = strchr(key_value, '=');
    if (!eq || eq == key_value || eq[1] == '\0') {
        cli_error("--set '%s': expected KEY=VALUE, e.g. --set fluid.viscosity=0.01", key_value);
        return CLI_EXIT_USAGE;
    }
    char key[256];
    size_t len = (size_t)(eq - key_value);
    if (len >= sizeof key) {
        cli_error("--set: key '%.40s...' is too long", key_value);
        return CLI_EXIT_USAGE;
    }
    memcpy(key, key_value, len);
    key[len] = '\0';
    if (wetdem_sim_set_param_str(sim, key, eq + 1) != WETDEM_OK) {
        cli_error("--set %s: %s", key_value, wetdem_sim_errmsg(sim));
        return CLI_EXIT_USAGE;
    }
    return CLI_EXIT_OK;
}

/* The provenance lines "wetdem VERSION (git HASH)" and "command: wetdem ARGS", each begun with
 * `mark`, the first ended by a newline (the last's end is the caller's): the one text of
 * cli_print_provenance and cli_provenance_text. A line break within an argument (a file name
 * may hold one) continues the command on a line begun with `mark` again, so that it cannot end
 * the comment and pass for the header or a row. */
static void write_provenance(FILE* f, const char* mark, int argc, char** argv)
{
    fprintf(f, "%swetdem %s (git %s)\n%scommand: wetdem", mark, WETDEM_VERSION, WETDEM_GIT_HASH,
            mark);
    for (int k = 0; k < argc; k++) {
        fputc(' ', f);
        for (const char* c = argv[k]; *c; c++)
            if (*c == '\n' || *c == '\r')
                fprintf(f, "\n%s", mark);
            else
                fputc(*c, f);
    }
}

void cli_print_provenance(FILE* f, int argc, char** argv)
{
    write_provenance(f, "# ", argc, argv); /* (written as it goes: printing allocates nothing) */
    fputc('\n', f);
}

char* cli_provenance_text(int argc, char** argv)
{
    char* text = NULL;
    size_t len = 0;
    FILE* f = open_memstream(&text, &len);
    if (!f)
        return NULL;
    write_provenance(f, "", argc, argv);
    bool ok = !ferror(f);
    if (fclose(f) == 0 && ok)
        return text;
    free(text);
    return NULL;
}

/* Creates dir and its parents (mkdir -p). */
int cli_make_dirs(const char* dir)
{
    char path[1024];
    if (snprintf(path, sizeof path, "%s", dir) >= (int)sizeof path) {
        errno = ENAMETOOLONG;
        return -1;
    }
    for (char* p = path + 1; *p; p++)
        if (*p == '/') {
            *p = '\0';
            if (mkdir(path, 0777) != 0 && errno != EEXIST)
                return -1;
            *p = '/';
        }
    return (mkdir(path, 0777) == 0 || errno == EEXIST) ? 0 : -1;
}

/* The parent directory of path (empty when it has none). */
void cli_parent_dir(const char* path, char* dir, size_t n)
{
    snprintf(dir, n, "%s", path);
    char* slash = strrchr(dir, '/');
    if (slash)
        slash[slash == dir] = '\0'; /* ("/x": "/") */
    else
        dir[0] = '\0';
}

int cli_check_output_path(const char* what, const char* option, const char* path, bool is_dir)
{
    struct stat st;
    if (!path)
        return CLI_EXIT_OK;
    if (!path[0]) {
        cli_error("%s: %s needs a %s name", what, option, is_dir ? "directory" : "file");
        return CLI_EXIT_USAGE;
    }
    if (stat(path, &st) == 0 && !S_ISDIR(st.st_mode) != !is_dir) {
        if (is_dir)
            cli_error("%s: %s %s exists and is not a directory", what, option, path);
        else
            cli_error("%s: %s %s is a directory; give a file name in it, e.g. %s/%s.csv", what,
                      option, path, path, what);
        return CLI_EXIT_USAGE;
    }
    /* the directories on the way are made when the file is written: none may be a file */
    char prefix[1024];
    snprintf(prefix, sizeof prefix, "%s", path);
    for (char* slash = strchr(prefix + 1, '/'); slash; slash = strchr(slash + 1, '/')) {
        *slash = '\0';
        bool not_dir = stat(prefix, &st) == 0 && !S_ISDIR(st.st_mode);
        *slash = '/';
        if (not_dir) {
            *slash = '\0';
            cli_error("%s: %s %s: %s is not a directory", what, option, path, prefix);
            return CLI_EXIT_USAGE;
        }
    }
    return CLI_EXIT_OK;
}

/* Whether paths a and b, of which one at least does not exist (yet), name one file: the same
 * name in the same directory (its real path; as written when it does not exist either: then
 * the same text), so that "./x.csv" and "x.csv" are one. */
static bool same_new_file(const char* a, const char* b)
{
    if (strcmp(a, b) == 0)
        return true;
    const char* base_a = strrchr(a, '/') ? strrchr(a, '/') + 1 : a;
    const char* base_b = strrchr(b, '/') ? strrchr(b, '/') + 1 : b;
    if (strcmp(base_a, base_b) != 0 || !base_a[0])
        return false;
    char dir_a[1024], dir_b[1024];
    cli_parent_dir(a, dir_a, sizeof dir_a);
    cli_parent_dir(b, dir_b, sizeof dir_b);
    char* real_a = realpath(dir_a[0] ? dir_a : ".", NULL);
    char* real_b = realpath(dir_b[0] ? dir_b : ".", NULL);
    bool same = real_a && real_b && strcmp(real_a, real_b) == 0;
    free(real_a);
    free(real_b);
    return same;
}

int cli_check_not_input(const char* what, const char* option, const char* out,
                        const char* const* in, const char* const* in_names, int n)
{
    struct stat so, si;
    bool out_exists = out && stat(out, &so) == 0;
    for (int k = 0; out && k < n; k++) {
        if (!in[k])
            continue;
        bool same = out_exists && stat(in[k], &si) == 0
                        ? so.st_dev == si.st_dev && so.st_ino == si.st_ino && S_ISREG(so.st_mode)
                        : same_new_file(out, in[k]);
        if (same) {
            cli_error("%s: %s %s is also %s: the command would write over it; give another "
                      "name",
                      what, option, out, in_names[k]);
            return CLI_EXIT_USAGE;
        }
    }
    return CLI_EXIT_OK;
}

/* The standard stream (stdout or stderr) whose open file `path` names, or NULL: /dev/stdout,
 * /dev/fd/1 or any other name of that file. Such output goes through the stream itself, after
 * what the command printed there and before what it prints next: when standard output is a
 * regular file (`> FILE`), /dev/stdout names that file, and writing it under a temporary name
 * renamed over it would unlink the file the stream still writes to, losing the rest of the
 * output (the summary that fit and track print after their files). */
static FILE* output_std_stream(const char* path)
{
    struct stat sp, sf;
    if (stat(path, &sp) != 0)
        return NULL;
    const int fds[2] = {STDOUT_FILENO, STDERR_FILENO};
    FILE* const streams[2] = {stdout, stderr};
    for (int k = 0; k < 2; k++)
        if (fstat(fds[k], &sf) == 0 && sf.st_dev == sp.st_dev && sf.st_ino == sp.st_ino)
            return streams[k];
    return NULL;
}

/* snprintf into buf of what fits: false when it was cut (the name is then not used). */
bool cli_format_path(char* buf, size_t size, const char* fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(buf, size, fmt, ap);
    va_end(ap);
    return n >= 0 && (size_t)n < size;
}

/* Where output to `path` goes: *direct when path names a standard stream's file (above) or
 * exists and is not a regular file (a device such as /dev/null, a FIFO, a process
 * substitution), which is written in place, never replaced; otherwise the regular file that
 * path names, with a symbolic link followed to its target (so the link stays a link), written
 * under a temporary name next to it and renamed over it when whole. false when the name does
 * not fit in final (n characters). */
static bool output_target(const char* path, char* final, size_t n, bool* direct)
{
    struct stat st;
    *direct = false;
    if (!cli_format_path(final, n, "%s", path))
        return false;
    if (lstat(path, &st) != 0)
        return true; /* a new file */
    if (output_std_stream(path)) {
        *direct = true;
        return true;
    }
    if (S_ISLNK(st.st_mode)) {
        char* target = realpath(path, NULL);
        bool fits = true;
        if (target && stat(target, &st) == 0 && S_ISREG(st.st_mode))
            fits = cli_format_path(final, n, "%s", target);
        else
            *direct = true; /* (a link to a device, or a dangling one: written through) */
        free(target);
        return fits;
    }
    *direct = !S_ISREG(st.st_mode);
    return true;
}

/* 0 when a file can be written at path, whose directory exists: the temporary file that output
 * to it writes is created, then removed (a device or a FIFO, written in place, is asked with
 * access(): opening it could block); else the errno of the failure. */
static int probe_writable(const char* path)
{
    char final[1400], dir[1400], tmp[2900];
    bool direct;
    if (!output_target(path, final, sizeof final, &direct))
        return ENAMETOOLONG;
    if (direct) /* (a directory in a file's place fails at its rename: the set is not kept) */
        return access(final, W_OK) == 0 ? 0 : errno;
    cli_parent_dir(final, dir, sizeof dir);
    snprintf(tmp, sizeof tmp, "%s/%s.tmp%ld", dir[0] ? dir : ".",
             strrchr(final, '/') ? strrchr(final, '/') + 1 : final,
             (long)getpid()); /* (the name written later) */
    FILE* f = fopen(tmp, "w");
    if (!f)
        return errno;
    fclose(f);
    remove(tmp);
    return 0;
}

int cli_check_writable(const char* what, const char* option, const char* path)
{
    if (!path)
        return CLI_EXIT_OK;
    char dir[1400];
    cli_parent_dir(path, dir, sizeof dir);
    if (dir[0] && cli_make_dirs(dir) != 0) {
        cli_error("%s: %s %s: cannot create directory %s: %s", what, option, path, dir,
                  strerror(errno));
        return CLI_EXIT_USAGE;
    }
    int err = probe_writable(path);
    if (err) {
        cli_error("%s: %s %s cannot be written: %s", what, option, path, strerror(err));
        return CLI_EXIT_USAGE;
    }
    return CLI_EXIT_OK;
}

int cli_check_out_dir(const char* what, const char* dir, const char* const* names, size_t n)
{
    if (!dir)
        return CLI_EXIT_OK;
    if (cli_make_dirs(dir) != 0) {
        cli_error("%s: --out %s: cannot create the directory: %s", what, dir, strerror(errno));
        return CLI_EXIT_USAGE;
    }
    for (size_t k = 0; k < n; k++) {
        char path[2048];
        if (!names[k] || !names[k][0])
            continue;
        int err = cli_format_path(path, sizeof path, "%s/%s", dir, names[k]) ? probe_writable(path)
                                                                             : ENAMETOOLONG;
        if (err) {
            cli_error("%s: --out %s: %s cannot be written there: %s", what, dir, names[k],
                      strerror(err));
            return CLI_EXIT_USAGE;
        }
    }
    return CLI_EXIT_OK;
}

/* Opens the file that output to `path` writes: in place (o->direct) or under the temporary
 * name of its target (o->tmp), after putting in order what killed processes left there
 * (cli_journal_recover). 0, or -1 with errno set. */
static int open_output(struct cli_out_file* o, const char* path, const char* tmp_format)
{
    o->f = NULL;
    if (!output_target(path, o->final, sizeof o->final, &o->direct)) {
        o->final[0] = o->tmp[0] = '\0';
        errno = ENAMETOOLONG; /* (a name cut short would be another file) */
        return -1;
    }
    o->std = o->direct ? output_std_stream(o->final) : NULL;
    if (o->direct) {
        cli_format_path(o->tmp, sizeof o->tmp, "%s", o->final);
        o->f = o->std ? o->std : fopen(o->final, "w");
    } else {
        /* the temporary name: tmp_format applied to the target's directory and base name */
        char dir[1400];
        cli_parent_dir(o->final, dir, sizeof dir);
        const char* base = strrchr(o->final, '/');
        base = base ? base + 1 : o->final;
        if (!cli_format_path(o->tmp, sizeof o->tmp, tmp_format, dir[0] ? dir : ".", base,
                             (long)getpid())) {
            o->tmp[0] = '\0'; /* (one cut short would not hold this process's whole PID) */
            errno = ENAMETOOLONG;
            return -1;
        }
        cli_journal_recover(o->final);
        o->f = fopen(o->tmp, "w");
    }
    return o->f ? 0 : -1;
}

/* Closes o's stream: 0 when every write reached the file, otherwise the errno of the failure
 * (EIO when none is known; a failed write's errno may be long gone, flushing the rest fails
 * again with the reason). */
static int close_stream(struct cli_out_file* o)
{
    if (!o->f)
        return 0;
    bool bad = ferror(o->f) != 0;
    errno = 0;
    int err = (o->std ? fflush(o->f) : fclose(o->f)) != 0 ? (errno ? errno : EIO) : 0;
    o->f = NULL;
    return err ? err : bad ? EIO : 0;
}

int cli_write_outputs(const struct cli_output* outs, size_t n, const char* what)
{
    struct cli_out_file files[CLI_MAX_OUTPUTS];
    struct cli_out_file* set[CLI_MAX_OUTPUTS];
    size_t open = 0;
    int rc = CLI_EXIT_OK;
    for (size_t k = 0; k < n && k < CLI_MAX_OUTPUTS && rc == CLI_EXIT_OK; k++) {
        if (!outs[k].path)
            continue;
        char dir[1024];
        cli_parent_dir(outs[k].path, dir, sizeof dir);
        if (dir[0] && cli_make_dirs(dir) != 0) {
            cli_error("%s: cannot create directory %s for %s: %s", what, dir, outs[k].path,
                      strerror(errno));
            rc = CLI_EXIT_RUNTIME;
        } else if (open_output(&files[open], outs[k].path, "%s/%s.tmp%ld") != 0) {
            cli_error("%s: cannot write %s: %s", what, outs[k].path, strerror(errno));
            rc = CLI_EXIT_RUNTIME;
        } else {
            outs[k].write(files[open].f, outs[k].ctx);
            set[open] = &files[open];
            open++;
        }
    }
    if (cli_out_close_all(set, open, what, rc == CLI_EXIT_OK) != 0)
        rc = CLI_EXIT_RUNTIME;
    return rc;
}

int cli_write_output(const char* path, const char* what, void (*write)(FILE* f, const void* ctx),
                     const void* ctx)
{
    if (!path) {
        write(stdout, ctx); /* a failed write is reported at the exit (main's finish_stdout) */
        return CLI_EXIT_OK;
    }
    const struct cli_output out = {path, write, ctx};
    return cli_write_outputs(&out, 1, what);
}

int cli_out_open(struct cli_out_file* o, const char* what, const char* dir, const char* name)
{
    o->f = NULL;
    o->std = NULL;
    o->final[0] = o->tmp[0] = '\0';
    o->direct = false;
    if (!dir || !name[0])
        return 0;
    char path[1400];
    bool fits = cli_format_path(path, sizeof path, "%s/%s", dir, name);
    if (!fits)
        errno = ENAMETOOLONG;
    if (!fits || open_output(o, path, "%s/.%s.tmp%ld") != 0) {
        cli_error("%s: cannot write %s: %s", what, path, strerror(errno));
        return -1;
    }
    return 0;
}

int cli_out_close(struct cli_out_file* o, const char* what, bool keep)
{
    struct cli_out_file* files[1] = {o};
    return cli_out_close_all(files, 1, what, keep);
}

/* The name an existing target is kept under while its set is replaced: its temporary name
 * with ".old" appended. */
static void backup_name(const struct cli_out_file* o, char* buf, size_t size)
{
    cli_format_path(buf, size, "%s.old", o->tmp);
}

/* Puts the set's targets back as they were before the first k renames of replace_set: the
 * new files removed, the old ones (had[j]) renamed back. */
static void restore_set(struct cli_out_file* const* files, size_t k, const bool* had,
                        const bool* placed)
{
    char old[1500];
    for (size_t j = 0; j < k; j++) {
        if (placed[j])
            remove(files[j]->final);
        backup_name(files[j], old, sizeof old);
        if (had[j])
            rename(old, files[j]->final);
    }
}

/* Replaces the targets of the n written files as one set: every existing target is first
 * moved aside (to its backup name), then every temporary file renamed into place, then the
 * backups removed. When any rename fails, the renames already made are undone, so the set is
 * replaced whole or not at all (a renaming the directory refuses, e.g. a sticky directory's
 * file of another user, fails in the first pass). A set of two or more files is recorded in
 * journals first, so that what a process killed between the passes leaves (the targets under
 * their backup names, .NAME.tmpPID.old) is completed by the next process that writes one of
 * them (cli_journal_recover). 0, or the index of the file that failed + 1 with *err its errno. */
static size_t replace_set(struct cli_out_file* const* files, size_t n, int* err)
{
    bool had[CLI_MAX_OUTPUTS] = {false}, placed[CLI_MAX_OUTPUTS] = {false};
    bool renamed[CLI_MAX_OUTPUTS] = {false};
    char old[1500], dirs[CLI_MAX_OUTPUTS][CLI_SET_PATH];
    size_t n_renamed = 0, n_dirs = 0;
    n = n < CLI_MAX_OUTPUTS ? n : CLI_MAX_OUTPUTS;
    for (size_t k = 0; k < n; k++) {
        renamed[k] = files[k]->tmp[0] && !files[k]->direct;
        n_renamed += renamed[k];
    }
    if (n_renamed > 1 && cli_journal_write(files, n, renamed, dirs, &n_dirs) != 0) {
        *err = errno ? errno : EIO;
        return 1;
    }
    for (size_t k = 0; k < n; k++) {
        const struct cli_out_file* o = files[k];
        struct stat st;
        if (!renamed[k] || lstat(o->final, &st) != 0)
            continue;
        backup_name(o, old, sizeof old);
        if (S_ISDIR(st.st_mode) || rename(o->final, old) != 0) {
            *err = S_ISDIR(st.st_mode) ? EISDIR : errno;
            restore_set(files, k, had, placed);
            cli_journal_remove(dirs, n_dirs);
            return k + 1;
        }
        had[k] = true;
    }
    size_t done = 0;
    if (n_dirs)
        cli_journal_test_kill(done);
    for (size_t k = 0; k < n; k++) {
        const struct cli_out_file* o = files[k];
        if (!renamed[k])
            continue;
        if (rename(o->tmp, o->final) != 0) {
            *err = errno;
            restore_set(files, n, had, placed);
            cli_journal_remove(dirs, n_dirs);
            return k + 1;
        }
        placed[k] = true;
        if (n_dirs)
            cli_journal_test_kill(++done);
    }
    for (size_t k = 0; k < n; k++)
        if (had[k]) {
            backup_name(files[k], old, sizeof old);
            remove(old);
        }
    cli_journal_remove(dirs, n_dirs);
    return 0;
}

int cli_out_close_all(struct cli_out_file* const* files, size_t n, const char* what, bool keep)
{
    int failed = -1, err = 0; /* the first file that could not be written whole, and why */
    for (size_t k = 0; k < n; k++) {
        bool was_open = files[k]->f != NULL;
        int e = close_stream(files[k]);
        if (was_open && e && failed < 0) {
            failed = (int)k;
            err = e;
        }
    }
    if (keep && failed < 0) {
        size_t bad = replace_set(files, n, &err);
        failed = bad ? (int)bad - 1 : -1;
    }
    for (size_t k = 0; k < n; k++) {
        struct cli_out_file* o = files[k];
        /* (not wanted, or written in place, which cannot be taken back; kept ones are gone) */
        if (o->tmp[0] && !o->direct)
            remove(o->tmp);
        o->tmp[0] = '\0';
    }
    if (failed < 0)
        return 0;
    cli_error("%s: cannot write %s: %s", what, files[failed]->final, strerror(err));
    return -1;
}

const char* cli_article(const char* word)
{
    return word[0] && strchr("aeiouAEIOU", word[0]) ? "an" : "a";
}

double cli_plain_zero(double v)
{
    return v == 0.0 ? 0.0 : v; /* (-0 == 0: both zeros give +0) */
}

void cli_print_double(FILE* f, double v)
{
    char buf[40];
    wetdem_param_format_value(cli_plain_zero(v), 15, buf, sizeof buf);
    fputs(buf, f);
}

bool cli_wants_help(int argc, char** argv)
{
    for (int k = 1; k < argc; k++)
        if (strcmp(argv[k], "--help") == 0 || strcmp(argv[k], "-h") == 0)
            return true;
    return false;
}

int cli_csv_split(char* line, char** f, int max)
{
    int n = 0;
    for (char* p = line; p && n < max; n++) {
        char* comma = strchr(p, ',');
        if (comma)
            *comma = '\0';
        while (*p == ' ' || *p == '\t')
            p++;
        char* end = p + strcspn(p, "\r\n");
        while (end > p && (end[-1] == ' ' || end[-1] == '\t'))
            end--;
        *end = '\0';
        f[n] = p;
        p = comma ? comma + 1 : NULL;
    }
    return n;
}

/* Cuts a header field "name [unit]" in place into its name (blanks trimmed) and *unit (the
 * text between the brackets, blanks trimmed; NULL without brackets). Returns false when the
 * brackets are not one pair ending the field. */
static bool split_unit(char* field, const char** unit)
{
    *unit = NULL;
    char* open = strchr(field, '[');
    if (!open)
        return !strchr(field, ']');
    char* close = strchr(open, ']');
    if (!close || close[1] != '\0' || strchr(open + 1, '[') || strchr(close + 1, ']'))
        return false;
    *close = '\0';
    char* u = open + 1;
    while (*u == ' ' || *u == '\t')
        u++;
    for (char* e = close; e > u && (e[-1] == ' ' || e[-1] == '\t');)
        *--e = '\0';
    *unit = u;
    for (char* e = open; e > field && (e[-1] == ' ' || e[-1] == '\t');)
        *--e = '\0';
    *open = '\0';
    return true;
}

/* Whether a header's unit label is the column's SI unit (a dimensionless one, "-", also "1"
 * or nothing). */
static bool unit_matches(const char* given, const char* unit)
{
    if (strcmp(unit, "-") == 0)
        return !given[0] || strcmp(given, "-") == 0 || strcmp(given, "1") == 0;
    return strcmp(given, unit) == 0;
}

int cli_csv_columns(char** f, int n, const char* const* names, const char* const* units, int* col,
                    int* bad, char* err, size_t err_len)
{
    int n_names = 0;
    while (names[n_names])
        col[n_names++] = -1;
    for (int k = 0; k < n; k++) {
        *bad = k;
        char given[256];
        snprintf(given, sizeof given, "%s", f[k]);
        const char* unit;
        if (!split_unit(f[k], &unit)) {
            snprintf(err, err_len, "column '%s': a unit is written as 'name [unit]'", given);
            return CLI_CSV_UNKNOWN;
        }
        int c = 0;
        while (c < n_names && strcmp(f[k], names[c]) != 0)
            c++;
        if (c < n_names && col[c] >= 0) {
            snprintf(err, err_len, "column %s appears twice (columns %d and %d)", f[k], col[c] + 1,
                     k + 1);
            return CLI_CSV_TWICE;
        }
        if (c < n_names && unit && !unit_matches(unit, units[c])) {
            snprintf(err, err_len,
                     "column '%s': %s is read in %s, not %s (values are read as they stand, "
                     "in SI units: convert them, or label the column [%s])",
                     given, names[c], units[c], unit[0] ? unit : "[]", units[c]);
            return CLI_CSV_UNKNOWN;
        }
        if (c < n_names) {
            col[c] = k;
            continue;
        }
        const char* hint = f[k][0] ? wetdem_param_suggest(f[k], names) : NULL;
        for (int m = 0; !hint && f[k][0] && m < n_names; m++) /* the unit left out: angle */
            if (strncmp(names[m], f[k], strlen(f[k])) == 0)
                hint = names[m];
        snprintf(err, err_len, "unknown column '%s'%s%s%s", f[k], hint ? " (did you mean '" : "",
                 hint ? hint : "", hint ? "'?)" : "");
        return CLI_CSV_UNKNOWN;
    }
    return 0;
}

bool cli_is_frame_name(const char* prefix, const char* name)
{
    size_t lp = strlen(prefix), n = strlen(name);
    if (n < lp + 1 + 6 + 4 || strncmp(name, prefix, lp) != 0 || name[lp] != '_' ||
        strcmp(name + n - 4, ".vtk") != 0)
        return false;
    for (size_t k = lp + 1; k < n - 4; k++)
        if (!isdigit((unsigned char)name[k]))
            return false;
    return true;
}

bool cli_needs_value(const char* cmd, const char* arg, const char* const* what)
{
    for (size_t k = 0; what[k]; k += 2)
        if (strcmp(arg, what[k]) == 0) {
            if (what[k + 1])
                cli_error("%s: %s needs a value (%s)", cmd, arg, what[k + 1]);
            else
                cli_error("%s: %s needs a value", cmd, arg);
            return true;
        }
    return false;
}

bool cli_name_in(const char* arg, const char* const* names)
{
    for (size_t k = 0; names[k]; k++)
        if (strcmp(arg, names[k]) == 0)
            return true;
    return false;
}

const char* cli_option_hint(const char* arg, const char* const* options, char* buf, size_t n)
{
    const char* hint = arg[0] == '-' ? wetdem_param_suggest(arg, options) : NULL;
    if (hint && strcmp(hint, arg) == 0) /* (cli_needs_value said what its value is) */
        hint = NULL;
    snprintf(buf, n, "%s%s%s", hint ? " (did you mean '" : "", hint ? hint : "", hint ? "'?)" : "");
    return buf;
}

int cli_option_once(const char* cmd, const char* arg, const char* const* once, unsigned* seen)
{
    for (unsigned k = 0; once[k] && k < 32; k++) {
        if (strcmp(arg, once[k]) != 0)
            continue;
        if (*seen & (1u << k)) {
            cli_error("%s: %s is given twice: give it once (the second value would replace the "
                      "first)",
                      cmd, arg);
            return CLI_EXIT_USAGE;
        }
        *seen |= 1u << k;
    }
    return CLI_EXIT_OK;
}

void cli_param_default_text(const struct wetdem_param_desc* d, char* buf, size_t n)
{
    if (d->choices) {
        size_t idx = (size_t)d->default_value;
        size_t count = 0;
        while (d->choices[count])
            count++;
        snprintf(buf, n, "%s", idx < count ? d->choices[idx] : "?");
        return;
    }
    snprintf(buf, n, "%g", d->default_value);
}

/* ---- progress of a long run ---- */

void cli_progress_start(struct cli_progress* p, double done)
{
    *p = (struct cli_progress){
        .tty = isatty(STDERR_FILENO) == 1, .start = omp_get_wtime(), .done0 = done};
}

void cli_progress_show(struct cli_progress* p, double done, const char* fmt, ...)
{
    if (!p->tty || cli_stop_signal) /* (stopping: the signal's notice stays the last line) */
        return;
    double elapsed = omp_get_wtime() - p->start;
    bool last = done >= 1;
    if (!(elapsed - p->last >= CLI_PROGRESS_EVERY || last) || !(done > p->done0))
        return;
    p->last = elapsed;
    char what[200];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(what, sizeof what, fmt, ap);
    va_end(ap);
    double left = ceil(elapsed * (1 - fmin(done, 1)) / (done - p->done0));
    cli_progress_shown = 1; /* (before the line: a signal's notice then erases it) */
    int n = fprintf(stderr, "\rwetdem: %s (%5.1f %%), %.0f s elapsed, about %.*g s left   ", what,
                    100 * done, elapsed, left < 1e6 ? 6 : 2, left);
    p->shown = n > 1 ? n - 1 : 0; /* (less the carriage return) */
    if (last)
        cli_progress_clear(p);
    fflush(stderr);
}

void cli_progress_clear(struct cli_progress* p)
{
    if (p->shown)
        fprintf(stderr, "\r%*s\r", p->shown, "");
    p->shown = 0;
    cli_progress_shown = 0;
    fflush(stderr);
}

int cli_progress_time(double t, double t_end, double elapsed, void* ctx)
{
    (void)elapsed; /* (the line's own clock started with the command's run) */
    cli_progress_show(ctx, t / t_end, "t = %.4g of %.4g s", t, t_end);
    return 0;
}

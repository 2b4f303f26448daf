/*
 * cli_util.c — helpers shared by the CLI subcommands (see cli_util.h): messages, strict
 * parsing of numbers and "A:B:N" ranges, "--set KEY=VALUE", CSV provenance lines, tables
 * and --out files written whole (temporary file, then rename) or not at all.
 *
 * Range values: linear x_k = A + (B - A) k/(N - 1); geometric x_k = A (B/A)^(k/(N - 1)),
 * computed as 10^(log10 A + (log10 B - log10 A) k/(N - 1)) so that decades come out as the
 * round numbers they are; k = 0..N-1, with x_0 = A and x_{N-1} = B returned exactly.
 */
#include <ctype.h>
#include <dirent.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <signal.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli_util.h"

void cli_error(const char* fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    fputs("wetdem: ", stderr);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
}

int cli_number(const char* text, double* out)
{
    /* [+-] digits [. digits] [(e|E) [+-] digits], with at least one digit before the exponent */
    const char* p = text;
    size_t mantissa = 0;
    p += *p == '+' || *p == '-';
    for (; isdigit((unsigned char)*p); p++)
        mantissa++;
    if (*p == '.')
        for (p++; isdigit((unsigned char)*p); p++)
            mantissa++;
    if (mantissa && (*p == 'e' || *p == 'E')) {
        p++;
        p += *p == '+' || *p == '-';
        if (!isdigit((unsigned char)*p))
            return -1;
        while (isdigit((unsigned char)*p))
            p++;
    }
    if (!mantissa || *p != '\0')
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

int cli_parse_double(const char* text, const char* what, double* out)
{
    if (cli_number(text, out) != 0) {
        cli_error("%s: '%s' is %s", what, text, cli_number_problem(text));
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

void cli_print_provenance(FILE* f, int argc, char** argv)
{
    fprintf(f, "# wetdem %s (git %s)\n# command: wetdem", WETDEM_VERSION, WETDEM_GIT_HASH);
    for (int k = 0; k < argc; k++)
        fprintf(f, " %s", argv[k]);
    fputc('\n', f);
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
static void parent_dir(const char* path, char* dir, size_t n)
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
                        : strcmp(out, in[k]) == 0;
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
static bool format_path(char* buf, size_t size, const char* fmt, ...)
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
    if (!format_path(final, n, "%s", path))
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
            fits = format_path(final, n, "%s", target);
        else
            *direct = true; /* (a link to a device, or a dangling one: written through) */
        free(target);
        return fits;
    }
    *direct = !S_ISREG(st.st_mode);
    return true;
}

int cli_check_writable(const char* what, const char* option, const char* path)
{
    if (!path)
        return CLI_EXIT_OK;
    char dir[1400], tmp[2900];
    parent_dir(path, dir, sizeof dir);
    if (dir[0] && cli_make_dirs(dir) != 0) {
        cli_error("%s: %s %s: cannot create directory %s: %s", what, option, path, dir,
                  strerror(errno));
        return CLI_EXIT_USAGE;
    }
    char final[1400];
    bool direct;
    output_target(path, final, sizeof final, &direct);
    if (direct) { /* written in place (a device, a FIFO: not opened here, it could block) */
        if (access(final, W_OK) == 0)
            return CLI_EXIT_OK;
        cli_error("%s: %s %s cannot be written: %s", what, option, path, strerror(errno));
        return CLI_EXIT_USAGE;
    }
    parent_dir(final, dir, sizeof dir);
    snprintf(tmp, sizeof tmp, "%s/%s.tmp%ld", dir[0] ? dir : ".",
             strrchr(final, '/') ? strrchr(final, '/') + 1 : final,
             (long)getpid()); /* (the name written later) */
    FILE* f = fopen(tmp, "w");
    if (!f) {
        cli_error("%s: %s %s cannot be written: %s", what, option, path, strerror(errno));
        return CLI_EXIT_USAGE;
    }
    fclose(f);
    remove(tmp);
    return CLI_EXIT_OK;
}

/* ---- sets of files: the journal, and what a killed process left behind ----
 *
 * A set of files is replaced in three passes (replace_set): the targets moved aside to their
 * backup names (TMP.old), the temporary files renamed to the targets, the backups removed.
 * Before the first pass, a journal DIR/.wetdem-set.PID is written in every directory of the
 * set (temporary name, then rename: each appears whole or not at all), listing the set's
 * directories and each file's temporary and final name; the set counts as committed once
 * every one of its journals exists, and they are removed when the passes are done. A process
 * killed at any point (SIGKILL, a power cut) leaves files whose names hold its PID; the next
 * process that writes one of the targets (open_output) finds them when that PID is no longer
 * alive and puts them in order, saying so on stderr: a committed set is completed (every
 * temporary file still there renamed to its target, the backups removed), one not committed
 * is taken back (its temporary files removed, any target moved aside put back), and a
 * temporary or backup file of the target outside any journal (a process killed while writing,
 * or a version without journals) is removed, a backup put back first when its target is
 * missing. So the directory holds either the earlier set or the new one, whole. */

#define JOURNAL_PREFIX ".wetdem-set."
#define SET_PATH (PATH_MAX + 256)    /* a directory or file of a set, absolute */
#define JOURNAL_PATH (SET_PATH + 40) /* a journal's path */

/* Appends `path` to buf at *len with a backslash, tab and newline written as two characters
 * each (backslash then itself, 't' or 'n'), so
 * that any name keeps to its field of the journal's tab-separated line. false when full. */
static bool journal_escape(char* buf, size_t size, size_t* len, const char* path)
{
    for (const char* p = path; *p; p++) {
        const char* e = *p == '\\' ? "\\\\" : *p == '\t' ? "\\t" : *p == '\n' ? "\\n" : NULL;
        size_t n = e ? 2 : 1;
        if (*len + n >= size)
            return false;
        memcpy(buf + *len, e ? e : p, n);
        *len += n;
    }
    buf[*len] = '\0';
    return true;
}

/* Appends text to buf at *len. false when full. */
static bool journal_put(char* buf, size_t size, size_t* len, const char* text)
{
    size_t n = strlen(text);
    if (*len + n >= size)
        return false;
    memcpy(buf + *len, text, n + 1);
    *len += n;
    return true;
}

/* Decodes a field of a journal line (journal_escape) into out. false when it does not fit or
 * holds an escape the journal does not write. */
static bool journal_unescape(const char* field, char* out, size_t size)
{
    size_t n = 0;
    for (const char* p = field; *p; p++) {
        char c = *p;
        if (c == '\\') {
            p++;
            c = *p == '\\' ? '\\' : *p == 't' ? '\t' : *p == 'n' ? '\n' : '\0';
            if (!c)
                return false;
        }
        if (n + 1 >= size)
            return false;
        out[n++] = c;
    }
    out[n] = '\0';
    return n > 0;
}

/* Whether process pid is alive (or its liveness cannot be known: then it is left alone). */
static bool pid_alive(long pid)
{
    if (pid <= 0 || pid > INT_MAX || pid == (long)getpid())
        return true;
    return kill((pid_t)pid, 0) == 0 || errno != ESRCH;
}

static bool path_exists(const char* path)
{
    struct stat st;
    return lstat(path, &st) == 0;
}

/* The PID in `name` after `prefix` when the rest is digits and then `suffix` exactly, or -1. */
static long name_pid(const char* name, const char* prefix, const char* suffix)
{
    size_t n = strlen(prefix);
    if (strncmp(name, prefix, n) != 0 || !isdigit((unsigned char)name[n]))
        return -1;
    char* end;
    long pid = strtol(name + n, &end, 10);
    return strcmp(end, suffix) == 0 ? pid : -1;
}

/* The sets of a journal (recover_journal). */
struct journal {
    char dirs[CLI_MAX_OUTPUTS][SET_PATH], tmp[CLI_MAX_OUTPUTS][SET_PATH],
        final[CLI_MAX_OUTPUTS][SET_PATH];
    size_t n_dirs, n;
    bool whole;
};

/* Whether entry k of journal j (process pid) names what a set of wetdem's files holds: a
 * temporary file of its target, BASE.tmpPID or .BASE.tmpPID, beside it in one of the set's
 * directories. Anything else (a corrupt journal, or one that is not wetdem's) names files
 * that are not its to move. */
static bool journal_entry_valid(const struct journal* j, size_t k, long pid)
{
    char dir_tmp[SET_PATH], dir_final[SET_PATH], visible[SET_PATH], hidden[SET_PATH];
    parent_dir(j->tmp[k], dir_tmp, sizeof dir_tmp);
    parent_dir(j->final[k], dir_final, sizeof dir_final);
    if (j->tmp[k][0] != '/' || strcmp(dir_tmp, dir_final) != 0)
        return false;
    bool listed = false;
    for (size_t d = 0; d < j->n_dirs; d++)
        listed = listed || strcmp(j->dirs[d], dir_tmp) == 0;
    const char* base = strrchr(j->final[k], '/') + 1;
    const char* tmp_base = strrchr(j->tmp[k], '/') + 1;
    return listed && base[0] && format_path(visible, sizeof visible, "%s.tmp%ld", base, pid) &&
           format_path(hidden, sizeof hidden, ".%s.tmp%ld", base, pid) &&
           (strcmp(tmp_base, visible) == 0 || strcmp(tmp_base, hidden) == 0);
}

/* Reads the journal at `path` of process pid into j: false when it is not this user's, cannot
 * be read, or holds a line or an entry that a journal of wetdem does not (it is then left, and
 * its files with it). */
static bool read_journal(const char* path, long pid, struct journal* j)
{
    FILE* f = fopen(path, "r");
    if (!f)
        return false;
    struct stat st;
    bool ok = fstat(fileno(f), &st) == 0 && S_ISREG(st.st_mode) && st.st_uid == geteuid();
    char* line = NULL;
    size_t cap = 0;
    ssize_t len;
    j->n_dirs = j->n = 0;
    j->whole = false;
    for (bool first = true; ok && (len = getline(&line, &cap, f)) > 0; first = false) {
        if (line[len - 1] != '\n' || j->whole) {
            ok = false; /* (a line cut short, or one after "end") */
            break;
        }
        line[len - 1] = '\0';
        char* tab = strchr(line, '\t');
        if (first)
            ok = strcmp(line, "wetdem output set") == 0;
        else if (strncmp(line, "dir\t", 4) == 0 && j->n_dirs < CLI_MAX_OUTPUTS)
            ok = journal_unescape(line + 4, j->dirs[j->n_dirs++], SET_PATH) &&
                 strchr(line + 4, '\t') == NULL;
        else if (strncmp(line, "file\t", 5) == 0 && j->n < CLI_MAX_OUTPUTS &&
                 (tab = strchr(line + 5, '\t')) != NULL && strchr(tab + 1, '\t') == NULL) {
            *tab = '\0';
            ok = journal_unescape(line + 5, j->tmp[j->n], SET_PATH) &&
                 journal_unescape(tab + 1, j->final[j->n], SET_PATH);
            j->n++;
        } else if (strcmp(line, "end") == 0)
            j->whole = true;
        else
            ok = false;
    }
    free(line);
    ok = ok && !ferror(f);
    fclose(f);
    for (size_t k = 0; ok && k < j->n; k++)
        ok = journal_entry_valid(j, k, pid);
    /* the journal lies in one of the set's directories */
    char dir[SET_PATH], real[PATH_MAX];
    parent_dir(path, dir, sizeof dir);
    bool here = false;
    if (ok && realpath(dir[0] ? dir : ".", real))
        for (size_t d = 0; d < j->n_dirs; d++)
            here = here || strcmp(j->dirs[d], real) == 0;
    return ok && here;
}

/* Completes (committed) or takes back the set of a dead process from its journal at `path`.
 * A journal that is not a whole one of this user's (read_journal) is left as it is, and the
 * files of that process with it: they are not known to be a set of wetdem's. */
static void recover_journal(const char* path, long pid)
{
    struct journal* j = malloc(sizeof *j);
    if (!j)
        return;
    if (!read_journal(path, pid, j)) {
        cli_error("%s: not a journal of a set of files that wetdem can put in order (another "
                  "user's, or damaged); it and the files of process %ld are left as they are",
                  path, pid);
        free(j);
        return;
    }
    char journal[JOURNAL_PATH];
    bool committed = j->whole;
    for (size_t d = 0; d < j->n_dirs && committed; d++)
        committed =
            format_path(journal, sizeof journal, "%s/" JOURNAL_PREFIX "%ld", j->dirs[d], pid) &&
            path_exists(journal);
    for (size_t k = 0; k < j->n; k++) {
        char old[SET_PATH + 8];
        if (!format_path(old, sizeof old, "%s.old", j->tmp[k]))
            continue;
        bool has_tmp = path_exists(j->tmp[k]), has_old = path_exists(old);
        if (committed && has_tmp && rename(j->tmp[k], j->final[k]) == 0)
            cli_error("%s: completed from a set of files that process %ld, now gone, was "
                      "replacing",
                      j->final[k], pid);
        else if (!committed && has_tmp)
            remove(j->tmp[k]);
        if (has_old && !committed && !path_exists(j->final[k]) && rename(old, j->final[k]) == 0)
            cli_error("%s: put back: process %ld, now gone, had moved it aside to replace it",
                      j->final[k], pid);
        else if (has_old)
            remove(old);
    }
    if (!committed && j->n > 0)
        cli_error("%s: the files that process %ld, now gone, was writing there were not all "
                  "written; the earlier ones stay",
                  j->final[0], pid);
    for (size_t d = 0; d < j->n_dirs; d++)
        if (format_path(journal, sizeof journal, "%s/" JOURNAL_PREFIX "%ld", j->dirs[d], pid))
            remove(journal);
    remove(path);
    free(j);
}

/* Puts in order what dead processes left in the directory of `final` (see above): their
 * journals there, then the temporary and backup files of `final` (named as open_output and
 * cli_out_open name them: BASE.tmpPID, .BASE.tmpPID, and those with .old). */
static void recover_stale(const char* final)
{
    char dir[1400];
    parent_dir(final, dir, sizeof dir);
    const char* base = strrchr(final, '/');
    base = base ? base + 1 : final;
    DIR* d = opendir(dir[0] ? dir : ".");
    if (!d)
        return;
    char names[2][CLI_MAX_OUTPUTS * 4][300];
    size_t n_names[2] = {0, 0};
    char visible[300], hidden[300];
    format_path(visible, sizeof visible, "%s.tmp", base);
    format_path(hidden, sizeof hidden, ".%s.tmp", base);
    for (struct dirent* e = readdir(d); e; e = readdir(d)) {
        bool journal = name_pid(e->d_name, JOURNAL_PREFIX, "") > 0 ||
                       name_pid(e->d_name, JOURNAL_PREFIX, ".part") > 0;
        bool mine = name_pid(e->d_name, visible, "") > 0 || name_pid(e->d_name, hidden, "") > 0 ||
                    name_pid(e->d_name, visible, ".old") > 0 ||
                    name_pid(e->d_name, hidden, ".old") > 0;
        int kind = journal ? 0 : 1;
        if ((journal || mine) && n_names[kind] < CLI_MAX_OUTPUTS * 4 && strlen(e->d_name) < 300)
            format_path(names[kind][n_names[kind]++], 300, "%s", e->d_name);
    }
    closedir(d);
    char path[1800];
    for (size_t k = 0; k < n_names[0]; k++) {
        long pid = name_pid(names[0][k], JOURNAL_PREFIX, "");
        bool part = pid < 0;
        if (part)
            pid = name_pid(names[0][k], JOURNAL_PREFIX, ".part");
        if (pid_alive(pid))
            continue;
        format_path(path, sizeof path, "%s/%s", dir[0] ? dir : ".", names[0][k]);
        if (part)
            remove(path);
        else
            recover_journal(path, pid);
    }
    for (size_t k = 0; k < n_names[1]; k++) {
        const char* name = names[1][k];
        bool old = name_pid(name, visible, ".old") > 0 || name_pid(name, hidden, ".old") > 0;
        long pid = old ? (name_pid(name, visible, ".old") > 0 ? name_pid(name, visible, ".old")
                                                              : name_pid(name, hidden, ".old"))
                       : (name_pid(name, visible, "") > 0 ? name_pid(name, visible, "")
                                                          : name_pid(name, hidden, ""));
        format_path(path, sizeof path, "%s/%s", dir[0] ? dir : ".", name);
        if (pid_alive(pid) || !path_exists(path)) /* (a journal may have dealt with it) */
            continue;
        /* a file of a set whose journal is still there (left as not wetdem's, or one whose
           process died after the journals above were passed over) is the journal's to put
           in order: on its own it might be taken back while the rest of the set is not */
        char journal[1500];
        if (!format_path(journal, sizeof journal, "%s/" JOURNAL_PREFIX "%ld", dir[0] ? dir : ".",
                         pid) ||
            path_exists(journal))
            continue;
        if (old && !path_exists(final) && rename(path, final) == 0) {
            cli_error("%s: put back from %s, where process %ld, now gone, had moved it aside "
                      "to replace it",
                      final, path, pid);
            continue;
        }
        remove(path);
        cli_error("%s: removed %s, left by process %ld, now gone, %s", final, path, pid,
                  old ? "beside the file it had replaced" : "which had not finished writing it");
    }
}

/* The absolute form of path (its directory resolved), into buf. 0 or -1. */
static int absolute_path(const char* path, char* buf, size_t size)
{
    char dir[1400], real[PATH_MAX];
    parent_dir(path, dir, sizeof dir);
    const char* base = strrchr(path, '/');
    base = base ? base + 1 : path;
    if (!realpath(dir[0] ? dir : ".", real))
        return -1;
    if (format_path(buf, size, "%s/%s", strcmp(real, "/") == 0 ? "" : real, base))
        return 0;
    errno = ENAMETOOLONG;
    return -1;
}

/* Writes the journal of the set (files to be renamed: rename[k]) into each of its
 * directories; 0, or -1 with those written removed. */
static int write_journals(struct cli_out_file* const* files, size_t n, const bool* renamed,
                          char dirs[][SET_PATH], size_t* n_dirs)
{
    /* the journal's text: at most CLI_MAX_OUTPUTS directories and files, each name escaped
       (journal_escape: at most two characters for one) */
    char text[CLI_MAX_OUTPUTS * 3 * 2 * SET_PATH + 64];
    size_t size = sizeof text, len = 0;
    bool ok = journal_put(text, size, &len, "wetdem output set\n");
    *n_dirs = 0;
    for (size_t k = 0; k < n && ok; k++) {
        char tmp[SET_PATH], final[SET_PATH], dir[SET_PATH];
        if (!renamed[k])
            continue;
        if (absolute_path(files[k]->tmp, tmp, sizeof tmp) != 0 ||
            absolute_path(files[k]->final, final, sizeof final) != 0)
            return -1;
        parent_dir(tmp, dir, sizeof dir);
        bool seen = false;
        for (size_t d = 0; d < *n_dirs; d++)
            seen = seen || strcmp(dirs[d], dir) == 0;
        if (!seen) {
            format_path(dirs[(*n_dirs)++], SET_PATH, "%s", dir);
            ok = journal_put(text, size, &len, "dir\t") && journal_escape(text, size, &len, dir) &&
                 journal_put(text, size, &len, "\n");
        }
        ok = ok && journal_put(text, size, &len, "file\t") &&
             journal_escape(text, size, &len, tmp) && journal_put(text, size, &len, "\t") &&
             journal_escape(text, size, &len, final) && journal_put(text, size, &len, "\n");
    }
    if (!(ok && journal_put(text, size, &len, "end\n"))) {
        errno = ENAMETOOLONG;
        return -1;
    }
    for (size_t d = 0; d < *n_dirs; d++) {
        char path[JOURNAL_PATH], part[JOURNAL_PATH + 8];
        format_path(path, sizeof path, "%s/" JOURNAL_PREFIX "%ld", dirs[d], (long)getpid());
        format_path(part, sizeof part, "%s.part", path);
        errno = 0;
        FILE* f = fopen(part, "w");
        bool written = f && fwrite(text, 1, len, f) == len;
        written = f && fclose(f) == 0 && written;
        if (!written || rename(part, path) != 0) {
            int err = errno ? errno : EIO;
            remove(part);
            for (size_t e = 0; e < d; e++) {
                format_path(path, sizeof path, "%s/" JOURNAL_PREFIX "%ld", dirs[e], (long)getpid());
                remove(path);
            }
            errno = err;
            return -1;
        }
    }
    return 0;
}

/* Removes the set's journals (the last first: the set stops counting as committed at once). */
static void remove_journals(char dirs[][SET_PATH], size_t n_dirs)
{
    for (size_t d = n_dirs; d-- > 0;) {
        char path[JOURNAL_PATH];
        format_path(path, sizeof path, "%s/" JOURNAL_PREFIX "%ld", dirs[d], (long)getpid());
        remove(path);
    }
}

/* Test hook: WETDEM_TEST_KILL_AT_RENAME=k kills the process with SIGKILL once k temporary
 * files of a set of two or more have been renamed to their targets (0: right after the
 * targets were moved aside), as a kill -9 or a power cut might. */
static void maybe_killed(size_t renamed)
{
    const char* at = getenv("WETDEM_TEST_KILL_AT_RENAME");
    if (at && at[0] && strtoul(at, NULL, 10) == renamed)
        raise(SIGKILL);
}

/* Opens the file that output to `path` writes: in place (o->direct) or under the temporary
 * name of its target (o->tmp), after putting in order what killed processes left there
 * (recover_stale). 0, or -1 with errno set. */
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
        format_path(o->tmp, sizeof o->tmp, "%s", o->final);
        o->f = o->std ? o->std : fopen(o->final, "w");
    } else {
        /* the temporary name: tmp_format applied to the target's directory and base name */
        char dir[1400];
        parent_dir(o->final, dir, sizeof dir);
        const char* base = strrchr(o->final, '/');
        base = base ? base + 1 : o->final;
        if (!format_path(o->tmp, sizeof o->tmp, tmp_format, dir[0] ? dir : ".", base,
                         (long)getpid())) {
            o->tmp[0] = '\0'; /* (one cut short would not hold this process's whole PID) */
            errno = ENAMETOOLONG;
            return -1;
        }
        recover_stale(o->final);
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
        parent_dir(outs[k].path, dir, sizeof dir);
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
    bool fits = format_path(path, sizeof path, "%s/%s", dir, name);
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
    format_path(buf, size, "%s.old", o->tmp);
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
 * them (recover_stale). 0, or the index of the file that failed + 1 with *err its errno. */
static size_t replace_set(struct cli_out_file* const* files, size_t n, int* err)
{
    bool had[CLI_MAX_OUTPUTS] = {false}, placed[CLI_MAX_OUTPUTS] = {false};
    bool renamed[CLI_MAX_OUTPUTS] = {false};
    char old[1500], dirs[CLI_MAX_OUTPUTS][SET_PATH];
    size_t n_renamed = 0, n_dirs = 0;
    n = n < CLI_MAX_OUTPUTS ? n : CLI_MAX_OUTPUTS;
    for (size_t k = 0; k < n; k++) {
        renamed[k] = files[k]->tmp[0] && !files[k]->direct;
        n_renamed += renamed[k];
    }
    if (n_renamed > 1 && write_journals(files, n, renamed, dirs, &n_dirs) != 0) {
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
            remove_journals(dirs, n_dirs);
            return k + 1;
        }
        had[k] = true;
    }
    size_t done = 0;
    if (n_dirs)
        maybe_killed(done);
    for (size_t k = 0; k < n; k++) {
        const struct cli_out_file* o = files[k];
        if (!renamed[k])
            continue;
        if (rename(o->tmp, o->final) != 0) {
            *err = errno;
            restore_set(files, n, had, placed);
            remove_journals(dirs, n_dirs);
            return k + 1;
        }
        placed[k] = true;
        if (n_dirs)
            maybe_killed(++done);
    }
    for (size_t k = 0; k < n; k++)
        if (had[k]) {
            backup_name(files[k], old, sizeof old);
            remove(old);
        }
    remove_journals(dirs, n_dirs);
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

void cli_print_double(FILE* f, double v)
{
    char buf[40];
    wetdem_param_format_value(v, 15, buf, sizeof buf);
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

bool cli_series_entry(const char* line, char* name, size_t n, double* time)
{
    const char* p = strstr(line, "\"name\" : \"");
    const char* q = p ? strstr(line, "\"time\" : ") : NULL;
    if (!q)
        return false;
    p += strlen("\"name\" : \"");
    size_t len = strcspn(p, "\"");
    char* end;
    *time = strtod(q + strlen("\"time\" : "), &end);
    if (len == 0 || len >= n || p[len] != '"' || end == q + strlen("\"time\" : "))
        return false;
    memcpy(name, p, len);
    name[len] = '\0';
    return true;
}

const char* cli_option_hint(const char* arg, const char* const* options, char* buf, size_t n)
{
    const char* hint = arg[0] == '-' ? wetdem_param_suggest(arg, options) : NULL;
    if (hint && strcmp(hint, arg) == 0) /* a known option that reached here: its value is missing */
        snprintf(buf, n, " (needs a value)");
    else
        snprintf(buf, n, "%s%s%s", hint ? " (did you mean '" : "", hint ? hint : "",
                 hint ? "'?)" : "");
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

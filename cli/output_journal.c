/*
 * output_journal.c — the journal of a set of output files, and what a killed process left
 * behind (see output_journal.h; cli_util.c replaces the sets).
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
 * missing. So the directory holds either the earlier set or the new one, whole.
 */
#include <ctype.h>
#include <dirent.h>
#include <errno.h>
#include <limits.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli_util.h"
#include "output_journal.h"

#define JOURNAL_PREFIX ".wetdem-set."
#define JOURNAL_PATH (CLI_SET_PATH + 40) /* a journal's path */

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
    char dirs[CLI_MAX_OUTPUTS][CLI_SET_PATH], tmp[CLI_MAX_OUTPUTS][CLI_SET_PATH],
        final[CLI_MAX_OUTPUTS][CLI_SET_PATH];
    size_t n_dirs, n;
    bool whole;
};

/* Whether entry k of journal j (process pid) names what a set of wetdem's files holds: a
 * temporary file of its target, BASE.tmpPID or .BASE.tmpPID, beside it in one of the set's
 * directories. Anything else (a corrupt journal, or one that is not wetdem's) names files
 * that are not its to move. */
static bool journal_entry_valid(const struct journal* j, size_t k, long pid)
{
    char dir_tmp[CLI_SET_PATH], dir_final[CLI_SET_PATH], visible[CLI_SET_PATH],
        hidden[CLI_SET_PATH];
    cli_parent_dir(j->tmp[k], dir_tmp, sizeof dir_tmp);
    cli_parent_dir(j->final[k], dir_final, sizeof dir_final);
    if (j->tmp[k][0] != '/' || strcmp(dir_tmp, dir_final) != 0)
        return false;
    bool listed = false;
    for (size_t d = 0; d < j->n_dirs; d++)
        listed = listed || strcmp(j->dirs[d], dir_tmp) == 0;
    const char* base = strrchr(j->final[k], '/') + 1;
    const char* tmp_base = strrchr(j->tmp[k], '/') + 1;
    return listed && base[0] && cli_format_path(visible, sizeof visible, "%s.tmp%ld", base, pid) &&
           cli_format_path(hidden, sizeof hidden, ".%s.tmp%ld", base, pid) &&
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
            ok = journal_unescape(line + 4, j->dirs[j->n_dirs++], CLI_SET_PATH) &&
                 strchr(line + 4, '\t') == NULL;
        else if (strncmp(line, "file\t", 5) == 0 && j->n < CLI_MAX_OUTPUTS &&
                 (tab = strchr(line + 5, '\t')) != NULL && strchr(tab + 1, '\t') == NULL) {
            *tab = '\0';
            ok = journal_unescape(line + 5, j->tmp[j->n], CLI_SET_PATH) &&
                 journal_unescape(tab + 1, j->final[j->n], CLI_SET_PATH);
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
    char dir[CLI_SET_PATH], real[PATH_MAX];
    cli_parent_dir(path, dir, sizeof dir);
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
            cli_format_path(journal, sizeof journal, "%s/" JOURNAL_PREFIX "%ld", j->dirs[d], pid) &&
            path_exists(journal);
    for (size_t k = 0; k < j->n; k++) {
        char old[CLI_SET_PATH + 8];
        if (!cli_format_path(old, sizeof old, "%s.old", j->tmp[k]))
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
        if (cli_format_path(journal, sizeof journal, "%s/" JOURNAL_PREFIX "%ld", j->dirs[d], pid))
            remove(journal);
    remove(path);
    free(j);
}

/* Puts in order what dead processes left in the directory of `final` (see above): their
 * journals there, then the temporary and backup files of `final` (named as open_output and
 * cli_out_open name them: BASE.tmpPID, .BASE.tmpPID, and those with .old). */
void cli_journal_recover(const char* final)
{
    char dir[1400];
    cli_parent_dir(final, dir, sizeof dir);
    const char* base = strrchr(final, '/');
    base = base ? base + 1 : final;
    DIR* d = opendir(dir[0] ? dir : ".");
    if (!d)
        return;
    char names[2][CLI_MAX_OUTPUTS * 4][300];
    size_t n_names[2] = {0, 0};
    char visible[300], hidden[300];
    cli_format_path(visible, sizeof visible, "%s.tmp", base);
    cli_format_path(hidden, sizeof hidden, ".%s.tmp", base);
    for (struct dirent* e = readdir(d); e; e = readdir(d)) {
        bool journal = name_pid(e->d_name, JOURNAL_PREFIX, "") > 0 ||
                       name_pid(e->d_name, JOURNAL_PREFIX, ".part") > 0;
        bool mine = name_pid(e->d_name, visible, "") > 0 || name_pid(e->d_name, hidden, "") > 0 ||
                    name_pid(e->d_name, visible, ".old") > 0 ||
                    name_pid(e->d_name, hidden, ".old") > 0;
        int kind = journal ? 0 : 1;
        if ((journal || mine) && n_names[kind] < CLI_MAX_OUTPUTS * 4 && strlen(e->d_name) < 300)
            cli_format_path(names[kind][n_names[kind]++], 300, "%s", e->d_name);
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
        cli_format_path(path, sizeof path, "%s/%s", dir[0] ? dir : ".", names[0][k]);
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
        cli_format_path(path, sizeof path, "%s/%s", dir[0] ? dir : ".", name);
        if (pid_alive(pid) || !path_exists(path)) /* (a journal may have dealt with it) */
            continue;
        /* a file of a set whose journal is still there (left as not wetdem's, or one whose
           process died after the journals above were passed over) is the journal's to put
           in order: on its own it might be taken back while the rest of the set is not */
        char journal[1500];
        if (!cli_format_path(journal, sizeof journal, "%s/" JOURNAL_PREFIX "%ld",
                             dir[0] ? dir : ".", pid) ||
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
    cli_parent_dir(path, dir, sizeof dir);
    const char* base = strrchr(path, '/');
    base = base ? base + 1 : path;
    if (!realpath(dir[0] ? dir : ".", real))
        return -1;
    if (cli_format_path(buf, size, "%s/%s", strcmp(real, "/") == 0 ? "" : real, base))
        return 0;
    errno = ENAMETOOLONG;
    return -1;
}

/* Writes the journal of the set (files to be renamed: rename[k]) into each of its
 * directories; 0, or -1 with those written removed. */
int cli_journal_write(struct cli_out_file* const* files, size_t n, const bool* renamed,
                      char dirs[][CLI_SET_PATH], size_t* n_dirs)
{
    /* the journal's text: at most CLI_MAX_OUTPUTS directories and files, each name escaped
       (journal_escape: at most two characters for one) */
    char text[CLI_MAX_OUTPUTS * 3 * 2 * CLI_SET_PATH + 64];
    size_t size = sizeof text, len = 0;
    bool ok = journal_put(text, size, &len, "wetdem output set\n");
    *n_dirs = 0;
    for (size_t k = 0; k < n && ok; k++) {
        char tmp[CLI_SET_PATH], final[CLI_SET_PATH], dir[CLI_SET_PATH];
        if (!renamed[k])
            continue;
        if (absolute_path(files[k]->tmp, tmp, sizeof tmp) != 0 ||
            absolute_path(files[k]->final, final, sizeof final) != 0)
            return -1;
        cli_parent_dir(tmp, dir, sizeof dir);
        bool seen = false;
        for (size_t d = 0; d < *n_dirs; d++)
            seen = seen || strcmp(dirs[d], dir) == 0;
        if (!seen) {
            cli_format_path(dirs[(*n_dirs)++], CLI_SET_PATH, "%s", dir);
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
        cli_format_path(path, sizeof path, "%s/" JOURNAL_PREFIX "%ld", dirs[d], (long)getpid());
        cli_format_path(part, sizeof part, "%s.part", path);
        errno = 0;
        FILE* f = fopen(part, "w");
        bool written = f && fwrite(text, 1, len, f) == len;
        written = f && fclose(f) == 0 && written;
        if (!written || rename(part, path) != 0) {
            int err = errno ? errno : EIO;
            remove(part);
            for (size_t e = 0; e < d; e++) {
                cli_format_path(path, sizeof path, "%s/" JOURNAL_PREFIX "%ld", dirs[e],
                                (long)getpid());
                remove(path);
            }
            errno = err;
            return -1;
        }
    }
    return 0;
}

/* Removes the set's journals (the last first: the set stops counting as committed at once). */
void cli_journal_remove(char dirs[][CLI_SET_PATH], size_t n_dirs)
{
    for (size_t d = n_dirs; d-- > 0;) {
        char path[JOURNAL_PATH];
        cli_format_path(path, sizeof path, "%s/" JOURNAL_PREFIX "%ld", dirs[d], (long)getpid());
        remove(path);
    }
}

/* Test hook: WETDEM_TEST_KILL_AT_RENAME=k kills the process with SIGKILL once k temporary
 * files of a set of two or more have been renamed to their targets (0: right after the
 * targets were moved aside), as a kill -9 or a power cut might. */
void cli_journal_test_kill(size_t renamed)
{
    const char* at = getenv("WETDEM_TEST_KILL_AT_RENAME");
    if (at && at[0] && strtoul(at, NULL, 10) == renamed)
        raise(SIGKILL);
}

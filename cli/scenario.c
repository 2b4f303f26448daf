/*
 * scenario.c — reading and checking scenario files (INI via inih), --set overrides and typed
 * accessors. Building a simulation from a scenario is in scenario_build.c; the key tables and
 * the generated documentation in scenario_keys.c.
 *
 * Syntax (inih): "[section]" headers, "key = value" lines, comments on lines starting with
 * ';' or '#', inline comments after " ;" or " #". Lines are at most 196 characters. Every
 * error is reported as "FILE:LINE: ..." and all of them are listed before giving up, so one
 * run shows every mistake in a file.
 *
 * Line numbers: the installed inih does not pass them to the handler, so the reader below
 * counts the lines it hands to inih (one call per line; an over-long line is reported and the
 * rest of it skipped, so the count stays right).
 */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include <ini.h>

#include "cli_util.h"
#include "scenario.h"

/* ---- small string helpers ---- */

static void copy_text(char* dst, size_t n, const char* src)
{
    snprintf(dst, n, "%s", src);
}

static void trim(char* s)
{
    size_t len = strlen(s);
    while (len > 0 && isspace((unsigned char)s[len - 1]))
        s[--len] = '\0';
    size_t start = 0;
    while (s[start] && isspace((unsigned char)s[start]))
        start++;
    if (start)
        memmove(s, s + start, len - start + 1);
}

/* Removes an inline "#" comment (a '#' preceded by white space). */
static void strip_hash_comment(char* s)
{
    for (char* p = s; *p; p++)
        if (*p == '#' && p > s && isspace((unsigned char)p[-1])) {
            *p = '\0';
            break;
        }
    trim(s);
}

bool cli_is_name(const char* s)
{
    if (!*s)
        return false;
    for (const char* p = s; *p; p++)
        if (!isalnum((unsigned char)*p) && *p != '_' && *p != '-')
            return false;
    return true;
}

const char* cli_list_empty_name(const char* list)
{
    bool name = false, comma = false; /* a name, a comma seen so far */
    const char* first = NULL;         /* the first empty place */
    for (const char* p = list;; p++) {
        const char* start = p;
        while (*p && *p != ',')
            p++;
        bool empty = strspn(start, " \t") >= (size_t)(p - start);
        if (!empty)
            name = true;
        else if (!first && (comma || *p == ','))
            first = !comma ? "a comma with no name before it"
                    : *p   ? "two commas with no name between them"
                           : "a comma with no name after it";
        if (!*p)
            break;
        comma = true;
    }
    return !comma ? NULL : !name ? "only commas, no name" : first;
}

/* ---- growing arrays ---- */

static int push_entry(struct cli_scenario* sc, const char* section, const char* key,
                      const char* value, int line)
{
    if (sc->n_entries == sc->entries_cap) {
        size_t cap = sc->entries_cap ? 2 * sc->entries_cap : 32;
        struct cli_entry* e = realloc(sc->entries, cap * sizeof *e);
        if (!e)
            return -1;
        sc->entries = e;
        sc->entries_cap = cap;
    }
    struct cli_entry* e = &sc->entries[sc->n_entries++];
    copy_text(e->section, sizeof e->section, section);
    copy_text(e->key, sizeof e->key, key);
    copy_text(e->value, sizeof e->value, value);
    e->line = line;
    return 0;
}

static int push_section(struct cli_scenario* sc, const char* name, int line)
{
    if (sc->n_sections == sc->sections_cap) {
        size_t cap = sc->sections_cap ? 2 * sc->sections_cap : 16;
        struct cli_section_mark* s = realloc(sc->sections, cap * sizeof *s);
        if (!s)
            return -1;
        sc->sections = s;
        sc->sections_cap = cap;
    }
    struct cli_section_mark* s = &sc->sections[sc->n_sections++];
    copy_text(s->name, sizeof s->name, name);
    s->line = line;
    return 0;
}

void cli_scenario_free(struct cli_scenario* sc)
{
    free(sc->entries);
    free(sc->sections);
    memset(sc, 0, sizeof *sc);
}

int cli_scenario_copy(const struct cli_scenario* src, struct cli_scenario* dst)
{
    /* entries and section marks are plain values: copied whole (a batch copies one per point) */
    memset(dst, 0, sizeof *dst);
    copy_text(dst->file, sizeof dst->file, src->file);
    size_t n_e = src->n_entries, n_s = src->n_sections;
    dst->entries = malloc((n_e ? n_e : 1) * sizeof *dst->entries);
    dst->sections = malloc((n_s ? n_s : 1) * sizeof *dst->sections);
    if (!dst->entries || !dst->sections) {
        cli_scenario_free(dst);
        cli_error("out of memory copying a scenario");
        return CLI_EXIT_RUNTIME;
    }
    if (n_e)
        memcpy(dst->entries, src->entries, n_e * sizeof *dst->entries);
    if (n_s)
        memcpy(dst->sections, src->sections, n_s * sizeof *dst->sections);
    dst->n_entries = dst->entries_cap = n_e;
    dst->n_sections = dst->sections_cap = n_s;
    return CLI_EXIT_OK;
}

/* ---- messages ---- */

static void vreport(const struct cli_scenario* sc, const struct cli_entry* e, const char* fmt,
                    va_list ap)
{
    if (e->line > 0)
        fprintf(stderr, "%s:%d: [%s] %s = %s: ", sc->file, e->line, e->section, e->key, e->value);
    else
        fprintf(stderr, "%s: --set %s.%s=%s: ", sc->file, e->section, e->key, e->value);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
}

void cli_scenario_error(const struct cli_scenario* sc, const struct cli_entry* e, const char* fmt,
                        ...)
{
    va_list ap;
    va_start(ap, fmt);
    vreport(sc, e, fmt, ap);
    va_end(ap);
}

/* The line of section's header (or of its first key in the file); 0 when the file has none
 * (-1 when --set gave its keys). */
static int section_line(const struct cli_scenario* sc, const char* section)
{
    for (size_t k = 0; k < sc->n_sections; k++)
        if (strcmp(sc->sections[k].name, section) == 0)
            return sc->sections[k].line;
    int line = 0;
    for (size_t k = 0; k < sc->n_entries && line <= 0; k++)
        if (strcmp(sc->entries[k].section, section) == 0)
            line = sc->entries[k].line > 0 ? sc->entries[k].line : -1;
    return line;
}

void cli_scenario_section_error(const struct cli_scenario* sc, const char* section, const char* fmt,
                                ...)
{
    va_list ap;
    va_start(ap, fmt);
    int line = section_line(sc, section);
    if (line > 0)
        fprintf(stderr, "%s:%d: [%s]: ", sc->file, line, section);
    else if (line < 0) /* (keys of --set only) */
        fprintf(stderr, "%s: [%s] of --set: ", sc->file, section);
    else /* (a line of the file would point at something else) */
        fprintf(stderr, "%s: no [%s] section: ", sc->file, section);
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
}

/* ---- accessors ---- */

const struct cli_entry* cli_scenario_find(const struct cli_scenario* sc, const char* section,
                                          const char* key)
{
    for (size_t k = 0; k < sc->n_entries; k++)
        if (strcmp(sc->entries[k].section, section) == 0 && strcmp(sc->entries[k].key, key) == 0)
            return &sc->entries[k];
    return NULL;
}

bool cli_scenario_has_section(const struct cli_scenario* sc, const char* section)
{
    for (size_t k = 0; k < sc->n_sections; k++)
        if (strcmp(sc->sections[k].name, section) == 0)
            return true;
    for (size_t k = 0; k < sc->n_entries; k++)
        if (strcmp(sc->entries[k].section, section) == 0)
            return true;
    return false;
}

bool cli_section_matches(const char* name, const char* pattern)
{
    const char* star = strstr(pattern, ".*");
    return star ? strncmp(name, pattern, (size_t)(star - pattern) + 1) == 0
                : strcmp(name, pattern) == 0;
}

/* Whether section `name` matches one of the NULL-terminated `reads`. */
static bool section_read(const char* name, const char* const* reads)
{
    for (size_t k = 0; reads[k]; k++)
        if (cli_section_matches(name, reads[k]))
            return true;
    return false;
}

int cli_scenario_check_read(const struct cli_scenario* sc, const char* reader,
                            const char* const* reads)
{
    const char* name = NULL;
    const struct cli_entry* set = NULL;
    for (size_t k = 0; k < sc->n_sections && !name; k++)
        if (!section_read(sc->sections[k].name, reads))
            name = sc->sections[k].name;
    for (size_t k = 0; k < sc->n_entries && !name; k++)
        if (!section_read(sc->entries[k].section, reads)) {
            name = sc->entries[k].section;
            set = sc->entries[k].line == 0 ? &sc->entries[k] : NULL;
        }
    if (!name)
        return CLI_EXIT_OK;
    char list[512];
    size_t used = 0;
    for (size_t k = 0; reads[k] && used < sizeof list; k++) {
        const char* star = strstr(reads[k], ".*");
        int len = star ? (int)(star - reads[k]) : (int)strlen(reads[k]);
        used += (size_t)snprintf(list + used, sizeof list - used, "%s[%.*s%s]",
                                 k == 0         ? ""
                                 : reads[k + 1] ? ", "
                                                : " and ",
                                 len, reads[k], star ? ".NAME" : "");
    }
    /* in a binary collision, a section of the pairwise engine, which only [engine] type =
       pairwise chooses (the many-particle mode is chosen by its own sections) */
    static const char* const pairwise[] = {"davis", "pairwise", "sphere.*", NULL};
    const char* fix = section_read(name, pairwise) && section_read("collision", reads)
                          ? " (a section of the pairwise engine: to run several spheres with it, "
                            "add [engine] type = pairwise)"
                          : "";
    if (set)
        cli_scenario_error(sc, set, "[%s] is not read by %s, which reads %s%s", name, reader, list,
                           fix);
    else
        cli_scenario_section_error(sc, name, "not read by %s, which reads %s: remove it%s", reader,
                                   list, fix);
    return CLI_EXIT_USAGE;
}

double cli_scenario_number(const struct cli_scenario* sc, const char* section, const char* key,
                           double def)
{
    const struct cli_entry* e = cli_scenario_find(sc, section, key);
    return e ? strtod(e->value, NULL) : def;
}

const char* cli_scenario_text(const struct cli_scenario* sc, const char* section, const char* key,
                              const char* def)
{
    const struct cli_entry* e = cli_scenario_find(sc, section, key);
    return e ? e->value : def;
}

/* ---- value checks ---- */

/* Checks a number against a descriptor; on failure prints the message and returns 2. */
static int check_number(const struct cli_scenario* sc, const struct cli_entry* e,
                        const struct wetdem_param_desc* d)
{
    double v;
    if (cli_number(e->value, &v) != 0) {
        const char* why = cli_number_problem(e->value);
        char hint[160];
        cli_number_hint(e->value, d->unit, hint, sizeof hint);
        cli_scenario_error(sc, e, "%s%s%s%s%s", why, d->unit[0] ? " [" : "", d->unit,
                           d->unit[0] ? "]" : "",
                           hint[0] ? hint : " (decimal or exponent notation, e.g. 6.35e-3)");
        return CLI_EXIT_USAGE;
    }
    char msg[512];
    if (wetdem_param_validate(d, v, msg, sizeof msg) != WETDEM_OK) {
        cli_scenario_error(sc, e, "%s", msg);
        return CLI_EXIT_USAGE;
    }
    return CLI_EXIT_OK;
}

static int check_choice(const struct cli_scenario* sc, const struct cli_entry* e,
                        const char* const* choices)
{
    for (size_t k = 0; choices[k]; k++)
        if (strcmp(choices[k], e->value) == 0)
            return CLI_EXIT_OK;
    const char* hint = wetdem_param_suggest(e->value, choices);
    char list[256] = "";
    for (size_t k = 0; choices[k]; k++) {
        size_t len = strlen(list);
        snprintf(list + len, sizeof list - len, "%s%s", k ? ", " : "", choices[k]);
    }
    cli_scenario_error(sc, e, "must be one of: %s%s%s%s", list, hint ? " (did you mean '" : "",
                       hint ? hint : "", hint ? "'?)" : "");
    return CLI_EXIT_USAGE;
}

static int check_names(const struct cli_scenario* sc, const struct cli_entry* e, bool list)
{
    char buf[CLI_VALUE_MAX];
    copy_text(buf, sizeof buf, e->value);
    int count = 0;
    const char* names[CLI_VALUE_MAX / 2];
    const char* word = NULL; /* 'none' or 'all', which stand for the whole list */
    const char* empty = cli_list_empty_name(e->value);
    if (empty) { /* "hertz,,db": a name left out, or a slip; strtok would skip it unseen */
        cli_scenario_error(sc, e, "%s%s", empty,
                           !list                            ? ": expected one name"
                           : strncmp(empty, "only", 4) == 0 ? ": expected one or more names"
                                                            : ": separate the names by one comma "
                                                              "or by blanks ('hertz, db' or "
                                                              "'hertz db')");
        return CLI_EXIT_USAGE;
    }
    char* save = NULL;
    for (char* tok = strtok_r(buf, " ,\t", &save); tok; tok = strtok_r(NULL, " ,\t", &save)) {
        if (!cli_is_name(tok)) {
            cli_scenario_error(sc, e, "'%s' is not a name (letters, digits, '_' and '-')", tok);
            return CLI_EXIT_USAGE;
        }
        /* A repeated name is a slip (meant another axis, face or model), not a request. */
        for (int k = 0; k < count; k++)
            if (strcmp(names[k], tok) == 0) {
                cli_scenario_error(sc, e, "'%s' is listed twice", tok);
                return CLI_EXIT_USAGE;
            }
        if (strcmp(tok, "none") == 0 || strcmp(tok, "all") == 0)
            word = tok;
        names[count++] = tok;
    }
    if (count == 0 || (!list && count > 1)) {
        cli_scenario_error(sc, e, list ? "expected one or more names" : "expected one name");
        return CLI_EXIT_USAGE;
    }
    if (word && count > 1) {
        cli_scenario_error(sc, e, "'%s' stands for the whole list: write it alone", word);
        return CLI_EXIT_USAGE;
    }
    return CLI_EXIT_OK;
}

/* A cli_key_desc number as a library descriptor, for validation and range text. */
struct wetdem_param_desc cli_key_as_param(const struct cli_key_desc* k)
{
    struct wetdem_param_desc d = {0};
    d.name = k->key;
    d.unit = k->unit;
    d.doc = k->doc;
    d.min = k->min;
    d.max = k->max;
    d.min_open = k->min_open;
    d.max_open = k->max_open;
    d.choices = k->kind == CLI_VALUE_CHOICE ? k->choices : NULL;
    d.integer = k->integer;
    return d;
}

static int check_key_value(const struct cli_scenario* sc, const struct cli_entry* e,
                           const struct cli_key_desc* k)
{
    switch (k->kind) {
    case CLI_VALUE_NUMBER: {
        struct wetdem_param_desc d = cli_key_as_param(k);
        return check_number(sc, e, &d);
    }
    case CLI_VALUE_CHOICE: return check_choice(sc, e, k->choices);
    case CLI_VALUE_NAME: return check_names(sc, e, false);
    case CLI_VALUE_NAME_LIST: return check_names(sc, e, true);
    case CLI_VALUE_TEXT: return CLI_EXIT_OK;
    }
    return CLI_EXIT_OK;
}

static int check_lib_value(const struct cli_scenario* sc, const struct cli_entry* e,
                           const struct wetdem_param_desc* d)
{
    if (d->choices)
        return check_choice(sc, e, d->choices);
    return check_number(sc, e, d);
}

/* ---- keys of a section ---- */

/* Collects every key name a section accepts into names (NULL-terminated), for suggestions. */
static size_t section_key_names(const struct cli_section_info* info, const char** names, size_t cap)
{
    size_t n = 0;
    for (size_t k = 0; info->desc && info->desc->keys && info->desc->keys[k].key && n + 1 < cap;
         k++)
        names[n++] = info->desc->keys[k].key;
    for (size_t k = 0; info->lib_keys && info->lib_keys[k].name && n + 1 < cap; k++)
        names[n++] = info->lib_keys[k].name;
    names[n] = NULL;
    return n;
}

/* Whether the section accepts key: one of its table or of its library table, or any key of a
 * section whose keys the library checks ([integrator], [sim]). */
static bool section_has_key(const struct cli_section_info* info, const char* key)
{
    for (size_t k = 0; info->desc && info->desc->keys && info->desc->keys[k].key; k++)
        if (strcmp(info->desc->keys[k].key, key) == 0)
            return true;
    return info->open_keys || wetdem_param_find(info->lib_keys, key) != NULL;
}

static void unknown_key(const struct cli_scenario* sc, const struct cli_entry* e,
                        const struct cli_section_info* info)
{
    const char* names[128];
    size_t n = section_key_names(info, names, 128);
    const char* hint = wetdem_param_suggest(e->key, names);
    /* a word of a key's name, angle for angle_deg: its one key */
    size_t len = strlen(e->key), starts = 0;
    for (size_t k = 0; !hint && k < n; k++)
        if (strncmp(names[k], e->key, len) == 0 && names[k][len] == '_' && ++starts == 1)
            hint = names[k];
    if (starts > 1)
        hint = NULL;
    char home[400];
    int where = cli_key_home(sc, e, home, sizeof home);
    if (where == 1) { /* a key of another section of this engine: not a misspelling */
        cli_scenario_error(sc, e, "unknown key '%s' in [%s]: %s", e->key, e->section, home);
        return;
    }
    char aside[420] = ""; /* another engine's key: said beside the hint or list */
    if (where == 2)
        snprintf(aside, sizeof aside, " (%s)", home);
    if (hint) {
        cli_scenario_error(sc, e, "unknown key '%s' in [%s] (did you mean '%s'?)%s", e->key,
                           e->section, hint, aside);
        return;
    }
    char list[512] = "";
    for (size_t k = 0; names[k]; k++) {
        size_t used = strlen(list);
        snprintf(list + used, sizeof list - used, "%s%s", k ? ", " : "", names[k]);
    }
    cli_scenario_error(sc, e, "unknown key '%s' in [%s]; valid keys: %s%s", e->key, e->section,
                       list, aside);
}

/* Checks one entry against its section. Returns an exit code; prints the error. */
static int check_entry(const struct cli_scenario* sc, const struct cli_entry* e)
{
    struct cli_section_info info;
    if (cli_section_lookup(e->section, &info) != 0)
        return CLI_EXIT_USAGE; /* reported once per section by the caller */
    if (info.desc && info.desc->keys)
        for (size_t k = 0; info.desc->keys[k].key; k++)
            if (strcmp(info.desc->keys[k].key, e->key) == 0)
                return check_key_value(sc, e, &info.desc->keys[k]);
    const struct wetdem_param_desc* d = wetdem_param_find(info.lib_keys, e->key);
    if (d)
        return check_lib_value(sc, e, d);
    if (info.open_keys) {
        if (!cli_is_name(e->key)) {
            cli_scenario_error(sc, e, "'%s' is not a key name", e->key);
            return CLI_EXIT_USAGE;
        }
        return CLI_EXIT_OK; /* checked by the library when the scenario is built */
    }
    unknown_key(sc, e, &info);
    return CLI_EXIT_USAGE;
}

static void unknown_section(const struct cli_scenario* sc, const char* name, int line)
{
    char msg[256];
    cli_section_suggestion(name, msg, sizeof msg);
    fprintf(stderr, "%s:%d: unknown section [%s]%s\n", sc->file, line, name, msg);
}

/* Checks every section header and entry; reports all errors. Returns an exit code. */
static int check_all(const struct cli_scenario* sc)
{
    int rc = CLI_EXIT_OK;
    for (size_t k = 0; k < sc->n_sections; k++) {
        struct cli_section_info info;
        if (cli_section_lookup(sc->sections[k].name, &info) != 0) {
            unknown_section(sc, sc->sections[k].name, sc->sections[k].line);
            rc = CLI_EXIT_USAGE;
        }
        for (size_t m = 0; m < k; m++)
            if (strcmp(sc->sections[m].name, sc->sections[k].name) == 0) {
                fprintf(stderr, "%s:%d: section [%s] appears twice (first at line %d)\n", sc->file,
                        sc->sections[k].line, sc->sections[k].name, sc->sections[m].line);
                rc = CLI_EXIT_USAGE;
            }
    }
    for (size_t k = 0; k < sc->n_entries; k++) {
        const struct cli_entry* e = &sc->entries[k];
        struct cli_section_info info;
        if (cli_section_lookup(e->section, &info) != 0)
            continue;
        if (check_entry(sc, e) != CLI_EXIT_OK)
            rc = CLI_EXIT_USAGE;
        for (size_t m = 0; m < k; m++)
            if (strcmp(sc->entries[m].section, e->section) == 0 &&
                strcmp(sc->entries[m].key, e->key) == 0) {
                cli_scenario_error(sc, e,
                                   "key given twice (first at line %d; a value cannot continue "
                                   "on an indented line)",
                                   sc->entries[m].line);
                rc = CLI_EXIT_USAGE;
            }
    }
    return rc;
}

/* ---- reading ---- */

struct reader {
    FILE* f;
    struct cli_scenario* sc;
    int line;
    int n_errors;
    bool out_of_memory;
    int read_errno; /* a read error (e.g. EISDIR: the path is a directory), else 0 */
    char* buf;      /* the physical line (getline) */
    size_t cap;
    int shape_line;   /* the last line check_shape reported (inih would report it again) */
    bool header_lost; /* a header was malformed: keys up to the next one have no section */
};

/* Records a "[name]" header line (inih reports malformed ones itself). */
static void note_section(struct reader* r, const char* text)
{
    const char* p = text;
    while (isspace((unsigned char)*p))
        p++;
    if (*p != '[')
        return;
    const char* close = strchr(p, ']');
    if (!close)
        return;
    char name[CLI_NAME_MAX];
    size_t len = (size_t)(close - p - 1);
    if (len >= sizeof name)
        len = sizeof name - 1;
    memcpy(name, p + 1, len);
    name[len] = '\0';
    trim(name);
    /* inih drops what follows the ']' (a key written on the header's line would be lost) */
    const char* rest = close + 1;
    while (isspace((unsigned char)*rest))
        rest++;
    if (*rest) {
        size_t n = strcspn(rest, "\r\n");
        fprintf(stderr,
                "%s:%d: text after the section header [%s]: '%.*s'; a header stands alone on its "
                "line, its keys on the lines below\n",
                r->sc->file, r->line, name, (int)(n < 60 ? n : 60), rest);
        r->n_errors++;
    }
    if (push_section(r->sc, name, r->line) != 0)
        r->out_of_memory = true;
}

/* The length of line s without its comment: a whole-line comment (';' or '#' first) or an
 * inline one (' ;' or ' #': the character after white space), and the white space before. */
static size_t without_comment(const char* s, size_t len)
{
    size_t k = 0;
    while (k < len && isspace((unsigned char)s[k]))
        k++;
    if (k < len && (s[k] == ';' || s[k] == '#'))
        return 0;
    for (; k < len; k++)
        if ((s[k] == ';' || s[k] == '#') && k > 0 && isspace((unsigned char)s[k - 1]))
            break;
    while (k > 0 && isspace((unsigned char)s[k - 1]))
        k--;
    return k;
}

/* inih reader: one line per call, counted, given to inih without its comment (inih's lines
 * hold num - 1 characters, which long comments would exceed); a line longer than that
 * without its comment is reported and skipped. */
/* Reports a line that inih will refuse, at once and in the words of its fault (a header
 * without its ']', a line without '='), so that its message comes in line order before those
 * of the lines after it: the keys under a header without its ']' are reported by it alone,
 * not each as a key before any [section]. Indented lines are left to inih, which reads them
 * as continuations of a value. */
static void check_shape(struct reader* r, const char* str, size_t len)
{
    const char* p = str;
    const char* end = str + len;
    if (len == 0 || isspace((unsigned char)*p))
        return;
    if (*p == '[') {
        if (memchr(p, ']', len)) {
            r->header_lost = false;
            return;
        }
        fprintf(
            stderr,
            "%s:%d: malformed line '%.*s': a section header needs its closing ']', e.g. '%.*s]'\n",
            r->sc->file, r->line, (int)len, p, (int)len, p);
        r->header_lost = true;
    } else if (!memchr(p, '=', len) && !memchr(p, ':', len)) {
        const char* blank = p;
        while (blank < end && !isspace((unsigned char)*blank))
            blank++;
        const char* word = blank;
        while (word < end && isspace((unsigned char)*word))
            word++;
        if (word < end)
            fprintf(stderr,
                    "%s:%d: malformed line '%.*s': no '=': write 'key = value' (%.*s = %.*s?), a "
                    "[section] "
                    "header or a comment\n",
                    r->sc->file, r->line, (int)len, p, (int)(blank - p), p, (int)(end - word),
                    word);
        else
            fprintf(stderr,
                    "%s:%d: malformed line '%.*s': no '=': write 'key = value', a [section] header "
                    "or a "
                    "comment\n",
                    r->sc->file, r->line, (int)len, p);
    } else
        return;
    r->n_errors++;
    r->shape_line = r->line;
}

static char* read_line(char* str, int num, void* stream)
{
    struct reader* r = stream;
    ssize_t got = getline(&r->buf, &r->cap, r->f);
    if (got < 0) {
        if (ferror(r->f))
            r->read_errno = errno ? errno : EIO;
        return NULL;
    }
    r->line++;
    const char* text = r->buf;
    if (r->line == 1 && got >= 3 && memcmp(text, "\xef\xbb\xbf", 3) == 0) { /* a UTF-8 BOM */
        text += 3;
        got -= 3;
    }
    if (memchr(text, '\0', (size_t)got)) { /* a binary file: one message, not one a line */
        fprintf(stderr, "%s:%d: a NUL byte: not a text (INI) scenario file\n", r->sc->file,
                r->line);
        r->n_errors++;
        return NULL;
    }
    const char* cr = memchr(text, '\r', (size_t)got);
    size_t at = cr ? (size_t)(cr - text) : 0, n_got = (size_t)got;
    /* (CRLF, or a CR last in the file, ends a line; a CR inside one ends lines too) */
    if (cr && !(at + 1 == n_got || (at + 2 == n_got && text[at + 1] == '\n'))) {
        fprintf(stderr,
                "%s:%d: a carriage return inside the line: line endings of classic Mac OS (CR "
                "only)? convert them: tr '\\r' '\\n' < FILE > NEW\n",
                r->sc->file, r->line);
        r->n_errors++;
        return NULL;
    }
    size_t len = without_comment(text, (size_t)got);
    if (len + 2 > (size_t)num) { /* (room for "\n" and the terminating '\0') */
        fprintf(stderr, "%s:%d: line longer than %d characters without its comment\n", r->sc->file,
                r->line, num - 2);
        r->n_errors++;
        len = 0;
    }
    memcpy(str, text, len);
    str[len] = '\n';
    str[len + 1] = '\0';
    check_shape(r, str, len);
    note_section(r, str);
    return str;
}

static int on_pair(void* user, const char* section_as_read, const char* key, const char* value)
{
    struct reader* r = user;
    char v[CLI_VALUE_MAX];
    copy_text(v, sizeof v, value);
    strip_hash_comment(v);
    /* "[ fluid ]" is [fluid], as the section marks have it (note_section); inih keeps the
       spaces (its lines hold fewer than 256 characters) */
    if (r->header_lost) /* under a header without its ']': reported there */
        return 1;
    char section[256];
    copy_text(section, sizeof section, section_as_read);
    trim(section);
    if (section[0] == '\0') { /* (a header "[ ]" is reported as an unknown section []) */
        if (section_as_read[0] == '\0') {
            fprintf(stderr, "%s:%d: key '%s' comes before any [section]\n", r->sc->file, r->line,
                    key);
            r->n_errors++;
        }
        return 1;
    }
    if (strlen(section) >= CLI_NAME_MAX || strlen(key) >= CLI_NAME_MAX) {
        fprintf(stderr, "%s:%d: section or key name longer than %d characters\n", r->sc->file,
                r->line, CLI_NAME_MAX - 1);
        r->n_errors++;
        return 1;
    }
    if (push_entry(r->sc, section, key, v, r->line) != 0)
        r->out_of_memory = true;
    return 1;
}

int cli_scenario_load(const char* path, struct cli_scenario* sc)
{
    memset(sc, 0, sizeof *sc);
    copy_text(sc->file, sizeof sc->file, path);
    struct reader r = {.f = fopen(path, "r"), .sc = sc};
    if (!r.f) {
        cli_error("%s: cannot open scenario file: %s", path, strerror(errno));
        return CLI_EXIT_USAGE;
    }
    char head[4096]; /* a binary file: said so at once, not as a malformed line after another */
    size_t n_head = fread(head, 1, sizeof head, r.f);
    if (memchr(head, '\0', n_head)) {
        fclose(r.f);
        cli_error("%s: a NUL byte in its first %zu bytes: not a text (INI) scenario file", path,
                  n_head);
        return CLI_EXIT_USAGE;
    }
    rewind(r.f);
    int bad_line = ini_parse_stream(read_line, &r, on_pair, &r);
    fclose(r.f);
    free(r.buf);
    if (r.read_errno == ENOMEM || r.out_of_memory || bad_line == -2) {
        cli_error("%s: out of memory reading the scenario", path);
        return CLI_EXIT_RUNTIME;
    }
    if (r.read_errno) {
        cli_error("%s: cannot read scenario file: %s", path, strerror(r.read_errno));
        return CLI_EXIT_USAGE;
    }
    int rc = r.n_errors ? CLI_EXIT_USAGE : CLI_EXIT_OK;
    if (bad_line > 0 && bad_line > r.shape_line) { /* (those up to shape_line are reported) */
        fprintf(stderr,
                "%s:%d: malformed line: expected '[section]', 'key = value' or a "
                "comment\n",
                path, bad_line);
        rc = CLI_EXIT_USAGE;
    }
    if (check_all(sc) != CLI_EXIT_OK)
        rc = CLI_EXIT_USAGE;
    return rc;
}

/* ---- overrides ---- */

/* cli_override_split, with the messages naming `option`: "--set" for "a.b.c=value", or the
 * option that gave a key alone ("--param": text is "a.b.c=0", shown without its "=0"). */
static int split_key_value(const char* option, const char* text, char* section, char* key,
                           char* value)
{
    bool set = strcmp(option, "--set") == 0;
    const char* eq = strchr(text, '=');
    const char* dot = NULL;
    for (const char* p = text; eq && p < eq; p++)
        if (*p == '.')
            dot = p;
    int shown = set || !eq ? (int)strlen(text) : (int)(eq - text);
    if (!eq || !dot || dot == text || dot + 1 == eq) {
        cli_error("%s '%.*s': expected section.key%s, e.g. %s collision.stokes%s", option, shown,
                  text, set ? "=value" : "", option, set ? "=50" : "");
        return -1;
    }
    size_t slen = (size_t)(dot - text), klen = (size_t)(eq - dot - 1);
    if (slen >= CLI_NAME_MAX - 6 || klen >= CLI_NAME_MAX || strlen(eq + 1) >= CLI_VALUE_MAX - 1) {
        cli_error("%s '%.60s...': section, key or value too long", option, text);
        return -1;
    }
    memcpy(section, text, slen);
    section[slen] = '\0';
    memcpy(key, dot + 1, klen);
    key[klen] = '\0';
    trim(section); /* (as a file's "key = value" lines: --set "collision.stokes = 50") */
    trim(key);
    if (value) {
        copy_text(value, CLI_VALUE_MAX, eq + 1);
        trim(value);
    }
    struct cli_section_info info;
    const struct wetdem_model* model = wetdem_model_find(section);
    bool is_section = cli_section_lookup(section, &info) == 0;
    /* a model's library name, nijssen.cutoff_ratio: [model.nijssen] cutoff_ratio; also where
     * the model shares its name with a section that lacks the key (davis.below_hmin is the
     * davis model's, [davis] the pairwise engine's) */
    if (model &&
        (!is_section || (!section_has_key(&info, key) && wetdem_param_find(model->params, key)))) {
        memmove(section + 6, section, slen + 1); /* slen < CLI_NAME_MAX - 6 checked above */
        memcpy(section, "model.", 6);
    } else if (wetdem_integrator_params(section)) {
        /* the library's names of integrator parameters, cvode.rtol: [integrator] rtol */
        copy_text(section, CLI_NAME_MAX, "integrator");
    }
    return 0;
}

/* The families of named sections that are things of the scenario, each with its noun, and
 * [insert] (an insertion too: its keys are read only where the file has the section). The
 * first whose prefix a section starts with is its family. */
static const struct {
    const char* prefix;
    const char* noun;
} named_families[] = {{"material.", "a material"}, {"particle.", "a sphere"},
                      {"sphere.", "a sphere"},     {"insert.", "an insertion"},
                      {"insert", "an insertion"},  {"read.", "a read of a file"}};

int cli_override_split(const char* text, char* section, char* key, char* value)
{
    return split_key_value("--set", text, section, key, value);
}

int cli_key_split(const char* option, const char* name, char* section, char* key)
{
    char probe[CLI_VALUE_MAX];
    snprintf(probe, sizeof probe, "%s=0", name);
    return split_key_value(option, probe, section, key, NULL);
}

/* A --set of a named section the file does not define ([material.NAME], [particle.NAME],
 * [sphere.NAME], [insert.NAME], [read.NAME]) or of an [insert] it does not have would add an
 * entry that no section reads (a misspelt name; for a material, a preset's name, whose section
 * would start from the field defaults, not from the preset; an [insert] is built only where
 * the file has one): refused with the file's sections of that family as a hint. Returns an
 * exit code. */
static int new_named_section(const struct cli_scenario* sc, const char* key_value,
                             const char* section)
{
    size_t f = 0, n_families = sizeof named_families / sizeof named_families[0];
    while (f < n_families &&
           strncmp(section, named_families[f].prefix, strlen(named_families[f].prefix)) != 0)
        f++;
    if (f == n_families || cli_scenario_has_section(sc, section))
        return CLI_EXIT_OK;
    const char* prefix = named_families[f].prefix;
    const char* names[64];
    size_t n = 0;
    for (size_t k = 0; k < sc->n_sections && n + 1 < 64; k++)
        if (strncmp(sc->sections[k].name, prefix, strlen(prefix)) == 0)
            names[n++] = sc->sections[k].name;
    names[n] = NULL;
    const char* hint = wetdem_param_suggest(section, names);
    char also[256] = "";
    struct wetdem_material m;
    if (!hint && f == 0 && wetdem_material_preset(section + 9, &m) == WETDEM_OK)
        snprintf(also, sizeof also,
                 "; to change preset %s, give the file a [material.NAME] section with preset = %s "
                 "and use NAME",
                 section + 9, section + 9);
    /* (the form of every other error of a --set: "FILE: --set KEY=VALUE: why") */
    fprintf(stderr,
            "%s: --set %s: the file has no section [%s]%s%s%s%s; --set changes %s the file "
            "defines, it does not add one\n",
            sc->file, key_value, section, hint ? " (did you mean [" : "", hint ? hint : "",
            hint ? "]?)" : "", also, named_families[f].noun);
    return CLI_EXIT_USAGE;
}

/* A --set KEY=VALUE without a section, where exactly one section of the scenario's engine has
 * KEY: "did you mean 'SECTION.KEY=VALUE'?". Returns whether it said so. */
static bool bare_key_suggestion(const struct cli_scenario* sc, const char* key_value)
{
    const char* eq = strchr(key_value, '=');
    size_t klen = eq ? (size_t)(eq - key_value) : 0;
    char key[CLI_NAME_MAX], value[CLI_VALUE_MAX], home[CLI_NAME_MAX];
    if (!eq || klen == 0 || klen >= sizeof key || memchr(key_value, '.', klen))
        return false;
    memcpy(key, key_value, klen);
    key[klen] = '\0';
    copy_text(value, sizeof value, eq + 1);
    trim(value);
    if (!cli_is_name(key) || cli_key_only_home(sc, key, value, home, sizeof home) != 1)
        return false;
    cli_error("--set '%s': expected section.key=value (did you mean '%s.%s=%s'?)", key_value, home,
              key, value);
    return true;
}

int cli_scenario_override(struct cli_scenario* sc, const char* key_value)
{
    char section[CLI_NAME_MAX], key[CLI_NAME_MAX], value[CLI_VALUE_MAX];
    if (bare_key_suggestion(sc, key_value))
        return CLI_EXIT_USAGE;
    if (cli_override_split(key_value, section, key, value) != 0)
        return CLI_EXIT_USAGE;
    struct cli_section_info info;
    if (cli_section_lookup(section, &info) != 0) {
        char msg[256];
        cli_section_suggestion(section, msg, sizeof msg);
        cli_error("--set %s: unknown section [%s]%s", key_value, section, msg);
        return CLI_EXIT_USAGE;
    }
    if (new_named_section(sc, key_value, section) != CLI_EXIT_OK)
        return CLI_EXIT_USAGE;
    struct cli_entry probe = {.line = 0};
    copy_text(probe.section, sizeof probe.section, section);
    copy_text(probe.key, sizeof probe.key, key);
    copy_text(probe.value, sizeof probe.value, value);
    if (check_entry(sc, &probe) != CLI_EXIT_OK)
        return CLI_EXIT_USAGE;
    /* speed and stokes exclude each other: overriding one replaces the other */
    bool is_speed = strcmp(section, "collision") == 0 &&
                    (strcmp(key, "speed") == 0 || strcmp(key, "stokes") == 0);
    bool found = false;
    for (size_t k = 0; k < sc->n_entries; k++) {
        struct cli_entry* e = &sc->entries[k];
        if (strcmp(e->section, section) != 0)
            continue;
        if (strcmp(e->key, key) == 0) {
            *e = probe;
            found = true;
        } else if (is_speed && (strcmp(e->key, "speed") == 0 || strcmp(e->key, "stokes") == 0))
            copy_text(e->value, sizeof e->value, "0");
    }
    if (!found && push_entry(sc, section, key, value, 0) != 0) {
        cli_error("out of memory applying --set");
        return CLI_EXIT_RUNTIME;
    }
    return CLI_EXIT_OK;
}

/* ---- shared by run, sweep and fit ---- */

/* Warns (once a command) about a [material.NAME] named after a preset without preset = NAME:
 * a striker = NAME then takes the section, whose fields start from the field defaults, not
 * from the preset's (delrin's section with only a roughness ran at steel's density). */
static void warn_shadowed_presets(const struct cli_scenario* sc)
{
    for (size_t k = 0; k < sc->n_sections; k++) {
        const char* name = sc->sections[k].name;
        struct wetdem_material m;
        if (strncmp(name, "material.", 9) != 0 ||
            wetdem_material_preset(name + 9, &m) != WETDEM_OK ||
            cli_scenario_find(sc, name, "preset"))
            continue;
        cli_error("warning: %s:%d: [%s] has the name of a preset but no 'preset = %s': its "
                  "fields not given start from the field defaults (docs/scenarios.md), not from "
                  "the preset's; add the line to start from it",
                  sc->file, sc->sections[k].line, name, name + 9);
    }
}

static bool is_impact_key(const char* full)
{
    return strcmp(full, "collision.speed") == 0 || strcmp(full, "collision.stokes") == 0;
}

int cli_keys_clash(const char* a, const char* b)
{
    return strcmp(a, b) == 0 ? 1 : is_impact_key(a) && is_impact_key(b) ? 2 : 0;
}

/* cli_keys_clash of two --set overrides, already applied (so they split). */
static int same_override_key(const char* a, const char* b)
{
    char sa[CLI_NAME_MAX], ka[CLI_NAME_MAX], sb[CLI_NAME_MAX], kb[CLI_NAME_MAX];
    if (cli_override_split(a, sa, ka, NULL) != 0 || cli_override_split(b, sb, kb, NULL) != 0)
        return 0;
    char full_a[2 * CLI_NAME_MAX + 2], full_b[2 * CLI_NAME_MAX + 2];
    snprintf(full_a, sizeof full_a, "%s.%s", sa, ka);
    snprintf(full_b, sizeof full_b, "%s.%s", sb, kb);
    return cli_keys_clash(full_a, full_b);
}

/* Loads the file and applies the overrides; two of one key are refused, as a key given twice
 * in the file is: the later replaced the earlier unseen. */
int cli_load_with_overrides(const char* file, const char* const* sets, int n_sets,
                            struct cli_scenario* sc)
{
    int rc = cli_scenario_load(file, sc);
    for (int k = 0; rc == CLI_EXIT_OK && k < n_sets; k++) {
        rc = cli_scenario_override(sc, sets[k]);
        for (int j = 0; rc == CLI_EXIT_OK && j < k; j++) {
            int clash = same_override_key(sets[j], sets[k]);
            if (!clash)
                continue;
            cli_error("%s: --set %s and --set %s set one key%s: give it once", file, sets[j],
                      sets[k], clash == 2 ? CLI_IMPACT_CLASH : "");
            rc = CLI_EXIT_USAGE;
        }
    }
    if (rc == CLI_EXIT_OK && sc->n_sections == 0 && sc->n_entries == 0) { /* (no --set) */
        cli_error("%s: no [section] in the file: a scenario has [section] headers and "
                  "'key = value' lines (docs/scenarios.md)",
                  file);
        rc = CLI_EXIT_USAGE;
    }
    if (rc == CLI_EXIT_OK)
        warn_shadowed_presets(sc);
    return rc;
}

int cli_check_numeric_key(const char* cmd, const char* option, const char* tok, const char* section,
                          const char* key, const char* verb)
{
    struct cli_section_info info;
    char msg[512] = "";
    if (cli_section_lookup(section, &info) != 0) {
        const char* hint = strchr(section, '.') ? NULL : cli_model_suggestion(section);
        if (hint)
            snprintf(msg, sizeof msg, " (did you mean '%s.%s'?)", hint, key);
        else
            cli_section_suggestion(section, msg, sizeof msg);
        cli_error("%s: %s %s: unknown section [%s]%s", cmd, option, tok, section, msg);
        return CLI_EXIT_USAGE;
    }
    const char* names[128];
    size_t n = 0;
    for (size_t k = 0; info.desc->keys && info.desc->keys[k].key && n + 1 < 128; k++) {
        const struct cli_key_desc* d = &info.desc->keys[k];
        if (strcmp(d->key, key) == 0 && d->kind != CLI_VALUE_NUMBER) {
            cli_error("%s: %s %s: [%s] %s takes a word, not a number; only numeric keys "
                      "can be %s",
                      cmd, option, tok, section, key, verb);
            return CLI_EXIT_USAGE;
        }
        if (strcmp(d->key, key) == 0)
            return CLI_EXIT_OK;
        names[n++] = d->key;
    }
    for (size_t k = 0; info.lib_keys && info.lib_keys[k].name && n + 1 < 128; k++) {
        const struct wetdem_param_desc* d = &info.lib_keys[k];
        if (strcmp(d->name, key) == 0 && d->choices) {
            cli_error("%s: %s %s: [%s] %s is a choice, not a number; only numeric "
                      "parameters can be %s",
                      cmd, option, tok, section, key, verb);
            return CLI_EXIT_USAGE;
        }
        if (strcmp(d->name, key) == 0)
            return CLI_EXIT_OK;
        names[n++] = d->name;
    }
    if (info.open_keys)
        return CLI_EXIT_OK;
    names[n] = NULL;
    const char* hint = wetdem_param_suggest(key, names);
    if (hint)
        snprintf(msg, sizeof msg, " (did you mean '%s'?)", hint);
    cli_error("%s: %s %s: unknown key '%s' in [%s]%s; 'wetdem describe' lists a model's "
              "parameters, docs/scenarios.md the scenario keys",
              cmd, option, tok, key, section, msg);
    return CLI_EXIT_USAGE;
}

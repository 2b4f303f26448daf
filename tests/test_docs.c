/*
 * test_docs.c — docs/models.md is the output of `wetdem docs-models` (the generated model
 * reference must not go stale), and it has a section for every model of the registry;
 * docs/cli.md is the output of `wetdem docs-cli` (every command's --help).
 *
 * What a user copies from README.md and docs/ works (test_docs_snippets_work):
 *   - every ```ini block passes `wetdem run FILE --check`; a block fenced ```ini fragment
 *     (a part of a scenario) has only known sections and keys;
 *   - every `wetdem COMMAND ...` line, in ```sh and unlabelled blocks and in inline code,
 *     names a command that exists and options that its --help lists; every --set KEY=VALUE,
 *     --param KEY and --fit KEY names a scenario key or model parameter; a line that runs a
 *     shipped scenario passes `wetdem run FILE --check` with its --set overrides and the first
 *     value of each --param;
 *   - every `make TARGET` is a target of the Makefile, and every scripts/, bench/, tools/,
 *     figures/ and examples/ path of a command line exists;
 *   - an inline `[section] key` names a known section and key.
 * A failure names the page and line. Not checked: docs/cli.md (generated, above) and
 * docs/performance-history.md (records of earlier versions, with the options they had).
 *
 * The CLI path comes from WETDEM_CLI (set by `make test`), falling back to build/wetdem; the
 * working directory is the repository root. On failure: run `make docs` and commit the file.
 */
#include <ctype.h>
#include <unistd.h>

#include "harness.h"

/* The output of `wetdem COMMAND` (docs-models, docs-cli). */
static char* generated_docs(const char* command)
{
    struct test_run r = test_run_cli("", command, false);
    if (r.code != 0)
        fail_msg("'%s %s' failed (exit %d)", test_cli_path(), command, r.code);
    return r.out;
}

static char* committed_docs(const char* path)
{
    char* text = test_read_file(path, NULL);
    if (!text)
        fail_msg("%s not found (the working directory must be the repository root; create "
                 "the file with 'make docs')",
                 path);
    return text;
}

/* Start of the line that contains p, in text. */
static const char* line_start(const char* text, const char* p)
{
    while (p > text && p[-1] != '\n')
        p--;
    return p;
}

/* Fails with the first line where the committed and generated texts differ. */
static void check_same_text(const char* path, const char* committed, const char* generated)
{
    size_t k = 0, line = 1;
    while (committed[k] && committed[k] == generated[k]) {
        if (committed[k] == '\n')
            line++;
        k++;
    }
    if (committed[k] == generated[k])
        return;
    const char* a = line_start(committed, committed + k);
    const char* b = line_start(generated, generated + k);
    fail_msg("%s is stale at line %zu (run 'make docs' and commit it):\n"
             "  committed: %.*s\n  generated: %.*s",
             path, line, (int)strcspn(a, "\n"), a, (int)strcspn(b, "\n"), b);
}

static void test_docs_models_md_is_fresh(void** state)
{
    (void)state;
    char* gen = generated_docs("docs-models");
    char* doc = committed_docs("docs/models.md");
    check_same_text("docs/models.md", doc, gen);
    free(gen);
    free(doc);
}

static void test_docs_cli_md_is_fresh(void** state)
{
    (void)state;
    char* gen = generated_docs("docs-cli");
    char* doc = committed_docs("docs/cli.md");
    check_same_text("docs/cli.md", doc, gen);
    free(gen);
    free(doc);
}

/* Every command of `wetdem --help` has its section in docs/cli.md, and every option the
 * map and fit parsers accept is explained there (they were once only in the usage line). */
static void test_docs_cli_md_covers_commands(void** state)
{
    (void)state;
    char* doc = committed_docs("docs/cli.md");
    const char* names[] = {"models",  "describe", "forces", "run",         "sweep",
                           "map",     "fit",      "track",  "docs-models", "docs-scenarios",
                           "docs-cli"};
    for (size_t k = 0; k < sizeof names / sizeof names[0]; k++) {
        char heading[64];
        snprintf(heading, sizeof heading, "\n## wetdem %s\n", names[k]);
        CHECK_CONTAINS(doc, heading);
    }
    CHECK_CONTAINS(doc, "--log2: geometric");
    CHECK_CONTAINS(doc, "  --values2 A:B:N");
    CHECK_CONTAINS(doc, "  --curve FILE");
    free(doc);
}

static void test_docs_models_md_covers_registry(void** state)
{
    (void)state;
    char* doc = committed_docs("docs/models.md");
    const struct wetdem_model* const* reg = wetdem_model_registry();
    for (size_t k = 0; reg[k]; k++) {
        char anchor[128];
        snprintf(anchor, sizeof anchor, "<a id=\"model-%s\"></a>", reg[k]->name);
        CHECK_CONTAINS(doc, anchor);
    }
    CHECK_CONTAINS(doc, "## Material presets");
    free(doc);
}

/* ---- snippets of the docs that a user copies ---- */

#define WORD_MAX 512
#define WORDS_MAX 96

/* What the snippets are checked against, read once. */
struct doc_context {
    char* main_help; /* wetdem --help */
    char* tables;    /* wetdem docs-scenarios: a "### `[section]`" heading, then "| `key` |" rows */
    char* makefile;
    char* help_names[32];
    char* helps[32]; /* wetdem COMMAND --help, as asked for */
    size_t n_helps;
};

/* Every problem found, one line each, "PAGE:LINE: what". */
struct doc_report {
    char* text;
    size_t len, cap;
    int count;
};

/* Where a snippet is: the page and the line it starts on. */
struct doc_place {
    const char* page;
    int line;
};

static void report_add(struct doc_report* r, struct doc_place at, const char* fmt, ...)
{
    char msg[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    size_t need = r->len + strlen(at.page) + strlen(msg) + 32;
    if (need > r->cap) {
        r->cap = 2 * need;
        r->text = realloc(r->text, r->cap);
        assert_non_null(r->text);
    }
    r->len += (size_t)sprintf(r->text + r->len, "%s:%d: %s\n", at.page, at.line, msg);
    r->count++;
}

/* The --help of a command, from the cache (NULL for an unknown command). */
static const char* command_help(struct doc_context* ctx, const char* command)
{
    for (size_t k = 0; k < ctx->n_helps; k++)
        if (strcmp(ctx->help_names[k], command) == 0)
            return ctx->helps[k];
    char listed[WORD_MAX + 16];
    snprintf(listed, sizeof listed, "\n  wetdem %s", command);
    const char* p = strstr(ctx->main_help, listed);
    if (!p || (p[strlen(listed)] != ' ' && p[strlen(listed)] != '\n') ||
        ctx->n_helps == sizeof ctx->helps / sizeof ctx->helps[0])
        return NULL;
    char args[WORD_MAX + 16];
    snprintf(args, sizeof args, "%s --help", command);
    struct test_run r = test_run_cli("", args, true);
    ctx->help_names[ctx->n_helps] = strdup(command);
    assert_non_null(ctx->help_names[ctx->n_helps]);
    ctx->helps[ctx->n_helps] = r.out;
    return ctx->helps[ctx->n_helps++];
}

static bool is_option_char(char c)
{
    return isalnum((unsigned char)c) || c == '-';
}

/* Whether the help text lists option opt ("--log" is not found in "--log2"). */
static bool help_has_option(const char* help, const char* opt)
{
    size_t n = strlen(opt);
    for (const char* p = strstr(help, opt); p; p = strstr(p + 1, opt))
        if ((p == help || !is_option_char(p[-1])) && !is_option_char(p[n]))
            return true;
    return false;
}

/* Whether the docs-scenarios tables give section (e.g. "collision", "material.NAME") the key;
 * false also when the section has no table. */
static bool table_has_key(const char* tables, const char* section, const char* key)
{
    char heading[WORD_MAX + 16], row[WORD_MAX + 16];
    snprintf(heading, sizeof heading, "### `[%s]`\n", section);
    snprintf(row, sizeof row, "\n| `%s` |", key);
    const char* start = strstr(tables, heading);
    if (!start)
        return false;
    const char* end = strstr(start + 1, "\n### ");
    const char* hit = strstr(start, row);
    return hit && (!end || hit < end);
}

/* The table of a section: itself, or its family's for a named one ("material.steel" is
 * "material.NAME"); "" when there is none. */
static void table_of_section(const char* tables, const char* section, char* out, size_t n)
{
    char heading[WORD_MAX + 16];
    snprintf(heading, sizeof heading, "### `[%s]`\n", section);
    if (strstr(tables, heading)) {
        snprintf(out, n, "%s", section);
        return;
    }
    const char* dot = strchr(section, '.');
    snprintf(out, n, "%.*s.NAME", dot ? (int)(dot - section) : 0, section);
    snprintf(heading, sizeof heading, "### `[%s]`\n", out);
    if (!dot || !strstr(tables, heading))
        out[0] = '\0';
}

/* Whether [section] key is a key of a scenario file: one of the section's table, or of the
 * model of a [model.NAME] section. */
static bool scenario_key_known(const char* tables, const char* section, const char* key)
{
    if (strncmp(section, "model.", 6) == 0) {
        const struct wetdem_model* m = wetdem_model_find(section + 6);
        return strcmp(section + 6, "NAME") == 0 || (m && wetdem_param_find(m->params, key));
    }
    char table[WORD_MAX];
    table_of_section(tables, section, table, sizeof table);
    return table[0] && table_has_key(tables, table, key);
}

/* Whether a dotted name (--set, --param, --fit) is a scenario key ("collision.stokes",
 * "material.soft.roughness", "model.nijssen.cutoff_ratio") or a parameter by its library
 * name ("nijssen.cutoff_ratio", "cvode.rtol"). */
static bool dotted_name_known(const char* tables, const char* name)
{
    const char* dot = strrchr(name, '.');
    if (!dot || dot == name || !dot[1])
        return false;
    char section[WORD_MAX];
    snprintf(section, sizeof section, "%.*s", (int)(dot - name), name);
    const char* key = dot + 1;
    const struct wetdem_model* m = wetdem_model_find(section);
    const struct wetdem_param_desc* integrator = wetdem_integrator_params(section);
    return scenario_key_known(tables, section, key) || (m && wetdem_param_find(m->params, key)) ||
           (integrator && wetdem_param_find(integrator, key));
}

static bool has_upper(const char* s)
{
    for (; *s; s++)
        if (isupper((unsigned char)*s))
            return true;
    return false;
}

/* The words of a command line as the shell splits these docs' lines: blanks separate, quotes
 * group and are removed, a run of | ; & < > is a word of its own (an operator), and a word
 * that starts with '#' ends the line (a comment). The brackets of an optional part
 * ("[--init 4e6]") are dropped. Returns the number of words. */
static size_t shell_words(const char* line, char words[][WORD_MAX], size_t cap)
{
    size_t n = 0;
    const char* p = line;
    while (n < cap) {
        while (*p == ' ' || *p == '\t')
            p++;
        if (!*p || *p == '#')
            break;
        size_t len = 0;
        char quote = 0;
        if (strchr("|;&<>", *p))
            while (*p && strchr("|;&<>", *p) && len + 1 < WORD_MAX)
                words[n][len++] = *p++;
        else
            for (; *p && (quote || !strchr(" \t|;&<>", *p)); p++)
                if (quote ? *p == quote : (*p == '"' || *p == '\''))
                    quote = quote ? 0 : *p;
                else if (len + 1 < WORD_MAX)
                    words[n][len++] = *p;
        while (len && words[n][len - 1] == ']')
            len--;
        words[n][len] = '\0';
        size_t skip = strspn(words[n], "[");
        memmove(words[n], words[n] + skip, len - skip + 1);
        if (words[n][0])
            n++;
    }
    return n;
}

static bool is_operator(const char* word)
{
    return strchr("|;&<>", word[0]) != NULL;
}

static bool is_wetdem(const char* word)
{
    size_t n = strlen(word);
    return strcmp(word, "wetdem") == 0 || (n > 7 && strcmp(word + n - 7, "/wetdem") == 0);
}

/* A path of the repository that a command reads: it must exist. Patterns and placeholders
 * (upper case, as in examples/NN_topic) are not paths. */
static void check_path(struct doc_place at, const char* word, struct doc_report* r)
{
    static const char* const dirs[] = {"scripts/", "bench/", "tools/", "figures/", "examples/"};
    bool in_repo = false;
    for (size_t k = 0; k < sizeof dirs / sizeof dirs[0]; k++)
        in_repo = in_repo || strncmp(word, dirs[k], strlen(dirs[k])) == 0;
    if (in_repo && !strpbrk(word, "*?<$") && !has_upper(word) && access(word, F_OK) != 0)
        report_add(r, at, "%s: no such file in the repository", word);
}

/* Whether --set KEY=VALUE is a pattern, not a setting: section.key=value, name=value, K=V. */
static bool is_placeholder_set(const char* key, const char* value)
{
    return has_upper(key) || strncmp(value, "value", 5) == 0;
}

/* Checks a --set KEY=VALUE (placeholders such as section.key=value and K=V are skipped). */
static void check_set(struct doc_place at, const char* kv, const struct doc_context* ctx,
                      struct doc_report* r)
{
    const char* eq = strchr(kv, '=');
    if (strncmp(kv, "...", 3) == 0)
        return; /* "--set ...", as in a message's pattern */
    if (!eq) {
        report_add(r, at, "--set %s: expected KEY=VALUE", kv);
        return;
    }
    char key[WORD_MAX];
    snprintf(key, sizeof key, "%.*s", (int)(eq - kv), kv);
    if (is_placeholder_set(key, eq + 1))
        return;
    if (!dotted_name_known(ctx->tables, key))
        report_add(r, at,
                   "--set %s: '%s' is no scenario key or model parameter "
                   "(wetdem docs-scenarios, docs/models.md)",
                   kv, key);
}

/* Checks the KEY[,KEY...] of --param, --param2 or --fit. */
static void check_key_list(struct doc_place at, const char* opt, const char* keys,
                           const struct doc_context* ctx, struct doc_report* r)
{
    char key[WORD_MAX];
    for (const char* p = keys; *p;) {
        size_t len = strcspn(p, ",");
        snprintf(key, sizeof key, "%.*s", (int)len, p);
        if (key[0] && !has_upper(key) && !dotted_name_known(ctx->tables, key))
            report_add(r, at, "%s %s: '%s' is no scenario key or model parameter", opt, keys, key);
        p += len + (p[len] == ',');
    }
}

static bool is_output_option(const char* word)
{
    return strcmp(word, "--out") == 0 || strcmp(word, "--curve") == 0 ||
           strcmp(word, "--frames") == 0 || strcmp(word, "--png") == 0;
}

/* Appends " --set 'KEY=VALUE'" to a command line being built; false if it cannot be quoted. */
static bool add_override(char* args, size_t n, const char* key, const char* value)
{
    if (strchr(key, '\'') || strchr(value, '\''))
        return false;
    size_t len = strlen(args);
    snprintf(args + len, n - len, " --set '%s=%s'", key, value);
    return true;
}

/* What a wetdem command line sets: its --set overrides (quoted for the shell, for `run
 * --check`), and the keys it varies or fits with their values (--param/--values,
 * --param2/--values2, --fit/--init). */
struct command_settings {
    char overrides[2048];
    const char* key[3];
    const char* value[3];
};

/* Takes the value of opt into s; false if opt takes no value that is checked. */
static bool note_setting(struct command_settings* s, const char* opt, const char* value)
{
    static const char* const key_opts[] = {"--param", "--param2", "--fit"};
    static const char* const value_opts[] = {"--values", "--values2", "--init"};
    for (int k = 0; k < 3; k++) {
        if (strcmp(opt, key_opts[k]) == 0)
            s->key[k] = value;
        else if (strcmp(opt, value_opts[k]) == 0)
            s->value[k] = value;
        else
            continue;
        return true;
    }
    const char* eq = strchr(value, '=');
    if (strcmp(opt, "--set") != 0)
        return false;
    char key[WORD_MAX];
    snprintf(key, sizeof key, "%.*s", eq ? (int)(eq - value) : 0, value);
    if (eq && !is_placeholder_set(key, eq + 1) && strcmp(eq + 1, "...") != 0)
        add_override(s->overrides, sizeof s->overrides, key, eq + 1);
    return true;
}

/* `wetdem run FILE --check` with the line's overrides, for a line that names a shipped
 * scenario (run, sweep, map, fit); a sweep's or fit's key takes its first value. */
static void check_scenario_line(struct doc_place at, const char* command, const char* file,
                                const struct command_settings* s, struct doc_report* r)
{
    size_t n = strlen(file);
    if (!strstr(" run sweep map fit ", command) || strncmp(file, "examples/", 9) != 0 || n < 4 ||
        strcmp(file + n - 4, ".ini") != 0 || access(file, F_OK) != 0)
        return;
    char args[3072], value[WORD_MAX];
    snprintf(args, sizeof args, "run '%s' --check%s", file, s->overrides);
    for (int k = 0; k < 3; k++) {
        if (!s->key[k] || !s->value[k] || has_upper(s->value[k]))
            continue;
        snprintf(value, sizeof value, "%.*s", (int)strcspn(s->value[k], ":,"), s->value[k]);
        if (!add_override(args, sizeof args, s->key[k], value))
            return;
    }
    struct test_run run = test_run_cli("", args, true);
    if (run.code != 0)
        report_add(r, at, "the scenario of this line does not check: 'wetdem %s' exits %d: %.*s",
                   args, run.code, (int)strcspn(run.out, "\n"), run.out);
    free(run.out);
}

/* Checks the option words[k] of a `wetdem COMMAND` line and, for --set, --param, --fit and
 * their values, the word after it. Returns the index of the last word it took. */
static size_t check_option(struct doc_place at, const char* command, const char* help,
                           char words[][WORD_MAX], size_t n, size_t k, struct doc_context* ctx,
                           struct command_settings* s, struct doc_report* r)
{
    char opt[WORD_MAX];
    snprintf(opt, sizeof opt, "%.*s", (int)strcspn(words[k], "="), words[k]);
    if (strcmp(opt, "--help") != 0 && !help_has_option(help, opt))
        report_add(r, at, "wetdem %s: unknown option %s (see 'wetdem %s --help')", command, opt,
                   command);
    if (k + 1 >= n || strchr(words[k], '=') || strncmp(words[k + 1], "--", 2) == 0 ||
        !note_setting(s, opt, words[k + 1]))
        return k;
    if (strcmp(opt, "--set") == 0)
        check_set(at, words[k + 1], ctx, r);
    else if (!strcmp(opt, "--param") || !strcmp(opt, "--param2") || !strcmp(opt, "--fit"))
        check_key_list(at, opt, words[k + 1], ctx, r);
    return k + 1;
}

/* Checks "wetdem COMMAND ARGS" (words: COMMAND ARGS): the command, every option, every --set
 * and key, the paths it reads, and the shipped scenario it names. */
static void check_wetdem_command(struct doc_place at, char words[][WORD_MAX], size_t n,
                                 struct doc_context* ctx, struct doc_report* r)
{
    if (n == 0 || (!islower((unsigned char)words[0][0]) && words[0][0] != '-'))
        return; /* "wetdem", a placeholder (COMMAND, <name>) or the version */
    bool global = words[0][0] == '-';
    const char* command = global ? "" : words[0];
    const char* help = global ? ctx->main_help : command_help(ctx, command);
    if (!help) {
        report_add(r, at, "wetdem %s: no such command (see 'wetdem --help')", command);
        return;
    }
    struct command_settings s = {.overrides = ""};
    for (size_t k = global ? 0 : 1; k < n; k++) {
        if (strncmp(words[k], "--", 2) == 0)
            k = check_option(at, command, help, words, n, k, ctx, &s, r);
        else if (!is_output_option(words[k - (k > 0)]))
            check_path(at, words[k], r);
    }
    if (n > 1)
        check_scenario_line(at, command, words[1], &s, r);
}

/* Checks "make ARGS": every target is one of the Makefile. */
static void check_make(struct doc_place at, char words[][WORD_MAX], size_t n,
                       const struct doc_context* ctx, struct doc_report* r)
{
    for (size_t k = 0; k < n; k++) {
        if (words[k][0] == '-' || strchr(words[k], '=') || has_upper(words[k]))
            continue;
        char rule[WORD_MAX + 4];
        snprintf(rule, sizeof rule, "\n%s:", words[k]);
        if (!strstr(ctx->makefile, rule))
            report_add(r, at, "make %s: no such target in the Makefile", words[k]);
    }
}

/* Checks one command line (a fenced line with its continuations, or inline code): each
 * wetdem and make command in it, a --set outside them, and the repository paths. */
static void check_command_line(struct doc_place at, const char* line, struct doc_context* ctx,
                               struct doc_report* r)
{
    static char words[WORDS_MAX][WORD_MAX];
    size_t n = shell_words(line, words, WORDS_MAX);
    for (size_t k = 0; k < n; k++) {
        size_t end = k + 1;
        while (end < n && !is_operator(words[end]))
            end++;
        if (is_wetdem(words[k]) || strcmp(words[k], "make") == 0) {
            if (is_wetdem(words[k]))
                check_wetdem_command(at, words + k + 1, end - k - 1, ctx, r);
            else
                check_make(at, words + k + 1, end - k - 1, ctx, r);
            k = end;
        } else if (strcmp(words[k], "--set") == 0 && k + 1 < end)
            check_set(at, words[++k], ctx, r);
        else if (k == 0 || !is_output_option(words[k - 1]))
            check_path(at, words[k], r);
    }
}

/* The name in "[name]" at s (copied into out), and the rest after the ']'; NULL if s does not
 * start with a header. */
static const char* ini_header(const char* s, char* out, size_t n)
{
    const char* close = s[0] == '[' ? strchr(s, ']') : NULL;
    if (!close || close == s + 1)
        return NULL;
    snprintf(out, n, "%.*s", (int)(close - s - 1), s + 1);
    for (char* c = out; *c; c++)
        if (!(islower((unsigned char)*c) || isdigit((unsigned char)*c) || strchr("._NAME", *c)))
            return NULL;
    return close + 1;
}

static bool section_known(const char* tables, const char* section)
{
    char table[WORD_MAX];
    if (strncmp(section, "model.", 6) == 0)
        return strcmp(section + 6, "NAME") == 0 || wetdem_model_find(section + 6);
    table_of_section(tables, section, table, sizeof table);
    return table[0] != '\0';
}

/* Checks the lines of an ```ini fragment: every section is known, every key one of its
 * section. */
static void check_ini_fragment(const char* page, char** lines, size_t first, size_t end,
                               const struct doc_context* ctx, struct doc_report* r)
{
    char section[WORD_MAX] = "", key[WORD_MAX];
    bool known = false; /* (the keys of an unknown section are not reported again) */
    for (size_t k = first; k < end; k++) {
        struct doc_place at = {page, (int)k + 1};
        const char* s = lines[k] + strspn(lines[k], " \t");
        size_t len = strcspn(s, ";#");
        if (ini_header(s, section, sizeof section)) {
            known = section_known(ctx->tables, section);
            if (!known)
                report_add(r, at, "[%s]: no such section (wetdem docs-scenarios)", section);
        } else if (memchr(s, '=', len) && (known || !section[0])) {
            snprintf(key, sizeof key, "%.*s", (int)strcspn(s, " \t="), s);
            if (!section[0] || !scenario_key_known(ctx->tables, section, key))
                report_add(r, at, "[%s] %s: no such key (wetdem docs-scenarios)", section, key);
        }
    }
}

/* Checks a whole ```ini block: it is a scenario that `wetdem run FILE --check` accepts. */
static void check_ini_scenario(const char* page, char** lines, size_t first, size_t end,
                               struct doc_report* r)
{
    size_t indent = strspn(lines[first - 1], " "); /* that of the fence (in a list item) */
    char dir[] = "/tmp/wetdem_docs_XXXXXX", path[64], args[128];
    assert_non_null(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/snippet.ini", dir);
    FILE* f = fopen(path, "w");
    assert_non_null(f);
    for (size_t k = first; k < end; k++)
        fprintf(f, "%s\n", lines[k] + (strspn(lines[k], " ") < indent ? 0 : indent));
    assert_int_equal(fclose(f), 0);
    snprintf(args, sizeof args, "run '%s' --check", path);
    struct test_run run = test_run_cli("", args, true);
    /* the message names the line of the file ("PATH:3: ..."): the page's line of it */
    size_t path_len = strlen(path);
    int line = 0;
    const char* message = run.out;
    if (strncmp(run.out, path, path_len) == 0 && sscanf(run.out + path_len, ":%d:", &line) == 1)
        message = strchr(run.out + path_len + 1, ':') + 1;
    if (run.code != 0)
        report_add(r, (struct doc_place){page, (int)first + line},
                   "the ```ini block fails 'wetdem run FILE --check' (exit %d; fence a part of a "
                   "scenario as ```ini fragment):%.*s",
                   run.code, (int)strcspn(message, "\n"), message);
    free(run.out);
    unlink(path);
    rmdir(dir);
}

/* Checks the command lines of a ```sh or unlabelled block, joining continued lines. */
static void check_shell_block(const char* page, char** lines, size_t first, size_t end,
                              struct doc_context* ctx, struct doc_report* r)
{
    char line[8192];
    for (size_t k = first; k < end; k++) {
        struct doc_place at = {page, (int)k + 1};
        line[0] = '\0';
        for (; k < end; k++) {
            const char* s = lines[k] + strspn(lines[k], " \t");
            size_t len = strlen(s), used = strlen(line);
            bool continued = len > 0 && s[len - 1] == '\\';
            snprintf(line + used, sizeof line - used, "%.*s ", (int)(len - continued), s);
            if (!continued)
                break;
        }
        check_command_line(at, line, ctx, r);
    }
}

/* Checks a fenced block: lines[open] is its opening fence, lines[end] its closing one. */
static void check_fenced_block(const char* page, char** lines, size_t open, size_t end,
                               struct doc_context* ctx, struct doc_report* r)
{
    char info[64];
    const char* s = lines[open] + strspn(lines[open], " \t") + 3;
    snprintf(info, sizeof info, "%s", s + strspn(s, " "));
    for (size_t len = strlen(info); len && isspace((unsigned char)info[len - 1]);)
        info[--len] = '\0';
    if (strcmp(info, "ini") == 0)
        check_ini_scenario(page, lines, open + 1, end, r);
    else if (strcmp(info, "ini fragment") == 0)
        check_ini_fragment(page, lines, open + 1, end, ctx, r);
    else if (strcmp(info, "sh") == 0 || info[0] == '\0')
        check_shell_block(page, lines, open + 1, end, ctx, r);
}

/* Checks one span of inline code: a command line, or "[section] key". */
static void check_inline_code(struct doc_place at, const char* code, struct doc_context* ctx,
                              struct doc_report* r)
{
    char section[WORD_MAX], key[WORD_MAX];
    const char* rest = ini_header(code, section, sizeof section);
    if (!rest) {
        check_command_line(at, code, ctx, r);
        return;
    }
    if (*rest != ' ' || strcmp(section, "section") == 0)
        return;
    rest += strspn(rest, " ");
    snprintf(key, sizeof key, "%.*s", (int)strspn(rest, "abcdefghijklmnopqrstuvwxyz0123456789_"),
             rest);
    if (!key[0] || strncmp(section, "model.", 6) == 0)
        return;
    if (!section_known(ctx->tables, section))
        report_add(r, at, "`%s`: no section [%s] (wetdem docs-scenarios)", code, section);
    else if (!scenario_key_known(ctx->tables, section, key))
        report_add(r, at, "`%s`: no key %s in [%s] (wetdem docs-scenarios)", code, key, section);
}

static bool is_fence(const char* line)
{
    return strncmp(line + strspn(line, " \t"), "```", 3) == 0;
}

/* Checks the inline code of a prose line; a span may go on over the next lines (until a blank
 * line): *open says whether one is open, span holds it so far and *span_line its line. */
static void check_prose_line(const char* page, int line, const char* text, char* span,
                             size_t span_size, bool* open, int* span_line, struct doc_context* ctx,
                             struct doc_report* r)
{
    if (text[strspn(text, " \t")] == '\0') {
        *open = false;
        return;
    }
    for (const char* p = text; *p; p++) {
        size_t len = strlen(span);
        if (*p == '`' && *open)
            check_inline_code((struct doc_place){page, *span_line}, span, ctx, r);
        if (*p == '`') {
            *open = !*open;
            span[0] = '\0';
            *span_line = line;
        } else if (*open && len + 1 < span_size) {
            span[len] = *p;
            span[len + 1] = '\0';
        }
    }
    size_t len = strlen(span);
    if (*open && len + 1 < span_size)
        strcpy(span + len, " ");
}

/* Checks every snippet of one page. */
static void check_page(const char* page, struct doc_context* ctx, struct doc_report* r)
{
    char* text = test_read_file(page, NULL);
    if (!text)
        fail_msg("%s not found (the working directory must be the repository root)", page);
    size_t n = 1;
    for (const char* p = text; *p; p++)
        n += *p == '\n';
    char** lines = malloc(n * sizeof *lines);
    assert_non_null(lines);
    n = 0;
    lines[n++] = text;
    for (char* p = text; *p; p++)
        if (*p == '\n') {
            *p = '\0';
            lines[n++] = p + 1;
        }
    char span[4096] = "";
    bool open = false;
    int span_line = 0;
    for (size_t k = 0; k < n; k++) {
        if (!is_fence(lines[k])) {
            check_prose_line(page, (int)k + 1, lines[k], span, sizeof span, &open, &span_line, ctx,
                             r);
            continue;
        }
        size_t end = k + 1;
        while (end < n && !is_fence(lines[end]))
            end++;
        check_fenced_block(page, lines, k, end, ctx, r);
        open = false;
        k = end;
    }
    free(lines);
    free(text);
}

/* Appends the Markdown pages of dir to pages (paths, heap), except the two not checked. */
static size_t list_pages(const char* dir, char** pages, size_t n, size_t cap)
{
    struct dirent** names = NULL;
    int count = scandir(dir, &names, NULL, alphasort);
    assert_true(count >= 0);
    for (int k = 0; k < count; k++) {
        const char* name = names[k]->d_name;
        size_t len = strlen(name);
        if (len > 3 && strcmp(name + len - 3, ".md") == 0 && strcmp(name, "cli.md") != 0 &&
            strcmp(name, "performance-history.md") != 0 && n < cap) {
            pages[n] = malloc(strlen(dir) + len + 2);
            assert_non_null(pages[n]);
            sprintf(pages[n++], "%s/%s", dir, name);
        }
        free(names[k]);
    }
    free(names);
    return n;
}

static void test_docs_snippets_work(void** state)
{
    (void)state;
    struct doc_context ctx = {.main_help = generated_docs("--help"),
                              .tables = generated_docs("docs-scenarios"),
                              .makefile = committed_docs("Makefile")};
    char* pages[64] = {strdup("README.md")};
    assert_non_null(pages[0]);
    size_t n = list_pages("docs", pages, 1, 64);
    n = list_pages("docs/derivations", pages, n, 64);
    assert_true(n > 10); /* README and the docs were found */
    struct doc_report report = {NULL, 0, 0, 0};
    for (size_t k = 0; k < n; k++) {
        check_page(pages[k], &ctx, &report);
        free(pages[k]);
    }
    for (size_t k = 0; k < ctx.n_helps; k++) {
        free(ctx.help_names[k]);
        free(ctx.helps[k]);
    }
    free(ctx.main_help);
    free(ctx.tables);
    free(ctx.makefile);
    if (report.count) {
        print_error("%s", report.text);
        fail_msg("%d snippets of README.md and docs/ that do not work as written (above)",
                 report.count);
    }
    free(report.text);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_docs_models_md_is_fresh),
        cmocka_unit_test(test_docs_models_md_covers_registry),
        cmocka_unit_test(test_docs_cli_md_is_fresh),
        cmocka_unit_test(test_docs_cli_md_covers_commands),
        cmocka_unit_test(test_docs_snippets_work),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

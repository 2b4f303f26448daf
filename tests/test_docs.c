/*
 * test_docs.c — docs/models.md is the output of `wetdem docs-models` (the generated model
 * reference must not go stale), and it has a section for every model of the registry.
 *
 * The CLI path comes from WETDEM_CLI (set by `make test`), falling back to build/wetdem; the
 * working directory is the repository root. On failure: run `make docs` and commit the file.
 */
#include <stdlib.h>
#include <sys/wait.h>

#include "harness.h"

/* Reads all of stream f into a NUL-terminated heap buffer. */
static char* slurp(FILE* f)
{
    size_t cap = 1 << 16, len = 0, got;
    char* buf = malloc(cap);
    assert_non_null(buf);
    while ((got = fread(buf + len, 1, cap - len - 1, f)) > 0) {
        len += got;
        if (len + 1 == cap) {
            cap *= 2;
            buf = realloc(buf, cap);
            assert_non_null(buf);
        }
    }
    buf[len] = '\0';
    return buf;
}

static char* generated_docs(void)
{
    const char* cli = getenv("WETDEM_CLI");
    char cmd[1024];
    snprintf(cmd, sizeof cmd, "'%s' docs-models", cli && *cli ? cli : "build/wetdem");
    FILE* p = popen(cmd, "r");
    if (!p)
        fail_msg("cannot run %s", cmd);
    char* text = slurp(p);
    int status = pclose(p);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
        fail_msg("'%s' failed (status %d)", cmd, status);
    return text;
}

static char* committed_docs(void)
{
    FILE* f = fopen("docs/models.md", "r");
    if (!f)
        fail_msg("docs/models.md not found (the working directory must be the repository "
                 "root; create the file with 'make docs')");
    char* text = slurp(f);
    fclose(f);
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
static void check_same_text(const char* committed, const char* generated)
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
    fail_msg("docs/models.md is stale at line %zu (run 'make docs' and commit it):\n"
             "  committed: %.*s\n  generated: %.*s",
             line, (int)strcspn(a, "\n"), a, (int)strcspn(b, "\n"), b);
}

static void test_docs_models_md_is_fresh(void** state)
{
    (void)state;
    char* gen = generated_docs();
    char* doc = committed_docs();
    check_same_text(doc, gen);
    free(gen);
    free(doc);
}

static void test_docs_models_md_covers_registry(void** state)
{
    (void)state;
    char* doc = committed_docs();
    const struct wetdem_model* const* reg = wetdem_model_registry();
    for (size_t k = 0; reg[k]; k++) {
        char anchor[128];
        snprintf(anchor, sizeof anchor, "<a id=\"model-%s\"></a>", reg[k]->name);
        CHECK_CONTAINS(doc, anchor);
    }
    CHECK_CONTAINS(doc, "## Material presets");
    free(doc);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_docs_models_md_is_fresh),
        cmocka_unit_test(test_docs_models_md_covers_registry),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

/*
 * test_docs.c — docs/models.md is the output of `wetdem docs-models` (the generated model
 * reference must not go stale), and it has a section for every model of the registry.
 *
 * The CLI path comes from WETDEM_CLI (set by `make test`), falling back to build/wetdem; the
 * working directory is the repository root. On failure: run `make docs` and commit the file.
 */
#include "harness.h"

static char* generated_docs(void)
{
    struct test_run r = test_run_cli("", "docs-models", false);
    if (r.code != 0)
        fail_msg("'%s docs-models' failed (exit %d)", test_cli_path(), r.code);
    return r.out;
}

static char* committed_docs(void)
{
    char* text = test_read_file("docs/models.md", NULL);
    if (!text)
        fail_msg("docs/models.md not found (the working directory must be the repository "
                 "root; create the file with 'make docs')");
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

/*
 * test_docs.c — docs/models.md is the output of `wetdem docs-models` (the generated model
 * reference must not go stale), and it has a section for every model of the registry;
 * docs/cli.md is the output of `wetdem docs-cli` (every command's --help).
 *
 * The CLI path comes from WETDEM_CLI (set by `make test`), falling back to build/wetdem; the
 * working directory is the repository root. On failure: run `make docs` and commit the file.
 */
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

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_docs_models_md_is_fresh),
        cmocka_unit_test(test_docs_models_md_covers_registry),
        cmocka_unit_test(test_docs_cli_md_is_fresh),
        cmocka_unit_test(test_docs_cli_md_covers_commands),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}

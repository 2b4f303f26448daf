/*
 * fuzz_args.c — libFuzzer target: any bytes as a command line of `wetdem`, one word a line (at
 * most MAX_WORDS words of at most MAX_WORD bytes), run in the process. It reaches the parsing of
 * every option value (numbers, A:B:N ranges, --set's dotted keys and values, model, preset and
 * fluid names with their "did you mean" hints) and the commands that answer at once: models,
 * describe, forces, docs-*, run --check, and sweep and map of a few points.
 *
 * A word that names a shipped scenario (davis_three.ini, ...) stands for its file in
 * examples/scenarios/ (found from WETDEM_FUZZ_ROOT, or the current directory). Passed over,
 * to keep each input short and the machine untouched: words with a '/' and the options that
 * name files to write or read (--out, --restart, --curve, --frames, --data); the commands fit
 * and track (the file targets fuzz their input); ranges of more than MAX_POINTS points for
 * sweep and map (a sweep of 10^7 collisions is a size of the job, not a defect) or
 * MAX_GAPS for forces, and --set of more than MAX_SPHERES spheres. `run` always gets --check,
 * so a many-particle scenario is set up and not run.
 *
 * A finding is a crash, a sanitizer report, a leak, a hang, or an exit code other than 0 and
 * 2 (fuzz_cli.h). Exit 1 is one too, though `sweep` and `map` give it for a point whose run
 * failed: such a failure is either a limit the message names or a defect of the engine (this
 * target found three spheres in a closed loop of contacts that could not settle their events,
 * docs/validation_davis.md), so it is kept to be examined; words that lower a run's own limits
 * (max_steps) are passed over, as their failures are the intended answer.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_cli.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

enum { MAX_WORDS = 14, MAX_WORD = 200, MAX_POINTS = 3, MAX_GAPS = 200, MAX_SPHERES = 2000 };

static const char* const SCENARIOS[] = {"davis_three.ini",
                                        "davis_two_oblique.ini",
                                        "davis_unequal.ini",
                                        "dry_hertz.ini",
                                        "many_agglomeration.ini",
                                        "many_settling.ini",
                                        "many_stokes_cradle.ini",
                                        "nijssen_head_on.ini",
                                        "nijssen_oblique.ini",
                                        "nijssen_roughness.ini",
                                        "punch_oblique.ini",
                                        "wall_collision.ini",
                                        NULL};

static const char* const REFUSED_OPTIONS[] = {"--out",    "--restart", "--curve",
                                              "--frames", "--data",    NULL};

/* Whether the word is passed over: a path, an option naming a file, a range whose count
 * (after its last ':') exceeds max_points, or a --set of a count above MAX_SPHERES (as
 * fuzz_scenario.c passes over such files). */
static int word_refused(const char* w, double max_points)
{
    if (strchr(w, '/') || strstr(w, "max_steps"))
        return 1;
    for (const char* const* o = REFUSED_OPTIONS; *o; o++)
        if (strncmp(w, *o, strlen(*o)) == 0)
            return 1;
    const char* count = strstr(w, "count");
    const char* eq = count ? strchr(count, '=') : NULL;
    if (eq && !(strtod(eq + 1, NULL) <= MAX_SPHERES))
        return 1;
    const char* colon = strrchr(w, ':');
    return colon && !(strtod(colon + 1, NULL) <= max_points); /* (NaN refused too) */
}

/* The path of a shipped scenario named by the word, or NULL. */
static const char* scenario_path(const char* w, char* buf, size_t n)
{
    for (const char* const* s = SCENARIOS; *s; s++)
        if (strcmp(w, *s) == 0) {
            const char* root = getenv("WETDEM_FUZZ_ROOT");
            snprintf(buf, n, "%s/examples/scenarios/%s", root ? root : ".", *s);
            return buf;
        }
    return NULL;
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    static char words[MAX_WORDS][MAX_WORD + 1];
    static char paths[MAX_WORDS][512];
    char* argv[MAX_WORDS + 3] = {"wetdem"};
    int argc = 1;
    size_t start = 0;
    for (size_t k = 0; k <= size; k++) {
        if (k < size && data[k] != '\n')
            continue;
        size_t len = k - start;
        if (argc > MAX_WORDS || len > MAX_WORD || memchr(data + start, '\0', len))
            return 0;
        memcpy(words[argc - 1], data + start, len);
        words[argc - 1][len] = '\0';
        argv[argc] = words[argc - 1];
        argc++;
        start = k + 1;
    }
    const char* command = argv[1];
    if (strcmp(command, "fit") == 0 || strcmp(command, "track") == 0)
        return 0;
    int is_batch = strcmp(command, "sweep") == 0 || strcmp(command, "map") == 0;
    for (int k = 1; k < argc; k++) {
        if (word_refused(argv[k], is_batch ? MAX_POINTS : MAX_GAPS))
            return 0;
        const char* path = scenario_path(argv[k], paths[k - 1], sizeof paths[k - 1]);
        if (path)
            argv[k] = paths[k - 1];
    }
    if (strcmp(command, "run") == 0)
        argv[argc++] = "--check";
    argv[argc] = NULL;
    int rc = wetdem_cli_main(argc, argv);
    if (rc != 0 && rc != 2)
        abort();
    return 0;
}

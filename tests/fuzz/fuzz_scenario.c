/*
 * fuzz_scenario.c — libFuzzer target: any bytes as a scenario file, read, checked and built as
 * `wetdem run FILE --check` does, for every engine (soft, pairwise, many-particle: the engine
 * is chosen by the file's sections). Built and run by `make fuzz` (clang, with AddressSanitizer
 * and UndefinedBehaviorSanitizer); the CLI's main() is compiled in as wetdem_cli_main.
 *
 * A finding is a crash, a sanitizer report, a leak, a hang, or an exit code other than 0 (a
 * scenario that checks) and 2 (bad input, reported with its file and line): fuzz_cli.h.
 *
 * Inputs asking for more than MAX_SPHERES spheres are passed over: a valid scenario may ask for
 * 1e8 spheres, whose insertion in --check takes gigabytes and minutes (a size of the job, not a
 * defect), and the fuzzer would spend its time there.
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_cli.h"

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

enum { MAX_SPHERES = 2000 };

/* Whether the text has a "count" key whose value (as strtod reads it) exceeds MAX_SPHERES. */
static int asks_too_many(const char* text)
{
    for (const char* p = strstr(text, "count"); p; p = strstr(p + 1, "count")) {
        const char* v = p + 5;
        while (*v == ' ' || *v == '\t' || *v == '=' || *v == ':')
            v++;
        if (strtod(v, NULL) > MAX_SPHERES)
            return 1;
    }
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
    char* text = malloc(size + 1);
    if (!text)
        return 0;
    memcpy(text, data, size);
    text[size] = '\0';
    int skip = asks_too_many(text);
    free(text);
    if (!skip)
        fuzz_cli_on_file(data, size, "ini", (const char* const[]){"run", "FILE", "--check", NULL});
    return 0;
}

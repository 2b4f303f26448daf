/*
 * fuzz_cli.h — for the libFuzzer targets that hand the CLI a file: the input is written to a
 * file of this process and `wetdem ARGS` is run on it in the process (the CLI's main() is
 * compiled in as wetdem_cli_main by `make fuzz`).
 *
 * The CLI answers bad input with a message and exit code 2 (CLI_EXIT_USAGE) and keeps exit
 * code 1 for failures of the machine (memory, files), which no input file causes here: any
 * other code than 0 or 2 is a finding, as is a crash or a sanitizer report.
 */
#ifndef WETDEM_FUZZ_CLI_H
#define WETDEM_FUZZ_CLI_H
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

int wetdem_cli_main(int argc, char** argv);

/* Writes data to /tmp/wetdem_fuzz_PID.EXT, runs `wetdem` with args[] in which the word "FILE"
 * stands for that path (at most 15 words), removes the file and returns the exit code. */
static inline int fuzz_cli_run_on_file(const uint8_t* data, size_t size, const char* ext,
                                       const char* const* args)
{
    char path[64];
    snprintf(path, sizeof path, "/tmp/wetdem_fuzz_%ld.%s", (long)getpid(), ext);
    FILE* f = fopen(path, "wb");
    if (!f || (size && fwrite(data, 1, size, f) != size) || fclose(f) != 0)
        abort();
    char* argv[17] = {"wetdem"};
    int argc = 1;
    for (; args[argc - 1] && argc < 16; argc++)
        argv[argc] = strcmp(args[argc - 1], "FILE") == 0 ? path : (char*)args[argc - 1];
    argv[argc] = NULL;
    int rc = wetdem_cli_main(argc, argv);
    remove(path);
    return rc;
}

/* fuzz_cli_run_on_file, aborting (a finding) on an exit code other than 0 and 2. */
static inline void fuzz_cli_on_file(const uint8_t* data, size_t size, const char* ext,
                                    const char* const* args)
{
    int rc = fuzz_cli_run_on_file(data, size, ext, args);
    if (rc != 0 && rc != 2)
        abort();
}

#endif

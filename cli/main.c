/*
 * main.c — entry point of the wetdem CLI: global options and dispatch to subcommands.
 * Subcommands that a build does not contain are reported as such (weak symbols).
 */
#include <stdio.h>
#include <string.h>

#include "cli.h"

#pragma weak cmd_models
#pragma weak cmd_describe
#pragma weak cmd_docs_models
#pragma weak cmd_forces
#pragma weak cmd_run
#pragma weak cmd_sweep
#pragma weak cmd_map
#pragma weak cmd_fit
#pragma weak cmd_track
#pragma weak cmd_docs_scenarios

struct command {
    const char* name;
    int (*fn)(int argc, char** argv);
    const char* usage;
    const char* summary;
};

static const struct command commands[] = {
    {"models", cmd_models, "wetdem models", "list every model, one line each"},
    {"describe", cmd_describe, "wetdem describe NAME",
     "every parameter of a model with unit, default, range and doc"},
    {"forces", cmd_forces, "wetdem forces [MODEL...] [--set K=V ...]",
     "table of the pair force vs gap for two spheres"},
    {"run", cmd_run, "wetdem run FILE [--set section.key=value ...] [--out DIR] [--json]",
     "run a scenario file"},
    {"sweep", cmd_sweep, "wetdem sweep FILE --param KEY --values A:B:N [--log] [--out FILE]",
     "independent collisions over a parameter, in parallel"},
    {"map", cmd_map, "wetdem map FILE --param KEY --values A:B:N --param2 KEY --values2 A:B:N",
     "two-parameter map of collisions, grid CSV"},
    {"fit", cmd_fit, "wetdem fit FILE --data CSV --fit KEY[,KEY...]",
     "fit scenario parameters to measured restitution by least squares"},
    {"track", cmd_track, "wetdem track DOTS.csv --fps F --pixel-size S",
     "velocities, spin and restitution from tracked dots (Punch Sec. 3.2)"},
    {"docs-models", cmd_docs_models, "wetdem docs-models",
     "write docs/models.md (Markdown) to stdout"},
    {"docs-scenarios", cmd_docs_scenarios, "wetdem docs-scenarios",
     "write the key tables of docs/scenarios.md (Markdown) to stdout"},
};

static void print_help(FILE* f)
{
    fprintf(f, "wetdem %s — collisions of wet and immersed spheres (DEM)\n\n", WETDEM_VERSION);
    fprintf(f, "usage: wetdem [--version] [--help] COMMAND [ARGS]\n\ncommands:\n");
    for (size_t k = 0; k < sizeof commands / sizeof commands[0]; k++)
        if (commands[k].fn)
            fprintf(f, "  %-70s\n      %s\n", commands[k].usage, commands[k].summary);
    fprintf(f, "\nexit codes: 0 ok, 1 runtime error, 2 usage or input error\n"
               "docs: docs/index.md\n");
}

int main(int argc, char** argv)
{
    if (argc < 2) {
        print_help(stderr);
        return CLI_EXIT_USAGE;
    }
    if (strcmp(argv[1], "--version") == 0 || strcmp(argv[1], "version") == 0) {
        printf("wetdem %s (git %s)\n", WETDEM_VERSION, WETDEM_GIT_HASH);
        return CLI_EXIT_OK;
    }
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0 ||
        strcmp(argv[1], "help") == 0) {
        print_help(stdout);
        return CLI_EXIT_OK;
    }
    for (size_t k = 0; k < sizeof commands / sizeof commands[0]; k++)
        if (strcmp(argv[1], commands[k].name) == 0) {
            if (!commands[k].fn) {
                fprintf(stderr, "wetdem: command '%s' is not in this build\n", argv[1]);
                return CLI_EXIT_RUNTIME;
            }
            return commands[k].fn(argc - 1, argv + 1);
        }
    const char* names[32];
    size_t n = 0;
    for (size_t k = 0; k < sizeof commands / sizeof commands[0]; k++)
        names[n++] = commands[k].name;
    names[n] = NULL;
    const char* hint = wetdem_param_suggest(argv[1], names);
    fprintf(stderr, "wetdem: unknown command '%s'%s%s%s; see 'wetdem --help'\n", argv[1],
            hint ? " (did you mean '" : "", hint ? hint : "", hint ? "'?)" : "");
    return CLI_EXIT_USAGE;
}

/*
 * cli.h — subcommands of the wetdem command-line tool. Each lives in cli/cmd_<name>.c and
 * returns the process exit code: 0 OK, 1 runtime error, 2 usage or input error.
 * The CLI includes only the public header wetdem.h.
 */
#ifndef WETDEM_CLI_H
#define WETDEM_CLI_H

#include "wetdem.h"

#ifndef WETDEM_GIT_HASH
#define WETDEM_GIT_HASH "unknown"
#endif

#define CLI_EXIT_OK 0
#define CLI_EXIT_RUNTIME 1
#define CLI_EXIT_USAGE 2

int cmd_models(int argc, char** argv);
int cmd_describe(int argc, char** argv);
int cmd_docs_models(int argc, char** argv);
int cmd_docs_scenarios(int argc, char** argv);
int cmd_forces(int argc, char** argv);
int cmd_run(int argc, char** argv);
int cmd_sweep(int argc, char** argv);
int cmd_map(int argc, char** argv);
int cmd_fit(int argc, char** argv);
int cmd_track(int argc, char** argv);

#endif

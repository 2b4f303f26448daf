/*
 * output_journal.h — the journal that makes a set of output files replaced whole or not at all
 * also after a kill (SIGKILL, a power cut) between its rename passes: written before the
 * passes, removed after them, and read by the next process that writes one of the files
 * (output_journal.c describes the scheme).
 */
#ifndef WETDEM_CLI_OUTPUT_JOURNAL_H
#define WETDEM_CLI_OUTPUT_JOURNAL_H

#include <limits.h>
#include <stdbool.h>
#include <stddef.h>

#include "cli_util.h"

/* A directory or file of a set, absolute [chars]. */
#define CLI_SET_PATH (PATH_MAX + 256)

/* Puts in order what dead processes left beside `final` (their journals in its directory, then
 * the temporary and backup files of `final`), saying on stderr what was done. */
void cli_journal_recover(const char* final);

/* Writes the journal of the set (the files with renamed[k]) into each of its directories,
 * listed into dirs (*n_dirs of them); 0, or -1 with errno set and those written removed. */
int cli_journal_write(struct cli_out_file* const* files, size_t n, const bool* renamed,
                      char dirs[][CLI_SET_PATH], size_t* n_dirs);

/* Removes the set's journals (the last first: the set stops counting as committed at once). */
void cli_journal_remove(char dirs[][CLI_SET_PATH], size_t n_dirs);

/* Test hook: WETDEM_TEST_KILL_AT_RENAME=k kills the process with SIGKILL once k temporary
 * files of a set of two or more have been renamed to their targets (0: right after the targets
 * were moved aside), as a kill -9 or a power cut might. */
void cli_journal_test_kill(size_t renamed);

#endif

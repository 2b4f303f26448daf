/*
 * signals.h — SIGINT and SIGTERM for the long commands (`run` of many particles, `sweep`,
 * `map`, and `run --out` of one collision while its trajectory is written): the first signal
 * asks the command to stop cleanly (write its checkpoint, or the table of the points that ran;
 * a single collision keeps no file, as its files are written whole or not at all); a repeat within CLI_SIGNAL_GRACE_S of it is taken as the same
 * request (GNU timeout signals the process, then its process group, which holds the process:
 * two signals milliseconds apart); a second signal after that, or a third, stops at once by
 * the signal's default action. A signal ignored when the handlers are installed (nohup, a
 * background job of a non-interactive shell) stays ignored.
 *
 * The handler may run on any thread (OpenMP workers included), and two may run at once: the
 * count is one atomic fetch-and-add and the time of the first signal an atomic, stored before
 * a repeat can read it (a repeat that finds it unset is taken as simultaneous, the same
 * request). Everything the handler calls is async-signal-safe.
 */
#ifndef WETDEM_CLI_SIGNALS_H
#define WETDEM_CLI_SIGNALS_H

#include <signal.h>

/* A repeat sooner than this after the first signal is the same request [s]: duplicates come
 * within milliseconds, and a person pressing Ctrl-C again to stop at once does so later (or
 * three times). */
#define CLI_SIGNAL_GRACE_S 1.0

/* The first signal's number, 0 while none came; what a library stop flag points to. */
extern volatile sig_atomic_t cli_stop_signal;

/* 1 while a progress line (cli_progress_show, cli_util.c) may stand on the terminal: the
 * handler then erases it ("\r\033[K") before its message, which starts on that clean line. */
extern volatile sig_atomic_t cli_progress_shown;

struct cli_saved_signals {
    struct sigaction sigint, sigterm;
};

/* Installs the handler for SIGINT and SIGTERM, saving the previous ones. `notice` is written
 * to stderr on the first signal, `stop_note` when a repeated signal stops the command at once;
 * `remove_on_stop`, when not NULL or empty, is a file removed then (a checkpoint being
 * written). All three are copied. */
void cli_signals_install(const char* notice, const char* stop_note, const char* remove_on_stop,
                         struct cli_saved_signals* saved);

/* Puts back the handlers cli_signals_install saved. After a signal, keep them instead: a
 * duplicate arriving once the command has finished would otherwise kill it, turning its exit
 * code into death by the signal. */
void cli_signals_restore(const struct cli_saved_signals* saved);

/* A single run whose file `tmp` (a trajectory under its temporary name) is open while it runs:
 * the first SIGINT or SIGTERM asks the run to stop (its observer returns non-zero when
 * cli_stop_signal is set), and a repeated one removes `tmp` before it stops at once. */
void cli_signals_install_run(const char* tmp, struct cli_saved_signals* saved);

/* After such a run: 0 when no signal came (the handlers put back), otherwise prints "wetdem:
 * <what>: interrupted by signal N: ..." and returns the exit code 128 + N (the handlers kept,
 * as cli_signals_restore says); the caller removes the run's temporary files. Called with the
 * signals blocked (cli_signals_block) before the files are renamed, so that none comes between
 * the test and the renames: one that comes then is delivered, under the handlers put back,
 * once the files are whole. */
int cli_signals_finish_run(const char* what, const struct cli_saved_signals* saved);

/* Blocks SIGINT and SIGTERM (held pending), saving the mask in *old; unblocks them. */
void cli_signals_block(sigset_t* old);
void cli_signals_unblock(const sigset_t* old);

#endif

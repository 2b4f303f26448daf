/*
 * signals.c — the CLI's handler of SIGINT and SIGTERM (signals.h): stop cleanly on the first
 * signal, take a repeat within CLI_SIGNAL_GRACE_S as the same request, stop at once on a later
 * one or a third.
 */
#include "signals.h"

#include <stdatomic.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

volatile sig_atomic_t cli_stop_signal = 0;
volatile sig_atomic_t cli_progress_shown = 0;

static atomic_int signal_count;
static atomic_llong first_signal_ns; /* CLOCK_MONOTONIC of the first signal; 0: not stored yet */
/* Set before the handlers are installed (the handler reads them only) */
static char notice_text[2400], stop_text[400];
static char remove_path[2100];

_Static_assert(ATOMIC_INT_LOCK_FREE == 2 && ATOMIC_LLONG_LOCK_FREE == 2,
               "the signal handler needs lock-free atomics");

static void say(const char* text)
{
    ssize_t unused = write(STDERR_FILENO, text, strlen(text));
    (void)unused;
}

/* text on a line of its own: over a progress line, that line erased (carriage return, erase
 * to the end of the line) and text's leading newline dropped, which would have left the
 * progress line standing above it; write(2) only */
static void say_on_clean_line(const char* text)
{
    if (!cli_progress_shown) {
        say(text);
        return;
    }
    cli_progress_shown = 0;
    say("\r\033[K");
    say(text[0] == '\n' ? text + 1 : text);
}

static long long monotonic_ns(void)
{
    struct timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    return (long long)now.tv_sec * 1000000000LL + now.tv_nsec;
}

static void on_signal(int sig)
{
    long long now = monotonic_ns();
    int before = atomic_fetch_add(&signal_count, 1);
    if (before == 0) {
        atomic_store(&first_signal_ns, now > 0 ? now : 1);
        cli_stop_signal = sig;
        say_on_clean_line(notice_text);
        return;
    }
    long long first = atomic_load(&first_signal_ns);
    if (before == 1 && (first == 0 || (double)(now - first) < 1e9 * CLI_SIGNAL_GRACE_S))
        return; /* the same request again (first == 0: both at once) */
    say_on_clean_line(stop_text);
    if (remove_path[0])
        unlink(remove_path);
    /* die by the signal, as the caller asked: default action, raised again (delivered when
       this handler returns) */
    struct sigaction dfl = {.sa_handler = SIG_DFL};
    sigemptyset(&dfl.sa_mask);
    sigaction(sig, &dfl, NULL);
    raise(sig);
}

/* Installs on_signal for sig unless sig is ignored; *saved receives the previous action. */
static void install_one(int sig, struct sigaction* saved)
{
    sigaction(sig, NULL, saved);
    if (saved->sa_handler == SIG_IGN)
        return;
    struct sigaction sa = {.sa_handler = on_signal};
    sigemptyset(&sa.sa_mask);
    sigaddset(&sa.sa_mask, SIGINT);
    sigaddset(&sa.sa_mask, SIGTERM);
    sigaction(sig, &sa, NULL);
}

void cli_signals_install(const char* notice, const char* stop_note, const char* remove_on_stop,
                         struct cli_saved_signals* saved)
{
    cli_stop_signal = 0;
    atomic_store(&signal_count, 0);
    atomic_store(&first_signal_ns, 0);
    snprintf(notice_text, sizeof notice_text, "%s", notice);
    snprintf(stop_text, sizeof stop_text, "%s", stop_note);
    snprintf(remove_path, sizeof remove_path, "%s", remove_on_stop ? remove_on_stop : "");
    install_one(SIGINT, &saved->sigint);
    install_one(SIGTERM, &saved->sigterm);
}

void cli_signals_restore(const struct cli_saved_signals* saved)
{
    sigaction(SIGINT, &saved->sigint, NULL);
    sigaction(SIGTERM, &saved->sigterm, NULL);
}

void cli_signals_install_run(const char* tmp, struct cli_saved_signals* saved)
{
    cli_signals_install("\nwetdem: run: stopping; this run's files are not kept (a second "
                        "signal 1 s or more after this one, or a third, stops at once)\n",
                        "\nwetdem: run: stopped at once by a repeated signal\n", tmp, saved);
}

int cli_signals_finish_run(const char* what, const struct cli_saved_signals* saved)
{
    int sig = (int)cli_stop_signal;
    if (!sig) {
        cli_signals_restore(saved);
        return 0;
    }
    fprintf(stderr,
            "wetdem: %s: interrupted by signal %d: no file written (a run's files are kept "
            "only whole)\n",
            what, sig);
    return 128 + sig;
}

void cli_signals_block(sigset_t* old)
{
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, SIGINT);
    sigaddset(&set, SIGTERM);
    sigprocmask(SIG_BLOCK, &set, old);
}

void cli_signals_unblock(const sigset_t* old)
{
    sigprocmask(SIG_SETMASK, old, NULL);
}

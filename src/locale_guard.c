/*
 * locale_guard.c — the C locale for the calling thread while the library reads or writes
 * numbers as text.
 *
 * printf, strtod and sscanf follow the calling thread's LC_NUMERIC: a host that called
 * setlocale(LC_ALL, "") in a German or French locale would get "0,5" in the library's VTK and
 * CSV files, and "0.5" would not parse in its parameter strings and track files. setlocale
 * itself would change the locale of the whole process, under the host's other threads, so each
 * public call that reads or writes such text switches its own thread to the C locale with
 * uselocale (POSIX.1-2008) and back at its end, once per call: no global state, and nothing
 * in the steps of a run.
 */
#include "locale_guard.h"
#include "wetdem.h"

int wetdem_locale_guard_enter(struct wetdem_locale_guard* g)
{
    /* (glibc and musl give their static C locale object here, without allocating) */
    g->c = newlocale(LC_NUMERIC_MASK, "C", (locale_t)0);
    if (g->c == (locale_t)0) {
        g->old = (locale_t)0;
        return WETDEM_ERR_NOMEM;
    }
    g->old = uselocale(g->c);
    return WETDEM_OK;
}

void wetdem_locale_guard_leave(struct wetdem_locale_guard* g)
{
    if (g->c == (locale_t)0)
        return;
    uselocale(g->old);
    freelocale(g->c);
    g->c = (locale_t)0;
}

/*
 * locale_guard.h — the C locale for the calling thread while the library reads or writes
 * numbers as text (locale_guard.c).
 */
#ifndef WETDEM_LOCALE_GUARD_H
#define WETDEM_LOCALE_GUARD_H

#include <locale.h>

struct wetdem_locale_guard {
    locale_t c;   /* the C locale in use, (locale_t)0 if none could be made */
    locale_t old; /* the thread's locale before, put back by wetdem_locale_guard_leave */
};

/* Makes the C locale the calling thread's locale (decimal point '.', whatever LC_NUMERIC the
 * host set) until the matching wetdem_locale_guard_leave(); other threads keep theirs. Returns
 * WETDEM_OK, or WETDEM_ERR_NOMEM if no C locale object could be made (the thread's locale is
 * then unchanged, and leave does nothing). Guards nest. */
int wetdem_locale_guard_enter(struct wetdem_locale_guard* g);
void wetdem_locale_guard_leave(struct wetdem_locale_guard* g);

#endif

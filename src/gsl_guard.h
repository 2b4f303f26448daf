/*
 * gsl_guard.h — GSL's error handler off while the library calls GSL (gsl_guard.c).
 */
#ifndef WETDEM_GSL_GUARD_H
#define WETDEM_GSL_GUARD_H

/* Switches GSL's process-wide error handler off (its default aborts the program; the library
 * checks every GSL status itself) until the matching wetdem_gsl_guard_leave(). Calls from
 * several threads nest: the first enter saves the caller's handler, the last leave puts it
 * back. */
void wetdem_gsl_guard_enter(void);
void wetdem_gsl_guard_leave(void);

#endif

/*
 * gsl_guard.c — GSL's error handler off while the library calls GSL.
 *
 * GSL reports errors through one process-wide handler whose default aborts; the library must
 * never abort its host, so it switches the handler off around its GSL calls that can fail
 * (the fit's solver, the quadrature table of the collision analysis) and checks their status.
 * The handler is one variable for the whole process: each caller saving it, switching it off
 * and putting the saved one back would race with callers in other threads, and the wrong order
 * of ends would leave it on while a call still runs, or off for good. So the callers count
 * themselves in under a lock: the first switches it off, the last restores the caller's. (The
 * library's only mutable state outside its objects.)
 */
#include <pthread.h>
#include <stddef.h>

#include <gsl/gsl_errno.h>

#include "gsl_guard.h"

static pthread_mutex_t guard_lock = PTHREAD_MUTEX_INITIALIZER;
static size_t guard_depth;           /* calls within the guard, over all threads */
static gsl_error_handler_t* callers; /* the caller's handler while guard_depth > 0 */

void wetdem_gsl_guard_enter(void)
{
    pthread_mutex_lock(&guard_lock);
    if (guard_depth++ == 0)
        callers = gsl_set_error_handler_off();
    pthread_mutex_unlock(&guard_lock);
}

void wetdem_gsl_guard_leave(void)
{
    pthread_mutex_lock(&guard_lock);
    if (--guard_depth == 0)
        gsl_set_error_handler(callers);
    pthread_mutex_unlock(&guard_lock);
}

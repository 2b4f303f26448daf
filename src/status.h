/*
 * status.h — internal: the message of a failed call for functions that report into a caller's
 * buffer (char* msg, size_t msg_size) rather than into a simulation (wetdem_sim_fail, sim.h).
 * Status codes and their sign convention are those of enum wetdem_status (wetdem.h).
 */
#ifndef WETDEM_STATUS_H
#define WETDEM_STATUS_H

#include <stddef.h>

/* Formats the printf-style message into msg (msg_size bytes, truncated and terminated;
 * nothing is written when msg is NULL or msg_size is 0) and returns status. */
int wetdem_status_fail(char* msg, size_t msg_size, int status, const char* fmt, ...)
    __attribute__((format(printf, 4, 5)));

#endif

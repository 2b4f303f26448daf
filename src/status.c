/*
 * status.c — names of status codes (enum wetdem_status in wetdem.h), and the message of a
 * failed call into a caller's buffer (status.h).
 * Sign convention as CVODE: 0 success, > 0 success with information, < 0 error.
 */
#include <stdarg.h>
#include <stdio.h>

#include "status.h"
#include "wetdem.h"

const char* wetdem_status_name(int status)
{
    switch (status) {
    case WETDEM_OK: return "WETDEM_OK";
    case WETDEM_EVENT: return "WETDEM_EVENT";
    case WETDEM_RETRY: return "WETDEM_RETRY";
    case WETDEM_ERR_NOMEM: return "WETDEM_ERR_NOMEM";
    case WETDEM_ERR_INVALID: return "WETDEM_ERR_INVALID";
    case WETDEM_ERR_NOT_FOUND: return "WETDEM_ERR_NOT_FOUND";
    case WETDEM_ERR_STEP: return "WETDEM_ERR_STEP";
    case WETDEM_ERR_MAX_STEPS: return "WETDEM_ERR_MAX_STEPS";
    case WETDEM_ERR_CALLBACK: return "WETDEM_ERR_CALLBACK";
    case WETDEM_ERR_IO: return "WETDEM_ERR_IO";
    case WETDEM_ERR_PARSE: return "WETDEM_ERR_PARSE";
    case WETDEM_ERR_NUMERIC: return "WETDEM_ERR_NUMERIC";
    case WETDEM_ERR_UNDETERMINED: return "WETDEM_ERR_UNDETERMINED";
    default: return "WETDEM_UNKNOWN";
    }
}

int wetdem_status_fail(char* msg, size_t msg_size, int status, const char* fmt, ...)
{
    if (msg && msg_size > 0) {
        va_list ap;
        va_start(ap, fmt);
        vsnprintf(msg, msg_size, fmt, ap);
        va_end(ap);
    }
    return status;
}

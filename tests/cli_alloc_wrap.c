/*
 * cli_alloc_wrap.c — the failing allocator of build/tests/wetdem_alloc_fail, the command-line
 * tool linked with the wrappers of the allocation-failure test (Makefile, ALLOC_WRAP): every
 * malloc, calloc, realloc and strdup of the CLI and of the library, and every constructor of a
 * SUNDIALS or GSL object the library calls, counts as one allocation, and the one numbered
 * WETDEM_TEST_FAIL_ALLOC (1-based; unset or 0: none) fails as in tests/test_alloc_failure.c (an
 * allocator returns NULL, a SUNDIALS constructor NULL or its memory-failure flag, a GSL one
 * NULL after calling GSL's error handler, whose default aborts). At exit the program writes
 * "allocations A failed F live L" to the file WETDEM_TEST_ALLOC_REPORT (when set): A
 * allocations counted, F 1 when the one to fail was reached, L blocks allocated through the
 * wrappers and not freed (-1: too many to keep track of).
 * tests/test_cli_alloc_failure.sh drives it. Allocations inside the shared libraries (libc's
 * stdio buffers, SUNDIALS, GSL, inih, OpenMP) do not pass through the wrappers.
 */
#include <stdatomic.h>
#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "alloc_fallible.h" /* the wrappers' declarations, the SUNDIALS and GSL ones */

/* The blocks allocated through the wrappers and not freed: an open-addressing set of pointers
 * under a spin lock (a sweep may run in several threads). Blocks libc allocates itself
 * (getline's, scandir's) are not in it, and freeing them changes nothing. */
#define LIVE_CAP (1u << 18)
static void* live[LIVE_CAP];
static size_t live_n;
static bool live_overflow; /* more blocks than the set takes: the count is not known */
static void* const live_tomb = &live_n;
static atomic_flag live_lock = ATOMIC_FLAG_INIT;

static size_t live_hash(const void* p)
{
    return (size_t)(((uintptr_t)p >> 4) * 0x9E3779B97F4A7C15ull) & (LIVE_CAP - 1);
}

static void live_update(void* removed, void* added)
{
    while (atomic_flag_test_and_set_explicit(&live_lock, memory_order_acquire))
        ;
    if (removed)
        for (size_t k = live_hash(removed); live[k]; k = (k + 1) & (LIVE_CAP - 1))
            if (live[k] == removed) {
                live[k] = live_tomb;
                live_n--;
                break;
            }
    if (added && live_n < LIVE_CAP / 2) {
        size_t k = live_hash(added);
        while (live[k] && live[k] != live_tomb)
            k = (k + 1) & (LIVE_CAP - 1);
        live[k] = added;
        live_n++;
    } else if (added)
        live_overflow = true;
    atomic_flag_clear_explicit(&live_lock, memory_order_release);
}

static void* counted(void* p)
{
    if (p)
        live_update(NULL, p);
    return p;
}

void* __wrap_malloc(size_t size)
{
    return inject() ? NULL : counted(__real_malloc(size));
}

void* __wrap_calloc(size_t n, size_t size)
{
    return inject() ? NULL : counted(__real_calloc(n, size));
}

void* __wrap_realloc(void* p, size_t size)
{
    if (inject())
        return NULL;
    void* q = __real_realloc(p, size);
    if (q)
        live_update(p, q);
    return q;
}

char* __wrap_strdup(const char* s)
{
    return inject() ? NULL : counted(__real_strdup(s));
}

void __wrap_free(void* p)
{
    if (p)
        live_update(p, NULL);
    __real_free(p);
}

static void report(void)
{
    const char* path = getenv("WETDEM_TEST_ALLOC_REPORT");
    if (!path || !*path)
        return;
    FILE* f = fopen(path, "w");
    if (!f)
        return;
    fprintf(f, "allocations %ld failed %d live %ld\n", atomic_load(&alloc_count),
            atomic_load(&alloc_failed) ? 1 : 0, live_overflow ? -1L : (long)live_n);
    fclose(f);
}

/* Before main: reads the allocation to fail and registers the report. */
__attribute__((constructor)) static void arm_from_environment(void)
{
    const char* n = getenv("WETDEM_TEST_FAIL_ALLOC");
    alloc_fail_at = n ? strtol(n, NULL, 10) : 0;
    atexit(report);
}

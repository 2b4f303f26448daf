/*
 * many_bulk.c — four pairs at a time (many_bulk.h) for the baseline instruction set (SSE2 on
 * x86-64, plain C elsewhere), and the choice of the version for the processor.
 */
#define WETDEM_MANY_BULK_NAME wetdem_many_bulk_base
#define WETDEM_MANY_BULK_WALLS_NAME wetdem_many_bulk_base_walls
#include "many_bulk.h"

/* Whether the AVX2 versions run here (never with `base_only`). */
static bool avx2_usable(bool base_only)
{
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
    /* (libgcc's check includes the operating system's support of the AVX registers) */
    return !base_only && __builtin_cpu_supports("avx2");
#else
    (void)base_only;
    return false;
#endif
}

wetdem_many_bulk_fn* wetdem_many_bulk_choose(bool base_only)
{
    return avx2_usable(base_only) ? wetdem_many_bulk_avx2 : wetdem_many_bulk_base;
}

wetdem_many_bulk_walls_fn* wetdem_many_bulk_walls_choose(bool base_only)
{
    return avx2_usable(base_only) ? wetdem_many_bulk_avx2_walls : wetdem_many_bulk_base_walls;
}

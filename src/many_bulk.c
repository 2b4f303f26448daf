/*
 * many_bulk.c — four pairs at a time (many_bulk.h) for the baseline instruction set (SSE2 on
 * x86-64, plain C elsewhere), and the choice of the version for the processor.
 */
#define WETDEM_MANY_BULK_NAME wetdem_many_bulk_base
#define WETDEM_MANY_BULK_WALLS_NAME wetdem_many_bulk_base_walls
#include "many_bulk.h"

/* Whether the processor (and its operating system: libgcc's check includes the state of the
 * wider registers) runs version `isa`. */
bool wetdem_many_bulk_usable(enum wetdem_many_bulk_isa isa)
{
    switch (isa) {
    case WETDEM_MANY_BULK_BEST:
    case WETDEM_MANY_BULK_BASE: return true;
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
    case WETDEM_MANY_BULK_AVX2: return __builtin_cpu_supports("avx2");
    case WETDEM_MANY_BULK_AVX512:
        return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("avx512f") &&
               __builtin_cpu_supports("avx512vl") && __builtin_cpu_supports("avx512dq");
#endif
    default: return false;
    }
}

/* The version that runs: `isa` where usable, BEST the widest usable one, else the baseline. */
static enum wetdem_many_bulk_isa version_of(enum wetdem_many_bulk_isa isa)
{
    if (isa == WETDEM_MANY_BULK_BEST)
        return wetdem_many_bulk_usable(WETDEM_MANY_BULK_AVX512) ? WETDEM_MANY_BULK_AVX512
               : wetdem_many_bulk_usable(WETDEM_MANY_BULK_AVX2) ? WETDEM_MANY_BULK_AVX2
                                                                : WETDEM_MANY_BULK_BASE;
    return wetdem_many_bulk_usable(isa) ? isa : WETDEM_MANY_BULK_BASE;
}

/* The functions of each version (BEST is resolved by version_of). */
static const struct {
    wetdem_many_bulk_fn* pairs;
    wetdem_many_bulk_walls_fn* walls;
} versions[] = {
    [WETDEM_MANY_BULK_BASE] = {wetdem_many_bulk_base, wetdem_many_bulk_base_walls},
    [WETDEM_MANY_BULK_AVX2] = {wetdem_many_bulk_avx2, wetdem_many_bulk_avx2_walls},
    [WETDEM_MANY_BULK_AVX512] = {wetdem_many_bulk_avx512, wetdem_many_bulk_avx512_walls},
};

wetdem_many_bulk_fn* wetdem_many_bulk_choose(enum wetdem_many_bulk_isa isa)
{
    return versions[version_of(isa)].pairs;
}

wetdem_many_bulk_walls_fn* wetdem_many_bulk_walls_choose(enum wetdem_many_bulk_isa isa)
{
    return versions[version_of(isa)].walls;
}

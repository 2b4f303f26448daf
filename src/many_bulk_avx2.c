/*
 * many_bulk_avx2.c — four pairs at a time (many_bulk.h) in AVX2, chosen at run time by
 * wetdem_many_bulk_choose (many_bulk.c) where the processor has it (x86-64, GCC). The same
 * operations as the baseline version, so the same bits: AVX2 alone does not enable fused
 * multiply-adds, and the build has -ffp-contract=off. Elsewhere this is a second copy of the
 * baseline version, never chosen.
 */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#pragma GCC target("avx2")
#endif
#define WETDEM_MANY_BULK_NAME wetdem_many_bulk_avx2
#define WETDEM_MANY_BULK_WALLS_NAME wetdem_many_bulk_avx2_walls
#include "many_bulk.h"

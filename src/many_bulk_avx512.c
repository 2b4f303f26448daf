/*
 * many_bulk_avx512.c — four pairs at a time (many_bulk.h) in AVX2 with the AVX-512 encoding of
 * its 256-bit instructions (AVX-512F, VL and DQ), chosen at run time by wetdem_many_bulk_choose
 * (many_bulk.c) where the processor has them (x86-64, GCC). The lanes stay four: what AVX-512
 * adds here is 32 vector registers instead of 16 (fewer values of the kernels kept on the
 * stack) and mask registers for the comparisons and selections. The same operations as the
 * baseline version, so the same bits: the build has -ffp-contract=off, so the fused
 * multiply-adds of AVX-512F are never used. Elsewhere this is a third copy of the baseline
 * version, never chosen.
 */
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#pragma GCC target("avx2,avx512f,avx512vl,avx512dq")
#endif
#define WETDEM_MANY_BULK_NAME wetdem_many_bulk_avx512
#define WETDEM_MANY_BULK_WALLS_NAME wetdem_many_bulk_avx512_walls
#include "many_bulk.h"

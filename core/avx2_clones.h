// RSIBR_AVX2_CLONES: marks a vectorised row loop to be built twice, for AVX2 and for the baseline
// x86-64, with the choice made at load time (GCC/Clang target_clones; elsewhere a single build).
// No FMA in either clone, so both give the same bits.
// RSIBR_AVX512_CLONES: a third build for AVX-512F (16 floats a vector), for the blend engine's row
// loops (runtime/). AVX-512F brings FMA, into which GCC would contract a * b + c, so the files using
// it are compiled with -ffp-contract=off (runtime/CMakeLists.txt): every clone gives the same bits.
#pragma once

#if defined(__x86_64__) && defined(__GNUC__)
#define RSIBR_AVX2_CLONES __attribute__((target_clones("avx2", "default")))
#define RSIBR_AVX512_CLONES __attribute__((target_clones("avx512f", "avx2", "default")))
#else
#define RSIBR_AVX2_CLONES
#define RSIBR_AVX512_CLONES
#endif

#pragma once
// PCL_DDG_WIDE_LANES before a function compiles it twice, for AVX2 (four doubles a lane group)
// and for the x86-64 baseline (two), and the loader picks the one this CPU runs: for loops
// written for the vector lanes, which the baseline build alone keeps at half width. FMA is not
// enabled, so both versions round every operation alike and give the same results.
// Only for functions with internal linkage (callers in the same file): clang resolves the
// versions only where every caller sees them.
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__)) && defined(__ELF__)
#define PCL_DDG_WIDE_LANES __attribute__((target_clones("avx2", "default")))
#else
#define PCL_DDG_WIDE_LANES
#endif

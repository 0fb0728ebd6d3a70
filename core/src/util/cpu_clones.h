// PENUMBRA_X86_64_V3_CLONES: compiles a hot scalar function twice, for the portable x86-64 baseline
// and for x86-64-v3 (AVX2 and FMA: every x86 server processor since 2013-2015), and lets the dynamic
// loader pick one when the core is loaded (GCC's target_clones, an ifunc). The rest of the build
// stays portable, as a Debian package must be.
//
// Only for functions the profile shows, whose polynomial or interpolation chains the compiler fuses
// into FMAs (docs/benchmarks.md, "FMA clones of the hottest scalar math"). The two versions round
// differently in the last bit; which one runs depends on the processor, as with -march=native.
// Not for clang (the fuzzers) nor for builds that target AVX2 already (PENUMBRA_NATIVE_ARCH).
#pragma once

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__AVX2__)
#define PENUMBRA_X86_64_V3_CLONES __attribute__((target_clones("arch=x86-64-v3", "default")))
#else
#define PENUMBRA_X86_64_V3_CLONES
#endif

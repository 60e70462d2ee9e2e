// Attributes for the few loops written for the auto-vectoriser (docs/decisions/0028): their
// files are compiled with -fno-math-errno -fno-trapping-math, the loops are branch-free over
// structure-of-arrays data, and these make them inline, clone them for AVX2 and let them
// ignore aliasing the code rules out.
#ifndef DRIFT_CORE_VECTORISE_H
#define DRIFT_CORE_VECTORISE_H

// A loop written once and specialised by inlining.
#if defined(__GNUC__)
#    define DRIFT_ALWAYS_INLINE __attribute__((always_inline))
#else
#    define DRIFT_ALWAYS_INLINE
#endif
// Compiled for AVX2 (8 lanes, hardware gathers) too, picked at load time where the CPU has it
// (GCC and clang function multi-versioning on x86-64 ELF). With -ffp-contract=off both
// versions do the same IEEE operations: the same image to the bit. Not under ThreadSanitizer:
// the clones' resolver runs at load time, before TSan's runtime is up, and crashed. Clang 14
// gives a static function's resolver external linkage: two files must not clone functions of
// the same name (the fuzz build's link fails).
#if defined(__SANITIZE_THREAD__)
#    define DRIFT__TSAN 1
#elif defined(__has_feature)
#    if __has_feature(thread_sanitizer)
#        define DRIFT__TSAN 1
#    endif
#endif
#if (defined(__GNUC__) || defined(__clang__)) && defined(__x86_64__) && defined(__ELF__) && \
    !defined(DRIFT__TSAN)
#    define DRIFT_AVX2_CLONES __attribute__((target_clones("avx2", "default")))
#else
#    define DRIFT_AVX2_CLONES
#endif
// The next loop's pointers never overlap where it writes.
#if defined(__clang__)
#    define DRIFT_IVDEP _Pragma("clang loop vectorize(assume_safety)")
#elif defined(__GNUC__)
#    define DRIFT_IVDEP _Pragma("GCC ivdep")
#else
#    define DRIFT_IVDEP
#endif

#endif // DRIFT_CORE_VECTORISE_H

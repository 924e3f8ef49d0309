#pragma once
// What the processor the program runs on can do, for the code paths chosen at run time (the
// build targets baseline x86-64): asked once, then remembered.

namespace featsense::tsdf::detail {

/// Whether the processor has AVX2 (false where the compiler can't ask: not x86-64 with GCC or
/// Clang).
inline bool cpu_has_avx2() {
#if defined(__x86_64__) && defined(__GNUC__)
  static const bool has_avx2 = __builtin_cpu_supports("avx2") != 0;
  return has_avx2;
#else
  return false;
#endif
}

}  // namespace featsense::tsdf::detail

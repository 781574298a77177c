#pragma once
// Handing freed heap pages back to the system, where the C library can.
#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace kit {

namespace detail {
inline bool& freed_memory_kept_between_scenes() {
  static bool kept = false;
  return kept;
}
}  // namespace detail

// For a process that renders scene after scene (the grader's render worker): from now on
// give_back_freed_memory keeps the pages, since the next scene's targets and images take
// them again. Given back, every scene faulted them in anew, and llvmpipe zeroes each new
// texture: with the trim, grading the solutions took 90 thousand page faults and 1.7 s
// warm on 2 cores, kept 50 thousand and 1.2 s (docs/performance.md). Process-wide, as
// malloc's own settings are.
inline void keep_freed_memory_between_scenes() { detail::freed_memory_kept_between_scenes() = true; }

// glibc: malloc_trim(0), the freed blocks that lie among others in the heap given back
// (unless keep_freed_memory_between_scenes was called). Elsewhere (emscripten's malloc: a
// WebAssembly memory never shrinks) nothing.
inline void give_back_freed_memory() {
#if defined(__GLIBC__)
  if (!detail::freed_memory_kept_between_scenes()) malloc_trim(0);
#endif
}

}  // namespace kit

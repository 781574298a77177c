#pragma once
// Handing freed heap pages back to the system, where the C library can.
#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace kit {

// glibc: malloc_trim(0), the freed blocks that lie among others in the heap given back.
// Elsewhere (emscripten's malloc: a WebAssembly memory never shrinks) nothing.
inline void give_back_freed_memory() {
#if defined(__GLIBC__)
  malloc_trim(0);
#endif
}

}  // namespace kit

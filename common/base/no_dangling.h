#pragma once
// KIT_NO_DANGLING marks a function whose returned reference outlives its arguments (it
// points into a table or a cache), so that GCC 14's -Wdangling-reference does not warn
// at `const T& x = f("literal")`. GCC 14 has the attribute; older compilers and clang,
// which would warn that it is unknown, get nothing.
#if defined(__has_cpp_attribute)
#if __has_cpp_attribute(gnu::no_dangling)
#define KIT_NO_DANGLING [[gnu::no_dangling]]
#endif
#endif
#ifndef KIT_NO_DANGLING
#define KIT_NO_DANGLING
#endif

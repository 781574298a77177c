#pragma once
// glibc's huge-page malloc (GLIBC_TUNABLES=glibc.malloc.hugetlb=1): malloc asks for
// transparent huge pages (madvise), so a buffer faults in 2 MiB at a time instead of 4 KiB.
// glibc reads the tunable only when a process starts: a program sets it, then starts
// (exec) itself or another program with it. Who does: `./kit render`'s launcher
// (tools/launcher/) and kit-grade (tools/grade/main.cpp); docs/performance.md has what
// each saves.
#include <cstdlib>
#include <string>

namespace kit {

// Adds glibc.malloc.hugetlb=1 to GLIBC_TUNABLES unless GLIBC_TUNABLES names that tunable
// already (a caller's own setting of it stands, 0 included). Returns whether it added it,
// i.e. whether the program still has to be started for it to apply.
inline bool request_hugepage_malloc() {
  const char* kTunable = "glibc.malloc.hugetlb";
  const char* set = std::getenv("GLIBC_TUNABLES");
  std::string tunables = set ? set : "";
  if (tunables.find(kTunable) != std::string::npos) return false;
  tunables += (tunables.empty() ? "" : ":") + std::string(kTunable) + "=1";
  return setenv("GLIBC_TUNABLES", tunables.c_str(), 1) == 0;
}

}  // namespace kit

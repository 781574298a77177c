// The one place the kit turns on glibc's huge-page malloc: sets
// GLIBC_TUNABLES=glibc.malloc.hugetlb=1 (a caller's own setting of it stands) and runs
// KIT_LAUNCHED_PROGRAM, the program beside this one, with the same arguments, in this
// process (exec: the process id stays the same). Built as kit-render-hugepages
// (tools/CMakeLists.txt, kit_hugepage_launcher), which `./kit render` runs for kit-render.
//
// Why: a heavy scene's decoded images and llvmpipe's buffers fault in page by page.
// With the tunable glibc's malloc asks for transparent huge pages (madvise), one fault
// per 2 MiB instead of per 4 KiB (docs/performance.md, Loading large models). The
// grader does without: its many short render children zero more huge pages than they
// fill (tools/grade.cmake). glibc reads the tunable only when a process starts, so a
// program cannot set it for itself without starting twice (loading its libraries
// again); this program links nothing but the C library.
#include <errno.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cstdio>
#include <string>

int main(int argc, char** argv) {
  (void)argc;
  const char* kTunable = "glibc.malloc.hugetlb";
  const char* set = getenv("GLIBC_TUNABLES");
  std::string tunables = set ? set : "";
  if (tunables.find(kTunable) == std::string::npos) {  // a caller's own choice stands
    tunables += (tunables.empty() ? "" : ":") + std::string(kTunable) + "=1";
    setenv("GLIBC_TUNABLES", tunables.c_str(), 1);
  }
  char self[PATH_MAX];
  ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
  if (n <= 0) {
    std::fprintf(stderr, "%s: cannot find its own path (/proc/self/exe): %s\n", KIT_LAUNCHER_NAME, strerror(errno));
    return 2;
  }
  std::string path(self, static_cast<size_t>(n));
  path = path.substr(0, path.rfind('/') + 1) + KIT_LAUNCHED_PROGRAM;
  execv(path.c_str(), argv);
  std::fprintf(stderr, "%s: cannot run %s: %s\n", KIT_LAUNCHER_NAME, path.c_str(), strerror(errno));
  return 2;
}

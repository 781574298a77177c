// The one place the kit turns on glibc's huge-page malloc: sets
// GLIBC_TUNABLES=glibc.malloc.hugetlb=1 (a caller's own setting of it stands) and runs
// KIT_LAUNCHED_PROGRAM, the program beside this one, with the same arguments, in this
// process (exec: the process id the grader's lock and temporary folders record stays
// the same). Built twice (tools/CMakeLists.txt, kit_hugepage_launcher): as kit-grade,
// running the grader kit-grade-main, and as kit-render-hugepages, which `./kit render`
// runs for kit-render.
//
// Why: grading is dominated by page faults (instructor/grading/measure.sh): the
// parent's images, the forked render children's copy-on-write pages and
// llvmpipe's buffers; a heavy scene's decoded images fault in the same way. With the
// tunable glibc's malloc asks for transparent huge pages (madvise), one fault per
// 2 MiB instead of per 4 KiB: about a third less CPU for a whole submission. glibc
// reads the tunable only when a process starts, so a program cannot set it for
// itself without starting twice (loading its libraries again); this program links
// nothing but the C library.
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

// Runs KIT_LAUNCHED_PROGRAM, the program beside this one, with glibc's huge-page malloc
// (common/base/hugepage_malloc.h) and the same arguments, in this process (exec: the
// process id stays the same). Built as kit-render-hugepages (tools/CMakeLists.txt,
// kit_hugepage_launcher), which `./kit render` runs for kit-render.
//
// Why: a heavy scene's decoded images and llvmpipe's buffers fault in page by page
// (docs/performance.md, Loading large models). A separate program, linking nothing but
// the C and C++ libraries, so that kit-render's libraries load once.
#include <errno.h>
#include <limits.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <cstdio>
#include <string>

#include "base/hugepage_malloc.h"

int main(int argc, char** argv) {
  (void)argc;
  kit::request_hugepage_malloc();
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

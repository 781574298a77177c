#include "images/openimageio_formats.h"

#include <dlfcn.h>

#include "base/error.h"

namespace kit {

const OpenImageIoFormats& openimageio_formats() {
  struct Loaded {
    const OpenImageIoFormats* formats = nullptr;
    std::string problem;
  };
  // KIT_OPENIMAGEIO_MODULE: the module's absolute path in the build, set by CMake.
  static const Loaded loaded = [] {
    Loaded l;
    void* module = dlopen(KIT_OPENIMAGEIO_MODULE, RTLD_NOW | RTLD_LOCAL);
    auto entry = module ? reinterpret_cast<const OpenImageIoFormats* (*)()>(dlsym(module, "kit_openimageio_formats"))
                        : nullptr;
    if (entry) l.formats = entry();
    const char* why = dlerror();
    if (!l.formats) l.problem = why ? why : "it has no entry point";
    return l;
  }();
  if (!loaded.formats)
    throw Error("this file needs OpenImageIO, and its module " KIT_OPENIMAGEIO_MODULE " could not be loaded (" +
                loaded.problem + "): build it with the kit's other programs (./kit setup)");
  return *loaded.formats;
}

}  // namespace kit

#pragma once
// A current GL 3.3 core context, created by one of three backends chosen at
// run time. Headless rendering always goes through framebuffer objects, so the
// backends differ only in how the context is made and how GL is loaded.
#include <memory>
#include <string>

namespace kit {

enum class Backend { OSMesa, EGL, Window };

Backend parse_backend(const std::string& name);  // "osmesa" | "egl" | "window"
const char* backend_name(Backend backend);

// Whether this build has the OSMesa backend: KIT_HAS_OSMESA is set by CMake (kitcore's
// public definitions) to 1 where libosmesa6-dev was found and KIT_OSMESA is ON. Mesa
// removed OSMesa in 25.1, so newer distributions build without it and render through EGL.
#ifndef KIT_HAS_OSMESA
#define KIT_HAS_OSMESA 0
#endif
constexpr bool kHasOSMesa = KIT_HAS_OSMESA != 0;
// The headless backend a program uses when no --backend is given: OSMesa where the build
// has it (its images are bit-identical to EGL's on llvmpipe), else EGL.
constexpr Backend kDefaultHeadlessBackend = kHasOSMesa ? Backend::OSMesa : Backend::EGL;
inline const char* default_headless_backend_name() { return kHasOSMesa ? "osmesa" : "egl"; }

class GlContext {
 public:
  virtual ~GlContext() = default;
  virtual Backend backend() const = 0;
  // "GL_RENDERER / GL_VERSION", for logs and reports.
  std::string describe() const;
};

// Creates and makes current a headless context (OSMesa or EGL surfaceless,
// falling back to EGL device enumeration). Throws kit::Error with the reason.
// Also sets glibc's malloc to keep freed memory for reuse (keep_freed_memory_for_reuse).
std::unique_ptr<GlContext> create_headless_context(Backend backend);
// Fixed malloc thresholds so a renderer's per-frame allocations are not returned to the
// kernel and faulted back in every frame (context.cpp says what it cost).
void keep_freed_memory_for_reuse();

// Loads GL entry points through `get_proc` and checks the version is >= 3.3.
using GlProcLoader = void* (*)(const char* name);
void load_gl(GlProcLoader get_proc, const char* backend);

}  // namespace kit

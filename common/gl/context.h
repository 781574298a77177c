#pragma once
// A current GL 3.3 core context, created by one of three backends chosen at
// run time. Headless rendering always goes through framebuffer objects, so the
// backends differ only in how the context is made and how GL is loaded.
#include <memory>
#include <string>
#include <vector>

namespace kit {

enum class Backend { OSMesa, EGL, Window };

Backend parse_backend(const std::string& name);  // "osmesa" | "egl" | "window"
const char* backend_name(Backend backend);

// Whether this build has the OSMesa backend: 1 where libosmesa6-dev was found and KIT_OSMESA
// is ON. Mesa removed OSMesa in 25.1, so newer distributions build without it and render
// through EGL. CMake sets KIT_HAS_OSMESA on context.cpp alone, so that every other object
// compiles the same with or without OSMesa and a second build (a student copy's) shares them
// through the compiler cache.
bool has_osmesa();
// The headless backend a program uses when no --backend is given: OSMesa where the build
// has it (its images are bit-identical to EGL's on llvmpipe), else EGL.
Backend default_headless_backend();
const char* default_headless_backend_name();

class GlContext {
 public:
  virtual ~GlContext() = default;
  virtual Backend backend() const = 0;
  // "GL_RENDERER / GL_VERSION", for logs and reports.
  std::string describe() const;
};

// Which OpenGL implementation a headless context asks for.
//   Any:      what the platform gives first: EGL's surfaceless platform takes the GPU's
//             Mesa driver where there is one, device enumeration NVIDIA's. For speed
//             (kit-render, the viewer's headless twin, the tests).
//   Software: Mesa's CPU rasteriser (llvmpipe, or softpipe with GALLIUM_DRIVER), the
//             implementations grading's tolerances are measured on, whatever GPU the
//             machine has: the EGL device that reports EGL_MESA_device_software. OSMesa
//             is always Mesa's software rasteriser.
enum class Device { Any, Software };
const char* device_name(Device device);  // "any" | "software"

// The EGL device to open, given each enumerated device's extension string, in order:
// for Software the first that reports EGL_MESA_device_software; for Any the first that
// does not (a GPU), else the first. -1 when none fits.
int choose_egl_device(const std::vector<std::string>& device_extensions, Device device);

// Creates and makes current a headless context (OSMesa, or EGL: surfaceless, falling
// back to device enumeration, for Any; the software device for Software). Throws
// kit::Error with the reason. Also sets glibc's malloc to keep freed memory for reuse
// (keep_freed_memory_for_reuse).
std::unique_ptr<GlContext> create_headless_context(Backend backend, Device device = Device::Any);

// After this, a fatal signal (SIGSEGV, SIGBUS, SIGILL, SIGFPE, SIGABRT) prints
// "TOOL: crashed (SIGSEGV) ..." naming the GL backend and driver in use, or being
// created, before the program ends with that signal as it would have: a crash inside
// the OpenGL implementation (GALLIUM_DRIVER=zink without a Vulkan driver, say) then
// says where it happened instead of a bare "Segmentation fault". For the programs a
// person runs (kit-render, kit-view); the grader's render workers report crashes
// themselves.
void name_gl_crashes(const char* tool);
// What a crash message names as the GL in use: set by the backends as a context is
// created ("while creating ...") and once it is current (its describe()).
void note_gl_in_use(const std::string& what);
// Fixed malloc thresholds so a renderer's per-frame allocations are not returned to the
// kernel and faulted back in every frame (context.cpp says what it cost).
void keep_freed_memory_for_reuse();

// Starts opening `backend`'s library (OSMesa's, with the LLVM it brings: about 20 ms) on
// a thread, so that a program's own setup runs beside it; does nothing for EGL (Mesa's
// driver opens in eglInitialize) or where it is already started. A process that forks
// calls finish_preloading first: a child must not inherit a half-opened library. So does
// a program before it returns from main: exit would destroy the library's static objects
// while the thread still constructs them (a hang, seen in a run that forked nothing).
void preload_headless_library(Backend backend);
// Waits for preload_headless_library's thread, if one runs.
void finish_preloading();

// Loads GL entry points through `get_proc` and checks the version is >= 3.3.
using GlProcLoader = void* (*)(const char* name);
void load_gl(GlProcLoader get_proc, const char* backend);

}  // namespace kit

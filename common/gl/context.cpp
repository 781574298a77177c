#include "gl/context.h"

// glad's header must come before any system GL header (osmesa.h includes GL/gl.h).
#include "gl/gl.h"
//
#if !KIT_GL_ES
#include <EGL/egl.h>
#include <EGL/eglext.h>
#if KIT_HAS_OSMESA
// Mesa 25's GL/osmesa.h declares its functions with GLAPI and APIENTRY, which only
// GL/gl.h defines, and glad's header (first, above) keeps GL/gl.h out: "expected
// initializer before OSMesaCreateContext" on Debian 13 (libosmesa6-dev 25.0). Mesa
// 22's header defines them itself. Defined as GL/gl.h would on Linux.
#ifndef GLAPI
#define GLAPI extern
#endif
#ifndef APIENTRY
#define APIENTRY
#endif
#include <GL/osmesa.h>
#endif

#include <dlfcn.h>
#include <malloc.h>
#endif
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <thread>
#include <type_traits>
#include <vector>

#include "base/error.h"
#include "base/fatal_signals.h"

namespace kit {

#ifndef KIT_HAS_OSMESA
#define KIT_HAS_OSMESA 0
#endif
bool has_osmesa() { return KIT_HAS_OSMESA != 0; }
Backend default_headless_backend() { return has_osmesa() ? Backend::OSMesa : Backend::EGL; }
const char* default_headless_backend_name() { return has_osmesa() ? "osmesa" : "egl"; }

Backend parse_backend(const std::string& name) {
  if (name == "osmesa") {
    if (!has_osmesa())
      throw Error("--backend osmesa: this build of the kit has no OSMesa (libosmesa6-dev was not installed when it "
                  "was configured, or Mesa 25.1 and later, which removed OSMesa); use --backend egl, the default here");
    return Backend::OSMesa;
  }
  if (name == "egl") return Backend::EGL;
  if (name == "window") return Backend::Window;
  throw Error("unknown backend '" + name + "' (expected osmesa, egl or window)");
}

const char* backend_name(Backend backend) {
  switch (backend) {
    case Backend::OSMesa: return "osmesa";
    case Backend::EGL: return "egl";
    case Backend::Window: return "window";
  }
  return "?";
}

const char* device_name(Device device) { return device == Device::Software ? "software" : "any"; }

int choose_egl_device(const std::vector<std::string>& device_extensions, Device device) {
  auto software = [&](size_t i) {
    // Whole-word match: an extension string is a space-separated list.
    const std::string padded = " " + device_extensions[i] + " ";
    return padded.find(" EGL_MESA_device_software ") != std::string::npos;
  };
  for (size_t i = 0; i < device_extensions.size(); ++i)
    if (software(i) == (device == Device::Software)) return static_cast<int>(i);
  if (device == Device::Any && !device_extensions.empty()) return 0;
  return -1;
}

namespace {

// The crash message's parts, written by the signal handler with write(2) alone (nothing
// else is safe there): fixed buffers filled before any crash can happen.
char g_crash_tool[64] = "kit";
char g_crash_gl[512] = "before any OpenGL context was created";

void copy_into(char* buffer, size_t size, const std::string& text) {
  const size_t n = std::min(size - 1, text.size());
  std::memcpy(buffer, text.data(), n);
  buffer[n] = '\0';
}

const char* signal_word(int sig) {
  switch (sig) {
    case SIGSEGV: return "SIGSEGV, a segmentation fault";
    case SIGBUS: return "SIGBUS";
    case SIGILL: return "SIGILL";
    case SIGFPE: return "SIGFPE";
    case SIGABRT: return "SIGABRT, an abort";
  }
  return "a fatal signal";
}

void on_crash(int sig) {
  write_stderr(g_crash_tool);
  write_stderr(": crashed (");
  write_stderr(signal_word(sig));
  write_stderr(") ");
  write_stderr(g_crash_gl);
  write_stderr(". A crash there is most likely in the OpenGL implementation, not in your shaders: try "
             "another backend (--backend egl or osmesa) or driver (unset GALLIUM_DRIVER), and see "
             "docs/troubleshooting.md.\n");
  raise(sig);  // SA_RESETHAND restored the default action: the program ends as it would have
}

#if !KIT_GL_ES
// "GALLIUM_DRIVER=zink" when a Mesa driver is forced by the environment, else "".
std::string forced_driver() {
  std::string text;
  for (const char* name : {"GALLIUM_DRIVER", "MESA_LOADER_DRIVER_OVERRIDE", "LIBGL_ALWAYS_SOFTWARE"})
    if (const char* value = std::getenv(name); value && *value)
      text += std::string(text.empty() ? "" : ", ") + name + "=" + value;
  return text;
}
#endif

}  // namespace

void name_gl_crashes(const char* tool) {
  copy_into(g_crash_tool, sizeof g_crash_tool, tool);
  on_fatal_signals(on_crash);
}

void note_gl_in_use(const std::string& what) { copy_into(g_crash_gl, sizeof g_crash_gl, what); }

std::string GlContext::describe() const {
  auto str = [](GLenum e) {
    const GLubyte* s = glGetString(e);
    return s ? std::string(reinterpret_cast<const char*>(s)) : std::string("?");
  };
  return std::string(backend_name(backend())) + ": " + str(GL_RENDERER) + " / " + str(GL_VERSION);
}

void load_gl(GlProcLoader get_proc, const char* backend) {
#if KIT_GL_ES
  // Emscripten links WebGL2's functions directly: there is nothing to load.
  (void)get_proc;
  (void)backend;
#elif KIT_GLAD_GENERATION == 1
  if (!gladLoadGLLoader(reinterpret_cast<GLADloadproc>(get_proc)))
    throw Error(std::string(backend) + ": could not load OpenGL entry points");
  const int major = GLVersion.major, minor = GLVersion.minor;
#else
  int version = gladLoadGL(reinterpret_cast<GLADloadfunc>(get_proc));
  if (version == 0) throw Error(std::string(backend) + ": could not load OpenGL entry points");
  const int major = GLAD_VERSION_MAJOR(version), minor = GLAD_VERSION_MINOR(version);
#endif
#if !KIT_GL_ES
  if (major * 10 + minor < 33)
    throw Error(std::string(backend) + ": OpenGL 3.3 core is required, got " + std::to_string(major) + "." +
                std::to_string(minor));
#endif
}

#if !KIT_GL_ES
namespace {

#if KIT_HAS_OSMESA
// OSMesa's entry points, from the library opened at run time rather than linked. Linked,
// libOSMesa and the LLVM it brings cost a program 20-30 ms of loading before main (3,300
// page faults; Mesa 22.3), all of it before kit-grade could fork its first render worker;
// opened, it loads on a thread beside kit-grade's own setup (preload_headless_library).
// KIT_OSMESA_LIBRARY is its soname, from CMake.
struct OSMesaLibrary {
  void* handle = nullptr;
  std::string error;  // why it could not be opened, else ""
  decltype(&OSMesaCreateContextAttribs) create_context = nullptr;
  decltype(&OSMesaMakeCurrent) make_current = nullptr;
  decltype(&OSMesaDestroyContext) destroy_context = nullptr;
  decltype(&OSMesaGetProcAddress) get_proc_address = nullptr;
};

OSMesaLibrary open_osmesa() {
  OSMesaLibrary lib;
  // RTLD_NOW: every symbol bound once here, not again in each forked render worker.
  lib.handle = dlopen(KIT_OSMESA_LIBRARY, RTLD_NOW | RTLD_LOCAL);
  if (!lib.handle) {
    const char* why = dlerror();
    lib.error = std::string("osmesa: cannot load ") + KIT_OSMESA_LIBRARY + " (" + (why ? why : "?") +
                "); install libosmesa6, or use --backend egl";
    return lib;
  }
  auto symbol = [&](auto& out, const char* name) {
    out = reinterpret_cast<std::remove_reference_t<decltype(out)>>(dlsym(lib.handle, name));
    if (!out && lib.error.empty()) lib.error = std::string("osmesa: ") + KIT_OSMESA_LIBRARY + " has no " + name;
  };
  symbol(lib.create_context, "OSMesaCreateContextAttribs");
  symbol(lib.make_current, "OSMesaMakeCurrent");
  symbol(lib.destroy_context, "OSMesaDestroyContext");
  symbol(lib.get_proc_address, "OSMesaGetProcAddress");
  return lib;
}

// Opened once per process, by whichever thread asks first.
const OSMesaLibrary& osmesa() {
  static const OSMesaLibrary lib = open_osmesa();
  if (!lib.error.empty()) throw Error(lib.error);
  return lib;
}

class OSMesaContextImpl : public GlContext {
 public:
  OSMesaContextImpl() {
    // Core profile 3.3; no depth/stencil on the default buffer: the kit draws into FBOs.
    const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 0,
                           OSMESA_PROFILE, OSMESA_CORE_PROFILE,
                           OSMESA_CONTEXT_MAJOR_VERSION, 3, OSMESA_CONTEXT_MINOR_VERSION, 3, 0};
    context_ = lib_.create_context(attribs, nullptr);
    if (!context_) throw Error("osmesa: could not create a GL 3.3 core context");
    if (!lib_.make_current(context_, pixels_.data(), GL_UNSIGNED_BYTE, 1, 1)) {
      lib_.destroy_context(context_);
      throw Error("osmesa: could not make the context current");
    }
    load_gl(reinterpret_cast<GlProcLoader>(lib_.get_proc_address), "osmesa");
  }
  ~OSMesaContextImpl() override { lib_.destroy_context(context_); }
  Backend backend() const override { return Backend::OSMesa; }

 private:
  const OSMesaLibrary& lib_ = osmesa();
  OSMesaContext context_ = nullptr;
  std::vector<unsigned char> pixels_ = std::vector<unsigned char>(4);
};
#endif

class EglContextImpl : public GlContext {
 public:
  explicit EglContextImpl(Device device) {
    auto get_platform_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
        eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (!get_platform_display) throw Error("egl: eglGetPlatformDisplayEXT is not available");
    if (device == Device::Software) {
      // Never surfaceless here: it opens the GPU's Mesa driver where the machine has one.
      display_ = device_display(get_platform_display, Device::Software);
      if (!initialize())
        throw Error("egl: no EGL device reports EGL_MESA_device_software (Mesa's software rasteriser), so "
                    "grading cannot render as it is measured (is libegl-mesa0 installed?); --gpu grades on "
                    "whatever device there is");
    } else {
      display_ = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
      if (!initialize()) {
        display_ = device_display(get_platform_display, Device::Any);
        if (!initialize()) throw Error("egl: no display could be initialised (tried surfaceless and device enumeration)");
      }
    }
    if (!eglBindAPI(EGL_OPENGL_API)) throw Error("egl: desktop OpenGL API not available");
    const EGLint context_attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 3,
                                      EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                      EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    // Configless + surfaceless: the kit never draws to an EGL surface.
    context_ = eglCreateContext(display_, EGL_NO_CONFIG_KHR, EGL_NO_CONTEXT, context_attribs);
    if (context_ == EGL_NO_CONTEXT) throw Error("egl: could not create a GL 3.3 core context (error 0x" + hex(eglGetError()) + ")");
    if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
      throw Error("egl: could not make the context current (error 0x" + hex(eglGetError()) + ")");
    load_gl(reinterpret_cast<GlProcLoader>(eglGetProcAddress), "egl");
  }
  ~EglContextImpl() override {
    if (display_ != EGL_NO_DISPLAY) {
      eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
      if (context_ != EGL_NO_CONTEXT) eglDestroyContext(display_, context_);
      eglTerminate(display_);
    }
  }
  Backend backend() const override { return Backend::EGL; }

 private:
  static std::string hex(EGLint v) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "%x", static_cast<unsigned>(v));
    return buf;
  }
  bool initialize() {
    if (display_ == EGL_NO_DISPLAY) return false;
    EGLint major = 0, minor = 0;
    return eglInitialize(display_, &major, &minor) == EGL_TRUE;
  }
  // An enumerated device's display, chosen by choose_egl_device: the software device,
  // or (Any: drivers without Mesa's surfaceless platform, e.g. NVIDIA) a GPU first.
  // Devices whose display does not initialise are passed over.
  static EGLDisplay device_display(PFNEGLGETPLATFORMDISPLAYEXTPROC get_platform_display, Device device) {
    auto query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
    auto query_string = reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(eglGetProcAddress("eglQueryDeviceStringEXT"));
    if (!query_devices || !query_string) return EGL_NO_DISPLAY;
    EGLDeviceEXT devices[16];
    EGLint count = 0;
    if (!query_devices(16, devices, &count) || count <= 0) return EGL_NO_DISPLAY;
    std::vector<EGLDeviceEXT> candidates(devices, devices + count);
    while (!candidates.empty()) {
      std::vector<std::string> extensions;
      for (EGLDeviceEXT d : candidates) {
        const char* e = query_string(d, EGL_EXTENSIONS);
        extensions.push_back(e ? e : "");
      }
      const int chosen = choose_egl_device(extensions, device);
      if (chosen < 0) return EGL_NO_DISPLAY;
      EGLDisplay d = get_platform_display(EGL_PLATFORM_DEVICE_EXT, candidates[chosen], nullptr);
      EGLint major = 0, minor = 0;
      if (d != EGL_NO_DISPLAY && eglInitialize(d, &major, &minor)) {
        eglTerminate(d);
        return d;
      }
      candidates.erase(candidates.begin() + chosen);
    }
    return EGL_NO_DISPLAY;
  }

  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
};

}  // namespace
#endif

void keep_freed_memory_for_reuse() {
  // llvmpipe allocates and frees its per-frame binning memory every frame. With glibc's
  // adaptive thresholds, a process whose heap has seen large images come and go (kit-bench
  // after its reference, the grader) hands that memory back to the kernel after each frame
  // and faults it in again in the next: kit-bench's geometry pass on the crowd scene took
  // 90 ms that way, 22-28 ms with the memory kept (handouts/02-lighting.md, "Speed").
  // Fixed thresholds keep freed blocks in the heap for the next frame; blocks of 64 MiB
  // and more (whole images) are still mapped and returned on their own.
  // In the browser (no glibc, no llvmpipe) there is nothing to keep.
#if !KIT_GL_ES
  constexpr int kMmapThresholdBytes = 64 << 20;
  constexpr int kTrimThresholdBytes = 128 << 20;
  mallopt(M_MMAP_THRESHOLD, kMmapThresholdBytes);
  mallopt(M_TRIM_THRESHOLD, kTrimThresholdBytes);
#endif
}

std::unique_ptr<GlContext> create_headless_context(Backend backend, Device device) {
#if KIT_GL_ES
  (void)device;
  throw Error(std::string(backend_name(backend)) + ": no headless context in the browser (kit-web draws into "
              "its canvas's WebGL2 context)");
#else
  keep_freed_memory_for_reuse();
  const std::string forced = forced_driver();
  note_gl_in_use(std::string("while creating the ") + backend_name(backend) + " context (device: " +
                 device_name(device) + (forced.empty() ? "" : ", " + forced) + ")");
  std::unique_ptr<GlContext> context;
  switch (backend) {
    case Backend::OSMesa:
#if KIT_HAS_OSMESA
      context = std::make_unique<OSMesaContextImpl>();
      break;
#else
      throw Error("osmesa: this build of the kit has no OSMesa backend (use egl)");
#endif
    case Backend::EGL: context = std::make_unique<EglContextImpl>(device); break;
    case Backend::Window:
      throw Error("create_headless_context: the window backend is created by the viewer (kit::Window)");
  }
  note_gl_in_use("with " + context->describe() + (forced.empty() ? "" : " (" + forced + ")"));
  return context;
#endif
}

namespace {

// preload_headless_library's thread: joined before any fork and before main returns
// (finish_preloading); the destructor joins only a thread still running at exit.
struct Preload {
  std::thread thread;
  ~Preload() {
    if (thread.joinable()) thread.join();
  }
};

Preload& preload() {
  static Preload p;
  return p;
}

}  // namespace

void preload_headless_library(Backend backend) {
#if KIT_HAS_OSMESA
  if (backend != Backend::OSMesa || preload().thread.joinable()) return;
  // The thread starts with every signal blocked: a Ctrl-C is the main thread's to handle
  // (kit-grade's InterruptGuard waits for it there). Its error, if any, is thrown again
  // where the first context is made.
  sigset_t all, previous;
  sigfillset(&all);
  pthread_sigmask(SIG_BLOCK, &all, &previous);
  preload().thread = std::thread([] {
    try {
      osmesa();
    } catch (const Error&) {
    }
  });
  pthread_sigmask(SIG_SETMASK, &previous, nullptr);
#else
  (void)backend;
#endif
}

void finish_preloading() {
  if (preload().thread.joinable()) preload().thread.join();
}

}  // namespace kit

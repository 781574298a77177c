// Which OpenGL implementation a headless context opens (common/gl/context.h): grading
// asks for Mesa's software rasteriser explicitly, whatever GPU the machine has, so the
// EGL device that reports EGL_MESA_device_software is chosen even when a GPU's device
// is enumerated first; and a crash inside the GL implementation names the backend and
// the driver instead of ending with a bare signal.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <string>
#include <vector>

#include "gl/context.h"
#include "gl/gl.h"

namespace {

// Extension strings as drivers report them: NVIDIA's device, then Mesa's software one
// (the order device enumeration gives on a machine with an NVIDIA GPU and Mesa).
const std::string kNvidia = "EGL_NV_device_cuda EGL_EXT_device_drm EGL_EXT_device_drm_render_node";
const std::string kMesaGpu = "EGL_EXT_device_drm EGL_EXT_device_drm_render_node";
const std::string kMesaSoftware = "EGL_MESA_device_software";

TEST(GlDevice, SoftwareIsChosenAfterAHardwareDevice) {
  EXPECT_EQ(kit::choose_egl_device({kNvidia, kMesaSoftware}, kit::Device::Software), 1);
  EXPECT_EQ(kit::choose_egl_device({kNvidia, kMesaGpu, "EGL_EXT_foo " + kMesaSoftware}, kit::Device::Software), 2);
  // Witness: the first device that works, as the platform gives them, is the GPU.
  EXPECT_EQ(kit::choose_egl_device({kNvidia, kMesaSoftware}, kit::Device::Any), 0);
}

TEST(GlDevice, AnyPrefersAGpuAndFallsBackToSoftware) {
  EXPECT_EQ(kit::choose_egl_device({kMesaSoftware, kMesaGpu}, kit::Device::Any), 1);
  EXPECT_EQ(kit::choose_egl_device({kMesaSoftware}, kit::Device::Any), 0);
  EXPECT_EQ(kit::choose_egl_device({}, kit::Device::Any), -1);
}

TEST(GlDevice, SoftwareNeedsTheWholeExtensionName) {
  EXPECT_EQ(kit::choose_egl_device({kNvidia, kMesaGpu}, kit::Device::Software), -1);
  EXPECT_EQ(kit::choose_egl_device({"EGL_MESA_device_software_x", "xEGL_MESA_device_software"}, kit::Device::Software), -1);
  EXPECT_EQ(kit::choose_egl_device({}, kit::Device::Software), -1);
}

// On this machine: EGL's software device is Mesa's CPU rasteriser.
TEST(GlDevice, EglSoftwareContextIsMesasRasteriser) {
  auto context = kit::create_headless_context(kit::Backend::EGL, kit::Device::Software);
  const std::string renderer = context->describe();
  EXPECT_TRUE(renderer.find("llvmpipe") != std::string::npos || renderer.find("softpipe") != std::string::npos)
      << renderer;
}

// Runs `body` in a child with stderr captured; returns that text and sets `status`.
template <typename Body>
std::string child_stderr(Body body, int* status) {
  int fds[2];
  if (pipe(fds) != 0) return "pipe failed";
  pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    dup2(fds[1], STDERR_FILENO);
    body();
    _exit(0);
  }
  close(fds[1]);
  std::string text;
  char buffer[512];
  for (ssize_t n; (n = read(fds[0], buffer, sizeof buffer)) > 0;) text.append(buffer, static_cast<size_t>(n));
  close(fds[0]);
  waitpid(pid, status, 0);
  return text;
}

TEST(GlCrash, ASegfaultNamesTheBackendAndTheDriver) {
  int status = 0;
  std::string text = child_stderr(
      [] {
        kit::name_gl_crashes("kit-render");
        kit::note_gl_in_use("while creating the osmesa context (device: any, GALLIUM_DRIVER=zink)");
        raise(SIGSEGV);
      },
      &status);
  ASSERT_TRUE(WIFSIGNALED(status)) << "the program must still end with its signal";
  EXPECT_EQ(WTERMSIG(status), SIGSEGV);
  EXPECT_NE(text.find("kit-render: crashed (SIGSEGV"), std::string::npos) << text;
  EXPECT_NE(text.find("osmesa context"), std::string::npos) << text;
  EXPECT_NE(text.find("GALLIUM_DRIVER=zink"), std::string::npos) << text;

  // Witness: without it the same crash says nothing (the default action, which a
  // sanitizer build replaces with its own report).
  text = child_stderr(
      [] {
        signal(SIGSEGV, SIG_DFL);
        raise(SIGSEGV);
      },
      &status);
  ASSERT_TRUE(WIFSIGNALED(status));
  EXPECT_EQ(text, "");
}

// Once a context is current, the crash message names its renderer.
TEST(GlCrash, TheMessageNamesTheContextInUse) {
  int status = 0;
  std::string text = child_stderr(
      [] {
        kit::name_gl_crashes("kit-view");
        auto context = kit::create_headless_context(kit::Backend::EGL, kit::Device::Software);
        raise(SIGBUS);
      },
      &status);
  ASSERT_TRUE(WIFSIGNALED(status));
  EXPECT_EQ(WTERMSIG(status), SIGBUS);
  EXPECT_NE(text.find("kit-view: crashed (SIGBUS) with egl: "), std::string::npos) << text;
}

}  // namespace

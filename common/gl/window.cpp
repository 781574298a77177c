#include "gl/window.h"

#define GLFW_INCLUDE_NONE  // GL declarations come from glad
#include <GLFW/glfw3.h>

#include "base/error.h"
#include "gl/gl.h"

namespace kit {

namespace {
std::string g_last_glfw_error;  // written by GLFW's C callback, read right after a failed call
void remember_glfw_error(int, const char* description) { g_last_glfw_error = description ? description : ""; }
}  // namespace

Window::Window(int width, int height, const std::string& title, bool visible) {
  glfwSetErrorCallback(remember_glfw_error);
  if (!glfwInit()) throw Error("window: GLFW could not initialise (no display? " + g_last_glfw_error + ")");
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_VISIBLE, visible ? GLFW_TRUE : GLFW_FALSE);
  keep_freed_memory_for_reuse();  // context.h: the viewer renders a frame after another
  note_gl_in_use("while creating the window's GL context (GLFW)");
  window_ = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
  if (!window_) {
    glfwTerminate();
    throw Error("window: could not create a GL 3.3 core window (" + g_last_glfw_error + ")");
  }
  glfwMakeContextCurrent(window_);
  glfwSwapInterval(1);
  load_gl(reinterpret_cast<GlProcLoader>(glfwGetProcAddress), "window");
  note_gl_in_use("with " + describe());
}

Window::~Window() {
  if (window_) glfwDestroyWindow(window_);
  glfwTerminate();
}

bool Window::should_close() const { return glfwWindowShouldClose(window_); }
void Window::swap_buffers() const { glfwSwapBuffers(window_); }
void Window::framebuffer_size(int* width, int* height) const { glfwGetFramebufferSize(window_, width, height); }

}  // namespace kit

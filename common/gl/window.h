#pragma once
// The GLFW window backend: a visible (or hidden) window with a GL 3.3 core
// context, loaded through glfwGetProcAddress.
#include <string>

#include "gl/context.h"

struct GLFWwindow;

namespace kit {

class Window : public GlContext {
 public:
  Window(int width, int height, const std::string& title, bool visible = true);
  ~Window() override;
  Window(const Window&) = delete;
  Window& operator=(const Window&) = delete;
  Backend backend() const override { return Backend::Window; }

  GLFWwindow* handle() const { return window_; }
  bool should_close() const;
  void swap_buffers() const;
  void framebuffer_size(int* width, int* height) const;

 private:
  GLFWwindow* window_ = nullptr;
};

}  // namespace kit

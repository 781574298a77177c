#pragma once
// The G-buffer: KIT_GBUF_COUNT colour attachments and a depth texture in one FBO. The
// layout (formats, channel meaning, texture units) is in shaders/gbuffer_layout.h.
#include <array>

#include "gbuffer_layout.h"
#include "gl/gl_objects.h"

namespace kit {

// The geometry pass's start on any G-buffer FBO (GBuffer and the bench's layouts):
// binds `fbo`, sets the viewport, depth test LESS with writes, back-face culling,
// no blending, and clears every colour attachment it draws to (its draw buffers) to
// `clear` (0 for G-buffers, whose mask must read "no surface") and, with `clear_depth`,
// depth to 1 (the forward pass's layers keep the opaque depth they were given). Clears
// obey the scissor test.
void begin_geometry_pass_on(const Framebuffer& fbo, int width, int height, const glm::vec4& clear = glm::vec4(0.0f),
                            bool clear_depth = true);

class GBuffer {
 public:
  GBuffer(int width, int height);
  // Reallocates the attachments when the size changes (window resize).
  void resize(int width, int height);
  int width() const { return width_; }
  int height() const { return height_; }

  static TextureFormat attachment_format(int index);  // index: KIT_GBUF_*
  static TextureFormat depth_format();
  static const char* attachment_name(int index);       // "position", "normal", ...
  // Bytes one pixel takes across all attachments and depth.
  static int bytes_per_pixel();

  const Texture2D& attachment(int index) const { return colors_[static_cast<size_t>(index)]; }
  const Texture2D& depth() const { return depth_; }
  const Framebuffer& framebuffer() const { return fbo_; }

  // Binds the FBO, sets the viewport and clears: mask 0 and depth 1 everywhere.
  void begin_geometry_pass() const;
  // Binds every attachment and depth to its KIT_UNIT_GBUF_* unit.
  void bind_textures() const;

 private:
  void allocate();
  int width_, height_;
  std::array<Texture2D, KIT_GBUF_COUNT> colors_;
  Texture2D depth_;
  Framebuffer fbo_;
};

}  // namespace kit

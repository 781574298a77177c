#include "render/gbuffer.h"

#include "base/error.h"
#include "gbuffer_layout.h"

namespace kit {

GBuffer::GBuffer(int width, int height) : width_(width), height_(height) { allocate(); }

TextureFormat GBuffer::attachment_format(int index) {
  switch (index) {
    case KIT_GBUF_POSITION: return {GL_RGBA16F, GL_RGBA, GL_FLOAT};
    case KIT_GBUF_NORMAL: return {GL_RGBA16F, GL_RGBA, GL_FLOAT};
    case KIT_GBUF_ALBEDO: return {GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE};
    case KIT_GBUF_MATERIAL: return {GL_RGBA16F, GL_RGBA, GL_FLOAT};
    case KIT_GBUF_EMISSION: return {GL_RGBA16F, GL_RGBA, GL_FLOAT};
  }
  throw Error("no G-buffer attachment " + std::to_string(index));
}

TextureFormat GBuffer::depth_format() { return {GL_DEPTH_COMPONENT24, GL_DEPTH_COMPONENT, GL_FLOAT}; }

const char* GBuffer::attachment_name(int index) {
  static const char* names[] = {"position", "normal", "albedo", "material", "emission"};
  return index >= 0 && index < KIT_GBUF_COUNT ? names[index] : "?";
}

int GBuffer::bytes_per_pixel() { return 8 + 8 + 4 + 8 + 8 + 4; }  // 4 x RGBA16F, RGBA8, 32-bit depth word

void GBuffer::allocate() {
  for (int i = 0; i < KIT_GBUF_COUNT; ++i) {
    colors_[static_cast<size_t>(i)] = Texture2D(width_, height_, attachment_format(i));
    fbo_.attach_color(i, colors_[static_cast<size_t>(i)]);
  }
  depth_ = Texture2D(width_, height_, depth_format());
  fbo_.attach_depth(depth_);
  fbo_.set_draw_buffers(KIT_GBUF_COUNT);
  std::string reason = fbo_.incomplete_reason();
  if (!reason.empty()) throw Error("G-buffer framebuffer is incomplete: " + reason);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

void GBuffer::resize(int width, int height) {
  if (width == width_ && height == height_) return;
  width_ = width;
  height_ = height;
  allocate();
}

void begin_geometry_pass_on(const Framebuffer& fbo, int width, int height, const glm::vec4& clear, bool clear_depth) {
  fbo.bind();
  glViewport(0, 0, width, height);
  glDisable(GL_BLEND);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glEnable(GL_CULL_FACE);
  glCullFace(GL_BACK);
  // One clear of all the attachments: under a scissor (the forward pass's layers) Mesa
  // clears by drawing a quad, and one glClearBuffer per attachment made a shader for
  // llvmpipe to compile for each (5 of a cold grading run's compilations).
  glClearColor(clear.r, clear.g, clear.b, clear.a);
  glClear(GL_COLOR_BUFFER_BIT);
  const float far_depth = 1.0f;
  if (clear_depth) glClearBufferfv(GL_DEPTH, 0, &far_depth);
}

void GBuffer::begin_geometry_pass() const { begin_geometry_pass_on(fbo_, width_, height_); }

void GBuffer::bind_textures() const {
  for (int i = 0; i < KIT_GBUF_COUNT; ++i) colors_[static_cast<size_t>(i)].bind(KIT_UNIT_GBUF_POSITION + i);
  depth_.bind(KIT_UNIT_GBUF_DEPTH);
}

}  // namespace kit

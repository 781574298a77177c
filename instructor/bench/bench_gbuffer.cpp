#include "bench_gbuffer.h"

#include <cstdio>

#include "bench_layout.h"
#include "base/error.h"
#include "render/gbuffer.h"
#include "gbuffer_layout.h"

namespace kit::bench {

namespace {

constexpr TextureFormat kRgba32f{GL_RGBA32F, GL_RGBA, GL_FLOAT};
constexpr TextureFormat kRgba8{GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE};
// Unorm, not snorm: unorm formats are colour-renderable in every GL 3.3 implementation.
constexpr TextureFormat kRg16{GL_RG16, GL_RG, GL_UNSIGNED_SHORT};
constexpr TextureFormat kRg8{GL_RG8, GL_RG, GL_UNSIGNED_BYTE};

std::vector<LayoutInfo> make_layouts() {
  auto labs = [](int i) { return GBuffer::attachment_format(i); };
  std::vector<LayoutInfo> out;
  out.push_back({"reference", false,
                 {kRgba32f, kRgba32f, labs(KIT_GBUF_ALBEDO), labs(KIT_GBUF_MATERIAL), labs(KIT_GBUF_EMISSION)},
                 GBuffer::depth_format()});
  out.push_back({"seed002", false,
                 {labs(KIT_GBUF_POSITION), labs(KIT_GBUF_NORMAL), labs(KIT_GBUF_ALBEDO), labs(KIT_GBUF_MATERIAL),
                  labs(KIT_GBUF_EMISSION)},
                 GBuffer::depth_format()});
  out.push_back({"lean16", true, {kRg16, kRgba8, kRgba8, kRgba8}, GBuffer::depth_format()});
  out.push_back({"lean8", true, {kRg8, kRgba8, kRgba8, kRgba8}, GBuffer::depth_format()});
  return out;
}

}  // namespace

const LayoutInfo& layout_info(Layout layout) {
  static const std::vector<LayoutInfo> layouts = make_layouts();
  return layouts[static_cast<size_t>(layout)];
}

Layout parse_layout(const std::string& name) {
  for (Layout l : {Layout::Reference, Layout::Seed002, Layout::Lean16, Layout::Lean8})
    if (name == layout_info(l).name) return l;
  throw Error("unknown G-buffer layout '" + name + "' (reference, seed002, lean16, lean8)");
}

int bytes_per_texel(const TextureFormat& f) {
  switch (f.internal_format) {
    case GL_RGBA32F: return 16;
    case GL_RGBA16F: return 8;
    case GL_RGBA8:
    case GL_SRGB8_ALPHA8:
    case GL_RG16:
    case GL_RG16F:
    case GL_DEPTH_COMPONENT24:
    case GL_DEPTH_COMPONENT32F: return 4;
    case GL_RG8: return 2;
  }
  char hex[16];
  std::snprintf(hex, sizeof hex, "0x%04x", f.internal_format);
  throw Error(std::string("bytes_per_texel: format ") + hex + " is not in the table");
}

int bytes_per_pixel(Layout layout) {
  const LayoutInfo& info = layout_info(layout);
  int bytes = bytes_per_texel(info.depth);
  for (const TextureFormat& f : info.colors) bytes += bytes_per_texel(f);
  return bytes;
}

LayoutGBuffer::LayoutGBuffer(Layout layout, int width, int height) : layout_(layout), width_(width), height_(height) {
  const LayoutInfo& info = layout_info(layout);
  int count = static_cast<int>(info.colors.size());
  for (int i = 0; i < count; ++i) {
    colors_.emplace_back(width, height, info.colors[static_cast<size_t>(i)]);
    fbo_.attach_color(i, colors_.back());
  }
  depth_ = Texture2D(width, height, info.depth);
  fbo_.attach_depth(depth_);
  fbo_.set_draw_buffers(count);
  std::string reason = fbo_.incomplete_reason();
  if (!reason.empty()) throw Error(std::string("G-buffer '") + info.name + "' is incomplete: " + reason);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

void LayoutGBuffer::begin_geometry_pass() const {
  begin_geometry_pass_on(fbo_, width_, height_);
}

void LayoutGBuffer::bind_textures() const {
  if (layout_info(layout_).lean) {
    colors_[KIT_LEAN_NORMAL].bind(KIT_UNIT_GBUF_NORMAL);
    colors_[KIT_LEAN_ALBEDO].bind(KIT_UNIT_GBUF_ALBEDO);
    colors_[KIT_LEAN_MATERIAL].bind(KIT_UNIT_GBUF_MATERIAL);
    colors_[KIT_LEAN_EMISSION].bind(KIT_UNIT_GBUF_EMISSION);
  } else {
    for (size_t i = 0; i < colors_.size(); ++i) colors_[i].bind(KIT_UNIT_GBUF_POSITION + static_cast<int>(i));
  }
  depth_.bind(KIT_UNIT_GBUF_DEPTH);
}

}  // namespace kit::bench

#pragma once
// G-buffer layouts kit-bench compares (formats in instructor/bench/shaders/bench_layout.h):
//   Reference  RGBA32F position + RGBA32F normal, RGBA8 albedo, RGBA16F material and
//              emission, depth
//   Seed002    the labs' GBuffer (gbuffer.h): RGBA16F position + normal, RGBA8 albedo,
//              RGBA16F material and emission, depth
//   Lean16     depth (position reconstructed), RG16 octahedral normal, RGBA8 albedo,
//              RGBA8 packed material, RGBA8 encoded emission
//   Lean8      as Lean16 with an RG8 normal
#include <string>
#include <vector>

#include "gl/gl_objects.h"

namespace kit::bench {

enum class Layout { Reference, Seed002, Lean16, Lean8 };

struct LayoutInfo {
  const char* name;                   // "reference", "seed002", "lean16", "lean8"
  bool lean;                          // KIT_BENCH_LAYOUT_LEAN (else FAT)
  std::vector<TextureFormat> colors;  // attachment i: gbuffer_layout.h (FAT) or bench_layout.h (LEAN) index
  TextureFormat depth;
};

const LayoutInfo& layout_info(Layout layout);
Layout parse_layout(const std::string& name);

// Bytes one texel of `format` occupies (a 24-bit depth counts as its 32-bit word,
// as GBuffer::bytes_per_pixel counts it).
int bytes_per_texel(const TextureFormat& format);
// Bytes per pixel over all attachments and depth.
int bytes_per_pixel(Layout layout);

// A G-buffer of any layout: colour attachments and a depth texture in one FBO.
class LayoutGBuffer {
 public:
  LayoutGBuffer(Layout layout, int width, int height);
  Layout layout() const { return layout_; }
  int width() const { return width_; }
  int height() const { return height_; }
  const Texture2D& attachment(int index) const { return colors_[static_cast<size_t>(index)]; }
  const Texture2D& depth() const { return depth_; }

  // Binds the FBO, sets the viewport and the geometry pass's depth/cull state, and
  // clears every attachment to 0 (mask 0) and depth to 1, as GBuffer does.
  void begin_geometry_pass() const;
  // Binds the attachments to the KIT_UNIT_GBUF_* units the shaders read them from:
  // FAT by attachment index; LEAN normal, albedo, material and emission to the
  // normal, albedo, material and emission units. Depth to KIT_UNIT_GBUF_DEPTH.
  void bind_textures() const;

 private:
  Layout layout_;
  int width_, height_;
  std::vector<Texture2D> colors_;
  Texture2D depth_;
  Framebuffer fbo_;
};

}  // namespace kit::bench

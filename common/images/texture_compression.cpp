#include "images/texture_compression.h"

#include <algorithm>

#include "base/text.h"

namespace kit {

bool is_large_texture(int width, int height) {
  return static_cast<size_t>(width) * static_cast<size_t>(height) >= kLargeTextureTexels;
}

size_t rgba8_chain_bytes(int width, int height) {
  size_t bytes = 0;
  for (;;) {
    bytes += static_cast<size_t>(std::max(width, 0)) * static_cast<size_t>(std::max(height, 0)) * 4;
    if (width <= 1 && height <= 1) return bytes;
    width = std::max(1, width / 2);
    height = std::max(1, height / 2);
  }
}

bool renders_on_cpu(const std::string& gl_renderer) {
  const std::string name = lower_case(gl_renderer);
  for (const char* cpu : {"llvmpipe", "softpipe", "swrast", "software rasterizer", "swiftshader"})
    if (name.find(cpu) != std::string::npos) return true;
  return false;
}

std::string mebibytes(size_t bytes) { return std::to_string((bytes + (size_t{1} << 19)) >> 20) + " MiB"; }

TextureCompressionDecision decide_texture_compression(TextureCompression mode, size_t uncompressed_bytes,
                                                      bool any_large, const std::string& gl_renderer,
                                                      const std::string& s3tc_unavailable) {
  TextureCompressionDecision d;
  d.uncompressed_bytes = uncompressed_bytes;
  const bool over_budget = uncompressed_bytes > kTextureMemoryBudgetBytes;
  std::string why;
  if (mode == TextureCompression::Off) {
    why = "--compress-textures off";
  } else if (!any_large) {
    why = "none of 1024x1024 texels or more";
  } else if (mode == TextureCompression::On) {
    d.wanted = true;
    why = "--compress-textures on";
  } else if (over_budget) {
    d.wanted = true;
  } else if (!renders_on_cpu(gl_renderer)) {
    d.wanted = true;
    why = "a GPU decodes S3TC as it samples: " + gl_renderer;
  } else {
    why = gl_renderer.substr(0, gl_renderer.find(' ')) + " decodes S3TC in software, slower to sample";
  }
  d.compress = d.wanted && s3tc_unavailable.empty();
  if (d.wanted && !d.compress) why = s3tc_unavailable;
  d.reason = "textures: " + mebibytes(uncompressed_bytes) + " uncompressed, " +
             (over_budget ? "over the " + mebibytes(kTextureMemoryBudgetBytes) + " budget"
                          : "budget " + mebibytes(kTextureMemoryBudgetBytes)) +
             (d.compress ? ": large ones compressed to S3TC" : ": not compressed") + (why.empty() ? "" : " (" + why + ")");
  return d;
}

}  // namespace kit

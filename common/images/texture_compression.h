#pragma once
// Whether a scene's large textures are uploaded as S3TC blocks (texture_prepare.h makes
// them): decided once per scene by SceneGpu, from how many bytes its textures take and
// what samples them, and said by kit-render --timings.
#include <cstddef>
#include <string>

namespace kit {

// A texture of at least this many texels (1024x1024) is large: when a scene's textures
// are compressed (decide_texture_compression), its large ones are, normal maps excepted.
constexpr size_t kLargeTextureTexels = size_t{1024} * 1024;
bool is_large_texture(int width, int height);

// --compress-textures auto|on|off.
enum class TextureCompression { Auto, On, Off };

// The texture bytes (RGBA8 with mip chains) a scene may upload before `auto` compresses
// its large textures. Compression trades speed for memory on llvmpipe, which decodes
// S3TC texel by texel in software: six 1024x1024 base colours compressed cost its
// geometry pass about 25 ms a frame at 800x600 (LearnOpenGL 8.1's nanosuits,
// docs/performance.md). It pays where the bytes matter: llvmpipe keeps textures in the
// process's own memory, and the heavy scene (kit-scenes --heavy: 16 textures of
// 2048x2048, 341 MiB uncompressed, 43 MiB compressed) must stay under 500 MB resident
// with its million triangles. The budget is half of that: a scene over it is
// compressed; every kit scene, and a model with a few 1024x1024 textures, is not.
constexpr size_t kTextureMemoryBudgetBytes = size_t{256} << 20;

// The bytes of a width x height RGBA8 texture with its mip chain down to 1x1.
size_t rgba8_chain_bytes(int width, int height);

// Whether a GL_RENDERER string names a rasteriser running on the CPU (llvmpipe,
// softpipe, swrast, SwiftShader), which decodes S3TC in software at every sample. A GPU
// decodes blocks in its texture units as it samples and reads fewer bytes: there
// `auto` compresses the large textures whatever their total.
bool renders_on_cpu(const std::string& gl_renderer);

// What SceneGpu does with a scene's large textures, and why, in the words --timings
// prints ("textures: 32 MiB uncompressed, budget 256 MiB: not compressed (...)").
struct TextureCompressionDecision {
  bool compress = false;
  bool wanted = false;            // compress but for a context without the S3TC formats
  size_t uncompressed_bytes = 0;  // every texture the scene uploads, as RGBA8 chains
  size_t uploaded_bytes = 0;      // what SceneGpu uploaded, compressed or not (set after the upload)
  std::string reason;
};

// `mode` for a scene whose textures take `uncompressed_bytes` as RGBA8 chains, `any_large`
// when one of them is large (normal maps aside), on a context whose GL_RENDERER is
// `gl_renderer`; `s3tc_unavailable` is empty where the context has the S3TC formats,
// else says why not. Off never compresses; On does when a texture is large. Auto does
// when a texture is large and either the bytes exceed kTextureMemoryBudgetBytes or the
// context samples on a GPU (renders_on_cpu false). Neither does without S3TC.
TextureCompressionDecision decide_texture_compression(TextureCompression mode, size_t uncompressed_bytes,
                                                      bool any_large, const std::string& gl_renderer,
                                                      const std::string& s3tc_unavailable);

// "12 MiB": bytes rounded to the nearest MiB.
std::string mebibytes(size_t bytes);

}  // namespace kit

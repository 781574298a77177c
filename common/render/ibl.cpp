#include "render/ibl.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>

#include "base/error.h"
#include "images/image_codecs.h"
#include "images/openimageio_formats.h"
#include "gl/pass_clock.h"
#include "images/texture_prepare.h"
#include "render/stages.h"
#include "gbuffer_layout.h"

namespace kit {

namespace {
constexpr TextureFormat kRadianceFormat{GL_RGBA32F, GL_RGBA, GL_FLOAT};

// Levels of a full mip chain for a width x height texture.
int mip_levels(int width, int height) {
  int levels = 1;
  while ((std::max(width, height) >> levels) > 0) ++levels;
  return levels;
}

// An equirectangular map's sampling: bilinear, wrapping across u = 0/1 (the
// azimuth is periodic), clamped at the poles.
void set_equirect_sampling(const Texture2D& texture, bool mipmapped) {
  texture.set_filter(mipmapped ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR, GL_LINEAR);
  texture.set_wrap(GL_REPEAT, GL_CLAMP_TO_EDGE);
}

// An equirectangular RGBA32F texture of an image's RGB (rows top-down), alpha 1.
Texture2D equirect_texture(const Image& image, bool mipmapped) {
  if (image.channels < 3) throw Error("an equirectangular map needs RGB channels");
  const int width = image.width, height = image.height;
  // GL's row 0 is the image's bottom row (environment.glsl: t = 0 is the nadir).
  Image rgba(width, height, 4);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      for (int c = 0; c < 3; ++c) rgba.at(x, height - 1 - y, c) = image.at(x, y, c);
      rgba.at(x, height - 1 - y, 3) = 1.0f;
    }
  // The mip chain is box-filtered here rather than by glGenerateMipmap, which on
  // llvmpipe JIT-compiles a blit for the format in every process (texture_prepare.h).
  std::vector<Image> chain{std::move(rgba)};
  while (mipmapped && (chain.back().width > 1 || chain.back().height > 1)) chain.push_back(next_mip_level(chain.back()));
  std::vector<TextureLevelData> levels;
  for (const Image& level : chain) levels.push_back({level.width, level.height, level.pixels.data(), 0});
  Texture2D texture(kRadianceFormat, false, levels);
  set_equirect_sampling(texture, mipmapped);
  return texture;
}

// Throws NonFiniteMapError when level `level` of `map` holds NaN or Inf, naming the
// shader that wrote it and the first such texel as the shader saw it: (x, y) from the
// bottom left (gl_FragCoord.xy - 0.5) and its v_uv. `one_level`: the map has no other level to name.
void refuse_non_finite(const Texture2D& map, int level, const std::string& map_name, const Program& writer,
                       bool one_level) {
  const Image image = read_texture_level(map, level);
  const std::optional<NonFinitePixel> first = first_non_finite(image);
  if (!first) return;
  const int x = first->x, y = image.height - 1 - first->y;  // GL's rows start at the bottom
  char where[160];
  std::snprintf(where, sizeof where, "texel (%d, %d) (v_uv = (%.4f, %.4f); %zu of its %d texels are NaN or Inf)", x, y,
                (x + 0.5) / image.width, (y + 0.5) / image.height, count_non_finite(image), image.width * image.height);
  const std::string value = std::isnan(first->value) ? "NaN" : first->value > 0.0f ? "+Inf" : "-Inf";
  throw NonFiniteMapError(writer.main_file() + " wrote " + value + " into the " + map_name +
                          (one_level ? std::string(", ") : ", level " + std::to_string(level) + ", ") + where +
                          ". The frame would hide it (on llvmpipe ibl.frag's min(NaN, KIT_HDR_MAX) is KIT_HDR_MAX, "
                          "a white pixel): look for a division by zero, normalize() of a zero vector, or sqrt() or "
                          "log2() of a negative number");
}
}  // namespace

bool operator==(const IblSettings& a, const IblSettings& b) {
  return a.prefilter_samples == b.prefilter_samples && a.prefilter_size == b.prefilter_size &&
         a.brdf_lut_samples == b.brdf_lut_samples && a.irradiance_size == b.irradiance_size &&
         a.irradiance_source_width == b.irradiance_source_width && a.refuse_non_finite == b.refuse_non_finite;
}

const std::vector<std::string>& kit_environment_names() {
  static const std::vector<std::string> kNames = {"studio", "sun"};
  return kNames;
}

std::string environment_or_default(const std::string& environment) {
  return environment.empty() ? kDefaultEnvironment : environment;
}

std::string resolve_environment(const std::string& name_or_path) {
  const auto& names = kit_environment_names();
  if (std::find(names.begin(), names.end(), name_or_path) == names.end()) return name_or_path;
  return (scene_dir() / "environments" / (name_or_path + ".exr")).string();
}

Image load_environment(const std::string& path) {
  // EXR (the kit's own environments) through OpenEXR; any other format OpenImageIO reads
  // (Radiance .hdr, ...) through its module. Larger is refused before the texels are read.
  const int max_width = kMaxEnvironmentWidth, max_height = kMaxEnvironmentWidth / 2;
  Image read;
  try {
    read = has_extension(path, ".exr") ? read_exr(path, max_width, max_height)
                                   : openimageio_formats().read_image(path, max_width, max_height);
  } catch (const Error& e) {
    throw Error(std::string("cannot read the environment: ") + e.what());
  }
  if (read.width < 2 || read.height < 1)
    throw Error(path + ": the environment is " + std::to_string(read.width) + "x" + std::to_string(read.height) +
                " texels (an equirectangular image of at most " + std::to_string(max_width) + "x" +
                std::to_string(max_height) + ")");
  if (read.channels != 1 && read.channels < 3)
    throw Error(path + ": the environment has " + std::to_string(read.channels) +
                " channels (it needs RGB, or 1 for grey)");
  // The sizes are bounded above, so the products fit in size_t.
  const size_t texels = static_cast<size_t>(read.width) * static_cast<size_t>(read.height);
  const size_t n = static_cast<size_t>(read.channels);
  Image image(read.width, read.height, 3);
  for (size_t t = 0; t < texels; ++t) {
    for (size_t c = 0; c < 3; ++c) {
      const float value = read.pixels[t * n + (n == 1 ? 0 : c)];
      if (!std::isfinite(value) || value < 0.0f)
        throw Error(path + ": texel (" + std::to_string(t % static_cast<size_t>(read.width)) + ", " +
                    std::to_string(t / static_cast<size_t>(read.width)) + ") has radiance " + std::to_string(value) +
                    " (radiance must be finite and not negative)");
      image.pixels[t * 3 + c] = value;
    }
  }
  return image;
}

ImageBasedLighting::ImageBasedLighting(const Image& environment) : environment_(equirect_texture(environment, true)) {}

void ImageBasedLighting::set_irradiance(const Image& irradiance) { irradiance_ = equirect_texture(irradiance, false); }

void ImageBasedLighting::precompute(const Program& irradiance, const Program& prefilter, const Program& brdf_lut,
                                    const FullscreenTriangle& triangle, const IblSettings& settings) {
  const auto start = std::chrono::steady_clock::now();
  if (settings.prefilter_size < (2 << (KIT_PREFILTER_LEVELS - 1)) || settings.irradiance_size < 2)
    throw Error("IBL maps too small: the prefiltered map needs " + std::to_string(2 << (KIT_PREFILTER_LEVELS - 1)) +
                " texels a row for its " + std::to_string(KIT_PREFILTER_LEVELS) + " levels");
  // The maps are written here, so none may stay bound where a pass could sample it.
  for (int unit : {KIT_UNIT_IRRADIANCE, KIT_UNIT_PREFILTERED, KIT_UNIT_BRDF_LUT}) {
    glActiveTexture(GL_TEXTURE0 + static_cast<GLenum>(unit));
    glBindTexture(GL_TEXTURE_2D, 0);
  }
  Framebuffer fbo;
  auto render_into = [&](const Program& program, const Texture2D& target, int level) {
    fbo.attach_color(0, target, level);
    fbo.set_draw_buffers(1);
    const std::string reason = fbo.incomplete_reason();
    if (!reason.empty()) throw Error("IBL map target incomplete: " + reason);
    // Bound here, just before drawing: creating or configuring a texture binds it on
    // the active unit, which would otherwise replace the environment there.
    environment_.bind(KIT_UNIT_ENVIRONMENT);
    triangle.pass(program, fbo, std::max(target.width() >> level, 1), std::max(target.height() >> level, 1));
  };

  // Irradiance: summed over the first environment level no wider than the setting.
  irradiance_ = Texture2D(settings.irradiance_size, std::max(settings.irradiance_size / 2, 1), kRadianceFormat);
  set_equirect_sampling(irradiance_, false);
  const int width = environment_.width(), levels = mip_levels(width, environment_.height());
  int source_level = 0;
  while (source_level + 1 < levels && (width >> source_level) > settings.irradiance_source_width) ++source_level;
  irradiance.use();
  irradiance.set("u_source_level", source_level);
  render_into(irradiance, irradiance_, 0);
  check_gl("irradiance map (irradiance.frag)");
  glFinish();
  irradiance_seconds_ = seconds_since(start);

  // Prefiltered radiance: level k for roughness k / (levels - 1).
  // Its levels allocated one by one (levels 0 to KIT_PREFILTER_LEVELS - 1, each
  // rendered below), not by glGenerateMipmap (equirect_texture says why).
  std::vector<TextureLevelData> prefiltered_levels;
  for (int level = 0; level < KIT_PREFILTER_LEVELS; ++level)
    prefiltered_levels.push_back(
        {std::max(settings.prefilter_size >> level, 1), std::max((settings.prefilter_size / 2) >> level, 1), nullptr, 0});
  prefiltered_ = Texture2D(kRadianceFormat, false, prefiltered_levels);
  set_equirect_sampling(prefiltered_, true);
  prefilter.use();
  prefilter.set("u_sample_count", settings.prefilter_samples);
  for (int level = 0; level < KIT_PREFILTER_LEVELS; ++level) {
    prefilter.use();
    prefilter.set("u_roughness", static_cast<float>(level) / static_cast<float>(KIT_PREFILTER_LEVELS - 1));
    render_into(prefilter, prefiltered_, level);
  }
  check_gl("prefiltered map (prefilter.frag)");

  // The BRDF table: a grid including n.v and roughness 0 and 1.
  brdf_lut_ = Texture2D(KIT_BRDF_LUT_SIZE, KIT_BRDF_LUT_SIZE, kRadianceFormat);
  brdf_lut_.set_filter(GL_LINEAR, GL_LINEAR);
  brdf_lut.use();
  brdf_lut.set("u_sample_count", settings.brdf_lut_samples);
  render_into(brdf_lut, brdf_lut_, 0);
  check_gl("BRDF table (brdf_lut.frag)");

  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glFinish();
  precompute_seconds_ = seconds_since(start);

  // The maps are small (32x16, 256x128 and its levels, 64x64): reading them back costs
  // a few milliseconds (test_ibl measures it), far less than a NaN found in the frame.
  if (!settings.refuse_non_finite) return;
  const auto check_start = std::chrono::steady_clock::now();
  refuse_non_finite(irradiance_, 0, "irradiance map", irradiance, true);
  for (int level = 0; level < KIT_PREFILTER_LEVELS; ++level)
    refuse_non_finite(prefiltered_, level, "prefiltered map", prefilter, false);
  refuse_non_finite(brdf_lut_, 0, "BRDF table", brdf_lut, true);
  finite_check_seconds_ = seconds_since(check_start);
}

void ImageBasedLighting::bind() const {
  environment_.bind(KIT_UNIT_ENVIRONMENT);
  irradiance_.bind(KIT_UNIT_IRRADIANCE);
  prefiltered_.bind(KIT_UNIT_PREFILTERED);
  brdf_lut_.bind(KIT_UNIT_BRDF_LUT);
}

Image read_prefiltered_levels(const Texture2D& prefiltered) {
  int height = 0;
  for (int level = 0; level < KIT_PREFILTER_LEVELS; ++level) height += std::max(prefiltered.height() >> level, 1);
  Image out(prefiltered.width(), height, 4);
  int top = 0;
  for (int level = 0; level < KIT_PREFILTER_LEVELS; ++level) {
    Image image = read_texture_level(prefiltered, level);
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x)
        for (int c = 0; c < 4; ++c) out.at(x, top + y, c) = image.at(x, y, c);
    top += image.height;
  }
  return out;
}

}  // namespace kit

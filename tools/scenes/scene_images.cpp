#include "scene_images.h"

#include <OpenImageIO/imageio.h>

#include <stdexcept>
#include <string>

#include "scene_math.h"

namespace kit_scenes {

namespace fs = std::filesystem;

namespace {

// --- Brick texture parameters (shared by the colour map and the normal map) ---
constexpr int kTextureSize = 256;       // square; the pattern tiles seamlessly
constexpr int kBrickWidthPx = 64;       // divides kTextureSize; even, for the half-brick offset
constexpr int kBrickHeightPx = 32;      // divides kTextureSize into an even number of rows
constexpr float kMortarWidthPx = 6.0f;  // full width of a mortar joint
constexpr float kBevelPx = 3.0f;        // rounded brick edge between mortar and brick face
constexpr float kBumpDepthPx = 2.5f;    // height of a brick face above the mortar, in texels

constexpr int kCheckerCells = 4;  // checker cells per texture side

}  // namespace

struct BrickSample {
  float height;  // 0 in the mortar, 1 on a brick face, smooth bevel in between
  std::uint32_t brick_id;
};

// Where texel (x, y) falls in a running-bond brick pattern.
BrickSample sample_bricks(int x, int y) {
  // Wrap so that the normal map's central differences tile seamlessly too.
  x = (x % kTextureSize + kTextureSize) % kTextureSize;
  y = (y % kTextureSize + kTextureSize) % kTextureSize;
  const int row = y / kBrickHeightPx;
  const int shift = (row % 2) * (kBrickWidthPx / 2);  // odd rows offset by half a brick
  const int column = ((x + shift) / kBrickWidthPx) % (kTextureSize / kBrickWidthPx);
  const float lx = float((x + shift) % kBrickWidthPx) + 0.5f;  // texel centre inside the brick
  const float ly = float(y % kBrickHeightPx) + 0.5f;
  // Joints run along the cell borders; the distance to the nearest one gives the height.
  const float d = std::min(std::min(lx, kBrickWidthPx - lx), std::min(ly, kBrickHeightPx - ly));
  const float half_mortar = 0.5f * kMortarWidthPx;
  return {smoothstep(half_mortar, half_mortar + kBevelPx, d), std::uint32_t(row * 64 + column)};
}

Image8 make_brick_color() {
  Image8 img(kTextureSize, kTextureSize, 3);
  const glm::vec3 mortar(0.70f, 0.68f, 0.64f);  // sRGB-encoded: baseColor textures are sRGB
  const glm::vec3 brick(0.58f, 0.27f, 0.20f);
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x) {
      const BrickSample s = sample_bricks(x, y);
      const float shade = 0.82f + 0.30f * hash01(s.brick_id);
      const glm::vec3 tint = brick * shade + glm::vec3(0.04f * hash01(s.brick_id + 977u), 0, 0);
      img.set(x, y, glm::mix(mortar, tint, s.height));
    }
  }
  return img;
}

// Tangent-space normal map stored as (n + 1) / 2 in linear 8-bit RGB:
// +X = +u (image right), +Y = image up (decreasing glTF v), +Z = out of the surface.
Image8 make_brick_normal() {
  Image8 img(kTextureSize, kTextureSize, 3);
  for (int y = 0; y < img.height; ++y) {
    for (int x = 0; x < img.width; ++x) {
      const float dh_dx = 0.5f * (sample_bricks(x + 1, y).height - sample_bricks(x - 1, y).height);
      // Rows grow downwards, so the slope towards "up" is minus the slope along the rows.
      const float dh_dup =
          -0.5f * (sample_bricks(x, y + 1).height - sample_bricks(x, y - 1).height);
      const glm::vec3 n =
          glm::normalize(glm::vec3(-kBumpDepthPx * dh_dx, -kBumpDepthPx * dh_dup, 1.0f));
      img.set(x, y, 0.5f * n + 0.5f);
    }
  }
  return img;
}

Image8 make_checker() {
  Image8 img(kTextureSize, kTextureSize, 3);
  const int cell = kTextureSize / kCheckerCells;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      img.set(x, y, ((x / cell + y / cell) % 2) ? glm::vec3(0.50f) : glm::vec3(0.90f));
  return img;
}

// The masked quad's base colour: the checker's greys in RGB and an alpha ramp from 0
// at the left edge to 1 at the right, so the MASK cutoff decides where the quad ends.
Image8 make_alpha_ramp_checker() {
  const Image8 checker = make_checker();
  Image8 img(kTextureSize, kTextureSize, 4);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      std::uint8_t* p = &img.pixels[(size_t(y) * img.width + x) * 4];
      std::copy_n(&checker.pixels[(size_t(y) * checker.width + x) * 3], 3, p);
      p[3] = std::uint8_t(std::lround(255.0 * x / (img.width - 1)));
    }
  return img;
}

// A tangent-space normal map (as make_brick_normal stores it) of smooth egg-crate bumps,
// h = sin(2 pi x / P) sin(2 pi y / P) with P half the image: its normals lean everywhere
// but along the bumps' crests and troughs, by up to 45 degrees at normalTexture.scale 1.
// Unlike the bricks, whose slopes are bevels a pixel or two wide in a small render, a
// mistake in the scale or the tangent frame changes whole areas.
Image8 make_bump_normal() {
  constexpr int kSide = 128, kPeriodPx = kSide / 2;
  constexpr double kMaxSlope = 1.0;  // |dh/dx| at most: 45 degrees
  Image8 img(kSide, kSide, 3);
  for (int y = 0; y < kSide; ++y)
    for (int x = 0; x < kSide; ++x) {
      const double a = 2.0 * kPi * (x + 0.5) / kPeriodPx, b = 2.0 * kPi * (y + 0.5) / kPeriodPx;
      const double dh_dx = kMaxSlope * std::cos(a) * std::sin(b);
      const double dh_dup = -kMaxSlope * std::sin(a) * std::cos(b);  // rows grow downwards
      const glm::vec3 n = glm::normalize(glm::vec3(float(-dh_dx), float(-dh_dup), 1.0f));
      img.set(x, y, 0.5f * n + 0.5f);
    }
  return img;
}

// A 4 x 4 grid of distinct colours, each cell shaded darker towards its lower right:
// every texel's place in the image shows, so a texture read at another UV set, or with
// another transform, shows colours or a turn the right read does not.
Image8 make_uv_grid() {
  constexpr int kCellPx = 16, kCellsPerSide = 4;
  Image8 img(kCellPx * kCellsPerSide, kCellPx * kCellsPerSide, 3);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const std::uint32_t cell = std::uint32_t(y / kCellPx * kCellsPerSide + x / kCellPx);
      const glm::vec3 hue(0.2f + 0.8f * hash01(cell * 3u + 7u), 0.2f + 0.8f * hash01(cell * 3u + 8u),
                          0.2f + 0.8f * hash01(cell * 3u + 9u));
      const float shade = 1.0f - 0.35f * float(x % kCellPx + y % kCellPx) / float(2 * kCellPx);
      img.set(x, y, hue * shade);
    }
  return img;
}

// A metallic-roughness texture whose three channels differ, as a packed occlusion-
// roughness-metallic texture's do: R (occlusion, which the labs do not read) diagonal
// stripes, G (roughness) a ramp from 0.2 at the left to 0.9 at the right, B (metallic)
// horizontal bands of 0 and 1. Reading roughness or metallic from another channel shows.
Image8 make_packed_orm() {
  constexpr int kSide = 64, kStripePx = 8, kBandPx = 16;
  Image8 img(kSide, kSide, 3);
  for (int y = 0; y < kSide; ++y)
    for (int x = 0; x < kSide; ++x) {
      const float occlusion = ((x + y) / kStripePx) % 2 ? 1.0f : 0.35f;
      const float roughness = 0.2f + 0.7f * float(x) / float(kSide - 1);
      const float metallic = (y / kBandPx) % 2 ? 1.0f : 0.0f;
      img.set(x, y, {occlusion, roughness, metallic});
    }
  return img;
}

void write_png(const fs::path& path, const Image8& img) {
  auto out = OIIO::ImageOutput::create(path.string());
  if (!out)
    throw std::runtime_error("no PNG writer for " + path.string() + ": " + OIIO::geterror());
  OIIO::ImageSpec spec(img.width, img.height, img.channels, OIIO::TypeDesc::UINT8);
  // The bytes are PNG's own, colour not multiplied by alpha: without this OpenImageIO takes
  // them for premultiplied and divides colour by alpha on the way out, rounding differently
  // by version (alpha_ramp.png's 128 greys came out 127 in places with Debian 12's 2.4 and 128
  // with Debian 13's 2.5). Written as given, the file is the same on every version.
  spec.attribute("oiio:UnassociatedAlpha", 1);
  if (!out->open(path.string(), spec) ||
      !out->write_image(OIIO::TypeDesc::UINT8, img.pixels.data()) || !out->close())
    throw std::runtime_error("cannot write " + path.string() + ": " + out->geterror());
}

}  // namespace kit_scenes

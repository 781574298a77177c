// The G-buffer (common/render/gbuffer.*, shaders/gbuffer_layout.h) and what the
// reference geometry pass (solutions/01-gbuffer) writes into it, checked pixel
// by pixel against ray casts through the scene's camera in double precision.
#include <gtest/gtest.h>

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "cpu_reference.h"
#include "base/error.h"
#include "render/gbuffer.h"
#include "gbuffer_layout.h"
#include "kit_test.h"
#include "kit_test_files.h"
#include "reference_frames.h"
#include "shader_variants.h"
#include "render/stages.h"
#include "images/texture_prepare.h"
#include "tiny_scenes.h"

namespace fs = std::filesystem;
using nlohmann::json;
namespace ref = kit::reference;

namespace {

constexpr int kWidth = kit::test::kSmallWidth;
constexpr int kHeight = kit::test::kSmallHeight;

// RGBA16F keeps 11 significant bits: a stored value is within 2^-11 of its size,
// so 2^-10 relative leaves room for the float arithmetic before the store.
constexpr double kHalfRelative = 1.0 / 1024.0;
// Absolute slack for the rasteriser's float interpolation at the pixel centre (the
// floor's y, exactly 0, has no relative room).
constexpr double kPositionSlack = 1e-4;
// A unit vector stored as RGBA16F: each component off by at most 2^-11 of itself.
constexpr double kUnitLengthTolerance = 1e-3;
// The 64 x 32 UV sphere's flat triangles tilt the interpolated normal by well under this
// (angle between the true sphere normal at the ray hit and the mesh normal).
constexpr double kTessellationAngleDegrees = 1.5;
// The sphere scene's UV sphere: 64 segments around, 32 rings from pole to pole. Its flat
// triangles lie inside the sphere, no deeper than the cosine of half a grid cell's
// angular diagonal (the widest cell is at the equator).
constexpr int kSphereSegments = 64, kSphereRings = 32;
const double kInscribedMinRadius =
    std::cos(0.5 * std::hypot(2.0 * M_PI / kSphereSegments, M_PI / kSphereRings));
// Pixels where the true sphere is seen at a grazing angle are left out: there the
// tessellated silhouette departs from the true one.
constexpr double kMinSphereFacing = 0.3;
// RGBA8 albedo: rounding of the store plus the sRGB decode table of the driver.
constexpr double kAlbedoTolerance = 2.0 / 255.0;
// Metallic and roughness are RGBA16F values in [0, 1], emitted radiance in [0, 4].
constexpr double kMaterialTolerance = 4.0 * kHalfRelative;
// The debug view's target is RGBA32F: (n + 1) / 2 in float arithmetic.
constexpr double kDebugViewTolerance = 1e-6;
// 24-bit window depth: a few 2^-24 steps of storage plus float interpolation.
constexpr double kWindowDepthTolerance = 1e-6;
// Linearised depth: deviation from a straight line in view-space distance. Reading
// the depth back through the 24-bit store costs ~1e-5 here; showing window depth
// itself would deviate by ~5e-3 (and by ~0.3 once stretched to [0, 1]).
constexpr double kDepthLinearityTolerance = 1e-4;

struct Ray {
  glm::dvec3 origin, direction;  // direction is unit length
};

// The scene camera of a kWidth x kHeight render, rebuilt in double from the scene's camera.
struct CpuCamera {
  glm::dmat4 view, view_projection, inverse_view_projection;

  explicit CpuCamera(const kit::Camera& camera) {
    view = glm::dmat4(camera.view);
    glm::dmat4 projection = glm::perspective(static_cast<double>(camera.yfov), static_cast<double>(kWidth) / kHeight,
                                             static_cast<double>(camera.znear), static_cast<double>(camera.zfar));
    view_projection = projection * view;
    inverse_view_projection = glm::inverse(view_projection);
  }

  // The ray through the centre of image pixel (x, y); image row 0 is the top row.
  Ray pixel_ray(int x, int y) const {
    glm::dvec2 ndc((x + 0.5) / kWidth * 2.0 - 1.0, 1.0 - (y + 0.5) / kHeight * 2.0);
    glm::dvec4 near_point = inverse_view_projection * glm::dvec4(ndc, -1.0, 1.0);
    glm::dvec4 far_point = inverse_view_projection * glm::dvec4(ndc, 1.0, 1.0);
    glm::dvec3 a = glm::dvec3(near_point) / near_point.w, b = glm::dvec3(far_point) / far_point.w;
    return {a, glm::normalize(b - a)};
  }

  // The image pixel (x, y) a world point projects into.
  std::pair<int, int> pixel_of(const glm::dvec3& p) const {
    glm::dvec4 clip = view_projection * glm::dvec4(p, 1.0);
    return {static_cast<int>(std::floor((clip.x / clip.w + 1.0) * 0.5 * kWidth)),
            static_cast<int>(std::floor((1.0 - clip.y / clip.w) * 0.5 * kHeight))};
  }
  // GL window depth in [0, 1] of a world point (default depth range).
  double window_depth(const glm::dvec3& p) const {
    glm::dvec4 clip = view_projection * glm::dvec4(p, 1.0);
    return 0.5 * clip.z / clip.w + 0.5;
  }
  // Distance in front of the camera along its viewing axis.
  double view_depth(const glm::dvec3& p) const { return -(view * glm::dvec4(p, 1.0)).z; }
};

using kit::test::small_settings;

glm::dvec4 pixel(const kit::Image& image, int x, int y) {
  glm::dvec4 v(0.0);
  for (int c = 0; c < std::min(image.channels, 4); ++c) v[c] = image.at(x, y, c);
  return v;
}

// Entry (t) of a ray into an axis-aligned box, if it meets the box in front of the origin.
std::optional<double> ray_box_entry(const Ray& ray, const glm::dvec3& lo, const glm::dvec3& hi) {
  double t_min = 0.0, t_max = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (ray.direction[a] == 0.0) {
      if (ray.origin[a] < lo[a] || ray.origin[a] > hi[a]) return std::nullopt;
      continue;
    }
    double t0 = (lo[a] - ray.origin[a]) / ray.direction[a], t1 = (hi[a] - ray.origin[a]) / ray.direction[a];
    t_min = std::max(t_min, std::min(t0, t1));
    t_max = std::min(t_max, std::max(t0, t1));
  }
  if (t_min > t_max) return std::nullopt;
  return t_min;
}

// World-space bounding box of a draw (its primitive's bounds through its world matrix).
std::pair<glm::dvec3, glm::dvec3> world_box(const kit::Scene& scene, const kit::DrawItem& d) {
  const kit::Primitive& p = scene.primitives[static_cast<size_t>(d.primitive)];
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
  for (int corner = 0; corner < 8; ++corner) {
    glm::dvec3 c((corner & 1) ? p.bounds_max.x : p.bounds_min.x, (corner & 2) ? p.bounds_max.y : p.bounds_min.y,
                 (corner & 4) ? p.bounds_max.z : p.bounds_min.z);
    glm::dvec3 w(glm::dmat4(d.world) * glm::dvec4(c, 1.0));
    lo = glm::min(lo, w);
    hi = glm::max(hi, w);
  }
  return {lo, hi};
}

bool is_mesh(const kit::Scene& scene, const kit::DrawItem& d, const std::string& mesh_name) {
  return scene.primitives[static_cast<size_t>(d.primitive)].name.find("('" + mesh_name + "')") != std::string::npos;
}

KIT_NO_DANGLING const kit::DrawItem& draw_of(const kit::Scene& scene, const std::string& mesh_name) {
  for (const kit::DrawItem& d : scene.draws)
    if (is_mesh(scene, d, mesh_name)) return d;
  throw std::runtime_error("no draw of mesh '" + mesh_name + "' in " + scene.path);
}

// Where (t) a ray meets the plane y = 0 in front of its origin.
std::optional<double> ground_hit(const Ray& ray) {
  if (ray.direction.y >= 0.0) return std::nullopt;
  return -ray.origin.y / ray.direction.y;
}

// A pixel whose centre ray meets the floor (the plane y = 0) before any other draw's box.
struct FloorPixel {
  int x, y;
  glm::dvec3 hit;
};

// Floor pixels of a scene whose floor is the mesh "floor" lying in y = 0, keeping
// `margin` metres away from the floor's edges.
std::vector<FloorPixel> visible_floor(const kit::Scene& scene, const CpuCamera& camera, double margin) {
  auto [floor_lo, floor_hi] = world_box(scene, draw_of(scene, "floor"));
  EXPECT_EQ(floor_lo.y, 0.0);
  EXPECT_EQ(floor_hi.y, 0.0);
  std::vector<FloorPixel> out;
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      Ray ray = camera.pixel_ray(x, y);
      std::optional<double> t = ground_hit(ray);
      if (!t) continue;
      glm::dvec3 hit = ray.origin + *t * ray.direction;
      if (hit.x < floor_lo.x + margin || hit.x > floor_hi.x - margin || hit.z < floor_lo.z + margin ||
          hit.z > floor_hi.z - margin)
        continue;
      bool occluded = false;
      for (const kit::DrawItem& d : scene.draws) {
        if (is_mesh(scene, d, "floor")) continue;
        auto [lo, hi] = world_box(scene, d);
        std::optional<double> entry = ray_box_entry(ray, lo, hi);
        if (entry && *entry < *t) occluded = true;
      }
      if (!occluded) out.push_back({x, y, hit});
    }
  }
  return out;
}

using kit::srgb_to_linear;  // texture_prepare.h

json scene_json(const kit::Scene& scene) { return json::parse(kit::test::read_file(scene.path)); }

// The glTF material (JSON) of the node named `node_name`'s first primitive.
KIT_NO_DANGLING const json& material_of_node(const json& doc, const std::string& node_name) {
  for (const json& node : doc["nodes"])
    if (node.value("name", "") == node_name && node.contains("mesh"))
      return doc["materials"][doc["meshes"][node["mesh"].get<size_t>()]["primitives"][0]["material"].get<size_t>()];
  throw std::runtime_error("no mesh node '" + node_name + "'");
}

// ---------------------------------------------------------------------------
// Formats and completeness

GLint texture_parameter(const kit::Texture2D& texture, GLenum parameter) {
  GLint value = 0;
  glBindTexture(GL_TEXTURE_2D, texture.id());
  glGetTexLevelParameteriv(GL_TEXTURE_2D, 0, parameter, &value);
  return value;
}

// Bytes a texel of `texture` takes: its channel bits, in whole 32-bit words (a 24-bit
// depth texel is stored in a 32-bit word).
int texel_bytes(const kit::Texture2D& texture) {
  int bits = 0;
  for (GLenum p : {GL_TEXTURE_RED_SIZE, GL_TEXTURE_GREEN_SIZE, GL_TEXTURE_BLUE_SIZE, GL_TEXTURE_ALPHA_SIZE,
                   GL_TEXTURE_DEPTH_SIZE})
    bits += texture_parameter(texture, p);
  return (bits + 31) / 32 * 4;
}

void expect_gbuffer_shape(const kit::GBuffer& g, int width, int height) {
  EXPECT_EQ(g.framebuffer().incomplete_reason(), "");
  EXPECT_EQ(g.width(), width);
  EXPECT_EQ(g.height(), height);
  for (int i = 0; i < KIT_GBUF_COUNT; ++i) {
    const kit::Texture2D& t = g.attachment(i);
    EXPECT_EQ(texture_parameter(t, GL_TEXTURE_WIDTH), width) << kit::GBuffer::attachment_name(i);
    EXPECT_EQ(texture_parameter(t, GL_TEXTURE_HEIGHT), height) << kit::GBuffer::attachment_name(i);
    EXPECT_EQ(static_cast<GLenum>(texture_parameter(t, GL_TEXTURE_INTERNAL_FORMAT)),
              kit::GBuffer::attachment_format(i).internal_format)
        << kit::GBuffer::attachment_name(i);
  }
  EXPECT_EQ(texture_parameter(g.depth(), GL_TEXTURE_WIDTH), width);
  EXPECT_EQ(texture_parameter(g.depth(), GL_TEXTURE_HEIGHT), height);
  EXPECT_EQ(static_cast<GLenum>(texture_parameter(g.depth(), GL_TEXTURE_INTERNAL_FORMAT)),
            kit::GBuffer::depth_format().internal_format);
}

TEST(GBufferFormats, EachAttachmentIsCompleteAlone) {
  kit::test::context();
  for (int i = 0; i < KIT_GBUF_COUNT; ++i) {
    kit::Texture2D texture(kWidth, kHeight, kit::GBuffer::attachment_format(i));
    kit::Framebuffer fbo;
    fbo.attach_color(0, texture);
    fbo.set_draw_buffers(1);
    EXPECT_EQ(fbo.incomplete_reason(), "") << kit::GBuffer::attachment_name(i);
  }
  kit::Texture2D depth(kWidth, kHeight, kit::GBuffer::depth_format());
  kit::Framebuffer fbo;
  fbo.attach_depth(depth);
  glDrawBuffer(GL_NONE);  // a depth-only framebuffer draws no colour
  glReadBuffer(GL_NONE);
  EXPECT_EQ(fbo.incomplete_reason(), "") << "depth";
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
  EXPECT_THROW(kit::GBuffer::attachment_format(KIT_GBUF_COUNT), kit::Error);
}

TEST(GBufferFormats, AllTogetherAndAfterResize) {
  kit::test::context();
  kit::GBuffer g(kWidth, kHeight);
  expect_gbuffer_shape(g, kWidth, kHeight);
  g.resize(kWidth / 2 + 3, kHeight * 2);  // odd size, other aspect
  expect_gbuffer_shape(g, kWidth / 2 + 3, kHeight * 2);
  g.resize(1, 1);
  expect_gbuffer_shape(g, 1, 1);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST(GBufferFormats, BytesPerPixelMatchTheFormats) {
  kit::test::context();
  kit::GBuffer g(4, 4);
  int bytes = texel_bytes(g.depth());
  for (int i = 0; i < KIT_GBUF_COUNT; ++i) bytes += texel_bytes(g.attachment(i));
  EXPECT_EQ(kit::GBuffer::bytes_per_pixel(), bytes);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST(GBufferFormats, GeometryPassClearsToBackground) {
  kit::test::context();
  kit::GBuffer g(8, 6);
  g.begin_geometry_pass();
  for (int i = 0; i < KIT_GBUF_COUNT; ++i) {
    kit::Image image = kit::read_texture(g.attachment(i));
    for (float v : image.pixels) ASSERT_EQ(v, 0.0f) << kit::GBuffer::attachment_name(i);
  }
  kit::Image depth = kit::read_texture(g.depth(), true);
  for (float v : depth.pixels) ASSERT_EQ(v, 1.0f);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

// ---------------------------------------------------------------------------
// Contents written by the reference geometry pass

TEST(GBufferContents, FloorPositionAndDepthMatchRayCasts) {
  auto renderer = kit::test::render_stage("gbuffer", "default", small_settings());
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
  const kit::Scene& scene = renderer->scene();
  CpuCamera camera(*scene.camera);
  kit::Image position = renderer->read_view(kit::View::Position, true);
  kit::Image depth = renderer->read_view(kit::View::Depth, true);
  kit::Image material = renderer->read_view(kit::View::Material, true);
  kit::Image depth_view = renderer->read_view(kit::View::Depth, false);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));

  constexpr double kEdgeMargin = 0.05;  // metres kept from the floor's edges
  std::vector<FloorPixel> floor = visible_floor(scene, camera, kEdgeMargin);
  ASSERT_GT(floor.size(), static_cast<size_t>(kWidth * kHeight / 10)) << "too few floor pixels to test";
  for (const FloorPixel& f : floor) {
    glm::dvec4 p = pixel(position, f.x, f.y);
    for (int c = 0; c < 3; ++c)
      ASSERT_NEAR(p[c], f.hit[c], kHalfRelative * std::fabs(f.hit[c]) + kPositionSlack)
          << "pixel (" << f.x << ", " << f.y << ") axis " << c;
    ASSERT_EQ(p.a, 1.0) << "pixel (" << f.x << ", " << f.y << ")";
    ASSERT_EQ(pixel(material, f.x, f.y).a, 1.0) << "mask at (" << f.x << ", " << f.y << ")";
    ASSERT_NEAR(depth.at(f.x, f.y, 0), camera.window_depth(f.hit), kWindowDepthTolerance)
        << "pixel (" << f.x << ", " << f.y << ")";
  }

  // The depth view is linear in view-space distance: fit shown = a + b * distance over
  // the floor pixels; every residual is small and b > 0 (farther is brighter).
  double sz = 0, sc = 0, szz = 0, szc = 0;
  for (const FloorPixel& f : floor) {
    double z = camera.view_depth(f.hit), c = depth_view.at(f.x, f.y, 0);
    sz += z, sc += c, szz += z * z, szc += z * c;
  }
  double n = static_cast<double>(floor.size());
  double slope = (n * szc - sz * sc) / (n * szz - sz * sz), offset = (sc - slope * sz) / n;
  EXPECT_GT(slope, 0.0);
  for (const FloorPixel& f : floor) {
    double c = depth_view.at(f.x, f.y, 0);
    ASSERT_GT(c, 0.0);  // inside the unclamped range, so the fit means something
    ASSERT_LT(c, 1.0);
    ASSERT_NEAR(c, offset + slope * camera.view_depth(f.hit), kDepthLinearityTolerance)
        << "pixel (" << f.x << ", " << f.y << ")";
  }
  // Two known pixels: the nearest and the farthest floor point keep their order.
  auto by_distance = [&](const FloorPixel& a, const FloorPixel& b) { return camera.view_depth(a.hit) < camera.view_depth(b.hit); };
  const FloorPixel& nearest = *std::min_element(floor.begin(), floor.end(), by_distance);
  const FloorPixel& farthest = *std::max_element(floor.begin(), floor.end(), by_distance);
  EXPECT_LT(depth_view.at(nearest.x, nearest.y, 0), depth_view.at(farthest.x, farthest.y, 0));
}

TEST(GBufferContents, FloorAlbedoIsFactorTimesDecodedTexel) {
  auto renderer = kit::test::render_stage("gbuffer", "default", small_settings());
  const kit::Scene& scene = renderer->scene();
  CpuCamera camera(*scene.camera);
  kit::Image albedo = renderer->read_view(kit::View::Albedo, true);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));

  // The floor's material and texture file, from the glTF JSON.
  json doc = scene_json(scene);
  const json& material = material_of_node(doc, "floor");
  glm::dvec4 factor(1.0);
  const json& pbr = material["pbrMetallicRoughness"];
  if (pbr.contains("baseColorFactor"))
    for (int c = 0; c < 4; ++c) factor[c] = pbr["baseColorFactor"][static_cast<size_t>(c)].get<double>();
  size_t texture = pbr["baseColorTexture"]["index"].get<size_t>();
  std::string uri = doc["images"][doc["textures"][texture]["source"].get<size_t>()]["uri"];
  kit::Image texels = kit::read_image((fs::path(scene.path).parent_path() / uri).string());
  ASSERT_GT(texels.width, 0);

  // The floor's UV mapping, from its mesh as loaded: an affine map of the local position,
  // solved on the first triangle (p = p0 + s e1 + t e2  ->  uv = uv0 + s du1 + t du2).
  const kit::DrawItem& floor_draw = draw_of(scene, "floor");
  const kit::Primitive& prim = scene.primitives[static_cast<size_t>(floor_draw.primitive)];
  const kit::Vertex& v0 = prim.vertices[prim.indices[0]];
  const kit::Vertex& v1 = prim.vertices[prim.indices[1]];
  const kit::Vertex& v2 = prim.vertices[prim.indices[2]];
  glm::dvec3 e1 = glm::dvec3(v1.position - v0.position), e2 = glm::dvec3(v2.position - v0.position);
  glm::dmat4 to_local = glm::inverse(glm::dmat4(floor_draw.world));
  auto uv_at = [&](const glm::dvec3& world) {
    glm::dvec3 q = glm::dvec3(to_local * glm::dvec4(world, 1.0)) - glm::dvec3(v0.position);
    double a = glm::dot(e1, e1), b = glm::dot(e1, e2), c = glm::dot(e2, e2);
    double det = a * c - b * b;
    double s = (c * glm::dot(e1, q) - b * glm::dot(e2, q)) / det, t = (a * glm::dot(e2, q) - b * glm::dot(e1, q)) / det;
    return glm::dvec2(v0.texcoord) + s * glm::dvec2(v1.texcoord - v0.texcoord) + t * glm::dvec2(v2.texcoord - v0.texcoord);
  };
  // The map reproduces every vertex's UV (the quad is affinely mapped); only double
  // round-off separates them.
  constexpr double kAffineMapTolerance = 1e-9;
  for (const kit::Vertex& v : prim.vertices)
    ASSERT_NEAR(glm::distance(uv_at(glm::dvec3(glm::dmat4(floor_draw.world) * glm::dvec4(glm::dvec3(v.position), 1.0))),
                              glm::dvec2(v.texcoord)),
                0.0, kAffineMapTolerance);

  auto wrap = [](long i, int size) { return static_cast<int>(((i % size) + size) % size); };
  const glm::dvec2 texture_size(texels.width, texels.height);
  // Continuous texel coordinates where a pixel's centre ray meets the floor (v = 0 is
  // the top row, as in the image file); none when the ray misses the plane.
  auto texel_at = [&](int x, int y) -> std::optional<glm::dvec2> {
    Ray ray = camera.pixel_ray(x, y);
    std::optional<double> t = ground_hit(ray);
    if (!t) return std::nullopt;
    return uv_at(ray.origin + *t * ray.direction) * texture_size;
  };
  // Trilinear filtering at level L reads texels up to 1.5 texels of level L + 1 (2^(L+1)
  // base texels each) from the sample; L grows with the pixel's footprint. Keep pixels
  // whose sample has at least that margin of one uniform colour around it.
  constexpr double kFootprintSafety = 1.5;  // drivers estimate the footprint coarsely
  size_t tested = 0;
  for (const FloorPixel& f : visible_floor(scene, camera, 0.0)) {
    if (f.x + 1 >= kWidth || f.y + 1 >= kHeight) continue;
    std::optional<glm::dvec2> here = texel_at(f.x, f.y), right = texel_at(f.x + 1, f.y), down = texel_at(f.x, f.y + 1);
    if (!here || !right || !down) continue;
    double footprint = std::max(glm::length(*right - *here), glm::length(*down - *here)) * kFootprintSafety;
    int level = footprint > 1.0 ? static_cast<int>(std::floor(std::log2(footprint))) : 0;
    long margin = static_cast<long>(std::ceil(1.5 * std::ldexp(1.0, level + 1))) + 1;
    long cx = static_cast<long>(std::floor(here->x)), cy = static_cast<long>(std::floor(here->y));
    const int centre_x = wrap(cx, texels.width), centre_y = wrap(cy, texels.height);
    bool uniform = margin < std::min(texels.width, texels.height) / 2;
    for (long dy = -margin; uniform && dy <= margin; ++dy)
      for (long dx = -margin; uniform && dx <= margin; ++dx)
        for (int c = 0; c < 3; ++c)
          if (texels.at(wrap(cx + dx, texels.width), wrap(cy + dy, texels.height), c) != texels.at(centre_x, centre_y, c))
            uniform = false;
    if (!uniform) continue;
    for (int c = 0; c < 3; ++c) {
      double expected = factor[c] * srgb_to_linear(texels.at(centre_x, centre_y, c));
      ASSERT_NEAR(albedo.at(f.x, f.y, c), expected, kAlbedoTolerance)
          << "pixel (" << f.x << ", " << f.y << ") channel " << c << " texel (" << centre_x << ", " << centre_y << ")";
    }
    ++tested;
  }
  constexpr size_t kMinTestedPixels = 50;
  EXPECT_GE(tested, kMinTestedPixels) << "too few floor pixels lie well inside a checker square";
}

TEST(GBufferContents, KnownSpheresMaterial) {
  auto renderer = kit::test::render_stage("gbuffer", "default", small_settings());
  const kit::Scene& scene = renderer->scene();
  CpuCamera camera(*scene.camera);
  kit::Image material = renderer->read_view(kit::View::Material, true);
  kit::Image emission = renderer->read_view(kit::View::Emission, true);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
  json doc = scene_json(scene);
  // Metallic and roughness of a gold and a dielectric sphere, the emitted radiance (a
  // colour: emissiveFactor x emissiveStrength, no emissive texture) of the glowing one,
  // at the pixel their centre projects into.
  for (const std::string node : {"sphere_gold_r50", "sphere_dielectric_r25", "sphere_gold_r100", "emissive_sphere"}) {
    const json& m = material_of_node(doc, node);
    const json& pbr = m["pbrMetallicRoughness"];
    double metallic = pbr.value("metallicFactor", 1.0), roughness = pbr.value("roughnessFactor", 1.0);
    glm::dvec3 emitted(0.0);
    const json factor = m.value("emissiveFactor", json::array({0.0, 0.0, 0.0}));
    for (int c = 0; c < 3; ++c) emitted[c] = factor[static_cast<size_t>(c)].get<double>();
    if (m.contains("extensions") && m["extensions"].contains("KHR_materials_emissive_strength"))
      emitted *= m["extensions"]["KHR_materials_emissive_strength"]["emissiveStrength"].get<double>();
    auto [x, y] = camera.pixel_of(glm::dvec3(draw_of(scene, node).world[3]));
    ASSERT_TRUE(x >= 0 && x < kWidth && y >= 0 && y < kHeight) << node;
    glm::dvec4 got = pixel(material, x, y);
    EXPECT_NEAR(got.r, metallic, kMaterialTolerance) << node;
    EXPECT_NEAR(got.g, roughness, kMaterialTolerance) << node;
    EXPECT_EQ(got.b, 0.0) << node << ": material.b is unused";
    EXPECT_EQ(got.a, 1.0) << node;
    glm::dvec4 emitted_got = pixel(emission, x, y);
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(emitted_got[c], emitted[c], kMaterialTolerance * std::max(1.0, emitted[c])) << node << " channel " << c;
  }
}

TEST(GBufferContents, SphereNormalsMaskAndDebugView) {
  // The sphere scene: one 64 x 32 UV sphere of radius 1 at the origin.
  const glm::dvec3 kCentre(0.0);
  constexpr double kRadius = 1.0;
  auto renderer = kit::test::render_stage("gbuffer", "sphere", small_settings());
  const kit::Scene& scene = renderer->scene();
  ASSERT_EQ(scene.draws.size(), 1u);
  auto [lo, hi] = world_box(scene, scene.draws[0]);
  ASSERT_NEAR(glm::distance(lo, kCentre - kRadius), 0.0, 1e-6);
  ASSERT_NEAR(glm::distance(hi, kCentre + kRadius), 0.0, 1e-6);
  CpuCamera camera(*scene.camera);
  kit::Image position = renderer->read_view(kit::View::Position, true);
  kit::Image normal = renderer->read_view(kit::View::Normal, true);
  kit::Image albedo = renderer->read_view(kit::View::Albedo, true);
  kit::Image material = renderer->read_view(kit::View::Material, true);
  kit::Image normal_view = renderer->read_view(kit::View::Normal, false);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));

  json doc = scene_json(scene);
  const json& m = material_of_node(doc, "sphere");
  const json& pbr = m["pbrMetallicRoughness"];
  glm::dvec3 base_color(pbr["baseColorFactor"][0], pbr["baseColorFactor"][1], pbr["baseColorFactor"][2]);
  const double metallic = pbr.value("metallicFactor", 1.0), roughness = pbr.value("roughnessFactor", 1.0);

  // Rays passing this far outside / inside the radius are clearly background / sphere.
  constexpr double kOutside = 1.02, kInside = 0.98;
  const double max_angle = glm::radians(kTessellationAngleDegrees);
  size_t sphere_pixels = 0, background_pixels = 0;
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      Ray ray = camera.pixel_ray(x, y);
      glm::dvec3 to_centre = kCentre - ray.origin;
      double along = glm::dot(to_centre, ray.direction);
      double miss = glm::length(to_centre - along * ray.direction) / kRadius;  // closest approach / radius
      glm::dvec4 mat = pixel(material, x, y);
      if (miss > kOutside) {
        ASSERT_EQ(mat.a, 0.0) << "background pixel (" << x << ", " << y << ") has mask " << mat.a;
        ASSERT_EQ(pixel(position, x, y), glm::dvec4(0.0)) << "background pixel (" << x << ", " << y << ")";
        ASSERT_EQ(pixel(normal_view, x, y), glm::dvec4(0.0, 0.0, 0.0, 1.0)) << "background pixel (" << x << ", " << y << ")";
        ++background_pixels;
        continue;
      }
      if (miss > kInside) continue;
      ASSERT_EQ(mat.a, 1.0) << "sphere pixel (" << x << ", " << y << ")";
      double t = along - std::sqrt(kRadius * kRadius - glm::dot(to_centre, to_centre) + along * along);
      glm::dvec3 hit = ray.origin + t * ray.direction;
      glm::dvec3 expected = glm::normalize(hit - kCentre);
      if (-glm::dot(expected, ray.direction) < kMinSphereFacing) continue;
      ++sphere_pixels;
      glm::dvec3 n(pixel(normal, x, y));
      ASSERT_NEAR(glm::length(n), 1.0, kUnitLengthTolerance) << "pixel (" << x << ", " << y << ")";
      double angle = std::acos(std::clamp(glm::dot(glm::normalize(n), expected), -1.0, 1.0));
      ASSERT_LT(angle, max_angle) << "pixel (" << x << ", " << y << "): normal off by " << glm::degrees(angle) << " degrees";
      // The stored point lies on the inscribed mesh: inside the sphere, close to it.
      double radial = glm::distance(glm::dvec3(pixel(position, x, y)), kCentre);
      ASSERT_LE(radial, kRadius * (1.0 + kHalfRelative)) << "pixel (" << x << ", " << y << ")";
      ASSERT_GE(radial, kRadius * kInscribedMinRadius * (1.0 - kHalfRelative)) << "pixel (" << x << ", " << y << ")";
      // No texture: albedo and material are the factors.
      for (int c = 0; c < 3; ++c)
        ASSERT_NEAR(albedo.at(x, y, c), base_color[c], kAlbedoTolerance) << "pixel (" << x << ", " << y << ")";
      ASSERT_NEAR(mat.r, metallic, kMaterialTolerance);
      ASSERT_NEAR(mat.g, roughness, kMaterialTolerance);
      ASSERT_EQ(mat.b, 0.0);
      // The normal debug view maps the raw normal as (n + 1) / 2.
      for (int c = 0; c < 3; ++c)
        ASSERT_NEAR(normal_view.at(x, y, c), (n[c] + 1.0) * 0.5, kDebugViewTolerance) << "pixel (" << x << ", " << y << ")";
    }
  }
  EXPECT_GT(sphere_pixels, static_cast<size_t>(kWidth * kHeight / 10));
  EXPECT_GT(background_pixels, static_cast<size_t>(kWidth * kHeight / 10));
}

// ---------------------------------------------------------------------------
// glTF material modes: emissive colour, alphaMode MASK, doubleSided. One 2 m x 2 m
// quad in the z = 0 plane facing +z, built in code, seen along the z axis.

// The image pixel (x, y) a world point projects into (row 0 at the top), in double.
std::pair<int, int> pixel_of(const kit::FrameCamera& camera, const glm::dvec3& p) {
  const glm::dvec4 clip = glm::dmat4(camera.projection) * glm::dmat4(camera.view) * glm::dvec4(p, 1.0);
  return {static_cast<int>(std::floor((clip.x / clip.w + 1.0) * 0.5 * kWidth)),
          static_cast<int>(std::floor((1.0 - clip.y / clip.w) * 0.5 * kHeight))};
}

kit::Scene quad_scene(const kit::Material& material) {
  kit::Primitive quad = kit::test::quad_primitive({1, 0, 0}, {0, 1, 0}, {2, 2});
  quad.material = 0;
  return kit::test::tiny_scene({quad}, {material}, {{0, glm::mat4(1.0f)}}, {});
}

kit::FrameCamera quad_camera(double eye_z) {
  return kit::test::look_at_camera({0.0f, 0.0f, static_cast<float>(eye_z)}, {0.0f, 0.0f, 0.0f}, 0.8f, small_settings());
}

// Renders `scene` at `stage` with the solutions, or with the lab files under `lab_root`
// (a variant_root) when given. The renderer keeps a reference to `scene`.
std::unique_ptr<kit::Renderer> render_quad(const std::string& stage, const kit::Scene& scene, const kit::FrameCamera& camera,
                                           const fs::path& lab_root = {}) {
  auto renderer = lab_root.empty()
                      ? kit::test::make_renderer(stage, scene, small_settings())
                      : kit::test::make_renderer(stage, scene, small_settings(),
                                                 kit::test::full_root_library(kit::find_stage(stage), lab_root));
  renderer->render(camera);
  return renderer;
}

TEST(GBufferMaterialModes, EmissiveColourOnBlackBaseIsTheEmittedRadiance) {
  // A red emitter (emissiveFactor (1, 0.1, 0.05), strength 3) on a black base colour,
  // no lights: the lighting pass's HDR value is L_e alone.
  const glm::dvec3 factor(1.0, 0.1, 0.05);
  const double strength = 3.0;
  const glm::dvec3 expected = factor * strength;
  kit::Material m = kit::test::plain_material(0.5f);
  m.base_color_factor = glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
  m.emissive = glm::vec3(expected);  // the loader's emissiveFactor * emissiveStrength
  const kit::FrameCamera camera = quad_camera(3.0);
  const kit::Scene scene = quad_scene(m);
  auto renderer = render_quad("lighting", scene, camera);
  const kit::Image hdr = renderer->read_view(kit::View::Hdr, true);
  const kit::Image emission = renderer->read_view(kit::View::Emission, true);
  auto [x, y] = pixel_of(camera, {0.0, 0.0, 0.0});
  // Two RGBA16F stores (the emission attachment, then the HDR target), each within 2^-11.
  for (int c = 0; c < 3; ++c) {
    const double tolerance = 2.0 * kHalfRelative * expected[c];
    EXPECT_NEAR(emission.at(x, y, c), expected[c], tolerance) << "emission attachment, channel " << c;
    EXPECT_NEAR(hdr.at(x, y, c), expected[c], tolerance) << "HDR, channel " << c;
  }
  // Witness: the old layout's rule, L_e = max(emissive) x albedo, makes this pixel black.
  const double old_rule = std::max(expected.r, std::max(expected.g, expected.b)) * 0.0;
  EXPECT_GT(std::fabs(old_rule - expected.r), 2.0 * kHalfRelative * expected.r);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST(GBufferMaterialModes, MaskCutoffDecidesCoverage) {
  // A 2 x 1 base colour texture, nearest filtered: alpha 64/255 (below the cutoff 0.5)
  // on the quad's left half, 191/255 (above) on its right half.
  constexpr unsigned char kLowAlpha = 64, kHighAlpha = 191;
  constexpr double kCutoff = 0.5;
  ASSERT_LT(kLowAlpha / 255.0, kCutoff);
  ASSERT_GT(kHighAlpha / 255.0, kCutoff);
  kit::Material m = kit::test::plain_material(0.5f);
  m.base_color_factor = glm::vec4(1.0f);
  m.alpha_mode = KIT_ALPHA_MASK;
  m.alpha_cutoff = static_cast<float>(kCutoff);
  m.texture(KIT_UNIT_BASE_COLOR).image = 0;
  m.texture(KIT_UNIT_BASE_COLOR).sampler = 0;
  kit::Scene scene = quad_scene(m);
  scene.images.push_back(
      {"alpha ramp", 2, 1, {}, kit::ImageRgba8{2, 1, {200, 200, 200, kLowAlpha, 200, 200, 200, kHighAlpha}}});
  kit::TextureSampler nearest;
  nearest.min_filter = GL_NEAREST;
  nearest.mag_filter = GL_NEAREST;
  nearest.wrap_s = nearest.wrap_t = GL_CLAMP_TO_EDGE;
  scene.samplers.push_back(nearest);
  const kit::FrameCamera camera = quad_camera(3.0);
  const auto below = pixel_of(camera, {-0.5, 0.0, 0.0});  // u = 0.25: texel 0
  const auto above = pixel_of(camera, {0.5, 0.0, 0.0});   // u = 0.75: texel 1

  auto renderer = render_quad("gbuffer", scene, camera);
  const kit::Image material = renderer->read_view(kit::View::Material, true);
  const kit::Image albedo = renderer->read_view(kit::View::Albedo, true);
  EXPECT_EQ(material.at(below.first, below.second, 3), 0.0f) << "a texel below the cutoff is no surface";
  EXPECT_EQ(material.at(above.first, above.second, 3), 1.0f) << "a texel above the cutoff is surface";
  // albedo.a keeps the base colour alpha (RGBA8: one rounding step).
  EXPECT_NEAR(albedo.at(above.first, above.second, 3), kHighAlpha / 255.0, 1.0 / 255.0);

  // Witness: without the discard, the texel below the cutoff is drawn as surface.
  const fs::path no_discard = kit::test::variant_root(
      "gbuffer_mask_no_discard",
      {{"01-gbuffer/gbuffer.frag", "    kit_alpha_discard(base_color.a);  // MASK: below the cutoff, no surface here\n", ""}});
  auto naive = render_quad("gbuffer", scene, camera, no_discard);
  EXPECT_EQ(naive->read_view(kit::View::Material, true).at(below.first, below.second, 3), 1.0f);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

// Where the centre ray of image pixel (x, y) meets the plane z = 0, in double.
glm::dvec3 hit_on_z0(const kit::FrameCamera& camera, int x, int y) {
  const glm::dmat4 inverse = glm::inverse(glm::dmat4(camera.projection) * glm::dmat4(camera.view));
  const glm::dvec2 ndc((x + 0.5) / kWidth * 2.0 - 1.0, 1.0 - (y + 0.5) / kHeight * 2.0);
  const glm::dvec4 near_point = inverse * glm::dvec4(ndc, -1.0, 1.0), far_point = inverse * glm::dvec4(ndc, 1.0, 1.0);
  const glm::dvec3 a = glm::dvec3(near_point) / near_point.w, b = glm::dvec3(far_point) / far_point.w;
  return a + (b - a) * (-a.z / (b.z - a.z));
}

TEST(GBufferMaterialModes, AlbedoIsFactorTimesTexelTimesVertexColour) {
  // The quad's COLOR_0 goes from `left` (x = -1) to `right` (x = +1): an affine function
  // of the position, which both triangles interpolate exactly, so the colour at a pixel
  // is known in double from where its centre ray meets the quad. A 1 x 1 texture and a
  // factor multiply it; alpha too (OPAQUE keeps it in albedo.a).
  const glm::vec4 left(1.0f, 0.2f, 0.5f, 1.0f), right(0.3f, 1.0f, 0.1f, 0.6f);
  const std::array<unsigned char, 4> texel = {200, 150, 100, 230};
  kit::Material m = kit::test::plain_material(0.5f);
  m.base_color_factor = glm::vec4(0.9f, 0.8f, 0.6f, 0.95f);
  m.texture(KIT_UNIT_BASE_COLOR).image = 0;
  kit::Scene scene = quad_scene(m);
  scene.images.push_back({"texel", 1, 1, {}, kit::ImageRgba8{1, 1, {texel.begin(), texel.end()}}});
  const kit::Vertex *at_left = nullptr, *at_right = nullptr;
  for (kit::Vertex& v : scene.primitives[0].vertices) {
    const glm::vec4 color = v.position.x < 0.0f ? left : right;
    for (int c = 0; c < 4; ++c) v.color[c] = kit::vertex_color_component(color[c]);
    (v.position.x < 0.0f ? at_left : at_right) = &v;
  }
  const glm::dvec4 linear_texel(srgb_to_linear(texel[0] / 255.0), srgb_to_linear(texel[1] / 255.0),
                                srgb_to_linear(texel[2] / 255.0), texel[3] / 255.0);
  const glm::dvec4 left_color = ref::vertex_color(*at_left), right_color = ref::vertex_color(*at_right);
  const kit::FrameCamera camera = quad_camera(3.0);
  auto expected_at = [&](int x, int y) {
    const double t = (hit_on_z0(camera, x, y).x + 1.0) / 2.0;
    return ref::base_color(m, linear_texel, glm::mix(left_color, right_color, t));
  };
  auto renderer = render_quad("gbuffer", scene, camera);
  const kit::Image albedo = renderer->read_view(kit::View::Albedo, true);
  // Witness: the geometry pass without the vertex colour.
  const fs::path no_color = kit::test::variant_root(
      "gbuffer_no_vertex_color", {{"01-gbuffer/gbuffer.frag", "(v_texcoords)) * v_color;", "(v_texcoords));"}});
  auto naive = render_quad("gbuffer", scene, camera, no_color);
  const kit::Image naive_albedo = naive->read_view(kit::View::Albedo, true);
  size_t tested = 0;
  for (double x_world : {-0.9, -0.5, -0.1, 0.3, 0.7, 0.9}) {
    const auto [x, y] = pixel_of(camera, {x_world, 0.1, 0.0});
    const glm::dvec4 expected = expected_at(x, y);
    double naive_error = 0.0;
    for (int c = 0; c < 4; ++c) {
      ASSERT_NEAR(albedo.at(x, y, c), expected[c], kAlbedoTolerance) << "pixel (" << x << ", " << y << ") channel " << c;
      naive_error = std::max(naive_error, std::fabs(naive_albedo.at(x, y, c) - expected[c]));
    }
    EXPECT_GT(naive_error, 10.0 * kAlbedoTolerance) << "pixel (" << x << ", " << y << "): ignoring COLOR_0 must show";
    ++tested;
  }
  EXPECT_EQ(tested, 6u);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST(GBufferMaterialModes, EachTextureSamplesItsOwnUvSetAndTransform) {
  // A linear 256 x 256 metallic-roughness texture: roughness (G) = column / 255 and
  // metallic (B) = row / 255. Bilinear sampling of a ramp returns the ramp itself:
  // inside the outer half texels, roughness = (256 u - 0.5) / 255 and metallic =
  // (256 v - 0.5) / 255, so the material attachment shows the UV it was sampled at.
  constexpr int kSize = 256;
  kit::ImageRgba8 ramp{kSize, kSize, std::vector<unsigned char>(static_cast<size_t>(kSize) * kSize * 4, 255)};
  for (int row = 0; row < kSize; ++row)
    for (int column = 0; column < kSize; ++column) {
      unsigned char* texel = &ramp.pixels[(static_cast<size_t>(row) * kSize + static_cast<size_t>(column)) * 4];
      texel[1] = static_cast<unsigned char>(column);
      texel[2] = static_cast<unsigned char>(row);
    }
  kit::Material m = kit::test::plain_material(1.0f);
  m.metallic_factor = 1.0f;
  m.texture(KIT_UNIT_METALLIC_ROUGHNESS).image = 0;
  m.texture(KIT_UNIT_METALLIC_ROUGHNESS).sampler = 0;
  kit::TextureSampler bilinear;
  bilinear.min_filter = bilinear.mag_filter = GL_LINEAR;
  bilinear.wrap_s = bilinear.wrap_t = GL_CLAMP_TO_EDGE;
  // The quad's UV sets as functions of where a point lies on it, s = (x + 1) / 2 and
  // t = (y + 1) / 2: TEXCOORD_0 as quad_primitive makes it, TEXCOORD_1 another affine map.
  auto uv0_at = [](glm::dvec2 st) { return glm::dvec2(st.x, 1.0 - st.y); };
  auto uv1_at = [](glm::dvec2 st) { return glm::dvec2(0.8 - 0.6 * st.x, 0.1 + 0.7 * st.y); };
  kit::Scene scene = quad_scene(m);
  for (kit::Vertex& v : scene.primitives[0].vertices) {
    const glm::dvec2 st((v.position.x + 1.0) / 2.0, (v.position.y + 1.0) / 2.0);
    ASSERT_EQ(glm::dvec2(v.texcoord), uv0_at(st));
    v.texcoord1 = glm::vec2(uv1_at(st));
  }
  scene.images.push_back({"ramp", kSize, kSize, {}, ramp});
  scene.samplers.push_back(bilinear);
  const kit::FrameCamera camera = quad_camera(3.0);
  // Witness: every texture sampled at UV slot 0 untransformed, as one UV per vertex would.
  const fs::path one_uv = kit::test::variant_root(
      "gbuffer_one_uv_for_every_texture",
      {{"01-gbuffer/gbuffer.frag", "kit_metallic_roughness_uv(v_texcoords)", "v_texcoords.xy"}});
  // llvmpipe's bilinear filter of 8-bit texels runs in fixed point and gives an 8-bit
  // result: up to half a texel step (1/255) from the exact ramp. The RGBA16F store
  // then seems to round towards zero (159/255 reads back as 1276 * 2^-11, not the
  // nearest 1277 * 2^-11): up to one half-float step lower, 2^-11 in [0.5, 1), 0.125
  // of a texel step. Measured over every covered pixel of both cases (and of both
  // with the other rotation sign): up to 0.621 of a step; the 25 pixels tested below
  // had shown 0.47. A step is 1/256 of the UV: a UV off by 2 % is 5 steps.
  constexpr double kRampTolerance = 0.65 / 255.0;
  struct Case {
    const char* name;
    int slot;
    glm::dvec2 offset;
    double rotation;
    glm::dvec2 scale;
  };
  // The witness cannot tell a case apart where its transformed UV comes close to slot
  // 0's untransformed one: these cases keep that point off the quad. (With rotation
  // -0.4, TEXCOORD_0's lies at (u, v) = (0.36, 0.52), beside the pixel tested at
  // (-0.35, 0); with 0.4 at (0.60, -0.11).)
  const Case cases[] = {{"TEXCOORD_0, transformed", 0, {0.3, 0.1}, 0.4, {0.6, 0.7}},
                        {"TEXCOORD_1, transformed", 1, {0.15, 0.05}, -0.3, {0.9, 0.8}}};
  for (const Case& c : cases) {
    SCOPED_TRACE(c.name);
    // The loader's TextureUv for KHR_texture_transform {offset, rotation, scale}.
    kit::TextureUv& uv = scene.materials[0].texture(KIT_UNIT_METALLIC_ROUGHNESS).uv;
    uv.slot = c.slot;
    uv.transform = kit::texture_transform_matrix(glm::vec2(c.offset), static_cast<float>(c.rotation), glm::vec2(c.scale));
    auto renderer = render_quad("gbuffer", scene, camera);
    auto naive = render_quad("gbuffer", scene, camera, one_uv);
    const kit::Image material = renderer->read_view(kit::View::Material, true);
    const kit::Image naive_material = naive->read_view(kit::View::Material, true);
    size_t tested = 0, naive_wrong = 0;
    for (double xw : {-0.7, -0.35, 0.0, 0.35, 0.7})
      for (double yw : {-0.7, -0.35, 0.0, 0.35, 0.7}) {
        const auto [x, y] = pixel_of(camera, {xw, yw, 0.0});
        const glm::dvec3 hit = hit_on_z0(camera, x, y);
        const glm::dvec2 st((hit.x + 1.0) / 2.0, (hit.y + 1.0) / 2.0);
        const glm::dvec2 sampled =
            kit::test::texture_transformed(c.slot == 1 ? uv1_at(st) : uv0_at(st), c.offset, c.rotation, c.scale);
        const double inner_min = 1.5 / kSize, inner_max = 1.0 - 1.5 / kSize;
        if (sampled.x < inner_min || sampled.x > inner_max || sampled.y < inner_min || sampled.y > inner_max) continue;
        const double roughness = (kSize * sampled.x - 0.5) / 255.0, metallic = (kSize * sampled.y - 0.5) / 255.0;
        EXPECT_NEAR(material.at(x, y, 0), metallic, kRampTolerance) << "pixel (" << x << ", " << y << ")";
        EXPECT_NEAR(material.at(x, y, 1), roughness, kRampTolerance) << "pixel (" << x << ", " << y << ")";
        naive_wrong += std::fabs(naive_material.at(x, y, 0) - metallic) > 10.0 * kRampTolerance ||
                       std::fabs(naive_material.at(x, y, 1) - roughness) > 10.0 * kRampTolerance;
        ++tested;
      }
    EXPECT_GE(tested, 20u);
    EXPECT_EQ(naive_wrong, tested) << "one UV for every texture must show at every tested pixel";
  }
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

TEST(GBufferMaterialModes, DoubleSidedBackFaceNormalFacesTheViewer) {
  // The quad faces +z; the camera looks at its back from z = -3.
  kit::Material m = kit::test::plain_material(0.5f);
  m.double_sided = true;
  const kit::FrameCamera camera = quad_camera(-3.0);
  const auto [x, y] = pixel_of(camera, {0.0, 0.0, 0.0});
  const glm::dvec3 to_camera(0.0, 0.0, -1.0);  // from the quad's centre towards the eye

  const kit::Scene scene = quad_scene(m);
  auto renderer = render_quad("gbuffer", scene, camera);
  const kit::Image normal = renderer->read_view(kit::View::Normal, true);
  EXPECT_EQ(renderer->read_view(kit::View::Material, true).at(x, y, 3), 1.0f) << "the back face is drawn";
  const glm::dvec3 n(normal.at(x, y, 0), normal.at(x, y, 1), normal.at(x, y, 2));
  // The flipped normal is exactly -(0, 0, 1): every component is representable.
  EXPECT_EQ(n, to_camera) << "back-face normal (" << n.x << ", " << n.y << ", " << n.z << ")";

  // Witness 1: without the flip, the stored normal points away from the camera.
  const fs::path no_flip = kit::test::variant_root(
      "gbuffer_double_sided_no_flip",
      {{"01-gbuffer/gbuffer.frag", "out_normal = vec4(kit_facing_normal(normalize(v_world_normal)), 0.0);",
        "out_normal = vec4(normalize(v_world_normal), 0.0);"}});
  auto unflipped = render_quad("gbuffer", scene, camera, no_flip);
  const kit::Image away = unflipped->read_view(kit::View::Normal, true);
  EXPECT_LT(glm::dot(glm::dvec3(away.at(x, y, 0), away.at(x, y, 1), away.at(x, y, 2)), to_camera), 0.0);

  // Witness 2: the same material single-sided is culled: nothing is drawn.
  m.double_sided = false;
  const kit::Scene single_sided = quad_scene(m);
  auto culled = render_quad("gbuffer", single_sided, camera);
  EXPECT_EQ(culled->read_view(kit::View::Material, true).at(x, y, 3), 0.0f);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

// ---------------------------------------------------------------------------
// Large textures uploaded as S3TC blocks (common/images/texture_prepare.h; from 1024 x
// 1024 texels, --compress-textures on, as auto does for a scene over the texture budget):
// the albedo the geometry pass writes from the compressed texture against the same
// texture uploaded as RGBA8.

constexpr int kLargeTextureSide = 1024;
constexpr int kGridSpacing = 16;  // texels between the texture's dark grid lines
constexpr int kNoiseAmplitude = 12;  // per-texel noise, +- codes

// A base colour with detail at every scale: a smooth two-way gradient, a grid of one-texel
// dark lines every kGridSpacing texels and per-texel noise; opaque, so BC1.
kit::ImageRgba8 detailed_large_texture() {
  kit::ImageRgba8 image{kLargeTextureSide, kLargeTextureSide, {}};
  image.pixels.resize(static_cast<size_t>(kLargeTextureSide) * kLargeTextureSide * 4);
  for (int y = 0; y < kLargeTextureSide; ++y)
    for (int x = 0; x < kLargeTextureSide; ++x) {
      const bool line = x % kGridSpacing == 0 || y % kGridSpacing == 0;
      const uint32_t hash = (static_cast<uint32_t>(x) * 73856093u) ^ (static_cast<uint32_t>(y) * 19349663u);
      const int noise = static_cast<int>(hash % (2 * kNoiseAmplitude + 1)) - kNoiseAmplitude;
      const int base[3] = {40 + 180 * x / kLargeTextureSide, 200 - 150 * y / kLargeTextureSide, 60 + 120 * (x + y) / (2 * kLargeTextureSide)};
      unsigned char* texel = &image.pixels[(static_cast<size_t>(y) * kLargeTextureSide + static_cast<size_t>(x)) * 4];
      for (int c = 0; c < 3; ++c) texel[c] = static_cast<unsigned char>(std::clamp(line ? base[c] / 4 : base[c] + noise, 0, 255));
      texel[3] = 255;
    }
  return image;
}

// Every 4 x 4 block replaced by the mean of its codes: an encoder that keeps one colour a block.
kit::ImageRgba8 block_means(kit::ImageRgba8 image) {
  constexpr int kBlock = 4;
  for (int by = 0; by < image.height; by += kBlock)
    for (int bx = 0; bx < image.width; bx += kBlock)
      for (int c = 0; c < 4; ++c) {
        int sum = 0;
        for (int y = by; y < by + kBlock; ++y)
          for (int x = bx; x < bx + kBlock; ++x) sum += image.pixels[(static_cast<size_t>(y) * static_cast<size_t>(image.width) + static_cast<size_t>(x)) * 4 + static_cast<size_t>(c)];
        for (int y = by; y < by + kBlock; ++y)
          for (int x = bx; x < bx + kBlock; ++x)
            image.pixels[(static_cast<size_t>(y) * static_cast<size_t>(image.width) + static_cast<size_t>(x)) * 4 + static_cast<size_t>(c)] =
                static_cast<unsigned char>((sum + kBlock * kBlock / 2) / (kBlock * kBlock));
      }
  return image;
}

// Per-channel mean and largest absolute difference of two albedo views, in 1/255 steps,
// and the PSNR of their RGB; every pixel shows the quad.
struct AlbedoDifference {
  glm::dvec3 mean{0.0}, max{0.0};
  double psnr_db = 0.0;
};
AlbedoDifference albedo_difference(const kit::Image& a, const kit::Image& b) {
  AlbedoDifference d;
  double squared = 0.0;
  const size_t pixels = static_cast<size_t>(a.width) * static_cast<size_t>(a.height);
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x)
      for (int c = 0; c < 3; ++c) {
        const double e = 255.0 * std::fabs(a.at(x, y, c) - b.at(x, y, c));
        d.mean[c] += e / static_cast<double>(pixels);
        d.max[c] = std::max(d.max[c], e);
        squared += e * e;
      }
  d.psnr_db = 10.0 * std::log10(255.0 * 255.0 / std::max(squared / static_cast<double>(3 * pixels), 1e-12));
  return d;
}

kit::Image albedo_of(const kit::Scene& scene, const kit::FrameCamera& camera, bool compress) {
  kit::RenderSettings settings = small_settings();
  settings.texture_compression = compress ? kit::TextureCompression::On : kit::TextureCompression::Off;
  auto renderer = kit::test::make_renderer("gbuffer", scene, settings);
  renderer->render(camera);
  return renderer->read_view(kit::View::Albedo, true);
}

TEST(GBufferTextures, CompressedLargeTextureStaysNearTheUncompressedOne) {
  kit::Material m = kit::test::plain_material(0.5f);
  m.base_color_factor = glm::vec4(1.0f);
  m.texture(KIT_UNIT_BASE_COLOR).image = 0;
  kit::Scene scene = quad_scene(m);
  const kit::ImageRgba8 texture = detailed_large_texture();
  scene.images.push_back({"detailed", texture.width, texture.height, {}, texture});
  ASSERT_TRUE(kit::is_large_texture(texture.width, texture.height));
  kit::Scene blocky = quad_scene(m);
  blocky.images.push_back({"block means", texture.width, texture.height, {}, block_means(texture)});
  // Bounds in 1/255 steps of the linear albedo (RGBA8), per channel, and dB over RGB.
  struct View {
    float eye_z;
    double max_mean, max_error, min_psnr_db;
  };
  // 0.2 m away the quad fills the view and a texel covers more than a pixel (level 0):
  // measured mean 2.1-2.4, max 16-19, 37.9 dB. 1.5 m away about 8 texels fall on a
  // pixel (levels 2-3), averaging the blocks' errors out: 0.8-1.2, 7-10, 45.0 dB.
  for (const View& view : {View{0.2f, 3.0, 24.0, 35.0}, View{1.5f, 2.0, 16.0, 40.0}}) {
    const kit::FrameCamera camera = quad_camera(view.eye_z);
    const kit::Image exact = albedo_of(scene, camera, false);
    const AlbedoDifference compressed = albedo_difference(albedo_of(scene, camera, true), exact);
    std::printf("eye %.1f m: compressed albedo mean (%.2f %.2f %.2f), max (%.1f %.1f %.1f) /255, PSNR %.1f dB\n",
                view.eye_z, compressed.mean.r, compressed.mean.g, compressed.mean.b, compressed.max.r,
                compressed.max.g, compressed.max.b, compressed.psnr_db);
    for (int c = 0; c < 3; ++c) {
      EXPECT_LE(compressed.mean[c], view.max_mean) << "eye " << view.eye_z << " channel " << c;
      EXPECT_LE(compressed.max[c], view.max_error) << "eye " << view.eye_z << " channel " << c;
    }
    EXPECT_GE(compressed.psnr_db, view.min_psnr_db) << "eye " << view.eye_z;
    // Witness: one colour a block (uploaded uncompressed, so only that loss differs) breaks
    // the bounds (measured 25.9 and 34.8 dB, means 8.8-10.3 and 3.0-4.1).
    const AlbedoDifference naive = albedo_difference(albedo_of(blocky, camera, false), exact);
    std::printf("eye %.1f m: block means mean (%.2f %.2f %.2f), max (%.1f %.1f %.1f) /255, PSNR %.1f dB\n",
                view.eye_z, naive.mean.r, naive.mean.g, naive.mean.b, naive.max.r, naive.max.g, naive.max.b,
                naive.psnr_db);
    EXPECT_LT(naive.psnr_db, view.min_psnr_db) << "eye " << view.eye_z;
    for (int c = 0; c < 3; ++c) EXPECT_GT(naive.mean[c], view.max_mean) << "eye " << view.eye_z << " channel " << c;
  }
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

// A tangent-space normal map with detail: two crossing waves of slope up to 0.4 and
// per-texel noise, stored as (n + 1) / 2.
kit::ImageRgba8 detailed_normal_map() {
  constexpr double kSlope = 0.4, kNoiseSlope = 0.05;
  constexpr double kWaveX = 37.0, kWaveY = 53.0;  // texels a wave, prime: no alignment with 4x4 blocks
  kit::ImageRgba8 image{kLargeTextureSide, kLargeTextureSide, {}};
  image.pixels.resize(static_cast<size_t>(kLargeTextureSide) * kLargeTextureSide * 4);
  for (int y = 0; y < kLargeTextureSide; ++y)
    for (int x = 0; x < kLargeTextureSide; ++x) {
      const uint32_t hash = (static_cast<uint32_t>(x) * 83492791u) ^ (static_cast<uint32_t>(y) * 2654435761u);
      const double noise = (static_cast<double>(hash % 1001) / 500.0 - 1.0) * kNoiseSlope;
      const glm::dvec3 n = glm::normalize(glm::dvec3(kSlope * std::sin(2.0 * glm::pi<double>() * x / kWaveX) + noise,
                                                     kSlope * std::cos(2.0 * glm::pi<double>() * y / kWaveY) - noise, 1.0));
      unsigned char* texel = &image.pixels[(static_cast<size_t>(y) * kLargeTextureSide + static_cast<size_t>(x)) * 4];
      for (int c = 0; c < 3; ++c) texel[c] = static_cast<unsigned char>(std::lround((n[c] + 1.0) * 0.5 * 255.0));
      texel[3] = 255;
    }
  return image;
}

TEST(GBufferTextures, LargeNormalMapsStayUncompressed) {
  // BC1 turned this normal map's normals by 1.5 degrees on average (8.3 at most) 0.2 m
  // away and by 5.7 (21) 1.5 m away, when SceneGpu still compressed normal maps: they
  // stay RGBA8. The same material's large base colour is compressed (the witness that
  // compression was on).
  kit::Material m = kit::test::plain_material(0.5f);
  m.base_color_factor = glm::vec4(1.0f);
  m.texture(KIT_UNIT_NORMAL_MAP).image = 0;
  m.texture(KIT_UNIT_BASE_COLOR).image = 1;
  kit::Scene scene = quad_scene(m);
  const kit::ImageRgba8 normals = detailed_normal_map(), colour = detailed_large_texture();
  scene.images.push_back({"normals", normals.width, normals.height, {}, normals});
  scene.images.push_back({"colour", colour.width, colour.height, {}, colour});
  for (float eye_z : {0.2f, 1.5f}) {
    const kit::FrameCamera camera = quad_camera(eye_z);
    kit::Image normal[2], albedo[2];
    for (int compress = 0; compress < 2; ++compress) {
      kit::RenderSettings settings = small_settings();
      settings.texture_compression = compress == 1 ? kit::TextureCompression::On : kit::TextureCompression::Off;
      auto renderer = kit::test::make_renderer("normalmap", scene, settings);
      renderer->render(camera);
      normal[compress] = renderer->read_view(kit::View::Normal, true);
      albedo[compress] = renderer->read_view(kit::View::Albedo, true);
    }
    EXPECT_EQ(kit::test::max_abs_difference(normal[0], normal[1]), 0.0f) << "eye " << eye_z;
    EXPECT_GT(kit::test::max_abs_difference(albedo[0], albedo[1]), 0.0f) << "eye " << eye_z;
  }
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

}  // namespace

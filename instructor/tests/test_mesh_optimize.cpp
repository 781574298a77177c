// Geometry-pass optimisation (common/scene/mesh_optimize.h): welding, triangle and
// vertex reordering keep the mesh and the rendered G-buffer; frustum culling
// is conservative and leaves the image bitwise unchanged. Suite names start
// with MeshOptimize, the file's name.
#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstddef>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "kit_test.h"
#include "scene/mesh_optimize.h"

namespace {

using kit::Image;
using kit::Primitive;
using kit::Vertex;

// A whole vertex as comparable floats (position, normal, texcoord, tangent, colour).
using VertexKey = std::array<float, 16>;
// A triangle's three vertices, rotated so the smallest comes first: the same
// triangle with the same winding gives the same key wherever it starts.
using TriangleKey = std::array<VertexKey, 3>;

VertexKey key_of(const Vertex& v) {
  VertexKey k{};
  std::memcpy(k.data(), &v, offsetof(Vertex, color));  // the 12 floats before the colour
  for (int c = 0; c < 4; ++c) k[12 + static_cast<size_t>(c)] = v.color[c];
  return k;
}

VertexKey position_key(const Vertex& v) { return {v.position.x, v.position.y, v.position.z}; }

// Rotation::Canonical compares triangles modulo rotation (same winding);
// Rotation::AsStored also requires the same first (provoking) vertex.
enum class Rotation { Canonical, AsStored };

template <typename KeyFn>
std::vector<TriangleKey> triangles(const Primitive& p, KeyFn key, Rotation rotation = Rotation::Canonical) {
  std::vector<TriangleKey> out;
  for (size_t t = 0; t + 2 < p.indices.size(); t += 3) {
    TriangleKey tri{key(p.vertices[p.indices[t]]), key(p.vertices[p.indices[t + 1]]), key(p.vertices[p.indices[t + 2]])};
    if (rotation == Rotation::Canonical)
      std::rotate(tri.begin(), std::min_element(tri.begin(), tri.end()), tri.end());  // keeps the cyclic order
    out.push_back(tri);
  }
  std::sort(out.begin(), out.end());
  return out;
}

// An n x n grid of quads as a triangle soup: every triangle has its own three
// vertices, so each inner grid point is stored up to six times.
Primitive triangle_soup_grid(int n) {
  Primitive p;
  auto vertex = [](int i, int j) {
    Vertex v;
    v.position = glm::vec3(static_cast<float>(i), 0.0f, static_cast<float>(j));
    v.normal = glm::vec3(0, 1, 0);
    v.texcoord = glm::vec2(static_cast<float>(i), static_cast<float>(j));
    v.tangent = glm::vec4(1, 0, 0, 1);
    return v;
  };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const Vertex quad[6] = {vertex(i, j), vertex(i, j + 1), vertex(i + 1, j + 1),
                              vertex(i, j), vertex(i + 1, j + 1), vertex(i + 1, j)};
      for (const Vertex& v : quad) {
        p.indices.push_back(static_cast<uint32_t>(p.vertices.size()));
        p.vertices.push_back(v);
      }
    }
  p.bounds_min = glm::vec3(0.0f);
  p.bounds_max = glm::vec3(static_cast<float>(n), 0.0f, static_cast<float>(n));
  return p;
}

TEST(MeshOptimize, WeldingMergesDuplicatesAndKeepsEveryTriangle) {
  constexpr int kGrid = 8;
  Primitive p = triangle_soup_grid(kGrid);
  const Primitive before = p;
  kit::optimize_primitive(p);
  EXPECT_EQ(p.vertices.size(), static_cast<size_t>((kGrid + 1) * (kGrid + 1)));  // one per grid point
  EXPECT_EQ(p.indices.size(), before.indices.size());
  for (uint32_t i : p.indices) ASSERT_LT(i, p.vertices.size());
  // Index -> position mapping: every triangle has the same corners in the same cyclic order.
  EXPECT_EQ(triangles(p, position_key), triangles(before, position_key));
  EXPECT_EQ(triangles(p, key_of), triangles(before, key_of));
  EXPECT_EQ(triangles(p, key_of, Rotation::AsStored), triangles(before, key_of, Rotation::AsStored));
  EXPECT_EQ(p.bounds_min, before.bounds_min);
  EXPECT_EQ(p.bounds_max, before.bounds_max);
}

TEST(MeshOptimize, WeldingKeepsVerticesThatDifferInAnyAttribute) {
  // A hard edge: the same positions with two different normals must stay apart.
  Primitive p = triangle_soup_grid(1);
  p.vertices[3].normal = glm::vec3(0, 0, 1);  // second triangle's first corner: position (0,0,0) again
  p.vertices[4].texcoord.x += 0.5f;             // and one with another UV
  kit::optimize_primitive(p);
  EXPECT_EQ(p.vertices.size(), 6u);  // 4 corners + the two changed duplicates
}

TEST(MeshOptimize, EmptyPrimitiveIsLeftAlone) {
  Primitive p;
  kit::optimize_primitive(p);
  EXPECT_TRUE(p.vertices.empty());
  kit::MeshStats s = kit::analyze(p);
  EXPECT_EQ(s.vertex_count, 0u);
  EXPECT_EQ(s.triangle_count, 0u);
  EXPECT_EQ(s.acmr, 0.0f);
}

// Prints one row of the before/after table (the figures reported for the kit).
void print_stats(const std::string& name, const kit::MeshStats& a, const kit::MeshStats& b) {
  std::printf("%-50s verts %5zu -> %5zu  tris %5zu -> %5zu  ACMR %.3f -> %.3f  ATVR %.3f -> %.3f  "
              "overdraw %.3f -> %.3f  overfetch %.3f -> %.3f\n",
              name.c_str(), a.vertex_count, b.vertex_count, a.triangle_count, b.triangle_count, a.acmr, b.acmr, a.atvr,
              b.atvr, a.overdraw, b.overdraw, a.overfetch, b.overfetch);
}

TEST(MeshOptimize, DefaultScenePrimitivesKeepTheirTrianglesAndCacheDoesNotGetWorse) {
  const kit::Scene& original = kit::test::scene("default");
  kit::Scene optimized = original;
  kit::optimize_scene(optimized);
  ASSERT_EQ(optimized.primitives.size(), original.primitives.size());
  size_t spheres = 0, verts_before = 0, verts_after = 0, tris = 0;
  for (size_t i = 0; i < original.primitives.size(); ++i) {
    const Primitive& a = original.primitives[i];
    const Primitive& b = optimized.primitives[i];
    SCOPED_TRACE(a.name);
    const kit::MeshStats sa = kit::analyze(a), sb = kit::analyze(b);
    print_stats(a.name, sa, sb);
    EXPECT_EQ(sb.triangle_count, sa.triangle_count);
    EXPECT_LE(sb.vertex_count, sa.vertex_count);
    EXPECT_EQ(triangles(b, key_of), triangles(a, key_of));  // same triangles, same winding
    // meshoptimizer moves whole triangles and never rotates one: the first vertex stays first.
    EXPECT_EQ(triangles(b, key_of, Rotation::AsStored), triangles(a, key_of, Rotation::AsStored));
    EXPECT_EQ(b.material, a.material);
    EXPECT_EQ(b.bounds_min, a.bounds_min);
    EXPECT_EQ(b.bounds_max, a.bounds_max);
    if (a.name.find("sphere") != std::string::npos) {
      ++spheres;
      EXPECT_LE(sb.acmr, sa.acmr);
      EXPECT_LE(sb.atvr, sa.atvr);
    }
    verts_before += sa.vertex_count;
    verts_after += sb.vertex_count;
    tris += sa.triangle_count;
  }
  std::printf("default scene: %zu primitives, %zu triangles, %zu -> %zu vertices\n", original.primitives.size(), tris,
              verts_before, verts_after);
  EXPECT_GT(spheres, 0u);
}

// Renders one frame of `stage` from `camera` with solutions' shaders and
// reads back the raw G-buffer (and the stage's final image).
struct Frame {
  Image position, normal, albedo, material, depth, final_image;
};

Frame render(const std::string& stage_name, const kit::Scene& scene, const kit::Camera& camera,
             kit::RenderSettings settings = {}) {
  kit::test::context();
  const kit::Stage& stage = kit::find_stage(stage_name);
  kit::Renderer renderer(stage, kit::stage_library(stage, kit::kit_root() / "solutions"), scene, settings);
  renderer.render(kit::frame_camera(camera, static_cast<float>(settings.width) / static_cast<float>(settings.height)));
  glFinish();
  Frame f;
  f.position = renderer.read_view(kit::View::Position, true);
  f.normal = renderer.read_view(kit::View::Normal, true);
  f.albedo = renderer.read_view(kit::View::Albedo, true);
  f.material = renderer.read_view(kit::View::Material, true);
  f.depth = renderer.read_view(kit::View::Depth, true);
  f.final_image = renderer.read_view(kit::View::Final, true);
  return f;
}

kit::Camera camera_of(const kit::Scene& scene) { return scene.camera ? *scene.camera : kit::framing_camera(scene); }

// Pixels where any channel differs at all (bitwise comparison of the floats read back).
size_t differing_pixels(const Image& a, const Image& b) {
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_EQ(a.channels, b.channels);
  if (a.pixels.size() != b.pixels.size()) return static_cast<size_t>(-1);
  size_t count = 0;
  const size_t channels = static_cast<size_t>(a.channels);
  for (size_t p = 0; p < a.pixels.size(); p += channels)
    if (std::memcmp(&a.pixels[p], &b.pixels[p], channels * sizeof(float)) != 0) ++count;
  return count;
}

TEST(MeshOptimize, GBufferOfOptimizedDefaultSceneMatches) {
  // Reordering can only change which of two fragments at exactly the same
  // depth wins; the default scene's meshes are convex or flat with back faces
  // culled, so no tie is expected, but a handful of pixels would still be a pass.
  constexpr size_t kMaxTiePixels = 16;
  const kit::Scene& original = kit::test::scene("default");
  kit::Scene optimized = original;
  kit::optimize_scene(optimized);
  const Frame a = render("gbuffer", original, camera_of(original));
  const Frame b = render("gbuffer", optimized, camera_of(original));
  const size_t position = differing_pixels(a.position, b.position);
  const size_t normal = differing_pixels(a.normal, b.normal);
  const size_t albedo = differing_pixels(a.albedo, b.albedo);
  const size_t material = differing_pixels(a.material, b.material);
  const size_t depth = differing_pixels(a.depth, b.depth);
  std::printf("optimised G-buffer: differing pixels of %d: position %zu, normal %zu, albedo %zu, material %zu, depth %zu\n",
              a.position.width * a.position.height, position, normal, albedo, material, depth);
  EXPECT_LE(position, kMaxTiePixels);
  EXPECT_LE(normal, kMaxTiePixels);
  EXPECT_LE(albedo, kMaxTiePixels);
  EXPECT_LE(material, kMaxTiePixels);
  EXPECT_LE(depth, kMaxTiePixels);
}

// ---- frustum culling ----

constexpr float kAspect = 4.0f / 3.0f;
constexpr float kFov = 0.8f;
constexpr float kNear = 0.1f, kFar = 100.0f;

// A camera at the origin looking down -z.
glm::mat4 test_view_projection() {
  return glm::perspective(kFov, kAspect, kNear, kFar) * glm::lookAt(glm::vec3(0.0f), glm::vec3(0, 0, -1), glm::vec3(0, 1, 0));
}

bool unit_box_visible(const glm::mat4& world) {
  return kit::intersects(kit::frustum_from(test_view_projection()), glm::vec3(-0.5f), glm::vec3(0.5f), world);
}

glm::mat4 at(float x, float y, float z) { return glm::translate(glm::mat4(1.0f), glm::vec3(x, y, z)); }

TEST(MeshOptimizeFrustum, PlanesAreNormalisedAndPointInwards) {
  const kit::Frustum f = kit::frustum_from(test_view_projection());
  const glm::vec3 inside(0, 0, -5);
  for (const glm::vec4& p : f.planes) {
    EXPECT_NEAR(glm::length(glm::vec3(p)), 1.0f, 1e-5f);
    EXPECT_GT(glm::dot(glm::vec3(p), inside) + p.w, 0.0f);
  }
  // Near plane (index 4): z = -near, facing -z; its distance is in world units.
  EXPECT_NEAR(glm::dot(glm::vec3(f.planes[4]), glm::vec3(0, 0, -1)) + f.planes[4].w, 1.0f - kNear, 1e-4f);
}

TEST(MeshOptimizeFrustum, CullsOnlyBoxesWhollyOutside) {
  // Half width of the view at 5 m: 5 * tan(fov / 2) * aspect, about 2.82 m.
  EXPECT_TRUE(unit_box_visible(at(0, 0, -5)));      // in front
  EXPECT_FALSE(unit_box_visible(at(0, 0, 5)));      // behind the camera
  EXPECT_TRUE(unit_box_visible(at(0, 0, -0.1f)));   // straddles the near plane (and the eye)
  EXPECT_TRUE(unit_box_visible(at(-3.0f, 0, -5)));  // partly past the left edge
  EXPECT_FALSE(unit_box_visible(at(-5.0f, 0, -5)));  // wholly left of the view
  EXPECT_FALSE(unit_box_visible(at(0, 6.0f, -5)));   // wholly above
  EXPECT_TRUE(unit_box_visible(at(0, 0, -kFar)));    // straddles the far plane
  EXPECT_FALSE(unit_box_visible(at(0, 0, -kFar - 1.0f)));  // beyond it

  // A 10 m rod along local z, turned to lie along x, centred 7 m left: its
  // right end reaches x = -2, inside the view. The untransformed box would be culled.
  const glm::mat4 rod = at(-7.0f, 0, -5) * glm::rotate(glm::mat4(1.0f), glm::half_pi<float>(), glm::vec3(0, 1, 0));
  const kit::Frustum f = kit::frustum_from(test_view_projection());
  EXPECT_TRUE(kit::intersects(f, glm::vec3(-0.05f, -0.05f, -5.0f), glm::vec3(0.05f, 0.05f, 5.0f), rod));
  EXPECT_FALSE(kit::intersects(f, glm::vec3(-0.05f, -0.05f, -5.0f), glm::vec3(0.05f, 0.05f, 5.0f), at(-7.0f, 0, -5)));
}

TEST(MeshOptimizeFrustum, NeverCullsABoxWithAPointInsideTheView) {
  // Random boxes under random rotations, non-uniform scales and translations:
  // whenever a sample point of the box is inside the clip volume the test must keep it.
  constexpr int kBoxes = 4000;
  constexpr int kSamplesPerAxis = 5;
  const glm::mat4 vp = test_view_projection();
  const kit::Frustum f = kit::frustum_from(vp);
  std::mt19937 rng(12345);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  int culled = 0, kept_visible = 0;
  for (int b = 0; b < kBoxes; ++b) {
    const glm::vec3 lo(unit(rng), unit(rng), unit(rng));
    const glm::vec3 hi = lo + glm::abs(glm::vec3(unit(rng), unit(rng), unit(rng))) * 2.0f;
    glm::mat4 world = at(8.0f * unit(rng), 8.0f * unit(rng), -6.0f + 8.0f * unit(rng));
    world = glm::rotate(world, 3.14159f * unit(rng), glm::normalize(glm::vec3(unit(rng), unit(rng), unit(rng)) + 1e-3f));
    world = glm::scale(world, glm::vec3(1.5f) + 1.2f * glm::vec3(unit(rng), unit(rng), unit(rng)));
    bool any_inside = false;
    for (int i = 0; i < kSamplesPerAxis && !any_inside; ++i)
      for (int j = 0; j < kSamplesPerAxis && !any_inside; ++j)
        for (int k = 0; k < kSamplesPerAxis && !any_inside; ++k) {
          const glm::vec3 t = glm::vec3(i, j, k) / static_cast<float>(kSamplesPerAxis - 1);
          const glm::vec4 clip = vp * world * glm::vec4(glm::mix(lo, hi, t), 1.0f);
          any_inside = clip.w > 0.0f && std::fabs(clip.x) <= clip.w && std::fabs(clip.y) <= clip.w &&
                       std::fabs(clip.z) <= clip.w;
        }
    const bool kept = kit::intersects(f, lo, hi, world);
    if (any_inside) {
      ASSERT_TRUE(kept) << "box " << b << " has a point in view but was culled";
      ++kept_visible;
    }
    if (!kept) ++culled;
  }
  // Both outcomes occur, so the check above is not vacuous.
  EXPECT_GT(culled, kBoxes / 10);
  EXPECT_GT(kept_visible, kBoxes / 10);
}

int culled_draws(const kit::Scene& scene, const kit::Camera& camera, const kit::RenderSettings& settings) {
  const kit::FrameCamera fc =
      kit::frame_camera(camera, static_cast<float>(settings.width) / static_cast<float>(settings.height));
  const kit::Frustum f = kit::frustum_from(fc.projection * fc.view);
  int culled = 0;
  for (const kit::DrawItem& d : scene.draws) {
    const Primitive& p = scene.primitives[static_cast<size_t>(d.primitive)];
    if (!kit::intersects(f, p.bounds_min, p.bounds_max, d.world)) ++culled;
  }
  return culled;
}

void expect_identical(const Frame& a, const Frame& b) {
  EXPECT_EQ(differing_pixels(a.position, b.position), 0u);
  EXPECT_EQ(differing_pixels(a.normal, b.normal), 0u);
  EXPECT_EQ(differing_pixels(a.albedo, b.albedo), 0u);
  EXPECT_EQ(differing_pixels(a.material, b.material), 0u);
  EXPECT_EQ(differing_pixels(a.depth, b.depth), 0u);
  EXPECT_EQ(differing_pixels(a.final_image, b.final_image), 0u);
}

TEST(MeshOptimizeFrustum, CullingLeavesTheDefaultSceneRenderBitwiseUnchanged) {
  const kit::Scene& scene = kit::test::scene("default");
  const std::string last_stage = kit::stages().back().name;  // every pass, so the final image covers them all
  kit::RenderSettings off, on;
  on.frustum_culling = true;
  const kit::Camera camera = camera_of(scene);
  std::printf("default camera: %d of %zu draws culled\n", culled_draws(scene, camera, on), scene.draws.size());
  expect_identical(render(last_stage, scene, camera, off), render(last_stage, scene, camera, on));

  // A close view of the right-hand sphere, where most draws are outside the view.
  kit::Camera close = camera;
  close.position = glm::vec3(3.0f, 0.8f, 1.5f);
  close.view = glm::lookAt(close.position, glm::vec3(3.2f, 0.5f, -1.0f), glm::vec3(0, 1, 0));
  close.yfov = 0.6f;
  const int culled = culled_draws(scene, close, on);
  std::printf("close camera: %d of %zu draws culled\n", culled, scene.draws.size());
  EXPECT_GT(culled, 0);
  expect_identical(render(last_stage, scene, close, off), render(last_stage, scene, close, on));
}

}  // namespace

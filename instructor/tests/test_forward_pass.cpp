// The forward pass (common/render/forward_pass.*): glTF BLEND materials drawn after the
// lighting pass, back to front, and laid over the deferred result with the over
// operator, checked at known pixels against the blend equation evaluated on the CPU
// in double (the CPU reference's shade() of each surface, found by casting the
// pixel's ray); and the viewer's light markers.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "render/forward_pass.h"
#include "gbuffer_layout.h"
#include "reference_frames.h"
#include "tiny_scenes.h"

namespace {

using kit::reference::dvec3;
using kit::test::Frame;

// The HDR target is RGBA16F, which llvmpipe truncates (up to 2^-10 relative), and
// both G-buffers hold RGBA16F positions, while the CPU casts exact rays: measured
// 1.2e-3 to 1.5e-3 here, so 3e-3; the witnesses below are off by 0.29 and more.
constexpr double kBlendRelativeTolerance = 3e-3;

// Base colours and alphas exactly representable in the RGBA8 albedo attachment.
constexpr double k8(int value) { return value / 255.0; }

kit::Material blend_material(glm::dvec3 rgb, double alpha) {
  kit::Material m = kit::test::plain_material(0.5f);
  m.name = "blend";
  m.base_color_factor = glm::vec4(glm::vec3(rgb), static_cast<float>(alpha));
  m.alpha_mode = KIT_ALPHA_BLEND;
  return m;
}

// One camera for every test: at (0, 0, 3) looking at the origin.
kit::FrameCamera test_camera() {
  return kit::test::look_at_camera({0.0f, 0.0f, 3.0f}, {0.0f, 0.0f, 0.0f}, 0.8f, kit::test::small_settings());
}

// Where pixel (x, y) (top row first) sees the plane z = plane_z, in double.
dvec3 hit_on_plane(const kit::FrameCamera& camera, int x, int y, double plane_z) {
  const glm::dmat4 inverse = glm::inverse(glm::dmat4(camera.projection) * glm::dmat4(camera.view));
  const double ndc_x = (x + 0.5) / kit::test::kSmallWidth * 2.0 - 1.0;
  const double ndc_y = 1.0 - (y + 0.5) / kit::test::kSmallHeight * 2.0;
  glm::dvec4 near = inverse * glm::dvec4(ndc_x, ndc_y, -1.0, 1.0), far = inverse * glm::dvec4(ndc_x, ndc_y, 1.0, 1.0);
  const dvec3 a = dvec3(near) / near.w, b = dvec3(far) / far.w;
  const double t = (plane_z - a.z) / (b.z - a.z);
  return a + t * (b - a);
}

// The CPU reference's radiance of a surface facing +z at `p` in `material`.
dvec3 shade_plane(const kit::FrameCamera& camera, const dvec3& p, const kit::Material& material,
                  const std::vector<kit::Light>& lights, int stage) {
  kit::reference::SurfaceSample s;
  s.position = p;
  s.normal = dvec3(0.0, 0.0, 1.0);
  s.albedo = dvec3(material.base_color_factor);
  s.metallic = material.metallic_factor;
  s.roughness = material.roughness_factor;
  s.covered = true;
  const auto settings = kit::reference::shading_settings(kit::test::small_settings(), stage);
  return kit::reference::shade(s, dvec3(camera.position), lights, settings);
}

double relative_error(const dvec3& got, const dvec3& want) {
  const double scale = std::max({std::fabs(want.x), std::fabs(want.y), std::fabs(want.z), 1e-3});
  return std::max({std::fabs(got.x - want.x), std::fabs(got.y - want.y), std::fabs(got.z - want.z)}) / scale;
}

// An opaque white 4 x 4 quad at z = 0 and BLEND quads in front of it (each a
// 1.2 x 1.2 quad at (0, 0, z)), lit by one point light in front.
struct BlendScene {
  kit::Scene scene;
  std::vector<kit::Material> materials;  // [0] the opaque one, then the BLEND ones in scene order
  std::vector<double> depths;            // z of each BLEND quad, in scene order
};

BlendScene blend_scene(const std::vector<std::pair<kit::Material, double>>& layers) {
  BlendScene out;
  kit::Primitive back = kit::test::quad_primitive({1, 0, 0}, {0, 1, 0}, {4, 4});
  back.material = 0;
  std::vector<kit::Primitive> primitives = {back};
  out.materials = {kit::test::plain_material(0.6f)};
  std::vector<kit::DrawItem> draws = {{0, glm::mat4(1.0f)}};
  for (const auto& [material, z] : layers) {
    kit::Primitive quad = kit::test::quad_primitive({1, 0, 0}, {0, 1, 0}, {1.2f, 1.2f});
    quad.material = static_cast<int>(out.materials.size());
    out.materials.push_back(material);
    out.depths.push_back(z);
    primitives.push_back(quad);
    glm::mat4 world(1.0f);
    world[3] = glm::vec4(0.0f, 0.0f, static_cast<float>(z), 1.0f);
    draws.push_back({static_cast<int>(primitives.size() - 1), world});
  }
  out.scene = kit::test::tiny_scene(primitives, out.materials, draws, {kit::test::point_light({0.4f, 0.6f, 2.0f}, 2.0f)});
  return out;
}

// The pixels well inside every BLEND quad's image (the quads' centres project to the
// image centre; +-12 pixels stay inside the nearest-smallest one).
std::vector<std::pair<int, int>> inner_pixels() {
  std::vector<std::pair<int, int>> out;
  for (int y = kit::test::kSmallHeight / 2 - 12; y <= kit::test::kSmallHeight / 2 + 12; y += 4)
    for (int x = kit::test::kSmallWidth / 2 - 12; x <= kit::test::kSmallWidth / 2 + 12; x += 4) out.emplace_back(x, y);
  return out;
}

// The over operator applied by the CPU to the layers in `order` (indices into the
// BLEND layers), from the opaque surface up.
dvec3 expected_radiance(const BlendScene& s, const kit::FrameCamera& camera, int x, int y, const std::vector<size_t>& order,
                        int stage) {
  dvec3 radiance = shade_plane(camera, hit_on_plane(camera, x, y, 0.0), s.materials[0], s.scene.lights, stage);
  for (size_t layer : order) {
    const kit::Material& m = s.materials[layer + 1];
    const double a = m.base_color_factor.a;
    const dvec3 lit = shade_plane(camera, hit_on_plane(camera, x, y, s.depths[layer]), m, s.scene.lights, stage);
    radiance = a * lit + (1.0 - a) * radiance;
  }
  return radiance;
}

Frame render(const kit::Scene& scene, const std::string& stage, bool light_markers = false) {
  kit::RenderSettings settings = kit::test::small_settings();
  settings.light_markers = light_markers;
  auto renderer = kit::test::make_renderer(stage, scene, settings);
  return kit::test::render_frame(*renderer, test_camera());
}

}  // namespace

// One BLEND quad over an opaque one: L = a L_blend + (1 - a) L_opaque at stages 2
// and 3. Witness: drawn as OPAQUE (the G-buffer's one surface a pixel, the kit before
// the forward pass) the same pixels are the BLEND surface's own radiance, far off.
TEST(ForwardPass, BlendQuadOverOpaqueMatchesTheOverOperator) {
  const kit::Material blend = blend_material({k8(230), k8(102), k8(77)}, k8(102));
  const BlendScene s = blend_scene({{blend, 0.5}});
  BlendScene as_opaque = s;
  as_opaque.scene.materials[1].alpha_mode = KIT_ALPHA_OPAQUE;
  for (const std::string stage : {"lighting", "attenuation"}) {
    const int number = stage == "lighting" ? 2 : 3;
    const Frame frame = render(s.scene, stage);
    const Frame naive = render(as_opaque.scene, stage);
    double worst = 0.0, naive_best = INFINITY;
    for (const auto& [x, y] : inner_pixels()) {
      const dvec3 want = expected_radiance(s, frame.camera, x, y, {0}, number);
      worst = std::max(worst, relative_error(kit::test::pixel_rgb(frame.hdr, x, y), want));
      naive_best = std::min(naive_best, relative_error(kit::test::pixel_rgb(naive.hdr, x, y), want));
    }
    std::printf("%s: largest error %.2e of the over operator; drawn opaque, at least %.2e\n", stage.c_str(), worst,
                naive_best);
    EXPECT_LT(worst, kBlendRelativeTolerance) << stage;
    EXPECT_GT(naive_best, 10.0 * kBlendRelativeTolerance) << stage << ": the witness should be far off";
    // The G-buffer holds the opaque surface behind the BLEND one (albedo 0.8 grey, z = 0).
    const int cx = kit::test::kSmallWidth / 2, cy = kit::test::kSmallHeight / 2;
    EXPECT_NEAR(frame.gbuffer.albedo.at(cx, cy, 0), 0.8, 2.0 / 255.0);
    EXPECT_NEAR(frame.gbuffer.position.at(cx, cy, 2), 0.0, 1e-3);
  }
}

// Stage 1 has no lighting pass and so no forward pass: its G-buffer shows a BLEND
// surface like an opaque one, with its alpha in albedo.a (what lab 1 is graded on).
TEST(ForwardPass, StageOneKeepsBlendSurfacesInTheGBuffer) {
  const BlendScene s = blend_scene({{blend_material({k8(230), k8(102), k8(77)}, k8(102)), 0.5}});
  auto renderer = kit::test::make_renderer("gbuffer", s.scene, kit::test::small_settings());
  renderer->render(test_camera());
  const kit::reference::GBufferImages gbuffer = kit::reference::read_gbuffer(*renderer);
  const int cx = kit::test::kSmallWidth / 2, cy = kit::test::kSmallHeight / 2;
  EXPECT_NEAR(gbuffer.albedo.at(cx, cy, 0), k8(230), 0.5 / 255.0);
  EXPECT_NEAR(gbuffer.albedo.at(cx, cy, 3), k8(102), 0.5 / 255.0);
  EXPECT_NEAR(gbuffer.position.at(cx, cy, 2), 0.5, 1e-3);
}

// Two BLEND quads listed near one first: the forward pass sorts them back to front.
// Witness: the over operator applied in the scene's order (near first) is far off.
TEST(ForwardPass, BlendLayersAreDrawnBackToFront) {
  const kit::Material near = blend_material({k8(26), k8(204), k8(51)}, k8(153));
  const kit::Material far = blend_material({k8(230), k8(51), k8(26)}, k8(128));
  const BlendScene s = blend_scene({{near, 0.9}, {far, 0.45}});
  EXPECT_EQ(kit::blend_draws_back_to_front(s.scene, test_camera().view), (std::vector<size_t>{2, 1}));
  const Frame frame = render(s.scene, "attenuation");
  double worst = 0.0, unsorted_best = INFINITY;
  for (const auto& [x, y] : inner_pixels()) {
    const dvec3 got = kit::test::pixel_rgb(frame.hdr, x, y);
    worst = std::max(worst, relative_error(got, expected_radiance(s, frame.camera, x, y, {1, 0}, 3)));
    unsorted_best = std::min(unsorted_best, relative_error(got, expected_radiance(s, frame.camera, x, y, {0, 1}, 3)));
  }
  std::printf("largest error %.2e back to front; in the scene's order, at least %.2e\n", worst, unsorted_best);
  EXPECT_LT(worst, kBlendRelativeTolerance);
  EXPECT_GT(unsorted_best, 10.0 * kBlendRelativeTolerance);
}

// A BLEND quad behind the opaque one is hidden by it (the layer is depth-tested
// against the opaque depth): the pixels are the opaque surface's radiance alone.
// Witness: the same quad in front changes them.
TEST(ForwardPass, BlendLayerBehindAnOpaqueSurfaceIsHidden) {
  const kit::Material blend = blend_material({k8(230), k8(102), k8(77)}, k8(102));
  const BlendScene behind = blend_scene({{blend, -0.5}});
  const Frame frame = render(behind.scene, "attenuation");
  const Frame in_front = render(blend_scene({{blend, 0.5}}).scene, "attenuation");
  double worst = 0.0, moved = INFINITY;
  for (const auto& [x, y] : inner_pixels()) {
    const dvec3 opaque = expected_radiance(behind, frame.camera, x, y, {}, 3);
    worst = std::max(worst, relative_error(kit::test::pixel_rgb(frame.hdr, x, y), opaque));
    moved = std::min(moved, relative_error(kit::test::pixel_rgb(in_front.hdr, x, y), opaque));
  }
  EXPECT_LT(worst, kBlendRelativeTolerance);
  EXPECT_GT(moved, 10.0 * kBlendRelativeTolerance);
}

// Light markers: a point light in front of the opaque quad shows kit's marker
// radiance at its image position; one behind the quad is hidden. Without markers the
// same pixel is the lit surface.
TEST(ForwardPass, LightMarkersShowInFrontAndHideBehindSurfaces) {
  BlendScene s = blend_scene({});
  kit::Light in_front = kit::test::point_light({0.0f, 0.0f, 1.0f}, 2.0f);
  in_front.color = glm::vec3(1.0f, 0.5f, 0.25f);
  const kit::Light behind = kit::test::point_light({-1.0f, 0.0f, -1.0f}, 2.0f);
  s.scene.lights = {in_front, behind};
  const Frame with = render(s.scene, "attenuation", true);
  const Frame without = render(s.scene, "attenuation", false);
  const int cx = kit::test::kSmallWidth / 2, cy = kit::test::kSmallHeight / 2;
  const dvec3 marker = dvec3(kit::light_marker_radiance(in_front));
  EXPECT_LT(relative_error(kit::test::pixel_rgb(with.hdr, cx, cy), marker), 1e-3);
  EXPECT_GT(relative_error(kit::test::pixel_rgb(without.hdr, cx, cy), marker), 0.1);
  // The light behind the quad projects left of the centre: there the image is unchanged.
  const glm::dvec4 clip = glm::dmat4(with.camera.projection) * glm::dmat4(with.camera.view) * glm::dvec4(-1, 0, -1, 1);
  const int bx = static_cast<int>((clip.x / clip.w * 0.5 + 0.5) * kit::test::kSmallWidth);
  EXPECT_EQ(kit::test::pixel_rgb(with.hdr, bx, cy), kit::test::pixel_rgb(without.hdr, bx, cy));
}

// The pixels a box can cover: inside the view a rectangle around its projection;
// across the camera's plane no bound (nullopt); wholly outside the view, empty.
TEST(ForwardPass, ProjectedRectBoundsTheBox) {
  const kit::FrameCamera camera = test_camera();
  const glm::mat4 view_projection = camera.projection * camera.view;
  const int w = kit::test::kSmallWidth, h = kit::test::kSmallHeight;
  const auto centre = kit::projected_rect({-0.1f, -0.1f, 0.0f}, {0.1f, 0.1f, 0.0f}, glm::mat4(1.0f), view_projection, w, h);
  ASSERT_TRUE(centre.has_value());
  EXPECT_LE(centre->x, w / 2);
  EXPECT_GE(centre->x + centre->width, w / 2);
  EXPECT_LT(centre->width, w / 4);
  EXPECT_FALSE(kit::projected_rect({-1, -1, 2.5f}, {1, 1, 3.5f}, glm::mat4(1.0f), view_projection, w, h).has_value());
  const auto outside = kit::projected_rect({50, 0, 0}, {51, 1, 1}, glm::mat4(1.0f), view_projection, w, h);
  ASSERT_TRUE(outside.has_value());
  EXPECT_EQ(outside->width, 0);
}

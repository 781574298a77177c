// Each light's share of a reference frame (tools/grade/frames/light_shares.h): what a failed lit
// check's worst pixel says of the lights there.
//   - hand-made frames with obvious answers: the encoding, the order, the rounding;
//   - the stored shares of lab 3's default scene against the CPU reference in double, light by
//     light, on the stored G-buffer: independent of the solutions' shaders;
//   - witness: on lab 7's 128 lights the nearest light (what a description named first before)
//     is not the one that gives the most at two thirds of the lit pixels; the description now
//     names that one first.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "cpu_reference.h"
#include "frames/checks.h"
#include "frames/light_shares.h"
#include "gbuffer_layout.h"
#include "kit_test.h"
#include "render/stages.h"
#include "verdict/lab_verdict.h"

namespace {

namespace fs = std::filesystem;
namespace ref = kit::reference;
using kit::Image;
using kit::grade::light_shares_at;
using kit::grade::light_shares_image;
using kit::grade::PixelLightShares;

fs::path references() { return kit::kit_root() / "tools/grade/references"; }

Image flat(int width, int height, float value) {
  Image image(width, height, 4);
  for (size_t i = 0; i < image.pixels.size(); ++i) image.pixels[i] = (i % 4 == 3) ? 1.0f : value;
  return image;
}

void add(Image& image, int x, int y, float rgb) {
  for (int c = 0; c < 3; ++c) image.at(x, y, c) += rgb;
}

double luminance(const ref::dvec3& c) { return ref::KIT_LUMINANCE[0] * c.x + ref::KIT_LUMINANCE[1] * c.y + ref::KIT_LUMINANCE[2] * c.z; }

// Grey frames: each light adds a known grey on top of a constant emission.
TEST(LightShares, HandMadeFramesGiveTheirShares) {
  const Image none = flat(3, 1, 0.1f);
  std::vector<Image> alone(5, none);
  add(alone[0], 0, 0, 0.3f);  // pixel 0: lights 1 and 2 give 3 : 1, light 3 nothing
  add(alone[1], 0, 0, 0.1f);
  for (Image& light : alone) add(light, 1, 0, 0.25f);  // pixel 1: five equal lights
  add(alone[2], 2, 0, -1e-3f);                          // pixel 2: below the frame without: none
  const Image shares = light_shares_image(alone, none);

  PixelLightShares p = light_shares_at(shares, 0, 0);
  EXPECT_NEAR(p.luminance, 0.4, 0.4 / 128.0);
  ASSERT_EQ(p.lights.size(), 2u);
  EXPECT_EQ(p.lights[0].light, 0);
  EXPECT_NEAR(p.lights[0].share, 0.75, 1.0 / 512.0);
  EXPECT_EQ(p.lights[1].light, 1);
  EXPECT_NEAR(p.lights[1].share, 0.25, 1.0 / 512.0);

  // Three named of five: the first three in the scene's order, a fifth each.
  p = light_shares_at(shares, 1, 0);
  EXPECT_NEAR(p.luminance, 1.25, 1.25 / 128.0);
  ASSERT_EQ(p.lights.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(p.lights[static_cast<size_t>(k)].light, k);
    EXPECT_NEAR(p.lights[static_cast<size_t>(k)].share, 0.2, 1.0 / 512.0);
  }

  p = light_shares_at(shares, 2, 0);
  EXPECT_EQ(p.luminance, 0.0);
  EXPECT_TRUE(p.lights.empty());
  // A single light gives all of it: its share is 1, not the next light's number.
  const Image one = light_shares_image({alone[0]}, none);
  p = light_shares_at(one, 0, 0);
  ASSERT_EQ(p.lights.size(), 1u);
  EXPECT_EQ(p.lights[0].light, 0);
  EXPECT_EQ(p.lights[0].share, 1.0);
  // Outside the image: nothing.
  EXPECT_TRUE(light_shares_at(one, 3, 0).lights.empty());
}

// With the shares, the lights that give the most lead with their shares; the others follow,
// "none" where every light that gives some is named, "under 1 %" where the named give all of it.
TEST(LightShares, DescriptionNamesTheLightsByTheirShares) {
  kit::Scene scene;
  for (float x : {1.0f, 2.0f, 3.0f, 4.0f}) {
    kit::Light light;
    light.type = KIT_LIGHT_POINT;
    light.position = {x, 0.0f, 0.0f};
    scene.lights.push_back(light);
  }
  kit::grade::PixelInputs in;
  in.has_light_shares = true;
  in.light_shares.luminance = 0.5;
  in.light_shares.lights = {{2, 0.75}, {3, 0.25}};
  std::string text = kit::grade::describe_pixel_inputs(in, scene);
  EXPECT_NE(text.find("the lights give it luminance 0.5 in the reference; light 3 (point, no range)"), std::string::npos)
      << text;
  EXPECT_NE(text.find("3 m, 75 % of it; light 4 "), std::string::npos) << text;
  EXPECT_NE(text.find("4 m, 25 % of it; light 1 "), std::string::npos) << text;
  EXPECT_NE(text.find("1 m, none; light 2 "), std::string::npos) << text;
  in.light_shares.lights = {{2, 0.5}, {3, 0.25}, {0, 0.25}};
  text = kit::grade::describe_pixel_inputs(in, scene);
  EXPECT_NE(text.find("2 m, under 1 %"), std::string::npos) << text;
  in.light_shares = {};
  text = kit::grade::describe_pixel_inputs(in, scene);
  EXPECT_NE(text.find("no light reaches it in the reference; light 1 "), std::string::npos) << text;
  // Without them (a reference kept without its shares), as before: no share named.
  in.has_light_shares = false;
  text = kit::grade::describe_pixel_inputs(in, scene);
  EXPECT_EQ(text.find("% of it"), std::string::npos) << text;
  EXPECT_EQ(text.find("in the reference"), std::string::npos) << text;
}

// The stored shares of lab 3's default scene (four lights, a spot among them) against the CPU
// reference evaluated light by light on the stored G-buffer of the same frame.
TEST(LightShares, ReferenceSharesAgreeWithTheCpuReference) {
  const kit::grade::RenderSpec& spec = kit::grade::find_render("lab3-default-physical-hdr");
  const std::string id = kit::grade::light_shares_id(spec);
  ASSERT_EQ(id, "lab3-default-physical-lights");
  const Image shares = kit::read_image((references() / (id + ".exr")).string());
  ref::GBufferImages g;
  g.position = kit::read_image((references() / "lab1-default-position.exr").string());
  g.normal = kit::read_image((references() / "lab1-default-normal.exr").string());
  g.albedo = kit::read_image((references() / "lab1-default-albedo.exr").string());
  g.material = kit::read_image((references() / "lab1-default-material.exr").string());
  g.emission = kit::read_image((references() / "lab1-default-emission.exr").string());
  const kit::Scene scene = kit::load_scene(kit::resolve_scene(spec.scene));
  const kit::RenderSettings render = kit::grade::render_settings(spec);
  const ref::ShadingSettings settings = ref::shading_settings(render, spec.stage);
  const std::vector<ref::ShadingLight> lights = ref::uploaded_lights(ref::frame_lights(scene, render));
  ASSERT_EQ(lights.size(), 4u);
  const kit::Camera camera = scene.camera ? *scene.camera : kit::framing_camera(scene);
  const kit::FrameCamera frame =
      kit::frame_camera(camera, static_cast<float>(render.width) / static_cast<float>(render.height));
  const ref::dvec3 eye(frame.position);

  size_t compared = 0, luminance_off = 0, light_off = 0, shared_by_two = 0;
  for (const auto& [x, y] : ref::covered_pixels(g)) {
    const ref::SurfaceSample surface = ref::gbuffer_sample(g, x, y);
    const ref::dvec3 base = ref::shade(surface, eye, std::vector<ref::ShadingLight>{}, settings);
    std::vector<double> own;
    double sum = 0.0;
    for (const ref::ShadingLight& light : lights) {
      own.push_back(std::max(luminance(ref::shade(surface, eye, std::vector<ref::ShadingLight>{light}, settings) - base), 0.0));
      sum += own.back();
    }
    const PixelLightShares stored = light_shares_at(shares, x, y);
    ++compared;
    // 7 significant bits stored, the HDR target's half floats under each light: 1.5 %.
    if (!(std::abs(stored.luminance - sum) <= 0.015 * sum + 1e-4)) ++luminance_off;
    if (sum <= 1e-4) continue;
    const auto most = std::max_element(own.begin(), own.end()) - own.begin();
    if (own[static_cast<size_t>(most)] / sum >= 0.6) {
      if (stored.lights.empty() || stored.lights[0].light != most ||
          std::abs(stored.lights[0].share - own[static_cast<size_t>(most)] / sum) > 0.01)
        ++light_off;
    } else {
      ++shared_by_two;
    }
  }
  std::printf("[ shares ] %zu pixels of lab 3's default scene: %zu with another summed luminance than the CPU "
              "reference's, %zu with another light most (of those where one gives 60 %%), %zu lit by several\n",
              compared, luminance_off, light_off, shared_by_two);
  EXPECT_GT(compared, 20000u);
  EXPECT_GT(shared_by_two, 1000u);  // the scene shares its light: the test is not about one light
  // Edges, where a texel's neighbours are other surfaces, may differ: at most 0.5 %.
  EXPECT_LE(static_cast<double>(luminance_off), 0.005 * static_cast<double>(compared));
  EXPECT_LE(static_cast<double>(light_off), 0.005 * static_cast<double>(compared));
}

// Lab 7's 128 lights: the nearest light is often not the one that gives a pixel the most (the
// dim directional light counts as nearest; where no small light's range reaches, the nearest
// point light gives nothing). A description naming the nearest first named the wrong one there;
// with the shares it names the right one first.
TEST(LightShares, OnLab7TheLightThatGivesMostIsOftenNotTheNearest) {
  const kit::grade::RenderSpec& spec = kit::grade::find_render("lab7-lights-hdr");
  const Image shares = kit::read_image((references() / (kit::grade::light_shares_id(spec) + ".exr")).string());
  const Image position = kit::read_image((references() / "lab1-lights-position.exr").string());
  const Image material = kit::read_image((references() / "lab1-lights-material.exr").string());
  const kit::Scene scene = kit::load_scene(kit::resolve_scene(spec.scene));
  ASSERT_EQ(scene.lights.size(), 129u);  // and a dim directional light
  size_t lit = 0, nearest_not_most = 0, nearest_point_not_most = 0;
  int wx = -1, wy = -1, most = -1;
  for (int y = 0; y < shares.height; ++y)
    for (int x = 0; x < shares.width; ++x) {
      const PixelLightShares p = light_shares_at(shares, x, y);
      if (material.at(x, y, 3) < 0.5f || p.lights.empty() || p.lights[0].share < 0.6) continue;
      ++lit;
      const glm::vec3 at(position.at(x, y, 0), position.at(x, y, 1), position.at(x, y, 2));
      // As the description ordered them without shares: a directional light counts as nearest.
      const auto distance = [&](size_t i) {
        return scene.lights[i].type == KIT_LIGHT_DIRECTIONAL ? 0.0f : glm::length(scene.lights[i].position - at);
      };
      size_t nearest = 0;
      for (size_t i = 1; i < scene.lights.size(); ++i)
        if (distance(i) < distance(nearest)) nearest = i;
      size_t nearest_point = 0;  // the nearest of the point lights alone, for the record
      for (size_t i = 0; i < scene.lights.size(); ++i)
        if (scene.lights[i].type != KIT_LIGHT_DIRECTIONAL &&
            (scene.lights[nearest_point].type == KIT_LIGHT_DIRECTIONAL ||
             glm::length(scene.lights[i].position - at) < glm::length(scene.lights[nearest_point].position - at)))
          nearest_point = i;
      if (static_cast<int>(nearest_point) != p.lights[0].light) ++nearest_point_not_most;
      if (static_cast<int>(nearest) != p.lights[0].light) {
        ++nearest_not_most;
        if (wx < 0) wx = x, wy = y, most = p.lights[0].light;
      }
    }
  std::printf("[ shares ] lab 7's 128 lights: the nearest light is not the one giving 60 %% or more at %zu of %zu "
              "pixels (the nearest point light is not at %zu)\n", nearest_not_most, lit, nearest_point_not_most);
  ASSERT_GT(nearest_not_most, lit / 20) << "witness: the nearest light would have done";
  // The description at such a pixel names the light that gives the most first.
  kit::grade::PixelInputs in;
  in.position = glm::vec3(position.at(wx, wy, 0), position.at(wx, wy, 1), position.at(wx, wy, 2));
  in.has_light_shares = true;
  in.light_shares = light_shares_at(shares, wx, wy);
  const std::string text = kit::grade::describe_pixel_inputs(in, scene);
  const std::string first = "; light " + std::to_string(most + 1) + " (";
  ASSERT_NE(text.find("the lights give it luminance"), std::string::npos) << text;
  EXPECT_EQ(text.find("; light "), text.find(first)) << text;
  EXPECT_NE(text.find(" % of it"), std::string::npos) << text;
}

}  // namespace

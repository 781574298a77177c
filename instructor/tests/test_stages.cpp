// Every stage of the lab sequence, end to end: the reference solutions render
// every kit scene with finite pixels and no GL error, each starter (labs/)
// compiles and visibly differs from its solution, stage 5 with post-processing
// off is stage 4 exactly, and rendering is deterministic.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "base/error.h"
#include "kit_test.h"
#include "kit_test_images.h"
#include "reference_frames.h"
#include "gl/gl_objects.h"
#include "render/renderer.h"
#include "render/stages.h"

namespace {

constexpr int kWidth = kit::test::kSmallWidth;
constexpr int kHeight = kit::test::kSmallHeight;
const char* const kScenes[] = {"default", "sphere", "grazing", "normalmap"};

using kit::test::small_settings;

// ---- the solutions on every scene ----

// One solution render: no GL error, no NaN or Inf in the final image or (lit stages) HDR.
void expect_finite_render(const kit::Stage& stage, const std::string& scene) {
  auto renderer = kit::test::render_stage(stage.name, scene, small_settings());
  ASSERT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
  kit::Image final_image = renderer->read_view(kit::View::Final, true);
  ASSERT_EQ(final_image.width, kWidth);
  ASSERT_EQ(final_image.height, kHeight);
  EXPECT_EQ(kit::count_non_finite(final_image), 0u);
  if (stage.lighting) {
    EXPECT_EQ(kit::count_non_finite(renderer->read_view(kit::View::Hdr, true)), 0u);
  }
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

// ctest runs each suite of this file as one test, test_stages.<suite>, in a process of its
// own (cmake/gtest_suites.cmake), so `ctest -R stages` selects them all. Stages and scenes
// are loops in one test, each case named by its SCOPED_TRACE when it fails.
TEST(StagesSolutions, EveryStageRendersEverySceneFinite) {
  for (const kit::Stage& stage : kit::stages()) {
    for (const char* scene : kScenes) {
      SCOPED_TRACE("stage " + stage.name + ", scene " + scene);
      expect_finite_render(stage, scene);
    }
  }
}

// ---- the starters ----

// The scene where each step's missing work shows most: lab 4 only changes normal-mapped
// surfaces, which fill most of the normalmap scene.
std::string scene_showing(const kit::Stage& stage) { return stage.name == "normalmap" ? "normalmap" : "default"; }

// Mean absolute difference of the colour channels over the pixels where `coverage`
// (the G-buffer material view) has a surface: the background is the clear colour in
// every image and would only dilute the measure.
double mean_difference_on_surfaces(const kit::Image& a, const kit::Image& b, const kit::Image& coverage) {
  constexpr int kColorChannels = 3;
  double sum = 0.0;
  size_t covered = 0;
  for (int y = 0; y < a.height; ++y) {
    for (int x = 0; x < a.width; ++x) {
      if (coverage.at(x, y, 3) < 0.5f) continue;
      ++covered;
      for (int c = 0; c < kColorChannels; ++c) sum += std::fabs(static_cast<double>(a.at(x, y, c)) - b.at(x, y, c));
    }
  }
  return covered ? sum / static_cast<double>(covered * kColorChannels) : 0.0;
}

// Starters are compared at twice the size: at 160 x 120 mipmapping averages the brick
// normal map's narrow bevels away, and lab 4's missing work with them.
constexpr int kStarterWidth = 2 * kWidth, kStarterHeight = 2 * kHeight;

// The starter of `stage` (labs/) builds and its final image is clearly not the solution's.
void expect_starter_differs(const kit::Stage& stage) {
  // Mean absolute difference of the final images, channels in [0, 1]: a clear margin
  // above what a rounding difference could give (< 1/255).
  constexpr double kMinMeanDifference = 0.01;
  const std::string scene = scene_showing(stage);
  std::unique_ptr<kit::Renderer> starter;
  try {
    starter = kit::test::render_stage(stage.name, scene, small_settings(kStarterWidth, kStarterHeight),
                                      kit::kit_root() / "labs");
  } catch (const kit::Error& e) {
    FAIL() << "the starter of " << stage.folder << " does not build: " << e.what();
  }
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
  kit::Image starter_image = starter->read_view(kit::View::Final, true);
  auto solution = kit::test::render_stage(stage.name, scene, small_settings(kStarterWidth, kStarterHeight));
  kit::Image solution_image = solution->read_view(kit::View::Final, true);
  ASSERT_EQ(starter_image.width, solution_image.width);
  ASSERT_EQ(starter_image.height, solution_image.height);
  double difference =
      mean_difference_on_surfaces(starter_image, solution_image, solution->read_view(kit::View::Material, true));
  EXPECT_GT(difference, kMinMeanDifference) << stage.folder << " on " << scene;
}

TEST(StagesStarters, EachCompilesAndDiffersFromItsSolution) {
  for (const kit::Stage& stage : kit::stages()) {
    SCOPED_TRACE(stage.folder);
    expect_starter_differs(stage);
  }
}

// ---- stage 5 against stage 4 ----

TEST(StagesPostprocess, OffIsStage4ExactlyAndOnIsNot) {
  // With the toggle off, bloom and the custom effect pass the image through untouched.
  kit::RenderSettings off = small_settings();
  off.postprocess = false;
  kit::Image stage4 = kit::test::render_stage("normalmap", "default", small_settings())->read_view(kit::View::Final, true);
  kit::Image stage5_off = kit::test::render_stage("postprocess", "default", off)->read_view(kit::View::Final, true);
  EXPECT_EQ(kit::test::first_difference(stage4, stage5_off), "");

  // The default scene has emitters and highlights above the bloom threshold: bloom adds light.
  constexpr double kMinBloomDifference = 1e-3;
  kit::Image stage5_on = kit::test::render_stage("postprocess", "default", small_settings())->read_view(kit::View::Final, true);
  EXPECT_NE(kit::test::first_difference(stage4, stage5_on), "");
  double difference = kit::test::mean_abs_difference(stage4, stage5_on);
  EXPECT_GT(difference, kMinBloomDifference);
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

// ---- determinism ----

TEST(StagesDeterminism, TwoRendersAreBitwiseIdentical) {
  for (const kit::View view : {kit::View::Final, kit::View::Hdr, kit::View::Position, kit::View::Normal}) {
    SCOPED_TRACE(kit::view_name(view));
    kit::Image first = kit::test::render_stage("postprocess", "default", small_settings())->read_view(view, true);
    kit::Image second = kit::test::render_stage("postprocess", "default", small_settings())->read_view(view, true);
    EXPECT_EQ(kit::test::first_difference(first, second), "");
  }
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

// ---- programs shared between Renderers (the grader's render worker) ----

// Renderers that build their programs through one LinkedProgramCache share the GL programs,
// uniform values included. The witness: a value set through one Program is what the other
// reads. Each Renderer sets every uniform before it draws with it, so two scenes with other
// cameras and lights, drawn in turn and back again, give the images each gives with programs
// of its own (a Renderer that set its camera only in its first frame fails here).
TEST(StagesSharedPrograms, RenderersInTurnDrawWhatEachDrawsAlone) {
  kit::test::context();
  const kit::Stage& stage = kit::find_stage("attenuation");
  kit::LinkedProgramCache cache;
  auto library = [&](bool shared) {
    kit::ShaderLibrary l = kit::stage_library(stage, kit::kit_root() / "solutions");
    if (shared) l.share_programs_through(&cache);
    return l;
  };
  {
    kit::Program a(library(true), "fullscreen.vert", "debug_view.frag");
    kit::Program b(library(true), "fullscreen.vert", "debug_view.frag");
    ASSERT_EQ(a.id(), b.id());
    EXPECT_EQ(cache.reused(), 1);
    a.use();
    a.set("u_view_mode", 4);
    GLint seen = 0;
    glGetUniformiv(b.id(), b.location("u_view_mode"), &seen);
    EXPECT_EQ(seen, 4) << "the programs share uniform values";
  }
  const std::string scenes[] = {"range", "lights"};
  ASSERT_NE(kit::test::scene(scenes[0]).lights.size(), kit::test::scene(scenes[1]).lights.size());
  const kit::RenderSettings settings = small_settings();
  auto draw = [&](kit::Renderer& renderer, const std::string& name) {
    renderer.render(kit::test::scene_frame_camera(kit::test::scene(name), settings));
    return std::make_pair(renderer.read_view(kit::View::Hdr, true), renderer.read_view(kit::View::Final, true));
  };
  std::pair<kit::Image, kit::Image> alone[2];
  for (int i = 0; i < 2; ++i) {
    kit::Renderer renderer(stage, library(false), kit::test::scene(scenes[i]), settings);
    alone[i] = draw(renderer, scenes[i]);
  }
  const int reused_before = cache.reused();
  kit::Renderer first(stage, library(true), kit::test::scene(scenes[0]), settings);
  kit::Renderer second(stage, library(true), kit::test::scene(scenes[1]), settings);
  EXPECT_GT(cache.reused(), reused_before) << "the second Renderer built every program again";
  for (int i : {0, 1, 0, 1}) {
    SCOPED_TRACE(scenes[i]);
    const auto drawn = draw(i == 0 ? first : second, scenes[i]);
    EXPECT_EQ(kit::test::first_difference(drawn.first, alone[i].first), "");
    EXPECT_EQ(kit::test::first_difference(drawn.second, alone[i].second), "");
  }
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

// ---- programs specialised to the frame (RenderSettings::specialise_shaders) ----

// The grader draws with one lighting and one geometry program per lab instead of one per
// scene's lights and materials: the same image, bit for bit, on scenes of spot lights, of a
// sun, of lights with a range, under either attenuation model, with the light volumes, and
// on the texturing scene's materials (a second UV set, transforms, MASK). The witness that
// the setting changes the programs: with specialisation, a Renderer per scene builds
// lighting and geometry programs of its own; without, they share them.
TEST(StagesSpecialisedShaders, SameImageWithOrWithout) {
  kit::test::context();
  const std::string scenes[] = {"spot", "sun", "range", "lights", "texturing"};
  for (const char* stage_name : {"attenuation", "lightvolumes"}) {
    const kit::Stage& stage = kit::find_stage(stage_name);
    int reused[2] = {0, 0};
    for (bool specialise : {true, false}) {
      kit::LinkedProgramCache cache;
      std::vector<std::unique_ptr<kit::Renderer>> renderers;
      for (const std::string& name : scenes) {
        kit::ShaderLibrary library = kit::stage_library(stage, kit::kit_root() / "solutions");
        library.share_programs_through(&cache);
        kit::RenderSettings settings = small_settings();
        settings.specialise_shaders = specialise;
        renderers.push_back(std::make_unique<kit::Renderer>(stage, std::move(library), kit::test::scene(name), settings));
      }
      reused[specialise ? 1 : 0] = cache.reused();
    }
    EXPECT_GT(reused[0], reused[1]) << stage_name << ": the scenes' programs differ without specialisation too";
    for (const std::string& name : scenes)
      for (int model : {0, 1}) {
        SCOPED_TRACE(std::string(stage_name) + ", " + name + ", attenuation model " + std::to_string(model));
        kit::Image hdr[2], final_image[2];
        for (bool specialise : {true, false}) {
          kit::RenderSettings settings = small_settings();
          settings.attenuation_model = model;
          settings.specialise_shaders = specialise;
          kit::Renderer renderer(stage, kit::stage_library(stage, kit::kit_root() / "solutions"), kit::test::scene(name),
                                 settings);
          renderer.render(kit::test::scene_frame_camera(kit::test::scene(name), settings));
          hdr[specialise] = renderer.read_view(kit::View::Hdr, true);
          final_image[specialise] = renderer.read_view(kit::View::Final, true);
        }
        EXPECT_EQ(kit::test::first_difference(hdr[0], hdr[1]), "");
        EXPECT_EQ(kit::test::first_difference(final_image[0], final_image[1]), "");
      }
  }
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

// ---- post-processing alone drawn again (Renderer::render_reusing_lit_frame) ----

// A frame whose camera and lit-pass settings are the last frame's runs only the post
// passes, and gives the image a whole frame gives, bit for bit: under another bloom
// threshold, gamma, blur count, with post-processing off and with the custom effect on.
// A change the lit passes read (the attenuation model, the camera) draws the whole
// frame. The witness that the uniform check matters: an attenuation.glsl that reads
// u_gamma lights another HDR image under gamma 1.0, and there the frame is drawn whole.
TEST(StagesLitFrameReuse, PostSettingsAloneRunThePostPassesAgain) {
  kit::test::context();
  const kit::Stage& stage = kit::find_stage("postprocess");
  const kit::Scene& scene = kit::test::scene("default");
  const kit::RenderSettings base = small_settings();
  const kit::FrameCamera camera = kit::test::scene_frame_camera(scene, base);
  auto whole = [&](kit::ShaderLibrary library, const kit::RenderSettings& settings, const kit::FrameCamera& at) {
    kit::Renderer fresh(stage, std::move(library), scene, settings);
    fresh.render(at);
    return std::make_pair(fresh.read_view(kit::View::Hdr, true), fresh.read_view(kit::View::Final, true));
  };
  auto solutions = [&] { return kit::stage_library(stage, kit::kit_root() / "solutions"); };
  using Change = void (*)(kit::RenderSettings&);
  const std::pair<const char*, Change> post_only[] = {
      {"bloom_threshold", [](kit::RenderSettings& s) { s.bloom_threshold = 0.5f; }},
      {"gamma", [](kit::RenderSettings& s) { s.gamma = 1.0f; }},
      {"blur_passes", [](kit::RenderSettings& s) { s.blur_passes = 2; }},
      {"postprocess", [](kit::RenderSettings& s) { s.postprocess = false; }},
      {"custom_effect", [](kit::RenderSettings& s) { s.custom_effect = true; }},
  };
  kit::Renderer renderer(stage, solutions(), scene, base);
  EXPECT_FALSE(renderer.render_reusing_lit_frame(camera)) << "the first frame has nothing to reuse";
  for (const auto& [field, change] : post_only) {
    SCOPED_TRACE(field);
    kit::RenderSettings settings = base;
    change(settings);
    renderer.settings() = settings;
    EXPECT_TRUE(renderer.render_reusing_lit_frame(camera));
    const auto expected = whole(solutions(), settings, camera);
    EXPECT_EQ(kit::test::first_difference(renderer.read_view(kit::View::Final, true), expected.second), "");
  }
  kit::RenderSettings simple = base;
  simple.attenuation_model = 1;
  renderer.settings() = simple;
  EXPECT_FALSE(renderer.render_reusing_lit_frame(camera)) << "the attenuation model changes the lit passes";
  EXPECT_EQ(kit::test::first_difference(renderer.read_view(kit::View::Final, true), whole(solutions(), simple, camera).second), "");
  kit::FrameCamera moved = camera;
  moved.position.x += 0.5f;
  moved.view[3][0] -= 0.5f;
  EXPECT_FALSE(renderer.render_reusing_lit_frame(moved)) << "another camera";

  // An attenuation that reads u_gamma (a mistake a student could make): the lit frame
  // depends on gamma, so a gamma change draws it whole.
  const std::filesystem::path overlay = kit::test::temp_dir("lit-frame-reuse");
  std::ifstream in(kit::kit_root() / "solutions" / "03-attenuation" / "attenuation.glsl");
  std::string attenuation((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string last_return = "return light.color * intensity * kit_range_window(light, p);";
  ASSERT_NE(attenuation.find(last_return), std::string::npos);
  attenuation.replace(attenuation.find(last_return), last_return.size(),
                      "return light.color * intensity * kit_range_window(light, p) * (u_gamma / 2.2);");
  std::ofstream(overlay / "attenuation.glsl") << attenuation;
  auto reads_gamma = [&] {
    std::vector<kit::ShaderFolder> folders = solutions().folders();
    folders.insert(folders.begin(), kit::ShaderFolder{overlay, "overlay", {"attenuation.glsl"}});
    return kit::ShaderLibrary(std::move(folders));
  };
  kit::RenderSettings gamma1 = base;
  gamma1.gamma = 1.0f;
  const auto at_22 = whole(reads_gamma(), base, camera), at_10 = whole(reads_gamma(), gamma1, camera);
  ASSERT_NE(kit::test::first_difference(at_22.first, at_10.first), "") << "the lit frame does not depend on gamma";
  kit::Renderer reading(stage, reads_gamma(), scene, base);
  reading.render_reusing_lit_frame(camera);
  reading.settings() = gamma1;
  EXPECT_FALSE(reading.render_reusing_lit_frame(camera)) << "a lit pass reads u_gamma";
  EXPECT_EQ(kit::test::first_difference(reading.read_view(kit::View::Hdr, true), at_10.first), "");
  EXPECT_EQ(kit::test::first_difference(reading.read_view(kit::View::Final, true), at_10.second), "");
  EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
}

// The viewer renders a frame again only when same_image_settings says the settings
// changed (tools/view/viewer_frame.cpp): every field that changes the image must count, and
// only the size and u_time (which the viewer compares or animates itself) and
// specialise_shaders (which does not change it) may not.
TEST(StagesSettings, EveryFieldThatChangesTheImageCounts) {
  const kit::RenderSettings base;
  EXPECT_TRUE(kit::same_image_settings(base, base));
  kit::RenderSettings ignored = base;
  ignored.width += 1;
  ignored.height += 1;
  ignored.time += 1.0f;
  ignored.specialise_shaders = !ignored.specialise_shaders;  // the same image (StagesSpecialisedShaders)
  EXPECT_TRUE(kit::same_image_settings(base, ignored)) << "the size and u_time are the viewer's to compare";

  using Change = void (*)(kit::RenderSettings&);
  const std::pair<const char*, Change> changes[] = {
      {"gamma", [](kit::RenderSettings& s) { s.gamma += 0.5f; }},
      {"attenuation_model", [](kit::RenderSettings& s) { s.attenuation_model = 1 - s.attenuation_model; }},
      {"postprocess", [](kit::RenderSettings& s) { s.postprocess = !s.postprocess; }},
      {"custom_effect", [](kit::RenderSettings& s) { s.custom_effect = !s.custom_effect; }},
      {"bloom_threshold", [](kit::RenderSettings& s) { s.bloom_threshold += 0.5f; }},
      {"blur_passes", [](kit::RenderSettings& s) { s.blur_passes += 2; }},
      {"clear_color", [](kit::RenderSettings& s) { s.clear_color.g += 0.1f; }},
      {"extra_lights", [](kit::RenderSettings& s) { s.extra_lights += 1; }},
      {"frustum_culling", [](kit::RenderSettings& s) { s.frustum_culling = !s.frustum_culling; }},
      {"texture_compression", [](kit::RenderSettings& s) { s.texture_compression = kit::TextureCompression::On; }},
      {"default_light_rig", [](kit::RenderSettings& s) { s.default_light_rig = !s.default_light_rig; }},
      {"light_markers", [](kit::RenderSettings& s) { s.light_markers = !s.light_markers; }},
      {"environment", [](kit::RenderSettings& s) { s.environment = "sun"; }},
      {"ibl.prefilter_samples", [](kit::RenderSettings& s) { s.ibl.prefilter_samples *= 2; }},
      {"ibl.refuse_non_finite", [](kit::RenderSettings& s) { s.ibl.refuse_non_finite = !s.ibl.refuse_non_finite; }},
  };
  for (const auto& [field, change] : changes) {
    kit::RenderSettings changed = base;
    change(changed);
    EXPECT_FALSE(kit::same_image_settings(base, changed)) << field << " changed, and the settings still compare equal";
  }
}

}  // namespace

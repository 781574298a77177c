// Lab 6, image-based lighting, against the integral it approximates
// (instructor/reference/ibl_reference.h), and its failure cases.
//
// Accuracy is measured in two parts, at known pixels and texels:
//  * the GPU's error: the lab's maps and image against the split sum evaluated in
//    double (brdf_table, irradiance, prefiltered_radiance, split_sum_radiance);
//  * the split sum's own error: split_sum_radiance against the integral itself
//    (reflected_radiance_integral, Monte Carlo with a 5-standard-error bound).
// Both are printed; the note of the issue quotes them.
//
// Each failure case has a witness: a copy of the solutions (or of one framework
// module) with the guarded line swapped for the naive one, shown to break on the
// test's environment, and the kit's line shown not to.
#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include "base/error.h"
#include "gbuffer_layout.h"
#include "render/ibl.h"
#include "base/no_dangling.h"
#include "ibl_reference.h"
#include "kit_test.h"
#include "kit_test_files.h"
#include "reference_frames.h"
#include "shader_variants.h"
#include "tiny_scenes.h"

namespace kit::test {
namespace {

namespace ref = kit::reference;
using ref::dvec2;
using ref::dvec3;

KIT_NO_DANGLING const Image& environment(const std::string& name) {
  static std::map<std::string, Image> loaded;
  auto it = loaded.find(name);
  if (it == loaded.end()) it = loaded.emplace(name, load_environment(resolve_environment(name))).first;
  return it->second;
}

RenderSettings ibl_settings(const std::string& environment_name) {
  RenderSettings settings = small_settings();
  settings.environment = environment_name;
  settings.default_light_rig = false;
  return settings;
}

// A scene as the kit generated it, without its lights: the image is the environment's
// light alone (plus L_e, which the comparisons subtract).
Scene unlit(const std::string& name) {
  Scene s = scene(name);
  s.lights.clear();
  return s;
}

// The sphere scene without its light, kept for the whole run (renderers refer to their scene).
const Scene& unlit_sphere() {
  static const Scene s = unlit("sphere");
  return s;
}

double max3(dvec3 v) { return std::max(v.x, std::max(v.y, v.z)); }
dvec3 rgb(const Image& image, int x, int y) { return pixel_rgb(image, x, y); }

using ref::relative_error;

// Image coordinates (u, v) of a texel centre of a W x H equirectangular image (rows top-down).
dvec2 texel_uv(int x, int y, int width, int height) { return {(x + 0.5) / width, (y + 0.5) / height}; }

std::unique_ptr<Renderer> ibl_renderer(const Scene& s, const RenderSettings& settings) {
  auto renderer = make_renderer("ibl", s, settings);
  renderer->render(scene_frame_camera(s, settings));
  return renderer;
}

std::unique_ptr<Renderer> ibl_variant(const Scene& s, const RenderSettings& settings, const std::string& name,
                                      const std::vector<LineSwap>& swaps) {
  auto renderer = make_renderer("ibl", s, settings, full_root_library(find_stage("ibl"), variant_root(name, swaps)));
  renderer->render(scene_frame_camera(s, settings));
  return renderer;
}

// The solutions' stage 6 and a variant of them (`swaps` applied), both rendered under
// `environment_name` on the unlit sphere scene.
struct KitAndNaive {
  std::unique_ptr<Renderer> kit, naive;
};
// `refuse_non_finite` off lets a variant's NaN reach the maps and the frame (IblSettings).
KitAndNaive kit_and_naive(const std::string& environment_name, const std::string& variant_name,
                          const std::vector<LineSwap>& swaps, bool refuse_non_finite = true) {
  const Scene& s = unlit_sphere();
  RenderSettings naive_settings = ibl_settings(environment_name);
  naive_settings.ibl.refuse_non_finite = refuse_non_finite;
  return {ibl_renderer(s, ibl_settings(environment_name)), ibl_variant(s, naive_settings, variant_name, swaps)};
}

// The BRDF table without its n.v guards (GrazingViewInTheBrdfTable): the n.v = 0 column is 0/0.
const std::vector<LineSwap>& table_without_n_dot_v_guards() {
  static const std::vector<LineSwap> swaps = {
      {"06-ibl/brdf_lut.frag", "float n_dot_v = max(kit_brdf_lut_grid_value(v_uv.x), KIT_MIN_N_DOT_V);",
       "float n_dot_v = kit_brdf_lut_grid_value(v_uv.x);"},
      {"06-ibl/brdf_lut.frag", "float weight = g * v_dot_h / max(n_dot_h * n_dot_v, KIT_MIN_DENOMINATOR);",
       "float weight = g * v_dot_h / (n_dot_h * n_dot_v);"}};
  return swaps;
}

// Level `level` of the prefiltered map out of View::Prefiltered's stack.
Image prefiltered_level(const Image& stack, int level) {
  int top = 0, width = stack.width, height = stack.width / 2;
  for (int k = 0; k < level; ++k) {
    top += height;
    width = std::max(width / 2, 1);
    height = std::max(height / 2, 1);
  }
  Image out(width, height, 4);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x)
      for (int c = 0; c < 4; ++c) out.at(x, y, c) = stack.at(x, top + y, c);
  return out;
}

double level_roughness(int level) { return static_cast<double>(level) / (KIT_PREFILTER_LEVELS - 1); }

// The largest relative error of a prefiltered level against prefiltered_radiance, over
// a grid of texels (every `step`-th in each direction).
double prefiltered_level_error(const Image& level_image, const Image& env, int level, int step) {
  double worst = 0.0;
  for (int y = step / 2; y < level_image.height; y += step)
    for (int x = step / 2; x < level_image.width; x += step) {
      const dvec2 uv = texel_uv(x, y, level_image.width, level_image.height);
      const dvec3 expected = ref::prefiltered_radiance(env, ref::equirect_direction(uv.x, uv.y), level_roughness(level));
      const double e = relative_error(rgb(level_image, x, y), expected, 0.05);
      if (e > worst && std::getenv("KIT_IBL_DEBUG"))
        std::printf("  level %d texel %d,%d: gpu %.4f %.4f %.4f cpu %.4f %.4f %.4f\n", level, x, y, rgb(level_image, x, y).x,
                    rgb(level_image, x, y).y, rgb(level_image, x, y).z, expected.x, expected.y, expected.z);
      worst = std::max(worst, e);
    }
  return worst;
}

// ---------------------------------------------------------------------------
// The maps against the split sum's factors in double.

TEST(Ibl, BrdfTableMatchesTheQuadrature) {
  auto renderer = ibl_renderer(unlit_sphere(), ibl_settings("studio"));
  const Image table = renderer->read_view(View::BrdfLut, true);
  ASSERT_EQ(table.width, KIT_BRDF_LUT_SIZE);
  double worst = 0.0;
  for (int j = 0; j < KIT_BRDF_LUT_SIZE; j += 3)
    for (int i = 0; i < KIT_BRDF_LUT_SIZE; i += 3) {
      const double n_dot_v = std::max(i / double(KIT_BRDF_LUT_SIZE - 1), ref::KIT_MIN_N_DOT_V);
      const double roughness = j / double(KIT_BRDF_LUT_SIZE - 1);
      // Grid row j (GL row j from the bottom) is image row N - 1 - j.
      const dvec3 gpu = rgb(table, i, KIT_BRDF_LUT_SIZE - 1 - j);
      worst = std::max(worst, max3(glm::abs(gpu - ref::brdf_table(n_dot_v, roughness))));
    }
  std::printf("[ ibl ] BRDF table (%d samples a texel) against the quadrature: largest error %.2e\n",
              IblSettings{}.brdf_lut_samples, worst);
  // 512 Hammersley points: the largest error sits where the specular estimator's
  // weight G (v.h) / ((n.h)(n.v)) varies most, at grazing n.v and low roughness
  // (measured 0.028).
  EXPECT_LT(worst, 0.04);
}

TEST(Ibl, IrradianceMapMatchesTheIntegral) {
  for (const char* name : {"studio", "sun"}) {
    auto renderer = ibl_renderer(unlit_sphere(), ibl_settings(name));
    const Image map = renderer->read_view(View::Irradiance, true);
    const ref::IrradianceIntegral irradiance(environment(name));
    double worst = 0.0;
    for (int y = 0; y < map.height; ++y)
      for (int x = 0; x < map.width; x += 3) {
        const dvec2 uv = texel_uv(x, y, map.width, map.height);
        const dvec3 expected = irradiance(ref::equirect_direction(uv.x, uv.y));
        worst = std::max(worst, relative_error(rgb(map, x, y), expected, 0.05));
      }
    std::printf("[ ibl ] irradiance map (%s) against the integral: largest relative error %.2e\n", name, worst);
    // The sum runs over a 128 x 64 level of the environment, a box filter of level 0:
    // the sun moves by up to half its texel, which matters where n.l is small
    // (measured: 0.12 % under studio, 2.2 % under sun).
    EXPECT_LT(worst, std::string(name) == "sun" ? 0.1 : 0.02) << name;
  }
}

TEST(Ibl, PrefilteredLevelsMatchTheIntegral) {
  for (const char* name : {"studio", "sun"}) {
    auto renderer = ibl_renderer(unlit_sphere(), ibl_settings(name));
    const Image stack = renderer->read_view(View::Prefiltered, true);
    for (int level = 1; level < KIT_PREFILTER_LEVELS; ++level) {
      const Image level_image = prefiltered_level(stack, level);
      const double worst = prefiltered_level_error(level_image, environment(name), level, std::max(level_image.width / 8, 1));
      std::printf("[ ibl ] prefiltered level %d (roughness %.1f, %s) against the integral: largest relative error %.2e\n",
                  level, level_roughness(level), name, worst);
      // Filtered importance sampling trades variance for blur (reading one mip level
      // above the sample's footprint, Colbert and Krivanek's bias): light from bright
      // regions spreads into dark ones, most at the rough levels, and most of all
      // around the sun (measured up to 32 % under studio, 96 % under sun at roughness 1).
      EXPECT_LT(worst, std::string(name) == "sun" ? 1.2 : 0.4) << name << " level " << level;
    }
  }
}

// ---------------------------------------------------------------------------
// The lab's image against the split sum (the GPU's error) and the integral (the
// split sum's own error), at sampled covered pixels of the default scene.

struct ImageErrors {
  double gpu_vs_split_sum = 0.0, split_sum_vs_integral = 0.0, gpu_vs_integral = 0.0;
  int pixels = 0;
};

ImageErrors compare_with_integral(const std::string& scene_name, const std::string& env_name, int integral_samples) {
  const Scene s = unlit(scene_name);
  const RenderSettings settings = ibl_settings(env_name);
  const FrameCamera camera = scene_frame_camera(s, settings);
  auto renderer = make_renderer("ibl", s, settings);
  const Frame frame = render_frame(*renderer, camera);
  const Image& env = environment(env_name);
  ImageErrors e;
  const PixelList covered = covered_pixels(frame);
  const size_t stride = std::max<size_t>(covered.size() / 40, 1);
  for (size_t i = stride / 2; i < covered.size(); i += stride) {
    const auto [x, y] = covered[i];
    const ref::SurfaceSample sample = ref::gbuffer_sample(frame.gbuffer, x, y);
    const dvec3 gpu = rgb(frame.hdr, x, y) - sample.emission;
    const dvec3 split = ref::split_sum_radiance(env, sample, dvec3(camera.position));
    const ref::IntegralEstimate integral =
        ref::reflected_radiance_integral(env, sample, dvec3(camera.position), integral_samples, 1234u + i);
    if (std::getenv("KIT_IBL_DEBUG"))
      std::printf("  pixel %d,%d rough %.2f metal %.2f: gpu %.4f split %.4f integral %.4f +- %.4f\n", x, y,
                  sample.roughness, sample.metallic, gpu.y, split.y, integral.value.y, integral.standard_error.y);
    // Relative to the pixel's value, floored where it is dark (a tenth of the sky's radiance).
    const double floor = 0.02;
    e.gpu_vs_split_sum = std::max(e.gpu_vs_split_sum, relative_error(gpu, split, floor));
    e.split_sum_vs_integral = std::max(e.split_sum_vs_integral, relative_error(split, integral.value, floor));
    e.gpu_vs_integral = std::max(e.gpu_vs_integral, relative_error(gpu, integral.value, floor));
    // The Monte Carlo bound itself must be tight enough to measure these.
    EXPECT_LT(relative_error(integral.value + 5.0 * integral.standard_error, integral.value, floor), 0.06)
        << "pixel " << x << "," << y;
    ++e.pixels;
  }
  std::printf("[ ibl ] %s under %s, %d pixels: GPU vs split sum %.3f, split sum vs integral %.3f, GPU vs integral %.3f "
              "(largest relative errors)\n",
              scene_name.c_str(), env_name.c_str(), e.pixels, e.gpu_vs_split_sum, e.split_sum_vs_integral,
              e.gpu_vs_integral);
  return e;
}

TEST(Ibl, DefaultSceneAgainstTheIntegral) {
  for (const char* env : {"studio", "sun"}) {
    const bool sun = std::string(env) == "sun";
    const ImageErrors e = compare_with_integral("default", env, 65536);
    EXPECT_GT(e.pixels, 20);
    // The GPU's own error: the maps' sampling and resolution, bilinear lookups, fp16
    // (measured 0.06 under studio, 0.15 under sun, where the prefiltered map's blur
    // around the sun dominates).
    EXPECT_LT(e.gpu_vs_split_sum, sun ? 0.25 : 0.1) << env;
    // The split sum's own departures (handouts/06-ibl.md) add to it: measured 0.10 and
    // 0.24, the largest at grazing n.v and where the sun lies inside a lobe.
    EXPECT_LT(e.gpu_vs_integral, sun ? 0.6 : 0.25) << env;
  }
}

// White furnace: under a uniform environment the split sum is exact, so the image
// must equal the integral up to the GPU's own error.
TEST(Ibl, WhiteFurnaceIsExact) {
  const std::filesystem::path dir = temp_dir("ibl_furnace");
  Image uniform(64, 32, 3);
  std::fill(uniform.pixels.begin(), uniform.pixels.end(), 1.0f);
  write_image((dir / "uniform.exr").string(), uniform);
  environment((dir / "uniform.exr").string());
  const ImageErrors e = compare_with_integral("default", (dir / "uniform.exr").string(), 65536);
  EXPECT_LT(e.split_sum_vs_integral, 0.02);
  // What is left is the BRDF table's sampling error (up to 0.028, BrdfTableMatchesTheQuadrature).
  EXPECT_LT(e.gpu_vs_integral, 0.05);
}

// ---------------------------------------------------------------------------
// Failure cases.

// Fireflies: the sun (1.5 degrees, 3000 times the sky) hit by a few of the prefilter's
// GGX samples makes spikes and holes; reading the mip level chosen by each sample's PDF
// spreads it evenly.
TEST(IblStability, FirefliesFromTheSun) {
  const std::vector<LineSwap> level_zero = {
      {"06-ibl/prefilter.frag", "float level = max(0.5 * log2(sample_solid_angle / texel_solid_angle) + 1.0, 0.0);",
       "float level = 0.0;"}};
  auto [kit, naive] = kit_and_naive("sun", "ibl_fireflies", level_zero);
  const Image kit_stack = kit->read_view(View::Prefiltered, true), naive_stack = naive->read_view(View::Prefiltered, true);
  for (int level : {3}) {
    const Image k = prefiltered_level(kit_stack, level), n = prefiltered_level(naive_stack, level);
    const int step = std::max(k.width / 8, 1);
    const double kit_error = prefiltered_level_error(k, environment("sun"), level, step);
    const double naive_error = prefiltered_level_error(n, environment("sun"), level, step);
    std::printf("[ ibl ] fireflies, level %d: largest relative error %.2f with the PDF's mip level, %.2f reading level 0\n",
                level, kit_error, naive_error);
    EXPECT_GT(naive_error, 2.0 * kit_error) << "witness: level 0 alone makes fireflies";
    EXPECT_GT(naive_error, 1.0);
  }
}

// Roughness 0: alpha = 0 makes D (and so the PDF) 0 at the one half vector sampled,
// so the sample's solid angle, and the level read, become enormous: a mirror shows the
// environment's average. The roughness floor keeps the PDF finite.
TEST(IblStability, RoughnessZeroInThePrefilter) {
  const std::vector<LineSwap> no_floor = {
      {"06-ibl/prefilter.frag", "float alpha = max(u_roughness, KIT_MIN_ROUGHNESS) * max(u_roughness, KIT_MIN_ROUGHNESS);",
       "float alpha = u_roughness * u_roughness;"}};
  auto [kit, naive] = kit_and_naive("studio", "ibl_roughness_zero", no_floor);
  const Image& env = environment("studio");
  auto level0_error = [&](Renderer& r) {
    const Image level0 = prefiltered_level(r.read_view(View::Prefiltered, true), 0);
    double worst = 0.0;
    for (int y = 4; y < level0.height; y += 8)
      for (int x = 4; x < level0.width; x += 8) {
        const dvec2 uv = texel_uv(x, y, level0.width, level0.height);
        worst = std::max(worst, relative_error(rgb(level0, x, y), ref::environment_radiance_uv(env, uv), 0.05));
      }
    return worst;
  };
  const double kit_error = level0_error(*kit), naive_error = level0_error(*naive);
  std::printf("[ ibl ] roughness 0, level 0 against the environment: %.3f with the floor, %.3f without\n", kit_error,
              naive_error);
  EXPECT_GT(naive_error, 0.5) << "witness: a mirror shows the environment's average";
  EXPECT_LT(kit_error, 0.35);  // the floor's lobe and the map's half resolution
}

// n.v = 0 in the BRDF table: G = 0 and the estimator divides by n.v, 0/0 in the first column.
TEST(IblStability, GrazingViewInTheBrdfTable) {
  auto [kit, naive] = kit_and_naive("studio", "ibl_grazing_table", table_without_n_dot_v_guards(), false);
  const size_t kit_broken = count_non_finite(kit->read_view(View::BrdfLut, true));
  const size_t naive_broken = count_non_finite(naive->read_view(View::BrdfLut, true));
  std::printf("[ ibl ] n.v = 0: %zu non-finite table texels with the floor, %zu without\n", kit_broken, naive_broken);
  // How many of the column's texels come out NaN is the implementation's: Mesa 22's llvmpipe
  // gives half the column, Mesa 25's (LLVM 19) one texel. One is enough to break the frame.
  EXPECT_GE(naive_broken, 1u) << "witness: the n.v = 0 column is 0/0";
  EXPECT_EQ(kit_broken, 0u);
}

// A zero-length direction: normalising it is 0/0, and its angles NaN. kit_equirect_uv
// maps it to the pole (the GLSL guard KIT_MIN_DIRECTION_LENGTH_SQUARED); the CPU
// mirror does the same, and the naive formula shows what it prevents.
TEST(IblStability, ZeroLengthDirection) {
  const dvec3 zero(0.0);
  const dvec3 naive_unit = zero / glm::length(zero);
  EXPECT_TRUE(std::isnan(std::acos(std::clamp(naive_unit.y, -1.0, 1.0)))) << "witness: 0/0";
  const dvec2 uv = ref::equirect_uv(zero);
  EXPECT_TRUE(std::isfinite(uv.x) && std::isfinite(uv.y));
  EXPECT_TRUE(finite(ref::environment_radiance(environment("sun"), zero)));
}

// A NaN in a map hides in the frame: on llvmpipe ibl.frag's min(NaN, KIT_HDR_MAX) is
// KIT_HDR_MAX, so no view kit-render and the grader count (the HDR target among them)
// holds a non-finite pixel; the bloom spreads each such pixel into a white disc. The kit
// reads the maps back after the precompute and stops, naming the shader, map and texel.
TEST(IblStability, NanInAMapIsNamedNotHidden) {
  // Witness: the table without its n.v guards (0/0 in its first column), the check off,
  // at 320x240 (the handout's image), where the outline's n.v is below the table's first
  // step, 1/63, so lookups there blend that column in.
  RenderSettings settings = ibl_settings("sun");
  settings.width = 320;
  settings.height = 240;
  const auto kit = ibl_renderer(unlit_sphere(), settings);
  settings.ibl.refuse_non_finite = false;
  const auto naive = ibl_variant(unlit_sphere(), settings, "ibl_nan_unchecked", table_without_n_dot_v_guards());
  const size_t table_broken = count_non_finite(naive->read_view(View::BrdfLut, true));
  size_t frame_broken = 0;
  for (const NonFiniteCount& n : naive->non_finite_pixels()) frame_broken += n.pixels;
  // Where the NaN went: HDR pixels at KIT_HDR_MAX (65504), against the solution's.
  auto at_hdr_max = [](Renderer& r) {
    const Image hdr = r.read_view(View::Hdr, true);
    size_t count = 0;
    for (int y = 0; y < hdr.height; ++y)
      for (int x = 0; x < hdr.width; ++x) count += max3(rgb(hdr, x, y)) >= 65504.0 ? 1 : 0;
    return count;
  };
  const size_t naive_white = at_hdr_max(*naive), kit_white = at_hdr_max(*kit);
  std::printf("[ ibl ] NaN in the BRDF table: %zu non-finite texels in the table, %zu non-finite pixels in the frame's "
              "views, %zu HDR pixels at KIT_HDR_MAX (%zu with the solution's table)\n",
              table_broken, frame_broken, naive_white, kit_white);
  ASSERT_GE(table_broken, 1u) << "witness: the n.v = 0 column is 0/0 (one texel or half the column: GrazingViewInTheBrdfTable)";
  EXPECT_EQ(frame_broken, 0u) << "witness: the frame does not show the NaN as NaN";
  // Where the frame reads the NaN texels (Mesa 22's llvmpipe: half the n.v = 0 column),
  // min(NaN, KIT_HDR_MAX) shows them as KIT_HDR_MAX white; Mesa 25's one NaN texel, at
  // (0, 0), is read by no pixel: the frame hides it entirely. Either way only the check sees it.
  if (table_broken >= size_t(KIT_BRDF_LUT_SIZE / 2))
    EXPECT_GT(naive_white, kit_white) << "witness: min(NaN, KIT_HDR_MAX) gave KIT_HDR_MAX";
  else
    EXPECT_EQ(naive_white, kit_white) << "one NaN texel that no pixel reads";

  // The kit's check refuses the same shaders, naming the file, the map and the first texel.
  std::string message;
  try {
    ibl_variant(unlit_sphere(), ibl_settings("sun"), "ibl_nan_checked", table_without_n_dot_v_guards());
  } catch (const NonFiniteMapError& e) {
    message = e.what();
  }
  std::printf("[ ibl ] the check says: %s\n", message.c_str());
  EXPECT_NE(message.find("ibl_nan_checked/06-ibl/brdf_lut.frag wrote NaN into the BRDF table, texel (0, "),
            std::string::npos)
      << message;

  // What the read-back costs, on the solution's maps (32x16, 256x128 and 5 more levels, 64x64).
  const ImageBasedLighting& maps = *kit->image_based_lighting();
  std::printf("[ ibl ] reading the maps back for the check: %.1f ms (the precompute: %.1f ms)\n",
              maps.finite_check_seconds() * 1e3, maps.precompute_seconds() * 1e3);
  EXPECT_GT(maps.finite_check_seconds(), 0.0);
}

// ---------------------------------------------------------------------------
// The wrap seam: u = 0/1 is one meridian (phi = +-pi, looking along +Z).

// An equirectangular environment of two halves, radiance (4, 0.5, 0.25) where u < 0.5
// and (0.25, 0.5, 4) where u >= 0.5: the same step on the meridian u = 0.5 (looking
// along -Z) and across the wrap. Any map made from it must look alike across both.
const std::string& two_halves_environment() {
  static const std::string path = [] {
    const std::filesystem::path file = temp_dir("ibl_two_halves") / "two_halves.exr";
    Image image(64, 32, 3);
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x) {
        const bool first_half = x < image.width / 2;
        image.at(x, y, 0) = first_half ? 4.0f : 0.25f;
        image.at(x, y, 1) = 0.5f;
        image.at(x, y, 2) = first_half ? 0.25f : 4.0f;
      }
    write_image(file.string(), image);
    return file.string();
  }();
  return path;
}

// The largest jump (any channel, rows away from the poles) of an equirectangular map
// between columns x - 1 and x; x = 0 is across the wrap, from the last column to the first.
double column_jump(const Image& map, int x) {
  double worst = 0.0;
  for (int y = map.height / 4; y < map.height - map.height / 4; ++y)
    worst = std::max(worst, max3(glm::abs(rgb(map, x, y) - rgb(map, (x + map.width - 1) % map.width, y))));
  return worst;
}

// The largest relative error against prefiltered_radiance of columns x - 1 and x (rows as above).
double columns_error(const Image& map, const Image& env, int level, int x) {
  double worst = 0.0;
  for (int column : {(x + map.width - 1) % map.width, x})
    for (int y = map.height / 4; y < map.height - map.height / 4; ++y) {
      const dvec2 uv = texel_uv(column, y, map.width, map.height);
      const dvec3 expected = ref::prefiltered_radiance(env, ref::equirect_direction(uv.x, uv.y), level_roughness(level));
      worst = std::max(worst, relative_error(rgb(map, column, y), expected, 0.05));
    }
  return worst;
}

// The precompute. The rough levels of the prefiltered map read the environment's
// coarse levels (a sample's footprint), where a texel spans many degrees. Wrapping in u
// (GL_REPEAT, set_equirect_sampling) a lookup near u = 0/1 blends the two sides of the
// meridian, as a lookup anywhere else blends its neighbours. Naive: GL_CLAMP_TO_EDGE
// (Texture2D's default), which reads one side only. A sampler object on the
// environment's unit stands for the naive wrap mode (GL's sampler objects override a
// texture's own settings); the shaders are the solutions' in both.
TEST(IblStability, WrapSeamInThePrefilteredMap) {
  const std::string& env_path = two_halves_environment();
  const Image& env = environment(env_path);
  const RenderSettings settings = ibl_settings(env_path);
  auto kit = ibl_renderer(unlit_sphere(), settings);
  std::unique_ptr<Renderer> naive;
  {
    const Sampler clamped(GL_LINEAR_MIPMAP_LINEAR, GL_LINEAR, GL_CLAMP_TO_EDGE, GL_CLAMP_TO_EDGE);
    clamped.bind(KIT_UNIT_ENVIRONMENT);
    naive = ibl_renderer(unlit_sphere(), settings);
    Sampler::unbind(KIT_UNIT_ENVIRONMENT);
  }
  const Image kit_stack = kit->read_view(View::Prefiltered, true), naive_stack = naive->read_view(View::Prefiltered, true);
  double worst_ratio_of_errors = 0.0;
  for (int level = 2; level < KIT_PREFILTER_LEVELS; ++level) {
    const Image k = prefiltered_level(kit_stack, level), n = prefiltered_level(naive_stack, level);
    const int middle = k.width / 2;
    // The jump across the wrap against the jump across u = 0.5, the same step of the environment.
    const double kit_ratio = column_jump(k, 0) / column_jump(k, middle);
    const double naive_ratio = column_jump(n, 0) / column_jump(n, middle);
    const double kit_seam_error = columns_error(k, env, level, 0), kit_middle_error = columns_error(k, env, level, middle);
    const double naive_seam_error = columns_error(n, env, level, 0);
    std::printf("[ ibl ] wrap seam, prefiltered level %d (%dx%d): jump across the wrap / across u = 0.5: %.2f wrapping, "
                "%.2f clamped; error against the integral at the wrap %.3f wrapping (%.3f at u = 0.5), %.3f clamped\n",
                level, k.width, k.height, kit_ratio, naive_ratio, kit_seam_error, kit_middle_error, naive_seam_error);
    // Wrapping, the two steps look alike and the wrap is as accurate as u = 0.5.
    EXPECT_NEAR(kit_ratio, 1.0, 0.1) << "level " << level;
    EXPECT_LT(kit_seam_error, 1.5 * kit_middle_error + 0.005) << "level " << level;
    worst_ratio_of_errors = std::max(worst_ratio_of_errors, naive_seam_error / kit_seam_error);
  }
  // Clamped, the texels beside the wrap are several times further off (measured 2.6 to
  // 6.6 times over levels 2 to 5: 2 to 5 %). The steps still look alike: the lobes are
  // wider than the few degrees a clamped lookup gets wrong, so the error is spread out,
  // not a step of its own (the lookups' seam is WrapSeamInTheLookups').
  EXPECT_GT(worst_ratio_of_errors, 3.0) << "witness: clamped at u = 0/1, the maps are off beside phi = +-pi";
}

// An equirectangular environment smooth everywhere but changing fastest across the
// wrap: radiance (1 + 0.9 sin phi, 0.25 + 4 g, 1 - 0.9 sin phi), which at phi = +-pi
// falls by 0.9 a radian in red and rises as fast in blue, with a green stripe along
// the wrap, g = exp(-(d / 0.2)^2) at d radians from it, that the coarse levels blur away.
const std::string& sine_environment() {
  static const std::string path = [] {
    const std::filesystem::path file = temp_dir("ibl_sine") / "sine.exr";
    Image image(64, 32, 3);
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x) {
        const double phi = ((x + 0.5) / image.width - 0.5) * 2.0 * M_PI;
        image.at(x, y, 0) = static_cast<float>(1.0 + 0.9 * std::sin(phi));
        const double d = M_PI - std::abs(phi);
        image.at(x, y, 1) = static_cast<float>(0.25 + 4.0 * std::exp(-(d / 0.2) * (d / 0.2)));
        image.at(x, y, 2) = static_cast<float>(1.0 - 0.9 * std::sin(phi));
      }
    write_image(file.string(), image);
    return file.string();
  }();
  return path;
}

// The lookup directions of a covered pixel: n and r = reflect(-v, n).
std::pair<dvec3, dvec3> lookup_directions(const Frame& frame, int x, int y) {
  const ref::SurfaceSample sample = ref::gbuffer_sample(frame.gbuffer, x, y);
  const dvec3 n = glm::normalize(sample.normal), v = glm::normalize(dvec3(frame.camera.position) - sample.position);
  return {n, glm::reflect(-v, n)};
}

// Whether neighbouring pixels' lookups lie on either side of the wrap, phi = +-pi,
// looking along +Z: n's or r's x changes sign where z > 0.
bool straddles_wrap(const Frame& frame, int x, int y) {
  const auto [n0, r0] = lookup_directions(frame, x - 1, y);
  const auto [n1, r1] = lookup_directions(frame, x, y);
  auto across = [](dvec3 a, dvec3 b) { return a.z > 0.0 && b.z > 0.0 && (a.x < 0.0) != (b.x < 0.0); };
  return across(n0, n1) || across(r0, r1);
}

// The largest horizontal jump (any channel) of the HDR image between neighbouring
// pixels at the wrap (the pair whose lookups straddle it, and the pairs either side, the
// edges of a 2x2 quad holding it), against the largest between neighbours 3 to 16 pixels
// away, over the 21 middle rows of the sphere (42 pixels in radius); and the largest
// relative error against the exact split sum at both.
struct SeamJumps {
  double seam = 0.0, elsewhere = 0.0, seam_error = 0.0, elsewhere_error = 0.0;
};
SeamJumps seam_jumps(const Frame& frame, const Image& env) {
  SeamJumps j;
  const int cx = frame.hdr.width / 2, cy = frame.hdr.height / 2;
  for (int y = cy - 10; y <= cy + 10; ++y) {
    int wrap = -1;  // the pair (wrap - 1, wrap) straddling it
    for (int x = cx - 16; x <= cx + 16 && wrap < 0; ++x)
      if (straddles_wrap(frame, x, y)) wrap = x;
    EXPECT_GE(wrap, 0) << "row " << y << ": no lookup crosses the wrap";
    for (int x = cx - 16; x <= cx + 16; ++x) {
      const double jump = max3(glm::abs(rgb(frame.hdr, x, y) - rgb(frame.hdr, x - 1, y)));
      const bool seam = std::abs(x - wrap) <= 1;
      if (seam) j.seam = std::max(j.seam, jump);
      else if (std::abs(x - wrap) >= 3) j.elsewhere = std::max(j.elsewhere, jump);
      // Against the exact split sum (every other row, a few columns: tens of ms a pixel).
      if (y % 2 != 0 || !(seam || std::abs(x - wrap) == 6 || std::abs(x - wrap) == 12)) continue;
      const double error = relative_error(rgb(frame.hdr, x, y),
                                          ref::split_sum_radiance(env, ref::gbuffer_sample(frame.gbuffer, x, y),
                                                                  dvec3(frame.camera.position)),
                                          0.02);
      (seam ? j.seam_error : j.elsewhere_error) = std::max(seam ? j.seam_error : j.elsewhere_error, error);
    }
  }
  return j;
}

// The lookups. Two ways to get the wrap wrong, each against the kit's image:
//  * clamped: the irradiance and prefiltered maps sampled with GL_CLAMP_TO_EDGE in u
//    (sampler objects on their units) instead of GL_REPEAT: within half a texel of
//    u = 0/1 a lookup reads the edge column alone, so the image steps where the
//    lookups cross the wrap instead of blending across it;
//  * implicit level: texture() for the prefiltered map instead of kit_prefiltered_
//    radiance's textureLod: the 2x2 pixels straddling the wrap see u jump by about 1,
//    a derivative a whole texture wide, and read the coarsest level: a notch two
//    pixels wide. Only where the wrap runs inside a quad: on llvmpipe a wrap between
//    two quads (the centred camera's) leaves no trace, since no derivative spans it.
TEST(IblStability, WrapSeamInTheLookups) {
  const std::string& env_path = sine_environment();
  const Image& env = environment(env_path);
  const RenderSettings settings = ibl_settings(env_path);
  const Scene& s = unlit_sphere();
  // The sphere scene's own camera, at (0, 0, 4) looking along -Z at the unit sphere,
  // moved one pixel's width (at the sphere's front) to the left: its lookups cross +Z,
  // the wrap, in the image's middle, between two pixels of one 2x2 quad (centred, the
  // wrap would run between two quads, where no derivative spans it).
  const float pixel = 2.0f * 3.0f * std::tan(0.35f) / static_cast<float>(settings.height);
  const FrameCamera camera = look_at_camera({-pixel, 0.0f, 4.0f}, {-pixel, 0.0f, 0.0f}, 0.7f, settings);
  auto renderer = make_renderer("ibl", s, settings);
  const SeamJumps kit = seam_jumps(render_frame(*renderer, camera), env);

  SeamJumps clamped;
  {
    const Sampler irradiance(GL_LINEAR, GL_LINEAR, GL_CLAMP_TO_EDGE, GL_CLAMP_TO_EDGE);
    const Sampler prefiltered(GL_LINEAR_MIPMAP_LINEAR, GL_LINEAR, GL_CLAMP_TO_EDGE, GL_CLAMP_TO_EDGE);
    irradiance.bind(KIT_UNIT_IRRADIANCE);
    prefiltered.bind(KIT_UNIT_PREFILTERED);
    clamped = seam_jumps(render_frame(*renderer, camera), env);
    Sampler::unbind(KIT_UNIT_IRRADIANCE);
    Sampler::unbind(KIT_UNIT_PREFILTERED);
  }
  auto implicit_renderer = make_renderer(
      "ibl", s, settings,
      full_root_library(find_stage("ibl"),
                        variant_root("ibl_seam_implicit_level",
                                     {{"06-ibl/ibl.frag", "kit_prefiltered_radiance(reflect(-v, n), roughness)",
                                       "texture(u_prefiltered, kit_equirect_uv(reflect(-v, n))).rgb"}})));
  const SeamJumps implicit = seam_jumps(render_frame(*implicit_renderer, camera), env);

  for (const auto& [name, j] : {std::pair<const char*, const SeamJumps&>{"kit (wrapping, explicit level)", kit},
                                {"clamped at u = 0/1", clamped},
                                {"texture()'s implicit level", implicit}})
    std::printf("[ ibl ] wrap seam in the image, %s: jump across it %.4f, elsewhere at most %.4f (%.1f times); error "
                "against the split sum %.3f there, %.3f elsewhere\n",
                name, j.seam, j.elsewhere, j.seam / j.elsewhere, j.seam_error, j.elsewhere_error);
  EXPECT_LT(kit.seam, 1.5 * kit.elsewhere) << "the kit's lookups blend across the wrap";
  EXPECT_LT(kit.seam_error, 1.5 * kit.elsewhere_error + 0.01);
  EXPECT_GT(clamped.seam, 3.0 * clamped.elsewhere) << "witness: clamped lookups step at the wrap";
  EXPECT_GT(implicit.seam, 3.0 * implicit.elsewhere) << "witness: texture() reads the coarsest level at the wrap";
}

}  // namespace
}  // namespace kit::test

// kit-render on both headless backends: OSMesa and EGL (surfaceless Mesa here)
// must give bit-identical images, and bad command lines must fail with a clear
// message. EGL is required: if it cannot make a context the test fails.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include "kit_test.h"
#include "kit_test_images.h"

namespace fs = std::filesystem;

namespace {

const std::string kSize = "160x120";  // small: each kit-render run stays well under a second

// Single-quoted for the shell (the kit's paths hold no quote characters).
std::string shell_quoted(const std::string& s) { return "'" + s + "'"; }

// Runs kit-render with `args`; returns its exit status, its output in *output.
int kit_render(const std::string& args, std::string* output) {
  std::string program = kit::test::tool("kit-render");
  if (!fs::exists(program)) {
    *output = program + " is not built";
    return -1;
  }
  return kit::test::run(shell_quoted(program) + " " + args, output);
}

// The images both backends write, by file name, and the arguments that make them.
struct Job {
  std::string stage;
  std::vector<std::pair<std::string, std::string>> outputs;  // view, file name
};
const Job kJobs[] = {
    {"gbuffer", {{"position", "position.exr"}, {"normal", "normal.png"}}},
    {"postprocess", {{"final", "final.png"}, {"hdr", "hdr.exr"}}},
};

// Renders every job with `backend` into dir/backend/; fails the test with kit-render's message.
fs::path render_with(const std::string& backend, const fs::path& dir) {
  fs::path out = dir / backend;
  fs::create_directories(out);
  for (const Job& job : kJobs) {
    std::string args = "--solution --stage " + job.stage + " --scene default --size " + kSize + " --backend " + backend + " --timings";
    for (const auto& [view, file] : job.outputs) args += " --view " + view + " --out " + shell_quoted((out / file).string());
    std::string output;
    int status = kit_render(args, &output);
    EXPECT_EQ(status, 0) << "kit-render --backend " << backend << " failed:\n" << output;
    // --timings names the context that rendered: the backend flag was honoured.
    EXPECT_NE(output.find("(" + backend + ": "), std::string::npos) << output;
  }
  return out;
}

// Largest minus smallest value over the image's first three channels.
float value_range(const kit::Image& image) {
  float lo = image.pixels.empty() ? 0.0f : image.pixels[0], hi = lo;
  for (size_t i = 0; i < image.pixels.size(); ++i) {
    if (static_cast<int>(i % static_cast<size_t>(image.channels)) >= 3) continue;
    lo = std::min(lo, image.pixels[i]);
    hi = std::max(hi, image.pixels[i]);
  }
  return hi - lo;
}

// With OSMesa in the build, both backends write the same bytes. Without it (Mesa 25.1 and
// later; -DKIT_OSMESA=OFF, as instructor/tests/no_osmesa_test.sh builds), --backend osmesa is refused
// by name and EGL, the default, renders.
TEST(Backends, OsmesaAndEglImagesAreBitIdenticalOrOsmesaIsRefused) {
  fs::path dir = kit::test::temp_dir("backends/identical");
  if (!kit::has_osmesa()) {
    std::string output;
    EXPECT_NE(kit_render("--solution --stage 1 --size 8x6 --backend osmesa --out " +
                             shell_quoted((dir / "osmesa.png").string()), &output), 0) << output;
    EXPECT_NE(output.find("this build of the kit has no OSMesa"), std::string::npos) << output;
    render_with("egl", dir);
    return;
  }
  fs::path osmesa = render_with("osmesa", dir);
  fs::path egl = render_with("egl", dir);
  ASSERT_FALSE(HasFailure()) << "a backend could not render (see above)";
  for (const Job& job : kJobs) {
    for (const auto& [view, file] : job.outputs) {
      kit::Image a = kit::read_image((osmesa / file).string());
      kit::Image b = kit::read_image((egl / file).string());
      // A blank image on both sides would compare equal and prove nothing.
      EXPECT_GT(value_range(a), 0.1f) << file << " is nearly uniform";
      std::string difference = kit::test::first_difference(a, b);
      EXPECT_EQ(difference, "") << job.stage << " " << file << ": osmesa and egl differ";
    }
  }
}

TEST(Backends, BadCommandLinesFailClearly) {
  fs::path dir = kit::test::temp_dir("backends/bad_arguments");
  const std::string out = " --out " + shell_quoted((dir / "image.png").string());
  const std::string missing_scene = (dir / "no_such_scene.gltf").string();
  // Each run costs ~0.3 s of process start-up (Mesa's libraries), so one case per flag.
  const std::pair<std::string, std::string> cases[] = {
      {"--stage bogus" + out, "unknown stage 'bogus' (stages: gbuffer, lighting, attenuation, normalmap, postprocess, ibl, lightvolumes)"},
      {"--view bogus" + out, "unknown view 'bogus' (views: final, position, normal, albedo, material, emission, depth, hdr, and at stage 6 irradiance, prefiltered, brdf-lut)"},
      {"--size 0x120" + out, "--size must be between 1x1 and 8192x8192 (got '0x120')"},
      {"--size 160" + out, "--size expects WxH, e.g. 640x480 (got '160')"},
      {"--stage gbuffer", "--out FILE is required"},
      {"--scene " + shell_quoted(missing_scene) + out, missing_scene + ": scene file not found"},
      {"--backend vulkan" + out, "unknown backend 'vulkan' (expected osmesa, egl or window)"},
      {"--frobnicate" + out, "unknown option '--frobnicate'"},
      {out + " --view", "--view needs a value"},  // a known flag at the end, its value missing
  };
  for (const auto& [args, phrase] : cases) {
    std::string output;
    int status = kit_render(args, &output);
    EXPECT_NE(status, 0) << "kit-render " << args << " succeeded:\n" << output;
    EXPECT_NE(output.find("kit-render: "), std::string::npos) << args << ":\n" << output;
    EXPECT_NE(output.find(phrase), std::string::npos) << "kit-render " << args << "\nexpected: " << phrase << "\ngot: " << output;
  }
  // The same options with a valid value succeed, so the failures above are the values' doing.
  std::string output;
  EXPECT_EQ(kit_render("--stage 1 --view normal --size 8x6" + out, &output), 0) << output;
  EXPECT_EQ(kit::read_image((dir / "image.png").string()).width, 8);
}

}  // namespace

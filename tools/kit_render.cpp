// kit-render: one deterministic headless frame of a stage, written as PNG or EXR.
//   kit-render --stage gbuffer --view normal --out normal.png [--view depth --out depth.exr ...]
// It renders the student's labs/ (--solution: the reference solutions; --shaders: any lab folders).
// Several --view/--out pairs share one context, scene load and shader compile.
#include <malloc.h>
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>

#include "cli.h"
#include "gl/context.h"
#include "base/error.h"
#include "gl/pass_clock.h"

namespace {

struct Output {
  kit::View view;
  std::string path;
};

// The most memory the process has had resident (Linux's ru_maxrss is in KiB).
double peak_resident_mib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

void usage() {
  std::printf(
      "usage: kit-render --stage NAME [--view VIEW] --out FILE.png|FILE.exr [--view VIEW --out FILE ...] [options]\n"
      "Renders one headless frame. VIEW: final (default) | position | normal | albedo | material | emission | depth | hdr,\n"
      "and at stage 6 irradiance | prefiltered (its levels stacked, level 0 on top) | brdf-lut.\n"
      "PNG shows a view for people (vectors as (v+1)/2, depth linearised); EXR keeps the float values.\n"
      "Renders your labs/ unless --solution or --shaders says otherwise. Warns (stderr) about NaN/Inf pixels\n"
      "and uniforms nothing sets; exits 1 on a shader error, %d when --timeout runs out.\n"
      "  --timings             print where the time went (stderr)\n"
      "  --frames N            render the frame N times (default 1); with --timings, each frame's\n"
      "                        wall-clock time in ms, glFinish included (the first holds llvmpipe's JIT),\n"
      "                        then each pass's median over N more frames\n%s",
      kit::kTimedOutStatus,
      kit::common_options_help());
}

}  // namespace

int main(int argc, char** argv) {
  auto t0 = std::chrono::steady_clock::now();
  // One malloc arena for every thread, set before any thread starts: a thread's own
  // arena keeps the top of its heap when keep_freed_memory_for_reuse's trim threshold
  // is not reached, and malloc_trim never trims it, so the texture decode threads'
  // images (tens of MB) stayed resident through the frame.
  mallopt(M_ARENA_MAX, 1);
  kit::CommonOptions options;
  std::vector<Output> outputs;
  kit::View pending = kit::View::Final;
  bool timings = false;
  int frames = 1;
  kit::name_gl_crashes("kit-render");
  return kit::run_tool("kit-render", 1, [&]() -> int {
    for (int i = 1; i < argc; ++i)
      if (!std::strcmp(argv[i], "--help") || !std::strcmp(argv[i], "-h")) {
        usage();
        return 0;
      }
    kit::parse_options(argc, argv, options, [&](const std::string& flag, const kit::OptionValue& value) -> int {
      if (flag == "--timings") return timings = true, 1;
      if (flag == "--frames") {
        std::string text = value();
        const std::optional<long> n = kit::parse_whole_number(text, 1, 1000);
        if (!n) throw kit::Error("--frames expects a count from 1 to 1000 (got '" + text + "')");
        return frames = static_cast<int>(*n), 2;
      }
      if (flag == "--view") return pending = kit::parse_view(value()), 2;
      if (flag == "--out") return outputs.push_back({pending, value()}), 2;
      return 0;
    });
    if (outputs.empty()) throw kit::Error("--out FILE is required (see --help)");

    const kit::LabSelection lab = kit::select_lab(options);
    const kit::Stage& stage = *lab.stage;
    kit::Scene scene = kit::load_scene(kit::resolve_scene(options.scene));
    for (const std::string& warning : scene.warnings) std::fprintf(stderr, "kit-render: warning: %s\n", warning.c_str());
    const kit::Camera camera = kit::initial_camera(scene, options);
    auto t_scene = kit::seconds_since(t0);
    auto context = kit::create_headless_context(kit::parse_backend(options.backend));
    auto t_context = kit::seconds_since(t0);
    // One time limit for compiling, drawing and reading back, as the grader gives a lab.
    kit::Watchdog watchdog("kit-render", options.timeout);
    watchdog.arm("compiling the shaders of stage " + stage.name);
    kit::Renderer renderer(stage, kit::stage_library(stage, lab.root), scene, options.settings);
    kit::release_uploaded_data(scene);
    kit::note_default_light_rig("kit-render", scene, stage, options.settings);
    auto t_compile = kit::seconds_since(t0);
    watchdog.relabel("rendering stage " + stage.name);
    const auto& s = options.settings;
    std::vector<double> frame_ms;
    std::vector<kit::PassTimes> pass_ms;
    const kit::FrameCamera frame_camera =
        kit::frame_camera(camera, static_cast<float>(s.width) / static_cast<float>(s.height));
    for (int f = 0; f < frames; ++f) {
      auto t_frame = std::chrono::steady_clock::now();
      renderer.render(frame_camera);
      glFinish();
      frame_ms.push_back(1000.0 * kit::seconds_since(t_frame));
    }
    // The breakdown is taken in frames of its own: its glFinish after every pass
    // would slow the frames timed above.
    if (timings && frames > 1)
      for (int f = 0; f < frames; ++f) renderer.render(frame_camera, &pass_ms.emplace_back());
    auto t_render = kit::seconds_since(t0);
    for (const Output& out : outputs) {
      bool raw = out.path.size() > 4 && out.path.compare(out.path.size() - 4, 4, ".exr") == 0;
      kit::write_image(out.path, renderer.read_view(out.view, raw));
    }
    // What the grader would say besides the images: NaN/Inf in the float buffers, uniforms nothing sets.
    for (const kit::NonFiniteCount& n : renderer.non_finite_pixels())
      if (n.pixels > 0)
        std::fprintf(stderr, "kit-render: warning: %zu of %zu pixels of the %s view are NaN or Inf: %s\n", n.pixels, n.of,
                     kit::view_name(n.view), kit::kNonFiniteAdvice);
    for (const std::string& line : renderer.uniform_warnings()) std::fprintf(stderr, "kit-render: warning: %s\n", line.c_str());
    watchdog.disarm();
    if (timings) {
      // The upload (decoding the textures materials use, on worker threads) is part of
      // the Renderer's construction; "compile" is the rest of it.
      const double upload = renderer.scene_upload_seconds();
      std::fprintf(stderr, "timings: scene %.3fs, context %.3fs, upload %.3fs, compile %.3fs, render %.3fs, write %.3fs (%s)\n",
                   t_scene, t_context - t_scene, upload, t_compile - t_context - upload, t_render - t_compile,
                   kit::seconds_since(t0) - t_render, context->describe().c_str());
      std::fprintf(stderr, "memory: peak %.0f MiB resident (the process so far, GL driver included)\n", peak_resident_mib());
      const kit::TextureCompressionDecision& textures = renderer.texture_compression();
      std::fprintf(stderr, "%s; %s uploaded\n", textures.reason.c_str(), kit::mebibytes(textures.uploaded_bytes).c_str());
    }
    if (timings && frames > 1) {
      std::string list;
      for (double ms : frame_ms) list += (list.empty() ? "" : " ") + std::to_string(ms);
      std::fprintf(stderr, "frame ms: %s\n", list.c_str());
      std::string passes;
      for (const auto& [pass, ms] : kit::median_pass_times(pass_ms)) passes += " " + pass + " " + std::to_string(ms);
      std::fprintf(stderr, "pass ms (median of %d, glFinish after each):%s\n", frames, passes.c_str());
    }
    return 0;
  });
}

#include "page_check.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "base/error.h"
#include "frames/checks.h"
#include "frames/function_probes.h"
#include "frames/lab_frames.h"
#include "frames/probe_pass.h"
#include "gl/pass_clock.h"
#include "render/renderer.h"
#include "render/stages.h"
#include "verdict/compare.h"
#include "verdict/config.h"
#include "verdict/diagnosis.h"
#include "verdict/lab_verdict.h"

namespace fs = std::filesystem;

namespace kit::web {

namespace {

using Json = nlohmann::json;
using namespace kit::grade;

fs::path references_dir() { return kit_root() / "tools" / "grade" / "references"; }

Json write_rgba(const fs::path& path, const Image& image) {
  const std::vector<unsigned char> bytes = rgba8(image, false);
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw Error(path.string() + ": cannot write");
  return {{"path", path.string()}, {"width", image.width}, {"height", image.height}};
}

}  // namespace

std::vector<unsigned char> rgba8(const Image& image, bool bottom_up) {
  const int w = image.width, h = image.height, n = image.channels;
  std::vector<unsigned char> rgba(static_cast<size_t>(w) * h * 4, 255);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const float* from = &image.pixels[(static_cast<size_t>(y) * w + x) * n];
      unsigned char* to = &rgba[(static_cast<size_t>(bottom_up ? h - 1 - y : y) * w + x) * 4];
      for (int c = 0; c < 3; ++c) to[c] = to_unorm8(from[n >= 3 ? c : 0]);
    }
  return rgba;
}

Json check_catalogue() {
  const Config config = load_config(default_config_path());
  Json out = Json::object();
  for (const Stage& stage : stages())
    for (const Check* check : lab_checks(stage.number))
      out[std::to_string(stage.number)].push_back(
          {{"key", check->key}, {"title", check->title}, {"points", config.max_score(*check) / 1000.0}});
  return out;
}

Json check_scenes() {
  Json out = Json::object();
  for (const Stage& stage : stages()) {
    std::set<std::string> scenes;
    for (const RenderSpec* spec : lab_renders(stage.number)) scenes.insert(spec->scene);
    out[std::to_string(stage.number)] = scenes;
  }
  return out;
}

Json run_check(int lab_number, const fs::path& lab_root, const fs::path& out_dir) {
  const auto t0 = std::chrono::steady_clock::now();
  const Stage& stage = find_stage(lab_number);
  const Config config = load_config(default_config_path());
  fs::remove_all(out_dir);
  fs::create_directories(out_dir);
  LabOutcome lab = lab_outcome(config, lab_number);
  Json answer = {{"lab", lab_number}, {"stage", stage.name}};

  std::map<std::string, Scene> scenes;
  for (const RenderSpec* spec : lab_renders(lab_number))
    if (!scenes.count(spec->scene)) scenes.emplace(spec->scene, load_scene(resolve_scene(spec->scene)));

  // The renders, as a render worker makes them (render_worker.cpp), with its report's
  // "work" and "hdr_non_finite".
  std::map<std::string, Image> renders;
  Json child = Json::object();
  const Json probes_reference = read_probes_reference(references_dir());
  {
    LabFrames frames(stage, lab_root, scenes);
    for (const RenderSpec* spec : lab_renders(lab_number)) {
      try {
        Renderer& renderer = frames.renderer_for(*spec);
        frames.draw(*spec);
        if (stage.light_volumes) child["work"][spec->id] = work_json(renderer.light_volume_work(), renderer.light_volume_state());
        renders[spec->id] = renderer.read_view(spec->view, spec->raw);
        if (stage.lighting && spec->view != View::Hdr && !is_precomputed_map(spec->view))
          child["hdr_non_finite"][spec->id] = renderer.count_non_finite(View::Hdr);
      } catch (const NonFiniteMapError& e) {
        answer["status"] = "non_finite_map";
        answer["message"] = e.what();
        break;
      } catch (const Error& e) {
        answer["status"] = renders.empty() ? "compile_error" : "render_error";
        answer["message"] = e.what();
        break;
      }
    }
    // The lab's function probes, with the same context, as the render worker runs them.
    if (!answer.contains("status")) report_function_probes(stage, lab_root, probes_reference, child);
  }
  const double render_seconds = seconds_since(t0);

  if (!answer.contains("status")) {
    answer["status"] = "graded";
    lab.probes = probe_outcomes(lab_number, child, probes_reference);
    std::map<std::string, Image> pixel_references;  // by reference id, for the worst pixels' inputs
    for (CheckOutcome& c : lab.checks) {
      const Check& check = *c.check;
      const bool own = compares_own_renders(check.metric);
      Image reference_image, allowance;
      Background background{};
      StoredReference stored;
      if (!own) {
        const RenderSpec& spec = find_render(check.reference);
        const fs::path file = references_dir() / (check.reference + "." + reference_extension(spec));
        reference_image = read_image(file.string());
        const fs::path allowance_file = references_dir() / (check.reference + ".allowance.exr");
        if (fs::exists(allowance_file)) allowance = read_image(allowance_file.string());
        background = reference_background(check.metric, reference_image);
        stored = {&reference_image, &allowance, &background};
      }
      compare_check(config, lab, c, renders, child, stored);
      if (!c.passed && lab_number >= 2) {
        // The worst pixel's inputs, from the references of the render's scene and frame.
        add_reference_pixel_inputs(c, scenes.at(find_render(check.image).scene), pixel_references,
                                   [](const std::string& id) { return read_image((references_dir() / (id + ".exr")).string()); });
      }
      const Image& image = renders.at(check.image);
      const Image& reference = own ? renders.at(check.reference) : reference_image;
      const fs::path stem = out_dir / check.key;
      Json row = {{"key", check.key},       {"title", check.title},           {"passed", c.passed},
                  {"points", c.max_score / 1000.0}, {"score", c.score / 1000.0}, {"summary", c.comparison.summary}, {"note", c.comparison.note},
                  {"metric", metric_name(check.metric)}};
      if (!c.comparison.worst_pixel.empty()) {
        row["worst_pixel"] = c.comparison.worst_pixel;
        row["worst"] = {{"x", c.comparison.max_x}, {"y", c.comparison.max_y}};  // ringed on the difference
      }
      {
        const Metric shown = shown_metric(check);
        row["image"] = write_rgba(stem.string() + ".image.rgba", display_image(shown, image, reference));
        row["reference"] = write_rgba(stem.string() + ".reference.rgba", display_image(shown, reference, reference));
        if (c.comparison.diff.width > 0) row["diff"] = write_rgba(stem.string() + ".diff.rgba", c.comparison.diff);
      }
      answer["checks"].push_back(row);
    }
    name_likely_mistakes(load_mistake_signatures(references_dir() / kMistakeSignaturesFile), lab);
    answer["functions"] = Json::array();
    for (const ProbeOutcome& p : lab.probes) answer["functions"].push_back(probe_outcome_json(p));
    answer["functions_text"] = probe_feedback(lab.probes, lab.passed_checks() < static_cast<int>(lab.checks.size()));
    for (const LikelyMistake& m : lab.likely_mistakes)
      answer["likely_mistakes"].push_back({{"id", m.id}, {"description", m.description}, {"similarity", m.similarity}});
  }
  answer["passed"] = lab.passed_checks();
  answer["total"] = lab.checks.size();
  answer["score"] = lab.score() / 1000.0;
  answer["max_score"] = lab.max_score() / 1000.0;
  answer["seconds"] = {{"render", render_seconds}, {"total", seconds_since(t0)}};
  return answer;
}

}  // namespace kit::web

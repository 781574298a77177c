#include "verdict/lab_verdict.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "base/error.h"
#include "frames/lab_frames.h"
#include "gbuffer_layout.h"  // KIT_LIGHT_*
#include "render/renderer.h"

namespace kit::grade {

LabOutcome lab_outcome(const Config& config, int lab) {
  LabOutcome out;
  out.lab = lab;
  for (const Check* check : lab_checks(lab)) {
    CheckOutcome c;
    c.check = check;
    c.max_score = config.max_score(*check);
    out.checks.push_back(c);
  }
  return out;
}

namespace {

// Lab 7's work check: the frame's counted work against its limits, credited only where the
// frame's image check (earlier in the list) passed. Work over the limit behind a right image
// is evidence for naming (kWorkPart).
Comparison compare_work_check(const Config& config, LabOutcome& lab, const CheckOutcome& c,
                              const nlohmann::json& child, const Image& image) {
  const CheckOutcome* shown = nullptr;
  for (const CheckOutcome& other : lab.checks)
    if (&other != &c && other.compared && other.check->image == c.check->image && other.check->metric != Metric::Work)
      shown = &other;
  const nlohmann::json counted = child.contains("work") ? child["work"].value(c.check->image, nlohmann::json()) : nlohmann::json();
  Comparison r = compare_work(config.tolerance(*c.check), work_from_json(counted), shown && shown->passed,
                              shown ? shown->check->key : c.check->image, image.width, image.height);
  if (counted.is_object()) r.summary += "; state " + counted.value("state", std::string("?"));
  if (!r.passed && shown && shown->passed) lab.evidence.insert(kWorkPart);
  return r;
}

}  // namespace

void compare_check(const Config& config, LabOutcome& lab, CheckOutcome& c, const std::map<std::string, Image>& renders,
                   const nlohmann::json& child, const StoredReference& stored) {
  const Check& check = *c.check;
  const Image& image = renders.at(check.image);
  const bool own = compares_own_renders(check.metric);  // its "reference" is the submission's own render
  if (check.metric == Metric::Work) {
    c.comparison = compare_work_check(config, lab, c, child, image);
  } else {
    const Image& reference = own ? renders.at(check.reference) : *stored.image;
    const Background* background = own ? nullptr : stored.background;
    const Image* allowance = !own && stored.allowance && stored.allowance->width > 0 ? stored.allowance : nullptr;
    c.comparison = compare_images(check.metric, config.tolerance(check), image, reference, background, allowance);
    // Lab 7: where the frame's volumes go wrong, light by light, beside where its image does.
    const nlohmann::json counted =
        check.metric == Metric::Hdr && child.contains("work") ? child["work"].value(check.image, nlohmann::json()) : nlohmann::json();
    if (counted.is_object()) {
      lab.volume_counted = lab.volume_counted || counted.value("counted", true);
      const VolumeEvidence evidence = work_from_json(counted).evidence;
      const std::vector<float> signature = volume_evidence_signature(evidence);
      // After the tiles, at the same place for every submission (an image not compared has none).
      c.comparison.signature.resize(static_cast<size_t>(kSignatureColumns * kSignatureRows), 0.0f);
      c.comparison.signature.insert(c.comparison.signature.end(), signature.begin(), signature.end());
      for (const std::string& part : volume_evidence_parts(evidence)) lab.evidence.insert(part);
      const std::string text = describe_volume_evidence(evidence);
      if (!c.comparison.passed && !text.empty())
        c.comparison.note += (c.comparison.note.empty() ? "" : "; ") + text;
    }
  }
  const size_t hdr_bad = child.contains("hdr_non_finite") ? child["hdr_non_finite"].value(check.image, size_t{0}) : 0;
  if (hdr_bad > 0 && !own) {
    c.comparison.passed = false;
    c.comparison.note = "the HDR buffer behind this image holds " + std::to_string(hdr_bad) +
                        " NaN or Inf pixels: " + kNonFiniteAdvice;
  }
  c.compared = true;
  c.passed = c.comparison.passed;
  c.score = c.passed ? c.max_score : 0;
}

std::map<std::string, std::string> gbuffer_reference_ids(const RenderSpec& spec) {
  std::map<std::string, std::string> ids;
  const auto stored = [](const std::string& id) {
    for (const RenderSpec* r : reference_renders())
      if (r->id == id) return true;
    return false;
  };
  for (const char* attachment : {"position", "normal", "albedo", "material", "emission"}) {
    const std::string lab1 = "lab1-" + spec.scene + "-" + attachment;
    if (stored(lab1)) ids[attachment] = lab1;
  }
  if (spec.stage >= 4 && stored("lab4-" + spec.scene + "-normal")) ids["normal"] = "lab4-" + spec.scene + "-normal";
  return ids;
}

std::string describe_pixel_inputs(const PixelInputs& in, const Scene& scene) {
  const auto vec = [](const glm::vec3& v) {
    char text[64];
    std::snprintf(text, sizeof text, "(%.3g, %.3g, %.3g)", static_cast<double>(v.x), static_cast<double>(v.y),
                  static_cast<double>(v.z));
    return std::string(text);
  };
  char numbers[96];
  std::snprintf(numbers, sizeof numbers, ", metallic %.3g, roughness %.3g, emission ", static_cast<double>(in.metallic),
                static_cast<double>(in.roughness));
  std::string out = "there the G-buffer holds position " + vec(in.position) + " m, normal " + vec(in.normal) + ", albedo " +
                    vec(in.albedo) + numbers + vec(in.emission);
  const Camera camera = chosen_camera(scene, -1);
  const glm::vec3 to_eye = camera.position - in.position;
  if (glm::length(to_eye) > 0.0f) out += "; towards the camera " + vec(glm::normalize(to_eye));
  constexpr size_t kMostLights = 4;
  // Where the light shares are stored, the lights that give the most lead, each with its share.
  std::vector<size_t> order;
  std::map<size_t, double> share;
  const bool shared = in.has_light_shares;
  if (shared) {
    char luminance[96];
    std::snprintf(luminance, sizeof luminance, "; the lights give it luminance %.2g in the reference",
                  in.light_shares.luminance);
    out += in.light_shares.lights.empty() ? std::string("; no light reaches it in the reference") : luminance;
    for (const LightShare& s : in.light_shares.lights)
      if (s.light >= 0 && static_cast<size_t>(s.light) < scene.lights.size() && !share.count(static_cast<size_t>(s.light))) {
        order.push_back(static_cast<size_t>(s.light));
        share[static_cast<size_t>(s.light)] = s.share;
      }
  }
  // Every light that gives some is named: the others give none. Or the named give (to their
  // rounding) all of it: the others give under 1 %.
  double named = 0.0;
  for (const LightShare& s : in.light_shares.lights) named += s.share;
  const bool all_named = shared && in.light_shares.lights.size() < static_cast<size_t>(kSharedLights);
  const bool nearly_all_named = shared && !all_named && named >= 0.99;
  // Then, where there are more (lab 7's 128), the ones that light this pixel most likely: the nearest.
  std::vector<size_t> rest;
  for (size_t i = 0; i < scene.lights.size(); ++i)
    if (!share.count(i)) rest.push_back(i);
  const auto distance = [&](size_t i) {
    const Light& light = scene.lights[i];
    return light.type == KIT_LIGHT_DIRECTIONAL ? 0.0f : glm::length(light.position - in.position);
  };
  if (scene.lights.size() > kMostLights)
    std::stable_sort(rest.begin(), rest.end(), [&](size_t a, size_t b) { return distance(a) < distance(b); });
  order.insert(order.end(), rest.begin(), rest.end());
  for (size_t n = 0; n < order.size() && n < kMostLights; ++n) {
    const size_t i = order[n];
    const Light& light = scene.lights[i];
    const char* type = light.type == KIT_LIGHT_DIRECTIONAL ? "directional" : light.type == KIT_LIGHT_SPOT ? "spot" : "point";
    const bool parallel = light.type == KIT_LIGHT_DIRECTIONAL;  // no position: a direction only
    // Its glTF range: where lab 3's window ends, and what lab 7's volumes must not be scaled by.
    char range[48] = ", no range";
    if (parallel)
      range[0] = '\0';
    else if (light.range > 0.0f)
      std::snprintf(range, sizeof range, ", range %.3g m", static_cast<double>(light.range));
    out += "; light " + std::to_string(i + 1) + " (" + type + range + "): towards it ";
    if (parallel) {
      out += vec(-light.direction);
    } else {
      const glm::vec3 d = light.position - in.position;
      char distance[32];
      std::snprintf(distance, sizeof distance, ", %.3g m", static_cast<double>(glm::length(d)));
      out += vec(glm::length(d) > 0.0f ? glm::normalize(d) : d) + distance;
    }
    if (share.count(i)) {
      char given[48];
      std::snprintf(given, sizeof given, ", %.0f %% of it", 100.0 * share[i]);
      out += given;
    } else if (all_named) {
      out += ", none";
    } else if (nearly_all_named) {
      out += ", under 1 %";
    }
  }
  if (scene.lights.size() > kMostLights) out += "; and " + std::to_string(scene.lights.size() - kMostLights) + " more lights";
  return out;
}

void add_pixel_inputs(CheckOutcome& c, const std::map<std::string, const Image*>& gbuffer, const Scene& scene,
                      const Image* light_shares) {
  const Metric metric = c.check->metric;
  if (c.passed || c.comparison.worst_pixel.empty() || (metric != Metric::Ldr && metric != Metric::Hdr)) return;
  for (const char* attachment : {"position", "normal", "albedo", "material", "emission"})
    if (!gbuffer.count(attachment) || !gbuffer.at(attachment)) return;
  const int x = c.comparison.max_x, y = c.comparison.max_y;
  const Image& position = *gbuffer.at("position");
  if (x < 0 || y < 0 || x >= position.width || y >= position.height) return;
  const auto at = [&](const char* attachment) {
    const Image& image = *gbuffer.at(attachment);
    return glm::vec3(image.at(x, y, 0), image.at(x, y, 1), image.at(x, y, 2));
  };
  if (gbuffer.at("material")->channels >= 4 && gbuffer.at("material")->at(x, y, 3) < 0.5f) {
    c.comparison.worst_pixel += "; there the G-buffer holds no surface (the background)";
    return;
  }
  PixelInputs in;
  in.position = at("position");
  in.normal = at("normal");
  in.albedo = at("albedo");
  in.emission = at("emission");
  in.metallic = gbuffer.at("material")->at(x, y, 0);
  in.roughness = gbuffer.at("material")->at(x, y, 1);
  if (light_shares && light_shares->width == position.width && light_shares->height == position.height) {
    in.has_light_shares = true;
    in.light_shares = light_shares_at(*light_shares, x, y);
  }
  c.comparison.worst_pixel += "; " + describe_pixel_inputs(in, scene);
}

void add_reference_pixel_inputs(CheckOutcome& c, const Scene& scene, std::map<std::string, Image>& cache,
                                const std::function<Image(const std::string& id)>& read) {
  const auto stored = [&](const std::string& id) -> const Image* {
    auto cached = cache.find(id);
    if (cached == cache.end()) {
      Image image;
      try {
        image = read(id);
      } catch (const Error&) {
        // Left out: the check's verdict does not depend on it.
      }
      cached = cache.emplace(id, std::move(image)).first;
    }
    return cached->second.width > 0 ? &cached->second : nullptr;
  };
  const RenderSpec& spec = find_render(c.check->image);
  std::map<std::string, const Image*> gbuffer;
  for (const auto& [attachment, id] : gbuffer_reference_ids(spec))
    if (const Image* image = stored(id)) gbuffer[attachment] = image;
  const std::string shares = light_shares_id(spec);
  add_pixel_inputs(c, gbuffer, scene, shares.empty() ? nullptr : stored(shares));
}

Metric shown_metric(const Check& check) {
  return check.metric == Metric::Work ? Metric::Hdr : compares_own_renders(check.metric) ? Metric::Ldr : check.metric;
}

NamingInputs naming_inputs(const LabOutcome& lab) {
  NamingInputs inputs;
  for (const CheckOutcome& c : lab.checks) inputs.features[c.check->key] = check_features(c.comparison.signature, !c.passed);
  // The probed functions that differ, where every probe of the lab ran (function_probes.h).
  inputs.probed = !lab.probes.empty();
  for (const ProbeOutcome& p : lab.probes) {
    inputs.probed = inputs.probed && p.status != kProbeNotRun;
    if (p.status == kProbeDiffers || (p.status == kProbeExplained && p.part != p.probe->function))
      inputs.differing.insert(p.part);
  }
  inputs.differing.insert(lab.evidence.begin(), lab.evidence.end());
  inputs.volume_counted = lab.volume_counted;
  return inputs;
}

bool needs_naming(const LabOutcome& lab) {
  return lab.status == kGraded && lab.passed_checks() < static_cast<int>(lab.checks.size());
}

void name_likely_mistakes(const MistakeSignatures& mistakes, LabOutcome& lab) {
  if (mistakes.empty() || lab.passed_checks() >= static_cast<int>(lab.checks.size())) return;
  lab.likely_mistakes = likely_mistakes(mistakes, lab.lab, naming_inputs(lab));
  lab.diagnosed = true;
}

}  // namespace kit::grade

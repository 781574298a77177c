#include "verdict/diagnosis.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>

#include "base/error.h"
#include "frames/function_probes.h"
#include "verdict/compare.h"

namespace kit::grade {

namespace {

constexpr float kSteps = 255.0f;  // the file's integers: 0 .. kSteps

}  // namespace

std::vector<float> check_features(const std::vector<float>& signature, bool failed) {
  std::vector<float> out;
  out.reserve(signature.size() + 1);
  for (float v : signature) out.push_back(std::sqrt(std::clamp(v, 0.0f, kSignatureCap) / kSignatureCap));
  out.push_back(failed ? kFailedWeight : 0.0f);
  return out;
}

MistakeSignatures load_mistake_signatures(const std::filesystem::path& file) {
  MistakeSignatures out;
  std::ifstream in(file);
  if (!in) return out;
  try {
    const nlohmann::json doc = nlohmann::json::parse(in);
    for (const auto& m : doc.at("mistakes")) {
      MistakeSignature s;
      s.id = m.at("id").get<std::string>();
      s.description = m.at("description").get<std::string>();
      s.family = m.value("family", s.id);
      std::set<std::string> failed;
      for (const auto& key : m.value("failed", nlohmann::json::array())) failed.insert(key.get<std::string>());
      for (const auto& [key, values] : m.at("signatures").items()) {
        std::vector<float>& v = s.checks[key];
        for (const auto& q : values) v.push_back(std::clamp(static_cast<float>(q.get<int>()), 0.0f, kSteps) / kSteps);
        v.push_back(failed.count(key) ? kFailedWeight : 0.0f);
      }
      if (m.contains("functions") && m["functions"].is_array()) {
        s.probed = true;
        for (const auto& f : m["functions"]) s.functions.insert(f.get<std::string>());
      }
      out.labs[m.at("lab").get<int>()].push_back(std::move(s));
    }
  } catch (const nlohmann::json::exception& e) {
    throw Error(file.string() + ": not a mistake signature file (" + e.what() + ")");
  }
  return out;
}

double signature_similarity(const std::map<std::string, std::vector<float>>& a,
                            const std::map<std::string, std::vector<float>>& b) {
  double dot = 0.0, aa = 0.0, bb = 0.0;
  const auto pair = [&](double x, double y) {
    dot += x * y;
    aa += x * x;
    bb += y * y;
  };
  for (const auto& [key, va] : a) {
    auto it = b.find(key);
    if (it == b.end() || va.empty() || it->second.empty()) {
      for (float x : va) aa += static_cast<double>(x) * x;
      if (it != b.end())
        for (float y : it->second) bb += static_cast<double>(y) * y;
      continue;
    }
    // Over the signature both have, then the failed flags (each vector's last value): every
    // value where the lengths agree; where one side has more (lab 7's volume evidence, which
    // a browser cannot count), those are left out.
    const std::vector<float>& vb = it->second;
    const size_t n = std::min(va.size(), vb.size());
    for (size_t i = 0; i + 1 < n; ++i) pair(va[i], vb[i]);
    pair(va.back(), vb.back());
  }
  for (const auto& [key, vb] : b)
    if (!a.count(key))
      for (float y : vb) bb += static_cast<double>(y) * y;
  return aa > 0.0 && bb > 0.0 ? dot / std::sqrt(aa * bb) : 0.0;
}

namespace {

// How alike a mistake's differing functions and the submission's are: the Jaccard index of
// the two sets (1 when both are empty: every function agrees for both), 0 without probes. The
// mistake's parts that start with `unmeasured` (when not empty) are left out: the submission's
// run could not have found them.
double probe_agreement(const MistakeSignature& s, const std::set<std::string>* differing,
                       const std::string& unmeasured = "") {
  if (!differing || !s.probed) return 0.0;
  size_t common = 0, own = 0;
  for (const std::string& f : s.functions) {
    if (!unmeasured.empty() && f.rfind(unmeasured, 0) == 0) continue;
    ++own;
    common += differing->count(f);
  }
  if (own == 0 && differing->empty()) return 1.0;
  return static_cast<double>(common) / static_cast<double>(own + differing->size() - common);
}

// Whether a term probe's decided term (a differing part "FUNCTION, TERM": term_probes.h) is
// the TERM of the mistake's family (the catalogue's LAB-PART.TERM): the evidence then places
// the mistake in that term, whether its own edit was in the function or in its caller.
bool term_names_family(const MistakeSignature& s, const std::set<std::string>& differing) {
  const size_t dot = s.family.rfind('.');
  if (dot == std::string::npos) return false;
  for (const std::string& part : differing) {
    const size_t comma = part.find(", ");
    if (comma != std::string::npos && part.compare(comma + 2, std::string::npos, s.family, dot + 1) == 0) return true;
  }
  return false;
}

}  // namespace

std::vector<LikelyMistake> likely_mistakes(const MistakeSignatures& signatures, int lab,
                                           const std::map<std::string, std::vector<float>>& submission,
                                           const std::set<std::string>* differing, bool volume_counted) {
  std::vector<LikelyMistake> named;
  auto it = signatures.labs.find(lab);
  if (it == signatures.labs.end()) return named;
  struct Ranked {
    LikelyMistake mistake;
    const std::string* family;
    double rank;
    bool named_anyway;  // the evidence places it, named even below the floor: lab 7's shared part, a decided term
  };
  std::vector<Ranked> all;
  const std::vector<FunctionProbe>& probes = function_probes(lab);
  const bool passes = !probes.empty() && probes.front().pass;
  // Lab 7, whose probe draws light_volume.frag (diagnosis.h), names a mistake that shares a part with
  // the submission's even where the images are unlike it.
  const bool evidence_first = !probes.empty() && probes.front().light_volume != nullptr;
  bool terms = false;  // a term probe's decided term among the differing parts
  if (differing && !passes)
    for (const std::string& part : *differing) terms = terms || part.find(", ") != std::string::npos;
  const double weight = passes ? kPassProbeWeight : terms ? kTermProbeWeight : kProbeWeight;
  for (const MistakeSignature& s : it->second) {
    const double similarity = signature_similarity(s.checks, submission);
    if (evidence_first) {
      const double agreement = probe_agreement(s, differing, volume_counted ? "" : kVolumeEvidencePrefix);
      const bool shares = agreement > 0.0 && differing && !differing->empty();
      // There the starter (every part wrong at once) is named only where every part agrees with it:
      // files that did any part right are not the starter.
      if (s.id.rfind("starter-", 0) == 0 && agreement < 1.0) continue;
      // Lab 7 ranks by the parts first (their Jaccard index), the images only between equals.
      all.push_back({{s.id, s.description, similarity}, &s.family, agreement, shares});
      continue;
    }
    // Where a term is decided, it alone places the mistake: a family of another term gets nothing.
    const bool placed = terms && term_names_family(s, *differing);
    const double agreement = terms ? (placed ? 1.0 : 0.0) : probe_agreement(s, differing);
    all.push_back({{s.id, s.description, similarity}, &s.family, similarity + weight * agreement, placed});
  }
  std::stable_sort(all.begin(), all.end(), [evidence_first](const Ranked& x, const Ranked& y) {
    if (evidence_first && x.rank == y.rank) return x.mistake.similarity > y.mistake.similarity;
    return x.rank > y.rank;
  });
  std::set<std::string> families;
  for (const auto& [m, family, rank, named_anyway] : all) {
    if (named.size() == kMostNamed) break;
    if ((m.similarity >= kMinNamedSimilarity || named_anyway) && families.insert(*family).second) named.push_back(m);
  }
  return named;
}

std::vector<LikelyMistake> likely_mistakes(const MistakeSignatures& signatures, int lab, const NamingInputs& inputs) {
  return likely_mistakes(signatures, lab, inputs.features, inputs.probed ? &inputs.differing : nullptr,
                         inputs.volume_counted);
}

nlohmann::json naming_inputs_json(const NamingInputs& inputs) {
  nlohmann::json features = nlohmann::json::object();
  for (const auto& [key, values] : inputs.features) features[key] = values;
  nlohmann::json out = {{"features", features}, {"volume_counted", inputs.volume_counted}};
  out["differing"] = inputs.probed ? nlohmann::json(inputs.differing) : nlohmann::json(nullptr);
  return out;
}

NamingInputs naming_inputs_from_json(const nlohmann::json& json) {
  NamingInputs inputs;
  try {
    for (const auto& [key, values] : json.at("features").items())
      for (const auto& v : values) inputs.features[key].push_back(static_cast<float>(v.get<double>()));
    inputs.volume_counted = json.at("volume_counted").get<bool>();
    const nlohmann::json& differing = json.at("differing");
    inputs.probed = !differing.is_null();
    if (inputs.probed)
      for (const auto& part : differing) inputs.differing.insert(part.get<std::string>());
  } catch (const nlohmann::json::exception& e) {
    throw Error(std::string("not naming inputs (") + e.what() + ")");
  }
  return inputs;
}

}  // namespace kit::grade

#include "diagnosis.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>

#include "base/error.h"
#include "compare.h"

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
  for (const auto& [key, va] : a) {
    for (float v : va) aa += static_cast<double>(v) * v;
    auto it = b.find(key);
    if (it == b.end()) continue;
    for (size_t i = 0; i < std::min(va.size(), it->second.size()); ++i)
      dot += static_cast<double>(va[i]) * it->second[i];
  }
  for (const auto& [key, vb] : b)
    for (float v : vb) bb += static_cast<double>(v) * v;
  return aa > 0.0 && bb > 0.0 ? dot / std::sqrt(aa * bb) : 0.0;
}

std::vector<LikelyMistake> likely_mistakes(const MistakeSignatures& signatures, int lab,
                                           const std::map<std::string, std::vector<float>>& submission) {
  std::vector<LikelyMistake> named;
  auto it = signatures.labs.find(lab);
  if (it == signatures.labs.end()) return named;
  std::vector<std::pair<LikelyMistake, const std::string*>> all;
  for (const MistakeSignature& s : it->second)
    all.push_back({{s.id, s.description, signature_similarity(s.checks, submission)}, &s.family});
  std::stable_sort(all.begin(), all.end(),
                   [](const auto& x, const auto& y) { return x.first.similarity > y.first.similarity; });
  std::set<std::string> families;
  for (const auto& [m, family] : all) {
    if (named.size() == kMostNamed || m.similarity < kMinNamedSimilarity) break;
    if (families.insert(*family).second) named.push_back(m);
  }
  return named;
}

}  // namespace kit::grade

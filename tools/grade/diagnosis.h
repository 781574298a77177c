#pragma once
// Naming the likely mistake behind a lab's failed checks: every catalogued mistake
// (instructor/grading/catalogue.json) was graded when the references were made, and each of
// its checks' signatures (compare.h, Comparison::signature: where the error lies, coarsely)
// kept in <references>/mistakes.json (`kit grade --self-check --write-signatures`). A
// submission whose lab failed a check is compared with each of that lab's mistakes; the
// closest are named when they are close enough. The score never depends on it, and the file
// holds no solution: descriptions and coarse error maps only.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace kit::grade {

// One mistake: per check key, its signature (kSignatureColumns x kSignatureRows values).
struct MistakeSignature {
  std::string id;
  std::string description;
  std::map<std::string, std::vector<float>> checks;
};

struct MistakeSignatures {
  std::map<int, std::vector<MistakeSignature>> labs;
  bool empty() const { return labs.empty(); }
};

// The file's name in a references folder.
constexpr const char* kMistakeSignaturesFile = "mistakes.json";

// Reads `file` (each value an integer in [0, 255]: kSignatureCap / 255 a step); none (empty)
// when it does not exist. Throws kit::Error naming the file when it is malformed.
MistakeSignatures load_mistake_signatures(const std::filesystem::path& file);

// How alike two sets of signatures are: the cosine of the angle between them, each the
// concatenation of its checks' signatures (a check one side lacks counts as zeros). 0 when
// either is all zeros.
double signature_similarity(const std::map<std::string, std::vector<float>>& a,
                            const std::map<std::string, std::vector<float>>& b);

struct LikelyMistake {
  std::string id;
  std::string description;
  double similarity = 0.0;
};

// Below this similarity no mistake is named ("no catalogued mistake fits"). From the
// catalogue's own figures (handouts/instructors.md, Naming the mistake): with each mistake
// left out, a relative came first for 55 of 96 with no floor, 54 at 0.6, 42 at 0.8.
constexpr double kMinNamedSimilarity = 0.6;
// Beside the closest, others are named when within this of it (at most kMostNamed in all).
constexpr double kNamedBesideBest = 0.05;
constexpr size_t kMostNamed = 3;

// The mistakes of `lab` that `submission` (check key -> signature) most resembles, closest
// first; empty when none reaches kMinNamedSimilarity.
std::vector<LikelyMistake> likely_mistakes(const MistakeSignatures& signatures, int lab,
                                           const std::map<std::string, std::vector<float>>& submission);

}  // namespace kit::grade

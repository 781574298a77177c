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
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace kit::grade {

// One mistake: per check key, its features (check_features: the check's signature, encoded,
// then whether it failed).
struct MistakeSignature {
  std::string id;
  std::string description;
  std::string family;  // the catalogue's: mistakes in the same term of the same formula
  std::map<std::string, std::vector<float>> checks;
  // The probed functions (function_probes.h) that differ for it, where its lab has probes.
  bool probed = false;
  std::set<std::string> functions;
};

struct MistakeSignatures {
  std::map<int, std::vector<MistakeSignature>> labs;
  bool empty() const { return labs.empty(); }
};

// The file's name in a references folder.
constexpr const char* kMistakeSignaturesFile = "mistakes.json";

// What a check contributes to the comparison: each tile of its signature (compare.h, capped at
// kSignatureCap) as sqrt(value / kSignatureCap), then kFailedWeight when the check failed, else
// 0. The square root keeps a faint error (a few pixels over the threshold in a tile, 0.01 of
// the cap) from vanishing beside a strong one; the failed flag lets checks that compare no
// image with a reference (changes, same, work) count. Measured with the catalogue, each
// mistake left out (handouts/instructors.md, Naming the mistake): linear values and no flag
// named a relative first for 59 of 125, the square root 62, with the flag at 0.5 65.
constexpr float kFailedWeight = 0.5f;
std::vector<float> check_features(const std::vector<float>& signature, bool failed);

// Reads `file`: per mistake, each check's signature as integers in [0, 255] (round(255 x the
// square root above)), the keys of the checks it failed and its family. None (empty) when the
// file does not exist. Throws kit::Error naming the file when it is malformed.
MistakeSignatures load_mistake_signatures(const std::filesystem::path& file);

// How alike two sets of features are: the cosine of the angle between them, each the
// concatenation of its checks' features (a check one side lacks counts as zeros). Where a
// check's features are longer on one side (lab 7's HDR checks carry the volume evidence,
// compare.h volume_evidence_signature, which the browser's page cannot count), the check is
// compared over the signature both have and the failed flag. 0 when either is all zeros.
double signature_similarity(const std::map<std::string, std::vector<float>>& a,
                            const std::map<std::string, std::vector<float>>& b);

struct LikelyMistake {
  std::string id;
  std::string description;
  double similarity = 0.0;
};

// Below this similarity no mistake is named ("no catalogued mistake fits"): where the checks a
// submission fails and where its errors lie barely overlap any catalogued mistake's. A higher
// floor buys no precision (handouts/instructors.md, Naming the mistake): with each mistake left
// out, the share of first names whose family is right is 0.57-0.58 for floors 0.1 to 0.3, and
// of the 5 left-out mistakes whose closest relative lies between 0.1 and 0.3, 4 are of the
// right family. At 0.1 a relative is named first for 75 of 125 (72 at 0.3), 133 of 135 are
// named, and a mistake unlike every catalogued one (no failed check in common) still is not.
constexpr double kMinNamedSimilarity = 0.1;
// At most this many are named, one per family: the closest, then the closest of each other
// family above the floor. Three near-copies of one mistake would tell a student less than
// three different places to look (with each mistake left out of the catalogue's signatures,
// its family is among the first three for 112 of 126 this way, 101 counting every mistake).
// A family is ranked by its closest mistake: scoring it by more of its members named fewer
// relatives first (126 with a relative, 78 this way: the mean of its two closest 72, the
// closest plus 0.1 of the second 69, a soft maximum at temperature 0.02 73). These figures
// predate lab 7's volume evidence (compare.h), with which they are 82 first and 113 within three.
constexpr size_t kMostNamed = 3;

// What the probes add to a mistake's rank: kProbeWeight times the Jaccard index of its
// differing functions and the submission's (function_probes.h). Two mistakes that leave the
// same error in the images (GGX without its pi, the specular term without its 4) are told
// apart by the function that holds the mistake, and a mistake in the caller by every function
// agreeing. Measured with the catalogue, each mistake left out (labs 2 and 3, 40 with a
// relative): 26 relatives named first and 36 within three by the images alone, 30 and 38
// with 0.1 (0.05: 26 and 36; 0.3: 28 and 38; ranking every exact match first: 28 and 34).
constexpr double kProbeWeight = 0.1;
// The same for a lab whose probes are passes (labs 1 and 4's geometry pass, lab 5's passes,
// lab 6's ibl.frag: function_probes.h, FunctionProbe::pass). A pass drawn alone on its own
// inputs confines a difference to its file, or to the part of it a probe isolates (an
// attachment, a term), with no caller to spread it, so agreement counts as much as the
// images. Measured the same way (labs 1, 4, 5 and 6, 79 mistakes with a relative): with
// 0.5, 67 relatives named first and 75 within three; with 1, 71 and 76; with 2, 72 and 77.
// Lab 5 alone, before the others had probes: 5 and 8 by the images alone, 11 and 11 at 0.5
// and at 1.
constexpr double kPassProbeWeight = 1.0;
// Lab 7's probe (light_volume.frag drawn alone) and its per-light counts (compare.h,
// volume_evidence_parts) name the part at fault more surely than its images, whose checks all
// fail alike (light missing or wrong somewhere): there a mistake that shares a part with the
// submission is named even below kMinNamedSimilarity (a radius that only lights without a
// range show fails one check, unlike its relatives'), and mistakes are ranked by the parts
// they share first (the Jaccard index), the images only between equals.
// Where the submission's differing parts hold a term probe's decided term (function
// probes' "cook_torrance, fresnel": term_probes.h): the term names where the mistake lies as a
// pass probe's part does, so it counts as much, and a mistake whose family's TERM (the
// catalogue's LAB-PART.TERM) is that term agrees fully, and is named even below
// kMinNamedSimilarity: the evidence places it whatever the images' resemblance.
constexpr double kTermProbeWeight = 1.0;
// The mistakes of `lab` that `submission` (check key -> check_features) most resembles,
// closest first, one per family; empty when none reaches kMinNamedSimilarity. With
// `differing` (the probed functions that differ, where every probe of the lab ran), each
// mistake's similarity gets kProbeWeight's share for its functions (kPassProbeWeight's where the
// lab's probes are passes) before they are ranked. `volume_counted` false: lab 7's per-light
// counts were not taken (the browser's check: WebGL2 counts no samples), so the parts of its
// mistakes that come from them (compare.h, kVolumeEvidencePrefix) are left out.
std::vector<LikelyMistake> likely_mistakes(const MistakeSignatures& signatures, int lab,
                                           const std::map<std::string, std::vector<float>>& submission,
                                           const std::set<std::string>* differing = nullptr,
                                           bool volume_counted = true);

// What a failed lab's likely mistakes are named from (lab_verdict.h, naming_inputs): the
// arguments of likely_mistakes above. kit-grade writes them beside summary.json
// (kNamingInputsFile), the features as the floats they are (a float goes to JSON's double and
// back exactly, where summary.json's signatures are rounded), so that `kit-grade --name-again`
// names the same mistakes from another mistakes.json without rendering anything: the
// self-check does so once it has written the file anew (instructor/grading/self_check.py).
struct NamingInputs {
  std::map<std::string, std::vector<float>> features;  // check key -> check_features
  bool probed = false;                                 // every probe of the lab ran
  std::set<std::string> differing;                     // then: the parts that differ
  bool volume_counted = true;
};
constexpr const char* kNamingInputsFile = "naming.json";
std::vector<LikelyMistake> likely_mistakes(const MistakeSignatures& signatures, int lab, const NamingInputs& inputs);
nlohmann::json naming_inputs_json(const NamingInputs& inputs);
// Throws kit::Error naming what is missing where `json` is not naming_inputs_json's.
NamingInputs naming_inputs_from_json(const nlohmann::json& json);

}  // namespace kit::grade

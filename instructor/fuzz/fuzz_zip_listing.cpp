// libFuzzer harness: the grader's zip listing parser, kit::grade::layout_from_zip_listing
// (tools/grade/submission.*), which turns `unzip -Z1` output into the layout
// decisions (which folder each lab's files come from, which entries to extract)
// before anything is extracted.
//
// The input's first byte picks the labs graded (bit n-1 for lab n; none set: all
// five), the rest is the listing. The function never throws; its result is
// checked against what the grader relies on, and a violation aborts (a finding):
//   - a refused archive picks nothing;
//   - every pick is a line of the listing, never absolute, never with a ".."
//     component (zip-slip), picked once, and graded as "NN-name/file" of a graded lab.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "intake/submission.h"
#include "render/stages.h"

namespace {

[[noreturn]] void violated(const std::string& what, const std::string& entry) {
  std::fprintf(stderr, "fuzz_zip_listing: %s: '%s'\n", what.c_str(), entry.c_str());
  std::abort();
}

bool climbs_or_absolute(const std::string& entry) {
  if (entry.empty() || entry[0] == '/' || entry[0] == '\\' || (entry.size() > 1 && entry[1] == ':')) return true;
  std::string part;
  for (size_t i = 0; i <= entry.size(); ++i) {
    if (i == entry.size() || entry[i] == '/' || entry[i] == '\\') {
      if (part == "..") return true;
      part.clear();
    } else {
      part += entry[i];
    }
  }
  return false;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  std::vector<int> labs;
  for (const kit::Stage& s : kit::stages())
    if (data[0] & (1u << (s.number - 1))) labs.push_back(s.number);
  if (labs.empty())
    for (const kit::Stage& s : kit::stages()) labs.push_back(s.number);
  std::string listing(reinterpret_cast<const char*>(data + 1), size - 1);

  kit::grade::ZipListingLayout result = kit::grade::layout_from_zip_listing(listing, "submission.zip", labs);

  if (!result.problem.empty() && !result.picks.empty()) violated("a refused archive picked entries", result.picks[0].entry);
  std::set<std::string> lines, picked;
  std::istringstream in(listing);
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    lines.insert(line);
  }
  std::set<std::string> keys;
  for (int lab : labs) {
    const kit::Stage& stage = kit::find_stage(lab);
    for (const std::string& f : stage.files) keys.insert(stage.folder + "/" + f);
  }
  for (const kit::grade::ZipPick& pick : result.picks) {
    if (!lines.count(pick.entry)) violated("a pick is not a line of the listing", pick.entry);
    if (climbs_or_absolute(pick.entry)) violated("a pick could be written outside the folder", pick.entry);
    if (!picked.insert(pick.entry).second) violated("an entry is picked twice", pick.entry);
    if (!keys.count(pick.key)) violated("a pick is graded as no graded lab's file", pick.key);
  }
  return 0;
}

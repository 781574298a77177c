#pragma once
// Sanitizing a submission before anything renders it.
//
// A submission is a folder or a .zip holding the student's lab files. Each lab's
// folder (NN-name, matched case-insensitively: 02-Lighting is 02-lighting) is
// looked for at most kMaxWrapperDepth folders below the top: 02-lighting/,
// labs/02-lighting/, alice/labs/02-lighting/, alice/alice/labs/02-lighting/.
// Different labs may come from different places; one lab found in two places is
// refused naming both. With no folder for it, a lab's files lying loose at the
// top or directly inside one top-level folder are taken when that lab is the only
// one graded (--labs 2), and refused with a message saying the layout otherwise.
// Hidden entries and __MACOSX are ignored at every level. The folder each lab came
// from is recorded (LabFiles::folder) and told to the student in the notes.
//
// For every lab graded, only the file names that lab expects (the table in
// common/render/stages.cpp) are copied into a private temporary lab root; the renderer
// never sees anything else. Refused: symbolic links (checked with lstat and opened
// with O_NOFOLLOW; the search never descends into one), anything that is not a
// regular file, hard links (a regular file with more than one name: its other
// name may lie outside the submission; checked with fstat on the descriptor
// opened with O_NOFOLLOW, by kit's safe reader, common/base/safe_file.h), files
// over kit::kMaxShaderFileBytes, and text the shader reader refuses (empty, NUL
// bytes, not UTF-8). A zip is listed first, every line of the listing read, and
// refused as a whole when an entry is absolute or has a ".." component
// (zip-slip), when a name appears twice, or when it lists more than
// kMaxZipEntries entries or more than kMaxZipListingMiB of names; the layout is
// decided on the listing, and only the chosen expected entries are extracted,
// by unzip under limits. An expected entry that is encrypted, over the size
// limit, or damaged (bad CRC, data that does not inflate) is refused by name.
#include <cstddef>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "base/text.h"  // lower_case: lab folders and a batch's own file names match in any case
#include "intake/sandbox.h"

namespace kit::grade {

struct LabFiles {
  bool ready = false;    // every expected file copied and accepted
  std::string status;    // when not ready: "missing_files" or "invalid_files"
  std::string message;   // one line per problem, naming the file
  // Where the files were taken from, relative to the submission ("alice/labs/02-Lighting";
  // "." for the top itself, with loose files); "" when nothing was found for the lab.
  std::string folder;
};

struct PreparedSubmission {
  std::string name;                // folder name or zip name without .zip
  std::filesystem::path lab_root;  // <private temp>/labs, holding NN-name/<expected files>
  std::string problem;             // a problem with the whole submission (every lab scores 0)
  std::vector<std::string> notes;  // information for the student (e.g. the wrapper folder used)
  std::map<int, LabFiles> labs;
  // Zip entries refused before extraction, by "NN-name/file" (over the size limit).
  std::map<std::string, std::string> refused_entries;
};

// `temp` is a fresh private folder the caller removes afterwards.
PreparedSubmission prepare_submission(const std::filesystem::path& submission, const std::vector<int>& labs,
                                      const std::filesystem::path& temp, const Limits& unzip_limits);

// One entry of a zip to extract: its name in the archive, and "NN-name/file" it is graded as.
struct ZipPick {
  std::string entry, key;
};

// What the grader decides from a zip's listing alone (`unzip -Z1` output: one
// entry name per line), before anything is extracted: `problem` when the archive
// is refused as a whole, else the entries to extract for the graded `labs` (lab
// numbers). prepare_submission takes the same decisions with the same code; this
// entry point lets the fuzz harness (instructor/fuzz/fuzz_zip_listing.cpp) check
// them without unzip. `zip_name` only names the archive in messages.
struct ZipListingLayout {
  std::string problem;
  std::vector<ZipPick> picks;
};
ZipListingLayout layout_from_zip_listing(const std::string& listing, const std::string& zip_name,
                                         const std::vector<int>& labs);

// The name a submission is reported under: the folder's name, or the zip's without ".zip".
std::string submission_name(const std::filesystem::path& submission);
bool is_zip(const std::filesystem::path& path);

// Folders a lab folder may sit below the top of a submission (name/name/labs/02-lighting).
constexpr size_t kMaxWrapperDepth = 3;
// More entries than any plausible submission: the whole zip is refused (after
// every entry's name was checked, so an unsafe one is still named).
constexpr size_t kMaxZipEntries = 10000;
// The most unzip may write when listing a zip's names (RLIMIT_FSIZE of its log):
// a longer list refuses the whole zip, since only a complete list can be checked.
constexpr rlim_t kMaxZipListingMiB = 64;

// A fingerprint of what a submission holds, "sha1:<40 hex digits>" (OpenSSL's SHA-1):
// a zip's bytes, or for a folder the sorted relative paths of its entries with each
// regular file's bytes and each symbolic link's target (never followed);
// hidden entries and __MACOSX are left out, as the grader ignores them. A batch
// stores it in summary.json and regrades a submission whose fingerprint changed.
std::string content_hash(const std::filesystem::path& submission);
// A regular file's SHA-1 in 40 lower-case hex digits, "" when it cannot be read
// (links followed only when `follow_links`).
std::string file_digest(const std::filesystem::path& file, bool follow_links);

// How a lab's file is named in messages: "labs/02-lighting/brdf.glsl" (the
// folder label kit::stage_library gives the private lab root).
std::string shown_name(const std::string& folder, const std::string& file);

}  // namespace kit::grade

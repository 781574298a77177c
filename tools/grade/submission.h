#pragma once
// Sanitizing a submission before anything renders it.
//
// A submission is a folder or a .zip holding the student's lab files in the
// labs/ layout (NN-name/file), directly or under one wrapper folder
// (labs/02-lighting/..., alice/02-lighting/...). For every lab graded, only the
// file names that lab expects (the table in framework/stages.cpp) are copied into a
// private temporary lab root; the renderer never sees anything else. Refused:
// symbolic links (checked with lstat and opened with O_NOFOLLOW), anything that
// is not a regular file, files over kit::kMaxShaderFileBytes, and text the
// shader reader refuses (empty, NUL bytes, not UTF-8). A zip is listed first and
// refused as a whole when an entry is absolute or has a ".." component
// (zip-slip); only the expected entries are extracted, by unzip under limits.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "sandbox.h"

namespace kit::grade {

struct LabFiles {
  bool ready = false;    // every expected file copied and accepted
  std::string status;    // when not ready: "missing_files" or "invalid_files"
  std::string message;   // one line per problem, naming the file
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

// The name a submission is reported under: the folder's name, or the zip's without ".zip".
std::string submission_name(const std::filesystem::path& submission);
bool is_zip(const std::filesystem::path& path);

// How a lab's file is named in messages: "labs/02-lighting/brdf.glsl" (the
// folder label kit::stage_library gives the private lab root).
std::string shown_name(const std::string& folder, const std::string& file);

}  // namespace kit::grade

#include "submission.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>

#include "error.h"
#include "shader_source.h"
#include "stages.h"

namespace fs = std::filesystem;

namespace kit::grade {

namespace {

// Name of the private lab root: messages then read "labs/02-lighting/brdf.glsl",
// the layout students work in.
constexpr const char* kLabRootName = "labs";
// More entries than any plausible submission: refuse instead of listing on.
constexpr size_t kMaxZipEntries = 10000;
// Wall-clock limit for one unzip run (listing or extracting a few small files).
constexpr double kUnzipSeconds = 20.0;
// Folders archivers add that never hold lab files.
bool ignored_top_entry(const std::string& name) { return name.empty() || name[0] == '.' || name == "__MACOSX"; }

enum class Kind { Missing, Directory, Regular, Symlink, Other };

Kind entry_kind(const fs::path& p) {
  struct stat st {};
  if (lstat(p.c_str(), &st) != 0) return Kind::Missing;
  if (S_ISLNK(st.st_mode)) return Kind::Symlink;
  if (S_ISDIR(st.st_mode)) return Kind::Directory;
  if (S_ISREG(st.st_mode)) return Kind::Regular;
  return Kind::Other;
}

const Stage* stage_for_folder(const std::string& folder) {
  for (const Stage& s : stages())
    if (s.folder == folder) return &s;
  return nullptr;
}

bool has_lab_folder(const fs::path& dir) {
  for (const Stage& s : stages())
    if (entry_kind(dir / s.folder) == Kind::Directory) return true;
  return false;
}

std::string list_names(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "'" : ", '") + n + "'";
  return out;
}

// Copies one expected file without following links; "" on success, else why not.
std::string copy_regular_file(const fs::path& from, const fs::path& to, const std::string& shown) {
  int in = open(from.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
  if (in < 0) {
    if (errno == ELOOP) return shown + " is a symbolic link: refused (submit the file itself)";
    return shown + ": cannot open (" + std::strerror(errno) + ")";
  }
  struct stat st {};
  std::string problem;
  if (fstat(in, &st) != 0 || !S_ISREG(st.st_mode)) {
    problem = shown + " is not a regular file: refused";
  } else if (static_cast<std::uintmax_t>(st.st_size) > kMaxShaderFileBytes) {
    problem = shown + ": file is " + std::to_string(st.st_size) + " bytes, over the " +
              std::to_string(kMaxShaderFileBytes) + "-byte limit for a shader (kit::kMaxShaderFileBytes): refused";
  } else {
    // Read at most one byte past the limit, whatever the size said a moment ago.
    std::string data(static_cast<size_t>(kMaxShaderFileBytes) + 1, '\0');
    size_t used = 0;
    while (used < data.size()) {
      ssize_t n = read(in, data.data() + used, data.size() - used);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      used += static_cast<size_t>(n);
    }
    if (used > kMaxShaderFileBytes) {
      problem = shown + ": file grew over the " + std::to_string(kMaxShaderFileBytes) + "-byte limit: refused";
    } else {
      std::ofstream out(to, std::ios::binary);
      out.write(data.data(), static_cast<std::streamsize>(used));
      if (!out) problem = shown + ": could not be copied for grading";
    }
  }
  close(in);
  return problem;
}

// Picks the folder holding the NN-name lab folders: the submission itself, or
// the one wrapper folder below it that holds them.
fs::path find_lab_root(const fs::path& top, PreparedSubmission& out) {
  if (has_lab_folder(top)) return top;
  std::vector<std::string> wrappers, seen;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(top, ec)) {
    std::string name = entry.path().filename().string();
    if (ignored_top_entry(name)) continue;
    Kind kind = entry_kind(entry.path());
    seen.push_back(name + (kind == Kind::Directory ? "/" : kind == Kind::Symlink ? " (symbolic link, ignored)" : ""));
    if (kind == Kind::Directory && has_lab_folder(entry.path())) wrappers.push_back(name);
  }
  std::sort(seen.begin(), seen.end());
  if (wrappers.size() == 1) {
    out.notes.push_back("lab folders found in '" + wrappers[0] + "/'");
    return top / wrappers[0];
  }
  if (wrappers.size() > 1) {
    std::sort(wrappers.begin(), wrappers.end());
    out.problem = "lab folders were found in several folders (" + list_names(wrappers) +
                  "): submit one set, as NN-name/ folders or inside one folder";
    return {};
  }
  out.notes.push_back("no lab folder (01-gbuffer, 02-lighting, ...) found" +
                      (seen.empty() ? std::string(": the submission is empty") : " among: " + list_names(seen)));
  return top;
}

void prepare_lab(const Stage& stage, const fs::path& root, const PreparedSubmission& sub, LabFiles& lab) {
  const fs::path& lab_root = sub.lab_root;
  std::vector<std::string> missing, refused;
  fs::path source_dir = root / stage.folder;
  Kind folder_kind = root.empty() ? Kind::Missing : entry_kind(source_dir);
  std::string shown_folder = std::string(kLabRootName) + "/" + stage.folder;
  if (folder_kind == Kind::Symlink || folder_kind == Kind::Other || folder_kind == Kind::Regular) {
    refused.push_back(shown_folder + " is " + (folder_kind == Kind::Symlink ? "a symbolic link" : "not a folder") +
                      ": refused (submit the folder itself)");
  } else {
    fs::create_directories(lab_root / stage.folder);
    for (const std::string& file : stage.files) {
      std::string shown = shown_name(stage.folder, file);
      fs::path from = source_dir / file;
      auto archive_refusal = sub.refused_entries.find(stage.folder + "/" + file);
      if (archive_refusal != sub.refused_entries.end()) {
        refused.push_back(archive_refusal->second);
        continue;
      }
      Kind kind = folder_kind == Kind::Missing ? Kind::Missing : entry_kind(from);
      if (kind == Kind::Missing) {
        missing.push_back(shown);
        continue;
      }
      if (kind == Kind::Symlink) {
        refused.push_back(shown + " is a symbolic link: refused (submit the file itself)");
        continue;
      }
      if (kind != Kind::Regular) {
        refused.push_back(shown + " is not a regular file: refused");
        continue;
      }
      fs::path to = lab_root / stage.folder / file;
      std::string problem = copy_regular_file(from, to, shown);
      if (problem.empty()) {
        try {
          read_shader_text(to, shown);  // empty, binary, not UTF-8: the kit's own reader decides
        } catch (const Error& e) {
          problem = std::string(e.what()) + ": refused";
        }
      }
      if (!problem.empty()) refused.push_back(problem);
    }
  }
  std::string message;
  for (const std::string& r : refused) message += r + "\n";
  if (!missing.empty()) message += "not in the submission: " + list_names(missing) + "\n";
  lab.ready = refused.empty() && missing.empty();
  lab.status = lab.ready ? "" : !refused.empty() ? "invalid_files" : "missing_files";
  lab.message = message;
}

std::vector<std::string> split_path(const std::string& entry) {
  std::vector<std::string> parts;
  std::string part;
  for (char c : entry) {
    if (c == '/' || c == '\\') {
      if (!part.empty()) parts.push_back(part);
      part.clear();
    } else {
      part += c;
    }
  }
  if (!part.empty()) parts.push_back(part);
  return parts;
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (!line.empty()) lines.push_back(line);
  }
  return lines;
}

// unzip's wildcard characters matched literally ("[" becomes "[[]").
std::string unzip_literal(const std::string& name) {
  std::string out;
  for (char c : name) {
    if (c == '[' || c == '*' || c == '?') out += std::string("[") + c + "]";
    else out += c;
  }
  return out;
}

// Runs unzip with `args`; its output in *output. False when it could not finish.
bool run_unzip(const std::vector<std::string>& args, const Limits& base, const fs::path& log, std::string* output,
               std::string* why) {
  Limits limits = base;
  limits.wall_seconds = kUnzipSeconds;
  Child child = Child::exec_program(args, limits, log);
  const Outcome& o = child.wait();
  *output = read_tail(log, 4 * 1024 * 1024);
  bool ok = o.kind == Outcome::Kind::Exited && (o.code == 0 || o.code == 1);  // 1: warnings only
  if (!ok) *why = "unzip ended with " + o.describe();
  return ok;
}

// Lists, checks and extracts the expected entries of a zip into `dest`.
// Returns "" or a problem with the whole archive.
std::string extract_zip(const fs::path& zip, const fs::path& dest, const fs::path& temp, const Limits& limits,
                        PreparedSubmission& out) {
  std::string listing, why;
  if (!run_unzip({"unzip", "-Z1", zip.string()}, limits, temp / "unzip-list.log", &listing, &why))
    return zip.filename().string() + ": not a readable zip archive (" + why + ")";
  std::vector<std::string> entries = lines_of(listing);
  if (entries.size() > kMaxZipEntries)
    return zip.filename().string() + ": " + std::to_string(entries.size()) + " entries, more than the " +
           std::to_string(kMaxZipEntries) + " accepted: refused";
  std::vector<std::string> unsafe;
  for (const std::string& e : entries) {
    std::vector<std::string> parts = split_path(e);
    bool absolute = e[0] == '/' || e[0] == '\\' || (e.size() > 1 && e[1] == ':');
    bool climbs = std::find(parts.begin(), parts.end(), "..") != parts.end();
    if (absolute || climbs) unsafe.push_back(e);
  }
  // The same name twice (say a link, then a file) could make unzip write through the first.
  std::set<std::string> names;
  for (const std::string& e : entries)
    if (!names.insert(e).second) unsafe.push_back(e);
  if (!unsafe.empty()) {
    if (unsafe.size() > 5) unsafe.resize(5);
    return zip.filename().string() + ": refused, nothing was extracted: entries with an absolute path or a '..' "
           "component would be written outside the submission folder, and a name may appear only once (" +
           list_names(unsafe) + ")";
  }
  // Expected entries: NN-name/file, or W/NN-name/file under one wrapper W.
  std::vector<std::string> direct;
  std::map<std::string, std::vector<std::string>> wrapped;
  for (const std::string& e : entries) {
    std::vector<std::string> parts = split_path(e);
    size_t n = parts.size();
    if (n < 2 || n > 3 || e.back() == '/') continue;
    const Stage* stage = stage_for_folder(parts[n - 2]);
    if (!stage || std::find(stage->files.begin(), stage->files.end(), parts[n - 1]) == stage->files.end()) continue;
    if (n == 2) direct.push_back(e);
    else if (!ignored_top_entry(parts[0])) wrapped[parts[0]].push_back(e);
  }
  std::vector<std::string> selected = direct;
  if (direct.empty() && wrapped.size() > 1) {
    std::vector<std::string> names;
    for (const auto& [w, list] : wrapped) names.push_back(w);
    return zip.filename().string() + ": lab folders were found in several folders (" + list_names(names) +
           "): submit one set";
  }
  if (direct.empty() && wrapped.size() == 1) {
    // Entry names are passed to unzip as arguments: one starting with '-' would be read as an option.
    if (wrapped.begin()->first[0] == '-')
      return zip.filename().string() + ": the folder '" + wrapped.begin()->first +
             "' starts with '-': rename it (or zip the lab folders themselves)";
    selected = wrapped.begin()->second;
  }
  if (selected.empty()) return "";  // every lab reports its missing files
  // Declared sizes first, so an oversized entry is refused by name, not extracted.
  std::string long_listing;
  if (!run_unzip({"unzip", "-Zl", zip.string()}, limits, temp / "unzip-sizes.log", &long_listing, &why))
    return zip.filename().string() + ": not a readable zip archive (" + why + ")";
  std::set<std::string> oversized;
  for (const std::string& line : lines_of(long_listing)) {
    // zipinfo -l: perms version os size type csize method date time name
    std::istringstream fields(line);
    std::string f[9];
    for (std::string& field : f) fields >> field;
    std::string name;
    std::getline(fields, name);
    size_t start = name.find_first_not_of(' ');
    name = start == std::string::npos ? "" : name.substr(start);
    if (std::find(selected.begin(), selected.end(), name) == selected.end()) continue;
    try {
      if (std::stoull(f[3]) > kMaxShaderFileBytes) oversized.insert(name);
    } catch (const std::exception&) {
    }
  }
  std::vector<std::string> args = {"unzip", "-qq", "-o", zip.string()};
  for (const std::string& e : selected) {
    std::vector<std::string> parts = split_path(e);
    std::string key = parts[parts.size() - 2] + "/" + parts.back();
    if (oversized.count(e)) {
      // Reported by its lab as refused rather than missing.
      out.refused_entries[key] = shown_name(parts[parts.size() - 2], parts.back()) + ": over the " +
                                 std::to_string(kMaxShaderFileBytes) +
                                 "-byte limit for a shader (kit::kMaxShaderFileBytes) in the archive: refused";
      continue;
    }
    args.push_back(unzip_literal(e));
  }
  args.push_back("-d");
  args.push_back(dest.string());
  fs::create_directories(dest);
  if (args.size() > 6) {
    // The declared sizes can lie: the written size is capped as well.
    Limits capped = limits;
    capped.file_size_mib = 1 + kMaxShaderFileBytes / (1024 * 1024);
    std::string output;
    if (!run_unzip(args, capped, temp / "unzip-extract.log", &output, &why))
      out.notes.push_back(zip.filename().string() + ": extraction incomplete (" + why + ")");
  }
  return "";
}

}  // namespace

bool is_zip(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return ext == ".zip";
}

std::string submission_name(const fs::path& submission) {
  fs::path p = submission;
  if (p.filename().empty()) p = p.parent_path();  // "alice/"
  return is_zip(p) ? p.stem().string() : p.filename().string();
}

std::string shown_name(const std::string& folder, const std::string& file) {
  return std::string(kLabRootName) + "/" + folder + "/" + file;
}

PreparedSubmission prepare_submission(const fs::path& submission, const std::vector<int>& labs, const fs::path& temp,
                                      const Limits& unzip_limits) {
  PreparedSubmission out;
  out.name = submission_name(submission);
  out.lab_root = temp / kLabRootName;
  fs::create_directories(out.lab_root);
  std::error_code ec;
  fs::path top = submission;
  if (is_zip(submission) && fs::is_regular_file(submission, ec)) {
    top = temp / "unzipped";
    out.problem = extract_zip(submission, top, temp, unzip_limits, out);
  } else if (!fs::is_directory(submission, ec)) {
    out.problem = submission.string() + ": not a folder or a .zip archive";
  }
  fs::path root;
  if (out.problem.empty() && fs::is_directory(top, ec)) root = find_lab_root(top, out);
  for (int lab : labs) {
    LabFiles& files = out.labs[lab];
    if (!out.problem.empty()) {
      files.status = "invalid_files";
      files.message = out.problem + "\n";
      continue;
    }
    prepare_lab(find_stage(std::to_string(lab)), root, out, files);
  }
  return out;
}

}  // namespace kit::grade

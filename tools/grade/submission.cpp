#include "submission.h"

#include <OpenImageIO/hash.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdint>
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
// How deep the tree is looked at: the wrappers, one more (to name a lab folder
// that is too deep), the lab folder and its files.
constexpr size_t kMaxTreeParts = kMaxWrapperDepth + 1 + 2;
// Entries a folder's search looks at before it stops (a whole build tree is not a submission).
constexpr size_t kMaxTreeEntries = 20000;

// Names archivers and systems add that never hold lab files (ignored at every level).
bool ignored_name(const std::string& name) { return name.empty() || name[0] == '.' || name == "__MACOSX"; }

enum class Kind { Missing, Directory, Regular, Symlink, Other };

Kind entry_kind(const fs::path& p) {
  struct stat st {};
  if (lstat(p.c_str(), &st) != 0) return Kind::Missing;
  if (S_ISLNK(st.st_mode)) return Kind::Symlink;
  if (S_ISDIR(st.st_mode)) return Kind::Directory;
  if (S_ISREG(st.st_mode)) return Kind::Regular;
  return Kind::Other;
}

std::string list_names(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "'" : ", '") + n + "'";
  return out;
}

std::string lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return std::tolower(c); });
  return text;
}

std::string join(const std::vector<std::string>& parts) {
  std::string out;
  for (const std::string& p : parts) out += (out.empty() ? "" : "/") + p;
  return out;
}

std::vector<std::string> plus(std::vector<std::string> parts, const std::string& name) {
  parts.push_back(name);
  return parts;
}

// "the top of the submission" or "'alice/labs/'".
std::string shown_place(const std::vector<std::string>& folder) {
  return folder.empty() ? std::string("the top of the submission") : "'" + join(folder) + "/'";
}

// "at the top of the submission" or "in 'alice/'".
std::string where_loose(const std::vector<std::string>& folder) {
  return (folder.empty() ? "at " : "in ") + shown_place(folder);
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


// What a submission holds, as far down as the layout is looked for: relative
// paths ('/'-separated) from a folder walk that never follows a link, or from a
// zip's listing (its folders implied by the entries' paths). Ignored names are left out.
struct TreeEntry {
  std::vector<std::string> parts;
  Kind kind = Kind::Missing;
  std::string zip_name;  // the entry's name in the archive (files of a zip only)
};

struct Tree {
  std::map<std::string, TreeEntry> entries;  // by relative path
  bool truncated = false;                    // kMaxTreeEntries reached
  bool has(const std::vector<std::string>& parts) const { return entries.count(join(parts)) > 0; }
};

void walk_folder(const fs::path& dir, std::vector<std::string>& parts, Tree& tree) {
  std::vector<std::string> names;
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    if (names.size() > kMaxTreeEntries) break;
    names.push_back(it->path().filename().string());
  }
  std::sort(names.begin(), names.end());
  for (const std::string& name : names) {
    if (ignored_name(name)) continue;
    if (tree.entries.size() >= kMaxTreeEntries) {
      tree.truncated = true;
      return;
    }
    parts.push_back(name);
    Kind kind = entry_kind(dir / name);
    tree.entries[join(parts)] = {parts, kind, ""};
    if (kind == Kind::Directory && parts.size() < kMaxTreeParts) walk_folder(dir / name, parts, tree);
    parts.pop_back();
  }
}

void add_zip_entry(const std::string& entry, Tree& tree) {
  std::vector<std::string> parts = split_path(entry);
  if (parts.empty() || parts.size() > kMaxTreeParts) return;
  if (std::any_of(parts.begin(), parts.end(), ignored_name)) return;
  for (size_t n = 1; n < parts.size(); ++n) {
    std::vector<std::string> folder(parts.begin(), parts.begin() + static_cast<std::ptrdiff_t>(n));
    tree.entries.emplace(join(folder), TreeEntry{folder, Kind::Directory, ""});
  }
  bool folder = entry.back() == '/' || entry.back() == '\\';
  tree.entries[join(parts)] = {parts, folder ? Kind::Directory : Kind::Regular, folder ? "" : entry};
}

// Where one lab's files are taken from, decided on the tree.
struct LabSource {
  bool found = false;
  std::vector<std::string> folder;  // relative to the top; empty: the top itself
  bool loose = false;               // the files lie outside a lab folder
  std::string problem;              // the layout is refused: the lab scores 0 with this message
};

bool holds_any(const Tree& tree, const std::vector<std::string>& folder, const Stage& stage) {
  return std::any_of(stage.files.begin(), stage.files.end(),
                     [&](const std::string& f) { return tree.has(plus(folder, f)); });
}

bool is_lab_folder_name(const std::string& name) {
  std::string l = lower(name);
  return std::any_of(stages().begin(), stages().end(), [&](const Stage& s) { return s.folder == l; });
}

LabSource find_lab_source(const Tree& tree, const Stage& stage, size_t labs_graded) {
  LabSource source;
  // Folders named like the lab's (any case) within reach, and any just too deep.
  std::vector<const TreeEntry*> near, deep;
  for (const auto& [key, e] : tree.entries) {
    if (lower(e.parts.back()) != stage.folder) continue;
    (e.parts.size() - 1 <= kMaxWrapperDepth ? near : deep).push_back(&e);
  }
  // A folder of that name holding none of the lab's files (say a folder of
  // screenshots), or a plain file of that name, gives way to a folder that holds
  // them; a link or a device of that name does not, so that it is refused by name.
  std::vector<const TreeEntry*> holding;
  for (const TreeEntry* e : near)
    if (e->kind == Kind::Directory ? holds_any(tree, e->parts, stage) : e->kind != Kind::Regular) holding.push_back(e);
  const std::vector<const TreeEntry*>& choice = holding.empty() ? near : holding;
  if (choice.size() == 1) {
    source.found = true;
    source.folder = choice[0]->parts;
    return source;
  }
  if (choice.size() > 1) {
    std::vector<std::string> places;
    for (const TreeEntry* e : choice) places.push_back(join(e->parts) + "/");
    source.problem = "the lab folder " + stage.folder + " was found in " + std::to_string(places.size()) +
                     " places (" + list_names(places) +
                     "): the grader will not pick one; keep the one to grade and submit again";
    return source;
  }
  if (!deep.empty()) {
    source.problem = "'" + join(deep[0]->parts) + "/' is " + std::to_string(deep[0]->parts.size() - 1) +
                     " folders deep: lab folders are looked for at most " + std::to_string(kMaxWrapperDepth) +
                     " folders deep (" + stage.folder + "/, labs/" + stage.folder + "/, name/labs/" + stage.folder +
                     "/ or name/name/labs/" + stage.folder + "/): submit a folder nearer to it";
    return source;
  }
  // No lab folder: the lab's files lying loose at the top or directly inside
  // one top-level folder (not another lab's).
  std::vector<std::vector<std::string>> places;
  if (holds_any(tree, {}, stage)) places.push_back({});
  for (const auto& [key, e] : tree.entries)
    if (e.parts.size() == 1 && e.kind == Kind::Directory && !is_lab_folder_name(e.parts[0]) &&
        holds_any(tree, e.parts, stage))
      places.push_back(e.parts);
  if (places.empty()) return source;  // nothing: the lab lists its missing files
  std::vector<std::string> files;
  for (const std::string& f : stage.files)
    if (tree.has(plus(places[0], f))) files.push_back(f);
  std::string example = stage.folder + "/" + stage.files[0];
  if (labs_graded > 1) {
    source.problem = "no " + stage.folder + "/ folder: " + list_names(files) + " lie loose " +
                     where_loose(places[0]) + ". Loose files are accepted only when one lab is graded (--labs " +
                     std::to_string(stage.number) + "); with several labs each lab's files go in its own folder: " +
                     example + " or labs/" + example;
    return source;
  }
  if (places.size() > 1) {
    std::vector<std::string> shown;
    for (const auto& p : places) shown.push_back(p.empty() ? "./" : join(p) + "/");
    source.problem = "the lab's files lie loose in " + std::to_string(places.size()) + " places (" +
                     list_names(shown) + "): the grader will not pick one; keep one copy, or put it in " +
                     stage.folder + "/";
    return source;
  }
  source.found = true;
  source.loose = true;
  source.folder = places[0];
  return source;
}

// The top-level entries, for the note that says nothing was found.
std::vector<std::string> top_entries(const Tree& tree) {
  std::vector<std::string> seen;
  for (const auto& [key, e] : tree.entries)
    if (e.parts.size() == 1)
      seen.push_back(e.parts[0] + (e.kind == Kind::Directory ? "/" : e.kind == Kind::Symlink ? " (symbolic link, ignored)" : ""));
  return seen;
}

void prepare_lab(const Stage& stage, const fs::path& top, const LabSource& source, const PreparedSubmission& sub,
                 LabFiles& lab) {
  if (!source.problem.empty()) {
    lab.ready = false;
    lab.status = "invalid_files";
    lab.message = source.problem + "\n";
    return;
  }
  const fs::path& lab_root = sub.lab_root;
  std::vector<std::string> missing, refused;
  fs::path source_dir = top;
  for (const std::string& part : source.folder) source_dir /= part;
  Kind folder_kind = source.found ? entry_kind(source_dir) : Kind::Missing;
  if (source.found) lab.folder = source.folder.empty() ? "." : join(source.folder);
  std::string shown_folder = "'" + join(source.folder) + "'";
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


// Lists a zip into `tree` after its safety checks. Returns "" or a problem with the whole archive.
std::string list_zip(const fs::path& zip, const fs::path& temp, const Limits& limits, Tree& tree) {
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
  for (const std::string& e : entries) add_zip_entry(e, tree);
  return "";
}

// One entry to extract: its name in the archive, and "NN-name/file" it is graded as.
struct ZipPick {
  std::string entry, key;
};

// Extracts the chosen entries of a zip into `dest`. Returns "" or a problem with the whole archive.
std::string extract_zip(const fs::path& zip, const fs::path& dest, const fs::path& temp, const Limits& limits,
                        const std::vector<ZipPick>& picks, PreparedSubmission& out) {
  if (picks.empty()) return "";  // every lab reports its missing files
  // Entry names are passed to unzip as arguments: one starting with '-' would be read as an option.
  for (const ZipPick& p : picks)
    if (p.entry[0] == '-')
      return zip.filename().string() + ": the folder '" + split_path(p.entry)[0] +
             "' starts with '-': rename it (or zip the lab folders themselves)";
  // Declared sizes first, so an oversized entry is refused by name, not extracted.
  std::string long_listing, why;
  if (!run_unzip({"unzip", "-Zl", zip.string()}, limits, temp / "unzip-sizes.log", &long_listing, &why))
    return zip.filename().string() + ": not a readable zip archive (" + why + ")";
  std::set<std::string> picked, oversized;
  for (const ZipPick& p : picks) picked.insert(p.entry);
  for (const std::string& line : lines_of(long_listing)) {
    // zipinfo -l: perms version os size type csize method date time name
    std::istringstream fields(line);
    std::string f[9];
    for (std::string& field : f) fields >> field;
    std::string name;
    std::getline(fields, name);
    size_t start = name.find_first_not_of(' ');
    name = start == std::string::npos ? "" : name.substr(start);
    if (!picked.count(name)) continue;
    try {
      if (std::stoull(f[3]) > kMaxShaderFileBytes) oversized.insert(name);
    } catch (const std::exception&) {
    }
  }
  std::vector<std::string> args = {"unzip", "-qq", "-o", zip.string()};
  for (const ZipPick& p : picks) {
    if (oversized.count(p.entry)) {
      // Reported by its lab as refused rather than missing.
      size_t slash = p.key.find('/');
      out.refused_entries[p.key] = shown_name(p.key.substr(0, slash), p.key.substr(slash + 1)) + ": over the " +
                                   std::to_string(kMaxShaderFileBytes) +
                                   "-byte limit for a shader (kit::kMaxShaderFileBytes) in the archive: refused";
      continue;
    }
    args.push_back(unzip_literal(p.entry));
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

// Feeds `file`'s bytes to `sha`; false when it cannot be read. Links are not
// followed, and a FIFO never blocks (O_NONBLOCK, then only regular files are read).
bool hash_file(OIIO::SHA1& sha, const fs::path& file, bool follow) {
  int fd = open(file.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | (follow ? 0 : O_NOFOLLOW));
  if (fd < 0) return false;
  struct stat st {};
  bool ok = fstat(fd, &st) == 0 && S_ISREG(st.st_mode);
  std::vector<char> buffer(1 << 16);
  while (ok) {
    ssize_t n = read(fd, buffer.data(), buffer.size());
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) ok = false;
    if (n <= 0) break;
    sha.append(buffer.data(), static_cast<size_t>(n));
  }
  close(fd);
  return ok;
}

// Every entry of a folder, by relative path, without following links or entering ignored names.
void list_all(const fs::path& dir, const std::string& prefix, std::vector<std::pair<std::string, fs::path>>& out) {
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    std::string name = it->path().filename().string();
    if (ignored_name(name)) continue;
    std::string rel = prefix.empty() ? name : prefix + "/" + name;
    out.push_back({rel, it->path()});
    if (entry_kind(it->path()) == Kind::Directory) list_all(it->path(), rel, out);
  }
}

}  // namespace

std::string content_hash(const fs::path& submission) {
  OIIO::SHA1 sha;
  // Length-prefixed fields, so no two different trees feed the same bytes.
  auto field = [&sha](const std::string& text) {
    std::uint64_t n = text.size();
    sha.append(&n, sizeof n);
    sha.append(text.data(), text.size());
  };
  std::error_code ec;
  if (is_zip(submission) && fs::is_regular_file(submission, ec)) {
    field("zip");
    if (!hash_file(sha, submission, true)) field("unreadable");
    return "sha1:" + lower(sha.digest());
  }
  field("folder");
  std::vector<std::pair<std::string, fs::path>> entries;
  list_all(submission, "", entries);
  std::sort(entries.begin(), entries.end());
  for (const auto& [rel, path] : entries) {
    field(rel);
    switch (entry_kind(path)) {
      case Kind::Directory: field("folder"); break;
      case Kind::Symlink: field("link"); field(fs::read_symlink(path, ec).string()); break;
      case Kind::Regular: {
        // The file's own digest: its bytes need no length prefix.
        OIIO::SHA1 file_sha;
        field(hash_file(file_sha, path, false) ? "file" : "unreadable file");
        field(file_sha.digest());
        break;
      }
      default: field("other"); break;
    }
  }
  return "sha1:" + lower(sha.digest());
}

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
  Tree tree;
  bool zip = is_zip(submission) && fs::is_regular_file(submission, ec);
  if (zip) {
    top = temp / "unzipped";
    out.problem = list_zip(submission, temp, unzip_limits, tree);
  } else if (fs::is_directory(submission, ec)) {
    std::vector<std::string> parts;
    walk_folder(submission, parts, tree);
  } else {
    out.problem = submission.string() + ": not a folder or a .zip archive";
  }
  std::map<int, LabSource> sources;
  if (out.problem.empty())
    for (int lab : labs) sources[lab] = find_lab_source(tree, find_stage(std::to_string(lab)), labs.size());
  if (zip && out.problem.empty()) {
    std::vector<ZipPick> picks;
    for (const auto& [lab, source] : sources) {
      if (!source.found || !source.problem.empty()) continue;
      const Stage& stage = find_stage(std::to_string(lab));
      for (const std::string& file : stage.files) {
        auto it = tree.entries.find(join(plus(source.folder, file)));
        if (it != tree.entries.end() && !it->second.zip_name.empty())
          picks.push_back({it->second.zip_name, stage.folder + "/" + file});
      }
    }
    out.problem = extract_zip(submission, top, temp, unzip_limits, picks, out);
  }
  if (out.problem.empty()) {
    // Tell the student where each lab's files were taken from.
    bool any = false;
    for (const auto& [lab, source] : sources) {
      any = any || source.found || !source.problem.empty();
      if (!source.found) continue;
      const Stage& stage = find_stage(std::to_string(lab));
      out.notes.push_back("lab " + std::to_string(lab) + " " + stage.name + ": " +
                          (source.loose ? "loose files taken from " + shown_place(source.folder)
                                        : "files taken from '" + join(source.folder) + "/'"));
    }
    if (!any) {
      std::vector<std::string> seen = top_entries(tree);
      out.notes.push_back("no lab folder (01-gbuffer, 02-lighting, ...) found" +
                          (seen.empty() ? std::string(": the submission is empty")
                                        : " among: " + list_names(seen) + " (lab folders are looked for at most " +
                                              std::to_string(kMaxWrapperDepth) + " folders deep)"));
    }
    if (tree.truncated)
      out.notes.push_back("the submission holds more than " + std::to_string(kMaxTreeEntries) +
                          " files and folders: only the first were searched for lab folders");
  }
  for (int lab : labs) {
    LabFiles& files = out.labs[lab];
    if (!out.problem.empty()) {
      files.status = "invalid_files";
      files.message = out.problem + "\n";
      continue;
    }
    prepare_lab(find_stage(std::to_string(lab)), top, sources[lab], out, files);
  }
  return out;
}

}  // namespace kit::grade

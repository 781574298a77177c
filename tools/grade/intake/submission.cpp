#include "intake/submission.h"

#include <openssl/evp.h>
#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <csignal>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>

#include "base/error.h"
#include "base/safe_file.h"
#include "gl/shader_source.h"
#include "render/stages.h"

namespace fs = std::filesystem;

namespace kit::grade {

namespace {

// Name of the private lab root: messages then read "labs/02-lighting/brdf.glsl",
// the layout students work in.
constexpr const char* kLabRootName = "labs";
// Unsafe or repeated entries named in the message.
constexpr size_t kMaxNamedEntries = 5;
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

// Copies one expected file; "" on success, else why not. Read by kit's safe
// reader: opened with O_NOFOLLOW and without blocking, then checked on the
// descriptor: a regular file, one name only (a hard link's other name may lie
// outside the submission), at most kit::kMaxShaderFileBytes.
std::string copy_regular_file(const fs::path& from, const fs::path& to, const std::string& shown) {
  std::vector<unsigned char> data;
  SafeOpen how;
  how.shown = shown;
  how.refuse_hard_links = true;
  try {
    data = read_regular_file(from, kMaxShaderFileBytes, how);
  } catch (const Error& e) {
    return std::string(e.what()) + ": refused";
  }
  std::ofstream out(to, std::ios::binary);
  out.write(reinterpret_cast<const char*>(data.data()), static_cast<std::streamsize>(data.size()));
  if (!out) return shown + ": could not be copied for grading";
  return "";
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

// Calls `use` with each non-empty line of a stream, however long it is.
void for_each_line(std::istream& in, const std::function<void(const std::string&)>& use) {
  std::string line;
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (!line.empty()) use(line);
  }
}
// The same for a file (a log of ours).
void for_each_line(const fs::path& path, const std::function<void(const std::string&)>& use) {
  std::ifstream in(path, std::ios::binary);
  for_each_line(in, use);
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

// Runs unzip with `args` (absolute paths), its stdout and stderr going to `log`,
// in the folder of the log (the grader's temporary folder).
Outcome run_unzip(const std::vector<std::string>& args, const Limits& base, const fs::path& log) {
  Limits limits = base;
  limits.wall_seconds = kUnzipSeconds;
  ChildSetup setup;
  setup.working_dir = fs::absolute(log).parent_path();
  Child child = Child::exec_program(args, limits, log, setup);
  return child.wait();
}

bool unzip_succeeded(const Outcome& o) {
  return o.kind == Outcome::Kind::Exited && (o.code == 0 || o.code == 1);  // 1: warnings only
}

// The start of unzip's log on one line, for a message.
std::string unzip_said(const fs::path& log) {
  constexpr size_t kMaxSaid = 400;
  std::string text;
  for_each_line(log, [&](const std::string& line) {
    if (text.size() > kMaxSaid) return;
    size_t start = line.find_first_not_of(' ');
    text += (text.empty() ? "" : " ") + line.substr(start == std::string::npos ? 0 : start);
  });
  if (text.size() > kMaxSaid) text = text.substr(0, kMaxSaid) + "...";
  return text;
}

std::string unzip_failed(const std::string& zip, const Outcome& o, const fs::path& log) {
  if (o.kind == Outcome::Kind::Signaled && o.code == SIGXFSZ)
    return zip + ": the list of its entries is over " + std::to_string(kMaxZipListingMiB) +
           " MiB (far more files, or far longer names, than a submission has): refused, nothing was extracted";
  std::string said = unzip_said(log);
  return zip + ": not a readable zip archive (unzip ended with " + o.describe() + (said.empty() ? "" : ": " + said) +
         ")";
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
  std::string l = lower_case(name);
  return std::any_of(stages().begin(), stages().end(), [&](const Stage& s) { return s.folder == l; });
}

LabSource find_lab_source(const Tree& tree, const Stage& stage, size_t labs_graded) {
  LabSource source;
  // Folders named like the lab's (any case) within reach, and any just too deep.
  std::vector<const TreeEntry*> near, deep;
  for (const auto& [key, e] : tree.entries) {
    if (lower_case(e.parts.back()) != stage.folder) continue;
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


// An entry that would be written outside the folder it is extracted into.
bool unsafe_entry(const std::string& e) {
  std::vector<std::string> parts = split_path(e);
  bool absolute = e[0] == '/' || e[0] == '\\' || (e.size() > 1 && e[1] == ':');
  return absolute || std::find(parts.begin(), parts.end(), "..") != parts.end();
}

// Reads a zip's listing (`unzip -Z1`: one entry name per line) into `tree` after
// its safety checks. Returns "" or a problem with the whole archive (`name` names it).
// Every line is read and every entry checked, whatever the listing's length.
std::string tree_from_listing(std::istream& listing, const std::string& name, Tree& tree) {
  size_t count = 0, unsafe_count = 0;
  std::vector<std::string> unsafe, entries;
  std::set<std::string> names;
  for_each_line(listing, [&](const std::string& e) {
    ++count;
    // The same name twice (say a link, then a file) could make unzip write through the first.
    bool bad = unsafe_entry(e) || (count <= kMaxZipEntries && !names.insert(e).second);
    if (bad) {
      if (++unsafe_count <= kMaxNamedEntries) unsafe.push_back(e);
    } else if (count <= kMaxZipEntries) {
      entries.push_back(e);
    }
  });
  if (!unsafe.empty()) {
    std::string more = unsafe_count > unsafe.size() ? " and " + std::to_string(unsafe_count - unsafe.size()) + " more"
                                                    : "";
    return name + ": refused, nothing was extracted: entries with an absolute path or a '..' component would be "
           "written outside the submission folder, and a name may appear only once (" + list_names(unsafe) + more +
           ")";
  }
  if (count > kMaxZipEntries)
    return name + ": " + std::to_string(count) + " entries, more than the " + std::to_string(kMaxZipEntries) +
           " accepted: refused, nothing was extracted";
  for (const std::string& e : entries) add_zip_entry(e, tree);
  return "";
}

// Lists a zip with unzip into `tree` (tree_from_listing). Returns "" or a problem with the whole archive.
std::string list_zip(const fs::path& zip, const fs::path& temp, const Limits& limits, Tree& tree) {
  const std::string name = zip.filename().string();
  const fs::path log = temp / "unzip-list.log";
  Limits listing = limits;
  listing.file_size_mib = kMaxZipListingMiB;
  Outcome o = run_unzip({"unzip", "-Z1", fs::absolute(zip).string()}, listing, log);
  if (!unzip_succeeded(o)) return unzip_failed(name, o, log);
  std::ifstream in(log, std::ios::binary);
  return tree_from_listing(in, name, tree);
}

// Where each graded lab's files come from, decided on the tree.
std::map<int, LabSource> lab_sources(const Tree& tree, const std::vector<int>& labs) {
  std::map<int, LabSource> sources;
  for (int lab : labs) sources[lab] = find_lab_source(tree, find_stage(lab), labs.size());
  return sources;
}

// The zip entries to extract: each expected file of each lab whose source was accepted.
std::vector<ZipPick> zip_picks(const Tree& tree, const std::map<int, LabSource>& sources) {
  std::vector<ZipPick> picks;
  for (const auto& [lab, source] : sources) {
    if (!source.found || !source.problem.empty()) continue;
    const Stage& stage = find_stage(lab);
    for (const std::string& file : stage.files) {
      auto it = tree.entries.find(join(plus(source.folder, file)));
      if (it != tree.entries.end() && !it->second.zip_name.empty())
        picks.push_back({it->second.zip_name, stage.folder + "/" + file});
    }
  }
  return picks;
}

void refuse_pick(const ZipPick& p, const std::string& why, PreparedSubmission& out) {
  // Reported by its lab as refused rather than missing.
  size_t slash = p.key.find('/');
  out.refused_entries[p.key] = shown_name(p.key.substr(0, slash), p.key.substr(slash + 1)) + ": refused: " + why;
}

// Why unzip could not test one entry, from its log: encrypted, damaged (bad CRC,
// data that does not inflate) or a compression method it does not know.
std::string damaged_entry(const std::string& entry, const fs::path& log) {
  std::string said = unzip_said(log);
  if (said.find("password") != std::string::npos)
    return "encrypted entries are not supported: '" + entry + "' is encrypted (zip the files again without a password)";
  if (said.find("bad CRC") != std::string::npos)
    return "the archive's entry '" + entry + "' is corrupt: its bytes do not match their CRC checksum (unzip: " + said +
           "); zip the files again";
  if (said.find("compression method") != std::string::npos)
    return "the archive's entry '" + entry + "' uses a compression method unzip cannot read (unzip: " + said +
           "); zip the files again with the zip command or your system's Compress";
  return "the archive's entry '" + entry + "' is corrupt and could not be extracted (unzip: " +
         (said.empty() ? std::string("no message") : said) + "); zip the files again";
}

// Extracts the chosen entries of a zip into `dest`. Returns "" or a problem with the whole archive.
std::string extract_zip(const fs::path& zip, const fs::path& dest, const fs::path& temp, const Limits& limits,
                        const std::vector<ZipPick>& picks, PreparedSubmission& out) {
  if (picks.empty()) return "";  // every lab reports its missing files
  const std::string name = zip.filename().string();
  // Entry names are passed to unzip as arguments: one starting with '-' would be read as an option.
  for (const ZipPick& p : picks)
    if (p.entry[0] == '-')
      return name + ": the folder '" + split_path(p.entry)[0] +
             "' starts with '-': rename it (or zip the lab folders themselves)";
  // Declared sizes and encryption first, so such an entry is refused by name, not extracted.
  const fs::path long_log = temp / "unzip-sizes.log";
  Limits listing = limits;
  listing.file_size_mib = kMaxZipListingMiB;
  const std::string archive = fs::absolute(zip).string();
  Outcome o = run_unzip({"unzip", "-Zl", archive}, listing, long_log);
  if (!unzip_succeeded(o)) return unzip_failed(name, o, long_log);
  std::set<std::string> picked, oversized, encrypted;
  for (const ZipPick& p : picks) picked.insert(p.entry);
  for_each_line(long_log, [&](const std::string& line) {
    // zipinfo -l: perms version os size type csize method date time name; the
    // type's first letter is capitalised (T, B) when the entry is encrypted.
    std::istringstream fields(line);
    std::string f[9];
    for (std::string& field : f) fields >> field;
    std::string entry;
    std::getline(fields, entry);
    size_t start = entry.find_first_not_of(' ');
    entry = start == std::string::npos ? "" : entry.substr(start);
    if (!picked.count(entry)) return;
    if (!f[4].empty() && (f[4][0] == 'T' || f[4][0] == 'B')) encrypted.insert(entry);
    try {
      if (std::stoull(f[3]) > kMaxShaderFileBytes) oversized.insert(entry);
    } catch (const std::exception&) {
    }
  });
  std::vector<const ZipPick*> extract;
  for (const ZipPick& p : picks) {
    if (encrypted.count(p.entry)) {
      refuse_pick(p, "encrypted entries are not supported: '" + p.entry +
                         "' is encrypted (zip the files again without a password)", out);
    } else if (oversized.count(p.entry)) {
      refuse_pick(p, "over the " + std::to_string(kMaxShaderFileBytes) +
                         "-byte limit for a shader (kit::kMaxShaderFileBytes) in the archive", out);
    } else {
      extract.push_back(&p);
    }
  }
  if (extract.empty()) return "";
  std::vector<std::string> args = {"unzip", "-qq", "-o", archive};
  for (const ZipPick* p : extract) args.push_back(unzip_literal(p->entry));
  args.push_back("-d");
  args.push_back(fs::absolute(dest).string());
  fs::create_directories(dest);
  // The declared sizes can lie: the written size is capped as well.
  Limits capped = limits;
  capped.file_size_mib = 1 + kMaxShaderFileBytes / (1024 * 1024);
  Outcome extracted = run_unzip(args, capped, temp / "unzip-extract.log");
  if (unzip_succeeded(extracted)) return "";
  // Something failed: test each entry on its own to name the damaged ones (a
  // bad CRC leaves a file of wrong bytes, bad compressed data an empty one).
  bool named = false;
  for (const ZipPick* p : extract) {
    const fs::path test_log = temp / "unzip-test.log";
    Outcome tested = run_unzip({"unzip", "-tqq", archive, unzip_literal(p->entry)}, limits, test_log);
    if (unzip_succeeded(tested)) continue;
    refuse_pick(*p, damaged_entry(p->entry, test_log), out);
    named = true;
  }
  if (!named) {
    std::string said = unzip_said(temp / "unzip-extract.log");
    out.notes.push_back(name + ": extraction incomplete (unzip ended with " + extracted.describe() +
                        (said.empty() ? "" : ": " + said) + ")");
  }
  return "";
}

// SHA-1 through OpenSSL's EVP interface. digest() is in upper-case hex, as the
// fingerprints stored in summary.json were made (with OpenImageIO's SHA-1).
class Sha1 {
 public:
  Sha1() : context_(EVP_MD_CTX_new()) {
    if (!context_ || EVP_DigestInit_ex(context_, EVP_sha1(), nullptr) != 1) throw Error("kit-grade: SHA-1 is not available");
  }
  ~Sha1() { EVP_MD_CTX_free(context_); }
  Sha1(const Sha1&) = delete;
  Sha1& operator=(const Sha1&) = delete;
  void append(const void* bytes, size_t size) { EVP_DigestUpdate(context_, bytes, size); }
  std::string digest() {
    unsigned char value[EVP_MAX_MD_SIZE];
    unsigned int size = 0;
    EVP_DigestFinal_ex(context_, value, &size);
    static const char kHex[] = "0123456789ABCDEF";
    std::string hex;
    for (unsigned int i = 0; i < size; ++i) {
      hex += kHex[value[i] >> 4];
      hex += kHex[value[i] & 15];
    }
    return hex;
  }

 private:
  EVP_MD_CTX* context_;
};

// Feeds `file`'s bytes to `sha`; false when it cannot be read (kit's safe
// reader: links followed only when `follow`, a FIFO never blocks, regular files only).
bool hash_file(Sha1& sha, const fs::path& file, bool follow) {
  SafeOpen how;
  how.follow_link = follow;
  try {
    stream_regular_file(file, [&sha](const unsigned char* bytes, size_t n) { sha.append(bytes, n); }, how);
    return true;
  } catch (const Error&) {
    return false;
  }
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

std::string file_digest(const fs::path& file, bool follow_links) {
  Sha1 sha;
  return hash_file(sha, file, follow_links) ? lower_case(sha.digest()) : "";
}

std::string content_hash(const fs::path& submission) {
  Sha1 sha;
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
    return "sha1:" + lower_case(sha.digest());
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
        Sha1 file_sha;
        field(hash_file(file_sha, path, false) ? "file" : "unreadable file");
        field(file_sha.digest());
        break;
      }
      default: field("other"); break;
    }
  }
  return "sha1:" + lower_case(sha.digest());
}

bool is_zip(const fs::path& path) {
  return lower_case(path.extension().string()) == ".zip";
}

ZipListingLayout layout_from_zip_listing(const std::string& listing, const std::string& zip_name,
                                         const std::vector<int>& labs) {
  ZipListingLayout out;
  Tree tree;
  std::istringstream in(listing);
  out.problem = tree_from_listing(in, zip_name, tree);
  if (out.problem.empty()) out.picks = zip_picks(tree, lab_sources(tree, labs));
  return out;
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
  if (out.problem.empty()) sources = lab_sources(tree, labs);
  if (zip && out.problem.empty()) {
    std::vector<ZipPick> picks = zip_picks(tree, sources);
    out.problem = extract_zip(submission, top, temp, unzip_limits, picks, out);
  }
  if (out.problem.empty()) {
    // Tell the student where each lab's files were taken from.
    bool any = false;
    for (const auto& [lab, source] : sources) {
      any = any || source.found || !source.problem.empty();
      if (!source.found) continue;
      const Stage& stage = find_stage(lab);
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
    prepare_lab(find_stage(lab), top, sources[lab], out, files);
  }
  return out;
}

}  // namespace kit::grade

#include "reference_store/references.h"

#include <nlohmann/json.hpp>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <set>

#include "base/error.h"
#include "files/files.h"
#include "intake/submission.h"
#include "render/stages.h"

namespace fs = std::filesystem;

namespace kit::grade {

namespace {

constexpr const char* kManifestName = "manifest.json";

nlohmann::json expected_images() {
  nlohmann::json images = nlohmann::json::array();
  for (const RenderSpec* spec : reference_renders()) images.push_back(manifest_entry(*spec));
  return images;
}

nlohmann::json read_manifest(const fs::path& dir) {
  std::ifstream in(dir / kManifestName);
  if (!in)
    throw Error("references missing: " + (dir / kManifestName).string() +
                " does not exist (run kit-grade --update-references)");
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw Error((dir / kManifestName).string() + ": not valid JSON (" + e.what() + ")");
  }
}

// `path` with `suffix` added to its file name.
fs::path suffixed(fs::path path, const std::string& suffix) {
  path += suffix;
  return path;
}

// Removes the cache files of `id`'s other versions: "<id>-<40 hex digits>.<what>" with
// other digits (a bare prefix match would take lab5-default-custom-on-off's files for
// lab5-default-custom-on's).
void remove_older_versions(const fs::path& cache, const std::string& id, const std::string& digest) {
  constexpr size_t kDigits = 40;
  std::error_code ec;
  for (fs::directory_iterator it(cache, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() <= id.size() + 1 + kDigits || name.compare(0, id.size() + 1, id + "-") != 0) continue;
    const std::string digits = name.substr(id.size() + 1, kDigits);
    if (name[id.size() + 1 + kDigits] != '.' || digits == digest ||
        digits.find_first_not_of("0123456789abcdef") != std::string::npos)
      continue;
    std::error_code remove_ec;
    fs::remove(it->path(), remove_ec);
  }
}

constexpr const char* kAllowanceSuffix = ".allowance.exr";

// The image in `file`, decoded once and kept in `cache` as "<key>-<SHA-1 of file>.raw"
// (`stem` receives "<cache>/<key>-<SHA-1>"), or read from `prepared` where it holds that
// file (`*from_prepared` then true, `stem` there). Throws kit::Error when the file cannot be read.
Image read_cached_image(const fs::path& file, const std::string& key, const fs::path& cache, const fs::path& prepared,
                        fs::path* stem, bool* from_prepared) {
  const std::string digest = file_digest(file, true);
  if (digest.empty()) throw Error(file.string() + ": cannot read the reference");
  const std::string name = key + "-" + digest;
  *from_prepared = false;
  if (!prepared.empty()) {
    try {
      Image image = read_raw_image(prepared / (name + ".raw"));
      *stem = prepared / name;
      *from_prepared = true;
      return image;
    } catch (const Error&) {  // not prepared for this version of the file: the cache's
    }
  }
  *stem = cache / name;
  const fs::path raw = suffixed(*stem, ".raw");
  try {
    return read_raw_image(raw);
  } catch (const Error&) {  // not cached yet, or damaged: decoded below
  }
  Image image = read_image(file.string());
  remove_older_versions(cache, key, digest);
  const fs::path temp = suffixed(raw, ".tmp-" + std::to_string(getpid()));
  try {
    write_raw_image(temp, image);
    fs::rename(temp, raw);  // a run beside this one reads the whole file or none
  } catch (const std::exception&) {  // Error, or filesystem_error: the cache is only a cache
    std::error_code ec;
    fs::remove(temp, ec);
  }
  return image;
}

// `spec`'s reference and its filter allowance.
LoadedReference load_reference(const fs::path& dir, const RenderSpec& spec, const fs::path& cache,
                               const fs::path& prepared) {
  LoadedReference reference;
  reference.image = read_cached_image(dir / (spec.id + "." + reference_extension(spec)), spec.id, cache, prepared,
                                      &reference.cache_stem, &reference.prepared);
  // Listed in the manifest wherever it exists (manifest_differences checks that).
  const fs::path allowance = dir / (spec.id + kAllowanceSuffix);
  std::error_code ec;
  if (fs::exists(allowance, ec)) {
    fs::path stem;
    bool from_prepared = false;
    reference.allowance = read_cached_image(allowance, spec.id + ".allowance", cache, prepared, &stem, &from_prepared);
    if (reference.allowance.channels != 1) throw Error(allowance.string() + ": a filter allowance has one channel");
  }
  return reference;
}

}  // namespace

const std::vector<FilterRendering> kFilterRenderings = {
    {"brilinear", "trilinear filtering as GPUs approximate it: only near a level's midpoint are two mip levels blended"},
    {"rho_approx", "the level of detail from an approximate length of the texture coordinates' derivatives"},
    {"brilinear,rho_approx,no_quad_lod", "both, with a level of detail for each pixel rather than each 2x2 quad"},
};

std::map<std::string, Image> filter_allowances(const std::map<std::string, Image>& renders,
                                               const std::vector<std::map<std::string, Image>>& variants) {
  std::map<std::string, Image> out;
  for (const Stage& stage : stages())
    for (const Check* check : lab_checks(stage.number)) {
      auto reference = renders.find(check->reference);
      if (compares_own_renders(check->metric) || reference == renders.end()) continue;
      for (const std::map<std::string, Image>& variant : variants) {
        auto other = variant.find(check->reference);
        if (other == variant.end()) throw Error("the solutions' render '" + check->reference + "' is missing");
        const Image d = pixel_differences(check->metric, other->second, reference->second);
        Image& allowance = out.try_emplace(check->reference, Image(d.width, d.height, 1)).first->second;
        for (size_t i = 0; i < d.pixels.size(); ++i) allowance.pixels[i] = std::max(allowance.pixels[i], d.pixels[i]);
      }
    }
  for (auto it = out.begin(); it != out.end();)
    it = std::all_of(it->second.pixels.begin(), it->second.pixels.end(), [](float v) { return v == 0.0f; })
             ? out.erase(it)
             : std::next(it);
  return out;
}

fs::path default_references_dir() { return kit_root() / "tools" / "grade" / "references"; }

nlohmann::json manifest_entry(const RenderSpec& spec) {
  nlohmann::json entry = {{"id", spec.id},
                          {"file", spec.id + "." + reference_extension(spec)},
                          {"stage", spec.stage},
                          {"scene", spec.scene},
                          {"view", view_name(spec.view)},
                          {"raw", spec.raw},
                          {"gamma", spec.gamma},
                          {"attenuation", spec.attenuation_model == 0 ? "physical" : "simple"},
                          {"postprocess", spec.postprocess},
                          {"custom_effect", spec.custom_effect},
                          {"bloom_threshold", spec.bloom_threshold},
                          {"isolate_custom", spec.isolate_custom}};
  // Only where an environment lights the stage: the other entries stay as they were.
  if (find_stage(spec.stage).ibl) entry["environment"] = environment_name(spec);
  // Kept to describe a failed check's worst pixel, compared by no check (checks.h).
  if (spec.describes_pixels_only) entry["describes_pixels_only"] = true;
  if (spec.light_shares) entry["light_shares"] = true;  // light_shares.h says what it holds
  return entry;
}

namespace {

// Writes `image` to dir/file unless the file there already reads back as the same pixels
// (the new image is written beside it and both are read: a PNG's 8-bit rounding, an EXR's
// floats). Returns whether the file changed.
bool write_if_changed(const fs::path& dir, const std::string& file, const Image& image) {
  const fs::path path = dir / file, fresh = dir / ("." + path.stem().string() + ".new" + path.extension().string());
  write_image(fresh.string(), image);
  if (fs::exists(path)) {
    bool same = false;
    try {
      const Image old = read_image(path.string()), now = read_image(fresh.string());
      same = old.width == now.width && old.height == now.height && old.channels == now.channels &&
             std::equal(old.pixels.begin(), old.pixels.end(), now.pixels.begin(),
                        [](float a, float b) { return a == b || (std::isnan(a) && std::isnan(b)); });
    } catch (const Error&) {
      same = false;  // an unreadable old file is replaced
    }
    if (same) {
      fs::remove(fresh);
      return false;
    }
  }
  fs::rename(fresh, path);
  return true;
}

}  // namespace

std::vector<std::string> write_references(const fs::path& dir, const std::map<std::string, Image>& renders,
                                          const std::map<std::string, Image>& allowances,
                                          const std::string& renderer) {
  fs::create_directories(dir);
  std::set<std::string> wanted;
  std::vector<std::string> changed;
  auto write = [&](const std::string& file, const Image& image) {
    if (write_if_changed(dir, file, image)) changed.push_back(file);
    wanted.insert(file);
  };
  for (const RenderSpec* spec : reference_renders()) {
    auto it = renders.find(spec->id);
    if (it == renders.end()) throw Error("the solutions' render '" + spec->id + "' is missing");
    write(spec->id + "." + reference_extension(*spec), it->second);
  }
  nlohmann::json allowance_ids = nlohmann::json::array(), renderings = nlohmann::json::array();
  for (const auto& [id, allowance] : allowances) {
    write(id + kAllowanceSuffix, allowance);
    allowance_ids.push_back(id);
  }
  if (!allowances.empty())
    for (const FilterRendering& f : kFilterRenderings) renderings.push_back({{"GALLIVM_PERF", f.name}, {"about", f.about}});
  // Files of checks that no longer exist would only confuse.
  for (const auto& entry : fs::directory_iterator(dir)) {
    std::string name = entry.path().filename().string();
    std::string ext = entry.path().extension().string();
    bool ours = name.rfind("lab", 0) == 0 && (ext == ".png" || ext == ".exr");
    if (ours && !wanted.count(name)) {
      fs::remove(entry.path());
      changed.push_back(name + " (removed)");
    }
  }
  nlohmann::json manifest = {
      {"about", "Reference renders of solutions/ for kit-grade. Generated by `kit-grade --update-references`; "
                "checked by `kit-grade --check-references`. Do not edit by hand."},
      {"renderer", renderer},
      {"size", {kGradeWidth, kGradeHeight}},
      {"images", expected_images()},
      {"filter_allowance",
       {{"about", "Per pixel, how far each listed reference moves when the solutions are rendered again under "
                  "GPU-like texture filtering (llvmpipe with each GALLIVM_PERF below): <id>.allowance.exr, in the "
                  "units its checks compare (tools/grade/references.h)."},
        {"renderings", renderings},
        {"images", allowance_ids}}}};
  const std::string text = manifest.dump(1) + "\n";
  std::ifstream in(dir / kManifestName);
  const std::string before((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (before != text) {
    std::ofstream out(dir / kManifestName);
    out << text;
    if (!out) throw Error((dir / kManifestName).string() + ": cannot write");
    changed.push_back(kManifestName);
  }
  return changed;
}

std::string references_renderer(const fs::path& dir) {
  const nlohmann::json manifest = read_manifest(dir);
  return manifest.contains("renderer") && manifest["renderer"].is_string() ? manifest["renderer"].get<std::string>() : "";
}

std::vector<std::string> manifest_differences(const fs::path& dir) {
  nlohmann::json stored = read_manifest(dir);
  std::vector<std::string> out;
  nlohmann::json size = {kGradeWidth, kGradeHeight};
  if (stored.value("size", nlohmann::json()) != size)
    out.push_back("size: the references are " + stored.value("size", nlohmann::json()).dump() + ", the grader renders " + size.dump());
  std::map<std::string, nlohmann::json> have;
  if (stored.contains("images") && stored["images"].is_array())
    for (const auto& e : stored["images"])
      if (e.is_object() && e.contains("id") && e["id"].is_string()) have[e["id"].get<std::string>()] = e;
  std::set<std::string> expected_ids;
  for (const auto& e : expected_images()) {
    std::string id = e["id"];
    expected_ids.insert(id);
    auto it = have.find(id);
    if (it == have.end()) out.push_back(id + ": no reference (a new check)");
    else if (it->second != e) out.push_back(id + ": rendered with other settings than the check list says");
    else if (!fs::exists(dir / e["file"].get<std::string>())) out.push_back(id + ": file " + e["file"].get<std::string>() + " is missing");
  }
  for (const auto& [id, e] : have)
    if (!expected_ids.count(id)) out.push_back(id + ": reference of a check that no longer exists");
  const nlohmann::json allowance = stored.value("filter_allowance", nlohmann::json::object());
  if (!allowance.is_object() || !allowance.value("images", nlohmann::json::array()).is_array())
    out.push_back("filter_allowance: not an object with a list of images");
  else
    for (const auto& id : allowance.value("images", nlohmann::json::array()))
      if (!id.is_string() || !fs::exists(dir / (id.get<std::string>() + kAllowanceSuffix)))
        out.push_back(id.dump() + ": its filter allowance file is missing");
  return out;
}

void require_current_references(const fs::path& dir) {
  std::vector<std::string> problems = manifest_differences(dir);
  if (problems.empty()) return;
  std::string text;
  for (const std::string& p : problems) text += "\n  " + p;
  throw Error("references in " + dir.string() + " are stale (run kit-grade --update-references):" + text);
}

std::map<std::string, LoadedReference> load_lab_references(const fs::path& dir, int lab, const fs::path& cache,
                                                           const fs::path& prepared) {
  std::map<std::string, LoadedReference> out;
  for (const Check* check : lab_checks(lab))
    if (!compares_own_renders(check->metric) && !out.count(check->reference))
      out.emplace(check->reference, load_reference(dir, find_render(check->reference), cache, prepared));
  return out;
}

Image load_describing_reference(const fs::path& dir, const std::string& id, const fs::path& cache,
                                const fs::path& prepared) {
  fs::path stem;
  bool from_prepared = false;
  return read_cached_image(dir / (id + "." + reference_extension(find_render(id))), id, cache, prepared, &stem,
                           &from_prepared);
}

fs::path prepared_references_dir() {
  const char* env = std::getenv("KIT_PREPARED_REFERENCES");
  return fs::path(env ? env : KIT_PREPARED_REFERENCES_DIR);
}

Background cached_background(const LoadedReference& reference, Metric metric) {
  const fs::path path = suffixed(reference.cache_stem, std::string(".") + metric_name(metric) + ".background");
  Background background{};
  {
    std::ifstream in(path, std::ios::binary);
    if (in.read(reinterpret_cast<char*>(background.data()), sizeof background) && in.peek() == EOF) return background;
  }
  background = reference_background(metric, reference.image);
  if (reference.prepared) return background;  // the build's folder is only read
  std::string bytes(reinterpret_cast<const char*>(background.data()), sizeof background);
  try {
    write_file_atomic(path, bytes);
  } catch (const std::exception&) {
  }
  return background;
}

}  // namespace kit::grade

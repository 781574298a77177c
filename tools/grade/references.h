#pragma once
// The reference renders of the solutions (tools/grade/references/): one PNG (display
// images, exact 8-bit values) or EXR (float G-buffer attachments and HDR
// buffers) per reference render, and manifest.json recording the size and the
// settings each was rendered with. `kit-grade --update-references` writes them;
// `--check-references` (and a ctest) re-renders the solutions and fails when
// the code's check list or the solutions no longer match them.
#include <nlohmann/json.hpp>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "checks.h"
#include "compare.h"
#include "images/image_io.h"

namespace kit::grade {

std::filesystem::path default_references_dir();  // <kit root>/tools/grade/references

// The manifest's "images" entry for a render: what it was rendered with.
nlohmann::json manifest_entry(const RenderSpec& spec);

// Writes the references (from the solutions' raw renders, by render id) and the manifest.
void write_references(const std::filesystem::path& dir, const std::map<std::string, Image>& renders,
                      const std::string& renderer);

// What rendered the references: the manifest's "renderer" ("" when it names none).
std::string references_renderer(const std::filesystem::path& dir);

// Differences between the stored manifest and the code's check list, in words
// (empty when they agree). Throws kit::Error when the manifest is missing.
std::vector<std::string> manifest_differences(const std::filesystem::path& dir);

// Throws kit::Error (naming --update-references) when the manifest is missing or
// stale, or a file is: a run checks this before it renders anything.
void require_current_references(const std::filesystem::path& dir);

// A reference as a run holds it: the image, and the stem of the cache files made from
// it ("<cache>/<id>-<SHA-1 of its file>"; each adds ".<what>"): a reference file that
// changes gets new ones.
struct LoadedReference {
  Image image;
  std::filesystem::path cache_stem;
};

// Loads the references one lab's checks compare with (require_current_references
// first). A run loads a lab's when its first render child has finished, so the
// children start without waiting for them. Each is decoded once and kept in `cache`
// (an existing folder) as a raw image under its stem: decoding the 42 EXR and PNG
// files took 0.15 s of every run's CPU, reading them raw about a tenth of that. A cache
// file that cannot be read or written is passed over (the file is decoded again).
// Throws kit::Error when a reference file cannot be read.
std::map<std::string, LoadedReference> load_lab_references(const std::filesystem::path& dir, int lab,
                                                           const std::filesystem::path& cache);

// reference_background(metric, reference.image), kept in the cache beside it.
Background cached_background(const LoadedReference& reference, Metric metric);

}  // namespace kit::grade

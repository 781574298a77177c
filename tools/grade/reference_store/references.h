#pragma once
// The reference renders of the solutions (tools/grade/references/): one PNG (display
// images, exact 8-bit values) or EXR (float G-buffer attachments and HDR
// buffers) per reference render, and manifest.json recording the size and the
// settings each was rendered with. `kit-grade --update-references` writes them;
// `--check-references` (and a ctest) re-renders the solutions and fails when
// the code's check list or the solutions no longer match them.
#include <nlohmann/json_fwd.hpp>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "frames/checks.h"
#include "images/image_io.h"
#include "verdict/compare.h"

namespace kit::grade {

std::filesystem::path default_references_dir();  // <kit root>/tools/grade/references

// The manifest's "images" entry for a render: what it was rendered with.
nlohmann::json manifest_entry(const RenderSpec& spec);

// A reference's filter allowance. GL leaves a texture lookup's filter partly to the
// implementation (how trilinear weights are rounded, the level of detail's formula, one
// level of detail per 2x2 quad or per pixel), and GPUs take those freedoms where Mesa's
// CPU rasterisers do not. llvmpipe takes them too when asked (GALLIVM_PERF), so
// --update-references renders the solutions once more under each of
// kFilterRenderings, and a reference's allowance is, per pixel, the largest difference
// (pixel_differences) between its render and those: how far the right answer itself moves
// under GPU-like filtering. A submission's difference there counts that much less
// (compare_images). A reference no texture filter touches has none (no file).
struct FilterRendering {
  const char* name;   // GALLIVM_PERF's value
  const char* about;  // what it approximates, as the manifest says it
};
extern const std::vector<FilterRendering> kFilterRenderings;

// The allowances of `renders` (the solutions' renders, by render id) from `variants` (the
// same renders under each of kFilterRenderings): only those with a pixel over 0.
std::map<std::string, Image> filter_allowances(const std::map<std::string, Image>& renders,
                                               const std::vector<std::map<std::string, Image>>& variants);

// Writes the references (from the solutions' raw renders, by render id), their filter
// allowances ("<id>.allowance.exr") and the manifest, and removes the files of checks that
// are gone. A file whose pixels read back the same as the new image's is left as it is,
// byte for byte (an EXR written again differs in its bytes, and a course's history would
// fill with files that did not change). Returns the names of the files written or removed.
std::vector<std::string> write_references(const std::filesystem::path& dir,
                                          const std::map<std::string, Image>& renders,
                                          const std::map<std::string, Image>& allowances,
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
  Image allowance;  // its filter allowance; 0x0 where it has none
  std::filesystem::path cache_stem;
  bool prepared = false;  // cache_stem is in the build's prepared folder: read, never written
};

// Loads the references one lab's checks compare with (require_current_references
// first). A run loads a lab's when its first render worker has finished, so the
// workers start without waiting for them. Each is decoded once and kept in `cache`
// (an existing folder) as a raw image under its stem: decoding the 42 EXR and PNG
// files took 0.15 s of every run's CPU, reading them raw about a tenth of that. A cache
// file that cannot be read or written is passed over (the file is decoded again). A
// reference `prepared` holds in its version (kit-grade --prepare-references: the build
// makes them beside kit-grade) is read from there, with its backgrounds and report PNGs.
// Throws kit::Error when a reference file cannot be read.
std::map<std::string, LoadedReference> load_lab_references(const std::filesystem::path& dir, int lab,
                                                           const std::filesystem::path& cache,
                                                           const std::filesystem::path& prepared = {});
// A reference kept only to describe a worst pixel (checks.h, describes_pixels_only): the G-buffer
// attachment or light shares `id` of `dir`, cached and prepared as load_lab_references keeps a
// check's (decoding one took 3 to 5 ms). Throws kit::Error when the file cannot be read.
Image load_describing_reference(const std::filesystem::path& dir, const std::string& id,
                                const std::filesystem::path& cache, const std::filesystem::path& prepared = {});
// The folder the build prepares the references in (tools/grade.cmake), or
// $KIT_PREPARED_REFERENCES where it is set ("": none).
std::filesystem::path prepared_references_dir();

// reference_background(metric, reference.image), kept in the cache beside it (read
// from the prepared folder, never written there).
Background cached_background(const LoadedReference& reference, Metric metric);

}  // namespace kit::grade

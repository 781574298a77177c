#pragma once
// A lab's verdict from its renders: every check compared by kit-grade's rules, the score,
// and the catalogued mistakes the failures resemble. kit-grade (run/lab_results.cpp, compare_lab)
// and the browser's in-page check (tools/web/page_check.cpp) both come here, so the page's
// preview is the grader's own comparison compiled for WebAssembly.
#include <functional>
#include <map>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "frames/light_shares.h"
#include "images/image_io.h"
#include "scene/scene.h"
#include "verdict/compare.h"
#include "verdict/config.h"
#include "verdict/diagnosis.h"
#include "verdict/outcome.h"

#include <glm/glm.hpp>

namespace kit::grade {

// A lab with its checks (lab_checks) and their points (config), nothing compared yet.
LabOutcome lab_outcome(const Config& config, int lab);

// The stored reference a check compares with (none for checks of the submission's own renders).
struct StoredReference {
  const Image* image = nullptr;
  const Image* allowance = nullptr;    // its filter allowance, or null
  const Background* background = nullptr;  // reference_background's, when already found
};

// Compares check `c` of `lab`: `renders` by render id; `child` the render report's "work"
// (lab 7's counted work) and "hdr_non_finite" (NaN/Inf in the HDR buffer behind each
// image), as child.json holds them. Sets c's comparison, verdict and score. Lab 7's work
// check reads the verdict of its frame's image check, which comes earlier in the list.
void compare_check(const Config& config, LabOutcome& lab, CheckOutcome& c, const std::map<std::string, Image>& renders,
                   const nlohmann::json& child, const StoredReference& reference);

// How a report shows a check's images (display_image's metric).
Metric shown_metric(const Check& check);

// The inputs of a lit lab's shaders at one pixel, from the reference G-buffer of the render's
// scene: what the lighting pass reads there.
struct PixelInputs {
  glm::vec3 position{0.0f}, normal{0.0f}, albedo{0.0f}, emission{0.0f};
  float metallic = 0.0f, roughness = 0.0f;
  // What each light gives there in the reference frame (light_shares.h), where it is stored.
  bool has_light_shares = false;
  PixelLightShares light_shares;
};
// The G-buffer references a lit check's pixel inputs come from, by attachment ("position",
// "normal", "albedo", "material", "emission"): lab 1's of the render's scene, the normal lab
// 4's from lab 5 on (stages 5-7 draw lab 4's normal-mapped G-buffer), and those of lab 4's own
// checks. Every scene a lab 2-7 image renders has them (checks.h, describes_pixels_only);
// empty for another (a lab 1 or lab 6 map's).
std::map<std::string, std::string> gbuffer_reference_ids(const RenderSpec& spec);
// "There: position (x, y, z) m, normal (...), albedo (...), metallic m, roughness r, emission
// (...); towards the camera (...); light 1 (point, range 5 m): towards it (...), 2.3 m": at most 4 lights,
// each numbered as the scene lists it. With the light shares: "the lights give it luminance
// 0.31 in the reference", then the lights that give the most first, each with its share
// ("62 % of it"; "none" where every light that gives some is named before), then the others;
// without them, or after them, the scene's first, or where it has more the nearest (a
// directional light counts as nearest).
std::string describe_pixel_inputs(const PixelInputs& inputs, const Scene& scene);
// Fills c's worst pixel's inputs from `gbuffer` (by attachment, as gbuffer_reference_ids names
// them) and, where given, the frame's light shares, for a failed display or HDR check of a lit
// lab; nothing where an attachment is missing.
void add_pixel_inputs(CheckOutcome& c, const std::map<std::string, const Image*>& gbuffer, const Scene& scene,
                      const Image* light_shares = nullptr);
// The same from the references of c's render: its scene's G-buffer (gbuffer_reference_ids) and
// its frame's light shares (light_shares_id), each read once with `read(id)` into `cache` (by id;
// an empty image where `read` throws kit::Error: the verdict does not depend on it). The grader
// and the browser page both describe a worst pixel so.
void add_reference_pixel_inputs(CheckOutcome& c, const Scene& scene, std::map<std::string, Image>& cache,
                                const std::function<Image(const std::string& id)>& read);

// Where a check of `lab` failed: the catalogued mistakes its signatures resemble (diagnosis.h).
void name_likely_mistakes(const MistakeSignatures& mistakes, LabOutcome& lab);
// What name_likely_mistakes names them from, and whether a lab has any to name (graded, a
// check failed): kit-grade writes these (diagnosis.h, kNamingInputsFile) for --name-again.
NamingInputs naming_inputs(const LabOutcome& lab);
bool needs_naming(const LabOutcome& lab);

}  // namespace kit::grade

#pragma once
// What kit-grade renders and compares for each lab: the one list of checks.
//
// A *render* is one image a lab's child process produces (a scene, a view and
// the settings that differ from the defaults). A *check* compares one render of
// the submission with a reference render of the solutions (tools/grade/references/),
// or, for the custom-effect toggle, with another render of the submission.
// Adding a check is one row here plus its points in tools/grade/grading.json;
// `kit-grade --update-references` then renders its reference.
#include <string>
#include <vector>

#include "render/renderer.h"

namespace kit::grade {

// The size every check is rendered at (lab 6's precomputed maps have their own,
// fixed by the framework: common/render/ibl.h). 256x192 (4:3 like the scenes' cameras)
// keeps a whole submission under ~2 s on llvmpipe, yet each sphere of the
// default scene still covers ~200 pixels, so one wrong term in a BRDF, a falloff
// or a tangent frame changes far more pixels than the tolerances allow.
constexpr int kGradeWidth = 256;
constexpr int kGradeHeight = 192;

// Stage 6's precompute when grading: 64 GGX samples a prefiltered texel and 128 a BRDF
// table texel, a quarter of the viewer's (ibl.h IblSettings). The references are made the
// same way, so a check compares like with like; what a mistake changes in a map (a missing
// weight, a wrong lobe, a swapped table) does not need 256 samples to show: the self-check
// catches every lab 6 mistake with these as with the viewer's. Lab 6's render worker, two
// environments' maps and four frames, took 0.99 s of CPU with the viewer's, 0.63 s with these.
constexpr int kGradePrefilterSamples = 64;
constexpr int kGradeBrdfLutSamples = 128;

// How a check measures the difference (tolerances per metric in grading.json).
enum class Metric {
  Ldr,       // display image (RGBA8 final): |a - b| per channel
  Hdr,       // linear HDR buffer: compared after c / (1 + c), so the tolerance is
             // absolute for dim pixels and relative for bright ones
  Position,  // G-buffer world position: |a - b| in metres
  Normal,    // G-buffer normal: angle between the vectors in degrees, and unit length
  Albedo,    // G-buffer base colour: |a - b|
  Material,  // G-buffer metallic, roughness, (unused), mask: |a - b|
  Changes,   // must differ from another render of the submission (custom-effect toggle)
  Same,      // must equal another render of the submission (display images): both come from
             // the same machine, so the right answer is exact on every OpenGL implementation
  Work,      // lab 7: the fragments the light volumes shaded, counted in the render's frame
             // (render/light_volumes.h LightVolumeWork), credited only where that frame's
             // image check passed
};
const char* metric_name(Metric metric);  // "ldr", "hdr", ... (the keys in grading.json)
// Changes and Same compare two renders of the submission: no reference file, no edges.
inline bool compares_own_renders(Metric metric) {
  return metric == Metric::Changes || metric == Metric::Same || metric == Metric::Work;
}

struct RenderSpec {
  std::string id;     // unique; also the reference's file name (without extension)
  int stage;          // the stage (= lab number) it is rendered at
  std::string scene;  // kit scene name
  View view;
  bool raw;           // true: float values (G-buffer attachments, HDR) kept as EXR; false: display PNG
  float gamma = 2.2f;
  int attenuation_model = 0;
  bool postprocess = true;
  bool custom_effect = false;
  float bloom_threshold = 1.0f;
  // Lab 5: the submission's custom_effect.frag with the solution's bloom
  // shaders, so the toggle is graded independently of the bloom.
  bool isolate_custom = false;
  // Stage 6: the environment that lights the scene (a kit environment's name; empty:
  // kDefaultEnvironment).
  std::string environment = {};
  // A G-buffer attachment kept only to describe a failed check's worst pixel (lab_verdict.h,
  // gbuffer_reference_ids), for a scene whose lab 1 checks do not render it: made from the
  // solutions by --update-references, never rendered from a submission, compared by no
  // check; --check-references renders it again and compares it with its file.
  bool describes_pixels_only = false;
  // Describing only too: each light's share of this lit frame, pixel by pixel
  // (light_shares.h), drawn light by light from the solutions; view Hdr, the frame's settings.
  bool light_shares = false;
};

struct Check {
  int lab;
  std::string key;        // stable within the lab, the key of its points in grading.json
  std::string title;      // "default scene, HDR" (results.json name: "lab 2 lighting: default scene, HDR")
  Metric metric;
  std::string image;      // RenderSpec id rendered from the submission
  std::string reference;  // RenderSpec id: the solution's render (Changes, Same: another render of the submission)
};

const std::vector<RenderSpec>& renders();
const std::vector<Check>& checks();
const RenderSpec& find_render(const std::string& id);  // throws kit::Error
std::vector<const Check*> lab_checks(int lab);
// Every render a lab's child makes when it grades: the images of its checks, in list order;
// with `describing`, those of RenderSpec::describes_pixels_only too (--update-references).
std::vector<const RenderSpec*> lab_renders(int lab, bool describing = false);
// The id of the light shares (RenderSpec::light_shares) of `spec`'s frame: one per lab, scene
// and falloff model, since neither gamma, post-processing nor a stage 6 environment changes
// what each light gives ("lab3-default-physical-lights", "lab2-sphere-lights"); "" for a frame
// without lighting (lab 1's, lab 6's maps).
std::string light_shares_id(const RenderSpec& spec);
// The renders whose solution images are stored as references: the checks' and those that
// describe a worst pixel.
std::vector<const RenderSpec*> reference_renders();
// RenderSettings for a render at the grading size.
RenderSettings render_settings(const RenderSpec& spec);
// The environment a render is lit by as the manifest names it: the kit's default
// for an empty RenderSpec::environment.
std::string environment_name(const RenderSpec& spec);
// "png" or "exr": how a render is stored as a reference file.
std::string reference_extension(const RenderSpec& spec);

}  // namespace kit::grade

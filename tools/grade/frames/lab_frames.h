#pragma once
// One lab's renders (checks.h, lab_renders) drawn in list order, as the grader's render
// worker (render_worker.cpp) and the browser's in-page check (tools/web/page_check.cpp) both
// draw them: one Renderer per (scene, isolated custom effect), so each shader is compiled once
// and only uniforms change between settings, and one IblCache, so stage 6's maps are
// precomputed once per environment. A render that differs from the last frame of its
// Renderer only in the view it reads reads that frame again.
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <utility>

#include "frames/checks.h"
#include <nlohmann/json_fwd.hpp>

#include "gl/gl_objects.h"
#include "gl/shader_source.h"
#include "render/ibl.h"
#include "render/light_volumes.h"
#include "render/renderer.h"
#include "render/stages.h"
#include "scene/scene.h"

namespace kit::grade {

// Whether lab `stage`'s custom effect is isolated on the kit's own solution of the lab
// (lab_frames.cpp, isolated_custom_library): false in a kit without that solution (a
// student copy for lab 5, a Classroom 50 bundle), where the effect is rendered on the
// submission's own bloom and the report says so (kOwnBloomNote).
bool custom_effect_isolated(const Stage& stage);

class LabFrames {
 public:
  // `lab_root`: the folder of the submission's NN-name lab folders; `scenes`: every scene
  // the lab's renders name, loaded (kept by the caller).
  LabFrames(const Stage& stage, std::filesystem::path lab_root, const std::map<std::string, Scene>& scenes);

  // What a report calls the Renderer of `spec`: its scene, and "(custom effect alone)".
  static std::string renderer_name(const RenderSpec& spec);
  // The Renderer of `spec`, built on first use; the seconds building it took go to
  // *compile_seconds. Throws NonFiniteMapError (a stage 6 map), kit::Error (a shader; the
  // scene missing from `scenes`).
  Renderer& renderer_for(const RenderSpec& spec, double* compile_seconds = nullptr);
  // Draws `spec`'s frame with the scene's camera at the grading size unless its Renderer's
  // last frame is that frame; the seconds drawing took (0 when it was there). Throws kit::Error.
  double draw(const RenderSpec& spec);
  // The light shares of `spec`'s frame (RenderSpec::light_shares, light_shares.h): the frame
  // drawn once with each of its lights alone and once with none. Throws kit::Error.
  Image light_shares(const RenderSpec& spec);
  size_t programs_reused() const { return program_cache_.reused(); }

 private:
  const Stage& stage_;
  std::filesystem::path lab_root_;
  const std::map<std::string, Scene>& scenes_;
  IblCache ibl_cache_;
  // The Renderers build many of the same programs (display, debug, post, and lighting where
  // the scenes' light defines agree): each is compiled and linked once (gl_objects.h).
  LinkedProgramCache program_cache_;
  // And each shader is assembled once: the lab's files do not change during a check.
  AssembledShaderCache assembled_cache_;
  std::map<std::pair<std::string, bool>, std::unique_ptr<Renderer>> renderers_;
  // The settings of each Renderer's last frame. Checks that differ only in the view they
  // read (lab 1's G-buffer attachments of one scene, an image and its HDR buffer, lab 6's
  // maps beside the frame) read the frame already there instead of rendering it again:
  // the same scene, camera and settings give the same frame (21 of the 62 renders).
  std::map<std::pair<std::string, bool>, RenderSettings> last_frame_;
};

// A lab 7 frame's counted work (render/light_volumes.h) as child.json holds it, and back (zeros
// for what a report lacks).
nlohmann::json work_json(const LightVolumeWork& work, const LightVolumeState& state);
LightVolumeWork work_from_json(const nlohmann::json& json);

}  // namespace kit::grade

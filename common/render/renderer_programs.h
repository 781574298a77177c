#pragma once
// The Renderer's programs, shared by the files that define its passes: renderer.cpp builds
// them, lighting_pass.cpp, postprocess.cpp and views.cpp draw with them.
#include "render/renderer.h"

namespace kit {

struct Renderer::Programs {
  GeometryPrograms geometry;  // one program per material variant the scene's draws use
  Program lighting, display, bright, blur, composite, custom, debug;
  // Stage 6: the lab's precompute shaders, its IBL pass, and the framework's background.
  Program irradiance, prefilter, brdf_lut, ibl, background;
  // Stage 7: the lab's light volumes, and the framework's programs that count their work.
  Program volume, volume_count, volume_coverage, surface_count, volume_evidence, state_evidence;
};

}  // namespace kit

#pragma once
// A link check stricter than Mesa's: every fragment-shader input the shader
// reads must be written by the vertex shader under the same name and type.
// Mesa links a desktop GL 3.3 program whose fragment input has no matching
// output (the input then reads zero) while other drivers refuse it; the kit
// reports it as a link error naming both files, so a renamed varying gets a
// clear message instead of a garbled image. The Renderer runs it before it
// compiles a stage, so kit-render, kit-view and the grader refuse the same pairs.
#include <string>

#include "gl/shader_source.h"
#include "render/stages.h"

namespace kit {

// Checks the vertex/fragment pairs made of the stage's own files (gbuffer.vert
// with gbuffer.frag; shaders/fullscreen.vert with each full-screen .frag the
// lab supplies). Throws kit::Error ("link error (A + B):" then one line per input,
// "B:LINE: fragment shader input `name' ...") on a mismatch.
void check_stage_interfaces(const Stage& stage, const ShaderLibrary& library);

}  // namespace kit

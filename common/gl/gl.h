#pragma once
// The one include for GL declarations. Two flavours of GL, one set of sources:
//   desktop: OpenGL 3.3 core through the glad loader generated at configure time
//            (cmake/glad.cmake); glad 2 writes <glad/gl.h>, glad 0.1 (Ubuntu 22.04)
//            <glad/glad.h>.
//   web:     WebGL2, which emscripten presents as OpenGL ES 3.0 (<GLES3/gl3.h>).
// What the two do differently is behind gl/gl_flavour.h; outside common/gl/ no file
// tests the flavour for GL calls.
#if defined(__EMSCRIPTEN__)
#define KIT_GL_ES 1
// The extension functions' prototypes (glGetQueryObjectui64vEXT) as well as their enums.
#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif
#include <GLES3/gl3.h>
// The extensions' enums (EXT_depth_clamp, EXT_disjoint_timer_query_webgl2, ...).
#include <GLES2/gl2ext.h>
// Desktop sampler types that an ES 3.0 implementation never reports from
// glGetActiveUniform (gl_objects.cpp lists them among the types it recognises): the
// desktop values, so the same switch compiles for both flavours and never meets them.
#ifndef GL_SAMPLER_1D
#define GL_SAMPLER_1D 0x8B5D
#endif
#ifndef GL_SAMPLER_2D_RECT
#define GL_SAMPLER_2D_RECT 0x8B63
#endif
#ifndef GL_SAMPLER_BUFFER
#define GL_SAMPLER_BUFFER 0x8DC2
#endif
// ... and a framebuffer status only desktop GL reports (gl_objects.cpp names the statuses).
#ifndef GL_FRAMEBUFFER_INCOMPLETE_DRAW_BUFFER
#define GL_FRAMEBUFFER_INCOMPLETE_DRAW_BUFFER 0x8CDB
#endif
#else
#define KIT_GL_ES 0
#if KIT_GLAD_GENERATION == 1
#include <glad/glad.h>
#else
#include <glad/gl.h>
#endif
#endif

#include <string>

namespace kit {

// Throws kit::Error naming `where` if glGetError reports anything.
void check_gl(const char* where);

}  // namespace kit

#pragma once
// The few GL calls that differ between the kit's two GL flavours (gl/gl.h): desktop
// OpenGL 3.3 core, and WebGL2 (OpenGL ES 3.0) in the browser. The framework calls these
// instead of the desktop-only names; each is implemented once per flavour in
// gl_flavour.cpp, the desktop one being exactly the call it replaces. Where WebGL2
// lacks a feature, the web flavour uses the browser's extension when it has one and a
// fallback when not, and gl_flavour_report() says which, so a page can tell its reader.
#include <cstdint>
#include <string>
#include <vector>

#include "gl/gl.h"

namespace kit {

enum class GlFlavour { Desktop, WebGL2 };
constexpr GlFlavour kGlFlavour = KIT_GL_ES ? GlFlavour::WebGL2 : GlFlavour::Desktop;
const char* gl_flavour_name();  // "desktop OpenGL 3.3 core" | "WebGL2 (OpenGL ES 3.0)"

// Looks up the extensions the web flavour can use in the current context (nothing to
// do on the desktop). Call once a context is current, before the first renderer. Throws
// kit::Error where the kit cannot render at all (WebGL2 without float render targets).
void init_gl_flavour();

// Depth clamping (lab 7's light volumes). Web: EXT_depth_clamp, else nothing: a volume
// crossing the near or far plane is clipped there.
void set_depth_clamp(bool on);

// An occlusion query counting the samples a draw lets through (GL_SAMPLES_PASSED).
// Web: ANY_SAMPLES_PASSED, whose result is 0 or 1, not a count.
void begin_samples_passed(GLuint query);
void end_samples_passed();
uint64_t samples_passed_result(GLuint query);
// Whether samples_passed_result is a count (desktop) or only 0/1 (web).
bool samples_passed_counts();

// GPU time of the commands between begin and end (GL_TIME_ELAPSED). Web:
// EXT_disjoint_timer_query_webgl2 where the browser has it; without it
// has_timer_queries() is false and the others must not be called.
bool has_timer_queries();
void begin_time_elapsed(GLuint query);
void end_time_elapsed();
// Whether the query's result is ready, and it in nanoseconds.
bool time_elapsed_ready(GLuint query);
uint64_t time_elapsed_ns(GLuint query);

// The bound draw framebuffer writes no colour (glDrawBuffer(GL_NONE); web: glDrawBuffers).
void draw_no_colour_buffer();
// glDrawBuffer(GL_BACK) for the default framebuffer.
void draw_to_back_buffer();
// glDepthRange (web: glDepthRangef).
void set_depth_range(double near_value, double far_value);
// Whether glReadPixels can read a depth attachment (GL_DEPTH_COMPONENT): desktop yes,
// WebGL2 no.
bool can_read_depth_pixels();

// glReadPixels of the bound read buffer's lower-left width x height as RGBA floats. Web:
// a unorm8 attachment is read as bytes and converted as desktop GL converts it (v / 255):
// WebGL2 reads such a buffer as GL_UNSIGNED_BYTE only.
void read_colour_pixels_as_float(int width, int height, float* rgba);

// The pixel type glTexImage2D is given when it only allocates `internal_format`'s
// storage (no data). Desktop GL ignores it then: `type`. OpenGL ES still requires a
// type that matches the format (GL_DEPTH_COMPONENT24 takes GL_UNSIGNED_INT only).
GLenum type_for_storage_only(GLenum internal_format, GLenum type);

// One line per feature that differs: what it is, and what this context uses for it.
struct GlFeatureChoice {
  std::string feature;  // "depth clamp"
  std::string used;     // "GL_DEPTH_CLAMP", "EXT_depth_clamp", "none: volumes clip at the far plane"
};
std::vector<GlFeatureChoice> gl_flavour_report();

}  // namespace kit

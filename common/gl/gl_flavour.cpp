#include "gl/gl_flavour.h"

#if KIT_GL_ES
#include <emscripten/html5.h>
#endif

#include "base/error.h"

namespace kit {

#if !KIT_GL_ES

// Desktop OpenGL 3.3 core: every feature is core; each function is the call it replaces.

const char* gl_flavour_name() { return "desktop OpenGL 3.3 core"; }
void init_gl_flavour() {}
void set_depth_clamp(bool on) { on ? glEnable(GL_DEPTH_CLAMP) : glDisable(GL_DEPTH_CLAMP); }
void begin_samples_passed(GLuint query) { glBeginQuery(GL_SAMPLES_PASSED, query); }
void end_samples_passed() { glEndQuery(GL_SAMPLES_PASSED); }
uint64_t samples_passed_result(GLuint query) {
  GLuint64 samples = 0;
  glGetQueryObjectui64v(query, GL_QUERY_RESULT, &samples);
  return samples;
}
bool samples_passed_counts() { return true; }
bool has_timer_queries() { return true; }
void begin_time_elapsed(GLuint query) { glBeginQuery(GL_TIME_ELAPSED, query); }
void end_time_elapsed() { glEndQuery(GL_TIME_ELAPSED); }
bool time_elapsed_ready(GLuint query) {
  GLint ready = 0;
  glGetQueryObjectiv(query, GL_QUERY_RESULT_AVAILABLE, &ready);
  return ready != 0;
}
uint64_t time_elapsed_ns(GLuint query) {
  GLuint64 ns = 0;
  glGetQueryObjectui64v(query, GL_QUERY_RESULT, &ns);
  return ns;
}
void draw_no_colour_buffer() { glDrawBuffer(GL_NONE); }
void draw_to_back_buffer() { glDrawBuffer(GL_BACK); }
void set_depth_range(double near_value, double far_value) { glDepthRange(near_value, far_value); }
bool can_read_depth_pixels() { return true; }
GLenum type_for_storage_only(GLenum, GLenum type) { return type; }
void read_colour_pixels_as_float(int width, int height, float* rgba) {
  glReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, rgba);
}
std::vector<GlFeatureChoice> gl_flavour_report() {
  return {{"depth clamp", "GL_DEPTH_CLAMP"},
          {"occlusion counts", "GL_SAMPLES_PASSED"},
          {"timer queries", "GL_TIME_ELAPSED"},
          {"float render targets", "core"}};
}

#else

// WebGL2 through emscripten. Emscripten enables every extension the browser offers when
// it creates a context (its enableExtensionsByDefault); emscripten_webgl_enable_extension
// then says whether the browser has it.
namespace {

struct WebFeatures {
  bool probed = false;
  bool depth_clamp = false;
  bool timer = false;
  bool float_targets = false;
  bool float_blend = false;
};

WebFeatures& features() {
  static WebFeatures f;
  return f;
}

bool has_extension(const char* name) {
  const EMSCRIPTEN_WEBGL_CONTEXT_HANDLE context = emscripten_webgl_get_current_context();
  return context != 0 && emscripten_webgl_enable_extension(context, name) == EM_TRUE;
}

const WebFeatures& probed() {
  if (!features().probed) init_gl_flavour();
  return features();
}

}  // namespace

const char* gl_flavour_name() { return "WebGL2 (OpenGL ES 3.0)"; }

void init_gl_flavour() {
  WebFeatures& f = features();
  if (emscripten_webgl_get_current_context() == 0)
    throw Error("init_gl_flavour: no WebGL2 context is current");
  f.depth_clamp = has_extension("EXT_depth_clamp");
  f.timer = has_extension("EXT_disjoint_timer_query_webgl2");
  f.float_targets = has_extension("EXT_color_buffer_float");
  // Blending into RGBA32F (the HDR targets are RGBA16F, which EXT_color_buffer_float
  // blends; only noted).
  f.float_blend = has_extension("EXT_float_blend");
  f.probed = true;
  if (!f.float_targets)
    throw Error("this browser's WebGL2 has no EXT_color_buffer_float: the kit's G-buffer and HDR targets are "
                "float textures, which it cannot render into");
}

void set_depth_clamp(bool on) {
  if (!probed().depth_clamp) return;  // no fallback: volumes are clipped at the near and far planes
  on ? glEnable(GL_DEPTH_CLAMP_EXT) : glDisable(GL_DEPTH_CLAMP_EXT);
}
void begin_samples_passed(GLuint query) { glBeginQuery(GL_ANY_SAMPLES_PASSED, query); }
void end_samples_passed() { glEndQuery(GL_ANY_SAMPLES_PASSED); }
uint64_t samples_passed_result(GLuint query) {
  GLuint any = 0;
  glGetQueryObjectuiv(query, GL_QUERY_RESULT, &any);
  return any;
}
bool samples_passed_counts() { return false; }
bool has_timer_queries() { return probed().timer; }
void begin_time_elapsed(GLuint query) { glBeginQuery(GL_TIME_ELAPSED_EXT, query); }
void end_time_elapsed() { glEndQuery(GL_TIME_ELAPSED_EXT); }
bool time_elapsed_ready(GLuint query) {
  GLuint ready = 0;
  glGetQueryObjectuiv(query, GL_QUERY_RESULT_AVAILABLE, &ready);
  return ready != 0;
}
uint64_t time_elapsed_ns(GLuint query) {
  GLuint64 ns = 0;
  glGetQueryObjectui64vEXT(query, GL_QUERY_RESULT, &ns);
  return ns;
}
void draw_no_colour_buffer() {
  const GLenum none = GL_NONE;
  glDrawBuffers(1, &none);
}
void draw_to_back_buffer() {
  const GLenum back = GL_BACK;
  glDrawBuffers(1, &back);
}
void set_depth_range(double near_value, double far_value) {
  glDepthRangef(static_cast<GLfloat>(near_value), static_cast<GLfloat>(far_value));
}
bool can_read_depth_pixels() { return false; }
GLenum type_for_storage_only(GLenum internal_format, GLenum type) {
  switch (internal_format) {
    case GL_DEPTH_COMPONENT16: return GL_UNSIGNED_SHORT;
    case GL_DEPTH_COMPONENT24: return GL_UNSIGNED_INT;
    case GL_DEPTH_COMPONENT32F: return GL_FLOAT;
    case GL_DEPTH24_STENCIL8: return GL_UNSIGNED_INT_24_8;
    case GL_RGBA8: case GL_SRGB8_ALPHA8: case GL_RGB8: case GL_RG8: case GL_R8: return GL_UNSIGNED_BYTE;
    default: return type;
  }
}
void read_colour_pixels_as_float(int width, int height, float* rgba) {
  GLint read_buffer = GL_COLOR_ATTACHMENT0, component = GL_FLOAT;
  glGetIntegerv(GL_READ_BUFFER, &read_buffer);
  glGetFramebufferAttachmentParameteriv(GL_READ_FRAMEBUFFER, static_cast<GLenum>(read_buffer),
                                        GL_FRAMEBUFFER_ATTACHMENT_COMPONENT_TYPE, &component);
  if (component == GL_FLOAT) {
    glReadPixels(0, 0, width, height, GL_RGBA, GL_FLOAT, rgba);
    return;
  }
  const size_t count = static_cast<size_t>(width) * static_cast<size_t>(height) * 4;
  std::vector<unsigned char> bytes(count);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, bytes.data());
  for (size_t i = 0; i < count; ++i) rgba[i] = static_cast<float>(bytes[i]) / 255.0f;
}

std::vector<GlFeatureChoice> gl_flavour_report() {
  const WebFeatures& f = probed();
  return {{"depth clamp", f.depth_clamp ? "EXT_depth_clamp" : "none: light volumes clip at the near and far planes"},
          {"occlusion counts", "ANY_SAMPLES_PASSED: 0 or 1, not a count"},
          {"timer queries", f.timer ? "EXT_disjoint_timer_query_webgl2" : "none"},
          {"float render targets", f.float_targets ? "EXT_color_buffer_float" : "none"},
          {"float blending", f.float_blend ? "EXT_float_blend" : "none (the kit blends RGBA16F only)"}};
}

#endif

}  // namespace kit

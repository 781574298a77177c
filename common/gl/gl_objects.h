#pragma once
// RAII wrappers for the GL objects the kit uses. Each owns one GL name, is
// movable and not copyable, and frees its name in the destructor.
#include <glm/glm.hpp>
#include <glm/gtc/type_precision.hpp>  // u16vec4

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "gl/gl.h"
#include "gl/shader_source.h"

namespace kit {

// Owns one GL name; Deleter is a function that frees it.
template <void (*Deleter)(GLuint)>
class GlName {
 public:
  GlName() = default;
  explicit GlName(GLuint id) : id_(id) {}
  GlName(GlName&& o) noexcept : id_(std::exchange(o.id_, 0)) {}
  GlName& operator=(GlName&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = std::exchange(o.id_, 0);
    }
    return *this;
  }
  GlName(const GlName&) = delete;
  GlName& operator=(const GlName&) = delete;
  ~GlName() { reset(); }
  GLuint get() const { return id_; }
  void reset() {
    if (id_) Deleter(id_);
    id_ = 0;
  }

 private:
  GLuint id_ = 0;
};

void delete_texture(GLuint id);
void delete_framebuffer(GLuint id);
void delete_buffer(GLuint id);
void delete_vertex_array(GLuint id);
void delete_program(GLuint id);
void delete_sampler(GLuint id);

// Linked GL programs by the vertex and fragment texts they were built from, for a
// process that builds the same programs for many scenes: the grader's render worker has a
// Renderer per scene, and half of its program building was repeats, each of which also
// drew its first frame with llvmpipe code made afresh (docs/performance.md, Grading).
// Programs built through it (ShaderLibrary::share_programs_through) share one GL program,
// so they share its uniform values too: it suits callers that set every uniform before
// each use, as the Renderer does. It holds no program alive: the last Program built from
// a text deletes it, as without the cache.
class LinkedProgramCache {
 public:
  using Handle = std::shared_ptr<const GlName<delete_program>>;
  Handle find(const std::string& texts);
  void store(const std::string& texts, const Handle& program);
  int reused() const { return reused_; }  // how many builds found their program here

 private:
  std::map<std::string, std::weak_ptr<const GlName<delete_program>>> programs_;
  int reused_ = 0;
};

// A linked program from a vertex and a fragment shader found through a
// ShaderLibrary. Compile and link errors throw kit::Error with the log mapped
// to the original files and lines. Uniform locations are cached by name.
class Program {
 public:
  Program() = default;
  Program(const ShaderLibrary& library, const std::string& vertex, const std::string& fragment);
  // A compute program (needs a GL 4.3 context or ARB_compute_shader at run time;
  // the shader enables the extensions it uses after its #version 330 core line).
  Program(const ShaderLibrary& library, const std::string& compute);
  Program(Program&&) = default;  // one owner of its GL program, unless built through a LinkedProgramCache
  Program& operator=(Program&&) = default;
  Program(const Program&) = delete;
  Program& operator=(const Program&) = delete;

  GLuint id() const { return program_ ? program_->get() : 0; }
  void use() const { glUseProgram(id()); }
  bool valid() const { return id() != 0; }
  // Whether `library` assembles `vertex` and `fragment` to the very texts this program was
  // built from: building them again would make the same program.
  bool built_from(const ShaderLibrary& library, const std::string& vertex, const std::string& fragment) const;
  // Real paths of every file this program was assembled from (for hot reload).
  const std::vector<std::filesystem::path>& source_paths() const { return source_paths_; }
  // How messages name the program's last top-level file: its fragment shader's (a
  // compute program's shader), e.g. "labs/06-ibl/prefilter.frag"; "?" when empty.
  std::string main_file() const;

  GLint location(const std::string& name) const;
  bool has(const std::string& name) const { return location(name) >= 0; }
  // Setters skip uniforms the shader does not use (location -1), as GL does.
  void set(const std::string& name, int v) const;
  void set(const std::string& name, bool v) const { set(name, v ? 1 : 0); }
  void set(const std::string& name, float v) const;
  void set(const std::string& name, const glm::vec2& v) const;
  void set(const std::string& name, const glm::vec3& v) const;
  void set(const std::string& name, const glm::vec4& v) const;
  void set(const std::string& name, const glm::mat3& v) const;
  void set(const std::string& name, const glm::mat4& v) const;

  // What the program's uniforms tell once it has drawn with everything its
  // caller sets: each line reads "FILE:LINE: uniform `name' ...", naming where
  // the uniform is declared.
  struct UniformProblems {
    std::vector<std::string> unset;     // used by the shaders, never looked up by name: nothing sets them, they read 0
    std::vector<std::string> mistyped;  // set with a value of another type than declared: GL refuses the call
  };
  UniformProblems uniform_problems() const;

 private:
  struct Slot {
    GLint location = -1;
    GLenum set_as = 0;  // the GL type of the last value set (GL_INT, GL_FLOAT_VEC3, ...); 0 before any
  };
  const Slot& slot(const std::string& name) const;
  void record(const std::string& name, GLenum type) const;
  std::string declaration_site(const std::string& uniform) const;

  LinkedProgramCache::Handle program_;  // shared with other Programs only through a LinkedProgramCache
  mutable std::unordered_map<std::string, Slot> slots_;
  std::vector<std::filesystem::path> source_paths_;
  std::vector<AssembledShader> sources_;  // for the file and line of a declaration
};

struct TextureFormat {
  GLenum internal_format;
  GLenum format;
  GLenum type;
};

// One mip level's texels as glTexImage2D, or glCompressedTexImage2D for a compressed
// format, reads them.
struct TextureLevelData {
  int width = 0, height = 0;
  const void* data = nullptr;
  size_t bytes = 0;  // what glCompressedTexImage2D needs to be told
};

class Texture2D {
 public:
  Texture2D() = default;
  // Allocates storage for one level (data may be null). Filtering defaults to nearest,
  // clamp to edge. (No glGenerateMipmap: on llvmpipe it JIT-compiles a blit per
  // format in every process; chains are made on the CPU, texture_prepare.h.)
  Texture2D(int width, int height, TextureFormat fmt, const void* data = nullptr);
  // A texture of the given mip levels (level 0 first; the last given is its max
  // level, and data may be null), sampled trilinearly, clamp to edge. `compressed`: fmt.internal_format is a block format
  // (S3TC) and each level's bytes are its blocks; fmt.format and fmt.type are unused.
  Texture2D(TextureFormat fmt, bool compressed, const std::vector<TextureLevelData>& levels);
  GLuint id() const { return texture_.get(); }
  int width() const { return width_; }
  int height() const { return height_; }
  const TextureFormat& format() const { return format_; }
  void bind(int unit) const;
  void set_filter(GLenum min_filter, GLenum mag_filter) const;
  void set_wrap(GLenum wrap_s, GLenum wrap_t) const;
  // The last mip level sampling may use (GL_TEXTURE_MAX_LEVEL): a chain cut short stays complete.
  void set_max_level(int level) const;

 private:
  GlName<delete_texture> texture_;
  int width_ = 0, height_ = 0;
  TextureFormat format_{};
};

// A sampler object: how a texture unit filters and wraps whatever texture it
// holds, overriding the texture's own settings while bound.
class Sampler {
 public:
  Sampler() = default;
  Sampler(GLenum min_filter, GLenum mag_filter, GLenum wrap_s, GLenum wrap_t);
  GLuint id() const { return sampler_.get(); }
  void bind(int unit) const { glBindSampler(static_cast<GLuint>(unit), sampler_.get()); }
  // The unit goes back to its texture's own settings.
  static void unbind(int unit) { glBindSampler(static_cast<GLuint>(unit), 0); }

 private:
  GlName<delete_sampler> sampler_;
};

class Framebuffer {
 public:
  Framebuffer();
  GLuint id() const { return fbo_.get(); }
  void bind() const { glBindFramebuffer(GL_FRAMEBUFFER, fbo_.get()); }
  // Attaches mip level `level` of `texture` (its size is the level's, not level 0's).
  void attach_color(int index, const Texture2D& texture, int level = 0) const;
  void attach_depth(const Texture2D& texture) const;
  // Sets the draw buffers to attachments 0..count-1.
  void set_draw_buffers(int count) const;
  // Empty when complete, otherwise the status name (e.g. "GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT").
  std::string incomplete_reason() const;

 private:
  GlName<delete_framebuffer> fbo_;
};

// Interleaved vertex layout the scene loader produces.
struct Vertex {
  glm::vec3 position;
  glm::vec3 normal;
  glm::vec2 texcoord;             // UV slot 0: the first UV set the material's textures read
  glm::vec2 texcoord1{0.0f};      // UV slot 1: a second one, when they read two (else zero)
  glm::vec4 tangent;  // xyz unit tangent, w = handedness (+1 or -1)
  // glTF COLOR_0 (linear rgba; OBJ's `v x y z r g b`), white when absent, as
  // unsigned 16-bit normalized (c / 65535): 8 bytes a vertex instead of a vec4's 16
  // (4 MB less in CPU and GPU memory each for the heavy scene's 530,000 vertices), exact
  // for 8- and 16-bit files (c8 / 255 is c8 * 257 / 65535) and within 1/131070 of a
  // float file's value, far finer than the RGBA8 albedo it ends in. The GPU reads it as
  // a normalized vec4.
  glm::u16vec4 color{kVertexColorOne};
  static constexpr uint16_t kVertexColorOne = 65535;
};

class Mesh {
 public:
  Mesh() = default;
  Mesh(const std::vector<Vertex>& vertices, const std::vector<uint32_t>& indices);
  void draw() const;
  // `instances` copies in one draw; shaders tell them apart by gl_InstanceID.
  void draw_instanced(int instances) const;
  GLsizei index_count() const { return index_count_; }
  // Whether every vertex holds the default white COLOR_0 (the array is then not fetched).
  bool default_color() const { return (fetch_defaults_ & kDefaultColor) != 0; }

 private:
  static constexpr unsigned kDefaultTexcoord1 = 1, kDefaultColor = 2;
  void set_default_attributes() const;
  GlName<delete_vertex_array> vao_;
  GlName<delete_buffer> vbo_, ebo_;
  GLsizei index_count_ = 0;
  unsigned fetch_defaults_ = 0;  // attributes left at their current value, kDefault* bits
};

// The one full-screen draw: a single triangle covering the viewport, its
// positions made in shaders/fullscreen.vert from gl_VertexID.
class FullscreenTriangle {
 public:
  FullscreenTriangle();
  void draw() const;
  // A full-screen pass: binds `target`, sets the viewport to width x height, turns
  // depth test and culling off, uses `program` and draws. Blending is off, or with
  // `additive` the colour is added to the target's (its alpha kept).
  void pass(const Program& program, const Framebuffer& target, int width, int height, bool additive = false) const;
  // The same, but only over the pixels where `target`'s depth attachment holds a
  // surface (depth < 1): the triangle is put at depth 1 (glDepthRange(1, 1)) and
  // tested GL_GREATER without writing, so the rasteriser drops every pixel no geometry
  // covered before its fragment shader runs. Those pixels keep what `target` held.
  void pass_over_surfaces(const Program& program, const Framebuffer& target, int width, int height) const;

 private:
  GlName<delete_vertex_array> vao_;
};

}  // namespace kit

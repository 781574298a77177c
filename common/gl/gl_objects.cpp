#include "gl/gl_objects.h"

#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <sstream>

#include "base/error.h"
#include "gbuffer_layout.h"
#include "gl/gl_flavour.h"
#include "gl/loop_guard.h"

namespace kit {

void delete_texture(GLuint id) { glDeleteTextures(1, &id); }
void delete_framebuffer(GLuint id) { glDeleteFramebuffers(1, &id); }
void delete_buffer(GLuint id) { glDeleteBuffers(1, &id); }
void delete_vertex_array(GLuint id) { glDeleteVertexArrays(1, &id); }
void delete_program(GLuint id) { glDeleteProgram(id); }
void delete_sampler(GLuint id) { glDeleteSamplers(1, &id); }

void check_gl(const char* where) {
  std::string errors;
  for (GLenum e = glGetError(); e != GL_NO_ERROR; e = glGetError()) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "0x%04x", e);
    errors += (errors.empty() ? "" : ", ") + std::string(buf);
  }
  if (!errors.empty()) throw Error(std::string("GL error after ") + where + ": " + errors);
}

namespace {

std::string info_log(GLuint object, bool is_program) {
  GLint length = 0;
  if (is_program) glGetProgramiv(object, GL_INFO_LOG_LENGTH, &length);
  else glGetShaderiv(object, GL_INFO_LOG_LENGTH, &length);
  std::string log(static_cast<size_t>(std::max(length, 1)), '\0');
  if (is_program) glGetProgramInfoLog(object, length, nullptr, log.data());
  else glGetShaderInfoLog(object, length, nullptr, log.data());
  while (!log.empty() && (log.back() == '\0' || log.back() == '\n')) log.pop_back();
  return log;
}

GLuint compile(GLenum stage, const AssembledShader& source) {
  GLuint shader = glCreateShader(stage);
  const char* text = source.text.c_str();
  glShaderSource(shader, 1, &text, nullptr);
  glCompileShader(shader);
  GLint ok = 0;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    std::string log = source.map_log(info_log(shader, false));
    glDeleteShader(shader);
    throw Error("compile error in " + source.files.front() + ":\n" + log);
  }
  return shader;
}

// Links the compiled shaders into a program and deletes them (they are no longer
// needed once linked); a link error throws kit::Error naming `what`.
GLuint link(std::initializer_list<GLuint> shaders, const std::string& what) {
  GLuint program = glCreateProgram();
  for (GLuint s : shaders) glAttachShader(program, s);
  glLinkProgram(program);
  for (GLuint s : shaders) glDeleteShader(s);
  GLint ok = 0;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    std::string log = info_log(program, true);
    glDeleteProgram(program);
    throw Error("link error (" + what + "):\n" + log);
  }
  return program;
}

}  // namespace

LinkedProgramCache::Handle LinkedProgramCache::find(const std::string& texts) {
  auto it = programs_.find(texts);
  Handle found = it == programs_.end() ? nullptr : it->second.lock();
  if (found) ++reused_;
  return found;
}

void LinkedProgramCache::store(const std::string& texts, const Handle& program) { programs_[texts] = program; }

Program::Program(const ShaderLibrary& library, const std::string& vertex, const std::string& fragment) {
  AssembledShader vs = library.assemble(vertex);
  AssembledShader fs = library.assemble(fragment);
  for (const auto* s : {&vs, &fs}) source_paths_.insert(source_paths_.end(), s->paths.begin(), s->paths.end());
  LinkedProgramCache* cache = library.program_cache();
  // '\0' cannot occur in shader text (read_shader_text refuses it): the key splits one way.
  const std::string texts = cache ? vs.text + '\0' + fs.text : std::string();
  if (cache) program_ = cache->find(texts);
  if (!program_) {
    GLuint v = compile(GL_VERTEX_SHADER, vs);
    GLuint f = 0;
    try {
      f = compile(GL_FRAGMENT_SHADER, fs);
    } catch (...) {
      glDeleteShader(v);
      throw;
    }
    program_ = std::make_shared<const GlName<delete_program>>(link({v, f}, vs.files.front() + " + " + fs.files.front()));
    if (cache) cache->store(texts, program_);
  }
  sources_ = {std::move(vs), std::move(fs)};
}

bool Program::built_from(const ShaderLibrary& library, const std::string& vertex, const std::string& fragment) const {
  return valid() && sources_.size() == 2 && library.assemble(vertex).text == sources_[0].text &&
         library.assemble(fragment).text == sources_[1].text;
}

Program::Program(const ShaderLibrary& library, const std::string& compute) {
  AssembledShader cs = library.assemble(compute);
#if KIT_GL_ES
  throw Error(cs.files.front() + ": compute shaders need OpenGL 4.3; WebGL2 (OpenGL ES 3.0) has none");
#else
  source_paths_ = cs.paths;
  GLuint shader = compile(GL_COMPUTE_SHADER, cs);
  program_ = std::make_shared<const GlName<delete_program>>(link({shader}, cs.files.front()));
  sources_ = {std::move(cs)};
#endif
}

const Program::Slot& Program::slot(const std::string& name) const {
  auto it = slots_.find(name);
  if (it != slots_.end()) return it->second;
  Slot s;
  s.location = glGetUniformLocation(id(), name.c_str());
  return slots_.emplace(name, s).first->second;
}

GLint Program::location(const std::string& name) const { return slot(name).location; }

void Program::record(const std::string& name, GLenum type) const { slots_[name].set_as = type; }

void Program::set(const std::string& name, int v) const { glUniform1i(location(name), v); record(name, GL_INT); }
void Program::set(const std::string& name, float v) const { glUniform1f(location(name), v); record(name, GL_FLOAT); }
void Program::set(const std::string& name, const glm::vec2& v) const {
  glUniform2fv(location(name), 1, glm::value_ptr(v));
  record(name, GL_FLOAT_VEC2);
}
void Program::set(const std::string& name, const glm::vec3& v) const {
  glUniform3fv(location(name), 1, glm::value_ptr(v));
  record(name, GL_FLOAT_VEC3);
}
void Program::set(const std::string& name, const glm::vec4& v) const {
  glUniform4fv(location(name), 1, glm::value_ptr(v));
  record(name, GL_FLOAT_VEC4);
}
void Program::set(const std::string& name, const glm::mat3& v) const {
  glUniformMatrix3fv(location(name), 1, GL_FALSE, glm::value_ptr(v));
  record(name, GL_FLOAT_MAT3);
}
void Program::set(const std::string& name, const glm::mat4& v) const {
  glUniformMatrix4fv(location(name), 1, GL_FALSE, glm::value_ptr(v));
  record(name, GL_FLOAT_MAT4);
}

namespace {

// GLSL's name for a uniform type (those a lab could declare).
std::string glsl_type_name(GLenum type) {
  switch (type) {
    case GL_FLOAT: return "float";
    case GL_FLOAT_VEC2: return "vec2";
    case GL_FLOAT_VEC3: return "vec3";
    case GL_FLOAT_VEC4: return "vec4";
    case GL_INT: return "int";
    case GL_INT_VEC2: return "ivec2";
    case GL_INT_VEC3: return "ivec3";
    case GL_INT_VEC4: return "ivec4";
    case GL_UNSIGNED_INT: return "uint";
    case GL_BOOL: return "bool";
    case GL_BOOL_VEC2: return "bvec2";
    case GL_BOOL_VEC3: return "bvec3";
    case GL_BOOL_VEC4: return "bvec4";
    case GL_FLOAT_MAT2: return "mat2";
    case GL_FLOAT_MAT3: return "mat3";
    case GL_FLOAT_MAT4: return "mat4";
    case GL_SAMPLER_2D: return "sampler2D";
    case GL_SAMPLER_3D: return "sampler3D";
    case GL_SAMPLER_CUBE: return "samplerCube";
    default: return "a type the framework does not set";
  }
}

bool is_sampler(GLenum type) {
  switch (type) {
    case GL_SAMPLER_1D: case GL_SAMPLER_2D: case GL_SAMPLER_3D: case GL_SAMPLER_CUBE:
    case GL_SAMPLER_2D_SHADOW: case GL_SAMPLER_2D_ARRAY: case GL_SAMPLER_BUFFER:
    case GL_INT_SAMPLER_2D: case GL_UNSIGNED_INT_SAMPLER_2D: case GL_SAMPLER_2D_RECT:
      return true;
    default:
      return false;
  }
}

// Whether glUniform* for a value of type `set_as` may set a uniform declared `declared`.
bool accepts(GLenum declared, GLenum set_as) {
  if (declared == set_as) return true;
  switch (set_as) {
    case GL_INT: return declared == GL_BOOL || is_sampler(declared);
    case GL_FLOAT: return declared == GL_BOOL;
    case GL_FLOAT_VEC2: return declared == GL_BOOL_VEC2;
    case GL_FLOAT_VEC3: return declared == GL_BOOL_VEC3;
    case GL_FLOAT_VEC4: return declared == GL_BOOL_VEC4;
    default: return false;
  }
}

}  // namespace

std::string Program::declaration_site(const std::string& uniform) const {
  for (const AssembledShader& source : sources_) {
    std::istringstream lines(source.text);
    std::string line;
    for (size_t n = 0; std::getline(lines, line); ++n) {
      if (n >= source.lines.size() || !declares_uniform(line, uniform)) continue;
      const SourceLine& at = source.lines[n];
      return source.files[static_cast<size_t>(at.file)] + ":" + std::to_string(at.line);
    }
  }
  return main_file();
}

std::string Program::main_file() const { return sources_.empty() ? std::string("?") : sources_.back().files.front(); }

Program::UniformProblems Program::uniform_problems() const {
  UniformProblems problems;
  GLint count = 0, longest = 0;
  glGetProgramiv(id(), GL_ACTIVE_UNIFORMS, &count);
  glGetProgramiv(id(), GL_ACTIVE_UNIFORM_MAX_LENGTH, &longest);
  std::string pass;
  for (const AssembledShader& s : sources_) pass += (pass.empty() ? "" : " + ") + s.files.front();
  for (GLuint i = 0; i < static_cast<GLuint>(count); ++i) {
    std::vector<char> buffer(static_cast<size_t>(std::max(longest, 1)) + 1, '\0');
    GLsizei length = 0;
    GLint size = 0, block = -1;
    GLenum type = 0;
    glGetActiveUniform(id(), i, static_cast<GLsizei>(buffer.size()), &length, &size, &type, buffer.data());
    glGetActiveUniformsiv(id(), 1, &i, GL_UNIFORM_BLOCK_INDEX, &block);
    if (block != -1) continue;  // a uniform block's member: set through its buffer, not by name
    std::string name(buffer.data(), static_cast<size_t>(length));
    if (name.rfind("gl_", 0) == 0 || name.rfind(kLoopGuardPrefix, 0) == 0) continue;  // GL's, or the loop guard's
    const size_t bracket = name.find('[');
    const std::string base = name.substr(0, bracket);
    auto it = slots_.find(base);
    if (it == slots_.end() && bracket != std::string::npos) it = slots_.find(name);
    const std::string site = declaration_site(base.substr(0, base.find('.')));
    if (it == slots_.end()) {
      problems.unset.push_back(site + ": uniform `" + base + "' is never set by the framework for " + pass +
                               ", so it reads 0 (use a const for a value of your own)");
    } else if (it->second.set_as != 0 && !accepts(type, it->second.set_as)) {
      problems.mistyped.push_back(site + ": uniform `" + base + "' is declared " + glsl_type_name(type) +
                                  ", but the framework sets it as " + glsl_type_name(it->second.set_as) +
                                  " (include uniforms.glsl or geometry_uniforms.glsl rather than declaring it yourself)");
    }
  }
  return problems;
}

Texture2D::Texture2D(int width, int height, TextureFormat fmt, const void* data)
    : Texture2D(fmt, false, {TextureLevelData{width, height, data, 0}}) {
  set_filter(GL_NEAREST, GL_NEAREST);
}

Texture2D::Texture2D(TextureFormat fmt, bool compressed, const std::vector<TextureLevelData>& levels)
    : width_(levels.at(0).width), height_(levels.at(0).height), format_(fmt) {
  GLuint id = 0;
  glGenTextures(1, &id);
  texture_ = GlName<delete_texture>(id);
  glBindTexture(GL_TEXTURE_2D, id);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  for (size_t level = 0; level < levels.size(); ++level) {
    const TextureLevelData& l = levels[level];
    if (compressed)
      glCompressedTexImage2D(GL_TEXTURE_2D, static_cast<GLint>(level), fmt.internal_format, l.width, l.height, 0,
                             static_cast<GLsizei>(l.bytes), l.data);
    else
      glTexImage2D(GL_TEXTURE_2D, static_cast<GLint>(level), static_cast<GLint>(fmt.internal_format), l.width, l.height,
                   0, fmt.format, l.data ? fmt.type : type_for_storage_only(fmt.internal_format, fmt.type), l.data);
  }
  set_max_level(static_cast<int>(levels.size()) - 1);
  set_filter(GL_LINEAR_MIPMAP_LINEAR, GL_LINEAR);
  set_wrap(GL_CLAMP_TO_EDGE, GL_CLAMP_TO_EDGE);
}

void Texture2D::bind(int unit) const {
  glActiveTexture(GL_TEXTURE0 + static_cast<GLenum>(unit));
  glBindTexture(GL_TEXTURE_2D, texture_.get());
}

void Texture2D::set_filter(GLenum min_filter, GLenum mag_filter) const {
  glBindTexture(GL_TEXTURE_2D, texture_.get());
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, static_cast<GLint>(min_filter));
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, static_cast<GLint>(mag_filter));
}

void Texture2D::set_max_level(int level) const {
  glBindTexture(GL_TEXTURE_2D, texture_.get());
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, level);
}

void Texture2D::set_wrap(GLenum wrap_s, GLenum wrap_t) const {
  glBindTexture(GL_TEXTURE_2D, texture_.get());
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, static_cast<GLint>(wrap_s));
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, static_cast<GLint>(wrap_t));
}

Sampler::Sampler(GLenum min_filter, GLenum mag_filter, GLenum wrap_s, GLenum wrap_t) {
  GLuint id = 0;
  glGenSamplers(1, &id);
  sampler_ = GlName<delete_sampler>(id);
  glSamplerParameteri(id, GL_TEXTURE_MIN_FILTER, static_cast<GLint>(min_filter));
  glSamplerParameteri(id, GL_TEXTURE_MAG_FILTER, static_cast<GLint>(mag_filter));
  glSamplerParameteri(id, GL_TEXTURE_WRAP_S, static_cast<GLint>(wrap_s));
  glSamplerParameteri(id, GL_TEXTURE_WRAP_T, static_cast<GLint>(wrap_t));
}

Framebuffer::Framebuffer() {
  GLuint id = 0;
  glGenFramebuffers(1, &id);
  fbo_ = GlName<delete_framebuffer>(id);
}

void Framebuffer::attach_color(int index, const Texture2D& texture, int level) const {
  bind();
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(index), GL_TEXTURE_2D, texture.id(),
                         level);
}

void Framebuffer::attach_depth(const Texture2D& texture) const {
  bind();
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, texture.id(), 0);
}

void Framebuffer::set_draw_buffers(int count) const {
  bind();
  std::vector<GLenum> buffers;
  for (int i = 0; i < count; ++i) buffers.push_back(GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(i));
  glDrawBuffers(count, buffers.data());
}

std::string Framebuffer::incomplete_reason() const {
  bind();
  switch (glCheckFramebufferStatus(GL_FRAMEBUFFER)) {
    case GL_FRAMEBUFFER_COMPLETE: return "";
    case GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT: return "GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT";
    case GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT: return "GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT";
    case GL_FRAMEBUFFER_INCOMPLETE_DRAW_BUFFER: return "GL_FRAMEBUFFER_INCOMPLETE_DRAW_BUFFER";
    case GL_FRAMEBUFFER_UNSUPPORTED: return "GL_FRAMEBUFFER_UNSUPPORTED";
    case GL_FRAMEBUFFER_INCOMPLETE_MULTISAMPLE: return "GL_FRAMEBUFFER_INCOMPLETE_MULTISAMPLE";
    default: return "framebuffer incomplete (unknown status)";
  }
}

Mesh::Mesh(const std::vector<Vertex>& vertices, const std::vector<uint32_t>& indices)
    : index_count_(static_cast<GLsizei>(indices.size())) {
  GLuint ids[2] = {0, 0};
  GLuint vao = 0;
  glGenVertexArrays(1, &vao);
  glGenBuffers(2, ids);
  vao_ = GlName<delete_vertex_array>(vao);
  vbo_ = GlName<delete_buffer>(ids[0]);
  ebo_ = GlName<delete_buffer>(ids[1]);
  glBindVertexArray(vao);
  glBindBuffer(GL_ARRAY_BUFFER, ids[0]);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices.size() * sizeof(Vertex)), vertices.data(), GL_STATIC_DRAW);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ids[1]);
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(indices.size() * sizeof(uint32_t)), indices.data(), GL_STATIC_DRAW);
  auto attribute = [](GLuint location, GLint size, size_t offset, GLenum type = GL_FLOAT, GLboolean normalized = GL_FALSE) {
    glEnableVertexAttribArray(location);
    glVertexAttribPointer(location, size, type, normalized, sizeof(Vertex), reinterpret_cast<const void*>(offset));
  };
  attribute(KIT_ATTR_POSITION, 3, offsetof(Vertex, position));
  attribute(KIT_ATTR_NORMAL, 3, offsetof(Vertex, normal));
  attribute(KIT_ATTR_TEXCOORD, 2, offsetof(Vertex, texcoord));
  attribute(KIT_ATTR_TANGENT, 4, offsetof(Vertex, tangent));
  // UV slot 1 and COLOR_0 are fetched per vertex only where a vertex holds another value
  // than the default: a mesh without them (most) leaves their arrays disabled, and the
  // vertex stage reads the attribute's current value instead, the same default
  // (draw() sets it: white for COLOR_0, GL's (0, 0, 0, 1) for slot 1, whose xy is zero).
  const auto has = [&](auto differs) { return std::any_of(vertices.begin(), vertices.end(), differs); };
  if (has([](const Vertex& v) { return v.texcoord1 != glm::vec2(0.0f); }))
    attribute(KIT_ATTR_TEXCOORD1, 2, offsetof(Vertex, texcoord1));
  else
    fetch_defaults_ |= kDefaultTexcoord1;
  if (has([](const Vertex& v) { return v.color != glm::u16vec4(Vertex::kVertexColorOne); }))
    attribute(KIT_ATTR_COLOR, 4, offsetof(Vertex, color), GL_UNSIGNED_SHORT, GL_TRUE);
  else
    fetch_defaults_ |= kDefaultColor;
  glBindVertexArray(0);
}

void Mesh::set_default_attributes() const {
  // Current values are context state, not the VAO's: set for every draw that reads them.
  if (fetch_defaults_ & kDefaultTexcoord1) glVertexAttrib4f(KIT_ATTR_TEXCOORD1, 0.0f, 0.0f, 0.0f, 1.0f);
  if (fetch_defaults_ & kDefaultColor) glVertexAttrib4f(KIT_ATTR_COLOR, 1.0f, 1.0f, 1.0f, 1.0f);
}

void Mesh::draw() const {
  glBindVertexArray(vao_.get());
  set_default_attributes();
  glDrawElements(GL_TRIANGLES, index_count_, GL_UNSIGNED_INT, nullptr);
}

void Mesh::draw_instanced(int instances) const {
  glBindVertexArray(vao_.get());
  set_default_attributes();
  glDrawElementsInstanced(GL_TRIANGLES, index_count_, GL_UNSIGNED_INT, nullptr, instances);
}

FullscreenTriangle::FullscreenTriangle() {
  GLuint vao = 0;
  glGenVertexArrays(1, &vao);
  vao_ = GlName<delete_vertex_array>(vao);
}

void FullscreenTriangle::draw() const {
  glBindVertexArray(vao_.get());
  glDrawArrays(GL_TRIANGLES, 0, 3);
}

namespace {
// What every fullscreen pass starts with: `target` bound, the viewport its size, culling off.
void begin_fullscreen_pass(const Framebuffer& target, int width, int height) {
  target.bind();
  glViewport(0, 0, width, height);
  glDisable(GL_CULL_FACE);
}

// A browser's program (loop_guard.h) learns how many iterations its loops may run in this
// pass; the desktop's have no such uniform.
void set_loop_budget(const Program& program, int width, int height) {
  if (program.has(kLoopBudgetUniform)) program.set(kLoopBudgetUniform, loop_budget(width, height));
}
}  // namespace

void FullscreenTriangle::pass(const Program& program, const Framebuffer& target, int width, int height,
                              bool additive) const {
  begin_fullscreen_pass(target, width, height);
  glDisable(GL_DEPTH_TEST);
  if (additive) {
    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_ONE, GL_ONE, GL_ZERO, GL_ONE);
  } else {
    glDisable(GL_BLEND);
  }
  program.use();
  set_loop_budget(program, width, height);
  draw();
  if (additive) glDisable(GL_BLEND);
}

void FullscreenTriangle::pass_over_surfaces(const Program& program, const Framebuffer& target, int width,
                                            int height) const {
  begin_fullscreen_pass(target, width, height);
  glDisable(GL_BLEND);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_GREATER);
  glDepthMask(GL_FALSE);
  set_depth_range(1.0, 1.0);
  program.use();
  set_loop_budget(program, width, height);
  draw();
  set_depth_range(0.0, 1.0);
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_LESS);
  glDisable(GL_DEPTH_TEST);
}

}  // namespace kit

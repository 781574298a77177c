#include "gl_objects.h"

#include <glm/gtc/type_ptr.hpp>

#include "error.h"
#include "gbuffer_layout.h"

namespace kit {

void delete_texture(GLuint id) { glDeleteTextures(1, &id); }
void delete_framebuffer(GLuint id) { glDeleteFramebuffers(1, &id); }
void delete_buffer(GLuint id) { glDeleteBuffers(1, &id); }
void delete_vertex_array(GLuint id) { glDeleteVertexArrays(1, &id); }
void delete_program(GLuint id) { glDeleteProgram(id); }

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

Program::Program(const ShaderLibrary& library, const std::string& vertex, const std::string& fragment) {
  AssembledShader vs = library.assemble(vertex);
  AssembledShader fs = library.assemble(fragment);
  for (const auto* s : {&vs, &fs}) source_paths_.insert(source_paths_.end(), s->paths.begin(), s->paths.end());
  GLuint v = compile(GL_VERTEX_SHADER, vs);
  GLuint f = 0;
  try {
    f = compile(GL_FRAGMENT_SHADER, fs);
  } catch (...) {
    glDeleteShader(v);
    throw;
  }
  program_ = GlName<delete_program>(link({v, f}, vs.files.front() + " + " + fs.files.front()));
}

Program::Program(const ShaderLibrary& library, const std::string& compute) {
  AssembledShader cs = library.assemble(compute);
  source_paths_ = cs.paths;
  GLuint shader = compile(GL_COMPUTE_SHADER, cs);
  program_ = GlName<delete_program>(link({shader}, cs.files.front()));
}

GLint Program::location(const std::string& name) const {
  auto it = locations_.find(name);
  if (it != locations_.end()) return it->second;
  GLint loc = glGetUniformLocation(program_.get(), name.c_str());
  locations_.emplace(name, loc);
  return loc;
}

void Program::set(const std::string& name, int v) const { glUniform1i(location(name), v); }
void Program::set(const std::string& name, float v) const { glUniform1f(location(name), v); }
void Program::set(const std::string& name, const glm::vec2& v) const { glUniform2fv(location(name), 1, glm::value_ptr(v)); }
void Program::set(const std::string& name, const glm::vec3& v) const { glUniform3fv(location(name), 1, glm::value_ptr(v)); }
void Program::set(const std::string& name, const glm::vec4& v) const { glUniform4fv(location(name), 1, glm::value_ptr(v)); }
void Program::set(const std::string& name, const glm::mat3& v) const { glUniformMatrix3fv(location(name), 1, GL_FALSE, glm::value_ptr(v)); }
void Program::set(const std::string& name, const glm::mat4& v) const { glUniformMatrix4fv(location(name), 1, GL_FALSE, glm::value_ptr(v)); }

Texture2D::Texture2D(int width, int height, TextureFormat fmt, const void* data, bool mipmaps)
    : width_(width), height_(height), format_(fmt) {
  GLuint id = 0;
  glGenTextures(1, &id);
  texture_ = GlName<delete_texture>(id);
  glBindTexture(GL_TEXTURE_2D, id);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, static_cast<GLint>(fmt.internal_format), width, height, 0, fmt.format, fmt.type, data);
  if (mipmaps) {
    glGenerateMipmap(GL_TEXTURE_2D);
    set_filter(GL_LINEAR_MIPMAP_LINEAR, GL_LINEAR);
  } else {
    set_filter(GL_NEAREST, GL_NEAREST);
  }
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

void Texture2D::set_wrap(GLenum wrap_s, GLenum wrap_t) const {
  glBindTexture(GL_TEXTURE_2D, texture_.get());
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, static_cast<GLint>(wrap_s));
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, static_cast<GLint>(wrap_t));
}

Framebuffer::Framebuffer() {
  GLuint id = 0;
  glGenFramebuffers(1, &id);
  fbo_ = GlName<delete_framebuffer>(id);
}

void Framebuffer::attach_color(int index, const Texture2D& texture) const {
  bind();
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(index), GL_TEXTURE_2D, texture.id(), 0);
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
  auto attribute = [](GLuint location, GLint size, size_t offset) {
    glEnableVertexAttribArray(location);
    glVertexAttribPointer(location, size, GL_FLOAT, GL_FALSE, sizeof(Vertex), reinterpret_cast<const void*>(offset));
  };
  attribute(KIT_ATTR_POSITION, 3, offsetof(Vertex, position));
  attribute(KIT_ATTR_NORMAL, 3, offsetof(Vertex, normal));
  attribute(KIT_ATTR_TEXCOORD, 2, offsetof(Vertex, texcoord));
  attribute(KIT_ATTR_TANGENT, 4, offsetof(Vertex, tangent));
  glBindVertexArray(0);
}

void Mesh::draw() const {
  glBindVertexArray(vao_.get());
  glDrawElements(GL_TRIANGLES, index_count_, GL_UNSIGNED_INT, nullptr);
}

void Mesh::draw_instanced(int instances) const {
  glBindVertexArray(vao_.get());
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

void FullscreenTriangle::pass(const Program& program, const Framebuffer& target, int width, int height) const {
  target.bind();
  glViewport(0, 0, width, height);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  program.use();
  draw();
}

}  // namespace kit

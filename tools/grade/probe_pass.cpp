#include "probe_pass.h"

#include <memory>
#include <vector>

#include "base/error.h"
#include "gl/gl.h"
#include "gl/gl_flavour.h"
#include "gl/gl_objects.h"
#include "gl/shader_source.h"
#include "gbuffer_layout.h"  // KIT_UNIT_*
#include "render/renderer.h"  // set_resource_bindings

namespace kit::grade {

namespace {

constexpr TextureFormat kProbeFormat{GL_RGBA32F, GL_RGBA, GL_FLOAT};

// The first line of a build error, with the next where it only introduces it ("compile
// error in FILE:"): enough to say why a function was not probed.
std::string first_line(const std::string& text) {
  const size_t end = text.find('\n');
  if (end == std::string::npos) return text;
  std::string line = text.substr(0, end);
  if (!line.empty() && line.back() == ':') {
    const size_t next = text.find('\n', end + 1);
    line += " " + text.substr(end + 1, next == std::string::npos ? std::string::npos : next - end - 1);
  }
  return line;
}

// What a probe draws into: one float RGBA texel per case, `probe.column` deciding its shape.
// Made before the probe's inputs are bound: making a texture binds it to the active unit.
class ProbeTarget {
 public:
  explicit ProbeTarget(const FunctionProbe& probe)
      : probe_(probe),
        width_(probe.column ? 1 : static_cast<int>(probe.cases.size())),
        height_(probe.column ? static_cast<int>(probe.cases.size()) : 1),
        values_(width_, height_, kProbeFormat) {
    target_.attach_color(0, values_);
    target_.set_draw_buffers(1);
    if (const std::string why = target_.incomplete_reason(); !why.empty()) throw Error(kind() + ": the target is " + why);
  }
  int width() const { return width_; }
  int height() const { return height_; }

  // Sets the probe's uniforms on `program` (in use, its inputs bound), draws it over the
  // target and reads the values back.
  ProbeValues draw(const Program& program, const FullscreenTriangle& triangle) const {
    for (const ProbeUniform& u : probe_.uniforms) {
      if (u.integer) program.set(u.name, static_cast<int>(u.value));
      else program.set(u.name, u.value);
    }
    triangle.pass(program, target_, width_, height_);
    ProbeValues out;
    out.values.resize(probe_.cases.size());
    target_.bind();
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    read_colour_pixels_as_float(width_, height_, &out.values[0].x);
    if (const GLenum error = glGetError(); error != GL_NO_ERROR)
      throw Error(kind() + ": GL error " + std::to_string(error) + " while probing " + probe_.part());
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    return out;
  }

 private:
  std::string kind() const { return probe_.pass ? "pass probes" : "function probes"; }
  const FunctionProbe& probe_;
  int width_, height_;
  Texture2D values_;
  Framebuffer target_;
};

ProbeValues draw_probe(const FunctionProbe& probe, const Program& program, const FullscreenTriangle& triangle) {
  const int width = static_cast<int>(probe.cases.size());
  std::vector<float> texels(static_cast<size_t>(width) * kProbeTexels * 4, 0.0f);
  for (int x = 0; x < width; ++x) {
    const std::vector<float>& in = probe.cases[static_cast<size_t>(x)].inputs;
    for (size_t k = 0; k < in.size() && k < static_cast<size_t>(kProbeTexels) * 4; ++k)
      texels[(k / 4 * static_cast<size_t>(width) + static_cast<size_t>(x)) * 4 + k % 4] = in[k];
  }
  Texture2D inputs(width, kProbeTexels, kProbeFormat, texels.data());
  const ProbeTarget target(probe);
  program.use();
  inputs.bind(0);
  program.set("u_probe_inputs", 0);
  program.set("u_probe_function", probe.index);
  return target.draw(program, triangle);
}

// A pass probe (function_probes.h, FunctionProbe::pass): the lab's own pass over one texel
// per case, its samplers' textures holding the cases' values (RGBA16F, as the passes' own).
ProbeValues draw_pass_probe(const FunctionProbe& probe, const Program& program, const FullscreenTriangle& triangle) {
  const ProbeTarget target(probe);
  const size_t n = probe.cases.size();
  std::vector<std::unique_ptr<Texture2D>> inputs;
  size_t offset = 0;
  for (size_t a = 0; a < probe.arguments.size(); ++a, offset += 3) {
    std::vector<float> texels(n * 4, 0.0f);
    for (size_t i = 0; i < n; ++i)
      for (size_t k = 0; k < 3; ++k) texels[i * 4 + k] = probe.cases[i].inputs.at(offset + k);
    inputs.push_back(std::make_unique<Texture2D>(target.width(), target.height(),
                                                 TextureFormat{GL_RGBA16F, GL_RGBA, GL_FLOAT}, texels.data()));
  }
  program.use();
  // Bound once all are made (each is made on the active unit).
  for (size_t a = 0; a < inputs.size(); ++a) inputs[a]->bind(probe.arguments[a].name == "u_bloom" ? KIT_UNIT_BLOOM : KIT_UNIT_HDR);
  program.set("u_resolution", glm::vec2(static_cast<float>(target.width()), static_cast<float>(target.height())));
  return target.draw(program, triangle);
}

}  // namespace

std::map<std::string, ProbeValues> run_function_probes(const Stage& stage, const std::filesystem::path& lab_root,
                                                       const nlohmann::json& reference) {
  std::map<std::string, ProbeValues> out;
  const std::vector<FunctionProbe> probes = probes_to_run(stage.number, reference);
  if (probes.empty()) return out;
  FullscreenTriangle triangle;
  std::map<std::string, std::vector<const FunctionProbe*>> by_shader;
  std::map<std::string, std::vector<const FunctionProbe*>> passes;  // by the lab's file
  for (const FunctionProbe& p : probes) (p.pass ? passes : by_shader)[p.shader].push_back(&p);
  for (const auto& [file, list] : passes) {
    std::unique_ptr<Program> program;
    try {
      program = std::make_unique<Program>(stage_library(stage, lab_root), "fullscreen.vert", file);
      set_resource_bindings(*program);
    } catch (const Error& e) {
      for (const FunctionProbe* p : list) out[p->id].error = first_line(e.what());
      continue;
    }
    for (const FunctionProbe* p : list) out[p->id] = draw_pass_probe(*p, *program, triangle);
  }
  for (const auto& [shader, list] : by_shader) {
    ShaderLibrary library = stage_library(stage, lab_root);
    // Every call in one program first: one build where the files declare every function.
    for (const FunctionProbe* p : list) library.set_define(p->define, true);
    std::unique_ptr<Program> all;
    try {
      all = std::make_unique<Program>(library, "fullscreen.vert", shader);
    } catch (const Error&) {
    }
    if (all) {
      for (const FunctionProbe* p : list) out[p->id] = draw_probe(*p, *all, triangle);
      continue;
    }
    for (const FunctionProbe* p : list) library.set_define(p->define, false);
    std::map<std::string, std::shared_ptr<Program>> built;  // by define: two probes may share one
    for (const FunctionProbe* p : list) {
      auto it = built.find(p->define);
      if (it == built.end()) {
        library.set_define(p->define, true);
        std::shared_ptr<Program> program;
        try {
          program = std::make_shared<Program>(library, "fullscreen.vert", shader);
        } catch (const Error& e) {
          out[p->id].error = first_line(e.what());
        }
        library.set_define(p->define, false);
        it = built.emplace(p->define, program).first;
      }
      if (it->second) out[p->id] = draw_probe(*p, *it->second, triangle);
      else if (out[p->id].error.empty()) out[p->id].error = "the function does not build";
    }
  }
  return out;
}

void report_function_probes(const Stage& stage, const std::filesystem::path& lab_root, const nlohmann::json& reference,
                            nlohmann::json& report) {
  if (function_probes(stage.number).empty()) return;
  try {
    for (const auto& [id, values] : run_function_probes(stage, lab_root, reference)) report["probes"][id] = probe_values_json(values);
  } catch (const Error& e) {
    report["probes_error"] = e.what();
  }
}

}  // namespace kit::grade

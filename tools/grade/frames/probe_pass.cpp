#include "frames/probe_pass.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <memory>
#include <map>
#include <utility>
#include <vector>

#include "base/error.h"
#include "gbuffer_layout.h"  // KIT_UNIT_*
#include "gl/gl.h"
#include "gl/gl_flavour.h"
#include "gl/gl_objects.h"
#include "gl/shader_source.h"
#include "render/renderer.h"  // set_resource_bindings, set_frame_uniforms, draw_item
#include "scene/scene.h"

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

// What a probe draws into: one float RGBA texel per case, `probe.column` deciding its shape;
// for a geometry probe, one such attachment for each of the G-buffer's.
// Made before the probe's inputs are bound: making a texture binds it to the active unit.
class ProbeTarget {
 public:
  explicit ProbeTarget(const FunctionProbe& probe)
      : probe_(probe),
        width_(probe.column ? 1 : static_cast<int>(probe.cases.size())),
        height_(probe.column ? static_cast<int>(probe.cases.size()) : 1) {
    const int attachments = probe.geometry ? KIT_GBUF_COUNT : 1;
    for (int k = 0; k < attachments; ++k) values_.emplace_back(width_, height_, kProbeFormat);
    for (int k = 0; k < attachments; ++k) target_.attach_color(k, values_[static_cast<size_t>(k)]);
    target_.set_draw_buffers(attachments);
    if (const std::string why = target_.incomplete_reason(); !why.empty()) throw Error(kind() + ": the target is " + why);
  }
  int width() const { return width_; }
  int height() const { return height_; }
  const Framebuffer& framebuffer() const { return target_; }

  // Sets the probe's uniforms on `program` (in use, its inputs bound), draws it over the
  // target and reads the values back.
  ProbeValues draw(const Program& program, const FullscreenTriangle& triangle) const {
    for (const ProbeUniform& u : probe_.uniforms) {
      if (u.is_vec3) program.set(u.name, u.vec3);
      else if (u.integer) program.set(u.name, static_cast<int>(u.value));
      else program.set(u.name, u.value);
    }
    triangle.pass(program, target_, width_, height_);
    return read(0);
  }

  // The values of attachment `attachment`, once drawn.
  ProbeValues read(int attachment) const {
    ProbeValues out;
    out.values.resize(probe_.cases.size());
    target_.bind();
    glReadBuffer(GL_COLOR_ATTACHMENT0 + static_cast<GLenum>(attachment));
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
  std::vector<Texture2D> values_;
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

// The sizes of lab 6's maps in a pass probe: the real maps' shapes (equirectangular 2:1, the
// prefiltered map with every level the lab writes, the BRDF table the size kit_brdf_lut reads).
// The prefiltered map's smallest level is 8 x 4, so its coordinates are still bilinear over
// the [0.25, 0.75] the probes look up.
constexpr int kProbeIrradianceWidth = 64;
constexpr int kProbePrefilteredWidth = 256;

// A map of a pass probe (function_probes.h, ProbeMap), sampled as the framework's own are:
// RGBA32F, bilinear (trilinear over levels), wrapping in u where it is equirectangular.
Texture2D probe_map(const ProbeMap& map) {
  const bool table = map.sampler == "u_brdf_lut";
  const bool levels = map.sampler == "u_prefiltered";
  const int width = table ? KIT_BRDF_LUT_SIZE : levels ? kProbePrefilteredWidth : kProbeIrradianceWidth;
  const int height = table ? KIT_BRDF_LUT_SIZE : width / 2;
  std::vector<std::vector<float>> texels;
  std::vector<TextureLevelData> data;
  for (int k = 0; k < (levels ? KIT_PREFILTER_LEVELS : 1); ++k) {
    const int w = std::max(width >> k, 1), h = std::max(height >> k, 1);
    std::vector<float>& level = texels.emplace_back(static_cast<size_t>(w) * h * 4);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        glm::vec3 v = map.value;
        if (map.fill == ProbeMap::Fill::Coordinates) v = glm::vec3((x + 0.5f) / w, (y + 0.5f) / h, map.value.z);
        if (map.fill == ProbeMap::Fill::Levels) v = map.value * (1.0f + static_cast<float>(k));
        float* at = &level[(static_cast<size_t>(y) * w + x) * 4];
        at[0] = v.x, at[1] = v.y, at[2] = v.z, at[3] = 1.0f;
      }
    data.push_back({w, h, level.data(), 0});
  }
  Texture2D texture(kProbeFormat, false, data);
  texture.set_filter(levels ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR, GL_LINEAR);
  texture.set_wrap(table ? GL_CLAMP_TO_EDGE : GL_REPEAT, GL_CLAMP_TO_EDGE);
  return texture;
}

// A pass probe (function_probes.h, FunctionProbe::pass): the lab's own pass over one texel
// per case, its samplers' textures holding the cases' values (alpha 1: the G-buffer's
// coverage), its maps filled as the probe says, and every other unit the framework binds
// holding one black texel, so that nothing a submission reads depends on the frames before.
ProbeValues draw_pass_probe(const FunctionProbe& probe, const Program& program, const FullscreenTriangle& triangle) {
  const ProbeTarget target(probe);
  const size_t n = probe.cases.size();
  std::map<int, Texture2D> bound;
  const float black[4] = {0.0f, 0.0f, 0.0f, 0.0f};
  for (int unit : sampler_units()) bound.emplace(unit, Texture2D(1, 1, kProbeFormat, black));
  const auto bind_at = [&](const std::string& sampler, Texture2D texture) {
    const int unit = sampler_unit(sampler);
    if (unit < 0) throw Error("pass probes: " + sampler + " is no sampler the framework binds");
    bound.at(unit) = std::move(texture);
  };
  size_t offset = 0;
  for (size_t a = 0; a < probe.arguments.size(); ++a, offset += 3) {
    std::vector<float> texels(n * 4, 1.0f);
    for (size_t i = 0; i < n; ++i)
      for (size_t k = 0; k < 3; ++k) texels[i * 4 + k] = probe.cases[i].inputs.at(offset + k);
    bind_at(probe.arguments[a].name, Texture2D(target.width(), target.height(), kProbeFormat, texels.data()));
  }
  for (const ProbeMap& map : probe.maps) bind_at(map.sampler, probe_map(map));
  // Lab 7: the lights kit_light reads, as the framework uploads them.
  const LightBuffers lights = probe.light_volume ? LightBuffers(probe.light_volume->lights, probe.light_volume->volume_radii)
                                                 : LightBuffers();
  if (probe.light_volume) {
    if (lights.in_texture()) throw Error("pass probes: " + probe.id + " has more lights than the uniform block holds");
    lights.bind();
  }
  program.use();
  // Bound once all are made (each is made on the active unit).
  for (const auto& [unit, texture] : bound) texture.bind(unit);
  program.set("u_resolution", glm::vec2(static_cast<float>(target.width()), static_cast<float>(target.height())));
  return target.draw(program, triangle);
}

// A geometry pass probe (function_probes.h, GeometryProbeSetup): a scene of one quad per
// case, drawn by the framework's own draw_item with the lab's gbuffer.vert and gbuffer.frag
// into a row of float G-buffer attachments (0 where nothing is written), one read back.
ProbeValues draw_geometry_probe(const FunctionProbe& probe, const Program& program) {
  const GeometryProbeSetup& setup = *probe.geometry;
  const int n = static_cast<int>(probe.cases.size());
  Scene scene;
  for (const ImageRgba8& image : setup.images)
    scene.images.push_back({"a probe texture", image.width, image.height, {}, image});
  scene.samplers.push_back({GL_NEAREST, GL_NEAREST, GL_REPEAT, GL_REPEAT});
  scene.materials.push_back(setup.material);
  // Each quad around its texel's centre in the view's plane z = -1, taken back to object space.
  const glm::mat4 to_object = glm::inverse(setup.view * setup.model);
  const float half_width = 1.0f / static_cast<float>(n);
  for (int i = 0; i < n; ++i) {
    Primitive quad;
    quad.material = 0;
    const glm::vec3 centre = geometry_probe_view_point(i, n);
    for (const glm::vec2 corner : {glm::vec2(-1, -1), glm::vec2(1, -1), glm::vec2(1, 1), glm::vec2(-1, 1)}) {
      Vertex v = geometry_probe_vertex(probe.cases[static_cast<size_t>(i)].inputs);
      v.position = glm::vec3(to_object * glm::vec4(centre + glm::vec3(corner.x * half_width, corner.y * 2.0f, 0.0f), 1.0f));
      quad.vertices.push_back(v);
    }
    // Counter-clockwise on screen is the front; the other way round shows the back.
    quad.indices = setup.back_faces ? std::vector<uint32_t>{0, 2, 1, 0, 3, 2} : std::vector<uint32_t>{0, 1, 2, 0, 2, 3};
    scene.primitives.push_back(quad);
    scene.draws.push_back({i, setup.model});
  }
  const SceneGpu gpu(scene, TextureCompression::Off);
  const ProbeTarget target(probe);
  target.framebuffer().bind();
  glViewport(0, 0, n, 1);
  const GLboolean depth_test = glIsEnabled(GL_DEPTH_TEST);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glClearColor(0.0f, 0.0f, 0.0f, 0.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  RenderSettings settings;
  settings.width = n;
  settings.height = 1;
  set_frame_uniforms(program, geometry_probe_camera(setup.view), settings, 0);
  for (const DrawItem& draw : scene.draws) draw_item(program, scene, gpu, draw);
  end_scene_draws();
  ProbeValues out = target.read(setup.attachment);
  if (setup.alpha)
    for (glm::vec4& v : out.values) v = glm::vec4(v.a, 0.0f, 0.0f, 0.0f);
  if (depth_test) glEnable(GL_DEPTH_TEST);
  return out;
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
    // A geometry probe draws the lab's vertex stage too, lab 7's light_volume.frag the stage
    // that gives it its light (all of a file's probes are alike).
    const bool geometry = list.front()->geometry != nullptr;
    const char* vertex = geometry ? "gbuffer.vert" : list.front()->light_volume ? "probe_light_volume.vert" : "fullscreen.vert";
    std::unique_ptr<Program> program;
    try {
      program = std::make_unique<Program>(stage_library(stage, lab_root), vertex, file);
      set_resource_bindings(*program);
    } catch (const Error& e) {
      for (const FunctionProbe* p : list) out[p->id].error = first_line(e.what());
      continue;
    }
    for (const FunctionProbe* p : list)
      out[p->id] = geometry ? draw_geometry_probe(*p, *program) : draw_pass_probe(*p, *program, triangle);
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
  try {
    if (function_probes(stage.number).empty()) return;
    for (const auto& [id, values] : run_function_probes(stage, lab_root, reference)) report["probes"][id] = probe_values_json(values);
  } catch (const Error& e) {
    report["probes_error"] = e.what();
  }
}

}  // namespace kit::grade

// What every program is told (renderer.h): the texture unit of each sampler and the binding
// of each uniform block, the frame uniforms every pass reads, and the uniforms a frame's
// programs read but nothing set.
#include "render/renderer.h"

#include <algorithm>

#include "gbuffer_layout.h"

namespace kit {

namespace {

// Every sampler uniform the framework binds, with its texture unit.
const std::pair<const char*, int> kSamplerUnits[] = {
    {"u_gbuffer_position", KIT_UNIT_GBUF_POSITION}, {"u_gbuffer_normal", KIT_UNIT_GBUF_NORMAL},
    {"u_gbuffer_albedo", KIT_UNIT_GBUF_ALBEDO},     {"u_gbuffer_material", KIT_UNIT_GBUF_MATERIAL},
    {"u_gbuffer_emission", KIT_UNIT_GBUF_EMISSION}, {"u_gbuffer_depth", KIT_UNIT_GBUF_DEPTH},
    {"u_light_texture", KIT_UNIT_LIGHTS},
    {"u_hdr", KIT_UNIT_HDR},                        {"u_bloom", KIT_UNIT_BLOOM},
    {"u_ldr", KIT_UNIT_LDR},                        {"u_base_color_texture", KIT_UNIT_BASE_COLOR},
    {"u_metallic_roughness_texture", KIT_UNIT_METALLIC_ROUGHNESS},
    {"u_normal_texture", KIT_UNIT_NORMAL_MAP},      {"u_emissive_texture", KIT_UNIT_EMISSIVE},
    {"u_environment", KIT_UNIT_ENVIRONMENT},        {"u_irradiance", KIT_UNIT_IRRADIANCE},
    {"u_prefiltered", KIT_UNIT_PREFILTERED},        {"u_brdf_lut", KIT_UNIT_BRDF_LUT},
};

}  // namespace

void set_resource_bindings(const Program& program) {
  program.use();
  for (const auto& [name, unit] : kSamplerUnits) program.set(name, unit);
  // GL 3.3 has no layout(binding = N) for blocks: the program is told.
  const GLuint lights = glGetUniformBlockIndex(program.id(), "KitLightBlock");
  if (lights != GL_INVALID_INDEX) glUniformBlockBinding(program.id(), lights, KIT_BLOCK_LIGHTS);
}

int sampler_unit(const std::string& name) {
  for (const auto& [sampler, unit] : kSamplerUnits)
    if (name == sampler) return unit;
  return -1;
}

std::set<int> sampler_units() {
  std::set<int> units;
  for (const auto& [sampler, unit] : kSamplerUnits) units.insert(unit);
  return units;
}

Program make_program(const ShaderLibrary& library, const std::string& vs, const std::string& fs) {
  Program p(library, vs, fs);
  set_resource_bindings(p);
  // Leave no program current: if a later program of the same build fails, this
  // one is deleted while current, and a UI drawing afterwards would restore a dead name.
  glUseProgram(0);
  return p;
}

void set_frame_uniforms(const Program& p, const FrameCamera& camera, const RenderSettings& settings, int light_count) {
  p.use();
  glm::mat4 view_projection = camera.projection * camera.view;
  p.set("u_view", camera.view);
  p.set("u_projection", camera.projection);
  p.set("u_view_projection", view_projection);
  p.set("u_inv_view_projection", glm::inverse(view_projection));
  p.set("u_camera_position", camera.position);
  p.set("u_camera_near_far", glm::vec2(camera.znear, camera.zfar));
  p.set("u_resolution", glm::vec2(settings.width, settings.height));
  p.set("u_light_count", light_count);
  p.set("u_gamma", settings.gamma);
  p.set("u_attenuation_model", settings.attenuation_model);
  p.set("u_clear_color", settings.clear_color);
  p.set("u_bloom_threshold", settings.bloom_threshold);
  p.set("u_postprocess_enabled", settings.postprocess);
  p.set("u_custom_enabled", settings.custom_effect);
  p.set("u_time", settings.time);
}

void Renderer::set_frame_uniforms(const Program& p) const {
  kit::set_frame_uniforms(p, camera_, settings_, light_count_);
}

std::vector<std::string> Renderer::uniform_warnings() const {
  std::vector<std::string> out;
  for (const Program* program : used_)
    for (const std::string& line : program->uniform_problems().unset)
      if (std::find(out.begin(), out.end(), line) == out.end()) out.push_back(line);
  return out;
}

}  // namespace kit

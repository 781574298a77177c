// The lights a frame uploads (renderer.h): the scene's or the default rig's, the spawned
// extra lights, their flux, the buffers the lighting shaders read them from, and the
// defines that specialise those shaders to them.
#include "render/renderer.h"

#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <cmath>

#include "gbuffer_layout.h"

namespace kit {

float light_flux(const Light& light) {
  if (light.type == KIT_LIGHT_DIRECTIONAL) return 0.0f;
  if (light.type == KIT_LIGHT_SPOT)
    return glm::two_pi<float>() * (1.0f - 0.5f * (std::cos(light.inner_cone) + std::cos(light.outer_cone))) * light.intensity;
  return 2.0f * glm::two_pi<float>() * light.intensity;
}

std::vector<Light> spawned_lights(const Scene& scene, int count) {
  std::vector<Light> out;
  glm::vec3 lo = scene.bounds_min, hi = scene.bounds_max;
  glm::vec3 extent = hi - lo;
  for (int i = 0; i < count; ++i) {
    float t = (i + 0.5f) / static_cast<float>(count);
    float angle = 2.39996323f * static_cast<float>(i);
    float radius = std::sqrt(t);
    Light l;
    l.type = KIT_LIGHT_POINT;
    l.position = glm::vec3(lo.x + extent.x * (0.5f + 0.5f * radius * std::cos(angle)),
                           lo.y + 0.05f * extent.y + 0.1f + 0.3f * extent.y * std::fmod(t * 7.0f, 1.0f),
                           lo.z + extent.z * (0.5f + 0.5f * radius * std::sin(angle)));
    l.color = glm::vec3(0.5f + 0.5f * std::cos(angle), 0.5f + 0.5f * std::cos(angle + 2.1f), 0.5f + 0.5f * std::cos(angle + 4.2f));
    l.intensity = 0.5f;
    l.range = kSpawnedLightRange * std::max(glm::length(extent), 1e-3f);
    out.push_back(l);
  }
  return out;
}

std::vector<Light> default_light_rig(const Scene& scene, const Stage& stage, int attenuation_model) {
  struct RigLight {
    glm::vec3 direction;  // from the centre, before normalising
    glm::vec3 color;
    float irradiance;     // at the centre, in the units the lights' colour times intensity give
  };
  static const RigLight kRig[] = {
      {{-1.0f, 1.0f, 1.0f}, {1.0f, 0.95f, 0.88f}, 3.0f},   // key: warm, upper left, in front
      {{1.2f, 0.3f, 0.8f}, {0.85f, 0.9f, 1.0f}, 1.0f},     // fill: cool, right, lower
      {{0.2f, 1.0f, -1.5f}, {1.0f, 1.0f, 1.0f}, 1.5f},     // rim: above and behind
  };
  const glm::vec3 center = 0.5f * (scene.bounds_min + scene.bounds_max);
  const float radius = std::max(0.5f * glm::length(scene.bounds_max - scene.bounds_min), 1e-6f);
  const float distance = 3.0f * radius;
  // The falloff the stage's light_radiance applies at `distance` (attenuation.glsl).
  const bool falls_off = stage.number >= find_stage("attenuation").number;
  const float falloff = !falls_off ? 1.0f : attenuation_model == 1 ? 1.0f + distance * distance : distance * distance;
  std::vector<Light> out;
  for (const RigLight& r : kRig) {
    Light l;
    l.type = KIT_LIGHT_POINT;
    l.position = center + glm::normalize(r.direction) * distance;
    l.color = r.color;
    l.intensity = r.irradiance * falloff;
    out.push_back(l);
  }
  return out;
}

bool uses_default_light_rig(const Scene& scene, const RenderSettings& settings) {
  return settings.default_light_rig && scene.lights.empty();
}

bool uses_default_light_rig(const Scene& scene, const Stage& stage, const RenderSettings& settings) {
  return !stage.ibl && uses_default_light_rig(scene, settings);
}

std::vector<Light> frame_lights(const Scene& scene, const Stage& stage, const RenderSettings& settings,
                                std::vector<int>* list_index) {
  std::vector<Light> lights = uses_default_light_rig(scene, stage, settings)
                                  ? default_light_rig(scene, stage, settings.attenuation_model)
                                  : scene.lights;
  std::vector<Light> extra = spawned_lights(scene, settings.extra_lights);
  lights.insert(lights.end(), extra.begin(), extra.end());
  std::vector<int> index(lights.size());
  for (size_t i = 0; i < index.size(); ++i) index[i] = static_cast<int>(i);
  if (stage.light_volumes) {
    std::stable_partition(index.begin(), index.end(), [&](int i) { return lights[static_cast<size_t>(i)].type == KIT_LIGHT_DIRECTIONAL; });
    std::vector<Light> ordered;
    for (int i : index) ordered.push_back(lights[static_cast<size_t>(i)]);
    lights = std::move(ordered);
  }
  if (list_index) *list_index = std::move(index);
  return lights;
}

LightBuffers::LightBuffers(const std::vector<Light>& lights, const std::vector<float>& volume_radii) {
  auto all_of_type = [&](int type) {
    return !lights.empty() &&
           std::all_of(lights.begin(), lights.end(), [type](const Light& l) { return l.type == type; });
  };
  const bool without_range =
      std::none_of(lights.begin(), lights.end(), [](const Light& l) { return l.range > 0.0f; });
  const bool in_texture = lights.size() > size_t{KIT_LIGHT_BLOCK_CAPACITY};
  defines_ = {{kLightsInTexture, in_texture},
              {kLightsAllPoint, all_of_type(KIT_LIGHT_POINT)},
              {kLightsAllSpot, all_of_type(KIT_LIGHT_SPOT)},
              {kLightsAllDirectional, all_of_type(KIT_LIGHT_DIRECTIONAL)},
              {kLightsWithoutRange, without_range}};
  const size_t rows = std::max(lights.size(), size_t{KIT_LIGHT_BLOCK_CAPACITY});
  std::vector<float> texels(rows * KIT_LIGHT_TEXELS * 4, 0.0f);
  for (size_t i = 0; i < lights.size(); ++i) {
    const Light& l = lights[i];
    const float row[16] = {l.position.x, l.position.y, l.position.z, static_cast<float>(l.type),
                           l.direction.x, l.direction.y, l.direction.z, l.range,
                           l.color.r, l.color.g, l.color.b, l.intensity,
                           std::cos(l.inner_cone), std::cos(l.outer_cone), light_flux(l),
                           i < volume_radii.size() ? volume_radii[i] : 0.0f};
    std::copy(row, row + 16, &texels[i * KIT_LIGHT_TEXELS * 4]);
  }
  if (in_texture) {
    texture_ = Texture2D(KIT_LIGHT_TEXELS, static_cast<int>(rows), {GL_RGBA32F, GL_RGBA, GL_FLOAT}, texels.data());
    return;
  }
  GLuint id = 0;
  glGenBuffers(1, &id);
  block_ = GlName<delete_buffer>(id);
  glBindBuffer(GL_UNIFORM_BUFFER, id);
  glBufferData(GL_UNIFORM_BUFFER, static_cast<GLsizeiptr>(texels.size() * sizeof(float)), texels.data(), GL_STATIC_DRAW);
  glBindBuffer(GL_UNIFORM_BUFFER, 0);
}

void LightBuffers::apply_defines(ShaderLibrary& library, bool specialise) const {
  std::vector<std::pair<std::string, bool>> defines = defines_;
  if (!specialise)
    for (auto& [name, on] : defines) on = on && name == kLightsInTexture;
  library.set_defines(defines);
}

void LightBuffers::bind() const {
  if (in_texture())
    texture_.bind(KIT_UNIT_LIGHTS);
  else
    glBindBufferBase(GL_UNIFORM_BUFFER, KIT_BLOCK_LIGHTS, block_.get());
}

void apply_attenuation_model_define(ShaderLibrary& library, int model) {
  library.set_defines({{"KIT_ATTENUATION_MODEL_PHYSICAL", model == 0}, {"KIT_ATTENUATION_MODEL_SIMPLE", model == 1}});
}

void Renderer::upload_lights() {
  lit_frame_.reset();
  frame_lights_ = frame_lights(scene_, stage_, settings_, &frame_light_numbers_);
  light_count_ = static_cast<int>(frame_lights_.size());
  directional_count_ = static_cast<int>(std::count_if(frame_lights_.begin(), frame_lights_.end(),
                                                      [](const Light& l) { return l.type == KIT_LIGHT_DIRECTIONAL; }));
  std::vector<float> radii;
  const float epsilon = light_volume_epsilon(frame_lights_, settings_.gamma);
  for (const Light& l : frame_lights_)
    radii.push_back(l.type == KIT_LIGHT_DIRECTIONAL ? 0.0f : light_cutoff_radius(l, epsilon, settings_.attenuation_model));
  // After the radii: a light alone keeps the volume it has among the others.
  if (settings_.only_light >= 0)
    for (size_t j = 0; j < frame_lights_.size(); ++j)
      if (frame_light_numbers_[j] != settings_.only_light) frame_lights_[j].intensity = 0.0f;
  lights_ = LightBuffers(frame_lights_, radii);
  lights_.apply_defines(library_, settings_.specialise_shaders);
  // -1: neither model's define, u_attenuation_model a uniform (set_frame_uniforms).
  apply_attenuation_model_define(library_, settings_.specialise_shaders ? settings_.attenuation_model : -1);
  if (programs_ && (library_.defines() != programs_defines_ || settings_.specialise_shaders != shaders_specialised_))
    build_programs();
  lights_extra_ = settings_.extra_lights;
  lights_only_ = settings_.only_light;
  lights_default_rig_ = settings_.default_light_rig;
  lights_attenuation_model_ = settings_.attenuation_model;
  lights_gamma_ = settings_.gamma;
}

}  // namespace kit

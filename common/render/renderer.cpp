#include "render/renderer.h"

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_inverse.hpp>

#include <algorithm>
#include <chrono>

#include "base/error.h"
#include "gbuffer_layout.h"
#include "gl/gl_flavour.h"
#include "render/interface_check.h"
#include "scene/mesh_optimize.h"

namespace kit {

namespace {

constexpr TextureFormat kHdrFormat{GL_RGBA16F, GL_RGBA, GL_FLOAT};
constexpr TextureFormat kLdrFormat{GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE};
constexpr TextureFormat kDebugFormat{GL_RGBA32F, GL_RGBA, GL_FLOAT};

// Debug view modes understood by shaders/debug_view.frag.
int debug_mode(View view) {
  switch (view) {
    case View::Position: return 0;
    case View::Normal: return 1;
    case View::Albedo: return 2;
    case View::Material: return 3;
    case View::Depth: return 4;
    case View::Emission: return 5;
    default: return 2;
  }
}

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

struct Renderer::Programs {
  GeometryPrograms geometry;  // one program per material variant the scene's draws use
  Program lighting, display, bright, blur, composite, custom, debug;
  // Stage 6: the lab's precompute shaders, its IBL pass, and the framework's background.
  Program irradiance, prefilter, brdf_lut, ibl, background;
  // Stage 7: the lab's light volumes, and the framework's programs that count their work.
  Program volume, volume_count, volume_coverage, surface_count, volume_evidence, state_evidence;
};

View parse_view(const std::string& name) {
  static const std::pair<const char*, View> names[] = {
      {"final", View::Final},       {"position", View::Position}, {"normal", View::Normal}, {"albedo", View::Albedo},
      {"material", View::Material}, {"emission", View::Emission}, {"depth", View::Depth},   {"hdr", View::Hdr},
      {"irradiance", View::Irradiance}, {"prefiltered", View::Prefiltered}, {"brdf-lut", View::BrdfLut}};
  for (const auto& [n, v] : names)
    if (name == n) return v;
  throw Error("unknown view '" + name +
              "' (views: final, position, normal, albedo, material, emission, depth, hdr, and at stage 6 "
              "irradiance, prefiltered, brdf-lut)");
}

const char* view_name(View view) {
  switch (view) {
    case View::Final: return "final";
    case View::Position: return "position";
    case View::Normal: return "normal";
    case View::Albedo: return "albedo";
    case View::Material: return "material";
    case View::Emission: return "emission";
    case View::Depth: return "depth";
    case View::Hdr: return "hdr";
    case View::Irradiance: return "irradiance";
    case View::Prefiltered: return "prefiltered";
    case View::BrdfLut: return "brdf-lut";
  }
  return "?";
}

bool same_image_settings(const RenderSettings& a, const RenderSettings& b) {
  return a.gamma == b.gamma && a.attenuation_model == b.attenuation_model && a.postprocess == b.postprocess &&
         a.custom_effect == b.custom_effect && a.bloom_threshold == b.bloom_threshold &&
         a.blur_passes == b.blur_passes && a.clear_color == b.clear_color && a.extra_lights == b.extra_lights &&
         a.only_light == b.only_light &&
         a.frustum_culling == b.frustum_culling && a.texture_compression == b.texture_compression &&
         a.default_light_rig == b.default_light_rig &&
         a.light_markers == b.light_markers && a.environment == b.environment && a.ibl == b.ibl &&
         a.count_light_volume_work == b.count_light_volume_work;
}

bool is_precomputed_map(View view) {
  return view == View::Irradiance || view == View::Prefiltered || view == View::BrdfLut;
}

bool same_frame_camera(const FrameCamera& a, const FrameCamera& b) {
  return a.view == b.view && a.projection == b.projection && a.position == b.position && a.znear == b.znear &&
         a.zfar == b.zfar;
}

FrameCamera frame_camera(const Camera& camera, float aspect) {
  FrameCamera f;
  f.view = camera.view;
  f.projection = camera.projection(aspect);
  f.position = glm::vec3(glm::inverse(camera.view)[3]);
  f.znear = camera.znear;
  f.zfar = camera.zfar;
  return f;
}

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

const Material& draw_material(const Scene& scene, const DrawItem& draw) {
  static const Material kDefaultMaterial{};
  const Primitive& prim = scene.primitives[static_cast<size_t>(draw.primitive)];
  return prim.material >= 0 ? scene.materials[static_cast<size_t>(prim.material)] : kDefaultMaterial;
}

void draw_item(const Program& geometry, const Scene& scene, const SceneGpu& gpu, const DrawItem& d) {
  const Material& m = draw_material(scene, d);
  geometry.set("u_model", d.world);
  geometry.set("u_normal_matrix", glm::inverseTranspose(glm::mat3(d.world)));
  geometry.set("u_base_color_factor", m.base_color_factor);
  geometry.set("u_metallic_factor", m.metallic_factor);
  geometry.set("u_roughness_factor", m.roughness_factor);
  geometry.set("u_emissive_factor", m.emissive);
  geometry.set("u_normal_scale", m.normal_scale);
  geometry.set("u_has_normal_texture", m.texture(KIT_UNIT_NORMAL_MAP).image >= 0);
  geometry.set("u_alpha_mode", m.alpha_mode);
  geometry.set("u_alpha_cutoff", m.alpha_cutoff);
  geometry.set("u_double_sided", m.double_sided);
  // Each texture's UV slot and KHR_texture_transform, indexed by its unit (kit_texture_uv).
  static const char* const kUvSlot[] = {"u_texture_uv_slot[0]", "u_texture_uv_slot[1]", "u_texture_uv_slot[2]",
                                        "u_texture_uv_slot[3]"};
  static const char* const kUvTransform[] = {"u_texture_uv_transform[0]", "u_texture_uv_transform[1]",
                                             "u_texture_uv_transform[2]", "u_texture_uv_transform[3]"};
  static_assert(kMaterialTextureCount == 4, "u_texture_uv_* has an entry per material texture unit");
  for (int unit = 0; unit < kMaterialTextureCount; ++unit) {
    const MaterialTexture& t = m.texture(unit);
    geometry.set(kUvSlot[unit], t.uv.slot);
    geometry.set(kUvTransform[unit], t.uv.transform);
    // A missing normal map reads as the flat normal; other missing textures as white.
    const bool flat = unit == KIT_UNIT_NORMAL_MAP && t.image < 0;
    (flat ? gpu.flat_normal() : gpu.texture(t.image, material_texture_is_color(unit))).bind(unit);
    gpu.sampler(t.sampler).bind(unit);
  }
  glFrontFace(d.mirrored() ? GL_CW : GL_CCW);
  // A double-sided material shows its back faces too (material_modes.glsl flips their normal).
  if (m.double_sided) glDisable(GL_CULL_FACE); else glEnable(GL_CULL_FACE);
  gpu.mesh(d.primitive).draw();
}

void end_scene_draws() {
  glFrontFace(GL_CCW);  // GL's default, which every other pass expects
  glEnable(GL_CULL_FACE);  // as begin_geometry_pass_on left it
  // Units other passes may reuse sample with their textures' own settings again.
  for (int unit : {KIT_UNIT_BASE_COLOR, KIT_UNIT_METALLIC_ROUGHNESS, KIT_UNIT_NORMAL_MAP, KIT_UNIT_EMISSIVE})
    Sampler::unbind(unit);
}

void note_drawn(std::vector<const Program*>* drawn, const Program& program) {
  if (drawn && std::find(drawn->begin(), drawn->end(), &program) == drawn->end()) drawn->push_back(&program);
}

namespace {
// draw_scene's loop: `program_for(d)` draws d, put in use when it is another than the last draw's.
template <typename ProgramFor>
void draw_scene_with(const ProgramFor& program_for, const Scene& scene, const SceneGpu& gpu,
                     const glm::mat4& view_projection, bool frustum_culling, DrawSet set,
                     std::vector<const Program*>* drawn) {
  const Frustum frustum = frustum_from(view_projection);
  const Program* current = nullptr;
  for (const DrawItem& d : scene.draws) {
    if (set == DrawSet::AllButBlend && is_blend_draw(scene, d)) continue;  // the forward pass draws it
    const Primitive& prim = scene.primitives[static_cast<size_t>(d.primitive)];
    // A draw wholly outside the view adds no fragment: skipping it saves its vertex work.
    if (frustum_culling && !intersects(frustum, prim.bounds_min, prim.bounds_max, d.world)) continue;
    const Program& program = program_for(d);
    if (&program != current) {
      program.use();
      current = &program;
      note_drawn(drawn, program);
    }
    draw_item(program, scene, gpu, d);
  }
  end_scene_draws();
}
}  // namespace

void draw_scene(const Program& geometry, const Scene& scene, const SceneGpu& gpu,
                const glm::mat4& view_projection, bool frustum_culling, DrawSet set) {
  draw_scene_with([&](const DrawItem&) -> const Program& { return geometry; }, scene, gpu, view_projection,
                  frustum_culling, set, nullptr);
}

void draw_scene(const GeometryPrograms& geometry, const Scene& scene, const SceneGpu& gpu,
                const glm::mat4& view_projection, bool frustum_culling, DrawSet set,
                std::vector<const Program*>* drawn) {
  draw_scene_with([&](const DrawItem& d) -> const Program& { return geometry.for_draw(scene, d); }, scene, gpu,
                  view_projection, frustum_culling, set, drawn);
}

namespace {
SceneGpu timed_scene_upload(const Scene& scene, TextureCompression compression, double& seconds) {
  const auto start = std::chrono::steady_clock::now();
  SceneGpu gpu(scene, compression);
  glFinish();  // the upload's GL work is done, not only queued
  seconds = seconds_since(start);
  return gpu;
}
}  // namespace

std::shared_ptr<const ImageBasedLighting> IblCache::find(const std::string& key) const {
  auto it = maps_.find(key);
  return it == maps_.end() ? nullptr : it->second;
}

void IblCache::store(const std::string& key, std::shared_ptr<const ImageBasedLighting> maps) {
  maps_[key] = std::move(maps);
}

Renderer::Renderer(const Stage& stage, ShaderLibrary library, const Scene& scene, RenderSettings settings,
                   IblCache* ibl_cache)
    : stage_(stage),
      library_(std::move(library)),
      scene_(scene),
      settings_(settings),
      scene_gpu_(timed_scene_upload(scene, settings.texture_compression, scene_upload_seconds_)),
      gbuffer_(settings.width, settings.height),
      ibl_cache_(ibl_cache) {
  blend_draws_ = has_blend_draws(scene_);
  upload_lights();  // first: the light count chooses how the programs read lights
  build_programs();
  allocate_targets();
  check_gl("Renderer setup");
}

Renderer::~Renderer() = default;

void Renderer::build_programs() {
  lit_frame_.reset();
  check_stage_interfaces(stage_, library_);
  // A program whose shaders assemble to the same texts as the current one's is kept, so
  // a define change (the lights, the attenuation model) or a hot reload builds only the
  // programs it reaches. Kept ones move over only once every other one compiled and
  // linked: a failure leaves the current set whole.
  auto p = std::make_unique<Programs>();
  std::vector<Program Programs::*> kept;
  auto build = [&](Program Programs::*slot, const char* vertex, const char* fragment) {
    if (programs_ && ((*programs_).*slot).built_from(library_, vertex, fragment))
      kept.push_back(slot);
    else
      (*p).*slot = make_program(library_, vertex, fragment);
  };
  // Not specialised: the variant with every feature draws every material.
  const std::vector<unsigned> feature_sets = settings_.specialise_shaders ? GeometryPrograms::feature_sets(scene_)
                                                                          : std::vector<unsigned>{kMaterialAllFeatures};
  p->geometry = GeometryPrograms(library_, feature_sets, "gbuffer.vert", "gbuffer.frag",
                                 programs_ ? &programs_->geometry : nullptr);
  if (stage_.lighting) {
    build(&Programs::lighting, "fullscreen.vert", "lighting.frag");
    build(&Programs::display, "fullscreen.vert", "display.frag");
  }
  if (stage_.postprocess) {
    build(&Programs::bright, "fullscreen.vert", "bright.frag");
    build(&Programs::blur, "fullscreen.vert", "blur.frag");
    build(&Programs::composite, "fullscreen.vert", "composite.frag");
    build(&Programs::custom, "fullscreen.vert", "custom_effect.frag");
  }
  build(&Programs::debug, "fullscreen.vert", "debug_view.frag");
  if (stage_.light_volumes) {
    build(&Programs::volume, "light_volume.vert", "light_volume.frag");
    build(&Programs::volume_count, "light_volume.vert", "light_volume_count.frag");
    build(&Programs::volume_coverage, "light_volume_coverage.vert", "light_volume_count.frag");
    build(&Programs::surface_count, "fullscreen.vert", "light_volume_count.frag");
    build(&Programs::volume_evidence, "light_volume.vert", "light_volume_evidence.frag");
    build(&Programs::state_evidence, "light_volume_coverage.vert", "light_volume_evidence.frag");
  }
  if (stage_.ibl) {
    build(&Programs::irradiance, "fullscreen.vert", "irradiance.frag");
    build(&Programs::prefilter, "fullscreen.vert", "prefilter.frag");
    build(&Programs::brdf_lut, "fullscreen.vert", "brdf_lut.frag");
    build(&Programs::ibl, "fullscreen.vert", "ibl.frag");
    build(&Programs::background, "fullscreen.vert", "environment_background.frag");
  }
  // The forward pass is built for a scene it has work in (BLEND draws, or the viewer's
  // light markers: render_passes builds it when they are turned on later). Most scenes have
  // neither: built anyway, its layer G-buffer and programs cost a grading run 165k page
  // faults instead of 147k.
  const bool keep_forward = forward_ && forward_->built_from(library_);
  std::unique_ptr<ForwardPass> forward;
  if (stage_.lighting && !keep_forward && (blend_draws_ || settings_.light_markers))
    forward = std::make_unique<ForwardPass>(library_, settings_.width, settings_.height);
  for (Program Programs::*slot : kept) (*p).*slot = std::move((*programs_).*slot);
  if (programs_) p->geometry.keep_from(programs_->geometry);
  auto was_kept = [&](Program Programs::*slot) { return std::find(kept.begin(), kept.end(), slot) != kept.end(); };
  // The maps are made by the precompute programs alone: kept, they would come out the same.
  const bool maps_current = ibl_ && was_kept(&Programs::irradiance) && was_kept(&Programs::prefilter) &&
                            was_kept(&Programs::brdf_lut);
  // Read before the programs change hands: a pragma that does not parse keeps the old set.
  if (stage_.light_volumes) volume_state_ = parse_light_volume_state(library_.assemble("light_volume.vert"));
  programs_ = std::move(p);
  programs_defines_ = library_.defines();
  shaders_specialised_ = settings_.specialise_shaders;
  if (!keep_forward) forward_ = std::move(forward);
  used_.clear();
  if (stage_.ibl && !maps_current) update_ibl();
}

std::string Renderer::ibl_cache_key() const {
  std::string key = environment_or_default(settings_.environment);
  const IblSettings& s = settings_.ibl;
  for (int v : {s.prefilter_samples, s.prefilter_size, s.brdf_lut_samples, s.irradiance_size, s.irradiance_source_width,
                static_cast<int>(s.refuse_non_finite)})
    key += '\n' + std::to_string(v);
  for (const char* shader : {"fullscreen.vert", "irradiance.frag", "prefilter.frag", "brdf_lut.frag"})
    key += '\n' + library_.assemble(shader).text;
  return key;
}

ImageBasedLighting* Renderer::image_based_lighting() {
  if (ibl_cache_) throw Error("the environment's maps are shared through an IblCache and cannot be changed");
  // Not from a cache: this Renderer made the maps and is their only owner.
  lit_frame_.reset();  // a map may change before the next frame
  return std::const_pointer_cast<ImageBasedLighting>(ibl_).get();
}

void Renderer::update_ibl() {
  lit_frame_.reset();
  const std::string key = ibl_cache_ ? ibl_cache_key() : std::string();
  std::shared_ptr<const ImageBasedLighting> maps = ibl_cache_ ? ibl_cache_->find(key) : nullptr;
  if (!maps) {
    // Made afresh when cached maps would change under other Renderers, or the environment is another.
    std::shared_ptr<ImageBasedLighting> made;
    if (ibl_ && !ibl_cache_ && settings_.environment == ibl_environment_) {
      made = std::const_pointer_cast<ImageBasedLighting>(ibl_);
    } else {
      const std::string name = environment_or_default(settings_.environment);
      made = std::make_shared<ImageBasedLighting>(kit::load_environment(resolve_environment(name)));
    }
    const Programs& p = *programs_;
    made->precompute(p.irradiance, p.prefilter, p.brdf_lut, triangle_, settings_.ibl);
    if (ibl_cache_) ibl_cache_->store(key, made);
    maps = std::move(made);
  }
  ibl_ = std::move(maps);
  ibl_environment_ = settings_.environment;
  ibl_settings_ = settings_.ibl;
}

void Renderer::reload_shaders() { build_programs(); }

std::vector<std::filesystem::path> Renderer::shader_paths() const {
  std::vector<std::filesystem::path> out;
  // Every geometry variant is assembled from the same files: the first one names them.
  const Program* geometry = programs_->geometry.all().front();
  const Programs& p = *programs_;
  for (const Program* program : std::initializer_list<const Program*>{
           geometry, &p.lighting, &p.display, &p.bright, &p.blur, &p.composite, &p.custom, &p.irradiance,
           &p.prefilter, &p.brdf_lut, &p.ibl, &p.volume})
    out.insert(out.end(), program->source_paths().begin(), program->source_paths().end());
  return out;
}

void Renderer::allocate_targets() {
  lit_frame_.reset();
  int w = settings_.width, h = settings_.height;
  // Float targets are sampled with nearest filtering: every pass reads them at
  // texel centres, and a linear filter would spread a NaN into its neighbours
  // (0 * NaN is NaN). Only the tone-mapped image, which the custom effect may
  // sample between texels, is filtered linearly.
  auto target = [&](Texture2D& tex, Framebuffer& fbo, TextureFormat fmt) {
    tex = Texture2D(w, h, fmt);
    if (fmt.internal_format == kLdrFormat.internal_format) tex.set_filter(GL_LINEAR, GL_LINEAR);
    fbo.attach_color(0, tex);
    fbo.set_draw_buffers(1);
    std::string reason = fbo.incomplete_reason();
    if (!reason.empty()) throw Error("render target incomplete: " + reason);
  };
  target(hdr_, hdr_fbo_, kHdrFormat);
  lighting_fbo_.attach_color(0, hdr_);
  lighting_fbo_.attach_depth(gbuffer_.depth());
  lighting_fbo_.set_draw_buffers(1);
  if (std::string reason = lighting_fbo_.incomplete_reason(); !reason.empty())
    throw Error("lighting pass target incomplete: " + reason);
  target(bloom_[0], bloom_fbo_[0], kHdrFormat);
  target(bloom_[1], bloom_fbo_[1], kHdrFormat);
  target(composite_, composite_fbo_, kLdrFormat);
  target(final_, final_fbo_, kLdrFormat);
  target(debug_target_, debug_fbo_, kDebugFormat);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

void Renderer::resize(int width, int height) {
  if (width == settings_.width && height == settings_.height) return;
  settings_.width = width;
  settings_.height = height;
  gbuffer_.resize(width, height);
  if (forward_) forward_->resize(width, height);
  allocate_targets();
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

int blur_result(int passes) { return passes % 2 == 0 ? 0 : 1; }

void blur_ping_pong(const FullscreenTriangle& triangle, const Program& blur, const Texture2D (&targets)[2],
                    const Framebuffer (&fbos)[2], int passes, int width, int height) {
  for (int pass = 0; pass < passes; ++pass) {
    const bool horizontal = pass % 2 == 0;
    targets[horizontal ? 0 : 1].bind(KIT_UNIT_BLOOM);
    blur.set("u_horizontal", horizontal);
    triangle.pass(blur, fbos[horizontal ? 1 : 0], width, height);
  }
  targets[blur_result(passes)].bind(KIT_UNIT_BLOOM);
}

void Renderer::set_frame_uniforms(const Program& p) const {
  kit::set_frame_uniforms(p, camera_, settings_, light_count_);
}

void Renderer::fullscreen_pass(const Program& program, const Framebuffer& target, int width, int height) const {
  triangle_.pass(program, target, width, height);
}

void apply_attenuation_model_define(ShaderLibrary& library, int model) {
  library.set_defines({{"KIT_ATTENUATION_MODEL_PHYSICAL", model == 0}, {"KIT_ATTENUATION_MODEL_SIMPLE", model == 1}});
}

bool skips_background_pixels(const Stage& stage) {
  return stage.lighting && std::find(stage.files.begin(), stage.files.end(), "lighting.frag") == stage.files.end();
}

void Renderer::lighting_pass(const Program& lighting) const {
  if (!skips_background_pixels(stage_)) {
    fullscreen_pass(lighting, hdr_fbo_, settings_.width, settings_.height);
    return;
  }
  // What lighting.frag writes where its coverage mask is 0, given before the pass.
  lighting_fbo_.bind();
  glClearColor(settings_.clear_color.r, settings_.clear_color.g, settings_.clear_color.b, 1.0f);
  glClear(GL_COLOR_BUFFER_BIT);
  triangle_.pass_over_surfaces(lighting, lighting_fbo_, settings_.width, settings_.height);
}

namespace {

// Draws `instances` volumes of `sphere` with `program` (in use, uniforms set) under
// `state`, into the bound target; `colour` false writes no colour (counting draws). GL's
// defaults are restored after. Depth clamping keeps a volume that reaches past the far
// plane: its faces there are clamped to depth 1, where the depth test still decides.
void draw_light_volumes(const Mesh& sphere, int instances, const LightVolumeState& state, bool colour) {
  glDepthMask(GL_FALSE);
  if (state.depth == LightVolumeState::Depth::Off) {
    glDisable(GL_DEPTH_TEST);
  } else {
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(state.depth == LightVolumeState::Depth::LessEqual ? GL_LEQUAL : GL_GEQUAL);
  }
  if (state.cull == LightVolumeState::Cull::None) {
    glDisable(GL_CULL_FACE);
  } else {
    glEnable(GL_CULL_FACE);
    glCullFace(state.cull == LightVolumeState::Cull::Back ? GL_BACK : GL_FRONT);
  }
  if (colour && state.blend_add) {
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
  } else {
    glDisable(GL_BLEND);
  }
  if (!colour) glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  set_depth_clamp(true);
  sphere.draw_instanced(instances);
  set_depth_clamp(false);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glDisable(GL_BLEND);
  glDisable(GL_CULL_FACE);
  glCullFace(GL_BACK);
  glDisable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
}

// The samples `draw` lets through (GL_SAMPLES_PASSED: one per pixel here, exact; in
// WebGL2 only whether any did, gl_flavour.h).
template <typename Draw>
uint64_t samples_passed(Draw draw) {
  GLuint query = 0;
  glGenQueries(1, &query);
  begin_samples_passed(query);
  draw();
  end_samples_passed();
  const uint64_t samples = samples_passed_result(query);
  glDeleteQueries(1, &query);
  return samples;
}

}  // namespace

void Renderer::light_volume_pass() {
  const Programs& p = *programs_;
  const int volumes = light_count_ - directional_count_;
  volume_work_ = LightVolumeWork{};
  volume_work_.volume_lights = volumes;
  if (volumes <= 0) return;
  if (volume_sphere_.index_count() == 0) volume_sphere_ = enclosing_sphere_mesh(kLightVolumeSubdivisions);
  lighting_fbo_.bind();  // the HDR target with the G-buffer's depth
  glViewport(0, 0, settings_.width, settings_.height);
  auto set_uniforms = [&](const Program& program) {
    set_frame_uniforms(program);
    program.set("u_volume_light_offset", directional_count_);
  };
  set_uniforms(p.volume);
  draw_light_volumes(volume_sphere_, volumes, volume_state_, true);
  if (!settings_.count_light_volume_work) return;
  // The same volumes under the same state, through a fragment shader that writes
  // nothing: every fragment the student's fragment shader was run for.
  set_uniforms(p.volume_count);
  volume_work_.shaded_fragments =
      samples_passed([&] { draw_light_volumes(volume_sphere_, volumes, volume_state_, false); });
  // The framework's own spheres, back faces only and no depth test: every pixel each
  // volume covers on screen, once (also with the camera inside it).
  set_uniforms(p.volume_coverage);
  LightVolumeState coverage;
  coverage.cull = LightVolumeState::Cull::Front;
  coverage.depth = LightVolumeState::Depth::Off;
  volume_work_.volume_coverage = samples_passed([&] { draw_light_volumes(volume_sphere_, volumes, coverage, false); });
  // The pixels the full-screen loop shades: those with a surface.
  set_frame_uniforms(p.surface_count);
  volume_work_.surface_pixels = samples_passed([&] {
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    triangle_.pass_over_surfaces(p.surface_count, lighting_fbo_, settings_.width, settings_.height);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  });
  if (samples_passed_counts()) measure_volume_evidence();
}

void Renderer::measure_volume_evidence() {
  const Programs& p = *programs_;
  const int volumes = light_count_ - directional_count_;
  VolumeEvidence& e = volume_work_.evidence;
  e = VolumeEvidence{};
  e.adds = volume_state_.blend_add;
  // The framework's counting state: back faces only, no depth test, so a closed volume
  // gives each pixel it covers one fragment, also with the camera inside it.
  LightVolumeState once;
  once.cull = LightVolumeState::Cull::Front;
  once.depth = LightVolumeState::Depth::Off;
  // One light's volume alone: instance 0 of the draw is light u_volume_light_offset.
  enum Count { kFootprint, kOverlap, kStudentFootprint, kMustShade, kShaded, kCounts };
  const int measured = std::min(volumes, kEvidenceLights);
  std::vector<GLuint> queries(static_cast<size_t>(measured) * kCounts);
  glGenQueries(static_cast<GLsizei>(queries.size()), queries.data());
  std::vector<int> number(static_cast<size_t>(measured));  // each measured light's in the scene's list
  static const float circumradius = enclosing_sphere_circumradius(kLightVolumeSubdivisions);
  for (int m = 0; m < measured; ++m) {
    // Evenly spread over the volume lights, the first and the last included.
    const int i = measured == 1 ? 0 : static_cast<int>((static_cast<int64_t>(m) * (volumes - 1)) / (measured - 1));
    const int light = directional_count_ + i;
    number[static_cast<size_t>(m)] = frame_light_numbers_[static_cast<size_t>(light)];
    auto count = [&](Count which, const Program& program, const LightVolumeState& state, int mode) {
      set_frame_uniforms(program);
      program.set("u_volume_light_offset", light);
      if (mode >= 0) {
        program.set("u_evidence_mode", mode);
        program.set("u_volume_circumradius", circumradius);
      }
      begin_samples_passed(queries[static_cast<size_t>(m) * kCounts + which]);
      draw_light_volumes(volume_sphere_, 1, state, false);
      end_samples_passed();
    };
    count(kFootprint, p.volume_coverage, once, -1);
    count(kOverlap, p.volume_evidence, once, 0);
    count(kStudentFootprint, p.volume_count, once, -1);
    // The state alone, on the framework's volume: does it give each surface pixel inside the
    // light's sphere one fragment?
    count(kMustShade, p.state_evidence, once, 1);
    count(kShaded, p.state_evidence, volume_state_, 1);
  }
  // Read once all are drawn: one wait for the queries, not one per light.
  uint64_t worst_volume = 0, worst_state = 0;
  for (int m = 0; m < measured; ++m) {
    uint64_t c[kCounts];
    for (int k = 0; k < kCounts; ++k) c[k] = samples_passed_result(queries[static_cast<size_t>(m) * kCounts + k]);
    // The framework's footprint is the enclosing sphere's less a sliver: overlap may exceed it.
    const uint64_t missing = c[kFootprint] > c[kOverlap] ? c[kFootprint] - c[kOverlap] : 0;
    const uint64_t extra = c[kStudentFootprint] > c[kOverlap] ? c[kStudentFootprint] - c[kOverlap] : 0;
    const uint64_t state_off = c[kShaded] > c[kMustShade] ? c[kShaded] - c[kMustShade] : c[kMustShade] - c[kShaded];
    e.lights += 1;
    e.footprint += c[kFootprint];
    e.missing += missing;
    e.extra += extra;
    e.must_shade += c[kMustShade];
    e.shaded_wrong += state_off;
    if (missing + extra > worst_volume) {
      worst_volume = missing + extra;
      e.worst_volume_light = number[static_cast<size_t>(m)];
      e.worst_footprint = c[kFootprint];
      e.worst_missing = missing;
      e.worst_extra = extra;
    }
    if (state_off > worst_state) {
      worst_state = state_off;
      e.worst_state_light = number[static_cast<size_t>(m)];
      e.worst_must_shade = c[kMustShade];
      e.worst_shaded = c[kShaded];
    }
  }
  glDeleteQueries(static_cast<GLsizei>(queries.size()), queries.data());
}

void Renderer::render(const FrameCamera& camera, PassTimes* pass_times) { render_frame(camera, pass_times, false); }

bool Renderer::render_reusing_lit_frame(const FrameCamera& camera) { return render_frame(camera, nullptr, true); }

bool Renderer::render_frame(const FrameCamera& camera, PassTimes* pass_times, bool reuse_lit_frame) {
  used_.clear();
  PassClock clock(pass_times);
  try {
    return render_passes(camera, clock, reuse_lit_frame);
  } catch (const Error& e) {
    // A uniform set with another type than declared is a GL error in its pass: say which.
    std::string mistyped;
    for (const Program* program : used_)
      for (const std::string& line : program->uniform_problems().mistyped) mistyped += line + "\n";
    if (mistyped.empty()) throw;
    throw Error(mistyped + "(" + e.what() + ")");
  }
}

bool Renderer::render_passes(const FrameCamera& camera, PassClock& clock, bool reuse_lit_frame) {
  if (settings_.extra_lights != lights_extra_ || settings_.only_light != lights_only_ ||
      settings_.default_light_rig != lights_default_rig_ ||
      settings_.attenuation_model != lights_attenuation_model_ || settings_.specialise_shaders != shaders_specialised_ ||
      (stage_.light_volumes && settings_.gamma != lights_gamma_))
    upload_lights();
  if (ibl_ && (settings_.environment != ibl_environment_ || !(settings_.ibl == ibl_settings_))) update_ibl();
  if (stage_.lighting && settings_.light_markers && !forward_)  // turned on since build_programs
    forward_ = std::make_unique<ForwardPass>(library_, settings_.width, settings_.height);
  clock.lap("setup");
  camera_ = camera;
  const Programs& p = *programs_;
  for (const Program* program : {&p.lighting, &p.display, &p.bright, &p.blur, &p.composite, &p.custom,
                                 &p.irradiance, &p.prefilter, &p.brdf_lut, &p.ibl, &p.background, &p.volume}) {
    bool drawn = program->valid() && (program != &p.display || !stage_.postprocess) &&
                 (program != &p.blur || settings_.blur_passes > 0);
    if (drawn) used_.push_back(program);
  }
  if (forward_ && blend_draws_) used_.push_back(&forward_->blend_program());
  if (forward_ && settings_.light_markers) used_.push_back(&forward_->marker_program());

  const bool reused = reuse_lit_frame && stage_.lighting && lit_frame_current(camera);
  if (reused) {
    // The programs the skipped passes drew with lead the list, as they did, and the units
    // they leave bound for the passes after are bound again (another Renderer's frame, in
    // the grader's render child, may have bound its own there since).
    used_.insert(used_.begin(), lit_frame_->drawn.begin(), lit_frame_->drawn.end());
    gbuffer_.bind_textures();
    lights_.bind();
    if (ibl_) ibl_->bind();
  } else {
    lit_frame_.reset();
    const size_t fixed = used_.size();
    draw_lit_frame(clock);
    if (!stage_.lighting) return false;
    const auto drawn_end = used_.end() - static_cast<std::ptrdiff_t>(fixed);  // draw_lit_frame puts them first
    lit_frame_ = LitFrame{camera, settings_, std::vector<const Program*>(used_.begin(), drawn_end)};
  }
  hdr_.bind(KIT_UNIT_HDR);

  if (!stage_.postprocess) {
    // 3. Display: tone mapping and gamma (tonemap.glsl) -> LDR.
    set_frame_uniforms(p.display);
    fullscreen_pass(p.display, final_fbo_, settings_.width, settings_.height);
    check_gl("display pass");
    clock.lap("display");
    return reused;
  }

  // 3'. Bloom: bright pass, separable blur ping-pong, composite before tone mapping.
  set_frame_uniforms(p.bright);
  fullscreen_pass(p.bright, bloom_fbo_[0], settings_.width, settings_.height);
  set_frame_uniforms(p.blur);
  blur_ping_pong(triangle_, p.blur, bloom_, bloom_fbo_, settings_.blur_passes, settings_.width, settings_.height);
  hdr_.bind(KIT_UNIT_HDR);
  set_frame_uniforms(p.composite);
  fullscreen_pass(p.composite, composite_fbo_, settings_.width, settings_.height);
  composite_.bind(KIT_UNIT_LDR);
  set_frame_uniforms(p.custom);
  fullscreen_pass(p.custom, final_fbo_, settings_.width, settings_.height);
  check_gl("postprocess passes");
  clock.lap("postprocess");
  return reused;
}

bool Renderer::lit_frame_current(const FrameCamera& camera) const {
  if (!lit_frame_ || !same_frame_camera(lit_frame_->camera, camera)) return false;
  const RenderSettings& last = lit_frame_->settings;
  if (last.width != settings_.width || last.height != settings_.height) return false;
  // Whether a pass before post-processing reads `uniform` (a lab shader may read any).
  const Programs& p = *programs_;
  std::vector<const Program*> before_post = p.geometry.all();
  for (const Program* program : {&p.lighting, &p.ibl, &p.background, &p.volume, &p.volume_count,
                                 &p.volume_coverage, &p.surface_count, &p.volume_evidence,
                                 &p.state_evidence})
    before_post.push_back(program);
  if (forward_) {
    before_post.push_back(&forward_->blend_program());
    before_post.push_back(&forward_->marker_program());
  }
  auto read_before_post = [&](const char* uniform) {
    return std::any_of(before_post.begin(), before_post.end(),
                       [&](const Program* program) { return program->valid() && program->has(uniform); });
  };
  // The settings only post-processing (or the display pass) reads may differ.
  RenderSettings s = settings_;
  if (!read_before_post("u_gamma")) s.gamma = last.gamma;
  if (!read_before_post("u_postprocess_enabled")) s.postprocess = last.postprocess;
  if (!read_before_post("u_custom_enabled")) s.custom_effect = last.custom_effect;
  if (!read_before_post("u_bloom_threshold")) s.bloom_threshold = last.bloom_threshold;
  s.blur_passes = last.blur_passes;  // a loop count of blur_ping_pong's
  if (read_before_post("u_time") && s.time != last.time) return false;
  return same_image_settings(last, s);
}

// Passes 1 to 2' of a frame: everything before post-processing, into the G-buffer and
// (lit stages) the HDR target.
void Renderer::draw_lit_frame(PassClock& clock) {
  const Programs& p = *programs_;
  // 1. Geometry pass: every draw item into the G-buffer; from stage 2, BLEND
  //    materials are left to the forward pass (stage 1 has no lighting to blend).
  const glm::mat4 view_projection = camera_.projection * camera_.view;
  gbuffer_.begin_geometry_pass();
  for (const Program* variant : p.geometry.all()) set_frame_uniforms(*variant);
  std::vector<const Program*> drawn;
  draw_scene(p.geometry, scene_, scene_gpu_, view_projection, settings_.frustum_culling,
             stage_.lighting ? DrawSet::AllButBlend : DrawSet::All, &drawn);
  used_.insert(used_.begin(), drawn.begin(), drawn.end());
  check_gl("geometry pass");
  clock.lap("geometry");
  if (!stage_.lighting) return;

  // 2. Lighting pass: G-buffer -> HDR.
  gbuffer_.bind_textures();
  lights_.bind();
  set_frame_uniforms(p.lighting);
  // Stage 7: the full-screen pass lights with the directional lights alone (they lead
  // the list); the volumes add the others.
  if (stage_.light_volumes) p.lighting.set("u_light_count", directional_count_);
  lighting_pass(p.lighting);
  check_gl("lighting pass");
  if (stage_.light_volumes) {
    light_volume_pass();
    p.lighting.use();
    p.lighting.set("u_light_count", light_count_);  // the forward pass lights with all of them
    check_gl("light volume pass (light_volume.vert, light_volume.frag)");
  }
  clock.lap("lighting");

  // 2''. Stage 6: the environment's light added (ibl.frag), then the environment
  //      itself where no surface is.
  if (ibl_) {
    ibl_->bind();
    set_frame_uniforms(p.ibl);
    triangle_.pass(p.ibl, hdr_fbo_, settings_.width, settings_.height, true);
    check_gl("IBL pass (ibl.frag)");
    set_frame_uniforms(p.background);
    fullscreen_pass(p.background, hdr_fbo_, settings_.width, settings_.height);
    check_gl("environment background");
    clock.lap("ibl");
  }

  // 2'. Forward pass (forward_pass.h): BLEND draws back to front over the HDR
  //     target, lit by the same lighting pass; then the light markers.
  if (blend_draws_) {
    // Only the variants the geometry pass did not draw with join `drawn`, after its own.
    const size_t drawn_opaque = drawn.size();
    forward_->draw_blend_layers(p.geometry, p.lighting, ibl_ ? &p.ibl : nullptr, scene_, scene_gpu_, gbuffer_,
                                hdr_fbo_, camera_.view, view_projection, triangle_, &drawn);
    used_.insert(used_.begin(), drawn.begin() + static_cast<std::ptrdiff_t>(drawn_opaque), drawn.end());
    gbuffer_.bind_textures();  // the opaque G-buffer again, for the passes after
    check_gl("forward pass (BLEND materials)");
  }
  if (settings_.light_markers) {
    set_frame_uniforms(forward_->marker_program());
    forward_->draw_light_markers(frame_lights_, scene_, gbuffer_, hdr_);
    check_gl("forward pass (light markers)");
  }
  if (blend_draws_ || settings_.light_markers) clock.lap("forward");
}

size_t Renderer::count_non_finite(View view) {
  if (view == View::Final && stage_.lighting) view = View::Hdr;
  return kit::count_non_finite(read_view(view, true));
}

std::vector<NonFiniteCount> Renderer::non_finite_pixels() {
  std::vector<NonFiniteCount> out;
  const size_t pixels = static_cast<size_t>(settings_.width) * static_cast<size_t>(settings_.height);
  for (View view : {View::Position, View::Normal, View::Material, View::Emission, View::Hdr}) {
    if (view == View::Hdr && !stage_.lighting) continue;
    out.push_back({view, count_non_finite(view), pixels});
  }
  return out;
}

std::vector<std::string> Renderer::uniform_warnings() const {
  std::vector<std::string> out;
  for (const Program* program : used_)
    for (const std::string& line : program->uniform_problems().unset)
      if (std::find(out.begin(), out.end(), line) == out.end()) out.push_back(line);
  return out;
}

const Texture2D& Renderer::final_texture() const {
  return stage_.lighting ? final_ : gbuffer_.attachment(KIT_GBUF_ALBEDO);
}

Image Renderer::read_view(View view, bool raw) {
  if (is_precomputed_map(view)) {
    if (!ibl_) throw Error(std::string("view '") + view_name(view) + "' needs stage 6 (ibl)");
    if (view == View::Irradiance) return read_texture(ibl_->irradiance());
    if (view == View::BrdfLut) return read_texture(ibl_->brdf_lut());
    return read_prefiltered_levels(ibl_->prefiltered());
  }
  if (raw && view != View::Final && view != View::Hdr) {
    if (view == View::Depth) return read_texture(gbuffer_.depth(), true);
    int index = view == View::Position ? KIT_GBUF_POSITION : view == View::Normal ? KIT_GBUF_NORMAL
              : view == View::Albedo ? KIT_GBUF_ALBEDO : view == View::Emission ? KIT_GBUF_EMISSION : KIT_GBUF_MATERIAL;
    return read_texture(gbuffer_.attachment(index));
  }
  return read_texture(display_texture(view));
}

const Texture2D& Renderer::display_texture(View view) {
  if (view == View::Final) return final_texture();
  if (is_precomputed_map(view)) {
    if (!ibl_) throw Error(std::string("view '") + view_name(view) + "' needs stage 6 (ibl)");
    return view == View::Irradiance ? ibl_->irradiance() : view == View::BrdfLut ? ibl_->brdf_lut() : ibl_->prefiltered();
  }
  if (view == View::Hdr) {
    if (!stage_.lighting) throw Error("view 'hdr' needs a lit stage (lighting or later)");
    return hdr_;
  }
  // Display mapping in shaders/debug_view.frag.
  gbuffer_.bind_textures();
  const Program& d = programs_->debug;
  set_frame_uniforms(d);
  d.set("u_view_mode", debug_mode(view));
  glm::vec3 center = 0.5f * (scene_.bounds_min + scene_.bounds_max);
  glm::vec3 half = glm::max(0.5f * (scene_.bounds_max - scene_.bounds_min), glm::vec3(1e-3f));
  d.set("u_position_center", center);
  d.set("u_position_half_extent", half);
  float far_display = 0.0f;
  for (int c = 0; c < 8; ++c) {
    glm::vec3 corner((c & 1) ? scene_.bounds_max.x : scene_.bounds_min.x, (c & 2) ? scene_.bounds_max.y : scene_.bounds_min.y,
                     (c & 4) ? scene_.bounds_max.z : scene_.bounds_min.z);
    far_display = std::max(far_display, glm::length(corner - camera_.position));
  }
  d.set("u_depth_display_far", std::min(far_display, camera_.zfar));
  fullscreen_pass(d, debug_fbo_, settings_.width, settings_.height);
  check_gl("debug view");
  return debug_target_;
}

}  // namespace kit

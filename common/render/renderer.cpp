#include "render/renderer.h"

#include <algorithm>
#include <chrono>

#include "base/error.h"
#include "gbuffer_layout.h"
#include "render/interface_check.h"
#include "render/renderer_programs.h"

namespace kit {

namespace {

constexpr TextureFormat kHdrFormat{GL_RGBA16F, GL_RGBA, GL_FLOAT};
constexpr TextureFormat kLdrFormat{GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE};
constexpr TextureFormat kDebugFormat{GL_RGBA32F, GL_RGBA, GL_FLOAT};

}  // namespace

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

void Renderer::fullscreen_pass(const Program& program, const Framebuffer& target, int width, int height) const {
  triangle_.pass(program, target, width, height);
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
    // the grader's render worker, may have bound its own there since).
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
  post_passes(clock);
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

}  // namespace kit

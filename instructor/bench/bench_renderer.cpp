#include "bench_renderer.h"

#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "bench_ibl.h"
#include "bench_layout.h"
#include "base/error.h"
#include "render/forward_pass.h"
#include "gbuffer_layout.h"
#include "scene/mesh_optimize.h"
#include "render/stages.h"

namespace kit::bench {

namespace {

constexpr TextureFormat kHdr16{GL_RGBA16F, GL_RGBA, GL_FLOAT};  // the labs' HDR target (renderer.cpp)
constexpr TextureFormat kHdr32{GL_RGBA32F, GL_RGBA, GL_FLOAT};
constexpr TextureFormat kLdr8{GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE};

// Float targets are sampled with GL_NEAREST, as the labs' Renderer samples its own
// (renderer.cpp): the display, composite and full-resolution blur passes read them
// at texel centres. With GL_LINEAR the float rounding in v_uv (about 1e-4 texel at
// 1280 pixels) leaks a specular peak of ~1e4 into its neighbours, up to 4/255
// after tone mapping. Only the half-resolution bloom samples between texels: its
// bright pass averages 2x2 HDR texels and its blur and upsampling interpolate.
constexpr GLenum kHdrFilter = GL_NEAREST;

// The proxy sphere of a light volume: an icosahedron subdivided this many times
// (80 faces at 1). More faces fit the sphere tighter (fewer pixels shaded for
// nothing outside it) but cost vertex work per light.
constexpr int kVolumeSphereSubdivisions = 1;

Method make(std::string name, std::string family, std::string summary) {
  Method m;
  m.name = std::move(name);
  m.family = std::move(family);
  m.summary = std::move(summary);
  return m;
}

std::vector<Method> make_methods() {
  std::vector<Method> out;
  Method ref = make("reference", "reference", "RGBA32F position+normal, full-screen loop, RGBA32F HDR (the GPU reference)");
  ref.layout = Layout::Reference;
  ref.hdr32 = true;
  out.push_back(ref);

  Method labs = make("labs", "gbuffer", "seed 002 G-buffer (RGBA16F position+normal), full-screen loop: what the labs run");
  out.push_back(labs);
  Method g32 = make("gbuffer-ref32", "gbuffer", "RGBA32F position+normal G-buffer, full-screen loop, RGBA16F HDR");
  g32.layout = Layout::Reference;
  out.push_back(g32);
  Method lean16 = make("gbuffer-lean16", "gbuffer", "depth-reconstructed position, RG16 octahedral normal, RGBA8 material");
  lean16.layout = Layout::Lean16;
  out.push_back(lean16);
  Method lean8 = make("gbuffer-lean8", "gbuffer", "as gbuffer-lean16 with an RG8 octahedral normal");
  lean8.layout = Layout::Lean8;
  out.push_back(lean8);

  // Culling methods: light volumes and tiles at three epsilons on the labs' G-buffer,
  // then tiles at 1/1024 on the G-buffers that hold positions to better than fp16
  // (small lights a few centimetres from the floor magnify fp16's millimetre steps).
  auto culling = [&](const std::string& name, Lighting lighting, Layout layout, int denominator, const std::string& what) {
    Method m = make(name, "lighting", what + ", epsilon 1/" + std::to_string(denominator));
    m.lighting = lighting;
    m.layout = layout;
    m.epsilon = 1.0f / static_cast<float>(denominator);
    out.push_back(m);
  };
  const int denominators[] = {1024, 256, 64};
  for (int d : denominators)
    culling("volumes-e" + std::to_string(d), Lighting::Volumes, Layout::Seed002, d,
            "light volumes (instanced spheres, back faces, additive)");
  for (int d : denominators)
    culling("tiled-e" + std::to_string(d), Lighting::Tiled, Layout::Seed002, d,
            "tiled deferred (16x16 tiles: compute culling, fragment shading)");
  culling("tiled-lean16-e1024", Lighting::Tiled, Layout::Lean16, 1024,
          "tiled deferred on the gbuffer-lean16 G-buffer (depth-reconstructed position)");
  culling("tiled-ref32-e1024", Lighting::Tiled, Layout::Reference, 1024,
          "tiled deferred on the gbuffer-ref32 G-buffer (RGBA32F position+normal)");
  Method forward = make("forward", "lighting", "forward shading: one pass, every light per fragment");
  forward.lighting = Lighting::Forward;
  out.push_back(forward);

  for (int passes : {2, 6, 10}) {
    for (bool half : {false, true}) {
      Method b = make("bloom" + std::to_string(passes) + (half ? "-half" : "-full"), "bloom",
                      "labs + bloom, " + std::to_string(passes) + " blur passes at " +
                          (half ? "half" : "full") + " resolution");
      b.blur_passes = passes;
      b.bloom_half = half;
      out.push_back(b);
    }
  }
  Method geometry = make("geometry-optimized", "geometry",
                         "labs with meshoptimizer-ordered meshes and view-frustum culling");
  geometry.optimized_geometry = true;
  out.push_back(geometry);
  return out;
}

// A render target. `filter` is how later passes sample it: GL_LINEAR where they
// sample between texels (blur taps, half-resolution bloom), GL_NEAREST where they
// read texel centres (see kHdrFilter).
Texture2D target(Framebuffer& fbo, int width, int height, TextureFormat format, GLenum filter) {
  Texture2D texture(width, height, format);
  texture.set_filter(filter, filter);
  fbo.attach_color(0, texture);
  fbo.set_draw_buffers(1);
  std::string reason = fbo.incomplete_reason();
  if (!reason.empty()) throw Error("bench render target incomplete: " + reason);
  return texture;
}

ShaderLibrary bench_library() {
  // instructor/bench/shaders first (its names are the bench's own), then the reference
  // solutions of every lab (stage 5 and the earlier steps), then shaders/.
  const Stage& last = find_stage("postprocess");
  ShaderLibrary stage = stage_library(last, kit_root() / "solutions");
  std::vector<ShaderFolder> folders = {{kit_root() / "instructor" / "bench" / "shaders", "instructor/bench/shaders", {}}};
  folders.insert(folders.end(), stage.folders().begin(), stage.folders().end());
  return ShaderLibrary(std::move(folders));
}

}  // namespace

const std::vector<Method>& methods() {
  static const std::vector<Method> all = make_methods();
  return all;
}

const Method& find_method(const std::string& name) {
  std::string names;
  for (const Method& m : methods()) {
    if (m.name == name) return m;
    names += (names.empty() ? "" : ", ") + m.name;
  }
  for (const IblMethod& m : ibl_methods()) names += ", " + m.name;
  throw Error("unknown method '" + name + "' (methods: " + names + ")");
}

const Method& reference_method() { return methods().front(); }
const Method& labs_method() { return find_method("labs"); }

std::vector<Light> small_lights(const Scene& scene, int count, SmallLightRange range) {
  std::vector<Light> lights = spawned_lights(scene, count);
  // Golden-ratio sequence: heights spread evenly whatever the count.
  const float golden = 0.618033988749895f;
  for (size_t i = 0; i < lights.size(); ++i) {
    Light& light = lights[i];
    float spread = std::fmod(golden * static_cast<float>(i), 1.0f);
    light.position.y = scene.bounds_min.y + kSmallLightMinHeight + kSmallLightHeightSpan * spread;
    light.intensity = kSmallLightsTotalIntensity / static_cast<float>(count);
    // Ranged: where its light falls to kSmallLightRangeRadiance (not spawned_lights' own range,
    // made for lights of another intensity); unlimited: none.
    light.range = 0.0f;
    if (range == SmallLightRange::Ranged) light.range = light_cutoff_radius(light, kSmallLightRangeRadiance, 0);
  }
  return lights;
}

std::vector<Light> bench_lights(const Scene& scene, int extra, SmallLightRange range) {
  std::vector<Light> lights = scene.lights;
  std::vector<Light> small = small_lights(scene, extra, range);
  lights.insert(lights.end(), small.begin(), small.end());
  return lights;
}

void require_positional_lights(const std::vector<Light>& lights, const std::string& method) {
  for (size_t i = 0; i < lights.size(); ++i)
    if (lights[i].type == KIT_LIGHT_DIRECTIONAL)
      throw Error("method '" + method + "' culls lights by a sphere around each, and light " + std::to_string(i) +
                  " is directional (it reaches everywhere): use a full-screen loop or forward method");
}

BenchRenderer::BenchRenderer(const Scene& scene, std::vector<Light> lights, const RenderSettings& settings)
    : scene_(scene),
      lights_(std::move(lights)),
      settings_(settings),
      library_(bench_library()),
      scene_gpu_(scene),
      volume_sphere_(enclosing_sphere_mesh(kVolumeSphereSubdivisions)),
      light_buffers_(lights_) {
  light_buffers_.apply_defines(library_);
  settings_.postprocess = true;     // composite.frag adds the bloom only with the toggle on
  settings_.custom_effect = false;  // the free-choice effect is no method
  const int w = settings_.width, h = settings_.height;
  hdr16_ = target(hdr16_fbo_, w, h, kHdr16, kHdrFilter);
  hdr32_ = target(hdr32_fbo_, w, h, kHdr32, kHdrFilter);
  ldr_ = target(ldr_fbo_, w, h, kLdr8, GL_NEAREST);
  display_ = target(display_fbo_, w, h, kHdr32, GL_NEAREST);
  forward_depth_ = Texture2D(w, h, GBuffer::depth_format());
  forward_fbo_.attach_color(0, hdr16_);
  forward_fbo_.attach_depth(forward_depth_);
  forward_fbo_.set_draw_buffers(1);
  for (int half = 0; half < 2; ++half)
    for (int i = 0; i < 2; ++i)
      bloom_[half][i] = target(bloom_fbo_[half][i], std::max(w >> half, 1), std::max(h >> half, 1), kHdr16,
                               half ? GL_LINEAR : kHdrFilter);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  check_gl("BenchRenderer setup");
}

BenchRenderer::~BenchRenderer() = default;

const Program& BenchRenderer::program(const std::string& key) {
  auto it = programs_.find(key);
  if (it != programs_.end()) return it->second;
  static const std::map<std::string, std::pair<const char*, const char*>> sources = {
      {"geometry-fat", {"gbuffer.vert", "gbuffer.frag"}},
      {"geometry-lean", {"gbuffer.vert", "gbuffer_lean.frag"}},
      {"forward", {"gbuffer.vert", "forward.frag"}},
      {"loop", {"fullscreen.vert", "deferred_loop.frag"}},
      {"volume", {"volume.vert", "volume.frag"}},
      {"tiled-shade", {"fullscreen.vert", "tiled_shade.frag"}},
      {"display", {"fullscreen.vert", "display.frag"}},
      {"bright", {"fullscreen.vert", "bright.frag"}},
      {"blur", {"fullscreen.vert", "blur.frag"}},
      {"composite", {"fullscreen.vert", "composite.frag"}},
  };
  Program p;
  if (key == "tiled-cull") {
    p = Program(library_, "tiled_cull.comp");
    set_resource_bindings(p);
  } else {
    const auto& [vs, fs] = sources.at(key);
    p = make_program(library_, vs, fs);
  }
  GLuint block = glGetProgramResourceIndex(p.id(), GL_SHADER_STORAGE_BLOCK, "TileLights");
  if (block != GL_INVALID_INDEX) glShaderStorageBlockBinding(p.id(), block, KIT_TILE_LIGHTS_BINDING);
  p.use();
  p.set("u_light_bounds", KIT_UNIT_LIGHT_BOUNDS);
  glUseProgram(0);
  return programs_.emplace(key, std::move(p)).first->second;
}

LayoutGBuffer& BenchRenderer::gbuffer(Layout layout) {
  auto& slot = gbuffers_[layout];
  if (!slot) slot = std::make_unique<LayoutGBuffer>(layout, settings_.width, settings_.height);
  return *slot;
}

const Texture2D& BenchRenderer::hdr() const { return last_.hdr32 ? hdr32_ : hdr16_; }
const Framebuffer& BenchRenderer::hdr_fbo() const { return last_.hdr32 ? hdr32_fbo_ : hdr16_fbo_; }

void BenchRenderer::set_uniforms(const Program& p, int light_count) const {
  set_frame_uniforms(p, camera_, settings_, light_count);
  const bool lean = layout_info(last_.layout).lean && last_.lighting != Lighting::Forward;
  p.set("u_gbuffer_layout", lean ? KIT_BENCH_LAYOUT_LEAN : KIT_BENCH_LAYOUT_FAT);
  p.set("u_shading_origin", lean ? camera_.position : glm::vec3(0.0f));
  // The view without its translation maps (world - camera) to camera space; its
  // inverse with the projection, in double, keeps reconstructed positions precise
  // however far the scene is from the origin.
  glm::dmat4 view_rotation(camera_.view);
  view_rotation[3] = glm::dvec4(0.0, 0.0, 0.0, 1.0);
  p.set("u_inv_view_projection_relative", glm::mat4(glm::inverse(glm::dmat4(camera_.projection) * view_rotation)));
  p.set("u_count_lights", false);
}

void BenchRenderer::geometry_pass(const Method& m) {
  const Scene& scene = m.optimized_geometry ? *optimized_scene_ : scene_;
  const SceneGpu& gpu = m.optimized_geometry ? *optimized_gpu_ : scene_gpu_;
  const glm::mat4 view_projection = camera_.projection * camera_.view;
  if (m.lighting == Lighting::Forward) {
    begin_geometry_pass_on(forward_fbo_, settings_.width, settings_.height, glm::vec4(settings_.clear_color, 1.0f));
    const Program& p = program("forward");
    set_uniforms(p, light_count());
    light_buffers_.bind();
    draw_scene(p, scene, gpu, view_projection, m.optimized_geometry);
    check_gl("forward pass");
    return;
  }
  LayoutGBuffer& gb = gbuffer(m.layout);
  gb.begin_geometry_pass();
  const Program& p = program(layout_info(m.layout).lean ? "geometry-lean" : "geometry-fat");
  set_uniforms(p, light_count());
  draw_scene(p, scene, gpu, view_projection, m.optimized_geometry);
  check_gl("geometry pass");
}

void BenchRenderer::lighting_pass(const Method& m) {
  if (m.lighting == Lighting::Forward) return;  // shaded in the geometry pass
  const int w = settings_.width, h = settings_.height;
  gbuffer(m.layout).bind_textures();
  light_buffers_.bind();
  if (m.lighting == Lighting::Tiled) {
    if (m.hdr32) throw Error("tiled lighting writes the RGBA16F HDR target only");
    tiled_passes(false);
    return;
  }
  // Loop: every light. Volumes: the same pass with no lights writes emission and
  // the clear colour; the volumes add the lights onto it.
  const Program& loop = program("loop");
  set_uniforms(loop, m.lighting == Lighting::Loop ? light_count() : 0);
  triangle_.pass(loop, hdr_fbo(), w, h);
  if (m.lighting == Lighting::Volumes) volume_pass(false);
  check_gl("lighting pass");
}

void BenchRenderer::bind_light_bounds() {
  require_positional_lights(lights_, last_.name);
  const std::pair<float, int> key{last_.epsilon, settings_.attenuation_model};
  if (key != bounds_key_) {
    std::vector<glm::vec4> texels(std::max(lights_.size(), size_t{1}), glm::vec4(0.0f));
    for (size_t i = 0; i < lights_.size(); ++i)
      texels[i] = glm::vec4(lights_[i].position, light_cutoff_radius(lights_[i], key.first, key.second));
    // Creating a texture binds it on the active unit: make that the bounds' own
    // unit, so no G-buffer or light texture bound for this pass is displaced.
    glActiveTexture(GL_TEXTURE0 + KIT_UNIT_LIGHT_BOUNDS);
    light_bounds_ = Texture2D(1, static_cast<int>(texels.size()), kHdr32, texels.data());
    bounds_key_ = key;
  }
  light_bounds_.bind(KIT_UNIT_LIGHT_BOUNDS);
}

void BenchRenderer::volume_pass(bool count_lights) {
  if (light_count() == 0) return;
  const Program& p = program("volume");
  set_uniforms(p, light_count());
  bind_light_bounds();
  p.set("u_count_lights", count_lights);
  // FAT layouts: the G-buffer's depth is attached (writes off) and tested GEQUAL
  // against each back face, so pixels whose surface lies behind the whole volume
  // are rejected before shading. The LEAN layout samples that depth texture to
  // reconstruct positions, and sampling an attached texture is a feedback loop GL
  // leaves undefined, so there the shader's radius test alone decides.
  const bool depth_test = !layout_info(last_.layout).lean;
  if (depth_test) {
    auto& fbo = volume_fbos_[{last_.layout, last_.hdr32}];
    if (!fbo) {
      fbo = std::make_unique<Framebuffer>();
      fbo->attach_color(0, hdr());
      fbo->attach_depth(gbuffer(last_.layout).depth());
      fbo->set_draw_buffers(1);
      std::string reason = fbo->incomplete_reason();
      if (!reason.empty()) throw Error("light volume target incomplete: " + reason);
    }
    fbo->bind();
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_GEQUAL);
    glDepthMask(GL_FALSE);
  } else {
    hdr_fbo().bind();
  }
  glViewport(0, 0, settings_.width, settings_.height);
  glEnable(GL_BLEND);
  glBlendFunc(GL_ONE, GL_ONE);
  glEnable(GL_CULL_FACE);
  // Back faces only: exactly one per covered pixel, in front of the camera even
  // when it is inside the volume. Drawing front faces breaks there: they are
  // behind the camera and the light vanishes (stability case 7).
  glCullFace(last_.cull_front_faces ? GL_FRONT : GL_BACK);
  // Without near/far clipping a volume reaching past the far plane still covers
  // its pixels: its back faces are clamped to depth 1, pass GEQUAL against every
  // surface, and the shader's radius test decides.
  glEnable(GL_DEPTH_CLAMP);
  volume_sphere_.draw_instanced(light_count());
  glDisable(GL_DEPTH_CLAMP);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glDisable(GL_DEPTH_TEST);
  glDepthMask(GL_TRUE);
  check_gl("light volumes");
}

void BenchRenderer::tiled_passes(bool count_lights) {
  const int w = settings_.width, h = settings_.height;
  // tiled_lists.glsl tile_count(), on the CPU for the buffer size and the dispatch.
  const glm::ivec2 tiles((w + KIT_TILE_SIZE - 1) / KIT_TILE_SIZE, (h + KIT_TILE_SIZE - 1) / KIT_TILE_SIZE);
  // Room for every light in every tile: the lists never overflow, whatever the scene.
  const size_t ints = static_cast<size_t>(tiles.x) * tiles.y * (static_cast<size_t>(light_count()) + 1);
  if (ints > tile_buffer_ints_) {
    GLuint id = 0;
    glGenBuffers(1, &id);
    tile_buffer_ = GlName<delete_buffer>(id);
    glBindBuffer(GL_SHADER_STORAGE_BUFFER, id);
    glBufferData(GL_SHADER_STORAGE_BUFFER, static_cast<GLsizeiptr>(ints * sizeof(GLint)), nullptr, GL_DYNAMIC_COPY);
    tile_buffer_ints_ = ints;
  }
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, KIT_TILE_LIGHTS_BINDING, tile_buffer_.get());
  auto groups = [](int n) { return static_cast<GLuint>((n + KIT_TILE_GROUP - 1) / KIT_TILE_GROUP); };
  const Program& cull = program("tiled-cull");
  set_uniforms(cull, light_count());
  bind_light_bounds();
  glDispatchCompute(groups(tiles.x), groups(tiles.y), 1);
  glMemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);  // the lists, before shading reads them
  const Program& shade = program("tiled-shade");
  set_uniforms(shade, light_count());
  shade.set("u_count_lights", count_lights);
  triangle_.pass(shade, hdr16_fbo_, w, h);
  check_gl("tiled lighting");
}

void BenchRenderer::render(const Method& m, const FrameCamera& camera, PassTimes* pass_times) {
  if (m.optimized_geometry && !optimized_scene_) {
    optimized_scene_ = std::make_unique<Scene>(scene_);
    optimize_scene(*optimized_scene_);
    optimized_gpu_ = std::make_unique<SceneGpu>(*optimized_scene_);
  }
  camera_ = camera;
  last_ = m;
  PassClock clock(pass_times);
  geometry_pass(m);
  clock.lap(m.lighting == Lighting::Forward ? "forward" : "geometry");
  lighting_pass(m);
  if (m.lighting != Lighting::Forward) clock.lap("lighting");
  if (m.blur_passes > 0) {
    bloom_passes();
    clock.lap("bloom");
  }
  display_pass(ldr_fbo_);
  clock.lap("display");
}

void BenchRenderer::bloom_passes() {
  const int half = last_.bloom_half ? 1 : 0;
  const int bw = bloom_[half][0].width(), bh = bloom_[half][0].height();
  // At half resolution each bright-pass pixel centre falls between 2x2 HDR texels:
  // bilinear filtering averages them.
  if (half) hdr().set_filter(GL_LINEAR, GL_LINEAR);
  hdr().bind(KIT_UNIT_HDR);
  const Program& bright = program("bright");
  set_uniforms(bright, light_count());
  triangle_.pass(bright, bloom_fbo_[half][0], bw, bh);
  if (half) hdr().set_filter(kHdrFilter, kHdrFilter);
  // u_resolution stays the full size, so at half resolution the blur's taps keep
  // their full-resolution spacing and the glow its size; only the sampling is coarser.
  const Program& blur = program("blur");
  set_uniforms(blur, light_count());
  blur_ping_pong(triangle_, blur, bloom_[half], bloom_fbo_[half], last_.blur_passes, bw, bh);
  check_gl("bloom passes");
}

void BenchRenderer::display_pass(const Framebuffer& out) {
  hdr().bind(KIT_UNIT_HDR);
  const char* key = "display";
  if (last_.blur_passes > 0) {
    // Bound again: a read-back since bloom_passes may have used the unit.
    bloom_[last_.bloom_half ? 1 : 0][blur_result(last_.blur_passes)].bind(KIT_UNIT_BLOOM);
    key = "composite";
  }
  const Program& p = program(key);
  set_uniforms(p, light_count());
  triangle_.pass(p, out, settings_.width, settings_.height);
  check_gl("display pass");
}

Image BenchRenderer::read_hdr() { return read_texture(hdr()); }

Image BenchRenderer::read_display() {
  display_pass(display_fbo_);
  return read_texture(display_);
}

std::vector<Image> BenchRenderer::read_gbuffer() {
  if (layout_info(last_.layout).lean || last_.lighting == Lighting::Forward)
    throw Error("read_gbuffer: the last frame has no position attachment (use a FAT layout)");
  const LayoutGBuffer& gb = gbuffer(last_.layout);
  std::vector<Image> out;
  for (int i = 0; i < KIT_GBUF_COUNT; ++i) out.push_back(read_texture(gb.attachment(i)));
  return out;
}

double BenchRenderer::lights_per_pixel() {
  const Method m = last_;
  if (m.lighting == Lighting::Loop || m.lighting == Lighting::Forward) return light_count();
  const LayoutGBuffer& gb = gbuffer(m.layout);
  gb.bind_textures();
  light_buffers_.bind();
  const int w = settings_.width, h = settings_.height;
  if (m.lighting == Lighting::Tiled) {
    tiled_passes(true);
  } else {
    hdr_fbo().bind();
    glViewport(0, 0, w, h);
    const float zero[4] = {0, 0, 0, 0};
    glClearBufferfv(GL_COLOR, 0, zero);
    volume_pass(true);
  }
  check_gl("light count pass");
  Image counts = read_texture(hdr());
  Image material = read_texture(gb.attachment(layout_info(m.layout).lean ? KIT_LEAN_MATERIAL : KIT_GBUF_MATERIAL));
  double sum = 0.0;
  size_t covered = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      if (material.at(x, y, 3) >= 0.5f) {
        sum += counts.at(x, y, 0);
        ++covered;
      }
  // The counting pass overwrote the HDR image: render the frame again so reads stay valid.
  render(m, camera_);
  return covered ? sum / static_cast<double>(covered) : 0.0;
}

size_t BenchRenderer::triangles(const Method& m, const FrameCamera& camera) const {
  const Frustum frustum = frustum_from(camera.projection * camera.view);
  size_t count = 0;
  for (const DrawItem& d : scene_.draws) {
    const Primitive& prim = scene_.primitives[static_cast<size_t>(d.primitive)];
    // Reordering keeps every triangle; only culling removes whole draws.
    if (m.optimized_geometry && !intersects(frustum, prim.bounds_min, prim.bounds_max, d.world)) continue;
    count += prim.indices.size() / 3;
  }
  return count;
}

}  // namespace kit::bench

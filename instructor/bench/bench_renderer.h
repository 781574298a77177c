#pragma once
// kit-bench's rendering framework: one pipeline that renders a scene with any of
// the compared methods (G-buffer layout x light evaluation x bloom x geometry
// pass), headless, from the same Scene, lights and camera, so times and images
// are comparable. The labs' own Renderer is one configuration of it ("labs"), and
// instructor/tests/test_bench_methods.cpp checks the two agree.
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "bench_gbuffer.h"
#include "base/no_dangling.h"
#include "render/renderer.h"

namespace kit::bench {

enum class Lighting {
  Loop,     // full-screen pass, every light at every pixel (the labs' method)
  Volumes,  // a proxy sphere per light, additive blending, back faces only
  Tiled,    // compute shader: lights culled per 16x16 tile
  Forward,  // no G-buffer: the scene drawn once, every light per fragment
};

struct Method {
  std::string name;           // the --method spelling
  std::string family;         // "reference", "gbuffer", "lighting", "bloom" or "geometry"
  Layout layout = Layout::Seed002;
  Lighting lighting = Lighting::Loop;
  float epsilon = 0.0f;       // Volumes/Tiled: radiance a light may add outside its radius (light_cutoff_radius)
  int blur_passes = 0;        // > 0: bloom with this many separable blur passes (stage 5)
  bool bloom_half = false;    // bloom at half resolution in each axis
  bool optimized_geometry = false;  // meshoptimizer reordering + view-frustum culling (mesh_optimize.h)
  bool hdr32 = false;         // RGBA32F HDR target instead of the labs' RGBA16F
  bool cull_front_faces = true;     // Volumes: false draws front faces, the naive way (tests' witness)
  std::string summary;        // one line for --list
};

// Every method kit-bench knows, the reference first.
const std::vector<Method>& methods();
// By name; throws kit::Error listing the names.
KIT_NO_DANGLING const Method& find_method(const std::string& name);  // a row of the method table
// The GPU reference: RGBA32F position and normal, full-screen loop, RGBA32F HDR.
const Method& reference_method();
// What the labs run: seed 002's G-buffer and the full-screen loop.
const Method& labs_method();

// The many-lights scene's small lights: RenderSettings::extra_lights' placement
// (spawned_lights) over the scene's floor plan, lowered to just above the floor and
// dimmed so that all of them together keep kSmallLightsTotalIntensity: more lights
// means smaller ones, so their volumes shrink as their number grows.
constexpr float kSmallLightsTotalIntensity = 2.0f;  // candela over all small lights
constexpr float kSmallLightMinHeight = 0.05f;       // metres above the scene's lowest point
constexpr float kSmallLightHeightSpan = 0.25f;      // heights spread over [min, min + span]
// Each small light has a glTF range (lab 3's window, lights.glsl kit_range_window):
// where its unwindowed radiance off a white Lambertian surface, I c_max / (pi d^2),
// falls to this. Past it the light adds exactly nothing, so a volume or tile radius
// of `range` is exact (light_bounds.glsl).
constexpr float kSmallLightRangeRadiance = 1.0f / 512.0f;
enum class SmallLightRange { Ranged, Unlimited };
std::vector<Light> small_lights(const Scene& scene, int count, SmallLightRange range = SmallLightRange::Ranged);
// The scene's own lights followed by `extra` small lights.
std::vector<Light> bench_lights(const Scene& scene, int extra, SmallLightRange range = SmallLightRange::Ranged);

// light_cutoff_radius (render/light_volumes.h) bounds each light of the culling methods,
// lab 7's volumes among them.
// Light volumes and tiles bound each light by a sphere around its position; a
// directional light has neither, so those methods throw kit::Error naming it.
void require_positional_lights(const std::vector<Light>& lights, const std::string& method);

class BenchRenderer {
 public:
  // `settings` gives the size, gamma, attenuation model, clear colour and bloom
  // threshold (its extra_lights is ignored: `lights` is the light list).
  BenchRenderer(const Scene& scene, std::vector<Light> lights, const RenderSettings& settings);
  ~BenchRenderer();
  BenchRenderer(const BenchRenderer&) = delete;
  BenchRenderer& operator=(const BenchRenderer&) = delete;

  // One frame, ending in the 8-bit display image as the labs' pipeline does.
  // Programs and targets a method needs are made on its first frame. With
  // `pass_times`, each pass ends in glFinish and its wall-clock time is appended
  // (the extra synchronisation makes the frame slower: for breakdowns only).
  void render(const Method& method, const FrameCamera& camera, PassTimes* pass_times = nullptr);

  // The last frame's linear HDR image (RGBA).
  Image read_hdr();
  // The last frame's display image before 8-bit quantisation: its final pass
  // (tone mapping, or bloom composite) rendered again into an RGBA32F target.
  Image read_display();
  // The last frame's G-buffer in world space as the CPU reference reads it:
  // position, normal, albedo, material per gbuffer_layout.h (FAT layouts only).
  std::vector<Image> read_gbuffer();
  // Average number of lights evaluated per covered pixel in the last frame, from a
  // counting pass: every light for Loop/Forward, the lights whose volume holds the
  // pixel for Volumes/Tiled.
  double lights_per_pixel();
  // Triangles the method's geometry pass submits for this camera.
  size_t triangles(const Method& method, const FrameCamera& camera) const;

  int light_count() const { return static_cast<int>(lights_.size()); }
  const std::vector<Light>& lights() const { return lights_; }
  const RenderSettings& settings() const { return settings_; }

 private:
  struct Programs;
  const Program& program(const std::string& key);
  LayoutGBuffer& gbuffer(Layout layout);
  void set_uniforms(const Program& program, int light_count) const;
  void geometry_pass(const Method& method);
  void lighting_pass(const Method& method);
  void bloom_passes();
  // The light volumes added onto the HDR target (radiance, or 1 per light when counting).
  void volume_pass(bool count_lights);
  // The tiled method's culling and shading dispatches into the RGBA16F HDR target.
  void tiled_passes(bool count_lights);
  // Tone mapping (display.frag), or the bloom composite, from the HDR image into `target`.
  void display_pass(const Framebuffer& target);
  const Texture2D& hdr() const;
  const Framebuffer& hdr_fbo() const;

  const Scene& scene_;
  std::vector<Light> lights_;
  RenderSettings settings_;
  ShaderLibrary library_;
  SceneGpu scene_gpu_;
  std::unique_ptr<Scene> optimized_scene_;
  std::unique_ptr<SceneGpu> optimized_gpu_;
  std::map<std::string, Program> programs_;
  std::map<Layout, std::unique_ptr<LayoutGBuffer>> gbuffers_;
  // Light volumes' targets: the HDR image with a FAT G-buffer's depth, per (layout, hdr32).
  std::map<std::pair<Layout, bool>, std::unique_ptr<Framebuffer>> volume_fbos_;
  FullscreenTriangle triangle_;
  Mesh volume_sphere_;
  GlName<delete_buffer> tile_buffer_;  // the tiles' light lists (tiled_lists.glsl)
  size_t tile_buffer_ints_ = 0;
  LightBuffers light_buffers_;
  // One texel per light for the culling methods (light_bounds.glsl): world
  // position and light_cutoff_radius at bounds_key_'s epsilon and falloff model.
  Texture2D light_bounds_;
  std::pair<float, int> bounds_key_{-1.0f, -1};
  void bind_light_bounds();
  Texture2D hdr16_, hdr32_, forward_depth_, ldr_, display_;
  Framebuffer hdr16_fbo_, hdr32_fbo_, forward_fbo_, ldr_fbo_, display_fbo_;
  Texture2D bloom_[2][2];          // [half][ping-pong]
  Framebuffer bloom_fbo_[2][2];
  FrameCamera camera_;
  Method last_;                    // the method of the last render()
};

}  // namespace kit::bench

#pragma once
// The deferred pipeline for one stage: geometry pass into the G-buffer, then
// (from stage 2) the full-screen lighting pass into an HDR target and a display
// pass through tonemap.glsl, then (stage 5) bright pass, separable blur
// ping-pong, composite and the student's custom effect. The framework sets
// every uniform, so lab shaders only compute.
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "render/forward_pass.h"
#include "render/gbuffer.h"
#include "render/ibl.h"
#include "render/light_volumes.h"
#include "images/image_io.h"
#include "render/material_variants.h"
#include "gl/pass_clock.h"
#include "scene/scene.h"
#include "render/stages.h"

namespace kit {

struct RenderSettings {
  int width = 640, height = 480;
  float gamma = 2.2f;               // u_gamma, used by tonemap.glsl from stage 3
  int attenuation_model = 0;        // u_attenuation_model: 0 physical (seed 000), 1 simple 1/(1+d^2) (seed 002)
  bool postprocess = true;          // u_postprocess_enabled (stage 5)
  bool custom_effect = false;       // u_custom_enabled (stage 5 free-choice slot)
  float bloom_threshold = 1.0f;     // u_bloom_threshold, luminance in linear HDR
  int blur_passes = 6;              // separable blur passes (alternating horizontal/vertical)
  float time = 0.0f;                // u_time for animated custom effects; fixed headless
  glm::vec3 clear_color{0.02f, 0.02f, 0.025f};  // u_clear_color, linear HDR
  int extra_lights = 0;             // small point lights added around the scene (viewer slider, bench)
  // -1: every frame light shines. i >= 0: frame light i alone (numbered as frame_lights lists
  // them before a stage's reordering; i past the last: none). The others are uploaded with
  // intensity 0, so the frame keeps its programs, light order and volumes, and the difference
  // from the frame with none is exactly that light's share of it: the grader's per-light
  // references (tools/grade/frames/light_shares.h).
  int only_light = -1;
  bool frustum_culling = false;     // skip draws wholly outside the view (mesh_optimize.h); off by default
  // Whether textures of at least kLargeTextureTexels are uploaded as S3TC blocks
  // (--compress-textures): Auto decides by the scene's texture bytes and the context
  // (decide_texture_compression, texture_compression.h); smaller ones never are.
  TextureCompression texture_compression = TextureCompression::Auto;
  // A scene without lights gets default_light_rig's lights. The tools turn this on
  // (cli.h; --no-default-lights turns it off); the grader and the tests render
  // scenes as they are.
  bool default_light_rig = false;
  // A small sphere of the light's colour at each point and spot light, drawn
  // forward after the lighting pass (forward_pass.h); the viewer's option, off headless.
  bool light_markers = false;
  // Stage 7: count the light volume pass's work each frame (light_volumes.h; three more
  // draws, each in an occlusion query). The grader's option; off elsewhere.
  bool count_light_volume_work = false;
  // Compile programs specialised to what a frame draws: the frame's light types, its
  // lights' lack of range and the attenuation model as constants in the lighting shaders
  // (light_specialisation.glsl), and a geometry program per feature set of the scene's
  // materials (material_variants.h). Faster frames on llvmpipe, at one compilation for
  // each combination a scene brings. The grader turns it off: its render workers draw a
  // few small frames with each program, where a compilation (tens of ms, more on a cold
  // shader cache) costs more than it saves. The image is the same either way.
  bool specialise_shaders = true;
  // Stage 6: the environment (a kit environment's name or an .hdr/.exr file; empty:
  // kDefaultEnvironment) and how its maps are precomputed (ibl.h).
  std::string environment;
  IblSettings ibl;
};

// Whether two settings give the same image at the same size and camera: every field
// but the size, u_time and specialise_shaders (which changes how the image is computed,
// not the image). A new field goes here too.
bool same_image_settings(const RenderSettings& a, const RenderSettings& b);

// The last three are stage 6's precomputed maps: the irradiance map, the prefiltered
// map's levels stacked (read_prefiltered_levels) and the BRDF table, each at its own size.
enum class View { Final, Position, Normal, Albedo, Material, Emission, Depth, Hdr, Irradiance, Prefiltered, BrdfLut };
// final|position|normal|albedo|material|emission|depth|hdr|irradiance|prefiltered|brdf-lut
View parse_view(const std::string& name);
const char* view_name(View view);
// Whether `view` is one of stage 6's precomputed maps: made from the environment alone
// (not from the frame), each at its own size; other stages have none.
bool is_precomputed_map(View view);

// Camera matrices for one frame.
struct FrameCamera {
  glm::mat4 view{1.0f}, projection{1.0f};
  glm::vec3 position{0.0f};
  float znear = 0.1f, zfar = 100.0f;
};
FrameCamera frame_camera(const Camera& camera, float aspect);
// Whether two cameras are the same, value for value.
bool same_frame_camera(const FrameCamera& a, const FrameCamera& b);

// Light radiometry the framework derives from glTF units (see handouts/03-attenuation.md):
// flux = 4*pi*I for a point light, 2*pi*(1 - (cos_inner + cos_outer)/2)*I for a spot light.
// A directional light has no finite flux (its intensity is an illuminance): 0, which no
// shader may use.
float light_flux(const Light& light);

// Sets the uniforms of uniforms.glsl every pass reads (camera matrices and position,
// resolution, light count, display and postprocess settings) and uses `program`.
void set_frame_uniforms(const Program& program, const FrameCamera& camera, const RenderSettings& settings,
                        int light_count);

// Points every sampler uniform the framework binds at its texture unit, and every
// uniform block at its binding point (gbuffer_layout.h).
void set_resource_bindings(const Program& program);
// The texture unit of a sampler uniform the framework binds ("u_irradiance"), or -1.
int sampler_unit(const std::string& name);
// Every texture unit the framework binds a sampler to (the geometry pass's material textures
// share units with the G-buffer's).
std::set<int> sampler_units();
// A vertex + fragment program from `library` with the sampler units set.
Program make_program(const ShaderLibrary& library, const std::string& vertex, const std::string& fragment);

// RenderSettings::extra_lights' placement: `count` deterministic small point lights
// spread over the scene's bounds (golden-angle spiral), 0.5 cd each, each with a glTF
// range of kSpawnedLightRange times the bounds' diagonal: small lights, whose light volumes
// (stage 7) stay small however many there are.
constexpr float kSpawnedLightRange = 0.08f;
std::vector<Light> spawned_lights(const Scene& scene, int count);

// Three point lights for a scene that has none, so a model brought without lights
// still shows its shape: a key light (upper left front), a fill light (right, lower,
// weaker) and a rim light (above and behind), each at 3 bounding-sphere radii from
// the bounds' centre. Each light's intensity is chosen so the illuminance it gives
// at the centre is the same for a 1 cm and a 100 m model: its irradiance constant
// (3, 1 and 1.5) times the falloff the stage applies at that distance d (d^2 with
// the physical model from stage 3 on, 1 + d^2 with the simple one, 1 in stage 2,
// which has no falloff).
std::vector<Light> default_light_rig(const Scene& scene, const Stage& stage, int attenuation_model);
// Whether the lights of a frame include the default rig: the scene has no lights and
// `settings` ask for it.
bool uses_default_light_rig(const Scene& scene, const RenderSettings& settings);
// The same at `stage`: never at a stage lit by an environment, which lights a scene
// without lights by itself.
bool uses_default_light_rig(const Scene& scene, const Stage& stage, const RenderSettings& settings);
// The lights a frame uploads: the scene's (or the default rig), then
// RenderSettings::extra_lights spawned ones. At a stage drawing light volumes the
// directional lights come first, in their order, then the rest in theirs: the full-screen
// pass loops over the first ones, the volumes are the others. `list_index`, where given,
// gets each frame light's index in the list before that reordering.
std::vector<Light> frame_lights(const Scene& scene, const Stage& stage, const RenderSettings& settings,
                                std::vector<int>* list_index = nullptr);

// Defines KIT_ATTENUATION_MODEL_PHYSICAL (model 0) or KIT_ATTENUATION_MODEL_SIMPLE (1)
// in `library` and no other, so light_specialisation.glsl (which lights.glsl includes)
// declares u_attenuation_model as that constant; another model (-1) defines neither, and
// u_attenuation_model is a uniform.
void apply_attenuation_model_define(ShaderLibrary& library, int model);

// Whether `stage`'s lighting pass runs only where the G-buffer's depth holds a surface
// (FullscreenTriangle::pass_over_surfaces), the background cleared to the clear colour
// before it: at every lit stage but lab 2's own, whose lighting.frag decides by the
// coverage mask, pixel by pixel, what is background (that branch is the lab's to write,
// and a mistake in it must show). On the crowd scene 71 % of the pixels are background
// (what skipping them saves: docs/performance.md, via handouts/02-lighting.md "Speed").
bool skips_background_pixels(const Stage& stage);

// Defined in every shader (ShaderLibrary::set_define) when a frame has more lights
// than the uniform block holds: lights.glsl then reads them all from the texture.
constexpr const char* kLightsInTexture = "KIT_LIGHTS_IN_TEXTURE";
// Defined when every light of a frame has that one type, and when none has a glTF range:
// kit_light() then returns the type and range as constants, and the shader compiler
// removes the branches for the types the frame does not have (light_specialisation.glsl says why that
// pays on llvmpipe). The values the shaders see are the same either way.
constexpr const char* kLightsAllPoint = "KIT_LIGHTS_ALL_POINT";
constexpr const char* kLightsAllSpot = "KIT_LIGHTS_ALL_SPOT";
constexpr const char* kLightsAllDirectional = "KIT_LIGHTS_ALL_DIRECTIONAL";
constexpr const char* kLightsWithoutRange = "KIT_LIGHTS_WITHOUT_RANGE";
// The lights every lighting shader reads (lights.glsl), KIT_LIGHT_TEXELS vec4 per light,
// light i in row i: up to KIT_LIGHT_BLOCK_CAPACITY in a uniform buffer (always its full
// size: std140 reads past the lights given are zeros, never unbacked), more in an
// RGBA32F texture. Only the one the shaders read is made.
class LightBuffers {
 public:
  LightBuffers() = default;
  // `volume_radii`: each light's light volume radius (Light.volume_radius in lights.glsl;
  // 0 where not given).
  explicit LightBuffers(const std::vector<Light>& lights, const std::vector<float>& volume_radii = {});
  // Whether the lights are in the texture: the programs that read them must be
  // compiled with kLightsInTexture defined exactly then.
  bool in_texture() const { return texture_.id() != 0; }
  // Sets the defines above in `library` as these lights need them (programs assembled from
  // `library` before must then be built again); `specialise` false leaves every one but
  // kLightsInTexture undefined (RenderSettings::specialise_shaders).
  void apply_defines(ShaderLibrary& library, bool specialise = true) const;
  // The texture on KIT_UNIT_LIGHTS, or the buffer at KIT_BLOCK_LIGHTS.
  void bind() const;

 private:
  Texture2D texture_;
  GlName<delete_buffer> block_;
  std::vector<std::pair<std::string, bool>> defines_;  // every define above, on or off
};

// Which draws a geometry pass draws: every one (stage 1, which has no forward
// pass, and kit-bench), or all but glTF BLEND materials, which the forward pass
// draws after lighting (forward_pass.h).
enum class DrawSet { All, AllButBlend };

// The geometry pass's draw loop: per draw item the model/normal matrices and
// material uniforms of geometry_uniforms.glsl, the material textures with their
// glTF samplers, then the mesh, wound clockwise where the draw is mirrored
// (DrawItem::mirrored) and without back-face culling where the material is
// double-sided. After the loop the samplers are unbound, GL's counter-clockwise
// front faces restored and culling enabled again. `geometry` must be in use with its
// frame uniforms set. With `frustum_culling`, draws wholly outside
// `view_projection` are skipped.
void draw_scene(const Program& geometry, const Scene& scene, const SceneGpu& gpu,
                const glm::mat4& view_projection, bool frustum_culling, DrawSet set = DrawSet::All);
// The same with each draw's material variant (GeometryPrograms::for_draw, material_variants.h),
// every variant's frame uniforms set; each program it draws with is added once to `drawn`.
void draw_scene(const GeometryPrograms& geometry, const Scene& scene, const SceneGpu& gpu,
                const glm::mat4& view_projection, bool frustum_culling, DrawSet set,
                std::vector<const Program*>* drawn = nullptr);
// Adds `program` to `drawn`, when given, unless it is there: the programs a pass drew
// with, each once, in the order first drawn.
void note_drawn(std::vector<const Program*>* drawn, const Program& program);
// The material a draw item is drawn with: its primitive's, or glTF's default material.
const Material& draw_material(const Scene& scene, const DrawItem& draw);
// One draw item as draw_scene draws it; end_scene_draws() restores GL's state after the last.
void draw_item(const Program& geometry, const Scene& scene, const SceneGpu& gpu, const DrawItem& draw);
void end_scene_draws();

// Stage 5's separable blur: `passes` full-screen passes of blur.frag (in use,
// frame uniforms set) ping-ponging between targets[0] (holding the bright pass)
// and targets[1], horizontal first. Binds the blurred result,
// targets[blur_result(passes)], on KIT_UNIT_BLOOM.
int blur_result(int passes);  // 0 after an even pass count, 1 after an odd one
void blur_ping_pong(const FullscreenTriangle& triangle, const Program& blur, const Texture2D (&targets)[2],
                    const Framebuffer (&fbos)[2], int passes, int width, int height);

// What to do about NaN/Inf pixels, in the words every tool uses.
constexpr const char* kNonFiniteAdvice = "guard the divisions and square roots (guards.glsl)";

// NaN/Inf pixels in one float buffer of a frame.
struct NonFiniteCount {
  View view;
  size_t pixels = 0, of = 0;  // pixels holding a NaN or Inf in any channel, out of all
};

// Stage 6's environments and precomputed maps, shared by the Renderers of one GL
// context (the grader renders a lab's scenes under two environments: each
// environment's maps are made once, not once per Renderer). Keyed by the
// environment, the IblSettings and the assembled text of the precompute shaders,
// so a Renderer with other shaders, or reloaded ones, never gets another's maps.
// It must not outlive the context its textures belong to.
class IblCache {
 public:
  std::shared_ptr<const ImageBasedLighting> find(const std::string& key) const;
  void store(const std::string& key, std::shared_ptr<const ImageBasedLighting> maps);

 private:
  std::map<std::string, std::shared_ptr<const ImageBasedLighting>> maps_;
};

class Renderer {
 public:
  // `library` resolves the stage's shaders (see stage_library). Throws kit::Error
  // on any shader or GL problem; before compiling, the stage's vertex/fragment
  // pairs must agree on their varyings (interface_check.h). With `ibl_cache`,
  // stage 6 takes its environment's maps from it when they are there, and
  // leaves them there when it makes them.
  Renderer(const Stage& stage, ShaderLibrary library, const Scene& scene, RenderSettings settings,
           IblCache* ibl_cache = nullptr);
  ~Renderer();

  void reload_shaders();  // recompiles; on error keeps the old programs and throws
  void resize(int width, int height);
  RenderSettings& settings() { return settings_; }
  const Stage& stage() const { return stage_; }
  const Scene& scene() const { return scene_; }
  std::vector<std::filesystem::path> shader_paths() const;  // for hot reload
  // Seconds the scene's meshes and textures took to decode and upload (SceneGpu).
  double scene_upload_seconds() const { return scene_upload_seconds_; }
  // Whether the scene's large textures were compressed, and why (SceneGpu).
  const TextureCompressionDecision& texture_compression() const { return scene_gpu_.texture_compression(); }
  // Stage 6: the environment and its maps (null at other stages).
  const ImageBasedLighting* image_based_lighting() const { return ibl_.get(); }
  // The same, to change a map (ImageBasedLighting::set_irradiance, kit-bench): lasts until
  // the settings change or the shaders reload. Throws kit::Error for a Renderer made with
  // an IblCache, whose maps other Renderers share.
  ImageBasedLighting* image_based_lighting();

  // One frame. With `pass_times`, each pass ends in glFinish and its time is appended
  // (pass_clock.h: for breakdowns only).
  void render(const FrameCamera& camera, PassTimes* pass_times = nullptr);
  // One frame as render() draws it, but when the last frame was drawn with the same camera
  // and the same settings for every pass before post-processing, only the post-processing
  // (or display) passes run: the HDR target already holds what the others would draw, bit
  // for bit. The settings that may differ are those only post-processing reads (gamma,
  // postprocess, custom_effect, bloom_threshold, blur_passes, time), each unless a pass
  // before it reads the setting's uniform (a lighting shader that reads u_gamma). The
  // grader draws lab 5's scene under eight post settings. Returns whether it reused.
  // Not for frame timings: the passes it skips take no time.
  bool render_reusing_lit_frame(const FrameCamera& camera);

  const GBuffer& gbuffer() const { return gbuffer_; }
  // Stage 7: the state light_volume.vert asks for, and the last frame's counted work
  // (zeros unless RenderSettings::count_light_volume_work).
  const LightVolumeState& light_volume_state() const { return volume_state_; }
  const LightVolumeWork& light_volume_work() const { return volume_work_; }
  // The stage's output texture: the LDR image for lit stages, albedo for stage 1.
  const Texture2D& final_texture() const;
  // The view as an image. raw=true reads the attachment's float values (for
  // EXR); raw=false maps it for display: vectors as (v+1)/2, depth linearised.
  Image read_view(View view, bool raw);
  // The view as a GPU texture, mapped for display as read_view(view, false)
  // maps it, so a window can show it without a CPU round trip.
  const Texture2D& display_texture(View view);

  // NaN/Inf pixels in the float data behind `view` as the last frame left it:
  // the attachment for a G-buffer view, the HDR buffer for hdr and (lit stages)
  // final, whose 8-bit image cannot hold them.
  size_t count_non_finite(View view);
  // The same for every float buffer the frame wrote: position, normal and
  // material, and hdr on lit stages. Reads them back (not for every frame).
  std::vector<NonFiniteCount> non_finite_pixels();
  // Uniforms the last frame's programs use but the framework never set (they
  // read 0), one line each naming the file and line of the declaration.
  std::vector<std::string> uniform_warnings() const;

 private:
  struct Programs;
  void build_programs();
  bool render_frame(const FrameCamera& camera, PassTimes* pass_times, bool reuse_lit_frame);
  bool render_passes(const FrameCamera& camera, PassClock& clock, bool reuse_lit_frame);
  void draw_lit_frame(PassClock& clock);
  void post_passes(PassClock& clock);  // after draw_lit_frame: display, or stage 5's post-processing
  bool lit_frame_current(const FrameCamera& camera) const;
  void upload_lights();
  void set_frame_uniforms(const Program& program) const;
  void fullscreen_pass(const Program& program, const Framebuffer& target, int width, int height) const;
  void lighting_pass(const Program& lighting) const;
  void light_volume_pass();
  void measure_volume_evidence();  // light_volume_work().evidence, after the pass
  void allocate_targets();
  // Stage 6: the maps for settings_.environment and settings_.ibl, from the cache or
  // made (loading the environment when it is another than ibl_'s).
  void update_ibl();
  std::string ibl_cache_key() const;

  Stage stage_;
  ShaderLibrary library_;
  const Scene& scene_;
  RenderSettings settings_;
  double scene_upload_seconds_ = 0.0;  // declared before scene_gpu_, whose construction sets it
  SceneGpu scene_gpu_;
  GBuffer gbuffer_;
  FullscreenTriangle triangle_;
  std::unique_ptr<Programs> programs_;
  // The library's defines programs_ were built with: when a build fails, the defines have
  // changed and the programs have not, and the next frame builds again.
  std::vector<std::string> programs_defines_;
  // The forward pass (BLEND draws, light markers): stages with a lighting pass only, and
  // null until a frame has work for it (build_programs).
  std::unique_ptr<ForwardPass> forward_;
  // Stage 6's environment and maps, and the environment and settings they were made for.
  // Shared with ibl_cache_ (and other Renderers) when it came from there: never changed then.
  std::shared_ptr<const ImageBasedLighting> ibl_;
  std::string ibl_environment_;
  IblSettings ibl_settings_;
  IblCache* ibl_cache_ = nullptr;
  bool blend_draws_ = false;  // the scene has BLEND draws (it never changes: found once)
  std::vector<Light> frame_lights_;  // as uploaded, for the light markers
  LightBuffers lights_;
  int light_count_ = 0;
  // The settings the uploaded lights were made for: a change re-uploads them.
  int lights_extra_ = -1, lights_attenuation_model_ = -1, lights_only_ = -1;
  bool shaders_specialised_ = true;  // the setting the programs were built for
  bool lights_default_rig_ = false;
  float lights_gamma_ = -1.0f;  // the volume radii depend on it (light_volume_epsilon)
  // Stage 7: the directional lights lead frame_lights_; the volumes draw the rest.
  int directional_count_ = 0;
  std::vector<int> frame_light_numbers_;  // each frame light's index in the scene's (or rig's) list
  LightVolumeState volume_state_;
  LightVolumeWork volume_work_;
  Mesh volume_sphere_;
  Texture2D hdr_, bloom_[2], composite_, final_;
  Framebuffer hdr_fbo_, bloom_fbo_[2], composite_fbo_, final_fbo_, debug_fbo_;
  // The HDR target with the G-buffer's depth, for a lighting pass drawn only over
  // surfaces (skips_background_pixels).
  Framebuffer lighting_fbo_;
  Texture2D debug_target_;
  FrameCamera camera_;
  std::vector<const Program*> used_;  // the programs the last frame drew with, in order
  // The camera and settings of the last frame whose passes before post-processing ran, and
  // the programs they drew with (render_reusing_lit_frame); reset whenever what those
  // passes draw with changes (programs, lights, maps, targets).
  struct LitFrame {
    FrameCamera camera;
    RenderSettings settings;
    std::vector<const Program*> drawn;
  };
  std::optional<LitFrame> lit_frame_;
};

}  // namespace kit

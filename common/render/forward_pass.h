#pragma once
// What deferred shading cannot draw, drawn forward after the lighting pass and
// before tone mapping (handouts/README.md, "The forward pass"):
//
//  * glTF BLEND materials. A G-buffer holds one surface a pixel, so a see-through
//    surface and what lies behind it cannot both be in it. Each BLEND draw, back to
//    front, is drawn by the stage's own geometry pass into a layer G-buffer of its
//    own, depth-tested against the opaque depth, lit by the stage's own lighting
//    pass (the same BRDF and light modules as the opaque surfaces), and laid over
//    the HDR target with the over operator: L = a L_layer + (1 - a) L_behind, a the
//    base colour alpha the geometry pass wrote in albedo.a. Within one draw the
//    nearest surface wins (one layer a draw); draws are ordered by the distance of
//    their bounds' centre along the view, farthest first.
//  * Light markers (the viewer's option): a small sphere of the light's colour at
//    each point and spot light, depth-tested against the G-buffer's depth.
#include <optional>
#include <vector>

#include "render/gbuffer.h"
#include "gl/gl_objects.h"
#include "render/material_variants.h"
#include "scene/scene.h"

namespace kit {

class ShaderLibrary;

// Whether the draw's material is glTF BLEND.
bool is_blend_draw(const Scene& scene, const DrawItem& draw);
// Whether the scene has any BLEND draw (the forward pass has work).
bool has_blend_draws(const Scene& scene);

// Indices into scene.draws of the BLEND draws, farthest first: by the view-space
// depth of the centre of each draw's world bounds (the primitive's bounds corners
// transformed by the draw's matrix), ties in the scene's order.
std::vector<size_t> blend_draws_back_to_front(const Scene& scene, const glm::mat4& view);

// A window-space rectangle in pixels: x, y the lower left corner.
struct PixelRect {
  int x = 0, y = 0, width = 0, height = 0;
};
// The pixels a box (object-space bounds under `world`) can cover in a width x
// height target, one pixel of margin around it; nullopt when the box reaches
// behind the camera's plane (w <= 0), where its projection is unbounded: the
// caller then uses the whole target. An empty rect (width or height 0) means the
// box is outside the view.
std::optional<PixelRect> projected_rect(const glm::vec3& bounds_min, const glm::vec3& bounds_max, const glm::mat4& world,
                                        const glm::mat4& view_projection, int width, int height);

// A polyhedron enclosing the unit sphere: an icosahedron subdivided `subdivisions`
// times, scaled so that its nearest face plane is at distance 1 (a mesh with its
// vertices on the sphere would cut into the sphere between them). Light volumes
// (kit-bench) and light markers draw it.
Mesh enclosing_sphere_mesh(int subdivisions);
// The distance of that mesh's vertices from its centre: the smallest sphere enclosing it.
float enclosing_sphere_circumradius(int subdivisions);

// Radius of a light marker: 0.5 % of the scene's bounding-box diagonal, so
// markers look alike at any scale.
float light_marker_radius(const Scene& scene);

// The radiance a marker shows for `light`: its colour scaled so the brightest
// channel is kMarkerRadiance, bright enough to read as a light after tone mapping
// whatever the light's intensity.
constexpr float kMarkerRadiance = 4.0f;
glm::vec3 light_marker_radiance(const Light& light);

// GL resources and passes of the forward pass; the Renderer owns one per stage
// with a lighting pass.
class ForwardPass {
 public:
  // `library` is the stage's: blend_layer.frag and the marker shaders come from
  // shaders.
  ForwardPass(const ShaderLibrary& library, int width, int height);
  // Whether its programs are what `library` would build now (Program::built_from).
  bool built_from(const ShaderLibrary& library) const;
  void resize(int width, int height);

  // The BLEND draws over `hdr_fbo` (colour: the HDR target). `geometry` (each draw's
  // material variant) and `lighting` (and at stage 6 `ibl`, else null, added to the layer
  // as to the opaque surfaces) are the stage's programs with their frame uniforms set; the lights
  // texture (and the IBL maps) are bound; `opaque` is the frame's G-buffer with the opaque surfaces.
  // Leaves the layer's textures bound on the G-buffer units: rebind the opaque ones
  // before a pass reads them. Each geometry program it draws with is added once to `drawn`.
  void draw_blend_layers(const GeometryPrograms& geometry, const Program& lighting, const Program* ibl,
                         const Scene& scene, const SceneGpu& gpu,
                         const GBuffer& opaque, const Framebuffer& hdr_fbo, const glm::mat4& view,
                         const glm::mat4& view_projection, const FullscreenTriangle& triangle,
                         std::vector<const Program*>* drawn = nullptr);

  // Light markers into `hdr` (the HDR texture), depth-tested against `opaque`'s
  // depth. `marker` programs need their frame uniforms set (set_frame_uniforms).
  void draw_light_markers(const std::vector<Light>& lights, const Scene& scene, const GBuffer& opaque,
                          const Texture2D& hdr);

  // The programs, for the Renderer's frame uniforms and uniform checks.
  const Program& blend_program() const { return blend_; }
  const Program& marker_program() const { return marker_; }

 private:
  void allocate();
  int width_, height_;
  GBuffer layer_;
  Texture2D layer_hdr_;
  Framebuffer layer_hdr_fbo_, marker_fbo_;
  Program blend_, marker_;
  Mesh marker_sphere_;
};

}  // namespace kit

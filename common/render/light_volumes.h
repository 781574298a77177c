#pragma once
// Lab 7's light volumes (handouts/07-lightvolumes.md): each point and spot light drawn as
// a sphere of its volume radius, shading only the pixels it covers, added into the HDR
// target. What the framework gives: the radius, the state the student's
// light_volume.vert asks for, and the work the pass did, counted exactly.
#include <cstdint>
#include <string>
#include <vector>

#include "gl/shader_source.h"
#include "scene/scene.h"

namespace kit {

// The volume every light is drawn with: enclosing_sphere_mesh(1) (forward_pass.h), an
// icosahedron subdivided once (80 faces) whose faces lie outside the unit sphere, so the
// mesh scaled by a radius covers every pixel the sphere of that radius covers.
constexpr int kLightVolumeSubdivisions = 1;

// The display error the cut-off may cause: one 8-bit step. Tone mapping is Reinhard
// then gamma (lab 3's tonemap.glsl), display(L) = (L / (1 + L))^(1/gamma): concave, so
// adding dL to any radiance changes the display by at most display(dL), and the most
// radiance all cut-off lights together may drop at one pixel is the dL whose display is
// one step: kCutoffDisplayStep^gamma / (1 - kCutoffDisplayStep^gamma) (5.1e-6 at 2.2).
constexpr float kCutoffDisplayStep = 1.0f / 255.0f;

// The radiance a light may drop where it is cut off (the lights without a glTF range
// share light_volume_budget(gamma) equally: each gets it divided by their number, so
// together they stay under one display step at any pixel).
float light_volume_budget(float gamma);
float light_volume_epsilon(const std::vector<Light>& lights, float gamma);

// Where a light's contribution falls below epsilon: the radius of its light volume, at
// most its glTF range (past which the range window, lights.glsl kit_range_window, makes it
// exactly 0, so a range radius drops nothing).
//
// Bound: outgoing radiance from one light is f L_i (n.l) with n.l <= 1, the spot cone
// factor <= 1, the range window <= 1 and L_i <= I c_max / d^2 (I the glTF intensity in
// candela: the physical model's flux / (4 pi d^2) is exactly I / d^2 for a point light and
// at most that for a spot). For f the bound is the Lambertian lobe at albedo 1, 1/pi. So
// I c_max / (pi r^2) = epsilon gives r = sqrt(I c_max / (pi epsilon)); with seed 002's
// simple model I / (1 + d^2) the same bound gives r^2 = I c_max / (pi epsilon) - 1. The
// bound leaves out the specular lobe: a glossy highlight of a light outside its radius
// is lost (the handout measures it). A directional light reaches everywhere: +infinity.
float light_cutoff_radius(const Light& light, float epsilon, int attenuation_model);

// The GL state the student's light_volume.vert asks for on its line
//   #pragma kit_light_volume cull(none|back|front) depth(off|less_equal|greater_equal) blend(off|add)
// (GLSL compilers ignore a pragma they do not know). Depth writes are always off: the
// test reads the G-buffer's depth.
struct LightVolumeState {
  enum class Cull { None, Back, Front } cull = Cull::Back;
  enum class Depth { Off, LessEqual, GreaterEqual } depth = Depth::LessEqual;
  bool blend_add = false;
};
// Throws kit::Error naming the file and line when the pragma is missing, given twice or
// holds a word it does not know.
LightVolumeState parse_light_volume_state(const AssembledShader& vertex);
std::string describe(const LightVolumeState& state);  // "cull(front) depth(greater_equal) blend(add)"

// The work of one frame's light volume pass, counted with GL_SAMPLES_PASSED (exact on
// Mesa's rasterisers): what lab 7 is graded on beside the image.
struct LightVolumeWork {
  int volume_lights = 0;           // point and spot lights drawn as volumes
  uint64_t surface_pixels = 0;     // pixels with a surface: what the full-screen loop shades per light
  uint64_t shaded_fragments = 0;   // fragments the student's volumes reached the fragment shader with
  uint64_t volume_coverage = 0;    // the framework's own spheres (radius as given, back faces, no depth
                                   // test): every pixel each volume covers on screen, once
  // The loop's work over the volumes': surface_pixels * volume_lights / shaded_fragments.
  double speedup() const;
};

}  // namespace kit

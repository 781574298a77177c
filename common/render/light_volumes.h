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

// Where a frame's volumes go wrong, measured light by light (each light's volume drawn alone
// inside occlusion queries; up to kEvidenceLights of them, evenly spread over the list, so a
// frame of 128 lights costs 16 lights' queries): evidence for naming lab 7's mistakes
// (tools/grade/verdict/diagnosis.h) and for telling a student which light to look at. Pixels, summed
// over the lights measured. Zeros where the counts are not exact (WebGL2, gl_flavour.h).
constexpr int kEvidenceLights = 16;
struct VolumeEvidence {
  int lights = 0;              // lights measured
  uint64_t footprint = 0;      // pixels the framework's volumes cover (back faces, no depth test)
  uint64_t missing = 0;        // of those, pixels the student's volumes do not cover
  uint64_t extra = 0;          // pixels the student's volumes cover outside the framework's
  uint64_t must_shade = 0;     // surface pixels inside a light's sphere: each to be shaded once
  uint64_t shaded_wrong = 0;   // how far the fragments the student's state lets through on those pixels,
                               // drawing the framework's volume, are from one each (|fragments - pixels|
                               // per light, summed)
  bool adds = true;            // the state adds each light's term (blend(add)) rather than replacing
  // The light (its index in the scene's light list, from 0) whose volume misses or adds the
  // most pixels, with its counts, and the one whose state is furthest off; -1 for none.
  int worst_volume_light = -1;
  uint64_t worst_footprint = 0, worst_missing = 0, worst_extra = 0;
  int worst_state_light = -1;
  uint64_t worst_must_shade = 0, worst_shaded = 0;
};

// The work of one frame's light volume pass, counted with GL_SAMPLES_PASSED (exact on
// Mesa's rasterisers): what lab 7 is graded on beside the image.
struct LightVolumeWork {
  int volume_lights = 0;           // point and spot lights drawn as volumes
  uint64_t surface_pixels = 0;     // pixels with a surface: what the full-screen loop shades per light
  uint64_t shaded_fragments = 0;   // fragments the student's volumes reached the fragment shader with
  uint64_t volume_coverage = 0;    // the framework's own spheres (radius as given) under the state that
                                   // shades least, cull(front) depth(greater_equal): each pixel a volume
                                   // covers on screen where the surface lies in front of its far side, once
  // The loop's work over the volumes': surface_pixels * volume_lights / shaded_fragments.
  double speedup() const;
  VolumeEvidence evidence;  // light by light: where the volumes go wrong
};

}  // namespace kit

#pragma once
// Rendering frames for comparison with the CPU reference (cpu_reference.h), and
// the comparison itself: linear HDR within a relative bound, or the displayed
// image within one 8-bit step.
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "cpu_reference.h"
#include "kit_test.h"  // small_settings, kSmallWidth, kSmallHeight
#include "render/renderer.h"
#include "gl/shader_source.h"

namespace kit::test {

// Everything one rendered frame leaves for the CPU reference to check.
struct Frame {
  reference::GBufferImages gbuffer;  // raw attachment values
  Image hdr;                         // View::Hdr: the RGBA16F lighting result, raw
  Image final;                       // the stage's displayed RGBA8 image
  FrameCamera camera;
  int stage = 0;
};

// A Renderer for `stage` (name or number) over `scene` with shaders from `library`;
// without one, the stage's solutions. Creates the test process's context first.
std::unique_ptr<Renderer> make_renderer(const std::string& stage, const Scene& scene, const RenderSettings& settings);
std::unique_ptr<Renderer> make_renderer(const std::string& stage, const Scene& scene, const RenderSettings& settings,
                                        ShaderLibrary library);

// The camera render_stage uses: the scene's own, else framing_camera.
FrameCamera scene_frame_camera(const Scene& scene, const RenderSettings& settings);
// A perspective camera at `eye` looking at `target`; +Y is up unless the view runs
// along it, then -Z is.
FrameCamera look_at_camera(glm::vec3 eye, glm::vec3 target, float yfov, const RenderSettings& settings,
                           float znear = 0.1f, float zfar = 50.0f);

// A close-up of the `sphere` scene's outline from its own camera at (0, 0, 4): the
// unit sphere's silhouette runs through (sqrt(15)/4, 0, 1/4), and a 0.01 rad field
// of view aimed there puts about ten pixel columns where n.v < 0.05.
FrameCamera sphere_silhouette_camera(const Scene& sphere, const RenderSettings& settings);

// Renders one frame with the renderer's current settings and reads it back.
Frame render_frame(Renderer& renderer, const FrameCamera& camera);

using reference::pixel_rgb;
// The value an RGBA8 target stored at a pixel, exactly k/255 (read back as float,
// k/255 is off by up to 3e-10, enough to tip an error of one step over the bound).
reference::dvec3 stored_ldr(const Image& image, int x, int y);
bool finite(reference::dvec3 v);
// Angle between two (not necessarily unit) vectors, in degrees.
double angle_degrees(reference::dvec3 a, reference::dvec3 b);

// n.v at a pixel, from the G-buffer and the camera (double); NaN where not covered.
double n_dot_v(const Frame& frame, int x, int y);
using PixelList = std::vector<std::pair<int, int>>;
PixelList covered_pixels(const Frame& frame);
// Covered pixels seen at a grazing angle: n.v below `max_n_dot_v`.
PixelList grazing_pixels(const Frame& frame, double max_n_dot_v);

// The accuracy bounds. Linear HDR: 1e-3 relative to max(|reference|,
// kHalfMinNormal), measured from the fp16 values either side of the reference
// (the RGBA16F target stores one of them: llvmpipe truncates, others round to
// nearest), so what is bounded is the shading's own error, not the storage's.
// The floor: below 2^-14 fp16's step is a constant 2^-24, which is under
// 1e-3 * 2^-14, so the bound never asks for more than the target can hold.
// Displayed image: one 8-bit step.
constexpr double kHdrRelativeTolerance = 1e-3;
constexpr double kLdrTolerance = 1.0 / 255.0;

struct Agreement {
  size_t pixels = 0;           // compared
  size_t hdr_within = 0;       // within kHdrRelativeTolerance in linear HDR
  size_t ldr_within_only = 0;  // outside it, but within kLdrTolerance once displayed
  size_t failures = 0;         // neither
  double max_hdr_relative = 0.0;      // over all compared pixels, beyond fp16 storage
  double max_hdr_raw_relative = 0.0;  // the same including the storage's rounding
  double max_ldr_abs = 0.0;       // over all compared pixels
  std::string worst;              // the pixel with the largest HDR error, for messages
};

// Compares `frame` at `pixels` with the reference evaluated on the frame's own
// read-back G-buffer (converted to double) with `lights` and `settings`.
Agreement compare_with_reference(const Frame& frame, const std::vector<Light>& lights,
                                 const reference::ShadingSettings& settings, const PixelList& pixels);
std::string describe(const Agreement& agreement);

}  // namespace kit::test

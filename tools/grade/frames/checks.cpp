#include "frames/checks.h"

#include <algorithm>

#include "base/error.h"

namespace kit::grade {

namespace {

// Shorthands for the table below.
RenderSpec gbuffer(const std::string& id, int stage, const std::string& scene, View view) {
  return {id, stage, scene, view, true};
}
RenderSpec final_image(const std::string& id, int stage, const std::string& scene) {
  return {id, stage, scene, View::Final, false};
}
RenderSpec hdr(const std::string& id, int stage, const std::string& scene) {
  return {id, stage, scene, View::Hdr, true};
}
template <typename Edit>
RenderSpec with(RenderSpec spec, Edit edit) {
  edit(spec);
  return spec;
}

}  // namespace

const char* metric_name(Metric metric) {
  switch (metric) {
    case Metric::Ldr: return "ldr";
    case Metric::Hdr: return "hdr";
    case Metric::Position: return "position";
    case Metric::Normal: return "normal";
    case Metric::Albedo: return "albedo";
    case Metric::Material: return "material";
    case Metric::Changes: return "changes";
    case Metric::Same: return "same";
    case Metric::Work: return "work";
  }
  return "?";
}

namespace {

// renders()'s table, lab by lab, in list order.

void add_lab1_renders(std::vector<RenderSpec>& r) {
  // Lab 1: the G-buffer attachments as floats, on the textured default scene and on
  // the normal-map scene (its non-uniformly scaled, tilted quad separates the normal
  // matrix from the model matrix).
  // (The normal-map scene has no base colour texture: its albedo would repeat the factor.)
  for (const char* scene : {"default", "normalmap"}) {
    std::string s = scene;
    r.push_back(gbuffer("lab1-" + s + "-position", 1, s, View::Position));
    r.push_back(gbuffer("lab1-" + s + "-normal", 1, s, View::Normal));
    if (s == "default") r.push_back(gbuffer("lab1-" + s + "-albedo", 1, s, View::Albedo));
    r.push_back(gbuffer("lab1-" + s + "-material", 1, s, View::Material));
  }
  // Emitted radiance as a colour: the default scene's warm emitter, and on the materials
  // scene a red emitter on a black base colour with an emissive texture. The materials
  // scene also has a MASK quad (mask), a double-sided quad seen from behind (normal)
  // and a BLEND strip whose alpha the albedo keeps.
  r.push_back(gbuffer("lab1-default-emission", 1, "default", View::Emission));
  r.push_back(gbuffer("lab1-materials-normal", 1, "materials", View::Normal));
  r.push_back(gbuffer("lab1-materials-albedo", 1, "materials", View::Albedo));
  r.push_back(gbuffer("lab1-materials-material", 1, "materials", View::Material));
  r.push_back(gbuffer("lab1-materials-emission", 1, "materials", View::Emission));
  // Each texture at its own UV: the texturing scene's base colour reads UV set 0, its
  // metallic-roughness and emissive textures UV set 1, each through its own transform,
  // and the metallic-roughness texture's channels differ (tools/scenes/scene_catalogue.cpp).
  for (View view : {View::Albedo, View::Material, View::Emission})
    r.push_back(gbuffer(std::string("lab1-texturing-") + view_name(view), 1, "texturing", view));
}

void add_lab2_renders(std::vector<RenderSpec>& r) {
  // Lab 2: no falloff and a clamped display yet (shaders/attenuation.glsl, tonemap.glsl),
  // so both the HDR buffer and the display image show the BRDF alone.
  for (const char* scene : {"default", "sphere"}) {
    std::string s = scene;
    r.push_back(final_image("lab2-" + s + "-final", 2, s));
    r.push_back(hdr("lab2-" + s + "-hdr", 2, s));
  }
  // A close-up of one glossy highlight: a mistake in the specular peak alone covers
  // thousands of pixels here, a handful elsewhere. HDR only: the clamped display
  // image of lab 2 saturates the peak.
  r.push_back(hdr("lab2-highlight-hdr", 2, "highlight"));
  // L_e is the emission attachment itself: a black base colour still glows, and the
  // double-sided quad is lit from behind.
  r.push_back(hdr("lab2-materials-hdr", 2, "materials"));
  // A low sun (a directional light: l = -direction wherever its node is) and a point
  // light: treating the sun as a point at its node, or l = +direction, darkens or
  // turns most of the floor and sphere.
  r.push_back(hdr("lab2-sun-hdr", 2, "sun"));
  // A glossy plane seen and lit at grazing angles: n.v and n.l are small across the
  // whole image, not only at silhouettes, so the geometry term's two sides (and which
  // dot product each takes) show inside the surface, where no edge tolerance applies.
  r.push_back(hdr("lab2-grazing-hdr", 2, "grazing"));
}

void add_lab3_renders(std::vector<RenderSpec>& r) {
  // Lab 3: the HDR buffer isolates attenuation.glsl; the display images add tonemap.glsl.
  auto simple = [](RenderSpec& s) { s.attenuation_model = 1; };
  auto gamma1 = [](RenderSpec& s) { s.gamma = 1.0f; };
  r.push_back(hdr("lab3-default-physical-hdr", 3, "default"));
  r.push_back(with(hdr("lab3-default-simple-hdr", 3, "default"), simple));
  r.push_back(hdr("lab3-sphere-physical-hdr", 3, "sphere"));
  r.push_back(final_image("lab3-default-physical-gamma22", 3, "default"));
  r.push_back(with(final_image("lab3-default-physical-gamma10", 3, "default"), gamma1));
  r.push_back(with(with(final_image("lab3-sphere-simple-gamma10", 3, "sphere"), simple), gamma1));
  // A wide penumbra (cones of 10 and 45 degrees): the smoothstep over the cosine and
  // one over the angle differ here by far more than the tolerance.
  r.push_back(hdr("lab3-spot-physical-hdr", 3, "spot"));
  // A directional light has no falloff under either model, where the point light beside
  // it falls off: a sun dimmed with distance (or given the point light's flux) shows.
  r.push_back(hdr("lab3-sun-physical-hdr", 3, "sun"));
  r.push_back(with(hdr("lab3-sun-simple-hdr", 3, "sun"), simple));
  // Two lights whose glTF range ends inside the view: the window must dim them. Under the
  // simple model too: its spot light stands 2-3 m from the floor it lights, where
  // 1/(1 + d^2) and the inverse square differ by 12-25 % (on the spot scene, 6-8 m away,
  // by about 2 %: a spot that ignores the model passes there).
  r.push_back(hdr("lab3-range-physical-hdr", 3, "range"));
  r.push_back(with(hdr("lab3-range-simple-hdr", 3, "range"), simple));
}

void add_lab4_renders(std::vector<RenderSpec>& r) {
  // Lab 4: the lit image and the mapped normal itself.
  r.push_back(final_image("lab4-normalmap-final", 4, "normalmap"));
  r.push_back(final_image("lab4-default-final", 4, "default"));
  r.push_back(gbuffer("lab4-normalmap-normal", 4, "normalmap", View::Normal));
  r.push_back(gbuffer("lab4-default-normal", 4, "default", View::Normal));
  // A normal map with normalTexture.scale 0.4 and its own UV transform, on a quad whose
  // tangent lies along no axis of its parent's non-uniform scale; beside it the quad whose
  // textures read two UV sets (lab 4's geometry pass reads them as lab 1's does).
  r.push_back(final_image("lab4-texturing-final", 4, "texturing"));
  r.push_back(gbuffer("lab4-texturing-normal", 4, "texturing", View::Normal));
  // The bricks magnified (the closeup scene says why): a faint mistake over every mapped
  // normal shows here, where the filter cannot hide it under its own approximation.
  r.push_back(final_image("lab4-closeup-final", 4, "closeup"));
  r.push_back(gbuffer("lab4-closeup-normal", 4, "closeup", View::Normal));
}

void add_lab5_renders(std::vector<RenderSpec>& r) {
  // Lab 5: bloom at two thresholds and on the sphere's highlight, the toggle off
  // (must equal stage 4), and the free-choice effect isolated on the solution's bloom.
  auto off = [](RenderSpec& s) { s.postprocess = false; };
  auto threshold = [](RenderSpec& s) { s.bloom_threshold = 0.5f; };
  auto isolated = [](RenderSpec& s) { s.isolate_custom = true; };
  auto custom_on = [](RenderSpec& s) { s.custom_effect = true; };
  r.push_back(final_image("lab5-default-bloom", 5, "default"));
  r.push_back(with(final_image("lab5-default-threshold05", 5, "default"), threshold));
  r.push_back(final_image("lab5-sphere-bloom", 5, "sphere"));
  r.push_back(with(final_image("lab5-default-off", 5, "default"), off));
  r.push_back(with(final_image("lab5-default-custom-off", 5, "default"), isolated));
  r.push_back(with(with(final_image("lab5-default-custom-on", 5, "default"), isolated), custom_on));
  // The handout's other settings: bloom at a second display gamma (a composite that
  // hard-codes 2.2 instead of calling tonemap() shows here), and the custom effect
  // switched on while postprocessing is off, when it must still pass the image through.
  auto gamma10 = [](RenderSpec& s) { s.gamma = 1.0f; };
  r.push_back(with(final_image("lab5-default-bloom-gamma10", 5, "default"), gamma10));
  r.push_back(with(with(with(final_image("lab5-default-custom-on-off", 5, "default"), isolated), custom_on), off));
  // ... compared with the same frame with the effect's toggle off: the two differ in
  // u_custom_enabled alone, so they are equal on any renderer when the effect is gated.
  r.push_back(with(with(final_image("lab5-default-custom-off-off", 5, "default"), isolated), off));
}

void add_lab6_renders(std::vector<RenderSpec>& r) {
  // Lab 6: the maps are precomputed once per environment (the render worker's Renderers
  // share them through an IblCache), so the maps are read from the highlight
  // scene's renderer under "sun", which its HDR render needs anyway.
  auto sun = [](RenderSpec& s) { s.environment = "sun"; };
  auto studio = [](RenderSpec& s) { s.environment = "studio"; };
  // The BRDF table, on its own: G, alpha = roughness^2 and the Fresnel split into A
  // and B change most of its texels, and a C without the diffuse Fresnel (1 - Fc)
  // shows only here (4 times the mean error's limit; half of it in the images, where
  // the diffuse part is dim beside the environment's reflection).
  r.push_back(with(gbuffer("lab6-brdf-lut", 6, "highlight", View::BrdfLut), sun));
  // The maps of "sun", the hard case (a 1.5-degree sun 3000 times brighter than the
  // sky): an irradiance sum without the solid angle or the cosine, or with uniform
  // weights, misplaces the sun's share; a prefilter without the n.l weight, without
  // alpha = roughness^2, or reading level 0 only (the sun hit by a few samples:
  // fireflies) changes the rough levels by far more than the tolerance.
  r.push_back(with(gbuffer("lab6-sun-irradiance", 6, "highlight", View::Irradiance), sun));
  r.push_back(with(gbuffer("lab6-sun-prefiltered", 6, "highlight", View::Prefiltered), sun));
  // The pass that combines them (ibl.frag): the sun's glossy reflection covers a
  // corner of the close-up, so r = reflect(-v, n) (not reflect(v, n), nor n) and the
  // table's (n.v, roughness) order show on thousands of pixels.
  r.push_back(with(hdr("lab6-highlight-sun-hdr", 6, "highlight"), sun));
  // Metal and dielectric spheres of every roughness under the soft studio: the
  // diffuse's (1 - metallic), (1 - F0) and 1/pi, and the irradiance looked up at n.
  r.push_back(with(hdr("lab6-default-studio-hdr", 6, "default"), studio));
  // BLEND layers (lit by the same ibl.frag in the forward pass), an emitter on black
  // and a double-sided back face: the IBL is added to what the lighting pass wrote.
  r.push_back(with(hdr("lab6-materials-studio-hdr", 6, "materials"), studio));
  // A white rough floor at grazing angles, where the diffuse part is as large as the
  // reflection and the table's diffuse Fresnel weight C is smallest (about 0.97): an
  // ibl.frag without C is 3 % too bright over the whole floor (elsewhere C is near 1).
  r.push_back(with(hdr("lab6-matte-sun-hdr", 6, "matte"), sun));
}

void add_lab7_renders(std::vector<RenderSpec>& r) {
  // Lab 7: 128 small ranged lights (the work the volumes save), the camera inside a
  // volume (front faces culled, not back), and a spot and a point light whose ranges end
  // in view (lab 3's range scene), and a point and a spot light without a range, whose volumes
  // reach the framework's cut-off. Each frame's HDR buffer is compared with the solution's,
  // and the same frame's counted work checked (Metric::Work; not the unranged lights': their
  // volumes cover most of the view, as they must).
  r.push_back(hdr("lab7-lights-hdr", 7, "lights"));
  r.push_back(final_image("lab7-lights-final", 7, "lights"));
  r.push_back(hdr("lab7-inside-hdr", 7, "inside"));
  r.push_back(hdr("lab7-range-hdr", 7, "range"));
  r.push_back(hdr("lab7-unranged-hdr", 7, "unranged"));
}

void add_describing_renders(std::vector<RenderSpec>& r) {
  // What a failed lit check's worst pixel is described from: every scene a lab 2-7 image
  // renders gets the G-buffer attachments the checks leave out, each from the stage that
  // writes what the lit stage reads (lab_verdict.h, gbuffer_reference_ids): stage 1's, and
  // from stage 4 on lab 4's normal-mapped normal.
  std::vector<RenderSpec> describing;
  const auto add = [&](const std::string& id, int stage, const std::string& scene, View view) {
    const auto same = [&](const RenderSpec& other) { return other.id == id; };
    if (std::none_of(r.begin(), r.end(), same) && std::none_of(describing.begin(), describing.end(), same))
      describing.push_back(with(gbuffer(id, stage, scene, view), [](RenderSpec& d) { d.describes_pixels_only = true; }));
  };
  for (const RenderSpec& spec : r) {
    if (spec.stage < 2 || (spec.view != View::Final && spec.view != View::Hdr)) continue;
    for (View view : {View::Position, View::Normal, View::Albedo, View::Material, View::Emission}) {
      const int stage = view == View::Normal && spec.stage >= 4 ? 4 : 1;
      add("lab" + std::to_string(stage) + "-" + spec.scene + "-" + view_name(view), stage, spec.scene, view);
    }
    // Each light's share of the frame, from the first of its renders (the settings that
    // change no light's share may differ between them).
    const std::string shares = light_shares_id(spec);
    const auto same = [&](const RenderSpec& other) { return other.id == shares; };
    if (!spec.isolate_custom && std::none_of(describing.begin(), describing.end(), same))
      describing.push_back(with(spec, [&](RenderSpec& d) {
        d.id = shares;
        d.view = View::Hdr;
        d.raw = true;
        d.describes_pixels_only = true;
        d.light_shares = true;
      }));
  }
  r.insert(r.end(), describing.begin(), describing.end());
}

}  // namespace

const std::vector<RenderSpec>& renders() {
  static const std::vector<RenderSpec> kRenders = [] {
    std::vector<RenderSpec> r;
    add_lab1_renders(r);
    add_lab2_renders(r);
    add_lab3_renders(r);
    add_lab4_renders(r);
    add_lab5_renders(r);
    add_lab6_renders(r);
    add_lab7_renders(r);
    add_describing_renders(r);
    return r;
  }();
  return kRenders;
}

const std::vector<Check>& checks() {
  static const std::vector<Check> kChecks = {
      // lab, key, title, metric, submission render, reference render
      {1, "default-position", "default scene, position", Metric::Position, "lab1-default-position", "lab1-default-position"},
      {1, "default-normal", "default scene, normal", Metric::Normal, "lab1-default-normal", "lab1-default-normal"},
      {1, "default-albedo", "default scene, albedo", Metric::Albedo, "lab1-default-albedo", "lab1-default-albedo"},
      {1, "default-material", "default scene, material", Metric::Material, "lab1-default-material", "lab1-default-material"},
      {1, "normalmap-position", "normalmap scene, position", Metric::Position, "lab1-normalmap-position", "lab1-normalmap-position"},
      {1, "normalmap-normal", "normalmap scene, normal", Metric::Normal, "lab1-normalmap-normal", "lab1-normalmap-normal"},
      {1, "normalmap-material", "normalmap scene, material", Metric::Material, "lab1-normalmap-material", "lab1-normalmap-material"},
      // Emitted radiance is compared like HDR radiance (it is one).
      {1, "default-emission", "default scene, emission", Metric::Hdr, "lab1-default-emission", "lab1-default-emission"},
      {1, "materials-normal", "materials scene, normal (double-sided back face)", Metric::Normal, "lab1-materials-normal", "lab1-materials-normal"},
      {1, "materials-albedo", "materials scene, albedo and alpha", Metric::Albedo, "lab1-materials-albedo", "lab1-materials-albedo"},
      {1, "materials-material", "materials scene, material (MASK coverage)", Metric::Material, "lab1-materials-material", "lab1-materials-material"},
      {1, "materials-emission", "materials scene, emission", Metric::Hdr, "lab1-materials-emission", "lab1-materials-emission"},
      {1, "texturing-albedo", "texturing scene, albedo (UV set 0, transformed)", Metric::Albedo, "lab1-texturing-albedo", "lab1-texturing-albedo"},
      {1, "texturing-material", "texturing scene, material (UV set 1, transformed; channels G and B)", Metric::Material, "lab1-texturing-material", "lab1-texturing-material"},
      {1, "texturing-emission", "texturing scene, emission (UV set 1, transformed)", Metric::Hdr, "lab1-texturing-emission", "lab1-texturing-emission"},

      {2, "default-final", "default scene, final image", Metric::Ldr, "lab2-default-final", "lab2-default-final"},
      {2, "default-hdr", "default scene, HDR", Metric::Hdr, "lab2-default-hdr", "lab2-default-hdr"},
      {2, "sphere-final", "sphere scene, final image", Metric::Ldr, "lab2-sphere-final", "lab2-sphere-final"},
      {2, "sphere-hdr", "sphere scene, HDR", Metric::Hdr, "lab2-sphere-hdr", "lab2-sphere-hdr"},
      {2, "highlight-hdr", "highlight close-up, HDR", Metric::Hdr, "lab2-highlight-hdr", "lab2-highlight-hdr"},
      {2, "materials-hdr", "materials scene (emitter on black, double-sided), HDR", Metric::Hdr, "lab2-materials-hdr", "lab2-materials-hdr"},
      {2, "sun-hdr", "sun scene (directional and point light), HDR", Metric::Hdr, "lab2-sun-hdr", "lab2-sun-hdr"},
      {2, "grazing-hdr", "grazing plane (small n.v and n.l everywhere), HDR", Metric::Hdr, "lab2-grazing-hdr", "lab2-grazing-hdr"},

      {3, "default-physical-hdr", "default scene, physical falloff, HDR", Metric::Hdr, "lab3-default-physical-hdr", "lab3-default-physical-hdr"},
      {3, "default-simple-hdr", "default scene, simple falloff, HDR", Metric::Hdr, "lab3-default-simple-hdr", "lab3-default-simple-hdr"},
      {3, "sphere-physical-hdr", "sphere scene, physical falloff, HDR", Metric::Hdr, "lab3-sphere-physical-hdr", "lab3-sphere-physical-hdr"},
      {3, "default-physical-gamma22", "default scene, physical falloff, gamma 2.2", Metric::Ldr, "lab3-default-physical-gamma22", "lab3-default-physical-gamma22"},
      {3, "default-physical-gamma10", "default scene, physical falloff, gamma 1.0", Metric::Ldr, "lab3-default-physical-gamma10", "lab3-default-physical-gamma10"},
      {3, "sphere-simple-gamma10", "sphere scene, simple falloff, gamma 1.0", Metric::Ldr, "lab3-sphere-simple-gamma10", "lab3-sphere-simple-gamma10"},
      {3, "spot-physical-hdr", "spot scene (wide penumbra), physical falloff, HDR", Metric::Hdr, "lab3-spot-physical-hdr", "lab3-spot-physical-hdr"},
      {3, "sun-physical-hdr", "sun scene (directional light), physical falloff, HDR", Metric::Hdr, "lab3-sun-physical-hdr", "lab3-sun-physical-hdr"},
      {3, "sun-simple-hdr", "sun scene (directional light), simple falloff, HDR", Metric::Hdr, "lab3-sun-simple-hdr", "lab3-sun-simple-hdr"},
      {3, "range-simple-hdr", "range scene (a spot 2-3 m from the floor), simple falloff, HDR", Metric::Hdr, "lab3-range-simple-hdr", "lab3-range-simple-hdr"},
      {3, "range-physical-hdr", "range scene (glTF range ends in view), physical falloff, HDR", Metric::Hdr, "lab3-range-physical-hdr", "lab3-range-physical-hdr"},

      {4, "normalmap-final", "normalmap scene, final image", Metric::Ldr, "lab4-normalmap-final", "lab4-normalmap-final"},
      {4, "default-final", "default scene, final image", Metric::Ldr, "lab4-default-final", "lab4-default-final"},
      {4, "normalmap-normal", "normalmap scene, mapped normal", Metric::Normal, "lab4-normalmap-normal", "lab4-normalmap-normal"},
      {4, "default-normal", "default scene, mapped normal", Metric::Normal, "lab4-default-normal", "lab4-default-normal"},
      {4, "texturing-final", "texturing scene (two UV sets, scaled normal map), final image", Metric::Ldr, "lab4-texturing-final", "lab4-texturing-final"},
      {4, "texturing-normal", "texturing scene, mapped normal (normal scale 0.4, tangent under non-uniform scale)", Metric::Normal, "lab4-texturing-normal", "lab4-texturing-normal"},
      {4, "closeup-final", "brick close-up (magnified normal map, grazing light), final image", Metric::Ldr, "lab4-closeup-final", "lab4-closeup-final"},
      {4, "closeup-normal", "brick close-up, mapped normal (no filter approximation)", Metric::Normal, "lab4-closeup-normal", "lab4-closeup-normal"},

      {7, "lights-hdr", "128 small lights, HDR", Metric::Hdr, "lab7-lights-hdr", "lab7-lights-hdr"},
      {7, "lights-final", "128 small lights, final image", Metric::Ldr, "lab7-lights-final", "lab7-lights-final"},
      {7, "inside-hdr", "camera inside a light's volume, HDR", Metric::Hdr, "lab7-inside-hdr", "lab7-inside-hdr"},
      {7, "range-hdr", "a spot and a point light with ranges, HDR", Metric::Hdr, "lab7-range-hdr", "lab7-range-hdr"},
      {7, "unranged-hdr", "a point and a spot light without a range, HDR", Metric::Hdr, "lab7-unranged-hdr",
       "lab7-unranged-hdr"},
      {7, "lights-work", "128 small lights, fragments shaded", Metric::Work, "lab7-lights-hdr", "lab7-lights-hdr"},
      {7, "inside-work", "camera inside a volume, fragments shaded", Metric::Work, "lab7-inside-hdr", "lab7-inside-hdr"},
      {7, "range-work", "spot and point light, fragments shaded", Metric::Work, "lab7-range-hdr", "lab7-range-hdr"},

      {5, "default-bloom", "default scene, bloom on", Metric::Ldr, "lab5-default-bloom", "lab5-default-bloom"},
      {5, "default-threshold05", "default scene, bloom threshold 0.5", Metric::Ldr, "lab5-default-threshold05", "lab5-default-threshold05"},
      {5, "sphere-bloom", "sphere scene, bloom on", Metric::Ldr, "lab5-sphere-bloom", "lab5-sphere-bloom"},
      // With the toggle off, stage 5 must show exactly what stage 4 shows.
      {5, "default-off", "default scene, postprocess off equals stage 4", Metric::Ldr, "lab5-default-off", "lab4-default-final"},
      // The free-choice effect: off is the identity (the solution's bloom image comes
      // through unchanged); on must change the image. What it does is not graded.
      {5, "custom-off", "custom effect off passes the image through", Metric::Ldr, "lab5-default-custom-off", "lab5-default-bloom"},
      {5, "custom-on", "custom effect on changes the image", Metric::Changes, "lab5-default-custom-on", "lab5-default-custom-off"},
      {5, "default-bloom-gamma10", "default scene, bloom on, gamma 1.0", Metric::Ldr, "lab5-default-bloom-gamma10", "lab5-default-bloom-gamma10"},
      // Postprocessing off gates the custom effect too: with its own toggle on, the image
      // must be the one with it off. Compared with the submission's own render, not with a
      // reference: the effect may move the image by less than a pixel (a ripple), which a
      // comparison across renderers has to allow at edges (compare.cpp, is_edge).
      {5, "custom-on-postprocess-off", "custom effect on, postprocess off, equals it off", Metric::Same, "lab5-default-custom-on-off", "lab5-default-custom-off-off"},

      // The maps are radiance (the table a fraction of it): compared like HDR.
      {6, "brdf-lut", "BRDF table (A, B, C)", Metric::Hdr, "lab6-brdf-lut", "lab6-brdf-lut"},
      {6, "sun-irradiance", "irradiance map of the sun environment", Metric::Hdr, "lab6-sun-irradiance", "lab6-sun-irradiance"},
      {6, "sun-prefiltered", "prefiltered map of the sun environment (6 levels)", Metric::Hdr, "lab6-sun-prefiltered", "lab6-sun-prefiltered"},
      {6, "highlight-sun-hdr", "highlight close-up under the sun environment, HDR", Metric::Hdr, "lab6-highlight-sun-hdr", "lab6-highlight-sun-hdr"},
      {6, "default-studio-hdr", "default scene under the studio environment, HDR", Metric::Hdr, "lab6-default-studio-hdr", "lab6-default-studio-hdr"},
      {6, "matte-sun-hdr", "rough floor at grazing angles under the sun environment (diffuse Fresnel weight), HDR", Metric::Hdr, "lab6-matte-sun-hdr", "lab6-matte-sun-hdr"},
      {6, "materials-studio-hdr", "materials scene (BLEND layers, emitter) under the studio environment, HDR", Metric::Hdr, "lab6-materials-studio-hdr", "lab6-materials-studio-hdr"},
  };
  return kChecks;
}

const RenderSpec& find_render(const std::string& id) {
  for (const RenderSpec& r : renders())
    if (r.id == id) return r;
  throw Error("kit-grade: no render named '" + id + "' (tools/grade/frames/checks.cpp)");
}

std::vector<const Check*> lab_checks(int lab) {
  std::vector<const Check*> out;
  for (const Check& c : checks())
    if (c.lab == lab) out.push_back(&c);
  return out;
}

std::vector<const RenderSpec*> lab_renders(int lab, bool describing) {
  std::vector<const RenderSpec*> out;
  for (const RenderSpec& r : renders())
    if (r.stage == lab && (describing || !r.describes_pixels_only)) out.push_back(&r);
  return out;
}

std::vector<const RenderSpec*> reference_renders() {
  std::vector<const RenderSpec*> out;
  for (const RenderSpec& r : renders()) {
    bool referenced = r.describes_pixels_only || std::any_of(checks().begin(), checks().end(), [&](const Check& c) {
      return !compares_own_renders(c.metric) && c.reference == r.id;
    });
    if (referenced) out.push_back(&r);
  }
  return out;
}

RenderSettings render_settings(const RenderSpec& spec) {
  RenderSettings s;
  s.width = kGradeWidth;
  s.height = kGradeHeight;
  s.gamma = spec.gamma;
  s.attenuation_model = spec.attenuation_model;
  s.postprocess = spec.postprocess;
  s.custom_effect = spec.custom_effect;
  s.bloom_threshold = spec.bloom_threshold;
  s.environment = spec.environment;
  s.ibl.prefilter_samples = kGradePrefilterSamples;
  s.ibl.brdf_lut_samples = kGradeBrdfLutSamples;
  s.count_light_volume_work = find_stage(spec.stage).light_volumes;  // lab 7's work checks
  // A lighting and a geometry program per lab rather than one per scene's lights and
  // materials (renderer.h).
  s.specialise_shaders = false;
  return s;
}

std::string light_shares_id(const RenderSpec& spec) {
  if (spec.stage < 2 || (spec.view != View::Final && spec.view != View::Hdr)) return "";
  // Stage 2 has no falloff model (shaders/attenuation.glsl).
  const std::string model = spec.stage < 3 ? "" : spec.attenuation_model == 1 ? "-simple" : "-physical";
  return "lab" + std::to_string(spec.stage) + "-" + spec.scene + model + "-lights";
}

std::string environment_name(const RenderSpec& spec) {
  return environment_or_default(spec.environment);
}

std::string reference_extension(const RenderSpec& spec) { return spec.raw ? "exr" : "png"; }

}  // namespace kit::grade

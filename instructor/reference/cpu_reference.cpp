#include "cpu_reference.h"

#include <glm/gtc/matrix_inverse.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "base/error.h"
#include "gbuffer_layout.h"

namespace kit::reference {

namespace {

// GLSL's min/max/clamp, component-wise. std::max(x, y) is (x < y) ? y : x and
// std::min(x, y) is (y < x) ? y : x, which is how the GLSL specification defines
// max and min, so a NaN passes through exactly where the shader's would.
double glsl_clamp(double x, double lo, double hi) { return std::min(std::max(x, lo), hi); }
dvec3 glsl_min(dvec3 x, double y) { return {std::min(x.x, y), std::min(x.y, y), std::min(x.z, y)}; }
dvec3 glsl_max(dvec3 x, double y) { return {std::max(x.x, y), std::max(x.y, y), std::max(x.z, y)}; }
dvec3 glsl_clamp(dvec3 x, double lo, double hi) { return glsl_min(glsl_max(x, lo), hi); }
double inversesqrt(double x) { return 1.0 / std::sqrt(x); }

void set_pixel(Image& image, int x, int y, dvec3 rgb) {
  for (int c = 0; c < 3; ++c) image.at(x, y, c) = static_cast<float>(rgb[c]);
  if (image.channels > 3) image.at(x, y, 3) = 1.0f;  // every full-screen pass writes alpha 1
}

// Applies `f(rgb)` to every pixel of `image` into a new RGBA image.
template <typename F>
Image map_pixels(const Image& image, F f) {
  Image out(image.width, image.height, 4);
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) set_pixel(out, x, y, f(pixel_rgb(image, x, y)));
  return out;
}

}  // namespace

dvec3 pixel_rgb(const Image& image, int x, int y) { return {image.at(x, y, 0), image.at(x, y, 1), image.at(x, y, 2)}; }

const std::vector<MirroredConstant>& mirrored_constants() {
  static const std::vector<MirroredConstant> kConstants = {
      {"KIT_MIN_N_DOT_V", "shaders/guards.glsl", {KIT_MIN_N_DOT_V}},
      {"KIT_MIN_N_DOT_L", "shaders/guards.glsl", {KIT_MIN_N_DOT_L}},
      {"KIT_MIN_V_DOT_H", "shaders/guards.glsl", {KIT_MIN_V_DOT_H}},
      {"KIT_MIN_ROUGHNESS", "shaders/guards.glsl", {KIT_MIN_ROUGHNESS}},
      {"KIT_MIN_DENOMINATOR", "shaders/guards.glsl", {KIT_MIN_DENOMINATOR}},
      {"KIT_MIN_GGX_DENOMINATOR", "shaders/guards.glsl", {KIT_MIN_GGX_DENOMINATOR}},
      {"KIT_MIN_DISTANCE_SQUARED", "shaders/guards.glsl", {KIT_MIN_DISTANCE_SQUARED}},
      {"KIT_MIN_CONE_COS_GAP", "shaders/guards.glsl", {KIT_MIN_CONE_COS_GAP}},
      {"KIT_MIN_SPOT_SOLID_ANGLE", "shaders/guards.glsl", {KIT_MIN_SPOT_SOLID_ANGLE}},
      {"KIT_HDR_MAX", "shaders/guards.glsl", {KIT_HDR_MAX}},
      {"KIT_MIN_TANGENT_LENGTH_SQUARED", "shaders/guards.glsl", {KIT_MIN_TANGENT_LENGTH_SQUARED}},
      {"KIT_PI", "shaders/math.glsl", {KIT_PI}},
      {"KIT_LUMINANCE", "shaders/math.glsl", {KIT_LUMINANCE[0], KIT_LUMINANCE[1], KIT_LUMINANCE[2]}},
      {"KIT_BLUR_WEIGHTS", "solutions/05-postprocess/blur.frag",
       {KIT_BLUR_WEIGHTS[0], KIT_BLUR_WEIGHTS[1], KIT_BLUR_WEIGHTS[2], KIT_BLUR_WEIGHTS[3], KIT_BLUR_WEIGHTS[4]}},
  };
  return kConstants;
}

namespace {

// Spacing of binary16 values around `magnitude` (> 0): 10 fraction bits, and
// subnormals share the step of the lowest binade, 2^-14.
double half_step(double magnitude) {
  constexpr int kFractionBits = 10;
  constexpr int kMinExponent = -14;
  return std::ldexp(1.0, std::max(std::ilogb(magnitude), kMinExponent) - kFractionBits);
}

// Past the largest finite half a stored value is infinite.
double half_overflow(double v) { return std::fabs(v) > KIT_HDR_MAX ? std::copysign(INFINITY, v) : v; }

}  // namespace

double round_to_half(double value) {
  if (!std::isfinite(value) || value == 0.0) return value;
  const double step = half_step(std::fabs(value));
  // nearbyint rounds in the default mode: to nearest, ties to even.
  return half_overflow(std::nearbyint(value / step) * step);
}

HalfNeighbours half_neighbours(double value) {
  if (!std::isfinite(value) || value == 0.0) return {value, value};
  const double step = half_step(std::fabs(value));
  // Steps are powers of two, so value / step and the products are exact.
  return {half_overflow(std::floor(value / step) * step), half_overflow(std::ceil(value / step) * step)};
}

Guards Guards::none() {
  constexpr double kNoFloor = -std::numeric_limits<double>::infinity();
  Guards g;
  g.min_n_dot_v = g.min_n_dot_l = g.min_v_dot_h = kNoFloor;
  g.min_roughness = g.min_denominator = g.min_ggx_denominator = g.min_distance_squared = kNoFloor;
  g.min_cone_cos_gap = g.min_spot_solid_angle = g.min_tangent_length_squared = kNoFloor;
  g.hdr_max = std::numeric_limits<double>::infinity();
  g.bright_pass_drops_non_finite = false;
  return g;
}

ShadingSettings shading_settings(const RenderSettings& settings, int stage) {
  if (stage < 2) throw Error("the CPU reference shades lit stages only (stage 2 on), not stage " + std::to_string(stage));
  ShadingSettings s;
  s.stage = stage;
  s.gamma = settings.gamma;
  s.attenuation_model = settings.attenuation_model;
  s.clear_color = dvec3(settings.clear_color);
  s.postprocess = settings.postprocess;
  s.bloom_threshold = settings.bloom_threshold;
  s.blur_passes = settings.blur_passes;
  return s;
}

double exact_light_flux(const Light& light) {
  if (light.type == KIT_LIGHT_DIRECTIONAL) return 0.0;
  const double intensity = light.intensity;
  if (light.type == KIT_LIGHT_SPOT) {
    const double cos_inner = std::cos(static_cast<double>(light.inner_cone));
    const double cos_outer = std::cos(static_cast<double>(light.outer_cone));
    return 2.0 * KIT_PI * (1.0 - 0.5 * (cos_inner + cos_outer)) * intensity;
  }
  return 4.0 * KIT_PI * intensity;
}

namespace {

// The fields both light conversions share; cosines and flux are filled by the caller.
ShadingLight light_fields(const Light& light) {
  ShadingLight s;
  s.type = light.type;
  s.position = dvec3(light.position);
  s.direction = dvec3(light.direction);
  s.color = dvec3(light.color);
  s.intensity = light.intensity;
  s.range = light.range;
  return s;
}

}  // namespace

ShadingLight exact_light(const Light& light) {
  ShadingLight s = light_fields(light);
  s.cos_inner = std::cos(static_cast<double>(light.inner_cone));
  s.cos_outer = std::cos(static_cast<double>(light.outer_cone));
  s.flux = exact_light_flux(light);
  return s;
}

ShadingLight uploaded_light(const Light& light) {
  ShadingLight s = light_fields(light);
  // light_texture evaluates these in float; kit::light_flux is that float formula.
  s.cos_inner = static_cast<double>(std::cos(light.inner_cone));
  s.cos_outer = static_cast<double>(std::cos(light.outer_cone));
  s.flux = static_cast<double>(kit::light_flux(light));
  return s;
}

std::vector<ShadingLight> uploaded_lights(const std::vector<Light>& lights) {
  std::vector<ShadingLight> out;
  out.reserve(lights.size());
  for (const Light& l : lights) out.push_back(uploaded_light(l));
  return out;
}

std::vector<Light> frame_lights(const Scene& scene, const RenderSettings& settings) {
  std::vector<Light> lights = scene.lights;
  std::vector<Light> extra = spawned_lights(scene, settings.extra_lights);
  lights.insert(lights.end(), extra.begin(), extra.end());
  return lights;
}

// --- Lab 2 ----------------------------------------------------------------------------

dvec3 fresnel_schlick(double v_dot_h, dvec3 f0) {
  return f0 + (1.0 - f0) * std::pow(glsl_clamp(1.0 - v_dot_h, 0.0, 1.0), 5.0);
}

double distribution_ggx(double n_dot_h, double alpha, const Guards& guards) {
  const double alpha2 = alpha * alpha;
  const double d = n_dot_h * n_dot_h * (alpha2 - 1.0) + 1.0;
  return alpha2 / std::max(KIT_PI * d * d, guards.min_ggx_denominator);
}

namespace {

// The microfacet geometric function, Cook-Torrance's: G = min(1, 2(n.h)(n.v)/(v.h), 2(n.h)(n.l)/(v.h)).
// The roughness is in the signature for other G's (brdf.glsl's microfacet_geometry).
double microfacet_geometry(double n_dot_h, double n_dot_v, double n_dot_l, double v_dot_h,
                           [[maybe_unused]] double roughness) {
  return std::min(1.0, std::min(2.0 * n_dot_h * n_dot_v / v_dot_h, 2.0 * n_dot_h * n_dot_l / v_dot_h));
}

}  // namespace

dvec3 cook_torrance(dvec3 n, dvec3 v, dvec3 l, dvec3 albedo, double metallic, double perceptual_roughness,
                    const Guards& guards) {
  const dvec3 half_sum = v + l;
  const dvec3 h = half_sum * inversesqrt(std::max(glm::dot(half_sum, half_sum), guards.min_denominator));
  const double n_dot_v = std::max(glm::dot(n, v), guards.min_n_dot_v);
  const double n_dot_l = std::max(glm::dot(n, l), guards.min_n_dot_l);
  const double n_dot_h = glsl_clamp(glm::dot(n, h), 0.0, 1.0);
  const double v_dot_h = std::max(glm::dot(v, h), guards.min_v_dot_h);
  const double roughness = std::max(perceptual_roughness, guards.min_roughness);
  const double alpha = roughness * roughness;

  const dvec3 f0 = glm::mix(dvec3(0.04), albedo, metallic);
  const dvec3 F = fresnel_schlick(v_dot_h, f0);
  const double D = distribution_ggx(n_dot_h, alpha, guards);
  const double G = microfacet_geometry(n_dot_h, n_dot_v, n_dot_l, v_dot_h, roughness);

  const dvec3 diffuse = (1.0 - F) * (1.0 - metallic) * albedo / KIT_PI;
  const dvec3 specular = F * D * G / std::max(4.0 * n_dot_l * n_dot_v, guards.min_denominator);
  return diffuse + specular;
}

// --- Lab 3 ----------------------------------------------------------------------------

double spot_cone_factor(const ShadingLight& light, dvec3 p, const Guards& guards) {
  dvec3 from_light = p - light.position;
  from_light *= inversesqrt(std::max(glm::dot(from_light, from_light), guards.min_distance_squared));
  const double cos_angle = glm::dot(from_light, light.direction);
  const double t = glsl_clamp(
      (cos_angle - light.cos_outer) / std::max(light.cos_inner - light.cos_outer, guards.min_cone_cos_gap), 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

// lights.glsl kit_range_window: glTF's recommended clamp(1 - (d / range)^4, 0, 1); 1 without a range.
double range_window(const ShadingLight& light, dvec3 p) {
  if (light.type == KIT_LIGHT_DIRECTIONAL || light.range <= 0.0) return 1.0;
  const dvec3 to_light = light.position - p;
  const double q = glm::dot(to_light, to_light) / (light.range * light.range);
  return glsl_clamp(1.0 - q * q, 0.0, 1.0);
}

dvec3 light_radiance(const ShadingLight& light, dvec3 p, const ShadingSettings& settings) {
  const Guards& g = settings.guards;
  // The illuminance on a surface facing it, at every stage and under both models.
  if (light.type == KIT_LIGHT_DIRECTIONAL) return light.color * light.intensity;
  if (settings.stage <= 2) {
    // shaders/attenuation.glsl: no falloff; a spot lights only inside its outer cone.
    const dvec3 radiance = light.color * light.intensity;
    if (light.type == KIT_LIGHT_SPOT) {
      const dvec3 to_point = glm::normalize(p - light.position);
      if (glm::dot(to_point, light.direction) < light.cos_outer) return dvec3(0.0);
    }
    return radiance;
  }
  const dvec3 to_light = light.position - p;
  const double r2 = std::max(glm::dot(to_light, to_light), g.min_distance_squared);
  double intensity;
  if (settings.attenuation_model == 1) {
    intensity = light.intensity / (1.0 + r2);
  } else if (light.type == KIT_LIGHT_SPOT) {
    const double solid = std::max(1.0 - 0.5 * (light.cos_inner + light.cos_outer), g.min_spot_solid_angle);
    intensity = light.flux / (2.0 * KIT_PI * r2 * solid);
  } else {
    intensity = light.flux / (4.0 * KIT_PI * r2);
  }
  if (light.type == KIT_LIGHT_SPOT) intensity *= spot_cone_factor(light, p, g);
  return light.color * intensity * range_window(light, p);
}

// --- Lighting pass ------------------------------------------------------------------------

dvec3 shade(const SurfaceSample& surface, const dvec3& camera_position, const std::vector<ShadingLight>& lights,
            const ShadingSettings& settings) {
  if (settings.stage < 2) throw Error("the CPU reference shades lit stages only (stage 2 on)");
  if (!surface.covered) return settings.clear_color;
  const Guards& g = settings.guards;
  const dvec3 p = surface.position;
  const dvec3 n = glm::normalize(surface.normal);
  const dvec3 v = glm::normalize(camera_position - p);

  dvec3 radiance = surface.emission;
  for (const ShadingLight& light : lights) {
    dvec3 l;
    if (light.type == KIT_LIGHT_DIRECTIONAL) {
      l = -light.direction;
    } else {
      const dvec3 to_light = light.position - p;
      // Shorter than unit within KIT_MIN_DISTANCE_SQUARED of the light, and 0 on it, as in the shader.
      l = to_light * inversesqrt(std::max(glm::dot(to_light, to_light), g.min_distance_squared));
    }
    const double n_dot_l = glm::dot(n, l);
    if (n_dot_l <= 0.0) continue;
    radiance += cook_torrance(n, v, l, surface.albedo, surface.metallic, surface.roughness, g) *
                light_radiance(light, p, settings) * n_dot_l;
  }
  return glsl_min(radiance, g.hdr_max);
}

dvec3 shade(const SurfaceSample& surface, const dvec3& camera_position, const std::vector<Light>& lights,
            const ShadingSettings& settings) {
  return shade(surface, camera_position, uploaded_lights(lights), settings);
}

dvec3 light_volume_term(const SurfaceSample& surface, const dvec3& camera_position, const ShadingLight& light,
                        double volume_radius, const ShadingSettings& settings) {
  if (!surface.covered) return dvec3(0.0);
  const dvec3 to_light = light.position - surface.position;
  if (glm::dot(to_light, to_light) > volume_radius * volume_radius) return dvec3(0.0);
  SurfaceSample lit = surface;
  lit.emission = dvec3(0.0);
  return shade(lit, camera_position, std::vector<ShadingLight>{light}, settings);
}

// --- Display ------------------------------------------------------------------------------

dvec3 tonemap(dvec3 hdr, double gamma) {
  const dvec3 c = glsl_max(hdr, 0.0);
  const dvec3 mapped = c / (c + 1.0);
  const double exponent = 1.0 / gamma;
  return {std::pow(mapped.x, exponent), std::pow(mapped.y, exponent), std::pow(mapped.z, exponent)};
}

dvec3 display(dvec3 hdr, const ShadingSettings& settings) {
  return settings.stage <= 2 ? glsl_clamp(hdr, 0.0, 1.0) : tonemap(hdr, settings.gamma);
}

// --- Whole frames -----------------------------------------------------------------------------

GBufferImages read_gbuffer(Renderer& renderer) {
  return {renderer.read_view(View::Position, true), renderer.read_view(View::Normal, true),
          renderer.read_view(View::Albedo, true), renderer.read_view(View::Material, true),
          renderer.read_view(View::Emission, true)};
}

SurfaceSample gbuffer_sample(const GBufferImages& gbuffer, int x, int y) {
  SurfaceSample s;
  s.position = pixel_rgb(gbuffer.position, x, y);
  s.normal = pixel_rgb(gbuffer.normal, x, y);
  s.albedo = pixel_rgb(gbuffer.albedo, x, y);
  s.metallic = gbuffer.material.at(x, y, 0);
  s.roughness = gbuffer.material.at(x, y, 1);
  s.emission = pixel_rgb(gbuffer.emission, x, y);
  // lighting.frag shades the clear colour where `material.a < 0.5`.
  s.covered = !(gbuffer.material.at(x, y, 3) < 0.5f);
  return s;
}

std::vector<std::pair<int, int>> covered_pixels(const GBufferImages& gbuffer) {
  std::vector<std::pair<int, int>> out;
  for (int y = 0; y < gbuffer.material.height; ++y)
    for (int x = 0; x < gbuffer.material.width; ++x)
      if (gbuffer_sample(gbuffer, x, y).covered) out.emplace_back(x, y);
  return out;
}

Image shade_gbuffer(const GBufferImages& gbuffer, const dvec3& camera_position, const std::vector<ShadingLight>& lights,
                    const ShadingSettings& settings) {
  const Image& any = gbuffer.position;
  Image out(any.width, any.height, 4);
  for (int y = 0; y < any.height; ++y)
    for (int x = 0; x < any.width; ++x)
      set_pixel(out, x, y, shade(gbuffer_sample(gbuffer, x, y), camera_position, lights, settings));
  return out;
}

Image final_image(const Image& hdr, const ShadingSettings& settings) {
  if (settings.stage >= 5) return composite(hdr, bloom(hdr, settings), settings);
  return map_pixels(hdr, [&](dvec3 c) { return display(c, settings); });
}

// --- Lab 4 ------------------------------------------------------------------------------------

dmat3 normal_matrix(const dmat4& model) { return glm::inverseTranspose(dmat3(model)); }

TangentFrame world_tangent_frame(const dmat4& model, dvec3 normal, dvec4 tangent) {
  TangentFrame f;
  f.normal = glm::normalize(normal_matrix(model) * normal);
  f.tangent = glm::normalize(dmat3(model) * dvec3(tangent));
  f.bitangent = glm::cross(f.normal, f.tangent) * tangent.w;
  return f;
}

dvec3 any_perpendicular(dvec3 n) {
  const dvec3 axis = std::fabs(n.x) < 0.9 ? dvec3(1.0, 0.0, 0.0) : dvec3(0.0, 1.0, 0.0);
  return glm::normalize(glm::cross(axis, n));
}

dvec3 mapped_normal(const TangentFrame& frame, dvec3 texel, double normal_scale, const Guards& guards) {
  const double min_len2 = guards.min_tangent_length_squared;
  const dvec3 n = glm::normalize(frame.normal);  // gbuffer.frag normalises v_world_normal first
  dvec3 t = frame.tangent - n * glm::dot(n, frame.tangent);
  const double t_len2 = glm::dot(t, t);
  t = t_len2 > min_len2 ? t * inversesqrt(t_len2) : any_perpendicular(n);
  dvec3 b = frame.bitangent - n * glm::dot(n, frame.bitangent) - t * glm::dot(t, frame.bitangent);
  const double b_len2 = glm::dot(b, b);
  b = b_len2 > min_len2 ? b * inversesqrt(b_len2) : glm::cross(n, t);
  const dvec3 tangent_normal = (2.0 * texel - 1.0) * dvec3(normal_scale, normal_scale, 1.0);
  const dvec3 world = t * tangent_normal.x + b * tangent_normal.y + n * tangent_normal.z;
  const double len2 = glm::dot(world, world);
  return len2 > min_len2 ? world * inversesqrt(len2) : n;
}

// --- Lab 5 ------------------------------------------------------------------------------------

dvec3 bright_pass(dvec3 hdr, double threshold, const Guards& guards) {
  dvec3 c = hdr;
  // A non-finite pixel would be smeared over the blur footprint: it adds no bloom.
  if (guards.bright_pass_drops_non_finite && (!std::isfinite(c.x) || !std::isfinite(c.y) || !std::isfinite(c.z)))
    c = dvec3(0.0);
  c = glsl_min(c, guards.hdr_max);
  const double luminance = c.x * KIT_LUMINANCE[0] + c.y * KIT_LUMINANCE[1] + c.z * KIT_LUMINANCE[2];
  return luminance > threshold ? c : dvec3(0.0);
}

Image blur_pass(const Image& image, bool horizontal) {
  Image out(image.width, image.height, 4);
  const int dx = horizontal ? 1 : 0, dy = horizontal ? 0 : 1;
  // Clamp-to-edge addressing: the bloom targets use GL_CLAMP_TO_EDGE.
  auto tap = [&](int x, int y) {
    return pixel_rgb(image, std::clamp(x, 0, image.width - 1), std::clamp(y, 0, image.height - 1));
  };
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      dvec3 sum = tap(x, y) * KIT_BLUR_WEIGHTS[0];
      for (int i = 1; i < 5; ++i) {
        sum += tap(x + dx * i, y + dy * i) * KIT_BLUR_WEIGHTS[i];
        sum += tap(x - dx * i, y - dy * i) * KIT_BLUR_WEIGHTS[i];
      }
      set_pixel(out, x, y, sum);
    }
  }
  return out;
}

Image bloom(const Image& hdr, const ShadingSettings& settings) {
  Image b = map_pixels(hdr, [&](dvec3 c) { return bright_pass(c, settings.bloom_threshold, settings.guards); });
  for (int pass = 0; pass < settings.blur_passes; ++pass) b = blur_pass(b, pass % 2 == 0);
  return b;
}

Image composite(const Image& hdr, const Image& bloom_image, const ShadingSettings& settings) {
  Image out(hdr.width, hdr.height, 4);
  for (int y = 0; y < hdr.height; ++y) {
    for (int x = 0; x < hdr.width; ++x) {
      dvec3 c = pixel_rgb(hdr, x, y);
      if (settings.postprocess) c += pixel_rgb(bloom_image, x, y);
      set_pixel(out, x, y, tonemap(c, settings.gamma));
    }
  }
  return out;
}

// --- Analytic geometry -------------------------------------------------------------------------

Ray camera_ray(const FrameCamera& camera, int width, int height, double x, double y) {
  const dmat4 inverse_view_projection = glm::inverse(dmat4(camera.projection) * dmat4(camera.view));
  // Image rows run top-down; NDC y runs bottom-up.
  const dvec4 ndc_far(2.0 * x / width - 1.0, 1.0 - 2.0 * y / height, 1.0, 1.0);
  const dvec4 far_point = inverse_view_projection * ndc_far;
  Ray ray;
  ray.origin = dvec3(camera.position);
  ray.direction = glm::normalize(dvec3(far_point) / far_point.w - ray.origin);
  return ray;
}

std::optional<Hit> intersect_sphere(const Ray& ray, dvec3 center, double radius) {
  const dvec3 oc = ray.origin - center;
  const double b = glm::dot(oc, ray.direction);
  const double c = glm::dot(oc, oc) - radius * radius;
  const double discriminant = b * b - c;
  if (discriminant < 0.0) return std::nullopt;
  // Only the entry point faces the ray; from inside the sphere its far side is a back face.
  const double t = -b - std::sqrt(discriminant);
  if (!(t > 0.0)) return std::nullopt;
  Hit hit;
  hit.t = t;
  hit.position = ray.origin + t * ray.direction;
  hit.normal = (hit.position - center) / radius;
  return hit;
}

std::optional<Hit> intersect_plane(const Ray& ray, dvec3 point, dvec3 normal) {
  const dvec3 n = glm::normalize(normal);
  const double facing = glm::dot(ray.direction, n);
  if (!(facing < 0.0)) return std::nullopt;  // parallel, or seen from behind (culled)
  const double t = glm::dot(point - ray.origin, n) / facing;
  if (!(t > 0.0)) return std::nullopt;
  Hit hit;
  hit.t = t;
  hit.position = ray.origin + t * ray.direction;
  hit.normal = n;
  return hit;
}

SurfaceSample surface_sample(const Hit& hit, const Material& material, dvec4 vertex_color) {
  SurfaceSample s;
  s.position = hit.position;
  s.normal = hit.normal;
  s.albedo = dvec3(base_color(material, dvec4(1.0), vertex_color));
  s.metallic = material.metallic_factor;
  s.roughness = material.roughness_factor;
  s.emission = dvec3(material.emissive);
  s.covered = true;
  return s;
}

dvec4 vertex_color(const Vertex& vertex) { return dvec4(vertex.color) / double{Vertex::kVertexColorOne}; }

dvec4 base_color(const Material& material, dvec4 linear_texel, dvec4 vertex_color) {
  return dvec4(material.base_color_factor) * linear_texel * vertex_color;
}

dvec3 ProbeArguments::vec3() {
  const dvec3 v(in_.at(at_), in_.at(at_ + 1), in_.at(at_ + 2));
  at_ += 3;
  return v;
}

ShadingLight ProbeArguments::light() {
  ShadingLight l;
  l.type = static_cast<int>(scalar() + 0.5);
  l.position = vec3();
  l.direction = vec3();
  l.range = scalar();
  l.color = vec3();
  l.intensity = scalar();
  l.cos_inner = scalar();
  l.cos_outer = scalar();
  l.flux = scalar();
  scalar();  // volume_radius
  return l;
}

const std::map<std::string, ProbeFunction>& probe_functions() {
  using A = ProbeArguments&;
  using S = const ShadingSettings&;
  static const std::map<std::string, ProbeFunction> functions = {
      // Lab 2 (solutions/02-lighting/brdf.glsl).
      {"fresnel_schlick", [](A a, S) { const double v_dot_h = a.scalar(); return fresnel_schlick(v_dot_h, a.vec3()); }},
      {"distribution_ggx", [](A a, S) { const double n_dot_h = a.scalar(); return dvec3(distribution_ggx(n_dot_h, a.scalar())); }},
      {"microfacet_geometry",
       [](A a, S) {
         const double n_dot_h = a.scalar(), n_dot_v = a.scalar(), n_dot_l = a.scalar(), v_dot_h = a.scalar();
         return dvec3(microfacet_geometry(n_dot_h, n_dot_v, n_dot_l, v_dot_h, a.scalar()));
       }},
      {"cook_torrance",
       [](A a, S) {
         const dvec3 n = a.vec3(), v = a.vec3(), l = a.vec3(), albedo = a.vec3();
         const double metallic = a.scalar();
         return cook_torrance(n, v, l, albedo, metallic, a.scalar());
       }},
      // Lab 3 (solutions/03-attenuation/attenuation.glsl and tonemap.glsl).
      {"spot_cone_factor", [](A a, S) { const ShadingLight light = a.light(); return dvec3(spot_cone_factor(light, a.vec3())); }},
      {"light_radiance", [](A a, S s) { const ShadingLight light = a.light(); return light_radiance(light, a.vec3(), s); }},
      {"tonemap", [](A a, S s) { return tonemap(a.vec3(), s.gamma); }},
  };
  return functions;
}

}  // namespace kit::reference

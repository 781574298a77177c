#include "tiny_scenes.h"

#include <cmath>

#include "gbuffer_layout.h"

namespace kit::test {

Primitive quad_primitive(glm::vec3 right, glm::vec3 up, glm::vec2 size, bool mirror_u) {
  Primitive p;
  p.name = "quad";
  const glm::vec3 normal = glm::normalize(glm::cross(right, up));
  const glm::vec2 corners[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};  // BL, BR, TR, TL
  for (const glm::vec2& c : corners) {
    Vertex v;
    v.position = right * ((c.x - 0.5f) * size.x) + up * ((c.y - 0.5f) * size.y);
    v.normal = normal;
    // glTF: v = 0 at the image's top row.
    v.texcoord = glm::vec2(mirror_u ? 1.0f - c.x : c.x, 1.0f - c.y);
    p.vertices.push_back(v);
  }
  p.indices = {0, 1, 2, 0, 2, 3};
  generate_tangents(p.vertices, p.indices);
  p.tangents_generated = true;
  p.bounds_min = glm::min(glm::min(p.vertices[0].position, p.vertices[1].position),
                          glm::min(p.vertices[2].position, p.vertices[3].position));
  p.bounds_max = glm::max(glm::max(p.vertices[0].position, p.vertices[1].position),
                          glm::max(p.vertices[2].position, p.vertices[3].position));
  return p;
}

Scene tiny_scene(std::vector<Primitive> primitives, std::vector<Material> materials, std::vector<DrawItem> draws,
                 std::vector<Light> lights) {
  Scene s;
  s.path = "(built in the test)";
  s.primitives = std::move(primitives);
  s.materials = std::move(materials);
  s.draws = std::move(draws);
  s.lights = std::move(lights);
  bool first = true;
  for (const DrawItem& d : s.draws) {
    const Primitive& p = s.primitives[static_cast<size_t>(d.primitive)];
    for (const Vertex& v : p.vertices) {
      const glm::vec3 w = glm::vec3(d.world * glm::vec4(v.position, 1.0f));
      s.bounds_min = first ? w : glm::min(s.bounds_min, w);
      s.bounds_max = first ? w : glm::max(s.bounds_max, w);
      first = false;
    }
  }
  return s;
}

Scene floor_scene(const Material& material, std::vector<Light> lights) {
  Primitive floor = quad_primitive({1, 0, 0}, {0, 0, -1}, {20, 20});
  floor.material = 0;
  return tiny_scene({floor}, {material}, {{0, glm::mat4(1.0f)}}, std::move(lights));
}

Material plain_material(float roughness) {
  Material m;
  m.name = "plain";
  m.base_color_factor = glm::vec4(0.8f, 0.8f, 0.8f, 1.0f);
  m.metallic_factor = 0.0f;
  m.roughness_factor = roughness;
  return m;
}

Light point_light(glm::vec3 position, float candela) {
  Light l;
  l.type = KIT_LIGHT_POINT;
  l.position = position;
  l.intensity = candela;
  return l;
}

glm::dvec2 texture_transformed(glm::dvec2 uv, glm::dvec2 offset, double rotation, glm::dvec2 scale) {
  const glm::dvec2 s = uv * scale;
  return {std::cos(rotation) * s.x + std::sin(rotation) * s.y + offset.x,
          -std::sin(rotation) * s.x + std::cos(rotation) * s.y + offset.y};
}

}  // namespace kit::test

#pragma once
// Scenes built in code, without glTF files, for tests that need one surface, one
// light and a camera placed exactly (the smallest scene that shows a failure).
#include <glm/glm.hpp>

#include <vector>

#include "scene/scene.h"

namespace kit::test {

// A rectangle centred on the origin, like kit-scenes' quads: `right` and `up` span
// it, its front face looks along cross(right, up), the image's top edge lies along
// +up and its left edge along -right (along +right when `mirror_u`). Tangents come
// from kit::generate_tangents (as the loader makes them for a file without TANGENT).
Primitive quad_primitive(glm::vec3 right, glm::vec3 up, glm::vec2 size, bool mirror_u = false);

// A scene of `draws` over `primitives` (each names its material by index), the
// given lights, no camera, and bounds over every draw.
Scene tiny_scene(std::vector<Primitive> primitives, std::vector<Material> materials, std::vector<DrawItem> draws,
                 std::vector<Light> lights);

// A 20 m x 20 m floor at y = 0 facing +Y in `material`, lit by `lights`.
Scene floor_scene(const Material& material, std::vector<Light> lights);

// A white dielectric material with the given roughness.
Material plain_material(float roughness);

// A point light of `candela` at `position`.
Light point_light(glm::vec3 position, float candela);

// KHR_texture_transform applied to `uv` (scale, then rotation, then offset), written
// out in double in the Khronos sample models' direction for glTF's v-down UVs:
// u' = ox + cos(r) sx u + sin(r) sy v, v' = oy - sin(r) sx u + cos(r) sy v (the
// extension README's GLSL listing turns the other way: glTF issue #1563). It restates
// the convention rather than checking it; test_texture_transform checks the
// direction against a texel table worked out by hand.
glm::dvec2 texture_transformed(glm::dvec2 uv, glm::dvec2 offset, double rotation, glm::dvec2 scale);

}  // namespace kit::test

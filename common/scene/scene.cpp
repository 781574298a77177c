#include "scene/scene.h"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <exception>
#include <new>

#include "base/error.h"
#include "base/freed_memory.h"
#include "scene/gltf_loader.h"
#include "scene/obj_scene.h"

namespace kit {

glm::mat4 Camera::projection(float window_aspect) const {
  if (orthographic) return glm::ortho(-xmag, xmag, -ymag, ymag, znear, zfar);
  return glm::perspective(yfov, aspect_ratio > 0.0f ? aspect_ratio : window_aspect, znear, zfar);
}

Scene load_scene(const std::string& path) {
  // Whatever the file makes the loader do, the message names the file: a
  // bad_alloc or length_error from a size the file asked for becomes a kit::Error.
  try {
    if (is_obj_path(path)) return load_obj_scene(path);
    return gltf::load_scene_unguarded(path);
  } catch (const Error&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw Error(path + ": the scene asks for more memory than there is (a size in the file is too large)");
  } catch (const std::exception& e) {
    throw Error(path + ": the scene could not be loaded: " + e.what());
  }
}

glm::mat3 texture_transform_matrix(glm::vec2 offset, float rotation, glm::vec2 scale) {
  // Column-major: translation * rotation * scale. The rotation's columns are
  // (cos, -sin) and (sin, cos): in glTF's v-down UV space this is the direction
  // the Khronos sample models (TextureTransformTest, TextureTransformMultiTest)
  // check and the sample viewer, three.js and Babylon draw. The README's GLSL
  // listing has the transpose, (cos, sin) and (-sin, cos), which turns the UVs the
  // opposite way (glTF issue #1563); tests/test_texture_transform.cpp shows which.
  const float c = std::cos(rotation), s = std::sin(rotation);
  const glm::mat3 translation(1, 0, 0, 0, 1, 0, offset.x, offset.y, 1);
  const glm::mat3 rotation_matrix(c, -s, 0, s, c, 0, 0, 0, 1);
  const glm::mat3 scale_matrix(scale.x, 0, 0, 0, scale.y, 0, 0, 0, 1);
  return translation * rotation_matrix * scale_matrix;
}

glm::vec2 TextureUv::of(const Vertex& v) const {
  return glm::vec2(transform * glm::vec3(slot == 1 ? v.texcoord1 : v.texcoord, 1.0f));
}

void generate_tangents(std::vector<Vertex>& vertices, const std::vector<uint32_t>& indices, const TextureUv& normal_uv) {
  std::vector<glm::vec3> tan(vertices.size(), glm::vec3(0.0f)), bitan(vertices.size(), glm::vec3(0.0f));
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    const Vertex& a = vertices[indices[t]];
    const Vertex& b = vertices[indices[t + 1]];
    const Vertex& c = vertices[indices[t + 2]];
    glm::vec3 e1 = b.position - a.position, e2 = c.position - a.position;
    const glm::vec2 uv_a = normal_uv.of(a);
    glm::vec2 d1 = normal_uv.of(b) - uv_a, d2 = normal_uv.of(c) - uv_a;
    float det = d1.x * d2.y - d2.x * d1.y;
    // A triangle with (near) zero UV area has no defined tangent: it adds nothing.
    if (std::fabs(det) < 1e-12f) continue;
    float r = 1.0f / det;
    glm::vec3 sdir = (e1 * d2.y - e2 * d1.y) * r;  // direction of increasing u
    glm::vec3 tdir = (e2 * d1.x - e1 * d2.x) * r;  // direction of increasing v
    for (int k = 0; k < 3; ++k) {
      tan[indices[t + k]] += sdir;
      bitan[indices[t + k]] += tdir;
    }
  }
  for (size_t i = 0; i < vertices.size(); ++i) {
    glm::vec3 n = glm::length(vertices[i].normal) > 0.0f ? glm::normalize(vertices[i].normal) : glm::vec3(0, 0, 1);
    glm::vec3 t = tan[i] - n * glm::dot(n, tan[i]);  // Gram-Schmidt
    if (!(glm::length(t) > 1e-8f)) {
      // No usable UV derivative: any unit vector perpendicular to n keeps the frame finite.
      glm::vec3 axis = std::fabs(n.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
      t = glm::cross(axis, n);
    }
    t = glm::normalize(t);
    // glTF's v grows down the image while a normal map's +Y points up it, so
    // B = cross(N, T) * w must point along decreasing v: w = +1 when the
    // accumulated d(position)/dv points the other way.
    float w = glm::dot(glm::cross(n, t), bitan[i]) > 0.0f ? -1.0f : 1.0f;
    vertices[i].tangent = glm::vec4(t, w);
  }
}

uint16_t vertex_color_component(float value) {
  return static_cast<uint16_t>(std::lround(std::clamp(value, 0.0f, 1.0f) * float{Vertex::kVertexColorOne}));
}

// glTF: "When normals are not specified, client implementations MUST calculate
// flat normals": every triangle gets its own three vertices, with the normal of
// its plane (a degenerate triangle gets +z, which keeps the frame finite).
void use_flat_normals(Primitive& prim) {
  std::vector<Vertex> vertices;
  vertices.reserve(prim.indices.size());
  for (size_t t = 0; t + 2 < prim.indices.size(); t += 3) {
    Vertex a = prim.vertices[prim.indices[t]], b = prim.vertices[prim.indices[t + 1]], c = prim.vertices[prim.indices[t + 2]];
    glm::vec3 normal = glm::cross(b.position - a.position, c.position - a.position);
    float length = glm::length(normal);
    normal = length > 0.0f && std::isfinite(length) ? normal / length : glm::vec3(0.0f, 0.0f, 1.0f);
    for (Vertex* v : {&a, &b, &c}) {
      v->normal = normal;
      vertices.push_back(*v);
    }
  }
  prim.vertices = std::move(vertices);
  prim.indices.resize(prim.vertices.size());
  for (size_t i = 0; i < prim.indices.size(); ++i) prim.indices[i] = static_cast<uint32_t>(i);
}

void set_bounds_from_vertices(Primitive& primitive) {
  for (size_t i = 0; i < primitive.vertices.size(); ++i) {
    const glm::vec3& p = primitive.vertices[i].position;
    primitive.bounds_min = i == 0 ? p : glm::min(primitive.bounds_min, p);
    primitive.bounds_max = i == 0 ? p : glm::max(primitive.bounds_max, p);
  }
}

void release_uploaded_data(Scene& scene) {
  for (Primitive& p : scene.primitives) {
    std::vector<Vertex>().swap(p.vertices);
    std::vector<uint32_t>().swap(p.indices);
  }
  for (SceneImage& image : scene.images) {
    std::vector<unsigned char>().swap(image.encoded);
    image.decoded = ImageRgba8{};
  }
  give_back_freed_memory();  // the freed blocks lie among others in the heap: give their pages back
}

void set_bounds_from_draws(Scene& scene) {
  bool first = true;
  for (const DrawItem& d : scene.draws) {
    const Primitive& p = scene.primitives[static_cast<size_t>(d.primitive)];
    for (int corner = 0; corner < 8; ++corner) {
      glm::vec3 c((corner & 1) ? p.bounds_max.x : p.bounds_min.x, (corner & 2) ? p.bounds_max.y : p.bounds_min.y,
                  (corner & 4) ? p.bounds_max.z : p.bounds_min.z);
      glm::vec3 w = glm::vec3(d.world * glm::vec4(c, 1.0f));
      scene.bounds_min = first ? w : glm::min(scene.bounds_min, w);
      scene.bounds_max = first ? w : glm::max(scene.bounds_max, w);
      first = false;
    }
  }
}

Camera framing_camera(const Scene& scene) {
  glm::vec3 center = 0.5f * (scene.bounds_min + scene.bounds_max);
  float radius = std::max(0.5f * glm::length(scene.bounds_max - scene.bounds_min), 1e-3f);
  Camera cam;
  cam.yfov = 0.8f;
  float distance = radius / std::sin(cam.yfov * 0.5f);
  cam.position = center + glm::vec3(0.0f, 0.3f, 1.0f) * (distance / glm::length(glm::vec3(0.0f, 0.3f, 1.0f)));
  cam.view = glm::lookAt(cam.position, center, glm::vec3(0, 1, 0));
  cam.znear = std::max(distance - radius * 1.5f, distance * 1e-3f);
  cam.zfar = distance + radius * 1.5f;
  return cam;
}

Camera chosen_camera(const Scene& scene, int index) {
  if (index < 0) return scene.camera ? *scene.camera : framing_camera(scene);
  const size_t count = scene.cameras.size();
  if (static_cast<size_t>(index) >= count)
    throw Error(scene.path + ": camera " + std::to_string(index) + " does not exist: the file has " +
                std::to_string(count) + (count == 1 ? " camera (0)" : count == 0 ? " cameras" : " cameras (0 to " + std::to_string(count - 1) + ")"));
  return scene.cameras[static_cast<size_t>(index)];
}

}  // namespace kit

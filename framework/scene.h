#pragma once
// glTF 2.0 scenes: loaded by tinygltf into plain CPU structures (validated,
// flattened node hierarchy, generated tangents), then uploaded to GL.
#include <glm/glm.hpp>

#include <optional>
#include <string>
#include <vector>

#include "gl_objects.h"

namespace kit {

struct ImageRgba8 {
  int width = 0, height = 0;
  std::vector<unsigned char> pixels;  // RGBA8, top row first
};

struct Material {
  glm::vec4 base_color_factor{1.0f};
  float metallic_factor = 1.0f;
  float roughness_factor = 1.0f;
  glm::vec3 emissive{0.0f};  // emissiveFactor * KHR_materials_emissive_strength
  float normal_scale = 1.0f;
  int base_color_image = -1;  // index into Scene::images, -1 when absent
  int metallic_roughness_image = -1;
  int normal_image = -1;
  int emissive_image = -1;
  std::string name;
};

struct Primitive {
  std::vector<Vertex> vertices;
  std::vector<uint32_t> indices;
  int material = -1;             // -1: the glTF default material
  bool tangents_generated = false;
  glm::vec3 bounds_min{0.0f}, bounds_max{0.0f};
  std::string name;              // "mesh 'x' primitive 0"
};

struct DrawItem {
  int primitive;
  glm::mat4 world;
};

struct Light {
  int type = 0;                  // KIT_LIGHT_POINT or KIT_LIGHT_SPOT
  glm::vec3 position{0.0f};
  glm::vec3 direction{0, 0, -1}; // where a spot light points (world space, unit)
  glm::vec3 color{1.0f};
  float intensity = 1.0f;        // glTF units: candela
  float range = 0.0f;            // 0: unlimited
  float inner_cone = 0.0f;       // radians
  float outer_cone = 0.7853982f; // radians (glTF default pi/4)
};

struct Camera {
  glm::mat4 view{1.0f};
  glm::vec3 position{0.0f};
  float yfov = 0.8f, znear = 0.1f, zfar = 100.0f;
  glm::mat4 projection(float aspect) const;
};

struct Scene {
  std::string path;
  std::vector<ImageRgba8> images;
  std::vector<Material> materials;
  std::vector<Primitive> primitives;
  std::vector<DrawItem> draws;
  std::vector<Light> lights;
  std::optional<Camera> camera;
  glm::vec3 bounds_min{0.0f}, bounds_max{0.0f};  // world space, over all draws
  // What was loaded differently from the file (points and lines left out, ...);
  // the programs print each once.
  std::vector<std::string> warnings;
};

// Loads and validates a .gltf/.glb file (an .obj goes to load_obj_scene, obj_scene.h). Any problem throws kit::Error whose
// message starts with the path and says what is wrong; nothing crashes.
Scene load_scene(const std::string& path);

// Fills Vertex::tangent from positions, normals and UVs (per-triangle UV
// derivatives, Gram-Schmidt, handedness in w). Degenerate UVs still give a
// unit tangent perpendicular to the normal.
void generate_tangents(std::vector<Vertex>& vertices, const std::vector<uint32_t>& indices);

// Flat normals for a primitive whose file gives none (glTF requires them; OBJ
// faces without vn get the same): every triangle gets its own three vertices
// carrying its plane's normal. Call before generate_tangents.
void use_flat_normals(Primitive& primitive);

// A camera that frames the scene's bounds, for scenes without a camera.
Camera framing_camera(const Scene& scene);

// GL resources of a scene: one Mesh per primitive and the textures materials
// use (colour data as sRGB, normal and metallic-roughness data as linear).
class SceneGpu {
 public:
  explicit SceneGpu(const Scene& scene);
  const Mesh& mesh(int primitive) const { return meshes_[static_cast<size_t>(primitive)]; }
  // Binds the material's textures to the KIT_UNIT_* material units (defaults when absent).
  const Texture2D& texture(int image, bool srgb) const;
  const Texture2D& white() const { return white_; }
  const Texture2D& flat_normal() const { return flat_normal_; }

 private:
  std::vector<Mesh> meshes_;
  std::vector<Texture2D> srgb_, linear_;
  Texture2D white_, flat_normal_;
};

}  // namespace kit

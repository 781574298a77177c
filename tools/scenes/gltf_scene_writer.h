// The glTF writer kit-scenes builds its scenes with (not the framework's loader): one
// glTF model whose vertex and index data live in a single buffer, its images written as
// PNG beside it, and the file read back to check that tinygltf kept everything.
#pragma once

#include <tiny_gltf.h>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_precision.hpp>  // u8vec4

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "scene_images.h"
#include "scene_meshes.h"

namespace kit_scenes {

// Accessor indices of one uploaded MeshData; several meshes (materials) may share them.
struct Geometry {
  int position = -1;
  int normal = -1;
  int texcoord = -1;
  int texcoord1 = -1;  // TEXCOORD_1; -1: none
  int tangent = -1;
  int color = -1;  // COLOR_0; -1: none (white)
  int indices = -1;
};

// How a material reads one of its textures: glTF's texCoord (which UV set) and, where
// `transformed`, a KHR_texture_transform (offset, rotation in radians, scale).
struct TextureUv {
  int tex_coord = 0;
  bool transformed = false;
  glm::dvec2 offset{0.0};
  double rotation = 0.0;
  glm::dvec2 scale{1.0};
};

struct MaterialDesc {
  std::string name;
  glm::dvec4 base_color{1.0};
  double metallic = 0.0;
  double roughness = 0.5;
  int base_color_texture = -1;
  int normal_texture = -1;
  double normal_scale = 1.0;
  glm::dvec3 emissive{0.0};
  double emissive_strength = 1.0;  // other than 1: KHR_materials_emissive_strength
  int emissive_texture = -1;
  int metallic_roughness_texture = -1;  // glTF: roughness in G, metallic in B (R is free: occlusion)
  TextureUv base_color_uv, metallic_roughness_uv, normal_uv, emissive_uv;
  std::string alpha_mode = "OPAQUE";  // glTF alphaMode: OPAQUE, MASK or BLEND
  double alpha_cutoff = 0.5;          // glTF's default; written only for MASK
  bool double_sided = false;
};

struct NodeDesc {
  std::string name;
  glm::dvec3 translation{0.0};
  glm::dquat rotation{1.0, 0.0, 0.0, 0.0};  // glm's constructor order: w, x, y, z
  glm::dvec3 scale{1.0};
  int mesh = -1;
};

inline const glm::dquat kNoRotation(1.0, 0.0, 0.0, 0.0);
inline const glm::dvec3 kUnitScale(1.0);
inline const glm::dvec3 kWhite(1.0);

// Builds one glTF model whose vertex and index data live in a single buffer.
class GltfSceneWriter {
 public:
  explicit GltfSceneWriter(std::string name);

  Geometry add_geometry(const MeshData& mesh);

  int add_mesh(const std::string& name, const Geometry& g, int material);

  // COLOR_0 for `g`, one colour a vertex: FLOAT VEC3 (alpha 1), or normalized
  // UNSIGNED_BYTE VEC4 (c / 255).
  void add_colors(Geometry& g, const std::vector<glm::vec3>& rgb);
  void add_colors(Geometry& g, const std::vector<glm::u8vec4>& rgba);

  // A mesh of one primitive, named `name`, and a node of the same name drawing it at
  // `translation` under `parent` (a root of the scene when parent < 0).
  int add_mesh_node(const std::string& name, glm::dvec3 translation, const Geometry& g, int material,
                    int parent = -1);

  // Lists an image; write() puts the PNG next to the .gltf, which references it by uri
  // only. Called alone, it adds an image no texture uses (a loader should not decode it).
  int add_image(const std::string& file_name, const Image8& image);

  int add_texture(const std::string& file_name, const Image8& image);

  int add_material(const MaterialDesc& desc);

  // Adds a node under `parent`, or as a root of the scene when parent < 0.
  int add_node(const NodeDesc& desc, int parent = -1);

  // Intensity in candela. range 0: the property is left out (unlimited).
  void add_point_light(const std::string& name, glm::dvec3 position, glm::dvec3 color, double candela,
                       double range = 0.0);

  // A spot light shines along its node's local -Z, so it is aimed like a camera.
  void add_spot_light(const std::string& name, glm::dvec3 position, glm::dvec3 target, glm::dvec3 color,
                      double candela, double inner_cone, double outer_cone, double range = 0.0);

  // A directional light shines along its node's local -Z, `direction` here; its
  // intensity is an illuminance (lux). Its node's position changes nothing (glTF),
  // which lets a scene put it where treating it as a point light shows.
  void add_directional_light(const std::string& name, glm::dvec3 node_position, glm::dvec3 direction,
                             glm::dvec3 color, double lux);

  // No aspect ratio: the renderer uses its viewport's. `roll_degrees` turns it about its view
  // axis, counter-clockwise as seen through it (the image turns clockwise).
  void add_camera(glm::dvec3 eye, glm::dvec3 target, double yfov, double roll_degrees = 0.0);

  // Writes OUT_DIR/<name>/<name>.gltf, <name>.bin and the PNG textures.
  void write(const std::filesystem::path& out_dir) const;

 private:
  // Reads the written file back as JSON and checks that the writer kept what the kit put in:
  // every array's length, and each light attached to a node. A tinygltf that drops a part
  // (2.9 dropped the nodes' lights: set_node_light in the .cpp) then fails the build by name instead
  // of leaving scenes that render differently on one distribution.
  void check_written(const std::filesystem::path& gltf) const;

  // texCoord and KHR_texture_transform of one texture reference (TextureInfo or
  // NormalTextureInfo); nothing is written for the defaults (UV set 0, no transform).
  template <typename Info>
  void set_texture_uv(Info& info, const TextureUv& uv);

  // Appends `data` to the buffer as its own tightly packed bufferView.
  template <typename T>
  int add_accessor(const std::vector<T>& data, int type, int component_type, int target);

  void attach_light(const tinygltf::Light& light, const NodeDesc& node);

  void use_extension(const std::string& ext);

  std::string name_;
  tinygltf::Model model_;
  size_t transformed_textures_ = 0;  // texture references given a KHR_texture_transform
  std::vector<std::pair<std::string, Image8>> images_;
};

}  // namespace kit_scenes

#include "gltf_scene_writer.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <tuple>

namespace kit_scenes {

namespace fs = std::filesystem;

namespace {

// Every camera's depth range: near enough for the close-ups, far enough for the floors.
constexpr double kZNear = 0.1;
constexpr double kZFar = 50.0;

// Adding +0.0 turns -0.0 into 0.0, so the JSON never shows "-0.0".
double tidy(double v) { return v + 0.0; }
std::vector<double> to_vector(glm::dvec3 v) { return {tidy(v.x), tidy(v.y), tidy(v.z)}; }
std::vector<double> to_vector(glm::dvec4 v) { return {tidy(v.x), tidy(v.y), tidy(v.z), tidy(v.w)}; }

// tinygltf 2.9 (Debian 13) has Node::light and writes a node's KHR_lights_punctual from
// it alone: with light = -1 it erases the extension written beside it, and every scene's
// lights were left attached to no node (so lit stages used the default rig instead).
// tinygltf 2.8 (Debian 12, Ubuntu 24.04) has no such field and writes the extension.
template <typename Node>
auto set_node_light(Node& node, int light, int) -> decltype(node.light = light, void()) {
  node.light = light;
}
template <typename Node>
void set_node_light(Node&, int, long) {}

// A KHR_lights_punctual light; range 0 leaves the property out (unlimited).
tinygltf::Light punctual_light(const std::string& name, const char* type, glm::dvec3 color, double intensity,
                               double range) {
  tinygltf::Light light;
  light.name = name;
  light.type = type;
  light.color = to_vector(color);
  light.intensity = intensity;
  light.range = range;
  return light;
}

}  // namespace

GltfSceneWriter::GltfSceneWriter(std::string name) : name_(std::move(name)) {
  model_.asset.version = "2.0";
  model_.asset.generator = "kit-scenes";
  model_.buffers.emplace_back();
  model_.buffers[0].uri = name_ + ".bin";
  tinygltf::Sampler sampler;  // trilinear + repeat, shared by every texture
  sampler.magFilter = TINYGLTF_TEXTURE_FILTER_LINEAR;
  sampler.minFilter = TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR;
  model_.samplers.push_back(sampler);
  model_.scenes.emplace_back();
  model_.scenes[0].name = name_;
  model_.defaultScene = 0;
}

Geometry GltfSceneWriter::add_geometry(const MeshData& mesh) {
  Geometry g;
  glm::vec3 lo = mesh.positions.front(), hi = mesh.positions.front();
  for (const glm::vec3& p : mesh.positions) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  g.position = add_accessor(mesh.positions, TINYGLTF_TYPE_VEC3, TINYGLTF_COMPONENT_TYPE_FLOAT,
                            TINYGLTF_TARGET_ARRAY_BUFFER);
  model_.accessors[g.position].minValues = to_vector(glm::dvec3(lo));  // required for POSITION
  model_.accessors[g.position].maxValues = to_vector(glm::dvec3(hi));
  g.normal = add_accessor(mesh.normals, TINYGLTF_TYPE_VEC3, TINYGLTF_COMPONENT_TYPE_FLOAT,
                          TINYGLTF_TARGET_ARRAY_BUFFER);
  g.texcoord = add_accessor(mesh.uvs, TINYGLTF_TYPE_VEC2, TINYGLTF_COMPONENT_TYPE_FLOAT,
                            TINYGLTF_TARGET_ARRAY_BUFFER);
  if (!mesh.uvs1.empty())
    g.texcoord1 = add_accessor(mesh.uvs1, TINYGLTF_TYPE_VEC2, TINYGLTF_COMPONENT_TYPE_FLOAT,
                               TINYGLTF_TARGET_ARRAY_BUFFER);
  if (!mesh.tangents.empty())
    g.tangent = add_accessor(mesh.tangents, TINYGLTF_TYPE_VEC4, TINYGLTF_COMPONENT_TYPE_FLOAT,
                             TINYGLTF_TARGET_ARRAY_BUFFER);
  g.indices =
      add_accessor(mesh.indices, TINYGLTF_TYPE_SCALAR, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT,
                   TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
  return g;
}

int GltfSceneWriter::add_mesh(const std::string& name, const Geometry& g, int material) {
  tinygltf::Primitive prim;
  prim.attributes["POSITION"] = g.position;
  prim.attributes["NORMAL"] = g.normal;
  prim.attributes["TEXCOORD_0"] = g.texcoord;
  if (g.texcoord1 >= 0) prim.attributes["TEXCOORD_1"] = g.texcoord1;
  if (g.tangent >= 0) prim.attributes["TANGENT"] = g.tangent;
  if (g.color >= 0) prim.attributes["COLOR_0"] = g.color;
  prim.indices = g.indices;
  prim.material = material;
  prim.mode = TINYGLTF_MODE_TRIANGLES;
  tinygltf::Mesh mesh;
  mesh.name = name;
  mesh.primitives.push_back(prim);
  model_.meshes.push_back(mesh);
  return int(model_.meshes.size()) - 1;
}

void GltfSceneWriter::add_colors(Geometry& g, const std::vector<glm::vec3>& rgb) {
  g.color = add_accessor(rgb, TINYGLTF_TYPE_VEC3, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TARGET_ARRAY_BUFFER);
}

void GltfSceneWriter::add_colors(Geometry& g, const std::vector<glm::u8vec4>& rgba) {
  g.color = add_accessor(rgba, TINYGLTF_TYPE_VEC4, TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, TINYGLTF_TARGET_ARRAY_BUFFER);
  model_.accessors[static_cast<size_t>(g.color)].normalized = true;
}

int GltfSceneWriter::add_mesh_node(const std::string& name, glm::dvec3 translation, const Geometry& g,
                                   int material, int parent) {
  return add_node({name, translation, kNoRotation, kUnitScale, add_mesh(name, g, material)}, parent);
}

int GltfSceneWriter::add_image(const std::string& file_name, const Image8& image) {
  tinygltf::Image img;
  img.name = fs::path(file_name).stem().string();
  img.uri = file_name;
  model_.images.push_back(img);
  images_.emplace_back(file_name, image);
  return int(model_.images.size()) - 1;
}

int GltfSceneWriter::add_texture(const std::string& file_name, const Image8& image) {
  tinygltf::Texture tex;
  tex.sampler = 0;
  tex.source = add_image(file_name, image);
  model_.textures.push_back(tex);
  return int(model_.textures.size()) - 1;
}

int GltfSceneWriter::add_material(const MaterialDesc& desc) {
  tinygltf::Material m;
  m.name = desc.name;
  m.doubleSided = desc.double_sided;
  m.alphaMode = desc.alpha_mode;
  m.alphaCutoff = desc.alpha_cutoff;
  m.emissiveTexture.index = desc.emissive_texture;
  m.pbrMetallicRoughness.baseColorFactor = to_vector(desc.base_color);
  m.pbrMetallicRoughness.metallicFactor = desc.metallic;
  m.pbrMetallicRoughness.roughnessFactor = desc.roughness;
  m.pbrMetallicRoughness.baseColorTexture.index = desc.base_color_texture;
  m.pbrMetallicRoughness.metallicRoughnessTexture.index = desc.metallic_roughness_texture;
  m.normalTexture.index = desc.normal_texture;
  m.normalTexture.scale = desc.normal_scale;
  set_texture_uv(m.pbrMetallicRoughness.baseColorTexture, desc.base_color_uv);
  set_texture_uv(m.pbrMetallicRoughness.metallicRoughnessTexture, desc.metallic_roughness_uv);
  set_texture_uv(m.normalTexture, desc.normal_uv);
  set_texture_uv(m.emissiveTexture, desc.emissive_uv);
  m.emissiveFactor = to_vector(desc.emissive);
  if (desc.emissive_strength != 1.0) {
    // glTF limits emissiveFactor to [0, 1]; brighter emitters need this extension.
    tinygltf::Value::Object ext{{"emissiveStrength", tinygltf::Value(desc.emissive_strength)}};
    m.extensions["KHR_materials_emissive_strength"] = tinygltf::Value(ext);
    use_extension("KHR_materials_emissive_strength");
  }
  model_.materials.push_back(m);
  return int(model_.materials.size()) - 1;
}

template <typename Info>
void GltfSceneWriter::set_texture_uv(Info& info, const TextureUv& uv) {
  if (info.index < 0) return;
  info.texCoord = uv.tex_coord;
  if (!uv.transformed) return;
  tinygltf::Value::Object transform{
      {"offset", tinygltf::Value(tinygltf::Value::Array{tinygltf::Value(uv.offset.x), tinygltf::Value(uv.offset.y)})},
      {"rotation", tinygltf::Value(uv.rotation)},
      {"scale", tinygltf::Value(tinygltf::Value::Array{tinygltf::Value(uv.scale.x), tinygltf::Value(uv.scale.y)})}};
  info.extensions["KHR_texture_transform"] = tinygltf::Value(transform);
  use_extension("KHR_texture_transform");
  ++transformed_textures_;
}

int GltfSceneWriter::add_node(const NodeDesc& desc, int parent) {
  tinygltf::Node node;
  node.name = desc.name;
  node.mesh = desc.mesh;
  // Identity parts are left out: glTF's defaults already mean identity.
  if (desc.translation != glm::dvec3(0.0)) node.translation = to_vector(desc.translation);
  if (desc.rotation != kNoRotation) {
    const glm::dquat& q = desc.rotation;
    node.rotation = to_vector(glm::dvec4(q.x, q.y, q.z, q.w));  // glTF order: x, y, z, w
  }
  if (desc.scale != kUnitScale) node.scale = to_vector(desc.scale);
  model_.nodes.push_back(node);
  const int index = int(model_.nodes.size()) - 1;
  if (parent < 0)
    model_.scenes[0].nodes.push_back(index);
  else
    model_.nodes[parent].children.push_back(index);
  return index;
}

void GltfSceneWriter::add_point_light(const std::string& name, glm::dvec3 position, glm::dvec3 color,
                                      double candela, double range) {
  attach_light(punctual_light(name, "point", color, candela, range), {name, position, kNoRotation, kUnitScale, -1});
}

void GltfSceneWriter::add_spot_light(const std::string& name, glm::dvec3 position, glm::dvec3 target,
                                     glm::dvec3 color, double candela, double inner_cone, double outer_cone,
                                     double range) {
  tinygltf::Light light = punctual_light(name, "spot", color, candela, range);
  light.spot.innerConeAngle = inner_cone;
  light.spot.outerConeAngle = outer_cone;
  attach_light(light, {name, position, look_at_rotation(position, target), kUnitScale, -1});
}

void GltfSceneWriter::add_directional_light(const std::string& name, glm::dvec3 node_position,
                                            glm::dvec3 direction, glm::dvec3 color, double lux) {
  attach_light(punctual_light(name, "directional", color, lux, 0.0),
               {name, node_position, look_at_rotation(node_position, node_position + direction), kUnitScale, -1});
}

void GltfSceneWriter::add_camera(glm::dvec3 eye, glm::dvec3 target, double yfov, double roll_degrees) {
  tinygltf::Camera cam;
  cam.name = "camera";
  cam.type = "perspective";
  cam.perspective.yfov = yfov;
  cam.perspective.znear = kZNear;
  cam.perspective.zfar = kZFar;
  model_.cameras.push_back(cam);
  // The roll turns the camera about its own view axis (its local -Z; +Z turns the same way).
  const glm::dquat rotation = look_at_rotation(eye, target) * glm::angleAxis(glm::radians(roll_degrees), glm::dvec3(0, 0, 1));
  const int node = add_node({"camera", eye, rotation, kUnitScale, -1});
  model_.nodes[node].camera = int(model_.cameras.size()) - 1;
}

void GltfSceneWriter::write(const fs::path& out_dir) const {
  const fs::path dir = out_dir / name_;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw std::runtime_error("cannot create " + dir.string() + ": " + ec.message());
  for (const auto& [file_name, image] : images_) write_png(dir / file_name, image);

  tinygltf::TinyGLTF writer;
  // The PNGs are already written: keep tinygltf's own (stb) image writer out of it. The
  // callback must still hand back the uri, or tinygltf writes an image with no source.
  // The callback's arguments differ by version: tinygltf 2.8 (Debian 12, Ubuntu 24.04)
  // passes (..., std::string* out_uri, void* user) to a function pointer; 2.9 (Debian 13)
  // puts FsCallbacks* and URICallbacks* before those two and takes a std::function. A
  // generic lambda converts to either; out_uri is the next to last argument in both.
  writer.SetImageWriter(
      [](const std::string*, const std::string*, const tinygltf::Image* image, bool, auto... rest) {
        std::string* out_uri = std::get<sizeof...(rest) - 2>(std::forward_as_tuple(rest...));
        *out_uri = image->uri;
        return true;
      },
      nullptr);
  const fs::path gltf = dir / (name_ + ".gltf");
  if (!writer.WriteGltfSceneToFile(&model_, gltf.string(), /*embedImages=*/false,
                                   /*embedBuffers=*/false, /*prettyPrint=*/true,
                                   /*writeBinary=*/false))
    throw std::runtime_error("cannot write " + gltf.string());
  check_written(gltf);
}

void GltfSceneWriter::check_written(const fs::path& gltf) const {
  std::ifstream in(gltf);
  const nlohmann::json doc = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (doc.is_discarded()) throw std::runtime_error(gltf.string() + ": the file written is not JSON");
  auto length = [&](const char* key) { return doc.contains(key) ? doc[key].size() : size_t{0}; };
  const std::pair<const char*, size_t> arrays[] = {
      {"nodes", model_.nodes.size()},         {"meshes", model_.meshes.size()},
      {"materials", model_.materials.size()}, {"textures", model_.textures.size()},
      {"images", model_.images.size()},       {"cameras", model_.cameras.size()}};
  for (const auto& [key, expected] : arrays)
    if (length(key) != expected)
      throw std::runtime_error(gltf.string() + ": tinygltf wrote " + std::to_string(length(key)) + " " + key +
                               " of the " + std::to_string(expected) + " the scene has");
  size_t attached = 0;
  for (const nlohmann::json& node : doc.value("nodes", nlohmann::json::array()))
    if (node.contains("extensions") && node["extensions"].contains("KHR_lights_punctual")) ++attached;
  if (attached != model_.lights.size())
    throw std::runtime_error(gltf.string() + ": tinygltf wrote " + std::to_string(attached) +
                             " nodes with a KHR_lights_punctual light, and the scene has " +
                             std::to_string(model_.lights.size()) + " lights");
  // Texture references are nested objects: count the transform's key in the materials' text.
  const std::string materials = doc.value("materials", nlohmann::json::array()).dump();
  size_t transforms = 0;
  for (size_t at = materials.find("\"KHR_texture_transform\""); at != std::string::npos;
       at = materials.find("\"KHR_texture_transform\"", at + 1))
    ++transforms;
  if (transforms != transformed_textures_)
    throw std::runtime_error(gltf.string() + ": tinygltf wrote " + std::to_string(transforms) +
                             " KHR_texture_transform objects, and the scene has " +
                             std::to_string(transformed_textures_));
}

template <typename T>
int GltfSceneWriter::add_accessor(const std::vector<T>& data, int type, int component_type, int target) {
  std::vector<unsigned char>& bytes = model_.buffers[0].data;
  const size_t offset = bytes.size();  // every element is made of 4-byte values: aligned
  const size_t length = data.size() * sizeof(T);
  bytes.resize(offset + length);
  std::memcpy(bytes.data() + offset, data.data(), length);

  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = offset;
  view.byteLength = length;
  view.target = target;
  model_.bufferViews.push_back(view);

  tinygltf::Accessor acc;
  acc.bufferView = int(model_.bufferViews.size()) - 1;
  acc.componentType = component_type;
  acc.type = type;
  acc.count = data.size();
  model_.accessors.push_back(acc);
  return int(model_.accessors.size()) - 1;
}

void GltfSceneWriter::attach_light(const tinygltf::Light& light, const NodeDesc& node) {
  model_.lights.push_back(light);
  const int index = add_node(node);
  const int light_index = int(model_.lights.size()) - 1;
  tinygltf::Value::Object ext{{"light", tinygltf::Value(light_index)}};
  model_.nodes[index].extensions["KHR_lights_punctual"] = tinygltf::Value(ext);
  set_node_light(model_.nodes[index], light_index, 0);
  use_extension("KHR_lights_punctual");
}

void GltfSceneWriter::use_extension(const std::string& ext) {
  auto& used = model_.extensionsUsed;
  if (std::find(used.begin(), used.end(), ext) == used.end()) used.push_back(ext);
}

}  // namespace kit_scenes

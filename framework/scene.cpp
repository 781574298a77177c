#include "scene.h"

#include <tiny_gltf.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "error.h"
#include "gbuffer_layout.h"
#include "obj_scene.h"
#include "safe_file.h"
#include "texture_decode.h"

namespace kit {

namespace {

// Limits on what a scene file may ask for (documented in scene.h).
constexpr std::uintmax_t kMaxSceneFileBytes = std::uintmax_t(1) << 30;  // a .gltf/.glb, a buffer or an image file
constexpr int kMaxJsonDepth = 64;       // glTF itself nests 7 deep; tinygltf's JSON parser recurses per level
constexpr int kMaxNodeDepth = 256;      // the node hierarchy is walked recursively

// ---- image decoding: tinygltf hands us the bytes, texture_decode.h decodes them ----
bool decode_image_with_oiio(tinygltf::Image* image, const int index, std::string* err, std::string*, int, int,
                            const unsigned char* bytes, int size, void*) {
  try {
    ImageRgba8 decoded = decode_texture_image(bytes, size > 0 ? static_cast<size_t>(size) : 0,
                                              "image " + std::to_string(index) + " ('" + image->uri + "')");
    image->width = decoded.width;
    image->height = decoded.height;
    image->component = 4;
    image->bits = 8;
    image->pixel_type = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
    image->image = std::move(decoded.pixels);
    return true;
  } catch (const Error& e) {
    if (err) *err += e.what();
    return false;
  }
}

// ---- accessors, read with every bound checked ----
struct AccessorReader {
  const tinygltf::Model& model;
  const std::string& path;

  [[noreturn]] void fail(const std::string& what) const { throw Error(path + ": " + what); }

  // Reads `components` values per element as floats (normalised integers scaled to [0,1]).
  std::vector<float> floats(int index, int type, int components, bool allow_normalized, const std::string& what) const {
    const tinygltf::Accessor& acc = accessor(index, what);
    if (acc.type != type)
      fail(what + ": accessor " + std::to_string(index) + " has the wrong type (expected " +
           std::to_string(components) + " components)");
    bool is_float = acc.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT;
    bool is_norm = acc.normalized && (acc.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
                                      acc.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT);
    if (!is_float && !(allow_normalized && is_norm))
      fail(what + ": accessor " + std::to_string(index) + " has an unsupported component type " +
           std::to_string(acc.componentType));
    int component_size = tinygltf::GetComponentSizeInBytes(static_cast<uint32_t>(acc.componentType));
    const unsigned char* base = element_base(acc, component_size * components, what);
    size_t stride = stride_of(acc, component_size * components);
    std::vector<float> out(acc.count * static_cast<size_t>(components));
    for (size_t i = 0; i < acc.count; ++i) {
      const unsigned char* e = base + i * stride;
      for (int c = 0; c < components; ++c) {
        float v;
        if (is_float) std::memcpy(&v, e + c * 4, 4);
        else if (component_size == 1) v = e[c] / 255.0f;
        else {
          uint16_t u;
          std::memcpy(&u, e + c * 2, 2);
          v = u / 65535.0f;
        }
        out[i * components + c] = v;
      }
    }
    return out;
  }

  std::vector<uint32_t> indices(int index, const std::string& what) const {
    const tinygltf::Accessor& acc = accessor(index, what);
    if (acc.type != TINYGLTF_TYPE_SCALAR) fail(what + ": index accessor " + std::to_string(index) + " is not SCALAR");
    int size = 0;
    switch (acc.componentType) {
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: size = 1; break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: size = 2; break;
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: size = 4; break;
      default: fail(what + ": index accessor " + std::to_string(index) + " has an unsupported component type");
    }
    const unsigned char* base = element_base(acc, size, what);
    size_t stride = stride_of(acc, size);
    std::vector<uint32_t> out(acc.count);
    for (size_t i = 0; i < acc.count; ++i) {
      uint32_t v = 0;
      std::memcpy(&v, base + i * stride, static_cast<size_t>(size));  // little-endian, as glTF requires
      out[i] = v;
    }
    return out;
  }

  const tinygltf::Accessor& accessor(int index, const std::string& what) const {
    if (index < 0 || index >= static_cast<int>(model.accessors.size()))
      fail(what + ": accessor index " + std::to_string(index) + " does not exist");
    return model.accessors[static_cast<size_t>(index)];
  }

  static size_t stride_of(const tinygltf::Accessor&, int element_size) { return static_cast<size_t>(element_size); }

  const unsigned char* element_base(const tinygltf::Accessor& acc, int element_size, const std::string& what) const {
    if (acc.sparse.isSparse) fail(what + ": sparse accessors are not supported");
    if (acc.bufferView < 0 || acc.bufferView >= static_cast<int>(model.bufferViews.size()))
      fail(what + ": accessor has no valid bufferView");
    const tinygltf::BufferView& view = model.bufferViews[static_cast<size_t>(acc.bufferView)];
    if (view.buffer < 0 || view.buffer >= static_cast<int>(model.buffers.size()))
      fail(what + ": bufferView " + std::to_string(acc.bufferView) + " names no valid buffer");
    const tinygltf::Buffer& buffer = model.buffers[static_cast<size_t>(view.buffer)];
    size_t stride = view.byteStride ? view.byteStride : static_cast<size_t>(element_size);
    if (stride != static_cast<size_t>(element_size))
      fail(what + ": interleaved buffer views (byteStride " + std::to_string(view.byteStride) + ") are not supported");
    // Every number below comes from the file: each comparison is arranged so that no
    // sum or product can wrap around (a count near 2^64 must fail here, not in a loop).
    const size_t size = buffer.data.size();
    if (view.byteOffset > size || view.byteLength > size - view.byteOffset)
      fail(what + ": bufferView " + std::to_string(acc.bufferView) + " (offset " + std::to_string(view.byteOffset) +
           ", length " + std::to_string(view.byteLength) + ") lies outside buffer " + std::to_string(view.buffer) +
           " (" + std::to_string(size) + " bytes)");
    if (acc.byteOffset > view.byteLength)
      fail(what + ": accessor byteOffset " + std::to_string(acc.byteOffset) + " lies past its bufferView (" +
           std::to_string(view.byteLength) + " bytes)");
    const size_t available = view.byteLength - acc.byteOffset;
    if (acc.count > 0 && (static_cast<size_t>(element_size) > available ||
                          acc.count - 1 > (available - static_cast<size_t>(element_size)) / stride))
      fail(what + ": accessor reads past the end of its buffer (" + std::to_string(acc.count) + " elements of " +
           std::to_string(element_size) + " bytes from byte " + std::to_string(acc.byteOffset) + " of a " +
           std::to_string(view.byteLength) + "-byte bufferView; buffer " + std::to_string(view.buffer) + " has " +
           std::to_string(size) + " bytes)");
    // From here count <= bytes in memory, so count * components (<= 4) cannot wrap.
    return buffer.data.data() + view.byteOffset + acc.byteOffset;
  }
};

glm::mat4 node_local_matrix(const tinygltf::Node& node) {
  if (node.matrix.size() == 16) {
    glm::mat4 m;
    for (int i = 0; i < 16; ++i) glm::value_ptr(m)[i] = static_cast<float>(node.matrix[static_cast<size_t>(i)]);
    return m;
  }
  glm::mat4 m(1.0f);
  if (node.translation.size() == 3)
    m = glm::translate(m, glm::vec3(node.translation[0], node.translation[1], node.translation[2]));
  if (node.rotation.size() == 4) {
    glm::quat q(static_cast<float>(node.rotation[3]), static_cast<float>(node.rotation[0]),
                static_cast<float>(node.rotation[1]), static_cast<float>(node.rotation[2]));
    m *= glm::mat4_cast(q);
  }
  if (node.scale.size() == 3) m = glm::scale(m, glm::vec3(node.scale[0], node.scale[1], node.scale[2]));
  return m;
}

int texture_image(const tinygltf::Model& model, int texture, const std::string& path) {
  if (texture < 0) return -1;
  if (texture >= static_cast<int>(model.textures.size()))
    throw Error(path + ": texture index " + std::to_string(texture) + " does not exist");
  int source = model.textures[static_cast<size_t>(texture)].source;
  if (source < 0 || source >= static_cast<int>(model.images.size()))
    throw Error(path + ": texture " + std::to_string(texture) + " has no valid image source");
  return source;
}

class SceneBuilder {
 public:
  SceneBuilder(const tinygltf::Model& model, const std::string& path) : model_(model), path_(path), reader_{model, path} {}

  Scene build() {
    scene_.path = path_;
    for (const auto& img : model_.images) {
      if (img.image.empty() || img.width <= 0 || img.height <= 0) throw Error(path_ + ": image '" + img.uri + "' has no pixels");
      scene_.images.push_back({img.width, img.height, img.image});
    }
    for (const auto& m : model_.materials) scene_.materials.push_back(material(m));
    for (size_t mi = 0; mi < model_.meshes.size(); ++mi) {
      std::vector<int> prims;
      for (size_t pi = 0; pi < model_.meshes[mi].primitives.size(); ++pi) {
        int id = primitive(mi, pi);
        if (id >= 0) prims.push_back(id);
      }
      mesh_primitives_.push_back(prims);
    }
    int scene_index = model_.defaultScene >= 0 ? model_.defaultScene : 0;
    if (model_.scenes.empty()) throw Error(path_ + ": the file has no scene");
    if (scene_index >= static_cast<int>(model_.scenes.size())) throw Error(path_ + ": defaultScene does not exist");
    for (int root : model_.scenes[static_cast<size_t>(scene_index)].nodes) visit(root, glm::mat4(1.0f), 0);
    if (scene_.draws.empty()) throw Error(path_ + ": the scene draws no triangles");
    bool first = true;
    for (const DrawItem& d : scene_.draws) {
      const Primitive& p = scene_.primitives[static_cast<size_t>(d.primitive)];
      for (int corner = 0; corner < 8; ++corner) {
        glm::vec3 c((corner & 1) ? p.bounds_max.x : p.bounds_min.x, (corner & 2) ? p.bounds_max.y : p.bounds_min.y,
                    (corner & 4) ? p.bounds_max.z : p.bounds_min.z);
        glm::vec3 w = glm::vec3(d.world * glm::vec4(c, 1.0f));
        scene_.bounds_min = first ? w : glm::min(scene_.bounds_min, w);
        scene_.bounds_max = first ? w : glm::max(scene_.bounds_max, w);
        first = false;
      }
    }
    return std::move(scene_);
  }

 private:
  Material material(const tinygltf::Material& m) {
    Material out;
    out.name = m.name;
    const auto& pbr = m.pbrMetallicRoughness;
    if (pbr.baseColorFactor.size() == 4)
      out.base_color_factor = glm::vec4(pbr.baseColorFactor[0], pbr.baseColorFactor[1], pbr.baseColorFactor[2], pbr.baseColorFactor[3]);
    out.metallic_factor = static_cast<float>(pbr.metallicFactor);
    out.roughness_factor = static_cast<float>(pbr.roughnessFactor);
    if (m.emissiveFactor.size() == 3) out.emissive = glm::vec3(m.emissiveFactor[0], m.emissiveFactor[1], m.emissiveFactor[2]);
    auto strength = m.extensions.find("KHR_materials_emissive_strength");
    if (strength != m.extensions.end() && strength->second.Has("emissiveStrength"))
      out.emissive *= static_cast<float>(strength->second.Get("emissiveStrength").GetNumberAsDouble());
    out.normal_scale = static_cast<float>(m.normalTexture.scale);
    out.base_color_image = texture_image(model_, pbr.baseColorTexture.index, path_);
    out.metallic_roughness_image = texture_image(model_, pbr.metallicRoughnessTexture.index, path_);
    out.normal_image = texture_image(model_, m.normalTexture.index, path_);
    out.emissive_image = texture_image(model_, m.emissiveTexture.index, path_);
    return out;
  }

  int primitive(size_t mesh, size_t prim) {
    const tinygltf::Primitive& p = model_.meshes[mesh].primitives[prim];
    std::string what = "mesh " + std::to_string(mesh) + " ('" + model_.meshes[mesh].name + "') primitive " + std::to_string(prim);
    const int mode = p.mode == -1 ? TINYGLTF_MODE_TRIANGLES : p.mode;
    if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP && mode != TINYGLTF_MODE_TRIANGLE_FAN) {
      // Points and lines have no surface to put in a G-buffer: left out, said once.
      scene_.warnings.push_back(path_ + ": " + what + ": mode " + std::to_string(mode) +
                                " (points or lines) is not drawn; the kit draws triangles");
      return -1;
    }
    auto attr = [&](const char* name) {
      auto it = p.attributes.find(name);
      return it == p.attributes.end() ? -1 : it->second;
    };
    if (attr("POSITION") < 0) throw Error(path_ + ": " + what + ": has no POSITION attribute");
    std::vector<float> pos = reader_.floats(attr("POSITION"), TINYGLTF_TYPE_VEC3, 3, false, what + " POSITION");
    size_t n = pos.size() / 3;
    // No NORMAL: glTF asks for flat normals, computed below once the triangles are known.
    const bool flat = attr("NORMAL") < 0;
    std::vector<float> nrm = flat ? std::vector<float>(pos.size(), 0.0f)
                                  : reader_.floats(attr("NORMAL"), TINYGLTF_TYPE_VEC3, 3, false, what + " NORMAL");
    if (nrm.size() / 3 != n) throw Error(path_ + ": " + what + ": NORMAL count differs from POSITION count");
    std::vector<float> uv, tan;
    if (attr("TEXCOORD_0") >= 0) uv = reader_.floats(attr("TEXCOORD_0"), TINYGLTF_TYPE_VEC2, 2, true, what + " TEXCOORD_0");
    if (attr("TANGENT") >= 0) tan = reader_.floats(attr("TANGENT"), TINYGLTF_TYPE_VEC4, 4, false, what + " TANGENT");
    if ((!uv.empty() && uv.size() / 2 != n) || (!tan.empty() && tan.size() / 4 != n))
      throw Error(path_ + ": " + what + ": attribute counts differ from POSITION count");

    Primitive out;
    out.name = what;
    out.material = p.material;
    if (p.material >= static_cast<int>(model_.materials.size())) throw Error(path_ + ": " + what + ": material index does not exist");
    out.vertices.resize(n);
    for (size_t i = 0; i < n; ++i) {
      Vertex& v = out.vertices[i];
      v.position = glm::vec3(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]);
      v.normal = glm::vec3(nrm[3 * i], nrm[3 * i + 1], nrm[3 * i + 2]);
      if (!std::isfinite(v.position.x) || !std::isfinite(v.position.y) || !std::isfinite(v.position.z))
        throw Error(path_ + ": " + what + ": POSITION " + std::to_string(i) + " is not finite (NaN or Inf)");
      if (!std::isfinite(glm::dot(v.normal, v.normal)))
        throw Error(path_ + ": " + what + ": NORMAL " + std::to_string(i) + " is not finite (NaN or Inf)");
      v.texcoord = uv.empty() ? glm::vec2(0.0f) : glm::vec2(uv[2 * i], uv[2 * i + 1]);
      v.tangent = tan.empty() ? glm::vec4(0.0f) : glm::vec4(tan[4 * i], tan[4 * i + 1], tan[4 * i + 2], tan[4 * i + 3]);
      out.bounds_min = i == 0 ? v.position : glm::min(out.bounds_min, v.position);
      out.bounds_max = i == 0 ? v.position : glm::max(out.bounds_max, v.position);
    }
    if (p.indices >= 0) {
      out.indices = reader_.indices(p.indices, what + " indices");
    } else {
      out.indices.resize(n);
      for (size_t i = 0; i < n; ++i) out.indices[i] = static_cast<uint32_t>(i);
    }
    for (size_t i = 0; i < out.indices.size(); ++i)
      if (out.indices[i] >= n)
        throw Error(path_ + ": " + what + ": index " + std::to_string(out.indices[i]) + " at position " + std::to_string(i) +
                    " is out of range (" + std::to_string(n) + " vertices)");
    if (mode != TINYGLTF_MODE_TRIANGLES) out.indices = triangle_list(out.indices, mode);
    if (out.indices.size() % 3 != 0) throw Error(path_ + ": " + what + ": index count is not a multiple of 3");
    if (flat) use_flat_normals(out);
    if (tan.empty() && !uv.empty()) {
      generate_tangents(out.vertices, out.indices);
      out.tangents_generated = true;
    } else if (tan.empty()) {
      generate_tangents(out.vertices, out.indices);  // no UVs: any frame around the normal
      out.tangents_generated = true;
    }
    scene_.primitives.push_back(std::move(out));
    return static_cast<int>(scene_.primitives.size()) - 1;
  }

  // A strip's or a fan's triangles as a list, each wound as glTF says (a strip's
  // odd triangles swap their first two corners to keep the winding).
  static std::vector<uint32_t> triangle_list(const std::vector<uint32_t>& in, int mode) {
    std::vector<uint32_t> out;
    for (size_t i = 2; i < in.size(); ++i) {
      if (mode == TINYGLTF_MODE_TRIANGLE_FAN) out.insert(out.end(), {in[0], in[i - 1], in[i]});
      else if (i % 2 == 0) out.insert(out.end(), {in[i - 2], in[i - 1], in[i]});
      else out.insert(out.end(), {in[i - 1], in[i - 2], in[i]});
    }
    return out;
  }

  // glTF's nodes form trees (a node has one parent at most), so each node is
  // visited once: a node reached twice is refused, which bounds the walk by the
  // node count (a graph listing each child twice would otherwise take 2^depth
  // visits) and catches cycles; the depth bound keeps the recursion off the stack's end.
  void visit(int node_index, const glm::mat4& parent, int depth) {
    if (node_index < 0 || node_index >= static_cast<int>(model_.nodes.size()))
      throw Error(path_ + ": node index " + std::to_string(node_index) + " does not exist");
    if (depth > kMaxNodeDepth)
      throw Error(path_ + ": the node hierarchy is deeper than " + std::to_string(kMaxNodeDepth) + " levels");
    if (visited_.empty()) visited_.assign(model_.nodes.size(), false);
    if (visited_[static_cast<size_t>(node_index)])
      throw Error(path_ + ": node " + std::to_string(node_index) +
                  " is reached twice (glTF nodes form a tree: one parent each, no cycles)");
    visited_[static_cast<size_t>(node_index)] = true;
    const tinygltf::Node& node = model_.nodes[static_cast<size_t>(node_index)];
    glm::mat4 world = parent * node_local_matrix(node);
    if (node.mesh >= 0) {
      if (node.mesh >= static_cast<int>(mesh_primitives_.size())) throw Error(path_ + ": node '" + node.name + "' names a mesh that does not exist");
      for (int prim : mesh_primitives_[static_cast<size_t>(node.mesh)]) scene_.draws.push_back({prim, world});
    }
    if (node.camera >= 0 && !scene_.camera) camera(node, world);
    auto ext = node.extensions.find("KHR_lights_punctual");
    if (ext != node.extensions.end() && ext->second.Has("light")) light(light_index(ext->second.Get("light")), world);
    for (int child : node.children) visit(child, world, depth + 1);
  }

  void camera(const tinygltf::Node& node, const glm::mat4& world) {
    if (node.camera >= static_cast<int>(model_.cameras.size())) throw Error(path_ + ": node '" + node.name + "' names a camera that does not exist");
    const tinygltf::Camera& c = model_.cameras[static_cast<size_t>(node.camera)];
    if (c.type != "perspective") return;  // orthographic cameras are ignored; the framing camera is used
    Camera cam;
    cam.view = glm::inverse(world);
    cam.position = glm::vec3(world[3]);
    cam.yfov = static_cast<float>(c.perspective.yfov);
    cam.znear = static_cast<float>(c.perspective.znear);
    cam.zfar = c.perspective.zfar > 0 ? static_cast<float>(c.perspective.zfar) : 1000.0f;
    if (!(cam.yfov > 0.0f) || !(cam.znear > 0.0f)) throw Error(path_ + ": camera " + std::to_string(node.camera) + " has an invalid yfov or znear");
    scene_.camera = cam;
  }

  // A node's KHR_lights_punctual "light": the index of an existing light. Read as a
  // double and checked before it becomes an int: tinygltf's GetNumberAsInt converts
  // any double, which is undefined behaviour past int's range (1e300).
  int light_index(const tinygltf::Value& value) const {
    double index = value.IsNumber() ? value.GetNumberAsDouble() : -1.0;
    if (!(index >= 0.0 && index < static_cast<double>(model_.lights.size()) && index == std::floor(index))) {
      std::ostringstream shown;
      if (value.IsNumber()) shown << index;
      else shown << "(not a number)";
      throw Error(path_ + ": KHR_lights_punctual light index " + shown.str() + " does not exist");
    }
    return static_cast<int>(index);
  }

  void light(int index, const glm::mat4& world) {
    if (index < 0 || index >= static_cast<int>(model_.lights.size()))
      throw Error(path_ + ": KHR_lights_punctual light index " + std::to_string(index) + " does not exist");
    const tinygltf::Light& l = model_.lights[static_cast<size_t>(index)];
    Light out;
    if (l.type == "point") out.type = KIT_LIGHT_POINT;
    else if (l.type == "spot") out.type = KIT_LIGHT_SPOT;
    else return;  // directional lights are outside the labs' scope
    out.position = glm::vec3(world[3]);
    out.direction = glm::normalize(glm::vec3(world * glm::vec4(0, 0, -1, 0)));
    if (l.color.size() == 3) out.color = glm::vec3(l.color[0], l.color[1], l.color[2]);
    out.intensity = static_cast<float>(l.intensity);
    // glTF: range, when present, is > 0; tinygltf reads an absent one as 0 (unlimited).
    if (!(l.range >= 0.0) || !std::isfinite(l.range))
      throw Error(path_ + ": KHR_lights_punctual light " + std::to_string(index) + " has range " +
                  std::to_string(l.range) + " (must be a positive distance, or left out for unlimited)");
    out.range = static_cast<float>(l.range);
    out.inner_cone = static_cast<float>(l.spot.innerConeAngle);
    out.outer_cone = static_cast<float>(l.spot.outerConeAngle);
    scene_.lights.push_back(out);
  }

  const tinygltf::Model& model_;
  const std::string& path_;
  AccessorReader reader_;
  Scene scene_;
  std::vector<std::vector<int>> mesh_primitives_;
  std::vector<bool> visited_;
};

// ---- the file and the files it names ----

// Refuses JSON nested deeper than kMaxJsonDepth before the recursive parser sees it.
void check_json_depth(const unsigned char* text, size_t size, const std::string& path) {
  int depth = 0;
  bool in_string = false, escaped = false;
  for (size_t i = 0; i < size; ++i) {
    unsigned char c = text[i];
    if (in_string) {
      if (escaped) escaped = false;
      else if (c == '\\') escaped = true;
      else if (c == '"') in_string = false;
    } else if (c == '"') {
      in_string = true;
    } else if (c == '{' || c == '[') {
      if (++depth > kMaxJsonDepth)
        throw Error(path + ": invalid glTF: JSON nested deeper than " + std::to_string(kMaxJsonDepth) +
                    " levels (at byte " + std::to_string(i) + ")");
    } else if (c == '}' || c == ']') {
      --depth;
    }
  }
}

// The length of a .glb's JSON chunk, which starts at kGlbJsonOffset (header and
// chunk lengths checked against the file).
constexpr size_t kGlbJsonOffset = 20;
size_t glb_json_chunk(const std::vector<unsigned char>& bytes, const std::string& path) {
  if (bytes.size() < kGlbJsonOffset || std::memcmp(bytes.data(), "glTF", 4) != 0)
    throw Error(path + ": invalid glTF: not a binary glTF file (no 'glTF' header)");
  uint32_t json_length;
  std::memcpy(&json_length, bytes.data() + 12, 4);
  if (json_length > bytes.size() - kGlbJsonOffset)
    throw Error(path + ": invalid glTF: the JSON chunk (" + std::to_string(json_length) + " bytes) is longer than the file");
  return json_length;
}

// A buffer's or image's URI names a file beside the scene or below it: absolute
// paths and ".." are refused here with the element's name (read_file_inside checks
// the file itself again, links included). Percent-escapes are decoded first, as
// the loader decodes them.
void check_uris(const unsigned char* json_text, size_t size, const std::string& path) {
  nlohmann::json doc = nlohmann::json::parse(json_text, json_text + size, nullptr, false);
  if (doc.is_discarded() || !doc.is_object()) return;  // the loader reports what is wrong with it
  for (const char* kind : {"buffers", "images"}) {
    auto list = doc.find(kind);
    if (list == doc.end() || !list->is_array()) continue;
    for (size_t i = 0; i < list->size(); ++i) {
      const nlohmann::json& item = (*list)[i];
      if (!item.is_object() || !item.contains("uri") || !item["uri"].is_string()) continue;
      std::string uri = item["uri"].get<std::string>(), decoded;
      if (uri.rfind("data:", 0) == 0) continue;
      for (size_t k = 0; k < uri.size(); ++k) {
        if (uri[k] == '%' && k + 2 < uri.size() && std::isxdigit(static_cast<unsigned char>(uri[k + 1])) &&
            std::isxdigit(static_cast<unsigned char>(uri[k + 2]))) {
          decoded += static_cast<char>(std::stoi(uri.substr(k + 1, 2), nullptr, 16));
          k += 2;
        } else {
          decoded += uri[k];
        }
      }
      if (!names_file_inside_folder(decoded))
        throw Error(path + ": " + std::string(kind).substr(0, std::strlen(kind) - 1) + " " + std::to_string(i) +
                    ": uri '" + uri + "' lies outside the scene's folder (a scene may only name files beside it or below it)");
    }
  }
}

// tinygltf reads buffers and images through these: confined to the scene's folder,
// regular files only, never blocking, size-limited (safe_file.h).
struct SceneFolder {
  std::filesystem::path folder;
};

bool scene_file_exists(const std::string& path, void*) {
  std::error_code ec;
  return std::filesystem::exists(std::filesystem::symlink_status(path, ec));
}

std::string scene_file_path(const std::string& path, void*) { return path; }  // no ~ or $VAR expansion

bool read_scene_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
  try {
    *out = read_file_inside(path, static_cast<SceneFolder*>(user)->folder, kMaxSceneFileBytes);
    return true;
  } catch (const Error& e) {
    if (err) *err += std::string(e.what()) + "\n";
    return false;
  }
}

bool refuse_write(std::string* err, const std::string& path, const std::vector<unsigned char>&, void*) {
  if (err) *err += path + ": the kit never writes scene files\n";
  return false;
}

// A file that requires an extension the kit does not implement would render
// wrongly or fail later with an unrelated message (a Draco mesh has no
// bufferView): it is refused up front, by the extension's name.
void check_required_extensions(const tinygltf::Model& model, const std::string& path) {
  static const char* const kSupported[] = {"KHR_lights_punctual", "KHR_materials_emissive_strength"};
  for (const std::string& name : model.extensionsRequired) {
    if (std::find(std::begin(kSupported), std::end(kSupported), name) != std::end(kSupported)) continue;
    std::string hint = name == "KHR_draco_mesh_compression" || name == "EXT_meshopt_compression"
                           ? " (its meshes are compressed: save the model uncompressed, e.g. with a glTF tool's --no-compression option)"
                           : "";
    throw Error(path + ": requires the glTF extension " + name + ", which the kit does not support" + hint +
                "; supported: KHR_lights_punctual, KHR_materials_emissive_strength");
  }
}

Scene load_scene_unguarded(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(std::filesystem::symlink_status(path, ec))) throw Error(path + ": scene file not found");
  std::vector<unsigned char> bytes = read_regular_file(path, kMaxSceneFileBytes);
  bool binary = path.size() > 4 && path.compare(path.size() - 4, 4, ".glb") == 0;
  // The JSON text (a .glb's first chunk): its depth, then the files it names.
  const unsigned char* json_text = bytes.data();
  size_t json_size = bytes.size();
  if (binary) {
    json_size = glb_json_chunk(bytes, path);
    json_text = bytes.data() + kGlbJsonOffset;
  }
  check_json_depth(json_text, json_size, path);
  check_uris(json_text, json_size, path);

  SceneFolder folder{std::filesystem::absolute(path).parent_path()};
  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(decode_image_with_oiio, nullptr);
  tinygltf::FsCallbacks files{};
  files.FileExists = scene_file_exists;
  files.ExpandFilePath = scene_file_path;
  files.ReadWholeFile = read_scene_file;
  files.WriteWholeFile = refuse_write;
  files.user_data = &folder;
  loader.SetFsCallbacks(files);
  std::string err, warn;
  const std::string base = folder.folder.string();
  bool ok = binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(), static_cast<unsigned>(bytes.size()), base)
                   : loader.LoadASCIIFromString(&model, &err, &warn, reinterpret_cast<const char*>(bytes.data()),
                                                static_cast<unsigned>(bytes.size()), base);
  if (!ok || !err.empty()) {
    while (!err.empty() && err.back() == '\n') err.pop_back();
    throw Error(path + ": invalid glTF: " + (err.empty() ? std::string("the file could not be parsed") : err));
  }
  check_required_extensions(model, path);
  return SceneBuilder(model, path).build();
}

}  // namespace

glm::mat4 Camera::projection(float aspect) const { return glm::perspective(yfov, aspect, znear, zfar); }

Scene load_scene(const std::string& path) {
  // Whatever the file makes the loader do, the message names the file: a
  // bad_alloc or length_error from a size the file asked for becomes a kit::Error.
  try {
    if (is_obj_path(path)) return load_obj_scene(path);
    return load_scene_unguarded(path);
  } catch (const Error&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw Error(path + ": the scene asks for more memory than there is (a size in the file is too large)");
  } catch (const std::exception& e) {
    throw Error(path + ": the scene could not be loaded: " + e.what());
  }
}

void generate_tangents(std::vector<Vertex>& vertices, const std::vector<uint32_t>& indices) {
  std::vector<glm::vec3> tan(vertices.size(), glm::vec3(0.0f)), bitan(vertices.size(), glm::vec3(0.0f));
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    const Vertex& a = vertices[indices[t]];
    const Vertex& b = vertices[indices[t + 1]];
    const Vertex& c = vertices[indices[t + 2]];
    glm::vec3 e1 = b.position - a.position, e2 = c.position - a.position;
    glm::vec2 d1 = b.texcoord - a.texcoord, d2 = c.texcoord - a.texcoord;
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

SceneGpu::SceneGpu(const Scene& scene) {
  for (const Primitive& p : scene.primitives) meshes_.emplace_back(p.vertices, p.indices);
  for (const ImageRgba8& img : scene.images) {
    // Images are stored top row first, which is what glTF UVs (v = 0 at the top) expect
    // when uploaded as-is: GL's first row is then sampled at v = 0.
    srgb_.emplace_back(img.width, img.height, TextureFormat{GL_SRGB8_ALPHA8, GL_RGBA, GL_UNSIGNED_BYTE}, img.pixels.data(), true);
    linear_.emplace_back(img.width, img.height, TextureFormat{GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE}, img.pixels.data(), true);
  }
  for (auto* list : {&srgb_, &linear_})
    for (auto& t : *list) t.set_wrap(GL_REPEAT, GL_REPEAT);
  const unsigned char white[4] = {255, 255, 255, 255};
  const unsigned char flat[4] = {128, 128, 255, 255};
  white_ = Texture2D(1, 1, {GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE}, white);
  flat_normal_ = Texture2D(1, 1, {GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE}, flat);
  check_gl("SceneGpu upload");
}

const Texture2D& SceneGpu::texture(int image, bool srgb) const {
  if (image < 0) return white_;
  return (srgb ? srgb_ : linear_)[static_cast<size_t>(image)];
}

}  // namespace kit

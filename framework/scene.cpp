#include "scene.h"

#include <tiny_gltf.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <type_traits>
#include <mutex>
#include <new>
#include <optional>
#include <sstream>
#include <system_error>
#include <thread>

#include <malloc.h>  // malloc_trim

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "draco_mesh.h"
#include "error.h"
#include "gbuffer_layout.h"
#include "obj_scene.h"
#include "safe_file.h"
#include "texture_decode.h"
#include "texture_prepare.h"

namespace kit {

namespace {

// Limits on what a scene file may ask for (documented in scene.h).
constexpr std::uintmax_t kMaxSceneFileBytes = std::uintmax_t(1) << 30;  // a .gltf/.glb, a buffer or an image file
constexpr int kMaxJsonDepth = 64;       // glTF itself nests 7 deep; tinygltf's JSON parser recurses per level
constexpr int kMaxNodeDepth = 256;      // the node hierarchy is walked recursively
constexpr int kMaxTexcoordSet = 7;      // TEXCOORD_0 to TEXCOORD_7: more than any exporter writes
// Where a Draco primitive's index accessor waits while tinygltf parses (move_draco_indices).
constexpr const char* kDracoIndicesKey = "kit_indices";

// ---- images: tinygltf hands us the bytes; only the header is read here ----
// SceneGpu decodes the images materials use, once each (texture_decode.h).
bool keep_encoded_image(tinygltf::Image* image, const int index, std::string* err, std::string*, int, int,
                        const unsigned char* bytes, int size, void*) {
  try {
    const size_t byte_count = size > 0 ? static_cast<size_t>(size) : 0;
    TextureHeader header =
        read_texture_header(bytes, byte_count, "image " + std::to_string(index) + " ('" + image->uri + "')");
    image->width = header.width;
    image->height = header.height;
    image->image.assign(bytes, bytes + byte_count);
    return true;
  } catch (const Error& e) {
    if (err) *err += e.what();
    return false;
  }
}

// ---- accessors, read with every bound checked ----

// The component types an accessor may have, as bits, so that each attribute can
// say which it accepts (glTF 2.0 "Meshes" table, widened by KHR_mesh_quantization).
enum ComponentFormat : unsigned {
  kFloatComponents = 1u,
  kUnsignedNormalized = 2u,  // UNSIGNED_BYTE/SHORT, normalized: c / 255, c / 65535
  kSignedNormalized = 4u,    // BYTE/SHORT, normalized: max(c / 127, -1), max(c / 32767, -1)
  kPlainIntegers = 8u,       // any 8- or 16-bit integer, not normalized: its value
};
constexpr unsigned kAnyInteger = kUnsignedNormalized | kSignedNormalized | kPlainIntegers;

struct AttributeFormats {
  unsigned core;       // what glTF 2.0 itself allows
  unsigned quantized;  // what a file using KHR_mesh_quantization may use
};
// POSITION (and EXT_mesh_gpu_instancing's TRANSLATION and SCALE)
constexpr AttributeFormats kPositionFormats{kFloatComponents, kFloatComponents | kAnyInteger};
// NORMAL and TANGENT
constexpr AttributeFormats kDirectionFormats{kFloatComponents, kFloatComponents | kSignedNormalized};
constexpr AttributeFormats kTexcoordFormats{kFloatComponents | kUnsignedNormalized, kFloatComponents | kAnyInteger};
// COLOR_0 (KHR_mesh_quantization widens nothing for it)
constexpr AttributeFormats kColorFormats{kFloatComponents | kUnsignedNormalized, kFloatComponents | kUnsignedNormalized};
// EXT_mesh_gpu_instancing's ROTATION (a unit quaternion)
constexpr AttributeFormats kRotationFormats{kFloatComponents | kSignedNormalized, kFloatComponents | kSignedNormalized};

unsigned component_format(const tinygltf::Accessor& acc) {
  switch (acc.componentType) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return kFloatComponents;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return acc.normalized ? kUnsignedNormalized : kPlainIntegers;
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_SHORT: return acc.normalized ? kSignedNormalized : kPlainIntegers;
    default: return 0;  // UNSIGNED_INT is for indices only
  }
}

std::string component_type_name(const tinygltf::Accessor& acc) {
  std::string name;
  switch (acc.componentType) {
    case TINYGLTF_COMPONENT_TYPE_FLOAT: return "FLOAT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: name = "UNSIGNED_BYTE"; break;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: name = "UNSIGNED_SHORT"; break;
    case TINYGLTF_COMPONENT_TYPE_BYTE: name = "BYTE"; break;
    case TINYGLTF_COMPONENT_TYPE_SHORT: name = "SHORT"; break;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: name = "UNSIGNED_INT"; break;
    default: return std::to_string(acc.componentType);
  }
  return (acc.normalized ? "normalized " : "") + name;
}

std::string accessor_type_name(int type) {
  switch (type) {
    case TINYGLTF_TYPE_SCALAR: return "SCALAR";
    case TINYGLTF_TYPE_VEC2: return "VEC2";
    case TINYGLTF_TYPE_VEC3: return "VEC3";
    case TINYGLTF_TYPE_VEC4: return "VEC4";
    case TINYGLTF_TYPE_MAT2: return "MAT2";
    case TINYGLTF_TYPE_MAT3: return "MAT3";
    case TINYGLTF_TYPE_MAT4: return "MAT4";
    default: return "type " + std::to_string(type);
  }
}

// One component as glTF 2.0 "Animations" / "Meshes" decode it: a normalized
// integer maps to [0, 1] or [-1, 1] (the most negative value clamps to -1).
float decode_component(const unsigned char* bytes, int component_type, bool normalized) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return normalized ? bytes[0] / 255.0f : bytes[0];
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
      int8_t c;
      std::memcpy(&c, bytes, 1);
      return normalized ? std::max(c / 127.0f, -1.0f) : c;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
      uint16_t c;
      std::memcpy(&c, bytes, 2);
      return normalized ? c / 65535.0f : c;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
      int16_t c;
      std::memcpy(&c, bytes, 2);
      return normalized ? std::max(c / 32767.0f, -1.0f) : c;
    }
    default: {  // FLOAT: the only other type component_format lets through
      float v;
      std::memcpy(&v, bytes, 4);
      return v;
    }
  }
}

// A 1-, 2- or 4-byte unsigned integer, little-endian as glTF requires.
uint32_t read_unsigned(const unsigned char* bytes, size_t size) {
  uint32_t v = 0;
  std::memcpy(&v, bytes, size);
  return v;
}

// The byte size of an index (indices and sparse indices), 0 for another type.
size_t index_size(int component_type) {
  switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return 1;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return 2;
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return 4;
    default: return 0;
  }
}

struct AccessorReader {
  const tinygltf::Model& model;
  const std::string& path;
  bool quantized;  // the file uses KHR_mesh_quantization

  [[noreturn]] void fail(const std::string& what) const { throw Error(path + ": " + what); }

  // Reads `components` values per element as floats, decoded from any component
  // type `formats` allows. With `decoded` (KHR_draco_mesh_compression), the values are
  // Draco's, which must agree with the accessor's count, type and component type.
  std::vector<float> floats(int index, int type, int components, AttributeFormats formats, const std::string& what,
                            const DracoAttribute* decoded = nullptr) const {
    const tinygltf::Accessor& acc = accessor(index, what);
    const std::string name = what + ": accessor " + std::to_string(index);
    if (acc.type != type) fail(name + " has the wrong type (expected " + std::to_string(components) + " components)");
    const unsigned format = component_format(acc);
    if (!(format & (quantized ? formats.quantized : formats.core)))
      fail(name + " has an unsupported component type " + component_type_name(acc) +
           (format & formats.quantized ? " (allowed only in a file that uses KHR_mesh_quantization)" : ""));
    if (decoded) check_agrees_with_draco(acc, components, *decoded, name);
    const size_t component_size = tinygltf::GetComponentSizeInBytes(static_cast<uint32_t>(acc.componentType));
    return elements<float>(acc, component_size * static_cast<size_t>(components), static_cast<size_t>(components), name,
                           decoded ? decoded->bytes.data() : nullptr, [&](const unsigned char* element, float* out) {
                             for (int c = 0; c < components; ++c)
                               out[c] = decode_component(element + static_cast<size_t>(c) * component_size,
                                                         acc.componentType, acc.normalized);
                           });
  }

  // With `decoded` (a Draco mesh's triangle corners), those are the indices, and
  // the accessor's count must agree with them.
  std::vector<uint32_t> indices(int index, const std::string& what, const std::vector<uint32_t>* decoded = nullptr) const {
    const tinygltf::Accessor& acc = accessor(index, what);
    const std::string name = what + ": index accessor " + std::to_string(index);
    if (acc.type != TINYGLTF_TYPE_SCALAR) fail(name + " is not SCALAR");
    const size_t size = index_size(acc.componentType);
    if (size == 0) fail(name + " has an unsupported component type " + component_type_name(acc));
    if (decoded) {
      if (acc.count != decoded->size())
        fail(name + " has count " + std::to_string(acc.count) + ", but the Draco mesh decoded " +
             std::to_string(decoded->size() / 3) + " triangles (" + std::to_string(decoded->size()) + " indices)");
      return *decoded;
    }
    return elements<uint32_t>(acc, size, 1, name, nullptr, [&](const unsigned char* element, uint32_t* out) {
      *out = read_unsigned(element, size);
    });
  }

  const tinygltf::Accessor& accessor(int index, const std::string& what) const {
    if (index < 0 || index >= static_cast<int>(model.accessors.size()))
      fail(what + ": accessor index " + std::to_string(index) + " does not exist");
    return model.accessors[static_cast<size_t>(index)];
  }

  // The accessor of a KHR_draco_mesh_compression attribute describes what Draco
  // decoded; where they disagree, the file is wrong about one of them.
  void check_agrees_with_draco(const tinygltf::Accessor& acc, int components, const DracoAttribute& decoded,
                               const std::string& name) const {
    if (acc.count != decoded.count)
      fail(name + " has count " + std::to_string(acc.count) + ", but the Draco mesh decoded " +
           std::to_string(decoded.count) + " points");
    if (decoded.components != components)
      fail(name + " has " + std::to_string(components) + " components, but Draco decoded " +
           std::to_string(decoded.components));
    if (decoded.component_type != acc.componentType) {
      tinygltf::Accessor draco_type;
      draco_type.componentType = decoded.component_type;
      fail(name + " has component type " + component_type_name(acc) + ", but Draco decoded " +
           component_type_name(draco_type));
    }
  }

  // An accessor's elements, each decoded by `decode` (its bytes -> `components`
  // values): read from `decoded` (tightly packed: a Draco attribute, its count
  // checked) or else from its bufferView, or zeros when it has none, then replaced
  // where its sparse part says (glTF 2.0 "Sparse Accessors").
  template <typename T, typename Decode>
  std::vector<T> elements(const tinygltf::Accessor& acc, size_t element_size, size_t components, const std::string& name,
                          const unsigned char* decoded, const Decode& decode) const {
    size_t stride = element_size;
    const unsigned char* base = decoded;  // its count is the accessor's (check_agrees_with_draco)
    if (!decoded && acc.bufferView >= 0)
      base = view_bytes(acc.bufferView, acc.byteOffset, acc.count, element_size, true, name, "", &stride);
    else if (!decoded && acc.count > kMaxSceneFileBytes / element_size)  // zeros, with no file bytes behind them
      fail(name + " has no bufferView and " + std::to_string(acc.count) + " elements of " + std::to_string(element_size) +
           " bytes (more than the " + std::to_string(kMaxSceneFileBytes) + " bytes the kit reads of a buffer)");
    // From here count is bounded by bytes in memory, so count * components (<= 4) cannot wrap.
    std::vector<T> out(acc.count * components, T(0));
    for (size_t i = 0; base && i < acc.count; ++i) decode(base + i * stride, &out[i * components]);
    if (acc.sparse.isSparse) {
      const auto& sparse = acc.sparse;
      if (sparse.count < 1 || static_cast<size_t>(sparse.count) > acc.count)
        fail(name + ": sparse count " + std::to_string(sparse.count) + " is not between 1 and the accessor's count (" +
             std::to_string(acc.count) + ")");
      if (sparse.indices.byteOffset < 0 || sparse.values.byteOffset < 0)
        fail(name + ": sparse indices or values have a negative byteOffset");
      const size_t count = static_cast<size_t>(sparse.count);
      const size_t indices_size = index_size(sparse.indices.componentType);
      if (indices_size == 0)
        fail(name + ": sparse indices have an unsupported component type " + std::to_string(sparse.indices.componentType));
      size_t unused_stride = 0;  // sparse indices and values are tightly packed
      const unsigned char* indices = view_bytes(sparse.indices.bufferView, static_cast<size_t>(sparse.indices.byteOffset),
                                                count, indices_size, false, name, "sparse indices ", &unused_stride);
      const unsigned char* values = view_bytes(sparse.values.bufferView, static_cast<size_t>(sparse.values.byteOffset),
                                               count, element_size, false, name, "sparse values ", &unused_stride);
      for (size_t i = 0; i < count; ++i) {
        const uint32_t target = read_unsigned(indices + i * indices_size, indices_size);
        if (target >= acc.count)
          fail(name + ": sparse index " + std::to_string(target) + " at position " + std::to_string(i) +
               " is out of range (the accessor has " + std::to_string(acc.count) + " elements)");
        decode(values + i * element_size, &out[target * components]);
      }
    }
    return out;
  }

  // Where `count` elements of `element_size` bytes start in bufferView `view_index`,
  // `byte_offset` bytes in; *stride gets the distance between elements (the view's
  // byteStride when `strided` and it has one, else the element size). `part` names
  // what is read when it is not the accessor's own data ("sparse indices ").
  const unsigned char* view_bytes(int view_index, size_t byte_offset, size_t count, size_t element_size, bool strided,
                                  const std::string& name, const std::string& part, size_t* stride) const {
    if (view_index < 0 || view_index >= static_cast<int>(model.bufferViews.size()))
      fail(name + ": " + part + "bufferView " + std::to_string(view_index) + " does not exist");
    const tinygltf::BufferView& view = model.bufferViews[static_cast<size_t>(view_index)];
    if (view.buffer < 0 || view.buffer >= static_cast<int>(model.buffers.size()))
      fail(name + ": bufferView " + std::to_string(view_index) + " names no valid buffer");
    const tinygltf::Buffer& buffer = model.buffers[static_cast<size_t>(view.buffer)];
    *stride = strided && view.byteStride ? view.byteStride : element_size;
    if (*stride < element_size)
      fail(name + ": bufferView " + std::to_string(view_index) + " has byteStride " + std::to_string(*stride) +
           ", less than one element (" + std::to_string(element_size) + " bytes)");
    // Every number below comes from the file: each comparison is arranged so that no
    // sum or product can wrap around (a count near 2^64 must fail here, not in a loop).
    const size_t size = buffer.data.size();
    if (view.byteOffset > size || view.byteLength > size - view.byteOffset)
      fail(name + ": bufferView " + std::to_string(view_index) + " (offset " + std::to_string(view.byteOffset) +
           ", length " + std::to_string(view.byteLength) + ") lies outside buffer " + std::to_string(view.buffer) +
           " (" + std::to_string(size) + " bytes)");
    if (byte_offset > view.byteLength)
      fail(name + ": " + part + "byteOffset " + std::to_string(byte_offset) + " lies past its bufferView (" +
           std::to_string(view.byteLength) + " bytes)");
    const size_t available = view.byteLength - byte_offset;
    if (count > 0 && (element_size > available || count - 1 > (available - element_size) / *stride))
      fail(name + ": " + part + "reads past the end of its buffer (" + std::to_string(count) + " elements of " +
           std::to_string(element_size) + " bytes every " + std::to_string(*stride) + " from byte " +
           std::to_string(byte_offset) + " of a " + std::to_string(view.byteLength) + "-byte bufferView; buffer " +
           std::to_string(view.buffer) + " has " + std::to_string(size) + " bytes)");
    return buffer.data.data() + view.byteOffset + byte_offset;
  }
};

// Whether the file lists `name` among the extensions it uses (or requires).
bool uses_extension(const tinygltf::Model& model, const std::string& name) {
  for (const auto* list : {&model.extensionsUsed, &model.extensionsRequired})
    if (std::find(list->begin(), list->end(), name) != list->end()) return true;
  return false;
}

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

// A material's texture: its image and sampler (-1 each when the material has none;
// sampler -1 also when the texture names none).
struct TextureSource {
  int image = -1, sampler = -1;
};
TextureSource texture_source(const tinygltf::Model& model, int texture, const std::string& path) {
  if (texture < 0) return {};
  if (texture >= static_cast<int>(model.textures.size()))
    throw Error(path + ": texture index " + std::to_string(texture) + " does not exist");
  const tinygltf::Texture& t = model.textures[static_cast<size_t>(texture)];
  if (t.source < 0 || t.source >= static_cast<int>(model.images.size()))
    throw Error(path + ": texture " + std::to_string(texture) + " has no valid image source");
  if (t.sampler >= static_cast<int>(model.samplers.size()))
    throw Error(path + ": texture " + std::to_string(texture) + " names sampler " + std::to_string(t.sampler) +
                ", which does not exist");
  return {t.source, std::max(t.sampler, -1)};
}

// A glTF sampler with its values checked; an undefined filter is the default's.
TextureSampler texture_sampler(const tinygltf::Sampler& s, size_t index, const std::string& path) {
  auto check = [&](int value, const char* field, std::initializer_list<int> allowed, const char* names) {
    if (std::find(allowed.begin(), allowed.end(), value) == allowed.end())
      throw Error(path + ": sampler " + std::to_string(index) + " has " + field + " " + std::to_string(value) +
                  " (glTF allows " + names + ")");
    return static_cast<GLenum>(value);
  };
  constexpr const char* kWraps = "33071 CLAMP_TO_EDGE, 33648 MIRRORED_REPEAT, 10497 REPEAT";
  TextureSampler out;
  out.wrap_s = check(s.wrapS, "wrapS", {GL_CLAMP_TO_EDGE, GL_MIRRORED_REPEAT, GL_REPEAT}, kWraps);
  out.wrap_t = check(s.wrapT, "wrapT", {GL_CLAMP_TO_EDGE, GL_MIRRORED_REPEAT, GL_REPEAT}, kWraps);
  if (s.magFilter != -1) out.mag_filter = check(s.magFilter, "magFilter", {GL_NEAREST, GL_LINEAR}, "9728 NEAREST, 9729 LINEAR");
  if (s.minFilter != -1)
    out.min_filter = check(s.minFilter, "minFilter",
                           {GL_NEAREST, GL_LINEAR, GL_NEAREST_MIPMAP_NEAREST, GL_LINEAR_MIPMAP_NEAREST,
                            GL_NEAREST_MIPMAP_LINEAR, GL_LINEAR_MIPMAP_LINEAR},
                           "9728 NEAREST, 9729 LINEAR, 9984 to 9987 the mipmapped filters");
  return out;
}

class SceneBuilder {
 public:
  SceneBuilder(const tinygltf::Model& model, const std::string& path) : model_(model), path_(path), reader_{model, path, uses_extension(model, "KHR_mesh_quantization")} {}

  Scene build() {
    scene_.path = path_;
    for (size_t i = 0; i < model_.images.size(); ++i) {
      const tinygltf::Image& img = model_.images[i];
      if (img.image.empty() || img.width <= 0 || img.height <= 0) throw Error(path_ + ": image '" + img.uri + "' has no pixels");
      scene_.images.push_back({path_ + ": image " + std::to_string(i) + " ('" + img.uri + "')", img.width, img.height,
                               img.image, {}});
    }
    for (size_t i = 0; i < model_.samplers.size(); ++i) scene_.samplers.push_back(texture_sampler(model_.samplers[i], i, path_));
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
    if (!scene_.cameras.empty()) scene_.camera = scene_.cameras.front();
    set_bounds_from_draws(scene_);
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
    out.alpha_mode = alpha_mode(m.alphaMode, m.name);
    out.alpha_cutoff = static_cast<float>(m.alphaCutoff);
    out.double_sided = m.doubleSided;
    const TextureSource base_color = texture_source(model_, pbr.baseColorTexture.index, path_);
    const TextureSource metallic_roughness = texture_source(model_, pbr.metallicRoughnessTexture.index, path_);
    const TextureSource normal = texture_source(model_, m.normalTexture.index, path_);
    const TextureSource emissive = texture_source(model_, m.emissiveTexture.index, path_);
    out.base_color_image = base_color.image;
    out.base_color_sampler = base_color.sampler;
    out.metallic_roughness_image = metallic_roughness.image;
    out.metallic_roughness_sampler = metallic_roughness.sampler;
    out.normal_image = normal.image;
    out.normal_sampler = normal.sampler;
    out.emissive_image = emissive.image;
    out.emissive_sampler = emissive.sampler;
    uv_mapping(m, out);
    return out;
  }

  // Each texture's TextureUv and Material::uv_set_of_slot: the UV sets the
  // textures name go into the vertex's two UV slots, in the order the textures are
  // listed; a third distinct set is refused, as a vertex carries two.
  void uv_mapping(const tinygltf::Material& m, Material& out) {
    struct Slot {
      const char* name;
      int index, texcoord;
      const tinygltf::ExtensionMap& extensions;
      TextureUv& uv;
    };
    const auto& pbr = m.pbrMetallicRoughness;
    const Slot slots[] = {
        {"baseColorTexture", pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord, pbr.baseColorTexture.extensions,
         out.base_color_uv},
        {"metallicRoughnessTexture", pbr.metallicRoughnessTexture.index, pbr.metallicRoughnessTexture.texCoord,
         pbr.metallicRoughnessTexture.extensions, out.metallic_roughness_uv},
        {"normalTexture", m.normalTexture.index, m.normalTexture.texCoord, m.normalTexture.extensions, out.normal_uv},
        {"emissiveTexture", m.emissiveTexture.index, m.emissiveTexture.texCoord, m.emissiveTexture.extensions,
         out.emissive_uv}};
    const std::string what = path_ + ": material '" + m.name + "'";
    out.uv_set_of_slot = {-1, -1};
    for (const Slot& slot : slots) {
      if (slot.index < 0) continue;
      int set = slot.texcoord;
      slot.uv.transform = texture_transform(slot.extensions, what + " " + slot.name, set);
      if (set < 0 || set > kMaxTexcoordSet)
        throw Error(what + " " + slot.name + ": texCoord " + std::to_string(set) + " is not a UV set the kit reads (0 to " +
                    std::to_string(kMaxTexcoordSet) + ")");
      if (out.uv_set_of_slot[0] < 0 || set == out.uv_set_of_slot[0]) {
        out.uv_set_of_slot[0] = set;
        slot.uv.slot = 0;
      } else if (out.uv_set_of_slot[1] < 0 || set == out.uv_set_of_slot[1]) {
        out.uv_set_of_slot[1] = set;
        slot.uv.slot = 1;
      } else {
        throw Error(what + " " + slot.name + ": texCoord " + std::to_string(set) + " is a third UV set for one material (TEXCOORD_" +
                    std::to_string(out.uv_set_of_slot[0]) + " and TEXCOORD_" + std::to_string(out.uv_set_of_slot[1]) +
                    " are read already); a vertex carries two");
      }
    }
    if (out.uv_set_of_slot[0] < 0) out.uv_set_of_slot[0] = 0;  // no texture: TEXCOORD_0, as a material without a file has
  }

  // KHR_texture_transform of a texture reference as its matrix
  // (texture_transform_matrix), and its texCoord override into `set`.
  static glm::mat3 texture_transform(const tinygltf::ExtensionMap& extensions, const std::string& what, int& set) {
    auto ext = extensions.find("KHR_texture_transform");
    if (ext == extensions.end()) return glm::mat3(1.0f);
    const tinygltf::Value& t = ext->second;
    auto number = [&](const tinygltf::Value& v, const std::string& field) {
      if (!v.IsNumber() || !std::isfinite(v.GetNumberAsDouble()))
        throw Error(what + ": KHR_texture_transform " + field + " is not a finite number");
      return static_cast<float>(v.GetNumberAsDouble());
    };
    auto pair = [&](const char* field, glm::vec2 fallback) {
      if (!t.Has(field)) return fallback;
      const tinygltf::Value& v = t.Get(field);
      if (!v.IsArray() || v.ArrayLen() != 2) throw Error(what + ": KHR_texture_transform " + field + " is not two numbers");
      return glm::vec2(number(v.Get(0), field), number(v.Get(1), field));
    };
    const glm::vec2 offset = pair("offset", glm::vec2(0.0f)), scale = pair("scale", glm::vec2(1.0f));
    const float rotation = t.Has("rotation") ? number(t.Get("rotation"), "rotation") : 0.0f;
    if (t.Has("texCoord")) {
      const double texcoord = t.Get("texCoord").IsNumber() ? t.Get("texCoord").GetNumberAsDouble() : -1.0;
      if (!(texcoord >= 0.0 && texcoord <= kMaxTexcoordSet && texcoord == std::floor(texcoord)))
        throw Error(what + ": KHR_texture_transform texCoord is not a UV set the kit reads (0 to " +
                    std::to_string(kMaxTexcoordSet) + ")");
      set = static_cast<int>(texcoord);
    }
    return texture_transform_matrix(offset, rotation, scale);
  }

  // glTF's alphaMode string; tinygltf fills in "OPAQUE" when it is absent.
  int alpha_mode(const std::string& mode, const std::string& material_name) {
    if (mode == "MASK") return KIT_ALPHA_MASK;
    if (mode == "BLEND") return KIT_ALPHA_BLEND;
    if (mode != "OPAQUE")
      scene_.warnings.push_back(path_ + ": material '" + material_name + "': alphaMode '" + mode +
                                "' is not glTF's (OPAQUE, MASK, BLEND); drawn as OPAQUE");
    return KIT_ALPHA_OPAQUE;
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
    auto attr = [&](const std::string& name) {
      auto it = p.attributes.find(name);
      return it == p.attributes.end() ? -1 : it->second;
    };
    const std::optional<DracoPrimitive> draco = draco_primitive(p, mode, what);
    // An attribute's values: Draco's when its mesh holds the attribute, else its accessor's.
    auto read = [&](const std::string& name, int type, int components, AttributeFormats formats) {
      std::optional<DracoAttribute> decoded;
      if (draco) {
        auto id = draco->unique_ids.find(name);
        if (id != draco->unique_ids.end()) decoded = draco->mesh.attribute(id->second, path_ + ": " + what + " " + name);
      }
      return reader_.floats(attr(name), type, components, formats, what + " " + name, decoded ? &*decoded : nullptr);
    };
    if (attr("POSITION") < 0) throw Error(path_ + ": " + what + ": has no POSITION attribute");
    std::vector<float> pos = read("POSITION", TINYGLTF_TYPE_VEC3, 3, kPositionFormats);
    size_t n = pos.size() / 3;
    // No NORMAL: glTF asks for flat normals, computed below once the triangles are known.
    const bool flat = attr("NORMAL") < 0;
    std::vector<float> nrm = flat ? std::vector<float>(pos.size(), 0.0f) : read("NORMAL", TINYGLTF_TYPE_VEC3, 3, kDirectionFormats);
    if (nrm.size() / 3 != n) throw Error(path_ + ": " + what + ": NORMAL count differs from POSITION count");
    std::vector<float> tan;
    const Material* material =
        p.material >= 0 && p.material < static_cast<int>(scene_.materials.size()) ? &scene_.materials[static_cast<size_t>(p.material)] : nullptr;
    // The UV sets its material's textures read, one per vertex UV slot. A missing
    // TEXCOORD_0 reads as zero (a texture then shows one texel), another missing set is refused.
    const std::array<int, 2> uv_sets = material ? material->uv_set_of_slot : std::array<int, 2>{0, -1};
    std::array<std::vector<float>, 2> uv;
    for (size_t slot = 0; slot < 2; ++slot) {
      if (uv_sets[slot] < 0) continue;
      const std::string uv_name = "TEXCOORD_" + std::to_string(uv_sets[slot]);
      if (attr(uv_name) >= 0)
        uv[slot] = read(uv_name, TINYGLTF_TYPE_VEC2, 2, kTexcoordFormats);
      else if (uv_sets[slot] != 0)
        throw Error(path_ + ": " + what + ": its material's textures read " + uv_name + ", which the primitive does not have");
    }
    if (attr("TANGENT") >= 0) tan = read("TANGENT", TINYGLTF_TYPE_VEC4, 4, kDirectionFormats);
    // COLOR_0 multiplies the base colour; VEC3 means alpha 1.
    std::vector<float> color;
    size_t color_components = 0;
    if (attr("COLOR_0") >= 0) {
      const std::string color_what = what + " COLOR_0";
      const tinygltf::Accessor& acc = reader_.accessor(attr("COLOR_0"), color_what);
      if (acc.type != TINYGLTF_TYPE_VEC3 && acc.type != TINYGLTF_TYPE_VEC4)
        throw Error(path_ + ": " + color_what + ": accessor " + std::to_string(attr("COLOR_0")) + " is " +
                    accessor_type_name(acc.type) + "; COLOR_0 must be VEC3 or VEC4");
      color_components = acc.type == TINYGLTF_TYPE_VEC3 ? 3 : 4;
      color = read("COLOR_0", acc.type, static_cast<int>(color_components), kColorFormats);
    }
    if ((!uv[0].empty() && uv[0].size() / 2 != n) || (!uv[1].empty() && uv[1].size() / 2 != n) || (!tan.empty() && tan.size() / 4 != n) ||
        (!color.empty() && color.size() / color_components != n))
      throw Error(path_ + ": " + what + ": attribute counts differ from POSITION count");

    Primitive out;
    out.name = what;
    out.material = p.material;
    if (p.material >= static_cast<int>(model_.materials.size())) throw Error(path_ + ": " + what + ": material index does not exist");
    out.vertices.resize(n);
    bool clamped_color = false;
    for (size_t i = 0; i < n; ++i) {
      Vertex& v = out.vertices[i];
      v.position = glm::vec3(pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]);
      v.normal = glm::vec3(nrm[3 * i], nrm[3 * i + 1], nrm[3 * i + 2]);
      if (!std::isfinite(v.position.x) || !std::isfinite(v.position.y) || !std::isfinite(v.position.z))
        throw Error(path_ + ": " + what + ": POSITION " + std::to_string(i) + " is not finite (NaN or Inf)");
      if (!std::isfinite(glm::dot(v.normal, v.normal)))
        throw Error(path_ + ": " + what + ": NORMAL " + std::to_string(i) + " is not finite (NaN or Inf)");
      v.texcoord = uv[0].empty() ? glm::vec2(0.0f) : glm::vec2(uv[0][2 * i], uv[0][2 * i + 1]);
      v.texcoord1 = uv[1].empty() ? glm::vec2(0.0f) : glm::vec2(uv[1][2 * i], uv[1][2 * i + 1]);
      v.tangent = tan.empty() ? glm::vec4(0.0f) : glm::vec4(tan[4 * i], tan[4 * i + 1], tan[4 * i + 2], tan[4 * i + 3]);
      for (size_t c = 0; c < color_components; ++c) {
        const float value = color[color_components * i + c];
        if (!std::isfinite(value))
          throw Error(path_ + ": " + what + ": COLOR_0 " + std::to_string(i) + " is not finite (NaN or Inf)");
        clamped_color |= value < 0.0f || value > 1.0f;
        v.color[static_cast<int>(c)] = vertex_color_component(value);
      }
    }
    if (clamped_color)
      scene_.warnings.push_back(path_ + ": " + what + ": COLOR_0 has FLOAT values outside [0, 1]; clamped to it");
    const int indices = index_accessor(p, what);
    if (draco) {
      const std::vector<uint32_t> corners = draco->mesh.triangle_indices();
      out.indices = indices >= 0 ? reader_.indices(indices, what + " indices", &corners) : corners;
    } else if (indices >= 0) {
      out.indices = reader_.indices(indices, what + " indices");
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
    set_bounds_from_vertices(out);
    if (flat) use_flat_normals(out);
    if (tan.empty()) {
      // Along the UVs the normal texture samples; without UVs, any frame around the normal.
      generate_tangents(out.vertices, out.indices, material ? material->normal_uv : TextureUv{});
      out.tangents_generated = true;
    }
    scene_.primitives.push_back(std::move(out));
    return static_cast<int>(scene_.primitives.size()) - 1;
  }

  // KHR_draco_mesh_compression: the primitive's mesh decoded from the extension's
  // bufferView, and the Draco unique id of each attribute it holds, by glTF name.
  // Without Draco support the extension is passed over: a file requiring it was
  // refused (check_required_extensions), one only using it has accessors to read.
  struct DracoPrimitive {
    DracoMesh mesh;
    std::map<std::string, uint32_t> unique_ids;
  };
  std::optional<DracoPrimitive> draco_primitive(const tinygltf::Primitive& p, int mode, const std::string& what) const {
    auto ext = p.extensions.find("KHR_draco_mesh_compression");
    if (ext == p.extensions.end() || !draco_supported()) return std::nullopt;
    const std::string name = what + " KHR_draco_mesh_compression";
    if (mode != TINYGLTF_MODE_TRIANGLES)
      throw Error(path_ + ": " + name + ": the primitive's mode is " + std::to_string(mode) +
                  "; a Draco mesh is a triangle list (mode 4)");
    const size_t view_index = static_cast<size_t>(index_in(ext->second.Get("bufferView"), model_.bufferViews.size(), name + " bufferView"));
    const tinygltf::Value& attributes = ext->second.Get("attributes");
    if (!attributes.IsObject()) throw Error(path_ + ": " + name + ": attributes is not an object");
    std::map<std::string, uint32_t> unique_ids;
    for (const std::string& attribute : attributes.Keys())
      unique_ids[attribute] = static_cast<uint32_t>(index_in(attributes.Get(attribute), std::numeric_limits<int>::max(),
                                                             name + " attribute " + attribute + ": unique id"));
    const size_t length = model_.bufferViews[view_index].byteLength;
    if (length == 0) throw Error(path_ + ": " + name + ": bufferView " + std::to_string(view_index) + " is empty");
    size_t stride = 0;
    const unsigned char* bytes = reader_.view_bytes(static_cast<int>(view_index), 0, 1, length, false, name, "", &stride);
    return DracoPrimitive{DracoMesh(bytes, length, path_ + ": " + name), std::move(unique_ids)};
  }

  // The primitive's index accessor, -1 when it has none. A Draco primitive's waits
  // in its extension object while tinygltf parses (move_draco_indices).
  int index_accessor(const tinygltf::Primitive& p, const std::string& what) const {
    auto ext = p.extensions.find("KHR_draco_mesh_compression");
    if (ext == p.extensions.end() || !ext->second.Has(kDracoIndicesKey)) return p.indices;
    return index_in(ext->second.Get(kDracoIndicesKey), model_.accessors.size(), what + " indices accessor");
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
      for (const glm::mat4& instance : instance_matrices(node, node_index))
        for (int prim : mesh_primitives_[static_cast<size_t>(node.mesh)]) {
          if (scene_.draws.size() >= kMaxSceneDraws)
            throw Error(path_ + ": node " + std::to_string(node_index) + " ('" + node.name + "'): the scene draws more than " +
                        std::to_string(kMaxSceneDraws) + " meshes (the kit's limit: each primitive of each node and "
                        "EXT_mesh_gpu_instancing instance is one draw)");
          scene_.draws.push_back({prim, world * instance});
        }
    }
    if (node.camera >= 0) camera(node, world);
    auto ext = node.extensions.find("KHR_lights_punctual");
    if (ext != node.extensions.end() && ext->second.Has("light")) light(index_in(ext->second.Get("light"), model_.lights.size(), "KHR_lights_punctual light index"), world);
    for (int child : node.children) visit(child, world, depth + 1);
  }

  void camera(const tinygltf::Node& node, const glm::mat4& world) {
    if (node.camera >= static_cast<int>(model_.cameras.size())) throw Error(path_ + ": node '" + node.name + "' names a camera that does not exist");
    const tinygltf::Camera& c = model_.cameras[static_cast<size_t>(node.camera)];
    const std::string what = path_ + ": camera " + std::to_string(node.camera) + " ('" + c.name + "')";
    auto positive = [](double v) { return v > 0.0 && std::isfinite(v); };
    Camera cam;
    cam.view = glm::inverse(world);
    cam.position = glm::vec3(world[3]);
    if (c.type == "perspective") {
      const tinygltf::PerspectiveCamera& p = c.perspective;
      if (!positive(p.yfov) || !(p.yfov < glm::pi<double>()))
        throw Error(what + " has yfov " + std::to_string(p.yfov) + " (must be between 0 and pi radians)");
      if (!positive(p.znear)) throw Error(what + " has znear " + std::to_string(p.znear) + " (must be > 0)");
      // Absent (0 in tinygltf): glTF's infinite projection; the kit's depth views need a finite far plane.
      if (p.zfar != 0.0 && !(positive(p.zfar) && p.zfar > p.znear))
        throw Error(what + " has zfar " + std::to_string(p.zfar) + " (must be greater than znear)");
      if (!(p.aspectRatio >= 0.0 && std::isfinite(p.aspectRatio)))
        throw Error(what + " has aspectRatio " + std::to_string(p.aspectRatio) + " (must be > 0, or left out)");
      cam.yfov = static_cast<float>(p.yfov);
      cam.znear = static_cast<float>(p.znear);
      cam.zfar = p.zfar > 0.0 ? static_cast<float>(p.zfar) : 1000.0f;
      cam.aspect_ratio = static_cast<float>(p.aspectRatio);
    } else if (c.type == "orthographic") {
      const tinygltf::OrthographicCamera& o = c.orthographic;
      if (o.xmag == 0.0 || o.ymag == 0.0 || !std::isfinite(o.xmag) || !std::isfinite(o.ymag))
        throw Error(what + " has xmag " + std::to_string(o.xmag) + " and ymag " + std::to_string(o.ymag) +
                    " (each must be a finite number other than 0)");
      if (!(o.znear >= 0.0 && positive(o.zfar) && o.zfar > o.znear))
        throw Error(what + " has znear " + std::to_string(o.znear) + " and zfar " + std::to_string(o.zfar) +
                    " (must be 0 <= znear < zfar)");
      cam.orthographic = true;
      cam.xmag = static_cast<float>(o.xmag);
      cam.ymag = static_cast<float>(o.ymag);
      cam.znear = static_cast<float>(o.znear);
      cam.zfar = static_cast<float>(o.zfar);
    } else {
      throw Error(what + " has type '" + c.type + "' (glTF cameras are perspective or orthographic)");
    }
    scene_.cameras.push_back(cam);
  }

  // An index an extension gives (a node's KHR_lights_punctual "light", ...): a whole
  // number below `count`. Read as a double and checked before it becomes an int:
  // tinygltf's GetNumberAsInt converts any double, which is undefined behaviour past
  // int's range (1e300). `what` names the index ("KHR_lights_punctual light index").
  int index_in(const tinygltf::Value& value, size_t count, const std::string& what) const {
    double index = value.IsNumber() ? value.GetNumberAsDouble() : -1.0;
    if (!(index >= 0.0 && index < static_cast<double>(count) && index == std::floor(index))) {
      std::ostringstream shown;
      if (value.IsNumber()) shown << index;
      else shown << "(not a number)";
      throw Error(path_ + ": " + what + " " + shown.str() + " does not exist");
    }
    return static_cast<int>(index);
  }

  // EXT_mesh_gpu_instancing: the node's mesh is drawn once per instance, at the
  // node's world matrix times the instance's T * R * S (each attribute optional).
  // A node without the extension has one instance, the identity.
  std::vector<glm::mat4> instance_matrices(const tinygltf::Node& node, int node_index) const {
    auto ext = node.extensions.find("EXT_mesh_gpu_instancing");
    if (ext == node.extensions.end()) return {glm::mat4(1.0f)};
    const std::string what = "node " + std::to_string(node_index) + " ('" + node.name + "') EXT_mesh_gpu_instancing";
    const tinygltf::Value& attributes = ext->second.Get("attributes");  // a null Value when absent
    struct Attribute {
      const char* name;
      int type, components;
      AttributeFormats formats;
      std::vector<float> values;
    };
    Attribute translation{"TRANSLATION", TINYGLTF_TYPE_VEC3, 3, kPositionFormats, {}};
    Attribute rotation{"ROTATION", TINYGLTF_TYPE_VEC4, 4, kRotationFormats, {}};
    Attribute scale{"SCALE", TINYGLTF_TYPE_VEC3, 3, kPositionFormats, {}};
    size_t count = 0;
    bool any = false;
    for (Attribute* a : {&translation, &rotation, &scale}) {
      if (!attributes.IsObject() || !attributes.Has(a->name)) continue;
      const std::string name = what + " " + a->name;
      const int accessor = index_in(attributes.Get(a->name), model_.accessors.size(), name + " accessor index");
      a->values = reader_.floats(accessor, a->type, a->components, a->formats, name);
      const size_t n = a->values.size() / static_cast<size_t>(a->components);
      if (any && n != count)
        throw Error(path_ + ": " + name + " has " + std::to_string(n) + " instances, the other attributes " +
                    std::to_string(count));
      count = n;
      any = true;
    }
    if (!any) throw Error(path_ + ": " + what + " has no TRANSLATION, ROTATION or SCALE attribute");
    if (count > kMaxSceneDraws)
      throw Error(path_ + ": " + what + " has " + std::to_string(count) + " instances, more than the kit draws (" +
                  std::to_string(kMaxSceneDraws) + " draws in all)");
    std::vector<glm::mat4> out(count, glm::mat4(1.0f));
    for (size_t i = 0; i < count; ++i) {
      glm::mat4& m = out[i];
      if (!translation.values.empty()) m = glm::translate(m, glm::make_vec3(&translation.values[3 * i]));
      if (!rotation.values.empty()) {
        const float* q = &rotation.values[4 * i];  // x, y, z, w
        // Normalized integer quaternions are unit only to their precision.
        const glm::quat unit = glm::normalize(glm::quat(q[3], q[0], q[1], q[2]));
        if (!std::isfinite(unit.w)) throw Error(path_ + ": " + what + " ROTATION " + std::to_string(i) + " is not a rotation");
        m *= glm::mat4_cast(unit);
      }
      if (!scale.values.empty()) m = glm::scale(m, glm::make_vec3(&scale.values[3 * i]));
    }
    return out;
  }

  void light(int index, const glm::mat4& world) {
    if (index < 0 || index >= static_cast<int>(model_.lights.size()))
      throw Error(path_ + ": KHR_lights_punctual light index " + std::to_string(index) + " does not exist");
    const tinygltf::Light& l = model_.lights[static_cast<size_t>(index)];
    const std::string what = path_ + ": KHR_lights_punctual light " + std::to_string(index);
    Light out;
    if (l.type == "point") out.type = KIT_LIGHT_POINT;
    else if (l.type == "spot") out.type = KIT_LIGHT_SPOT;
    else if (l.type == "directional") out.type = KIT_LIGHT_DIRECTIONAL;
    else throw Error(what + " has type '" + l.type + "' (must be point, spot or directional)");
    out.position = glm::vec3(world[3]);
    // Spot and directional lights shine along their node's -Z; a node scaled to
    // nothing gives no direction.
    out.direction = glm::normalize(glm::vec3(world * glm::vec4(0, 0, -1, 0)));
    if (out.type != KIT_LIGHT_POINT && !std::isfinite(out.direction.x + out.direction.y + out.direction.z))
      throw Error(what + " (" + l.type + ") is on a node whose transform has no -Z direction (a zero scale)");
    if (l.color.size() == 3) out.color = glm::vec3(l.color[0], l.color[1], l.color[2]);
    out.intensity = static_cast<float>(l.intensity);
    if (!std::isfinite(out.intensity) || out.intensity < 0.0f)
      throw Error(what + " has intensity " + std::to_string(l.intensity) + " (must be a finite value >= 0)");
    // glTF: range, when present, is > 0; tinygltf reads an absent one as 0 (unlimited).
    if (!(l.range >= 0.0) || !std::isfinite(l.range))
      throw Error(what + " has range " + std::to_string(l.range) +
                  " (must be a positive distance, or left out for unlimited)");
    // The spec: range does not apply to a directional light (it reaches everywhere).
    out.range = out.type == KIT_LIGHT_DIRECTIONAL ? 0.0f : static_cast<float>(l.range);
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

// Debian's tinygltf (2.7) refuses a primitive whose index accessor has no
// bufferView, and a Draco primitive's has none: its indices are in the Draco mesh.
// So before tinygltf sees the JSON, each Draco primitive's "indices" moves into its
// KHR_draco_mesh_compression object under kDracoIndicesKey, where the builder takes
// it back (SceneBuilder::index_accessor). Returns the JSON to parse, or nothing when
// no primitive needs it (the text is then parsed as it is).
std::optional<std::string> move_draco_indices(const unsigned char* json_text, size_t size) {
  static const std::string kName = "KHR_draco_mesh_compression";
  if (std::search(json_text, json_text + size, kName.begin(), kName.end()) == json_text + size) return std::nullopt;
  nlohmann::json doc = nlohmann::json::parse(json_text, json_text + size, nullptr, false);
  if (doc.is_discarded() || !doc.is_object() || !doc.contains("meshes") || !doc["meshes"].is_array()) return std::nullopt;
  bool moved = false;
  for (nlohmann::json& mesh : doc["meshes"]) {
    if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) continue;
    for (nlohmann::json& prim : mesh["primitives"]) {
      if (!prim.is_object() || !prim.contains("indices") || !prim.contains("extensions") ||
          !prim["extensions"].is_object() || !prim["extensions"].contains(kName) || !prim["extensions"][kName].is_object())
        continue;
      prim["extensions"][kName][kDracoIndicesKey] = prim["indices"];
      prim.erase("indices");
      moved = true;
    }
  }
  if (!moved) return std::nullopt;
  return doc.dump();
}

// A .glb's bytes with its JSON chunk replaced by `json` (padded with spaces to 4
// bytes, as the format asks); the chunks after it are kept as they are.
std::vector<unsigned char> glb_with_json(const std::vector<unsigned char>& glb, size_t old_json_length, std::string json,
                                         const std::string& path) {
  json.resize((json.size() + 3) / 4 * 4, ' ');
  const size_t rest = glb.size() - kGlbJsonOffset - old_json_length;  // glb_json_chunk checked the old length
  if (json.size() > std::numeric_limits<uint32_t>::max() - kGlbJsonOffset - rest)
    throw Error(path + ": invalid glTF: the JSON chunk grows past 4 GiB when its Draco primitives' indices move");
  std::vector<unsigned char> out(glb.begin(), glb.begin() + kGlbJsonOffset);
  const uint32_t total = static_cast<uint32_t>(kGlbJsonOffset + json.size() + rest), json_length = static_cast<uint32_t>(json.size());
  std::memcpy(out.data() + 8, &total, 4);
  std::memcpy(out.data() + 12, &json_length, 4);
  out.insert(out.end(), json.begin(), json.end());
  out.insert(out.end(), glb.begin() + static_cast<std::ptrdiff_t>(kGlbJsonOffset + old_json_length), glb.end());
  return out;
}

// tinygltf reads buffers and images through these: confined to the scene's folder,
// regular files only, never blocking, size-limited (safe_file.h).
struct SceneFolder {
  std::filesystem::path folder;
  // tinygltf 2.9 asks a file's size before it reads it (GetFileSizeInBytes): the size is
  // found by reading the file the safe way, and the bytes are kept here for the read
  // that follows, so no file is read twice.
  std::map<std::string, std::vector<unsigned char>> read_ahead;
};

bool scene_file_exists(const std::string& path, void*) {
  std::error_code ec;
  return std::filesystem::exists(std::filesystem::symlink_status(path, ec));
}

std::string scene_file_path(const std::string& path, void*) { return path; }  // no ~ or $VAR expansion

bool read_scene_file(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
  SceneFolder& folder = *static_cast<SceneFolder*>(user);
  auto ahead = folder.read_ahead.find(path);
  if (ahead != folder.read_ahead.end()) {
    *out = std::move(ahead->second);
    folder.read_ahead.erase(ahead);
    return true;
  }
  try {
    *out = read_file_inside(path, folder.folder, kMaxSceneFileBytes);
    return true;
  } catch (const Error& e) {
    if (err) *err += std::string(e.what()) + "\n";
    return false;
  }
}

// tinygltf 2.9's GetFileSizeInBytes: through read_scene_file's checks (a regular file
// inside the scene's folder, at most kMaxSceneFileBytes), never tinygltf's own, which
// opens any path it is given (a FIFO there waits forever).
bool scene_file_size(size_t* size, std::string* err, const std::string& path, void* user) {
  std::vector<unsigned char> bytes;
  if (!read_scene_file(&bytes, err, path, user)) return false;
  *size = bytes.size();
  static_cast<SceneFolder*>(user)->read_ahead[path] = std::move(bytes);
  return true;
}

// Debian 12's tinygltf 2.7 has four file callbacks and SetFsCallbacks returns
// nothing; Debian 13's 2.9 adds GetFileSizeInBytes, and SetFsCallbacks refuses callbacks
// without it (returning false) and keeps its own, which read any file: checked here,
// whichever the version.
template <typename Callbacks>
auto set_file_size_callback(Callbacks& files, int) -> decltype(files.GetFileSizeInBytes = scene_file_size, void()) {
  files.GetFileSizeInBytes = scene_file_size;
}
template <typename Callbacks>
void set_file_size_callback(Callbacks&, long) {}

template <typename Loader, typename Callbacks>
void install_file_callbacks(Loader& loader, const Callbacks& files, const std::string& path) {
  if constexpr (std::is_same_v<decltype(loader.SetFsCallbacks(files)), bool>) {
    std::string err;
    if (!loader.SetFsCallbacks(files, &err))
      throw Error(path + ": tinygltf refused the kit's file callbacks (" + err + ")");
  } else {
    loader.SetFsCallbacks(files);
  }
}

bool refuse_write(std::string* err, const std::string& path, const std::vector<unsigned char>&, void*) {
  if (err) *err += path + ": the kit never writes scene files\n";
  return false;
}

// A file that requires an extension the kit does not implement would render
// wrongly or fail later with an unrelated message (a Draco mesh's accessors have
// no bufferView): it is refused up front, by the extension's name. Draco is
// implemented when the build has libdraco (draco_mesh.h).
void check_required_extensions(const tinygltf::Model& model, const std::string& path) {
  std::vector<std::string> supported_names = {"KHR_lights_punctual", "KHR_materials_emissive_strength",
                                               "KHR_mesh_quantization", "EXT_mesh_gpu_instancing", "KHR_texture_transform"};
  if (draco_supported()) supported_names.push_back("KHR_draco_mesh_compression");
  for (const std::string& name : model.extensionsRequired) {
    if (std::find(supported_names.begin(), supported_names.end(), name) != supported_names.end()) continue;
    std::string supported;
    for (const std::string& known : supported_names) supported += (supported.empty() ? "" : ", ") + known;
    std::string hint = name == "KHR_draco_mesh_compression"
                           ? " (this build has no Draco decoder: install libdraco-dev and rebuild, or save the model "
                             "uncompressed, e.g. with a glTF tool's --no-compression option)"
                       : name == "EXT_meshopt_compression"
                           ? " (its meshes are compressed: save the model uncompressed, e.g. with a glTF tool's --no-compression option)"
                           : "";
    throw Error(path + ": requires the glTF extension " + name + ", which the kit does not support" + hint +
                "; supported: " + supported);
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
  // With or without Draco support: without it, a file requiring Draco is then refused by name.
  if (std::optional<std::string> json = move_draco_indices(json_text, json_size)) {
    if (binary) bytes = glb_with_json(bytes, json_size, std::move(*json), path);
    else bytes.assign(json->begin(), json->end());
  }

  SceneFolder folder{std::filesystem::absolute(path).parent_path(), {}};
  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(keep_encoded_image, nullptr);
  tinygltf::FsCallbacks files{};
  files.FileExists = scene_file_exists;
  files.ExpandFilePath = scene_file_path;
  files.ReadWholeFile = read_scene_file;
  files.WriteWholeFile = refuse_write;
  set_file_size_callback(files, 0);
  files.user_data = &folder;
  install_file_callbacks(loader, files, path);
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

glm::mat4 Camera::projection(float window_aspect) const {
  if (orthographic) return glm::ortho(-xmag, xmag, -ymag, ymag, znear, zfar);
  return glm::perspective(yfov, aspect_ratio > 0.0f ? aspect_ratio : window_aspect, znear, zfar);
}

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
  malloc_trim(0);  // the freed blocks lie among others in the heap: give their pages back
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

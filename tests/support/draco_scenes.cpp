#include "draco_scenes.h"

#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "kit_test_files.h"
#include "render/stages.h"

namespace kit::test {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr int kFloat = 5126, kUnsignedInt = 5125;  // glTF componentType

[[noreturn]] void fail(const fs::path& gltf, const std::string& what) {
  throw std::runtime_error("test fixture: " + gltf.string() + ": " + what);
}

// An accessor's 4-byte values, as the kit's scenes write them: tightly packed in a bufferView.
template <typename T>
std::vector<T> accessor_values(const json& doc, const std::string& bin, int index, int component_type, size_t components,
                               const fs::path& gltf) {
  const json& acc = doc["accessors"][static_cast<size_t>(index)];
  if (acc["componentType"].get<int>() != component_type || !acc.contains("bufferView"))
    fail(gltf, "accessor " + std::to_string(index) + " is not what the kit's scenes write");
  const json& view = doc["bufferViews"][acc["bufferView"].get<size_t>()];
  if (view.contains("byteStride")) fail(gltf, "accessor " + std::to_string(index) + " is interleaved");
  const size_t offset = view.value("byteOffset", size_t{0}) + acc.value("byteOffset", size_t{0});
  std::vector<T> values(acc["count"].get<size_t>() * components);
  if (offset + values.size() * sizeof(T) > bin.size()) fail(gltf, "accessor " + std::to_string(index) + " lies past the .bin");
  std::memcpy(values.data(), bin.data() + offset, values.size() * sizeof(T));
  return values;
}

size_t component_count(const std::string& type) {
  return type == "SCALAR" ? 1 : type == "VEC2" ? 2 : type == "VEC3" ? 3 : 4;
}

draco::GeometryAttribute::Type draco_type(const std::string& gltf_name) {
  if (gltf_name == "POSITION") return draco::GeometryAttribute::POSITION;
  if (gltf_name == "NORMAL") return draco::GeometryAttribute::NORMAL;
  if (gltf_name.rfind("TEXCOORD_", 0) == 0) return draco::GeometryAttribute::TEX_COORD;
  return draco::GeometryAttribute::GENERIC;  // TANGENT
}

// The primitive's mesh encoded by Draco; its attributes' unique ids go into *ids.
std::string encode_primitive(const json& doc, const std::string& bin, const json& prim, int position_bits, json* ids,
                             const fs::path& gltf) {
  draco::Mesh mesh;
  const size_t points = doc["accessors"][prim["attributes"]["POSITION"].get<size_t>()]["count"].get<size_t>();
  mesh.set_num_points(static_cast<uint32_t>(points));
  for (const auto& [name, index] : prim["attributes"].items()) {
    const json& acc = doc["accessors"][index.get<size_t>()];
    const size_t components = component_count(acc["type"].get<std::string>());
    const std::vector<float> values = accessor_values<float>(doc, bin, index.get<int>(), kFloat, components, gltf);
    if (values.size() != points * components) fail(gltf, name + " has another count than POSITION");
    draco::GeometryAttribute attribute;
    attribute.Init(draco_type(name), nullptr, static_cast<uint8_t>(components), draco::DT_FLOAT32, false,
                   static_cast<int64_t>(sizeof(float) * components), 0);
    draco::PointAttribute* added = mesh.attribute(mesh.AddAttribute(attribute, true, static_cast<uint32_t>(points)));
    for (size_t i = 0; i < points; ++i)
      added->SetAttributeValue(draco::AttributeValueIndex(static_cast<uint32_t>(i)), &values[i * components]);
    (*ids)[name] = added->unique_id();
  }
  const std::vector<uint32_t> indices = accessor_values<uint32_t>(doc, bin, prim["indices"].get<int>(), kUnsignedInt, 1, gltf);
  for (size_t t = 0; t + 2 < indices.size(); t += 3)
    mesh.AddFace({draco::PointIndex(indices[t]), draco::PointIndex(indices[t + 1]), draco::PointIndex(indices[t + 2])});

  draco::Encoder encoder;
  encoder.SetEncodingMethod(draco::MESH_SEQUENTIAL_ENCODING);
  if (position_bits > 0) encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, position_bits);
  draco::EncoderBuffer encoded;
  const draco::Status status = encoder.EncodeMeshToBuffer(mesh, &encoded);
  if (!status.ok()) fail(gltf, "Draco cannot encode a primitive: " + status.error_msg_string());
  return std::string(encoded.data(), encoded.size());
}

void add_extension(json& doc, const char* list, const std::string& name) {
  json& names = doc[list];
  if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
}

}  // namespace

fs::path write_draco_copy(const std::string& scene, const fs::path& dir, int position_bits) {
  const fs::path gltf = copy_scene(scene, dir), bin_path = dir / (gltf.stem().string() + ".bin");
  json doc = json::parse(read_file(gltf));
  std::string bin = read_file(bin_path);
  std::vector<int> compressed_accessors;
  for (json& mesh : doc["meshes"])
    for (json& prim : mesh["primitives"]) {
      if (prim.value("mode", 4) != 4) continue;
      json ids = json::object();
      const std::string encoded = encode_primitive(doc, bin, prim, position_bits, &ids, gltf);
      bin.resize((bin.size() + 3) / 4 * 4, '\0');
      doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", encoded.size()}});
      bin += encoded;
      prim["extensions"]["KHR_draco_mesh_compression"] = {{"bufferView", doc["bufferViews"].size() - 1}, {"attributes", ids}};
      for (const auto& [name, index] : prim["attributes"].items()) compressed_accessors.push_back(index.get<int>());
      compressed_accessors.push_back(prim["indices"].get<int>());
    }
  // Only now: primitives sharing an accessor each read it above.
  for (int index : compressed_accessors) {
    doc["accessors"][static_cast<size_t>(index)].erase("bufferView");
    doc["accessors"][static_cast<size_t>(index)].erase("byteOffset");
  }
  doc["buffers"][0]["byteLength"] = bin.size();
  add_extension(doc, "extensionsUsed", "KHR_draco_mesh_compression");
  add_extension(doc, "extensionsRequired", "KHR_draco_mesh_compression");
  write_file(gltf, doc.dump(2));
  write_file(bin_path, bin);
  return gltf;
}

}  // namespace kit::test

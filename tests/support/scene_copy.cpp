#include "scene_copy.h"

#include <gtest/gtest.h>

#include <cstring>

#include "kit_test.h"
#include "kit_test_files.h"

namespace kit::test {

using nlohmann::json;

SceneCopy::SceneCopy(const std::string& scene, const std::string& case_name) {
  dir = temp_dir("scene_loader/" + case_name);
  gltf = copy_scene(scene, dir);
  bin = dir / (gltf.stem().string() + ".bin");
  doc = json::parse(read_file(gltf));
}

void SceneCopy::save_json() const { write_file(gltf, doc.dump(2)); }

int SceneCopy::accessor(const std::string& attribute) const {
  const json& prim = doc["meshes"][0]["primitives"][0];
  return attribute == "indices" ? prim["indices"].get<int>() : prim["attributes"][attribute].get<int>();
}

size_t SceneCopy::byte_offset(int accessor_index, size_t element, size_t components, size_t component) const {
  const json& acc = doc["accessors"][static_cast<size_t>(accessor_index)];
  const json& view = doc["bufferViews"][acc["bufferView"].get<size_t>()];
  return view.value("byteOffset", size_t{0}) + acc.value("byteOffset", size_t{0}) + (element * components + component) * 4;
}

size_t SceneCopy::append_bin(const std::string& bytes) {
  std::string data = read_file(bin);
  data.resize((data.size() + 3) / 4 * 4, '\0');
  const size_t offset = data.size();
  write_file(bin, data + bytes);
  doc["buffers"][0]["byteLength"] = offset + bytes.size();
  return offset;
}

int SceneCopy::add_view(const std::string& bytes, size_t byte_stride) {
  json view = {{"buffer", 0}, {"byteOffset", append_bin(bytes)}, {"byteLength", bytes.size()}};
  if (byte_stride) view["byteStride"] = byte_stride;
  doc["bufferViews"].push_back(view);
  return static_cast<int>(doc["bufferViews"].size()) - 1;
}

int SceneCopy::add_accessor(const json& accessor) {
  doc["accessors"].push_back(accessor);
  return static_cast<int>(doc["accessors"].size()) - 1;
}

std::vector<float> SceneCopy::floats(int accessor_index, size_t components) const {
  const std::string bytes = read_file(bin);
  const size_t count = doc["accessors"][static_cast<size_t>(accessor_index)]["count"];
  std::vector<float> out(count * components);
  std::memcpy(out.data(), &bytes.at(byte_offset(accessor_index, 0, components, 0)), out.size() * 4);
  return out;
}

void SceneCopy::require_extension(const std::string& name) {
  doc["extensionsUsed"].push_back(name);
  doc["extensionsRequired"].push_back(name);
}

void SceneCopy::overwrite_bin(size_t offset, const void* bytes, size_t size) const {
  std::string data = read_file(bin);
  ASSERT_LE(offset + size, data.size());
  std::memcpy(&data[offset], bytes, size);
  write_file(bin, data);
}

}  // namespace kit::test

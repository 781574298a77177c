#pragma once
// A generated kit scene copied into a test's own folder, its glTF JSON at hand to be
// broken or extended (new buffer views and accessors appended to its .bin).
#include <nlohmann/json.hpp>

#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace kit::test {

struct SceneCopy {
  std::filesystem::path dir, gltf, bin;
  nlohmann::json doc;

  // The kit scene `scene` ("sphere", "default", ...) copied to the fresh temp folder
  // scene_loader/<case_name>.
  SceneCopy(const std::string& scene, const std::string& case_name);
  void save_json() const;

  // Accessor index of the first primitive's attribute ("POSITION", ...) or "indices".
  int accessor(const std::string& attribute) const;
  // Byte offset of element `element` (component `component`, 4-byte components) in the .bin.
  size_t byte_offset(int accessor_index, size_t element, size_t components, size_t component) const;
  // Appends `bytes` to the .bin (4-byte aligned, as glTF asks of vertex data) and
  // returns where they start; buffer 0's byteLength follows (save_json() to keep it).
  size_t append_bin(const std::string& bytes);
  // A new bufferView over `bytes` appended to the .bin; returns its index.
  int add_view(const std::string& bytes, size_t byte_stride = 0);
  int add_accessor(const nlohmann::json& accessor);
  // Every component of a tightly packed FLOAT accessor, read from the .bin as written.
  std::vector<float> floats(int accessor_index, size_t components) const;
  void require_extension(const std::string& name);
  // Overwrites 4 bytes of the .bin at `offset` with `value`'s bytes.
  template <typename T>
  void patch_bin(size_t offset, T value) const {
    static_assert(sizeof(T) == 4, "glTF components patched here are 4 bytes");
    overwrite_bin(offset, &value, sizeof(T));
  }
  // Overwrites `size` bytes of the .bin at `offset`; fails the test when the .bin is shorter.
  void overwrite_bin(size_t offset, const void* bytes, size_t size) const;
};

// The bytes of `values` as they lie in memory (little-endian, as glTF's buffers are).
template <typename T>
std::string bytes_of(const std::vector<T>& values) {
  return std::string(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
}

}  // namespace kit::test

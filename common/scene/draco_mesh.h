#pragma once
// glTF's KHR_draco_mesh_compression: a primitive's mesh compressed by Draco, decoded by
// libdraco (libdraco-dev; in the browser, Google's decoder from npm: draco_mesh_web.cpp).
// The glTF loader (gltf_builder.cpp) reads the decoded
// attributes through its accessor code, so every check and conversion it makes for
// a bufferView applies to them too; this module only calls the library.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace kit {

// Whether this build decodes Draco: libdraco-dev was found when it was configured; in the
// browser, the page has loaded its decoder (it does before it hands kit-web a model that needs it).
bool draco_supported();

// What a build without Draco (one without libdraco-dev, or the page without its decoder) says
// of a file that needs it: why it cannot decode it, and what to do instead.
std::string draco_missing_hint();

// One decoded attribute: a value per point of the mesh, each `components` values of
// glTF's `component_type` (5126 FLOAT, 5123 UNSIGNED_SHORT, ...), tightly packed in
// `bytes` as an uncompressed accessor's bufferView would hold them.
struct DracoAttribute {
  int component_type = 0;
  int components = 0;
  size_t count = 0;
  std::vector<unsigned char> bytes;
};

class DracoMesh {
 public:
  // Decodes `size` bytes. Throws kit::Error "`what`: Draco cannot decode ...: <Draco's
  // status message>" when they are no Draco mesh; in a build without Draco, always.
  DracoMesh(const unsigned char* bytes, size_t size, const std::string& what);
  ~DracoMesh();
  DracoMesh(DracoMesh&&) noexcept;

  size_t point_count() const;
  // The attribute Draco knows by `unique_id`, its values dequantized by Draco.
  // Throws kit::Error naming `what` when the mesh has no such attribute or one glTF
  // cannot hold (a component type glTF lacks, more than 4 components).
  DracoAttribute attribute(uint32_t unique_id, const std::string& what) const;
  // The triangles' corners, three point indices a face.
  std::vector<uint32_t> triangle_indices() const;

 private:
  struct Decoded;
  std::unique_ptr<Decoded> decoded_;
};

}  // namespace kit

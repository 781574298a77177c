#include "scene/draco_mesh.h"

#include "base/error.h"

#if KIT_HAS_DRACO
#include <draco/compression/decode.h>
#include <draco/mesh/mesh.h>

#include <cstring>
#include <limits>
#endif

namespace kit {

std::string draco_missing_hint() {
  return "this build has no Draco decoder: install libdraco-dev and rebuild, or save the model uncompressed, e.g. "
         "with a glTF tool's --no-compression option";
}

#if !KIT_HAS_DRACO

bool draco_supported() { return false; }

struct DracoMesh::Decoded {};

DracoMesh::DracoMesh(const unsigned char*, size_t, const std::string& what) {
  throw Error(what + ": " + draco_missing_hint());
}
DracoMesh::~DracoMesh() = default;
DracoMesh::DracoMesh(DracoMesh&&) noexcept = default;
size_t DracoMesh::point_count() const { return 0; }
DracoAttribute DracoMesh::attribute(uint32_t, const std::string& what) const {
  throw Error(what + ": this build has no Draco support");
}
std::vector<uint32_t> DracoMesh::triangle_indices() const { return {}; }

#else

bool draco_supported() { return true; }

struct DracoMesh::Decoded {
  std::unique_ptr<draco::Mesh> mesh;
};

DracoMesh::DracoMesh(const unsigned char* bytes, size_t size, const std::string& what) {
  draco::DecoderBuffer buffer;
  buffer.Init(reinterpret_cast<const char*>(bytes), size);
  draco::Decoder decoder;  // its default: attributes come back dequantized
  auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
  if (!decoded.ok()) throw Error(what + ": Draco cannot decode its mesh: " + decoded.status().error_msg_string());
  decoded_ = std::make_unique<Decoded>();
  decoded_->mesh = std::move(decoded).value();
  if (!decoded_->mesh) throw Error(what + ": Draco cannot decode its mesh: it decoded to nothing");
}

DracoMesh::~DracoMesh() = default;
DracoMesh::DracoMesh(DracoMesh&&) noexcept = default;

size_t DracoMesh::point_count() const { return decoded_->mesh->num_points(); }

namespace {

// glTF's componentType for a Draco data type, 0 for one glTF has no accessor for.
int gltf_component_type(draco::DataType type) {
  switch (type) {
    case draco::DT_INT8: return 5120;     // BYTE
    case draco::DT_UINT8: return 5121;    // UNSIGNED_BYTE
    case draco::DT_INT16: return 5122;    // SHORT
    case draco::DT_UINT16: return 5123;   // UNSIGNED_SHORT
    case draco::DT_UINT32: return 5125;   // UNSIGNED_INT
    case draco::DT_FLOAT32: return 5126;  // FLOAT
    default: return 0;
  }
}

// Every point's value of `attribute` as T (its own type, so Draco's ConvertValue
// copies it unchanged), tightly packed into `out`. False where Draco finds a value
// outside its buffer.
template <typename T>
bool copy_values(const draco::PointAttribute& attribute, size_t points, int components, unsigned char* out) {
  T value[4];
  for (size_t i = 0; i < points; ++i) {
    const draco::AttributeValueIndex index = attribute.mapped_index(draco::PointIndex(static_cast<uint32_t>(i)));
    if (index.value() >= attribute.size() ||
        !attribute.ConvertValue<T>(index, static_cast<int8_t>(components), value))
      return false;
    std::memcpy(out + i * sizeof(T) * static_cast<size_t>(components), value, sizeof(T) * static_cast<size_t>(components));
  }
  return true;
}

}  // namespace

DracoAttribute DracoMesh::attribute(uint32_t unique_id, const std::string& what) const {
  const draco::PointAttribute* attribute = decoded_->mesh->GetAttributeByUniqueId(unique_id);
  if (!attribute) throw Error(what + ": the Draco mesh has no attribute with unique id " + std::to_string(unique_id));
  DracoAttribute out;
  out.component_type = gltf_component_type(attribute->data_type());
  out.components = attribute->num_components();
  out.count = point_count();
  if (out.component_type == 0)
    throw Error(what + ": Draco attribute " + std::to_string(unique_id) + " has data type " +
                std::to_string(static_cast<int>(attribute->data_type())) + ", which no glTF accessor holds");
  if (out.components < 1 || out.components > 4)
    throw Error(what + ": Draco attribute " + std::to_string(unique_id) + " has " + std::to_string(out.components) +
                " components (glTF attributes have 1 to 4)");
  // points * components * component size, each factor checked against what is left.
  const size_t component_size = static_cast<size_t>(draco::DataTypeLength(attribute->data_type()));
  const size_t element_size = component_size * static_cast<size_t>(out.components);  // at most 16
  if (out.count > std::numeric_limits<size_t>::max() / element_size)
    throw Error(what + ": Draco mesh has " + std::to_string(out.count) + " points, too many to hold");
  out.bytes.resize(out.count * element_size);
  bool ok = false;
  switch (attribute->data_type()) {
    case draco::DT_INT8: ok = copy_values<int8_t>(*attribute, out.count, out.components, out.bytes.data()); break;
    case draco::DT_UINT8: ok = copy_values<uint8_t>(*attribute, out.count, out.components, out.bytes.data()); break;
    case draco::DT_INT16: ok = copy_values<int16_t>(*attribute, out.count, out.components, out.bytes.data()); break;
    case draco::DT_UINT16: ok = copy_values<uint16_t>(*attribute, out.count, out.components, out.bytes.data()); break;
    case draco::DT_UINT32: ok = copy_values<uint32_t>(*attribute, out.count, out.components, out.bytes.data()); break;
    default: ok = copy_values<float>(*attribute, out.count, out.components, out.bytes.data()); break;
  }
  if (!ok) throw Error(what + ": Draco attribute " + std::to_string(unique_id) + " names a value it does not hold");
  return out;
}

std::vector<uint32_t> DracoMesh::triangle_indices() const {
  const draco::Mesh& mesh = *decoded_->mesh;
  std::vector<uint32_t> indices;
  indices.reserve(static_cast<size_t>(mesh.num_faces()) * 3);  // num_faces is 32-bit: no wrap in 64-bit size_t
  for (draco::FaceIndex f(0); f < mesh.num_faces(); ++f)
    for (int corner = 0; corner < 3; ++corner) indices.push_back(mesh.face(f)[corner].value());
  return indices;
}

#endif

}  // namespace kit

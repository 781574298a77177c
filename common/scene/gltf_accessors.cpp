#include "scene/gltf_accessors.h"

#include <algorithm>
#include <cstring>

#include "scene/gltf_loader.h"

namespace kit::gltf {

namespace {

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

}  // namespace

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

std::vector<float> AccessorReader::floats(int index, int type, int components, AttributeFormats formats,
                                          const std::string& what, const DracoAttribute* decoded) const {
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

std::vector<uint32_t> AccessorReader::indices(int index, const std::string& what,
                                              const std::vector<uint32_t>* decoded) const {
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

const tinygltf::Accessor& AccessorReader::accessor(int index, const std::string& what) const {
  if (index < 0 || index >= static_cast<int>(model.accessors.size()))
    fail(what + ": accessor index " + std::to_string(index) + " does not exist");
  return model.accessors[static_cast<size_t>(index)];
}

void AccessorReader::check_agrees_with_draco(const tinygltf::Accessor& acc, int components,
                                             const DracoAttribute& decoded, const std::string& name) const {
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

template <typename T, typename Decode>
std::vector<T> AccessorReader::elements(const tinygltf::Accessor& acc, size_t element_size, size_t components,
                                        const std::string& name, const unsigned char* decoded,
                                        const Decode& decode) const {
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

const unsigned char* AccessorReader::view_bytes(int view_index, size_t byte_offset, size_t count, size_t element_size,
                                                bool strided, const std::string& name, const std::string& part,
                                                size_t* stride) const {
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

}  // namespace kit::gltf

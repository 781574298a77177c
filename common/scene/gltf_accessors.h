#pragma once
// glTF accessors, read with every bound checked (the glTF loader's: gltf_builder.cpp):
// the component types glTF 2.0 (and KHR_mesh_quantization) allows each attribute,
// strided bufferViews, sparse accessors, and the values Draco decoded in their place.
#include <tiny_gltf.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "scene/draco_mesh.h"
#include "base/error.h"

namespace kit::gltf {

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

// "SCALAR", "VEC3", ... for messages.
std::string accessor_type_name(int type);

struct AccessorReader {
  const tinygltf::Model& model;
  const std::string& path;
  bool quantized;  // the file uses KHR_mesh_quantization

  [[noreturn]] void fail(const std::string& what) const { throw Error(path + ": " + what); }

  // Reads `components` values per element as floats, decoded from any component
  // type `formats` allows. With `decoded` (KHR_draco_mesh_compression), the values are
  // Draco's, which must agree with the accessor's count, type and component type.
  std::vector<float> floats(int index, int type, int components, AttributeFormats formats, const std::string& what,
                            const DracoAttribute* decoded = nullptr) const;

  // With `decoded` (a Draco mesh's triangle corners), those are the indices, and
  // the accessor's count must agree with them.
  std::vector<uint32_t> indices(int index, const std::string& what, const std::vector<uint32_t>* decoded = nullptr) const;

  const tinygltf::Accessor& accessor(int index, const std::string& what) const;

  // The accessor of a KHR_draco_mesh_compression attribute describes what Draco
  // decoded; where they disagree, the file is wrong about one of them.
  void check_agrees_with_draco(const tinygltf::Accessor& acc, int components, const DracoAttribute& decoded,
                               const std::string& name) const;

  // An accessor's elements, each decoded by `decode` (its bytes -> `components`
  // values): read from `decoded` (tightly packed: a Draco attribute, its count
  // checked) or else from its bufferView, or zeros when it has none, then replaced
  // where its sparse part says (glTF 2.0 "Sparse Accessors").
  template <typename T, typename Decode>
  std::vector<T> elements(const tinygltf::Accessor& acc, size_t element_size, size_t components, const std::string& name,
                          const unsigned char* decoded, const Decode& decode) const;

  // Where `count` elements of `element_size` bytes start in bufferView `view_index`,
  // `byte_offset` bytes in; *stride gets the distance between elements (the view's
  // byteStride when `strided` and it has one, else the element size). `part` names
  // what is read when it is not the accessor's own data ("sparse indices ").
  const unsigned char* view_bytes(int view_index, size_t byte_offset, size_t count, size_t element_size, bool strided,
                                  const std::string& name, const std::string& part, size_t* stride) const;
};

}  // namespace kit::gltf

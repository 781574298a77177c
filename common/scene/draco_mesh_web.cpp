// The browser build's Draco decoder (draco_mesh.h): Google's own, from npm's draco3d, which the
// page loads when a model needs it (tools/web/page/draco_libs.js) and hands kit-web as
// Module.kitDraco. The calls mirror libdraco's in draco_mesh.cpp, and the loader checks what
// they decode as it checks the desktop's. Debian has no WebAssembly build of libdraco.
#include <emscripten.h>

#include <cstring>
#include <limits>

#include "base/error.h"
#include "scene/draco_mesh.h"

namespace {

// The decoder's calls in JavaScript (draco_libs.js, decoderCalls). A length or handle of 0 or
// less means the call failed; its reason is in Module.kitDraco.lastError (kit_draco_error).
EM_JS(int, kit_draco_loaded, (), { return Module.kitDraco ? 1 : 0; });
EM_JS(int, kit_draco_decode, (const unsigned char* bytes, int size), {
  return Module.kitDraco.decode(HEAPU8.slice(bytes, bytes + size));
});
EM_JS(int, kit_draco_error, (char* out, int capacity), {
  const text = new TextEncoder().encode(Module.kitDraco.lastError || "no reason given");
  const n = Math.min(text.length, capacity);
  HEAPU8.set(text.subarray(0, n), out);
  return n;
});
EM_JS(int, kit_draco_points, (int mesh), { return Module.kitDraco.points(mesh); });
EM_JS(double, kit_draco_attribute_info, (int mesh, unsigned id, int* info), {
  const a = Module.kitDraco.attributeInfo(mesh, id);
  if (!a) return -1;
  HEAP32[info >> 2] = a.componentType;
  HEAP32[(info >> 2) + 1] = a.components;
  return a.byteLength;
});
EM_JS(int, kit_draco_attribute_copy, (int mesh, unsigned id, unsigned char* out, double length), {
  const bytes = Module.kitDraco.attributeBytes(mesh, id);
  if (!bytes || bytes.length !== length) return 0;
  HEAPU8.set(bytes, out);
  return 1;
});
EM_JS(double, kit_draco_corner_count, (int mesh), {
  Module.kitDracoTriangles = Module.kitDraco.triangles(mesh);
  return Module.kitDracoTriangles.length;
});
EM_JS(void, kit_draco_corners_copy, (uint32_t* out), {
  HEAPU32.set(Module.kitDracoTriangles, out >> 2);
  Module.kitDracoTriangles = null;
});
EM_JS(void, kit_draco_free, (int mesh), { Module.kitDraco.free(mesh); });

std::string last_error() {
  char text[512];
  const int n = kit_draco_error(text, sizeof text);
  return std::string(text, static_cast<size_t>(n > 0 ? n : 0));
}

}  // namespace

namespace kit {

std::string draco_missing_hint() {
  return "the page could not load its Draco decoder (kit-draco.js, kit-draco-decoder.wasm): reload the page, or export "
         "the model again without mesh compression (Blender's glTF export: Compression off), or render it with "
         "./kit render or ./kit view";
}

bool draco_supported() { return kit_draco_loaded() != 0; }

struct DracoMesh::Decoded {
  int handle = 0;
  size_t points = 0;
};

DracoMesh::DracoMesh(const unsigned char* bytes, size_t size, const std::string& what) {
  if (!draco_supported()) throw Error(what + ": " + draco_missing_hint());
  if (size > static_cast<size_t>(std::numeric_limits<int>::max()))
    throw Error(what + ": its Draco mesh of " + std::to_string(size) + " bytes is too large to decode here");
  const int handle = kit_draco_decode(bytes, static_cast<int>(size));
  if (handle <= 0) throw Error(what + ": Draco cannot decode its mesh: " + last_error());
  decoded_ = std::make_unique<Decoded>();
  decoded_->handle = handle;
  decoded_->points = static_cast<size_t>(kit_draco_points(handle));
}

DracoMesh::~DracoMesh() {
  if (decoded_) kit_draco_free(decoded_->handle);
}
DracoMesh::DracoMesh(DracoMesh&&) noexcept = default;

size_t DracoMesh::point_count() const { return decoded_->points; }

DracoAttribute DracoMesh::attribute(uint32_t unique_id, const std::string& what) const {
  int info[2] = {0, 0};
  const double length = kit_draco_attribute_info(decoded_->handle, unique_id, info);
  if (length < 0) throw Error(what + ": " + last_error());
  DracoAttribute out;
  out.component_type = info[0];
  out.components = info[1];
  out.count = point_count();
  if (out.component_type == 0)
    throw Error(what + ": Draco attribute " + std::to_string(unique_id) + " has a data type no glTF accessor holds");
  if (out.components < 1 || out.components > 4)
    throw Error(what + ": Draco attribute " + std::to_string(unique_id) + " has " + std::to_string(out.components) +
                " components (glTF attributes have 1 to 4)");
  if (length > static_cast<double>(std::numeric_limits<int>::max()))
    throw Error(what + ": Draco mesh has " + std::to_string(out.count) + " points, too many to hold");
  out.bytes.resize(static_cast<size_t>(length));
  if (!kit_draco_attribute_copy(decoded_->handle, unique_id, out.bytes.data(), length))
    throw Error(what + ": Draco attribute " + std::to_string(unique_id) + " names a value it does not hold");
  return out;
}

std::vector<uint32_t> DracoMesh::triangle_indices() const {
  std::vector<uint32_t> indices(static_cast<size_t>(kit_draco_corner_count(decoded_->handle)));
  kit_draco_corners_copy(indices.data());
  return indices;
}

}  // namespace kit

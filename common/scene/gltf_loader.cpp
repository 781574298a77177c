#include "scene/gltf_loader.h"

#include <tiny_gltf.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <optional>
#include <system_error>
#include <type_traits>
#include <vector>

#include "scene/draco_mesh.h"
#include "base/error.h"
#include "base/safe_file.h"
#include "images/texture_decode.h"

namespace kit::gltf {

namespace {

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
// opens any path it is given (a FIFO there waits forever). Unused with tinygltf 2.7 (below).
[[maybe_unused]] bool scene_file_size(size_t* size, std::string* err, const std::string& path, void* user) {
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
    std::string hint = name == "KHR_draco_mesh_compression" ? " (" + draco_missing_hint() + ")"
                       : name == "EXT_meshopt_compression"
                           ? " (its meshes are compressed: save the model uncompressed, e.g. with a glTF tool's --no-compression option)"
                           : "";
    throw Error(path + ": requires the glTF extension " + name + ", which the kit does not support" + hint +
                "; supported: " + supported);
  }
}

}  // namespace

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
  return build_scene(model, path);
}

}  // namespace kit::gltf

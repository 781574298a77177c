#pragma once
// The glTF loader behind load_scene (scene.h says what it accepts and refuses):
// gltf_loader.cpp reads the file, checks its JSON (nesting depth, the files it
// names) before tinygltf parses it and confines tinygltf's reads to the scene's
// folder; gltf_builder.cpp turns the parsed model into a Scene, reading its
// accessors through gltf_accessors.h.
#include <cstdint>
#include <string>

#include "scene/scene.h"

namespace tinygltf {
class Model;
}

namespace kit::gltf {

// Limits on what a scene file may ask for (documented in scene.h).
constexpr std::uintmax_t kMaxSceneFileBytes = std::uintmax_t(1) << 30;  // a .gltf/.glb, a buffer or an image file
constexpr int kMaxJsonDepth = 64;       // glTF itself nests 7 deep; tinygltf's JSON parser recurses per level
constexpr int kMaxNodeDepth = 256;      // the node hierarchy is walked recursively
constexpr int kMaxTexcoordSet = 7;      // TEXCOORD_0 to TEXCOORD_7: more than any exporter writes
// Where a Draco primitive's index accessor waits while tinygltf parses (move_draco_indices).
constexpr const char* kDracoIndicesKey = "kit_indices";

// Loads a .gltf or .glb file; throws kit::Error naming `path`. load_scene turns any
// other exception the file causes into one.
Scene load_scene_unguarded(const std::string& path);

// The Scene of the model tinygltf parsed from `path` (which messages name).
Scene build_scene(const tinygltf::Model& model, const std::string& path);

}  // namespace kit::gltf

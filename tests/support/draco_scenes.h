#pragma once
// Draco-compressed (KHR_draco_mesh_compression) copies of the kit's scenes, written
// with libdraco's encoder, for the tests of the loader's Draco path.
#include <filesystem>
#include <string>

namespace kit::test {

// Writes kit scene `scene` ("sphere", ...) into `dir` (its images beside it) with every
// triangle primitive's attributes and indices held only in a Draco mesh: its
// accessors keep count, type and componentType and lose their bufferView. The
// encoding is sequential, which keeps the order of points and faces, so a loaded
// copy compares vertex by vertex with the original. POSITION is quantized to
// `position_bits` bits (0: not at all: every value comes back exactly); the other
// attributes are not quantized. Returns the copy's .gltf; its buffer is dir/<scene>.bin.
std::filesystem::path write_draco_copy(const std::string& scene, const std::filesystem::path& dir, int position_bits);

}  // namespace kit::test

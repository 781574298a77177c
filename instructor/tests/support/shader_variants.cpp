#include "shader_variants.h"

#include <stdexcept>

#include "kit_test.h"
#include "kit_test_files.h"

namespace fs = std::filesystem;

namespace kit::test {

fs::path variant_root(const std::string& name, const std::vector<LineSwap>& swaps) {
  const fs::path root = temp_dir(name);
  fs::copy(kit_root() / "solutions", root, fs::copy_options::recursive);
  for (const LineSwap& swap : swaps) {
    const fs::path file = root / swap.file;
    std::string text = read_file(file);
    const size_t at = text.find(swap.kit);
    if (at == std::string::npos || text.find(swap.kit, at + 1) != std::string::npos)
      throw std::runtime_error("shader variant '" + name + "': solutions/" + swap.file +
                               " must contain exactly once: " + swap.kit);
    text.replace(at, swap.kit.size(), swap.naive);
    write_file(file, text);
  }
  return root;
}

ShaderLibrary full_root_library(const Stage& stage, const fs::path& root) {
  std::vector<ShaderFolder> folders;
  const std::string label = root.filename().string();
  for (auto it = stages().rbegin(); it != stages().rend(); ++it) {
    if (it->number > stage.number) continue;
    folders.push_back({root / it->folder, label + "/" + it->folder, it->files});
  }
  folders.push_back({shaders_dir(), "shaders", {}});
  return ShaderLibrary(std::move(folders));
}

}  // namespace kit::test

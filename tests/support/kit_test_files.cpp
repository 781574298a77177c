#include "kit_test_files.h"

#include <fstream>
#include <iterator>
#include <stdexcept>

#include "render/stages.h"  // resolve_scene

namespace kit::test {

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("test fixture: cannot read " + path.string());
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void write_file(const std::filesystem::path& path, const std::string& bytes) {
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw std::runtime_error("test fixture: cannot write " + path.string());
}

std::filesystem::path copy_scene(const std::string& name, const std::filesystem::path& dir) {
  const std::filesystem::path source = resolve_scene(name);
  std::filesystem::create_directories(dir);
  for (const auto& entry : std::filesystem::directory_iterator(source.parent_path()))
    std::filesystem::copy_file(entry.path(), dir / entry.path().filename(),
                               std::filesystem::copy_options::overwrite_existing);
  return dir / source.filename();
}

}  // namespace kit::test

// The environments kit-scenes writes for lab 6 (common/render/ibl.h).
#pragma once

#include <filesystem>

namespace kit_scenes {

// A sky with a small sun (1.5 degrees, 3000 times the sky): the hard case for sampling.
void write_sun_environment(const std::filesystem::path& path);
// A soft studio: a dim grey room lit by three large panels.
void write_studio_environment(const std::filesystem::path& path);

}  // namespace kit_scenes

#include "render/light_volumes.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>

#include "base/error.h"
#include "gbuffer_layout.h"

namespace kit {

float light_volume_budget(float gamma) {
  const double q = std::pow(static_cast<double>(kCutoffDisplayStep), static_cast<double>(std::max(gamma, 1.0f)));
  return static_cast<float>(q / (1.0 - q));
}

float light_volume_epsilon(const std::vector<Light>& lights, float gamma) {
  const auto unranged = std::count_if(lights.begin(), lights.end(), [](const Light& l) {
    return l.type != KIT_LIGHT_DIRECTIONAL && l.range <= 0.0f;
  });
  return light_volume_budget(gamma) / static_cast<float>(std::max<std::ptrdiff_t>(unranged, 1));
}

float light_cutoff_radius(const Light& light, float epsilon, int attenuation_model) {
  if (light.type == KIT_LIGHT_DIRECTIONAL) return std::numeric_limits<float>::infinity();
  const float c_max = std::max(light.color.r, std::max(light.color.g, light.color.b));
  float r2 = light.intensity * c_max / (3.14159265f * epsilon);
  if (attenuation_model == 1) r2 -= 1.0f;
  const float radius = std::sqrt(std::max(r2, 0.0f));
  return light.range > 0.0f ? std::min(radius, light.range) : radius;
}

namespace {

constexpr const char* kPragma = "#pragma kit_light_volume";
constexpr const char* kPragmaHelp =
    "#pragma kit_light_volume cull(none|back|front) depth(off|less_equal|greater_equal) blend(off|add)";

}  // namespace

LightVolumeState parse_light_volume_state(const AssembledShader& vertex) {
  LightVolumeState state;
  bool found = false;
  std::istringstream lines(vertex.text);
  std::string line;
  for (size_t index = 0; std::getline(lines, line); ++index) {
    const size_t start = line.find_first_not_of(" \t");
    if (start == std::string::npos || line.compare(start, std::strlen(kPragma), kPragma) != 0) continue;
    std::string where = "light_volume.vert";
    if (index < vertex.lines.size() && static_cast<size_t>(vertex.lines[index].file) < vertex.files.size())
      where = vertex.files[static_cast<size_t>(vertex.lines[index].file)] + ":" + std::to_string(vertex.lines[index].line);
    if (found) throw Error(where + ": a second kit_light_volume pragma (give one)");
    found = true;
    bool cull = false, depth = false, blend = false;
    std::istringstream words(line.substr(start + std::strlen(kPragma)));
    std::string word;
    while (words >> word) {
      if (word.rfind("//", 0) == 0) break;
      if (word == "cull(none)") state.cull = LightVolumeState::Cull::None, cull = true;
      else if (word == "cull(back)") state.cull = LightVolumeState::Cull::Back, cull = true;
      else if (word == "cull(front)") state.cull = LightVolumeState::Cull::Front, cull = true;
      else if (word == "depth(off)") state.depth = LightVolumeState::Depth::Off, depth = true;
      else if (word == "depth(less_equal)") state.depth = LightVolumeState::Depth::LessEqual, depth = true;
      else if (word == "depth(greater_equal)") state.depth = LightVolumeState::Depth::GreaterEqual, depth = true;
      else if (word == "blend(off)") state.blend_add = false, blend = true;
      else if (word == "blend(add)") state.blend_add = true, blend = true;
      else throw Error(where + ": '" + word + "' is not a light volume setting; the line reads " + kPragmaHelp);
    }
    if (!cull || !depth || !blend)
      throw Error(where + ": the kit_light_volume pragma names " + std::string(!cull ? "no cull" : !depth ? "no depth" : "no blend") +
                  " setting; it reads " + kPragmaHelp);
  }
  if (!found)
    throw Error((vertex.files.empty() ? std::string("light_volume.vert") : vertex.files.front()) +
                ": no line '" + kPragmaHelp + "' (the state the framework draws the volumes with)");
  return state;
}

std::string describe(const LightVolumeState& s) {
  const char* cull = s.cull == LightVolumeState::Cull::None ? "none" : s.cull == LightVolumeState::Cull::Back ? "back" : "front";
  const char* depth = s.depth == LightVolumeState::Depth::Off         ? "off"
                      : s.depth == LightVolumeState::Depth::LessEqual ? "less_equal"
                                                                      : "greater_equal";
  return std::string("cull(") + cull + ") depth(" + depth + ") blend(" + (s.blend_add ? "add" : "off") + ")";
}

double LightVolumeWork::speedup() const {
  const double loop = static_cast<double>(surface_pixels) * static_cast<double>(volume_lights);
  return shaded_fragments == 0 ? std::numeric_limits<double>::infinity() : loop / static_cast<double>(shaded_fragments);
}

}  // namespace kit

#include "cli.h"

#include "error.h"

namespace kit {

const char* common_options_help() {
  return "  --stage NAME          gbuffer | lighting | attenuation | normalmap | postprocess (or 1-5)\n"
         "  --shaders DIR         folder holding NN-name/ lab folders (default: solutions/)\n"
         "  --scene NAME|FILE     kit scene name (default, sphere, grazing, normalmap) or a .gltf/.glb\n"
         "  --backend NAME        osmesa (default) | egl\n"
         "  --size WxH            image size (default 640x480)\n"
         "  --gamma G             display gamma (default 2.2)\n"
         "  --attenuation MODEL   physical (seed 000, default) | simple (seed 002, 1/(1+d^2))\n"
         "  --postprocess on|off  stage 5 toggle (default on)\n"
         "  --custom on|off       stage 5 free-choice effect toggle (default off)\n"
         "  --threshold T         bloom bright-pass threshold (default 1.0)\n"
         "  --blur-passes N       separable blur passes (default 6)\n"
         "  --lights N            add N small point lights (default 0)\n";
}

void parse_size(const std::string& text, int* width, int* height) {
  size_t x = text.find('x');
  try {
    if (x == std::string::npos) throw std::invalid_argument("no x");
    *width = std::stoi(text.substr(0, x));
    *height = std::stoi(text.substr(x + 1));
  } catch (const std::exception&) {
    throw Error("--size expects WxH, e.g. 640x480 (got '" + text + "')");
  }
  if (*width < 1 || *height < 1 || *width > 8192 || *height > 8192)
    throw Error("--size must be between 1x1 and 8192x8192 (got '" + text + "')");
}

bool parse_on_off(const std::string& text, const std::string& flag) {
  if (text == "on" || text == "1" || text == "true") return true;
  if (text == "off" || text == "0" || text == "false") return false;
  throw Error(flag + " expects on or off (got '" + text + "')");
}

static float parse_float(const std::string& text, const std::string& flag) {
  try {
    size_t used = 0;
    float v = std::stof(text, &used);
    if (used == text.size()) return v;
  } catch (const std::exception&) {
  }
  throw Error(flag + " expects a number (got '" + text + "')");
}

void parse_options(int argc, char** argv, CommonOptions& o,
                   const std::function<int(const std::string&, const OptionValue&)>& extra) {
  for (int i = 1; i < argc; ++i) {
    std::string flag = argv[i];
    const char* next = i + 1 < argc ? argv[i + 1] : nullptr;
    const OptionValue next_value = [&]() -> std::string {
      if (!next) throw Error(flag + " needs a value");
      return next;
    };
    auto value = [&]() -> std::string {
      std::string v = next_value();
      ++i;
      return v;
    };
    RenderSettings& s = o.settings;
    if (flag == "--stage") o.stage = value();
    else if (flag == "--shaders") o.shaders = value();
    else if (flag == "--scene") o.scene = value();
    else if (flag == "--backend") o.backend = value();
    else if (flag == "--size" || flag == "-s") parse_size(value(), &s.width, &s.height);
    else if (flag == "--gamma") s.gamma = parse_float(value(), flag);
    else if (flag == "--attenuation") {
      std::string m = value();
      if (m == "physical") s.attenuation_model = 0;
      else if (m == "simple") s.attenuation_model = 1;
      else throw Error("--attenuation expects physical or simple (got '" + m + "')");
    } else if (flag == "--postprocess") s.postprocess = parse_on_off(value(), flag);
    else if (flag == "--custom") s.custom_effect = parse_on_off(value(), flag);
    else if (flag == "--threshold") s.bloom_threshold = parse_float(value(), flag);
    else if (flag == "--blur-passes") s.blur_passes = static_cast<int>(parse_float(value(), flag));
    else if (flag == "--lights") s.extra_lights = static_cast<int>(parse_float(value(), flag));
    else {
      int used = extra ? extra(flag, next_value) : 0;
      if (used == 0) throw Error("unknown option '" + flag + "' (see --help)");
      i += used - 1;
    }
  }
  if (o.settings.blur_passes < 0 || o.settings.blur_passes > 64) throw Error("--blur-passes must be 0..64");
  if (o.settings.extra_lights < 0 || o.settings.extra_lights > 65536) throw Error("--lights must be 0..65536");
}

std::filesystem::path shaders_root(const CommonOptions& options) {
  return options.shaders.empty() ? kit_root() / "solutions" : std::filesystem::path(options.shaders);
}

}  // namespace kit

#include "cli.h"

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <system_error>

#include "base/error.h"

namespace kit {

const char* common_options_help() {
  return "  --stage NAME          gbuffer | lighting | attenuation | normalmap | postprocess | ibl |\n"
         "                        lightvolumes (or 1-7); default: the stage of the lab folder\n"
         "                        --shaders names, else gbuffer\n"
         "  --shaders DIR         your lab files: a folder holding NN-name/ lab folders (default: labs/),\n"
         "                        or one lab folder itself (labs/02-lighting)\n"
         "  --solution            the reference solutions (solutions/) instead of your labs\n"
         "  --timeout S           seconds the shaders may take to compile and draw before the run stops\n"
         "                        with a message (default 30, as the grader's; 0: no limit)\n"
         "  --scene NAME|FILE     kit scene name (default, sphere, grazing, normalmap, spot, sun,\n"
         "                        highlight, materials, texturing, closeup, lights, inside,\n"
         "                        range, matte, crowd) or a .gltf/.glb/.obj file\n"
         "  --camera N            the scene file's camera N, counted from 0 in the order of its node tree\n"
         "                        (default: its first camera, else one that frames the scene)\n"
         "  --backend NAME        osmesa | egl (default: osmesa where this build has it, else egl)\n"
         "  --size WxH            image size (default 640x480)\n"
         "  --gamma G             display gamma (default 2.2)\n"
         "  --attenuation MODEL   physical (inverse square, default) | simple (1/(1+d^2))\n"
         "  --postprocess on|off  stage 5 toggle (default on)\n"
         "  --custom on|off       stage 5 free-choice effect toggle (default off)\n"
         "  --threshold T         bloom bright-pass threshold (default 1.0)\n"
         "  --blur-passes N       separable blur passes (default 6)\n"
         "  --lights N            add N small point lights (default 0)\n"
         "  --no-default-lights   leave a scene without lights unlit (default: lit stages light it with\n"
         "                        the default rig: key, fill and rim point lights scaled to its bounds)\n"
         "  --environment NAME|FILE\n"
         "                        stage 6's environment: studio (default) or sun, the kit's own, or an\n"
         "                        equirectangular .hdr/.exr file\n"
         "  --check-maps on|off   stage 6: read the precomputed maps back and stop, naming the shader, map\n"
         "                        and texel, at a NaN or Inf (default on; off shows what it does to the image)\n"
         "  --compress-textures auto|on|off\n"
         "                        textures of at least 1024x1024 texels uploaded as S3TC (BC1, BC3 with\n"
         "                        alpha; normal maps and smaller textures never are). auto (default):\n"
         "                        when the scene's textures take over 256 MiB uncompressed, or a GPU\n"
         "                        samples them (not llvmpipe or softpipe); --timings says which\n"
         "  --light-markers       a small sphere of each point and spot light's colour where the light is\n"
         "                        (lit stages; drawn forward, hidden by what is in front; kit-view's M key)\n"
         "  --look-at EX,EY,EZ,TX,TY,TZ[,FOV]\n"
         "                        camera at EYE looking at TARGET, +Y up, vertical FOV in degrees\n"
         "                        (default: the scene's camera, else one framing its bounds; kit-view's\n"
         "                        L key prints the current view in this form)\n";
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

std::optional<long> parse_whole_number(const std::string& text, long min, long max) {
  char* end = nullptr;
  errno = 0;
  const long n = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0' || errno == ERANGE || n < min || n > max) return std::nullopt;
  return n;
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
    else if (flag == "--solution") o.solution = true;
    else if (flag == "--timeout") {
      o.timeout = parse_float(value(), flag);
      if (!(o.timeout >= 0.0 && o.timeout <= 86400.0)) throw Error("--timeout expects seconds from 0 (no limit) to 86400");
    }
    else if (flag == "--scene") o.scene = value();
    else if (flag == "--camera") {
      const std::string text = value();
      const std::optional<long> n = parse_whole_number(text, 0, 1000000);
      if (!n) throw Error("--camera expects a camera number from 0 (got '" + text + "')");
      o.camera = static_cast<int>(*n);
    }
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
    else if (flag == "--no-default-lights") s.default_light_rig = false;
    else if (flag == "--light-markers") s.light_markers = true;
    else if (flag == "--compress-textures") {
      const std::string mode = value();
      if (mode == "auto") s.texture_compression = TextureCompression::Auto;
      else if (mode == "on" || mode == "1" || mode == "true") s.texture_compression = TextureCompression::On;
      else if (mode == "off" || mode == "0" || mode == "false") s.texture_compression = TextureCompression::Off;
      else throw Error(flag + " expects auto, on or off (got '" + mode + "')");
    }
    else if (flag == "--environment") s.environment = value();
    else if (flag == "--check-maps") s.ibl.refuse_non_finite = parse_on_off(value(), flag);
    else if (flag == "--look-at") o.look_at = parse_look_at(value(), flag);
    else {
      int used = extra ? extra(flag, next_value) : 0;
      if (used == 0) throw Error("unknown option '" + flag + "' (see --help)");
      i += used - 1;
    }
  }
  if (o.settings.blur_passes < 0 || o.settings.blur_passes > 64) throw Error("--blur-passes must be 0..64");
  if (o.settings.extra_lights < 0 || o.settings.extra_lights > 65536) throw Error("--lights must be 0..65536");
  if (o.look_at && o.camera >= 0) throw Error("--camera and --look-at both choose the camera: give one of them");
}

Camera initial_camera(const Scene& scene, const CommonOptions& o) {
  if (o.look_at) return look_at_camera(*o.look_at, scene);
  return chosen_camera(scene, o.camera);
}

void note_default_light_rig(const char* tool, const Scene& scene, const Stage& stage, const RenderSettings& settings) {
  if (stage.ibl && scene.lights.empty())
    std::fprintf(stderr, "%s: note: scene has no lights: the environment (%s) lights it alone\n", tool,
                 environment_or_default(settings.environment).c_str());
  else if (stage.lighting && uses_default_light_rig(scene, stage, settings))
    std::fprintf(stderr,
                 "%s: note: scene has no lights: using the default rig (3 point lights: key, fill and rim around "
                 "its bounds); --no-default-lights turns it off\n",
                 tool);
}

namespace {

namespace fs = std::filesystem;

// The stage whose lab folder `path` is (its name is NN-name), or null.
const Stage* lab_folder_stage(const fs::path& path) {
  const std::string name = path.filename().string();
  for (const Stage& s : stages())
    if (s.folder == name) return &s;
  return nullptr;
}

std::string lab_folder_list() {
  std::string out;
  for (const Stage& s : stages()) out += (out.empty() ? "" : ", ") + s.folder;
  return out;
}

}  // namespace

void check_lab_folder(const CommonOptions& o, const fs::path& root, const Stage& stage) {
  std::error_code ec;
  const fs::path folder = root / stage.folder;
  if (fs::is_directory(folder, ec)) return;
  const std::string where = folder.string() + ": no such folder, so stage " + std::to_string(stage.number) + " (" +
                            stage.name + ") has no lab files to render. ";
  if (o.solution)
    throw Error(where + "This copy of the kit holds no solution of lab " + std::to_string(stage.number) +
                " (a student copy keeps only the solutions of the labs before its own); leave out --solution "
                "to render your own lab from labs/" + stage.folder);
  if (o.shaders.empty())
    throw Error(where + "labs/ should hold every lab's starter folder (" + lab_folder_list() +
                "): restore it (git checkout -- labs/" + stage.folder + "), or give --shaders DIR");
  throw Error(where + "--shaders " + o.shaders + " must be a folder holding the lab folders (" + lab_folder_list() +
              ") or one lab folder itself, e.g. --shaders " + (fs::path(o.shaders) / stage.folder).string());
}

LabSelection select_lab(const CommonOptions& o) {
  if (o.solution && !o.shaders.empty()) throw Error("--solution and --shaders both say where the lab files are: give one");
  LabSelection out;
  const Stage* from_folder = nullptr;
  if (o.solution) {
    out.root = kit_root() / "solutions";
  } else if (o.shaders.empty()) {
    out.root = kit_root() / "labs";
  } else {
    std::error_code ec;
    fs::path given(o.shaders);
    if (!fs::is_directory(given, ec))
      throw Error("--shaders " + o.shaders + ": no such folder (give the folder holding your NN-name lab folders, "
                  "such as labs, or one lab folder, such as labs/02-lighting)");
    fs::path absolute = fs::absolute(given, ec).lexically_normal();
    if (absolute.filename().empty()) absolute = absolute.parent_path();  // "labs/02-lighting/"
    from_folder = lab_folder_stage(absolute);
    out.root = from_folder ? absolute.parent_path() : given;
  }
  if (!o.stage.empty()) {
    out.stage = &find_stage(o.stage);
    if (from_folder && from_folder != out.stage)
      throw Error("--shaders " + o.shaders + " is the folder of lab " + std::to_string(from_folder->number) + " (" +
                  from_folder->name + "), but --stage asks for lab " + std::to_string(out.stage->number) + " (" +
                  out.stage->name + "): leave out --stage, or give --shaders " + out.root.string());
  } else {
    out.stage = from_folder ? from_folder : &find_stage("gbuffer");
  }
  check_lab_folder(o, out.root, *out.stage);
  return out;
}

}  // namespace kit

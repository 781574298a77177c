// kit-view: a window onto one stage. Renders the stage at the window's
// framebuffer size when something it depends on changed (camera, controls,
// shaders, size), at a lower resolution while the camera moves, shows the final
// image or a G-buffer view, and reloads the stage's shaders when their files
// change (errors are shown, the last good programs keep running).
// `./kit view --lab N [--solution]` opens it.
//   kit-view --stage lighting --shaders labs [--view normal] [--frames N --screenshot out.png]
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <utility>

#include "cli.h"
#include "base/error.h"
#include "view/viewer.h"

namespace {

void usage() {
  std::printf(
      "usage: kit-view --stage NAME [--shaders DIR] [options]\n"
      "Opens a window onto one stage; shaders reload when their files change.\n"
      "  --view VIEW           first view: final (default) | position | normal | albedo | material | emission |\n"
      "                        depth | hdr\n"
      "  --frames N            render N frames, then exit (non-zero if a shader error is still shown)\n"
      "  --screenshot FILE     after the last frame, write the stage's final image (PNG or EXR)\n"
      "  --window-screenshot FILE  after the last frame, write the window as shown, panel included\n"
      "  --hidden              invisible window (the image is still rendered)\n"
      "  --no-ui               no control panel (errors and warnings still go to stderr)\n"
      "  --spin                turn the camera a little every frame, as a steady drag would (with --frames:\n"
      "                        the frame rate while the camera moves; the last frame is still)\n"
      "  --timings             at exit, print how many frames were rendered, at which size, and their median time\n"
      "A frame is rendered only when the camera, a control, a shader or the window size changed (or the\n"
      "custom effect animates); while the camera moves, at half the width and height.\n"
      "Keys: 1-8 view (final, position, normal, albedo, material, emission, depth, hdr),\n"
      "      P postprocess, C custom effect,\n"
      "      G gamma 2.2/1.0/0.5/2.5, A attenuation model (orbit mode), F fly/orbit, F12 or K screenshot,\n"
      "      M light markers, R reload shaders, L print the camera as --look-at (stdout), Esc quit.\n"
      "Mouse: orbit: left drag rotates, wheel zooms, right/middle drag pans;\n"
      "       fly: WASD move, Q/E down/up, Shift faster, right drag looks around.\n"
      "A frame (or a shader build) that takes longer than --timeout ends the viewer with a message on stderr:\n"
      "a GL call that never returns blocks the window too.\n"
      "Shared options (--size sets the window size; --backend is not used, the window is the context):\n%s",
      kit::common_options_help());
}

int parse_frame_count(const std::string& text) {
  if (const std::optional<long> n = kit::parse_whole_number(text, 1, std::numeric_limits<int>::max()))
    return static_cast<int>(*n);
  throw kit::Error("--frames expects a whole number of at least 1 (got '" + text + "')");
}

}  // namespace

int main(int argc, char** argv) {
  kit_view::ViewerOptions options;
  kit::name_gl_crashes("kit-view");
  return kit::run_tool("kit-view", 1, [&]() -> int {
    for (int i = 1; i < argc; ++i)
      if (!std::strcmp(argv[i], "--help") || !std::strcmp(argv[i], "-h")) {
        usage();
        return 0;
      }
    kit::parse_options(argc, argv, options.common, [&](const std::string& flag, const kit::OptionValue& value) -> int {
      if (flag == "--hidden") return options.hidden = true, 1;
      if (flag == "--no-ui") return options.ui = false, 1;
      if (flag == "--spin") return options.spin = true, 1;
      if (flag == "--timings") return options.timings = true, 1;
      if (flag == "--frames") return options.frames = parse_frame_count(value()), 2;
      if (flag == "--screenshot") return options.screenshot = value(), 2;
      if (flag == "--window-screenshot") return options.window_screenshot = value(), 2;
      if (flag == "--view") return options.view = kit::parse_view(value()), 2;
      return 0;
    });
    kit_view::Viewer viewer(std::move(options));
    return viewer.run();
  });
}

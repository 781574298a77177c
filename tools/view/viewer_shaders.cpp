// The Viewer's shaders (viewer.h): building the stage, reloading it when its files change,
// and the errors, notes and warnings it shows.
#include "view/viewer.h"

#include <algorithm>
#include <cstdio>
#include <system_error>

#include "base/error.h"

namespace fs = std::filesystem;

namespace kit_view {

// Shader builds run under the time limit as well; inside a frame, the frame's
// limit starts again once the build is done.
class Viewer::TimedWork {
 public:
  TimedWork(Viewer& viewer, const std::string& activity) : viewer_(viewer) { viewer_.watchdog_.arm(activity); }
  ~TimedWork() {
    if (viewer_.in_frame_) viewer_.watchdog_.arm(viewer_.frame_activity());
    else viewer_.watchdog_.disarm();
  }
  TimedWork(const TimedWork&) = delete;
  TimedWork& operator=(const TimedWork&) = delete;

 private:
  Viewer& viewer_;
};

std::string Viewer::frame_activity() const {
  return "rendering stage " + (renderer_ ? renderer_->stage().name : stage_->name);
}

void Viewer::build_renderer() {
  TimedWork timed(*this, "compiling the shaders of stage " + stage_->name);
  try {
    kit::check_lab_folder(options_.common, shader_root_, *stage_);
    auto renderer = std::make_unique<kit::Renderer>(*stage_, kit::stage_library(*stage_, shader_root_), scene_, settings_);
    bool retry = !error_.empty();
    renderer_ = std::move(renderer);  // replaces the old stage only once the new one built
    ++shader_builds_;
    if (retry) set_note("stage " + stage_->name + " built");
    if (!gpu_timer_) gpu_timer_ = std::make_unique<GpuTimer>();
    if (!blit_source_) blit_source_ = std::make_unique<kit::Framebuffer>();
    error_.clear();
    warnings_due_ = true;
  } catch (const kit::Error& e) {
    report_error(e.what());
  }
}

void Viewer::switch_stage(const kit::Stage& stage) {
  stage_ = &stage;
  select_view(view_);
  build_renderer();
  watched_.clear();  // other files now; the next poll takes their times
  refresh_title();
}

bool Viewer::stage_is_built() const { return renderer_ && renderer_->stage().number == stage_->number; }

void Viewer::reload() {
  if (!stage_is_built()) {
    build_renderer();
    return;
  }
  TimedWork timed(*this, "compiling the shaders of stage " + stage_->name);
  try {
    renderer_->reload_shaders();
    ++shader_builds_;
    error_.clear();
    warnings_due_ = true;
    set_note("shaders reloaded");
  } catch (const kit::Error& e) {
    report_error(e.what());  // the old programs keep running
  }
}

void Viewer::reload_now() {  // the R key and the button; the next poll starts from the files as they are then
  reload();
  watched_.clear();
}

// The files the stage is made of; while it does not build, every file in its
// shader folders (a missing file may be about to appear).
std::vector<fs::path> Viewer::shader_files() const {
  if (stage_is_built()) return renderer_->shader_paths();
  std::vector<fs::path> files;
  const kit::ShaderLibrary library = kit::stage_library(*stage_, shader_root_);
  for (const kit::ShaderFolder& folder : library.folders()) {
    files.push_back(folder.path);  // its time changes when a file is added or removed
    std::error_code ec;
    for (fs::directory_iterator it(folder.path, ec), end; !ec && it != end; it.increment(ec)) files.push_back(it->path());
  }
  return files;
}

Viewer::FileTimes Viewer::file_times() const {
  FileTimes times;
  for (const fs::path& path : shader_files()) {
    std::error_code ec;
    times[path] = fs::last_write_time(path, ec);  // a missing file reads as an error time, also a change
  }
  return times;
}

void Viewer::poll_shader_files() {
  FileTimes times = file_times();
  if (watched_.empty() || times == watched_) {
    watched_ = std::move(times);
    return;
  }
  reload();
  // Keep the times from before the rebuild when the same files are watched,
  // so an edit saved while it compiled still counts at the next poll.
  FileTimes after = file_times();
  bool same_files = std::equal(after.begin(), after.end(), times.begin(), times.end(),
                               [](const auto& a, const auto& b) { return a.first == b.first; });
  watched_ = same_files ? std::move(times) : std::move(after);
}

// NaN/Inf pixels and uniforms nothing sets, as kit-render and the grader report
// them; printed once when they change, shown under the image.
void Viewer::refresh_warnings() {
  warnings_due_ = false;
  std::vector<std::string> found;
  try {
    for (const kit::NonFiniteCount& n : renderer_->non_finite_pixels())
      if (n.pixels > 0)
        found.push_back(std::to_string(n.pixels) + " of " + std::to_string(n.of) + " pixels of the " + kit::view_name(n.view) +
                        " view are NaN or Inf: " + kit::kNonFiniteAdvice);
    for (const std::string& line : renderer_->uniform_warnings()) found.push_back(line);
  } catch (const kit::Error& e) {
    report_error(e.what());
    return;
  }
  if (found == warnings_) return;
  for (const std::string& line : found)
    if (std::find(warnings_.begin(), warnings_.end(), line) == warnings_.end())
      std::fprintf(stderr, "kit-view: warning: %s\n", line.c_str());
  warnings_ = std::move(found);
}

void Viewer::set_note(const std::string& message) {
  std::printf("kit-view: %s\n", message.c_str());
  std::fflush(stdout);  // in order with the errors on stderr when both go to one log
  note_ = message;
}

void Viewer::report_error(const std::string& message) {
  if (message != error_) std::fprintf(stderr, "kit-view: %s\n", message.c_str());
  error_ = message;
}

}  // namespace kit_view

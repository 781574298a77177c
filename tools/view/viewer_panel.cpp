// The Viewer's window title and Dear ImGui panel (viewer.h): the controls, and the shader
// error and warnings under the image.
#include "view/viewer.h"

#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>

#include "gl/gl.h"  // glad before GLFW: GLFW_INCLUDE_NONE keeps GLFW's own GL header out
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <string>
#include <utility>

namespace kit_view {

namespace {

constexpr float kGammaMin = 0.2f, kGammaMax = 3.0f;
constexpr float kBloomThresholdMax = 5.0f;
constexpr float kPanelWidth = 340.0f, kPanelItemWidth = 180.0f;
constexpr float kWindowMargin = 8.0f;           // between the viewport's edges and the panel or messages
constexpr float kMessagesMaxHeightFraction = 0.45f;  // of the viewport: the image stays visible above
const ImVec4 kErrorColor{1.0f, 0.35f, 0.35f, 1.0f};
const ImVec4 kWarningColor{1.0f, 0.8f, 0.3f, 1.0f};
const ImVec4 kNoteColor{0.7f, 0.7f, 0.7f, 1.0f};
// The prefilter's sample counts the panel offers, as powers of two.
constexpr int kMinPrefilterSamplesLog2 = 4, kMaxPrefilterSamplesLog2 = 11;

}  // namespace

std::string Viewer::title_prefix() const { return "kit-view: " + std::to_string(stage_->number) + " " + stage_->name; }

void Viewer::refresh_title() {
  char text[256];
  std::snprintf(text, sizeof text, "%s [%s]  %.1f ms%s", title_prefix().c_str(), kit::view_name(view_), frame_ms_,
                error_.empty() ? "" : "  (shader error)");
  glfwSetWindowTitle(window_.handle(), text);
}

void Viewer::draw_ui() {
  ImGui_ImplOpenGL3_NewFrame();
  ImGui_ImplGlfw_NewFrame();
  ImGui::NewFrame();
  float messages_height = draw_messages();
  draw_panel(messages_height);
  ImGui::Render();
  ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
}

// The shader error and the warnings, in a window across the bottom of the
// viewport: wrapped to its width, never taller than kMessagesMaxHeightFraction
// of it (it scrolls), so they show at any window size. Returns its height.
float Viewer::draw_messages() {
  if (error_.empty() && warnings_.empty()) return 0.0f;
  const ImVec2 display = ImGui::GetIO().DisplaySize;
  const float width = std::max(display.x - 2.0f * kWindowMargin, 1.0f);
  const float max_height = std::max(display.y * kMessagesMaxHeightFraction, 1.0f);
  ImGui::SetNextWindowPos(ImVec2(kWindowMargin, display.y - kWindowMargin), ImGuiCond_Always, ImVec2(0.0f, 1.0f));
  ImGui::SetNextWindowSizeConstraints(ImVec2(width, 0.0f), ImVec2(width, max_height));
  ImGui::SetNextWindowBgAlpha(0.85f);
  const ImGuiWindowFlags flags = ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse |
                                 ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_AlwaysAutoResize;
  std::string title = error_.empty() ? "warnings" : "shader error";
  if (!error_.empty()) title += renderer_ ? ": the last shaders that built keep running" : ": nothing to show until it builds";
  ImGui::Begin((title + "###messages").c_str(), nullptr, flags);
  ImGui::PushTextWrapPos(0.0f);
  if (!error_.empty()) {
    ImGui::PushStyleColor(ImGuiCol_Text, kErrorColor);
    ImGui::TextUnformatted(error_.c_str());
    ImGui::PopStyleColor();
    ImGui::TextColored(kNoteColor, "saving a shader file (or R) tries again");
  }
  for (const std::string& warning : warnings_) {
    ImGui::PushStyleColor(ImGuiCol_Text, kWarningColor);
    ImGui::TextUnformatted(("warning: " + warning).c_str());
    ImGui::PopStyleColor();
  }
  ImGui::PopTextWrapPos();
  float height = ImGui::GetWindowSize().y;
  ImGui::End();
  return height;
}

// The controls, top left, above the messages. Only what changes the current
// stage's image is shown: lights from stage 2, gamma and the attenuation
// model from stage 3, bloom and the custom effect in stage 5.
void Viewer::draw_panel(float messages_height) {
  const ImVec2 display = ImGui::GetIO().DisplaySize;
  float room = display.y - 2.0f * kWindowMargin - (messages_height > 0.0f ? messages_height + kWindowMargin : 0.0f);
  ImGui::SetNextWindowPos(ImVec2(kWindowMargin, kWindowMargin), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSize(ImVec2(kPanelWidth, 0), ImGuiCond_FirstUseEver);
  ImGui::SetNextWindowSizeConstraints(ImVec2(0.0f, 0.0f), ImVec2(FLT_MAX, std::max(room, ImGui::GetFrameHeight())));
  ImGui::Begin("kit-view");
  ImGui::PushItemWidth(kPanelItemWidth);  // leaves room for the labels on the right
  ImGui::Text("frame %.2f ms (%.0f fps), GPU %.2f ms", frame_ms_, frame_ms_ > 0.0 ? 1000.0 / frame_ms_ : 0.0,
              gpu_timer_ ? gpu_timer_->milliseconds() : 0.0);

  std::string current = std::to_string(stage_->number) + " " + stage_->name;
  if (ImGui::BeginCombo("stage", current.c_str())) {
    for (const kit::Stage& s : kit::stages()) {
      std::string label = std::to_string(s.number) + " " + s.name;
      if (ImGui::Selectable(label.c_str(), &s == stage_) && &s != stage_) switch_stage(s);
    }
    ImGui::EndCombo();
  }
  if (renderer_ && !stage_is_built())
    ImGui::TextColored(kNoteColor, "showing %s until %s builds", renderer_->stage().name.c_str(), stage_->name.c_str());

  if (ImGui::BeginCombo("view", kit::view_name(view_))) {
    for (size_t i = 0; i < std::size(kViewKeys); ++i) {
      kit::View v = kViewKeys[i];
      if ((v == kit::View::Hdr && !stage_->lighting) || (kit::is_precomputed_map(v) && !stage_->ibl)) continue;
      std::string label = (static_cast<int>(i) < kViewNumberKeys ? std::to_string(i + 1) + " " : std::string("  ")) +
                          kit::view_name(v);
      if (ImGui::Selectable(label.c_str(), v == view_)) select_view(v);
    }
    ImGui::EndCombo();
  }

  const int stage = stage_->number;
  if (stage >= kFirstPostprocessStage) {
    ImGui::Checkbox("postprocess (P)", &settings_.postprocess);
    ImGui::Checkbox("custom effect (C)", &settings_.custom_effect);
    ImGui::BeginDisabled(!settings_.postprocess);
    ImGui::SliderFloat("bloom threshold", &settings_.bloom_threshold, 0.0f, kBloomThresholdMax);
    ImGui::EndDisabled();
  }
  if (stage >= kFirstDisplayStage) {
    ImGui::SliderFloat("gamma (G)", &settings_.gamma, kGammaMin, kGammaMax, "%.2f");
    ImGui::TextUnformatted("attenuation (A)");
    ImGui::SameLine();
    ImGui::RadioButton("physical", &settings_.attenuation_model, 0);
    ImGui::SameLine();
    ImGui::RadioButton("simple", &settings_.attenuation_model, 1);
  }
  if (stage >= kFirstLitStage) {
    ImGui::SliderInt("extra lights", &settings_.extra_lights, 0, kMaxViewerLights);
    ImGui::Checkbox("light markers (M)", &settings_.light_markers);
  }
  if (stage_->ibl) {
    const std::string shown = kit::environment_or_default(settings_.environment);
    if (ImGui::BeginCombo("environment", shown.c_str())) {
      for (const std::string& name : kit::kit_environment_names())
        if (ImGui::Selectable(name.c_str(), name == shown)) settings_.environment = name;
      ImGui::EndCombo();
    }
    // Powers of two, so the Hammersley points stay evenly spread.
    int samples_log2 = static_cast<int>(std::lround(std::log2(std::max(settings_.ibl.prefilter_samples, 1))));
    if (ImGui::SliderInt("prefilter samples", &samples_log2, kMinPrefilterSamplesLog2, kMaxPrefilterSamplesLog2,
                         std::to_string(1 << samples_log2).c_str()))
      settings_.ibl.prefilter_samples = 1 << samples_log2;
    if (const kit::ImageBasedLighting* ibl = renderer_ ? std::as_const(*renderer_).image_based_lighting() : nullptr)
      ImGui::Text("maps precomputed in %.0f ms", 1000.0 * ibl->precompute_seconds());
  }
  ImGui::TextWrapped("camera (F): %s", rig_.flying() ? "fly: WASD, Q/E down/up, right drag looks"
                                                       : "orbit: left drag turns, wheel zooms, right drag pans");
  if (ImGui::Button("reload shaders (R)")) reload_now();
  ImGui::SameLine();
  if (ImGui::Button("screenshot (K)")) screenshot_requested_ = true;
  if (!note_.empty()) ImGui::TextColored(kNoteColor, "%s", note_.c_str());
  if (!error_.empty()) ImGui::TextColored(kErrorColor, "shader error: see below");
  ImGui::PopItemWidth();
  ImGui::End();
}

}  // namespace kit_view

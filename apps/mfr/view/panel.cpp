#include "panel.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <imgui.h>

#include "mfr/core/units.hpp"
#include "mfr/method/method.hpp"
#include "mfr/method/method_options.hpp"

namespace mfr::view {

const std::vector<std::string>& viewerMethods() {
  static const std::vector<std::string> methods = [] {
    std::vector<std::string> m;
    for (const std::string& name : presetNames()) {
      m.push_back(name);
      if (methodPreset(name + "+occupancy")) m.push_back(name + "+occupancy");
    }
    return m;
  }();
  return methods;
}

namespace {

// method, compositing, budget and k; the budget's share of the exact A-buffer when known
void drawMethodControls(ViewSettings& s, const PanelInfo& info, PanelRequests& requests) {
  if (ImGui::BeginCombo("method", s.method.c_str())) {
    for (const std::string& name : viewerMethods())
      if (ImGui::Selectable(name.c_str(), name == s.method)) s.method = name;
    ImGui::EndCombo();
  }
  const char* rules[] = {"preset's own", "kbuffer", "hybrid"};
  int rule = s.composite == "kbuffer" ? 1 : s.composite == "hybrid" ? 2 : 0;
  if (ImGui::Combo("compositing", &rule, rules, 3)) s.composite = rule == 0 ? "" : rules[rule];
  const Frame* f = info.frame;
  float mb = static_cast<float>(static_cast<double>(s.budgetBytes) / 1048576.0);
  const float truthMb =
      f && f->truthBytes ? static_cast<float>(static_cast<double>(f->truthBytes) / 1048576.0) : 0;
  const float maxMb = std::max(16.0f, 2.0f * truthMb);
  if (ImGui::SliderFloat("budget (MB)", &mb, 0.0f, maxMb, "%.2f", ImGuiSliderFlags_Logarithmic))
    s.budgetBytes = static_cast<uint64_t>(std::llround(std::max(0.0f, mb) * 1048576.0));
  if (truthMb > 0) {
    float percent = 100.0f * mb / truthMb;
    if (ImGui::InputFloat("% of exact A-buffer", &percent, 5.0f, 25.0f, "%.1f",
                          ImGuiInputTextFlags_EnterReturnsTrue))
      requests.budgetShare = std::max(0.0f, percent) / 100.0;
    ImGui::Text("  exact A-buffer: %.2f MB", truthMb);
  }
  int k = static_cast<int>(s.k);
  if (ImGui::InputInt("k (0: auto)", &k)) s.k = static_cast<uint32_t>(std::max(0, k));
}

// the variable k-buffer's heuristic importance, Eqs. 3-6
void drawImportanceControls(ImportanceParams& ip, const PanelInfo& info) {
  ImGui::SliderFloat("alpha (Eq. 3)", &ip.alpha, 0.0f, 1.0f, "%.3f");
  ImGui::SliderFloat("N_limit (Eq. 3)", &ip.nLimit, 1.0f, 100.0f, "%.1f");
  ImGui::SliderFloat("periphery d (Eq. 4)", &ip.peripheryExponent, 0.1f, 10.0f, "%.2f");
  ImGui::SliderFloat("noise lambda (Eq. 6)", &ip.noise, 0.0f, 1.0f, "%.3f");
  ImGui::Checkbox("I_d", &ip.useDepth);
  ImGui::SameLine();
  ImGui::Checkbox("I_per", &ip.usePeriphery);
  ImGui::SameLine();
  ImGui::Checkbox("I_f", &ip.useFresnel);
  ImGui::SameLine();
  ImGui::Checkbox("noise", &ip.useNoise);
  bool fovea = ip.fovea.has_value();  // Eq. 4 o: the image centre unless placed
  if (ImGui::Checkbox("fovea o (Eq. 4; ctrl+click the image)", &fovea))
    ip.fovea = fovea ? std::optional<glm::vec2>(glm::vec2(0.5f * info.width, 0.5f * info.height))
                     : std::nullopt;
  if (ip.fovea) {
    ImGui::SliderFloat("fovea x", &ip.fovea->x, 0.0f, static_cast<float>(info.width), "%.0f");
    ImGui::SliderFloat("fovea y", &ip.fovea->y, 0.0f, static_cast<float>(info.height), "%.0f");
  }
}

// the preset's own parameters: occupancy d, importance, the model file
void drawPresetParameters(const MethodDesc& m, ViewSettings& s, const PanelInfo& info) {
  if (m.occupancyWords > 0) {
    int d = s.occupancyD > 0 ? s.occupancyD : m.occupancyWords;
    if (ImGui::SliderInt("occupancy d", &d, 1, 64)) s.occupancyD = d;
  }
  if (m.allocation == AllocationPolicy::Importance &&
      m.importanceSource == ImportanceSource::Heuristic)
    drawImportanceControls(s.importance, info);
  if (checkMethodOption(MethodOption::Model, m)) {
    static char path[1024] = "";
    if (!ImGui::IsAnyItemActive()) std::snprintf(path, sizeof path, "%s", s.model.c_str());
    if (ImGui::InputText("--model (Enter)", path, sizeof path,
                         ImGuiInputTextFlags_EnterReturnsTrue))
      s.model = path;
  }
}

// view mode, wiper split and the A-buffer comparison
void drawViewControls(ViewSettings& s) {
  ImGui::Separator();
  ImGui::Text("view");
  for (ViewMode mode : allViewModes())
    if (ImGui::RadioButton(viewModeLabel(mode), s.mode == mode)) s.mode = mode;
  if (s.mode == ViewMode::Wiper) ImGui::SliderFloat("split", &s.wiper, 0.0f, 1.0f, "%.2f");
  ImGui::Checkbox("compare with the A-buffer (FLIP, PSNR)", &s.compare);
}

// the memory bar (or the bytes used without a budget), bytes by category and F(M)
void drawMemoryStats(const RenderStats& st) {
  if (st.budgetBytes && *st.budgetBytes > 0) {
    char label[96];
    std::snprintf(label, sizeof label, "%s / %s", formatBytes(st.bytesUsed).c_str(),
                  formatBytes(*st.budgetBytes).c_str());
    ImGui::ProgressBar(static_cast<float>(static_cast<double>(st.bytesUsed) / *st.budgetBytes),
                       ImVec2(-1.0f, 0.0f), label);
  } else {
    ImGui::Text("memory %s (no budget)", formatBytes(st.bytesUsed).c_str());
  }
  for (const auto& [category, bytes] : st.bytesByCategory)
    ImGui::Text("  %-20s %s", category.c_str(), formatBytes(bytes).c_str());
  // F(M) (DHOIT Eq. 1): the node slots the budget buys once the per-pixel words are paid
  const auto nodes = st.bytesByCategory.find("nodes");
  if (st.budgetBytes && nodes != st.bytesByCategory.end() && st.fragmentSlots > 0 &&
      st.bytesUsed - nodes->second <= *st.budgetBytes) {
    const uint64_t nodeBytes = nodes->second / st.fragmentSlots;
    const uint64_t fm = (*st.budgetBytes - (st.bytesUsed - nodes->second)) / nodeBytes;
    ImGui::Text("F(M) %llu node slots, %llu allocated", static_cast<unsigned long long>(fm),
                static_cast<unsigned long long>(st.fragmentSlots));
  }
}

// the last frame's memory, fragments, k range, pass times and errors against the A-buffer
void drawFrameStats(const Frame& frame, const PanelInfo& info) {
  const RenderStats& st = *frame.stats;
  drawMemoryStats(st);
  ImGui::Text("fragments %llu  captured %llu",
              static_cast<unsigned long long>(st.fragmentsGenerated),
              static_cast<unsigned long long>(st.captured));
  ImGui::Text("lost %llu (%.2f%%)", static_cast<unsigned long long>(st.lost), st.lostPercent());
  ImGui::SameLine();
  ImGui::Text("  k min %u  max %u", st.kMin, st.kMax);
  for (const PassTime& p : st.passes) ImGui::Text("  %-12s %7.2f ms", p.name.c_str(), p.ms);
  ImGui::Text("passes %.2f ms, update %.1f ms, frame %.1f ms", st.totalMs(), frame.renderMs,
              info.frameMs);
  if (frame.flipMean) ImGui::Text("mean FLIP vs A-buffer %.5f", *frame.flipMean);
  if (frame.psnr) ImGui::Text("PSNR vs A-buffer %.2f dB", *frame.psnr);
}

// the render in flight, the notice and the frame's error, then its statistics
void drawStatistics(const PanelInfo& info) {
  const Frame* f = info.frame;
  ImGui::Separator();
  if (info.rendering) ImGui::TextColored(ImVec4(1.0f, 0.8f, 0.3f, 1.0f), "rendering ...");
  if (!info.notice.empty())
    ImGui::TextColored(ImVec4(1.0f, 0.4f, 0.4f, 1.0f), "%s", info.notice.c_str());
  if (f && !f->error.empty())
    ImGui::TextColored(ImVec4(1.0f, 0.4f, 0.4f, 1.0f), "%s", f->error.c_str());
  if (f && f->stats) drawFrameStats(*f, info);
}

// camera help, file cameras, field of view and the action buttons
void drawCameraAndActions(ViewSettings& s, const PanelInfo& info, PanelRequests& requests) {
  ImGui::Separator();
  ImGui::TextWrapped(
      "left drag: orbit, right drag: pan, wheel: zoom, WASD: fly, Q/E: down/up, "
      "[ ]: previous/next file camera, R: reset");
  if (info.fileCameras > 0) {
    ImGui::Text("file camera %d of %d", info.fileCamera, info.fileCameras);
    ImGui::SameLine();
    if (ImGui::Button("<")) requests.nextCamera = -1;
    ImGui::SameLine();
    if (ImGui::Button(">")) requests.nextCamera = 1;
  }
  float fov = s.camera.camera().fovYDegrees;
  if (ImGui::SliderFloat("fov", &fov, 5.0f, 120.0f, "%.1f")) s.camera.setFov(fov);
  if (ImGui::Button("reset camera")) s.camera.reset();
  ImGui::SameLine();
  if (ImGui::Button("screenshot")) requests.screenshot = true;
  ImGui::SameLine();
  if (ImGui::Button("all maps")) requests.screenshotMaps = true;
  ImGui::SameLine();
  if (ImGui::Button("copy command")) requests.copyCommand = true;
}

}  // namespace

PanelRequests drawPanel(float x, float width, float height, ViewSettings& s,
                        const PanelInfo& info) {
  PanelRequests requests;
  ImGui::SetNextWindowPos(ImVec2(x, 0.0f));
  ImGui::SetNextWindowSize(ImVec2(width, height));
  ImGui::Begin("mfr view", nullptr,
               ImGuiWindowFlags_NoMove | ImGuiWindowFlags_NoResize | ImGuiWindowFlags_NoCollapse);
  ImGui::PushItemWidth(width * 0.42f);  // widgets leave room for their labels on the right
  ImGui::Text("%s  %dx%d  engine %s", info.scene.c_str(), info.width, info.height,
              info.engine.c_str());
  drawMethodControls(s, info, requests);
  if (auto preset = methodPreset(s.method)) drawPresetParameters(preset.value(), s, info);
  drawViewControls(s);
  drawStatistics(info);
  drawCameraAndActions(s, info, requests);
  ImGui::PopItemWidth();
  ImGui::End();
  return requests;
}

}  // namespace mfr::view

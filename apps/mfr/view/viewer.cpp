#include "viewer.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <fstream>
#include <future>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>
#include <nlohmann/json.hpp>

#include "engine_context.hpp"
#include "frame_renderer.hpp"
#include "image_texture.hpp"
#include "mfr/core/atomic_file.hpp"
#include "mfr/core/json_limits.hpp"
#include "mfr/core/quote.hpp"
#include "mfr/core/units.hpp"
#include "mfr/method/method.hpp"
#include "mfr/method/peel.hpp"
#include "panel.hpp"
#include "script.hpp"

namespace mfr::view {

namespace {

constexpr int kPanelWidth = 380;
std::string glfwLastError;
std::vector<std::string> droppedPaths;  // files dropped on the window since the last frame

void onGlfwError(int, const char* description) {
  glfwLastError = description ? description : "?";
}

void onDrop(GLFWwindow*, int count, const char** paths) {
  for (int i = 0; i < count; ++i) droppedPaths.emplace_back(paths[i]);
}

int failNoWindow(const std::string& what) {
  return cli::fail("view: " + what + " (" + glfwLastError +
                   "); `mfr render` writes the same images without a window");
}

std::string shellQuote(const std::string& text) {
  if (text.find_first_of(" ?&*;'\"$|<>()") == std::string::npos) return text;
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

std::string number(float x) {
  char text[32];
  std::snprintf(text, sizeof text, "%.9g", x);
  return text;
}

/// render's options for the preset's own parameters that differ from their defaults.
std::string methodParameters(const ViewSettings& s) {
  std::string cmd;
  auto preset = methodPreset(s.method);
  if (!preset) return cmd;
  const MethodDesc& m = preset.value();
  if (m.occupancyWords > 0 && s.occupancyD > 0)
    cmd += " --occupancy-d " + std::to_string(s.occupancyD);
  if (peelingRule(m.compositing) && s.maxPeels > 0)
    cmd += " --max-peels " + std::to_string(s.maxPeels);
  if (m.allocation == AllocationPolicy::Importance) {
    const ImportanceParams ip = s.importance, d{};
    if (ip.alpha != d.alpha) cmd += " --importance-alpha " + number(ip.alpha);
    if (ip.nLimit != d.nLimit) cmd += " --n-limit " + number(ip.nLimit);
    if (ip.peripheryExponent != d.peripheryExponent)
      cmd += " --periphery-d " + number(ip.peripheryExponent);
    if (ip.noise != d.noise) cmd += " --noise " + number(ip.noise);
    if (ip.fovea) cmd += " --fovea " + number(ip.fovea->x) + "," + number(ip.fovea->y);
    if (!ip.useDepth) cmd += " --no-depth-term";
    if (!ip.usePeriphery) cmd += " --no-periphery-term";
    if (!ip.useFresnel) cmd += " --no-fresnel-term";
    if (!ip.useNoise) cmd += " --no-noise";
  }
  if (!s.model.empty()) cmd += " --model " + shellQuote(s.model);
  return cmd;
}

std::string renderCommand(const cli::SceneOptions& a, const ViewSettings& s) {
  std::string cmd =
      "mfr render " + shellQuote(a.source) + " --engine " + a.engine + " --method " + s.method;
  if (!s.composite.empty()) cmd += " --composite " + s.composite;
  if (s.budgetBytes > 0) cmd += " --budget " + std::to_string(s.budgetBytes);
  if (s.k > 0) cmd += " --k " + std::to_string(s.k);
  cmd += methodParameters(s);
  if (a.alpha) cmd += " --alpha " + std::to_string(*a.alpha);
  if (a.seed != 1) cmd += " --seed " + std::to_string(a.seed);
  cmd += " --width " + std::to_string(a.width) + " --height " + std::to_string(a.height) +
         " --camera " + s.camera.spec() + " -o view.png";
  return cmd;
}

/// The `mfr compare` line of the same view: the current method at the current budget (compare
/// needs a budget: without one, the exact A-buffer's bytes). compare has no --k: k is left out.
std::string compareCommand(const cli::SceneOptions& a, const ViewSettings& s, uint64_t truthBytes) {
  const uint64_t budget = s.budgetBytes > 0 ? s.budgetBytes : truthBytes;
  std::string cmd =
      "mfr compare " + shellQuote(a.source) + " --engine " + a.engine + " --methods " + s.method;
  if (!s.composite.empty()) cmd += " --composite " + s.composite;
  if (!s.model.empty()) cmd += " --model " + shellQuote(s.model);
  if (budget > 0) cmd += " --budget " + std::to_string(budget);
  if (a.alpha) cmd += " --alpha " + std::to_string(*a.alpha);
  if (a.seed != 1) cmd += " --seed " + std::to_string(a.seed);
  cmd += " --width " + std::to_string(a.width) + " --height " + std::to_string(a.height) +
         " --camera " + s.camera.spec() + " -o compare";
  return cmd;
}

nlohmann::json statsEntry(int frame, const ViewSettings& s, const Frame& f) {
  nlohmann::json j;
  j["frame"] = frame;
  j["method"] = s.method;
  j["mode"] = viewModeName(s.mode);
  j["budget_bytes"] = s.budgetBytes;
  j["camera"] = s.camera.spec();
  if (s.importance.fovea) j["fovea"] = {s.importance.fovea->x, s.importance.fovea->y};
  j["truth_bytes"] = f.truthBytes;
  j["error"] = f.error;
  j["update_ms"] = f.renderMs;
  j["display_width"] = f.display.width;
  j["display_height"] = f.display.height;
  if (f.stats) {
    j["bytes_used"] = f.stats->bytesUsed;
    j["fragments"] = f.stats->fragmentsGenerated;
    j["captured"] = f.stats->captured;
    j["lost"] = f.stats->lost;
    j["k_min"] = f.stats->kMin;
    j["k_max"] = f.stats->kMax;
    j["passes_ms"] = f.stats->totalMs();
    j["bytes_by_category"] = f.stats->bytesByCategory;
  }
  if (f.flipMean) j["flip_mean"] = *f.flipMean;
  if (f.psnr && std::isfinite(*f.psnr)) j["psnr"] = *f.psnr;
  return j;
}

/// The image and every map of the settings, each as its view mode shows it: PREFIX-MODE.png.
/// Modes the method has no map for (importance of a fixed-k method) are left out.
std::vector<std::string> screenshotMaps(FrameRenderer& renderer, const ViewSettings& settings,
                                        const std::string& prefix, std::string& error) {
  std::vector<std::string> written;
  for (ViewMode mode : allViewModes()) {
    if (mode == ViewMode::Wiper) continue;  // the image and the truth are written on their own
    ViewSettings s = settings;
    s.mode = mode;
    const Frame f = renderer.update(s);
    if (!f.error.empty()) continue;
    const std::string path = prefix + "-" + viewModeName(mode) + ".png";
    if (auto ok = writePng(path, f.display); !ok) {
      error = ok.error().message;
      break;
    }
    written.push_back(path);
  }
  return written;
}

// What the options set before a window opens: the scene, the first settings and the script.
struct SessionSetup {
  std::unique_ptr<cli::PreparedScene> prepared;
  ViewSettings settings;
  std::vector<nlohmann::json> steps;
  int frames = 0;  // --frames, or 2 for a lone --screenshot
};

// the options first, with render's errors
Result<SessionSetup> setUpSession(const ViewerArgs& a) {
  auto preparedResult = cli::prepareScene(a.scene);
  if (!preparedResult) return preparedResult.error();
  auto prepared = std::make_unique<cli::PreparedScene>(std::move(preparedResult.value()));
  ViewSettings settings(prepared->cameras.front());
  settings.method = a.method;
  settings.composite = a.composite;
  if (!a.budget.empty()) {
    auto budget = parseByteSize(a.budget);
    if (!budget) return budget.error();
    settings.budgetBytes = budget.value();
  }
  if (a.k) settings.k = *a.k;
  settings.occupancyD = a.occupancyD;
  settings.maxPeels = a.maxPeels;
  settings.model = a.model;
  settings.importance.seed = a.scene.seed;  // as render's ImportanceParams
  auto mode = parseViewMode(a.mode);
  if (!mode)
    return makeError("--mode " + quoteInput(a.mode) +
                     ": expected image, depth, kmap, importance, truth, flip or wiper");
  settings.mode = *mode;
  MFR_TRY(settingsMethod(settings));
  std::vector<nlohmann::json> steps;
  if (!a.script.empty()) {
    auto loaded = loadScript(a.script);
    if (!loaded) return loaded.error();
    steps = std::move(loaded.value());
  }
  if (a.frames < 0) return makeError("--frames: must be >= 0");
  const int frames = a.frames == 0 && !a.screenshot.empty() && a.script.empty() ? 2 : a.frames;
  return SessionSetup{std::move(prepared), std::move(settings), std::move(steps), frames};
}

// The window and its GL 3.3 core context (not current); the error says what is missing.
Result<GLFWwindow*> openWindow(int w, int h) {
  glfwSetErrorCallback(onGlfwError);
  if (!glfwInit()) return makeError("no display to open a window on");
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);
  GLFWwindow* window =
      glfwCreateWindow(w + kPanelWidth, std::max(h + 80, 720), "mfr view", nullptr, nullptr);
  if (window == nullptr) {
    glfwTerminate();
    return makeError("no OpenGL 3.3 context for a window");
  }
  return window;
}

void startImGui(GLFWwindow* window) {
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;
  ImGui::StyleColorsDark();
  ImGui_ImplGlfw_InitForOpenGL(window, true);
  ImGui_ImplOpenGL3_Init("#version 330");
  glfwSetDropCallback(window, onDrop);
}

void stopImGui() {
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
}

// pixels unlike the top-left one: 0 for an empty (uniform) shot
size_t pixelsUnlikeCorner(const Image8& shot) {
  size_t differing = 0;
  for (size_t i = 0; i < shot.rgba.size(); i += 4)
    differing += shot.rgba[i] != shot.rgba[0] || shot.rgba[i + 1] != shot.rgba[1] ||
                 shot.rgba[i + 2] != shot.rgba[2];
  return differing;
}

// The session loop's state: the scene shown, the settings, the renderer (on a worker thread or
// in step), the frame on screen and what the stats file collects. One runFrame per loop turn.
class ViewerSession {
 public:
  ViewerSession(const ViewerArgs& a, SessionSetup& setup, Engine& engine,
                EngineContext& engineContext, GLFWwindow* window, bool renderThread)
      : a_(a),
        prepared_(*setup.prepared),
        settings_(setup.settings),
        steps_(setup.steps),
        frames_(setup.frames),
        engine_(engine),
        engineContext_(engineContext),
        window_(window),
        scripted_(setup.frames > 0 || !setup.steps.empty()),
        renderThread_(renderThread),
        w_(a.scene.width),
        h_(a.scene.height),
        sceneOptions_(a.scene),
        fileCamera_(a.scene.view),
        renderer_(std::make_unique<FrameRenderer>(engine, engineContext, window, prepared_,
                                                  sceneOptions_)) {}

  // Runs until the window closes, the frames or the script end, or an error; the exit code.
  int run() {
    int framesShown = 0;
    for (int n = 0; !glfwWindowShouldClose(window_); framesShown = ++n)
      if (!runFrame(n)) break;
    if (inFlight_.valid()) finishRender(framesShown);  // waits; before the renderer goes
    if (!a_.statsJson.empty()) writeStats();
    texture_.destroy();
    return exitCode_;
  }

 private:
  // One turn of the loop: events, the script's step, input, the panel, a render of what changed,
  // screenshots and the window's frame. False ends the session.
  bool runFrame(int n) {
    const auto start = std::chrono::steady_clock::now();
    if (scripted_)
      glfwPollEvents();
    else
      glfwWaitEventsTimeout(0.1);  // idle: no busy loop (the worker posts an event when done)
    FrameActions actions;
    // a screenshot sees its own step, and a step the render of the one before
    if (step_ < steps_.size() && pendingShots_.empty() && idle_) {
      if (auto ok = applyStep(steps_[step_++], settings_, actions); !ok) {
        exitCode_ = cli::fail("--script: " + ok.error().message);
        return false;
      }
    }
    for (const std::string& path : droppedPaths) actions.open = path;  // the last one dropped
    droppedPaths.clear();
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    const ImGuiIO& io = ImGui::GetIO();
    if (glfwGetKey(window_, GLFW_KEY_ESCAPE) == GLFW_PRESS) glfwSetWindowShouldClose(window_, 1);
    if (!io.WantCaptureKeyboard) handleKeys(actions);
    handleMouse(io);
    int fbW = 0, fbH = 0;
    glfwGetFramebufferSize(window_, &fbW, &fbH);
    const PanelRequests requests = drawPanelOf(fbW, fbH);
    if (requests.nextCamera != 0) actions.nextCamera = requests.nextCamera;
    if (requests.budgetShare) actions.budgetShare = requests.budgetShare;
    if (!applySceneActions(actions)) return false;
    // while the camera is dragged, skip the A-buffer and FLIP (rendered again on release)
    ViewSettings shown = settings_;
    if (ImGui::IsMouseDown(ImGuiMouseButton_Left) || ImGui::IsMouseDown(ImGuiMouseButton_Right))
      shown.compare = shown.compare && io.WantCaptureMouse;
    bool updated = renderWhatChanged(shown, n);
    idle_ = !inFlight_.valid() && shownKey_ == shown.displayKey();
    if (requests.screenshotMaps)
      actions.screenshotMaps.push_back("mfr-view-" + std::to_string(++screenshotCount_));
    if (!actions.screenshotMaps.empty() && inFlight_.valid()) {  // the renderer is the worker's
      inFlight_.wait();
      updated = finishRender(n) || updated;
    }
    writeMapScreenshots(actions.screenshotMaps, shown, n);
    if (requests.copyCommand || actions.copyCommand) copyCommands();
    if (requests.screenshot)
      pendingShots_.emplace_back("mfr-view-" + std::to_string(++screenshotCount_) + ".png", false);
    for (const std::string& p : actions.screenshots) pendingShots_.emplace_back(p, false);
    for (const std::string& p : actions.screenshotsUi) pendingShots_.emplace_back(p, true);
    const bool last = idle_ && (frames_ > 0 ? n + 1 >= frames_
                                            : !steps_.empty() && step_ >= steps_.size() &&
                                                  pendingShots_.empty() && !updated);
    if (last && !a_.screenshot.empty()) pendingShots_.emplace_back(a_.screenshot, a_.screenshotUi);
    drawWindow(fbW, fbH);
    // screenshots of a frame whose panel already shows its render's statistics
    if (idle_ && (!updated || last)) takePendingShots(n, fbW, fbH);
    glfwSwapBuffers(window_);
    frameMs_ =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    windowFrameMs_.push_back(frameMs_);
    return !(exitCode_ != 0 || (last && pendingShots_.empty()));
  }

  // WASD fly, Q/E down/up, [ ] file cameras, R reset
  void handleKeys(FrameActions& actions) {
    auto pressed = [&](int key) {  // went down since the last frame
      const bool isDown = glfwGetKey(window_, key) == GLFW_PRESS;
      const bool was = keysDown_[key];
      keysDown_[key] = isDown;
      return isDown && !was;
    };
    auto down = [&](int key) { return glfwGetKey(window_, key) == GLFW_PRESS ? 1.0f : 0.0f; };
    const float flyStep = 0.5f * static_cast<float>(std::min(frameMs_, 100.0) / 1000.0);
    const float right = down(GLFW_KEY_D) - down(GLFW_KEY_A);
    const float up = down(GLFW_KEY_E) - down(GLFW_KEY_Q);
    const float forward = down(GLFW_KEY_W) - down(GLFW_KEY_S);
    if (right != 0.0f || up != 0.0f || forward != 0.0f)
      settings_.camera.fly(right * flyStep, up * flyStep, forward * flyStep);
    if (pressed(GLFW_KEY_RIGHT_BRACKET)) actions.nextCamera = 1;
    if (pressed(GLFW_KEY_LEFT_BRACKET)) actions.nextCamera = -1;
    if (pressed(GLFW_KEY_R)) settings_.camera.reset();
  }

  // on the image: ctrl+click places the fovea (Eq. 4 o), drags orbit and pan, the wheel zooms
  void handleMouse(const ImGuiIO& io) {
    if (!io.WantCaptureMouse && io.MousePos.x < w_ && io.MousePos.y < h_ && io.KeyCtrl &&
        ImGui::IsMouseClicked(ImGuiMouseButton_Left)) {  // ctrl+click: the fovea (Eq. 4 o)
      settings_.importance.fovea = glm::vec2(io.MousePos.x, io.MousePos.y);
    } else if (!io.WantCaptureMouse && io.MousePos.x < w_) {  // the camera, on the image
      if (ImGui::IsMouseDragging(ImGuiMouseButton_Left, 0.0f))
        settings_.camera.orbit(-0.3f * io.MouseDelta.x, 0.3f * io.MouseDelta.y);
      if (ImGui::IsMouseDragging(ImGuiMouseButton_Right, 0.0f) ||
          ImGui::IsMouseDragging(ImGuiMouseButton_Middle, 0.0f))
        settings_.camera.pan(io.MouseDelta.x / h_, io.MouseDelta.y / h_);
      if (io.MouseWheel != 0.0f) settings_.camera.zoom(std::pow(1.1f, io.MouseWheel));
    }
  }

  PanelRequests drawPanelOf(int fbW, int fbH) {
    PanelInfo info{sceneOptions_.source,
                   sceneOptions_.engine,
                   w_,
                   h_,
                   &frame_,
                   frameMs_,
                   static_cast<int>(prepared_.scene.cameras.size()),
                   fileCamera_,
                   notice_,
                   inFlight_.valid()};
    return drawPanel(static_cast<float>(w_), static_cast<float>(fbW - w_), static_cast<float>(fbH),
                     settings_, info);
  }

  // a scene to open, a file camera to choose or step to, a budget share; false: a scripted file
  // camera that does not exist ends the session
  bool applySceneActions(const FrameActions& actions) {
    if (!actions.open.empty()) openScene(actions.open);
    if (actions.fileCamera && !chooseFileCamera(*actions.fileCamera) && !steps_.empty()) {
      exitCode_ = cli::fail("--script: " + notice_);
      return false;
    }
    if (actions.nextCamera != 0 && !prepared_.scene.cameras.empty()) {
      const int count = static_cast<int>(prepared_.scene.cameras.size());
      chooseFileCamera(fileCamera_ < 0 ? (actions.nextCamera > 0 ? 0 : count - 1)
                                       : (fileCamera_ + actions.nextCamera + count) % count);
    }
    if (actions.budgetShare) {
      if (frame_.truthBytes > 0)
        settings_.budgetBytes = static_cast<uint64_t>(
            std::llround(*actions.budgetShare * static_cast<double>(frame_.truthBytes)));
      else
        notice_ = "budget share: the exact A-buffer is not rendered (compare is off)";
    }
    return true;
  }

  // Takes the worker's finished frame, then starts a render of `shown` if its display changed
  // (on the worker, or here in step); true when a new frame is on screen.
  bool renderWhatChanged(const ViewSettings& shown, int n) {
    bool updated = false;
    if (inFlight_.valid() &&
        inFlight_.wait_for(std::chrono::seconds(0)) == std::future_status::ready)
      updated = finishRender(n);
    if (shown.displayKey() != shownKey_ && !inFlight_.valid()) {  // re-render only what changed
      if (renderThread_) {
        inFlightKey_ = shown.displayKey();
        inFlightSettings_ = settings_;
        inFlight_ = std::async(std::launch::async, [&r = *renderer_, shown] {
          Frame f = r.update(shown);
          glfwPostEmptyEvent();  // wakes the event wait of the window's thread
          return f;
        });
      } else {
        frame_ = renderer_->update(shown);
        shownKey_ = shown.displayKey();
        texture_.upload(frame_.display);
        renders_.push_back(statsEntry(n, settings_, frame_));
        updated = true;
      }
    }
    return updated;
  }

  // takes the worker's frame once it is done
  bool finishRender(int n) {
    if (!inFlight_.valid()) return false;
    frame_ = inFlight_.get();
    shownKey_ = inFlightKey_;
    texture_.upload(frame_.display);
    renders_.push_back(statsEntry(n, *inFlightSettings_, frame_));
    return true;
  }

  // the file camera `index` of the scene, with --zoom as `mfr render --view` applies it
  bool chooseFileCamera(int index) {
    auto chosen = fileCamera(prepared_.scene, sceneOptions_.source, index);  // as --view picks
    if (!chosen) {
      notice_ = chosen.error().message;
      return false;
    }
    Camera camera = chosen.value();
    camera.eye = camera.target + (camera.eye - camera.target) / static_cast<float>(a_.scene.zoom);
    settings_.camera.restart(camera);
    fileCamera_ = index;
    notice_.clear();
    return true;
  }

  // a dropped (or scripted) scene file replaces the scene; on an error the old one stays
  void openScene(const std::string& path) {
    cli::SceneOptions o = sceneOptions_;
    o.source = path;
    o.view = -1;
    o.camera.clear();
    o.orbit = 0;
    o.orbitView = -1;
    auto loaded = cli::prepareScene(o);
    if (!loaded) {
      notice_ = loaded.error().message;
      return;
    }
    if (inFlight_.valid()) inFlight_.wait();  // the worker uses the old scene
    inFlight_ = {};
    renderer_.reset();  // it refers to the old scene
    prepared_ = std::move(loaded.value());
    sceneOptions_ = o;
    renderer_ =
        std::make_unique<FrameRenderer>(engine_, engineContext_, window_, prepared_, sceneOptions_);
    settings_.camera.restart(prepared_.cameras.front());
    fileCamera_ = -1;
    shownKey_.clear();
    notice_.clear();
  }

  // the image and every map of `shown` for each prefix asked for
  void writeMapScreenshots(const std::vector<std::string>& prefixes, const ViewSettings& shown,
                           int n) {
    for (const std::string& prefix : prefixes) {
      std::string error;
      for (const std::string& path : screenshotMaps(*renderer_, shown, prefix, error)) {
        nlohmann::json j = statsEntry(n, settings_, frame_);
        j["path"] = path;
        j["maps_of"] = prefix;
        shots_.push_back(j);
        if (!scripted_) std::printf("screenshot: %s\n", path.c_str());
      }
      if (!error.empty()) exitCode_ = cli::fail(error);
    }
  }

  // the render and compare command lines of the view: to the clipboard and stdout
  void copyCommands() {
    const std::string cmd = renderCommand(sceneOptions_, settings_);
    const std::string compare = compareCommand(sceneOptions_, settings_, frame_.truthBytes);
    glfwSetClipboardString(window_, (cmd + "\n" + compare).c_str());
    std::printf("%s\n%s\n", cmd.c_str(), compare.c_str());
    std::fflush(stdout);
  }

  void drawWindow(int fbW, int fbH) {
    texture_.draw();
    ImGui::Render();
    glViewport(0, 0, fbW, fbH);
    glClearColor(0.1f, 0.1f, 0.1f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
  }

  // the queued screenshots (the image area, or the whole window with the panel), each with its
  // statistics; a write error stops at that one
  void takePendingShots(int n, int fbW, int fbH) {
    while (!pendingShots_.empty()) {
      const auto [path, ui] = pendingShots_.front();
      pendingShots_.pop_front();
      const Image8 shot =
          ui ? readWindow(fbH, fbW, fbH) : readWindow(fbH, texture_.width(), texture_.height());
      if (auto written = writePng(path, shot); !written) {
        exitCode_ = cli::fail(written.error().message);
        break;
      }
      nlohmann::json j = statsEntry(n, settings_, frame_);
      j["scene"] = sceneOptions_.source;
      j["file_camera"] = fileCamera_;
      j["notice"] = notice_;
      j["path"] = path;
      j["ui"] = ui;
      j["width"] = shot.width;
      j["height"] = shot.height;
      j["pixels_unlike_corner"] = pixelsUnlikeCorner(shot);
      shots_.push_back(j);
      if (!scripted_) std::printf("screenshot: %s\n", path.c_str());
    }
  }

  // --stats-json: every render, every screenshot and how long the window waited for its frames
  void writeStats() {
    nlohmann::json out{{"renders", renders_}, {"screenshots", shots_}};
    if (!windowFrameMs_.empty()) {  // how long the window waited for its frames
      std::vector<double> sorted = windowFrameMs_;
      std::sort(sorted.begin(), sorted.end());
      out["window_frames"] = {{"count", sorted.size()},
                              {"median_ms", sorted[sorted.size() / 2]},
                              {"p95_ms", sorted[sorted.size() * 95 / 100]},
                              {"max_ms", sorted.back()},
                              {"render_thread", renderThread_}};
    }
    if (auto written = writeFileAtomically(a_.statsJson, jsonText(out) + "\n"); !written)
      exitCode_ = cli::fail(written.error().message);
  }

  const ViewerArgs& a_;
  cli::PreparedScene& prepared_;
  ViewSettings& settings_;
  const std::vector<nlohmann::json>& steps_;
  const int frames_;
  Engine& engine_;
  EngineContext& engineContext_;
  GLFWwindow* window_;
  const bool scripted_;
  const bool renderThread_;
  const int w_, h_;
  cli::SceneOptions sceneOptions_;  // of the scene shown (a dropped file replaces it)
  int fileCamera_;
  std::unique_ptr<FrameRenderer> renderer_;
  ImageTexture texture_;
  Frame frame_;
  std::string shownKey_;
  nlohmann::json renders_ = nlohmann::json::array(), shots_ = nlohmann::json::array();
  std::deque<std::pair<std::string, bool>> pendingShots_;  // path, with the panel
  size_t step_ = 0;
  double frameMs_ = 0.0;
  std::vector<double> windowFrameMs_;  // each loop iteration's wall time (responsiveness)
  int screenshotCount_ = 0;
  std::map<int, bool> keysDown_;
  std::string notice_;           // a scene that did not open, or a file camera that does not exist
  std::future<Frame> inFlight_;  // the worker's render (renderThread)
  std::string inFlightKey_;
  std::optional<ViewSettings> inFlightSettings_;
  bool idle_ = true;  // the image shows the current settings and no render is in flight
  int exitCode_ = 0;
};

}  // namespace

int runViewer(const ViewerArgs& a) {
  if (a.listMethods) {
    for (const std::string& m : viewerMethods()) std::printf("%s\n", m.c_str());
    return 0;
  }
  auto setup = setUpSession(a);
  if (!setup) return cli::fail(setup.error().message);
  auto window = openWindow(a.scene.width, a.scene.height);
  if (!window) return failNoWindow(window.error().message);
  // the engine makes its own (headless) context current: not while the window's is
  glfwMakeContextCurrent(nullptr);
  auto engine = cli::makeSceneEngine(a.scene);
  EngineContext engineContext;
  engineContext.captureCurrent();
  engineContext.release();
  if (!engine) {
    glfwDestroyWindow(*window);
    glfwTerminate();
    return cli::fail(engine.error().message);
  }
  glfwMakeContextCurrent(*window);
  const bool scripted = setup->frames > 0 || !setup->steps.empty();
  // interactive sessions render on a worker thread (the engine's own context is made current
  // there), so the window keeps drawing and taking input while a frame renders; scripted sessions
  // render in step unless --render-thread on asks otherwise
  const bool renderThread = a.renderThread == "on" || (a.renderThread == "auto" && !scripted);
  glfwSwapInterval(scripted ? 0 : 1);
  startImGui(*window);

  int exitCode = 0;
  {
    ViewerSession session(a, *setup, **engine, engineContext, *window, renderThread);
    exitCode = session.run();
  }  // the renderer frees the engine's views in the engine's context
  stopImGui();
  glfwMakeContextCurrent(nullptr);
  {
    engineContext.makeCurrent();
    engine.value().reset();
    engineContext.release();
  }
  glfwDestroyWindow(*window);
  glfwTerminate();
  return exitCode;
}

}  // namespace mfr::view

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
#include "mfr/core/quote.hpp"
#include "mfr/core/units.hpp"
#include "mfr/method/method.hpp"
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

}  // namespace

int runViewer(const ViewerArgs& a) {
  if (a.listMethods) {
    for (const std::string& m : viewerMethods()) std::printf("%s\n", m.c_str());
    return 0;
  }
  // the options first, with render's errors
  auto preparedResult = cli::prepareScene(a.scene);
  if (!preparedResult) return cli::fail(preparedResult.error().message);
  auto prepared = std::make_unique<cli::PreparedScene>(std::move(preparedResult.value()));
  cli::SceneOptions sceneOptions = a.scene;  // of the scene shown (a dropped file replaces it)
  int fileCamera = a.scene.view;
  ViewSettings settings(prepared->cameras.front());
  settings.method = a.method;
  settings.composite = a.composite;
  if (!a.budget.empty()) {
    auto budget = parseByteSize(a.budget);
    if (!budget) return cli::fail(budget.error().message);
    settings.budgetBytes = budget.value();
  }
  if (a.k) settings.k = *a.k;
  settings.occupancyD = a.occupancyD;
  settings.model = a.model;
  settings.importance.seed = a.scene.seed;  // as render's ImportanceParams
  auto mode = parseViewMode(a.mode);
  if (!mode)
    return cli::fail("--mode " + quoteInput(a.mode) +
                     ": expected image, depth, kmap, importance, truth, flip or wiper");
  settings.mode = *mode;
  if (auto method = settingsMethod(settings); !method) return cli::fail(method.error().message);
  std::vector<nlohmann::json> steps;
  if (!a.script.empty()) {
    auto loaded = loadScript(a.script);
    if (!loaded) return cli::fail(loaded.error().message);
    steps = std::move(loaded.value());
  }
  if (a.frames < 0) return cli::fail("--frames: must be >= 0");
  const int frames = a.frames == 0 && !a.screenshot.empty() && a.script.empty() ? 2 : a.frames;

  // the window and its GL context
  glfwSetErrorCallback(onGlfwError);
  if (!glfwInit()) return failNoWindow("no display to open a window on");
  const int w = a.scene.width, h = a.scene.height;
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);
  GLFWwindow* window =
      glfwCreateWindow(w + kPanelWidth, std::max(h + 80, 720), "mfr view", nullptr, nullptr);
  if (window == nullptr) {
    glfwTerminate();
    return failNoWindow("no OpenGL 3.3 context for a window");
  }
  // the engine makes its own (headless) context current: not while the window's is
  glfwMakeContextCurrent(nullptr);
  auto engine = cli::makeSceneEngine(a.scene);
  EngineContext engineContext;
  engineContext.captureCurrent();
  engineContext.release();
  if (!engine) {
    glfwDestroyWindow(window);
    glfwTerminate();
    return cli::fail(engine.error().message);
  }
  glfwMakeContextCurrent(window);
  const bool scripted = frames > 0 || !steps.empty();
  // interactive sessions render on a worker thread (the engine's own context is made current
  // there), so the window keeps drawing and taking input while a frame renders; scripted sessions
  // render in step unless --render-thread on asks otherwise
  const bool renderThread = a.renderThread == "on" || (a.renderThread == "auto" && !scripted);
  glfwSwapInterval(scripted ? 0 : 1);
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;
  ImGui::StyleColorsDark();
  ImGui_ImplGlfw_InitForOpenGL(window, true);
  ImGui_ImplOpenGL3_Init("#version 330");
  glfwSetDropCallback(window, onDrop);

  int exitCode = 0;
  {
    auto renderer =
        std::make_unique<FrameRenderer>(**engine, engineContext, window, *prepared, sceneOptions);
    ImageTexture texture;
    Frame frame;
    std::string shownKey;
    nlohmann::json renders = nlohmann::json::array(), shots = nlohmann::json::array();
    std::deque<std::pair<std::string, bool>> pendingShots;  // path, with the panel
    size_t step = 0;
    double frameMs = 0.0;
    std::vector<double> windowFrameMs;  // each loop iteration's wall time (responsiveness)
    int screenshotCount = 0;
    std::map<int, bool> keysDown;
    std::string notice;           // a scene that did not open, or a file camera that does not exist
    std::future<Frame> inFlight;  // the worker's render (renderThread)
    std::string inFlightKey;
    std::optional<ViewSettings> inFlightSettings;
    bool idle = true;  // the image shows the current settings and no render is in flight
    auto finishRender = [&](int n) {  // takes the worker's frame once it is done
      if (!inFlight.valid()) return false;
      frame = inFlight.get();
      shownKey = inFlightKey;
      texture.upload(frame.display);
      renders.push_back(statsEntry(n, *inFlightSettings, frame));
      return true;
    };
    // the file camera `index` of the scene, with --zoom as `mfr render --view` applies it
    auto chooseFileCamera = [&](int index) {
      const std::vector<Camera>& cameras = prepared->scene.cameras;
      if (index < 0 || index >= static_cast<int>(cameras.size())) {
        notice = echoPath(sceneOptions.source) + ": no camera " + std::to_string(index) +
                 ", the scene has " + std::to_string(cameras.size()) + " camera(s)";
        return false;
      }
      Camera camera = cameras[index];
      camera.eye = camera.target + (camera.eye - camera.target) / static_cast<float>(a.scene.zoom);
      settings.camera.restart(camera);
      fileCamera = index;
      notice.clear();
      return true;
    };
    // a dropped (or scripted) scene file replaces the scene; on an error the old one stays
    auto openScene = [&](const std::string& path) {
      cli::SceneOptions o = sceneOptions;
      o.source = path;
      o.view = -1;
      o.camera.clear();
      o.orbit = 0;
      o.orbitView = -1;
      auto loaded = cli::prepareScene(o);
      if (!loaded) {
        notice = loaded.error().message;
        return;
      }
      if (inFlight.valid()) inFlight.wait();  // the worker uses the old scene
      inFlight = {};
      renderer.reset();  // it refers to the old scene
      *prepared = std::move(loaded.value());
      sceneOptions = o;
      renderer =
          std::make_unique<FrameRenderer>(**engine, engineContext, window, *prepared, sceneOptions);
      settings.camera.restart(prepared->cameras.front());
      fileCamera = -1;
      shownKey.clear();
      notice.clear();
    };
    int framesShown = 0;
    for (int n = 0; !glfwWindowShouldClose(window); framesShown = ++n) {
      const auto start = std::chrono::steady_clock::now();
      if (scripted)
        glfwPollEvents();
      else
        glfwWaitEventsTimeout(0.1);  // idle: no busy loop (the worker posts an event when done)
      FrameActions actions;
      // a screenshot sees its own step, and a step the render of the one before
      if (step < steps.size() && pendingShots.empty() && idle) {
        if (auto ok = applyStep(steps[step++], settings, actions); !ok) {
          exitCode = cli::fail("--script: " + ok.error().message);
          break;
        }
      }
      for (const std::string& path : droppedPaths) actions.open = path;  // the last one dropped
      droppedPaths.clear();
      ImGui_ImplOpenGL3_NewFrame();
      ImGui_ImplGlfw_NewFrame();
      ImGui::NewFrame();
      const ImGuiIO& io = ImGui::GetIO();
      if (glfwGetKey(window, GLFW_KEY_ESCAPE) == GLFW_PRESS) glfwSetWindowShouldClose(window, 1);
      auto pressed = [&](int key) {  // went down since the last frame
        const bool isDown = glfwGetKey(window, key) == GLFW_PRESS;
        const bool was = keysDown[key];
        keysDown[key] = isDown;
        return isDown && !was;
      };
      if (!io.WantCaptureKeyboard) {  // WASD fly, Q/E down/up, [ ] file cameras, R reset
        auto down = [&](int key) { return glfwGetKey(window, key) == GLFW_PRESS ? 1.0f : 0.0f; };
        const float flyStep = 0.5f * static_cast<float>(std::min(frameMs, 100.0) / 1000.0);
        const float right = down(GLFW_KEY_D) - down(GLFW_KEY_A);
        const float up = down(GLFW_KEY_E) - down(GLFW_KEY_Q);
        const float forward = down(GLFW_KEY_W) - down(GLFW_KEY_S);
        if (right != 0.0f || up != 0.0f || forward != 0.0f)
          settings.camera.fly(right * flyStep, up * flyStep, forward * flyStep);
        if (pressed(GLFW_KEY_RIGHT_BRACKET)) actions.nextCamera = 1;
        if (pressed(GLFW_KEY_LEFT_BRACKET)) actions.nextCamera = -1;
        if (pressed(GLFW_KEY_R)) settings.camera.reset();
      }
      if (!io.WantCaptureMouse && io.MousePos.x < w && io.MousePos.y < h && io.KeyCtrl &&
          ImGui::IsMouseClicked(ImGuiMouseButton_Left)) {  // ctrl+click: the fovea (Eq. 4 o)
        settings.importance.fovea = glm::vec2(io.MousePos.x, io.MousePos.y);
      } else if (!io.WantCaptureMouse && io.MousePos.x < w) {  // the camera, on the image
        if (ImGui::IsMouseDragging(ImGuiMouseButton_Left, 0.0f))
          settings.camera.orbit(-0.3f * io.MouseDelta.x, 0.3f * io.MouseDelta.y);
        if (ImGui::IsMouseDragging(ImGuiMouseButton_Right, 0.0f) ||
            ImGui::IsMouseDragging(ImGuiMouseButton_Middle, 0.0f))
          settings.camera.pan(io.MouseDelta.x / h, io.MouseDelta.y / h);
        if (io.MouseWheel != 0.0f) settings.camera.zoom(std::pow(1.1f, io.MouseWheel));
      }
      int fbW = 0, fbH = 0;
      glfwGetFramebufferSize(window, &fbW, &fbH);
      PanelInfo info{sceneOptions.source,
                     sceneOptions.engine,
                     w,
                     h,
                     &frame,
                     frameMs,
                     static_cast<int>(prepared->scene.cameras.size()),
                     fileCamera,
                     notice,
                     inFlight.valid()};
      const PanelRequests requests = drawPanel(static_cast<float>(w), static_cast<float>(fbW - w),
                                               static_cast<float>(fbH), settings, info);
      if (requests.nextCamera != 0) actions.nextCamera = requests.nextCamera;
      if (requests.budgetShare) actions.budgetShare = requests.budgetShare;
      if (!actions.open.empty()) openScene(actions.open);
      if (actions.fileCamera && !chooseFileCamera(*actions.fileCamera) && !steps.empty()) {
        exitCode = cli::fail("--script: " + notice);
        break;
      }
      if (actions.nextCamera != 0 && !prepared->scene.cameras.empty()) {
        const int count = static_cast<int>(prepared->scene.cameras.size());
        chooseFileCamera(fileCamera < 0 ? (actions.nextCamera > 0 ? 0 : count - 1)
                                        : (fileCamera + actions.nextCamera + count) % count);
      }
      if (actions.budgetShare) {
        if (frame.truthBytes > 0)
          settings.budgetBytes = static_cast<uint64_t>(
              std::llround(*actions.budgetShare * static_cast<double>(frame.truthBytes)));
        else
          notice = "budget share: the exact A-buffer is not rendered (compare is off)";
      }
      bool updated = false;
      // while the camera is dragged, skip the A-buffer and FLIP (rendered again on release)
      ViewSettings shown = settings;
      if (ImGui::IsMouseDown(ImGuiMouseButton_Left) || ImGui::IsMouseDown(ImGuiMouseButton_Right))
        shown.compare = shown.compare && io.WantCaptureMouse;
      if (inFlight.valid() &&
          inFlight.wait_for(std::chrono::seconds(0)) == std::future_status::ready)
        updated = finishRender(n);
      if (shown.displayKey() != shownKey && !inFlight.valid()) {  // re-render only what changed
        if (renderThread) {
          inFlightKey = shown.displayKey();
          inFlightSettings = settings;
          inFlight = std::async(std::launch::async, [&r = *renderer, shown] {
            Frame f = r.update(shown);
            glfwPostEmptyEvent();  // wakes the event wait of the window's thread
            return f;
          });
        } else {
          frame = renderer->update(shown);
          shownKey = shown.displayKey();
          texture.upload(frame.display);
          renders.push_back(statsEntry(n, settings, frame));
          updated = true;
        }
      }
      idle = !inFlight.valid() && shownKey == shown.displayKey();
      if (requests.screenshotMaps)
        actions.screenshotMaps.push_back("mfr-view-" + std::to_string(++screenshotCount));
      if (!actions.screenshotMaps.empty() && inFlight.valid()) {  // the renderer is the worker's
        inFlight.wait();
        updated = finishRender(n) || updated;
      }
      for (const std::string& prefix : actions.screenshotMaps) {
        std::string error;
        for (const std::string& path : screenshotMaps(*renderer, shown, prefix, error)) {
          nlohmann::json j = statsEntry(n, settings, frame);
          j["path"] = path;
          j["maps_of"] = prefix;
          shots.push_back(j);
          if (!scripted) std::printf("screenshot: %s\n", path.c_str());
        }
        if (!error.empty()) exitCode = cli::fail(error);
      }
      if (requests.copyCommand || actions.copyCommand) {
        const std::string cmd = renderCommand(sceneOptions, settings);
        const std::string compare = compareCommand(sceneOptions, settings, frame.truthBytes);
        glfwSetClipboardString(window, (cmd + "\n" + compare).c_str());
        std::printf("%s\n%s\n", cmd.c_str(), compare.c_str());
        std::fflush(stdout);
      }
      if (requests.screenshot)
        pendingShots.emplace_back("mfr-view-" + std::to_string(++screenshotCount) + ".png", false);
      for (const std::string& p : actions.screenshots) pendingShots.emplace_back(p, false);
      for (const std::string& p : actions.screenshotsUi) pendingShots.emplace_back(p, true);
      const bool last = idle && (frames > 0 ? n + 1 >= frames
                                            : !steps.empty() && step >= steps.size() &&
                                                  pendingShots.empty() && !updated);
      if (last && !a.screenshot.empty()) pendingShots.emplace_back(a.screenshot, a.screenshotUi);
      texture.draw();
      ImGui::Render();
      glViewport(0, 0, fbW, fbH);
      glClearColor(0.1f, 0.1f, 0.1f, 1.0f);
      glClear(GL_COLOR_BUFFER_BIT);
      ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
      // screenshots of a frame whose panel already shows its render's statistics
      while (!pendingShots.empty() && idle && (!updated || last)) {
        const auto [path, ui] = pendingShots.front();
        pendingShots.pop_front();
        const Image8 shot =
            ui ? readWindow(fbH, fbW, fbH) : readWindow(fbH, texture.width(), texture.height());
        if (auto written = writePng(path, shot); !written) {
          exitCode = cli::fail(written.error().message);
          break;
        }
        nlohmann::json j = statsEntry(n, settings, frame);
        j["scene"] = sceneOptions.source;
        j["file_camera"] = fileCamera;
        j["notice"] = notice;
        j["path"] = path;
        j["ui"] = ui;
        j["width"] = shot.width;
        j["height"] = shot.height;
        size_t differing = 0;  // pixels unlike the top-left one: 0 for an empty (uniform) shot
        for (size_t i = 0; i < shot.rgba.size(); i += 4)
          differing += shot.rgba[i] != shot.rgba[0] || shot.rgba[i + 1] != shot.rgba[1] ||
                       shot.rgba[i + 2] != shot.rgba[2];
        j["pixels_unlike_corner"] = differing;
        shots.push_back(j);
        if (!scripted) std::printf("screenshot: %s\n", path.c_str());
      }
      glfwSwapBuffers(window);
      frameMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                    .count();
      windowFrameMs.push_back(frameMs);
      if (exitCode != 0 || (last && pendingShots.empty())) break;
    }
    if (inFlight.valid()) finishRender(framesShown);  // waits; before the renderer goes
    if (!a.statsJson.empty()) {
      nlohmann::json out{{"renders", renders}, {"screenshots", shots}};
      if (!windowFrameMs.empty()) {  // how long the window waited for its frames
        std::vector<double> sorted = windowFrameMs;
        std::sort(sorted.begin(), sorted.end());
        out["window_frames"] = {{"count", sorted.size()},
                                {"median_ms", sorted[sorted.size() / 2]},
                                {"p95_ms", sorted[sorted.size() * 95 / 100]},
                                {"max_ms", sorted.back()},
                                {"render_thread", renderThread}};
      }
      if (auto written = writeFileAtomically(a.statsJson, out.dump(2) + "\n"); !written)
        exitCode = cli::fail(written.error().message);
    }
    texture.destroy();
  }  // the renderer frees the engine's views in the engine's context
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  glfwMakeContextCurrent(nullptr);
  {
    engineContext.makeCurrent();
    engine.value().reset();
    engineContext.release();
  }
  glfwDestroyWindow(window);
  glfwTerminate();
  return exitCode;
}

}  // namespace mfr::view

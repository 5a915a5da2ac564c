// bench_engines: the same frames on every engine, in one run so the ratios are meaningful. The CPU
// engine (tile-owned capture, --threads workers) against the GL engine (OpenGL 4.5 through headless
// EGL; on a machine without a GPU, Mesa's llvmpipe on the same cores) on its native raster
// (--gl-raster native) and its exact one (the CPU engine's raster emulated), and the plain GL
// k-buffer of ../shared/anchors/gl-kbuffer (built from there where it exists; K = 8, 16 quads,
// about the layers frame's 9.1 M fragments) as the yardstick for the driver, for the k+-buffer with
// a max-array store and k = 8 (k+-buffer paper, Algorithm 3), kbuffer compositing:
//   layers    procedural:layers?k=8&r=2&pd=0.55 (16 layers; 9.24 M fragments at 1024x1024)
//   hairball  procedural:hairball
//   Dish      IridescentDishWithOlives from ../shared/scenes, alpha 0.5, zoom 1.6 (skipped when
//             the folder is absent)
// Per engine: each pass's median time over --reps runs, labelled by its timer (gl_pass_timer.hpp):
// "gpu", the GL engine's GL_TIME_ELAPSED queries, on a driver whose queries are usable; "wall",
// the host clock around the pass (glFinish included), for the CPU engine and on a software
// rasterizer such as llvmpipe, whose GL_TIME_ELAPSED leaves the compute passes out. Then the whole
// frame (wall time of render(); prepare and one untimed warm-up render excluded), fragments per
// second through the frame, the largest per-channel difference from the CPU engine's image (0: bit
// for bit), and each frame over the CPU engine's and over the anchor's (its best frame, the median
// of its runs before the scenes and in each round of the layers scene). The anchor's frame is its
// draw alone; an engine's frame is a whole render() (clears, passes, read-back, statistics).
// CSV: engines.csv, one row
// per scene and engine; PNG: engines.png, the frame times as bars per scene and engine (the anchor
// beside the layers scene, whose fragments it draws about as many of).
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "gl_pass_timer.hpp"
#include "mfr/cpu/cpu_engine.hpp"
#include "mfr/gl/gl_render_engine.hpp"

namespace {

using namespace mfr;
using namespace mfr::bench;

constexpr Program kProgram{.name = "bench_engines", .csv = "engines.csv"};
constexpr uint32_t kK = 8;

struct Measured {
  PassTimer timer = PassTimer::Wall;  // how `passes` were timed
  std::optional<std::string> error;
  std::map<std::string, std::vector<double>> passes;  // ms per pass, one per run
  std::vector<double> frame;                          // ms per run, wall time of render()
  RenderStats stats;
  ImageRGB image;
};

void measure(Engine& engine, const PreparedView& view, const MethodDesc& method, int reps,
             Measured& m) {
  for (int r = 0; r < reps && !m.error; ++r) {
    const Clock::time_point start = Clock::now();
    auto out = engine.render(view, method, RenderOptions{});
    const double ms = msSince(start);
    if (!out) {
      m.error = out.error().message;
      return;
    }
    if (m.timer == PassTimer::Gpu) {
      for (const TimedPass& p : glPassTimes(out->stats, m.timer)) m.passes[p.name].push_back(p.ms);
    } else {
      for (const PassTime& p : out->stats.passes) m.passes[p.name].push_back(p.ms);
    }
    m.frame.push_back(ms);
    m.stats = std::move(out->stats);
    m.image = std::move(out->image);
  }
}

// The anchor's best frame in ms ("draw timing: best X ms, ..."), or an error.
Result<double> runAnchor(int size, int reps) {
#ifdef MFR_ANCHOR_KBUFFER_PATH
  const std::string cmd = std::string(MFR_ANCHOR_KBUFFER_PATH) + " lock " + std::to_string(size) +
                          " " + std::to_string(size) + " 8 16 " + std::to_string(reps) + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return makeError("cannot run " + cmd);
  std::string out;
  char buffer[4096];
  while (size_t n = std::fread(buffer, 1, sizeof buffer, pipe)) out.append(buffer, n);
  const int status = pclose(pipe);
  const size_t at = out.find("draw timing: best ");
  if (status != 0 || at == std::string::npos)
    return makeError("the anchor failed: " + out.substr(0, 300));
  return std::strtod(out.c_str() + at + 18, nullptr);
#else
  (void)size;
  (void)reps;
  return makeError("not built (../shared/anchors/gl-kbuffer/ absent at configure time)");
#endif
}

// engines.png: the frame times as grouped bars, one group per scene, one bar per engine, and the
// anchor's bar beside the layers scene's (it draws about as many fragments); a log axis when the
// times span more than 10x.
bool writeEnginesPng(const Args& args, const std::string& renderer,
                     const std::vector<std::string>& scenes, const std::vector<double> frames[3],
                     const Result<double>& anchor) {
  if (scenes.empty()) return true;
  const glm::vec3 colors[4] = {
      {0.35f, 0.35f, 0.35f}, {0.12f, 0.47f, 0.71f}, {0.6f, 0.75f, 0.9f}, {0.85f, 0.37f, 0.01f}};
  const char* labels[4] = {"CPU engine", "GL native", "GL exact", "anchor (plain GL k-buffer)"};
  std::vector<BarSeries> bars;
  double lo = INFINITY, hi = 0.0;
  for (int e = 0; e < 4; ++e) {
    BarSeries b{labels[e], {}, colors[e]};
    for (size_t i = 0; i < scenes.size(); ++i)
      b.values.push_back(e < 3 ? frames[e][i] : anchor && scenes[i] == "layers" ? *anchor : NAN);
    for (double v : b.values)
      if (std::isfinite(v) && v > 0.0) lo = std::min(lo, v), hi = std::max(hi, v);
    bars.push_back(std::move(b));
  }
  PlotOptions po;
  po.width = 1000;
  po.height = 560;
  po.logY = hi > 10.0 * lo;
  po.title = "kplus-array k " + std::to_string(kK) + ", kbuffer, " + std::to_string(args.size) +
             "x" + std::to_string(args.size) + "; GL: " + renderer.substr(0, 40);
  po.yLabel = "ms per frame (wall, median of " + std::to_string(args.reps) + ")" +
              (po.logY ? ", log scale" : "");
  po.xLabel = "scene (anchor: its best draw; about the layers frame's fragments)";
  auto png = plotBars(scenes, bars, po);
  const std::filesystem::path path = std::filesystem::path(args.out) / "engines.png";
  if (!png || !writePng(path.string(), *png).ok()) {
    printError(kProgram, "cannot write " + path.string() +
                             (png ? std::string() : ": " + png.error().message));
    return false;
  }
  std::printf("PNG: %s\n", path.string().c_str());
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  const Args args = parseArgs(argc, argv, kProgram);
  Csv csv = openCsv(kProgram, args,
                    "scene,engine,renderer,pass_timer,width,height,threads,reps,fragments,count_ms,"
                    "prefix_sum_ms,capture_ms,resolve_ms,other_ms,frame_ms,mfrag_s,"
                    "over_cpu,over_anchor,image_max_diff,error");
  std::printf(
      "bench_engines: CPU engine vs GL engine (native, exact) vs the plain GL k-buffer, "
      "kplus-array k = %u, kbuffer, %s\n",
      kK, runDescription(args, resolveThreads(args.threads)).c_str());

  auto gl = gl::makeGlEngine("auto", "native");
  auto glExact = gl::makeGlEngine("auto", "exact");
  if (!gl || !glExact) {
    printError(kProgram, (gl ? glExact : gl).error().message);
    return 1;
  }
  CpuEngine cpu(EngineOptions{args.threads, 32});
  const std::string renderer = (*gl)->describe().at("renderer");
  const PassTimer glTimer = glPassTimer(renderer);
  std::printf("GL renderer: %s; GL pass times: %s\n\n", renderer.c_str(),
              glTimer == PassTimer::Gpu
                  ? "gpu (GL_TIME_ELAPSED)"
                  : "wall (host clock with glFinish: this driver's timer queries are not usable)");
  // the anchor before the scenes and again in each round of the layers scene (whose fragments it
  // draws about as many of), interleaved with the engines: the median of its best frames
  const int anchorFrames = std::max(args.reps, 2);
  std::vector<double> anchorRuns;
  Result<double> anchor = runAnchor(args.size, anchorFrames);
  if (anchor) anchorRuns.push_back(*anchor);
  const auto anchorRound = [&] {
    if (!anchor) return;
    const Result<double> run = runAnchor(args.size, anchorFrames);
    if (run) anchorRuns.push_back(*run);
    anchor = median(anchorRuns);
  };

  const std::string dish = std::string(MFR_SCENES_DIR) +
                           "/khronos/IridescentDishWithOlives/glTF/IridescentDishWithOlives.gltf";
  const std::vector<SceneCase> scenes = {{"layers", "procedural:layers?k=8&r=2&pd=0.55", false},
                                         {"hairball", "procedural:hairball", false},
                                         {"Dish", dish, true}};
  MethodDesc method = methodPreset("kplus-array").value();
  method.k = kK;
  method.compositing = Compositing::KBuffer;

  Table table({"scene", "engine", "timer", "fragments", "count", "prefix sum", "capture", "resolve",
               "other", "frame ms", "M frag/s", "/ CPU", "/ anchor", "max diff"});
  table.leftAlign(0);
  table.leftAlign(1);
  table.leftAlign(2);
  bool failed = false;
  constexpr int kEngines = 3;
  const char* names[kEngines] = {"cpu", "gl native", "gl exact"};
  std::vector<std::string> plotted;      // the scenes in the PNG
  std::vector<double> frames[kEngines];  // their frame ms per engine (NaN: failed)
  for (const SceneCase& sc : scenes) {
    if (sc.file && !std::filesystem::exists(sc.source)) {
      std::printf("skipping %s: %s not found (the shared scenes folder is absent)\n",
                  sc.label.c_str(), sc.source.c_str());
      continue;
    }
    auto loaded = loadScene(sc.source);
    if (!loaded) {
      printError(kProgram, loaded.error().message);
      failed = true;
      continue;
    }
    Scene& scene = loaded.value();
    Camera camera = sceneCamera(scene);
    if (sc.file) {  // the evaluation's framing of the real scenes
      scene.alphaOverride = 0.5f;
      camera.eye = camera.target + (camera.eye - camera.target) / 1.6f;
    }
    const View view{&scene, camera, args.size, args.size};
    Measured results[kEngines];
    results[1].timer = results[2].timer = glTimer;
    Engine* engines[kEngines] = {&cpu, gl->get(), glExact->get()};
    std::unique_ptr<PreparedView> views[kEngines];
    for (int e = 0; e < kEngines; ++e) {
      auto prepared = engines[e]->prepare(view);
      if (!prepared) {
        results[e].error = prepared.error().message;
        continue;
      }
      views[e] = std::move(prepared.value());
    }
    for (int e = 0; e < kEngines;
         ++e) {  // untimed warm-up (GL: shader compilation, first-frame timers)
      if (!views[e]) continue;
      auto warm = engines[e]->render(*views[e], method, RenderOptions{});
      if (!warm) {
        results[e].error = warm.error().message;
        views[e].reset();
      }
    }
    // interleaved rounds: a slow period of the shared machine hits both engines alike (and the
    // anchor, in the layers scene's)
    for (int r = 0; r < args.reps; ++r) {
      for (int e = 0; e < kEngines; ++e)
        if (views[e]) measure(*engines[e], *views[e], method, 1, results[e]);
      if (sc.label == "layers") anchorRound();
    }
    const double cpuFrame = results[0].error ? 0.0 : median(results[0].frame);
    plotted.push_back(sc.label);
    for (int e = 0; e < kEngines; ++e) {
      const Measured& m = results[e];
      const std::string name = names[e];
      frames[e].push_back(m.error ? NAN : median(m.frame));
      // scene, engine, renderer, pass_timer, width, height, threads, reps
      std::vector<std::string> cells = {sc.label, name, e ? renderer : "cpu", toString(m.timer)};
      cells.insert(cells.end(),
                   {std::to_string(args.size), std::to_string(args.size),
                    std::to_string(resolveThreads(args.threads)), std::to_string(args.reps)});
      if (m.error) {
        failed = true;
        printError(kProgram, sc.label + " on " + name + ": " + *m.error);
        cells.resize(19);  // no figures
        cells.push_back(*m.error);
        csv.row(cells);
        continue;
      }
      const auto pass = [&](const char* p) {
        const auto it = m.passes.find(p);
        return it == m.passes.end() ? 0.0 : median(it->second);
      };
      double other = 0.0;
      for (const auto& [p, samples] : m.passes)
        if (p != "count" && p != "prefix sum" && p != "capture" && p != "resolve")
          other += median(samples);
      const double frame = median(m.frame);
      const uint64_t fragments = m.stats.fragmentsGenerated;
      const bool bothOk = !results[0].error;
      const float diff = bothOk ? maxAbsDiff(results[0].image, m.image) : -1.0f;
      const std::string overCpu = e > 0 && cpuFrame > 0.0 ? fixed(frame / cpuFrame, 2) : "";
      const std::string overAnchor = anchor && *anchor > 0.0 ? fixed(frame / *anchor, 2) : "";
      table.add({sc.label, name, toString(m.timer), num(fragments), fixed(pass("count"), 1),
                 fixed(pass("prefix sum"), 1), fixed(pass("capture"), 1), fixed(pass("resolve"), 1),
                 fixed(other, 1), fixed(frame, 1), fixed(mfragPerS(fragments, frame), 1), overCpu,
                 overAnchor, bothOk ? fixed(diff, 6) : "-"});
      cells.insert(cells.end(), {std::to_string(fragments), fixed(pass("count"), 3),
                                 fixed(pass("prefix sum"), 3), fixed(pass("capture"), 3),
                                 fixed(pass("resolve"), 3), fixed(other, 3), fixed(frame, 3),
                                 fixed(mfragPerS(fragments, frame), 3), overCpu, overAnchor,
                                 bothOk ? fixed(diff, 8) : "", ""});
      csv.row(cells);
    }
  }
  if (anchor)
    std::printf(
        "anchor (../shared/anchors/gl-kbuffer, lock %d x %d, K 8, 16 quads): %.1f ms, the median "
        "of "
        "%zu runs' best of %d frames (%.1f to %.1f)\n\n",
        args.size, args.size, *anchor, anchorRuns.size(), anchorFrames,
        *std::min_element(anchorRuns.begin(), anchorRuns.end()),
        *std::max_element(anchorRuns.begin(), anchorRuns.end()));
  else
    std::printf("anchor: %s\n\n", anchor.error().message.c_str());
  const std::string side = std::to_string(args.size);
  csv.row({"anchor (K 8, 16 quads)",
           "gl-kbuffer",
           renderer,
           "wall",
           side,
           side,
           "",
           std::to_string(anchorRuns.size() * anchorFrames),
           "",
           "",
           "",
           "",
           "",
           "",
           anchor ? fixed(*anchor, 3) : "",
           "",
           "",
           "",
           "",
           anchor ? "" : anchor.error().message});
  table.print();
  std::printf(
      "\n/ CPU, / anchor: the frame time over the CPU engine's and over the plain GL k-buffer's "
      "(the anchor draws about the layers frame's fragments: read that row). Passes in ms "
      "(medians of %d runs; \"other\": the CPU engine's allocate and clear), timed as the timer "
      "column says: gpu = GL_TIME_ELAPSED, wall = host clock around the pass (glFinish "
      "included); frame ms: wall time of a whole render.\n",
      args.reps);
  if (!writeEnginesPng(args, renderer, plotted, frames, anchor)) failed = true;
  return failed ? 1 : 0;
}

// bench_engines: the same frames on both engines, in one run so the ratio is meaningful (issue
// "OpenGL 4.5 engine", benchmark section). The CPU engine (tile-owned capture, --threads workers)
// against the GL engine (OpenGL 4.5 through headless EGL; on a machine without a GPU, Mesa's
// llvmpipe on the same cores) for the k+-buffer with a max-array store and k = 8 (k+-buffer
// paper, Algorithm 3), kbuffer compositing:
//   layers    procedural:layers?k=8&r=2&pd=0.55 (16 layers; 9.24 M fragments at 1024x1024)
//   hairball  procedural:hairball
//   Dish      IridescentDishWithOlives from ../shared/scenes, alpha 0.5, zoom 1.6 (skipped when
//             the folder is absent)
// Per engine: each pass's median wall time over --reps runs (the GL engine warms up once per
// render and reports wall time: llvmpipe's GL_TIME_ELAPSED is not usable), the whole frame
// (prepare and one untimed warm-up render excluded), fragments per second through the frame, and
// the largest per-channel difference between the two engines' images (0: the engines agree bit for
// bit). CSV: engines.csv, one row per scene and engine.
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "mfr/cpu/cpu_engine.hpp"
#include "mfr/gl/gl_render_engine.hpp"

namespace {

using namespace mfr;
using namespace mfr::bench;

constexpr Program kProgram{.name = "bench_engines", .csv = "engines.csv"};
constexpr uint32_t kK = 8;

struct Measured {
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
    for (const PassTime& p : out->stats.passes) m.passes[p.name].push_back(p.ms);
    m.frame.push_back(ms);
    m.stats = std::move(out->stats);
    m.image = std::move(out->image);
  }
}

}  // namespace

int main(int argc, char** argv) {
  const Args args = parseArgs(argc, argv, kProgram);
  Csv csv = openCsv(kProgram, args,
                    "scene,engine,renderer,width,height,threads,reps,fragments,count_ms,"
                    "prefix_sum_ms,capture_ms,resolve_ms,other_ms,frame_ms,mfrag_s,"
                    "cpu_speedup,image_max_diff,error");
  std::printf("bench_engines: CPU engine vs GL engine, kplus-array k = %u, kbuffer, %s\n", kK,
              runDescription(args, resolveThreads(args.threads)).c_str());

  auto gl = gl::makeGlEngine();
  if (!gl) {
    printError(kProgram, gl.error().message);
    return 1;
  }
  CpuEngine cpu(EngineOptions{args.threads, 32});
  const std::string renderer = (*gl)->describe().at("renderer");
  std::printf("GL renderer: %s\n\n", renderer.c_str());

  const std::string dish = std::string(MFR_SCENES_DIR) +
                           "/khronos/IridescentDishWithOlives/glTF/IridescentDishWithOlives.gltf";
  const std::vector<SceneCase> scenes = {{"layers", "procedural:layers?k=8&r=2&pd=0.55", false},
                                         {"hairball", "procedural:hairball", false},
                                         {"Dish", dish, true}};
  MethodDesc method = methodPreset("kplus-array").value();
  method.k = kK;
  method.compositing = Compositing::KBuffer;

  Table table({"scene", "engine", "fragments", "count", "prefix sum", "capture", "resolve", "other",
               "frame ms", "M frag/s", "CPU x", "max diff"});
  table.leftAlign(0);
  table.leftAlign(1);
  bool failed = false;
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
    Measured results[2];
    Engine* engines[2] = {&cpu, gl->get()};
    std::unique_ptr<PreparedView> views[2];
    for (int e = 0; e < 2; ++e) {
      auto prepared = engines[e]->prepare(view);
      if (!prepared) {
        results[e].error = prepared.error().message;
        continue;
      }
      views[e] = std::move(prepared.value());
    }
    for (int e = 0; e < 2; ++e) {  // untimed warm-up (GL: shader compilation, first-frame timers)
      if (!views[e]) continue;
      auto warm = engines[e]->render(*views[e], method, RenderOptions{});
      if (!warm) {
        results[e].error = warm.error().message;
        views[e].reset();
      }
    }
    // interleaved rounds: a slow period of the shared machine hits both engines alike
    for (int r = 0; r < args.reps; ++r)
      for (int e = 0; e < 2; ++e)
        if (views[e]) measure(*engines[e], *views[e], method, 1, results[e]);
    const bool bothOk = !results[0].error && !results[1].error;
    const float diff = bothOk ? maxAbsDiff(results[0].image, results[1].image) : -1.0f;
    const double cpuFrame = results[0].error ? 0.0 : median(results[0].frame);
    const double glFrame = results[1].error ? 0.0 : median(results[1].frame);
    for (int e = 0; e < 2; ++e) {
      const Measured& m = results[e];
      const std::string name = e == 0 ? "cpu" : "gl";
      if (m.error) {
        failed = true;
        printError(kProgram, sc.label + " on " + name + ": " + *m.error);
        csv.row({sc.label, name, e ? renderer : "", std::to_string(args.size),
                 std::to_string(args.size), std::to_string(resolveThreads(args.threads)),
                 std::to_string(args.reps), "", "", "", "", "", "", "", "", "", "", *m.error});
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
      const double speedup = e == 0 && cpuFrame > 0.0 ? glFrame / cpuFrame : 0.0;
      table.add({sc.label, name, num(fragments), fixed(pass("count"), 1),
                 fixed(pass("prefix sum"), 1), fixed(pass("capture"), 1), fixed(pass("resolve"), 1),
                 fixed(other, 1), fixed(frame, 1), fixed(mfragPerS(fragments, frame), 1),
                 e == 0 ? fixed(speedup, 2) : "", bothOk ? fixed(diff, 6) : "-"});
      csv.row({sc.label, name, e ? renderer : "cpu", std::to_string(args.size),
               std::to_string(args.size), std::to_string(resolveThreads(args.threads)),
               std::to_string(args.reps), std::to_string(fragments), fixed(pass("count"), 3),
               fixed(pass("prefix sum"), 3), fixed(pass("capture"), 3), fixed(pass("resolve"), 3),
               fixed(other, 3), fixed(frame, 3), fixed(mfragPerS(fragments, frame), 3),
               e == 0 ? fixed(speedup, 3) : "", bothOk ? fixed(diff, 8) : "", ""});
    }
  }
  table.print();
  std::printf(
      "\nCPU x: GL frame time / CPU frame time. Passes in ms (medians of %d runs; "
      "\"other\": the CPU engine's allocate and clear).\n",
      args.reps);
  return failed ? 1 : 0;
}

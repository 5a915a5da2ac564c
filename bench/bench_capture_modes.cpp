// bench_capture_modes: fragment-parallel capture (the k+-buffer paper's Algorithm 3 as written:
// triangles from many threads, per-pixel spin-locks, the k+ test outside the critical section and
// again inside) vs tile-owned capture (each tile one worker's, no locks), at k = 8 for kplus-array,
// kplus-heap and fkb on procedural:hairball and procedural:layers. Measures the cost of the
// k+-buffer paper's per-pixel semaphores (its Algorithm 1 spin-lock, sec. 3) against the
// lock-free tile ownership a CPU rasterizer allows; no paper figure has this exact comparison.
//
// For each (scene, method, mode): capture-pass time (median of --reps runs), fragments/s through
// the capture pass, fragments culled by the k+ test and rejected inside the store (the in-store
// re-check only fires when another thread got there first), and whether the fragment-parallel
// image equals the tile-owned one (it should: both keep the k nearest fragments of every pixel).
// CSV: capture_modes.csv (one row per scene and method, both modes side by side).
#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "bench_common.hpp"

namespace {

using namespace mfr;
using namespace mfr::bench;

constexpr Program kProgram{.name = "bench_capture_modes", .csv = "capture_modes.csv"};

constexpr uint32_t kK = 8;

}  // namespace

int main(int argc, char** argv) {
  const Args args = parseArgs(argc, argv, kProgram);
  Csv csv =
      openCsv(kProgram, args,
              "scene,method,k,width,height,threads,reps,fragments,tile_capture_ms,tile_mfrag_s,"
              "parallel_capture_ms,parallel_mfrag_s,tile_speedup,tile_culled_kplus,"
              "parallel_culled_kplus,tile_in_store,parallel_in_store,tile_captured,"
              "parallel_captured,image_max_diff");
  std::printf("bench_capture_modes: tile-owned vs fragment-parallel capture, k = %u, %s\n", kK,
              runDescription(args, resolveThreads(args.threads)).c_str());

  const std::vector<SceneCase> scenes = {{"hairball", "procedural:hairball"},
                                         {"layers", "procedural:layers"}};
  const std::vector<std::string> methods = {"kplus-array", "kplus-heap", "fkb"};
  const CaptureMode modes[2] = {CaptureMode::TileOwned, CaptureMode::FragmentParallel};
  const char* modeNames[2] = {"tile-owned", "fragment-parallel"};

  Table table({"scene", "method", "mode", "capture ms", "M frag/s", "culled k+",
               "rejected in store", "captured", "same image"});
  table.leftAlign(1);
  table.leftAlign(2);
  table.leftAlign(8);
  bool failed = false;
  // every (scene, method, mode) is a case: cases[(scene * methods + method) * 2 + mode]
  FrameStore store(kProgram);
  std::vector<const SceneCase*> measured;
  std::vector<Case> cases;
  for (const SceneCase& sc : scenes) {
    const Scene* scene = store.load(sc.source);
    if (!scene) {
      failed = true;
      continue;
    }
    const auto setupStart = Clock::now();
    const RasterFrame* frame = store.build(*scene, args);
    if (!frame) return 1;
    std::printf("%s (%s): frame set-up %.1f ms\n", sc.label.c_str(), sc.source.c_str(),
                msSince(setupStart));
    measured.push_back(&sc);
    for (const std::string& name : methods)
      for (const CaptureMode mode : modes) {
        Case c;
        c.frame = frame;
        c.method = methodPreset(name).value();
        c.method.k = kK;
        c.options.capture = mode;
        c.keepImage = true;
        cases.push_back(std::move(c));
      }
  }
  runInterleaved(cases, args.reps);

  for (size_t si = 0; si < measured.size(); ++si) {
    const SceneCase& sc = *measured[si];
    for (size_t mi = 0; mi < methods.size(); ++mi) {
      const std::string& name = methods[mi];
      const Case* results[2] = {&cases[(si * methods.size() + mi) * 2],
                                &cases[(si * methods.size() + mi) * 2 + 1]};
      const RasterFrame* frame = results[0]->frame;
      if (results[0]->error || results[1]->error) {
        printError(kProgram, sc.label + " " + name + ": " +
                                 *(results[0]->error ? results[0]->error : results[1]->error));
        failed = true;
        continue;
      }
      const float diff = maxAbsDiff(results[0]->image, results[1]->image);
      for (int i = 0; i < 2; ++i) {
        const RenderStats& s = results[i]->stats;
        const double ms = results[i]->pass("capture");
        std::string same = "-";
        if (i == 1) same = diff == 0.0f ? "yes" : "NO (max diff " + fixed(diff, 4) + ")";
        table.add({i == 0 ? sc.label : "", i == 0 ? name : "", modeNames[i], fixed(ms, 1),
                   fixed(mfragPerS(s.fragmentsGenerated, ms), 1), num(s.culledKPlus),
                   num(s.rejectedInStore), num(s.captured), same});
      }
      const RenderStats& t = results[0]->stats;
      const RenderStats& p = results[1]->stats;
      const double tileMs = results[0]->pass("capture"), parMs = results[1]->pass("capture");
      csv.row({sc.label,
               name,
               std::to_string(kK),
               num(frame->width()),
               num(frame->height()),
               num(frame->threads()),
               num(args.reps),
               num(t.fragmentsGenerated),
               fixed(tileMs, 3),
               fixed(mfragPerS(t.fragmentsGenerated, tileMs), 3),
               fixed(parMs, 3),
               fixed(mfragPerS(p.fragmentsGenerated, parMs), 3),
               fixed(tileMs > 0 ? parMs / tileMs : 0.0, 3),
               num(t.culledKPlus),
               num(p.culledKPlus),
               num(t.rejectedInStore),
               num(p.rejectedInStore),
               num(t.captured),
               num(p.captured),
               fixed(diff, 6)});
    }
  }
  std::printf("\n");
  table.print();
  std::printf("\nM frag/s = fragments generated / capture-pass time\nwrote %s\n",
              csv.path().c_str());
  return failed ? 1 : 0;
}

// bench_dkb: the deep k-buffer's per-frame overhead (Deep hybrid OIT, sec. 4.1, Table 1: "NN
// feature extraction" and "importance computation"), at --size^2 with the built-in model, on
// every instruction-set path this CPU has (core/isa.hpp), next to a kplus-dynamic frame of the
// same view and budget (the paper's point: the network is cheap next to rendering).
//
// For each scene (procedural:hairball; IridescentDishWithOlives from ../shared/scenes at zoom 1.6
// with global alpha 0.5, skipped when absent), --budget (default 40 MB), medians of --reps
// interleaved runs of:
//   kplus     a whole kplus-dynamic frame (all passes)
//   count     the dkb frame's count pass (n(p) and the depth range)
//   features  the dkb frame's feature pass, wall time
//   infer     the dkb frame's inference pass, wall time (features and inference run fused per
//             tile; the fused wall time is split in proportion to each part's CPU time)
//   dkb       the whole dkb frame
//   infer-only  batch inference alone over the covered pixels' features (predictRows), and its
//             rate in M pixels/s
// and (features + infer) / kplus, the goal (<= 25%). CSV: dkb.csv; chart: dkb.png
// (features + inference per path and scene, with the kplus-dynamic frame).
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "mfr/core/isa.hpp"
#include "mfr/core/plot.hpp"
#include "mfr/core/units.hpp"
#include "mfr/cpu/deep_importance.hpp"
#include "mfr/learn/model_file.hpp"
#include "mfr/method/memory_model.hpp"

namespace {

using namespace mfr;
using namespace mfr::bench;

constexpr Program kProgram{.name = "bench_dkb",
                           .csv = "dkb.csv",
                           .options = " [--budget BYTES]",
                           .optionsHelp = "  --budget BYTES  the frames' budget (default 40MB)\n"};

struct PathRuns {
  Isa isa;
  Case dkb;
  std::vector<double> inferOnly;
};

}  // namespace

int main(int argc, char** argv) {
  std::optional<uint64_t> budgetOption;
  if (!takeBudget(kProgram, argc, argv, budgetOption)) return 2;
  const uint64_t budget = budgetOption.value_or(40ull << 20);
  const Args args = parseArgs(argc, argv, kProgram);
  auto model = builtinDkbModel();
  if (!model) {
    printError(kProgram, model.error().message);
    return 1;
  }
  const learn::Model& net = *model.value();
  Csv csv = openCsv(kProgram, args,
                    "scene,width,height,budget,isa,covered,fragments,kplus_dynamic_ms,count_ms,"
                    "features_ms,inference_ms,dkb_ms,overhead_percent,inference_only_ms,"
                    "inference_mpix_s");
  std::vector<Isa> paths = {Isa::Scalar};
  for (Isa isa : {Isa::Avx2, Isa::Avx512})
    if (static_cast<int>(isa) <= static_cast<int>(detectedIsa())) paths.push_back(isa);
  std::printf("bench_dkb: deep k-buffer feature pass and inference, %s, budget %s, paths:",
              runDescription(args, resolveThreads(args.threads)).c_str(),
              formatBytes(budget).c_str());
  for (Isa isa : paths) std::printf(" %s", std::string(isaName(isa)).c_str());
  std::printf(" (active %s)\n", std::string(isaName(activeIsa())).c_str());
  const std::string dish = std::string(MFR_SCENES_DIR) +
                           "/khronos/IridescentDishWithOlives/glTF/IridescentDishWithOlives.gltf";
  const std::vector<SceneCase> scenes = {{"hairball", "procedural:hairball", false},
                                         {"IridescentDishWithOlives", dish, true}};
  Table table({"scene", "isa", "covered px", "kplus-dyn ms", "count ms", "features ms",
               "inference ms", "dkb ms", "(f+i)/kplus", "infer-only ms", "Mpix/s"});
  table.leftAlign(1);
  std::vector<PlotSeries> series;
  const glm::vec3 colors[] = {
      {0.85f, 0.3f, 0.1f}, {0.1f, 0.45f, 0.8f}, {0.2f, 0.6f, 0.2f}, {0.5f, 0.3f, 0.7f}};
  FrameStore store(kProgram);
  bool failed = false;
  for (const SceneCase& sc : scenes) {
    if (sc.file && !std::filesystem::exists(sc.source)) {
      std::printf("skipping %s: %s not found (the shared scenes folder is absent)\n",
                  sc.label.c_str(), sc.source.c_str());
      continue;
    }
    Scene* scene = store.load(sc.source);
    if (!scene) {
      failed = true;
      continue;
    }
    Camera camera = sceneCamera(*scene);
    if (sc.file) {
      scene->alphaOverride = 0.5f;
      camera.eye = camera.target + (camera.eye - camera.target) / 1.6f;
    }
    auto built =
        RasterFrame::build(*scene, camera, RasterOptions{args.size, args.size, 16, args.threads});
    if (!built) {
      printError(kProgram, built.error().message);
      failed = true;
      continue;
    }
    const RasterFrame& frame = built.value();
    RenderOptions options;
    options.budgetBytes = budget;
    const auto makeCase = [&](const char* preset) {
      Case c;
      c.frame = &frame;
      c.method = methodPreset(preset).value();
      c.options = options;
      return c;
    };
    Case kplus = makeCase("kplus-dynamic");
    std::vector<PathRuns> runs;
    for (Isa isa : paths) runs.push_back({isa, makeCase("dkb"), {}});
    // the inference-only input: the covered pixels' features (the same on every path)
    ImageFeatureStats image;
    countWithDepthRange(frame, image);
    const uint64_t slots =
        MemoryModel::of(methodPreset("dkb").value()).fragmentSlots(budget, frame.pixelCount());
    std::vector<float> rows;
    for (const FeatureAccumulator& a : accumulateFeatures(frame)) {
      if (a.n == 0) continue;
      const PixelFeatures pf = pixelFeatures(a, image, slots);
      rows.insert(rows.end(), pf.begin(), pf.end());
    }
    const size_t covered = rows.size() / kDkbFeatureCount;
    std::vector<float> out(covered);
    // interleaved rounds: the kplus-dynamic frame, then every path's dkb frame and inference
    const Isa before = activeIsa();
    for (int rep = 0; rep < args.reps; ++rep) {
      std::vector<Case> one = {kplus};
      runInterleaved(one, 1);
      kplus = std::move(one[0]);
      for (PathRuns& r : runs) {
        setActiveIsa(r.isa);
        std::vector<Case> c = {r.dkb};
        runInterleaved(c, 1);
        r.dkb = std::move(c[0]);
        const auto start = Clock::now();
        learn::predictRows(net.net, rows.data(), covered, out.data());
        r.inferOnly.push_back(msSince(start));
      }
    }
    setActiveIsa(before);
    if (kplus.error || kplus.totalSamples.empty()) {
      printError(kProgram, sc.label + ": kplus-dynamic: " + kplus.error.value_or("no run"));
      failed = true;
      continue;
    }
    PlotSeries overhead{sc.label + " features + inference", {}, {}, colors[series.size() % 4]};
    PlotSeries frameMs{sc.label + " kplus-dynamic frame", {}, {}, colors[(series.size() + 1) % 4]};
    for (size_t i = 0; i < runs.size(); ++i) {
      const PathRuns& r = runs[i];
      if (r.dkb.error) {
        printError(kProgram, sc.label + ": dkb: " + *r.dkb.error);
        failed = true;
        continue;
      }
      const double f = r.dkb.pass("features"), inf = r.dkb.pass("inference");
      const double ratio = 100.0 * (f + inf) / kplus.totalMs();
      const double inferMs = median(r.inferOnly);
      const std::string isa(isaName(r.isa));
      table.add({sc.label, isa, num(covered), fixed(kplus.totalMs(), 1),
                 fixed(r.dkb.pass("count"), 1), fixed(f, 1), fixed(inf, 1),
                 fixed(r.dkb.totalMs(), 1), fixed(ratio, 1) + "%", fixed(inferMs, 1),
                 fixed(covered / inferMs / 1000.0, 2)});
      csv.row({sc.label, std::to_string(args.size), std::to_string(args.size),
               std::to_string(budget), isa, std::to_string(covered),
               std::to_string(r.dkb.stats.fragmentsGenerated), fixed(kplus.totalMs(), 3),
               fixed(r.dkb.pass("count"), 3), fixed(f, 3), fixed(inf, 3), fixed(r.dkb.totalMs(), 3),
               fixed(ratio, 2), fixed(inferMs, 3), fixed(covered / inferMs / 1000.0, 3)});
      overhead.x.push_back(static_cast<double>(r.isa));
      overhead.y.push_back(f + inf);
      frameMs.x.push_back(static_cast<double>(r.isa));
      frameMs.y.push_back(kplus.totalMs());
    }
    series.push_back(overhead);
    series.push_back(frameMs);
  }
  table.print();
  std::printf("CSV: %s\n", csv.path().string().c_str());
  PlotOptions po;
  po.title = "deep k-buffer: features + inference vs a kplus-dynamic frame";
  po.xLabel = "instruction set (0 scalar, 1 avx2, 2 avx512)";
  po.yLabel = "ms";
  if (!writePlotPng(kProgram, args.out, "dkb.png", series, po)) failed = true;
  return failed ? 1 : 0;
}

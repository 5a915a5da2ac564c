// bench_dkb: the deep k-buffer's per-frame overhead (Deep hybrid OIT, sec. 4.1, Table 1: "NN
// feature extraction" and "importance computation"), at --size^2 with the built-in model.
//
// For each scene (procedural:hairball; IridescentDishWithOlives from ../shared/scenes at zoom 1.6
// with global alpha 0.5, skipped when absent), medians of --reps runs of:
//   count     the count pass with the image's depth range (countWithDepthRange)
//   fused     the runtime importance pass: per tile, features + one inference batch
//             (predictImportance), wall time, with the CPU time of its two parts
//   features  a full-screen feature pass alone (accumulateFeatures + pixelFeatures)
//   infer     batch inference alone over the covered pixels' features (predictRows)
// and the inference rate in M pixels/s. CSV: dkb.csv.
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "mfr/cpu/deep_importance.hpp"
#include "mfr/learn/model_file.hpp"

namespace {

using namespace mfr;
using namespace mfr::bench;

constexpr Program kProgram{.name = "bench_dkb", .csv = "dkb.csv"};

}  // namespace

int main(int argc, char** argv) {
  const Args args = parseArgs(argc, argv, kProgram);
  auto model = builtinDkbModel();
  if (!model) {
    printError(kProgram, model.error().message);
    return 1;
  }
  const learn::Model& net = *model.value();
  Csv csv = openCsv(kProgram, args,
                    "scene,width,height,covered,fragments,count_ms,fused_ms,fused_feature_cpu_ms,"
                    "fused_inference_cpu_ms,features_ms,inference_ms,inference_mpix_s");
  std::printf("bench_dkb: deep k-buffer feature pass and inference, %s\n",
              runDescription(args, resolveThreads(args.threads)).c_str());
  const std::string dish = std::string(MFR_SCENES_DIR) +
                           "/khronos/IridescentDishWithOlives/glTF/IridescentDishWithOlives.gltf";
  const std::vector<SceneCase> scenes = {{"hairball", "procedural:hairball", false},
                                         {"IridescentDishWithOlives", dish, true}};
  Table table({"scene", "covered px", "fragments", "count ms", "fused ms", "(feature cpu",
               "inference cpu)", "features ms", "inference ms", "Mpix/s"});
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
    std::vector<double> count, fused, fusedFeature, fusedInference, features, inference;
    ImageFeatureStats image;
    size_t covered = 0;
    for (int rep = 0; rep < args.reps; ++rep) {
      auto start = Clock::now();
      const std::vector<uint32_t> n = countWithDepthRange(frame, image);
      count.push_back(msSince(start));
      const uint64_t slots = image.fragments / 2;
      double f = 0.0, i = 0.0;
      start = Clock::now();
      const std::vector<float> importance = predictImportance(frame, net, image, slots, &f, &i);
      fused.push_back(msSince(start));
      fusedFeature.push_back(f);
      fusedInference.push_back(i);
      start = Clock::now();
      const std::vector<FeatureAccumulator> acc = accumulateFeatures(frame);
      std::vector<float> rows;
      rows.reserve(image.coveredPixels * kDkbFeatureCount);
      for (const FeatureAccumulator& a : acc) {
        if (a.n == 0) continue;
        const PixelFeatures pf = pixelFeatures(a, image, slots);
        rows.insert(rows.end(), pf.begin(), pf.end());
      }
      features.push_back(msSince(start));
      covered = rows.size() / kDkbFeatureCount;
      std::vector<float> out(covered);
      start = Clock::now();
      learn::predictRows(net.net, rows.data(), covered, out.data());
      inference.push_back(msSince(start));
    }
    const double inferMs = median(inference);
    const std::vector<std::string> row = {sc.label,
                                          num(covered),
                                          num(image.fragments),
                                          fixed(median(count), 1),
                                          fixed(median(fused), 1),
                                          fixed(median(fusedFeature), 1),
                                          fixed(median(fusedInference), 1),
                                          fixed(median(features), 1),
                                          fixed(inferMs, 1),
                                          fixed(covered / inferMs / 1000.0, 2)};
    table.add(row);
    csv.row({sc.label, std::to_string(args.size), std::to_string(args.size),
             std::to_string(covered), std::to_string(image.fragments), fixed(median(count), 3),
             fixed(median(fused), 3), fixed(median(fusedFeature), 3),
             fixed(median(fusedInference), 3), fixed(median(features), 3), fixed(inferMs, 3),
             fixed(covered / inferMs / 1000.0, 3)});
  }
  table.print();
  std::printf("CSV: %s\n", csv.path().string().c_str());
  return failed ? 1 : 0;
}

// bench_presets: every method preset under one memory budget, in the layout of Table 2 of the
// variable k-buffer paper ("Variable k-buffer using importance maps", Vasilakis, Vardis,
// Papaioannou, Moustakas: time, k range, captured fragments and loss under a fixed M, per scene
// with its maximum depth complexity D).
//
// Scenes: IridescentDishWithOlives (real glTF from ../shared/scenes, rendered with a global alpha
// override of 0.5 as the papers render whole scenes transparent; skipped with a message when the
// file is absent) and procedural:hairball, at 1024x1024 with M = 20 MiB (20 * 2^20 bytes).
// Presets: every name presetNames() lists (zbuffer, abuffer with no budget as the exact reference,
// fkb, kplus-array, kplus-heap, kplus-sb, kplus-dynamic, the variable k-buffer ones, ...), then the
// +occupancy variant of every bounded one. For each: total time and time per pass (median of
// --reps runs), bytes used, k range over covered pixels, captured fragments and the % of generated
// fragments lost. A preset whose buffers do not fit M is reported as a row carrying the budget
// error. CSV: presets.csv (one row per scene and preset).
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bench_common.hpp"
#include "mfr/core/units.hpp"

namespace {

using namespace mfr;
using namespace mfr::bench;

constexpr Program kProgram{
    .name = "bench_presets",
    .csv = "presets.csv",
    .options = " [--budget M]",
    .optionsHelp =
        "  --budget M    memory budget, e.g. 20MB (default 20 MiB at 1024x1024, "
        "scaled with the pixel\n"
        "                count at other sizes so the bytes per pixel stay the same)\n"};

constexpr uint64_t kBudgetAt1024 = 20ull << 20;  // M = 20 MiB at 1024x1024
constexpr float kAlphaOverride = 0.5f;           // real scenes rendered fully transparent

// Passes outside the table's fixed columns (e.g. the variable k-buffer's nearest-normal and
// importance passes): summed into "other", their names joined by '+'.
double otherMs(const Case& m, std::string& names) {
  static const std::vector<std::string> kColumns = {
      "count",          "allocate",        "clear",   "depth_range",
      "occupancy_fill", "occupancy_count", "capture", "resolve"};
  double ms = 0.0;
  for (const auto& [name, samples] : m.passSamples) {
    if (std::find(kColumns.begin(), kColumns.end(), name) != kColumns.end()) continue;
    ms += median(samples);
    if (!names.empty()) names += "+";
    names += name;
  }
  return ms;
}

}  // namespace

int main(int argc, char** argv) {
  std::optional<uint64_t> budgetOption;
  if (!takeBudget(kProgram, argc, argv, budgetOption)) return 2;
  const Args args = parseArgs(argc, argv, kProgram);
  const double pixelScale = static_cast<double>(args.size) * args.size / (1024.0 * 1024.0);
  const uint64_t budget =
      budgetOption.value_or(static_cast<uint64_t>(static_cast<double>(kBudgetAt1024) * pixelScale));

  Csv csv =
      openCsv(kProgram, args,
              "scene,scene_index,method,method_index,width,height,budget_bytes,max_depth,status,"
              "k_min,k_max,global_k,bytes_used,fragments,captured,lost,loss_pct,total_ms,count_ms,"
              "alloc_ms,occupancy_ms,capture_ms,resolve_ms,other_ms,other_passes,error");
  std::printf("bench_presets: every preset under M = %s (%llu bytes)%s, %s\n",
              formatBytes(budget).c_str(), static_cast<unsigned long long>(budget),
              budgetOption ? "" : (args.size == 1024 ? "" : " (20 MiB scaled to the pixel count)"),
              runDescription(args, resolveThreads(args.threads)).c_str());

  // every preset, then the +occupancy variant of each one that has it (the bounded ones)
  std::vector<std::string> presets = presetNames();
  for (const std::string& name : presetNames())
    if (methodPreset(name + "+occupancy").ok()) presets.push_back(name + "+occupancy");

  const std::string dish = std::string(MFR_SCENES_DIR) +
                           "/khronos/IridescentDishWithOlives/glTF/IridescentDishWithOlives.gltf";
  const std::vector<SceneCase> scenes = {{"IridescentDishWithOlives", dish, true},
                                         {"hairball", "procedural:hairball", false}};
  bool failed = false;
  // every (scene, preset) is a case: cases[scene * presets + preset]
  struct SceneInfo {
    const SceneCase* scene;
    std::string header;  // name, D, fragments
    uint32_t maxDepth;
  };
  std::vector<SceneInfo> measured;
  FrameStore store(kProgram);
  std::vector<Case> cases;
  for (const SceneCase& sc : scenes) {
    if (sc.file && !std::filesystem::exists(sc.source)) {
      std::printf("\nskipping %s: %s not found (the shared scenes folder is absent)\n",
                  sc.label.c_str(), sc.source.c_str());
      continue;
    }
    Scene* loaded = store.load(sc.source);
    if (!loaded) {
      failed = true;
      continue;
    }
    Scene& scene = *loaded;
    std::string note;
    if (sc.file) {
      scene.alphaOverride = kAlphaOverride;
      note = ", global alpha override 0.5 (whole scene transparent, as in the papers)";
    }
    const RasterFrame* frame = store.build(scene, args);
    if (!frame) {
      failed = true;
      continue;
    }
    // D and the A-buffer's needs, from one count pass
    const std::vector<uint32_t> n = countFragments(*frame);
    uint64_t total = 0;
    uint32_t maxDepth = 0;
    for (uint32_t c : n) {
      total += c;
      maxDepth = std::max(maxDepth, c);
    }
    char header[512];
    std::snprintf(header, sizeof header, "%s: %zu triangles, D = %u, %llu fragments%s",
                  sc.label.c_str(), scene.triangleCount(), maxDepth,
                  static_cast<unsigned long long>(total), note.c_str());
    measured.push_back({&sc, header, maxDepth});
    for (const std::string& name : presets) {
      Case c;
      c.frame = frame;
      c.method = methodPreset(name).value();
      if (c.method.allocation != AllocationPolicy::Unbounded) c.options.budgetBytes = budget;
      cases.push_back(std::move(c));
    }
  }
  runInterleaved(cases, args.reps);

  for (size_t sceneIndex = 0; sceneIndex < measured.size(); ++sceneIndex) {
    const SceneCase& sc = *measured[sceneIndex].scene;
    const uint32_t maxDepth = measured[sceneIndex].maxDepth;
    std::printf("\n%s\n", measured[sceneIndex].header.c_str());
    Table table({"method", "k", "MiB", "total ms", "count", "alloc", "occupancy", "capture",
                 "resolve", "other", "captured", "loss", "note"});
    table.leftAlign(12);
    std::string otherPasses;  // over the scene's presets
    for (size_t methodIndex = 0; methodIndex < presets.size(); ++methodIndex) {
      const std::string& name = presets[methodIndex];
      const Case& m = cases[sceneIndex * presets.size() + methodIndex];
      const RasterFrame* frame = m.frame;
      const RenderOptions& options = m.options;
      std::vector<std::string> row = {sc.label,
                                      std::to_string(sceneIndex),
                                      name,
                                      std::to_string(methodIndex),
                                      num(frame->width()),
                                      num(frame->height()),
                                      options.budgetBytes ? num(budget) : "",
                                      num(maxDepth)};
      if (m.error) {
        const std::string& message = *m.error;
        table.add(
            {name, "-", "-", "-", "-", "-", "-", "-", "-", "-", "-", "-", "error: " + message});
        row.insert(row.end(), {"error", "", "", "", "", "", "", "", "", "", "", "", "", "", "", "",
                               "", message});
        csv.row(row);
        continue;
      }
      const RenderStats& s = m.stats;
      const double alloc = m.allocMs();
      const double occupancy = m.occupancyMs();
      std::string others;
      const double other = otherMs(m, others);
      if (!others.empty() && otherPasses.find(others) == std::string::npos)
        otherPasses += (otherPasses.empty() ? "" : ", ") + others;
      std::string k = std::to_string(s.kMin);
      if (s.kMax != s.kMin) {
        k += "-";
        k += std::to_string(s.kMax);
      }
      table.add({name, k, mib(s.bytesUsed), fixed(m.totalMs(), 1), fixed(m.pass("count"), 1),
                 fixed(alloc, 1), fixed(occupancy, 1), fixed(m.pass("capture"), 1),
                 fixed(m.pass("resolve"), 1), fixed(other, 1), num(s.captured),
                 fixed(s.lostPercent(), 1) + "%", options.budgetBytes ? "" : "no budget"});
      row.insert(
          row.end(),
          {"ok", num(s.kMin), num(s.kMax), s.globalK ? num(*s.globalK) : "", num(s.bytesUsed),
           num(s.fragmentsGenerated), num(s.captured), num(s.lost), fixed(s.lostPercent(), 3),
           fixed(m.totalMs(), 3), fixed(m.pass("count"), 3), fixed(alloc, 3), fixed(occupancy, 3),
           fixed(m.pass("capture"), 3), fixed(m.pass("resolve"), 3), fixed(other, 3), others, ""});
      csv.row(row);
    }
    table.print();
    if (!otherPasses.empty()) std::printf("other = %s\n", otherPasses.c_str());
  }
  std::printf(
      "\nk: slots per covered pixel (min-max); MiB: bytes used (abuffer: what it needs, no budget);"
      "\nloss: %% of generated fragments not captured; pass times in ms (alloc = allocate + clear,"
      "\noccupancy = depth range + fill + count passes)\nwrote %s\n",
      csv.path().c_str());
  return failed ? 1 : 0;
}

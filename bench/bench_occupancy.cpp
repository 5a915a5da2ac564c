// bench_occupancy: occupancy-map culling on a high-depth-complexity scene. Mirrors Figure 5 of
// "Improving k-buffer methods via occupancy maps" (Vasilakis & Papaioannou: the k+-buffer's
// speed-up with culling as d grows, on the Hairball at k = 8) and its Figure 1 counts of discarded
// fragments.
//
// procedural:hairball at k = 8: kplus-array with the explicit k = 8 as the baseline, then
// kplus-array+occupancy with occupancyWords = d for d in {1, 2, 4, 8, 16, 32, 64} (32*d depth
// buckets per pixel). For each: fragments rejected by the occupancy test, by the k+ test (before
// the critical section) and inside the store, as counts and as % of the generated fragments; the
// time of the three occupancy passes, the capture pass and the whole render (median of --reps
// runs); and the speed-up over the baseline in total time and in capture-pass time. Occupancy
// culling is conservative (Lemma 2.1), so each variant must capture what the baseline captures and
// produce the same image: the "same" column checks it. CSV: occupancy.csv.
#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "bench_common.hpp"

namespace {

using namespace mfr;
using namespace mfr::bench;

constexpr Program kProgram{
    .name = "bench_occupancy", .csv = "occupancy.csv", .quick = "d in {1, 4, 64}, "};

constexpr uint32_t kK = 8;
constexpr const char* kScene = "procedural:hairball";

}  // namespace

int main(int argc, char** argv) {
  const Args args = parseArgs(argc, argv, kProgram);
  Csv csv =
      openCsv(kProgram, args,
              "d,buckets,width,height,threads,reps,fragments,culled_occupancy,culled_kplus,"
              "rejected_in_store,inserted,evicted,captured,occupancy_pct,kplus_pct,in_store_pct,"
              "rejected_pct,bytes_used,occupancy_passes_ms,capture_ms,resolve_ms,total_ms,"
              "speedup_capture,speedup_total,image_max_diff");
  const std::vector<int> ds =
      args.quick ? std::vector<int>{1, 4, 64} : std::vector<int>{1, 2, 4, 8, 16, 32, 64};

  FrameStore store(kProgram);
  const Scene* scene = store.load(kScene);
  if (!scene) return 1;
  const auto setupStart = Clock::now();
  const RasterFrame* frame = store.build(*scene, args);
  if (!frame) return 1;
  std::printf(
      "bench_occupancy: %s, kplus-array k = %u with and without occupancy culling, %s\n"
      "frame set-up %.1f ms (shared by every run, not in the times below); times in ms; rejected "
      "as %% of generated fragments\n\n",
      kScene, kK, runDescription(args, frame->threads()).c_str(), msSince(setupStart));

  Table table({"d", "buckets", "by occupancy", "by k+", "in store", "captured", "MiB",
               "occ. passes", "capture", "total", "capture speed-up", "total speed-up",
               "same image"});
  table.leftAlign(12);
  // case 0: the baseline without occupancy (d = 0), then one case per d
  std::vector<int> dValues = {0};
  dValues.insert(dValues.end(), ds.begin(), ds.end());
  std::vector<Case> cases;
  for (const int d : dValues) {
    Case c;
    c.frame = frame;
    c.method = methodPreset(d == 0 ? "kplus-array" : "kplus-array+occupancy").value();
    c.method.k = kK;
    c.method.occupancyWords = d;
    c.keepImage = true;
    cases.push_back(std::move(c));
  }
  runInterleaved(cases, args.reps);
  const Case& base = cases[0];
  if (base.error) {
    printError(kProgram, "baseline: " + *base.error);
    return 1;
  }
  bool failed = false;
  for (size_t i = 0; i < cases.size(); ++i) {
    const int d = dValues[i];
    const Case& m = cases[i];
    if (m.error) {
      printError(kProgram, "d=" + std::to_string(d) + ": " + *m.error);
      failed = true;
      continue;
    }
    const RenderStats& s = m.stats;
    const uint64_t gen = s.fragmentsGenerated;
    const double speedCapture =
        m.pass("capture") > 0 ? base.pass("capture") / m.pass("capture") : 0.0;
    const double speedTotal = m.totalMs() > 0 ? base.totalMs() / m.totalMs() : 0.0;
    const float diff = maxAbsDiff(m.image, base.image);
    const bool same = diff == 0.0f && s.captured == base.stats.captured;
    const std::string label = d == 0 ? "off" : std::to_string(d);
    table.add({label, d == 0 ? "-" : std::to_string(32 * d),
               fixed(percent(s.culledOccupancy, gen), 2) + "%",
               fixed(percent(s.culledKPlus, gen), 2) + "%",
               fixed(percent(s.rejectedInStore, gen), 2) + "%", num(s.captured), mib(s.bytesUsed),
               fixed(m.occupancyMs(), 1), fixed(m.pass("capture"), 1), fixed(m.totalMs(), 1),
               fixed(speedCapture, 2) + "x", fixed(speedTotal, 2) + "x",
               same ? "yes" : "NO (max diff " + fixed(diff, 4) + ")"});
    csv.row({std::to_string(d),
             std::to_string(32 * d),
             num(frame->width()),
             num(frame->height()),
             num(frame->threads()),
             num(args.reps),
             num(gen),
             num(s.culledOccupancy),
             num(s.culledKPlus),
             num(s.rejectedInStore),
             num(s.inserted),
             num(s.evicted),
             num(s.captured),
             fixed(percent(s.culledOccupancy, gen), 3),
             fixed(percent(s.culledKPlus, gen), 3),
             fixed(percent(s.rejectedInStore, gen), 3),
             fixed(percent(s.culledOccupancy + s.culledKPlus + s.rejectedInStore, gen), 3),
             num(s.bytesUsed),
             fixed(m.occupancyMs(), 3),
             fixed(m.pass("capture"), 3),
             fixed(m.pass("resolve"), 3),
             fixed(m.totalMs(), 3),
             fixed(speedCapture, 3),
             fixed(speedTotal, 3),
             fixed(diff, 6)});
  }
  table.print();
  std::printf(
      "\n%llu fragments generated per run; speed-up = baseline time / time (baseline: "
      "d = off)\n",
      static_cast<unsigned long long>(base.stats.fragmentsGenerated));
  std::printf("wrote %s\n", csv.path().c_str());
  return failed ? 1 : 0;
}

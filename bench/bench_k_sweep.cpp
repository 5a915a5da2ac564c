// bench_k_sweep: max-array vs max-heap k+-buffer as k grows, at a fixed n = 128 fragments per
// covered pixel. Mirrors Figure 5 of the k+-buffer paper (Vasilakis & Fudos: "performance of
// k-buffer variants with varying k on a scene with constant fragment complexity (128)"), whose
// finding is that the heap wins above about k = 16 (which also gives the K+B-SB rule: heap when
// n(p) > k(p) > 16).
//
// Scene: procedural:layers?k=K&r=128/K&pd=0.5 (n = r*k randomly ordered full-square quads over half
// of the image). For k in {4, 8, 12, 16, 24, 32, 48, 64}, kplus-array and kplus-heap run with the
// explicit k (no budget); the program times the capture pass, the resolve pass and the whole render
// (median of --reps runs) and prints which store wins at each k. For k = 12, 24, 48, 128/k is not
// an integer: the layers scene depends only on n = r*k (the split into k and r is the paper's
// notation), so those points use the n = 128 scene layers?k=1&r=128 to keep n exact.
// CSV: k_sweep.csv.
#include <cstdint>
#include <cstdio>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "bench_common.hpp"

namespace {

using namespace mfr;
using namespace mfr::bench;

constexpr Program kProgram{
    .name = "bench_k_sweep", .csv = "k_sweep.csv", .quick = "k in {4, 16, 64}, "};

constexpr int kFragmentsPerPixel = 128;  // n

// The paper's scene for k: n = r*k = 128 quads; when k does not divide 128 the same n = 128 scene
// under the split k=1, r=128 (the geometry depends on n only).
std::string layersSpec(int k) {
  const int k1 = kFragmentsPerPixel % k == 0 ? k : 1;
  std::string spec = "procedural:layers?k=";
  spec += std::to_string(k1);
  spec += "&r=";
  spec += std::to_string(kFragmentsPerPixel / k1);
  spec += "&pd=0.5";
  return spec;
}

}  // namespace

int main(int argc, char** argv) {
  const Args args = parseArgs(argc, argv, kProgram);
  Csv csv =
      openCsv(kProgram, args,
              "k,n,scene,width,height,threads,reps,fragments,covered_pixels,culled_kplus,captured,"
              "array_alloc_ms,array_capture_ms,array_resolve_ms,array_total_ms,heap_alloc_ms,"
              "heap_capture_ms,heap_resolve_ms,heap_total_ms,heap_speedup_capture,"
              "heap_speedup_total,winner_capture,winner_total");
  const std::vector<int> ks =
      args.quick ? std::vector<int>{4, 16, 64} : std::vector<int>{4, 8, 12, 16, 24, 32, 48, 64};
  std::printf(
      "bench_k_sweep: kplus-array vs kplus-heap, n = %d fragments per covered pixel, pd = 0.5, "
      "%s; times in ms\n\n",
      kFragmentsPerPixel, runDescription(args, resolveThreads(args.threads)).c_str());

  Table table({"k", "n", "capture array", "capture heap", "resolve array", "resolve heap",
               "total array", "total heap", "heap speed-up", "faster (capture)", "faster (total)"});
  // one frame per k (the spec names the paper's split of n), two cases per frame
  FrameStore store(kProgram);
  std::vector<Case> cases;
  for (const int k : ks) {
    const Scene* scene = store.load(layersSpec(k));
    const RasterFrame* frame = scene ? store.build(*scene, args) : nullptr;
    if (!frame) return 1;
    for (const char* name : {"kplus-array", "kplus-heap"}) {
      Case c;
      c.frame = frame;
      c.method = methodPreset(name).value();
      c.method.k = static_cast<uint32_t>(k);
      cases.push_back(std::move(c));
    }
  }
  runInterleaved(cases, args.reps);

  std::vector<std::pair<int, bool>> heapWinsTotal;  // (k, heap faster in total)
  bool failed = false;
  for (size_t i = 0; i < ks.size(); ++i) {
    const int k = ks[i];
    const std::string spec = layersSpec(k);
    const Case& arr = cases[2 * i];
    const Case& heap = cases[2 * i + 1];
    if (arr.error || heap.error) {
      printError(kProgram, "k=" + std::to_string(k) + ": " + *(arr.error ? arr.error : heap.error));
      failed = true;
      continue;
    }
    const RasterFrame* frame = arr.frame;
    const RenderStats& s = arr.stats;
    if (s.captured != heap.stats.captured || s.fragmentsGenerated != heap.stats.fragmentsGenerated)
      std::printf("note: k=%d: array captured %llu of %llu, heap %llu of %llu\n", k,
                  static_cast<unsigned long long>(s.captured),
                  static_cast<unsigned long long>(s.fragmentsGenerated),
                  static_cast<unsigned long long>(heap.stats.captured),
                  static_cast<unsigned long long>(heap.stats.fragmentsGenerated));
    const double n =
        s.coveredPixels ? static_cast<double>(s.fragmentsGenerated) / s.coveredPixels : 0.0;
    const double capA = arr.pass("capture"), capH = heap.pass("capture");
    const double speedCapture = capH > 0 ? capA / capH : 0.0;
    const double speedTotal = heap.totalMs() > 0 ? arr.totalMs() / heap.totalMs() : 0.0;
    const char* winCapture = capH < capA ? "heap" : "array";
    const char* winTotal = heap.totalMs() < arr.totalMs() ? "heap" : "array";
    heapWinsTotal.emplace_back(k, heap.totalMs() < arr.totalMs());
    table.add({std::to_string(k), fixed(n, 1), fixed(capA, 1), fixed(capH, 1),
               fixed(arr.pass("resolve"), 1), fixed(heap.pass("resolve"), 1),
               fixed(arr.totalMs(), 1), fixed(heap.totalMs(), 1), fixed(speedTotal, 2) + "x",
               winCapture, winTotal});
    csv.row({std::to_string(k),
             fixed(n, 2),
             spec,
             num(frame->width()),
             num(frame->height()),
             num(frame->threads()),
             num(args.reps),
             num(s.fragmentsGenerated),
             num(s.coveredPixels),
             num(s.culledKPlus),
             num(s.captured),
             fixed(arr.allocMs(), 3),
             fixed(capA, 3),
             fixed(arr.pass("resolve"), 3),
             fixed(arr.totalMs(), 3),
             fixed(heap.allocMs(), 3),
             fixed(capH, 3),
             fixed(heap.pass("resolve"), 3),
             fixed(heap.totalMs(), 3),
             fixed(speedCapture, 3),
             fixed(speedTotal, 3),
             winCapture,
             winTotal});
  }
  table.print();
  // the crossover: the smallest k from which the heap wins at every larger k of the sweep
  std::optional<int> from;
  for (auto it = heapWinsTotal.rbegin(); it != heapWinsTotal.rend() && it->second; ++it)
    from = it->first;
  if (from)
    std::printf("\nheap faster in total from k = %d on (paper: above about k = 16)\n", *from);
  else
    std::printf("\nheap not faster in total at the largest k (paper: above about k = 16)\n");
  std::printf("heap speed-up = array total / heap total\nwrote %s\n", csv.path().c_str());
  return failed ? 1 : 0;
}

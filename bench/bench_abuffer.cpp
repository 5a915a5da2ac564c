// bench_abuffer: rasterize + capture throughput of the A-buffer (the unbounded reference every
// bounded method is measured against; "foundation" item 8).
//
// For procedural:layers (defaults: n = 128 fragments on half of the pixels) and procedural:hairball
// it times, as the median of --reps runs at --size x --size:
//   set-up   RasterFrame::build (transform, clip, bin)       once per frame, shared by every method
//   count    the count pass (coverage raster, n(p))
//   alloc    allocate + clear (prefix sum, node buffer)
//   capture  the store pass (full shading, append into exact-size arrays)
//   resolve  per-pixel sort + front-to-back compositing
// and reports throughput in fragments/s and ns/fragment for count + capture (the "rasterize +
// capture" figure: the A-buffer rasterizes every fragment twice) and for each pass alone. The goal
// printed next to it is at least 100 M fragments/s for layers on the 2-core reference machine.
// The A-buffer is the papers' unbounded ground truth (the k+-buffer paper's Figure 9 compares
// A-buffer alternatives); this is the raw rasterizer + store speed every other bench builds on.
// CSV: abuffer.csv.
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

constexpr Program kProgram{.name = "bench_abuffer", .csv = "abuffer.csv"};

constexpr double kGoalMFragPerS = 100.0;  // layers, rasterize + capture, 1024x1024, 2 cores

}  // namespace

int main(int argc, char** argv) {
  const Args args = parseArgs(argc, argv, kProgram);
  Csv csv =
      openCsv(kProgram, args,
              "scene,source,width,height,threads,reps,triangles,fragments,covered_pixels,max_depth,"
              "setup_ms,count_ms,alloc_ms,capture_ms,resolve_ms,total_ms,rc_ms,rc_mfrag_s,"
              "rc_ns_frag,count_mfrag_s,count_ns_frag,capture_mfrag_s,capture_ns_frag,"
              "resolve_mfrag_s,resolve_ns_frag,total_mfrag_s,goal_mfrag_s");

  std::printf("bench_abuffer: A-buffer rasterize + capture throughput, %s\n",
              runDescription(args, resolveThreads(args.threads)).c_str());

  const std::vector<SceneCase> scenes = {{"layers", "procedural:layers"},
                                         {"hairball", "procedural:hairball"}};
  bool failed = false;
  for (const SceneCase& sc : scenes) {
    FrameStore store(kProgram);  // this scene only
    const Scene* loaded = store.load(sc.source);
    if (!loaded) {
      failed = true;
      continue;
    }
    const Scene& scene = *loaded;
    std::vector<double> setupTimes;
    std::optional<RasterFrame> frame;
    for (int r = 0; r < args.reps; ++r) {
      const auto start = Clock::now();
      auto built = buildFrame(scene, args);
      setupTimes.push_back(msSince(start));
      if (!built) {
        printError(kProgram, built.error().message);
        return 1;
      }
      frame.emplace(std::move(built.value()));
    }
    const double setupMs = median(setupTimes);

    auto method = methodPreset("abuffer");
    MFR_CHECK(method.ok());
    std::vector<Case> cases(1);
    cases[0].frame = &*frame;
    cases[0].method = *method;
    runInterleaved(cases, args.reps);
    const Case& m = cases[0];
    if (m.error) {
      printError(kProgram, sc.label + ": " + *m.error);
      failed = true;
      continue;
    }
    const RenderStats& s = m.stats;
    const uint64_t frags = s.fragmentsGenerated;
    const double countMs = m.pass("count"), captureMs = m.pass("capture");
    const double allocMs = m.allocMs(), resolveMs = m.pass("resolve");
    const double rcMs = countMs + captureMs;

    std::printf("\n%s (%s): %zu triangles, %llu fragments, %llu covered pixels, max depth %u\n",
                sc.label.c_str(), sc.source.c_str(), scene.triangleCount(),
                static_cast<unsigned long long>(frags),
                static_cast<unsigned long long>(s.coveredPixels), s.maxDepthComplexity.value_or(0));
    if (s.fragmentSlots != frags)
      std::printf("  note: count pass saw %llu fragments but capture generated %llu\n",
                  static_cast<unsigned long long>(s.fragmentSlots),
                  static_cast<unsigned long long>(frags));
    Table t({"pass", "ms", "M frag/s", "ns/frag"});
    auto rate = [&](const std::string& name, double ms) {
      t.add({name, fixed(ms, 1), fixed(mfragPerS(frags, ms), 1), fixed(nsPerFrag(frags, ms), 2)});
    };
    t.add({"set-up (build)", fixed(setupMs, 1), "-", "-"});
    rate("count", countMs);
    t.add({"alloc + clear", fixed(allocMs, 1), "-", "-"});
    rate("capture (store)", captureMs);
    rate("count + capture", rcMs);
    rate("resolve", resolveMs);
    rate("render total", m.totalMs());
    t.print();
    const double rc = mfragPerS(frags, rcMs);
    if (sc.label == "layers") {
      std::string where;
      if (args.size != 1024) {
        where = " (measured at ";
        where += std::to_string(args.size);
        where += "x";
        where += std::to_string(args.size);
        where += "; the goal is stated for 1024x1024)";
      }
      std::printf("goal: rasterize + capture >= %.0f M fragments/s: %.1f M/s -> %s%s\n",
                  kGoalMFragPerS, rc, rc >= kGoalMFragPerS ? "MET" : "NOT MET", where.c_str());
    }

    csv.row({sc.label,
             sc.source,
             std::to_string(args.size),
             std::to_string(args.size),
             std::to_string(frame->threads()),
             std::to_string(args.reps),
             num(scene.triangleCount()),
             num(frags),
             num(s.coveredPixels),
             num(s.maxDepthComplexity.value_or(0)),
             fixed(setupMs, 3),
             fixed(countMs, 3),
             fixed(allocMs, 3),
             fixed(captureMs, 3),
             fixed(resolveMs, 3),
             fixed(m.totalMs(), 3),
             fixed(rcMs, 3),
             fixed(rc, 2),
             fixed(nsPerFrag(frags, rcMs), 3),
             fixed(mfragPerS(frags, countMs), 2),
             fixed(nsPerFrag(frags, countMs), 3),
             fixed(mfragPerS(frags, captureMs), 2),
             fixed(nsPerFrag(frags, captureMs), 3),
             fixed(mfragPerS(frags, resolveMs), 2),
             fixed(nsPerFrag(frags, resolveMs), 3),
             fixed(mfragPerS(frags, m.totalMs()), 2),
             sc.label == "layers" ? fixed(kGoalMFragPerS, 0) : ""});
  }
  std::printf("\nwrote %s\n", csv.path().c_str());
  return failed ? 1 : 0;
}

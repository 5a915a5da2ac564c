// bench_isa: the CPU engine's passes on each instruction-set path (mfr/core/isa.hpp): the scalar
// loops against the 8-lane AVX2 capture (raster_span_avx2.hpp; the k+-buffer paper's Algorithm 3
// with the k+ test before shading), side by side in one run, the paths interleaved round by round
// so that a shared machine's slow periods hit both alike. Issue 12's frame first:
// procedural:layers?k=8&r=2&pd=0.55 (16 layers), kplus-heap, k = 8, kbuffer compositing; then the
// hairball and the same layers with hybrid compositing (on the lanes too since 2026-12-02: every
// fragment shaded, no early k+ test) and the A-buffer (count pass).
//
// For each (scene, method, path): per-pass median ms (count, capture, resolve) and the whole frame,
// fragments/s per pass and per frame, and the speed-up of the path over the scalar one; the image
// of every path is checked against the scalar image (identical bytes expected).
// CSV: isa.csv (one row per scene, method and path).
#include <cstdint>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "bench_common.hpp"
#include "mfr/core/isa.hpp"
#include "mfr/method/stats_json.hpp"

namespace {

using namespace mfr;
using namespace mfr::bench;

constexpr Program kProgram{.name = "bench_isa", .csv = "isa.csv"};

struct MethodCase {
  std::string label;  // in the tables
  std::string preset;
  std::optional<uint32_t> k;
  Compositing compositing;
};

}  // namespace

int main(int argc, char** argv) {
  const Args args = parseArgs(argc, argv, kProgram);
  Csv csv = openCsv(kProgram, args,
                    "scene,method,isa,width,height,threads,reps,fragments,count_ms,capture_ms,"
                    "resolve_ms,frame_ms,count_mfrag_s,capture_mfrag_s,resolve_mfrag_s,"
                    "frame_mfrag_s,capture_speedup,frame_speedup,same_image");
  std::printf("bench_isa: scalar vs avx2 capture of the CPU engine (CPU: %s), %s\n",
              std::string(isaName(detectedIsa())).c_str(),
              runDescription(args, resolveThreads(args.threads)).c_str());

  const std::vector<SceneCase> scenes = {{"layers16", "procedural:layers?k=8&r=2&pd=0.55"},
                                         {"hairball", "procedural:hairball"}};
  const std::vector<MethodCase> methods = {
      {"kplus-heap k=8", "kplus-heap", 8, Compositing::KBuffer},
      {"kplus-array k=8", "kplus-array", 8, Compositing::KBuffer},
      {"kplus-heap k=8 hybrid", "kplus-heap", 8, Compositing::Hybrid},
      {"abuffer", "abuffer", std::nullopt, Compositing::KBuffer}};
  std::vector<Isa> paths = {Isa::Scalar};
  if (detectedIsa() != Isa::Scalar) paths.push_back(Isa::Avx2);

  FrameStore store(kProgram);
  struct Measured {
    const SceneCase* scene;
    const MethodCase* method;
    Isa isa;
    Case c;
  };
  std::vector<Measured> cases;
  bool failed = false;
  for (const SceneCase& sc : scenes) {
    const Scene* scene = store.load(sc.source);
    if (!scene) {
      failed = true;
      continue;
    }
    const RasterFrame* frame = store.build(*scene, args);
    if (!frame) return 1;
    for (const MethodCase& mc : methods)
      for (Isa isa : paths) {
        Case c;
        c.frame = frame;
        c.method = methodPreset(mc.preset).value();
        if (mc.k) c.method.k = *mc.k;
        c.method.compositing = mc.compositing;
        c.keepImage = true;
        cases.push_back({&sc, &mc, isa, std::move(c)});
      }
  }
  // interleaved rounds, each case on its own path
  const Isa restore = activeIsa();
  for (int round = 0; round < args.reps; ++round) {
    std::fprintf(stderr, "  round %d/%d: %zu case(s)\n", round + 1, args.reps, cases.size());
    for (Measured& m : cases) {
      if (m.c.error) continue;
      setActiveIsa(m.isa);
      auto out = render(*m.c.frame, m.c.method, m.c.options);
      if (!out) {
        m.c.error = out.error().message;
        continue;
      }
      for (const PassTime& p : out->stats.passes) m.c.passSamples[p.name].push_back(p.ms);
      m.c.totalSamples.push_back(out->stats.totalMs());
      m.c.stats = std::move(out->stats);
      m.c.image = std::move(out->image);
    }
  }
  setActiveIsa(restore);

  Table table({"scene", "method", "isa", "count ms", "capture ms", "resolve ms", "frame ms",
               "capture M frag/s", "frame M frag/s", "capture x", "frame x", "same image"});
  table.leftAlign(1);
  table.leftAlign(2);
  table.leftAlign(11);
  const Measured* scalar = nullptr;
  for (const Measured& m : cases) {
    if (m.isa == Isa::Scalar) scalar = &m;
    if (m.c.error) {
      printError(kProgram, m.scene->label + " " + m.method->label + ": " + *m.c.error);
      failed = true;
      continue;
    }
    const RenderStats& s = m.c.stats;
    const uint64_t n = s.fragmentsGenerated;
    const double count = m.c.pass("count"), capture = m.c.pass("capture"),
                 resolve = m.c.pass("resolve"), frame = m.c.totalMs();
    const double captureX = capture > 0 ? scalar->c.pass("capture") / capture : 0.0;
    const double frameX = frame > 0 ? scalar->c.totalMs() / frame : 0.0;
    const bool same = m.c.image.pixels == scalar->c.image.pixels;
    if (!same) failed = true;
    const std::string isa = statsToJson(s)["isa"].get<std::string>();
    table.add({m.scene->label, m.method->label, isa, fixed(count, 1), fixed(capture, 1),
               fixed(resolve, 1), fixed(frame, 1), fixed(mfragPerS(n, capture), 1),
               fixed(mfragPerS(n, frame), 1), fixed(captureX, 2), fixed(frameX, 2),
               same ? "yes" : "NO"});
    csv.row({m.scene->label, m.method->label, isa, num(m.c.frame->width()),
             num(m.c.frame->height()), num(m.c.frame->threads()), num(args.reps), num(n),
             fixed(count, 3), fixed(capture, 3), fixed(resolve, 3), fixed(frame, 3),
             fixed(mfragPerS(n, count), 3), fixed(mfragPerS(n, capture), 3),
             fixed(mfragPerS(n, resolve), 3), fixed(mfragPerS(n, frame), 3), fixed(captureX, 3),
             fixed(frameX, 3), same ? "1" : "0"});
  }
  std::printf("\n");
  table.print();
  std::printf(
      "\nisa = the capture path the statistics report; M frag/s = fragments generated / pass "
      "time;\nx = speed-up over the scalar path in the same run\nwrote %s\n",
      csv.path().c_str());
  return failed ? 1 : 0;
}

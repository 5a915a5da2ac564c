// bench_oracle: the optimal k-buffer oracle's cost (DHOIT sec. 3.1.2: exact A-buffer pre-pass,
// per-pixel error curves, the allocation of optimal_allocation.hpp) on procedural:hairball at
// --size^2 and --budget (default 120 MB), both compositing rules: medians of --reps runs of the
// oracle pass and the whole frame, the solver and its proven gap, and the process's peak resident
// memory (getrusage; it only grows, so run one configuration per process to read a frame's peak:
// --rule hybrid|kbuffer). CSV: oracle.csv; chart: oracle.png (ms per run).
#include <sys/resource.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "mfr/core/plot.hpp"
#include "mfr/core/units.hpp"

namespace {

using namespace mfr;
using namespace mfr::bench;

constexpr Program kProgram{
    .name = "bench_oracle",
    .csv = "oracle.csv",
    .options = " [--budget BYTES] [--rule hybrid|kbuffer|both]",
    .optionsHelp =
        "  --budget BYTES  the frame's budget (default 120MB)\n"
        "  --rule R        the compositing rule(s) the oracle optimises (default both)\n"};

double peakRssMiB() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;  // kilobytes on Linux
}

}  // namespace

int main(int argc, char** argv) {
  std::optional<uint64_t> budgetOption;
  if (!takeBudget(kProgram, argc, argv, budgetOption)) return 2;
  const uint64_t budget = budgetOption.value_or(120ull << 20);
  std::vector<Compositing> rules = {Compositing::Hybrid, Compositing::KBuffer};
  std::vector<char*> rest = {argv[0]};
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--rule") == 0 && i + 1 < argc) {
      const std::string r = argv[++i];
      if (r == "hybrid") {
        rules = {Compositing::Hybrid};
      } else if (r == "kbuffer") {
        rules = {Compositing::KBuffer};
      } else if (r != "both") {
        printError(kProgram, "--rule must be hybrid, kbuffer or both, not '" + r + "'");
        return 2;
      }
    } else {
      rest.push_back(argv[i]);
    }
  }
  const Args args = parseArgs(static_cast<int>(rest.size()), rest.data(), kProgram);
  Csv csv = openCsv(kProgram, args,
                    "scene,width,height,budget,rule,fragments,oracle_ms,frame_ms,solver,gap,"
                    "peak_rss_mib");
  std::printf("bench_oracle: optimal k-buffer oracle, %s, budget %s\n",
              runDescription(args, resolveThreads(args.threads)).c_str(),
              formatBytes(budget).c_str());
  FrameStore store(kProgram);
  Scene* scene = store.load("procedural:hairball");
  if (!scene) return 1;
  auto built = RasterFrame::build(*scene, sceneCamera(*scene),
                                  RasterOptions{args.size, args.size, 16, args.threads});
  if (!built) {
    printError(kProgram, built.error().message);
    return 1;
  }
  Table table({"rule", "fragments", "oracle ms", "frame ms", "solver", "gap", "peak RSS MiB"});
  std::vector<PlotSeries> series;
  bool failed = false;
  for (Compositing rule : rules) {
    Case c;
    c.frame = &built.value();
    c.method = methodPreset("optimal").value();
    c.method.compositing = rule;
    c.options.budgetBytes = budget;
    std::vector<Case> one = {c};
    runInterleaved(one, args.reps);
    const Case& r = one[0];
    if (r.error || !r.stats.oracle) {
      printError(kProgram, std::string(toString(rule)) + ": " + r.error.value_or("no oracle"));
      failed = true;
      continue;
    }
    const OracleReport& o = *r.stats.oracle;
    const double rss = peakRssMiB();
    table.add({toString(rule), num(r.stats.fragmentsGenerated), fixed(r.pass("oracle"), 0),
               fixed(r.totalMs(), 0), o.solver, fixed(o.gap(), 6), fixed(rss, 0)});
    csv.row({"hairball", std::to_string(args.size), std::to_string(args.size),
             std::to_string(budget), toString(rule), std::to_string(r.stats.fragmentsGenerated),
             fixed(r.pass("oracle"), 3), fixed(r.totalMs(), 3), o.solver, fixed(o.gap(), 9),
             fixed(rss, 1)});
    PlotSeries s{std::string(toString(rule)) + " oracle ms per run",
                 {},
                 {},
                 series.empty() ? glm::vec3(0.85f, 0.3f, 0.1f) : glm::vec3(0.1f, 0.45f, 0.8f)};
    const auto it = r.passSamples.find("oracle");
    for (size_t i = 0; it != r.passSamples.end() && i < it->second.size(); ++i) {
      s.x.push_back(static_cast<double>(i + 1));
      s.y.push_back(it->second[i]);
    }
    series.push_back(s);
  }
  table.print();
  std::printf("CSV: %s\n", csv.path().string().c_str());
  PlotOptions po;
  po.title = "optimal k-buffer oracle on procedural:hairball";
  po.xLabel = "run";
  po.yLabel = "ms";
  if (!writePlotPng(kProgram, args.out, "oracle.png", series, po)) failed = true;
  return failed ? 1 : 0;
}

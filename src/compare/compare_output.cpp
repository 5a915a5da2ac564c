// Writing a comparison's folder (see mfr/compare/compare_output.hpp).
#include "mfr/compare/compare_output.hpp"

#include <ctime>
#include <filesystem>
#include <fstream>
#include <system_error>
#include <vector>

#include "mfr/core/atomic_file.hpp"
#include "mfr/core/image.hpp"

namespace mfr {
namespace {

namespace fs = std::filesystem;

// a temporary file renamed into place (core/atomic_file.hpp): never a truncated file
Result<void> writeText(const fs::path& path, const std::string& text) {
  return writeFileAtomically(path.string(), text);
}

}  // namespace

Result<void> prepareOutputFolder(const std::string& out) {
  const fs::path dir(out);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir))
    return makeError(out + ": cannot create the output folder" +
                     (ec ? " (" + ec.message() + ")" : std::string(" (not a directory)")));
  const fs::path probe = dir / ".mfr_compare_write_test";
  if (!std::ofstream(probe)) return makeError(out + ": output folder is not writable");
  fs::remove(probe, ec);
  return {};
}

Result<std::string> writeComparison(const CompareResult& r, const std::string& out,
                                    const std::string& mfrVersion, const ReportInfo& info) {
  const fs::path dir(out);
  const auto png = [&](const std::string& file, const Image8& image) -> Result<void> {
    if (file.empty()) return {};
    return writePng((dir / file).string(), image);
  };
  std::vector<Result<void>> written;
  written.push_back(png(r.groundTruth.imageFile, r.groundTruth.image));
  written.push_back(png(r.depthComplexityFile, r.depthComplexityMap));
  for (const CompareBudget& cb : r.budgets)
    for (const CompareRun& run : cb.runs) {
      if (!run.ok()) continue;
      written.push_back(png(run.imageFile, run.image));
      written.push_back(png(run.flipFile, run.flipMap));
      written.push_back(png(run.kMapFile, run.kMap));
      written.push_back(png(run.importanceFile, run.importanceMap));
    }
  const std::string jsonText = compareToJson(r, mfrVersion).dump(2) + "\n";
  written.push_back(writeText(dir / "results.json", jsonText));
  written.push_back(writeText(dir / "results.csv", compareToCsv(r)));
  written.push_back(writeText(dir / "report.html", compareReportHtml(r, info)));
  for (const Result<void>& w : written)
    if (!w) return w.error();
  return jsonText;
}

std::string utcTimestamp() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buffer[64];
  std::strftime(buffer, sizeof buffer, "%Y-%m-%d %H:%M:%S UTC", &tm);
  return buffer;
}

}  // namespace mfr

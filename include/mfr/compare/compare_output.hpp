// Writing a comparison to disk: the folder `mfr compare --out DIR` produces, shared by the command
// line and the Python module (mfr.compare) so both write byte-identical images, results.json and
// results.csv. The comparison itself is runComparison (compare.hpp); nothing here renders.
#pragma once

#include <string>

#include "mfr/compare/compare.hpp"
#include "mfr/core/result.hpp"

namespace mfr {

/// Creates `dir` (and its parents) if needed and checks that a file can be created in it, so a
/// comparison fails before any rendering rather than after. Errors: "DIR: cannot create the output
/// folder (reason)", "... (not a directory)", "DIR: output folder is not writable".
Result<void> prepareOutputFolder(const std::string& dir);

/// Writes into `dir` (which must exist): every image of `result` under its file name
/// (ground_truth.png, ground_truth_depth_complexity.png, METHOD_BUDGET.png, _flip.png, _kmap.png,
/// _importance.png; failed runs have none), results.json (compareToJson(result, mfrVersion)
/// indented by 2, with a final newline), results.csv (compareToCsv) and report.html
/// (compareReportHtml(result, info)). Returns the results.json text. Every file is attempted; the
/// first error (naming the file) is returned.
Result<std::string> writeComparison(const CompareResult& result, const std::string& dir,
                                    const std::string& mfrVersion, const ReportInfo& info);

/// The current time as "YYYY-MM-DD HH:MM:SS UTC" (ReportInfo::generated).
std::string utcTimestamp();

}  // namespace mfr

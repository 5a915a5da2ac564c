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

/// The folder `mfr compare --out DIR` and mfr.compare write, never a mix of two comparisons (old
/// 64x64 results beside new 256x256 images): the files go to a fresh staging folder beside DIR
/// (".NAME.compare-tmp.PID.N"), which commit() puts in place in one step, swapping it with an
/// older DIR (Linux renameat2 RENAME_EXCHANGE; elsewhere two renames) and removing that one. Until
/// then DIR holds the previous comparison, whole. Concurrent comparisons into one DIR each stage
/// their own folder; the last to commit wins. A staging folder is removed when the OutputFolder
/// goes without commit() (an error); one left by a killed process is removed by the next begin().
class OutputFolder {
 public:
  /// Checks DIR and makes the staging folder. DIR may be absent (its parents are created), empty,
  /// or a previous comparison's (PNG, JSON, CSV and HTML files, frame_NNN folders of them):
  /// anything else is refused, so that no other folder is ever replaced. Errors: "DIR: cannot
  /// create the output folder (reason)", "... (not a directory)", "DIR: holds 'NAME', which a
  /// comparison does not write: not replacing it (choose another folder)", "DIR: output folder is
  /// not writable (reason)".
  static Result<OutputFolder> begin(const std::string& dir);

  OutputFolder(OutputFolder&& other) noexcept;
  OutputFolder& operator=(OutputFolder&&) = delete;
  OutputFolder(const OutputFolder&) = delete;
  ~OutputFolder();

  /// The staging folder: write the comparison here.
  const std::string& staging() const { return staging_; }
  /// Puts the staging folder in place as DIR. Errors name DIR.
  Result<void> commit();

 private:
  OutputFolder(std::string name, std::string destination, std::string staging);
  std::string name_;         // DIR as given (for messages)
  std::string destination_;  // DIR, absolute (symbolic links resolved)
  std::string staging_;      // empty once committed or moved from
};

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

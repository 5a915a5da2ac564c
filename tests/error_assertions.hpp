// Assertions on refusals, shared by the tests of bad input (docs/ROBUSTNESS.md): a library error
// or a CLI run is one bounded line that names the input and says why, never a crash, a hang, a
// second line or a serialised exception.
#pragma once

#include <gtest/gtest.h>

#include <cstddef>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <string>

#include "cli_runner.hpp"
#include "mfr/core/result.hpp"

namespace mfr::test {

inline bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

/// Writes `bytes` to `path` and returns the path as a string.
inline std::string writeFile(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
  return path.string();
}

/// A library message: one line of at most `maxBytes` naming `file`, with every one of `parts`.
inline ::testing::AssertionResult oneLineNaming(const std::string& message, const std::string& file,
                                                std::initializer_list<std::string> parts,
                                                size_t maxBytes = 1500) {
  if (!contains(message, file) || contains(message, "\n") || contains(message, "\r") ||
      message.size() > maxBytes)
    return ::testing::AssertionFailure()
           << "message of " << message.size() << " bytes should be one short line naming " << file
           << ": " << message.substr(0, 300);
  for (const std::string& part : parts)
    if (!contains(message, part))
      return ::testing::AssertionFailure() << "'" << message << "' lacks '" << part << "'";
  return ::testing::AssertionSuccess();
}

/// A failed call of the library whose message is oneLineNaming(file, parts).
template <class T>
::testing::AssertionResult refused(const Result<T>& result, const std::string& file,
                                   std::initializer_list<std::string> parts,
                                   size_t maxBytes = 1500) {
  if (result.ok()) return ::testing::AssertionFailure() << "succeeded, expected a refusal";
  return oneLineNaming(result.error().message, file, parts, maxBytes);
}

/// A process of the CLI that failed cleanly: exit 1, no signal, not timed out, and stderr one
/// "mfr: error:" line (the CLI cuts messages to 1000 characters) with every one of `parts` and
/// no exception text of a library underneath.
inline ::testing::AssertionResult oneErrorLine(int exitCode, bool signaled, bool timedOut,
                                               const std::string& err,
                                               std::initializer_list<std::string> parts) {
  if (timedOut) return ::testing::AssertionFailure() << "timed out (hung): " << err;
  if (signaled || exitCode != 1)
    return ::testing::AssertionFailure() << "exit " << exitCode << ", stderr: " << err;
  if (err.rfind("mfr: error: ", 0) != 0 || err.find('\n') + 1 != err.size() || err.size() > 1100 ||
      contains(err, "json.exception"))
    return ::testing::AssertionFailure() << "not one short 'mfr: error:' line: " << err;
  for (const std::string& part : parts)
    if (!contains(err, part))
      return ::testing::AssertionFailure() << "'" << err << "' lacks '" << part << "'";
  return ::testing::AssertionSuccess();
}

/// oneErrorLine of a runCli / runCliTimed run (a timeout exits 124).
inline ::testing::AssertionResult cleanError(const CliRun& r,
                                             std::initializer_list<std::string> parts) {
  return oneErrorLine(r.exitCode, r.signaled, r.exitCode == 124, r.err, parts);
}

}  // namespace mfr::test

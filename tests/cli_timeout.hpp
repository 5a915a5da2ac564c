// Runs the mfr binary (MFR_CLI_PATH) under `timeout`, optionally from another working folder and
// with a virtual-memory cap (`ulimit -v`): for inputs that could hang (FIFOs) or make mfr allocate
// gigabytes, a test fails instead of hanging or swapping.
#pragma once

#include <sys/wait.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "cli_runner.hpp"
#include "test_paths.hpp"

namespace mfr::test {

struct TimedCliOptions {
  int seconds = 10;                  // `timeout` exits 124 when mfr runs longer
  std::filesystem::path workingDir;  // empty: this process's
  uint64_t virtualMemoryKiB = 0;     // 0: no cap
};

/// Options for a run from `dir`.
inline TimedCliOptions inDir(const std::filesystem::path& dir) {
  TimedCliOptions o;
  o.workingDir = dir;
  return o;
}

/// Options for a run of at most `seconds` within `kib` KiB of address space.
inline TimedCliOptions capped(int seconds, uint64_t kib) {
  TimedCliOptions o;
  o.seconds = seconds;
  o.virtualMemoryKiB = kib;
  return o;
}

inline CliRun runCliTimed(const std::string& args, const std::filesystem::path& scratch,
                          const TimedCliOptions& options = {}) {
  const std::filesystem::path err = scratch / "stderr.txt", out = scratch / "stdout.txt";
  std::string script;
  if (!options.workingDir.empty()) script += "cd '" + options.workingDir.string() + "' && ";
  if (options.virtualMemoryKiB)
    script += "ulimit -v " + std::to_string(options.virtualMemoryKiB) + " && ";
  script += "exec timeout " + std::to_string(options.seconds) + " " + MFR_CLI_PATH + " " + args;
  script += " >'" + out.string() + "' 2>'" + err.string() + "' </dev/null";
  std::string quoted;  // for sh -c '...'
  for (char c : script) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  const int status = std::system(("sh -c '" + quoted + "'").c_str());
  CliRun r;
  r.signaled = WIFSIGNALED(status) || (WIFEXITED(status) && WEXITSTATUS(status) >= 128);
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream e(err), o(out);
  std::stringstream es, os;
  es << e.rdbuf();
  os << o.rdbuf();
  r.err = es.str();
  r.out = os.str();
  return r;
}

}  // namespace mfr::test

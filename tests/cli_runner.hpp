// Runs the mfr binary (MFR_CLI_PATH) as a user would, capturing exit status, stdout and stderr.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include "test_paths.hpp"

namespace mfr::test {

struct CliRun {
  int exitCode = -1;
  bool signaled = false;  // killed by a signal (a crash), or a shell-reported signal exit
  std::string err;
  std::string out;
};

/// A folder of this test process under the system temp dir, created on first use.
inline std::filesystem::path processTempDir(const std::string& tag) {
  std::string name = tag;
  name += '_';
  name += std::to_string(::getpid());
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / name;
  std::filesystem::create_directories(dir);
  return dir;
}

/// The shell command `command` with stdin closed; stdout and stderr go through files in `scratch`.
inline CliRun runShell(const std::string& command, const std::filesystem::path& scratch) {
  const std::filesystem::path err = scratch / "stderr.txt", out = scratch / "stdout.txt";
  std::string cmd = command;
  cmd += " >" + out.string();
  cmd += " 2>" + err.string();
  cmd += " </dev/null";
  const int status = std::system(cmd.c_str());
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

/// `mfr ARGS` with stdin closed; stdout and stderr go through files in `scratch`.
inline CliRun runCli(const std::string& args, const std::filesystem::path& scratch) {
  std::string cmd = MFR_CLI_PATH;
  cmd += " ";
  cmd += args;
  return runShell(cmd, scratch);
}

}  // namespace mfr::test

// A main() for the fuzz targets without libFuzzer: runs LLVMFuzzerTestOneInput once on every file
// named on the command line and on every regular file below every folder named there (sorted, so
// runs are reproducible). Absent paths are skipped (a target may have no stored crashes yet); no
// input at all is an error. With --max-seconds=S an input that takes longer than S seconds fails
// the run (it would be a timeout for the fuzzer too). Built with ASan + UBSan, a sanitizer report
// or a failed FUZZ_CHECK aborts the process, so the run fails naming the input first.
//
//   mfr_fuzz_replay_gltf [--max-seconds=S] fuzz/seeds/gltf fuzz/crashes/gltf
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);
extern "C" __attribute__((weak)) int LLVMFuzzerInitialize(int* argc, char*** argv);

namespace {

namespace fs = std::filesystem;

std::vector<fs::path> inputsBelow(const fs::path& root) {
  std::vector<fs::path> files;
  std::error_code ec;
  if (fs::is_regular_file(root, ec)) return {root};
  if (!fs::is_directory(root, ec)) return {};
  for (auto it = fs::recursive_directory_iterator(root, ec);
       !ec && it != fs::recursive_directory_iterator(); it.increment(ec))
    if (it->is_regular_file(ec) && it->path().filename().string()[0] != '.')
      files.push_back(it->path());
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace

int main(int argc, char** argv) {
  if (LLVMFuzzerInitialize) LLVMFuzzerInitialize(&argc, &argv);
  double maxSeconds = 0.0;
  std::vector<fs::path> inputs;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg.rfind("--max-seconds=", 0) == 0) {
      maxSeconds = std::atof(arg.c_str() + 14);
      continue;
    }
    const std::vector<fs::path> found = inputsBelow(arg);
    std::printf("%s: %zu input(s)%s\n", arg.c_str(), found.size(),
                fs::exists(arg) ? "" : " (absent, skipped)");
    inputs.insert(inputs.end(), found.begin(), found.end());
  }
  if (inputs.empty()) {
    std::fprintf(stderr, "no inputs (usage: %s [--max-seconds=S] FILE|FOLDER...)\n", argv[0]);
    return 1;
  }
  double slowest = 0.0;
  fs::path slowestInput;
  for (const fs::path& input : inputs) {
    std::ifstream in(input, std::ios::binary);
    const std::vector<char> bytes((std::istreambuf_iterator<char>(in)),
                                  std::istreambuf_iterator<char>());
    if (!in.good() && !in.eof()) {
      std::fprintf(stderr, "cannot read %s\n", input.c_str());
      return 1;
    }
    std::fprintf(stderr, "running %s (%zu bytes)\n", input.c_str(), bytes.size());
    const auto start = std::chrono::steady_clock::now();
    LLVMFuzzerTestOneInput(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (seconds > slowest) slowest = seconds, slowestInput = input;
    if (maxSeconds > 0.0 && seconds > maxSeconds) {
      std::fprintf(stderr, "%s took %.2f s (limit %.2f s)\n", input.c_str(), seconds, maxSeconds);
      return 1;
    }
  }
  std::printf("%zu input(s) ran without a finding; slowest %.3f s (%s)\n", inputs.size(), slowest,
              slowestInput.c_str());
  return 0;
}

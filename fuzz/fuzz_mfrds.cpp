// Training sets (.mfrds, include/mfr/learn/dataset.hpp): magic, version, feature count, scene
// names, metadata, sample count against the length, scene indices, finite features and targets in
// [0, 1]; the metadata's declared definitions (checkDatasetDefinitions). A dataset that reads must
// write and read back to the same contents.
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "fuzz_util.hpp"
#include "mfr/learn/dataset.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto& dir = mfr::fuzz::workDir();
  const std::string path = dir.write("data.mfrds", data, size);
  auto dataset = mfr::learn::readDataset(path);
  if (!dataset) {
    mfr::fuzz::checkError(dataset.error(), path);
    return 0;
  }
  auto defined = mfr::learn::checkDatasetDefinitions(dataset.value(), path);
  if (!defined) mfr::fuzz::checkError(defined.error(), path);
  const std::string copy = (dir.path() / "copy.mfrds").string();
  auto written = mfr::learn::writeDataset(copy, dataset.value());
  if (!written) {  // writing checks what reading accepted: it must not refuse it
    mfr::fuzz::checkError(written.error());
    FUZZ_CHECK(false, "a dataset that reads does not write: " + written.error().message);
  }
  auto again = mfr::learn::readDataset(copy);
  FUZZ_CHECK(again.ok(), again.ok() ? "" : again.error().message);
  FUZZ_CHECK(again->fileHash == dataset->fileHash, "written bytes differ from the input");
  FUZZ_CHECK(again->scenes == dataset->scenes && again->metadata == dataset->metadata &&
                 again->samples.size() == dataset->samples.size(),
             "contents differ after write and read");
  for (size_t i = 0; i < again->samples.size(); ++i) {
    const auto &a = again->samples[i], &b = dataset->samples[i];
    FUZZ_CHECK(a.scene == b.scene && a.view == b.view && a.budgetStep == b.budgetStep &&
                   a.pixel == b.pixel && a.target == b.target &&
                   std::memcmp(a.features.data(), b.features.data(), sizeof a.features) == 0,
               "sample " + std::to_string(i) + " differs after write and read");
  }
  return 0;
}

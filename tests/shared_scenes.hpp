// The real scenes of ../shared/scenes (MFR_SCENES_DIR) and the policy for their absence:
//   - the whole folder absent (a checkout without the shared data): the test is skipped, with a
//     message naming the folder;
//   - the folder present but an expected file missing (renamed, moved, deleted): the test FAILS,
//     naming the file, so a renamed scene cannot turn a test into a silent skip.
#pragma once

#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include "test_paths.hpp"

namespace mfr::test {

inline std::filesystem::path sharedScenesRoot() {
  return std::filesystem::path(MFR_SCENES_DIR);
}

inline bool sharedScenesPresent() {
  return std::filesystem::is_directory(sharedScenesRoot());
}

/// Success when `relative` is a file under the scenes folder; a failure naming it otherwise.
inline ::testing::AssertionResult sharedSceneExists(const std::string& relative) {
  const std::filesystem::path file = sharedScenesRoot() / relative;
  if (std::filesystem::is_regular_file(file)) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure()
         << "shared scene missing (renamed or moved?): " << file.string() << " under "
         << sharedScenesRoot().string();
}

}  // namespace mfr::test

/// In a test body: skips the test when the scenes folder is absent, fails it (naming the file)
/// when the folder is there but `relative` is not; otherwise declares `var`, the file's path.
#define MFR_SHARED_SCENE(var, relative)                                                          \
  if (!::mfr::test::sharedScenesPresent())                                                       \
    GTEST_SKIP() << "shared scenes folder absent: " << ::mfr::test::sharedScenesRoot().string(); \
  ASSERT_TRUE(::mfr::test::sharedSceneExists(relative));                                         \
  const std::filesystem::path var = ::mfr::test::sharedScenesRoot() / (relative)

// Where the tests find the CLI, the source tree and the shared real scenes. The values live in a
// file the build generates (test_paths.cpp, cmake/mfr_test_paths.cmake), not in compile
// definitions, so the test objects' command lines name no folder and a second checkout's build
// reuses them from a compiler cache.
#pragma once

#include <string>

namespace mfr::test {
extern const char* const kCliPath;    ///< the mfr binary of this build
extern const char* const kSourceDir;  ///< the checkout
extern const char* const kScenesDir;  ///< ../shared/scenes (MFR_SCENES_DIR)
}  // namespace mfr::test

#define MFR_CLI_PATH std::string(::mfr::test::kCliPath)
#define MFR_SOURCE_DIR std::string(::mfr::test::kSourceDir)
#define MFR_SCENES_DIR std::string(::mfr::test::kScenesDir)

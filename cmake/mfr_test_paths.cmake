# mfr_test_paths(TARGET): a generated source giving TARGET's tests the CLI's path, the checkout and
# the shared scenes (tests/test_paths.hpp declares them).
function(mfr_test_paths target)
  set(out "${CMAKE_CURRENT_BINARY_DIR}/generated/${target}_paths.cpp")
  file(GENERATE OUTPUT "${out}" CONTENT
"#include \"test_paths.hpp\"
namespace mfr::test {
const char* const kCliPath = \"$<TARGET_FILE:mfr_cli>\";
const char* const kSourceDir = \"${CMAKE_CURRENT_SOURCE_DIR}\";
const char* const kScenesDir = \"${MFR_SCENES_DIR}\";
}  // namespace mfr::test
")
  target_sources(${target} PRIVATE "${out}")
  target_include_directories(${target} PRIVATE "${CMAKE_CURRENT_SOURCE_DIR}/tests")
endfunction()

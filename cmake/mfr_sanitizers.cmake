# AddressSanitizer + UndefinedBehaviorSanitizer builds (issue 13), included from CMakeLists.txt.
#
# MFR_ASAN_TESTS (default ON with the tests; any compiler):
#   mfr_asan         a copy of the library built with -fsanitize=address,undefined (like mfr_tsan)
#   mfr_asan_tests   tests/asan/*.cpp against it: the random-configuration sweep
#   mfr_fuzz_replay_TARGET
#                    every fuzz target of fuzz/ (fuzz_TARGET.cpp) linked with a standalone driver
#                    (fuzz/standalone_main.cpp) instead of libFuzzer: ctest FuzzRegression.TARGET
#                    runs it over fuzz/seeds/TARGET and every stored crash input in
#                    fuzz/crashes/TARGET. No fuzzing happens in `make test`.
# MFR_FUZZ (default OFF; clang only, scripts/fuzz.sh configures build-fuzz with it):
#   mfr_fuzzlib      the library with -fsanitize=address,undefined,fuzzer-no-link
#   fuzz_TARGET      the libFuzzer executables, target `mfr_fuzzers` builds them all
#
# The sanitizer runtime options the tests use (mfr_asan_env): leaks are errors, the first UBSan
# report aborts with a stack trace.

if(MFR_BUILD_TESTS)
  option(MFR_ASAN_TESTS "Build the ASan+UBSan tests (mfr_asan_tests, FuzzRegression.*)" ON)
else()
  set(MFR_ASAN_TESTS OFF)
endif()
option(MFR_FUZZ "Build the libFuzzer targets in fuzz/ (requires clang)" OFF)

file(GLOB MFR_FUZZ_SOURCES CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/fuzz_*.cpp)
set(MFR_FUZZ_DIR ${CMAKE_CURRENT_SOURCE_DIR}/fuzz)

# A copy of the library with the given sanitizer flags (compile and link).
function(mfr_sanitized_library name)
  cmake_parse_arguments(ARG "" "" "FLAGS;LINK_FLAGS" ${ARGN})
  add_library(${name} STATIC ${MFR_SOURCES} $<TARGET_OBJECTS:mfr_default_model>)
  target_include_directories(${name} PUBLIC include PRIVATE src ${STB_INCLUDE_DIR})
  target_compile_options(${name} PRIVATE ${MFR_WARNINGS} PUBLIC ${ARG_FLAGS})
  target_link_options(${name} PUBLIC ${ARG_LINK_FLAGS})
  target_link_libraries(${name}
    PUBLIC glm::glm TBB::tbb nlohmann_json::nlohmann_json Eigen3::Eigen
    PRIVATE mfr::stb TinyGLTF::TinyGLTF tinyobjloader::tinyobjloader assimp::assimp)
endfunction()

# Fuzz target sources share fuzz/fuzz_util.hpp and the test data folders.
function(mfr_fuzz_target_settings target)
  target_include_directories(${target} PRIVATE ${MFR_FUZZ_DIR} src)
  target_compile_options(${target} PRIVATE ${MFR_WARNINGS})
endfunction()

set(MFR_ASAN_ENV
  "ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1"
  "UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1"
  "LSAN_OPTIONS=suppressions=${MFR_FUZZ_DIR}/lsan.supp:print_suppressions=0")

if(MFR_ASAN_TESTS)
  # gcc's -fsanitize=undefined leaves out float-cast-overflow (clang's includes it): a float to
  # int conversion out of range is undefined behaviour the rasterizer must never reach.
  set(MFR_ASAN_FLAGS -fsanitize=address,undefined -fno-sanitize-recover=all -g1 -O1
                     -fno-omit-frame-pointer)
  if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
    list(APPEND MFR_ASAN_FLAGS -fsanitize=float-cast-overflow)
  endif()
  mfr_sanitized_library(mfr_asan FLAGS ${MFR_ASAN_FLAGS}
                        LINK_FLAGS -fsanitize=address,undefined)

  file(GLOB MFR_ASAN_TEST_SOURCES CONFIGURE_DEPENDS tests/asan/*.cpp)
  add_executable(mfr_asan_tests ${MFR_ASAN_TEST_SOURCES})
  target_compile_options(mfr_asan_tests PRIVATE ${MFR_WARNINGS})
  target_include_directories(mfr_asan_tests PRIVATE tests src)
  target_link_libraries(mfr_asan_tests PRIVATE mfr_asan GTest::gtest GTest::gtest_main)
  # MFR_MAX_WORKERS=8: a run asking for 8 threads gets 8 workers on a 2-core machine
  gtest_discover_tests(mfr_asan_tests DISCOVERY_MODE PRE_TEST DISCOVERY_TIMEOUT 60
    PROPERTIES TIMEOUT 900 ENVIRONMENT "${MFR_ASAN_ENV};MFR_MAX_WORKERS=8")

  # The fuzz targets over their seeds and stored crash inputs (regression), gcc + the driver.
  add_library(mfr_fuzz_driver OBJECT ${MFR_FUZZ_DIR}/standalone_main.cpp)
  target_compile_options(mfr_fuzz_driver PRIVATE ${MFR_WARNINGS} ${MFR_ASAN_FLAGS})
  foreach(src ${MFR_FUZZ_SOURCES})
    get_filename_component(name ${src} NAME_WE)
    string(REGEX REPLACE "^fuzz_" "" target ${name})
    add_executable(mfr_fuzz_replay_${target} ${src} $<TARGET_OBJECTS:mfr_fuzz_driver>)
    mfr_fuzz_target_settings(mfr_fuzz_replay_${target})
    target_link_libraries(mfr_fuzz_replay_${target} PRIVATE mfr_asan)
    # extra inputs from the tests (absent folders are skipped by the driver)
    set(extra)
    if(target STREQUAL "png")
      set(extra ${CMAKE_CURRENT_SOURCE_DIR}/tests/data/flip)
    elseif(target STREQUAL "mfrnn")
      set(extra ${CMAKE_CURRENT_SOURCE_DIR}/models)
    endif()
    add_test(NAME FuzzRegression.${target}
      COMMAND mfr_fuzz_replay_${target} --max-seconds=20 ${MFR_FUZZ_DIR}/seeds/${target}
              ${MFR_FUZZ_DIR}/crashes/${target} ${extra})
    set_tests_properties(FuzzRegression.${target} PROPERTIES TIMEOUT 600
      ENVIRONMENT "${MFR_ASAN_ENV}")
  endforeach()
endif()

if(MFR_FUZZ)
  if(NOT CMAKE_CXX_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "MFR_FUZZ=ON needs clang (libFuzzer): configure with "
                        "-DCMAKE_CXX_COMPILER=clang++-14 (scripts/fuzz.sh does)")
  endif()
  set(MFR_FUZZ_FLAGS -fsanitize=address,undefined -fno-sanitize-recover=all -g -O1
                     -fno-omit-frame-pointer)
  mfr_sanitized_library(mfr_fuzzlib FLAGS ${MFR_FUZZ_FLAGS} -fsanitize=fuzzer-no-link
                        LINK_FLAGS -fsanitize=address,undefined)
  add_custom_target(mfr_fuzzers)
  foreach(src ${MFR_FUZZ_SOURCES})
    get_filename_component(name ${src} NAME_WE)
    add_executable(${name} ${src})
    mfr_fuzz_target_settings(${name})
    target_compile_options(${name} PRIVATE -fsanitize=fuzzer)
    target_link_options(${name} PRIVATE -fsanitize=fuzzer)
    target_link_libraries(${name} PRIVATE mfr_fuzzlib)
    add_dependencies(mfr_fuzzers ${name})
  endforeach()
endif()

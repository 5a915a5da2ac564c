# --- OpenGL 4.5 engine (issue 10) ---
# libmfr_gl: headless GL 4.5 core context through EGL + libepoxy, the shaders of shaders/ embedded
# at build time (cmake/mfr_shaders.cmake), and the GL engine (src/gl/). Kept out of libmfr so the
# CPU library has no GL dependency; tests/gl/ is its own test executable (mfr_gl_tests).
find_package(PkgConfig REQUIRED)
pkg_check_modules(EPOXY REQUIRED IMPORTED_TARGET epoxy)
find_package(OpenGL REQUIRED COMPONENTS EGL)

file(GLOB MFR_SHADER_FILES CONFIGURE_DEPENDS
     ${CMAKE_CURRENT_SOURCE_DIR}/shaders/*.vert ${CMAKE_CURRENT_SOURCE_DIR}/shaders/*.geom
     ${CMAKE_CURRENT_SOURCE_DIR}/shaders/*.frag ${CMAKE_CURRENT_SOURCE_DIR}/shaders/*.comp
     ${CMAKE_CURRENT_SOURCE_DIR}/shaders/*.glsl)
list(SORT MFR_SHADER_FILES)
set(MFR_SHADER_INPUTS ${MFR_SHADER_FILES}
    ${CMAKE_CURRENT_SOURCE_DIR}/include/mfr/gl/shared_layout.h
    ${CMAKE_CURRENT_SOURCE_DIR}/include/mfr/method/method_math.h)
string(REPLACE ";" "|" MFR_SHADER_ARG "${MFR_SHADER_INPUTS}")
set(MFR_SHADERS_CPP "${CMAKE_CURRENT_BINARY_DIR}/generated/gl_shaders.cpp")
add_custom_command(OUTPUT "${MFR_SHADERS_CPP}"
  COMMAND ${CMAKE_COMMAND} "-DFILES=${MFR_SHADER_ARG}" -DOUT=${MFR_SHADERS_CPP}
          -P "${CMAKE_CURRENT_SOURCE_DIR}/cmake/mfr_shaders.cmake"
  DEPENDS ${MFR_SHADER_INPUTS} "${CMAKE_CURRENT_SOURCE_DIR}/cmake/mfr_shaders.cmake"
  COMMENT "Embedding shaders/" VERBATIM)

file(GLOB MFR_GL_SOURCES CONFIGURE_DEPENDS src/gl/*.cpp)
add_library(mfr_gl STATIC ${MFR_GL_SOURCES} "${MFR_SHADERS_CPP}")
target_include_directories(mfr_gl PRIVATE src)
target_compile_options(mfr_gl PRIVATE ${MFR_WARNINGS})
target_link_libraries(mfr_gl PUBLIC mfr PRIVATE PkgConfig::EPOXY OpenGL::EGL)
set_target_properties(mfr_gl PROPERTIES POSITION_INDEPENDENT_CODE ON)
add_library(mfr::gl ALIAS mfr_gl)

if(MFR_BUILD_TESTS)
  file(GLOB MFR_GL_TEST_SOURCES CONFIGURE_DEPENDS tests/gl/*.cpp)
  add_executable(mfr_gl_tests ${MFR_GL_TEST_SOURCES})
  target_compile_options(mfr_gl_tests PRIVATE ${MFR_WARNINGS})
  target_include_directories(mfr_gl_tests PRIVATE src)  # gl/shader_sources.hpp
  target_link_libraries(mfr_gl_tests PRIVATE mfr_gl GTest::gtest GTest::gtest_main)
  mfr_test_paths(mfr_gl_tests)
  add_dependencies(mfr_gl_tests mfr_cli)
  # discovery at test time: a machine without a GL 4.5 context skips (or, with CI=true, fails) the
  # tests instead of failing the build
  gtest_discover_tests(mfr_gl_tests DISCOVERY_MODE PRE_TEST DISCOVERY_TIMEOUT 60
    PROPERTIES TIMEOUT 600)
endif()

# the command line runs either engine (--engine gl registers it at start-up)
target_link_libraries(mfr_cli PRIVATE mfr_gl)
target_compile_definitions(mfr_cli PRIVATE MFR_HAS_GL=1)

# bench_engines: the same frames on the CPU and the GL engine, in one run
if(MFR_BUILD_BENCH)
  add_executable(bench_engines bench/bench_engines.cpp)
  target_compile_options(bench_engines PRIVATE ${MFR_WARNINGS})
  target_compile_definitions(bench_engines PRIVATE MFR_SCENES_DIR="${MFR_SCENES_DIR}")
  target_link_libraries(bench_engines PRIVATE mfr_gl)
  # the plain GL k-buffer of ../shared/anchors/gl-kbuffer (the yardstick for GL speed on a driver),
  # built from that folder where it exists; bench_engines runs it in the same run. Not mfr's code:
  # compiled as its README says, without mfr's warning flags.
  set(MFR_ANCHOR_KBUFFER "${CMAKE_CURRENT_SOURCE_DIR}/../shared/anchors/gl-kbuffer/kbuf_test.cpp")
  if(EXISTS "${MFR_ANCHOR_KBUFFER}")
    add_executable(gl_kbuffer_anchor "${MFR_ANCHOR_KBUFFER}")
    set_target_properties(gl_kbuffer_anchor PROPERTIES CXX_STANDARD 17 COMPILE_WARNING_AS_ERROR OFF)
    target_compile_options(gl_kbuffer_anchor PRIVATE -w)
    target_link_libraries(gl_kbuffer_anchor PRIVATE PkgConfig::EPOXY)
    target_compile_definitions(bench_engines PRIVATE
                               MFR_ANCHOR_KBUFFER_PATH="$<TARGET_FILE:gl_kbuffer_anchor>")
    add_dependencies(bench_engines gl_kbuffer_anchor)
  endif()
endif()

# gpu_check: every preset on GL native against the CPU engine, one CSV (bench/gpu_check.cpp); what
# scripts/gpu-check.sh runs on a machine with a GPU. Built with the GL engine, benchmarks or not.
add_executable(gpu_check bench/gpu_check.cpp)
target_compile_options(gpu_check PRIVATE ${MFR_WARNINGS})
target_compile_definitions(gpu_check PRIVATE MFR_SCENES_DIR="${MFR_SCENES_DIR}")
target_link_libraries(gpu_check PRIVATE mfr_gl)
if(MFR_BUILD_TESTS)
  # the script itself, --quick at 64x64 on the binaries as built (llvmpipe where there is no GPU):
  # its CSV's header and every row agreeing; skipped (77) without a GL 4.5 context, failed under CI
  add_test(NAME GpuCheckScriptQuick
    COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/tests/gpu_check_test.sh ${CMAKE_CURRENT_SOURCE_DIR}
            $<TARGET_FILE_DIR:gpu_check>)
  set_tests_properties(GpuCheckScriptQuick PROPERTIES SKIP_RETURN_CODE 77 TIMEOUT 300)
endif()

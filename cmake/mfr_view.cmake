# --- mfr view (issue 16) ---
# The interactive viewer, part of the mfr command line when the GL engine is built: GLFW 3 and
# Dear ImGui from Debian (libglfw3-dev, libimgui-dev). Debian ships ImGui's GLFW and OpenGL 3
# backends as sources in the package's examples folder; they are compiled from there (not vendored).
find_package(PkgConfig REQUIRED)
find_package(glfw3 3.3 QUIET)
if(NOT TARGET glfw)
  pkg_check_modules(GLFW REQUIRED IMPORTED_TARGET glfw3)
  add_library(glfw ALIAS PkgConfig::GLFW)
endif()
pkg_check_modules(IMGUI REQUIRED IMPORTED_TARGET imgui)
find_package(OpenGL REQUIRED COMPONENTS OpenGL EGL)
set(MFR_IMGUI_BACKENDS_DIR "/usr/share/doc/libimgui-dev/examples/backends"
    CACHE PATH "Dear ImGui's backend sources (Debian: libimgui-dev's examples/backends)")
foreach(backend imgui_impl_glfw.cpp imgui_impl_opengl3.cpp)
  if(NOT EXISTS "${MFR_IMGUI_BACKENDS_DIR}/${backend}")
    message(FATAL_ERROR "mfr view: ${MFR_IMGUI_BACKENDS_DIR}/${backend} not found (libimgui-dev; "
                        "or -DMFR_BUILD_GL=OFF)")
  endif()
endforeach()
add_library(mfr_imgui_backends STATIC "${MFR_IMGUI_BACKENDS_DIR}/imgui_impl_glfw.cpp"
                                      "${MFR_IMGUI_BACKENDS_DIR}/imgui_impl_opengl3.cpp")
target_include_directories(mfr_imgui_backends PUBLIC /usr/include/imgui/backends)
target_link_libraries(mfr_imgui_backends PUBLIC PkgConfig::IMGUI glfw ${CMAKE_DL_LIBS})

file(GLOB MFR_VIEW_SOURCES CONFIGURE_DEPENDS apps/mfr/view/*.cpp)
target_sources(mfr_cli PRIVATE ${MFR_VIEW_SOURCES})
target_link_libraries(mfr_cli PRIVATE mfr_imgui_backends OpenGL::OpenGL OpenGL::EGL)
target_compile_definitions(mfr_cli PRIVATE MFR_HAS_VIEW=1)

# tests/view_test.sh: scripted sessions under Xvfb (xvfb-run); exits 77 (skipped) without Xvfb
# unless CI=true
if(MFR_BUILD_TESTS)
  add_test(NAME ViewerUnderXvfb
    COMMAND bash ${CMAKE_CURRENT_SOURCE_DIR}/tests/view_test.sh $<TARGET_FILE:mfr_cli>)
  set_tests_properties(ViewerUnderXvfb PROPERTIES SKIP_RETURN_CODE 77 TIMEOUT 400)
endif()

# Installable package: `cmake --install BUILD --prefix P` puts
#   P/include/mfr/**.hpp, **.h                 public headers (src/ stays private)
#   P/lib/libmfr.a                             the library (the built-in dkb model is compiled in)
#   P/bin/mfr                                  the command line
#   P/lib/cmake/mfr/mfr{Config,ConfigVersion,Targets}.cmake   find_package(mfr) -> mfr::mfr
#   P/lib/pkgconfig/mfr.pc                     pkg-config --cflags --libs mfr
#   P/share/mfr/models/dkb-default.mfrnn       the shipped model as a file (to fine-tune it; the
#                                              library does not read it)
# (lib may be lib64 or lib/<multiarch>: GNUInstallDirs' CMAKE_INSTALL_LIBDIR.)
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(MFR_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/mfr"
    CACHE STRING "Where mfrConfig.cmake is installed (relative to the prefix)")

install(TARGETS mfr EXPORT mfrTargets
  ARCHIVE DESTINATION "${CMAKE_INSTALL_LIBDIR}"
  INCLUDES DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}")
install(TARGETS mfr_cli RUNTIME DESTINATION "${CMAKE_INSTALL_BINDIR}")
install(DIRECTORY "${PROJECT_SOURCE_DIR}/include/mfr" DESTINATION "${CMAKE_INSTALL_INCLUDEDIR}"
  FILES_MATCHING PATTERN "*.hpp" PATTERN "*.h")
install(EXPORT mfrTargets NAMESPACE mfr:: DESTINATION "${MFR_INSTALL_CMAKEDIR}")

configure_package_config_file("${PROJECT_SOURCE_DIR}/cmake/mfrConfig.cmake.in"
  "${PROJECT_BINARY_DIR}/package/mfrConfig.cmake"
  INSTALL_DESTINATION "${MFR_INSTALL_CMAKEDIR}")
# 0.x: a minor version may break the API
write_basic_package_version_file("${PROJECT_BINARY_DIR}/package/mfrConfigVersion.cmake"
  VERSION "${PROJECT_VERSION}" COMPATIBILITY SameMinorVersion)
install(FILES "${PROJECT_BINARY_DIR}/package/mfrConfig.cmake"
              "${PROJECT_BINARY_DIR}/package/mfrConfigVersion.cmake"
        DESTINATION "${MFR_INSTALL_CMAKEDIR}")

# mfr.pc finds the prefix from its own folder, so an installed tree can be moved
file(RELATIVE_PATH MFR_PC_PREFIX_FROM_PCDIR "/prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/prefix")
configure_file("${PROJECT_SOURCE_DIR}/cmake/mfr.pc.in" "${PROJECT_BINARY_DIR}/package/mfr.pc" @ONLY)
install(FILES "${PROJECT_BINARY_DIR}/package/mfr.pc"
        DESTINATION "${CMAKE_INSTALL_LIBDIR}/pkgconfig")

if(EXISTS "${MFR_DEFAULT_MODEL}")
  install(FILES "${MFR_DEFAULT_MODEL}" DESTINATION "${CMAKE_INSTALL_DATADIR}/mfr/models")
endif()

# The Python module `mfr` (python/): a pybind11 extension mfr/_mfr*.so plus python/mfr/*.py, built
# into BUILD/python/mfr so that `PYTHONPATH=BUILD/python python3 -c "import mfr"` works after the
# build, and installed into P/${MFR_PYTHON_INSTALL_DIR}/mfr (default lib/pythonX.Y/site-packages).
#
# The interpreter: Python3_EXECUTABLE when given, else the first `python3` on the PATH that can
# import numpy, else /usr/bin/python3 (Debian's, where python3-numpy, python3-pybind11 and
# python3-pytest install). The module is built for that interpreter and the tests run with it.

if(NOT Python3_EXECUTABLE)
  find_program(MFR_PATH_PYTHON3 NAMES python3 NO_CACHE)
  set(_mfr_python_candidates ${MFR_PATH_PYTHON3} /usr/bin/python3)
  foreach(candidate IN LISTS _mfr_python_candidates)
    if(EXISTS "${candidate}")
      execute_process(COMMAND "${candidate}" -c "import numpy"
                      RESULT_VARIABLE _mfr_no_numpy OUTPUT_QUIET ERROR_QUIET)
      if(_mfr_no_numpy EQUAL 0)
        set(Python3_EXECUTABLE "${candidate}" CACHE FILEPATH "Python interpreter of the mfr module")
        break()
      endif()
    endif()
  endforeach()
  if(NOT Python3_EXECUTABLE)
    message(FATAL_ERROR "MFR_BUILD_PYTHON: no python3 with numpy found (run scripts/install-deps.sh "
                        "for python3-numpy, or pass -DPython3_EXECUTABLE=..., or -DMFR_BUILD_PYTHON=OFF)")
  endif()
endif()
find_package(Python3 3.8 REQUIRED COMPONENTS Interpreter Development.Module)
find_package(pybind11 2.6 CONFIG)
if(NOT pybind11_FOUND)
  # Debian's python3-pybind11 knows where its CMake files are
  execute_process(COMMAND "${Python3_EXECUTABLE}" -m pybind11 --cmakedir
                  OUTPUT_VARIABLE _mfr_pybind11_dir OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  find_package(pybind11 2.6 CONFIG REQUIRED HINTS "${_mfr_pybind11_dir}")
endif()
message(STATUS "mfr Python module: ${Python3_EXECUTABLE} (${Python3_VERSION}), pybind11 ${pybind11_VERSION}")

set(MFR_PYTHON_INSTALL_DIR
    "${CMAKE_INSTALL_LIBDIR}/python${Python3_VERSION_MAJOR}.${Python3_VERSION_MINOR}/site-packages"
    CACHE STRING "Where the mfr Python package is installed (relative to the prefix)")
set(MFR_PYTHON_BUILD_DIR "${PROJECT_BINARY_DIR}/python/mfr")

file(GLOB MFR_PYTHON_SOURCES CONFIGURE_DEPENDS "${PROJECT_SOURCE_DIR}/python/src/*.cpp")
# NO_EXTRAS: no LTO (libmfr.a is not LTO-built; a 2-core link stays short)
pybind11_add_module(mfr_python MODULE NO_EXTRAS ${MFR_PYTHON_SOURCES})
target_link_libraries(mfr_python PRIVATE mfr)
if(TARGET mfr_gl)  # engine="gl" (the GL engine registers itself when the module loads)
  target_link_libraries(mfr_python PRIVATE mfr_gl)
  target_compile_definitions(mfr_python PRIVATE MFR_HAS_GL=1)
endif()
target_compile_options(mfr_python PRIVATE ${MFR_WARNINGS})
target_compile_definitions(mfr_python PRIVATE MFR_VERSION="${PROJECT_VERSION}")
# the static library's symbols stay inside the module
target_link_options(mfr_python PRIVATE "LINKER:--exclude-libs,ALL")
set_target_properties(mfr_python PROPERTIES
  OUTPUT_NAME _mfr
  LIBRARY_OUTPUT_DIRECTORY "${MFR_PYTHON_BUILD_DIR}")

# the pure-Python part, copied next to the extension (re-copied when it changes)
file(GLOB MFR_PYTHON_PACKAGE_FILES CONFIGURE_DEPENDS "${PROJECT_SOURCE_DIR}/python/mfr/*.py")
foreach(file IN LISTS MFR_PYTHON_PACKAGE_FILES)
  get_filename_component(name "${file}" NAME)
  configure_file("${file}" "${MFR_PYTHON_BUILD_DIR}/${name}" COPYONLY)
endforeach()

# which interpreter the extension is for: `import mfr` under another says so (python/mfr)
set(MFR_PYTHON_BUILT_FOR "${MFR_PYTHON_BUILD_DIR}/_built_for.py")
file(WRITE "${MFR_PYTHON_BUILT_FOR}"
     "# written by cmake/mfr_python.cmake: the Python the extension module _mfr was built for\n"
     "INTERPRETER = \"${Python3_EXECUTABLE}\"\n"
     "VERSION = \"${Python3_VERSION_MAJOR}.${Python3_VERSION_MINOR}\"\n")

install(TARGETS mfr_python LIBRARY DESTINATION "${MFR_PYTHON_INSTALL_DIR}/mfr")
install(FILES ${MFR_PYTHON_PACKAGE_FILES} "${MFR_PYTHON_BUILT_FOR}"
        DESTINATION "${MFR_PYTHON_INSTALL_DIR}/mfr")

# libdrift as a product: the shared library, its public headers, an exported drift::drift
# target (find_package(drift)), drift.pc, and the drift CLI. docs/library.md says how to use
# them and the API stability rule.
#
# libdrift.so is the static library's objects (built position-independent) linked whole, so
# everything added to `drift` (sources, private dependencies) reaches it without an edit here.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

# DRIFT_VERSION and friends (include/drift/version.h.in -> generated/include/drift/version.h).
configure_file(${CMAKE_CURRENT_SOURCE_DIR}/include/drift/version.h.in
  ${CMAKE_BINARY_DIR}/generated/include/drift/version.h @ONLY)

# A fuzzing build (DRIFT_BUILD_FUZZERS, libFuzzer's instrumentation in every object) makes no
# product: no shared library, nothing to install.
if(DRIFT_BUILD_FUZZERS)
  return()
endif()

# A target needs a source of its own: an empty one.
file(CONFIGURE OUTPUT ${CMAKE_BINARY_DIR}/generated/drift_shared.c
  CONTENT "// libdrift.so: the objects of libdrift.a (cmake/drift_install.cmake)\ntypedef int drift_shared_unit;\n")
add_library(drift_shared SHARED ${CMAKE_BINARY_DIR}/generated/drift_shared.c)
add_library(drift::drift ALIAS drift_shared)
target_link_libraries(drift_shared PRIVATE "$<LINK_LIBRARY:WHOLE_ARCHIVE,drift>" PUBLIC Threads::Threads m)
target_include_directories(drift_shared INTERFACE
  $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
  $<BUILD_INTERFACE:${CMAKE_BINARY_DIR}/generated/include>
  $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
# Before 1.0 an API may change at each minor version, so the soname carries MAJOR.MINOR.
set_target_properties(drift_shared PROPERTIES OUTPUT_NAME drift EXPORT_NAME drift LINKER_LANGUAGE CXX
  VERSION ${PROJECT_VERSION} SOVERSION ${PROJECT_VERSION_MAJOR}.${PROJECT_VERSION_MINOR})
# A library built with sanitizers needs their runtimes first in the program that links it.
if(DRIFT_SANITIZE)
  target_link_options(drift_shared INTERFACE -fsanitize=${DRIFT_SANITIZE})
  set(DRIFT_PC_SANITIZE " -fsanitize=${DRIFT_SANITIZE}")
endif()

install(TARGETS drift_shared EXPORT driftTargets
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(TARGETS drift_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/include/drift DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
  FILES_MATCHING PATTERN "*.h")
install(FILES ${CMAKE_BINARY_DIR}/generated/include/drift/version.h
  DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/drift)
install(EXPORT driftTargets NAMESPACE drift:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/drift)
configure_package_config_file(${CMAKE_CURRENT_SOURCE_DIR}/cmake/driftConfig.cmake.in
  ${CMAKE_BINARY_DIR}/generated/driftConfig.cmake
  INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/drift)
write_basic_package_version_file(${CMAKE_BINARY_DIR}/generated/driftConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_BINARY_DIR}/generated/driftConfig.cmake
  ${CMAKE_BINARY_DIR}/generated/driftConfigVersion.cmake
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/drift)
configure_file(${CMAKE_CURRENT_SOURCE_DIR}/cmake/drift.pc.in ${CMAKE_BINARY_DIR}/generated/drift.pc @ONLY)
install(FILES ${CMAKE_BINARY_DIR}/generated/drift.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
# The Python module (ctypes over libdrift.so, python/drift): PREFIX/lib/drift/python, for
# PYTHONPATH (docs/python.md).
install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/python/drift
  DESTINATION ${CMAKE_INSTALL_LIBDIR}/drift/python FILES_MATCHING PATTERN "*.py")

# SPDX-License-Identifier: MIT
# Copyright (c) 2026 The Scree authors
# Install rules and the exported CMake package (included OPTIONAL at the end of the root CMakeLists.txt).
#
# Consumers write
#     find_package(Scree 0.1 CONFIG REQUIRED)
#     target_link_libraries(app PRIVATE Scree::scree)
# against an install prefix (CMAKE_PREFIX_PATH=<prefix>) or a build tree (Scree_DIR=<build dir>).
#
# Exported targets (export set ScreeTargets, namespace Scree::):
#   Scree::scree          umbrella INTERFACE target (all modules, <scree/scree.h>)
#   Scree::core / collide / solver / model   the module libraries (static by default)
#   Scree::scree_options  the project's own warning/sanitizer flags; consumers do not get it through
#                         Scree::scree (modules link it PRIVATE through $<BUILD_INTERFACE:...>).
# Static module libraries carry their private dependencies as $<LINK_ONLY:...> (CCD::CCD,
# SuiteSparse::CHOLMOD, PNG::PNG); ScreeConfig.cmake finds them with the find modules installed beside it
# (PNG with CMake's own FindPNG).
include(CMakePackageConfigHelpers)

set(SCREE_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/Scree" CACHE STRING
    "Install directory of ScreeConfig.cmake, relative to the prefix")
mark_as_advanced(SCREE_INSTALL_CMAKEDIR)

set(_scree_modules scree_core scree_collide scree_solver scree_model scree_io)
set_target_properties(scree PROPERTIES EXPORT_NAME scree)

install(TARGETS ${_scree_modules} scree
  EXPORT ScreeTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
# (Include directories come from each target's $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>.)
# (scree_options is installed into the same export set by the root CMakeLists.txt.)

# Public headers: every module's include/ plus the umbrella include/ merge into one tree. OPTIONAL: a module
# may not have public headers yet (model/).
foreach(_dir core/include collide/include solver/include model/include model/io/include include)
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${_dir}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR} OPTIONAL
          FILES_MATCHING PATTERN "*.h" PATTERN "*.hpp")
endforeach()

# The generated version header (core/CMakeLists.txt, cmake/version_number.h.in).
install(FILES ${PROJECT_BINARY_DIR}/generated/include/scree/version_number.h
        DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/scree)

# What the package config must re-find for consumers.
get_target_property(_scree_collide_type scree_collide TYPE)
if(_scree_collide_type STREQUAL "STATIC_LIBRARY")
  set(SCREE_PACKAGE_STATIC ON)
else()
  set(SCREE_PACKAGE_STATIC OFF)
endif()
set(SCREE_PACKAGE_WITH_SUITESPARSE ${SCREE_WITH_SUITESPARSE})
set(SCREE_PACKAGE_WITH_OPENMP ${SCREE_WITH_OPENMP})
set(SCREE_PACKAGE_ENABLE_ASSERTS ${SCREE_ENABLE_ASSERTS})
set(SCREE_PACKAGE_SANITIZE ${SCREE_SANITIZE})

# A sanitized build's static libraries reference the ASan/UBSan runtimes: their consumers must link with
# -fsanitize too (link option only; no compile flags or warnings are passed on). The build tree gets the same
# through $<LINK_ONLY:Scree::scree_options>. Release packages are unaffected.
if(SCREE_SANITIZE)
  target_link_options(scree_core INTERFACE $<INSTALL_INTERFACE:-fsanitize=address,undefined>)
endif()

set(_scree_find_modules ${PROJECT_SOURCE_DIR}/cmake/FindCCD.cmake ${PROJECT_SOURCE_DIR}/cmake/FindCHOLMOD.cmake)

# ---- install tree ---------------------------------------------------------------------------------------------
install(EXPORT ScreeTargets
  NAMESPACE Scree::
  FILE ScreeTargets.cmake
  DESTINATION ${SCREE_INSTALL_CMAKEDIR})

configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/ScreeConfig.cmake.in
  ${PROJECT_BINARY_DIR}/cmake/install/ScreeConfig.cmake
  INSTALL_DESTINATION ${SCREE_INSTALL_CMAKEDIR})
# 0.x: minor versions may break the API, so only the same major.minor is compatible.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/ScreeConfigVersion.cmake
  VERSION ${PROJECT_VERSION}
  COMPATIBILITY SameMinorVersion)

install(FILES
  ${PROJECT_BINARY_DIR}/cmake/install/ScreeConfig.cmake
  ${PROJECT_BINARY_DIR}/ScreeConfigVersion.cmake
  ${_scree_find_modules}
  DESTINATION ${SCREE_INSTALL_CMAKEDIR})

# ---- build tree: find_package(Scree) with Scree_DIR=<build dir> -------------------------------------------------
export(EXPORT ScreeTargets
  NAMESPACE Scree::
  FILE ${PROJECT_BINARY_DIR}/ScreeTargets.cmake)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/ScreeConfig.cmake.in
  ${PROJECT_BINARY_DIR}/ScreeConfig.cmake
  INSTALL_DESTINATION ${PROJECT_BINARY_DIR}
  INSTALL_PREFIX ${PROJECT_BINARY_DIR})
foreach(_f IN LISTS _scree_find_modules)
  configure_file(${_f} ${PROJECT_BINARY_DIR} COPYONLY)
endforeach()

# Licences, notices and the Debian package (CPack): cmake/ScreePackaging.cmake.
include(${PROJECT_SOURCE_DIR}/cmake/ScreePackaging.cmake)

unset(_scree_modules)
unset(_scree_collide_type)
unset(_scree_find_modules)

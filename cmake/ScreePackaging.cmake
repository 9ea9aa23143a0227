# SPDX-License-Identifier: MIT
# Copyright (c) 2026 The Scree authors
# Licences, notices and the Debian package libscree-dev (CPack), included by cmake/ScreeInstall.cmake.
#
#   cpack --config build/CPackConfig.cmake -B <dir>     ->  <dir>/libscree-dev_<version>_<arch>.deb
#
# The package holds what `cmake --install` installs, under /usr: the static module libraries, the headers, the
# CMake package files (lib/cmake/Scree), the `scree` program (when the examples are built) and
# share/doc/libscree-dev (copyright, THIRD-PARTY.md, CHANGELOG.md, three.js's LICENSE). Its version is the
# project version (the same one getVersionString() returns; scripts/package-test.sh checks the three agree).
#
# Depends, and why (a consumer links the static libraries, so it needs every private dependency's -dev
# package, exactly what ScreeConfig.cmake find_dependency()s):
#   libeigen3-dev       Eigen types in every public header (find_dependency(Eigen3 3.3))
#   libccd-dev          Scree::collide's narrowphase (FindCCD.cmake, installed beside ScreeConfig.cmake)
#   libpng-dev          Scree::model's PNG material maps (CMake's FindPNG)
#   zlib1g-dev          Scree::io's deflated recordings (CMake's FindZLIB)
#   libsuitesparse-dev  Scree::solver's DIRECT solver (FindCHOLMOD.cmake); only when SCREE_WITH_SUITESPARSE=ON
# OpenMP needs no package of its own: GCC's -fopenmp and libgomp come with g++ (Recommends). dpkg-shlibdeps adds
# the versioned run-time libraries of the `scree` program (libcholmod3, libccd2, libpng16-16, zlib1g, libgomp1,
# libstdc++6, libc6, ...). scripts/package-test.sh checks that every library and header directory a consumer's
# compile and link lines use belongs to a package this list reaches (with g++), and that apt resolves the list
# on an empty system.

# Doc files: installed by `cmake --install` too (share/doc/libscree-dev under any prefix).
set(SCREE_INSTALL_DOCDIR "${CMAKE_INSTALL_DATAROOTDIR}/doc/libscree-dev" CACHE STRING
    "Install directory of the licence and notice files, relative to the prefix")
mark_as_advanced(SCREE_INSTALL_DOCDIR)
install(FILES ${PROJECT_SOURCE_DIR}/cmake/debian/copyright ${PROJECT_SOURCE_DIR}/LICENSE
              ${PROJECT_SOURCE_DIR}/THIRD-PARTY.md ${PROJECT_SOURCE_DIR}/CHANGELOG.md
        DESTINATION ${SCREE_INSTALL_DOCDIR})
if(TARGET scree_viewer_page)
  # three.js is inlined into Scree::io and the scree program: ship its MIT licence text with them.
  install(FILES ${PROJECT_BINARY_DIR}/model/io/viewer/npm/node_modules/three/LICENSE
          DESTINATION ${SCREE_INSTALL_DOCDIR} RENAME three.js-LICENSE)
endif()

set(SCREE_PACKAGE_MAINTAINER "The Scree authors <scree@localhost>" CACHE STRING
    "Maintainer field of the Debian package (set a real address when publishing it)")
mark_as_advanced(SCREE_PACKAGE_MAINTAINER)

set(_scree_deb_depends "libeigen3-dev (>= 3.3), libccd-dev, libpng-dev, zlib1g-dev")
if(SCREE_WITH_SUITESPARSE)
  string(APPEND _scree_deb_depends ", libsuitesparse-dev")
endif()

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME libscree-dev)
set(CPACK_PACKAGE_VENDOR "The Scree authors")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_CONTACT ${SCREE_PACKAGE_MAINTAINER})
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "C++20 physics SDK for earthmoving, off-road vehicles and grasping")
set(CPACK_RESOURCE_FILE_LICENSE ${PROJECT_SOURCE_DIR}/LICENSE)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_STRIP_FILES OFF)  # static libraries keep their symbols; `scree` is small either way
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)  # libscree-dev_<version>_<arch>.deb
set(CPACK_DEBIAN_PACKAGE_NAME libscree-dev)
set(CPACK_DEBIAN_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_DEBIAN_PACKAGE_RELEASE "")
set(CPACK_DEBIAN_PACKAGE_SECTION libdevel)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
set(CPACK_DEBIAN_PACKAGE_MAINTAINER ${SCREE_PACKAGE_MAINTAINER})
# The Description's first line is CPACK_PACKAGE_DESCRIPTION_SUMMARY; this is the extended text (CPack indents it).
set(CPACK_DEBIAN_PACKAGE_DESCRIPTION
    "Scree simulates rigid bodies with joints and contacts (projected Gauss-Seidel
and a sparse direct solver), granular particles, and a model layer after the
agxModel chapter of the AGX Dynamics manual: a deformable terrain that can be
dug, two-body tire models, granular field post-processing and suction
grippers. This package holds the static libraries, headers and CMake package
(find_package(Scree)), and the scree program that runs, records and replays
the built-in scenes.")
set(CPACK_DEBIAN_PACKAGE_DEPENDS "${_scree_deb_depends}")
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "cmake (>= 3.25), g++ (>= 4:12)")
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)  # dpkg-shlibdeps (dpkg-dev) on the scree program
set(CPACK_DEBIAN_COMPRESSION_TYPE xz)
include(CPack)

unset(_scree_deb_depends)

# SPDX-License-Identifier: MIT
# Copyright (c) 2026 The Scree authors
# FindCCD: libccd (Debian: libccd-dev ships a pkg-config file, no CMake config). Defines CCD::CCD.
find_package(PkgConfig QUIET)
if(PKG_CONFIG_FOUND)
  pkg_check_modules(PC_CCD QUIET ccd)
endif()
find_path(CCD_INCLUDE_DIR ccd/ccd.h HINTS ${PC_CCD_INCLUDE_DIRS})
find_library(CCD_LIBRARY NAMES ccd HINTS ${PC_CCD_LIBRARY_DIRS})
include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(CCD REQUIRED_VARS CCD_LIBRARY CCD_INCLUDE_DIR)
if(CCD_FOUND AND NOT TARGET CCD::CCD)
  add_library(CCD::CCD UNKNOWN IMPORTED)
  set_target_properties(CCD::CCD PROPERTIES IMPORTED_LOCATION "${CCD_LIBRARY}"
                        INTERFACE_INCLUDE_DIRECTORIES "${CCD_INCLUDE_DIR}")
  if(PC_CCD_CFLAGS_OTHER)
    set_property(TARGET CCD::CCD PROPERTY INTERFACE_COMPILE_OPTIONS ${PC_CCD_CFLAGS_OTHER})
  endif()
endif()
mark_as_advanced(CCD_INCLUDE_DIR CCD_LIBRARY)

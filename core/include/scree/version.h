// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Version and the active build configuration as a runtime string.
//
// The version has one source: project(Scree VERSION x.y.z) in the root CMakeLists.txt. CMake writes it into the
// generated header scree/version_number.h (macros SCREE_VERSION_MAJOR/MINOR/PATCH/STRING, for compile-time
// checks), into the CMake package (ScreeConfigVersion.cmake) and into the Debian package's version, so
// getVersionString(), find_package(Scree x.y) and `dpkg -l libscree-dev` always agree (test_unit_version and
// scripts/package-test.sh check it). Semantic versioning; while the major version is 0, a minor version may
// change the API (the CMake package accepts only the same major.minor).
#pragma once

#include "scree/version_number.h"

namespace scree {
/// e.g. "Scree 0.1.0 (optimised; OpenMP on; SuiteSparse on; asserts off)".
const char* getConfigurationString();
/// The library's version, "MAJOR.MINOR.PATCH" (SCREE_VERSION_STRING of the build that compiled the library).
const char* getVersionString();
}  // namespace scree

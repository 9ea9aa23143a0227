// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The version has one source, project(Scree VERSION ...) in the root CMakeLists.txt (scree/version.h). This
// suite checks that the three places a user reads it agree: scree::getVersionString() (compiled into the
// library), the generated macros of scree/version_number.h, and the CMake package's ScreeConfigVersion.cmake
// (what find_package(Scree x.y) compares). The Debian package's version is checked against the installed
// library's getVersionString() by scripts/package-test.sh.
#include <doctest/doctest.h>

#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include <scree/scree.h>

#ifndef SCREE_TEST_PROJECT_VERSION
#error "test/CMakeLists.txt passes the CMake project version as SCREE_TEST_PROJECT_VERSION"
#endif

TEST_CASE("getVersionString is the CMake project version, in semantic-versioning form") {
  const std::string v = scree::getVersionString();
  CHECK(v == SCREE_TEST_PROJECT_VERSION);
  // MAJOR.MINOR.PATCH without leading zeros (semver.org, item 2); no pre-release or build suffix in 0.1.0.
  CHECK(std::regex_match(v, std::regex(R"((0|[1-9][0-9]*)\.(0|[1-9][0-9]*)\.(0|[1-9][0-9]*))")));
  // The compile-time macros say the same as the library (a header from another build would differ).
  CHECK(v == SCREE_VERSION_STRING);
  CHECK(v == std::to_string(SCREE_VERSION_MAJOR) + "." + std::to_string(SCREE_VERSION_MINOR) + "." +
                 std::to_string(SCREE_VERSION_PATCH));
  // The configuration string names the same version.
  const std::string config = scree::getConfigurationString();
  CHECK(config.rfind("Scree " + v + " (", 0) == 0);
}

TEST_CASE("the CMake package version (ScreeConfigVersion.cmake) equals getVersionString") {
  std::ifstream in(SCREE_TEST_CONFIG_VERSION_FILE);
  REQUIRE_MESSAGE(in.good(), "cannot read " << SCREE_TEST_CONFIG_VERSION_FILE);
  std::stringstream text;
  text << in.rdbuf();
  std::smatch m;
  const std::string s = text.str();
  REQUIRE(std::regex_search(s, m, std::regex(R"re(set\(PACKAGE_VERSION "([^"]*)"\))re")));
  CHECK(m[1].str() == scree::getVersionString());
}

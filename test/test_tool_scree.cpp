// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The scree program (examples/scree): `scree list` names every built-in scene, `scree run` runs one and prints
// its metrics, and bad arguments fail with one line on stderr, a non-zero exit and no file. The executable's
// path comes from CMake (SCREE_EXE).
#include <doctest/doctest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <scree/io/recording.h>

#ifndef SCREE_EXE
#define SCREE_EXE ""
#endif

namespace fs = std::filesystem;

namespace {

struct Result {
  int status = -1;
  std::string out, err;
};

std::string tempPath(const std::string& name) {
  return (fs::temp_directory_path() / ("scree_test_tool_" + std::to_string(::getpid()) + "_" + name)).string();
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Runs `scree ARGS` with stdout and stderr captured in files.
Result runScree(const std::string& args) {
  const std::string out = tempPath("stdout"), err = tempPath("stderr");
  const std::string cmd = std::string("'") + SCREE_EXE + "' " + args + " >'" + out + "' 2>'" + err + "'";
  Result r;
  const int rc = std::system(cmd.c_str());
  r.status = WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  fs::remove(out);
  fs::remove(err);
  return r;
}

std::vector<std::string> lines(const std::string& s) {
  std::vector<std::string> v;
  std::istringstream in(s);
  for (std::string l; std::getline(in, l);) v.push_back(l);
  return v;
}

/// The value after "  name" on a metrics line of `out` (NaN when missing).
double metric(const std::string& out, const std::string& name) {
  for (const std::string& l : lines(out))
    if (l.rfind("  " + name, 0) == 0) return std::stod(l.substr(2 + name.size()));
  return std::nan("");
}

// The reference scenes of docs/scenes.md and the scenes of the issue that asked for the program.
const std::vector<std::string> kScenes = {"pyramid20", "tower10",      "mass_ratio",   "chain20",  "slide",
                                          "incline_mu05", "incline_mu06", "vehicle",   "suction",  "pile",
                                          "terrain_vehicle", "terrain_plate", "dig",   "dozer"};

}  // namespace

TEST_SUITE("scree") {

TEST_CASE("scree list names every scene, one line each") {
  const Result r = runScree("list");
  REQUIRE(r.status == 0);
  std::vector<std::string> names;
  for (const std::string& l : lines(r.out)) names.push_back(l.substr(0, l.find(' ')));
  for (const std::string& s : kScenes) {
    CAPTURE(s);
    CHECK(std::count(names.begin(), names.end(), s) == 1);
  }
}

TEST_CASE("scree run tower10 --time 1 --quiet: exit 0 with the metrics, timings and solver statistics") {
  const Result r = runScree("run tower10 --time 1 --quiet");
  REQUIRE(r.status == 0);
  CHECK(r.err.empty());
  CHECK(r.out.find("60 steps of") != std::string::npos);  // 1 s at the scene's 1/60 s
  CHECK(r.out.find("ms/step: median") != std::string::npos);
  CHECK(r.out.find("metrics (tower10)") != std::string::npos);
  CHECK(r.out.find("solver: ") != std::string::npos);
  CHECK(r.out.find("stage timings") != std::string::npos);
  CHECK(r.out.find("step report: ok") != std::string::npos);
  CHECK(r.out.find("steps/s") == std::string::npos);  // --quiet: no progress
  // docs/scenes.md's goal for tower10, which Scree meets (test_analytic_stacks.cpp): every cube within 1 cm.
  const double worst = metric(r.out, "largest displacement");
  CHECK(worst >= 0);
  CHECK(worst < 0.01);
}

TEST_CASE("without --quiet and with stdout not a terminal: a plain progress line") {
  const Result r = runScree("run slide --time 0.5");
  REQUIRE(r.status == 0);
  CHECK(r.out.find("30/30 steps (100%)") != std::string::npos);
  CHECK(r.out.find('\r') == std::string::npos);
}

TEST_CASE("bad arguments: one line on stderr, a non-zero exit, no file") {
  const std::string dir = tempPath("dir");
  fs::create_directories(dir);
  const std::string file = tempPath("bad.screerec");
  const std::vector<std::string> bad = {
      "run no_such_scene",
      "run tower10 --time -1 --record '" + file + "'",
      "run tower10 --time 0",
      "run tower10 --dt 0 --record '" + file + "'",
      "run tower10 --dt -0.01",
      "run tower10 --iterations 0",
      "run tower10 --time 1 --record '" + dir + "'",                      // a directory
      "run tower10 --time 1 --record '" + dir + "/missing/x.screerec'",   // a directory that does not exist
      "run tower10 --time 1 --solve-type SIDEWAYS --record '" + file + "'",
      "run tower10 --time 1 --vtk /proc/scree-cannot-create",
      "run",
      "",
      "run tower10 --time abc",
  };
  for (const std::string& args : bad) {
    CAPTURE(args);
    const Result r = runScree(args);
    CHECK(r.status != 0);
    const std::vector<std::string> l = lines(r.err);
    REQUIRE(l.size() == 1);
    CHECK(l[0].rfind("scree: error: ", 0) == 0);
    CHECK_FALSE(fs::exists(file));
    CHECK_FALSE(fs::exists(file + ".part"));
  }
  CHECK(fs::is_empty(dir));
  fs::remove_all(dir);
}

TEST_CASE("--record writes a recording the reader reads; --vtk creates its directory") {
  const std::string file = tempPath("slide.screerec");
  const std::string vtk = tempPath("vtk");
  const Result r = runScree("run slide --time 1 --quiet --record '" + file + "' --vtk '" + vtk + "'");
  REQUIRE(r.status == 0);
  CHECK(fs::is_directory(vtk));
  CHECK_FALSE(fs::exists(file + ".part"));
  const scree::io::RecordingReader rec(file);
  // 60 steps at 30 frames/s: a frame every 2 steps and frame 0, 31 frames.
  CHECK(rec.getNumFrames() == 31);
  CHECK(rec.getScene().name == "slide");
  CHECK(rec.getScene().frameInterval == doctest::Approx(2.0 / 60).epsilon(1e-12));
  CHECK(rec.getFrame(30).time == doctest::Approx(1.0).epsilon(1e-9));
  fs::remove(file);
  fs::remove_all(vtk);
}

TEST_CASE("every scene builds and steps") {
  // Two steps each (the 10k-body scenes step at 1/100 s): a builder that throws or a step that reports a
  // non-finite body fails here.
  const Result list = runScree("list");
  REQUIRE(list.status == 0);
  for (const std::string& l : lines(list.out)) {
    const std::string name = l.substr(0, l.find(' '));
    CAPTURE(name);
    const Result r = runScree("run " + name + " --time 0.02 --quiet");
    CHECK(r.status == 0);
    CHECK(r.out.find("step report: ok") != std::string::npos);
  }
}

}  // TEST_SUITE

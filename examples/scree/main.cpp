// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// scree: the command-line program. `scree list` prints the built-in scenes (scene_registry.h); `scree run SCENE`
// runs one with a progress bar (a plain line per second when stdout is not a terminal) and ends with a summary:
// the median wall time per step, the scene's metrics, the solver's statistics and the per-stage timings
// (Simulation::getTimings). `--record FILE` writes a .screerec recording (docs/recording.md) at --fps frames per
// simulated second; `--vtk DIR` writes ParaView files at the same rate (scree::io::VtkExporter, docs/paraview.md).
// `scree view FILE [-o page.html]` writes a self-contained page that replays a recording in a browser
// (scree::io::writeViewerPage, docs/viewer.md).
//
// Errors (unknown scene, a bad number, a file or directory that cannot be written) print one line
// "scree: error: ..." on stderr and exit with 2 before anything runs; a recording is written to FILE.part and
// renamed only when the run completed, so a failed run leaves no partial file.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <scree/io/recording.h>
#include <scree/io/viewer_page.h>
#include <scree/io/vtk_export.h>
#include <scree/scree.h>

#include "scene_registry.h"

namespace fs = std::filesystem;
using namespace scree;

namespace {

/// Usage errors: one line on stderr, exit code 2.
struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

std::string formatSeconds(double s) {
  if (!std::isfinite(s) || s < 0) return "?";
  const long t = std::lround(s);
  char buf[32];
  if (t >= 3600)
    std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", t / 3600, (t / 60) % 60, t % 60);
  else
    std::snprintf(buf, sizeof buf, "%ld:%02ld", t / 60, t % 60);
  return buf;
}

/// Progress display: a redrawn bar on a terminal (at most 10 redraws a second), a plain line per second otherwise.
class Progress {
 public:
  Progress(long total, bool quiet) : total_(total), quiet_(quiet), tty_(isatty(STDOUT_FILENO) == 1) {
    start_ = last_ = Clock::now();
  }
  void update(long done) {
    if (quiet_) return;
    const auto now = Clock::now();
    const double sinceLast = std::chrono::duration<double>(now - last_).count();
    if (done < total_ && sinceLast < (tty_ ? 0.1 : 1.0)) return;
    last_ = now;
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    const double rate = elapsed > 0 ? done / elapsed : 0;
    const double eta = rate > 0 ? (total_ - done) / rate : -1;
    const double frac = total_ > 0 ? double(done) / total_ : 1;
    if (tty_) {
      constexpr int width = 30;
      const int filled = int(frac * width);
      std::string bar(filled, '#');
      bar.append(width - filled, '.');
      std::printf("\r[%s] %3.0f%%  %ld/%ld steps  %.0f steps/s  ETA %s   ", bar.c_str(), 100 * frac, done, total_,
                  rate, formatSeconds(eta).c_str());
      if (done >= total_) std::printf("\n");
    } else {
      std::printf("%ld/%ld steps (%.0f%%), %.0f steps/s, ETA %s\n", done, total_, 100 * frac, rate,
                  formatSeconds(eta).c_str());
    }
    std::fflush(stdout);
  }

 private:
  using Clock = std::chrono::steady_clock;
  long total_;
  bool quiet_, tty_;
  Clock::time_point start_, last_;
};

struct RunOptions {
  std::string scene;
  double time = 0;
  bool timeGiven = false;  // else the scene's default
  double dt = 0;
  bool dtGiven = false;  // else the scene's own
  int iterations = 0;
  std::string solveType;
  int threads = 0;
  std::string record;
  double fps = 30;
  bool contacts = false;
  std::string vtk;
  bool quiet = false;
};

FrictionModel::SolveType parseSolveType(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::toupper(c)); });
  if (s == "DIRECT") return FrictionModel::DIRECT;
  if (s == "ITERATIVE") return FrictionModel::ITERATIVE;
  if (s == "DIRECT_AND_ITERATIVE") return FrictionModel::DIRECT_AND_ITERATIVE;
  if (s == "SPLIT") return FrictionModel::SPLIT;
  throw UsageError("--solve-type " + s + " is not one of DIRECT, ITERATIVE, DIRECT_AND_ITERATIVE, SPLIT");
}

/// The solve type on the contact materials of every pair of materials present now (geometries and particles)
/// and on every constraint.
void applySolveType(Simulation& sim, FrictionModel::SolveType type) {
  std::vector<MaterialRef> mats;
  auto add = [&](const MaterialRef& m) {
    if (m && std::find(mats.begin(), mats.end(), m) == mats.end()) mats.push_back(m);
  };
  for (const GeometryRef& g : sim.getStaticGeometries()) add(g->getMaterial());
  for (const RigidBodyRef& b : sim.getRigidBodies())
    for (const GeometryRef& g : b->getGeometries()) add(g->getMaterial());
  for (const MaterialRef& m : sim.getGranularBodySystem().getMaterialTable()) add(m);
  add(sim.getGranularBodySystem().getMaterial());
  for (size_t i = 0; i < mats.size(); ++i)
    for (size_t j = i; j < mats.size(); ++j)
      sim.getMaterialManager().getOrCreateContactMaterial(mats[i], mats[j])->setSolveType(type);
  for (const ConstraintRef& c : sim.getConstraints()) c->setSolveType(type);
}

void checkVtkDirectory(const std::string& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir))
    throw UsageError("--vtk " + dir + ": cannot create the directory" + (ec ? " (" + ec.message() + ")" : ""));
  const fs::path probe = fs::path(dir) / ".scree-write-test";
  {
    std::ofstream f(probe);
    if (!f) throw UsageError("--vtk " + dir + ": the directory is not writable");
  }
  fs::remove(probe, ec);
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  const size_t m = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + m, v.end());
  return v[m];
}

void printTimings(const StepTimings& sum, long steps) {
  const std::pair<const char*, double StepTimings::*> stages[] = {
      {"preCollide", &StepTimings::preCollide},
      {"syncGeometries", &StepTimings::syncGeometries},
      {"collideGeometries", &StepTimings::collideGeometries},
      {"collideParticles", &StepTimings::collideParticles},
      {"resolveMaterials", &StepTimings::resolveMaterials},
      {"contactEvents", &StepTimings::contactEvents},
      {"pre", &StepTimings::pre},
      {"applyForces", &StepTimings::applyForces},
      {"contactRows", &StepTimings::contactRows},
      {"constraintRows", &StepTimings::constraintRows},
      {"particleRows", &StepTimings::particleRows},
      {"solve", &StepTimings::solve},
      {"integrateMotion", &StepTimings::integrateMotion},
      {"storeResults", &StepTimings::storeResults},
      {"projectPositions", &StepTimings::projectPositions},
      {"checkFinite", &StepTimings::checkFinite},
      {"post", &StepTimings::post},
      {"compactParticles", &StepTimings::compactParticles},
  };
  const double total = sum.total;
  std::printf("stage timings (mean ms/step, share of the step):\n");
  for (const auto& [name, field] : stages) {
    const double v = sum.*field;
    if (v <= 0) continue;
    std::printf("  %-28s %9.4f ms %5.1f %%\n", name, v / steps, total > 0 ? 100 * v / total : 0.0);
  }
  std::printf("  %-28s %9.4f ms\n", "total", total / steps);
}

int runScene(const RunOptions& o) {
  const cli::SceneEntry* entry = cli::findScene(o.scene);
  if (!entry) throw UsageError("unknown scene \"" + o.scene + "\" (scree list shows the scenes)");
  if (o.timeGiven && !(std::isfinite(o.time) && o.time > 0))
    throw UsageError("--time " + detail::formatValue(o.time) + " is invalid (must be > 0 s)");
  if (o.dtGiven && !(std::isfinite(o.dt) && o.dt > 0))
    throw UsageError("--dt " + detail::formatValue(o.dt) + " is invalid (must be > 0 s)");
  if (!(std::isfinite(o.fps) && o.fps > 0)) throw UsageError("--fps must be > 0");
  std::optional<FrictionModel::SolveType> solveType;
  if (!o.solveType.empty()) solveType = parseSolveType(o.solveType);
  if (!o.vtk.empty()) checkVtkDirectory(o.vtk);
  io::RecordingWriter writer;
  if (!o.record.empty()) {
    try {
      writer.open(o.record);
    } catch (const std::invalid_argument& e) {
      throw UsageError(std::string("--record: ") + e.what());
    }
  }
  if (o.threads > 0) setNumThreads(o.threads);

  cli::BuildOptions bo;
  bo.dt = o.dtGiven ? o.dt : 0;
  cli::SceneRun run = entry->build(bo);
  Simulation& sim = *run.sim;
  if (o.iterations > 0) sim.getSolver().setNumIterations(o.iterations);
  if (solveType) applySolveType(sim, *solveType);
  const double h = sim.getTimeStep();
  const double seconds = o.timeGiven ? o.time : entry->defaultTime;
  const long steps = std::max(1L, std::lround(seconds / h));
  const uint32_t frameEvery = std::max(1u, uint32_t(std::lround(1.0 / (o.fps * h))));

  std::printf("scree run %s: %s\n", entry->name.c_str(), entry->description.c_str());
  std::printf("%ld steps of %.6g s (%.4g s simulated), %d solver iterations, %d threads%s\n", steps, h, steps * h,
              sim.getSolver().getNumIterations(), getNumThreads(),
              o.record.empty() ? "" : (", recording to " + o.record).c_str());
  std::fflush(stdout);

  if (!o.record.empty()) {
    writer.setRecordEvery(frameEvery);
    writer.setRecordContacts(o.contacts);
    writer.begin(sim, entry->name, run.terrains);
  }
  // ParaView export (docs/paraview.md): the bodies, particles and terrains at the recording's frame rate.
  std::optional<io::VtkExporter> vtk;
  if (!o.vtk.empty()) {
    vtk.emplace(o.vtk, entry->name);
    for (const Terrain* t : run.terrains) vtk->addTerrain(*t);
    vtk->writeFrame(sim, sim.getTimeStamp());
  }

  using Clock = std::chrono::steady_clock;
  std::vector<double> stepMs, recordMs;
  stepMs.reserve(size_t(steps));
  StepTimings sum;
  size_t iterationsSum = 0, rowsMax = 0, contactsMax = 0, particleContactsMax = 0, directRowsMax = 0;
  bool allOk = true;
  std::vector<std::string> problems;
  Progress progress(steps, o.quiet);
  const auto wall0 = Clock::now();
  for (long i = 1; i <= steps; ++i) {
    const auto t0 = Clock::now();
    run.step();
    const auto t1 = Clock::now();
    stepMs.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    sum += sim.getTimings();
    const SolverStats& ss = sim.getSolver().getStats();
    iterationsSum += ss.numIterations;
    rowsMax = std::max(rowsMax, ss.numRows);
    directRowsMax = std::max(directRowsMax, ss.numDirectRows);
    contactsMax = std::max(contactsMax, sim.getStepStats().numContactPoints);
    particleContactsMax = std::max(particleContactsMax, sim.getStepStats().numParticleContacts);
    const StepReport& rep = sim.getLastStepReport();
    if (!rep.ok() && allOk) {
      allOk = false;
      problems = rep.messages;
      if (problems.empty()) problems.push_back("step " + std::to_string(i) + " reported a problem");
    }
    if (writer.isOpen()) {
      writer.writeFrame(sim);
      recordMs.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t1).count());
    }
    if (vtk && i % frameEvery == 0) vtk->writeFrame(sim, sim.getTimeStamp());
    progress.update(i);
  }
  const double wall = std::chrono::duration<double>(Clock::now() - wall0).count();
  uint64_t recordBytes = 0;
  uint32_t recordFrames = 0;
  if (writer.isOpen()) {
    recordFrames = writer.getNumFrames();
    recordBytes = writer.close();
  }

  std::printf("\nsummary: %ld steps in %.3f s wall (%.4g s simulated, %.2fx real time)\n", steps, wall, steps * h,
              wall > 0 ? steps * h / wall : 0.0);
  std::printf("ms/step: median %.4f (min %.4f, max %.4f)\n", median(stepMs),
              *std::min_element(stepMs.begin(), stepMs.end()), *std::max_element(stepMs.begin(), stepMs.end()));
  if (!o.record.empty()) {
    double recSum = 0;
    for (double v : recordMs) recSum += v;
    std::printf("recording: %s, %u frames every %u steps (%.4g s), %.2f MB, %.4f ms/step to record (mean)\n",
                o.record.c_str(), recordFrames, frameEvery, frameEvery * h, recordBytes / 1e6, recSum / steps);
  }
  if (vtk) {
    const size_t frames = vtk->getNumFrames();
    vtk->close();
    std::printf("vtk: %zu frames, open %s in ParaView\n", frames, vtk->getCollectionPath().c_str());
  }
  std::printf("metrics (%s):\n", entry->name.c_str());
  if (run.printMetrics) run.printMetrics();
  const SolverStats& ss = sim.getSolver().getStats();
  std::printf("solver: %.1f iterations/step (mean), rows max %zu (direct max %zu), contact points max %zu, particle "
              "contacts max %zu; last step: %zu bodies, %zu rows, residual %.3g N s\n",
              double(iterationsSum) / steps, rowsMax, directRowsMax, contactsMax, particleContactsMax, ss.numBodies,
              ss.numRows, ss.lastResidual);
  printTimings(sum, steps);
  if (!allOk) {
    std::printf("step report: problems (first): ");
    for (const std::string& m : problems) std::printf("%s; ", m.c_str());
    std::printf("\n");
  } else {
    std::printf("step report: ok\n");
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"scree: run Scree's built-in scenes"};
  app.require_subcommand(1);
  // scree --version: the library's configuration string, "Scree 0.1.0 (optimised; ...)" (scree/version.h).
  app.set_version_flag("--version", std::string(getConfigurationString()));
  CLI::App* list = app.add_subcommand("list", "print the built-in scenes, one line each");
  CLI::App* runCmd = app.add_subcommand("run", "run a scene and print a summary");
  RunOptions o;
  runCmd->add_option("scene", o.scene, "scene name (scree list)")->required();
  CLI::Option* timeOpt = runCmd->add_option("--time", o.time, "simulated seconds (default: the scene's own)");
  CLI::Option* dtOpt = runCmd->add_option("--dt", o.dt, "time step, s (default: the scene's own)");
  runCmd->add_option("--iterations", o.iterations, "solver iterations")->check(CLI::PositiveNumber);
  runCmd->add_option("--solve-type", o.solveType, "DIRECT, ITERATIVE, DIRECT_AND_ITERATIVE or SPLIT");
  runCmd->add_option("--threads", o.threads, "threads of the parallel stages")->check(CLI::PositiveNumber);
  runCmd->add_option("--record", o.record, "write a .screerec recording (docs/recording.md)");
  runCmd->add_option("--fps", o.fps, "recorded (and VTK) frames per simulated second (default 30)");
  runCmd->add_flag("--contacts", o.contacts, "record contact points and forces too");
  runCmd->add_option("--vtk", o.vtk, "write ParaView files into this directory (created if missing)");
  runCmd->add_flag("--quiet,-q", o.quiet, "no progress display");
  CLI::App* viewCmd = app.add_subcommand("view", "write a self-contained HTML page that replays a recording");
  std::string viewFile, viewOut;
  viewCmd->add_option("file", viewFile, "a .screerec recording (scree run SCENE --record FILE)")->required();
  viewCmd->add_option("-o,--output", viewOut, "the page to write (default: FILE with the extension .html)");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "scree: error: %s\n", e.what());
    return 2;
  }
  try {
    if (list->parsed()) {
      for (const cli::SceneEntry& e : cli::sceneRegistry())
        std::printf("%-18s %6.1f s  %s\n", e.name.c_str(), e.defaultTime, e.description.c_str());
      return 0;
    }
    o.timeGiven = timeOpt->count() > 0;
    o.dtGiven = dtOpt->count() > 0;
    if (runCmd->parsed()) return runScene(o);
    if (viewCmd->parsed()) {
      if (viewOut.empty()) viewOut = fs::path(viewFile).replace_extension(".html").string();
      io::writeViewerPage(viewFile, viewOut);
      std::printf("wrote %s (open it in a browser: file://%s)\n", viewOut.c_str(),
                  fs::absolute(viewOut).string().c_str());
      return 0;
    }
  } catch (const UsageError& e) {
    std::fprintf(stderr, "scree: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "scree: error: %s\n", e.what());
    return 1;
  }
  return 0;
}

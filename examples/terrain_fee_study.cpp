// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// terrain_fee_study: the digging force of a flat blade pushed through cohesionless Terrain soil (the cut soil
// becomes particles that heap in front of the blade) against the fundamental earthmoving equation, for three
// depths, two widths and two rake angles (bench/scenes/terrain_fee.h; docs/terrain.md, "Digging force against the
// fundamental earthmoving equation").
//
//   build/examples/terrain_fee_study [DIR [TRAVEL [WEDGE [PHASES]]]]   prints the table; with DIR writes DIR/fee.dat (one line per
//   setting: rake_deg depth width force fee fee_surcharge soil_volume force0 pile_slope) and DIR/fee_series.dat (travel, horizontal
//   and vertical force, heap top, particles and the force's 10-step running mean of every step of every setting, blocks separated by two blank lines);
//   docs/terrain/fee.gp plots them. TRAVEL (m, default 0.3) changes the push length; WEDGE 0 turns the cut's
//   failure wedge off (Terrain::setShovelFailureWedge); PHASES (default 4) start positions
//   within one cell are averaged (runTerrainFeeAveraged; the series too). F0 and k_s: the line F(s) = F0 + k_s s through the force
//   at travel s > 0.05 m (TerrainFeeResult::force0, pileSlope).
//
// FEE+q: the FEE with the surcharge q = gamma V / (w L), V the soil the particles carry (mean over the window),
// L = d (cot alpha + cot beta) the length of the failure wedge's top surface: all dug soil laid on the wedge,
// an upper bound of the surcharge the heap can exert.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "scenes/terrain_fee.h"
#include "scree/core/parallel.h"

int main(int argc, char** argv) {
  using namespace scree;
  using namespace scree::scenes;
  const std::string dir = argc > 1 ? argv[1] : "";
  // One thread: the particle solve gives the same result on any thread count (scree/core/parallel.h), and on a
  // loaded machine OpenMP's waiting threads cost more than they save at a few thousand particles.
  setNumThreads(1);
  FILE* table = dir.empty() ? nullptr : std::fopen((dir + "/fee.dat").c_str(), "w");
  FILE* series = dir.empty() ? nullptr : std::fopen((dir + "/fee_series.dat").c_str(), "w");
  const Real rakes[] = {45, 60};
  const Real depths[] = {0.03, 0.05, 0.07};
  const Real widths[] = {0.2, 0.3};
  const Real g = 9.81;
  TerrainFeeParams base;
  if (argc > 2) base.travel = std::atof(argv[2]);
  if (argc > 3) base.failureWedge = std::atoi(argv[3]) != 0;  // 0: the cut without the failure wedge
  const int phases = argc > 4 ? std::atoi(argv[4]) : 4;           // start positions averaged (runTerrainFeeAveraged)
  const Real phi = std::atan(base.soilFriction), delta = std::atan(base.bladeFriction);
  std::printf("phi = %.2f deg, delta = %.2f deg, gamma = %.0f N/m^3\n", phi * 180 / M_PI, delta * 180 / M_PI,
              base.density * g);
  std::printf("%6s %6s %6s %10s %10s %10s %10s %8s %8s %8s %8s %8s\n", "rake", "d", "w", "F (N)", "FEE (N)", "FEE+q (N)",
              "soil (m3)", "F/FEE", "F/FEE+q", "F0 (N)", "k_s(N/m)", "time(s)");
  if (table) std::fprintf(table, "# rake_deg depth_m width_m force_N fee_N fee_surcharge_N soil_volume_m3 force0_N pile_slope_N_per_m\n");
  for (Real rake : rakes)
    for (Real w : widths)
      for (Real d : depths) {
        TerrainFeeParams p = base;
        p.rake = rake * M_PI / 180;
        p.depth = d;
        p.width = w;
        const auto t0 = std::chrono::steady_clock::now();
        const TerrainFeeResult r = runTerrainFeeAveraged(p, phases);
        const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        const Real gamma = p.density * g;
        const Real fee = feeHorizontalForce(p.rake, phi, delta, gamma, d, w);
        const FeeFactors ff = feeFactors(p.rake, phi, delta);
        const Real wedge = d * (1 / std::tan(p.rake) + 1 / std::tan(ff.beta));
        const Real q = gamma * r.meanSoilVolume / (w * wedge);
        const Real feeQ = feeHorizontalForce(p.rake, phi, delta, gamma, d, w, q);
        std::printf("%6.0f %6.3f %6.2f %10.2f %10.2f %10.2f %10.5f %8.2f %8.2f %8.2f %8.1f %8.1f\n", rake, d, w, r.meanForce, fee,
                    feeQ, r.meanSoilVolume, r.meanForce / fee, r.meanForce / feeQ, r.force0, r.pileSlope, secs);
        if (table)
          std::fprintf(table, "%g %g %g %g %g %g %g %g %g\n", rake, d, w, r.meanForce, fee, feeQ, r.meanSoilVolume,
                       r.force0, r.pileSlope);
        if (series) {
          std::fprintf(series, "# rake %g depth %g width %g\n", rake, d, w);
          // Last column: the horizontal force's running mean over 10 steps (particles are made in batches every
          // few steps, so the force comes in pulses).
          for (size_t i = 0; i < r.samples.size(); ++i) {
            const TerrainFeeSample& s = r.samples[i];
            Real run = 0;
            const size_t n0 = i >= 9 ? i - 9 : 0;
            for (size_t k = n0; k <= i; ++k) run += r.samples[k].force;
            run /= Real(i - n0 + 1);
            std::fprintf(series, "%g %g %g %g %zu %g\n", s.travel, s.force, s.vertical, s.heapHeight, s.particles, run);
          }
          std::fprintf(series, "\n\n");
        }
        std::fflush(stdout);
      }
  if (table) std::fclose(table);
  if (series) std::fclose(series);
}

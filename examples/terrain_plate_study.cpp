// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Plate-sinkage study for docs/terrain.md: settled plastic sinkage of a Terrain under a uniform plate pressure
// (10-100 kPa) for three deformabilities, against the law's closed form z* = D ln(p/p0) / ((d+1) ln M) and
// against Bekker's p = (k_c/b + k_phi) z^n for a dry sand (J.Y. Wong, Theory of Ground Vehicles, Table 2.3, LLL
// dry sand: n = 1.1, k_c = 0.99 kN/m^(n+1), k_phi = 1528.43 kN/m^(n+2); plate width b = 0.5 m).
// It also fits the law to Bekker's curve over 10-100 kPa (p0 and a = D / ((d+1) ln M), least squares on the
// relative error at 91 log-spaced pressures) and prints the remaining error.
//
// The plate: bench/scenes/terrain_plate.h (a bed of guided pistons, one per vertex, 8 s at 60 Hz).
// Usage: terrain_plate_study [data file for gnuplot]
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <scree/scree.h>

#include "scenes/terrain_plate.h"

using namespace scree;

namespace {
constexpr Real kN = 1.1, kKc = 0.99e3, kKphi = 1528.43e3, kB = 0.5;  // Wong, Table 2.3, LLL dry sand
Real bekkerSinkage(Real p) { return std::pow(p / (kKc / kB + kKphi), 1 / kN); }

struct Fit {
  Real p0 = 0, a = 0, rms = 0, max = 0;
};

/// Least squares on the relative error of z = a ln(p/p0) against Bekker over [10, 100] kPa: for each p0 the best
/// a is closed form (a = sum(L/z) / sum((L/z)^2), L = ln(p/p0)); p0 by a scan in 1 Pa steps.
Fit fitLawToBekker() {
  std::vector<Real> ps, zs;
  for (int i = 0; i <= 90; ++i) {
    ps.push_back(10e3 * std::pow(10.0, i / 90.0));
    zs.push_back(bekkerSinkage(ps.back()));
  }
  Fit best;
  best.rms = 1e300;
  for (Real p0 = 100; p0 < 10e3; p0 += 1) {
    Real num = 0, den = 0;
    for (size_t i = 0; i < ps.size(); ++i) {
      const Real q = std::log(ps[i] / p0) / zs[i];
      num += q;
      den += q * q;
    }
    const Real a = num / den;
    Real ss = 0, mx = 0;
    for (size_t i = 0; i < ps.size(); ++i) {
      const Real e = (a * std::log(ps[i] / p0) - zs[i]) / zs[i];
      ss += e * e;
      mx = std::max(mx, std::abs(e));
    }
    const Real rms = std::sqrt(ss / Real(ps.size()));
    if (rms < best.rms) best = {p0, a, rms, mx};
  }
  return best;
}
}  // namespace

int main(int argc, char** argv) {
  const Fit fit = fitLawToBekker();
  const Real M = 16, dFit = 1;
  const Real D = fit.a * (dFit + 1) * std::log(M);
  std::printf("Fit of z = a ln(p/p0) to Bekker (Wong's LLL dry sand, b = 0.5 m) over 10-100 kPa:\n");
  std::printf("  p0 = %.0f Pa, a = %.5f m; with M = %g, d = %g: D = %.4f m; relative error rms %.1f %%, max %.1f %%\n\n",
              fit.p0, fit.a, M, dFit, D, 100 * fit.rms, 100 * fit.max);

  const Real ds[3] = {0.5, 1.0, 3.0};
  std::FILE* data = argc > 1 ? std::fopen(argv[1], "w") : nullptr;
  if (data) std::fprintf(data, "# p_kPa bekker_mm sim_d0.5 law_d0.5 sim_d1 law_d1 sim_d3 law_d3 (mm)\n");
  std::printf("| p (kPa) | Bekker (mm) |");
  for (Real d : ds) std::printf(" d = %g: sim (mm) | law (mm) |", d);
  std::printf("\n|---|---|---|---|---|---|---|---|\n");
  for (int k = 1; k <= 10; ++k) {
    const Real p = 10e3 * k;
    std::printf("| %g | %.1f |", p / 1e3, 1e3 * bekkerSinkage(p));
    if (data) std::fprintf(data, "%g %.4f", p / 1e3, 1e3 * bekkerSinkage(p));
    for (Real d : ds) {
      scenes::TerrainPlateParams pp;
      pp.pressure = p;
      pp.deformability = d;
      pp.yieldPressure = fit.p0;
      pp.maxMultiplier = M;
      pp.depthForMax = D;
      scenes::TerrainPlateScene s = scenes::buildTerrainPlate(pp);
      for (int i = 0; i < int(8.0 / pp.dt); ++i) s.step();
      const Real sim = s.meanInnerSinkage(), law = s.terrain->computeSettledSinkage(p, d);
      std::printf(" %.2f | %.2f |", 1e3 * sim, 1e3 * law);
      if (data) std::fprintf(data, " %.4f %.4f", 1e3 * sim, 1e3 * law);
    }
    std::printf("\n");
    if (data) std::fprintf(data, "\n");
  }
  if (data) std::fclose(data);
  return 0;
}

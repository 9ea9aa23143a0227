// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Writes the heap a tall column of soil relaxes into with Terrain::avalancheAll, to look at it against the angle
// of repose: a 65 x 65 terrain (0.1 m cells) with 4 m^3 of soil on its centre vertex, relaxed twice - once with
// the material's angle of repose unset (theta = atan(mu) = atan(0.5) = 26.6 deg) and once set to 35 deg. For each
// it writes rows "r h_axis r_diag h_diag line" (distance from the apex along +x and along the +x+y diagonal,
// m; the heap's height above the ground there, m; the repose line h(1 m) + tan(theta) (1 m - r) through the
// axis profile at r = 1 m, m) to <dir>/heap_<10 x deg>.dat, and prints the passes, the volume error and the apex
// height. docs/terrain/avalanche.gp turns them into docs/terrain/avalanche.png.
//
//   build/examples/terrain_avalanche_heap [dir]
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include <scree/scree.h>

int main(int argc, char** argv) {
  using namespace scree;
  const std::string dir = argc > 1 ? argv[1] : ".";
  const size_t n = 65, c = 32;
  const Real s = 0.1, base = 0.5;
  for (const Real thetaSet : {0.0, 35.0 * M_PI / 180}) {
    auto sand = std::make_shared<Material>("sand");
    sand->setFrictionCoefficient(0.5);
    auto hf = std::make_shared<HeightField>(n, n, s * Real(n - 1), s * Real(n - 1));
    hf->setHeights(std::vector<Real>(n * n, base));
    Terrain t(hf);
    t.getGeometry()->setMaterial(sand);
    t.getDataInterface().add(sand, 0, 0.0, 0.0, thetaSet);
    hf->setHeight(c, c, base + 4.0 / (s * s));
    const Real v0 = t.computeHeightFieldVolume();
    const TerrainAvalancheStats st = t.avalancheAll();
    const Real theta = t.computeAngleOfRepose(c, c);
    const int deg = int(std::lround(theta * 180 / M_PI * 10));
    const std::string out = dir + "/heap_" + std::to_string(deg) + ".dat";
    std::FILE* f = std::fopen(out.c_str(), "w");
    if (!f) {
      std::fprintf(stderr, "terrain_avalanche_heap: cannot write %s\n", out.c_str());
      return 1;
    }
    std::fprintf(f, "# theta = %.6f rad (tan %.6f); r, h along +x, r_diagonal, h along +x+y, repose line (m)\n",
                 theta, std::tan(theta));
    const Real anchor = hf->getHeight(c + 10, c) - base;  // r = 1 m, on the flank
    for (size_t k = 0; k <= c; ++k)
      std::fprintf(f, "%.6f %.9f %.6f %.9f %.9f\n", Real(k) * s, hf->getHeight(c + k, c) - base,
                   Real(k) * s * std::sqrt(2.0), hf->getHeight(c + k, c + k) - base,
                   anchor + std::tan(theta) * (1.0 - Real(k) * s));
    std::fclose(f);
    std::printf("theta %.4f deg: %zu passes, %zu moves, converged %d, volume error %.2e (relative), apex %.4f m -> %s\n",
                theta * 180 / M_PI, st.passes, st.moves, int(st.converged),
                (t.computeHeightFieldVolume() - v0) / v0, hf->getHeight(c, c) - base, out.c_str());
  }
  return 0;
}

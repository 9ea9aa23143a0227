// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Terrain material map: a two-material PNG maps each vertex to the right material in both image axes (column =
// +x, top row = highest y), unmapped vertices use the terrain geometry's material, and contacts take their
// parameters from the material of the vertex under them. The ledger is read after every step.
#include <doctest/doctest.h>

#include <cstdio>
#include <filesystem>
#include <vector>

#include "png_test_files.h"
#include "terrain_world.h"

using namespace scree;
using namespace scree::test;

namespace {
std::string tempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("scree_terrain_" + name)).string();
}
}  // namespace

TEST_SUITE("terrain") {
  TEST_CASE("a two-material PNG maps every vertex: image column = x, image top row = highest y") {
    // 7 x 5 vertices (not square, so a transposed read cannot pass). Rows 1..4 of the image (y = 3..0): index 1
    // in columns 0..3, index 2 in columns 4..6. The top row (y = 4) is the mirror image: 2 then 1.
    const size_t nx = 7, ny = 5;
    std::vector<std::vector<uint8_t>> img(ny, std::vector<uint8_t>(nx));
    for (size_t r = 0; r < ny; ++r)
      for (size_t c = 0; c < nx; ++c) img[r][c] = uint8_t((c < 4) == (r != 0) ? 1 : 2);
    const std::string path = tempPath("two_materials.png");
    writeBytes(path, makeIndexPng(img));

    TestWorld w;
    auto hf = std::make_shared<HeightField>(nx, ny, 6.0, 4.0);  // 1 m cells
    auto t = std::make_shared<Terrain>(hf);
    auto ground = std::make_shared<Material>("ground");
    t->getGeometry()->setMaterial(ground);
    w.sim->add(t);
    TerrainDataInterface& di = t->getDataInterface();
    auto sand = std::make_shared<Material>("sand");
    auto clay = std::make_shared<Material>("clay");
    di.add(sand, 1, 0.1, 2.0, 0.5);
    di.add(clay, 2, 0.2, 0.5, 0.3);
    // Before the map every vertex has index 0: unmapped, the geometry's material, non-deformable.
    CHECK(di.getMaterial(3, 2) == ground);
    CHECK(di.getDeformability(3, 2) == 0);
    di.setMaterialMapping(path);
    for (size_t y = 0; y < ny; ++y)
      for (size_t x = 0; x < nx; ++x) {
        const size_t expected = img[ny - 1 - y][x];
        CAPTURE(x);
        CAPTURE(y);
        CHECK(di.getMaterialIndex(x, y) == expected);
        CHECK(di.getMaterial(x, y) == (expected == 1 ? sand : clay));
        CHECK(di.getParticleMaterial(x, y) == di.getMaterial(x, y));
      }
    // Corners spelled out: x grows with the image column, y shrinks with the image row.
    CHECK(di.getMaterial(0, 0) == sand);        // bottom-left pixel (row 4, column 0)
    CHECK(di.getMaterial(6, 0) == clay);        // bottom-right
    CHECK(di.getMaterial(0, ny - 1) == clay);   // top-left pixel (row 0): the mirrored top row
    CHECK(di.getMaterial(6, ny - 1) == sand);   // top-right
    CHECK(di.getMaterial(3, 1) == sand);
    CHECK(di.getMaterial(4, 1) == clay);
    CHECK(di.getDeformability(0, 0) == 2.0);
    CHECK(di.getParticleAdhesion(6, 0) == 0.2);
    CHECK(di.getAngleOfRepose(6, 0) == 0.3);
    // Removing clay unmaps its vertices (back to the geometry's material, d = 0); sand stays.
    CHECK(di.remove(clay));
    CHECK_FALSE(di.remove(clay));
    CHECK(di.getMaterial(6, 0) == ground);
    CHECK(di.getDeformability(6, 0) == 0);
    CHECK(di.getMaterial(0, 0) == sand);
    CHECK(t->getVolumeLedger().total() == 0);  // a flat field at height 0: nothing in the ledger
    std::remove(path.c_str());
  }

  TEST_CASE("contacts take the parameters of the vertex material under them") {
    // A ball on the left half (sand, explicit contact material E = 2e5) and one on the right half (clay, 5e4):
    // each rests m g / E deep with its own material's E; both materials are non-deformable (m = 1).
    TestWorld w;
    TerrainRef t = addFlatTerrain(w, 21, 4.0);
    TerrainDataInterface& di = t->getDataInterface();
    auto sand = std::make_shared<Material>("sand");
    auto clay = std::make_shared<Material>("clay");
    w.sim->getMaterialManager().getOrCreateContactMaterial(w.material, sand)->setYoungsModulus(2e5);
    w.sim->getMaterialManager().getOrCreateContactMaterial(w.material, clay)->setYoungsModulus(5e4);
    di.add(sand, 1);
    di.add(clay, 2);
    for (size_t y = 0; y < 21; ++y)
      for (size_t x = 0; x < 21; ++x) di.setMaterialMapping(x, y, x < 10 ? 1 : 2);
    auto a = w.addSphere(0.1, Vec3(-1.0, 0.3, 0.1), 2.0);
    auto b = w.addSphere(0.1, Vec3(1.0, -0.3, 0.1), 2.0);
    stepCheckingLedger(w, *t, 120);
    const Real da = 0.1 - a->getPosition().z(), db = 0.1 - b->getPosition().z();
    MESSAGE("sand ball " << da << " m deep (m g / E = " << 2 * 9.81 / 2e5 << "), clay ball " << db << " m ("
                         << 2 * 9.81 / 5e4 << ")");
    // 2 %: SPOOK at rest gives exactly m g / E; 2 s of damped settling as in test_analytic_heightfield.
    CHECK(std::abs(da - 2 * 9.81 / 2e5) <= 0.02 * 2 * 9.81 / 2e5);
    CHECK(std::abs(db - 2 * 9.81 / 5e4) <= 0.02 * 2 * 9.81 / 5e4);
  }
}

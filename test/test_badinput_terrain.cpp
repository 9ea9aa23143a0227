// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Terrain bad input: every rejected call throws std::invalid_argument with a message naming the problem, and
// leaves the terrain unchanged (material map, compression, multipliers, parameters, heights and the ledger).
#include <doctest/doctest.h>

#include <cstdio>
#include <filesystem>
#include <limits>
#include <tuple>
#include <vector>

#include "png_test_files.h"
#include "terrain_world.h"

using namespace scree;
using namespace scree::test;

namespace {

constexpr Real kNaN = std::numeric_limits<Real>::quiet_NaN();

/// Everything a rejected call must leave alone.
struct Snapshot {
  std::vector<size_t> index;
  std::vector<Real> compression, multiplier, heights;
  Real M, D, maxChange, p0, ledgerTotal, ledgerHeightField;
  std::vector<MaterialRef> materials;
  explicit Snapshot(const Terrain& t) {
    const TerrainDataInterface& di = t.getDataInterface();
    for (size_t y = 0; y < di.getResolutionY(); ++y)
      for (size_t x = 0; x < di.getResolutionX(); ++x) {
        index.push_back(di.getMaterialIndex(x, y));
        compression.push_back(di.getCompression(x, y));
        multiplier.push_back(di.getYoungsModulusMultiplier(x, y));
        materials.push_back(di.getMaterial(x, y));
      }
    heights = t.getHeightField()->getHeights();
    M = di.getMaxCompressionMultiplier();
    D = di.getDepthForMaxCompression();
    maxChange = di.getMaxYoungsChangePerTimestep();
    p0 = di.getYieldPressure();
    ledgerTotal = t.getVolumeLedger().total();
    ledgerHeightField = t.getVolumeLedger().heightField;
  }
  bool operator==(const Snapshot& o) const {
    return index == o.index && compression == o.compression && multiplier == o.multiplier && heights == o.heights &&
           M == o.M && D == o.D && maxChange == o.maxChange && p0 == o.p0 && ledgerTotal == o.ledgerTotal &&
           ledgerHeightField == o.ledgerHeightField && materials == o.materials;
  }
};

std::string tempPath(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("scree_terrain_bad_" + name)).string();
}

#define CHECK_REJECTED(call, text)                                                   \
  do {                                                                               \
    const Snapshot before(*t);                                                       \
    CHECK_THROWS_WITH_AS(call, doctest::Contains(text), std::invalid_argument);     \
    CHECK(Snapshot(*t) == before);                                                   \
  } while (0)

}  // namespace

TEST_SUITE("terrain bad input") {
  TEST_CASE("material map files: missing, not a PNG, truncated, wrong size, unsupported format") {
    TestWorld w;
    TerrainRef t = addFlatTerrain(w, 6, 5.0);  // 6 x 6 vertices
    TerrainDataInterface& di = t->getDataInterface();
    auto sand = std::make_shared<Material>("sand");
    di.add(sand, 1, 0.0, 1.0);
    di.setMaterialMapping(2, 3, 1);
    di.setCompression(2, 3, 0.5);
    // A good map for reference: it loads.
    std::vector<std::vector<uint8_t>> good(6, std::vector<uint8_t>(6, 1));
    const std::string okPath = tempPath("ok.png");
    writeBytes(okPath, makeIndexPng(good));

    CHECK_REJECTED(di.setMaterialMapping(tempPath("does_not_exist.png")), "no such file");
    const std::string text = tempPath("text.png");
    writeBytes(text, std::vector<uint8_t>{'h', 'e', 'l', 'l', 'o', ' ', 'p', 'n', 'g', '\n'});
    CHECK_REJECTED(di.setMaterialMapping(text), "not a PNG");
    const std::vector<uint8_t> bytes = makeIndexPng(good);
    const std::string truncated = tempPath("truncated.png");
    writeBytes(truncated, std::vector<uint8_t>(bytes.begin(), bytes.begin() + std::ptrdiff_t(bytes.size() / 2)));
    CHECK_REJECTED(di.setMaterialMapping(truncated), "truncated");
    const std::string small = tempPath("small.png");
    writeBytes(small, makeIndexPng(std::vector<std::vector<uint8_t>>(5, std::vector<uint8_t>(6, 1))));
    CHECK_REJECTED(di.setMaterialMapping(small), "must match the height-field resolution 6 x 6");
    const std::string transposed = tempPath("transposed.png");
    writeBytes(transposed, makeIndexPng(std::vector<std::vector<uint8_t>>(6, std::vector<uint8_t>(7, 1))));
    CHECK_REJECTED(di.setMaterialMapping(transposed), "7 x 6 pixels");
    // 16-bit grey: samples are not indices 0..255.
    const std::string deep = tempPath("gray16.png");
    writeBytes(deep, makePng(6, 6, 16, 0, std::vector<std::vector<uint8_t>>(6, std::vector<uint8_t>(12, 0))));
    CHECK_REJECTED(di.setMaterialMapping(deep), "unsupported");
    // RGB with coloured pixels: not an index map.
    std::vector<std::vector<uint8_t>> rgb(6, std::vector<uint8_t>(18, 0));
    rgb[0][0] = 255;
    const std::string colour = tempPath("rgb.png");
    writeBytes(colour, makePng(6, 6, 8, 2, rgb));
    CHECK_THROWS_AS(di.setMaterialMapping(colour), std::invalid_argument);
    CHECK_NOTHROW(di.setMaterialMapping(okPath));
    CHECK(di.getMaterial(0, 0) == sand);
    for (const auto& p : {okPath, text, truncated, small, transposed, deep, colour}) std::remove(p.c_str());
  }

  TEST_CASE("data interface setters reject bad values and leave the terrain unchanged") {
    TestWorld w;
    TerrainRef t = addFlatTerrain(w, 6, 5.0);
    TerrainDataInterface& di = t->getDataInterface();
    auto sand = std::make_shared<Material>("sand");
    di.add(sand, 1, 0.0, 1.0);
    di.setMaterialMapping(1, 1, 1);
    t->pressVertex(1, 1, 0.05);
    CHECK(t->getVolumeLedger().compressed > 0);

    CHECK_REJECTED(di.setMaterialMapping(1, 1, 256), "materialIndex = 256");
    CHECK_REJECTED(di.setMaterialMapping(6, 1, 1), "x = 6");
    CHECK_REJECTED(di.setMaterialMapping(1, 6, 1), "y = 6");
    CHECK_REJECTED(di.add(sand, 256), "materialIndex = 256");
    CHECK_REJECTED(di.add(nullptr, 2), "material = null");
    CHECK_REJECTED(di.add(sand, 2, -1.0), "particleAdhesion = -1");
    CHECK_REJECTED(di.add(sand, 2, 0.0, -0.5), "deformability = -0.5");
    CHECK_REJECTED(di.add(sand, 2, kNaN), "particleAdhesion = nan");
    CHECK_REJECTED(di.add(sand, 2, 0.0, kNaN), "deformability = nan");
    CHECK_REJECTED(di.add(sand, 2, 0.0, 1.0, kNaN), "angleOfRepose = nan");
    CHECK_REJECTED(di.add(sand, 2, 0.0, 1.0, 2.0), "angleOfRepose = 2");
    CHECK_REJECTED(di.setMaxCompressionMultiplier(0.5), "multiplier = 0.5");
    CHECK_REJECTED(di.setMaxCompressionMultiplier(-4), "must be finite and >= 1");
    CHECK_REJECTED(di.setMaxCompressionMultiplier(6), "must be a power of two");
    CHECK_REJECTED(di.setMaxCompressionMultiplier(kNaN), "multiplier = nan");
    CHECK_REJECTED(di.setMaxCompressionMultiplier(std::numeric_limits<Real>::infinity()), "multiplier = inf");
    CHECK_REJECTED(di.setDepthForMaxCompression(0), "depth = 0");
    CHECK_REJECTED(di.setDepthForMaxCompression(-0.1), "depth = -0.1");
    CHECK_REJECTED(di.setDepthForMaxCompression(kNaN), "depth = nan");
    CHECK_REJECTED(di.setMaxYoungsChangePerTimestep(-1), "maxMultiplierChange = -1");
    CHECK_REJECTED(di.setMaxYoungsChangePerTimestep(kNaN), "maxMultiplierChange = nan");
    CHECK_REJECTED(di.setYieldPressure(0), "pressure = 0");
    CHECK_REJECTED(di.setYieldPressure(kNaN), "pressure = nan");
    CHECK_REJECTED(di.setCompression(1, 1, -0.1), "compression = -0.1");
    CHECK_REJECTED(di.setCompression(1, 1, kNaN), "compression = nan");
    CHECK_REJECTED(di.setCompression(9, 1, 0.1), "x = 9");
    CHECK_REJECTED(di.getCompression(1, 9), "y = 9");
    CHECK_REJECTED(di.getYoungsModulusMultiplier(6, 0), "x = 6");
    CHECK_REJECTED(di.getMaterial(0, 6), "y = 6");
    CHECK_REJECTED(t->pressVertex(1, 1, -0.01), "depth = -0.01");
    CHECK_REJECTED(t->pressVertex(1, 1, kNaN), "depth = nan");
    CHECK_REJECTED(t->pressVertex(6, 1, 0.01), "x = 6");
    CHECK_REJECTED(t->setDataInterface(nullptr), "dataInterface = null");
    // Accepted edge values.
    CHECK_NOTHROW(di.setMaxCompressionMultiplier(1));
    CHECK_NOTHROW(di.setMaxCompressionMultiplier(1024));
    CHECK_NOTHROW(di.setMaxYoungsChangePerTimestep(0));
    CHECK_NOTHROW(di.setMaxYoungsChangePerTimestep(std::numeric_limits<Real>::infinity()));
    CHECK(t->getVolumeLedger().total() == doctest::Approx(t->computeHeightFieldVolume() +
                                                          t->getVolumeLedger().compressed));
  }
  TEST_CASE("avalanche settings reject bad values and leave the terrain and the settings unchanged") {
    TestWorld w;
    TerrainRef t = addFlatTerrain(w, 6, 5.0);
    t->setEnableDynamicHeightField(true);
    t->setAvalancheStepLifeTime(7);
    t->setAvalancheDecayPercent(0.3);
    t->setAvalancheVertexDistanceExtent(1);
    t->setWetnessScale(0.4);
    t->getHeightField()->setHeight(2, 2, 3.0);
    t->armAvalanche(2, 2);
    const size_t armed = t->getNumArmedVertices();
    auto settingsUnchanged = [&] {
      CHECK(t->getAvalancheStepLifeTime() == 7);
      CHECK(t->getAvalancheDecayPercent() == 0.3);
      CHECK(t->getAvalancheVertexDistanceExtent() == 1);
      CHECK(t->getWetnessScale() == 0.4);
      CHECK(t->getEnableDynamicHeightField());
      CHECK(t->getNumArmedVertices() == armed);
      CHECK(t->getAvalancheStepsLeft(2, 2) == 7);
    };
    CHECK_REJECTED(t->setAvalancheDecayPercent(0.51), "decayScale = 0.51");
    CHECK_REJECTED(t->setAvalancheDecayPercent(-0.01), "decayScale = -0.01");
    CHECK_REJECTED(t->setAvalancheDecayPercent(kNaN), "decayScale = nan");
    CHECK_REJECTED(t->setAvalancheDecayPercent(std::numeric_limits<Real>::infinity()), "decayScale = inf");
    CHECK_REJECTED(t->setWetnessScale(1.5), "scale = 1.5");
    CHECK_REJECTED(t->setWetnessScale(-0.1), "scale = -0.1");
    CHECK_REJECTED(t->setWetnessScale(kNaN), "scale = nan");
    CHECK_REJECTED(t->setAvalancheStepLifeTime(-1), "numSteps = -1");
    CHECK_REJECTED(t->setAvalancheVertexDistanceExtent(-2), "numVertices = -2");
    CHECK_REJECTED(t->setAvalanceVertexDistanceExtent(-1), "numVertices = -1");  // the manual's spelling
    CHECK_REJECTED(t->armAvalanche(6, 0), "x = 6");
    CHECK_REJECTED(t->armAvalanche(0, 6), "y = 6");
    CHECK_REJECTED(t->computeAngleOfRepose(7, 0), "x = 7");
    CHECK_REJECTED(t->getAvalancheStepsLeft(0, 9), "y = 9");
    CHECK_REJECTED(t->avalancheAll(0), "maxIterations = 0");
    settingsUnchanged();
    // Accepted edge values.
    CHECK_NOTHROW(t->setAvalancheDecayPercent(0));
    CHECK_NOTHROW(t->setAvalancheDecayPercent(0.5));
    CHECK_NOTHROW(t->setWetnessScale(0));
    CHECK_NOTHROW(t->setWetnessScale(1));
    CHECK_NOTHROW(t->setAvalancheStepLifeTime(0));
    CHECK_NOTHROW(t->setAvalancheVertexDistanceExtent(0));
  }

  TEST_CASE("ground cutting force: negative or non-finite throws and leaves the value unchanged") {
    TestWorld w;
    TerrainRef t = addFlatTerrain(w, 6, 5.0);
    TerrainDataInterface& di = t->getDataInterface();
    CHECK(di.getShovelGroundCuttingForce() == 0);
    di.setShovelGroundCuttingForce(2.5);
    const Snapshot before(*t);
    CHECK_REJECTED(di.setShovelGroundCuttingForce(-1), "force = -1");
    CHECK_REJECTED(di.setShovelGroundCuttingForce(kNaN), "force = nan");
    CHECK_REJECTED(di.setShovelGroundCuttingForce(std::numeric_limits<Real>::infinity()), "force = inf");
    CHECK_REJECTED(di.setShovelGroundCuttingForce(-std::numeric_limits<Real>::infinity()), "force = -inf");
    CHECK(di.getShovelGroundCuttingForce() == 2.5);
    CHECK(Snapshot(*t) == before);
    CHECK_NOTHROW(di.setShovelGroundCuttingForce(0));
    CHECK(di.getShovelGroundCuttingForce() == 0);
  }

  TEST_CASE("particle contact materials: external material, Young's multiplier, particle solve type") {
    TestWorld w;
    TerrainRef t = addFlatTerrain(w, 6, 5.0);
    TerrainDataInterface& di = t->getDataInterface();
    TerrainParticleAttributes& pa = t->getParticleAttributes();
    auto steel = std::make_shared<Material>("steel");
    di.addExternalMaterial(steel);
    di.setInverseFrictionMultiplier(0.5);
    pa.setParticleYoungsModulusMultiplier(3);
    // Everything these setters own, checked unchanged after each rejected call (with the terrain Snapshot).
    auto state = [&] {
      return std::make_tuple(di.getExternalMaterials(), di.getParticleFrictionSolveType(),
                             di.getInverseFrictionMultiplier(), pa.getParticleYoungsModulusMultiplier());
    };
    const auto before = state();
    CHECK_REJECTED(di.addExternalMaterial(nullptr), "material = null");
    CHECK_REJECTED(pa.setParticleYoungsModulusMultiplier(0), "multiplier = 0");
    CHECK_REJECTED(pa.setParticleYoungsModulusMultiplier(-2), "multiplier = -2");
    CHECK_REJECTED(pa.setParticleYoungsModulusMultiplier(kNaN), "multiplier = nan");
    CHECK_REJECTED(pa.setParticleYoungsModulusMultiplier(std::numeric_limits<Real>::infinity()), "multiplier = inf");
    CHECK_REJECTED(di.setInverseFrictionMultiplier(-0.1), "inverseMultiplier = -0.1");
    CHECK_REJECTED(di.setInverseFrictionMultiplier(kNaN), "inverseMultiplier = nan");
    CHECK_REJECTED(di.setInverseFrictionMultiplier(std::numeric_limits<Real>::infinity()), "inverseMultiplier = inf");
    CHECK_REJECTED(di.setParticleFrictionSolveType(FrictionModel::SPLIT), "solveType = 3");
    CHECK_REJECTED(di.setParticleFrictionSolveType(FrictionModel::DIRECT_AND_ITERATIVE), "solveType = 2");
    CHECK_REJECTED(di.setParticleFrictionSolveType(FrictionModel::SolveType(7)), "solveType = 7");
    CHECK(state() == before);
    // Accepted edge values; removing an unknown material is not an error.
    CHECK_NOTHROW(di.setInverseFrictionMultiplier(0));
    CHECK_NOTHROW(di.setParticleFrictionSolveType(FrictionModel::DIRECT));
    CHECK_NOTHROW(pa.setParticleYoungsModulusMultiplier(1e-6));
    CHECK_FALSE(di.removeExternalMaterial(nullptr));
    CHECK_FALSE(di.removeExternalMaterial(std::make_shared<Material>("other")));
    CHECK(di.removeExternalMaterial(steel));
    CHECK(di.getExternalMaterials().empty());
  }

  TEST_CASE("deformer settings reject negative scalers and cut-offs and NaN, and leave the settings unchanged") {
    TestWorld w;
    TerrainRef t = addFlatTerrain(w, 6, 5.0);
    t->setEnableDynamicHeightField(true);
    t->setVerticalYoungsModulusAreaScaler(0.02);
    t->setHorizontalYoungsModulusAreaScaler(0.003);
    t->setDynamicHeightFieldCutOffVelocity(0.2);
    t->setDynamicHeightFieldCutOffAngularVelocity(0.3);
    const Snapshot snap(*t);
    auto settingsUnchanged = [&] {
      CHECK(t->getVerticalYoungsModulusAreaScaler() == 0.02);
      CHECK(t->getHorizontalYoungsModulusAreaScaler() == 0.003);
      CHECK(t->getDynamicHeightFieldCutOffVelocity() == 0.2);
      CHECK(t->getDynamicHeightFieldCutOffAngularVelocity() == 0.3);
      CHECK(Snapshot(*t) == snap);
    };
    CHECK_REJECTED(t->setVerticalYoungsModulusAreaScaler(-0.01), "scale = -0.01");
    CHECK_REJECTED(t->setVerticalYoungsModulusAreaScaler(0), "scale = 0");
    CHECK_REJECTED(t->setVerticalYoungsModulusAreaScaler(kNaN), "scale = nan");
    CHECK_REJECTED(t->setVerticalYoungsModulusAreaScaler(std::numeric_limits<Real>::infinity()), "scale = inf");
    CHECK_REJECTED(t->setHorizontalYoungsModulusAreaScaler(-1), "scale = -1");
    CHECK_REJECTED(t->setHorizontalYoungsModulusAreaScaler(kNaN), "scale = nan");
    CHECK_REJECTED(t->setDynamicHeightFieldCutOffVelocity(-0.5), "cutOffVelocity = -0.5");
    CHECK_REJECTED(t->setDynamicHeightFieldCutOffVelocity(kNaN), "cutOffVelocity = nan");
    CHECK_REJECTED(t->setDynamicHeightFieldCutOffAngularVelocity(-2), "cutOffAngularVelocity = -2");
    CHECK_REJECTED(t->setDynamicHeightFieldCutOffAngularVelocity(kNaN), "cutOffAngularVelocity = nan");
    settingsUnchanged();
    // Accepted edge values: a zero cut-off (always deform while moving).
    CHECK_NOTHROW(t->setDynamicHeightFieldCutOffVelocity(0));
    CHECK_NOTHROW(t->setDynamicHeightFieldCutOffAngularVelocity(0));
  }
}

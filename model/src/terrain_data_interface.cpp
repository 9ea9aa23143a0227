// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// TerrainDataInterface: per-vertex material index, compression and multiplier, and the compression parameters.
#include "scree/model/terrain_data_interface.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "scree/core/errors.h"
#include "scree/model/terrain.h"
#include "scree/solver/simulation.h"

#include "png_index_map.h"

namespace scree {

namespace {
constexpr const char* kClass = "TerrainDataInterface::";
std::string where(const char* fn) { return std::string(kClass) + fn; }
}  // namespace

TerrainDataInterface::TerrainDataInterface(const Terrain& terrain)
    : terrain_(terrain),
      nx_(terrain.getHeightField()->getResolutionX()),
      ny_(terrain.getHeightField()->getResolutionY()),
      index_(nx_ * ny_, 0),
      compression_(nx_ * ny_, 0.0),
      multiplier_(nx_ * ny_, 1.0) {}

void TerrainDataInterface::checkVertex(const char* fn, size_t x, size_t y) const {
  if (x >= nx_)
    detail::throwInvalid(where(fn), "x", (long long)x, "must be < resolutionX = " + std::to_string(nx_));
  if (y >= ny_)
    detail::throwInvalid(where(fn), "y", (long long)y, "must be < resolutionY = " + std::to_string(ny_));
}

Real TerrainDataInterface::multiplier(Real c, Real d, Real M) {
  if (!(d > 0) || !(M > 1)) return 1;  // non-deformable: the manual's "can't become harder" (terrain.h)
  return std::min(std::exp2((d + 1) * c), M);
}

void TerrainDataInterface::refreshMultipliers() {
  for (size_t v = 0; v < multiplier_.size(); ++v)
    multiplier_[v] = multiplier(compression_[v], deformabilityOf(v), maxMultiplier_);
}

MaterialRef TerrainDataInterface::defaultMaterial() const { return terrain_.defaultMaterial(); }

// --- material map ----------------------------------------------------------------------------------------------

void TerrainDataInterface::setMaterialMapping(const std::string& filePath) {
  // Read and check everything before touching the map, so a bad file leaves it unchanged.
  const detail::PngIndexMap img = detail::readPngIndexMap(filePath);
  if (img.width != nx_ || img.height != ny_)
    throw std::invalid_argument(where("setMaterialMapping") + ": \"" + filePath + "\" is " +
                                std::to_string(img.width) + " x " + std::to_string(img.height) +
                                " pixels; the material map must match the height-field resolution " +
                                std::to_string(nx_) + " x " + std::to_string(ny_));
  // Image row 0 is the top of the picture = the highest y; image column = x.
  for (size_t y = 0; y < ny_; ++y) {
    const size_t row = ny_ - 1 - y;
    std::copy_n(img.index.begin() + std::ptrdiff_t(row * nx_), nx_, index_.begin() + std::ptrdiff_t(y * nx_));
  }
  refreshMultipliers();
}

void TerrainDataInterface::setMaterialMapping(size_t x, size_t y, size_t materialIndex) {
  checkVertex("setMaterialMapping", x, y);
  if (materialIndex >= kNumMaterialIndices)
    detail::throwInvalid(where("setMaterialMapping"), "materialIndex", (long long)materialIndex, "must be < 256");
  const size_t v = vertex(x, y);
  index_[v] = uint8_t(materialIndex);
  multiplier_[v] = multiplier(compression_[v], deformabilityOf(v), maxMultiplier_);
}

size_t TerrainDataInterface::getMaterialIndex(size_t x, size_t y) const {
  checkVertex("getMaterialIndex", x, y);
  return index_[vertex(x, y)];
}

void TerrainDataInterface::add(MaterialRef material, size_t materialIndex, Real particleAdhesion,
                               Real deformability, Real angleOfRepose) {
  const std::string w = where("add");
  detail::requireNonNull(w, "material", material.get());
  if (materialIndex >= kNumMaterialIndices)
    detail::throwInvalid(w, "materialIndex", (long long)materialIndex, "must be < 256");
  detail::requireNonNegative(w, "particleAdhesion", particleAdhesion);
  detail::requireNonNegative(w, "deformability", deformability);
  if (!(std::isfinite(angleOfRepose) && angleOfRepose >= 0 && angleOfRepose < 0.5 * M_PI))
    detail::throwInvalid(w, "angleOfRepose", angleOfRepose, "must be in [0, pi/2) rad; 0 = atan(friction)");
  Entry& e = entries_[materialIndex];
  e.material = std::move(material);
  e.particleAdhesion = particleAdhesion;
  e.deformability = deformability;
  e.angleOfRepose = angleOfRepose;
  refreshMultipliers();
}

bool TerrainDataInterface::remove(const MaterialRef& material) {
  if (!material) return false;
  bool found = false;
  for (Entry& e : entries_)
    if (e.material == material) {
      e = Entry{};
      found = true;
    }
  if (found) refreshMultipliers();
  return found;
}

MaterialRef TerrainDataInterface::getMaterial(size_t x, size_t y) const {
  checkVertex("getMaterial", x, y);
  const Entry& e = entries_[index_[vertex(x, y)]];
  return e.material ? e.material : defaultMaterial();
}

MaterialRef TerrainDataInterface::getParticleMaterial(size_t x, size_t y) const {
  checkVertex("getParticleMaterial", x, y);
  return getMaterial(x, y);
}

Real TerrainDataInterface::getDeformability(size_t x, size_t y) const {
  checkVertex("getDeformability", x, y);
  return deformabilityOf(vertex(x, y));
}

Real TerrainDataInterface::getParticleAdhesion(size_t x, size_t y) const {
  checkVertex("getParticleAdhesion", x, y);
  return entries_[index_[vertex(x, y)]].particleAdhesion;
}

Real TerrainDataInterface::getAngleOfRepose(size_t x, size_t y) const {
  checkVertex("getAngleOfRepose", x, y);
  return entries_[index_[vertex(x, y)]].angleOfRepose;
}

// --- compression -----------------------------------------------------------------------------------------------

Real TerrainDataInterface::getCompression(size_t x, size_t y) const {
  checkVertex("getCompression", x, y);
  return compression_[vertex(x, y)];
}

void TerrainDataInterface::setCompression(size_t x, size_t y, Real c) {
  checkVertex("setCompression", x, y);
  detail::requireNonNegative(where("setCompression"), "compression", c);
  const size_t v = vertex(x, y);
  compression_[v] = c;
  multiplier_[v] = multiplier(c, deformabilityOf(v), maxMultiplier_);
}

Real TerrainDataInterface::getYoungsModulusMultiplier(size_t x, size_t y) const {
  checkVertex("getYoungsModulusMultiplier", x, y);
  return multiplier_[vertex(x, y)];
}

Real TerrainDataInterface::getMaxCompression(size_t x, size_t y) const {
  checkVertex("getMaxCompression", x, y);
  const Real d = deformabilityOf(vertex(x, y));
  return d > 0 ? std::log2(maxMultiplier_) / (d + 1) : 0;
}

void TerrainDataInterface::setMaxCompressionMultiplier(Real M) {
  const std::string w = where("setMaxCompressionMultiplier");
  if (!(std::isfinite(M) && M >= 1)) detail::throwInvalid(w, "multiplier", M, "must be finite and >= 1");
  int e = 0;
  if (std::frexp(M, &e) != 0.5) detail::throwInvalid(w, "multiplier", M, "must be a power of two (1, 2, 4, 8, ...)");
  maxMultiplier_ = M;
  refreshMultipliers();
}

void TerrainDataInterface::setDepthForMaxCompression(Real depth) {
  detail::requirePositive(where("setDepthForMaxCompression"), "depth", depth);
  depthForMax_ = depth;
}

void TerrainDataInterface::setMaxYoungsChangePerTimestep(Real maxMultiplierChange) {
  detail::requireNonNegativeOrInf(where("setMaxYoungsChangePerTimestep"), "maxMultiplierChange",
                                  maxMultiplierChange);
  maxChange_ = maxMultiplierChange;
}

void TerrainDataInterface::setYieldPressure(Real pressure) {
  detail::requirePositive(where("setYieldPressure"), "pressure", pressure);
  yieldPressure_ = pressure;
}

}  // namespace scree

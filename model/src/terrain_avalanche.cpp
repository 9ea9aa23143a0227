// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Terrain avalanches (manual 25.1.2.15, 25.1.2.19, 25.1.2.20): arming, the per-step pass over the armed
// vertices, avalancheAll, the angle of repose with wetness. The rules and why are in terrain.h's file comment
// ("Dynamic height field: avalanches and the angle of repose"); every move goes through the volume ledger.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <numeric>
#include <string>

#include "scree/core/errors.h"
#include "scree/model/terrain.h"
#include "scree/solver/simulation.h"

namespace scree {

namespace {
constexpr Real kHalfPi = 1.57079632679489661923;
using Clock = std::chrono::steady_clock;

/// The angle of repose of a vertex material, before wetness: the set angle or atan(friction).
Real dryAngle(Real setAngle, const Material* material) {
  if (setAngle > 0) return setAngle;
  const Real mu = material ? material->getFrictionCoefficient() : SurfaceParameters{}.getFrictionCoefficient();
  return std::atan(mu);
}

/// Per pass: the dry angle and its tangent of each material index, computed on first use.
struct DryAngleCache {
  Real angle[TerrainDataInterface::kNumMaterialIndices];
  Real tangent[TerrainDataInterface::kNumMaterialIndices];
  bool valid[TerrainDataInterface::kNumMaterialIndices] = {};
};
thread_local DryAngleCache* tCache = nullptr;
}  // namespace

// Height edits are batched by cluster (as compression does in terrain.cpp): a batch closes when an edit lies more
// than two tiles from it, so two far-apart avalanches do not update the bounds of everything between them.
class Terrain::EditBatch {
 public:
  explicit EditBatch(HeightField& hf) : hf_(hf) {}
  ~EditBatch() { close(); }
  void touch(size_t x, size_t y) {
    constexpr size_t span = 2 * HeightField::kTileSize;
    if (open_ && (std::max(r_.i1, x) - std::min(r_.i0, x) > span || std::max(r_.j1, y) - std::min(r_.j0, y) > span))
      close();
    if (!open_) {
      hf_.beginHeightEdit();
      r_ = HeightField::Rect{x, y, x, y};
      open_ = true;
    }
    r_.i0 = std::min(r_.i0, x), r_.i1 = std::max(r_.i1, x);
    r_.j0 = std::min(r_.j0, y), r_.j1 = std::max(r_.j1, y);
  }
  void close() {
    if (open_) hf_.endHeightEdit();
    open_ = false;
  }

 private:
  HeightField& hf_;
  HeightField::Rect r_;
  bool open_ = false;
};

// ---- settings -------------------------------------------------------------------------------------------------
void Terrain::setEnableDynamicHeightField(bool enable) {
  dynamicHeightField_ = enable;
  if (!enable) {
    for (size_t v : armed_) life_[v] = 0, inList_[v] = 0;
    armed_.clear();
  }
}

void Terrain::setAvalancheStepLifeTime(int numSteps) {
  if (numSteps < 0)
    detail::throwInvalid("Terrain::setAvalancheStepLifeTime", "numSteps", (long long)numSteps, "must be >= 0");
  avalancheLifeTime_ = numSteps;
}

void Terrain::setAvalancheDecayPercent(Real decay) {
  detail::requireInRange("Terrain::setAvalancheDecayPercent", "decayScale", decay, 0, 0.5);
  avalancheDecay_ = decay;
}

void Terrain::setAvalancheVertexDistanceExtent(int numVertices) {
  if (numVertices < 0)
    detail::throwInvalid("Terrain::setAvalancheVertexDistanceExtent", "numVertices", (long long)numVertices,
                         "must be >= 0");
  avalancheExtent_ = numVertices;
}

void Terrain::setWetnessScale(Real scale) {
  detail::requireInRange("Terrain::setWetnessScale", "scale", scale, 0, 1);
  wetness_ = scale;
}

// ---- the angle of repose --------------------------------------------------------------------------------------
Real Terrain::reposeAngle(size_t v) const {
  const TerrainDataInterface& di = *data_;
  const uint8_t index = di.index_[v];
  const TerrainDataInterface::Entry& e = di.entries_[index];
  Real theta;
  if (tCache && tCache->valid[index]) {
    theta = tCache->angle[index];
  } else {
    theta = dryAngle(e.angleOfRepose, e.material ? e.material.get() : defaultMaterial().get());
    if (tCache) {
      tCache->angle[index] = theta;
      tCache->tangent[index] = std::tan(theta);
      tCache->valid[index] = true;
    }
  }
  const Real M = di.maxMultiplier_;
  if (wetness_ > 0 && e.deformability > 0 && M > 1) {
    // theta(c) = theta0 + w (c / c_max) (pi/2 - theta0) / 2 (terrain.h).
    const Real cMax = std::log2(M) / (e.deformability + 1);
    const Real r = std::clamp<Real>(di.compression_[v] / cMax, 0, 1);
    theta += wetness_ * r * (kHalfPi - theta) / 2;
  }
  return theta;
}

Real Terrain::reposeTangent(size_t v) const {
  const TerrainDataInterface& di = *data_;
  const TerrainDataInterface::Entry& e = di.entries_[di.index_[v]];
  const bool wet = wetness_ > 0 && e.deformability > 0 && di.maxMultiplier_ > 1 && di.compression_[v] > 0;
  if (!wet && tCache) {
    const uint8_t index = di.index_[v];
    if (!tCache->valid[index]) reposeAngle(v);  // fills the cache
    return tCache->tangent[index];
  }
  return std::tan(reposeAngle(v));
}

Real Terrain::computeAngleOfRepose(size_t x, size_t y) const {
  constexpr const char* where = "Terrain::computeAngleOfRepose";
  if (x >= nx_) detail::throwInvalid(where, "x", (long long)x, "must be < resolutionX = " + std::to_string(nx_));
  if (y >= ny_) detail::throwInvalid(where, "y", (long long)y, "must be < resolutionY = " + std::to_string(ny_));
  return reposeAngle(y * nx_ + x);
}

// ---- arming ---------------------------------------------------------------------------------------------------
void Terrain::arm(size_t v, int life) {
  if (life_[v] < life) life_[v] = life;
  if (!inList_[v]) {
    inList_[v] = 1;
    armed_.push_back(v);
  }
}

void Terrain::armWithExtent(size_t v, int life) {
  if (life_.empty()) {
    life_.assign(nx_ * ny_, 0);
    inList_.assign(nx_ * ny_, 0);
  }
  const size_t x = v % nx_, y = v / nx_, e = size_t(avalancheExtent_);
  const size_t i0 = x > e ? x - e : 0, i1 = std::min(nx_ - 1, x + e);
  const size_t j0 = y > e ? y - e : 0, j1 = std::min(ny_ - 1, y + e);
  for (size_t j = j0; j <= j1; ++j)
    for (size_t i = i0; i <= i1; ++i) arm(j * nx_ + i, life);
}

void Terrain::armAvalancheAt(const size_t (&v)[3]) {
  if (!dynamicHeightField_ || avalancheLifeTime_ <= 0) return;
  for (size_t q : v) armWithExtent(q, avalancheLifeTime_);
}

size_t Terrain::armAvalanche(size_t x, size_t y) {
  constexpr const char* where = "Terrain::armAvalanche";
  if (x >= nx_) detail::throwInvalid(where, "x", (long long)x, "must be < resolutionX = " + std::to_string(nx_));
  if (y >= ny_) detail::throwInvalid(where, "y", (long long)y, "must be < resolutionY = " + std::to_string(ny_));
  if (!dynamicHeightField_ || avalancheLifeTime_ <= 0) return 0;
  armWithExtent(y * nx_ + x, avalancheLifeTime_);
  const size_t e = size_t(avalancheExtent_);
  return (std::min(nx_ - 1, x + e) - (x > e ? x - e : 0) + 1) * (std::min(ny_ - 1, y + e) - (y > e ? y - e : 0) + 1);
}

int Terrain::getAvalancheStepsLeft(size_t x, size_t y) const {
  constexpr const char* where = "Terrain::getAvalancheStepsLeft";
  if (x >= nx_) detail::throwInvalid(where, "x", (long long)x, "must be < resolutionX = " + std::to_string(nx_));
  if (y >= ny_) detail::throwInvalid(where, "y", (long long)y, "must be < resolutionY = " + std::to_string(ny_));
  return life_.empty() ? 0 : life_[y * nx_ + x];
}

// ---- one pair -------------------------------------------------------------------------------------------------
bool Terrain::relaxPair(size_t a, size_t b, Real ell, Real factor, TerrainAvalancheStats& stats) {
  const std::vector<Real>& h = heightField_->getHeights();
  size_t hi = a, lo = b;
  if (h[b] > h[a]) std::swap(hi, lo);
  const Real hHi = h[hi], hLo = h[lo];
  const Real excess = (hHi - hLo) - reposeTangent(hi) * ell;
  // Rounding tolerance: a pair within it is at repose (so that relaxation terminates, terrain.h).
  if (!(excess > 1e-12 * ell + 1e-14 * (std::abs(hHi) + std::abs(hLo)))) return false;
  const size_t xh = hi % nx_, yh = hi / nx_, xl = lo % nx_, yl = lo / nx_;
  if (lockedBorders_ && isBorderVertex(xh, yh)) return false;  // a locked border gives nothing
  const Real aHi = getVertexArea(xh, yh);
  if (lockedBorders_ && isBorderVertex(xl, yl)) {
    if (!avalancheMassLoss_) return false;  // held back by the border
    // Lost over the border: hi alone moves (decay 0.5: to repose against the fixed border height).
    const Real V = factor * excess * aHi;
    editBatch_->touch(xh, yh);
    heightField_->setHeight(xh, yh, hHi - V / aHi);
    ledger_.heightField -= V;
    ledger_.lostAtBorder += V;
    stats.volumeLost += V;
    ++stats.moves;
    return true;
  }
  const Real aLo = getVertexArea(xl, yl);
  const Real V = factor * excess * aHi * aLo / (aHi + aLo);
  const Real dzLo = V / aLo;
  editBatch_->touch(xh, yh);
  editBatch_->touch(xl, yl);
  heightField_->setHeight(xh, yh, hHi - V / aHi);
  heightField_->setHeight(xl, yl, hLo + dzLo);
  // Fresh loose soil on the receiver: c falls by the compression rule (not below 0); the giver keeps its c.
  TerrainDataInterface& di = *data_;
  const Real d = di.deformabilityOf(lo), M = di.maxMultiplier_;
  if (d > 0 && M > 1 && di.compression_[lo] > 0) {
    di.compression_[lo] = std::max<Real>(0, di.compression_[lo] - dzLo * std::log2(M) / di.depthForMax_);
    di.multiplier_[lo] = TerrainDataInterface::multiplier(di.compression_[lo], d, M);
  }
  stats.volumeMoved += V;
  ++stats.moves;
  return true;
}

// ---- the step's pass ------------------------------------------------------------------------------------------
namespace {
/// The 8 neighbours: offsets and which distance (0: dx, 1: dy, 2: diagonal).
constexpr int kNeighbour[8][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 1}, {0, -1, 1},
                                  {1, 1, 2}, {-1, -1, 2}, {1, -1, 2}, {-1, 1, 2}};
}  // namespace

void Terrain::avalancheStep() {
  avalancheStats_ = TerrainAvalancheStats{};
  lastAvalancheTime_ = 0;
  if (!dynamicHeightField_ || armed_.empty()) return;
  const auto t0 = Clock::now();
  DryAngleCache cache;
  tCache = &cache;
  const Real ell[3] = {dx_, dy_, std::hypot(dx_, dy_)};
  const Real factor = 2 * avalancheDecay_;
  EditBatch batch(*heightField_);
  editBatch_ = &batch;
  // inList_: 1 listed, 2 visited in this pass. A pair is relaxed once per pass, from the endpoint visited first.
  const size_t n0 = armed_.size();
  for (size_t i = 0; i < n0; ++i) {
    const size_t v = armed_[i];
    const int k = life_[v];
    inList_[v] = 2;
    if (k <= 0) continue;
    life_[v] = k - 1;
    ++avalancheStats_.visited;
    if (!(factor > 0)) continue;
    const long long x = (long long)(v % nx_), y = (long long)(v / nx_);
    for (const auto& nb : kNeighbour) {
      const long long xn = x + nb[0], yn = y + nb[1];
      if (xn < 0 || yn < 0 || xn >= (long long)nx_ || yn >= (long long)ny_) continue;
      const size_t n = size_t(yn) * nx_ + size_t(xn);
      if (inList_[n] == 2) continue;
      // Both vertices carry the avalanche on with the steps this one has left.
      if (relaxPair(v, n, ell[nb[2]], factor, avalancheStats_) && k > 1) arm(n, k - 1);
    }
  }
  batch.close();
  editBatch_ = nullptr;
  tCache = nullptr;
  size_t keep = 0;
  for (size_t v : armed_) {
    if (life_[v] > 0) {
      inList_[v] = 1;
      armed_[keep++] = v;
    } else {
      inList_[v] = 0;
    }
  }
  armed_.resize(keep);
  avalancheStats_.passes = 1;
  heightField_->clearDirtyRectangle();  // our edits are booked
  lastAvalancheTime_ = std::chrono::duration<double>(Clock::now() - t0).count();
}

// ---- the whole field ------------------------------------------------------------------------------------------
TerrainAvalancheStats Terrain::avalancheAll(int maxIterations) {
  if (maxIterations < 1)
    detail::throwInvalid("Terrain::avalancheAll", "maxIterations", (long long)maxIterations, "must be >= 1");
  reconcileExternalEdits();
  TerrainAvalancheStats stats;
  DryAngleCache cache;
  tCache = &cache;
  const Real ell[3] = {dx_, dy_, std::hypot(dx_, dy_)};
  std::vector<size_t> work(nx_ * ny_), next;
  std::iota(work.begin(), work.end(), size_t(0));
  // flag bit 1: listed for the next pass; bit 2: visited in this pass.
  std::vector<uint8_t> flag(nx_ * ny_, 0);
  EditBatch batch(*heightField_);
  editBatch_ = &batch;
  while (!work.empty() && stats.passes < size_t(maxIterations)) {
    ++stats.passes;
    for (size_t v : work) {
      flag[v] |= 2;
      ++stats.visited;
      const long long x = (long long)(v % nx_), y = (long long)(v / nx_);
      for (const auto& nb : kNeighbour) {
        const long long xn = x + nb[0], yn = y + nb[1];
        if (xn < 0 || yn < 0 || xn >= (long long)nx_ || yn >= (long long)ny_) continue;
        const size_t n = size_t(yn) * nx_ + size_t(xn);
        if (flag[n] & 2) continue;
        if (!relaxPair(v, n, ell[nb[2]], 1, stats)) continue;
        for (size_t u : {v, n})
          if (!(flag[u] & 1)) {
            flag[u] |= 1;
            next.push_back(u);
          }
      }
    }
    for (size_t v : work) flag[v] &= uint8_t(~2u);
    for (size_t v : next) flag[v] &= uint8_t(~1u);
    work.swap(next);
    next.clear();
  }
  stats.converged = work.empty();
  batch.close();
  editBatch_ = nullptr;
  tCache = nullptr;
  heightField_->clearDirtyRectangle();
  return stats;
}

}  // namespace scree

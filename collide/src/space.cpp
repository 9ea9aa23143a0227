// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Space: pair filtering, speculative AABBs, broadphase and narrowphase dispatch.
//
// Speculative margin per geometry (so fast bodies produce contacts before they tunnel):
//   margin = contactMargin + h (|v| + |w| r)
// with v, w the body's centre-of-mass linear and angular velocity and r the distance from the centre of mass
// to the farthest corner of the geometry's AABB — an upper bound on how far any point of the geometry moves
// in one step. Geometries without a body, or on a STATIC body, get contactMargin only. The pair's margin
// passed to the narrowphase is the sum of both.
//
// Non-dynamic pairs: two geometries neither of which is on a DYNAMICS body are skipped, except when one of
// them is a sensor and at least one of them is on a KINEMATICS body (a moving sensor sweeping static
// geometry, or a static sensor watching a kinematic body). Two fully static geometries never pair: their
// overlap cannot change.
#include "scree/collide/space.h"

#include <algorithm>
#include <cmath>

#include "scree/collide/narrowphase.h"
#include "scree/core/errors.h"

namespace scree {

void Space::add(GeometryRef g) {
  detail::requireNonNull("Space::add", "geometry", g.get());
  if (contains(g.get())) return;  // adding twice is a no-op
  geoms_.push_back(std::move(g));
}

bool Space::remove(const GeometryRef& g) {
  auto it = std::find(geoms_.begin(), geoms_.end(), g);
  if (it == geoms_.end()) return false;
  geoms_.erase(it);
  return true;
}

bool Space::contains(const Geometry* g) const {
  return std::any_of(geoms_.begin(), geoms_.end(), [g](const GeometryRef& r) { return r.get() == g; });
}

void Space::setEnablePair(uint32_t group1, uint32_t group2, bool enable) {
  if (enable) disabledGroups_.erase(pairKey(group1, group2));
  else disabledGroups_.insert(pairKey(group1, group2));
}

bool Space::getEnablePair(uint32_t group1, uint32_t group2) const {
  return disabledGroups_.count(pairKey(group1, group2)) == 0;
}

void Space::setEnableCollisions(const Geometry* a, const Geometry* b, bool enable) {
  detail::requireNonNull("Space::setEnableCollisions", "a", a);
  detail::requireNonNull("Space::setEnableCollisions", "b", b);
  if (enable) disabledGeoms_.erase(pairKey(a->getId(), b->getId()));
  else disabledGeoms_.insert(pairKey(a->getId(), b->getId()));
}

void Space::setEnableCollisions(const RigidBody* a, const RigidBody* b, bool enable) {
  detail::requireNonNull("Space::setEnableCollisions", "a", a);
  detail::requireNonNull("Space::setEnableCollisions", "b", b);
  if (enable) disabledBodies_.erase(pairKey(a->getId(), b->getId()));
  else disabledBodies_.insert(pairKey(a->getId(), b->getId()));
}

void Space::setContactMargin(Real m) {
  detail::requireNonNegative("Space::setContactMargin", "margin", m);
  margin_ = m;
}

bool Space::canCollide(const Geometry& a, const Geometry& b) const {
  if (&a == &b) return false;
  if (!a.getEnableCollisions() || !b.getEnableCollisions()) return false;
  const RigidBody* ba = a.getRigidBody();
  const RigidBody* bb = b.getRigidBody();
  if (ba && ba == bb) return false;
  const bool dynA = ba && ba->isDynamic(), dynB = bb && bb->isDynamic();
  if (!dynA && !dynB) {
    const bool sensor = a.isSensor() || b.isSensor();
    const bool moving = (ba && ba->getMotionControl() == RigidBody::KINEMATICS) ||
                        (bb && bb->getMotionControl() == RigidBody::KINEMATICS);
    if (!(sensor && moving)) return false;
  }
  if (!disabledGroups_.empty())
    for (uint32_t ga : a.getGroups())
      for (uint32_t gb : b.getGroups())
        if (disabledGroups_.count(pairKey(ga, gb))) return false;
  if (!disabledGeoms_.empty() && disabledGeoms_.count(pairKey(a.getId(), b.getId()))) return false;
  if (ba && bb && !disabledBodies_.empty() && disabledBodies_.count(pairKey(ba->getId(), bb->getId())))
    return false;
  return true;
}

void Space::collide(Real h, std::vector<GeometryContact>& out) {
  // The contacts of the last step are re-targeted in place, so their point buffers are reused: no per-contact
  // allocation in a steady scene.
  size_t used = 0;
  if (!(std::isfinite(h) && h >= 0)) h = 0;  // no exceptions inside the step; Simulation validates h
  const size_t n = geoms_.size();
  boxes_.resize(n);
  margins_.resize(n);

  // --- transforms, speculative AABBs ---------------------------------------------------------------------
  for (size_t i = 0; i < n; ++i) {
    Geometry& g = *geoms_[i];
    g.updateTransform();
    Aabb box = g.getBoundingBox();
    Real m = margin_;
    const RigidBody* b = g.getRigidBody();
    if (b && b->getMotionControl() != RigidBody::STATIC && h > 0) {
      const Vec3 c = b->getCmPosition();
      const Vec3 far = (box.lo - c).cwiseAbs().cwiseMax((box.hi - c).cwiseAbs());
      Real r = far.norm();
      if (!std::isfinite(r) || r > 1e290) r = 0;  // unbounded shapes (planes): no angular sweep term
      const Real sweep = h * (b->getVelocity().norm() + b->getAngularVelocity().norm() * r);
      if (std::isfinite(sweep)) m += sweep;
    }
    margins_[i] = m;
    box.inflate(m);
    boxes_[i] = box;
  }

  // --- broadphase ---------------------------------------------------------------------------------------
  grid_.findPairs(boxes_, pairs_);
  numPairs_ = pairs_.size();

  // --- filter and narrowphase -----------------------------------------------------------------------------
  // DESIGN (issue 18, parallel narrowphase; docs/solver-internals.md "Partitioned sweeps"): the candidate pairs
  // are cut into chunks of a fixed size (independent of the thread count); the threads share the chunks, each
  // chunk collects its touching pairs and their points in its own buffers (kept across steps: no allocation in
  // a steady scene), and the chunks are merged in order. Each pair's narrowphase reads only its two geometries
  // (transforms updated above), so the contacts -- and, after the sort below, their order -- are the same for
  // any thread count. Few pairs are not worth waking threads for; the result is the same either way.
  //
  // DESIGN (issue 18, fixed cost of small scenes; docs/benchmarks.md "Small scenes against Bullet"): without the
  // parallel option (or with too few chunks) the pairs are collided in the same order on the calling thread,
  // with no OpenMP region and no chunk buffers. An `omp parallel` region entered with `if (false)` still costs
  // libgomp a team allocation, a free and a futex wake, and the chunk buffers cost one more copy of every
  // contact point: together about 0.6 us of mass_ratio's 4.9 us step (its collide stage went 1.27 -> 0.68 us).
  // Here each pair is collided into one scratch buffer that then trades storage with the contact's (a swap, no
  // copy; the buffers keep their capacity, so a steady scene allocates nothing). Both paths collide a pair with
  // `narrow` below, so they give the same contacts in the same order.
  constexpr size_t kChunkPairs = 64;
  const size_t numChunks = (pairs_.size() + kChunkPairs - 1) / kChunkPairs;
  const bool parallel = parallelNarrowphase_ && numChunks >= 4;
  // The narrowphase of candidate pair k: its points into `points` (cleared first), its geometries in id order
  // into (ga, gb); false when the pair is filtered out or does not touch.
  auto narrow = [this](size_t k, std::vector<ContactPoint>& points, Geometry*& ga, Geometry*& gb) {
    const auto [i, j] = pairs_[k];
    ga = geoms_[i].get();
    gb = geoms_[j].get();
    if (!canCollide(*ga, *gb)) return false;
    if (ga->getId() > gb->getId()) std::swap(ga, gb);
    points.clear();
    return collideGeometries(*ga, *gb, margins_[i] + margins_[j], points) > 0 && !points.empty();
  };
  if (!parallel) {
    for (size_t k = 0; k < pairs_.size(); ++k) {
      Geometry *ga, *gb;
      if (!narrow(k, serialScratch_, ga, gb)) continue;
      if (used == out.size()) out.emplace_back();
      GeometryContact& gc = out[used++];
      gc.reset(ga, gb, ga->getRigidBody(), gb->getRigidBody());  // clears its points, keeps their storage
      gc.points().swap(serialScratch_);
      gc.setSensor(ga->isSensor() || gb->isSensor());
    }
  } else {
    if (chunks_.size() < numChunks) chunks_.resize(numChunks);
#pragma omp parallel for schedule(dynamic, 1)
    for (size_t c = 0; c < numChunks; ++c) {
      Chunk& ch = chunks_[c];
      ch.points.clear();
      ch.hits.clear();
      const size_t end = std::min(pairs_.size(), (c + 1) * kChunkPairs);
      for (size_t k = c * kChunkPairs; k < end; ++k) {
        Geometry *ga, *gb;
        if (!narrow(k, ch.scratch, ga, gb)) continue;
        ch.hits.push_back({ga, gb, uint32_t(ch.points.size()), uint32_t(ch.scratch.size())});
        ch.points.insert(ch.points.end(), ch.scratch.begin(), ch.scratch.end());
      }
    }
    for (size_t c = 0; c < numChunks; ++c) {
      const Chunk& ch = chunks_[c];
      for (const Hit& hit : ch.hits) {
        if (used == out.size()) out.emplace_back();
        GeometryContact& gc = out[used++];
        gc.reset(hit.a, hit.b, hit.a->getRigidBody(), hit.b->getRigidBody());
        gc.points().assign(ch.points.begin() + hit.begin, ch.points.begin() + hit.begin + hit.count);
        gc.setSensor(hit.a->isSensor() || hit.b->isSensor());
      }
    }
  }

  out.resize(used);
  // Deterministic order by (geometry 0 id, geometry 1 id), independent of the geometry list order.
  std::sort(out.begin(), out.end(), [](const GeometryContact& x, const GeometryContact& y) {
    const uint32_t x0 = x.geometry(0)->getId(), y0 = y.geometry(0)->getId();
    if (x0 != y0) return x0 < y0;
    return x.geometry(1)->getId() < y.geometry(1)->getId();
  });
}

}  // namespace scree

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

#include "narrowphase_internal.h"
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
  //
  // Box-box pairs first try the last step's manifold (reuseManifold below); a pair clipped afresh records its
  // manifold in its own slot manifolds_[k], so the threads never write the same record.
  manifolds_.resize(pairs_.size());
  auto narrow = [this](size_t k, std::vector<ContactPoint>& points, Geometry*& ga, Geometry*& gb) {
    const auto [i, j] = pairs_[k];
    CachedManifold& rec = manifolds_[k];
    rec.count = 0;
    ga = geoms_[i].get();
    gb = geoms_[j].get();
    if (!canCollide(*ga, *gb)) return false;
    if (ga->getId() > gb->getId()) std::swap(ga, gb);
    points.clear();
    const Real margin = margins_[i] + margins_[j];
    const bool boxes = persistentManifolds_ && ga->getShape()->getType() == Shape::BOX &&
                       gb->getShape()->getType() == Shape::BOX;
    if (boxes && reuseManifold(*ga, *gb, margin, rec, points)) return true;
    if (!(collideGeometries(*ga, *gb, margin, points) > 0 && !points.empty())) return false;
    if (boxes) recordManifold(*ga, *gb, points, rec);
    return true;
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
  // This step's manifold records become the next step's cache, indexed by pair key.
  manifoldKeys_.clear();
  numReused_ = 0;
  for (size_t k = 0; k < pairs_.size(); ++k) {
    const CachedManifold& rec = manifolds_[k];
    if (rec.count == 0) continue;
    manifoldKeys_.emplace_back(rec.key, uint32_t(k));
    numReused_ += rec.reused;
  }
  // The pairs come in box-index order, which is id order whenever geometries were added in id order (the
  // usual case): then the keys are sorted already and the sort, O(n log n) even on sorted input, is skipped.
  if (!std::is_sorted(manifoldKeys_.begin(), manifoldKeys_.end()))
    std::sort(manifoldKeys_.begin(), manifoldKeys_.end());
  manifolds_.swap(lastManifolds_);
  // Deterministic order by (geometry 0 id, geometry 1 id), independent of the geometry list order.
  // A geometry pair has one contact, so the order is unique; already sorted (pairs in box-index order, ids in
  // the same order) it is left as it is (issue 18: the sort was 0.4 % of pyramid20's step).
  const auto byIds = [](const GeometryContact& x, const GeometryContact& y) {
    const uint32_t x0 = x.geometry(0)->getId(), y0 = y.geometry(0)->getId();
    if (x0 != y0) return x0 < y0;
    return x.geometry(1)->getId() < y.geometry(1)->getId();
  };
  if (!std::is_sorted(out.begin(), out.end(), byIds)) std::sort(out.begin(), out.end(), byIds);
}

// ---- issue 18: persistent box-box manifolds (docs/solver-internals.md "Persistent box-box manifolds") ---------
//
// DESIGN. In a resting stack the box-box narrowphase (15-axis SAT, a Sutherland-Hodgman clip of the incident
// face, manifold reduction) is the largest part of the collide stage, and its answer barely changes from step to
// step. As in Jolt's and PhysX's persistent contacts, a box-box pair keeps its manifold with the pose of box 1 in
// box 0's frame at the step it was clipped (`rel`), each point as the two body-fixed surface points
//     p0 = x - n d/2 on box 0,  p1 = x + n d/2 on box 1      (x the contact point, n from 1 towards 0, d depth)
// in the boxes' own frames, and the normal in box 0's frame. While the relative pose stays within
//     |dp| <= kPoseTol r   and   |dtheta| <= kPoseTol          (r the larger half diagonal of the two boxes)
// of `rel` -- the pose at the clip, not the last step's, so small motions cannot accumulate -- the record is
// reused: the points are placed with the current poses and the depth recomputed as d = (p1 - p0) . n. The
// depth is exact for those material points (they move rigidly with their boxes); what reuse gives up is where a
// fresh clip would have put the points: each point of the clipped polygon moves by at most |dp| + |dtheta| r
// <= 2 kPoseTol r relative to box 0, so the lever arms are off by at most 2e-4 r (0.1 mm on a 1 m box), and the
// depth at the moved point by that times the faces' relative tilt. The feature ids are the clip's, so the warm
// start matches as before. A point whose recomputed gap exceeds the margin is dropped as the clip would drop it;
// a record with no points left, a changed shape or extents, or a pose past the tolerance is clipped again.
// Reuse depends only on the pair and its record, never on the thread count: 1 and 2 threads give the same bits.
namespace {
constexpr Real kPoseTol = 1e-4;
}

bool Space::reuseManifold(const Geometry& g0, const Geometry& g1, Real margin, CachedManifold& rec,
                          std::vector<ContactPoint>& points) const {
  const uint64_t key = (uint64_t(g0.getId()) << 32) | g1.getId();
  rec.key = key;
  const auto it = std::lower_bound(manifoldKeys_.begin(), manifoldKeys_.end(), std::make_pair(key, uint32_t(0)));
  if (it == manifoldKeys_.end() || it->first != key) return false;
  const CachedManifold& old = lastManifolds_[it->second];
  const Shape* s0 = g0.getShape().get();
  const Shape* s1 = g1.getShape().get();
  if (old.s0 != s0 || old.s1 != s1) return false;
  const Vec3& h0 = static_cast<const Box*>(s0)->getHalfExtents();
  const Vec3& h1 = static_cast<const Box*>(s1)->getHalfExtents();
  if (old.h0 != h0 || old.h1 != h1) return false;
  const Transform& t0 = g0.getTransform();
  const Transform& t1 = g1.getTransform();
  const Transform rel = t0.inverse() * t1;
  const Real r = std::max(h0.norm(), h1.norm());
  if (!((rel.p - old.rel.p).norm() <= kPoseTol * r)) return false;
  const Quat dq = old.rel.q.conjugate() * rel.q;  // |dtheta| = 2 asin|dq.vec| ~ 2 |dq.vec|
  if (!(2 * dq.vec().norm() <= kPoseTol)) return false;
  const Vec3 n = t0.rotate(old.n0);
  for (uint32_t m = 0; m < old.count; ++m) {
    const Vec3 p0 = t0.apply(old.p0[m]), p1 = t1.apply(old.p1[m]);
    const Real depth = (p1 - p0).dot(n);
    if (-depth > margin) continue;
    points.push_back(detail::makeContact(Real(0.5) * (p0 + p1), n, depth, old.fid[m]));
  }
  if (points.empty()) return false;
  rec = old;
  rec.reused = true;
  return true;
}

void Space::recordManifold(const Geometry& g0, const Geometry& g1, const std::vector<ContactPoint>& points,
                           CachedManifold& rec) const {
  rec.key = (uint64_t(g0.getId()) << 32) | g1.getId();
  rec.reused = false;
  if (points.size() > 4) return;  // box-box keeps at most four (reduceManifold); anything else is not cached
  const Transform& t0 = g0.getTransform();
  const Transform& t1 = g1.getTransform();
  rec.s0 = g0.getShape().get();
  rec.s1 = g1.getShape().get();
  rec.h0 = static_cast<const Box*>(rec.s0)->getHalfExtents();
  rec.h1 = static_cast<const Box*>(rec.s1)->getHalfExtents();
  rec.rel = t0.inverse() * t1;
  const Vec3& n = points[0].normal;  // one normal per box-box manifold (the reference face's or the edge axis)
  rec.n0 = t0.rotateInverse(n);
  for (size_t m = 0; m < points.size(); ++m) {
    const ContactPoint& c = points[m];
    rec.p0[m] = t0.applyInverse(c.point - n * (Real(0.5) * c.depth));
    rec.p1[m] = t1.applyInverse(c.point + n * (Real(0.5) * c.depth));
    rec.fid[m] = c.featureId;
  }
  rec.count = uint32_t(points.size());
}

}  // namespace scree

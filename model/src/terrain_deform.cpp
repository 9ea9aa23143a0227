// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Terrain: the dynamic height field's deformers (manual 25.1.2.15-25.1.2.18): generated vertical and horizontal
// contacts with area-scaled Young's moduli, and volume-conserving pushing of the overlapped soil into a berm.
// The law and its readings are in terrain.h ("Dynamic height field: deformers").
#include <algorithm>
#include <cmath>

#include "scree/core/errors.h"
#include "scree/model/terrain.h"
#include "scree/solver/simulation.h"

namespace scree {

struct Terrain::DeformerOverlap {
  size_t i0 = 1, i1 = 0, j0 = 1, j1 = 0;  ///< footprint vertex range (empty when i0 > i1)
  Real zMin = 0, zMax = 0;                ///< the box's bottom and top in the field frame
  Vec3 lo, hi;                            ///< the box in the field frame
  Real verticalArea = 0;
  Real depth = 0;  ///< how deep the bottom lies below the highest vertex of the grown footprint (<= box height)
  bool empty() const { return i0 > i1 || j0 > j1; }
  bool inside(size_t i, size_t j) const { return i >= i0 && i <= i1 && j >= j0 && j <= j1; }
};

bool Terrain::isGeometryDeformer(const Geometry& g) {
  return g.getPropertyContainer().hasPropertyBool(DeformerProperty);
}

void Terrain::setVerticalYoungsModulusAreaScaler(Real scale) {
  detail::requirePositive("Terrain::setVerticalYoungsModulusAreaScaler", "scale", scale);
  scalerV_ = scale;
}
void Terrain::setHorizontalYoungsModulusAreaScaler(Real scale) {
  detail::requirePositive("Terrain::setHorizontalYoungsModulusAreaScaler", "scale", scale);
  scalerH_ = scale;
}
void Terrain::setDynamicHeightFieldCutOffVelocity(Real v) {
  detail::requireNonNegative("Terrain::setDynamicHeightFieldCutOffVelocity", "cutOffVelocity", v);
  cutOffV_ = v;
}
void Terrain::setDynamicHeightFieldCutOffAngularVelocity(Real w) {
  detail::requireNonNegative("Terrain::setDynamicHeightFieldCutOffAngularVelocity", "cutOffAngularVelocity", w);
  cutOffW_ = w;
}
Real Terrain::computeVerticalYoungsModulus(Real E, Real area) const { return E * std::max<Real>(1, area / scalerV_); }
Real Terrain::computeHorizontalYoungsModulus(Real E, Real area) const {
  return E * std::max<Real>(1, area / scalerH_);
}

bool Terrain::deformerOverlap(const Geometry& g, DeformerOverlap& o) const {
  const Aabb box = g.getBoundingBox();
  const Transform& T = geometry_->getTransform();
  o.lo = Vec3::Constant(1e300);
  o.hi = Vec3::Constant(-1e300);
  for (int k = 0; k < 8; ++k) {
    const Vec3 c((k & 1) ? box.hi.x() : box.lo.x(), (k & 2) ? box.hi.y() : box.lo.y(),
                 (k & 4) ? box.hi.z() : box.lo.z());
    const Vec3 q = T.applyInverse(c);
    o.lo = o.lo.cwiseMin(q);
    o.hi = o.hi.cwiseMax(q);
  }
  o.zMin = o.lo.z();
  o.zMax = o.hi.z();
  const Real ox = 0.5 * heightField_->getSizeX(), oy = 0.5 * heightField_->getSizeY();
  const Real ulo = std::max<Real>(0, std::ceil((o.lo.x() + ox) / dx_));
  const Real uhi = std::min<Real>(Real(nx_ - 1), std::floor((o.hi.x() + ox) / dx_));
  const Real vlo = std::max<Real>(0, std::ceil((o.lo.y() + oy) / dy_));
  const Real vhi = std::min<Real>(Real(ny_ - 1), std::floor((o.hi.y() + oy) / dy_));
  o.verticalArea = 0;
  o.depth = 0;
  if (!(ulo <= uhi && vlo <= vhi)) {
    o.i0 = 1, o.i1 = 0;
    return false;
  }
  o.i0 = size_t(ulo), o.i1 = size_t(uhi), o.j0 = size_t(vlo), o.j1 = size_t(vhi);
  const std::vector<Real>& h = heightField_->getHeights();
  size_t count = 0;
  for (size_t j = o.j0; j <= o.j1; ++j)
    for (size_t i = o.i0; i <= o.i1; ++i)
      if (h[j * nx_ + i] > o.zMin) ++count;
  o.verticalArea = Real(count) * dx_ * dy_;
  Real top = -1e300;
  const size_t gi0 = o.i0 > 0 ? o.i0 - 1 : 0, gi1 = std::min(nx_ - 1, o.i1 + 1);
  const size_t gj0 = o.j0 > 0 ? o.j0 - 1 : 0, gj1 = std::min(ny_ - 1, o.j1 + 1);
  for (size_t j = gj0; j <= gj1; ++j)
    for (size_t i = gi0; i <= gi1; ++i) top = std::max(top, h[j * nx_ + i]);
  o.depth = std::clamp<Real>(top - o.zMin, 0, o.zMax - o.zMin);
  return true;
}

void Terrain::modifyDeformerContact(GeometryContact& c, int self) {
  const Geometry& g = *c.geometry(1 - self);
  if (c.points().empty()) return;
  DeformerOverlap o;
  deformerOverlap(g, o);
  const Transform& T = geometry_->getTransform();
  const Vec3 up = T.rotate(Vec3::UnitZ());
  // The horizontal direction of motion d (world): the body's velocity at the box centre, else the contact
  // normals' horizontal part (pointing at the deformer).
  Vec3 d = Vec3::Zero();
  if (const RigidBody* b = g.getRigidBody()) {
    const Aabb box = g.getBoundingBox();
    const Vec3 v = b->getVelocityAt(0.5 * (box.lo + box.hi));
    d = v - v.dot(up) * up;
  }
  if (!(d.norm() > 1e-9)) {
    Vec3 n = Vec3::Zero();
    for (const ContactPoint& p : c.points()) n += self == 1 ? p.normal : Vec3(-p.normal);
    n -= n.dot(up) * up;
    d = -n;  // the soil pushes the deformer along n: it moves into -n
  }
  const bool hasDir = d.norm() > 1e-9 && o.depth > 0;
  if (hasDir) d.normalize();
  // Box width across d (field frame).
  const Vec3 dl = T.rotateInverse(d);
  const Real width = std::abs(dl.y()) * (o.hi.x() - o.lo.x()) + std::abs(dl.x()) * (o.hi.y() - o.lo.y());

  DeformerContactInfo info;
  info.geometry = &g;
  info.useContactDepth = g.getPropertyContainer().getPropertyBool(DeformerProperty);
  info.verticalArea = o.verticalArea;
  info.horizontalArea = hasDir ? width * o.depth : 0;
  const size_t n0 = c.points().size();
  info.numOriginalPoints = n0;
  const Real Ec = c.material().getYoungsModulus();
  const Real muContact = c.material().getFrictionCoefficient();
  c.points().reserve(3 * n0);
  const Vec3 nV = self == 1 ? up : Vec3(-up);   // from geometry 1 to geometry 0: pushes the deformer up
  const Vec3 nH = self == 1 ? Vec3(-d) : d;     // pushes the deformer against its motion
  for (size_t k = 0; k < n0; ++k) {
    ContactPoint& p = c.points()[k];
    const Real E = p.youngsModulus > 0 ? p.youngsModulus : Ec;
    const Real Ev = computeVerticalYoungsModulus(E, info.verticalArea);
    const Real Eh = computeHorizontalYoungsModulus(E, info.horizontalArea);
    if (k == 0) info.youngsModulus = E, info.verticalYoungsModulus = Ev, info.horizontalYoungsModulus = Eh;
    ContactPoint q = p;
    q.normalForce = 0;
    q.frictionForce = Vec3::Zero();
    q.normalImpulse = 0;
    q.frictionImpulse = Vec3::Zero();
    q.frictionCoefficient = 0;
    q.frictionDirection = Vec3::Zero();
    ContactPoint v = q;
    v.normal = nV;
    // The vertical point carries the load, so it carries the friction too: mu bounded by its own normal force
    // (terrain.h: the friction of a deformer contact is mu times the load of the generated vertical points).
    v.frictionCoefficient = p.frictionCoefficient >= 0 ? p.frictionCoefficient : muContact;
    v.depth = info.useContactDepth ? std::max<Real>(0, p.depth * std::abs(p.normal.dot(up))) : 0;
    v.youngsModulus = Ev;
    v.featureId = p.featureId ^ 0x40000000u;
    ContactPoint hz = q;
    hz.normal = nH;
    hz.depth = 0;
    hz.youngsModulus = Eh;
    hz.featureId = p.featureId ^ 0x80000000u;
    p.youngsModulus = E * kDeformerSoftness;  // very soft; keeps its friction (bounded by its own small load)
    c.points().push_back(v);  // may reallocate: p is not used after this
    ++info.numVerticalPoints;
    if (hasDir) {
      c.points().push_back(hz);
      ++info.numHorizontalPoints;
    }
  }
  deformerContacts_.push_back(info);
}

void Terrain::deformStep() {
  lastDeformerContacts_.swap(deformerContacts_);
  deformerContacts_.clear();
  deformStats_ = DeformStats{};
  if (!dynamicHeightField_) return;
  TerrainDataInterface& di = *data_;
  const Real M = di.maxMultiplier_, D = di.depthForMax_;
  const Transform& T = geometry_->getTransform();
  const Real ox = 0.5 * heightField_->getSizeX(), oy = 0.5 * heightField_->getSizeY();
  const std::vector<Real>& h = heightField_->getHeights();
  std::vector<const Geometry*> done;
  for (const DeformerContactInfo& info : lastDeformerContacts_) {
    const Geometry& g = *info.geometry;
    if (std::find(done.begin(), done.end(), &g) != done.end()) continue;
    done.push_back(&g);
    const RigidBody* body = g.getRigidBody();
    if (!body) continue;
    const Aabb box = g.getBoundingBox();
    const Vec3 vc = body->getVelocityAt(0.5 * (box.lo + box.hi));
    if (!(vc.norm() > cutOffV_ || body->getAngularVelocity().norm() > cutOffW_)) continue;
    DeformerOverlap o;
    if (!deformerOverlap(g, o)) continue;
    bool open = false;
    for (size_t j = o.j0; j <= o.j1; ++j)
      for (size_t i = o.i0; i <= o.i1; ++i) {
        const size_t src = j * nx_ + i;
        const Real e = h[src] - o.zMin;
        if (!(e > 0)) continue;
        if (lockedBorders_ && isBorderVertex(i, j)) continue;
        // The horizontal velocity of the body at this vertex (field frame).
        const Vec3 pl(Real(i) * dx_ - ox, Real(j) * dy_ - oy, h[src]);
        Vec3 vl = T.rotateInverse(body->getVelocityAt(T.apply(pl)));
        Real vx = vl.x(), vy = vl.y();
        Real len = std::hypot(vx, vy);
        if (!(len > 1e-12)) continue;
        vx /= len, vy /= len;
        // Targets: the first vertex outside the footprint along d and d turned by +-45 deg.
        size_t tgt[3];
        Real share[3] = {0.5, 0.25, 0.25};
        const Real c45 = std::sqrt(0.5);
        const Real dirs[3][2] = {{vx, vy}, {c45 * (vx - vy), c45 * (vx + vy)}, {c45 * (vx + vy), c45 * (vy - vx)}};
        Real sum = 0;
        for (int k = 0; k < 3; ++k) {
          tgt[k] = size_t(-1);
          const Real step = 0.25 * std::min(dx_, dy_);
          for (int s = 1; s < 4 * int(nx_ + ny_); ++s) {
            const Real px = pl.x() + dirs[k][0] * step * s, py = pl.y() + dirs[k][1] * step * s;
            const long long ti = std::llround((px + ox) / dx_), tj = std::llround((py + oy) / dy_);
            if (ti < 0 || tj < 0 || ti >= (long long)nx_ || tj >= (long long)ny_) break;
            if (o.inside(size_t(ti), size_t(tj))) continue;
            if (!(lockedBorders_ && isBorderVertex(size_t(ti), size_t(tj)))) tgt[k] = size_t(tj) * nx_ + size_t(ti);
            break;
          }
          if (tgt[k] == size_t(-1)) share[k] = 0;
          sum += share[k];
        }
        if (!(sum > 0)) continue;
        if (!open) heightField_->beginHeightEdit(), open = true;
        const Real aSrc = getVertexArea(i, j);
        const Real V = e * aSrc;
        heightField_->setHeight(i, j, h[src] - e);
        const Real d = di.deformabilityOf(src);
        const bool hardens = d > 0 && M > 1;
        if (hardens) {
          const Real cMax = std::log2(M) / (d + 1);
          const Real cNew = std::min(di.compression_[src] + e * std::log2(M) / D, std::max(di.compression_[src], cMax));
          di.compression_[src] = cNew;
          di.multiplier_[src] = TerrainDataInterface::multiplier(cNew, d, M);
        }
        armWithExtent(src, avalancheLifeTime_);
        for (int k = 0; k < 3; ++k) {
          if (share[k] == 0) continue;
          const size_t t = tgt[k];
          const size_t ti = t % nx_, tj = t / nx_;
          const Real dz = share[k] / sum * V / getVertexArea(ti, tj);
          heightField_->setHeight(ti, tj, h[t] + dz);
          const Real dt = di.deformabilityOf(t);
          if (dt > 0 && M > 1 && di.compression_[t] > 0) {
            di.compression_[t] = std::max<Real>(0, di.compression_[t] - dz * std::log2(M) / D);
            di.multiplier_[t] = TerrainDataInterface::multiplier(di.compression_[t], dt, M);
          }
          armWithExtent(t, avalancheLifeTime_);
        }
        ++deformStats_.verticesPushed;
        deformStats_.volumePushed += V;
      }
    if (open) heightField_->endHeightEdit();
  }
  // Our own edits move volume between vertices only (the heightField account is unchanged); clearing lets the
  // next step tell external edits apart.
  if (deformStats_.verticesPushed > 0) heightField_->clearDirtyRectangle();
}

}  // namespace scree

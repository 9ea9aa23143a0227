// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Terrain digging: shovel discovery and validation, the cut, particle creation on the FCC lattice and merging
// back (the rules are in terrain.h's file comment; the volume moves through the ledger, never created or lost).
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "scree/core/errors.h"
#include "scree/core/logger.h"
#include "scree/model/terrain.h"
#include "scree/solver/simulation.h"

namespace scree {

namespace {
constexpr Real kSqrt2 = 1.41421356237309504880;
constexpr Real kPi = 3.14159265358979323846;
/// |cos(up, forward)| above this is "not orthogonal".
constexpr Real kOrthogonalityTolerance = 1e-6;
}  // namespace

// ---- particle attributes ------------------------------------------------------------------------------------
void TerrainParticleAttributes::setParticleRadius(Real radius) {
  constexpr const char* where = "TerrainParticleAttributes::setParticleRadius";
  const Real maxR = terrain_.getMaximumParticleRadius();
  if (!(std::isfinite(radius) && radius > 0 && radius <= maxR))
    detail::throwInvalid(where, "radius", radius,
                         "must be finite, > 0 and <= Terrain::getMaximumParticleRadius() = " +
                             detail::formatValue(maxR));
  radius_ = radius;
}

Real TerrainParticleAttributes::getParticleRadius() const {
  if (radius_ > 0) return radius_;
  return terrain_.getMaximumParticleRadius() / (2 * (3 * kSqrt2 - 2));
}

// ---- settings and read-outs -----------------------------------------------------------------------------------
std::string Terrain::checkShovelVectors(const Vec3& up, const Vec3& forward) {
  if (!up.allFinite()) return "ShovelUpProperty " + detail::formatValue(up) + " is not finite";
  if (!forward.allFinite()) return "ShovelForwardProperty " + detail::formatValue(forward) + " is not finite";
  if (!(up.norm() > 0)) return "ShovelUpProperty is the zero vector";
  if (!(forward.norm() > 0)) return "ShovelForwardProperty is the zero vector";
  const Real c = up.dot(forward) / (up.norm() * forward.norm());
  if (!(std::abs(c) <= kOrthogonalityTolerance))
    return "ShovelUpProperty " + detail::formatValue(up) + " and ShovelForwardProperty " +
           detail::formatValue(forward) + " are not orthogonal (cosine " + detail::formatValue(c) + ", tolerance 1e-6)";
  return {};
}

namespace {
/// "" when g is a valid shovel; "-" when it has neither property (not meant as a shovel); else the problem.
// The property names as strings made once: PropertyContainer looks names up by std::string, and a name longer
// than the small-string buffer would otherwise be allocated for every lookup, for every geometry, every step.
const std::string& upKey() {
  static const std::string k = Terrain::ShovelUpProperty;
  return k;
}
const std::string& forwardKey() {
  static const std::string k = Terrain::ShovelForwardProperty;
  return k;
}

std::string shovelProblem(const Geometry& g) {
  const PropertyContainer& pc = g.getPropertyContainer();
  if (pc.size() == 0) return "-";  // the common case: no properties at all
  const bool hasUp = pc.hasProperty(upKey());
  const bool hasFwd = pc.hasProperty(forwardKey());
  if (!hasUp && !hasFwd) return "-";
  if (!hasUp) return "ShovelUpProperty is missing";
  if (!hasFwd) return "ShovelForwardProperty is missing";
  if (!pc.hasPropertyVec3(upKey())) return "ShovelUpProperty is not a Vec3";
  if (!pc.hasPropertyVec3(forwardKey())) return "ShovelForwardProperty is not a Vec3";
  return Terrain::checkShovelVectors(pc.getPropertyVec3(upKey()), pc.getPropertyVec3(forwardKey()));
}
}  // namespace

bool Terrain::isGeometryShovel(const Geometry& g) const { return shovelProblem(g).empty(); }

void Terrain::setShovelMinimumDigAngleToHorizontalPlane(Real angle) {
  if (!(angle >= 0 && angle <= kPi / 2))
    detail::throwInvalid("Terrain::setShovelMinimumDigAngleToHorizontalPlane", "angle", angle,
                         "must be in [0, pi/2]");
  minDigAngle_ = angle;
}

void Terrain::setMergeVelocity(Real v) {
  if (!(std::isfinite(v) && v >= 0))
    detail::throwInvalid("Terrain::setMergeVelocity", "velocity", v, "must be finite and >= 0");
  mergeVelocity_ = v;
}

Real Terrain::getParticleLatticeDistance() const {
  return particleAttributes_.getParticleRadius() * (3 - kSqrt2);
}

Real Terrain::getParticleVolume() const {
  const Real a = kSqrt2 * getParticleLatticeDistance();
  return a * a * a / 4;
}

std::vector<size_t> Terrain::getParticleIds() const {
  std::vector<size_t> ids;
  ids.reserve(particles_.size());
  for (const auto& p : particles_) ids.push_back(p.first);
  return ids;
}

Real Terrain::getParticleCarriedVolume(size_t id) const {
  for (const auto& p : particles_)
    if (p.first == id) return p.second;
  return 0;
}

// ---- the step ---------------------------------------------------------------------------------------------------
struct Terrain::Shovel {
  const Geometry* geometry = nullptr;
  Vec3 upL, tipL;        ///< unit up and the tip, in the height field's frame
  Real thickness = 0;    ///< |up|
  Aabb box;              ///< world bounding box
  Aabb zone;             ///< non-merge zone: box grown by one particle diameter
  Real boxLowL = 0;      ///< lowest z of the box in the field's frame
  Real loX = 0, hiX = 0, loY = 0, hiY = 0;  ///< footprint in the field's frame
  Real cap = 0;          ///< highest a site's centre may stand above the shovel plane, along up (terrain.h)
  const RigidBody* body = nullptr;
};

void Terrain::findShovels(std::vector<Shovel>& out) {
  Simulation& sim = *getSimulation();
  const Transform& T = geometry_->getTransform();
  const Real r = particleAttributes_.getParticleRadius();
  auto consider = [&](const GeometryRef& gr) {
    const Geometry& g = *gr;
    if (&g == geometry_.get()) return;
    const std::string problem = shovelProblem(g);
    if (problem == "-") return;
    if (!problem.empty()) {
      if (std::find(reportedBadShovels_.begin(), reportedBadShovels_.end(), &g) == reportedBadShovels_.end()) {
        reportedBadShovels_.push_back(&g);
        Logger::error("Terrain \"" + getModelName() + "\": geometry \"" + g.getName() +
                      "\" is not a shovel: " + problem);
      }
      return;
    }
    // The pose this step will collide at (the simulation syncs geometries after the pre-collide listeners).
    gr->updateTransform();
    Shovel s;
    s.geometry = &g;
    const Transform& G = g.getTransform();
    const PropertyContainer& pc = g.getPropertyContainer();
    const Vec3 up = G.rotate(pc.getPropertyVec3(upKey()));
    const Vec3 fwd = G.rotate(pc.getPropertyVec3(forwardKey()));
    s.thickness = up.norm();
    s.upL = T.rotateInverse(up / s.thickness);
    s.tipL = T.applyInverse(G.p + fwd);
    s.box = g.getBoundingBox();
    s.zone = s.box;
    s.zone.lo -= Vec3::Constant(2 * r);
    s.zone.hi += Vec3::Constant(2 * r);
    s.loX = s.loY = s.boxLowL = std::numeric_limits<Real>::infinity();
    s.hiX = s.hiY = -std::numeric_limits<Real>::infinity();
    for (int k = 0; k < 8; ++k) {
      const Vec3 c((k & 1) ? s.box.hi.x() : s.box.lo.x(), (k & 2) ? s.box.hi.y() : s.box.lo.y(),
                   (k & 4) ? s.box.hi.z() : s.box.lo.z());
      const Vec3 l = T.applyInverse(c);
      s.loX = std::min(s.loX, l.x()), s.hiX = std::max(s.hiX, l.x());
      s.loY = std::min(s.loY, l.y()), s.hiY = std::max(s.hiY, l.y());
      s.boxLowL = std::min(s.boxLowL, l.z());
    }
    s.body = g.getRigidBody();
    // The cap (terrain.h, "the cap"): the top of the shovel's body - every geometry on it, the shovel included -
    // along up above the shovel plane, from the corners of their world boxes; a site's sphere stays below it.
    // A bare blade (nothing a particle diameter above the plane) caps at the footprint's larger horizontal side.
    {
      const Vec3 planePoint = s.tipL + s.upL * s.thickness;
      Real top = -std::numeric_limits<Real>::infinity();
      auto addBox = [&](const Aabb& b) {
        for (int k = 0; k < 8; ++k) {
          const Vec3 c((k & 1) ? b.hi.x() : b.lo.x(), (k & 2) ? b.hi.y() : b.lo.y(), (k & 4) ? b.hi.z() : b.lo.z());
          top = std::max(top, (T.applyInverse(c) - planePoint).dot(s.upL));
        }
      };
      addBox(s.box);
      if (s.body)
        for (const GeometryRef& o : s.body->getGeometries())
          if (o.get() != &g) {
            o->updateTransform();
            addBox(o->getBoundingBox());
          }
      s.cap = top >= 2 * r ? top - r : std::max(s.hiX - s.loX, s.hiY - s.loY);
    }
    out.push_back(s);
  };
  for (const RigidBodyRef& b : sim.getRigidBodies())
    for (const GeometryRef& g : b->getGeometries()) consider(g);
  for (const GeometryRef& g : sim.getStaticGeometries()) consider(g);
}

void Terrain::preCollide() {
  digStats_ = TerrainDigStats{};
  Simulation* sim = getSimulation();
  if (!sim) return;
  reconcileExternalEdits();
  geometry_->updateTransform();
  std::vector<Shovel> shovels;
  findShovels(shovels);
  heightField_->beginHeightEdit();
  mergeParticles(shovels);
  for (const Shovel& s : shovels) cut(s);
  heightField_->endHeightEdit();
  heightField_->clearDirtyRectangle();
}

void Terrain::cut(const Shovel& s) {
  // Not upside down, and up at least the minimum dig angle above the horizontal plane (terrain.h).
  if (!(s.upL.z() > 0) || std::asin(std::min<Real>(1, s.upL.z())) < minDigAngle_) return;
  const Real x0 = -0.5 * heightField_->getSizeX(), y0 = -0.5 * heightField_->getSizeY();
  const auto clampIndex = [](Real u, size_t n) -> long long {
    return std::clamp<long long>((long long)std::floor(u), -1, (long long)n);
  };
  // The lead (terrain.h, "the cut"): the footprint reaches one cell plus one particle diameter beyond the box
  // on the side of the cutting edge, so the rigid wall of uncut ground stands clear of the edge.
  Real loX = s.loX, hiX = s.hiX, loY = s.loY, hiY = s.hiY;
  const Real lead = std::max(dx_, dy_) + 2 * particleAttributes_.getParticleRadius();
  const Real exR = s.tipL.x() - 0.5 * (s.loX + s.hiX), eyR = s.tipL.y() - 0.5 * (s.loY + s.hiY);
  const Real len = std::hypot(exR, eyR);
  Real ex = 0, ey = 0;  // unit horizontal direction to the edge
  // The failure wedge (terrain.h, "The failure wedge"): a plain shovel (not a deformer) with a horizontal
  // direction to its edge also cuts the soil above the FEE failure plane, which rises at beta* from the lead's
  // front up to the height of the shovel's box top; that soil becomes particles in front of the shovel.
  Real tanBeta = 0, reach = 0;
  const bool wedge = failureWedge_ && len > 0 && !isGeometryDeformer(*s.geometry);
  if (len > 0) {
    ex = exR / len, ey = eyR / len;
    if (wedge) {
      const size_t ti = size_t(std::clamp<long long>(std::llround((s.tipL.x() - x0) / dx_), 0, (long long)nx_ - 1));
      const size_t tj = size_t(std::clamp<long long>(std::llround((s.tipL.y() - y0) / dy_), 0, (long long)ny_ - 1));
      const TerrainDataInterface& di0 = *data_;
      MaterialRef soil = di0.entries_[di0.index_[tj * nx_ + ti]].material;
      if (!soil) soil = defaultMaterial();
      MaterialRef blade = s.geometry->getMaterial();
      Simulation& sim = *getSimulation();
      if (!blade) blade = sim.getMaterialManager().getDefaultMaterial();
      SurfaceParameters bs;
      const FrictionModel* fm = nullptr;
      sim.getMaterialManager().resolve(blade.get(), soil.get(), bs, &fm);
      const Real muS = soil->getFrictionCoefficient(), muB = bs.getFrictionCoefficient();
      const Real phi = std::isfinite(muS) ? std::atan(muS) : 0.5 * kPi - 1e-3;
      const Real delta = std::isfinite(muB) ? std::atan(muB) : 0.5 * kPi - 1e-3;
      // Rake: the cutting plane's angle from the field's horizontal (up is its normal).
      const Real rake = std::acos(std::clamp<Real>(s.upL.z(), -1, 1));
      const Real beta = failureWedgeAngle(rake, std::min<Real>(phi, 0.5 * kPi - 1e-3), std::min<Real>(delta, 0.5 * kPi - 1e-3));
      tanBeta = std::tan(beta);
      Real boxHighL = -std::numeric_limits<Real>::infinity();
      const Transform& T = geometry_->getTransform();
      for (int k = 0; k < 8; ++k) {
        const Vec3 c((k & 1) ? s.box.hi.x() : s.box.lo.x(), (k & 2) ? s.box.hi.y() : s.box.lo.y(),
                     (k & 4) ? s.box.hi.z() : s.box.lo.z());
        boxHighL = std::max(boxHighL, T.applyInverse(c).z());
      }
      reach = std::max<Real>(0, boxHighL - s.boxLowL) / tanBeta;
    }
    (exR > 0 ? hiX : loX) += (lead + reach) * exR / len;  // reach = 0: the lead alone, as without the wedge
    (eyR > 0 ? hiY : loY) += (lead + reach) * eyR / len;
  }
  const long long i0 = std::max<long long>(0, clampIndex((loX - x0) / dx_, nx_) + 1);
  const long long i1 = std::min<long long>((long long)nx_ - 1, clampIndex((hiX - x0) / dx_, nx_));
  const long long j0 = std::max<long long>(0, clampIndex((loY - y0) / dy_, ny_) + 1);
  const long long j1 = std::min<long long>((long long)ny_ - 1, clampIndex((hiY - y0) / dy_, ny_));
  if (i0 > i1 || j0 > j1) return;
  TerrainDataInterface& di = *data_;
  const Real M = di.maxMultiplier_, D = di.depthForMax_;
  const Vec3& n = s.upL;
  Real groundTop = -std::numeric_limits<Real>::infinity();  // highest footprint vertex before the cut (the wedge's cap)
  for (long long j = j0; j <= j1; ++j)
    for (long long i = i0; i <= i1; ++i) {
      if (lockedBorders_ && isBorderVertex(size_t(i), size_t(j))) continue;
      const Real x = x0 + Real(i) * dx_, y = y0 + Real(j) * dy_;
      const Real zPlane = s.tipL.z() - (n.x() * (x - s.tipL.x()) + n.y() * (y - s.tipL.y())) / n.z();
      Real floor = std::max(zPlane, s.boxLowL);
      if (wedge) {
        const Real xi = (x - s.tipL.x()) * ex + (y - s.tipL.y()) * ey;  // ahead of the edge, horizontally
        if (xi > lead) floor = std::max(floor, s.boxLowL + (xi - lead) * tanBeta);
      }
      const Real h = heightField_->getHeight(size_t(i), size_t(j));
      groundTop = std::max(groundTop, h);
      if (!(h > floor)) continue;
      const Real dz = h - floor;
      const size_t v = size_t(j) * nx_ + size_t(i);
      heightField_->setHeight(size_t(i), size_t(j), floor);
      const Real vol = getVertexArea(size_t(i), size_t(j)) * dz;
      ledger_.heightField -= vol;
      ledger_.pending += vol;
      pending_[v] += vol;
      digStats_.volumeDug += vol;
      // Dug deeper: harder ground (the compression rule, capped at c_max), deformable vertices only.
      const Real d = di.deformabilityOf(v);
      if (d > 0 && M > 1) {
        const Real cMax = std::log2(M) / (d + 1);
        di.compression_[v] = std::min(di.compression_[v] + dz * std::log2(M) / D, std::max(di.compression_[v], cMax));
        di.multiplier_[v] = TerrainDataInterface::multiplier(di.compression_[v], d, M);
      }
    }
  const Real rect[4] = {loX, hiX, loY, hiY};
  if (!wedge) {
    createParticles(s, size_t(i0), size_t(i1), size_t(j0), size_t(j1), nullptr);
    return;
  }
  // The wedge's cap (terrain.h, "The failure wedge"): sites over the wedge may stand where its soil stood. The
  // soil farthest from the shovel plane is the wedge's far top edge, where the failure plane meets the ground:
  // at height min(groundTop, box top) and xi = lead + (that height - box bottom) / tan(beta*) ahead of the edge.
  // A bare blade's cap (its box's top corner along up) is shorter than that for a steep rake and a deep cut
  // (60 degrees, d = 7 cm: 0.16 against 0.18 m), and the wedge's far soil then stayed pending: the blade never met
  // it (docs/terrain.md, "The failure wedge").
  Shovel sw = s;
  if (std::isfinite(groundTop) && tanBeta > 0) {
    const Real zTop = std::min(groundTop, s.boxLowL + reach * tanBeta);
    const Real xiTop = lead + std::max<Real>(0, zTop - s.boxLowL) / tanBeta;
    const Vec3 far(s.tipL.x() + ex * xiTop, s.tipL.y() + ey * xiTop, zTop);
    sw.cap = std::max(s.cap, (far - (s.tipL + s.upL * s.thickness)).dot(s.upL));
  }
  createParticles(sw, size_t(i0), size_t(i1), size_t(j0), size_t(j1), rect);
}

Real Terrain::failureWedgeAngle(Real rake, Real phi, Real delta) {
  constexpr const char* where = "Terrain::failureWedgeAngle";
  if (!std::isfinite(rake)) detail::throwInvalid(where, "rake", rake, "must be finite");
  if (!(phi >= 0 && phi < 0.5 * kPi)) detail::throwInvalid(where, "phi", phi, "must be in [0, pi/2)");
  if (!(delta >= 0 && delta < 0.5 * kPi)) detail::throwInvalid(where, "delta", delta, "must be in [0, pi/2)");
  const Real alpha = std::clamp<Real>(rake, 1e-3, 0.5 * kPi);
  // N_gamma(beta) (+inf where D <= 0); unimodal on (0, pi/2 - phi).
  auto n = [&](Real beta) {
    const Real D = std::cos(alpha + delta) + std::sin(alpha + delta) / std::tan(beta + phi);
    if (!(D > 0)) return std::numeric_limits<Real>::infinity();
    return (1 / std::tan(alpha) + 1 / std::tan(beta)) / (2 * D);
  };
  Real a = 1e-6, b = 0.5 * kPi - phi - 1e-6;
  const Real g = 0.5 * (std::sqrt(5.0) - 1);
  Real x1 = b - g * (b - a), x2 = a + g * (b - a), f1 = n(x1), f2 = n(x2);
  while (b - a > 1e-9) {
    if (f1 < f2) {
      b = x2, x2 = x1, f2 = f1, x1 = b - g * (b - a), f1 = n(x1);
    } else {
      a = x1, x1 = x2, f1 = f2, x2 = a + g * (b - a), f2 = n(x2);
    }
  }
  return 0.5 * (a + b);
}

MaterialRef Terrain::particleMaterial(size_t v) {
  const TerrainDataInterface& di = *data_;
  MaterialRef src = di.entries_[di.index_[v]].material;
  if (!src) src = defaultMaterial();
  const Real adhesion = di.entries_[di.index_[v]].particleAdhesion;
  const Real r = particleAttributes_.getParticleRadius();
  const Real density = src->getDensity();
  for (ParticleMaterialCache& c : particleMaterials_)
    if (c.source == src.get() && c.radius == r && c.adhesion == adhesion && c.density == density) return c.material;
  // A new material (its own id) with the vertex material's surface parameters and no adhesion of its own; mass
  // = bulk density x carried volume: the sphere of radius r gets density rho V / (4/3 pi r^3).
  auto m = std::make_shared<Material>(src->getName() + " (terrain particles)");
  static_cast<SurfaceParameters&>(*m) = static_cast<const SurfaceParameters&>(*src);
  m->setAdhesion(0, 0);
  m->setDensity(density * getParticleVolume() / (4.0 / 3.0 * kPi * r * r * r));
  // Its contact materials - with itself (the vertex material's parameters, the particle adhesion at the
  // lattice's overlap, the Young's multiplier, the particle solve type) and with every external material - are
  // written by syncParticleContactMaterials (terrain_particle_materials.cpp), again whenever a setting changes.
  ParticleMaterialCache entry;
  entry.source = src.get();
  entry.radius = r, entry.adhesion = adhesion, entry.density = density;
  entry.material = m;
  entry.sourceRef = src;
  particleMaterials_.push_back(std::move(entry));
  syncParticleContactMaterials(particleMaterials_.back());
  return m;
}

namespace {
struct CellKey {
  long long x, y, z;
  bool operator==(const CellKey& o) const { return x == o.x && y == o.y && z == o.z; }
};
// The terrain particles near a footprint by lattice cube, for createParticles' "is this site free" test: an
// open-addressing table of cubes (power-of-two size, linear probing, at most half full) whose slots head a
// linked list of the cube's points. It replaced a std::unordered_map of vectors (a modulo by a prime and a
// pointer chase per probe, 27 probes per site tested: most of createParticles' time). The test only asks
// whether any point is within reach, so the container changes nothing in the result.
class CubeGrid {
 public:
  explicit CubeGrid(size_t expected) {
    size_t t = 64;
    while (t < 2 * expected) t <<= 1;
    rehash(t);
  }
  void insert(const CellKey& k, const Vec3& p) {
    if (2 * (used_ + 1) > keys_.size()) rehash(2 * keys_.size());
    const size_t s = slot(k);
    if (head_[s] < 0) {
      keys_[s] = k;
      ++used_;
    }
    pts_.push_back(p);
    next_.push_back(head_[s]);
    head_[s] = int32_t(pts_.size() - 1);
  }
  /// Calls f(point) for the cube's points until f returns false; returns false then.
  template <class F>
  bool forEach(const CellKey& k, F&& f) const {
    for (int32_t e = head_[slot(k)]; e >= 0; e = next_[size_t(e)])
      if (!f(pts_[size_t(e)])) return false;
    return true;
  }

 private:
  size_t slot(const CellKey& k) const {
    const uint64_t h0 = uint64_t(k.x) * 73856093ull ^ uint64_t(k.y) * 19349663ull ^ uint64_t(k.z) * 83492791ull;
    size_t s = size_t((h0 * 0x9e3779b97f4a7c15ull) >> 20) & mask_;
    while (head_[s] >= 0 && !(keys_[s] == k)) s = (s + 1) & mask_;
    return s;
  }
  void rehash(size_t t) {
    std::vector<CellKey> oldKeys = std::move(keys_);
    std::vector<int32_t> oldHead = std::move(head_);
    keys_.assign(t, CellKey{0, 0, 0});
    head_.assign(t, -1);
    mask_ = t - 1;
    for (size_t s = 0; s < oldKeys.size(); ++s)
      if (oldHead[s] >= 0) {
        const size_t n = slot(oldKeys[s]);
        keys_[n] = oldKeys[s];
        head_[n] = oldHead[s];
      }
  }
  std::vector<CellKey> keys_;
  std::vector<int32_t> head_;  // first point of the slot's cube, -1: empty slot
  std::vector<Vec3> pts_;
  std::vector<int32_t> next_;  // next point of the same cube, -1: last
  size_t mask_ = 0, used_ = 0;
};
}  // namespace

void Terrain::createParticles(const Shovel& s, size_t i0, size_t i1, size_t j0, size_t j1, const Real* siteRect) {
  const Real V = getParticleVolume();
  bool any = false;
  for (size_t j = j0; j <= j1 && !any; ++j)
    for (size_t i = i0; i <= i1; ++i)
      if (pending_[j * nx_ + i] >= V) {
        any = true;
        break;
      }
  if (!any) return;
  GranularBodySystem& gbs = getSimulation()->getGranularBodySystem();
  gbs.addCustomBufferReal(ParticleVolumeBuffer);
  const Transform& T = geometry_->getTransform();
  const Real r = particleAttributes_.getParticleRadius();
  const Real d = getParticleLatticeDistance(), a = kSqrt2 * d;
  const Real x0 = -0.5 * heightField_->getSizeX(), y0 = -0.5 * heightField_->getSizeY();
  // Terrain particles near the footprint, hashed by lattice cube (d < a: neighbours are in the 27 cubes).
  CubeGrid grid(particles_.size() / 4 + 16);
  auto keyOf = [&](const Vec3& p) {
    return CellKey{(long long)std::floor(p.x() / a), (long long)std::floor(p.y() / a), (long long)std::floor(p.z() / a)};
  };
  // Only particles that can be within d of a site: sites lie over the shovel's world box (x, y), so a particle
  // farther than d outside it in x or y never blocks one (most live particles, once a heap is dumped elsewhere).
  const Real reachXY = d;
  for (const auto& [id, vol] : particles_)
    if (gbs.isValid(id)) {
      const Vec3 pw = gbs.getPosition(id);
      if (siteRect) {
        const Vec3 p = T.applyInverse(pw);
        if (p.x() < siteRect[0] - reachXY || p.x() > siteRect[1] + reachXY || p.y() < siteRect[2] - reachXY ||
            p.y() > siteRect[3] + reachXY)
          continue;
        grid.insert(keyOf(p), p);
        continue;
      }
      if (pw.x() < s.box.lo.x() - reachXY || pw.x() > s.box.hi.x() + reachXY || pw.y() < s.box.lo.y() - reachXY ||
          pw.y() > s.box.hi.y() + reachXY)
        continue;
      const Vec3 p = T.applyInverse(pw);
      grid.insert(keyOf(p), p);
    }
  // Within reach: |q - p| < dFree, decided as before (the square root of the squared norm against dFree); the
  // squared norm settles all but the pairs within 1e-12 of the bound without the square root (most points of
  // the 27 cubes are well outside it).
  const Real dFree = d * (1 - 1e-9);
  const Real dFree2Lo = dFree * dFree * (1 - 1e-12), dFree2Hi = dFree * dFree * (1 + 1e-12);
  auto within = [&](const Vec3& q, const Vec3& p) {
    const Real s2 = (q - p).squaredNorm();
    if (s2 >= dFree2Hi) return false;
    if (s2 < dFree2Lo) return true;
    return std::sqrt(s2) < dFree;
  };
  auto free = [&](const Vec3& p) {
    const CellKey k = keyOf(p);
    for (long long dz = -1; dz <= 1; ++dz)
      for (long long dy = -1; dy <= 1; ++dy)
        for (long long dx = -1; dx <= 1; ++dx) {
          if (!grid.forEach(CellKey{k.x + dx, k.y + dy, k.z + dz},
                            [&](const Vec3& q) { return !within(q, p); }))
            return false;
        }
    return true;
  };
  static const Real basis[4][3] = {{0, 0, 0}, {0.5, 0.5, 0}, {0.5, 0, 0.5}, {0, 0.5, 0.5}};
  const Vec3 planePoint = s.tipL + s.upL * s.thickness;  // the shovel plane: the cutting plane + the blade
  const MaterialRef previous = gbs.getMaterial();
  struct Site {
    Real above;
    Vec3 p;
  };
  std::vector<Site> sites;
  for (size_t j = j0; j <= j1; ++j)
    for (size_t i = i0; i <= i1; ++i) {
      const size_t v = j * nx_ + i;
      if (pending_[v] < V) continue;
      // Sites whose (x, y) lie in this vertex's cell column [x_v - dx/2, x_v + dx/2) x [y_v - dy/2, y_v + dy/2).
      const Real cx0 = (Real(i) - 0.5) * dx_, cx1 = (Real(i) + 0.5) * dx_;
      const Real cy0 = (Real(j) - 0.5) * dy_, cy1 = (Real(j) + 0.5) * dy_;
      const Real h = heightField_->getHeight(i, j);
      const Real zStart = std::min(h, planePoint.z() - 2 * std::max(dx_, dy_));
      const long long kz0 = (long long)std::floor(zStart / a) - 1;
      sites.clear();
      for (long long kx = (long long)std::floor(cx0 / a) - 1; kx <= (long long)std::ceil(cx1 / a); ++kx)
        for (long long ky = (long long)std::floor(cy0 / a) - 1; ky <= (long long)std::ceil(cy1 / a); ++ky) {
          // Which basis sites of this (kx, ky) column lie in the vertex's cell column: (x, y) does not depend
          // on kz, so the test is made once, not for each of the 64 layers (the same sites in the same order).
          unsigned inColumn = 0;
          for (unsigned bi = 0; bi < 4; ++bi) {
            const Real u = (Real(kx) + basis[bi][0]) * a, w = (Real(ky) + basis[bi][1]) * a;
            if (u >= cx0 && u < cx1 && w >= cy0 && w < cy1) inColumn |= 1u << bi;
          }
          if (inColumn == 0) continue;
          for (long long kz = kz0; kz < kz0 + 64; ++kz)
            for (unsigned bi = 0; bi < 4; ++bi) {
              if (!(inColumn >> bi & 1u)) continue;
              const auto& b = basis[bi];
              const Real u = (Real(kx) + b[0]) * a, w = (Real(ky) + b[1]) * a;
              const Vec3 p(x0 + u, y0 + w, (Real(kz) + b[2]) * a);
              const Real above = (p - planePoint).dot(s.upL);
              if (!(above >= r) || !(above <= s.cap) || !(p.z() >= h + r)) continue;
              // Clear of the ground around it: r above the highest corner of the cell holding the site (a site
              // in a cut column next to uncut ground would otherwise start inside the slope and fall through).
              {
                const size_t ci = std::min(size_t(std::max<Real>(0, u / dx_)), nx_ - 2);
                const size_t cj = std::min(size_t(std::max<Real>(0, w / dy_)), ny_ - 2);
                const Real top = std::max(std::max(heightField_->getHeight(ci, cj), heightField_->getHeight(ci + 1, cj)),
                                          std::max(heightField_->getHeight(ci, cj + 1), heightField_->getHeight(ci + 1, cj + 1)));
                if (!(p.z() >= top + r)) continue;
              }
              if (siteRect) {
                if (!(p.x() >= siteRect[0] && p.x() <= siteRect[1] && p.y() >= siteRect[2] && p.y() <= siteRect[3]))
                  continue;
              } else {
                const Vec3 pw = T.apply(p);
                if (!(pw.x() >= s.box.lo.x() && pw.x() <= s.box.hi.x() && pw.y() >= s.box.lo.y() &&
                      pw.y() <= s.box.hi.y()))
                  continue;
              }
              sites.push_back({above, p});
            }
        }
      std::sort(sites.begin(), sites.end(), [](const Site& l, const Site& rr) {
        return l.above < rr.above || (l.above == rr.above && l.p.z() < rr.p.z());
      });
      gbs.setMaterial(particleMaterial(v));
      for (const Site& site : sites) {
        if (pending_[v] < V) break;
        if (!free(site.p)) continue;
        const Vec3 pw = T.apply(site.p);
        const Vec3 vel = s.body ? s.body->getVelocityAt(pw) : Vec3::Zero();
        const size_t id = gbs.createParticle(pw, r, vel);
        gbs.setCustomReal(ParticleVolumeBuffer, id, V);
        particles_.emplace_back(id, V);
        grid.insert(keyOf(site.p), site.p);
        pending_[v] -= V;
        ledger_.pending -= V;
        ledger_.particles += V;
        ++digStats_.particlesCreated;
      }
    }
  gbs.setMaterial(previous);
}

void Terrain::mergeParticles(const std::vector<Shovel>& shovels) {
  if (particles_.empty()) return;
  GranularBodySystem& gbs = getSimulation()->getGranularBodySystem();
  const Transform& T = geometry_->getTransform();
  TerrainDataInterface& di = *data_;
  const Real M = di.maxMultiplier_, D = di.depthForMax_;
  const Real v2 = mergeVelocity_ * mergeVelocity_;
  size_t keep = 0;
  for (size_t k = 0; k < particles_.size(); ++k) {
    const auto [id, V] = particles_[k];
    if (!gbs.isValid(id)) {
      // Destroyed by someone else: its soil left the simulation.
      ledger_.particles -= V;
      ledger_.removed += V;
      ++digStats_.particlesRemoved;
      continue;
    }
    bool merge = mergeVelocity_ > 0 && gbs.getVelocity(id).squaredNorm() < v2;
    const Vec3 pw = gbs.getPosition(id);
    for (size_t s = 0; merge && s < shovels.size(); ++s) {
      const Aabb& z = shovels[s].zone;
      if (pw.x() >= z.lo.x() && pw.x() <= z.hi.x() && pw.y() >= z.lo.y() && pw.y() <= z.hi.y() &&
          pw.z() >= z.lo.z() && pw.z() <= z.hi.z())
        merge = false;
    }
    size_t vv[3];
    Real w[3];
    if (merge) {
      const Vec3 p = T.applyInverse(pw);
      merge = locate(p, vv, w);
      if (merge) {
        // Resting near the surface: its bottom within one diameter of the ground under it.
        const std::vector<Real>& hs = heightField_->getHeights();
        const Real surface = w[0] * hs[vv[0]] + w[1] * hs[vv[1]] + w[2] * hs[vv[2]];
        const Real r = gbs.getRadius(id);
        merge = p.z() - r <= surface + 2 * r;
        Real sum = 0;
        for (int q = 0; q < 3; ++q) {
          if (lockedBorders_ && isBorderVertex(vv[q] % nx_, vv[q] / nx_)) w[q] = 0;
          sum += w[q];
        }
        if (!(sum > 0)) merge = false;
        else
          for (Real& wq : w) wq /= sum;
      }
    }
    if (!merge) {
      particles_[keep++] = particles_[k];
      continue;
    }
    for (int q = 0; q < 3; ++q) {
      if (!(w[q] > 0)) continue;
      const size_t v = vv[q], x = v % nx_, y = v / nx_;
      const Real dz = w[q] * V / getVertexArea(x, y);
      heightField_->setHeight(x, y, heightField_->getHeight(x, y) + dz);
      // Fresh loose soil on top: c falls by the compression rule (not below 0).
      const Real d = di.deformabilityOf(v);
      if (d > 0 && M > 1) {
        di.compression_[v] = std::max<Real>(0, di.compression_[v] - dz * std::log2(M) / D);
        di.multiplier_[v] = TerrainDataInterface::multiplier(di.compression_[v], d, M);
      }
    }
    armAvalancheAt(vv);  // merged soil may stand steeper than repose (terrain_avalanche.cpp)
    ledger_.particles -= V;
    ledger_.heightField += V;
    digStats_.volumeMerged += V;
    ++digStats_.particlesMerged;
    gbs.destroyParticle(id);
  }
  particles_.resize(keep);
}

}  // namespace scree

// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Terrain: construction checks, the contact listener (per-point Young's modulus and material), the post-step
// compression yield and the volume ledger. The law and its closed form are in terrain.h.
#include "scree/model/terrain.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "scree/collide/execute_filters.h"
#include "scree/core/errors.h"
#include "scree/solver/simulation.h"

namespace scree {

namespace {
using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

HeightFieldRef heightFieldOf(const GeometryRef& g) {
  detail::requireNonNull("Terrain::Terrain", "terrainGeometry", g.get());
  auto hf = std::dynamic_pointer_cast<HeightField>(g->getShape());
  if (!hf)
    throw std::invalid_argument("Terrain::Terrain: terrainGeometry \"" + g->getName() +
                                "\" is invalid (its shape must be a HeightField)");
  return hf;
}
}  // namespace

// Listeners forward to the terrain; they hold a plain pointer because the terrain owns them and removes them
// (Model::addOwned) before it can go away.
class Terrain::ContactListener : public ContactEventListener {
 public:
  explicit ContactListener(Terrain* t) : ContactEventListener(IMPACT | CONTACT | PARTICLE_CONTACT), t_(t) {}
  KeepContactPolicy impact(const TimeStamp&, GeometryContact& c) override { return run(c); }
  KeepContactPolicy contact(const TimeStamp&, GeometryContact& c) override { return run(c); }
  /// The FAQ warning for particles on geometry of a non-external material (terrain_particle_materials.cpp).
  void particleContacts(const TimeStamp&, std::vector<ParticleContact>&,
                        std::vector<ParticleContact>& particleGeometry) override {
    t_->checkParticleContacts(particleGeometry);
  }

 private:
  KeepContactPolicy run(GeometryContact& c) {
    const auto t0 = Clock::now();
    t_->modifyContact(c);
    t_->contactTimeAccum_ += secondsSince(t0);
    return KEEP_CONTACT;
  }
  Terrain* t_;
};

class Terrain::StepListener : public StepEventListener {
 public:
  explicit StepListener(Terrain* t) : StepEventListener(PRE_COLLIDE | POST_STEP), t_(t) {}
  void preCollide(const TimeStamp&) override {
    const auto t0 = Clock::now();
    t_->preCollide();
    t_->lastPreCollideTime_ = secondsSince(t0);
  }
  void post(const TimeStamp&) override { t_->postStep(); }

 private:
  Terrain* t_;
};

Terrain::Terrain(HeightFieldRef heightField) : Model("Terrain") {
  detail::requireNonNull("Terrain::Terrain", "heightField", heightField.get());
  heightField_ = std::move(heightField);
  geometry_ = std::make_shared<Geometry>(heightField_, "terrain");
  init();
}

Terrain::Terrain(GeometryRef terrainGeometry) : Model("Terrain") {
  heightField_ = heightFieldOf(terrainGeometry);
  if (terrainGeometry->getRigidBody()) {
    const Transform& l = terrainGeometry->getLocalTransform();
    if (l.p.norm() != 0 || std::abs(std::abs(l.q.w()) - 1) > 1e-12)
      throw std::invalid_argument(
          "Terrain::Terrain: terrainGeometry \"" + terrainGeometry->getName() +
          "\" is invalid (on a body its local transform must be the identity: position " +
          detail::formatValue(l.p) + ", rotation " + detail::formatValue(l.q) + "; place the body instead)");
  }
  geometry_ = std::move(terrainGeometry);
  init();
}

Terrain::~Terrain() = default;

void Terrain::init() {
  nx_ = heightField_->getResolutionX();
  ny_ = heightField_->getResolutionY();
  dx_ = heightField_->getCellSizeX();
  dy_ = heightField_->getCellSizeY();
  data_ = std::make_unique<TerrainDataInterface>(*this);
  contactListener_ = std::make_shared<ContactListener>(this);
  contactListener_->setFilter(std::make_shared<GeometryFilter>(geometry_.get()));
  stepListener_ = std::make_shared<StepListener>(this);
  load_.assign(nx_ * ny_, 0.0);
  stiffness_.assign(nx_ * ny_, 0.0);
  avgLoad_.assign(nx_ * ny_, 0.0);
  avgStiff_.assign(nx_ * ny_, 0.0);
  pending_.assign(nx_ * ny_, 0.0);
  loaded_.reserve(64);
  ledger_.heightField = computeHeightFieldVolume();
  heightField_->clearDirtyRectangle();
}

void Terrain::setDataInterface(std::unique_ptr<TerrainDataInterface> di) {
  detail::requireNonNull("Terrain::setDataInterface", "dataInterface", di.get());
  if (&di->terrain_ != this)
    throw std::invalid_argument("Terrain::setDataInterface: dataInterface is invalid (built for another terrain)");
  data_ = std::move(di);
  syncParticleContactMaterials();  // the new interface's external materials and particle solve type
}

MaterialRef Terrain::defaultMaterial() const {
  if (geometry_->getMaterial()) return geometry_->getMaterial();
  if (Simulation* s = getSimulation()) return s->getMaterialManager().getDefaultMaterial();
  return nullptr;
}

void Terrain::onAdd(Simulation& sim) {
  // +z of the field must oppose gravity (manual 25.1.1): checked before anything is installed.
  geometry_->updateTransform();
  const Vec3 g = sim.getUniformGravity();
  if (g.norm() > 0) {
    const Vec3 up = geometry_->getTransform().rotate(Vec3::UnitZ());
    const Real cosine = up.dot(-g.normalized());
    if (!(cosine > 1 - 1e-6))
      throw std::invalid_argument("Simulation::add: terrain \"" + getModelName() +
                                  "\" is invalid (the height field's +z " + detail::formatValue(up) +
                                  " must point against gravity " + detail::formatValue(g) + ")");
  }
  if (!geometry_->getRigidBody()) {
    const auto& statics = sim.getStaticGeometries();
    if (std::find(statics.begin(), statics.end(), geometry_) == statics.end()) addOwned(geometry_);
  }
  addOwned(ContactEventListenerRef(contactListener_));
  addOwned(StepEventListenerRef(stepListener_));
  syncParticleContactMaterials();  // into this simulation's MaterialManager (terrain_particle_materials.cpp)
}

void Terrain::onRemove(Simulation&) {
  // The ground cutting rows leave with the model's owned items; made again on the next touch after a re-add.
  cutting_.clear();
}

void Terrain::setLoadAveragingTime(Real seconds) {
  detail::requireNonNegative("Terrain::setLoadAveragingTime", "seconds", seconds);
  loadAveragingTime_ = seconds;
}

void Terrain::setEnableLockedBorders(bool enable, bool avalancheMassLoss) {
  lockedBorders_ = enable;
  avalancheMassLoss_ = avalancheMassLoss;
}

bool Terrain::isBorderVertex(size_t x, size_t y) const { return x == 0 || y == 0 || x + 1 == nx_ || y + 1 == ny_; }

Real Terrain::getVertexArea(size_t x, size_t y) const {
  Real a = dx_ * dy_;
  if (x == 0 || x + 1 == nx_) a *= 0.5;
  if (y == 0 || y + 1 == ny_) a *= 0.5;
  return a;
}

Real Terrain::computeHeightFieldVolume() const {
  const std::vector<Real>& h = heightField_->getHeights();
  Real sum = 0;
  for (size_t y = 0; y < ny_; ++y)
    for (size_t x = 0; x < nx_; ++x) sum += getVertexArea(x, y) * h[y * nx_ + x];
  return sum;
}

void Terrain::reconcileExternalEdits() const {
  // Only direct HeightField edits leave the dirty rectangle set between terrain steps (the terrain clears it
  // after its own, already booked, edits), so this full sum runs once per external edit, never per step.
  if (heightField_->getDirtyRectangle().empty()) return;
  ledger_.heightField = computeHeightFieldVolume();
  heightField_->clearDirtyRectangle();
}

const TerrainVolumeLedger& Terrain::getVolumeLedger() const {
  reconcileExternalEdits();
  return ledger_;
}

Real Terrain::computeSettledSinkage(Real p, Real d) const {
  const TerrainDataInterface& di = *data_;
  const Real M = di.getMaxCompressionMultiplier(), p0 = di.getYieldPressure();
  if (!(d > 0) || !(M > 1) || p <= p0) return 0;
  if (p > p0 * M) return std::numeric_limits<Real>::infinity();
  return di.getDepthForMaxCompression() * std::log(p / p0) / ((d + 1) * std::log(M));
}

bool Terrain::locate(const Vec3& q, size_t (&v)[3], Real (&w)[3]) const {
  const Real u = (q.x() + 0.5 * heightField_->getSizeX()) / dx_;
  const Real s = (q.y() + 0.5 * heightField_->getSizeY()) / dy_;
  if (!(u >= 0 && s >= 0 && u <= Real(nx_ - 1) && s <= Real(ny_ - 1))) return false;
  const size_t i = std::min(size_t(u), nx_ - 2), j = std::min(size_t(s), ny_ - 2);
  const Real fu = u - Real(i), fv = s - Real(j);
  const size_t v00 = j * nx_ + i;
  // Same split as HeightField: below the diagonal (fu >= fv) triangle (00, 10, 11), above it (00, 11, 01).
  v[0] = v00;
  v[2] = v00 + nx_ + 1;
  if (fu >= fv) {
    v[1] = v00 + 1;
    w[0] = 1 - fu, w[1] = fu - fv, w[2] = fv;
  } else {
    v[1] = v00 + nx_;
    w[0] = 1 - fv, w[1] = fv - fu, w[2] = fu;
  }
  return true;
}

void Terrain::modifyContact(GeometryContact& c) {
  const int self = c.geometry(0) == geometry_.get() ? 0 : 1;
  const Geometry* other = c.geometry(1 - self);
  const Transform& T = geometry_->getTransform();
  const TerrainDataInterface& di = *data_;
  const Material* geomMat = geometry_->getMaterial().get();
  for (ContactPoint& p : c.points()) {
    size_t v[3];
    Real w[3];
    if (!locate(T.applyInverse(p.point), v, w)) continue;
    const Real m = w[0] * di.multiplier_[v[0]] + w[1] * di.multiplier_[v[1]] + w[2] * di.multiplier_[v[2]];
    // Material of the nearest vertex (largest weight; ties to the first).
    const int k = w[0] >= w[1] ? (w[0] >= w[2] ? 0 : 2) : (w[1] >= w[2] ? 1 : 2);
    const Material* vm = di.entries_[di.index_[v[k]]].material.get();
    if (vm && vm != geomMat && getSimulation()) {
      // A mapped material other than the geometry's: this point's parameters are those of (other, vm).
      Simulation& sim = *getSimulation();
      const Material* om = other->getMaterial() ? other->getMaterial().get()
                                                : sim.getMaterialManager().getDefaultMaterial().get();
      SurfaceParameters sp;
      const FrictionModel* fm = nullptr;
      sim.getMaterialManager().resolve(om, vm, sp, &fm);
      p.youngsModulus = sp.getYoungsModulus() * m;
      p.frictionCoefficient = sp.getFrictionCoefficient();
      p.restitution = sp.getRestitution();
      p.damping = sp.getDamping();
    } else if (m != 1) {
      const Real E = p.youngsModulus > 0 ? p.youngsModulus : c.material().getYoungsModulus();
      p.youngsModulus = E * m;
    }
  }
  applyGroundCuttingForce(c, *other);  // shovels only (terrain_shovel.cpp)
  // Deformer contacts are rebuilt into vertical and horizontal ones (terrain_deform.cpp).
  if (dynamicHeightField_ && isGeometryDeformer(*other)) modifyDeformerContact(c, self);
}

void Terrain::compressVertex(size_t v, Real dz, Real newMultiplier, Real dc) {
  TerrainDataInterface& di = *data_;
  const size_t x = v % nx_, y = v / nx_;
  heightField_->setHeight(x, y, heightField_->getHeight(x, y) - dz);
  const Real vol = getVertexArea(x, y) * dz;
  ledger_.heightField -= vol;
  ledger_.compressed += vol;
  const Real d = di.deformabilityOf(v);
  const Real cMax = std::log2(di.maxMultiplier_) / (d + 1);
  di.compression_[v] = std::min(di.compression_[v] + dc, std::max(di.compression_[v], cMax));
  di.multiplier_[v] = newMultiplier;
}

bool Terrain::pressVertex(size_t x, size_t y, Real depth) {
  constexpr const char* where = "Terrain::pressVertex";
  if (x >= nx_) detail::throwInvalid(where, "x", (long long)x, "must be < resolutionX = " + std::to_string(nx_));
  if (y >= ny_) detail::throwInvalid(where, "y", (long long)y, "must be < resolutionY = " + std::to_string(ny_));
  detail::requireNonNegative(where, "depth", depth);
  reconcileExternalEdits();
  TerrainDataInterface& di = *data_;
  const size_t v = y * nx_ + x;
  const Real d = di.deformabilityOf(v), M = di.maxMultiplier_;
  if (!(d > 0) || !(M > 1) || (lockedBorders_ && isBorderVertex(x, y))) return false;
  if (depth == 0) return true;
  const Real dc = depth * std::log2(M) / di.depthForMax_;
  const Real cMax = std::log2(M) / (d + 1);
  const Real cNew = std::min(di.compression_[v] + dc, std::max(di.compression_[v], cMax));
  compressVertex(v, depth, TerrainDataInterface::multiplier(cNew, d, M), dc);
  heightField_->clearDirtyRectangle();
  return true;
}

namespace {
/// The implicit yield of one vertex (terrain.h): the dz >= 0 with  p0 A min(m e^(a dz), M) + K dz = F, i.e. the
/// vertex sinks until the force its contacts still carry (F - K dz, the springs relaxed by dz with the bodies
/// held) equals the yield force of the compressed ground. a = (d+1) ln(M) / D. The left side is increasing and
/// convex below the cap, so Newton from an upper bound converges monotonically.
Real yieldDepth(Real F, Real K, Real p0A, Real m, Real M, Real a) {
  const Real dzCap = std::log(M / m) / a;  // where the multiplier reaches M (>= 0)
  if (p0A * M + K * dzCap <= F) return (F - p0A * M) / K;  // bearing failure: only the springs hold back
  Real dz = std::min(dzCap, std::log(F / (p0A * m)) / a);   // the rigid-contact answer (K = 0) bounds it
  if (K > 0) dz = std::min(dz, F / K);
  for (int it = 0; it < 30; ++it) {
    const Real e = p0A * m * std::exp(a * dz);
    const Real g = e + K * dz - F, dg = a * e + K;
    const Real next = dz - g / dg;
    if (!(next < dz)) break;  // converged (monotone from above)
    dz = std::max<Real>(0, next);
  }
  return dz;
}
}  // namespace

void Terrain::postStep() {
  const auto t0 = Clock::now();
  lastContactTime_ = contactTimeAccum_;
  contactTimeAccum_ = 0;
  numLoaded_ = numYielded_ = 0;
  reconcileExternalEdits();
  Simulation* sim = getSimulation();
  if (!sim) return;
  updateShovelStats();  // digging force and fill read-outs (terrain_shovel.cpp)

  // 1. Gather each contact point's normal load (along the field's +z) and normal stiffness (the point's Young's
  //    modulus, N/m) onto the vertices of its triangle, by barycentric weights; the points of a cylinder's or
  //    capsule's line of contact as a line load over the segment between them (terrain_line_load.cpp).
  for (const GeometryContact& c : sim->getContacts()) {
    const int self = c.geometry(0) == geometry_.get() ? 0 : (c.geometry(1) == geometry_.get() ? 1 : -1);
    if (self < 0 || !c.isEnabled() || c.isSensor()) continue;
    gatherContactLoads(c, self);
  }
  numLoaded_ = loaded_.size();

  // 2. Average the load over the load averaging time (an exponential moving average per vertex; the active
  //    list holds the vertices whose average has not decayed below relevance, so an untouched terrain does no
  //    work once the last contact's averages have faded).
  const bool averaging = loadAveragingTime_ > sim->getTimeStep();
  if (averaging) {
    const Real alpha = sim->getTimeStep() / loadAveragingTime_;
    const Real forget = 1e-3 * data_->yieldPressure_ * dx_ * dy_;
    for (size_t v : loaded_)
      if (avgLoad_[v] == 0) active_.push_back(v);
    size_t keep = 0;
    for (size_t v : active_) {
      avgLoad_[v] += alpha * (load_[v] - avgLoad_[v]);
      avgStiff_[v] += alpha * (stiffness_[v] - avgStiff_[v]);
      // Forgotten below 1e-3 of the smallest load that can yield (p0 A): about 1 s after a typical last contact.
      if (avgLoad_[v] > forget) active_[keep++] = v;
      else avgLoad_[v] = avgStiff_[v] = 0;
    }
    active_.resize(keep);
  }

  // 3. Yield: lower each overloaded deformable vertex (terrain.h).
  TerrainDataInterface& di = *data_;
  const Real M = di.maxMultiplier_, D = di.depthForMax_, p0 = di.yieldPressure_, maxChange = di.maxChange_;
  const Real area = dx_ * dy_;
  if (M > 1 && maxChange > 0 && !loaded_.empty()) {
    const Real log2M = std::log2(M), lnM = std::log(M);
    // Batches of nearby edits: one bounds update per batch, over the batch's tiles only. A new batch starts
    // when a vertex lies more than two tiles away from the current one (wheels far apart stay separate).
    const size_t span = 2 * HeightField::kTileSize;
    HeightField::Rect batch;
    bool open = false;
    for (size_t v : loaded_) {
      const Real d = di.deformabilityOf(v);
      if (!(d > 0)) continue;
      const size_t x = v % nx_, y = v / nx_;
      if (lockedBorders_ && isBorderVertex(x, y)) continue;
      // Only vertices loaded in this step yield (a body that left stops pressing), by the averaged load.
      const Real m = di.multiplier_[v], F = averaging ? avgLoad_[v] : load_[v];
      const Real K = averaging ? avgStiff_[v] : stiffness_[v];
      if (!(K > 0)) continue;
      if (!(F > p0 * area * m)) continue;
      const Real a = (d + 1) * lnM / D;
      Real dz = yieldDepth(F, K, p0 * area, m, M, a);
      // The per-step bound on the multiplier's growth bounds the depth too (also in bearing failure).
      if (std::isfinite(maxChange)) dz = std::min(dz, std::log((m + maxChange) / m) / a);
      if (!(dz > 0)) continue;
      const Real dc = dz * log2M / D;
      const Real cMax = log2M / (d + 1);
      const Real cNew = std::min(di.compression_[v] + dc, std::max(di.compression_[v], cMax));
      // The stored multiplier is the formula at the new c, except that rounding may not push it past m +
      // maxChange (the per-step bound is exact as read back).
      Real mt = std::min(TerrainDataInterface::multiplier(cNew, d, M), m + maxChange);
      while (mt - m > maxChange) mt = std::nextafter(mt, Real(0));
      if (open && (std::max(batch.i1, x) - std::min(batch.i0, x) > span ||
                   std::max(batch.j1, y) - std::min(batch.j0, y) > span)) {
        heightField_->endHeightEdit();
        open = false;
      }
      if (!open) {
        heightField_->beginHeightEdit();
        batch = HeightField::Rect{x, y, x, y};
        open = true;
      }
      batch.i0 = std::min(batch.i0, x), batch.i1 = std::max(batch.i1, x);
      batch.j0 = std::min(batch.j0, y), batch.j1 = std::max(batch.j1, y);
      compressVertex(v, dz, mt, dc);
      ++numYielded_;
    }
    if (open) heightField_->endHeightEdit();
    // Our own edits are booked already; clearing lets the next step tell external edits apart.
    heightField_->clearDirtyRectangle();
  }
  lastLoads_.clear();
  for (size_t v : loaded_) {
    lastLoads_.push_back(VertexLoad{v % nx_, v / nx_, load_[v], stiffness_[v]});
    load_[v] = stiffness_[v] = 0;
  }
  loaded_.clear();
  // 4. Deformers push the soil they overlap (terrain_deform.cpp), arming avalanches.
  deformStep();
  // 4. Avalanches of the armed vertices (terrain_avalanche.cpp; nothing while none is armed).
  avalancheStep();
  lastPostTime_ = secondsSince(t0);
}

}  // namespace scree

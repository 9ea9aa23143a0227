// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Reference scene builders and metrics; see scenes.h and docs/scenes.md.
#include "scenes/scenes.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <cmath>
#include <limits>
#include <numbers>
#include <unordered_map>

namespace scree::scenes {

namespace {

constexpr Real kNaN = std::numeric_limits<Real>::quiet_NaN();

bool bodyFinite(const RigidBody& b) {
  return b.getPosition().allFinite() && b.getRotation().coeffs().allFinite() && b.getVelocity().allFinite() &&
         b.getAngularVelocity().allFinite();
}

}  // namespace

// ------------------------------------------------------------------------------------------------------------
// common
// ------------------------------------------------------------------------------------------------------------
size_t Scene::numContactPoints() const {
  size_t n = 0;
  for (const GeometryContact& c : sim->getContacts()) n += c.points().size();
  return n;
}

void initScene(Scene& s, const std::string& name, Real mu, Real dt, int numSteps) {
  s.name = name;
  s.mu = mu;
  s.dt = dt;
  s.numSteps = numSteps;
  s.sim = std::make_unique<Simulation>();
  s.sim->setTimeStep(dt);
  s.sim->setUniformGravity(Vec3(0, 0, -SceneConstants::gravity));
  s.sim->getSolver().setNumIterations(SceneConstants::solverIterations);

  // One scene material carried by every geometry, with the scene's mu and restitution 0, and an explicit
  // contact material (mat, mat) so the effective coefficient is exactly mu (docs/scenes.md).
  s.material = std::make_shared<Material>(name);
  s.material->setFrictionCoefficient(mu);
  s.material->setRestitution(0.0);
  s.contactMaterial = s.sim->getMaterialManager().getOrCreateContactMaterial(s.material, s.material);
  s.contactMaterial->setFrictionCoefficient(mu);
  s.contactMaterial->setRestitution(0.0);
}

RigidBodyRef addStaticBox(Scene& s, const Vec3& halfExtents, const Vec3& position, const Quat& rotation) {
  auto geom = std::make_shared<Geometry>(std::make_shared<Box>(halfExtents));
  geom->setMaterial(s.material);
  auto body = std::make_shared<RigidBody>();
  body->setMotionControl(RigidBody::STATIC);
  body->add(geom);
  body->setPosition(position);
  body->setRotation(rotation);
  s.sim->add(body);
  return body;
}

RigidBodyRef addGround(Scene& s) {
  s.ground = addStaticBox(s,
                          Vec3(SceneConstants::groundHalfExtent, SceneConstants::groundHalfExtent,
                               SceneConstants::groundHalfThickness),
                          Vec3(0, 0, -SceneConstants::groundHalfThickness));
  s.ground->setName("ground");
  return s.ground;
}

RigidBodyRef addBox(Scene& s, const Vec3& halfExtents, Real mass, const Vec3& position, const Quat& rotation) {
  auto geom = std::make_shared<Geometry>(std::make_shared<Box>(halfExtents));
  geom->setMaterial(s.material);
  auto body = std::make_shared<RigidBody>();
  body->add(geom);
  body->setMass(mass);
  body->setPosition(position);
  body->setRotation(rotation);
  s.sim->add(body);
  return body;
}

bool allFinite(const Simulation& sim) {
  for (const RigidBodyRef& b : sim.getRigidBodies())
    if (!bodyFinite(*b)) return false;
  return true;
}

std::vector<Vec3> boxCorners(const RigidBody& body, const Vec3& he) {
  std::vector<Vec3> out;
  out.reserve(8);
  const Transform t = body.getTransform();
  for (int i = 0; i < 8; ++i) {
    const Vec3 local((i & 1) ? he.x() : -he.x(), (i & 2) ? he.y() : -he.y(), (i & 4) ? he.z() : -he.z());
    out.push_back(t.apply(local));
  }
  return out;
}

// ------------------------------------------------------------------------------------------------------------
// pyramid20
// ------------------------------------------------------------------------------------------------------------
PyramidScene buildPyramid(int rows, Real mu) {
  PyramidScene s;
  initScene(s, "pyramid" + std::to_string(rows), mu, 1.0 / 60.0, 600);
  addGround(s);
  const Vec3 he(0.5, 0.5, 0.5);
  const Real pitch = 1.01;  // 0.01 m gap between horizontal neighbours only; rows touch vertically
  for (int row = 0; row < rows; ++row) {
    const int n = rows - row;
    for (int i = 0; i < n; ++i) {
      const Vec3 p((i - 0.5 * (n - 1)) * pitch, 0.0, 0.5 + row);
      s.boxes.push_back(addBox(s, he, 1.0, p));
      s.initialPositions.push_back(p);
    }
  }
  s.top = s.boxes.back();
  s.topInitial = s.initialPositions.back();
  return s;
}

PyramidMetrics measurePyramid(const PyramidScene& s) {
  PyramidMetrics m;
  for (size_t i = 0; i < s.boxes.size(); ++i) {
    m.maxDisplacement = std::max(m.maxDisplacement, (s.boxes[i]->getPosition() - s.initialPositions[i]).norm());
    m.finite = m.finite && bodyFinite(*s.boxes[i]);
  }
  m.topDz = s.top->getPosition().z() - s.topInitial.z();
  m.stands = m.finite && std::abs(m.topDz) < 0.1;
  return m;
}

PyramidMetrics runPyramid(PyramidScene& s) {
  for (int i = 0; i < s.numSteps; ++i) s.step();
  return measurePyramid(s);
}

// ------------------------------------------------------------------------------------------------------------
// tower10
// ------------------------------------------------------------------------------------------------------------
TowerScene buildTower(int count, Real mu) {
  TowerScene s;
  initScene(s, "tower" + std::to_string(count), mu, 1.0 / 60.0, 600);
  addGround(s);
  for (int i = 0; i < count; ++i) {
    const Vec3 p(0, 0, 0.5 + i);
    s.boxes.push_back(addBox(s, Vec3(0.5, 0.5, 0.5), 1.0, p));
    s.initialPositions.push_back(p);
  }
  s.top = s.boxes.back();
  s.topInitial = s.initialPositions.back();
  return s;
}

TowerMetrics measureTower(const TowerScene& s) {
  TowerMetrics m;
  const Vec3 d = s.top->getPosition() - s.topInitial;
  m.topHorizontal = std::hypot(d.x(), d.y());
  m.topVertical = d.z();
  for (size_t i = 0; i < s.boxes.size(); ++i) {
    m.maxDisplacement = std::max(m.maxDisplacement, (s.boxes[i]->getPosition() - s.initialPositions[i]).norm());
    m.finite = m.finite && bodyFinite(*s.boxes[i]);
  }
  return m;
}

TowerMetrics runTower(TowerScene& s) {
  for (int i = 0; i < s.numSteps; ++i) s.step();
  return measureTower(s);
}

// ------------------------------------------------------------------------------------------------------------
// mass_ratio
// ------------------------------------------------------------------------------------------------------------
MassRatioScene buildMassRatio(Real heavyMass, Real lightMass, Real mu) {
  MassRatioScene s;
  initScene(s, "mass_ratio", mu, 1.0 / 60.0, 600);
  addGround(s);
  s.light = addBox(s, Vec3(0.5, 0.5, 0.5), lightMass, Vec3(0, 0, 0.5));
  s.light->setName("light");
  s.heavy = addBox(s, Vec3(0.5, 0.5, 0.5), heavyMass, Vec3(0, 0, 1.5));
  s.heavy->setName("heavy");
  s.heavyTargetZ = 1.5;
  return s;
}

bool massRatioSqueezed(const MassRatioScene& s) {
  const Vec3 local = s.heavy->getTransform().applyInverse(s.light->getPosition());
  return std::abs(local.x()) > 0.5 || std::abs(local.y()) > 0.5 || !local.allFinite();
}

Real massRatioOverlap(const MassRatioScene& s) {
  const Vec3 he(0.5, 0.5, 0.5);
  Real lightTop = -std::numeric_limits<Real>::infinity();
  Real heavyBottom = std::numeric_limits<Real>::infinity();
  for (const Vec3& c : boxCorners(*s.light, he)) lightTop = std::max(lightTop, c.z());
  for (const Vec3& c : boxCorners(*s.heavy, he)) heavyBottom = std::min(heavyBottom, c.z());
  return lightTop - heavyBottom;
}

void MassRatioObserver::observe() {
  ++step_;
  const bool finite = bodyFinite(*s_.light) && bodyFinite(*s_.heavy);
  m_.finite = m_.finite && finite;
  m_.heavyError = std::abs(s_.heavy->getPosition().z() - s_.heavyTargetZ);
  if (!finite) m_.heavyError = std::numeric_limits<Real>::infinity();
  m_.heavyErrorWorst = std::max(m_.heavyErrorWorst, m_.heavyError);
  const bool out = massRatioSqueezed(s_);
  if (out && !m_.squeezed) {
    m_.squeezed = true;
    m_.squeezedAtStep = step_;
  }
  if (out) {
    m_.overlap = kNaN;
  } else {
    m_.overlap = massRatioOverlap(s_);
    if (!m_.squeezed) m_.overlapWorst = std::max(m_.overlapWorst, m_.overlap);
  }
}

MassRatioMetrics runMassRatio(MassRatioScene& s) {
  MassRatioObserver obs(s);
  for (int i = 0; i < s.numSteps; ++i) {
    s.step();
    obs.observe();
  }
  return obs.result();
}

// ------------------------------------------------------------------------------------------------------------
// slide
// ------------------------------------------------------------------------------------------------------------
SlideScene buildSlide(Real mu, Real v0) {
  SlideScene s;
  initScene(s, "slide", mu, 1.0 / 60.0, 180);
  addGround(s);
  s.initialPosition = Vec3(0, 0, 0.5);
  s.box = addBox(s, Vec3(0.5, 0.5, 0.5), 1.0, s.initialPosition);
  s.box->setVelocity(Vec3(v0, 0, 0));
  s.v0 = v0;
  return s;
}

void SlideObserver::observe() {
  ++step_;
  if (stopTime_ < 0 && std::abs(s_.box->getVelocity().x()) < stopSpeed) stopTime_ = s_.sim->getTimeStamp();
}

SlideMetrics SlideObserver::result() const {
  SlideMetrics m;
  m.finite = bodyFinite(*s_.box);
  m.distance = s_.box->getPosition().x() - s_.initialPosition.x();
  m.stopTime = stopTime_;
  m.distanceErr = (m.distance - s_.analyticDistance()) / s_.analyticDistance();
  m.timeErr = stopTime_ < 0 ? kNaN : (stopTime_ - s_.analyticTime()) / s_.analyticTime();
  return m;
}

SlideMetrics runSlide(SlideScene& s) {
  SlideObserver obs(s);
  for (int i = 0; i < s.numSteps; ++i) {
    s.step();
    obs.observe();
  }
  return obs.result();
}

// ------------------------------------------------------------------------------------------------------------
// incline
// ------------------------------------------------------------------------------------------------------------
Real InclineScene::analyticDisplacement(Real t) const {
  const Real a = SceneConstants::gravity * (std::sin(angle) - mu * std::cos(angle));
  return a > 0 ? 0.5 * a * t * t : 0.0;
}

InclineScene buildIncline(Real mu, Real angleDeg) {
  InclineScene s;
  char name[32];
  std::snprintf(name, sizeof(name), "incline_mu%02d", int(std::lround(mu * 10)));
  initScene(s, name, mu, 1.0 / 60.0, 120);
  addGround(s);
  s.angle = angleDeg * std::numbers::pi / 180.0;
  // A positive rotation about +y turns +x towards -z: the slab descends towards +x.
  const Quat q(Eigen::AngleAxis<Real>(s.angle, Vec3::UnitY()));
  s.downSlope = q * Vec3::UnitX();
  s.slopeNormal = q * Vec3::UnitZ();
  // Slab 20 x 10 x 1 m, centred high enough that its lowest corner (6 - 10 sin30 - 0.5 cos30 = 0.57 m) clears
  // the ground.
  const Vec3 slabCentre(0, 0, 6.0);
  s.slab = addStaticBox(s, Vec3(10, 5, 0.5), slabCentre, q);
  s.slab->setName("slab");
  // Cube exactly touching: its bottom face on the slab's top face (0.5 + 0.5 along the normal).
  s.cubeInitial = slabCentre + s.slopeNormal * 1.0;
  s.cube = addBox(s, Vec3(0.5, 0.5, 0.5), 1.0, s.cubeInitial, q);
  s.cube->setName("cube");
  return s;
}

InclineMetrics measureIncline(const InclineScene& s) {
  InclineMetrics m;
  m.finite = bodyFinite(*s.cube);
  m.displacement = (s.cube->getPosition() - s.cubeInitial).dot(s.downSlope);
  m.analytic = s.analyticDisplacement(s.sim->getTimeStamp());
  m.error = m.analytic > 0 ? (m.displacement - m.analytic) / m.analytic : m.displacement;
  return m;
}

InclineMetrics runIncline(InclineScene& s) {
  for (int i = 0; i < s.numSteps; ++i) s.step();
  return measureIncline(s);
}

// ------------------------------------------------------------------------------------------------------------
// spheres
// ------------------------------------------------------------------------------------------------------------
uint64_t splitmix64(uint64_t& state) {
  uint64_t z = (state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

Real splitmixSymmetric(uint64_t& state) {
  const Real u = Real(splitmix64(state) >> 11) * 0x1.0p-53;  // [0, 1)
  return 2.0 * u - 1.0;
}

SpheresScene buildSphereLattice(const SphereLatticeParams& p) {
  SpheresScene s;
  std::string name = "spheres" + std::to_string(p.count);
  if (p.jitter) name += "_jitter";
  initScene(s, name, p.mu, p.dt, p.numSteps);
  s.params = p;
  s.material->setDensity(p.density);
  addGround(s);

  const Real half = 0.5 * (p.perRow - 1);  // 8.5 for 18 per row
  s.wallInner = 0.5 * p.perRow * p.spacing + (p.spacing - 2 * p.radius);  // 0.99 + 0.01 = 1 m
  const Real wt = 0.5 * p.wallThickness, wh = 0.5 * p.wallHeight;
  const Real wl = s.wallInner + p.wallThickness;  // half length: the walls overlap at the corners
  const Real wc = s.wallInner + wt;
  s.walls.push_back(addStaticBox(s, Vec3(wt, wl, wh), Vec3(wc, 0, wh)));
  s.walls.push_back(addStaticBox(s, Vec3(wt, wl, wh), Vec3(-wc, 0, wh)));
  s.walls.push_back(addStaticBox(s, Vec3(wl, wt, wh), Vec3(0, wc, wh)));
  s.walls.push_back(addStaticBox(s, Vec3(wl, wt, wh), Vec3(0, -wc, wh)));

  auto shape = std::make_shared<Sphere>(p.radius);
  uint64_t rng = p.seed;
  const size_t perLayer = size_t(p.perRow) * size_t(p.perRow);
  s.spheres.reserve(p.count);
  for (size_t n = 0; n < p.count; ++n) {
    const size_t k = n / perLayer, inLayer = n % perLayer;
    const size_t j = inLayer / size_t(p.perRow), i = inLayer % size_t(p.perRow);
    Vec3 pos((Real(i) - half) * p.spacing, (Real(j) - half) * p.spacing,
             p.radius + (p.spacing - 2 * p.radius) + p.spacing * Real(k));  // 0.06 + 0.11 k
    if (p.jitter) {
      const Real dx = splitmixSymmetric(rng) * p.jitterAmplitude;
      const Real dy = splitmixSymmetric(rng) * p.jitterAmplitude;
      pos.x() += dx;
      pos.y() += dy;
    }
    auto geom = std::make_shared<Geometry>(shape);
    geom->setMaterial(s.material);
    auto body = std::make_shared<RigidBody>();
    body->add(geom);  // mass from density 2500: 1.309 kg
    body->setPosition(pos);
    s.sim->add(body);
    s.spheres.push_back(body);
  }
  return s;
}

SpheresScene buildSpheres10k() { return buildSphereLattice(SphereLatticeParams{}); }

SpheresScene buildSpheres10kJitter() {
  SphereLatticeParams p;
  p.jitter = true;
  return buildSphereLattice(p);
}

SpheresMetrics measureSpheres(const SpheresScene& s) {
  SpheresMetrics m;
  const Real r = s.params.radius;
  const size_t n = s.spheres.size();
  std::vector<Vec3> pos(n);
  Real sumZ = 0;
  m.maxHeight = n ? -std::numeric_limits<Real>::infinity() : 0;
  for (size_t i = 0; i < n; ++i) {
    const RigidBody& b = *s.spheres[i];
    pos[i] = b.getPosition();
    const bool fin = bodyFinite(b);
    m.finite = m.finite && fin;
    const Real mass = b.getMass();
    const Real inertia = 0.4 * mass * r * r;
    m.kineticEnergy += 0.5 * mass * b.getVelocity().squaredNorm() + 0.5 * inertia * b.getAngularVelocity().squaredNorm();
    const Vec3& x = pos[i];
    if (!fin || std::abs(x.x()) > s.wallInner || std::abs(x.y()) > s.wallInner || x.z() < 0) ++m.escaped;
    if (!fin) continue;
    sumZ += x.z();
    m.maxHeight = std::max(m.maxHeight, x.z());
    m.maxPenFloor = std::max(m.maxPenFloor, r - x.z());
    const Real wallPen = std::max({x.x() + r - s.wallInner, -x.x() + r - s.wallInner, x.y() + r - s.wallInner,
                                   -x.y() + r - s.wallInner});
    // Only spheres still inside the container can press on a wall's inner face.
    if (std::abs(x.x()) <= s.wallInner && std::abs(x.y()) <= s.wallInner) m.maxPenWall = std::max(m.maxPenWall, wallPen);
  }
  m.meanHeight = n ? sumZ / Real(n) : 0;

  // Sphere-sphere: uniform grid with cell size 2r; each pair is checked once from the lower index.
  const Real cell = 2 * r;
  auto key = [](int64_t a, int64_t b, int64_t c) {
    return uint64_t((a & 0x1FFFFF) | ((b & 0x1FFFFF) << 21) | ((c & 0x1FFFFF) << 42));
  };
  std::unordered_map<uint64_t, std::vector<uint32_t>> grid;
  grid.reserve(n);
  std::vector<std::array<int64_t, 3>> cells(n);
  for (size_t i = 0; i < n; ++i) {
    if (!pos[i].allFinite()) continue;
    cells[i] = {int64_t(std::floor(pos[i].x() / cell)), int64_t(std::floor(pos[i].y() / cell)),
                int64_t(std::floor(pos[i].z() / cell))};
    grid[key(cells[i][0], cells[i][1], cells[i][2])].push_back(uint32_t(i));
  }
  for (size_t i = 0; i < n; ++i) {
    if (!pos[i].allFinite()) continue;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          auto it = grid.find(key(cells[i][0] + dx, cells[i][1] + dy, cells[i][2] + dz));
          if (it == grid.end()) continue;
          for (uint32_t j : it->second) {
            if (j <= i) continue;
            const Real d = (pos[i] - pos[j]).norm();
            m.maxPenSphereSphere = std::max(m.maxPenSphereSphere, 2 * r - d);
          }
        }
  }
  m.maxPenetration = std::max({m.maxPenSphereSphere, m.maxPenFloor, m.maxPenWall, Real(0)});
  return m;
}

SpheresMetrics runSpheres(SpheresScene& s) {
  for (int i = 0; i < s.numSteps; ++i) s.step();
  return measureSpheres(s);
}

// ------------------------------------------------------------------------------------------------------------
// overhead
// ------------------------------------------------------------------------------------------------------------
OverheadScene buildOverheadEmpty() {
  OverheadScene s;
  initScene(s, "overhead_empty", 0.5, 1.0 / 60.0, 600);
  return s;
}

OverheadScene buildOverheadOneBox() {
  OverheadScene s;
  initScene(s, "overhead_one_box", 0.5, 1.0 / 60.0, 600);
  addGround(s);
  s.box = addBox(s, Vec3(0.5, 0.5, 0.5), 1.0, Vec3(0, 0, 0.5));
  return s;
}

OverheadMetrics runOverhead(OverheadScene& s) {
  for (int i = 0; i < s.numSteps; ++i) s.step();
  OverheadMetrics m;
  m.finite = allFinite(*s.sim);
  if (s.box) m.boxDz = s.box->getPosition().z() - 0.5;
  return m;
}

// ---- chain20 ------------------------------------------------------------------------------------------------

Chain20Scene buildChain20(Real ballMass, bool hanging) {
  Chain20Scene s;
  initScene(s, "chain20", 0.5, 1.0 / 60.0, 600);
  const Real len = 0.2;
  const Vec3 pivot(0, 0, 5);
  // Unit vector along the chain: +x laid out, -z hanging; link shape oriented along it.
  const Vec3 dir = hanging ? Vec3(0, 0, -1) : Vec3(1, 0, 0);
  const Vec3 linkHalf = hanging ? Vec3(0.025, 0.025, 0.1) : Vec3(0.1, 0.025, 0.025);
  RigidBodyRef prev;
  for (int i = 0; i < 20; ++i) {
    auto link = addBox(s, linkHalf, 1.0, pivot + dir * (len * (i + 0.5)));
    for (auto& g : link->getGeometries()) g->setEnableCollisions(false);
    auto j = std::make_shared<BallJoint>(link, prev, pivot + dir * (len * i));
    s.sim->add(j);
    s.joints.push_back(j);
    s.links.push_back(link);
    prev = link;
  }
  auto geom = std::make_shared<Geometry>(std::make_shared<Sphere>(0.2));
  geom->setMaterial(s.material);
  geom->setEnableCollisions(false);
  s.ball = std::make_shared<RigidBody>("ball");
  s.ball->add(geom);
  s.ball->setMass(ballMass);
  s.ball->setPosition(pivot + dir * (len * 20 + 0.2));
  s.sim->add(s.ball);
  auto jb = std::make_shared<BallJoint>(s.ball, prev, pivot + dir * (len * 20));
  s.sim->add(jb);
  s.joints.push_back(jb);
  return s;
}

void ChainObserver::observe() {
  Real worst = 0;
  for (const auto& j : s_.joints) {
    const Real e = (j->getFrame(0).p - j->getFrame(1).p).norm();
    worst = std::max(worst, std::isfinite(e) ? e : Real(1e300));
    sum_ += e;
    ++count_;
  }
  m_.maxSeparation = std::max(m_.maxSeparation, worst);
  m_.finalSeparation = worst;
  m_.meanSeparation = count_ ? sum_ / Real(count_) : 0;
  if (m_.firstAbove10cm < 0 && worst > 0.1) m_.firstAbove10cm = s_.sim->getTimeStamp();
  m_.finite = m_.finite && allFinite(*s_.sim);
}

ChainMetrics ChainObserver::result() const { return m_; }

ChainMetrics runChain20(Chain20Scene& s) {
  ChainObserver obs(s);
  for (int i = 0; i < s.numSteps; ++i) {
    s.sim->stepForward();
    obs.observe();
  }
  return obs.result();
}

}  // namespace scree::scenes

// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Reference scenes (defined in docs/scenes.md) and their accuracy metrics, shared by the benchmarks
// (bench/bench_*.cpp), the tests (test/) and the examples. Every builder follows docs/scenes.md to the letter:
//   z up, gravity (0, 0, -9.81), restitution 0, no damping, one scene Material carried by every body (static
//   ones included) with the scene's friction coefficient, and an explicit contact material (mat, mat) with
//   friction mu and restitution 0. The ground is a static box 100 x 100 x 1 m with its top face at z = 0.
//   Solver iterations: 10.
//
// A builder returns a struct that owns the Simulation and holds handles to the bodies its metric needs, the
// time step and the scene's defined number of steps. `run*()` steps a freshly built scene through its defined
// number of steps and returns the metrics; the observers can be fed step by step by callers that step the
// simulation themselves (benchmarks, examples).
//
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <scree/scree.h>

namespace scree::scenes {

/// docs/scenes.md common values.
struct SceneConstants {
  static constexpr Real gravity = 9.81;           ///< m/s^2, along -z
  static constexpr int solverIterations = 10;
  static constexpr Real groundHalfExtent = 50.0;  ///< 100 x 100 x 1 m ground box
  static constexpr Real groundHalfThickness = 0.5;
};

/// What every scene has.
struct Scene {
  std::string name;
  std::unique_ptr<Simulation> sim;
  MaterialRef material;                ///< the scene material (every geometry carries it)
  ContactMaterialRef contactMaterial;  ///< explicit (material, material): friction mu, restitution 0
  RigidBodyRef ground;                 ///< static ground box (null for scenes without ground)
  Real mu = 0.5;
  Real dt = 1.0 / 60.0;
  int numSteps = 0;                    ///< the scene's defined number of steps

  void step() { sim->stepForward(); }
  /// Contact points of the last step (sum over all geometry contacts).
  size_t numContactPoints() const;
};

/// A scene's common setup: Simulation with dt, gravity (0,0,-9.81), 10 iterations, scene material with mu
/// and restitution 0, explicit contact material. Exposed for tests that build variants.
void initScene(Scene& s, const std::string& name, Real mu, Real dt, int numSteps);
/// Adds the docs/scenes.md ground (static box 100 x 100 x 1, top face at z = 0) to `s`.
RigidBodyRef addGround(Scene& s);
/// A static box body carrying the scene material.
RigidBodyRef addStaticBox(Scene& s, const Vec3& halfExtents, const Vec3& position,
                          const Quat& rotation = Quat::Identity());
/// A dynamic box of the given mass carrying the scene material.
RigidBodyRef addBox(Scene& s, const Vec3& halfExtents, Real mass, const Vec3& position,
                    const Quat& rotation = Quat::Identity());

// ============================================================================================================
// 1. pyramid20
// ============================================================================================================
struct PyramidScene : Scene {
  std::vector<RigidBodyRef> boxes;  ///< row by row from the bottom, -x to +x within a row
  std::vector<Vec3> initialPositions;
  RigidBodyRef top;
  Vec3 topInitial = Vec3::Zero();
};
/// `rows` = 20 gives the reference scene (210 unit cubes, 1 kg, 1.01 m apart in a row, rows touching).
PyramidScene buildPyramid(int rows = 20, Real mu = 0.5);
inline PyramidScene buildPyramid20() { return buildPyramid(20); }

struct PyramidMetrics {
  Real maxDisplacement = 0;  ///< m, the largest |p - p0| over all boxes
  Real topDz = 0;            ///< m, top box's change in height (negative: dropped)
  bool stands = false;       ///< |topDz| < 0.1 m
  bool finite = true;
};
PyramidMetrics measurePyramid(const PyramidScene& s);
/// Steps a scene through its numSteps, then measures.
PyramidMetrics runPyramid(PyramidScene& s);

// ============================================================================================================
// 3. tower10
// ============================================================================================================
struct TowerScene : Scene {
  std::vector<RigidBodyRef> boxes;  ///< bottom to top
  std::vector<Vec3> initialPositions;
  RigidBodyRef top;
  Vec3 topInitial = Vec3::Zero();
};
TowerScene buildTower(int count = 10, Real mu = 0.5);
inline TowerScene buildTower10() { return buildTower(10); }

struct TowerMetrics {
  Real topHorizontal = 0;    ///< m, |xy - xy0| of the top box
  Real topVertical = 0;      ///< m, z - z0 of the top box
  Real maxDisplacement = 0;  ///< m, the largest |p - p0| over all boxes (for the "< 1 cm per box" tests)
  bool finite = true;
};
TowerMetrics measureTower(const TowerScene& s);
TowerMetrics runTower(TowerScene& s);

// ============================================================================================================
// 4. mass_ratio
// ============================================================================================================
struct MassRatioScene : Scene {
  RigidBodyRef light;  ///< 1 kg at z = 0.5
  RigidBodyRef heavy;  ///< 1000 kg at z = 1.5
  Real heavyTargetZ = 1.5;
};
MassRatioScene buildMassRatio(Real heavyMass = 1000.0, Real lightMass = 1.0, Real mu = 0.5);

struct MassRatioMetrics {
  Real heavyError = 0;       ///< m, |z_heavy - 1.5| at the end
  Real heavyErrorWorst = 0;  ///< m, the largest |z_heavy - 1.5| over all steps
  /// m, vertical overlap of the two boxes at the end: highest corner of the light box minus lowest corner of
  /// the heavy box (world z; > 0 overlap). NaN once the light box has been squeezed out.
  Real overlap = 0;
  Real overlapWorst = 0;     ///< m, the largest overlap over the steps before any squeeze-out
  bool squeezed = false;     ///< the light box left the heavy box's footprint at some step
  int squeezedAtStep = -1;   ///< first step (1-based) at which it was out, or -1
  bool finite = true;
};
/// Per-step observer; call observe() after each stepForward().
class MassRatioObserver {
 public:
  explicit MassRatioObserver(const MassRatioScene& s) : s_(s) {}
  void observe();
  MassRatioMetrics result() const { return m_; }

 private:
  const MassRatioScene& s_;
  MassRatioMetrics m_;
  int step_ = 0;
};
/// The light box's centre lies outside the heavy box's footprint (heavy box frame, |x| or |y| > 0.5).
bool massRatioSqueezed(const MassRatioScene& s);
/// Highest light-box corner minus lowest heavy-box corner, world z.
Real massRatioOverlap(const MassRatioScene& s);
MassRatioMetrics runMassRatio(MassRatioScene& s);

// ============================================================================================================
// 5. slide
// ============================================================================================================
struct SlideScene : Scene {
  RigidBodyRef box;
  Vec3 initialPosition = Vec3::Zero();
  Real v0 = 5.0;
  Real analyticDistance() const { return v0 * v0 / (2 * mu * SceneConstants::gravity); }  ///< 4.2474 m
  Real analyticTime() const { return v0 / (mu * SceneConstants::gravity); }               ///< 1.699 s
};
SlideScene buildSlide(Real mu = 0.3, Real v0 = 5.0);

struct SlideMetrics {
  Real distance = 0;      ///< m, x displacement at the end of the run
  Real stopTime = -1;     ///< s, time of the first step after which |v_x| < 1e-3 m/s (-1: never)
  Real distanceErr = 0;   ///< relative, (distance - analytic) / analytic
  Real timeErr = 0;       ///< relative, (stopTime - analytic) / analytic (NaN if it never stopped)
  bool finite = true;
};
class SlideObserver {
 public:
  explicit SlideObserver(const SlideScene& s) : s_(s) {}
  void observe();
  SlideMetrics result() const;
  static constexpr Real stopSpeed = 1e-3;  ///< m/s

 private:
  const SlideScene& s_;
  int step_ = 0;
  Real stopTime_ = -1;
};
SlideMetrics runSlide(SlideScene& s);

// ============================================================================================================
// 6. incline_mu05 / incline_mu06
// ============================================================================================================
struct InclineScene : Scene {
  RigidBodyRef slab;                 ///< static 20 x 10 x 1 m, rotated 30 degrees about y
  RigidBodyRef cube;                 ///< 1 kg unit cube resting on it, same orientation
  Vec3 cubeInitial = Vec3::Zero();
  Vec3 downSlope = Vec3::UnitX();    ///< unit, along the slope towards +x (descending)
  Vec3 slopeNormal = Vec3::UnitZ();  ///< unit, the slab's top-face normal
  Real angle = 0;                    ///< rad
  /// Displacement along the slope after t seconds: 0 when mu >= tan(angle) (sticks), else
  /// 0.5 g (sin a - mu cos a) t^2 (1.3143 m for mu = 0.5, t = 2 s).
  Real analyticDisplacement(Real t) const;
};
InclineScene buildIncline(Real mu, Real angleDeg = 30.0);

struct InclineMetrics {
  Real displacement = 0;  ///< m, (p - p0) . downSlope at the end
  Real analytic = 0;      ///< m, analyticDisplacement(numSteps * dt)
  Real error = 0;         ///< relative when analytic > 0, else absolute m
  bool finite = true;
};
InclineMetrics measureIncline(const InclineScene& s);
InclineMetrics runIncline(InclineScene& s);

// ============================================================================================================
// 2. spheres10k, spheres10k_jitter, and lattices of other sizes
// ============================================================================================================
struct SphereLatticeParams {
  size_t count = 10000;
  int perRow = 18;                  ///< spheres per row: a layer holds perRow^2
  Real radius = 0.05;
  Real spacing = 0.11;
  Real density = 2500;
  Real mu = 0.5;
  Real dt = 1.0 / 100.0;
  int numSteps = 300;
  bool jitter = false;
  Real jitterAmplitude = 0.004;     ///< m, x and y offsets uniform in +-amplitude
  uint64_t seed = 0x5C4EEB0A7E5EEDull;  ///< splitmix64 seed of the jitter
  Real wallHeight = 5.0;
  Real wallThickness = 0.2;
};

struct SpheresScene : Scene {
  SphereLatticeParams params;
  std::vector<RigidBodyRef> spheres;
  std::vector<RigidBodyRef> walls;  ///< +x, -x, +y, -y
  Real wallInner = 1.0;             ///< m, inner faces at x = +-wallInner and y = +-wallInner
};
/// docs/scenes.md lattice: x, y = (i - (perRow/2 - 0.5)) * spacing, z = radius + 0.01 + spacing * k, filled layer
/// by layer, within a layer row by row (j along y outer, i along x inner). With perRow = 18 the walls' inner
/// faces sit at +-(perRow * spacing / 2 + 0.01) = +-1 m.
SpheresScene buildSphereLattice(const SphereLatticeParams& p);
SpheresScene buildSpheres10k();        ///< no jitter
SpheresScene buildSpheres10kJitter();  ///< +-0.004 m jitter in x and y

/// splitmix64 (Steele, Lea, Flood 2014): the jitter's generator. Advances `state`.
uint64_t splitmix64(uint64_t& state);
/// Uniform in [-1, 1) from splitmix64's top 53 bits.
Real splitmixSymmetric(uint64_t& state);

struct SpheresMetrics {
  Real kineticEnergy = 0;     ///< J, sum of 0.5 m v^2 + 0.5 (0.4 m r^2) w^2
  Real maxPenetration = 0;    ///< m, over sphere-sphere (grid), sphere-floor, sphere-wall
  Real maxPenSphereSphere = 0, maxPenFloor = 0, maxPenWall = 0;
  Real meanHeight = 0;        ///< m, centre z
  Real maxHeight = 0;         ///< m, centre z
  size_t escaped = 0;         ///< centre outside the container (|x| or |y| > wallInner, or z < 0) or non-finite
  bool finite = true;
};
SpheresMetrics measureSpheres(const SpheresScene& s);
SpheresMetrics runSpheres(SpheresScene& s);

// ============================================================================================================
// overhead: the cost of a step with nothing (or almost nothing) in it
// ============================================================================================================
struct OverheadScene : Scene {
  RigidBodyRef box;  ///< null for the empty scene
};
/// An empty simulation (no ground, no bodies); dt 1/60, 600 steps.
OverheadScene buildOverheadEmpty();
/// The ground and one unit cube (1 kg) resting on it at z = 0.5; mu 0.5, dt 1/60, 600 steps.
OverheadScene buildOverheadOneBox();

struct OverheadMetrics {
  Real boxDz = 0;  ///< m, z - 0.5 of the box (0 for the empty scene)
  bool finite = true;
};
OverheadMetrics runOverhead(OverheadScene& s);

// ============================================================================================================
// helpers
// ============================================================================================================
/// Position, rotation and velocities of every dynamic body are finite.
bool allFinite(const Simulation& sim);
/// The 8 world-space corners of a box body with half extents he.
std::vector<Vec3> boxCorners(const RigidBody& body, const Vec3& halfExtents);

// 7. chain20: pivot at (0, 0, 5), 20 box links (0.2 x 0.05 x 0.05 m, 1 kg) laid along +x and joined end to end
// by ball joints, a 100 kg sphere (r = 0.2) on a ball joint 0.2 m beyond the last link; collisions off;
// released from rest; dt 1/60, 600 steps. `hanging` builds the same chain hanging straight down at rest
// (a static-load check; not part of docs/scenes.md).
struct Chain20Scene : Scene {
  std::vector<RigidBodyRef> links;
  RigidBodyRef ball;
  std::vector<std::shared_ptr<BallJoint>> joints;  ///< pivot first, ball joint last
};
Chain20Scene buildChain20(Real ballMass = 100.0, bool hanging = false);

struct ChainMetrics {
  Real maxSeparation = 0;     ///< m, largest anchor separation over all joints and steps
  Real meanSeparation = 0;    ///< m, mean over joints and steps
  Real finalSeparation = 0;   ///< m, largest over joints at the last step
  Real firstAbove10cm = -1;   ///< s, first time any joint separates by more than 0.1 m (-1: never)
  bool finite = true;
};
class ChainObserver {
 public:
  explicit ChainObserver(const Chain20Scene& s) : s_(s) {}
  void observe();
  ChainMetrics result() const;

 private:
  const Chain20Scene& s_;
  ChainMetrics m_;
  Real sum_ = 0;
  size_t count_ = 0;
};
ChainMetrics runChain20(Chain20Scene& s);

}  // namespace scree::scenes

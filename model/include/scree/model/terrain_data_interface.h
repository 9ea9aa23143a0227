// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// TerrainDataInterface (AGX manual 25.1.1.1 and 25.1.2.1-25.1.2.4: agxModel::TerrainDataInterface): the
// per-vertex data of a Terrain and the parameters of its compression law. Reached through
// Terrain::getDataInterface(), which returns a reference (the manual's `->getDataInterface()->add(...)` is
// `.getDataInterface().add(...)` here).
//
// Vertices are addressed as the height field addresses them: (x, y) = (i, j), i along the height field's +x,
// j along +y, 0 <= x < resolutionX, 0 <= y < resolutionY.
//
// Material map. Every vertex holds a material index 0..255 (initially 0). add(material, index, ...) registers a
// material and its terrain properties at an index; a vertex whose index has no registered material is
// *unmapped*: it uses the terrain's default material (the terrain geometry's material, or the simulation's
// default material when the geometry has none) with deformability 0, particle adhesion 0 and angle of repose 0.
// So `add(sand, 0, 0, 2.0)` alone makes the whole terrain deformable sand; a PNG map selects several.
//
// PNG orientation (setMaterialMapping(path)): the image must have exactly resolutionX columns and resolutionY
// rows. Image column c is vertex x = c (left to right = +x); image row 0, the top row of the image, is the
// highest y (y = resolutionY - 1), and the bottom row is y = 0. Seen from above with +x to the right and +y up
// the page, the image lies on the terrain as it looks on screen. The pixel value (8-bit grey or palette index,
// as the reader accepts it) is the material index.
//
// Compression (the law itself is in terrain.h): per vertex the compression level c >= 0 and the Young's
// modulus multiplier m(c) = 2^((d+1) c), capped at the max compression multiplier M (d: the vertex material's
// deformability; d = 0 is non-deformable ground, m = 1). getYoungsModulusMultiplier(x, y) returns the stored
// multiplier, which is always that formula at the stored compression (kept in step with every change of c, d
// and M); contacts read it.
//
// Validation: every setter checks first and throws std::invalid_argument naming the function, the parameter and
// the value (e.g. "TerrainDataInterface::add: deformability = -1 is invalid (must be finite and >= 0)"), and
// leaves the interface unchanged.
//
// Subclassing (as the manual allows): the public methods are virtual, so a subclass can observe or extend
// configuration (log, mirror to a UI, add checks) and change what the getters report. The terrain's contacts and
// its compression step read the stored per-vertex arrays directly (flat arrays, no virtual call per point);
// install a subclass with Terrain::setDataInterface().
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "scree/core/material.h"
#include "scree/core/math.h"

namespace scree {

class Terrain;

class TerrainDataInterface {
 public:
  static constexpr size_t kNumMaterialIndices = 256;
  /// Defaults: with d = 1 they are the rounded least-squares fit of the law's settled plate sinkage to Bekker's
  /// curve for Wong's dry sand (LLL; b = 0.5 m) over 10-100 kPa (docs/terrain.md, plate-sinkage study): p0 = 7 kPa,
  /// M = 16 (the smallest power of two with p0 M above 100 kPa), D = 0.12 m. maxChange 1 per step lets a vertex
  /// go from loose (m = 1) to M = 16 in 15 steps and bounds how fast the ground hardens under a fast, deep contact.
  static constexpr Real defaultMaxCompressionMultiplier = 16;
  static constexpr Real defaultDepthForMaxCompression = 0.12;  ///< m
  static constexpr Real defaultMaxYoungsChangePerTimestep = 1;  ///< multiplier units per time step
  /// Pa. Loose, uncompressed soil (m = 1) starts to yield at this pressure (the fit above; a dry sand carries a
  /// walking person, 15-25 kPa, with a centimetre or two of sinkage).
  static constexpr Real defaultYieldPressure = 7e3;

  /// Sized for the terrain's height field; all vertices unmapped (index 0, nothing registered), c = 0, m = 1.
  explicit TerrainDataInterface(const Terrain& terrain);
  virtual ~TerrainDataInterface() = default;
  TerrainDataInterface(const TerrainDataInterface&) = delete;
  TerrainDataInterface& operator=(const TerrainDataInterface&) = delete;

  size_t getResolutionX() const { return nx_; }
  size_t getResolutionY() const { return ny_; }

  // --- material map -------------------------------------------------------------------------------------------
  /// Reads the material index of every vertex from a PNG file (orientation: file comment). Throws
  /// std::invalid_argument naming the path and the problem for a missing or unreadable file, a file that is not
  /// a PNG, a truncated PNG, a colour type the reader does not support, or an image whose size differs from the
  /// height-field resolution; the map is unchanged then.
  virtual void setMaterialMapping(const std::string& filePath);
  /// Material index of one vertex; index < 256.
  virtual void setMaterialMapping(size_t x, size_t y, size_t materialIndex);
  virtual size_t getMaterialIndex(size_t x, size_t y) const;

  /// Registers `material` at `materialIndex` (< 256) with its terrain properties: particleAdhesion (>= 0, the
  /// adhesive force of particles dug from it, N; used by digging), deformability d (>= 0; 0 = non-deformable,
  /// larger hardens exponentially faster with compression), angleOfRepose (rad, in [0, pi/2); 0 = use
  /// atan(friction); used by avalanches). An index already registered is replaced. Returns nothing; throws on a
  /// null material or an invalid value.
  virtual void add(MaterialRef material, size_t materialIndex, Real particleAdhesion = 0, Real deformability = 0,
                   Real angleOfRepose = 0);
  /// Unregisters the material from every index holding it; those vertices become unmapped. False if absent.
  virtual bool remove(const MaterialRef& material);
  /// The registered material of the vertex, or the terrain's default material for an unmapped vertex (may be
  /// null only when the terrain geometry has no material and the terrain is not in a simulation).
  virtual MaterialRef getMaterial(size_t x, size_t y) const;
  /// The material particles made from this vertex take their surface parameters from: getMaterial(x, y). Digging
  /// makes each particle a derived material (density for mass = bulk density x carried volume, the particle
  /// adhesion between particles; terrain.h).
  virtual MaterialRef getParticleMaterial(size_t x, size_t y) const;
  /// Terrain properties of the vertex's material (0 for an unmapped vertex).
  virtual Real getDeformability(size_t x, size_t y) const;
  virtual Real getParticleAdhesion(size_t x, size_t y) const;
  virtual Real getAngleOfRepose(size_t x, size_t y) const;

  // --- compression ------------------------------------------------------------------------------------------
  /// Compression level c of a vertex (dimensionless, >= 0).
  virtual Real getCompression(size_t x, size_t y) const;
  /// Sets c (finite, >= 0) and the vertex's multiplier m(c) (capped). Heights and the volume ledger are not
  /// touched: this is a state edit, not soil pressed out.
  virtual void setCompression(size_t x, size_t y, Real compression);
  /// m(c) = 2^((d+1) c) capped at the max compression multiplier; 1 where d = 0.
  virtual Real getYoungsModulusMultiplier(size_t x, size_t y) const;
  /// c_max(d) = log2(M) / (d + 1): the compression at which the vertex reaches M (0 where d = 0).
  virtual Real getMaxCompression(size_t x, size_t y) const;

  /// M: >= 1 and a power of two (log2(M) is the exponent's cap, manual 25.1.2.2). M = 1: the ground cannot
  /// harden, and the terrain treats it as non-deformable. Re-caps every vertex's multiplier.
  virtual void setMaxCompressionMultiplier(Real multiplier);
  Real getMaxCompressionMultiplier() const { return maxMultiplier_; }
  /// D, m, finite and > 0: lowering a vertex by D (pressed, dug or pushed) hardens every material to M.
  virtual void setDepthForMaxCompression(Real depth);
  Real getDepthForMaxCompression() const { return depthForMax_; }
  /// Bound on how much a vertex's multiplier may grow in one time step (>= 0, may be +infinity = no bound;
  /// 0 freezes the ground: nothing yields).
  virtual void setMaxYoungsChangePerTimestep(Real maxMultiplierChange);
  Real getMaxYoungsChangePerTimestep() const { return maxChange_; }
  /// p0, Pa, finite and > 0: the pressure at which loose, uncompressed soil (m = 1) starts to yield; a vertex
  /// with multiplier m yields above p0 m.
  virtual void setYieldPressure(Real pressure);
  Real getYieldPressure() const { return yieldPressure_; }

  // --- ground cutting force (manual 25.1.2.13; implemented in terrain_shovel.cpp) -----------------------------
  /// Extra resistance a shovel meets where it touches the terrain (finite, >= 0; default 0 = no effect; otherwise
  /// std::invalid_argument, unchanged). Read on every shovel-terrain contact point by the terrain's contact
  /// listener, so it may change at run time (a full bucket digs harder):
  ///  - a shovel that is also a deformer (bool geometry property Terrain::DeformerProperty, either value): a
  ///    force, N - a friction force along the shovel's forward direction only (terrain.h, "A shovel that is also a
  ///    deformer"): one velocity row at the cutting edge along forward, impulse bounds +-value h, armed on the
  ///    steps the shovel touches the terrain. It resists motion along forward with exactly `value`, holds the
  ///    shovel below it, never drives it, and does not resist sideways sliding. Read back as
  ///    TerrainShovelStats::groundCuttingForce.
  ///  - any other shovel: a dimensionless scale - each point's friction coefficient mu(shovel, terrain) becomes
  ///    mu (1 + value), so the friction bound is (1 + value) mu N. Why 1 + value and not value: 0 must leave
  ///    the contact as it was (the default), and a scale of 0 would remove its friction. This one acts through
  ///    the contact points' friction rows, hence in every tangential direction (the manual: "a friction
  ///    coefficient scale").
  virtual void setShovelGroundCuttingForce(Real force);
  Real getShovelGroundCuttingForce() const { return groundCuttingForce_; }
  // --- end ground cutting force -------------------------------------------------------------------------------

  /// The law's multiplier for compression c and deformability d under cap M (see terrain.h).
  static Real multiplier(Real compression, Real deformability, Real maxMultiplier);

  // --- particle contact materials (manual 25.1.2.10, 25.1.2.14; terrain.h "External materials and particle
  // solve type") ---------------------------------------------------------------------------------------------
  /// Registers a material that terrain particles meet (a bucket's steel): for every terrain-particle material
  /// the terrain registers a ContactMaterial (particle material, material) with E = max(E of material, E of the
  /// terrain material the particle was dug from), solve type SPLIT and the material's surface viscosity - now
  /// for the particle materials that exist and later for new ones. Null throws std::invalid_argument; adding a
  /// material twice changes nothing.
  virtual void addExternalMaterial(MaterialRef material);
  /// Unregisters it: its particle contact materials leave the MaterialManager. False if it was not registered.
  virtual bool removeExternalMaterial(const MaterialRef& material);
  /// In registration order.
  const std::vector<MaterialRef>& getExternalMaterials() const { return externalMaterials_; }
  bool isExternalMaterial(const Material* material) const;

  /// How particle-particle contacts are solved: ITERATIVE (default; the particle PGS sweeps) or DIRECT (a glued
  /// lump in the direct solver: infinite friction and adhesion, solve type DIRECT, surface viscosity = the
  /// inverse friction multiplier x the terrain material's surface viscosity; terrain.h). SPLIT and
  /// DIRECT_AND_ITERATIVE (and any other value) throw std::invalid_argument: with infinite friction their
  /// iterative friction rows would be unbounded PGS rows, so they are not particle modes. Applies to the
  /// particles that exist too.
  virtual void setParticleFrictionSolveType(FrictionModel::SolveType solveType);
  FrictionModel::SolveType getParticleFrictionSolveType() const { return particleSolveType_; }
  /// Scale of the particle-particle friction compliance in DIRECT mode (finite, >= 0; default 1): surface
  /// viscosity = multiplier x the terrain material's surface viscosity. Smaller: stiffer friction (0: none of
  /// the friction rows' compliance). Not used in ITERATIVE mode. Otherwise std::invalid_argument, unchanged.
  virtual void setInverseFrictionMultiplier(Real inverseMultiplier);
  Real getInverseFrictionMultiplier() const { return inverseFrictionMultiplier_; }

 protected:
  /// Throws std::invalid_argument when (x, y) is not a vertex.
  void checkVertex(const char* where, size_t x, size_t y) const;
  size_t vertex(size_t x, size_t y) const { return y * nx_ + x; }

 private:
  friend class Terrain;
  struct Entry {
    MaterialRef material;  ///< null: unregistered
    Real particleAdhesion = 0, deformability = 0, angleOfRepose = 0;
  };
  Real deformabilityOf(size_t v) const { return entries_[index_[v]].deformability; }
  /// Recomputes multiplier_ of every vertex (after d or M changed).
  void refreshMultipliers();
  MaterialRef defaultMaterial() const;

  const Terrain& terrain_;
  size_t nx_, ny_;
  // Per-vertex state, row-major with x fastest (index y * resolutionX + x), as HeightField::getHeights().
  std::vector<uint8_t> index_;      ///< material index
  std::vector<Real> compression_;   ///< c
  std::vector<Real> multiplier_;    ///< m(c), kept equal to multiplier(c, d, M)
  std::array<Entry, kNumMaterialIndices> entries_;
  Real maxMultiplier_ = defaultMaxCompressionMultiplier;
  Real depthForMax_ = defaultDepthForMaxCompression;
  Real maxChange_ = defaultMaxYoungsChangePerTimestep;
  Real yieldPressure_ = defaultYieldPressure;
  Real groundCuttingForce_ = 0;  ///< ground cutting force (terrain_shovel.cpp)
  // Particle contact materials (issue 16).
  std::vector<MaterialRef> externalMaterials_;
  FrictionModel::SolveType particleSolveType_ = FrictionModel::ITERATIVE;
  Real inverseFrictionMultiplier_ = 1;
};

}  // namespace scree

// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Terrain particle contact materials (terrain.h, "External materials and particle solve type"): the contact
// material of each terrain-particle material with itself (particle adhesion, the Young's multiplier, the
// particle friction solve type) and with every external material, the settings that drive them, and the
// warning for particles touching a geometry whose material is not external (manual FAQ 25.1.3.2 / 25.1.3.4).
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
/// N: the adhesive force of ITERATIVE particle-particle contacts when the material's particle adhesion is 0 (the
/// contact law applies a rest overlap only to adhesive contacts; terrain.h).
constexpr Real kNoAdhesion = 1e-9;
constexpr Real kInf = std::numeric_limits<Real>::infinity();

/// Every surface parameter through the setters (they keep the target's own name for error messages).
void copySurface(const SurfaceParameters& from, SurfaceParameters& to) {
  to.setYoungsModulus(from.getYoungsModulus());
  to.setDamping(from.getDamping());
  to.setFrictionCoefficient(from.getFrictionCoefficient());
  to.setRestitution(from.getRestitution());
  to.setAdhesion(from.getAdhesiveForce(), from.getAdhesiveOverlap());
  to.setSurfaceViscosity(from.getSurfaceViscosity());
  to.setRollingResistanceCoefficient(from.getRollingResistanceCoefficient());
}
}  // namespace

// ---- settings -------------------------------------------------------------------------------------------------
// The attributes and the data interface hold a const Terrain& (they are members / built for one terrain); a
// Terrain is never created const-qualified by the library, so writing its contact materials through it is sound.

void TerrainParticleAttributes::setParticleYoungsModulusMultiplier(Real multiplier) {
  detail::requirePositive("TerrainParticleAttributes::setParticleYoungsModulusMultiplier", "multiplier", multiplier);
  youngsMultiplier_ = multiplier;
  const_cast<Terrain&>(terrain_).syncParticleContactMaterials();
}

void TerrainDataInterface::addExternalMaterial(MaterialRef material) {
  detail::requireNonNull("TerrainDataInterface::addExternalMaterial", "material", material.get());
  if (isExternalMaterial(material.get())) return;
  externalMaterials_.push_back(std::move(material));
  const_cast<Terrain&>(terrain_).syncParticleContactMaterials();
}

bool TerrainDataInterface::removeExternalMaterial(const MaterialRef& material) {
  auto it = std::find(externalMaterials_.begin(), externalMaterials_.end(), material);
  if (!material || it == externalMaterials_.end()) return false;
  externalMaterials_.erase(it);
  const_cast<Terrain&>(terrain_).syncParticleContactMaterials();
  return true;
}

bool TerrainDataInterface::isExternalMaterial(const Material* material) const {
  for (const MaterialRef& m : externalMaterials_)
    if (m.get() == material) return true;
  return false;
}

void TerrainDataInterface::setParticleFrictionSolveType(FrictionModel::SolveType solveType) {
  if (solveType != FrictionModel::ITERATIVE && solveType != FrictionModel::DIRECT)
    detail::throwInvalid("TerrainDataInterface::setParticleFrictionSolveType", "solveType", (long long)solveType,
                         "must be FrictionModel::ITERATIVE (1) or FrictionModel::DIRECT (0); SPLIT and "
                         "DIRECT_AND_ITERATIVE are not particle modes");
  particleSolveType_ = solveType;
  const_cast<Terrain&>(terrain_).syncParticleContactMaterials();
}

void TerrainDataInterface::setInverseFrictionMultiplier(Real inverseMultiplier) {
  detail::requireNonNegative("TerrainDataInterface::setInverseFrictionMultiplier", "inverseMultiplier",
                             inverseMultiplier);
  inverseFrictionMultiplier_ = inverseMultiplier;
  const_cast<Terrain&>(terrain_).syncParticleContactMaterials();
}

// ---- the contact materials ------------------------------------------------------------------------------------
void Terrain::syncParticleContactMaterials() {
  for (ParticleMaterialCache& c : particleMaterials_) syncParticleContactMaterials(c);
}

void Terrain::syncParticleContactMaterials(ParticleMaterialCache& c) {
  Simulation* sim = getSimulation();
  if (!sim) return;  // onAdd syncs
  MaterialManager& mm = sim->getMaterialManager();
  const TerrainDataInterface& di = *data_;
  const Material& src = *c.sourceRef;

  // Particle-particle: the vertex material's parameters, E x the Young's multiplier, resting at the lattice's
  // overlap r(sqrt2 - 1) (see terrain.h for why DIRECT keeps that overlap too).
  if (!c.self) c.self = std::make_shared<ContactMaterial>(c.material, c.material);
  ContactMaterial& self = *c.self;
  copySurface(src, self);
  self.setYoungsModulus(src.getYoungsModulus() * particleAttributes_.getParticleYoungsModulusMultiplier());
  const Real restOverlap = c.radius * (kSqrt2 - 1);
  if (di.particleSolveType_ == FrictionModel::DIRECT) {
    self.setFrictionCoefficient(kInf);
    self.setAdhesion(kInf, restOverlap);
    self.setSurfaceViscosity(di.inverseFrictionMultiplier_ * src.getSurfaceViscosity());
    self.setSolveType(FrictionModel::DIRECT);
  } else {
    self.setAdhesion(std::max(c.adhesion, kNoAdhesion), restOverlap);
    self.setSolveType(FrictionModel::ITERATIVE);
  }
  mm.add(c.self);

  // DIRECT mode: the lump's support by the terrain is ITERATIVE, explicitly (a user's SPLIT or DIRECT terrain
  // material would put bounded rows, i.e. pivots, into the lump's direct solve); the solve stage alternates the
  // direct solve of the bonds with the sweeps over these contacts and ends with the direct solve (terrain.h).
  const MaterialRef groundMat = defaultMaterial();
  if (c.ground && (di.particleSolveType_ != FrictionModel::DIRECT || c.groundMaterial != groundMat)) {
    mm.remove(c.ground);
    c.ground.reset();
    c.groundMaterial.reset();
  }
  if (di.particleSolveType_ == FrictionModel::DIRECT && groundMat && !di.isExternalMaterial(groundMat.get())) {
    if (!c.ground) c.ground = std::make_shared<ContactMaterial>(c.material, groundMat);
    c.groundMaterial = groundMat;
    SurfaceParameters sp;
    mm.resolve(c.material.get(), groundMat.get(), sp, nullptr);
    copySurface(sp, *c.ground);
    c.ground->setSolveType(FrictionModel::ITERATIVE);
    mm.add(c.ground);
  }

  // Externals that left: unregister their contact materials.
  for (size_t k = 0; k < c.external.size();) {
    if (di.isExternalMaterial(c.external[k].first.get())) {
      ++k;
      continue;
    }
    mm.remove(c.external[k].second);
    c.external.erase(c.external.begin() + std::ptrdiff_t(k));
  }
  // Every external: the pair's parameters as the soil meets that material (an explicit contact material of the
  // two if the user made one, else the combination), with E = max(E_external, E_terrain material), solve type
  // SPLIT (stiff normals solved directly, friction iteratively) and the external material's surface viscosity
  // (the bucket's steel sets how its friction yields, whatever soil slides on it).
  for (const MaterialRef& ext : di.externalMaterials_) {
    ContactMaterialRef cm;
    for (const auto& [m, x] : c.external)
      if (m == ext) cm = x;
    if (!cm) {
      cm = std::make_shared<ContactMaterial>(c.material, ext);
      c.external.emplace_back(ext, cm);
    }
    SurfaceParameters sp;
    mm.resolve(&src, ext.get(), sp, nullptr);
    copySurface(sp, *cm);
    cm->setYoungsModulus(std::max(ext->getYoungsModulus(), src.getYoungsModulus()));
    cm->setSurfaceViscosity(ext->getSurfaceViscosity());
    // DIRECT particle mode: ITERATIVE, so the direct solve holds only the lump's equality bonds (no pivot) and
    // the bucket's contacts are swept between its direct solves (solve_stage.cpp, lumpPath).
    cm->setSolveType(di.particleSolveType_ == FrictionModel::DIRECT ? FrictionModel::ITERATIVE
                                                                     : FrictionModel::SPLIT);
    mm.add(cm);
  }
}

// ---- the FAQ warning ------------------------------------------------------------------------------------------
// Called from the terrain's contact listener (PARTICLE_CONTACT, terrain.cpp) with this step's particle-geometry
// contacts.
void Terrain::checkParticleContacts(const std::vector<ParticleContact>& pg) {
  // A terrain without particles pays this one test per step (and the simulation calls no particle listener at
  // all while there are no particles).
  if (particles_.empty() || pg.empty()) return;
  Simulation& sim = *getSimulation();
  const GranularBodySystem& gbs = sim.getGranularBodySystem();
  const std::vector<uint32_t>& index = gbs.materialIndices();
  const std::vector<MaterialRef>& table = gbs.getMaterialTable();
  auto isTerrainParticle = [&](size_t dense) {
    const Material* pm = dense < index.size() ? table[index[dense]].get() : nullptr;
    for (const ParticleMaterialCache& pc : particleMaterials_)
      if (pc.material.get() == pm) return true;
    return false;
  };
  const Material* fallback = sim.getMaterialManager().getDefaultMaterial().get();
  const TerrainDataInterface& di = *data_;
  for (const ParticleContact& c : pg) {
    if (c.sensor || !c.enabled || !(c.depth >= 0) || !c.geometry || c.geometry == geometry_.get()) continue;
    const Material* gm = c.geometry->getMaterial() ? c.geometry->getMaterial().get() : fallback;
    if (di.isExternalMaterial(gm) ||
        std::find(warnedMaterials_.begin(), warnedMaterials_.end(), gm) != warnedMaterials_.end())
      continue;
    if (!isTerrainParticle(c.a)) continue;
    const Material* pm = table[index[c.a]].get();
    warnedMaterials_.push_back(gm);
    SurfaceParameters sp;
    sim.getMaterialManager().resolve(pm, gm, sp, nullptr);
    Logger::warning("Terrain \"" + getModelName() + "\": terrain particles touch geometry \"" +
                    c.geometry->getName() + "\" of material \"" + gm->getName() +
                    "\", which is not an external material of the terrain: they meet it through the soil's "
                    "contact parameters (E = " + detail::formatValue(sp.getYoungsModulus()) +
                    " N/m) and can sink into or fall through it. Call "
                    "terrain.getDataInterface().addExternalMaterial(material) for that material.");
  }
}

}  // namespace scree

// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
#include "scree/core/material.h"

#include <atomic>
#include <cmath>

#include "scree/core/errors.h"

namespace scree {

void FrictionModel::setSolveType(SolveType t) {
  if (t < DIRECT || t > SPLIT) detail::throwInvalid("FrictionModel::setSolveType", "solveType", (long long)t, "unknown solve type");
  solveType_ = t;
}

void SurfaceParameters::setYoungsModulus(Real e) {
  const std::string where = std::string(where_) + "::setYoungsModulus";
  detail::requirePositive(where, "youngsModulus", e);
  youngsModulus_ = e;
}
void SurfaceParameters::setDamping(Real tau) {
  const std::string where = std::string(where_) + "::setDamping";
  detail::requireNonNegative(where, "damping", tau);
  damping_ = tau;
}
void SurfaceParameters::setFrictionCoefficient(Real mu) {
  const std::string where = std::string(where_) + "::setFrictionCoefficient";
  detail::requireNonNegativeOrInf(where, "frictionCoefficient", mu);
  friction_ = mu;
}
void SurfaceParameters::setRestitution(Real e) {
  const std::string where = std::string(where_) + "::setRestitution";
  detail::requireInRange(where, "restitution", e, 0.0, 1.0);
  restitution_ = e;
}
void SurfaceParameters::setAdhesion(Real force, Real overlap) {
  const std::string where = std::string(where_) + "::setAdhesion";
  detail::requireNonNegativeOrInf(where, "adhesiveForce", force);
  detail::requireNonNegative(where, "adhesiveOverlap", overlap);
  adhesiveForce_ = force;
  adhesiveOverlap_ = overlap;
}
void SurfaceParameters::setSurfaceViscosity(Real v) {
  const std::string where = std::string(where_) + "::setSurfaceViscosity";
  detail::requireNonNegative(where, "surfaceViscosity", v);
  surfaceViscosity_ = v;
}
void SurfaceParameters::setRollingResistanceCoefficient(Real c) {
  const std::string where = std::string(where_) + "::setRollingResistanceCoefficient";
  detail::requireNonNegativeOrInf(where, "rollingResistanceCoefficient", c);
  rollingResistance_ = c;
}

namespace {
uint32_t nextMaterialId() {
  static std::atomic<uint32_t> counter{1};
  return counter++;
}
}  // namespace

Material::Material(const std::string& name) : name_(name), id_(nextMaterialId()) { where_ = "Material"; }

void Material::setDensity(Real rho) {
  detail::requirePositive("Material::setDensity", "density", rho);
  density_ = rho;
}

void ContactMaterial::combine(const Material& a, const Material& b, SurfaceParameters& out) {
  // Springs in series for stiffness; geometric means for friction and restitution; sums for the viscous
  // compliance and adhesion (docs/design.md §3). Damping time: the mean, so equal materials keep their value.
  struct Access : SurfaceParameters {
    static void set(SurfaceParameters& o, Real E, Real tau, Real mu, Real e, Real af, Real ao, Real sv, Real rr) {
      Access& s = static_cast<Access&>(o);
      s.youngsModulus_ = E;
      s.damping_ = tau;
      s.friction_ = mu;
      s.restitution_ = e;
      s.adhesiveForce_ = af;
      s.adhesiveOverlap_ = ao;
      s.surfaceViscosity_ = sv;
      s.rollingResistance_ = rr;
    }
  };
  const Real Ea = a.getYoungsModulus(), Eb = b.getYoungsModulus();
  const Real E = (std::isinf(Ea) ? Eb : std::isinf(Eb) ? Ea : Ea * Eb / (Ea + Eb));
  const Real mua = a.getFrictionCoefficient(), mub = b.getFrictionCoefficient();
  const Real mu = (std::isinf(mua) || std::isinf(mub)) ? ((mua == 0 || mub == 0) ? 0.0 : INFINITY) : std::sqrt(mua * mub);
  Access::set(out, E, 0.5 * (a.getDamping() + b.getDamping()), mu, std::sqrt(a.getRestitution() * b.getRestitution()),
              a.getAdhesiveForce() + b.getAdhesiveForce(), a.getAdhesiveOverlap() + b.getAdhesiveOverlap(),
              a.getSurfaceViscosity() + b.getSurfaceViscosity(),
              a.getRollingResistanceCoefficient() + b.getRollingResistanceCoefficient());
}

ContactMaterial::ContactMaterial(MaterialRef a, MaterialRef b) {
  where_ = "ContactMaterial";
  detail::requireNonNull("ContactMaterial::ContactMaterial", "material1", a.get());
  detail::requireNonNull("ContactMaterial::ContactMaterial", "material2", b.get());
  m1_ = std::move(a);
  m2_ = std::move(b);
  combine(*m1_, *m2_, *this);
  frictionModel_ = std::make_shared<IterativeProjectedConeFriction>();
}

void ContactMaterial::setFrictionModel(FrictionModelRef model) {
  detail::requireNonNull("ContactMaterial::setFrictionModel", "frictionModel", model.get());
  frictionModel_ = std::move(model);
}

void ContactMaterial::setSolveType(FrictionModel::SolveType t) { frictionModel_->setSolveType(t); }

MaterialManager::MaterialManager() : default_(std::make_shared<Material>("DefaultMaterial")) {}

ContactMaterialRef MaterialManager::getOrCreateContactMaterial(MaterialRef a, MaterialRef b) {
  detail::requireNonNull("MaterialManager::getOrCreateContactMaterial", "material1", a.get());
  detail::requireNonNull("MaterialManager::getOrCreateContactMaterial", "material2", b.get());
  auto k = key(a.get(), b.get());
  auto it = explicit_.find(k);
  if (it != explicit_.end()) return it->second;
  auto cm = std::make_shared<ContactMaterial>(std::move(a), std::move(b));
  explicit_[k] = cm;
  return cm;
}

ContactMaterialRef MaterialManager::getContactMaterial(const MaterialRef& a, const MaterialRef& b) const {
  if (!a || !b) return nullptr;
  auto it = explicit_.find(key(a.get(), b.get()));
  return it == explicit_.end() ? nullptr : it->second;
}

void MaterialManager::add(ContactMaterialRef cm) {
  detail::requireNonNull("MaterialManager::add", "contactMaterial", cm.get());
  explicit_[key(cm->getMaterial1().get(), cm->getMaterial2().get())] = std::move(cm);
}

bool MaterialManager::remove(const ContactMaterialRef& cm) {
  if (!cm) return false;
  auto it = explicit_.find(key(cm->getMaterial1().get(), cm->getMaterial2().get()));
  if (it == explicit_.end() || it->second != cm) return false;
  explicit_.erase(it);
  return true;
}

void MaterialManager::resolve(const Material* a, const Material* b, SurfaceParameters& outParams,
                              const FrictionModel** outFriction) const {
  if (!a) a = default_.get();
  if (!b) b = default_.get();
  if (!explicit_.empty()) {
    auto it = explicit_.find(key(a, b));
    if (it != explicit_.end()) {
      outParams = *it->second;
      if (outFriction) *outFriction = it->second->getFrictionModel().get();
      return;
    }
  }
  ContactMaterial::combine(*a, *b, outParams);
  if (outFriction) *outFriction = &defaultFriction_;
}

}  // namespace scree

// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Materials, contact materials and friction models (AGX: agx::Material, agx::ContactMaterial,
// agx::MaterialManager, agx::FrictionModel).
//
// Defaults (docs/design.md §3, what AGX users expect), each defined once below in `MaterialDefaults`:
//   density 1000 kg/m^3; Young's modulus 4e8 Pa, used as the contact's normal spring constant per contact
//   point (N/m; see solver/spook.h for the mapping to SPOOK compliance); restitution 0.5; contact damping
//   time 0.075 s; friction coefficient 0.41667; surface viscosity (friction-row compliance) 5e-9 m/(N s);
//   adhesive force 0 N with adhesive overlap 0 m; rolling resistance 0.
// Combination of two materials without an explicit ContactMaterial:
//   Young's modulus as springs in series E1*E2/(E1+E2); friction and restitution geometric means;
//   damping time the mean; surface viscosity, adhesive force, adhesive overlap and rolling resistance summed.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>

#include "scree/core/math.h"

namespace scree {

struct MaterialDefaults {
  static constexpr Real density = 1000.0;
  static constexpr Real youngsModulus = 4e8;
  static constexpr Real restitution = 0.5;
  static constexpr Real damping = 0.075;
  static constexpr Real frictionCoefficient = 0.41667;
  static constexpr Real surfaceViscosity = 5e-9;
  static constexpr Real adhesiveForce = 0.0;
  static constexpr Real adhesiveOverlap = 0.0;
  static constexpr Real rollingResistance = 0.0;
};

/// Friction model and solve type of a contact material.
class FrictionModel {
 public:
  /// Where a contact's rows are solved. DIRECT: normal and friction in the direct solver. ITERATIVE: PGS.
  /// DIRECT_AND_ITERATIVE / SPLIT: normals in the direct set, friction iteratively (SPLIT solves the normals
  /// directly once more after the iterative friction pass; DIRECT_AND_ITERATIVE lets PGS sweep the direct rows
  /// too). Default ITERATIVE for contacts: PGS with shock propagation holds the reference stacks for a fraction
  /// of the direct cost (AGX ships SPLIT; measurements in docs/speed-accuracy.md). Without SuiteSparse every
  /// type is solved by PGS and a one-time warning is logged.
  enum SolveType { DIRECT = 0, ITERATIVE = 1, DIRECT_AND_ITERATIVE = 2, SPLIT = 3 };
  /// BOX: bounds mu * (normal force estimated from last step, or the body weight for a new contact).
  /// SCALED_BOX: bounds mu * (current normal impulse iterate), per direction.
  /// ITERATIVE_PROJECTED_CONE: both tangent rows solved together, then projected onto the disc of radius
  /// mu * normal impulse (AGX's default, isotropic).
  enum Type { BOX = 0, SCALED_BOX = 1, ITERATIVE_PROJECTED_CONE = 2 };

  explicit FrictionModel(Type type = ITERATIVE_PROJECTED_CONE, SolveType solveType = ITERATIVE)
      : type_(type), solveType_(solveType) {}
  virtual ~FrictionModel() = default;

  Type getType() const { return type_; }
  SolveType getSolveType() const { return solveType_; }
  void setSolveType(SolveType t);

 private:
  Type type_;
  SolveType solveType_;
};
using FrictionModelRef = std::shared_ptr<FrictionModel>;

class BoxFrictionModel : public FrictionModel {
 public:
  explicit BoxFrictionModel(SolveType st = ITERATIVE) : FrictionModel(BOX, st) {}
};
class ScaledBoxFrictionModel : public FrictionModel {
 public:
  explicit ScaledBoxFrictionModel(SolveType st = ITERATIVE) : FrictionModel(SCALED_BOX, st) {}
};
class IterativeProjectedConeFriction : public FrictionModel {
 public:
  explicit IterativeProjectedConeFriction(SolveType st = ITERATIVE) : FrictionModel(ITERATIVE_PROJECTED_CONE, st) {}
};

/// The contact parameters shared by Material and ContactMaterial; every setter validates.
class SurfaceParameters {
 public:
  /// N/m per contact point (AGX calls it Young's modulus). > 0.
  void setYoungsModulus(Real e);
  Real getYoungsModulus() const { return youngsModulus_; }
  /// SPOOK damping time of the contact normal, s. >= 0.
  void setDamping(Real tau);
  Real getDamping() const { return damping_; }
  /// Coulomb friction coefficient, >= 0 (may be +infinity: no slip).
  void setFrictionCoefficient(Real mu);
  Real getFrictionCoefficient() const { return friction_; }
  /// Newtonian restitution in [0, 1].
  void setRestitution(Real e);
  Real getRestitution() const { return restitution_; }
  /// Adhesive force (N, >= 0, may be infinite) and adhesive overlap (m, >= 0).
  void setAdhesion(Real force, Real adhesiveOverlap);
  Real getAdhesiveForce() const { return adhesiveForce_; }
  Real getAdhesiveOverlap() const { return adhesiveOverlap_; }
  /// Friction-row compliance, m/(N s), >= 0.
  void setSurfaceViscosity(Real v);
  Real getSurfaceViscosity() const { return surfaceViscosity_; }
  /// Rolling resistance coefficient (dimensionless: resisting torque <= coefficient * radius * normal force).
  void setRollingResistanceCoefficient(Real c);
  Real getRollingResistanceCoefficient() const { return rollingResistance_; }

 protected:
  const char* where_ = "Material";
  Real youngsModulus_ = MaterialDefaults::youngsModulus;
  Real damping_ = MaterialDefaults::damping;
  Real friction_ = MaterialDefaults::frictionCoefficient;
  Real restitution_ = MaterialDefaults::restitution;
  Real adhesiveForce_ = MaterialDefaults::adhesiveForce;
  Real adhesiveOverlap_ = MaterialDefaults::adhesiveOverlap;
  Real surfaceViscosity_ = MaterialDefaults::surfaceViscosity;
  Real rollingResistance_ = MaterialDefaults::rollingResistance;
};

class Material : public SurfaceParameters {
 public:
  explicit Material(const std::string& name = "");
  const std::string& getName() const { return name_; }
  /// kg/m^3, > 0. Bodies recompute their mass on the next RigidBody::updateMassProperties() or add().
  void setDensity(Real rho);
  Real getDensity() const { return density_; }
  /// Unique per process; used to key contact materials.
  uint32_t getId() const { return id_; }

 private:
  std::string name_;
  Real density_ = MaterialDefaults::density;
  uint32_t id_;
};
using MaterialRef = std::shared_ptr<Material>;

class ContactMaterial : public SurfaceParameters {
 public:
  /// Starts from the combination of a and b (see the file comment). a, b must not be null.
  ContactMaterial(MaterialRef a, MaterialRef b);
  const MaterialRef& getMaterial1() const { return m1_; }
  const MaterialRef& getMaterial2() const { return m2_; }

  void setFrictionModel(FrictionModelRef model);
  const FrictionModelRef& getFrictionModel() const { return frictionModel_; }
  /// Shorthand for getFrictionModel()->setSolveType(t) on a model owned by this contact material.
  void setSolveType(FrictionModel::SolveType t);
  FrictionModel::SolveType getSolveType() const { return frictionModel_->getSolveType(); }

  /// Combination rule used for implicit contact materials (exposed for tests and tools).
  static void combine(const Material& a, const Material& b, SurfaceParameters& out);

 private:
  MaterialRef m1_, m2_;
  FrictionModelRef frictionModel_;
};
using ContactMaterialRef = std::shared_ptr<ContactMaterial>;

/// Holds explicit contact materials and the default material used by geometries that have none.
class MaterialManager {
 public:
  MaterialManager();
  /// Explicit contact material of (a, b), created from the combination if it does not exist (order-free).
  ContactMaterialRef getOrCreateContactMaterial(MaterialRef a, MaterialRef b);
  /// The explicit one, or nullptr.
  ContactMaterialRef getContactMaterial(const MaterialRef& a, const MaterialRef& b) const;
  void add(ContactMaterialRef cm);
  bool remove(const ContactMaterialRef& cm);
  /// The material of geometries without one.
  const MaterialRef& getDefaultMaterial() const { return default_; }

  /// Contact parameters for a pair: the explicit contact material's, or the combination. Implicit
  /// combinations are computed on demand (a few flops; no cache to go stale when a material changes).
  /// `outFriction` receives the friction model (the default model when implicit).
  void resolve(const Material* a, const Material* b, SurfaceParameters& outParams,
               const FrictionModel** outFriction) const;

 private:
  static std::pair<uint32_t, uint32_t> key(const Material* a, const Material* b) {
    return a->getId() < b->getId() ? std::make_pair(a->getId(), b->getId()) : std::make_pair(b->getId(), a->getId());
  }
  std::map<std::pair<uint32_t, uint32_t>, ContactMaterialRef> explicit_;
  MaterialRef default_;
  FrictionModel defaultFriction_;
};

}  // namespace scree

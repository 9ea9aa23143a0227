// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Granular fields (AGX manual §25.3, agxModel::GranularFieldPostProcessor): continuum fields computed from the
// particles of a GranularBodySystem on a voxel grid.
//
// Geometry. A cuboid of side lengths `volume` (m) is split into shape[0] x shape[1] x shape[2] equal voxels of
// size volume[a] / shape[a]. The cuboid is placed by a rigid transform (default: axis-aligned, centred at the
// world origin): in its local frame it spans [-volume/2, +volume/2], and voxel (i, j, k) spans
//   [-volume/2 + (i, j, k) .* voxelSize,  -volume/2 + (i+1, j+1, k+1) .* voxelSize].
// Particles outside the cuboid are ignored; a particle straddling its boundary contributes only the part of its
// volume that lies inside.
//
// Weights. A particle's weight in a voxel is the exact fraction of its sphere's volume inside that voxel
// (closed-form sphere–box intersection, model/src/sphere_box_volume.h), so the weights of a particle fully
// inside the cuboid sum to 1 and mass is conserved to rounding. As the manual states, no voxel side may be
// smaller than the diameter of the largest particle (then a sphere touches at most two voxels per axis, at most
// eight in all): calculateFields() refuses such a configuration (see there).
//
// Fields (formulas from the manual; w_p the weight of particle p in voxel V_ijk, V_vox the voxel volume):
//   MASS                   1 component   m_ijk = sum m_p w_p                                   kg
//   MOMENTUM               3 components  p_ijk = sum m_p v_p w_p                               kg m/s
//   VELOCITY               3 components  v_ijk = p_ijk / m_ijk (0 where m_ijk = 0)             m/s
//   CUSTOM                 1 component   c_ijk = sum c_p w_p (c_p from the named custom buffer)
// Beyond the manual (what DEM users reach for next):
//   SOLID_VOLUME_FRACTION  1 component   phi_ijk = sum V_p w_p / V_vox (packing density)      dimensionless
//   KINETIC_STRESS         6 components  s_ijk = sum m_p w_p (v_p - v_ijk)(v_p - v_ijk)^T / V_vox   Pa
//                          (the streaming/kinetic part of the stress from velocity fluctuations, positive
//                          in compression as in the granular coarse-graining literature; computed as
//                          (sum m_p w_p v_p v_p^T - m_ijk v_ijk v_ijk^T) / V_vox, so its absolute rounding
//                          error is ~1e-16 m_ijk |v|^2 / V_vox)
// Dependencies are added automatically: VELOCITY adds MASS and MOMENTUM; KINETIC_STRESS adds VELOCITY.
//
// Data layout (getFieldData()): one contiguous array of numVoxels() * numComponents() Reals, voxel-major,
//   data[(i + shape[0] * (j + shape[1] * k)) * numComponents + c]
// i.e. x fastest, then y, then z; components of a voxel are adjacent. Vector components (momentum, velocity)
// are in world axes; the kinetic stress tensor is in world axes in the order xx, yy, zz, xy, yz, xz (VTK's
// symmetric-tensor order).
//
// Parallelism and determinism. The voxelisation runs with OpenMP: weights per particle in parallel, then the
// particles are bucketed by z-layer (a stable counting sort) and each z-layer of every field is accumulated by
// one thread in a fixed particle order. Results are bit-identical for any thread count.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "scree/core/listeners.h"
#include "scree/core/math.h"
#include "scree/solver/model.h"

namespace scree {

class GranularBodySystem;
class GranularFieldPostProcessor;

/// One field on the voxel grid of a GranularFieldPostProcessor (AGX: agxModel::GranularField).
class GranularField {
 public:
  enum Type { MASS, MOMENTUM, VELOCITY, CUSTOM, SOLID_VOLUME_FRACTION, KINETIC_STRESS };

  virtual ~GranularField() = default;
  Type getType() const { return type_; }
  /// "mass", "momentum", "velocity", "solid_volume_fraction", "kinetic_stress", or the custom buffer's name.
  const std::string& getName() const { return name_; }
  /// Reals per voxel: 1, 3, 3, 1, 1, 6 for the types above.
  int getNumComponents() const { return numComponents_; }
  /// The field values in the layout of the file comment; nullptr until the field is added to a post-processor.
  /// Zero until the first calculateFields().
  const Real* getFieldData() const { return data_.empty() ? nullptr : data_.data(); }
  Real* getFieldData() { return data_.empty() ? nullptr : data_.data(); }
  /// numVoxels() * getNumComponents() once added, else 0.
  size_t getDataSize() const { return data_.size(); }
  /// Component c of voxel (i, j, k). Out-of-range indices throw std::invalid_argument.
  Real getValue(size_t i, size_t j, size_t k, int c = 0) const;

 protected:
  GranularField(Type type, std::string name, int numComponents)
      : type_(type), name_(std::move(name)), numComponents_(numComponents) {}

 private:
  friend class GranularFieldPostProcessor;
  Type type_;
  std::string name_;
  int numComponents_;
  std::array<size_t, 3> shape_{0, 0, 0};
  std::vector<Real> data_;
};
using GranularFieldRef = std::shared_ptr<GranularField>;

class GranularMassField : public GranularField {
 public:
  GranularMassField() : GranularField(MASS, "mass", 1) {}
};
class GranularMomentumField : public GranularField {
 public:
  GranularMomentumField() : GranularField(MOMENTUM, "momentum", 3) {}
};
class GranularVelocityField : public GranularField {
 public:
  GranularVelocityField() : GranularField(VELOCITY, "velocity", 3) {}
};
/// Field of a custom real buffer of the GranularBodySystem; the field has the buffer's name (manual §25.3.2.4).
class GranularCustomBufferField : public GranularField {
 public:
  /// An empty name throws std::invalid_argument.
  explicit GranularCustomBufferField(const std::string& bufferName);
};
class GranularSolidVolumeFractionField : public GranularField {
 public:
  GranularSolidVolumeFractionField() : GranularField(SOLID_VOLUME_FRACTION, "solid_volume_fraction", 1) {}
};
class GranularKineticStressField : public GranularField {
 public:
  GranularKineticStressField() : GranularField(KINETIC_STRESS, "kinetic_stress", 6) {}
};

/// Computes granular fields over a voxelised cuboid (see the file comment).
class GranularFieldPostProcessor {
 public:
  /// Voxel counts per axis (AGX: agx::Vec3u).
  using Shape = std::array<size_t, 3>;

  /// gbs: the particles (kept by reference: it must outlive this object, e.g. Simulation's system).
  /// shape: voxels per axis, each >= 1, product <= 2^31. volume: side lengths of the cuboid, m, finite, > 0.
  /// Bad values throw std::invalid_argument naming the parameter and the value.
  GranularFieldPostProcessor(const GranularBodySystem& gbs, const Shape& shape, const Vec3& volume);

  // ---- placement --------------------------------------------------------------------------------------------
  /// Places the cuboid: its centre at transform.p, its axes rotated by transform.q (normalised). A non-finite
  /// or zero rotation, or a non-finite position, throws and leaves the placement unchanged.
  void setTransform(const Transform& transform);
  const Transform& getTransform() const { return transform_; }
  void setPosition(const Vec3& centre);
  void setRotation(const Quat& rotation);

  const Shape& getShape() const { return shape_; }
  /// Side lengths of the cuboid, m.
  const Vec3& getVolume() const { return volume_; }
  /// Side lengths of one voxel, m.
  Vec3 getVoxelSize() const;
  size_t getNumVoxels() const { return shape_[0] * shape_[1] * shape_[2]; }
  /// Linear index of voxel (i, j, k): i + shape[0] * (j + shape[1] * k).
  size_t voxelIndex(size_t i, size_t j, size_t k) const { return i + shape_[0] * (j + shape_[1] * k); }
  /// World position of the centre of voxel (i, j, k).
  Vec3 getVoxelCenter(size_t i, size_t j, size_t k) const;

  // ---- fields -----------------------------------------------------------------------------------------------
  /// Adds a field and the fields it depends on. Adding a type (or, for CUSTOM, a buffer name) that is already
  /// present keeps the existing field and returns it. A null field, a field already added to another
  /// post-processor, or a custom field whose buffer does not exist in the GranularBodySystem or whose name is a
  /// built-in field's name, throws std::invalid_argument.
  GranularFieldRef addField(GranularFieldRef field);
  /// Shorthand for the built-in types (not CUSTOM).
  GranularFieldRef addField(GranularField::Type type);
  bool hasField(GranularField::Type type) const;
  bool hasField(const std::string& name) const;
  /// The field of a type (for CUSTOM: the first custom field added). A type not added throws
  /// std::invalid_argument.
  GranularFieldRef getField(GranularField::Type type) const;
  /// The field with this name (built-in names of GranularField::getName() or a custom buffer's name). An
  /// unknown name throws std::invalid_argument listing the fields that exist.
  GranularFieldRef getField(const std::string& name) const;
  const std::vector<GranularFieldRef>& getFields() const { return fields_; }

  /// Computes every added field from the particles' current state. Refuses (std::invalid_argument naming the
  /// particle id, its diameter and the smallest voxel side; every field unchanged) when a particle that reaches
  /// into the cuboid has a diameter larger than the smallest voxel side (relative tolerance 1e-12), and when a
  /// custom field's buffer has been removed from the GranularBodySystem. A live particle with a non-finite
  /// position, velocity or mass (a blown-up simulation) throws std::runtime_error naming its id instead of
  /// spreading NaN into the fields (fields unchanged).
  void calculateFields();
  /// Particles that contributed to the last calculateFields() (at least partly inside the cuboid).
  size_t getNumParticlesInside() const { return numInside_; }
  /// Number of calculateFields() calls that completed.
  size_t getNumCalculations() const { return numCalculations_; }

  // ---- export -----------------------------------------------------------------------------------------------
  /// Writes every field as cell data of a VTK ImageData file (XML, ASCII, readable by ParaView): origin = world
  /// position of the cuboid's corner (-volume/2 in local coordinates), spacing = voxel size, Direction = the
  /// rotation. Throws std::runtime_error when the file cannot be written.
  void writeVti(const std::string& path) const;
  /// Writes one slice of voxels (axis 0, 1 or 2 held at `index`) as CSV: a header line, then one row per voxel
  /// with i, j, k, the voxel centre x, y, z (world) and every component of every field (columns named
  /// field or field_component). Bad axis or index throw std::invalid_argument; an unwritable file throws
  /// std::runtime_error.
  void writeCsvSlice(const std::string& path, int axis, size_t index) const;

 private:
  GranularField* findField(GranularField::Type type, const std::string& name) const;
  void attach(const GranularFieldRef& field);

  const GranularBodySystem* gbs_;
  Shape shape_;
  Vec3 volume_;
  Transform transform_;
  std::vector<GranularFieldRef> fields_;
  size_t numInside_ = 0;
  size_t numCalculations_ = 0;

  // Scratch reused between calls (no allocation once sized).
  std::vector<std::array<int32_t, 3>> baseCell_;  // [size()] lowest voxel touched per axis; x = INT32_MIN: skip
  std::vector<std::array<Real, 8>> weights_;      // [size()] weight per piece (bit a: upper voxel on axis a)
  std::vector<uint32_t> layerStart_;              // [shape[2] + 2] bucket offsets by base z-layer + 1
  std::vector<uint32_t> layerOrder_;              // particles sorted by base z-layer, stable
};
using GranularFieldPostProcessorRef = std::shared_ptr<GranularFieldPostProcessor>;

/// Step listener (post stage) that runs calculateFields() every N-th step and then calls an optional callback
/// (e.g. to export). A calculation that calculateFields() refuses (a particle too large for the voxels, a
/// removed custom buffer, a non-finite particle) is logged as an error and skipped; the step is not
/// interrupted.
///
/// It is a Model (scree/solver/model.h): `sim.add(listener)` takes the Model path, whose onAdd installs it as a
/// step listener, and `sim.remove(listener)` takes it out. Added as a plain StepEventListenerRef it is just a
/// listener, as before (not listed in getModels()); remove it the way it was added.
class GranularFieldStepListener : public StepEventListener, public Model {
 public:
  using Callback = std::function<void(const GranularFieldPostProcessor&, size_t stepIndex)>;
  /// everyNSteps >= 1; a null post-processor or 0 throws std::invalid_argument.
  GranularFieldStepListener(GranularFieldPostProcessorRef postProcessor, size_t everyNSteps, Callback callback = {});
  void post(const TimeStamp&) override;
  /// Steps seen so far (post calls).
  size_t getNumSteps() const { return numSteps_; }
  const GranularFieldPostProcessorRef& getPostProcessor() const { return gpp_; }
  /// The simulation running the listener (either way it was added), or nullptr. (Model has one too.)
  using StepEventListener::getSimulation;

 protected:
  /// Model hook: installs this object as a step listener.
  void onAdd(Simulation& sim) override;

 private:
  GranularFieldPostProcessorRef gpp_;
  size_t every_;
  Callback callback_;
  size_t numSteps_ = 0;
};
using GranularFieldStepListenerRef = std::shared_ptr<GranularFieldStepListener>;

}  // namespace scree

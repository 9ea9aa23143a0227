// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// GranularFieldPostProcessor: voxelisation with exact sphere–box weights (see the header for the layout and
// the field definitions).
#include "scree/model/granular_field_post_processor.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <stdexcept>

#include "scree/core/errors.h"
#include "scree/core/granular_body_system.h"
#include "scree/core/logger.h"
#include "sphere_box_volume.h"

#ifdef SCREE_WITH_OPENMP
#define SCREE_FIELDS_PARALLEL_FOR _Pragma("omp parallel for schedule(static)")
#define SCREE_FIELDS_PARALLEL_FOR_DYNAMIC _Pragma("omp parallel for schedule(dynamic, 1)")
#else
#define SCREE_FIELDS_PARALLEL_FOR
#define SCREE_FIELDS_PARALLEL_FOR_DYNAMIC
#endif

namespace scree {
namespace {

constexpr int32_t kSkip = std::numeric_limits<int32_t>::min();

std::string shapeText(const GranularFieldPostProcessor::Shape& s) {
  return "(" + std::to_string(s[0]) + ", " + std::to_string(s[1]) + ", " + std::to_string(s[2]) + ")";
}

int dependencyRank(GranularField::Type t) {
  // Order in which fields are finalised: mass and momentum before velocity, velocity before kinetic stress.
  switch (t) {
    case GranularField::MASS: return 0;
    case GranularField::MOMENTUM: return 1;
    case GranularField::VELOCITY: return 2;
    case GranularField::KINETIC_STRESS: return 3;
    default: return 4;
  }
}

}  // namespace

// ---- GranularField ----------------------------------------------------------------------------------------------

Real GranularField::getValue(size_t i, size_t j, size_t k, int c) const {
  constexpr const char* where = "GranularField::getValue";
  if (data_.empty()) throw std::invalid_argument(std::string(where) + ": field \"" + name_ + "\" is not added to a post-processor");
  if (i >= shape_[0]) detail::throwInvalid(where, "i", (long long)i, "must be < " + std::to_string(shape_[0]));
  if (j >= shape_[1]) detail::throwInvalid(where, "j", (long long)j, "must be < " + std::to_string(shape_[1]));
  if (k >= shape_[2]) detail::throwInvalid(where, "k", (long long)k, "must be < " + std::to_string(shape_[2]));
  if (c < 0 || c >= numComponents_)
    detail::throwInvalid(where, "c", (long long)c, "must be in [0, " + std::to_string(numComponents_ - 1) + "]");
  return data_[(i + shape_[0] * (j + shape_[1] * k)) * size_t(numComponents_) + size_t(c)];
}

GranularCustomBufferField::GranularCustomBufferField(const std::string& bufferName)
    : GranularField(CUSTOM, bufferName, 1) {
  if (bufferName.empty())
    detail::throwInvalid("GranularCustomBufferField", "bufferName", bufferName, "must not be empty");
}

// ---- construction and placement ---------------------------------------------------------------------------------

GranularFieldPostProcessor::GranularFieldPostProcessor(const GranularBodySystem& gbs, const Shape& shape,
                                                       const Vec3& volume)
    : gbs_(&gbs), shape_(shape), volume_(volume) {
  constexpr const char* where = "GranularFieldPostProcessor";
  static const char* names[3] = {"shape[0]", "shape[1]", "shape[2]"};
  for (int a = 0; a < 3; ++a)
    if (shape[a] < 1 || shape[a] > (size_t(1) << 30))
      detail::throwInvalid(where, names[a], (long long)shape[a], "must be in [1, 2^30]");
  if (double(shape[0]) * double(shape[1]) * double(shape[2]) > double(uint32_t(1) << 31))
    throw std::invalid_argument(std::string(where) + ": shape = " + shapeText(shape) +
                                " is invalid (at most 2^31 voxels)");
  static const char* vnames[3] = {"volume.x", "volume.y", "volume.z"};
  for (int a = 0; a < 3; ++a) detail::requirePositive(where, vnames[a], volume[a]);
}

void GranularFieldPostProcessor::setTransform(const Transform& transform) {
  constexpr const char* where = "GranularFieldPostProcessor::setTransform";
  detail::requireFinite(where, "transform.p", transform.p);
  detail::requireRotation(where, "transform.q", transform.q);
  transform_ = {transform.p, transform.q.normalized()};
}

void GranularFieldPostProcessor::setPosition(const Vec3& centre) {
  detail::requireFinite("GranularFieldPostProcessor::setPosition", "centre", centre);
  transform_.p = centre;
}

void GranularFieldPostProcessor::setRotation(const Quat& rotation) {
  detail::requireRotation("GranularFieldPostProcessor::setRotation", "rotation", rotation);
  transform_.q = rotation.normalized();
}

Vec3 GranularFieldPostProcessor::getVoxelSize() const {
  return Vec3(volume_.x() / Real(shape_[0]), volume_.y() / Real(shape_[1]), volume_.z() / Real(shape_[2]));
}

Vec3 GranularFieldPostProcessor::getVoxelCenter(size_t i, size_t j, size_t k) const {
  const Vec3 h = getVoxelSize();
  const Vec3 local = -0.5 * volume_ + Vec3((Real(i) + 0.5) * h.x(), (Real(j) + 0.5) * h.y(), (Real(k) + 0.5) * h.z());
  return transform_.apply(local);
}

// ---- fields -----------------------------------------------------------------------------------------------------

GranularField* GranularFieldPostProcessor::findField(GranularField::Type type, const std::string& name) const {
  for (const auto& f : fields_)
    if (f->getType() == type && (type != GranularField::CUSTOM || f->getName() == name)) return f.get();
  return nullptr;
}

void GranularFieldPostProcessor::attach(const GranularFieldRef& field) {
  field->shape_ = shape_;
  field->data_.assign(getNumVoxels() * size_t(field->getNumComponents()), Real(0));
  fields_.push_back(field);
  // Keep dependencies first so calculateFields() can finalise in list order.
  std::stable_sort(fields_.begin(), fields_.end(), [](const GranularFieldRef& a, const GranularFieldRef& b) {
    return dependencyRank(a->getType()) < dependencyRank(b->getType());
  });
}

GranularFieldRef GranularFieldPostProcessor::addField(GranularFieldRef field) {
  constexpr const char* where = "GranularFieldPostProcessor::addField";
  detail::requireNonNull(where, "field", field.get());
  if (field->getType() == GranularField::CUSTOM)
    for (const char* reserved : {"mass", "momentum", "velocity", "solid_volume_fraction", "kinetic_stress"})
      if (field->getName() == reserved)
        detail::throwInvalid(where, "field (custom buffer name)", field->getName(),
                             "the name of a built-in field; rename the custom buffer");
  if (field->getType() == GranularField::CUSTOM && !gbs_->hasCustomBufferReal(field->getName()))
    detail::throwInvalid(where, "field (custom buffer name)", field->getName(),
                         "no custom real buffer of that name in the GranularBodySystem");
  if (!field->data_.empty() && findField(field->getType(), field->getName()) != field.get())
    throw std::invalid_argument(std::string(where) + ": field \"" + field->getName() +
                                "\" is invalid (already added to another post-processor)");
  if (GranularField* existing = findField(field->getType(), field->getName())) {
    for (const auto& f : fields_)
      if (f.get() == existing) return f;
  }
  // Dependencies first (each is a no-op when present).
  switch (field->getType()) {
    case GranularField::VELOCITY:
      addField(GranularField::MASS);
      addField(GranularField::MOMENTUM);
      break;
    case GranularField::KINETIC_STRESS:
      addField(GranularField::VELOCITY);
      break;
    default: break;
  }
  attach(field);
  return field;
}

GranularFieldRef GranularFieldPostProcessor::addField(GranularField::Type type) {
  switch (type) {
    case GranularField::MASS: return addField(std::make_shared<GranularMassField>());
    case GranularField::MOMENTUM: return addField(std::make_shared<GranularMomentumField>());
    case GranularField::VELOCITY: return addField(std::make_shared<GranularVelocityField>());
    case GranularField::SOLID_VOLUME_FRACTION: return addField(std::make_shared<GranularSolidVolumeFractionField>());
    case GranularField::KINETIC_STRESS: return addField(std::make_shared<GranularKineticStressField>());
    default:
      detail::throwInvalid("GranularFieldPostProcessor::addField", "type", (long long)type,
                           "must be a built-in type; add a custom field as GranularCustomBufferField(name)");
  }
}

bool GranularFieldPostProcessor::hasField(GranularField::Type type) const {
  for (const auto& f : fields_)
    if (f->getType() == type) return true;
  return false;
}

bool GranularFieldPostProcessor::hasField(const std::string& name) const {
  for (const auto& f : fields_)
    if (f->getName() == name) return true;
  return false;
}

GranularFieldRef GranularFieldPostProcessor::getField(GranularField::Type type) const {
  for (const auto& f : fields_)
    if (f->getType() == type) return f;
  detail::throwInvalid("GranularFieldPostProcessor::getField", "type", (long long)type, "no field of that type was added");
}

GranularFieldRef GranularFieldPostProcessor::getField(const std::string& name) const {
  for (const auto& f : fields_)
    if (f->getName() == name) return f;
  std::string known;
  for (const auto& f : fields_) known += (known.empty() ? "" : ", ") + f->getName();
  detail::throwInvalid("GranularFieldPostProcessor::getField", "name", name,
                       "no such field; fields added: " + (known.empty() ? std::string("none") : known));
}

// ---- calculation ------------------------------------------------------------------------------------------------

void GranularFieldPostProcessor::calculateFields() {
  constexpr const char* where = "GranularFieldPostProcessor::calculateFields";
  const GranularBodySystem& gbs = *gbs_;
  const size_t n = gbs.size();
  if (n > size_t(std::numeric_limits<uint32_t>::max()))
    throw std::invalid_argument(std::string(where) + ": too many particles (" + std::to_string(n) + ")");

  // Custom buffers must still exist.
  std::vector<const Real*> customData;
  std::vector<Real*> customOut;
  for (const auto& f : fields_) {
    if (f->getType() != GranularField::CUSTOM) continue;
    const Real* buf = gbs.customBufferReal(f->getName());
    if (!buf && n > 0)
      detail::throwInvalid(where, "custom field", f->getName(), "its buffer was removed from the GranularBodySystem");
    customData.push_back(buf);
    customOut.push_back(f->data_.data());
  }

  const Vec3 h = getVoxelSize();
  const Real hMin = h.minCoeff();
  const Vec3 lo = -0.5 * volume_;
  const Quat toLocal = transform_.q.conjugate();
  const int32_t nx = int32_t(shape_[0]), ny = int32_t(shape_[1]), nz = int32_t(shape_[2]);
  const auto& pos = gbs.positions();
  const auto& radii = gbs.radii();

  baseCell_.resize(n);
  weights_.resize(n);

  // ---- pass 1 (parallel): per particle, the lowest voxel it touches and its weight in each of the <= 8 voxels.
  // Voxel sides >= the diameter, so along each axis the sphere meets voxel c or voxels c and c+1, cut by the
  // plane between them.
  const auto& vel = gbs.velocities();
  const auto& masses = gbs.masses();
  // Dense indices of the first offending particles (min over threads: deterministic).
  size_t firstTooLarge = n, firstNonFinite = n;
#ifdef SCREE_WITH_OPENMP
#pragma omp parallel for schedule(static) reduction(min : firstTooLarge, firstNonFinite)
#endif
  for (size_t p = 0; p < n; ++p) {
    auto& base = baseCell_[p];
    base[0] = kSkip;
    if (!gbs.isAliveDense(p)) continue;
    const Real r = radii[p];
    if (!pos[p].allFinite() || !vel[p].allFinite() || !std::isfinite(masses[p])) {
      firstNonFinite = std::min(firstNonFinite, p);
      continue;
    }
    const Vec3 x = toLocal * (pos[p] - transform_.p) - lo;  // relative to the cuboid's low corner
    bool outside = false;
    for (int a = 0; a < 3; ++a) outside |= (x[a] + r <= 0) || (x[a] - r >= volume_[a]);
    if (outside) continue;
    if (2 * r > hMin * (1 + 1e-12)) {
      firstTooLarge = std::min(firstTooLarge, p);
      continue;
    }
    Vec3 d;
    std::array<bool, 3> split;
    for (int a = 0; a < 3; ++a) {
      const Real c = std::floor((x[a] - r) / h[a]);
      const Real plane = (c + 1) * h[a];
      base[a] = int32_t(std::clamp(c, Real(-1), Real(shape_[a])));
      d[a] = plane - x[a];
      split[a] = x[a] + r > plane;
    }
    const auto pieces = detail::ballSplitVolumes(r, d, split);
    const Real invV = 1 / detail::ballVolume(r);
    for (int b = 0; b < 8; ++b) weights_[p][b] = pieces[b] * invV;
  }
  if (firstNonFinite < n) {
    const size_t id = gbs.idOfDense(firstNonFinite);
    throw std::runtime_error(std::string(where) + ": particle id " + std::to_string(id) +
                             " has a non-finite state (position " + detail::formatValue(pos[firstNonFinite]) +
                             ", velocity " + detail::formatValue(vel[firstNonFinite]) + "); fields not computed");
  }
  if (firstTooLarge < n) {
    const size_t id = gbs.idOfDense(firstTooLarge);
    throw std::invalid_argument(std::string(where) + ": particle id " + std::to_string(id) + " has diameter " +
                                detail::formatValue(2 * radii[firstTooLarge]) +
                                " larger than the smallest voxel side " + detail::formatValue(hMin) +
                                " (voxels must be at least one particle diameter wide; use fewer voxels)");
  }

  // ---- pass 2 (serial, O(n)): stable counting sort of the contributing particles by base z-layer (-1 .. nz-1).
  layerStart_.assign(size_t(nz) + 2, 0);
  size_t inside = 0;
  for (size_t p = 0; p < n; ++p)
    if (baseCell_[p][0] != kSkip) {
      ++layerStart_[size_t(baseCell_[p][2] + 1) + 1];
      ++inside;
    }
  for (size_t l = 1; l < layerStart_.size(); ++l) layerStart_[l] += layerStart_[l - 1];
  layerOrder_.resize(inside);
  {
    std::vector<uint32_t> cursor(layerStart_.begin(), layerStart_.end() - 1);
    for (size_t p = 0; p < n; ++p)
      if (baseCell_[p][0] != kSkip) layerOrder_[cursor[size_t(baseCell_[p][2] + 1)]++] = uint32_t(p);
  }

  // ---- pass 3 (parallel over z-layers): accumulate. Layer k receives the upper z-pieces of particles based in
  // layer k-1, then the lower z-pieces of those based in layer k, each in dense order: a fixed order for any
  // thread count.
  Real* mass = nullptr;
  Real* momentum = nullptr;
  Real* solid = nullptr;
  Real* stress = nullptr;
  for (const auto& f : fields_) {
    std::fill(f->data_.begin(), f->data_.end(), Real(0));
    switch (f->getType()) {
      case GranularField::MASS: mass = f->data_.data(); break;
      case GranularField::MOMENTUM: momentum = f->data_.data(); break;
      case GranularField::SOLID_VOLUME_FRACTION: solid = f->data_.data(); break;
      case GranularField::KINETIC_STRESS: stress = f->data_.data(); break;
      default: break;
    }
  }
  const size_t numCustom = customData.size();
  const size_t layerSize = size_t(nx) * size_t(ny);

  SCREE_FIELDS_PARALLEL_FOR_DYNAMIC
  for (int32_t k = 0; k < nz; ++k) {
    for (int part = 0; part < 2; ++part) {
      const int zBit = part == 0 ? 1 : 0;        // upper pieces of layer k-1, then lower pieces of layer k
      const size_t bucket = size_t(k + 1 - zBit);  // bucket index = base z + 1
      for (uint32_t o = layerStart_[bucket]; o < layerStart_[bucket + 1]; ++o) {
        const uint32_t p = layerOrder_[o];
        const auto& base = baseCell_[p];
        const auto& w = weights_[p];
        const Real m = masses[p];
        const Vec3& v = vel[p];
        const Real volP = detail::ballVolume(radii[p]);
        for (int yb = 0; yb < 2; ++yb) {
          const int32_t j = base[1] + yb;
          if (j < 0 || j >= ny) continue;
          for (int xb = 0; xb < 2; ++xb) {
            const int32_t i = base[0] + xb;
            if (i < 0 || i >= nx) continue;
            const Real wt = w[xb | (yb << 1) | (zBit << 2)];
            if (wt == 0) continue;
            const size_t vox = size_t(i) + size_t(nx) * size_t(j) + layerSize * size_t(k);
            const Real mw = m * wt;
            if (mass) mass[vox] += mw;
            if (momentum) {
              momentum[3 * vox + 0] += mw * v.x();
              momentum[3 * vox + 1] += mw * v.y();
              momentum[3 * vox + 2] += mw * v.z();
            }
            if (solid) solid[vox] += volP * wt;
            if (stress) {  // second moment sum m w v v^T, centred in the finalisation below
              Real* s = stress + 6 * vox;
              s[0] += mw * v.x() * v.x();
              s[1] += mw * v.y() * v.y();
              s[2] += mw * v.z() * v.z();
              s[3] += mw * v.x() * v.y();
              s[4] += mw * v.y() * v.z();
              s[5] += mw * v.x() * v.z();
            }
            for (size_t c = 0; c < numCustom; ++c) customOut[c][vox] += customData[c][p] * wt;
          }
        }
      }
    }
  }

  // ---- pass 4 (parallel over voxels): derived fields.
  Real* velocity = nullptr;
  for (const auto& f : fields_)
    if (f->getType() == GranularField::VELOCITY) velocity = f->data_.data();
  const Real invVoxelVolume = 1 / (h.x() * h.y() * h.z());
  const int64_t numVox = int64_t(getNumVoxels());
  SCREE_FIELDS_PARALLEL_FOR
  for (int64_t vox = 0; vox < numVox; ++vox) {
    if (solid) solid[vox] *= invVoxelVolume;
    // An empty voxel keeps the zeros written above (velocity 0 by convention, no fluctuation).
    if (mass && mass[vox] == 0) continue;
    if (velocity) {
      const Real m = mass[vox];
      for (int c = 0; c < 3; ++c) velocity[3 * vox + c] = m > 0 ? momentum[3 * vox + c] / m : Real(0);
    }
    if (stress) {
      // sum m w (v - vbar)(v - vbar)^T = sum m w v v^T - m vbar vbar^T (since sum m w v = m vbar).
      const Real m = mass[vox];
      const Real* vb = velocity + 3 * vox;
      Real* s = stress + 6 * vox;
      const Real centred[6] = {s[0] - m * vb[0] * vb[0], s[1] - m * vb[1] * vb[1], s[2] - m * vb[2] * vb[2],
                               s[3] - m * vb[0] * vb[1], s[4] - m * vb[1] * vb[2], s[5] - m * vb[0] * vb[2]};
      for (int c = 0; c < 6; ++c) s[c] = centred[c] * invVoxelVolume;
    }
  }
  numInside_ = inside;
  ++numCalculations_;
}

// ---- export -----------------------------------------------------------------------------------------------------

void GranularFieldPostProcessor::writeVti(const std::string& path) const {
  std::ofstream out(path);
  if (!out) throw std::runtime_error("GranularFieldPostProcessor::writeVti: cannot open \"" + path + "\" for writing");
  out.precision(17);
  const Vec3 h = getVoxelSize();
  const Vec3 origin = transform_.apply(-0.5 * volume_);
  const Mat3 R = transform_.q.toRotationMatrix();
  out << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"ImageData\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
      << "  <ImageData WholeExtent=\"0 " << shape_[0] << " 0 " << shape_[1] << " 0 " << shape_[2] << "\" Origin=\""
      << origin.x() << " " << origin.y() << " " << origin.z() << "\" Spacing=\"" << h.x() << " " << h.y() << " "
      << h.z() << "\" Direction=\"";
  // Direction: the 3x3 matrix whose columns are the grid axes in world coordinates, written row by row.
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out << R(r, c) << (r == 2 && c == 2 ? "" : " ");
  out << "\">\n"
      << "    <Piece Extent=\"0 " << shape_[0] << " 0 " << shape_[1] << " 0 " << shape_[2] << "\">\n"
      << "      <CellData>\n";
  for (const auto& f : fields_) {
    out << "        <DataArray type=\"Float64\" Name=\"" << f->getName() << "\" NumberOfComponents=\""
        << f->getNumComponents() << "\" format=\"ascii\">\n";
    const size_t nc = size_t(f->getNumComponents());
    for (size_t vox = 0; vox < getNumVoxels(); ++vox) {
      out << "         ";
      for (size_t c = 0; c < nc; ++c) out << ' ' << f->data_[vox * nc + c];
      out << '\n';
    }
    out << "        </DataArray>\n";
  }
  out << "      </CellData>\n    </Piece>\n  </ImageData>\n</VTKFile>\n";
  if (!out) throw std::runtime_error("GranularFieldPostProcessor::writeVti: writing \"" + path + "\" failed");
}

void GranularFieldPostProcessor::writeCsvSlice(const std::string& path, int axis, size_t index) const {
  constexpr const char* where = "GranularFieldPostProcessor::writeCsvSlice";
  if (axis < 0 || axis > 2) detail::throwInvalid(where, "axis", (long long)axis, "must be 0, 1 or 2");
  if (index >= shape_[size_t(axis)])
    detail::throwInvalid(where, "index", (long long)index,
                         "must be < shape[" + std::to_string(axis) + "] = " + std::to_string(shape_[size_t(axis)]));
  std::ofstream out(path);
  if (!out) throw std::runtime_error(std::string(where) + ": cannot open \"" + path + "\" for writing");
  out.precision(17);
  static const char* vecNames[3] = {"x", "y", "z"};
  static const char* tensorNames[6] = {"xx", "yy", "zz", "xy", "yz", "xz"};
  out << "i,j,k,x,y,z";
  for (const auto& f : fields_) {
    const int nc = f->getNumComponents();
    for (int c = 0; c < nc; ++c) {
      out << ',' << f->getName();
      if (nc == 3) out << '_' << vecNames[c];
      if (nc == 6) out << '_' << tensorNames[c];
    }
  }
  out << '\n';
  std::array<size_t, 3> lo{0, 0, 0}, hi = shape_;
  lo[size_t(axis)] = index;
  hi[size_t(axis)] = index + 1;
  for (size_t k = lo[2]; k < hi[2]; ++k)
    for (size_t j = lo[1]; j < hi[1]; ++j)
      for (size_t i = lo[0]; i < hi[0]; ++i) {
        const Vec3 c = getVoxelCenter(i, j, k);
        out << i << ',' << j << ',' << k << ',' << c.x() << ',' << c.y() << ',' << c.z();
        const size_t vox = voxelIndex(i, j, k);
        for (const auto& f : fields_) {
          const size_t nc = size_t(f->getNumComponents());
          for (size_t comp = 0; comp < nc; ++comp) out << ',' << f->data_[vox * nc + comp];
        }
        out << '\n';
      }
  if (!out) throw std::runtime_error(std::string(where) + ": writing \"" + path + "\" failed");
}

// ---- step listener ----------------------------------------------------------------------------------------------

GranularFieldStepListener::GranularFieldStepListener(GranularFieldPostProcessorRef postProcessor, size_t everyNSteps,
                                                     Callback callback)
    : StepEventListener(POST_STEP),
      Model("GranularFieldStepListener"),
      gpp_(std::move(postProcessor)),
      every_(everyNSteps),
      callback_(std::move(callback)) {
  constexpr const char* where = "GranularFieldStepListener";
  detail::requireNonNull(where, "postProcessor", gpp_.get());
  if (everyNSteps < 1) detail::throwInvalid(where, "everyNSteps", (long long)everyNSteps, "must be >= 1");
}

void GranularFieldStepListener::onAdd(Simulation&) { addOwned(selfAs<StepEventListener>()); }

void GranularFieldStepListener::post(const TimeStamp&) {
  ++numSteps_;
  if (numSteps_ % every_ != 0) return;
  try {
    gpp_->calculateFields();
  } catch (const std::exception& e) {  // too-large particle, removed buffer, non-finite particle state
    Logger::error(std::string("GranularFieldStepListener: fields not computed at step ") + std::to_string(numSteps_) +
                  ": " + e.what());
    return;
  }
  if (callback_) callback_(*gpp_, numSteps_);
}

}  // namespace scree

// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The .screerec writer and reader (docs/recording.md; design notes in scree/io/recording.h).
#include "scree/io/recording.h"

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <unordered_map>

#include <zlib.h>

#include "scree/collide/geometry.h"
#include "scree/collide/shapes.h"
#include "scree/core/errors.h"
#include "scree/core/logger.h"
#include "scree/model/terrain.h"
#include "scree/solver/simulation.h"

namespace scree::io {

namespace {

constexpr char kMagic[8] = {'S', 'C', 'R', 'E', 'E', 'R', 'E', 'C'};
constexpr size_t kHeaderSize = 16;
constexpr uint32_t kBlock = 32;  // vertices per side of a height block (one changed rectangle per block)
constexpr uint8_t kFlagDelta = 1, kFlagRadii = 2;

// A fixed palette of distinguishable, not too saturated colours; a material's colour is palette[hash(name)].
constexpr std::array<std::array<uint8_t, 3>, 12> kPalette = {{{166, 142, 108},
                                                              {120, 144, 170},
                                                              {196, 120, 92},
                                                              {126, 168, 116},
                                                              {200, 170, 90},
                                                              {150, 120, 176},
                                                              {98, 160, 160},
                                                              {184, 110, 140},
                                                              {140, 140, 140},
                                                              {110, 130, 96},
                                                              {210, 150, 120},
                                                              {92, 110, 150}}};

std::array<uint8_t, 3> colourOf(const std::string& name) {
  uint32_t h = 2166136261u;  // FNV-1a
  for (unsigned char c : name) h = (h ^ c) * 16777619u;
  return kPalette[h % kPalette.size()];
}

/// The speed as written: 12 significant bits (0.02 %, far more than a colour map shows), and 0 below 1e-4 m/s.
/// Why: a resting particle's speed is solver noise (1e-8 m/s) whose float bits change every step; written in full,
/// that noise would be most of a long recording (a settled pile) since XOR deltas and deflate cannot remove it.
float quantiseSpeed(double v) {
  if (!(v >= 1e-4)) return 0.0f;  // also NaN
  const uint32_t bits = std::bit_cast<uint32_t>(static_cast<float>(v)) & ~((1u << 11) - 1);
  return std::bit_cast<float>(bits);
}

template <class T>
uint32_t bitsOf(T v) {
  static_assert(sizeof(T) == 4);
  return std::bit_cast<uint32_t>(v);
}

void putPose(ByteWriter& w, const Transform& t) {
  w.put<double>(t.p.x());
  w.put<double>(t.p.y());
  w.put<double>(t.p.z());
  w.put<double>(t.q.x());
  w.put<double>(t.q.y());
  w.put<double>(t.q.z());
  w.put<double>(t.q.w());
}

/// A height-field geometry's pose moved to vertex (0, 0) (the shape is centred on its frame's origin).
Transform cornerPose(const Transform& t, const HeightField& hf) {
  return {t.p + t.q * Vec3(-0.5 * hf.getSizeX(), -0.5 * hf.getSizeY(), 0), t.q};
}

std::vector<uint8_t> deflate(const std::vector<uint8_t>& raw, int level) {
  uLongf bound = compressBound(static_cast<uLong>(raw.size()));
  std::vector<uint8_t> out(4 + bound);
  const uint32_t n = static_cast<uint32_t>(raw.size());
  std::memcpy(out.data(), &n, 4);
  if (compress2(out.data() + 4, &bound, raw.data(), static_cast<uLong>(raw.size()), level) != Z_OK)
    throw std::runtime_error("RecordingWriter: zlib compress2 failed");
  out.resize(4 + bound);
  return out;
}

}  // namespace

// =============================================================================================================
// Writer
// =============================================================================================================

struct RecordingWriter::State {
  std::vector<RigidBodyRef> bodies;
  bool staticPseudoBody = false;
  size_t bodiesAtBegin = 0;  // simulation body count at begin (to notice additions)
  bool warnedNewBodies = false;
  struct Field {
    std::shared_ptr<const HeightField> shape;
    std::vector<float> last;  // heights as last written
  };
  std::vector<Field> fields;
  std::unordered_map<const Material*, uint16_t> particleMaterialIndex;
  bool warnedUnknownMaterial = false;
  // The previous frame's particle arrays, as written (bit patterns).
  bool havePrevious = false;
  std::vector<uint32_t> ids, pos, speed, radius;
  std::vector<uint16_t> material;
  // Scratch arrays of the frame being written.
  std::vector<uint32_t> nIds, nPos, nSpeed, nRadius;
  std::vector<uint16_t> nMaterial;
};

RecordingWriter::RecordingWriter() = default;

RecordingWriter::~RecordingWriter() { abort(); }

void RecordingWriter::open(const std::string& path) {
  if (file_) throw std::logic_error("RecordingWriter::open: already open (" + path_ + ")");
  if (path.empty()) detail::throwInvalid("RecordingWriter::open", "path", path, "must not be empty");
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    detail::throwInvalid("RecordingWriter::open", "path", path, "must be a file name, not a directory");
  const std::string part = path + ".part";
  std::FILE* f = std::fopen(part.c_str(), "wb");
  if (!f)
    detail::throwInvalid("RecordingWriter::open", "path", path,
                         std::string("must be writable (cannot create ") + part + ": " + std::strerror(errno) + ")");
  file_ = f;
  path_ = path;
  partPath_ = part;
  frames_ = 0;
  calls_ = 0;
  bytes_ = 0;
  st_ = std::make_unique<State>();
  ByteWriter w;
  w.putBytes(kMagic, 8);
  w.put<uint16_t>(kRecordingMajor);
  w.put<uint16_t>(kRecordingMinor);
  w.put<uint32_t>(0);
  if (std::fwrite(w.bytes().data(), 1, w.size(), file_) != w.size())
    throw std::runtime_error("RecordingWriter: cannot write " + partPath_ + ": " + std::strerror(errno));
  bytes_ += w.size();
}

void RecordingWriter::setRecordEvery(uint32_t k) {
  if (k < 1) detail::throwInvalid("RecordingWriter::setRecordEvery", "k", (long long)k, "must be >= 1");
  every_ = k;
}

void RecordingWriter::setRecordContacts(bool on) { contacts_ = on; }

void RecordingWriter::setCompressionLevel(int level) {
  if (level < 1 || level > 9)
    detail::throwInvalid("RecordingWriter::setCompressionLevel", "level", (long long)level, "must be in [1, 9]");
  level_ = level;
}

void RecordingWriter::writeChunk(const char tag[4], const std::vector<uint8_t>& payload) {
  if (!file_) throw std::logic_error("RecordingWriter: not open");
  ByteWriter head;
  head.putBytes(tag, 4);
  head.put<uint32_t>(static_cast<uint32_t>(payload.size()));
  const uint32_t crc = crc32(payload.data(), payload.size());
  const bool ok = std::fwrite(head.bytes().data(), 1, 8, file_) == 8 &&
                  std::fwrite(payload.data(), 1, payload.size(), file_) == payload.size() &&
                  std::fwrite(&crc, 1, 4, file_) == 4;
  if (!ok) throw std::runtime_error("RecordingWriter: cannot write " + partPath_ + ": " + std::strerror(errno));
  bytes_ += 12 + payload.size();
}

void RecordingWriter::begin(const Simulation& sim, const std::string& sceneName,
                            const std::vector<const Terrain*>& terrains) {
  if (!file_) throw std::logic_error("RecordingWriter::begin: open() first");
  State& st = *st_;

  // Geometries: the static ones (with the terrains' geometries not in the simulation), then the bodies'.
  std::vector<GeometryRef> statics = sim.getStaticGeometries();
  for (const Terrain* t : terrains)
    if (t && t->getGeometry() && std::find(statics.begin(), statics.end(), t->getGeometry()) == statics.end())
      statics.push_back(t->getGeometry());
  st.staticPseudoBody = !statics.empty();
  st.bodies = sim.getRigidBodies();
  st.bodiesAtBegin = st.bodies.size();

  std::vector<const Material*> materials;
  std::unordered_map<const Material*, uint32_t> materialIndex;
  auto materialOf = [&](const Geometry& g) -> uint32_t {
    const Material* m = g.getMaterial().get();
    if (!m) return kNoMaterial;
    auto [it, added] = materialIndex.emplace(m, static_cast<uint32_t>(materials.size()));
    if (added) materials.push_back(m);
    return it->second;
  };
  std::unordered_map<const Geometry*, uint32_t> fieldIndex;
  auto fieldOf = [&](const GeometryRef& g) -> uint32_t {
    auto [it, added] = fieldIndex.emplace(g.get(), static_cast<uint32_t>(st.fields.size()));
    if (added) {
      auto hf = std::static_pointer_cast<const HeightField>(g->getShape());
      st.fields.push_back({hf, {}});
    }
    return it->second;
  };

  ByteWriter bodiesOut;
  auto putGeometry = [&](ByteWriter& w, const GeometryRef& g, const Transform& pose) {
    w.put<uint32_t>(materialOf(*g));
    const Shape& s = *g->getShape();
    Transform t = pose;
    if (s.getType() == Shape::HEIGHT_FIELD) t = cornerPose(pose, static_cast<const HeightField&>(s));
    putPose(w, t);
    w.put<uint8_t>(static_cast<uint8_t>(s.getType()));
    switch (s.getType()) {
      case Shape::SPHERE: w.put<double>(static_cast<const Sphere&>(s).getRadius()); break;
      case Shape::BOX: {
        const Vec3& he = static_cast<const Box&>(s).getHalfExtents();
        for (int k = 0; k < 3; ++k) w.put<double>(he[k]);
        break;
      }
      case Shape::CAPSULE:
        w.put<double>(static_cast<const Capsule&>(s).getRadius());
        w.put<double>(static_cast<const Capsule&>(s).getHeight());
        break;
      case Shape::CYLINDER:
        w.put<double>(static_cast<const Cylinder&>(s).getRadius());
        w.put<double>(static_cast<const Cylinder&>(s).getHeight());
        break;
      case Shape::PLANE: {
        const auto& p = static_cast<const Plane&>(s);
        for (int k = 0; k < 3; ++k) w.put<double>(p.getNormal()[k]);
        w.put<double>(p.getDistance());
        break;
      }
      case Shape::CONVEX: {
        const auto& c = static_cast<const Convex&>(s);
        w.put<uint32_t>(static_cast<uint32_t>(c.getVertices().size()));
        for (const Vec3& v : c.getVertices())
          for (int k = 0; k < 3; ++k) w.put<float>(static_cast<float>(v[k]));
        std::vector<uint32_t> tris;
        for (const auto& f : c.getFaces())
          for (size_t k = 1; k + 1 < f.vertices.size(); ++k)
            tris.insert(tris.end(), {f.vertices[0], f.vertices[k], f.vertices[k + 1]});
        w.put<uint32_t>(static_cast<uint32_t>(tris.size() / 3));
        for (uint32_t i : tris) w.put<uint32_t>(i);
        break;
      }
      case Shape::HEIGHT_FIELD: w.put<uint32_t>(fieldOf(g)); break;
      case Shape::LINE: {
        const auto& l = static_cast<const Line&>(s);
        for (int k = 0; k < 3; ++k) w.put<double>(l.getFirstPoint()[k]);
        for (int k = 0; k < 3; ++k) w.put<double>(l.getSecondPoint()[k]);
        break;
      }
      default: throw std::logic_error("RecordingWriter: unknown shape type");
    }
  };
  const uint32_t numBodies = static_cast<uint32_t>(st.bodies.size() + (st.staticPseudoBody ? 1 : 0));
  bodiesOut.put<uint32_t>(numBodies);
  if (st.staticPseudoBody) {
    bodiesOut.putString("(static geometries)");
    bodiesOut.put<uint8_t>(0);
    bodiesOut.put<uint32_t>(static_cast<uint32_t>(statics.size()));
    for (const GeometryRef& g : statics) putGeometry(bodiesOut, g, g->getTransform());
  }
  for (const RigidBodyRef& b : st.bodies) {
    bodiesOut.putString(b->getName());
    bodiesOut.put<uint8_t>(static_cast<uint8_t>(b->getMotionControl()));
    bodiesOut.put<uint32_t>(static_cast<uint32_t>(b->getGeometries().size()));
    for (const GeometryRef& g : b->getGeometries()) putGeometry(bodiesOut, g, g->getLocalTransform());
  }

  // Particle materials: the table so far and the current material.
  const GranularBodySystem& ps = sim.getGranularBodySystem();
  std::vector<const Material*> particleMaterials;
  auto addParticleMaterial = [&](const Material* m) {
    if (!m || st.particleMaterialIndex.count(m) || particleMaterials.size() >= kUnknownParticleMaterial) return;
    st.particleMaterialIndex.emplace(m, static_cast<uint16_t>(particleMaterials.size()));
    particleMaterials.push_back(m);
  };
  for (const MaterialRef& m : ps.getMaterialTable()) addParticleMaterial(m.get());
  addParticleMaterial(ps.getMaterial().get());

  ByteWriter scene;
  scene.putString(sceneName);
  scene.put<double>(sim.getTimeStep());
  scene.put<double>(sim.getTimeStep() * every_);
  const Vec3 g = sim.getUniformGravity();
  for (int k = 0; k < 3; ++k) scene.put<double>(g[k]);
  scene.put<uint32_t>(static_cast<uint32_t>(materials.size()));
  for (const Material* m : materials) {
    scene.putString(m->getName());
    for (uint8_t c : colourOf(m->getName())) scene.put<uint8_t>(c);
  }
  scene.putBytes(bodiesOut.bytes().data(), bodiesOut.size());
  scene.put<uint32_t>(static_cast<uint32_t>(particleMaterials.size()));
  for (const Material* m : particleMaterials) {
    scene.putString(m->getName());
    for (uint8_t c : colourOf(m->getName())) scene.put<uint8_t>(c);
  }
  writeChunk("SCNE", scene.bytes());

  // Height fields, in the order their geometries were met.
  std::vector<const Geometry*> fieldGeoms(st.fields.size());
  for (const auto& [geom, i] : fieldIndex) fieldGeoms[i] = geom;
  for (size_t i = 0; i < st.fields.size(); ++i) {
    auto& f = st.fields[i];
    const HeightField& hf = *f.shape;
    ByteWriter w;
    w.put<uint32_t>(static_cast<uint32_t>(hf.getResolutionX()));
    w.put<uint32_t>(static_cast<uint32_t>(hf.getResolutionY()));
    w.put<double>(hf.getCellSizeX());
    putPose(w, cornerPose(fieldGeoms[i]->getTransform(), hf));
    f.last.resize(hf.getHeights().size());
    for (size_t k = 0; k < f.last.size(); ++k) {
      f.last[k] = static_cast<float>(hf.getHeights()[k]);
      w.put<float>(f.last[k]);
    }
    writeChunk("HFLD", w.bytes());
  }
  recordFrame(sim);
}

bool RecordingWriter::writeFrame(const Simulation& sim) {
  if (!file_ || !st_) throw std::logic_error("RecordingWriter::writeFrame: begin() first");
  if (++calls_ % every_ != 0) return false;
  recordFrame(sim);
  return true;
}

void RecordingWriter::recordFrame(const Simulation& sim) {
  State& st = *st_;
  if (!st.warnedNewBodies && sim.getRigidBodies().size() > st.bodiesAtBegin) {
    st.warnedNewBodies = true;
    Logger::warning("RecordingWriter: bodies added after the recording began are not recorded (" + path_ + ")");
  }
  ByteWriter w;
  w.put<uint32_t>(frames_);
  w.put<double>(sim.getTimeStamp());
  const uint32_t numBodies = static_cast<uint32_t>(st.bodies.size() + (st.staticPseudoBody ? 1 : 0));
  w.put<uint32_t>(numBodies);
  if (st.staticPseudoBody) putPose(w, Transform{});
  for (const RigidBodyRef& b : st.bodies) putPose(w, b->getTransform());

  // Particles, in dense order.
  const GranularBodySystem& ps = sim.getGranularBodySystem();
  const auto& table = ps.getMaterialTable();
  std::vector<uint16_t> tableToScene(table.size(), kUnknownParticleMaterial);
  for (size_t k = 0; k < table.size(); ++k) {
    auto it = st.particleMaterialIndex.find(table[k].get());
    if (it != st.particleMaterialIndex.end()) tableToScene[k] = it->second;
  }
  st.nIds.clear();
  st.nPos.clear();
  st.nSpeed.clear();
  st.nRadius.clear();
  st.nMaterial.clear();
  const auto& positions = ps.positions();
  const auto& velocities = ps.velocities();
  const auto& radii = ps.radii();
  const auto& mats = ps.materialIndices();
  for (size_t i = 0; i < ps.size(); ++i) {
    if (!ps.isAliveDense(i)) continue;
    st.nIds.push_back(static_cast<uint32_t>(ps.idOfDense(i)));  // slot + 1: unique among live particles
    for (int k = 0; k < 3; ++k) st.nPos.push_back(bitsOf(static_cast<float>(positions[i][k])));
    st.nSpeed.push_back(bitsOf(quantiseSpeed(velocities[i].norm())));
    st.nRadius.push_back(bitsOf(static_cast<float>(radii[i])));
    const uint16_t m = mats[i] < tableToScene.size() ? tableToScene[mats[i]] : kUnknownParticleMaterial;
    if (m == kUnknownParticleMaterial && !st.warnedUnknownMaterial) {
      st.warnedUnknownMaterial = true;
      Logger::warning("RecordingWriter: a particle material first used after the recording began is recorded as "
                      "unknown (" + path_ + ")");
    }
    st.nMaterial.push_back(m);
  }
  const bool delta = st.havePrevious && st.nIds == st.ids;
  const bool radiiChanged = !delta || st.nRadius != st.radius || st.nMaterial != st.material;
  w.put<uint8_t>(static_cast<uint8_t>((delta ? kFlagDelta : 0) | (radiiChanged ? kFlagRadii : 0)));
  const uint32_t n = static_cast<uint32_t>(st.nIds.size());
  w.put<uint32_t>(n);
  auto putArray = [&](const std::vector<uint32_t>& now, const std::vector<uint32_t>& before) {
    for (size_t k = 0; k < now.size(); ++k) w.put<uint32_t>(delta ? now[k] ^ before[k] : now[k]);
  };
  putArray(st.nIds, st.ids);
  putArray(st.nPos, st.pos);
  putArray(st.nSpeed, st.speed);
  if (radiiChanged) {  // radii and materials are stored plain, also in a delta frame (docs/recording.md)
    for (size_t k = 0; k < n; ++k) w.put<uint32_t>(st.nRadius[k]);
    for (size_t k = 0; k < n; ++k) w.put<uint16_t>(st.nMaterial[k]);
  }
  std::swap(st.ids, st.nIds);
  std::swap(st.pos, st.nPos);
  std::swap(st.speed, st.nSpeed);
  std::swap(st.radius, st.nRadius);
  std::swap(st.material, st.nMaterial);
  st.havePrevious = true;

  // Height fields: per 32 x 32 block, the bounding rectangle of the vertices whose float32 height changed.
  w.put<uint32_t>(static_cast<uint32_t>(st.fields.size()));
  for (auto& f : st.fields) {
    const HeightField& hf = *f.shape;
    const uint32_t nx = static_cast<uint32_t>(hf.getResolutionX()), ny = static_cast<uint32_t>(hf.getResolutionY());
    const auto& h = hf.getHeights();
    ByteWriter rects;
    uint32_t count = 0;
    for (uint32_t bj = 0; bj < ny; bj += kBlock)
      for (uint32_t bi = 0; bi < nx; bi += kBlock) {
        uint32_t i0 = UINT32_MAX, j0 = UINT32_MAX, i1 = 0, j1 = 0;
        for (uint32_t j = bj; j < std::min(ny, bj + kBlock); ++j)
          for (uint32_t i = bi; i < std::min(nx, bi + kBlock); ++i) {
            const size_t k = size_t(j) * nx + i;
            if (bitsOf(static_cast<float>(h[k])) == bitsOf(f.last[k])) continue;
            i0 = std::min(i0, i);
            j0 = std::min(j0, j);
            i1 = std::max(i1, i);
            j1 = std::max(j1, j);
          }
        if (i0 == UINT32_MAX) continue;
        ++count;
        rects.put<uint32_t>(i0);
        rects.put<uint32_t>(j0);
        rects.put<uint32_t>(i1 - i0 + 1);
        rects.put<uint32_t>(j1 - j0 + 1);
        for (uint32_t j = j0; j <= j1; ++j)
          for (uint32_t i = i0; i <= i1; ++i) {
            const size_t k = size_t(j) * nx + i;
            f.last[k] = static_cast<float>(h[k]);
            rects.put<float>(f.last[k]);
          }
      }
    w.put<uint32_t>(count);
    w.putBytes(rects.bytes().data(), rects.size());
  }

  // Contacts.
  if (!contacts_) {
    w.put<uint32_t>(0);
  } else {
    ByteWriter c;
    uint32_t count = 0;
    auto put = [&](const Vec3& p, const Vec3& nrm, Real force) {
      for (int k = 0; k < 3; ++k) c.put<float>(static_cast<float>(p[k]));
      for (int k = 0; k < 3; ++k) c.put<float>(static_cast<float>(nrm[k]));
      c.put<float>(static_cast<float>(force));
      ++count;
    };
    for (const GeometryContact& gc : sim.getContacts())
      for (const ContactPoint& p : gc.points()) put(p.point, p.normal, p.normalForce);
    for (const ParticleContact& p : sim.getParticleParticleContacts()) put(p.point, p.normal, p.normalForce);
    for (const ParticleContact& p : sim.getParticleGeometryContacts()) put(p.point, p.normal, p.normalForce);
    w.put<uint32_t>(count);
    w.putBytes(c.bytes().data(), c.size());
  }
  writeChunk("FRAM", deflate(w.bytes(), level_));
  ++frames_;
}

uint64_t RecordingWriter::close() {
  if (!file_) throw std::logic_error("RecordingWriter::close: not open");
  ByteWriter w;
  w.put<uint32_t>(frames_);
  writeChunk("ENDR", w.bytes());
  const bool flushed = std::fflush(file_) == 0;
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  if (!flushed || !closed) {
    std::remove(partPath_.c_str());
    throw std::runtime_error("RecordingWriter: cannot write " + partPath_ + ": " + std::strerror(errno));
  }
  std::error_code ec;
  std::filesystem::rename(partPath_, path_, ec);
  if (ec) {
    std::remove(partPath_.c_str());
    throw std::runtime_error("RecordingWriter: cannot rename " + partPath_ + " to " + path_ + ": " + ec.message());
  }
  st_.reset();
  return bytes_;
}

void RecordingWriter::abort() {
  if (!file_) return;
  std::fclose(file_);
  file_ = nullptr;
  std::remove(partPath_.c_str());
  st_.reset();
}

// =============================================================================================================
// Reader
// =============================================================================================================

namespace {

/// A u32 count of items of at least `minBytes` bytes each, checked against what is left of the buffer.
uint32_t getCount(ByteReader& r, const char* field, size_t minBytes) {
  const uint32_t n = r.get<uint32_t>(field);
  if (minBytes > 0 && n > r.remaining() / minBytes)
    r.fail(std::string(field) + " = " + std::to_string(n) + " does not fit in the " + std::to_string(r.remaining()) +
           " bytes left");
  return n;
}

std::array<double, 3> getVec3(ByteReader& r, const char* field) {
  std::array<double, 3> v{};
  for (double& x : v) x = r.get<double>(field);
  return v;
}

std::array<double, 4> getQuat(ByteReader& r, const char* field) {
  std::array<double, 4> v{};
  for (double& x : v) x = r.get<double>(field);
  return v;
}

RecordedMaterial getMaterial(ByteReader& r) {
  RecordedMaterial m;
  m.name = r.getString("material name");
  for (uint8_t& c : m.colour) c = r.get<uint8_t>("material colour");
  return m;
}

std::string tagText(const uint8_t* tag) {
  std::string s;
  for (int k = 0; k < 4; ++k) {
    const char c = static_cast<char>(tag[k]);
    s += (c >= 32 && c < 127) ? c : '?';
  }
  return s;
}

}  // namespace

RecordingReader::RecordingReader(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("RecordingReader: cannot open " + path + ": " + std::strerror(errno));
  bytes_.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  if (in.bad()) throw std::runtime_error("RecordingReader: cannot read " + path);
  parse(path);
}

RecordingReader::RecordingReader(std::vector<uint8_t> bytes, const std::string& name) : bytes_(std::move(bytes)) {
  parse(name);
}

void RecordingReader::parse(const std::string& name) {
  if (bytes_.size() < kHeaderSize)
    throw FormatError(name + ": truncated header (" + std::to_string(bytes_.size()) + " bytes, a recording starts "
                      "with " + std::to_string(kHeaderSize) + ")");
  if (std::memcmp(bytes_.data(), kMagic, 8) != 0)
    throw FormatError(name + ": not a Scree recording (the file does not start with \"SCREEREC\")");
  ByteReader header(bytes_.data() + 8, 8, name + ": header", 8);
  major_ = header.get<uint16_t>("major version");
  minor_ = header.get<uint16_t>("minor version");
  if (major_ != kRecordingMajor)
    throw FormatError(name + " was written in recording format " + std::to_string(major_) + "." +
                      std::to_string(minor_) + "; this reader reads " + std::to_string(kRecordingMajor) + ".x");

  ByteReader file(bytes_.data(), bytes_.size(), name, 0);
  file.getBytes(kHeaderSize, "header");
  bool haveScene = false, ended = false;
  while (!file.atEnd()) {
    const size_t chunkOffset = file.offset();
    const uint8_t* tag = file.getBytes(4, "chunk tag");
    const std::string t = tagText(tag);
    const uint32_t len = file.get<uint32_t>("chunk length");
    const uint8_t* payload = file.getBytes(len, ("payload of chunk " + t).c_str());
    const uint32_t stored = file.get<uint32_t>("chunk CRC");
    const size_t payloadOffset = chunkOffset + 8;
    const std::string what = name + ": " + t + " chunk at byte " + std::to_string(chunkOffset);
    if (crc32(payload, len) != stored) throw FormatError(what + ": CRC mismatch (the chunk is corrupted)");
    ByteReader r(payload, len, what, payloadOffset);
    if (ended) r.fail("a chunk after the ENDR chunk");
    if (!haveScene && t != "SCNE") r.fail("the first chunk must be SCNE");

    if (t == "SCNE") {
      if (haveScene) r.fail("a second SCNE chunk");
      haveScene = true;
      RecordedScene& s = scene_;
      s.name = r.getString("scene name");
      s.timeStep = r.get<double>("time step");
      s.frameInterval = r.get<double>("frame interval");
      s.gravity = getVec3(r, "gravity");
      const uint32_t nm = getCount(r, "material count", 7);
      for (uint32_t k = 0; k < nm; ++k) s.materials.push_back(getMaterial(r));
      const uint32_t nb = getCount(r, "body count", 9);
      s.bodies.resize(nb);
      for (RecordedBody& b : s.bodies) {
        b.name = r.getString("body name");
        b.motion = r.get<uint8_t>("body motion");
        if (b.motion > 2) r.fail("body motion " + std::to_string(b.motion) + " (0, 1 or 2)");
        const uint32_t ng = getCount(r, "geometry count", 4 + 56 + 1);
        b.geometries.resize(ng);
        for (RecordedGeometry& g : b.geometries) {
          g.material = r.get<uint32_t>("geometry material");
          if (g.material != kNoMaterial && g.material >= nm)
            r.fail("geometry material " + std::to_string(g.material) + " of " + std::to_string(nm));
          g.position = getVec3(r, "geometry position");
          g.rotation = getQuat(r, "geometry rotation");
          const uint8_t type = r.get<uint8_t>("shape type");
          g.shape = static_cast<RecordedShapeType>(type);
          auto params = [&](int n) {
            for (int k = 0; k < n; ++k) g.params.push_back(r.get<double>("shape parameter"));
          };
          switch (type) {
            case 0: params(1); break;
            case 1: params(3); break;
            case 2:
            case 3: params(2); break;
            case 4: params(4); break;
            case 5: {
              const uint32_t nv = getCount(r, "convex vertex count", 12);
              g.convexVertices.resize(size_t(nv) * 3);
              for (float& x : g.convexVertices) x = r.get<float>("convex vertex");
              const uint32_t nt = getCount(r, "convex triangle count", 12);
              g.convexTriangles.resize(size_t(nt) * 3);
              for (uint32_t& i : g.convexTriangles) {
                i = r.get<uint32_t>("convex triangle");
                if (i >= nv) r.fail("convex triangle vertex " + std::to_string(i) + " of " + std::to_string(nv));
              }
              break;
            }
            case 6: g.heightField = r.get<uint32_t>("height field index"); break;
            case 7: params(6); break;
            default: r.fail("unknown shape type " + std::to_string(type));
          }
        }
      }
      const uint32_t np = getCount(r, "particle material count", 7);
      for (uint32_t k = 0; k < np; ++k) s.particleMaterials.push_back(getMaterial(r));
      // A newer minor version may append fields: the rest of the payload is skipped.
    } else if (t == "HFLD") {
      if (!frames_.empty()) r.fail("an HFLD chunk after the first frame");
      RecordedHeightField f;
      f.nx = r.get<uint32_t>("nx");
      f.ny = r.get<uint32_t>("ny");
      if (f.nx < 2 || f.ny < 2) r.fail("height field of " + std::to_string(f.nx) + " x " + std::to_string(f.ny) +
                                       " vertices (at least 2 x 2)");
      f.elementSize = r.get<double>("element size");
      f.position = getVec3(r, "height field position");
      f.rotation = getQuat(r, "height field rotation");
      if (uint64_t(f.nx) * f.ny > r.remaining() / 4) r.fail("height field heights do not fit in the chunk");
      f.heights.resize(size_t(f.nx) * f.ny);
      for (float& h : f.heights) h = r.get<float>("height");
      scene_.heightFields.push_back(std::move(f));
    } else if (t == "FRAM") {
      if (frames_.empty()) {  // the scene's height-field references are checked once all HFLD chunks are in
        for (const RecordedBody& b : scene_.bodies)
          for (const RecordedGeometry& g : b.geometries)
            if (g.shape == RecordedShapeType::HeightField && g.heightField >= scene_.heightFields.size())
              r.fail("a geometry refers to height field " + std::to_string(g.heightField) + " of " +
                     std::to_string(scene_.heightFields.size()));
      }
      const uint32_t rawLen = r.get<uint32_t>("raw frame length");
      const size_t zlen = r.remaining();
      // deflate expands at most 1032:1; a larger claim is a corrupted length, not a reason to allocate it.
      if (rawLen > 1032 * uint64_t(zlen) + 64) r.fail("raw frame length " + std::to_string(rawLen) + " for " +
                                                      std::to_string(zlen) + " compressed bytes");
      std::vector<uint8_t> raw(rawLen);
      uLongf outLen = rawLen;
      const int z = uncompress(raw.data(), &outLen, r.getBytes(zlen, "zlib stream"), static_cast<uLong>(zlen));
      if (z != Z_OK || outLen != rawLen)
        throw FormatError(what + ": the frame's zlib stream is broken (" +
                          (z != Z_OK ? std::string(zError(z)) : "inflates to " + std::to_string(outLen) + " bytes, not " + std::to_string(rawLen)) +
                          ")");
      ByteReader f(raw.data(), raw.size(), what + " (inflated frame)", 0);
      RecordedFrame fr;
      fr.storedBytes = 12 + len;
      fr.index = f.get<uint32_t>("frame index");
      if (fr.index != frames_.size())
        f.fail("frame index " + std::to_string(fr.index) + ", expected " + std::to_string(frames_.size()));
      fr.time = f.get<double>("time");
      const uint32_t nb = f.get<uint32_t>("body count");
      if (nb != scene_.bodies.size())
        f.fail("body count " + std::to_string(nb) + ", the scene has " + std::to_string(scene_.bodies.size()));
      if (size_t(nb) * 56 > f.remaining()) f.fail("poses do not fit in the frame");
      fr.poses.resize(size_t(nb) * 7);
      for (double& x : fr.poses) x = f.get<double>("pose");
      const uint8_t flags = f.get<uint8_t>("particle flags");
      fr.delta = flags & kFlagDelta;
      fr.radiiStored = flags & kFlagRadii;
      const uint32_t n = getCount(f, "particle count", 20);
      const RecordedFrame* prev = frames_.empty() ? nullptr : &frames_.back();
      if (fr.delta && (!prev || prev->particleIds.size() != n))
        f.fail("a delta frame without a previous frame of " + std::to_string(n) + " particles");
      // `before` null: stored plain (key frames; radii and materials always).
      auto getArray = [&](auto& out, size_t count, const auto* before, const char* field) {
        using T = typename std::decay_t<decltype(out)>::value_type;
        out.resize(count);
        const bool xorPrev = fr.delta && before != nullptr;
        for (size_t k = 0; k < count; ++k) {
          if constexpr (std::is_same_v<T, float>) {
            uint32_t bits = f.get<uint32_t>(field);
            if (xorPrev) bits ^= std::bit_cast<uint32_t>((*before)[k]);
            out[k] = std::bit_cast<float>(bits);
          } else {
            T v = f.get<T>(field);
            if (xorPrev) v = static_cast<T>(v ^ (*before)[k]);
            out[k] = v;
          }
        }
      };
      getArray(fr.particleIds, n, prev ? &prev->particleIds : nullptr, "particle ids");
      getArray(fr.particlePositions, size_t(n) * 3, prev ? &prev->particlePositions : nullptr, "particle positions");
      getArray(fr.particleSpeeds, n, prev ? &prev->particleSpeeds : nullptr, "particle speeds");
      if (fr.radiiStored) {
        getArray(fr.particleRadii, n, static_cast<const std::vector<float>*>(nullptr), "particle radii");
        getArray(fr.particleMaterials, n, static_cast<const std::vector<uint16_t>*>(nullptr), "particle materials");
        for (uint16_t m : fr.particleMaterials)
          if (m != kUnknownParticleMaterial && m >= scene_.particleMaterials.size())
            f.fail("particle material " + std::to_string(m) + " of " + std::to_string(scene_.particleMaterials.size()));
      } else if (fr.delta) {
        fr.particleRadii = prev->particleRadii;
        fr.particleMaterials = prev->particleMaterials;
      } else if (n > 0) {
        f.fail("a key frame without particle radii");
      }
      const uint32_t nt = f.get<uint32_t>("height field count");
      if (nt != scene_.heightFields.size())
        f.fail("height field count " + std::to_string(nt) + ", the scene has " +
               std::to_string(scene_.heightFields.size()));
      fr.heightRects.resize(nt);
      for (uint32_t k = 0; k < nt; ++k) {
        const RecordedHeightField& hf = scene_.heightFields[k];
        const uint32_t nr = getCount(f, "rectangle count", 16);
        fr.heightRects[k].resize(nr);
        for (RecordedHeightRect& rect : fr.heightRects[k]) {
          rect.i0 = f.get<uint32_t>("rectangle i0");
          rect.j0 = f.get<uint32_t>("rectangle j0");
          rect.w = f.get<uint32_t>("rectangle w");
          rect.h = f.get<uint32_t>("rectangle h");
          if (rect.i0 >= hf.nx || rect.j0 >= hf.ny || rect.w > hf.nx - rect.i0 || rect.h > hf.ny - rect.j0)
            f.fail("rectangle (" + std::to_string(rect.i0) + ", " + std::to_string(rect.j0) + ", " +
                   std::to_string(rect.w) + " x " + std::to_string(rect.h) + ") outside the " + std::to_string(hf.nx) +
                   " x " + std::to_string(hf.ny) + " field");
          if (uint64_t(rect.w) * rect.h > f.remaining() / 4) f.fail("rectangle heights do not fit in the frame");
          rect.heights.resize(size_t(rect.w) * rect.h);
          for (float& h : rect.heights) h = f.get<float>("rectangle heights");
        }
      }
      const uint32_t nc = getCount(f, "contact count", 28);
      fr.contacts.resize(size_t(nc) * 7);
      for (float& x : fr.contacts) x = f.get<float>("contact");
      frames_.push_back(std::move(fr));
    } else if (t == "ENDR") {
      const uint32_t n = r.get<uint32_t>("frame count");
      if (n != frames_.size())
        r.fail("ENDR says " + std::to_string(n) + " frames, the file holds " + std::to_string(frames_.size()));
      ended = true;
    }
    // Unknown tags: skipped (their CRC was checked).
  }
  if (!ended)
    throw FormatError(name + ": truncated: no ENDR chunk (the file ends after " + std::to_string(frames_.size()) +
                      " frames, at byte " + std::to_string(bytes_.size()) + ")");
}

std::vector<float> RecordingReader::heightsAt(size_t field, size_t frame) const {
  const RecordedHeightField& hf = scene_.heightFields.at(field);
  if (frame >= frames_.size()) throw std::out_of_range("RecordingReader::heightsAt: frame " + std::to_string(frame));
  std::vector<float> h = hf.heights;
  for (size_t k = 0; k <= frame; ++k)
    for (const RecordedHeightRect& r : frames_[k].heightRects[field])
      for (uint32_t j = 0; j < r.h; ++j)
        std::copy_n(r.heights.begin() + size_t(j) * r.w, r.w, h.begin() + (size_t(r.j0) + j) * hf.nx + r.i0);
  return h;
}

}  // namespace scree::io

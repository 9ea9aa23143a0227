// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// VtkExporter (scree/io/vtk_export.h): hand-written VTK XML writers, binary appended (raw), and the .pvd.
#include "scree/io/vtk_export.h"

#include "markup.h"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <initializer_list>
#include <fstream>
#include <stdexcept>
#include <string_view>
#include <system_error>
#include <type_traits>

#include "scree/collide/geometry.h"
#include "scree/collide/shapes.h"
#include "scree/core/errors.h"
#include "scree/core/granular_body_system.h"
#include "scree/core/logger.h"
#include "scree/core/rigid_body.h"
#include "scree/model/granular_field_post_processor.h"
#include "scree/model/terrain.h"
#include "scree/solver/simulation.h"

namespace scree::io {

static_assert(std::endian::native == std::endian::little, "the VTK files are written LittleEndian from native bytes");

namespace {

namespace fs = std::filesystem;

template <class T>
constexpr const char* vtkType() {
  if constexpr (std::is_same_v<T, float>) return "Float32";
  else if constexpr (std::is_same_v<T, double>) return "Float64";
  else if constexpr (std::is_same_v<T, int64_t>) return "Int64";
  else if constexpr (std::is_same_v<T, uint64_t>) return "UInt64";
  else if constexpr (std::is_same_v<T, uint32_t>) return "UInt32";
  else if constexpr (std::is_same_v<T, uint8_t>) return "UInt8";
  else static_assert(sizeof(T) == 0, "no VTK type for T");
}

/// Shortest text that reads back to the same double (std::to_chars round trip).
std::string num(double v) {
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}


/// One VTK XML data file: the XML of the dataset element's content plus the appended raw block.
class XmlFile {
 public:
  void open(const std::string& tag, int indent = 0) {
    line(indent, "<" + tag + ">");
  }
  void close(const std::string& tag, int indent = 0) { line(indent, "</" + tag + ">"); }
  void line(int indent, const std::string& s) {
    xml_.append(size_t(indent) * 2, ' ');
    xml_ += s;
    xml_ += '\n';
  }
  /// A DataArray element with `values` appended (count and ncomp must agree; not checked by VTK readers).
  template <class T>
  void array(int indent, std::string_view name, int numComponents, const std::vector<T>& values) {
    std::string e = "<DataArray type=\"";
    e += vtkType<T>();
    e += '"';
    if (!name.empty()) e += " Name=\"" + markupEscape(name) + "\"";
    if (numComponents != 1) e += " NumberOfComponents=\"" + std::to_string(numComponents) + "\"";
    e += " format=\"appended\" offset=\"" + std::to_string(data_.size()) + "\"/>";
    line(indent, e);
    const uint64_t bytes = values.size() * sizeof(T);
    const size_t at = data_.size();
    data_.resize(at + sizeof(uint64_t) + bytes);
    std::memcpy(data_.data() + at, &bytes, sizeof bytes);
    if (bytes) std::memcpy(data_.data() + at + sizeof bytes, values.data(), bytes);
  }

  /// Writes `<VTKFile type=type>` with `<type attributes>` around the content, atomically (tmp + rename).
  /// Returns the bytes written.
  size_t write(const fs::path& path, const std::string& type, const std::string& attributes) const {
    std::string head = "<?xml version=\"1.0\"?>\n<VTKFile type=\"" + type +
                       "\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n  <" + type +
                       (attributes.empty() ? "" : " " + attributes) + ">\n";
    std::string mid = "  </" + type + ">\n  <AppendedData encoding=\"raw\">\n   _";
    const std::string tail = "\n  </AppendedData>\n</VTKFile>\n";
    return writeAtomically(path, {head, xml_, mid}, data_, tail);
  }

  static size_t writeAtomically(const fs::path& path, std::initializer_list<std::string_view> text,
                                const std::vector<uint8_t>& data, std::string_view tail) {
    fs::path tmp = path;
    tmp += ".tmp";
    size_t total = 0;
    {
      std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
      if (!out) throw std::runtime_error("VtkExporter: cannot create " + tmp.string());
      for (auto s : text) {
        out.write(s.data(), std::streamsize(s.size()));
        total += s.size();
      }
      out.write(reinterpret_cast<const char*>(data.data()), std::streamsize(data.size()));
      out.write(tail.data(), std::streamsize(tail.size()));
      total += data.size() + tail.size();
      out.flush();
      if (!out) {
        out.close();
        std::error_code ec;
        fs::remove(tmp, ec);
        throw std::runtime_error("VtkExporter: cannot write " + path.string());
      }
    }
    std::error_code ec;
    fs::rename(tmp, path, ec);
    if (ec) {
      std::error_code ignored;
      fs::remove(tmp, ignored);
      throw std::runtime_error("VtkExporter: cannot rename " + tmp.string() + " to " + path.string() + ": " +
                               ec.message());
    }
    return total;
  }

 private:
  std::string xml_;
  std::vector<uint8_t> data_;
};

/// World placement of a geometry, from its body's current pose (not the cached transform, which the simulation
/// refreshes only when it steps or the body moves through its setters).
Transform worldTransform(const Geometry& g) {
  if (const RigidBody* b = g.getRigidBody()) return b->getTransform() * g.getLocalTransform();
  return g.getTransform();
}

/// A shape's surface in its own frame.
struct LocalMesh {
  std::vector<Vec3> points;
  std::vector<uint32_t> triangles;  ///< 3 per triangle, counter-clockwise seen from outside
  std::vector<uint32_t> lines;      ///< 2 per line
  void tri(uint32_t a, uint32_t b, uint32_t c) { triangles.insert(triangles.end(), {a, b, c}); }
};

/// A solid of revolution about local y: profile (rho, y) from the top pole (rho = 0) to the bottom pole.
void lathe(LocalMesh& m, const std::vector<std::pair<Real, Real>>& profile, int segments) {
  const uint32_t top = 0;
  m.points.push_back(Vec3(0, profile.front().second, 0));
  const size_t rings = profile.size() - 2;
  for (size_t k = 1; k + 1 < profile.size(); ++k)
    for (int s = 0; s < segments; ++s) {
      const Real phi = 2 * M_PI * s / segments;
      // (rho cos phi, y, -rho sin phi): with the profile running down, triangles (a, b, c) below face outward.
      m.points.push_back(Vec3(profile[k].first * std::cos(phi), profile[k].second, -profile[k].first * std::sin(phi)));
    }
  const uint32_t bottom = uint32_t(m.points.size());
  m.points.push_back(Vec3(0, profile.back().second, 0));
  auto ring = [&](size_t k, int s) { return uint32_t(1 + k * segments + (s % segments)); };
  for (int s = 0; s < segments; ++s) {
    m.tri(top, ring(0, s), ring(0, s + 1));
    for (size_t k = 0; k + 1 < rings; ++k) {
      m.tri(ring(k, s), ring(k + 1, s), ring(k + 1, s + 1));
      m.tri(ring(k, s), ring(k + 1, s + 1), ring(k, s + 1));
    }
    m.tri(ring(rings - 1, s), bottom, ring(rings - 1, s + 1));
  }
}

/// Orthonormal u with u . n = 0.
Vec3 anyPerpendicular(const Vec3& n) {
  const Vec3 a = std::abs(n.x()) < 0.9 ? Vec3::UnitX() : Vec3::UnitY();
  return n.cross(a).normalized();
}

LocalMesh tessellate(const Shape& shape, int segments, Real planeHalfSize) {
  LocalMesh m;
  const int bands = std::max(1, segments / 4);  // per hemisphere
  switch (shape.getType()) {
    case Shape::SPHERE: {
      const Real r = static_cast<const Sphere&>(shape).getRadius();
      std::vector<std::pair<Real, Real>> p;
      for (int k = 0; k <= 2 * bands; ++k) {
        const Real t = M_PI * k / (2 * bands);
        p.emplace_back(k == 0 || k == 2 * bands ? 0 : r * std::sin(t), r * std::cos(t));
      }
      lathe(m, p, segments);
      break;
    }
    case Shape::CAPSULE: {
      const auto& c = static_cast<const Capsule&>(shape);
      const Real r = c.getRadius(), h = c.getHeight();
      std::vector<std::pair<Real, Real>> p;
      for (int k = 0; k <= bands; ++k) {
        const Real t = 0.5 * M_PI * k / bands;
        p.emplace_back(k == 0 ? 0 : r * std::sin(t), 0.5 * h + r * std::cos(t));
      }
      for (int k = 0; k <= bands; ++k) {
        const Real t = 0.5 * M_PI + 0.5 * M_PI * k / bands;
        p.emplace_back(k == bands ? 0 : r * std::sin(t), -0.5 * h + r * std::cos(t));
      }
      lathe(m, p, segments);
      break;
    }
    case Shape::CYLINDER: {
      const auto& c = static_cast<const Cylinder&>(shape);
      const Real r = c.getRadius(), h = c.getHeight();
      lathe(m, {{0, 0.5 * h}, {r, 0.5 * h}, {r, -0.5 * h}, {0, -0.5 * h}}, segments);
      break;
    }
    case Shape::BOX: {
      const Vec3& he = static_cast<const Box&>(shape).getHalfExtents();
      for (uint32_t i = 0; i < 8; ++i)  // bit 0: +x, bit 1: +y, bit 2: +z
        m.points.push_back(Vec3(i & 1 ? he.x() : -he.x(), i & 2 ? he.y() : -he.y(), i & 4 ? he.z() : -he.z()));
      const uint32_t quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                    {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};  // outward, counter-clockwise
      for (const auto& q : quads) {
        m.tri(q[0], q[1], q[2]);
        m.tri(q[0], q[2], q[3]);
      }
      break;
    }
    case Shape::CONVEX: {
      const auto& c = static_cast<const Convex&>(shape);
      m.points = c.getVertices();
      for (const auto& f : c.getFaces())
        for (size_t i = 1; i + 1 < f.vertices.size(); ++i) m.tri(f.vertices[0], f.vertices[i], f.vertices[i + 1]);
      break;
    }
    case Shape::PLANE: {
      const auto& pl = static_cast<const Plane&>(shape);
      const Vec3 n = pl.getNormal(), c = n * pl.getDistance();
      const Vec3 u = anyPerpendicular(n) * planeHalfSize, v = n.cross(u);
      m.points = {c - u - v, c + u - v, c + u + v, c - u + v};
      m.tri(0, 1, 2);
      m.tri(0, 2, 3);
      break;
    }
    case Shape::HEIGHT_FIELD: {
      const auto& hf = static_cast<const HeightField&>(shape);
      const size_t nx = hf.getResolutionX(), ny = hf.getResolutionY();
      m.points.reserve(nx * ny);
      for (size_t j = 0; j < ny; ++j)
        for (size_t i = 0; i < nx; ++i) m.points.push_back(hf.getVertex(i, j));
      for (size_t j = 0; j + 1 < ny; ++j)
        for (size_t i = 0; i + 1 < nx; ++i) {
          const auto v00 = uint32_t(j * nx + i), v10 = v00 + 1, v01 = uint32_t(v00 + nx), v11 = v01 + 1;
          m.tri(v00, v10, v11);  // the collision triangulation's diagonal (i, j)-(i+1, j+1)
          m.tri(v00, v11, v01);
        }
      break;
    }
    case Shape::LINE: {
      const auto& l = static_cast<const Line&>(shape);
      m.points = {l.getFirstPoint(), l.getSecondPoint()};
      m.lines = {0, 1};
      break;
    }
    default:
      break;  // nothing drawable
  }
  return m;
}

/// Arrays of the bodies file.
struct BodiesMesh {
  std::vector<float> points;
  std::vector<double> velocity;
  std::vector<int64_t> triConn, triOff, lineConn, lineOff;
  std::vector<int64_t> triBody, lineBody;
  std::vector<uint32_t> triGeom, lineGeom;

  void add(const Geometry& g, int segments, Real planeHalfSize) {
    const LocalMesh m = tessellate(*g.getShape(), segments, planeHalfSize);
    const Transform t = worldTransform(g);
    const RigidBody* body = g.getRigidBody();
    const int64_t base = int64_t(points.size() / 3);
    for (const Vec3& pl : m.points) {
      const Vec3 p = t.apply(pl);
      points.insert(points.end(), {float(p.x()), float(p.y()), float(p.z())});
      const Vec3 v = body ? body->getVelocityAt(p) : Vec3::Zero();
      velocity.insert(velocity.end(), {v.x(), v.y(), v.z()});
    }
    const int64_t bodyId = body ? int64_t(body->getId()) : -1;
    for (size_t i = 0; i < m.triangles.size(); i += 3) {
      for (int k = 0; k < 3; ++k) triConn.push_back(base + m.triangles[i + k]);
      triOff.push_back(int64_t(triConn.size()));
      triBody.push_back(bodyId);
      triGeom.push_back(g.getId());
    }
    for (size_t i = 0; i < m.lines.size(); i += 2) {
      for (int k = 0; k < 2; ++k) lineConn.push_back(base + m.lines[i + k]);
      lineOff.push_back(int64_t(lineConn.size()));
      lineBody.push_back(bodyId);
      lineGeom.push_back(g.getId());
    }
  }
};

std::string frameName(const std::string& base, const std::string& part, size_t frame, const char* ext) {
  char num6[32];
  std::snprintf(num6, sizeof num6, "%06zu", frame);
  return base + "_" + part + "_" + num6 + "." + ext;
}

template <class T>
void appendAll(std::vector<T>& to, const std::vector<T>& from) {
  to.insert(to.end(), from.begin(), from.end());
}

}  // namespace

// ---------------------------------------------------------------------------------------------------------------

VtkExporter::VtkExporter(const std::string& directory, const std::string& baseName)
    : directory_(directory), baseName_(baseName) {
  if (baseName.empty() || baseName.find('/') != std::string::npos)
    detail::throwInvalid("VtkExporter", "baseName", baseName, "must be non-empty without '/'");
  if (directory.empty()) detail::throwInvalid("VtkExporter", "directory", directory, "must be non-empty");
  std::error_code ec;
  fs::create_directories(directory, ec);
  if (ec || !fs::is_directory(directory))
    detail::throwInvalid("VtkExporter", "directory", directory,
                         "cannot be created" + (ec ? ": " + ec.message() : std::string(": not a directory")));
  // Writable: create and remove a probe file (permissions alone do not tell, e.g. a read-only mount).
  const fs::path probe = fs::path(directory) / ("." + baseName + ".probe.tmp");
  {
    std::ofstream out(probe, std::ios::binary | std::ios::trunc);
    if (!out) detail::throwInvalid("VtkExporter", "directory", directory, "is not writable");
  }
  fs::remove(probe, ec);
}

VtkExporter::~VtkExporter() {
  if (closed_) return;
  try {
    close();
  } catch (const std::exception& e) {
    Logger::error(std::string("VtkExporter: ") + e.what());
  }
}

void VtkExporter::addTerrain(const Terrain& terrain) {
  if (std::find(terrains_.begin(), terrains_.end(), &terrain) == terrains_.end()) {
    terrains_.push_back(&terrain);
    parts_.push_back({&terrain, nullptr, terrains_.size() - 1});
  }
}

void VtkExporter::addGranularFields(const GranularFieldPostProcessor& fields) {
  if (std::find(fields_.begin(), fields_.end(), &fields) == fields_.end()) {
    fields_.push_back(&fields);
    parts_.push_back({nullptr, &fields, fields_.size() - 1});
  }
}

void VtkExporter::setTessellation(int segments) {
  if (segments < 4 || segments % 2 != 0)
    detail::throwInvalid("VtkExporter::setTessellation", "segments", (long long)segments, "must be even and >= 4");
  segments_ = segments;
}

void VtkExporter::setPlaneHalfSize(Real halfSize) {
  if (!std::isfinite(halfSize) || halfSize <= 0)
    detail::throwInvalid("VtkExporter::setPlaneHalfSize", "halfSize", halfSize, "must be finite and > 0");
  planeHalfSize_ = halfSize;
}

std::string VtkExporter::getCollectionPath() const { return (fs::path(directory_) / (baseName_ + ".pvd")).string(); }

void VtkExporter::writeFrame(const Simulation& sim, double time) {
  if (closed_) throw std::logic_error("VtkExporter::writeFrame: the exporter is closed (" + getCollectionPath() + ")");
  if (!std::isfinite(time)) detail::throwInvalid("VtkExporter::writeFrame", "time", Real(time), "must be finite");
  const size_t f = frames_.size();
  const fs::path dir(directory_);
  Frame frame{time, {}, {}};
  size_t bytes = 0;

  // Bodies.
  {
    BodiesMesh mesh;
    auto isTerrainGeometry = [&](const Geometry* g) {
      for (const Terrain* t : terrains_)
        if (t->getGeometry().get() == g) return true;
      return false;
    };
    for (const auto& b : sim.getRigidBodies())
      for (const auto& g : b->getGeometries())
        if (!isTerrainGeometry(g.get())) mesh.add(*g, segments_, planeHalfSize_);
    for (const auto& g : sim.getStaticGeometries())
      if (!isTerrainGeometry(g.get())) mesh.add(*g, segments_, planeHalfSize_);
    const size_t np = mesh.points.size() / 3, nl = mesh.lineOff.size(), nt = mesh.triOff.size();
    XmlFile x;
    x.open("Piece NumberOfPoints=\"" + std::to_string(np) + "\" NumberOfVerts=\"0\" NumberOfLines=\"" +
               std::to_string(nl) + "\" NumberOfStrips=\"0\" NumberOfPolys=\"" + std::to_string(nt) + "\"",
           2);
    x.open("PointData Vectors=\"velocity\"", 3);
    x.array(4, "velocity", 3, mesh.velocity);
    x.close("PointData", 3);
    // Cell data: VTK orders PolyData cells verts, lines, strips, polys.
    std::vector<int64_t> bodyId = mesh.lineBody;
    appendAll(bodyId, mesh.triBody);
    std::vector<uint32_t> geomId = mesh.lineGeom;
    appendAll(geomId, mesh.triGeom);
    x.open("CellData Scalars=\"body_id\"", 3);
    x.array(4, "body_id", 1, bodyId);
    x.array(4, "geometry_id", 1, geomId);
    x.close("CellData", 3);
    x.open("Points", 3);
    x.array(4, "Points", 3, mesh.points);
    x.close("Points", 3);
    x.open("Lines", 3);
    x.array(4, "connectivity", 1, mesh.lineConn);
    x.array(4, "offsets", 1, mesh.lineOff);
    x.close("Lines", 3);
    x.open("Polys", 3);
    x.array(4, "connectivity", 1, mesh.triConn);
    x.array(4, "offsets", 1, mesh.triOff);
    x.close("Polys", 3);
    x.close("Piece", 2);
    const std::string name = frameName(baseName_, "bodies", f, "vtp");
    bytes += x.write(dir / name, "PolyData", "");
    frame.files.push_back(name);
    frame.parts.push_back(0);
  }

  // Particles.
  {
    const GranularBodySystem& gbs = sim.getGranularBodySystem();
    const size_t dense = gbs.size();
    std::vector<float> pts;
    std::vector<double> radius, mass, vel, omega;
    std::vector<uint64_t> ids;
    std::vector<int64_t> conn, off;
    const auto names = gbs.getCustomBufferRealNames();
    std::vector<std::vector<double>> custom(names.size());
    std::vector<const Real*> customSrc;
    for (const auto& n : names) customSrc.push_back(gbs.customBufferReal(n));
    const size_t n = gbs.numParticles();
    pts.reserve(3 * n);
    vel.reserve(3 * n);
    omega.reserve(3 * n);
    radius.reserve(n);
    mass.reserve(n);
    ids.reserve(n);
    const auto& P = gbs.positions();
    const auto& V = gbs.velocities();
    const auto& W = gbs.angularVelocities();
    const auto& R = gbs.radii();
    const auto& M = gbs.masses();
    for (size_t i = 0; i < dense; ++i) {
      if (!gbs.isAliveDense(i)) continue;
      pts.insert(pts.end(), {float(P[i].x()), float(P[i].y()), float(P[i].z())});
      vel.insert(vel.end(), {V[i].x(), V[i].y(), V[i].z()});
      omega.insert(omega.end(), {W[i].x(), W[i].y(), W[i].z()});
      radius.push_back(R[i]);
      mass.push_back(M[i]);
      ids.push_back(uint64_t(gbs.idOfDense(i)));
      for (size_t c = 0; c < names.size(); ++c) custom[c].push_back(customSrc[c] ? customSrc[c][i] : 0.0);
    }
    const size_t np = ids.size();
    conn.resize(np);
    off.resize(np);
    for (size_t i = 0; i < np; ++i) {
      conn[i] = int64_t(i);
      off[i] = int64_t(i + 1);
    }
    XmlFile x;
    x.open("Piece NumberOfPoints=\"" + std::to_string(np) + "\" NumberOfVerts=\"" + std::to_string(np) +
               "\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"0\"",
           2);
    x.open("PointData Scalars=\"radius\" Vectors=\"velocity\"", 3);
    x.array(4, "radius", 1, radius);
    x.array(4, "mass", 1, mass);
    x.array(4, "velocity", 3, vel);
    x.array(4, "angular_velocity", 3, omega);
    x.array(4, "id", 1, ids);
    for (size_t c = 0; c < names.size(); ++c) x.array(4, names[c], 1, custom[c]);
    x.close("PointData", 3);
    x.open("Points", 3);
    x.array(4, "Points", 3, pts);
    x.close("Points", 3);
    x.open("Verts", 3);
    x.array(4, "connectivity", 1, conn);
    x.array(4, "offsets", 1, off);
    x.close("Verts", 3);
    x.close("Piece", 2);
    const std::string name = frameName(baseName_, "particles", f, "vtp");
    bytes += x.write(dir / name, "PolyData", "");
    frame.files.push_back(name);
    frame.parts.push_back(1);
  }

  // Terrains and fields, in the order they were added.
  for (size_t p = 0; p < parts_.size(); ++p) {
    const Part& part = parts_[p];
    XmlFile x;
    std::string name;
    if (part.terrain) {
      const Terrain& t = *part.terrain;
      const HeightField& hf = *t.getHeightField();
      const TerrainDataInterface& data = t.getDataInterface();
      const size_t nx = hf.getResolutionX(), ny = hf.getResolutionY();
      const Transform tf = worldTransform(*t.getGeometry());
      std::vector<float> pts;
      pts.reserve(3 * nx * ny);
      std::vector<double> height(hf.getHeights().begin(), hf.getHeights().end()), comp(nx * ny), mult(nx * ny),
          pending(nx * ny);
      std::vector<uint8_t> index(nx * ny);
      for (size_t j = 0; j < ny; ++j)
        for (size_t i = 0; i < nx; ++i) {
          const Vec3 w = tf.apply(hf.getVertex(i, j));
          pts.insert(pts.end(), {float(w.x()), float(w.y()), float(w.z())});
          const size_t v = j * nx + i;
          comp[v] = data.getCompression(i, j);
          mult[v] = data.getYoungsModulusMultiplier(i, j);
          pending[v] = t.getPendingVolume(i, j);
          index[v] = uint8_t(data.getMaterialIndex(i, j));
        }
      const std::string extent = "0 " + std::to_string(nx - 1) + " 0 " + std::to_string(ny - 1) + " 0 0";
      x.open("Piece Extent=\"" + extent + "\"", 2);
      x.open("PointData Scalars=\"height\"", 3);
      x.array(4, "height", 1, height);
      x.array(4, "compression", 1, comp);
      x.array(4, "youngs_modulus_multiplier", 1, mult);
      x.array(4, "pending_volume", 1, pending);
      x.array(4, "material_index", 1, index);
      x.close("PointData", 3);
      x.open("Points", 3);
      x.array(4, "Points", 3, pts);
      x.close("Points", 3);
      x.close("Piece", 2);
      name = frameName(baseName_, "terrain" + std::to_string(part.index), f, "vts");
      bytes += x.write(dir / name, "StructuredGrid", "WholeExtent=\"" + extent + "\"");
    } else {
      const GranularFieldPostProcessor& g = *part.fields;
      const auto& shape = g.getShape();
      const Transform& tf = g.getTransform();
      const Vec3 origin = tf.apply(-0.5 * g.getVolume());
      const Vec3 spacing = g.getVoxelSize();
      const Eigen::Matrix<Real, 3, 3> R = tf.q.toRotationMatrix();
      const std::string extent = "0 " + std::to_string(shape[0]) + " 0 " + std::to_string(shape[1]) + " 0 " +
                                 std::to_string(shape[2]);
      std::string attrs = "WholeExtent=\"" + extent + "\" Origin=\"" + num(origin.x()) + " " + num(origin.y()) +
                          " " + num(origin.z()) + "\" Spacing=\"" + num(spacing.x()) + " " + num(spacing.y()) + " " +
                          num(spacing.z()) + "\" Direction=\"";
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) attrs += num(R(r, c)) + (r == 2 && c == 2 ? "\"" : " ");
      x.open("Piece Extent=\"" + extent + "\"", 2);
      x.open("PointData", 3);
      x.close("PointData", 3);
      x.open("CellData", 3);
      for (const auto& field : g.getFields()) {
        const Real* d = field->getFieldData();
        std::vector<double> values(d ? d : nullptr, d ? d + field->getDataSize() : nullptr);
        if (values.empty()) values.assign(g.getNumVoxels() * size_t(field->getNumComponents()), 0.0);
        x.array(4, field->getName(), field->getNumComponents(), values);
      }
      x.close("CellData", 3);
      x.close("Piece", 2);
      name = frameName(baseName_, "fields" + std::to_string(part.index), f, "vti");
      bytes += x.write(dir / name, "ImageData", attrs);
    }
    frame.files.push_back(name);
    frame.parts.push_back(int(2 + p));
  }
  frames_.push_back(std::move(frame));
  lastFrameBytes_ = bytes;
}

void VtkExporter::close() {
  if (closed_) return;
  std::string xml =
      "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"1.0\" byte_order=\"LittleEndian\" "
      "header_type=\"UInt64\">\n  <Collection>\n";
  for (const Frame& fr : frames_)
    for (size_t i = 0; i < fr.files.size(); ++i)
      xml += "    <DataSet timestep=\"" + num(fr.time) + "\" group=\"\" part=\"" + std::to_string(fr.parts[i]) +
             "\" file=\"" + markupEscape(fr.files[i]) + "\"/>\n";
  xml += "  </Collection>\n</VTKFile>\n";
  XmlFile::writeAtomically(fs::path(getCollectionPath()), {xml}, {}, "");
  closed_ = true;
}

}  // namespace scree::io

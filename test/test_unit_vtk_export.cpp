// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// VtkExporter (scree/io/vtk_export.h): a small scene (a rotated moving box, a sphere, particles with a custom
// buffer, a terrain with a pressed vertex, a rotated granular field grid) written for two frames, then read back
// by test/vtk_read.py under Debian's /usr/bin/python3 - VTK's own XML readers (vtkXMLPolyDataReader,
// vtkXMLStructuredGridReader, vtkXMLImageDataReader: what ParaView runs; any VTK error or warning fails), meshio's
// binary-appended decoder and an independent xml + struct decoder, which must all agree - and compared with the
// simulation: points to float precision (they are written as Float32: the exact float of each double), every
// Float64 value and integer exactly, and the field grid's voxel centres as VTK places them (Origin, Spacing,
// Direction) at the post-processor's. VTK is a declared dependency (scripts/install-deps.sh: python3-vtk9):
// without it the test fails rather than skipping. Also: the .pvd
// lists both frames with their times, the surfaces are closed and outward (divergence-theorem volume), and the
// bad inputs (unwritable directory, a file that cannot be written) throw and leave no partial file.
#include <doctest/doctest.h>

#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <numbers>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "scree/io/vtk_export.h"
#include "scree/model/granular_field_post_processor.h"
#include "scree/model/terrain.h"
#include "test_world.h"

using namespace scree;
namespace fs = std::filesystem;

namespace {

/// A directory under the system temp dir, removed at the end of the test.
struct TempDir {
  fs::path path;
  explicit TempDir(const std::string& tag)
      : path(fs::temp_directory_path() / ("scree_vtk_" + tag + "_" + std::to_string(::getpid()))) {
    fs::remove_all(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

struct Array {
  std::string type;
  int components = 1;
  std::vector<std::string> text;  ///< as printed (floats: repr of the exact double)
  double at(size_t i) const { return std::stod(text.at(i)); }
  unsigned long long u(size_t i) const { return std::stoull(text.at(i)); }
  long long i64(size_t i) const { return std::stoll(text.at(i)); }
  size_t size() const { return text.size(); }
};
struct VtkFile {
  std::string type;
  std::string reader;                       ///< the VTK reader class that read it (vtk_read.py's "reader" line)
  std::map<std::array<int, 3>, Vec3> voxels;  ///< ImageData: cell centres as VTK maps (i+.5, j+.5, k+.5)
  std::map<std::string, std::string> attrs, piece;
  std::map<std::string, Array> arrays;  ///< key: "<section>/<name>"
  const Array& get(const std::string& key) const {
    auto it = arrays.find(key);
    if (it == arrays.end()) FAIL("no array " << key);
    return it->second;
  }
};
struct DataSet {
  double time;
  int part;
  std::string file;
};
struct ReadBack {
  bool meshio = false;
  std::string vtkVersion;  ///< VTK's version, empty if VTK's readers did not run
  std::vector<DataSet> datasets;
  std::map<std::string, VtkFile> files;
  std::string error;
};

ReadBack readBack(const std::string& pvd) {
  ReadBack r;
  REQUIRE_MESSAGE(fs::exists("/usr/bin/python3"),
                  "/usr/bin/python3 not found: run scripts/install-deps.sh (python3-vtk9, python3-meshio)");
  const fs::path script = fs::path(SCREE_TEST_SOURCE_DIR) / "vtk_read.py";
  const std::string cmd = "/usr/bin/python3 '" + script.string() + "' '" + pvd + "' 2>&1";
  FILE* p = ::popen(cmd.c_str(), "r");
  REQUIRE(p != nullptr);
  std::string out;
  char buf[65536];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
  const int status = ::pclose(p);
  if (status != 0) {
    r.error = out;
    return r;
  }
  std::istringstream in(out);
  std::string line;
  VtkFile* cur = nullptr;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::string tag;
    ls >> tag;
    if (tag == "vtk") {
      ls >> r.vtkVersion;
    } else if (tag == "reader") {
      ls >> cur->reader;
    } else if (tag == "voxel") {
      std::array<int, 3> ijk;
      Vec3 c;
      ls >> ijk[0] >> ijk[1] >> ijk[2] >> c.x() >> c.y() >> c.z();
      cur->voxels[ijk] = c;
    } else if (tag == "meshio") {
      std::string v;
      ls >> v;
      r.meshio = v == "yes";
    } else if (tag == "dataset") {
      DataSet d;
      ls >> d.time >> d.part >> d.file;
      r.datasets.push_back(d);
    } else if (tag == "file") {
      std::string name;
      ls >> name;
      cur = &r.files[name];
      ls >> cur->type;
    } else if (tag == "attr" || tag == "piece") {
      std::string k, v;
      ls >> k;
      std::getline(ls, v);
      (tag == "attr" ? cur->attrs : cur->piece)[k] = v.substr(v.find_first_not_of(' '));
    } else if (tag == "array") {
      std::string section, name;
      size_t count;
      Array a;
      ls >> section >> name >> a.type >> a.components >> count;
      a.text.resize(count);
      for (auto& t : a.text) ls >> t;
      cur->arrays[section + "/" + name] = std::move(a);
    }
  }
  return r;
}

std::vector<double> numbers(const std::string& s) {
  std::istringstream in(s);
  std::vector<double> v;
  double x;
  while (in >> x) v.push_back(x);
  return v;
}

double asFloat(double v) { return double(float(v)); }
/// Whether a point read back is the Float32 of p, coordinate by coordinate (exact).
bool isFloatOf(const Vec3& read, const Vec3& p) {
  return read.x() == asFloat(p.x()) && read.y() == asFloat(p.y()) && read.z() == asFloat(p.z());
}

/// Point k of a Points array.
Vec3 point(const Array& pts, size_t k) { return Vec3(pts.at(3 * k), pts.at(3 * k + 1), pts.at(3 * k + 2)); }

/// Signed volume (divergence theorem) of the triangles whose cell data geometry_id is `geomId`, and the set of
/// point indices they use. Polys follow the Lines in VTK's cell order.
Real closedVolume(const VtkFile& f, uint32_t geomId, std::set<size_t>& used) {
  const Array& pts = f.get("Points/Points");
  const Array& conn = f.get("Polys/connectivity");
  const Array& off = f.get("Polys/offsets");
  const Array& gid = f.get("CellData/geometry_id");
  const size_t numLines = f.get("Lines/offsets").size();
  Real vol = 0;
  size_t start = 0;
  for (size_t c = 0; c < off.size(); ++c) {
    const size_t end = size_t(off.i64(c));
    REQUIRE(end - start == 3);
    if (gid.u(numLines + c) == geomId) {
      const Vec3 a = point(pts, size_t(conn.i64(start))), b = point(pts, size_t(conn.i64(start + 1))),
                 d = point(pts, size_t(conn.i64(start + 2)));
      vol += a.dot(b.cross(d)) / 6;
      for (size_t k = start; k < end; ++k) used.insert(size_t(conn.i64(k)));
    }
    start = end;
  }
  return vol;
}

struct Scene {
  test::TestWorld w{1.0 / 60.0};
  RigidBodyRef box, ball;
  TerrainRef terrain;
  std::shared_ptr<GranularFieldPostProcessor> gpp;
  Vec3 boxHalf{0.3, 0.2, 0.1};
  Real ballRadius = 0.25;
  Real pressed = 0.02;

  Scene() {
    const Quat q(Eigen::AngleAxis<Real>(0.4, Vec3(1, 2, 3).normalized()));
    box = w.addBox(boxHalf, Vec3(1, 0.5, 2), 2.0, q);
    box->setVelocity(Vec3(0.5, -0.2, 0.1));
    box->setAngularVelocity(Vec3(0.3, 1.0, -0.7));
    ball = w.addSphere(ballRadius, Vec3(-1, 0, 1.5));
    // Terrain 6 x 5 vertices over 2.5 x 2 m, surface 0.5 m above its geometry at z = -0.5; vertex (2, 2) is
    // mapped to a deformable material (index 3) and pressed down.
    auto hf = std::make_shared<HeightField>(6, 5, 2.5, 2.0);
    hf->setHeights(std::vector<Real>(30, 0.5));
    terrain = std::make_shared<Terrain>(hf);
    terrain->getGeometry()->setMaterial(w.material);
    terrain->getGeometry()->setPosition(Vec3(0.2, -0.1, -0.5));
    w.sim->add(terrain);
    auto soil = std::make_shared<Material>("soil");
    terrain->getDataInterface().add(soil, 3, 0, 1.0);
    terrain->getDataInterface().setMaterialMapping(2, 2, 3);
    REQUIRE(terrain->pressVertex(2, 2, pressed));
    // Particles well above everything, with a custom buffer.
    auto& gbs = w.sim->getGranularBodySystem();
    gbs.setMaterial(w.material);
    gbs.addCustomBufferReal("temperature");
    for (int i = 0; i < 5; ++i) {
      const size_t id = gbs.createParticle(Vec3(0.31 * i - 0.6, 0.17 * i, 3.0 + 0.05 * i), 0.02 + 0.003 * i,
                                           Vec3(0.1 * i, -0.05, 0.2));
      gbs.setAngularVelocity(id, Vec3(1, 2, 3) * (0.1 * i));
      gbs.setCustomReal("temperature", id, 290 + 1.5 * i);
    }
    gbs.destroyParticle(gbs.getParticleIds()[1]);  // a hole in the dense order
    gpp = std::make_shared<GranularFieldPostProcessor>(gbs, GranularFieldPostProcessor::Shape{3, 2, 2},
                                                       Vec3(1.8, 1.2, 0.6));
    gpp->setTransform(Transform{Vec3(-0.2, 0.4, 3.1), Quat(Eigen::AngleAxis<Real>(0.3, Vec3::UnitZ()))});
    gpp->addField(GranularField::VELOCITY);
    gpp->addField(GranularField::KINETIC_STRESS);
    gpp->calculateFields();
  }
};

/// Checks one frame's files against the scene as it is now.
void checkFrame(const ReadBack& rb, const io::VtkExporter& ex, size_t frame, const Scene& s) {
  const auto& names = ex.getFrameFiles(frame);
  REQUIRE(names.size() == 4);
  for (const auto& n : names) REQUIRE_MESSAGE(rb.files.count(n) == 1, n);

  // ---- bodies ----
  {
    const VtkFile& f = rb.files.at(names[0]);
    CHECK(f.type == "PolyData");
    CHECK(f.reader == "vtkXMLPolyDataReader");
    const Array& pts = f.get("Points/Points");
    CHECK(pts.type == "Float32");
    const Array& vel = f.get("PointData/velocity");
    CHECK(vel.type == "Float64");
    const size_t np = pts.size() / 3;
    CHECK(vel.size() == 3 * np);
    CHECK(std::stoul(f.piece.at("NumberOfPoints")) == np);
    CHECK(std::stoul(f.piece.at("NumberOfPolys")) == f.get("Polys/offsets").size());
    // The terrain geometry is not among the bodies (its own .vts), the ground box and the two bodies are.
    std::set<unsigned long long> geoms;
    const Array& gid = f.get("CellData/geometry_id");
    const Array& bid = f.get("CellData/body_id");
    for (size_t c = 0; c < gid.size(); ++c) geoms.insert(gid.u(c));
    CHECK(geoms.count(s.terrain->getGeometry()->getId()) == 0);
    CHECK(geoms.count(s.box->getGeometries()[0]->getId()) == 1);
    CHECK(geoms.count(s.ball->getGeometries()[0]->getId()) == 1);
    for (size_t c = 0; c < gid.size(); ++c)
      if (gid.u(c) == s.box->getGeometries()[0]->getId()) CHECK(bid.i64(c) == s.box->getId());

    // Box: exactly its 8 world corners (as floats), a closed outward surface of volume 8 hx hy hz (float points:
    // relative 1e-6), and each point's velocity the body's velocity there (the point read back as float differs
    // from the written double by < 1e-6 m, so v differs by < |w| 1e-6).
    std::set<size_t> used;
    const Real vol = closedVolume(f, s.box->getGeometries()[0]->getId(), used);
    CHECK(vol == doctest::Approx(8 * s.boxHalf.prod()).epsilon(1e-6));
    CHECK(used.size() == 8);
    const Transform t = s.box->getTransform();
    for (int k = 0; k < 8; ++k) {
      const Vec3 c = t.apply(Vec3(k & 1 ? 1 : -1, k & 2 ? 1 : -1, k & 4 ? 1 : -1).cwiseProduct(s.boxHalf));
      bool found = false;
      for (size_t i : used)
        found |= isFloatOf(point(pts, i), c);
      CHECK_MESSAGE(found, "box corner " << k);
    }
    for (size_t i : used) {
      const Vec3 v(vel.at(3 * i), vel.at(3 * i + 1), vel.at(3 * i + 2));
      CHECK((v - s.box->getVelocityAt(point(pts, i))).norm() <= s.box->getAngularVelocity().norm() * 1e-6);
    }
    // Sphere: every point on the sphere (float precision), closed and outward; an inscribed polyhedron, so its
    // volume is below the ball's: 24 segments x 12 bands give 97.2 % (the inscribed polyhedron's volume, computed
    // separately), so above 95 % unless facets are missing or turned inward.
    used.clear();
    const Real sv = closedVolume(f, s.ball->getGeometries()[0]->getId(), used);
    const Real ballVol = 4.0 / 3.0 * std::numbers::pi * std::pow(s.ballRadius, 3);
    CHECK(sv < ballVol);
    CHECK(sv > 0.95 * ballVol);
    for (size_t i : used)
      CHECK(std::abs((point(pts, i) - s.ball->getPosition()).norm() - s.ballRadius) <= 1e-6);
  }

  // ---- particles ----
  {
    const VtkFile& f = rb.files.at(names[1]);
    CHECK(f.type == "PolyData");
    CHECK(f.reader == "vtkXMLPolyDataReader");
    const auto& gbs = s.w.sim->getGranularBodySystem();
    const Array& pts = f.get("Points/Points");
    const Array& id = f.get("PointData/id");
    REQUIRE(id.size() == gbs.numParticles());
    CHECK(f.get("Verts/offsets").size() == gbs.numParticles());
    CHECK(id.type == "UInt64");
    for (size_t k = 0; k < id.size(); ++k) {
      const size_t pid = size_t(id.u(k));
      REQUIRE(gbs.isValid(pid));
      const Vec3 p = gbs.getPosition(pid), v = gbs.getVelocity(pid), w = gbs.getAngularVelocity(pid);
      CHECK(isFloatOf(point(pts, k), p));
      CHECK(f.get("PointData/radius").at(k) == gbs.getRadius(pid));
      CHECK(f.get("PointData/mass").at(k) == gbs.getMass(pid));
      CHECK(f.get("PointData/temperature").at(k) == gbs.getCustomReal("temperature", pid));
      for (int c = 0; c < 3; ++c) {
        CHECK(f.get("PointData/velocity").at(3 * k + c) == v[c]);
        CHECK(f.get("PointData/angular_velocity").at(3 * k + c) == w[c]);
      }
    }
  }

  // ---- terrain ----
  {
    const VtkFile& f = rb.files.at(names[2]);
    CHECK(f.type == "StructuredGrid");
    CHECK(f.reader == "vtkXMLStructuredGridReader");
    CHECK(f.attrs.at("WholeExtent") == "0 5 0 4 0 0");
    const HeightField& hf = *s.terrain->getHeightField();
    const auto& data = s.terrain->getDataInterface();
    const Transform t = s.terrain->getGeometry()->getTransform();
    const Array& pts = f.get("Points/Points");
    REQUIRE(pts.size() == 3 * 30);
    for (size_t j = 0; j < 5; ++j)
      for (size_t i = 0; i < 6; ++i) {
        const size_t v = j * 6 + i;
        const Vec3 w = t.apply(hf.getVertex(i, j));
        CHECK(isFloatOf(point(pts, v), w));
        CHECK(f.get("PointData/height").at(v) == hf.getHeight(i, j));
        CHECK(f.get("PointData/compression").at(v) == data.getCompression(i, j));
        CHECK(f.get("PointData/youngs_modulus_multiplier").at(v) == data.getYoungsModulusMultiplier(i, j));
        CHECK(f.get("PointData/material_index").u(v) == data.getMaterialIndex(i, j));
        CHECK(f.get("PointData/pending_volume").at(v) == s.terrain->getPendingVolume(i, j));
      }
    // The pressed vertex is there: lower by `pressed`, compressed (c > 0, m > 1), material 3.
    const size_t v22 = 2 * 6 + 2;
    CHECK(f.get("PointData/height").at(v22) == doctest::Approx(0.5 - s.pressed).epsilon(1e-12));
    CHECK(f.get("PointData/compression").at(v22) > 0);
    CHECK(f.get("PointData/youngs_modulus_multiplier").at(v22) > 1);
    CHECK(f.get("PointData/material_index").u(v22) == 3);
  }

  // ---- granular fields ----
  {
    const VtkFile& f = rb.files.at(names[3]);
    CHECK(f.type == "ImageData");
    CHECK(f.reader == "vtkXMLImageDataReader");
    CHECK(f.attrs.at("WholeExtent") == "0 3 0 2 0 2");
    const GranularFieldPostProcessor& g = *s.gpp;
    const Vec3 origin = g.getTransform().apply(-0.5 * g.getVolume());
    CHECK(numbers(f.attrs.at("Origin")) == std::vector<double>{origin.x(), origin.y(), origin.z()});
    const Vec3 sp = g.getVoxelSize();
    CHECK(numbers(f.attrs.at("Spacing")) == std::vector<double>{sp.x(), sp.y(), sp.z()});
    const auto dir = numbers(f.attrs.at("Direction"));
    REQUIRE(dir.size() == 9);
    const auto R = g.getTransform().q.toRotationMatrix();
    for (int k = 0; k < 9; ++k) CHECK(dir[size_t(k)] == R(k / 3, k % 3));
    // Voxel (i, j, k)'s centre from the file's Origin/Spacing/Direction is the post-processor's.
    const auto on = numbers(f.attrs.at("Origin"));
    const Vec3 o(on.at(0), on.at(1), on.at(2));
    const Vec3 c = o + R * Vec3(2.5 * sp.x(), 0.5 * sp.y(), 1.5 * sp.z());
    CHECK((c - g.getVoxelCenter(2, 0, 1)).norm() <= 1e-12);
    // Every voxel centre as VTK itself maps index to world (its reading of Direction: rows or columns) is the
    // post-processor's; 1e-12 m: a few roundings of O(1) m coordinates.
    REQUIRE(f.voxels.size() == 3 * 2 * 2);
    for (const auto& [ijk, vc] : f.voxels)
      CHECK_MESSAGE((vc - g.getVoxelCenter(size_t(ijk[0]), size_t(ijk[1]), size_t(ijk[2]))).norm() <= 1e-12,
                    "voxel " << ijk[0] << " " << ijk[1] << " " << ijk[2]);
    REQUIRE(g.getFields().size() == 4);  // velocity pulls in mass and momentum; kinetic stress
    Real massSum = 0;
    for (const auto& field : g.getFields()) {
      const Array& a = f.get("CellData/" + field->getName());
      CHECK(a.type == "Float64");
      CHECK(a.components == field->getNumComponents());
      REQUIRE(a.size() == field->getDataSize());
      for (size_t k = 0; k < a.size(); ++k) CHECK(a.at(k) == field->getFieldData()[k]);
      if (field->getType() == GranularField::MASS)
        for (size_t k = 0; k < a.size(); ++k) massSum += a.at(k);
    }
    CHECK(massSum > 0);  // the particles are inside the grid: the fields are not all zero
  }
}

}  // namespace

TEST_CASE("VtkExporter: two frames read back by VTK's readers, meshio's decoder and xml+struct give the simulation's "
          "values") {
  TempDir dir("frames");
  Scene s;
  {
    io::VtkExporter ex((dir.path / "out").string(), "scene");
    ex.addTerrain(*s.terrain);
    ex.addTerrain(*s.terrain);  // twice: once
    ex.addGranularFields(*s.gpp);
    ex.writeFrame(*s.w.sim, s.w.time());
    CHECK(ex.getLastFrameBytes() > 0);
    const std::string pvd = ex.getCollectionPath();

    // Frame 1 after three steps; its values are compared with the scene as it is then (frame 0's with the
    // unstepped scene: the next test case).
    s.w.steps(3);
    s.gpp->calculateFields();
    const double t1 = s.w.time();
    ex.writeFrame(*s.w.sim, t1);
    ex.close();
    CHECK_THROWS_AS(ex.writeFrame(*s.w.sim, 1.0), std::logic_error);
    for (const auto& e : fs::directory_iterator(dir.path / "out")) CHECK(e.path().extension() != ".tmp");

    const ReadBack rb = readBack(pvd);
    REQUIRE_MESSAGE(rb.error.empty(), rb.error);
    REQUIRE_MESSAGE(!rb.vtkVersion.empty(), "VTK's readers did not run: run scripts/install-deps.sh (python3-vtk9)");
    MESSAGE("read back by VTK " << rb.vtkVersion << "'s XML readers" << std::string(rb.meshio ? ", meshio" : "")
                                << " and xml+struct");
    if (!rb.meshio) MESSAGE("/usr/bin/python3 cannot import meshio: read back by the xml+struct decoder only");
    // The collection: 2 frames x 4 parts with their times and parts, files as the exporter named them.
    REQUIRE(rb.datasets.size() == 8);
    for (size_t k = 0; k < 8; ++k) {
      CHECK(rb.datasets[k].time == (k < 4 ? 0.0 : t1));
      CHECK(rb.datasets[k].part == int(k % 4));
      CHECK(rb.datasets[k].file == ex.getFrameFiles(k / 4)[k % 4]);
    }
    // Frame 1 is the scene now.
    checkFrame(rb, ex, 1, s);
    // Frame 0 held the particles where they started: every particle has fallen since (t1 = 3 steps).
    const auto& p0 = rb.files.at(ex.getFrameFiles(0)[1]).get("Points/Points");
    const auto& p1 = rb.files.at(ex.getFrameFiles(1)[1]).get("Points/Points");
    REQUIRE(p0.size() == p1.size());
    for (size_t k = 2; k < p0.size(); k += 3) CHECK(p1.at(k) < p0.at(k));
  }
}

TEST_CASE("VtkExporter: frame 0 matches the scene it was written from") {
  TempDir dir("frame0");
  Scene s;
  io::VtkExporter ex(dir.path.string(), "f0");
  ex.addTerrain(*s.terrain);
  ex.addGranularFields(*s.gpp);
  ex.writeFrame(*s.w.sim, 0.25);
  ex.close();
  const ReadBack rb = readBack(ex.getCollectionPath());
  REQUIRE_MESSAGE(rb.error.empty(), rb.error);
  REQUIRE(!rb.vtkVersion.empty());
  REQUIRE(rb.datasets.size() == 4);
  CHECK(rb.datasets[0].time == 0.25);
  checkFrame(rb, ex, 0, s);
}

TEST_CASE("VtkExporter: bad input") {
  TempDir dir("bad");
  fs::create_directories(dir.path);
  const fs::path file = dir.path / "regular_file";
  std::ofstream(file) << "x";
  const std::string under = (file / "sub").string();
  // A directory under a regular file cannot be created: std::invalid_argument naming it.
  try {
    io::VtkExporter ex(under);
    FAIL("no exception");
  } catch (const std::invalid_argument& e) {
    CHECK(std::string(e.what()).find(under) != std::string::npos);
  }
  CHECK_THROWS_AS(io::VtkExporter(dir.path.string(), ""), std::invalid_argument);
  CHECK_THROWS_AS(io::VtkExporter(dir.path.string(), "a/b"), std::invalid_argument);

  // A frame file that cannot be written (its name is taken by a directory): std::runtime_error, the frame is
  // not counted, and no partial file (.tmp) is left.
  Scene s;
  io::VtkExporter ex((dir.path / "out").string(), "scene");
  CHECK_THROWS_AS(ex.setTessellation(5), std::invalid_argument);
  CHECK_THROWS_AS(ex.setPlaneHalfSize(0), std::invalid_argument);
  CHECK(ex.getTessellation() == 24);
  fs::create_directories(dir.path / "out" / "scene_particles_000000.vtp" / "x");
  CHECK_THROWS_AS(ex.writeFrame(*s.w.sim, 0.0), std::runtime_error);
  CHECK(ex.getNumFrames() == 0);
  for (const auto& e : fs::directory_iterator(dir.path / "out")) CHECK(e.path().extension() != ".tmp");
  fs::remove_all(dir.path / "out" / "scene_particles_000000.vtp");
  ex.writeFrame(*s.w.sim, 0.0);
  CHECK(ex.getNumFrames() == 1);
}

TEST_CASE("VtkExporter: every shape's surface in world coordinates (closed, outward, the closed-form volume)") {
  TempDir dir("shapes");
  test::TestWorld w;
  const Real r = 0.2, h = 0.5;
  auto place = [&](ShapeRef shape, const Vec3& p, const Quat& q) {
    auto g = std::make_shared<Geometry>(std::move(shape));
    g->setPosition(p);
    g->setRotation(q);
    w.sim->add(g);
    return g;
  };
  const Quat q(Eigen::AngleAxis<Real>(0.7, Vec3(0.2, -1, 0.5).normalized()));
  auto cyl = place(std::make_shared<Cylinder>(r, h), Vec3(1, 2, 3), q);
  auto cap = place(std::make_shared<Capsule>(r, h), Vec3(-1, 2, 3), q);
  std::vector<Vec3> cube;
  for (int k = 0; k < 8; ++k) cube.push_back(Vec3(k & 1, (k >> 1) & 1, (k >> 2) & 1) * 0.4);
  cube.push_back(Vec3(0.2, 0.2, 0.2));  // inside: not a hull vertex
  auto hull = place(std::make_shared<Convex>(cube), Vec3(0, -2, 1), q);
  auto plane = place(std::make_shared<Plane>(Vec3(0.1, 0.2, 1), 0.3), Vec3(0, 0, -1), q);
  auto hf = std::make_shared<HeightField>(4, 3, 1.5, 1.0);
  hf->setHeight(1, 1, 0.3);
  auto field = place(hf, Vec3(3, 0, 0), q);
  auto line = place(std::make_shared<Line>(Vec3(0, 0, 0), Vec3(0, 0, -2)), Vec3(0, 5, 1), q);

  io::VtkExporter ex(dir.path.string(), "shapes");
  ex.setTessellation(16);
  ex.setPlaneHalfSize(7);
  ex.writeFrame(*w.sim, 0.0);
  ex.close();
  const ReadBack rb = readBack(ex.getCollectionPath());
  REQUIRE_MESSAGE(rb.error.empty(), rb.error);
  REQUIRE(!rb.vtkVersion.empty());
  const VtkFile& f = rb.files.at(ex.getFrameFiles(0)[0]);
  CHECK(f.reader == "vtkXMLPolyDataReader");
  const Array& pts = f.get("Points/Points");
  std::set<size_t> used;

  // Cylinder: the inscribed prism of a regular 16-gon, volume (N/2) r^2 sin(2 pi / N) h (float points: 1e-6).
  const int N = 16;
  const Real ngon = 0.5 * N * r * r * std::sin(2 * std::numbers::pi / N);
  CHECK(closedVolume(f, cyl->getId(), used) == doctest::Approx(ngon * h).epsilon(1e-6));
  for (size_t i : used) {  // every point on the cylinder's rim circles or axis ends, in its frame
    const Vec3 l = cyl->getTransform().applyInverse(point(pts, i));
    CHECK(std::abs(std::abs(l.y()) - 0.5 * h) <= 1e-6);
    const Real rho = std::hypot(l.x(), l.z());
    CHECK((rho <= 1e-6 || std::abs(rho - r) <= 1e-6));
  }
  // Capsule: that prism plus an inscribed sphere polyhedron (16 x 8 facets: 93.7 % of the ball, computed
  // separately), so between prism + 90 % of the ball and the capsule's volume.
  used.clear();
  const Real ball = 4.0 / 3.0 * std::numbers::pi * r * r * r;
  const Real vc = closedVolume(f, cap->getId(), used);
  CHECK(vc > ngon * h + 0.9 * ball);
  CHECK(vc < std::numbers::pi * r * r * h + ball);
  // Convex hull of a 0.4 m cube (and an inner point): exactly the cube, its 8 corners.
  used.clear();
  CHECK(closedVolume(f, hull->getId(), used) == doctest::Approx(0.064).epsilon(1e-6));
  CHECK(used.size() == 8);
  // Plane: two triangles on n . x = d (in the plane's frame), facing along n, 14 m square.
  used.clear();
  const Plane& pl = static_cast<const Plane&>(*plane->getShape());
  closedVolume(f, plane->getId(), used);  // an open surface: only its points are used
  REQUIRE(used.size() == 4);
  for (size_t i : used)
    CHECK(std::abs(pl.getNormal().dot(plane->getTransform().applyInverse(point(pts, i))) - pl.getDistance()) <=
          1e-5);
  {
    const Array& conn = f.get("Polys/connectivity");
    const Array& gid = f.get("CellData/geometry_id");
    const size_t numLines = f.get("Lines/offsets").size();
    size_t found = 0;
    for (size_t c = 0; c < f.get("Polys/offsets").size(); ++c) {
      if (gid.u(numLines + c) != plane->getId()) continue;
      const Vec3 a = point(pts, size_t(conn.i64(3 * c))), b = point(pts, size_t(conn.i64(3 * c + 1))),
                 d = point(pts, size_t(conn.i64(3 * c + 2)));
      const Vec3 n = (b - a).cross(d - a);
      CHECK(n.norm() == doctest::Approx(0.5 * 14 * 14 * 2).epsilon(1e-5));  // |cross| = 2 x (half the square)
      CHECK(n.normalized().dot(plane->getRotation() * pl.getNormal()) == doctest::Approx(1).epsilon(1e-6));
      ++found;
    }
    CHECK(found == 2);
  }
  // Height field (not a terrain): 2 triangles per cell, its vertices placed by the geometry.
  {
    const Array& conn = f.get("Polys/connectivity");
    const Array& gid = f.get("CellData/geometry_id");
    const size_t numLines = f.get("Lines/offsets").size();
    size_t tris = 0;
    std::set<size_t> pv;
    for (size_t c = 0; c < f.get("Polys/offsets").size(); ++c)
      if (gid.u(numLines + c) == field->getId()) {
        ++tris;
        for (int k = 0; k < 3; ++k) pv.insert(size_t(conn.i64(3 * c + k)));
      }
    CHECK(tris == 2 * 3 * 2);
    REQUIRE(pv.size() == 12);
    const size_t first = *pv.begin();  // the field's points are consecutive, x fastest
    for (size_t j = 0; j < 3; ++j)
      for (size_t i = 0; i < 4; ++i)
        CHECK(isFloatOf(point(pts, first + j * 4 + i), field->getTransform().apply(hf->getVertex(i, j))));
  }
  // Line: one line cell (cells before the polys) between its world end points.
  const Array& lconn = f.get("Lines/connectivity");
  REQUIRE(lconn.size() == 2);
  CHECK(f.get("CellData/geometry_id").u(0) == line->getId());
  CHECK(f.get("CellData/body_id").i64(0) == -1);
  CHECK(isFloatOf(point(pts, size_t(lconn.i64(0))), line->getTransform().apply(Vec3(0, 0, 0))));
  CHECK(isFloatOf(point(pts, size_t(lconn.i64(1))), line->getTransform().apply(Vec3(0, 0, -2))));
}

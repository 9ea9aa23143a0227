// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The .screerec recording (docs/recording.md, scree/io/recording.h): a round trip is bit-identical (body poses
// as the doubles the simulation held, particle data and heights as the float32 of each value), XOR deltas make an
// unchanged frame nearly free, the writer leaves no partial file, and every truncation and single-bit corruption
// of a small file is a FormatError (never a crash: this test runs under ASan in CI).
#include <doctest/doctest.h>

#include <bit>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>

#include <scree/io/recording.h>
#include <scree/scree.h>

using namespace scree;
using namespace scree::io;
namespace fs = std::filesystem;

namespace {

/// What the reader must give back for one frame, captured from the simulation when the frame was written.
struct Expected {
  double time = 0;
  std::vector<double> poses;
  std::vector<uint32_t> ids;
  std::vector<float> positions, speeds, radii;
  std::vector<std::vector<float>> heights;
};

struct World {
  Simulation sim;
  MaterialRef stone = std::make_shared<Material>("stone");
  MaterialRef grain = std::make_shared<Material>("grain");
  HeightFieldRef field = std::make_shared<HeightField>(9, 7, 0.8, 0.6);
  std::vector<RigidBodyRef> bodies;

  explicit World(size_t particles) {
    sim.setTimeStep(1.0 / 60);
    auto ground = std::make_shared<Geometry>(std::make_shared<Box>(Vec3(5, 5, 0.5)), "ground");
    ground->setMaterial(stone);
    ground->setPosition(Vec3(0, 0, -0.5));
    sim.add(ground);
    auto fieldGeom = std::make_shared<Geometry>(field, "field");
    fieldGeom->setPosition(Vec3(3, 0, 0.01));
    fieldGeom->setRotation(Quat(Eigen::AngleAxis<Real>(0.3, Vec3::UnitZ())));
    sim.add(fieldGeom);
    const std::vector<ShapeRef> shapes = {
        std::make_shared<Sphere>(0.2), std::make_shared<Box>(Vec3(0.2, 0.3, 0.1)),
        std::make_shared<Capsule>(0.1, 0.3), std::make_shared<Cylinder>(0.15, 0.2),
        std::make_shared<Convex>(std::vector<Vec3>{{-0.2, -0.2, -0.2}, {0.2, -0.2, -0.2}, {0, 0.2, -0.2},
                                                   {0, 0, 0.2}, {0.05, 0.05, -0.25}})};
    for (size_t i = 0; i < shapes.size(); ++i) {
      auto b = std::make_shared<RigidBody>("body " + std::to_string(i));
      auto g = std::make_shared<Geometry>(shapes[i]);
      g->setMaterial(stone);
      g->setLocalPosition(Vec3(0.01 * i, 0, 0));
      b->add(g);
      b->setPosition(Vec3(-2 + 0.8 * i, 0, 0.6 + 0.1 * i));
      b->setRotation(Quat(Eigen::AngleAxis<Real>(0.2 * i, Vec3(1, 2, 3).normalized())));
      sim.add(b);
      bodies.push_back(b);
    }
    GranularBodySystem& ps = sim.getGranularBodySystem();
    ps.setMaterial(grain);
    std::mt19937 rng(42);  // jittered lattice: float data that does not compress to nothing by regularity
    std::uniform_real_distribution<double> jitter(-0.004, 0.004);
    for (size_t i = 0; i < particles; ++i)
      ps.createParticle(Vec3(-1 + 0.07 * (i % 10) + jitter(rng), 1 + 0.07 * ((i / 10) % 10) + jitter(rng),
                             0.05 + 0.07 * (i / 100) + jitter(rng)),
                        0.03);
  }

  Expected capture() const {
    Expected e;
    e.time = sim.getTimeStamp();
    for (int k = 0; k < 7; ++k) e.poses.push_back(k == 6 ? 1.0 : 0.0);  // the static pseudo-body
    for (const RigidBodyRef& b : bodies) {
      const Transform t = b->getTransform();
      e.poses.insert(e.poses.end(), {t.p.x(), t.p.y(), t.p.z(), t.q.x(), t.q.y(), t.q.z(), t.q.w()});
    }
    const GranularBodySystem& ps = sim.getGranularBodySystem();
    for (size_t i = 0; i < ps.size(); ++i) {
      if (!ps.isAliveDense(i)) continue;
      e.ids.push_back(static_cast<uint32_t>(ps.idOfDense(i)));
      for (int k = 0; k < 3; ++k) e.positions.push_back(static_cast<float>(ps.positions()[i][k]));
      // The writer's speed rounding (recording.h): 12 significant bits, 0 below 1e-4 m/s.
      const double v = ps.velocities()[i].norm();
      e.speeds.push_back(v < 1e-4 ? 0.0f
                                  : std::bit_cast<float>(std::bit_cast<uint32_t>(static_cast<float>(v)) & ~0x7FFu));
      e.radii.push_back(static_cast<float>(ps.radii()[i]));
    }
    std::vector<float> h;
    for (Real v : field->getHeights()) h.push_back(static_cast<float>(v));
    e.heights.push_back(h);
    return e;
  }
};

template <class T>
bool bitsEqual(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

std::string tempPath(const std::string& name) {
  return (fs::temp_directory_path() / ("scree_test_recording_" + std::to_string(::getpid()) + "_" + name)).string();
}

std::vector<uint8_t> readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// Records `world` for `steps` steps (a frame every `every` steps), editing heights, destroying a particle and
/// changing a radius on the way so that key frames, delta frames with and without radii and height rectangles
/// all occur. Returns what each frame must read back as.
std::vector<Expected> record(World& w, const std::string& path, int steps, uint32_t every, bool contacts) {
  RecordingWriter writer;
  writer.open(path);
  writer.setRecordEvery(every);
  writer.setRecordContacts(contacts);
  writer.begin(w.sim, "round trip");
  std::vector<Expected> expected = {w.capture()};
  GranularBodySystem& ps = w.sim.getGranularBodySystem();
  for (int s = 1; s <= steps; ++s) {
    w.sim.stepForward();
    if (s == 3) w.field->setHeight(2, 3, 0.05);                    // one vertex
    if (s == 5) w.field->setHeights(0, 0, 8, 6, std::vector<Real>(63, -0.02));  // the whole field
    if (s == 4 && ps.numParticles() > 1) ps.destroyParticle(ps.getParticleIds()[1]);  // a key frame
    if (s == 6 && ps.numParticles() > 0) ps.setRadius(ps.getParticleIds()[0], 0.025);  // radii in a delta frame
    if (writer.writeFrame(w.sim)) expected.push_back(w.capture());
  }
  CHECK(fs::exists(path + ".part"));
  CHECK_FALSE(fs::exists(path));
  const uint64_t size = writer.close();
  CHECK(size == fs::file_size(path));
  CHECK_FALSE(fs::exists(path + ".part"));
  return expected;
}

void checkRoundTrip(const RecordingReader& r, const std::vector<Expected>& expected) {
  REQUIRE(r.getNumFrames() == expected.size());
  for (size_t k = 0; k < expected.size(); ++k) {
    CAPTURE(k);
    const RecordedFrame& f = r.getFrame(k);
    const Expected& e = expected[k];
    CHECK(f.index == k);
    CHECK(f.time == e.time);
    CHECK(bitsEqual(f.poses, e.poses));
    CHECK(bitsEqual(f.particleIds, e.ids));
    CHECK(bitsEqual(f.particlePositions, e.positions));
    CHECK(bitsEqual(f.particleSpeeds, e.speeds));
    CHECK(bitsEqual(f.particleRadii, e.radii));
    CHECK(bitsEqual(r.heightsAt(0, k), e.heights[0]));
  }
}

}  // namespace

TEST_SUITE("recording") {

TEST_CASE("round trip: poses are the simulation's doubles and particles and heights their float32, bit for bit") {
  World w(120);
  const std::string path = tempPath("roundtrip.screerec");
  const std::vector<Expected> expected = record(w, path, 12, 2, true);
  const RecordingReader r(path);
  CHECK(r.getMajorVersion() == kRecordingMajor);
  CHECK(r.getMinorVersion() == kRecordingMinor);
  const RecordedScene& s = r.getScene();
  CHECK(s.name == "round trip");
  CHECK(s.timeStep == 1.0 / 60);
  CHECK(s.frameInterval == 2.0 / 60);
  // The static pseudo-body (ground box and height field), then the five bodies in the simulation's order.
  REQUIRE(s.bodies.size() == 6);
  CHECK(s.bodies[0].name == "(static geometries)");
  CHECK(s.bodies[0].motion == 0);
  REQUIRE(s.bodies[0].geometries.size() == 2);
  CHECK(s.bodies[0].geometries[1].shape == RecordedShapeType::HeightField);
  CHECK(s.bodies[0].geometries[1].heightField == 0);
  CHECK(s.bodies[1].name == "body 0");
  CHECK(s.bodies[1].motion == 2);
  CHECK(s.bodies[1].geometries[0].shape == RecordedShapeType::Sphere);
  CHECK(s.bodies[1].geometries[0].params == std::vector<double>{0.2});
  CHECK(s.bodies[2].geometries[0].params == std::vector<double>{0.2, 0.3, 0.1});
  CHECK(s.bodies[2].geometries[0].position[0] == 0.01);
  CHECK(s.bodies[5].geometries[0].shape == RecordedShapeType::Convex);
  CHECK(s.bodies[5].geometries[0].convexVertices.size() == 15);  // 5 hull points
  CHECK(s.bodies[5].geometries[0].convexTriangles.size() == 18);  // 6 triangles of a 5-vertex hull
  REQUIRE(s.materials.size() == 1);
  CHECK(s.materials[0].name == "stone");
  // The particle system's material table (its default material first) and the current material, grain.
  REQUIRE(s.particleMaterials.size() == 2);
  CHECK(s.particleMaterials[1].name == "grain");
  // The height field's frame: vertex (0, 0) is the geometry's origin moved by half the field's size.
  REQUIRE(s.heightFields.size() == 1);
  const RecordedHeightField& hf = s.heightFields[0];
  CHECK(hf.nx == 9);
  CHECK(hf.ny == 7);
  CHECK(hf.elementSize == doctest::Approx(0.1).epsilon(1e-12));
  const Vec3 corner = Vec3(3, 0, 0.01) + Quat(Eigen::AngleAxis<Real>(0.3, Vec3::UnitZ())) * Vec3(-0.4, -0.3, 0);
  for (int k = 0; k < 3; ++k) CHECK(hf.position[k] == doctest::Approx(corner[k]).epsilon(1e-14));
  checkRoundTrip(r, expected);
  // Frame 2 (after step 4) follows a destroy: a key frame; frame 3 (step 6) a radius change: delta with radii;
  // frame 1 (step 2) nothing but motion: delta without radii.
  CHECK(r.getFrame(1).delta);
  CHECK_FALSE(r.getFrame(1).radiiStored);
  CHECK_FALSE(r.getFrame(2).delta);
  CHECK(r.getFrame(3).delta);
  CHECK(r.getFrame(3).radiiStored);
  CHECK(r.getFrame(3).particleRadii[0] == 0.025f);
  CHECK(r.getFrame(3).particleMaterials[0] == 1);
  // Height rectangles: the one-vertex edit of step 3 is one 1 x 1 rectangle in frame 2; nothing in frame 1.
  CHECK(r.getFrame(1).heightRects[0].empty());
  REQUIRE(r.getFrame(2).heightRects[0].size() == 1);
  CHECK(r.getFrame(2).heightRects[0][0].w == 1);
  CHECK(r.getFrame(2).heightRects[0][0].h == 1);
  // Contacts were recorded (the bodies and particles rest on the ground after a few steps).
  CHECK(r.getFrame(6).contacts.size() > 0);
  CHECK(r.getFrame(6).contacts.size() % 7 == 0);
  fs::remove(path);
}

TEST_CASE("XOR delta: a frame identical to the previous one costs a small fraction of a key frame") {
  // 400 particles: 20 bytes each of id, position and speed. An unchanged frame XORs to zeros, which deflate
  // shrinks to a few bytes per kilobyte; the key frame's jittered positions keep most of their 12 bytes.
  World w(400);
  const std::string path = tempPath("delta.screerec");
  RecordingWriter writer;
  writer.open(path);
  writer.begin(w.sim, "delta");
  w.sim.stepForward();
  writer.writeFrame(w.sim);
  writer.writeFrame(w.sim);  // the same state again
  writer.close();
  const RecordingReader r(path);
  REQUIRE(r.getNumFrames() == 3);
  CHECK(r.getFrame(2).delta);
  CHECK_FALSE(r.getFrame(0).delta);
  CHECK(r.getFrame(0).storedBytes > 400 * 8);    // the key frame: most of the 400 x 20 raw bytes remain
  CHECK(r.getFrame(2).storedBytes < 400 * 20 / 20);  // unchanged: under a twentieth of the raw particle data
  CHECK(bitsEqual(r.getFrame(2).particlePositions, r.getFrame(1).particlePositions));
  fs::remove(path);
}

TEST_CASE("writer: no partial file without close(), bad input throws and changes nothing") {
  const std::string path = tempPath("abandoned.screerec");
  {
    World w(10);
    RecordingWriter writer;
    writer.open(path);
    writer.begin(w.sim, "abandoned");
    CHECK(fs::exists(path + ".part"));
  }  // destroyed before close()
  CHECK_FALSE(fs::exists(path + ".part"));
  CHECK_FALSE(fs::exists(path));
  RecordingWriter writer;
  CHECK_THROWS_AS(writer.open(fs::temp_directory_path().string()), std::invalid_argument);  // a directory
  CHECK_THROWS_AS(writer.open("/nonexistent-dir-scree/x.screerec"), std::invalid_argument);
  CHECK_THROWS_AS(writer.open(""), std::invalid_argument);
  CHECK_FALSE(writer.isOpen());
  CHECK_THROWS_AS(writer.setRecordEvery(0), std::invalid_argument);
  CHECK(writer.getRecordEvery() == 1);
  CHECK_THROWS_AS(writer.setCompressionLevel(0), std::invalid_argument);
  CHECK_THROWS_AS(RecordingReader("/nonexistent-dir-scree/x.screerec"), std::runtime_error);
}

TEST_CASE("reader: versions, unknown chunks, truncation and corruption") {
  World w(6);
  const std::string path = tempPath("fuzz.screerec");
  const std::vector<Expected> expected = record(w, path, 6, 2, true);
  const std::vector<uint8_t> good = readAll(path);
  fs::remove(path);
  REQUIRE(good.size() < 8000);  // small enough for the quadratic truncation sweep below
  checkRoundTrip(RecordingReader(good, "good"), expected);

  SUBCASE("a newer major version is refused with the format's message; a newer minor version is read") {
    std::vector<uint8_t> b = good;
    b[8] = 2;  // u16 major at byte 8
    try {
      RecordingReader(b, "future.screerec");
      FAIL("no error");
    } catch (const FormatError& e) {
      CHECK(std::string(e.what()) == "future.screerec was written in recording format 2.0; this reader reads 1.x");
    }
    b = good;
    b[10] = 7;  // u16 minor at byte 10
    const RecordingReader r(b, "minor");
    CHECK(r.getMinorVersion() == 7);
    checkRoundTrip(r, expected);
  }

  SUBCASE("an unknown chunk with a valid CRC is skipped") {
    std::vector<uint8_t> chunk = {'X', 'T', 'R', 'A', 3, 0, 0, 0, 1, 2, 3};
    const uint32_t crc = crc32(chunk.data() + 8, 3);
    chunk.insert(chunk.end(), reinterpret_cast<const uint8_t*>(&crc), reinterpret_cast<const uint8_t*>(&crc) + 4);
    std::vector<uint8_t> b = good;
    b.insert(b.end() - 16, chunk.begin(), chunk.end());  // before ENDR (12 + 4 bytes)
    checkRoundTrip(RecordingReader(b, "extra"), expected);
  }

  SUBCASE("every truncation is a FormatError") {
    int errors = 0;
    for (size_t len = 0; len < good.size(); ++len) {
      try {
        RecordingReader(std::vector<uint8_t>(good.begin(), good.begin() + len), "truncated");
      } catch (const FormatError&) {
        ++errors;
      }
    }
    CHECK(errors == int(good.size()));
  }

  SUBCASE("every single flipped bit outside the version and flags fields is a FormatError") {
    // Bytes 10..15 (minor version, flags) may hold anything a newer minor version writes: a flip there is read.
    // Everywhere else: the magic, the major version, or a chunk whose CRC-32 detects any single-bit error.
    std::mt19937 rng(12345);
    int errors = 0, tried = 0;
    for (size_t pos = 0; pos < good.size(); ++pos) {
      const int bits = pos < 16 ? 8 : 1;  // every bit of the header, one random bit elsewhere
      for (int k = 0; k < bits; ++k) {
        std::vector<uint8_t> b = good;
        b[pos] ^= uint8_t(1u << (bits == 8 ? k : int(rng() % 8)));
        const bool mayRead = pos >= 10 && pos < 16;
        try {
          const RecordingReader r(b, "flipped");
          CHECK_MESSAGE(mayRead, "flip at byte ", pos, " was not detected");
        } catch (const FormatError&) {
          CHECK_MESSAGE(!mayRead, "flip at byte ", pos, " was refused");
          ++errors;
        }
        ++tried;
      }
    }
    CHECK(errors == tried - 6 * 8);
  }

  SUBCASE("random byte corruption is a FormatError") {
    std::mt19937 rng(777);
    for (int n = 0; n < 3000; ++n) {
      std::vector<uint8_t> b = good;
      const size_t pos = 16 + rng() % (good.size() - 16);
      b[pos] = static_cast<uint8_t>(b[pos] ^ (1 + rng() % 255));
      CHECK_THROWS_AS(RecordingReader(b, "corrupted"), FormatError);
    }
  }
}

}  // TEST_SUITE

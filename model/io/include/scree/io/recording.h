// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Recording of a run to a `.screerec` file and reading it back (the format: docs/recording.md).
//
// RecordingWriter. open(path) creates `path + ".part"`; begin(sim) writes the scene (SCNE), one HFLD per
// height-field geometry (terrains included) and frame 0; writeFrame(sim), called after every step, writes a
// frame every k-th call (setRecordEvery(k)); close() writes ENDR and renames the ".part" file to `path`. A
// writer destroyed or abort()ed before close() removes its ".part" file: a run that fails leaves no partial
// recording. Why these choices (deflate, float32 particles with XOR deltas, changed height rectangles): the
// design section of docs/recording.md. What is captured:
//   - bodies: every body of the simulation at begin(), in its order, preceded by one static pseudo-body named
//     "(static geometries)" at the world origin holding the geometries added without a body (when there are
//     any). Bodies added later are not recorded (logged once); a body removed later keeps its last pose.
//   - materials: those of the recorded geometries, with a colour derived from the material's name (a hash into
//     a fixed palette, so the same name gets the same colour in every file);
//   - particle materials: the particle system's material table and current material at begin(); a particle
//     whose material was first used later is written with index 0xFFFF (unknown).
//   - height fields: the heights of every HEIGHT_FIELD geometry, first in full, then per frame the rectangles
//     that changed (one rectangle per 32 x 32-vertex block with a change: a rut or a trench touches a few
//     blocks, not the grid);
//   - particle speeds: |v| rounded to 12 significant bits and 0 below 1e-4 m/s (a resting particle's speed is
//     solver noise that changes every bit every step: written in full it would dominate a settled pile's file);
//   - contacts (setRecordContacts(true)): the geometry contact points and the particle contact points of the
//     last step with their normal forces.
//
// RecordingReader. Reads the whole file into memory, checks the header, every chunk's length and CRC-32, and
// decodes every frame at once (eager: all errors surface in the constructor, and a frame is random access
// afterwards). Frames hold the resolved state (XOR deltas undone; radii and material indices carried forward);
// height fields hold the initial heights, and heightsAt() applies the frames' rectangles. Everything that is
// not what the format says throws FormatError naming the chunk and the byte offset: truncation, a CRC
// mismatch, a broken zlib stream, counts that do not fit the payload, indices out of range, a newer major
// version ("FILE was written in recording format M.m; this reader reads 1.x").
#pragma once

#include <array>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "scree/io/bytes.h"

namespace scree {
class Simulation;
class Terrain;
class Geometry;
class RigidBody;
}  // namespace scree

namespace scree::io {

/// The format version this code writes, and the major version it reads.
inline constexpr uint16_t kRecordingMajor = 1;
inline constexpr uint16_t kRecordingMinor = 0;
/// Geometry without a material.
inline constexpr uint32_t kNoMaterial = 0xFFFFFFFFu;
/// Particle whose material is not in the scene's particle material list.
inline constexpr uint16_t kUnknownParticleMaterial = 0xFFFF;

/// Shape type codes of the SCNE chunk (equal to scree::Shape::Type).
enum class RecordedShapeType : uint8_t {
  Sphere = 0, Box = 1, Capsule = 2, Cylinder = 3, Plane = 4, Convex = 5, HeightField = 6, Line = 7
};

struct RecordedMaterial {
  std::string name;
  std::array<uint8_t, 3> colour{};  ///< sRGB
};

struct RecordedGeometry {
  uint32_t material = kNoMaterial;             ///< index into RecordedScene::materials
  std::array<double, 3> position{};            ///< in its body
  std::array<double, 4> rotation{0, 0, 0, 1};  ///< x, y, z, w
  RecordedShapeType shape = RecordedShapeType::Sphere;
  /// sphere {r}; box {hx, hy, hz}; capsule, cylinder {r, height} (axis = local y); plane {nx, ny, nz, offset};
  /// line {ax, ay, az, bx, by, bz}; empty for convex and height field.
  std::vector<double> params;
  std::vector<float> convexVertices;      ///< 3 per vertex
  std::vector<uint32_t> convexTriangles;  ///< 3 per triangle (faces fanned)
  uint32_t heightField = 0;               ///< index into RecordedScene::heightFields (height field only)
};

struct RecordedBody {
  std::string name;
  uint8_t motion = 2;  ///< 0 static, 1 kinematic, 2 dynamic
  std::vector<RecordedGeometry> geometries;
};

struct RecordedHeightField {
  uint32_t nx = 0, ny = 0;
  double elementSize = 0;                      ///< m
  std::array<double, 3> position{};            ///< vertex (0, 0), world
  std::array<double, 4> rotation{0, 0, 0, 1};  ///< x, y, z, w of the grid's frame
  std::vector<float> heights;                  ///< nx * ny at frame 0's start, x fastest
};

struct RecordedScene {
  std::string name;
  double timeStep = 0;       ///< s
  double frameInterval = 0;  ///< s
  std::array<double, 3> gravity{};
  std::vector<RecordedMaterial> materials;
  std::vector<RecordedBody> bodies;
  std::vector<RecordedMaterial> particleMaterials;
  std::vector<RecordedHeightField> heightFields;  ///< the HFLD chunks, in order
};

struct RecordedHeightRect {
  uint32_t i0 = 0, j0 = 0, w = 0, h = 0;
  std::vector<float> heights;  ///< w * h, x fastest
};

/// One frame, resolved (no deltas).
struct RecordedFrame {
  uint32_t index = 0;
  double time = 0;                        ///< s
  std::vector<double> poses;              ///< 7 per body: x, y, z, qx, qy, qz, qw
  std::vector<uint32_t> particleIds;
  std::vector<float> particlePositions;   ///< 3 per particle
  std::vector<float> particleSpeeds;      ///< m/s (12 significant bits, 0 below 1e-4 m/s: see the writer)
  std::vector<float> particleRadii;       ///< m
  std::vector<uint16_t> particleMaterials;
  std::vector<std::vector<RecordedHeightRect>> heightRects;  ///< per height field: the rectangles that changed
  std::vector<float> contacts;            ///< 7 per contact: point, normal, normal force (N)
  bool delta = false;                     ///< stored as an XOR delta of the previous frame
  bool radiiStored = false;               ///< radii and materials were stored in this frame
  size_t storedBytes = 0;                 ///< size of the FRAM chunk in the file
};

class RecordingWriter {
 public:
  RecordingWriter();
  /// Removes the ".part" file when close() was not reached.
  ~RecordingWriter();
  RecordingWriter(const RecordingWriter&) = delete;
  RecordingWriter& operator=(const RecordingWriter&) = delete;

  /// Creates `path + ".part"` for writing. Throws std::invalid_argument naming the path when it is empty or a
  /// directory, or when the ".part" file cannot be created (missing directory, no permission).
  void open(const std::string& path);
  /// Writes a frame every k-th writeFrame() call (k >= 1; default 1). Before begin().
  void setRecordEvery(uint32_t k);
  uint32_t getRecordEvery() const { return every_; }
  /// Also record contact points and normal forces (default off). Before begin().
  void setRecordContacts(bool on);
  /// zlib level 1 ... 9 of the frames (default 6). Before begin().
  void setCompressionLevel(int level);
  /// Writes the scene, its height fields and frame 0 (the state now). `terrains`: terrains whose height field
  /// geometry is not (yet) in the simulation; those that are are found through the simulation's geometries.
  void begin(const Simulation& sim, const std::string& sceneName,
             const std::vector<const Terrain*>& terrains = {});
  /// Call after every step: writes a frame on every k-th call. Returns true when it wrote one.
  bool writeFrame(const Simulation& sim);
  /// Writes ENDR, closes and renames to the final path. Returns the file size in bytes.
  uint64_t close();
  /// Stops without a file: removes the ".part" file.
  void abort();

  bool isOpen() const { return file_ != nullptr; }
  uint32_t getNumFrames() const { return frames_; }
  /// Bytes written so far.
  uint64_t getBytesWritten() const { return bytes_; }
  const std::string& getPath() const { return path_; }

 private:
  struct State;
  void writeChunk(const char tag[4], const std::vector<uint8_t>& payload);
  void recordFrame(const Simulation& sim);
  std::string path_, partPath_;
  std::FILE* file_ = nullptr;
  uint32_t every_ = 1;
  bool contacts_ = false;
  int level_ = 6;
  uint32_t frames_ = 0;
  uint64_t calls_ = 0;
  uint64_t bytes_ = 0;
  std::unique_ptr<State> st_;
};

class RecordingReader {
 public:
  /// Reads and decodes the file. Throws FormatError (see the file comment), or std::runtime_error when the file
  /// cannot be opened.
  explicit RecordingReader(const std::string& path);
  /// Decodes a file held in memory (`name` stands for the file in messages).
  RecordingReader(std::vector<uint8_t> bytes, const std::string& name);

  uint16_t getMajorVersion() const { return major_; }
  uint16_t getMinorVersion() const { return minor_; }
  const RecordedScene& getScene() const { return scene_; }
  size_t getNumFrames() const { return frames_.size(); }
  const RecordedFrame& getFrame(size_t k) const { return frames_.at(k); }
  const std::vector<RecordedFrame>& getFrames() const { return frames_; }
  /// Heights of height field `field` after frame `frame`'s rectangles were applied (nx * ny, x fastest).
  std::vector<float> heightsAt(size_t field, size_t frame) const;

 private:
  void parse(const std::string& name);
  std::vector<uint8_t> bytes_;
  uint16_t major_ = 0, minor_ = 0;
  RecordedScene scene_;
  std::vector<RecordedFrame> frames_;
};

}  // namespace scree::io

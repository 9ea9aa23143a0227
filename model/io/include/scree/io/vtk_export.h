// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// ParaView export (issue 19): a time series of VTK XML files and one .pvd collection that lists them.
//
// Files. VtkExporter(dir, base) writes, per writeFrame() call number f (6 digits, from 0):
//   <base>_bodies_<f>.vtp     PolyData: every geometry's surface in world coordinates, triangulated (lines for
//                             Line shapes). Cell data body_id (Int64: RigidBody::getId(), -1 for a geometry
//                             without a body) and geometry_id (UInt32: Geometry::getId()); point data velocity
//                             (Float64 x 3: the body's velocity at the point, 0 for static geometries).
//   <base>_particles_<f>.vtp  PolyData: one point and one vertex cell per live particle (dense order). Point
//                             data radius, mass (Float64), velocity, angular_velocity (Float64 x 3), id
//                             (UInt64: GranularBodySystem ids) and every custom real buffer under its own name
//                             (Float64).
//   <base>_terrain<k>_<f>.vts StructuredGrid per added terrain k: the height-field vertices in world
//                             coordinates (x fastest, as HeightField::getHeights()). Point data height (Float64,
//                             the field's own z), compression, youngs_modulus_multiplier, pending_volume
//                             (Float64) and material_index (UInt8) from the TerrainDataInterface.
//   <base>_fields<k>_<f>.vti  ImageData per added granular field post-processor k: Origin = the world position
//                             of the cuboid's corner (-volume/2 in its frame), Spacing = the voxel size,
//                             Direction = its rotation (row-major); every field as cell data under
//                             GranularField::getName() with its components (Float64; the voxel order of
//                             getFieldData() is VTK's cell order, x fastest). The values are those of the last
//                             calculateFields(): the exporter does not calculate.
//   <base>.pvd                Collection (written by close()): one DataSet per file with timestep = the time
//                             given to writeFrame and part = 0 bodies, 1 particles, 2.. terrains and fields
//                             in the order added (ParaView shows each part as a block of one multiblock
//                             time series).
// Every data file is `<VTKFile type=... version="1.0" byte_order="LittleEndian" header_type="UInt64">` with all
// arrays in one `<AppendedData encoding="raw">` section: `_`, then per array its byte count (UInt64) and the
// little-endian values, arrays in the order of their offsets. Binary raw is the compact and fast choice
// (no base64, no compression: writing is a memcpy per array).
//
// Precision (why). Point coordinates are Float32: they are rendering geometry (tessellated surfaces, markers),
// and Float32 keeps 1e-7 relative - 0.1 mm at 1 km from the origin - at half the bytes. Every physical value
// (heights, velocities, masses, radii, fields) is Float64, the simulation's own value bit for bit, so analysis in
// ParaView (or any reader) sees exactly what the simulation had; ids are 64-bit integers as in the simulation.
//
// Tessellation (shape frame, then placed by the geometry's world transform): sphere, capsule and cylinder as
// solids of revolution about their axis (Scree's local y for capsule and cylinder) with
// setTessellation(segments) segments around and max(1, segments/4) bands along each half-sphere; box 12 triangles; convex hull
// its faces fanned into triangles; plane a square of half side setPlaneHalfSize() centred on the point of the
// plane nearest the frame origin; height field two triangles per cell along the (i, j)-(i+1, j+1) diagonal, as
// it collides; line a line cell. A terrain's own geometry is left out of the bodies file (it is the .vts).
//
// Files are written under a temporary name (<name>.tmp) and renamed when complete: a failed or interrupted
// write never leaves a partial file under the final name (std::runtime_error naming the file; the exporter is
// unchanged and may be written to again). The terrain and post-processor are kept by reference: they must live
// until the last writeFrame.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "scree/core/math.h"

namespace scree {
class Simulation;
class Terrain;
class GranularFieldPostProcessor;
}  // namespace scree

namespace scree::io {

class VtkExporter {
 public:
  /// Creates `directory` (and its parents) if needed and checks that a file can be created in it: otherwise
  /// std::invalid_argument naming the directory. baseName: non-empty, no '/' (std::invalid_argument).
  explicit VtkExporter(const std::string& directory, const std::string& baseName = "scene");
  /// close() if not closed (errors are logged, not thrown).
  ~VtkExporter();
  VtkExporter(const VtkExporter&) = delete;
  VtkExporter& operator=(const VtkExporter&) = delete;

  /// Exports this terrain's height field (a .vts per frame). Adding the same terrain twice does nothing.
  void addTerrain(const Terrain& terrain);
  /// Exports this post-processor's fields (a .vti per frame). Adding the same one twice does nothing.
  void addGranularFields(const GranularFieldPostProcessor& fields);

  /// Segments around a sphere, capsule or cylinder (even, >= 4; default 24); otherwise std::invalid_argument.
  void setTessellation(int segments);
  int getTessellation() const { return segments_; }
  /// Half side of the square drawn for a Plane shape, m (finite, > 0; default 50).
  void setPlaneHalfSize(Real halfSize);
  Real getPlaneHalfSize() const { return planeHalfSize_; }

  /// Writes frame getNumFrames(): bodies, particles, terrains and fields at `time` (s, finite; the .pvd
  /// timestep). After close() throws std::logic_error. A file that cannot be written throws std::runtime_error;
  /// the frame is then not counted.
  void writeFrame(const Simulation& sim, double time);
  /// Writes <baseName>.pvd listing every frame written. Idempotent.
  void close();
  bool isClosed() const { return closed_; }

  size_t getNumFrames() const { return frames_.size(); }
  const std::string& getDirectory() const { return directory_; }
  /// Path of the .pvd (written by close()).
  std::string getCollectionPath() const;
  /// File names (relative to the directory) of frame f, in part order; bytes written for the last frame.
  const std::vector<std::string>& getFrameFiles(size_t frame) const { return frames_.at(frame).files; }
  size_t getLastFrameBytes() const { return lastFrameBytes_; }

 private:
  struct Frame {
    double time;
    std::vector<std::string> files;
    std::vector<int> parts;  ///< the .pvd part of each file
  };
  /// A terrain or a post-processor, in the order added (part 2 + position); index: k of terrain<k>/fields<k>.
  struct Part {
    const Terrain* terrain;
    const GranularFieldPostProcessor* fields;
    size_t index;
  };
  std::vector<Part> parts_;
  std::string directory_, baseName_;
  std::vector<const Terrain*> terrains_;
  std::vector<const GranularFieldPostProcessor*> fields_;
  std::vector<Frame> frames_;
  int segments_ = 24;
  Real planeHalfSize_ = 50;
  bool closed_ = false;
  size_t lastFrameBytes_ = 0;
};

}  // namespace scree::io

// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// Collision shapes (AGX: agxCollide::Sphere, Box, Capsule, Cylinder, Plane, Convex, HeightField, Line).
// Every shape is expressed in its own frame; a Geometry places it. Capsule and Cylinder have their axis along
// local y (AGX convention) and `height` is the length of the axis part (the cylinder's full height; the
// capsule's segment between the two hemisphere centres).
//
// Constructors and setters validate (finite, positive sizes) and throw std::invalid_argument naming the
// parameter and value; a rejected setter leaves the shape unchanged.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "scree/core/body_part.h"  // MassProperties
#include "scree/core/math.h"

namespace scree {

class Shape {
 public:
  enum Type { SPHERE = 0, BOX, CAPSULE, CYLINDER, PLANE, CONVEX, HEIGHT_FIELD, LINE, NUM_TYPES };

  explicit Shape(Type t) : type_(t) {}
  virtual ~Shape() = default;
  Type getType() const { return type_; }

  /// m^3; 0 for shapes without volume (PLANE, LINE, HEIGHT_FIELD).
  virtual Real getVolume() const = 0;
  /// Mass properties at uniform density (kg/m^3). Zero mass for shapes without volume.
  virtual MassProperties computeMassProperties(Real density) const;
  /// World-space AABB of the shape placed by `t` (shape frame -> world). Infinite for a plane.
  virtual Aabb getBoundingBox(const Transform& t) const = 0;
  /// True for shapes that GJK/MPR can handle through support().
  virtual bool isConvex() const { return false; }
  /// Farthest point of the shape in direction `dir` (shape frame; dir need not be unit).
  virtual Vec3 support(const Vec3& dir) const;
  /// Counts modifications (resize, height edits) so caches can notice.
  uint64_t getModificationCount() const { return modCount_; }

 protected:
  void touch() { ++modCount_; }

 private:
  Type type_;
  uint64_t modCount_ = 0;
};
using ShapeRef = std::shared_ptr<Shape>;

class Sphere : public Shape {
 public:
  explicit Sphere(Real radius);
  void setRadius(Real r);
  Real getRadius() const { return r_; }
  Real getVolume() const override;
  MassProperties computeMassProperties(Real density) const override;
  Aabb getBoundingBox(const Transform& t) const override;
  bool isConvex() const override { return true; }
  Vec3 support(const Vec3& dir) const override;

 private:
  Real r_;
};

class Box : public Shape {
 public:
  explicit Box(const Vec3& halfExtents);
  void setHalfExtents(const Vec3& he);
  const Vec3& getHalfExtents() const { return he_; }
  Real getVolume() const override;
  MassProperties computeMassProperties(Real density) const override;
  Aabb getBoundingBox(const Transform& t) const override;
  bool isConvex() const override { return true; }
  Vec3 support(const Vec3& dir) const override;

 private:
  Vec3 he_;
};

class Capsule : public Shape {
 public:
  Capsule(Real radius, Real height);
  void setRadius(Real r);
  void setHeight(Real h);
  Real getRadius() const { return r_; }
  Real getHeight() const { return h_; }
  Real getVolume() const override;
  MassProperties computeMassProperties(Real density) const override;
  Aabb getBoundingBox(const Transform& t) const override;
  bool isConvex() const override { return true; }
  Vec3 support(const Vec3& dir) const override;

 private:
  Real r_, h_;
};

class Cylinder : public Shape {
 public:
  Cylinder(Real radius, Real height);
  void setRadius(Real r);
  void setHeight(Real h);
  Real getRadius() const { return r_; }
  Real getHeight() const { return h_; }
  Real getVolume() const override;
  MassProperties computeMassProperties(Real density) const override;
  Aabb getBoundingBox(const Transform& t) const override;
  bool isConvex() const override { return true; }
  Vec3 support(const Vec3& dir) const override;

 private:
  Real r_, h_;
};

/// The half space below the plane {x : normal . x = distance} is solid. The normal is normalised on input.
class Plane : public Shape {
 public:
  Plane(const Vec3& normal, Real distance);
  const Vec3& getNormal() const { return n_; }
  Real getDistance() const { return d_; }
  Real getVolume() const override { return 0; }
  Aabb getBoundingBox(const Transform& t) const override;

 private:
  Vec3 n_;
  Real d_;
};

/// Convex hull of a point cloud (quickhull). Needs >= 4 non-coplanar points.
class Convex : public Shape {
 public:
  struct Face {
    std::vector<uint32_t> vertices;  ///< indices into getVertices(), counter-clockwise seen from outside
    Vec3 normal;                     ///< outward unit normal
    Real offset;                     ///< normal . x = offset on the face
  };
  explicit Convex(const std::vector<Vec3>& points);
  const std::vector<Vec3>& getVertices() const { return verts_; }
  const std::vector<Face>& getFaces() const { return faces_; }
  Real getVolume() const override;
  /// Exact polyhedral integration (Mirtich 1996 / Eberly): volume, centroid and inertia of the hull.
  MassProperties computeMassProperties(Real density) const override;
  Aabb getBoundingBox(const Transform& t) const override;
  bool isConvex() const override { return true; }
  Vec3 support(const Vec3& dir) const override;

 private:
  std::vector<Vec3> verts_;
  std::vector<Face> faces_;
  Real volume_ = 0;
};

/// A regular grid of heights over the x-y plane of the shape frame, centred on the origin:
/// vertex (i, j) sits at x = -sizeX/2 + i*sizeX/(resolutionX-1), y likewise, z = height. Each cell is split
/// into two triangles along the diagonal from (i, j) to (i+1, j+1). Solid below the surface.
/// Unequal x and y spacing is accepted with a logged warning (as in AGX).
class HeightField : public Shape {
 public:
  HeightField(size_t resolutionX, size_t resolutionY, Real sizeX, Real sizeY);
  size_t getResolutionX() const { return nx_; }
  size_t getResolutionY() const { return ny_; }
  Real getSizeX() const { return sx_; }
  Real getSizeY() const { return sy_; }
  Real getCellSizeX() const { return sx_ / Real(nx_ - 1); }
  Real getCellSizeY() const { return sy_ / Real(ny_ - 1); }
  void setHeight(size_t i, size_t j, Real h);
  Real getHeight(size_t i, size_t j) const { return h_[j * nx_ + i]; }
  /// Row-major with i fastest: heights[j * resolutionX + i]. Size must be resolutionX * resolutionY.
  void setHeights(const std::vector<Real>& heights);
  /// The rectangle of vertices i0 <= i <= i1, j0 <= j <= j1 (inclusive), row-major with i fastest:
  /// values[(j - j0) * (i1 - i0 + 1) + (i - i0)]. Bounds are updated from the touched tiles only (see
  /// kTileSize), so a local edit costs the rectangle, not the grid. Everything is checked before anything
  /// changes: indices in range with i0 <= i1, j0 <= j1, the size, every value finite.
  void setHeights(size_t i0, size_t j0, size_t i1, size_t j1, const std::vector<Real>& values);
  /// Batched edits: between beginHeightEdit() and endHeightEdit() (nestable) setHeight/setHeights only write
  /// heights and grow the dirty rectangle; endHeightEdit() updates the bounds of the touched tiles once.
  void beginHeightEdit() { ++editDepth_; }
  void endHeightEdit();
  /// Vertices changed since the counter was last cleared (inclusive rectangle; empty when i0 > i1). The
  /// terrain reads it to know what a step touched; clearDirtyRectangle() resets it.
  struct Rect {
    size_t i0 = 1, j0 = 1, i1 = 0, j1 = 0;
    bool empty() const { return i0 > i1 || j0 > j1; }
  };
  const Rect& getDirtyRectangle() const { return dirty_; }
  void clearDirtyRectangle() { dirty_ = Rect{}; }
  /// Vertices per tile side of the bounds hierarchy: tile (ti, tj) covers vertices [ti*16, ti*16 + 16] in i
  /// (it shares its last vertex column with the next tile, so every cell lies inside one tile), same in j.
  static constexpr size_t kTileSize = 16;
  size_t getNumTilesX() const { return tilesX_; }
  size_t getNumTilesY() const { return tilesY_; }
  /// Lowest/highest height of the vertices of tile (ti, tj).
  Real getTileMinHeight(size_t ti, size_t tj) const { return tileMin_[tj * tilesX_ + ti]; }
  Real getTileMaxHeight(size_t ti, size_t tj) const { return tileMax_[tj * tilesX_ + ti]; }
  const std::vector<Real>& getHeights() const { return h_; }
  /// Vertex (i, j) in the shape frame.
  Vec3 getVertex(size_t i, size_t j) const;
  /// Interpolated surface height at shape-frame (x, y) on the triangulation; NaN outside.
  Real getHeightAt(Real x, Real y) const;
  Real getMinHeight() const { return minH_; }
  Real getMaxHeight() const { return maxH_; }
  Real getVolume() const override { return 0; }
  Aabb getBoundingBox(const Transform& t) const override;

 private:
  void updateBounds();
  /// Recomputes the tiles that hold vertices of the rectangle, then the global bounds from the tiles.
  void updateBounds(const Rect& r);
  void markDirty(size_t i0, size_t j0, size_t i1, size_t j1);
  size_t nx_, ny_;
  Real sx_, sy_;
  std::vector<Real> h_;
  Real minH_ = 0, maxH_ = 0;
  size_t tilesX_ = 1, tilesY_ = 1;
  std::vector<Real> tileMin_, tileMax_;
  int editDepth_ = 0;
  Rect pending_;  ///< rectangle edited inside the current batch, bounds not yet updated
  Rect dirty_;
};

/// A line segment (sensor rays, suction-cup line sensors). Collides with every shape but Line and Plane's
/// back side; zero volume.
class Line : public Shape {
 public:
  Line(const Vec3& p1, const Vec3& p2);
  const Vec3& getFirstPoint() const { return p1_; }
  const Vec3& getSecondPoint() const { return p2_; }
  void set(const Vec3& p1, const Vec3& p2);
  Real getVolume() const override { return 0; }
  Aabb getBoundingBox(const Transform& t) const override;
  bool isConvex() const override { return true; }
  Vec3 support(const Vec3& dir) const override;

 private:
  Vec3 p1_, p2_;
};

using SphereRef = std::shared_ptr<Sphere>;
using BoxRef = std::shared_ptr<Box>;
using CapsuleRef = std::shared_ptr<Capsule>;
using CylinderRef = std::shared_ptr<Cylinder>;
using PlaneRef = std::shared_ptr<Plane>;
using ConvexRef = std::shared_ptr<Convex>;
using HeightFieldRef = std::shared_ptr<HeightField>;
using LineRef = std::shared_ptr<Line>;

}  // namespace scree

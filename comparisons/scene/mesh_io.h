// Meshes from outside: convex hulls of point sets (Qhull) and OBJ files (tinyobjloader).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "engine/polyhedron.h"

namespace rbx {

/// An OBJ file that cannot be read as OBJ text at all (unreadable, not a regular file, binary,
/// no vertices, a malformed 'v' line): taking the hull (hull = true) would not help, so the error
/// carries its own suggestion of what would.
class ObjReadError : public GeometryError {
 public:
  /// `message` says what is wrong (with the path); `fix` what would fix it.
  ObjReadError(const std::string& message, std::string fix)
      : GeometryError(message), fix_(std::move(fix)) {}
  /// What would fix it, e.g. "make the file readable (check its permissions)".
  const std::string& fix() const { return fix_; }

 private:
  std::string fix_;
};

/// The convex hull of `points` as a validated polyhedron (Qhull, triangulated output, outward
/// counter-clockwise triangles). Throws GeometryError for fewer than 4 points or a flat set.
ConvexPolyhedron convex_hull(const std::vector<Vec3>& points);

/// Loads an OBJ file. With `hull` false the mesh must already be closed and convex (validated,
/// errors name the face or vertex); with `hull` true its convex hull is used. Polygons are
/// fan-triangulated. Every 'v' line must hold exactly three finite numbers x y z (and at most a
/// finite w). Throws ObjReadError (with the path) for files that cannot be read as OBJ text,
/// GeometryError (with the path) for meshes that are not valid.
ConvexPolyhedron load_obj(const std::string& path, bool hull);

}  // namespace rbx

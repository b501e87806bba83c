// Meshes from outside: convex hulls of point sets (Qhull) and OBJ files (tinyobjloader).
#pragma once

#include <string>
#include <vector>

#include "engine/polyhedron.h"

namespace rbx {

/// The convex hull of `points` as a validated polyhedron (Qhull, triangulated output, outward
/// counter-clockwise triangles). Throws GeometryError for fewer than 4 points or a flat set.
ConvexPolyhedron convex_hull(const std::vector<Vec3>& points);

/// Loads an OBJ file. With `hull` false the mesh must already be closed and convex (validated,
/// errors name the face or vertex); with `hull` true its convex hull is used. Polygons are
/// fan-triangulated. Throws GeometryError (with the path) for unreadable, empty or bad files.
ConvexPolyhedron load_obj(const std::string& path, bool hull);

}  // namespace rbx

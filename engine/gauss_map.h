// The Gauss map of a convex polyhedron, in its body frame, for the contact plane's search
// (engine/contact_plane.h): its distinct face normals (points of the unit sphere), its solid
// edges (arcs between their two faces' normals) and a tree of cones over each, so that a search
// over directions can skip every face and edge whose normals lie in a cone it has bounded.
// Built once with the shape (which is immutable), for every shape.
#pragma once

#include <algorithm>
#include <vector>

#include "engine/bvh.h"

namespace rbx {

class ConvexPolyhedron;

/// A cone of directions: every unit vector within `angle` (rad) of `axis`. An angle of pi or
/// more holds the whole sphere (`whole`).
struct DirectionCone {
  Vec3 axis = Vec3::UnitZ();  // unit, body frame
  double cos_angle = -1.0, sin_angle = 0.0;
  bool whole = true;
};

/// The Gauss map of one shape, in its body frame.
struct GaussMap {
  /// A distinct face plane (the first triangle of each run of triangles sharing a normal).
  struct Face {
    Vec3 normal = Vec3::UnitZ();  // unit, outward
    double offset = 0.0;          // m, normal . p for every point p of the face
    int triangle = 0;
  };
  /// A solid edge (its two faces not coplanar): the short arc between their outward normals.
  struct Arc {
    Vec3 n0 = Vec3::UnitZ(), n1 = Vec3::UnitZ();  // unit: the normals of edge_faces()[edge]
    DirectionCone cone;                           // holds the whole arc
    double low = 0.0;  // m, at most the shape's support h(n) = max_p p . n at every n of the arc
    int edge = 0;
  };

  std::vector<Face> faces;
  std::vector<Arc> arcs;
  /// Trees over faces (by normal) and arcs (by cone centre): node k of `face_tree` holds the
  /// faces face_tree.order[begin, end) and `face_cones[k]` holds their normals; the same for
  /// arcs, whose node cones hold every point of their arcs.
  Bvh face_tree, arc_tree;
  std::vector<DirectionCone> face_cones, arc_cones;
  /// Per node, the least support h(n) over its faces' normals (their offsets) or over its arcs
  /// (their `low`), in the body frame.
  std::vector<double> face_lows, arc_lows;
  /// Vertex adjacency, compressed: the neighbours of vertex v are
  /// neighbors[neighbor_start[v] .. neighbor_start[v + 1]).
  std::vector<int> neighbor_start, neighbors;
  /// The triangles around each vertex, compressed the same way: those of vertex v are
  /// vertex_triangles[vertex_triangle_start[v] .. vertex_triangle_start[v + 1]).
  std::vector<int> vertex_triangle_start, vertex_triangles;
  /// Per triangle, the index in `faces` of its distinct plane.
  std::vector<int> face_of_triangle;
  /// Parallel to `neighbors`: the index in `arcs` of the edge to that neighbour, -1 for a flat
  /// face's diagonal (no arc).
  std::vector<int> neighbor_arcs;
  double radius = 0.0;  // m, the largest distance of a vertex from the body origin
  /// Start vertices for a climb: a cube map of directions (six faces of `cells` x `cells` cells,
  /// about one cell per two vertices), each cell holding the support vertex along its centre, so
  /// that a climb from the cell of its direction starts at or next to its answer.
  int cells = 0;
  std::vector<int> cell_vertices;
  /// The vertices again, in blocks of four laid out as four x, four y, four z (the last block
  /// padded with vertex 0), for `scan_vertices`.
  std::vector<double> lanes;
  int lane_vertices = 0;  // the vertices in `lanes`, padding not counted

  /// Builds the Gauss map of `shape` (its vertices, triangles, edges and planes must be set).
  static GaussMap build(const ConvexPolyhedron& shape);

  /// The start vertex of the cube map's cell that holds direction d (body frame, any length).
  int start_for(const Vec3& d) const {
    const Vec3 m = d.cwiseAbs();
    const int i = m.x() >= m.y() ? (m.x() >= m.z() ? 0 : 2) : (m.y() >= m.z() ? 1 : 2);
    if (!(m[i] > 0)) return cell_vertices[0];  // zero or NaN: any vertex will do
    const int j = i == 2 ? 0 : i + 1, k = j == 2 ? 0 : j + 1;
    const double scale = 0.5 * cells / m[i], mid = 0.5 * cells;
    // The cell's column: |x| <= m[i] keeps it below `cells`, and a NaN falls in column 0 (never
    // cast: that is undefined).
    auto column = [&](double x) {
      const double c = x * scale + mid;
      return c >= 1.0 ? std::min(static_cast<int>(c), cells - 1) : 0;
    };
    return cell_vertices[((2 * i + (d[i] < 0 ? 1 : 0)) * cells + column(d[j])) * cells +
                         column(d[k])];
  }
  /// Of `start` (-1: none) and the cube map's start vertex for d (body frame), the one further
  /// along d: the better place to begin a climb over `vertices` (the shape's, body frame).
  int better_start(const std::vector<Vec3>& vertices, const Vec3& d, int start) const {
    const int cell = start_for(d);
    return start < 0 || vertices[cell].dot(d) > vertices[start].dot(d) ? cell : start;
  }
  /// The vertex of `vertices` furthest along d (body frame), climbing the vertex graph from
  /// `start` (a vertex with no higher neighbour is highest on a convex polyhedron), or from the
  /// cube map's start vertex for d when `start` is negative; its projection goes
  /// to `height`. `vertices` may be the shape's body-frame vertices or the same placed in the
  /// world (with d in the same frame; then `start` must not be negative): only the vertex graph
  /// is the map's.
  int climb(const std::vector<Vec3>& vertices, const Vec3& d, int start, double& height) const;
  /// The instructions `scan_vertices` runs on: the widest the processor has, or one named (the
  /// tests compare each with a loop over the vertices). One the processor lacks falls back to
  /// the next narrower.
  enum class ScanUnit { Widest, Avx, Sse2, Plain };
  /// The first vertex furthest along d (body frame) among all of them, its projection to
  /// `height`: the same vertex and the same value, bit for bit, as a loop over the shape's
  /// vertices in order, with four vertices at a time and no branch on the data (whichever
  /// `unit` runs it).
  int scan_vertices(const Vec3& d, double& height, ScanUnit unit = ScanUnit::Widest) const;
};

}  // namespace rbx

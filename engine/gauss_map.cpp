#include "engine/gauss_map.h"

#include <algorithm>
#include <cmath>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__SSE2__) && (defined(__x86_64__) || defined(__i386__))
#include <immintrin.h>
#define RBX_X86 1
#endif

#include "engine/polyhedron.h"

namespace rbx {

namespace {

// Faces or arcs per leaf of the cone trees.
constexpr int kLeafSize = 4;
// Added to every cone's angle (rad): the angles are computed with atan2 to ~1e-16 rad, so a
// cone never misses a direction it should hold by round-off.
constexpr double kConeSlack = 1e-9;

// The angle between two unit vectors, accurate near 0 and pi (acos is not).
double angle_between(const Vec3& p, const Vec3& q) {
  return std::atan2(p.cross(q).norm(), p.dot(q));
}

DirectionCone cone_of(const Vec3& axis, double angle) {
  DirectionCone c;
  c.axis = axis;
  c.whole = !(angle + kConeSlack < M_PI);
  c.cos_angle = c.whole ? -1.0 : std::cos(angle + kConeSlack);
  c.sin_angle = c.whole ? 0.0 : std::sin(angle + kConeSlack);
  return c;
}

// The cone of a tree node: around the normalized sum of its items' axes, wide enough to hold
// every item's cone; the whole sphere when the axes cancel.
DirectionCone node_cone(const std::vector<int>& order, int begin, int end,
                        const std::vector<DirectionCone>& items,
                        const std::vector<double>& angles) {
  Vec3 sum = Vec3::Zero();
  for (int i = begin; i < end; ++i) sum += items[order[i]].axis;
  if (sum.norm() < 1e-6) return cone_of(Vec3::UnitZ(), M_PI);
  const Vec3 axis = sum.normalized();
  double angle = 0.0;
  for (int i = begin; i < end; ++i)
    angle = std::max(angle, angle_between(axis, items[order[i]].axis) + angles[order[i]]);
  return cone_of(axis, angle);
}

// A tree over item cones (split on their axes as points of the sphere) and the cone of each node.
void build_tree(const std::vector<DirectionCone>& items, const std::vector<double>& angles,
                Bvh& tree, std::vector<DirectionCone>& cones) {
  std::vector<Vec3> at;
  for (const DirectionCone& c : items) at.push_back(c.axis);
  tree = Bvh::build(at, at, kLeafSize);
  cones.clear();
  for (const BvhNode& node : tree.nodes)
    cones.push_back(node_cone(tree.order, node.begin, node.end, items, angles));
}

}  // namespace

GaussMap GaussMap::build(const ConvexPolyhedron& s) {
  GaussMap g;
  const auto& planes = s.planes();
  // Distinct face planes (consecutive coplanar triangles share one).
  std::vector<DirectionCone> items;
  std::vector<double> angles;
  for (int f = 0; f < static_cast<int>(planes.size()); ++f) {
    if (s.new_plane()[f]) g.faces.push_back({planes[f].normal, planes[f].offset, f});
    g.face_of_triangle.push_back(static_cast<int>(g.faces.size()) - 1);
    if (!s.new_plane()[f]) continue;
    items.push_back(cone_of(planes[f].normal, 0.0));
    angles.push_back(0.0);
  }
  build_tree(items, angles, g.face_tree, g.face_cones);
  // Solid edges: a flat face's diagonal (1 - cos below 1e-12, the validation's convexity
  // tolerance) has no arc and no axis of its own.
  items.clear();
  angles.clear();
  for (int i = 0; i < static_cast<int>(s.edges().size()); ++i) {
    const auto& f = s.edge_faces()[i];
    const Vec3 &n0 = planes[f[0]].normal, &n1 = planes[f[1]].normal;
    if (n0.dot(n1) > 1.0 - 1e-12) continue;
    Arc arc;
    arc.n0 = n0;
    arc.n1 = n1;
    arc.edge = i;
    const Vec3 mid = n0 + n1;
    // Faces nearly opposite (a sliver's rim): no useful centre, the whole sphere.
    const double half = mid.norm() > 1e-6 ? 0.5 * angle_between(n0, n1) : M_PI;
    arc.cone = cone_of(mid.norm() > 1e-6 ? Vec3(mid.normalized()) : n0, half);
    // Along the arc the support is v . n for the edge's vertex v, a sinusoid in the arc's angle
    // that equals the two faces' offsets at the ends. An arc shorter than a half circle with
    // both ends at or above 0 holds no trough of it, so its least is at an end; otherwise
    // -|v| is below it everywhere.
    const double o0 = planes[f[0]].offset, o1 = planes[f[1]].offset;
    arc.low = o0 >= 0 && o1 >= 0 && half < 0.5 * M_PI ? std::min(o0, o1)
                                                      : -s.vertices()[s.edges()[i].a].norm();
    g.arcs.push_back(arc);
    items.push_back(arc.cone);
    angles.push_back(half + kConeSlack);
  }
  build_tree(items, angles, g.arc_tree, g.arc_cones);
  // The least support per node.
  auto lows = [](const Bvh& tree, auto low_of, std::vector<double>& out) {
    for (const BvhNode& node : tree.nodes) {
      double low = low_of(tree.order[node.begin]);
      for (int i = node.begin; i < node.end; ++i) low = std::min(low, low_of(tree.order[i]));
      out.push_back(low);
    }
  };
  lows(
      g.face_tree, [&](int k) { return g.faces[k].offset; }, g.face_lows);
  lows(
      g.arc_tree, [&](int k) { return g.arcs[k].low; }, g.arc_lows);
  // Vertex adjacency from the edges (counting sort: each list in increasing order).
  const int nv = static_cast<int>(s.vertices().size());
  g.neighbor_start.assign(nv + 1, 0);
  for (const Edge& e : s.edges()) {
    ++g.neighbor_start[e.a + 1];
    ++g.neighbor_start[e.b + 1];
  }
  for (int v = 0; v < nv; ++v) g.neighbor_start[v + 1] += g.neighbor_start[v];
  g.neighbors.resize(g.neighbor_start.back());
  g.neighbor_arcs.assign(g.neighbors.size(), -1);
  std::vector<int> arc_of_edge(s.edges().size(), -1);
  for (int k = 0; k < static_cast<int>(g.arcs.size()); ++k) arc_of_edge[g.arcs[k].edge] = k;
  std::vector<int> fill(g.neighbor_start.begin(), g.neighbor_start.end() - 1);
  for (int i = 0; i < static_cast<int>(s.edges().size()); ++i) {
    const Edge& e = s.edges()[i];
    g.neighbor_arcs[fill[e.a]] = arc_of_edge[i];
    g.neighbors[fill[e.a]++] = e.b;
    g.neighbor_arcs[fill[e.b]] = arc_of_edge[i];
    g.neighbors[fill[e.b]++] = e.a;
  }
  // The triangles around each vertex (counting sort again).
  const auto& tris = s.triangles();
  g.vertex_triangle_start.assign(nv + 1, 0);
  for (const auto& t : tris)
    for (const int v : t) ++g.vertex_triangle_start[v + 1];
  for (int v = 0; v < nv; ++v) g.vertex_triangle_start[v + 1] += g.vertex_triangle_start[v];
  g.vertex_triangles.resize(g.vertex_triangle_start.back());
  fill.assign(g.vertex_triangle_start.begin(), g.vertex_triangle_start.end() - 1);
  for (int t = 0; t < static_cast<int>(tris.size()); ++t)
    for (const int v : tris[t]) g.vertex_triangles[fill[v]++] = t;
  for (const Vec3& v : s.vertices()) g.radius = std::max(g.radius, v.norm());
  g.lane_vertices = nv;
  g.lanes.resize(12 * ((nv + 3) / 4));
  for (int i = 0; i < 4 * ((nv + 3) / 4); ++i) {
    const Vec3& v = s.vertices()[i < nv ? i : 0];
    for (int c = 0; c < 3; ++c) g.lanes[12 * (i / 4) + 4 * c + i % 4] = v[c];
  }
  // The cube map of start vertices, each cell's found by a climb from the cell before it (once
  // per shape). Its size is capped: past a few thousand vertices a climb from a nearby cell is
  // short anyway.
  constexpr int kMaxCells = 64;
  g.cells = std::clamp(static_cast<int>(std::ceil(std::sqrt(0.5 * nv))), 1, kMaxCells);
  g.cell_vertices.reserve(6 * g.cells * g.cells);
  int at = s.support_index(Vec3::UnitX());
  for (int face = 0; face < 6; ++face) {
    const int i = face / 2, j = i == 2 ? 0 : i + 1, k = j == 2 ? 0 : j + 1;
    for (int u = 0; u < g.cells; ++u)
      for (int w = 0; w < g.cells; ++w) {
        Vec3 d = Vec3::Zero();
        d[i] = face % 2 ? -1.0 : 1.0;
        d[j] = (u + 0.5) * 2.0 / g.cells - 1.0;
        d[k] = (w + 0.5) * 2.0 / g.cells - 1.0;
        double h = 0.0;
        at = g.climb(s.vertices(), d, at, h);
        g.cell_vertices.push_back(at);
      }
  }
  return g;
}

int GaussMap::climb(const std::vector<Vec3>& vertices, const Vec3& d, int start,
                    double& height) const {
  int at = start < 0 ? start_for(d) : start;
  double best = vertices[at].dot(d);
  for (;;) {
    // The highest neighbour of `at`, if higher than it.
    int next = at;
    for (int k = neighbor_start[at]; k < neighbor_start[at + 1]; ++k) {
      const int o = neighbors[k];
      const double h = vertices[o].dot(d);
      if (h > best) {
        best = h;
        next = o;
      }
    }
    if (next == at) break;
    at = next;
  }
  height = best;
  return at;
}

namespace {

// The lanes' scans: `p` the vertices in blocks of four (x, y, z), `blocks` of them, d the
// direction. Each lane keeps its own first highest vertex; the lanes are then merged by height,
// the lower index on a tie, which is the first highest of all. Every projection is summed as
// Vec3::dot sums it, (x dx + y dy) + z dz, so the values are the plain loop's to the bit. A padded
// copy of vertex 0 ties with vertex 0 and loses on the index. Masks select, never a blend
// instruction: GCC turns a blend of a compare's mask back into branches.

// The plain scan, on any processor.
int scan_plain(const double* p, int blocks, const Vec3& d, double& height) {
  double best[4], arg[4];
  for (int k = 0; k < 4; ++k) {
    best[k] = (p[k] * d.x() + p[4 + k] * d.y()) + p[8 + k] * d.z();
    arg[k] = k;
  }
  for (int b = 1; b < blocks; ++b)
    for (int k = 0; k < 4; ++k) {
      const double* q = p + 12 * b;
      const double h = (q[k] * d.x() + q[4 + k] * d.y()) + q[8 + k] * d.z();
      if (h > best[k]) {
        best[k] = h;
        arg[k] = 4 * b + k;
      }
    }
  double top = best[0], first = arg[0];
  for (int k = 1; k < 4; ++k) {
    const bool take = best[k] > top || (best[k] == top && arg[k] < first);
    top = take ? best[k] : top;
    first = take ? arg[k] : first;
  }
  height = top;
  return static_cast<int>(first);
}

#if defined(__SSE2__)
// Two lanes into the first: the higher, the lower index on a tie.
inline void merge_lanes(__m128d& h, __m128d& i, const __m128d& h2, const __m128d& i2) {
  const __m128d take =
      _mm_or_pd(_mm_cmpgt_pd(h2, h), _mm_and_pd(_mm_cmpeq_pd(h2, h), _mm_cmplt_pd(i2, i)));
  h = _mm_or_pd(_mm_and_pd(take, h2), _mm_andnot_pd(take, h));
  i = _mm_or_pd(_mm_and_pd(take, i2), _mm_andnot_pd(take, i));
}

// Four lanes in two SSE2 registers, merged in the same registers (the compiler branches on a
// scalar merge).
int scan_sse2(const double* p, int blocks, const Vec3& d, double& height) {
  const __m128d dx = _mm_set1_pd(d.x()), dy = _mm_set1_pd(d.y()), dz = _mm_set1_pd(d.z());
  auto project = [&](const double* q) {
    return _mm_add_pd(
        _mm_add_pd(_mm_mul_pd(_mm_loadu_pd(q), dx), _mm_mul_pd(_mm_loadu_pd(q + 4), dy)),
        _mm_mul_pd(_mm_loadu_pd(q + 8), dz));
  };
  __m128d high[2] = {project(p), project(p + 2)};
  __m128d index[2] = {_mm_set_pd(1, 0), _mm_set_pd(3, 2)};
  __m128d at[2] = {index[0], index[1]};
  const __m128d step = _mm_set1_pd(4);
  for (int b = 1; b < blocks; ++b)
    for (int j = 0; j < 2; ++j) {
      at[j] = _mm_add_pd(at[j], step);
      const __m128d h = project(p + 12 * b + 2 * j);
      // Strictly higher: the lane keeps its first highest (and a NaN never replaces).
      const __m128d higher = _mm_cmpgt_pd(h, high[j]);
      high[j] = _mm_max_pd(h, high[j]);
      index[j] = _mm_or_pd(_mm_and_pd(higher, at[j]), _mm_andnot_pd(higher, index[j]));
    }
  merge_lanes(high[0], index[0], high[1], index[1]);
  merge_lanes(high[0], index[0], _mm_unpackhi_pd(high[0], high[0]),
              _mm_unpackhi_pd(index[0], index[0]));
  height = _mm_cvtsd_f64(high[0]);
  return _mm_cvttsd_si32(index[0]);
}
#endif

#if defined(RBX_X86)
// Compiled for AVX whatever the build's target; called only when the processor has it. AVX has
// no fused multiply-add (and none is asked for), so the sums are SSE2's.
#define RBX_AVX __attribute__((target("avx")))

// One block's four projections.
RBX_AVX inline __m256d project_avx(const double* q, __m256d dx, __m256d dy, __m256d dz) {
  return _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(_mm256_loadu_pd(q), dx),
                                     _mm256_mul_pd(_mm256_loadu_pd(q + 4), dy)),
                       _mm256_mul_pd(_mm256_loadu_pd(q + 8), dz));
}

// Four lanes in one AVX register: half the instructions of the SSE2 scan per block.
RBX_AVX int scan_avx(const double* p, int blocks, double x, double y, double z, double& height) {
  const __m256d dx = _mm256_set1_pd(x), dy = _mm256_set1_pd(y), dz = _mm256_set1_pd(z);
  __m256d high = project_avx(p, dx, dy, dz);
  __m256d index = _mm256_set_pd(3, 2, 1, 0);
  __m256d at = index;
  const __m256d step = _mm256_set1_pd(4);
  for (int b = 1; b < blocks; ++b) {
    at = _mm256_add_pd(at, step);
    const __m256d h = project_avx(p + 12 * b, dx, dy, dz);
    const __m256d higher = _mm256_cmp_pd(h, high, _CMP_GT_OQ);
    high = _mm256_max_pd(h, high);
    index = _mm256_or_pd(_mm256_and_pd(higher, at), _mm256_andnot_pd(higher, index));
  }
  __m128d h0 = _mm256_castpd256_pd128(high), i0 = _mm256_castpd256_pd128(index);
  // merge_lanes inlined here takes AVX's encoding (no switch between the two inside the scan).
  merge_lanes(h0, i0, _mm256_extractf128_pd(high, 1), _mm256_extractf128_pd(index, 1));
  merge_lanes(h0, i0, _mm_unpackhi_pd(h0, h0), _mm_unpackhi_pd(i0, i0));
  height = _mm_cvtsd_f64(h0);
  return _mm_cvttsd_si32(i0);
}
#endif

#if defined(RBX_X86)
// Read once, when the library loads (the processor's features first: no other constructor may
// have asked yet). A scan run by another static's constructor before this one sees false and
// takes SSE2: the same answer.
const bool kHasAvx = (__builtin_cpu_init(), __builtin_cpu_supports("avx"));
#else
const bool kHasAvx = false;
#endif

}  // namespace

int GaussMap::scan_vertices(const Vec3& d, double& height, ScanUnit unit) const {
  const double* p = lanes.data();
  const int blocks = (lane_vertices + 3) / 4;
  if (unit == ScanUnit::Widest) unit = kHasAvx ? ScanUnit::Avx : ScanUnit::Sse2;
#if defined(RBX_X86)
  if (unit == ScanUnit::Avx && kHasAvx) return scan_avx(p, blocks, d.x(), d.y(), d.z(), height);
#endif
#if defined(__SSE2__)
  if (unit != ScanUnit::Plain) return scan_sse2(p, blocks, d, height);
#endif
  return scan_plain(p, blocks, d, height);
}

}  // namespace rbx

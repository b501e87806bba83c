// The inner polytope of the Minkowski difference D = A - B that narrows the contact plane's search
// (engine/contact_plane_detail.h): GJK finds a tetrahedron of D's points around the origin, then
// EPA grows it toward D's boundary nearest the origin. docs/contact_plane.md says why the cone it
// leaves can only drop candidates beyond the tie margin of the least overlap, whatever state the
// polytope is left in: the search, not the polytope, still chooses the plane.
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "engine/contact_plane_detail.h"

namespace rbx::plane_detail {

namespace {

// Limits of the two loops. GJK beyond its cap gives up (the search then covers every direction);
// EPA's cap leaves the polytope as it is, which still bounds (every state does), only less
// tightly: neither cap costs correctness.
constexpr int kGjkIterations = 64;
constexpr int kEpaIterations = 96;

// A point of D: w = a - b for vertex ia of A and ib of B (world).
struct Point {
  Vec3 w = Vec3::Zero();
  int ia = -1, ib = -1;
};

// A triangle of the polytope, wound outward, with its unit normal and plane distance.
struct Face {
  std::array<int, 3> v{};
  Vec3 n = Vec3::UnitZ();
  double dist = 0.0;
};

// D's support point along d, each shape's climb starting from `from`'s vertices.
Point support(const Side& a, const Side& b, const Vec3& d, const Point& from) {
  Point p;
  p.ia = from.ia;
  p.ib = from.ib;
  a.support(d, p.ia);
  b.support(-d, p.ib);
  p.w = a.world(p.ia) - b.world(p.ib);
  return p;
}

// (u x v) x u: the direction perpendicular to u, in the plane of u and v, on v's side.
Vec3 toward(const Vec3& u, const Vec3& v) { return u.cross(v).cross(u); }

// GJK's step on a segment (s[1] the newest point): the new direction toward the origin.
void segment_step(std::array<Point, 4>& s, int& n, Vec3& d) {
  const Vec3 ab = s[0].w - s[1].w, ao = -s[1].w;
  if (ab.dot(ao) > 0) {
    d = toward(ab, ao);
  } else {
    s[0] = s[1];
    n = 1;
    d = ao;
  }
}

// GJK's step on a triangle (s[2] the newest point).
void triangle_step(std::array<Point, 4>& s, int& n, Vec3& d) {
  const Vec3 a = s[2].w, ab = s[1].w - a, ac = s[0].w - a, ao = -a;
  const Vec3 abc = ab.cross(ac);
  if (abc.cross(ac).dot(ao) > 0) {
    if (ac.dot(ao) > 0) {
      s[1] = s[2];  // the segment c-a
      n = 2;
      d = toward(ac, ao);
      return;
    }
    s[0] = s[1];  // the segment b-a
    s[1] = s[2];
    n = 2;
    segment_step(s, n, d);
    return;
  }
  if (ab.cross(abc).dot(ao) > 0) {
    s[0] = s[1];
    s[1] = s[2];
    n = 2;
    segment_step(s, n, d);
    return;
  }
  d = abc.dot(ao) > 0 ? abc : Vec3(-abc);
}

// GJK's step on a tetrahedron (s[3] the newest point): true when it holds the origin, else the
// face the origin lies beyond becomes the triangle.
bool tetrahedron_step(std::array<Point, 4>& s, int& n, Vec3& d) {
  const Vec3 a = s[3].w, ao = -a;
  // The three faces through the newest point, each with the vertex opposite it.
  const int faces[3][3] = {{2, 1, 0}, {1, 0, 2}, {0, 2, 1}};
  for (const auto& f : faces) {
    const Vec3 x = s[f[0]].w, y = s[f[1]].w, opposite = s[f[2]].w;
    Vec3 m = (x - a).cross(y - a);
    if (m.dot(opposite - a) > 0) m = -m;
    if (m.dot(ao) > 0) {
      s = {s[f[0]], s[f[1]], s[3], s[3]};
      n = 3;
      triangle_step(s, n, d);
      return false;
    }
  }
  return true;
}

// What GJK found: a tetrahedron holding the origin; a direction along which D reaches no further
// than the origin (apart or touching); or neither (the origin on a segment of the simplex, no
// progress, or the cap: a degenerate path, which another start direction may avoid).
enum class Gjk { kEnclosed, kApart, kDegenerate };

// GJK from direction d.
Gjk enclose_from(const Side& a, const Side& b, Vec3 d, std::array<Point, 4>& s) {
  s[0] = support(a, b, d, Point{});
  int n = 1;
  d = -s[0].w;
  for (int it = 0; it < kGjkIterations; ++it) {
    // The origin on the simplex. On its first point, D's support along the start direction is
    // zero: touching. On a segment, the origin lies in D, inside or on its boundary: any
    // direction across the segment goes on (the tetrahedron then holds the origin on an edge,
    // two flat triangles that EPA grows past, or finds D's boundary there).
    if (!(d.squaredNorm() > 0)) {
      if (n != 2) return n == 1 ? Gjk::kApart : Gjk::kDegenerate;
      d = (s[1].w - s[0].w).unitOrthogonal();
    }
    const Point w = support(a, b, d, s[n - 1]);
    if (!(w.w.dot(d) > 0)) return Gjk::kApart;  // no point of D beyond the origin along d
    for (int k = 0; k < n; ++k)
      if (s[k].ia == w.ia && s[k].ib == w.ib) return Gjk::kDegenerate;  // no progress
    s[n++] = w;
    if (n == 2)
      segment_step(s, n, d);
    else if (n == 3)
      triangle_step(s, n, d);
    else if (tetrahedron_step(s, n, d))
      return Gjk::kEnclosed;
  }
  return Gjk::kDegenerate;
}

// GJK: a tetrahedron of D's support points holding the origin, or false (apart, touching, or
// degenerate from every start). It starts along the line between the centres; poses of round
// coordinates (stacked boxes, centred) can put the origin exactly on a segment of the simplex
// from there, so a degenerate path is retried from a few directions aligned with no axis.
bool enclose(const Side& a, const Side& b, std::array<Point, 4>& s) {
  Vec3 d = b.p - a.p;
  if (!(d.squaredNorm() > 0)) d = Vec3::UnitX();
  const Gjk first = enclose_from(a, b, d, s);
  if (first != Gjk::kDegenerate) return first == Gjk::kEnclosed;
  for (const Vec3& retry :
       {Vec3(0.31, 0.52, 0.79), Vec3(-0.67, 0.23, 0.71), Vec3(0.43, -0.86, 0.29)}) {
    const Gjk again = enclose_from(a, b, retry, s);
    if (again != Gjk::kDegenerate) return again == Gjk::kEnclosed;
  }
  return false;
}

// The polytope being grown: its points and its triangles.
struct Polytope {
  std::vector<Point> points;
  std::vector<Face> faces;
  std::vector<std::array<int, 2>> horizon;
  // The nearest triangle (least plane distance; of equals, the first in `faces`), kept by add and
  // expand as they go, so that no iteration scans the triangles a second time for it.
  int nearest = -1;

  void consider(int g) {
    if (nearest < 0 || faces[g].dist < faces[nearest].dist) nearest = g;
  }

  // A triangle of points i, j, k (wound outward); false when the origin lies beyond its plane by
  // more than round-off. A flat triangle (the origin on its plane, to round-off: GJK's simplex on
  // symmetric poses) is kept, and grown past before any bound is drawn from the polytope.
  bool add(int i, int j, int k, double tie) {
    Face f;
    f.v = {i, j, k};
    const Vec3& p = points[i].w;
    const Vec3 m = (points[j].w - p).cross(points[k].w - p);
    const double len = m.norm();
    if (!(len > 0)) return false;
    f.n = m / len;
    f.dist = f.n.dot(p);
    if (!(f.dist > -tie)) return false;
    faces.push_back(f);
    consider(static_cast<int>(faces.size()) - 1);
    return true;
  }
  // Replaces the triangles that see point w (index `wi`) by a cone from w over their boundary.
  bool expand(int wi, double tie) {
    const Vec3& w = points[wi].w;
    horizon.clear();
    const std::size_t count = faces.size();
    // The triangles that stay are moved down over the seen ones as the scan goes (the scans of
    // later iterations stay short), and the nearest of them kept.
    nearest = -1;
    std::size_t stay = 0;
    double least = 0.0;
    for (std::size_t g = 0; g < count; ++g) {
      const Face& f = faces[g];
      // Seen only from beyond the tie margin: w on the plane of coplanar triangles (points of D on
      // one face of it) would be seen from some and not others by round-off, and the fan over
      // their edge would fold inward. The nearest triangle is always seen (the loop grows it only
      // when w is beyond it by more than the margin).
      if (!(f.n.dot(w) - f.dist > tie)) {
        if (nearest < 0 || f.dist < least) {
          nearest = static_cast<int>(stay);
          least = f.dist;
        }
        if (stay != g) faces[stay] = f;
        ++stay;
        continue;
      }
      // Each directed edge of a seen triangle, unless its reverse is one too (then interior).
      for (int e = 0; e < 3; ++e) {
        const int from = f.v[e], to = f.v[(e + 1) % 3];
        const auto rev = std::find_if(horizon.begin(), horizon.end(),
                                      [&](const auto& h) { return h[0] == to && h[1] == from; });
        if (rev != horizon.end()) {
          horizon.erase(rev);
        } else {
          // Written in place (a pair built aside and copied in stalls on its narrower stores).
          auto& h = horizon.emplace_back();
          h[0] = from;
          h[1] = to;
        }
      }
    }
    faces.resize(stay);
    for (const auto& e : horizon)
      if (!add(e[0], e[1], wi, tie)) return false;
    return !horizon.empty();
  }
};

}  // namespace

// The polytope's lists, kept by the caller's scratch between queries.
struct PolytopeLists {
  Polytope poly;
};

void ListsDeleter::operator()(PolytopeLists* p) const { delete p; }

bool inner_polytope_bound(const Side& a, const Side& b, double tie, Candidates& out,
                          Scratch& scratch) {
  std::array<Point, 4> s;
  if (!enclose(a, b, s)) return false;
  if (!scratch.polytope) scratch.polytope.reset(new PolytopeLists);
  Polytope& poly = scratch.polytope->poly;
  poly.points.assign(s.begin(), s.end());
  poly.faces.clear();
  poly.nearest = -1;
  // The tetrahedron, each face wound away from the vertex opposite it.
  for (const auto& f : {std::array<int, 4>{0, 1, 2, 3}, {0, 3, 1, 2}, {0, 2, 3, 1}, {1, 3, 2, 0}}) {
    const Vec3 m = (s[f[1]].w - s[f[0]].w).cross(s[f[2]].w - s[f[0]].w);
    const bool flip = m.dot(s[f[3]].w - s[f[0]].w) > 0;
    if (!(flip ? poly.add(f[0], f[2], f[1], tie) : poly.add(f[0], f[1], f[2], tie))) return false;
  }
  double upper = kInf;
  Vec3 upper_dir = Vec3::UnitZ();
  Point upper_at;
  for (int it = 0; it < kEpaIterations; ++it) {
    // The nearest triangle: its plane distance is a lower bound on the answer.
    const Face* near = &poly.faces[poly.nearest];
    const Vec3 n = near->n;
    const double lower = near->dist;
    // The climbs start from the triangle's corner furthest along its normal (nearest the answer).
    int from = near->v[0];
    for (const int v : {near->v[1], near->v[2]})
      if (poly.points[v].w.dot(n) > poly.points[from].w.dot(n)) from = v;
    const Point w = support(a, b, n, poly.points[from]);
    const double h = w.w.dot(n);
    if (h < upper) {
      upper = h;
      upper_dir = n;
      upper_at = w;
    }
    // Converged: the triangle lies on D's face (to round-off). On a flat triangle the origin is
    // then on D's boundary: contact, not overlap, so no proof.
    if (h - lower <= tie) {
      if (!(lower > tie)) return false;
      break;
    }
    poly.points.push_back(w);
    if (!poly.expand(static_cast<int>(poly.points.size()) - 1, tie)) return false;
  }
  // The proof's claim checked where round-off can spoil the polytope: with the origin on D's
  // boundary to round-off (a thin box touching a face), the expansion can lose the triangles of
  // the flat side and converge on the far one, claiming an overlap of the whole far extent. The
  // origin is inside D only if D reaches beyond it along every direction, and the lost side lies
  // opposite the converged triangle: D must reach beyond the origin there.
  if (!(support(a, b, -upper_dir, upper_at).w.dot(-upper_dir) > tie)) return false;

  // Along a direction u that meets triangle g, D reaches at least dist_g / (u . n_g) (the ray
  // meets g there, and g lies in D). A candidate within the tie margin of the answer reaches no
  // further than `limit` (several tie margins above the upper bound, for the round-off of both),
  // so it lies within the cone u . n_g >= dist_g / limit of some triangle with dist_g <= limit.
  // One circular cone holds all of those.
  const double limit = upper + 8.0 * tie;
  Vec3 axis = Vec3::Zero();
  for (const Face& f : poly.faces) {
    if (f.dist > limit) continue;
    if (!(f.dist > tie)) return false;  // still flat at the cap: no proof
    axis += f.n;
  }
  if (upper < out.known) {
    out.known = upper;
    out.known_normal = -upper_dir;  // D's direction u pushes A along -u
  }
  // Opposite triangles both at the least distance (a pose symmetric through the origin): no
  // cone narrows the search, but the overlap is proved.
  if (!(axis.squaredNorm() > 0)) return true;
  axis.normalize();
  double angle = 0.0;
  for (const Face& f : poly.faces)
    if (f.dist <= limit)
      angle = std::max(angle, std::acos(std::clamp(f.n.dot(axis), -1.0, 1.0)) +
                                  std::acos(std::clamp(f.dist / limit, -1.0, 1.0)));
  // Round-off of the angles themselves (acos near 1 loses half the digits: ~1e-8 rad).
  const double cos_angle = std::cos(angle + 1e-7);
  // A cone of half a sphere or more narrows nothing worth the tests.
  if (!(cos_angle > 0.0)) return true;
  out.within.axis = axis;
  out.within.cos_angle = cos_angle;
  out.within.sin_angle = std::sqrt(std::max(0.0, 1.0 - cos_angle * cos_angle));
  out.within.whole = false;
  out.within_a = upper_at.ia;
  out.within_b = upper_at.ib;
  return true;
}

}  // namespace rbx::plane_detail

#include "comparisons/eval/explore.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>

#include "comparisons/eval/contact_eval.h"
#include "comparisons/eval/harness.h"
#include "comparisons/eval/metrics.h"
#include "comparisons/scene/mesh_io.h"
#include "comparisons/scene/scene_file.h"
#include "engine/body.h"
#include "engine/bounding.h"
#include "engine/detect.h"
#include "reference/exact.h"

namespace rbx {

// ---------------------------------------------------------------------------------------------
// Random numbers

namespace {

uint64_t splitmix64(uint64_t& x) {
  uint64_t z = (x += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

}  // namespace

SampleRng::SampleRng(uint64_t seed, uint64_t index) {
  // Hash of (seed, index): two rounds of splitmix64 mix the pair into one well-spread state.
  uint64_t s = seed;
  const uint64_t h = splitmix64(s);
  uint64_t t = h ^ (index * 0xD1B54A32D192ED03ull);
  state_ = splitmix64(t);
}

uint64_t SampleRng::next() { return splitmix64(state_); }

double SampleRng::uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }

int SampleRng::integer(int lo, int hi) {
  return lo + static_cast<int>(next() % static_cast<uint64_t>(hi - lo + 1));
}

Vec3 SampleRng::direction() {
  const double z = uniform(-1.0, 1.0), phi = uniform(0.0, 2.0 * M_PI);
  const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
  return {r * std::cos(phi), r * std::sin(phi), z};
}

Quat SampleRng::rotation() {
  const double u1 = uniform(), u2 = uniform(0.0, 2.0 * M_PI), u3 = uniform(0.0, 2.0 * M_PI);
  const double a = std::sqrt(1.0 - u1), b = std::sqrt(u1);
  return Quat(a * std::sin(u2), a * std::cos(u2), b * std::sin(u3), b * std::cos(u3)).normalized();
}

// ---------------------------------------------------------------------------------------------
// Samples

namespace {

// The body's shape exactly as the scene loader builds it (box or convex hull of the points).
std::shared_ptr<const ConvexPolyhedron> build_shape(const ExploreBody& e) {
  if (e.shape_class == "box") return std::make_shared<const ConvexPolyhedron>(make_box(e.box_size));
  return std::make_shared<const ConvexPolyhedron>(convex_hull(e.points));
}

// Orientation exactly as the scene loader builds it from what sample_scene_text writes.
Quat build_orientation(const ExploreBody& e) {
  if (e.use_degrees) return Quat(rotation_from_euler_deg(e.rotation_deg)).normalized();
  return e.orientation.normalized();
}

RigidBody build_body(const ExploreBody& e, const std::string& name) {
  BodySpec spec;
  spec.name = name;
  spec.shape_kind = e.shape_class == "box" ? ShapeKind::Box : ShapeKind::Convex;
  spec.box_size = e.box_size;
  spec.shape = build_shape(e);
  spec.position = e.position;
  spec.orientation = build_orientation(e);
  return make_body(spec);
}

// Furthest extent of a placed shape along the unit direction n, from its local origin (m).
double support(const ConvexPolyhedron& shape, const Quat& q, const Vec3& n) {
  const Vec3 local = q.conjugate() * n;
  double best = -1e300;
  for (const Vec3& v : shape.vertices()) best = std::max(best, v.dot(local));
  return best;
}

// Random points of a hull: on a sphere, on an ellipsoid, or in a cube.
std::vector<Vec3> hull_points(SampleRng& r, int n, double scale) {
  const int style = r.integer(0, 2);
  Vec3 axes = Vec3::Ones();
  if (style == 1) axes = Vec3(r.uniform(0.3, 1.0), r.uniform(0.3, 1.0), r.uniform(0.3, 1.0));
  std::vector<Vec3> p;
  for (int i = 0; i < n; ++i) {
    if (style == 2)
      p.push_back(0.5 * scale * Vec3(r.uniform(-1, 1), r.uniform(-1, 1), r.uniform(-1, 1)));
    else
      p.push_back(0.5 * scale * r.direction().cwiseProduct(axes));
  }
  return p;
}

// A random body of roughly `scale` metres: a box, a hull of 4 to 2000 points, or a sliver.
ExploreBody random_body(SampleRng& r, double scale) {
  ExploreBody e;
  const double u = r.uniform();
  if (u < 0.4) {
    e.shape_class = "box";
    for (int k = 0; k < 3; ++k) e.box_size[k] = scale * std::pow(10.0, r.uniform(-0.5, 0.5));
  } else if (u < 0.85) {
    e.shape_class = "hull";
    // Mostly small hulls (the speed goal is set on under 100 vertices), a few up to 2000.
    const double v = r.uniform();
    const int n = v < 0.7 ? r.integer(4, 32)
                  : v < 0.97
                      ? r.integer(33, 99)
                      : static_cast<int>(std::round(std::pow(10.0, r.uniform(2.0, 3.30103))));
    e.points = hull_points(r, n, scale);
  } else {
    e.shape_class = "sliver";
    e.points = hull_points(r, r.integer(4, 10), scale);
    // Flat (one thin axis) or a needle (two), thickness 1e-3 to 3e-2 of the length.
    const double thin = std::pow(10.0, r.uniform(-3.0, -1.5));
    const int first = r.integer(0, 2);
    const bool needle = r.uniform() < 0.3;
    for (Vec3& p : e.points) {
      p[first] *= thin;
      if (needle) p[(first + 1) % 3] *= thin;
    }
  }
  return e;
}

double extent(const ConvexPolyhedron& s) { return (s.bounds().max - s.bounds().min).norm(); }

}  // namespace

ContactSample make_contact_sample(uint64_t seed, uint64_t index) {
  SampleRng r(seed, index);
  ContactSample s;
  s.seed = seed;
  s.index = index;
  // Sizes: mostly comparable, else a ratio up to 1e3 either way.
  const double scale_a = std::pow(10.0, r.uniform(-0.3, 0.3));
  double scale_b = std::pow(10.0, r.uniform(-0.3, 0.3));
  if (r.uniform() < 0.4) scale_b = scale_a * std::pow(10.0, r.uniform(-3.0, -0.5));
  const bool small_first = r.uniform() < 0.5;
  s.a = random_body(r, small_first ? scale_b : scale_a);
  s.b = random_body(r, small_first ? scale_a : scale_b);
  s.a.orientation = r.rotation();
  s.b.orientation = r.rotation();
  s.a.position = Vec3(r.uniform(-1, 1), r.uniform(-1, 1), r.uniform(-1, 1));

  const auto shape_a = build_shape(s.a), shape_b = build_shape(s.b);
  const double small = std::min(extent(*shape_a), extent(*shape_b));
  // B is placed so that the projections of A and B on n overlap by `overlap` (negative: a gap),
  // plus a sideways offset; n points from A toward B.
  Vec3 n = r.direction();
  double overlap = 0.0, sideways = r.uniform(0.0, 0.3) * small;
  const double u = r.uniform();
  if (u < 0.2) {
    s.pose_class = "touching";
    if (r.uniform() < 0.5) {
      const auto& planes = shape_a->planes();
      n = s.a.orientation * planes[r.integer(0, static_cast<int>(planes.size()) - 1)].normal;
    }
  } else if (u < 0.33) {
    s.pose_class = "separated";
    overlap = -std::pow(10.0, r.uniform(-6.0, -2.0)) * small;
  } else if (u < 0.46) {
    s.pose_class = "deep";
    overlap = r.uniform(0.1, 1.0) * small;
  } else if (u < 0.64) {
    // Near a face diagonal: the smaller body pushed in around a corner of the larger one,
    // along the direction from the larger one's origin through that corner (FCL issue 545).
    s.pose_class = "diagonal";
    const bool a_big = extent(*shape_a) >= extent(*shape_b);
    const ConvexPolyhedron& big = a_big ? *shape_a : *shape_b;
    const Quat& q = a_big ? s.a.orientation : s.b.orientation;
    const Vec3 corner = big.vertices()[r.integer(0, static_cast<int>(big.vertices().size()) - 1)];
    n = (q * corner.normalized() + 0.02 * r.direction()).normalized();
    if (!a_big) n = -n;
    overlap = r.uniform(0.3, 1.5) * small;
    sideways = r.uniform(0.0, 0.05) * small;
  } else if (u < 0.80) {
    // Nearly parallel faces: a face of B turned to face one of A's, then tilted slightly.
    s.pose_class = "parallel";
    const auto& pa = shape_a->planes();
    const auto& pb = shape_b->planes();
    n = s.a.orientation * pa[r.integer(0, static_cast<int>(pa.size()) - 1)].normal;
    const Vec3 mb = pb[r.integer(0, static_cast<int>(pb.size()) - 1)].normal;
    const Quat align = Quat::FromTwoVectors(mb, -n);
    const Quat spin(Eigen::AngleAxisd(r.uniform(0.0, 2.0 * M_PI), n));
    Vec3 axis = n.cross(r.direction());
    if (axis.norm() < 1e-6) axis = n.unitOrthogonal();
    const Quat tilt(Eigen::AngleAxisd(std::pow(10.0, r.uniform(-5.0, -1.5)), axis.normalized()));
    s.b.orientation = (tilt * spin * align).normalized();
    overlap = std::pow(10.0, r.uniform(-4.0, -1.0)) * small;
  } else if (u < 0.90) {
    // Edge on edge: n across one edge of A and one of B.
    s.pose_class = "edge_edge";
    const auto& ea = shape_a->edges()[r.integer(0, static_cast<int>(shape_a->edges().size()) - 1)];
    const auto& eb = shape_b->edges()[r.integer(0, static_cast<int>(shape_b->edges().size()) - 1)];
    const Vec3 da = s.a.orientation * (shape_a->vertices()[ea.b] - shape_a->vertices()[ea.a]);
    const Vec3 db = s.b.orientation * (shape_b->vertices()[eb.b] - shape_b->vertices()[eb.a]);
    const Vec3 c = da.cross(db);
    if (c.norm() > 1e-9 * da.norm() * db.norm()) n = c.normalized() * (r.uniform() < 0.5 ? 1 : -1);
    overlap = std::pow(10.0, r.uniform(-4.0, -1.5)) * small;
    sideways = r.uniform(0.0, 0.1) * small;
  } else {
    s.pose_class = "random";
    overlap = r.uniform(-0.1, 0.5) * small;
  }
  // Where A's and B's shapes are placed: shape frames are the scene's local frames (their
  // origins are what `position` places), so supports are measured from those origins.
  const double reach =
      support(*shape_a, s.a.orientation, n) + support(*shape_b, s.b.orientation, -n);
  Vec3 side = n.cross(r.direction());
  side = side.norm() > 1e-9 ? side.normalized() : Vec3::Zero();
  s.b.position = s.a.position + (reach - overlap) * n + sideways * side;
  return s;
}

// ---------------------------------------------------------------------------------------------
// Scene text

namespace {

std::string num(double x) {
  // The shortest text that reads back as the same double (at most 17 significant digits).
  char buf[40];
  for (int digits = 1; digits <= 17; ++digits) {
    std::snprintf(buf, sizeof buf, "%.*g", digits, x);
    // Plain decimals for ordinary magnitudes ("90.0", not "9e+01").
    const bool plain = std::abs(x) < 1e-5 || std::abs(x) >= 1e15 || !std::strchr(buf, 'e');
    if (plain && std::strtod(buf, nullptr) == x) break;
  }
  std::string s = buf;
  // TOML floats need a '.' or an exponent to read back as floats everywhere; integers are fine
  // as vector components, but keep the text uniform.
  if (s.find_first_of(".en") == std::string::npos) s += ".0";
  return s;
}

std::string vec(const Vec3& v) {
  return "[" + num(v.x()) + ", " + num(v.y()) + ", " + num(v.z()) + "]";
}

std::string body_text(const ExploreBody& e, const std::string& name) {
  std::ostringstream o;
  o << "[[body]]\nname = \"" << name << "\"\n";
  if (e.shape_class == "box") {
    o << "shape = \"box\"\nsize = " << vec(e.box_size) << "\n";
  } else {
    o << "shape = \"convex\"  # " << e.shape_class << ", " << e.points.size() << " points\n";
    o << "vertices = [";
    for (size_t i = 0; i < e.points.size(); ++i)
      o << (i ? ",\n            " : "") << vec(e.points[i]);
    o << "]\n";
  }
  o << "position = " << vec(e.position) << "\n";
  if (e.use_degrees)
    o << "rotation = " << vec(e.rotation_deg) << "\n";
  else
    o << "orientation = [" << num(e.orientation.w()) << ", " << num(e.orientation.x()) << ", "
      << num(e.orientation.y()) << ", " << num(e.orientation.z()) << "]\n";
  return o.str();
}

}  // namespace

std::string sample_scene_text(const ContactSample& s, const std::string& header,
                              const std::string& expect) {
  std::ostringstream o;
  o << header;
  o << "description = \"rbx explore seed " << s.seed << " sample " << s.index << " ("
    << s.pose_class << "), shrunk\"\n";
  o << "checks = [\"contact\"]\n\n[sim]\nduration = 0\n\n";
  o << body_text(s.a, "A") << "\n" << body_text(s.b, "B");
  if (!expect.empty()) o << "\n" << expect;
  return o.str();
}

// ---------------------------------------------------------------------------------------------
// Evaluation

namespace {

// Below this many body sizes of depth or gap, touching or not is round-off: a stated tolerance
// of the iterative references (FCL's 1e-6 m distance tolerance is far larger; the exact oracle's
// depth carries about 1e-15 relative error), so a touching mismatch inside it is not counted.
constexpr double kTouchBand = 1e-9;

SampleOutcome evaluate_bodies(const RigidBody& a, const RigidBody& b,
                              const std::vector<std::string>& names, const std::string& shapes,
                              const std::vector<Backend>* table = nullptr) {
  SampleOutcome out;
  out.shapes = shapes;
  const SatResult sat = sat_query(*a.shape, a.pose(), *b.shape, b.pose());
  const double size = std::min(2.0 * bounding_sphere(a).radius, 2.0 * bounding_sphere(b).radius);
  out.touching = sat.touching;
  out.depth_rel = sat.depth / size;
  out.feature = sat.touching ? sat.axis_kind : "separated";
  const double band = kTouchBand * size, true_depth = std::max(sat.depth, 0.0);
  for (const std::string& name : names) {
    const Backend* be = find_backend(name, table);
    if (!be || !be->contact) continue;
    const ContactRun run = run_contact(*be, a, b);
    if (run.result.status == Status::Unsupported) continue;
    BackendOutcome o;
    o.backend = name;
    if (run.result.status == Status::Error || run.result.status == Status::Timeout) {
      o.error = to_string(run.result.status);
      o.message = run.result.message;
      out.backends.push_back(o);
      continue;
    }
    // Touching with no normal: a false contact where the pair is clearly apart, else an answer
    // with nothing to score (kept apart from errors).
    if (run.result.status == Status::Touching) {
      if (!sat.touching && sat.depth < -band) o.error = "false_contact";
      out.backends.push_back(o);
      continue;
    }
    const ContactPoint* c = deepest(run.result);
    const bool touch = c != nullptr;
    if (touch != sat.touching) {
      if (sat.touching && sat.depth > band) o.error = "misses";
      if (!sat.touching && sat.depth < -band) o.error = "false_contact";
      out.backends.push_back(o);
      continue;
    }
    if (!touch) {
      out.backends.push_back(o);
      continue;
    }
    // The harness's rule for ties: a normal along which the overlap equals the true depth
    // (within round-off, 1e-12 of the body size) is as right as the oracle's.
    double angle = angle_deg(c->normal, sat.normal);
    if (angle > 0 && c->normal.allFinite() && c->normal.norm() > 0.5 &&
        std::abs(overlap_along(*a.shape, a.pose(), *b.shape, b.pose(), c->normal.normalized()) -
                 true_depth) <= 1e-12 * size)
      angle = 0.0;
    o.measured = true;
    o.normal_err_deg = angle;
    o.depth_err_rel = std::abs(c->depth - true_depth) / size;
    o.point_err_rel =
        sat.manifold.empty() ? 0.0 : contact_point_error(c->point, a, b, sat.manifold) / size;
    // Clear disagreements, by the harness's marks (harness.h): 1 degree, 1 % of the size.
    if (!(angle <= kMarkAngleDeg))
      o.error = "normal";
    else if (!(o.depth_err_rel <= kMarkDepthRel))
      o.error = "depth";
    else if (!(o.point_err_rel <= kMarkDepthRel))
      o.error = "point";
    out.backends.push_back(o);
  }
  return out;
}

}  // namespace

SampleOutcome evaluate_contact_sample(const ContactSample& s, const std::vector<std::string>& names,
                                      const std::vector<Backend>* table) {
  const RigidBody a = build_body(s.a, "A"), b = build_body(s.b, "B");
  SampleOutcome out = evaluate_bodies(a, b, names, s.a.shape_class + "-" + s.b.shape_class, table);
  out.index = s.index;
  out.pose_class = s.pose_class;
  return out;
}

SampleOutcome evaluate_scene_text(const std::string& text, const std::vector<std::string>& names,
                                  const std::string& pose_class, const std::string& shapes) {
  const Scene scene = parse_scene(text, "explore.toml");
  const std::vector<RigidBody> bodies = make_bodies(scene);
  SampleOutcome out = evaluate_bodies(bodies[0], bodies[1], names, shapes);
  out.pose_class = pose_class;
  return out;
}

std::string signature(const SampleOutcome& s, const BackendOutcome& b) {
  return b.backend + " " + s.shapes + " " + s.feature + " " + b.error;
}

std::string encode(const SampleOutcome& s) {
  Json j = {{"i", s.index},    {"p", s.pose_class}, {"s", s.shapes},     {"f", s.feature},
            {"t", s.touching}, {"d", s.depth_rel},  {"b", Json::array()}};
  for (const BackendOutcome& b : s.backends)
    j["b"].push_back({b.backend, b.error, b.measured, b.normal_err_deg, b.depth_err_rel,
                      b.point_err_rel, b.message, b.velocity_err_ke, b.momentum_err_ke,
                      b.position_err_m, b.turn_rad, b.rest_time_err_s});
  if (s.phase >= 0) j["ph"] = s.phase;
  return j.dump();
}

SampleOutcome decode(const std::string& text) {
  const Json j = Json::parse(text);
  SampleOutcome s;
  s.index = j["i"].get<uint64_t>();
  s.pose_class = j["p"];
  s.shapes = j["s"];
  s.feature = j["f"];
  s.touching = j["t"];
  s.depth_rel = j["d"];
  for (const Json& b : j["b"])
    s.backends.push_back(
        {b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7], b[8], b[9], b[10], b[11]});
  s.phase = j.value("ph", -1.0);
  return s;
}

// ---------------------------------------------------------------------------------------------
// Shrinking

namespace {

// Angle (rad, in [0, pi]) of the rotation taking orientation `from` to `to`; NaN when either
// is not finite.
double rotation_angle(const Quat& from, const Quat& to) {
  const Quat d = to.normalized() * from.normalized().conjugate();
  return 2.0 * std::atan2(d.vec().norm(), std::abs(d.w()));
}

// Euler angles (degrees, R = Rz Ry Rx as the scene format) of a rotation.
Vec3 euler_deg(const Quat& q) {
  const Vec3 zyx = q.toRotationMatrix().eulerAngles(2, 1, 0);
  return Vec3(zyx[2], zyx[1], zyx[0]) * (180.0 / M_PI);
}

// x to the nearest multiple of grid, as the decimal number a reader would write (3 * 0.1 is
// 0.30000000000000004; its 12-digit text reads back as 0.3).
double round_to(double x, double grid) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.12g", std::round(x / grid) * grid);
  return std::strtod(buf, nullptr);
}

// Each coordinate to the nearest multiple of grid (as above).
Vec3 round_to(const Vec3& v, double grid) {
  return Vec3(round_to(v.x(), grid), round_to(v.y(), grid), round_to(v.z(), grid));
}

int point_count(const ContactSample& s) {
  auto n = [](const ExploreBody& e) {
    return e.shape_class == "box" ? 8 : static_cast<int>(e.points.size());
  };
  return n(s.a) + n(s.b);
}

}  // namespace

ShrinkResult shrink(const ContactSample& start, const std::string& backend, const std::string& sig,
                    int max_evaluations) {
  ShrinkResult r;
  r.sample = start;
  r.vertices_before = point_count(start);
  const std::vector<std::string> names = {backend};
  // Keeps candidate c when its scene text still shows the same signature.
  auto keeps = [&](const ContactSample& c, SampleOutcome* out = nullptr) {
    if (r.evaluations >= max_evaluations) return false;
    ++r.evaluations;
    try {
      const SampleOutcome o = evaluate_scene_text(sample_scene_text(c), names, c.pose_class,
                                                  c.a.shape_class + "-" + c.b.shape_class);
      for (const BackendOutcome& b : o.backends)
        if (!b.error.empty() && signature(o, b) == sig) {
          if (out) *out = o;
          return true;
        }
    } catch (const std::exception&) {
      // A candidate the loader rejects (a flat hull, say) is simply not simpler.
    }
    return false;
  };
  auto accept = [&](const ContactSample& c) {
    if (!keeps(c)) return false;
    r.sample = c;
    ++r.steps_accepted;
    return true;
  };

  // 1. Fewer points: only the hull's own vertices, then drop chunks of points (halves first).
  for (ExploreBody ContactSample::*body : {&ContactSample::a, &ContactSample::b}) {
    if ((r.sample.*body).shape_class == "box") continue;
    ContactSample c = r.sample;
    try {
      (c.*body).points = convex_hull((c.*body).points).vertices();
      if ((c.*body).points.size() < (r.sample.*body).points.size()) accept(c);
    } catch (const std::exception&) {
    }
    for (size_t chunk = (r.sample.*body).points.size() / 2; chunk >= 1; chunk /= 2) {
      for (size_t at = 0;
           at < (r.sample.*body).points.size() && (r.sample.*body).points.size() > 4;) {
        ContactSample d = r.sample;
        auto& p = (d.*body).points;
        const size_t end = std::min(at + chunk, p.size());
        if (p.size() - (end - at) < 4) break;
        p.erase(p.begin() + at, p.begin() + end);
        if (!accept(d)) at += chunk;
      }
      if (r.evaluations >= max_evaluations) break;
    }
  }
  // 2. A at the origin.
  {
    ContactSample c = r.sample;
    c.b.position -= c.a.position;
    c.a.position = Vec3::Zero();
    accept(c);
  }
  // 3. Rotations toward axis-aligned: none, then Euler angles rounded, coarsest grid first.
  const double grids_deg[] = {90, 45, 15, 5, 1, 0.1, 0.01, 0.001};
  for (ExploreBody ContactSample::*body : {&ContactSample::a, &ContactSample::b}) {
    ContactSample c = r.sample;
    (c.*body).use_degrees = true;
    (c.*body).rotation_deg = Vec3::Zero();
    if (accept(c)) continue;
    const Vec3 deg = euler_deg(build_orientation(r.sample.*body));
    for (double g : grids_deg) {
      ContactSample d = r.sample;
      (d.*body).use_degrees = true;
      (d.*body).rotation_deg = round_to(deg, g);
      if (accept(d)) break;
    }
  }
  // 4. Rounder positions, sizes and points, on grids relative to the smaller body's extent.
  const double small = std::min(extent(*build_shape(r.sample.a)), extent(*build_shape(r.sample.b)));
  const double unit = std::pow(10.0, std::floor(std::log10(small)));
  const double grids[] = {1, 0.5, 0.1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6};
  for (ExploreBody ContactSample::*body : {&ContactSample::a, &ContactSample::b}) {
    for (double g : grids) {
      ContactSample d = r.sample;
      (d.*body).position = round_to((d.*body).position, g * unit);
      if ((d.*body).position == (r.sample.*body).position || accept(d)) break;
    }
    for (double g : grids) {
      ContactSample d = r.sample;
      ExploreBody& e = d.*body;
      if (e.shape_class == "box") {
        e.box_size = round_to(e.box_size, g * unit);
        if (e.box_size.minCoeff() <= 0) continue;
      } else {
        for (Vec3& p : e.points) p = round_to(p, g * unit);
      }
      if (accept(d)) break;
    }
  }
  r.vertices_after = point_count(r.sample);
  if (!keeps(r.sample, &r.outcome)) {
    // The budget ran out before the final check: evaluate once more regardless of the budget.
    ++max_evaluations;
    keeps(r.sample, &r.outcome);
  }
  return r;
}

// ---------------------------------------------------------------------------------------------
// Reproduction through the harness

bool harness_reproduces(const std::string& scene_text, const std::string& path,
                        const BackendOutcome& b, std::string* detail) {
  const Scene scene = parse_scene(scene_text, path);
  HarnessOptions hopt;
  hopt.backends = b.backend;
  hopt.sweep = false;
  hopt.timing_budget_s = 0.0;  // one query each: no timing repeats
  const SceneEvaluation ev = evaluate_scene(scene, hopt);
  const std::vector<RigidBody> bodies = make_bodies(scene);
  const double size =
      std::min(2.0 * bounding_sphere(bodies[0]).radius, 2.0 * bounding_sphere(bodies[1]).radius);
  auto metric = [&](const std::string& name) -> double {
    for (const Metric& m : ev.metrics)
      if (m.backend == b.backend && m.name == name) return m.value;
    return -1.0;
  };
  auto said = [&](const std::string& what) {
    for (const std::string& s : ev.disagreements)
      if (s.rfind(b.backend + " on ", 0) == 0 && s.find(what) != std::string::npos) return true;
    return false;
  };
  const std::string status = ev.json["backends"].contains(b.backend)
                                 ? ev.json["backends"][b.backend]["status"].get<std::string>()
                                 : "missing";
  bool ok = false;
  std::ostringstream d;
  if (b.error == "error" || b.error == "timeout") {
    ok = status == b.error;
    d << "status " << status;
  } else if (b.error == "misses") {
    ok = said("misses a contact");
    d << (ok ? "misses a contact" : "no missed contact");
  } else if (b.error == "false_contact") {
    ok = said("reports a contact where there is none");
    d << (ok ? "reports a contact where there is none" : "no false contact");
  } else if (b.error == "normal") {
    ok = metric("normal_err_deg") > kMarkAngleDeg;
    d << "normal_err_deg " << metric("normal_err_deg");
  } else if (b.error == "depth") {
    ok = metric("depth_err") > kMarkDepthRel * size;
    d << "depth_err " << metric("depth_err") << " m (size " << size << " m)";
  } else if (b.error == "point") {
    ok = metric("point_err_rel") > kMarkDepthRel;
    d << "point_err_rel " << metric("point_err_rel");
  } else if (b.error == "impulse" || b.error == "spin" || b.error == "missed") {
    // Impact kind: the harness's velocity error against the scene's [expect] closed form.
    ok = metric("velocity_err_ke") > kMarkVelocityErr;
    d << "velocity_err_ke " << metric("velocity_err_ke");
  } else if ((b.error == "position" || b.error == "turn") && status == "ok") {
    // Landing kind: the harness's final state of the first body against the scene's [expect]
    // position (horizontal distance) and against its own start orientation (turn).
    const Json& fin = ev.json["backends"][b.backend]["bodies"][bodies[0].name]["final"];
    const Json& p = fin["position"];
    const Json& q = fin["orientation"];
    const Vec3 want =
        scene.expect && !scene.expect->bodies.empty() && scene.expect->bodies.front().position
            ? *scene.expect->bodies.front().position
            : Vec3::Zero();
    const double position_err =
        std::hypot(p[0].get<double>() - want.x(), p[1].get<double>() - want.y());
    const double turn = rotation_angle(
        bodies[0].orientation,
        Quat(q[0].get<double>(), q[1].get<double>(), q[2].get<double>(), q[3].get<double>()));
    ok = b.error == "turn" ? !(turn <= kLandingTurnMark) : !(position_err <= kLandingPositionMark);
    d << "final position off by " << position_err << " m, turned by " << turn << " rad";
  } else if (b.error == "position" || b.error == "turn") {
    d << "status " << status;
  }
  if (detail) *detail = d.str();
  return ok;
}

// ---------------------------------------------------------------------------------------------
// Impact kind

namespace {

// Torque-free rotation: from orientation q, angular momentum L (world, constant) over time t;
// omega = R I^-1 R^T L, RK4 on the quaternion with steps of 1e-5 s (|omega h| < 1e-3 here, so
// the error is below 1e-12 per step; the closed form is the exact flight, not a library's).
Quat free_rotation(const Mat3& inverse_inertia_body, Quat q, const Vec3& L, double t) {
  if (t <= 0 || L.norm() == 0) return q;
  const int n = std::max(1, static_cast<int>(std::ceil(t / 1e-5)));
  const double h = t / n;
  auto deriv = [&](const Eigen::Vector4d& c) {
    const Quat qq = Quat(c[3], c[0], c[1], c[2]).normalized();
    const Mat3 R = qq.toRotationMatrix();
    const Vec3 w = R * inverse_inertia_body * R.transpose() * L;
    const Quat d = Quat(0.0, w.x(), w.y(), w.z()) * qq;
    return Eigen::Vector4d(0.5 * d.x(), 0.5 * d.y(), 0.5 * d.z(), 0.5 * d.w());
  };
  Eigen::Vector4d c = q.coeffs();
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector4d k1 = deriv(c), k2 = deriv(c + 0.5 * h * k1), k3 = deriv(c + 0.5 * h * k2),
                          k4 = deriv(c + h * k3);
    c += h / 6.0 * (k1 + 2 * k2 + 2 * k3 + k4);
    c.normalize();
  }
  return Quat(c[3], c[0], c[1], c[2]).normalized();
}

// A body of a dynamics sample (impact, landing): its shape and pose, mass, and either its
// velocity or `static = true`.
std::string dynamic_body_text(const ExploreBody& e, const std::string& name, double mass,
                              const Vec3& velocity, bool is_static) {
  std::string t = body_text(e, name);
  std::ostringstream o;
  o << "mass = " << num(mass) << "\n";
  if (is_static)
    o << "static = true\n";
  else
    o << "velocity = " << vec(velocity) << "\n";
  return t + o.str();
}

std::string impact_text(const ImpactSample& s, const std::string& header, const std::string& tail) {
  std::ostringstream o;
  o << header;
  o << "description = \"rbx explore impact seed " << s.seed << " sample " << s.index << " ("
    << (s.b_static ? "on a static box" : "two free bodies") << ", e = " << num(s.restitution)
    << ")\"\n";
  o << "checks = [\"impulse\"]\n\n[sim]\ndt = " << num(s.dt) << "\nduration = " << num(s.duration)
    << "\nrestitution = " << num(s.restitution)
    << "\nfriction = 0.0\ngravity = [0.0, 0.0, 0.0]\n\n";
  o << dynamic_body_text(s.a, "A", s.mass_a, s.velocity_a, false) << "\n"
    << dynamic_body_text(s.b, "B", s.mass_b, s.velocity_b, s.b_static);
  if (!tail.empty()) o << "\n" << tail;
  return o.str();
}

// Scene bodies moved along their velocities by t (translation only: no spin before the impact).
std::vector<RigidBody> at_time(std::vector<RigidBody> bodies, double t) {
  for (RigidBody& b : bodies)
    if (!b.is_static) b.position += b.velocity * t;
  return bodies;
}

int impact_points(const ImpactSample& s) {
  return (s.a.shape_class == "box" ? 8 : static_cast<int>(s.a.points.size())) + 8;
}

// Runs each named dynamics backend on `scene` (those without dynamics, or unsupported, left
// out) and appends one outcome each to `out`: a status error, or a run returning the wrong
// number of final states, as `error`; a finished run measured and classified by `judge`.
// Backends are looked up in `table` (null: the registry).
void run_dynamics_subjects(
    const Scene& scene, const std::vector<std::string>& names, const DynamicsOptions& options,
    const std::vector<Backend>* table, SampleOutcome& out,
    const std::function<void(BackendOutcome&, const DynamicsResult&)>& judge) {
  for (const std::string& name : names) {
    const Backend* be = find_backend(name, table);
    if (!be || !be->dynamics) continue;
    DynamicsResult run = run_dynamics_isolated(*be, scene, options).result;
    if (run.status == Status::Unsupported) continue;
    BackendOutcome o;
    o.backend = name;
    if (run.status == Status::Ok && run.finals.size() != scene.bodies.size()) {
      run.status = Status::Error;
      run.message = "returned " + std::to_string(run.finals.size()) + " final states";
    }
    if (run.status == Status::Error || run.status == Status::Timeout) {
      o.error = to_string(run.status);
      o.message = run.message;
    } else {
      o.measured = true;
      judge(o, run);
    }
    out.backends.push_back(o);
  }
}

// Greedy shrinking of a closed-form sample's design (impact and landing kinds): a candidate is
// realized (its closed form and scene rebuilt) and kept while `backend` still shows signature
// `sig` on it; at most `max_evaluations` tries.
template <class Sample>
struct DesignShrinker {
  Sample sample;  // the simplest kept so far
  std::vector<std::string> names;
  std::string sig;
  int max_evaluations = 0, evaluations = 0, steps_accepted = 0;
  bool (*realize)(Sample&) = nullptr;
  SampleOutcome (*evaluate)(const Sample&, const std::vector<std::string>&) = nullptr;

  // True (and c, realized, becomes the sample) when c still shows the signature.
  bool keeps(Sample c, SampleOutcome* out = nullptr) {
    if (evaluations >= max_evaluations) return false;
    ++evaluations;
    try {
      if (!realize(c)) return false;
      const SampleOutcome o = evaluate(c, names);
      for (const BackendOutcome& b : o.backends)
        if (!b.error.empty() && signature(o, b) == sig) {
          if (out) *out = o;
          sample = c;
          return true;
        }
    } catch (const std::exception&) {
      // A candidate the loader rejects is simply not simpler.
    }
    return false;
  }
  // keeps(c), counted as a simplification when it does.
  bool accept(const Sample& c) {
    if (!keeps(c)) return false;
    ++steps_accepted;
    return true;
  }
  // The kept sample evaluated once more, past the budget: what is reported for it.
  SampleOutcome finish() {
    SampleOutcome o;
    ++max_evaluations;
    const Sample last = sample;
    keeps(last, &o);
    return o;
  }
};

}  // namespace

bool realize_impact(ImpactSample& s) {
  s.text.clear();
  if (s.b_static) s.velocity_b = Vec3::Zero();
  // 1. Poses at the contact time: B's box centre at the origin, A's lowest vertex along B's face
  //    normal put on the chosen point of that face.
  ImpactSample c = s;
  c.a.position = Vec3::Zero();
  c.b.position = Vec3::Zero();
  std::vector<RigidBody> bodies;
  try {
    bodies = make_bodies(parse_scene(impact_text(c, "", ""), "explore.toml"));
  } catch (const std::exception&) {
    return false;
  }
  const RigidBody& A0 = bodies[0];
  const RigidBody& B0 = bodies[1];
  const int axis = s.face % 3;
  const double sign = s.face < 3 ? 1.0 : -1.0;
  Vec3 local_n = Vec3::Zero();
  local_n[axis] = sign;
  const Vec3 n = B0.orientation * local_n;  // from B toward A
  Vec3 local_c = Vec3::Zero();
  local_c[axis] = 0.5 * sign * s.b.box_size[axis];
  local_c[(axis + 1) % 3] = s.face_u * s.b.box_size[(axis + 1) % 3];
  local_c[(axis + 2) % 3] = s.face_v * s.b.box_size[(axis + 2) % 3];
  const Vec3 point = B0.pose().apply(local_c);
  const double size_a = extent(*A0.shape);
  const double size = std::min(size_a, extent(*B0.shape));
  int lowest = -1;
  double low = 1e300, second = 1e300;
  for (int i = 0; i < static_cast<int>(A0.shape->vertices().size()); ++i) {
    const double d = A0.world_vertex(i).dot(n);
    if (d < low) {
      second = low;
      low = d;
      lowest = i;
    } else if (d < second) {
      second = d;
    }
  }
  // One vertex clearly lowest (3 % of A's size below the next): a single contact point that
  // stays single over the step a backend takes to see it.
  if (lowest < 0 || second - low < 0.03 * size_a) return false;
  // The point inside the face by a margin (fractions below 0.4 of the face).
  if (std::abs(s.face_u) > 0.4 || std::abs(s.face_v) > 0.4) return false;
  const Vec3 shift = point - A0.world_vertex(lowest);
  // Approaching along the normal, by at least a tenth of the relative speed.
  const Vec3 v_rel = s.velocity_a - s.velocity_b;
  if (!(v_rel.dot(n) < -0.1 * v_rel.norm())) return false;
  // 2. Back along the velocities by the contact time.
  s.a.position = shift - s.velocity_a * s.contact_time;
  s.b.position = -s.velocity_b * s.contact_time;
  s.phase = s.contact_time / s.dt - std::floor(s.contact_time / s.dt);
  const std::string body_text0 = impact_text(s, "", "");
  try {
    bodies = make_bodies(parse_scene(body_text0, "explore.toml"));
  } catch (const std::exception&) {
    return false;
  }
  const RigidBody& A = bodies[0];
  const RigidBody& B = bodies[1];
  // 3. The exact oracle: separated just before the contact time, one point just after it.
  const double approach = -v_rel.dot(n);
  {
    const auto before = at_time(bodies, s.contact_time - 1e-3 * s.dt);
    const SatResult sb =
        sat_query(*before[0].shape, before[0].pose(), *before[1].shape, before[1].pose());
    if (sb.touching && sb.depth >= 0) return false;
  }
  const auto after = at_time(bodies, s.contact_time + 1e-7 * size / approach);
  const SatResult sat =
      sat_query(*after[0].shape, after[0].pose(), *after[1].shape, after[1].pose());
  if (!sat.touching || sat.manifold.empty() || sat.normal.dot(n) < 1.0 - 1e-9) return false;
  Vec3 p = Vec3::Zero();
  for (const Vec3& m : sat.manifold) p += m;
  p /= static_cast<double>(sat.manifold.size());
  for (const Vec3& m : sat.manifold)
    if ((m - p).norm() > 1e-6 * size) return false;  // not a single point
  const Vec3 normal = sat.normal;
  // 4. The closed form: single-point impulse with restitution e at exact's point and normal
  //    (seed corrections: world-frame inverse inertia, velocity of the point).
  const Vec3 ra = p - after[0].position, rb = p - after[1].position;
  const Mat3 ia = A.inverse_inertia_world();
  const Mat3 ib = B.is_static ? Mat3::Zero() : B.inverse_inertia_world();
  const double inv_mb = B.is_static ? 0.0 : 1.0 / B.mass;
  const double k = 1.0 / A.mass + inv_mb + normal.dot((ia * ra.cross(normal)).cross(ra)) +
                   normal.dot((ib * rb.cross(normal)).cross(rb));
  const double vn = (A.velocity - B.velocity).dot(normal);
  const double j = -(1.0 + s.restitution) * vn / k;
  const Vec3 va = A.velocity + j / A.mass * normal, wa = ia * ra.cross(j * normal);
  const Vec3 vb = B.velocity - j * inv_mb * normal, wb = -(ib * rb.cross(j * normal));
  const Vec3 La = A.inertia_world() * wa,
             Lb = B.is_static ? Vec3::Zero() : Vec3(B.inertia_world() * wb);
  // 5. Free flight to the end: no second contact (checked at 20 times), final spin from L.
  const double flight = s.duration - s.contact_time;
  Quat qa = A.orientation, qb = B.orientation;
  for (int step = 1; step <= 20; ++step) {
    const double t = flight * step / 20.0;
    RigidBody a2 = after[0], b2 = after[1];
    a2.position += va * t;
    a2.orientation = free_rotation(A.inverse_inertia_body, A.orientation, La, t);
    if (!B.is_static) {
      b2.position += vb * t;
      b2.orientation = free_rotation(B.inverse_inertia_body, B.orientation, Lb, t);
    }
    const SatResult r = sat_query(*a2.shape, a2.pose(), *b2.shape, b2.pose());
    if (r.touching || r.depth > -1e-6 * size) return false;
    qa = a2.orientation;
    qb = b2.orientation;
  }
  auto spin = [](const RigidBody& b, const Quat& q, const Vec3& L) {
    const Mat3 R = q.toRotationMatrix();
    return Vec3(R * b.inverse_inertia_body * R.transpose() * L);
  };
  s.expect_velocity[0] = va;
  s.expect_angular_velocity[0] = spin(A, qa, La);
  s.expect_angular_momentum[0] = La;
  s.expect_velocity[1] = vb;
  s.expect_angular_velocity[1] = B.is_static ? Vec3::Zero() : spin(B, qb, Lb);
  s.expect_angular_momentum[1] = Lb;
  // 6. The scene with its derivation and [expect].
  std::ostringstream d;
  d << "# Closed form (rbx explore, impact kind): no spin before the impact, so the contact\n"
       "# pose is the start pose moved along the velocities: first contact at t = "
    << num(s.contact_time) << " s,\n# phase " << num(s.phase)
    << " of its step. The exact oracle's contact, one point (vertex of A on a face of B):\n"
    << "#   p = " << vec(p) << ", n = " << vec(normal) << " (from B toward A)\n"
    << "# j = -(1 + e) (v_rel . n) / (1/mA + 1/mB + n.((IA^-1 (rA x n)) x rA) + same for B)\n"
    << "#   = " << num(j) << " N s (v_rel . n = " << num(vn) << " m/s)\n"
    << "# v' = v + j n / m, w' = I^-1 (r x j n) (B: minus); after it, torque-free flight to t = "
    << num(s.duration)
    << " s\n# (angular momentum kept, w = R I^-1 R^T L, integrated by RK4 at "
       "1e-5 s); no second contact\n# (the exact oracle at 20 times of the flight).\n";
  std::ostringstream x;
  char buf[200];
  x << "[expect]\n# The closed form is exact to round-off; 1e-3 of the speed is the harness's mark "
       "of a\n# clear velocity disagreement (0.1 % in the energy norm): below it, a "
       "deviation.\n";
  std::snprintf(buf, sizeof buf, "tolerance = %.3g\n", 1e-3 * std::max(1e-9, v_rel.norm()));
  x << buf;
  x << "[expect.body.A]\nvelocity = " << vec(va)
    << "\nangular_velocity = " << vec(s.expect_angular_velocity[0]) << "\n";
  if (!B.is_static)
    x << "[expect.body.B]\nvelocity = " << vec(vb)
      << "\nangular_velocity = " << vec(s.expect_angular_velocity[1]) << "\n";
  s.derivation = d.str();
  s.text = impact_text(s, "", s.derivation + x.str());
  return true;
}

ImpactSample make_impact_sample(uint64_t seed, uint64_t index) {
  SampleRng r(seed, index);
  for (int attempt = 0; attempt < 30; ++attempt) {
    ImpactSample s;
    s.seed = seed;
    s.index = index;
    s.b_static = r.uniform() < 0.4;
    const double scale = std::pow(10.0, r.uniform(-0.3, 0.3));
    // A: a box or a hull of 4 to 60 points (a sliver's lowest vertex is rarely unique).
    do {
      s.a = random_body(r, scale);
    } while (s.a.shape_class == "sliver" || s.a.points.size() > 60);
    s.a.orientation = r.rotation();
    // B: a box, a slab under A when static, else up to 3 times A's size.
    s.b.shape_class = "box";
    if (s.b_static)
      s.b.box_size = Vec3(4 * scale, 4 * scale, scale);
    else
      for (int k = 0; k < 3; ++k) s.b.box_size[k] = scale * r.uniform(1.0, 3.0);
    s.b.orientation = r.rotation();
    s.mass_a = std::pow(10.0, r.uniform(-0.5, 0.5));
    s.mass_b = s.b_static ? 1.0 : std::pow(10.0, r.uniform(-0.5, 0.5));
    s.restitution = r.uniform(0.2, 1.0);
    s.dt = 1e-3;
    s.face = s.b_static ? 2 : r.integer(0, 5);
    s.face_u = r.uniform(-0.3, 0.3);
    s.face_v = r.uniform(-0.3, 0.3);
    // Relative velocity: against the face normal, tilted up to 30 degrees; 0.5 to 3 m/s.
    Vec3 local_n = Vec3::Zero();
    local_n[s.face % 3] = s.face < 3 ? 1.0 : -1.0;
    const Vec3 n = s.b.orientation.normalized() * local_n;
    const Vec3 t = n.cross(r.direction()).normalized();
    const double tilt = r.uniform(0.0, 30.0) * M_PI / 180.0;
    const Vec3 v_rel = r.uniform(0.5, 3.0) * (-std::cos(tilt) * n + std::sin(tilt) * t);
    if (s.b_static) {
      s.velocity_a = v_rel;
    } else {
      // Centre-of-mass velocity up to 1 m/s, split by the masses.
      const Vec3 vcm = r.uniform(0.0, 1.0) * r.direction();
      const double m = s.mass_a + s.mass_b;
      s.velocity_a = vcm + v_rel * (s.mass_b / m);
      s.velocity_b = vcm - v_rel * (s.mass_a / m);
    }
    // First contact 2 to 5 steps ahead, at a random phase of its step; then at least 50 ms of
    // flight, to a whole number of steps (a scene's duration is one).
    s.contact_time = (r.integer(2, 5) + r.uniform(0.02, 0.98)) * s.dt;
    s.duration = std::ceil((s.contact_time + 0.05) / s.dt) * s.dt;
    if (realize_impact(s)) return s;
  }
  throw std::runtime_error("no single-point impact found in 30 attempts");
}

SampleOutcome evaluate_impact_sample(const ImpactSample& s, const std::vector<std::string>& names,
                                     const std::vector<Backend>* table) {
  SampleOutcome out;
  out.index = s.index;
  out.pose_class = s.b_static ? "static" : "free";
  out.shapes = s.a.shape_class + "-" + (s.b_static ? "static" : "box");
  out.feature = "vertex_face";
  out.touching = true;
  out.phase = s.phase;
  const Scene scene = parse_scene(s.text, "explore.toml");
  const std::vector<RigidBody> inputs = make_bodies(scene);
  double e0 = 0.0;
  for (const RigidBody& b : inputs)
    if (!b.is_static) e0 += 0.5 * b.mass * b.velocity.squaredNorm();
  std::vector<std::optional<RefState>> ref(2);
  double e_ref = 0.0;
  for (int i = 0; i < 2; ++i) {
    if (inputs[i].is_static) continue;
    ref[i] = RefState{s.expect_velocity[i], s.expect_angular_velocity[i]};
    e_ref += 0.5 * inputs[i].mass * s.expect_velocity[i].squaredNorm() +
             0.5 * s.expect_angular_velocity[i].dot(s.expect_angular_momentum[i]);
  }
  if (e_ref < 1e-12 * e0) e_ref = e0;
  run_dynamics_subjects(
      scene, names, DynamicsOptions{0.0, 0}, table, out,
      [&](BackendOutcome& o, const DynamicsResult& run) {
        o.velocity_err_ke = ke_norm_error(inputs, run.finals, ref, e0);
        // The same norm on momenta: p and L about the COM are what the impulse sets and the flight
        // keeps, so this error is the impulse's alone, whatever the library's free rotation does.
        double num_p = 0.0;
        for (int i = 0; i < 2; ++i) {
          if (inputs[i].is_static) continue;
          const BodyFinal& f = run.finals[i];
          const Mat3 R = f.orientation.toRotationMatrix();
          const Mat3 inv_i = R * inputs[i].inverse_inertia_body * R.transpose();
          const Mat3 inertia = R * inputs[i].inertia_body * R.transpose();
          const Vec3 dp = inputs[i].mass * (f.velocity - s.expect_velocity[i]);
          const Vec3 dl = inertia * f.angular_velocity - s.expect_angular_momentum[i];
          num_p += dp.squaredNorm() / inputs[i].mass + dl.dot(inv_i * dl);
        }
        o.momentum_err_ke = std::sqrt(num_p / (2.0 * e_ref));
        const double v0 = s.velocity_a.norm();
        if ((run.finals[0].velocity - s.velocity_a).norm() <= 1e-9 * v0 &&
            run.finals[0].angular_velocity.norm() <= 1e-9 * v0 / extent(*inputs[0].shape))
          o.error = "missed";  // A flew on untouched
        else if (!(o.momentum_err_ke <= kMarkVelocityErr))
          o.error = "impulse";
        else if (!(o.velocity_err_ke <= kMarkVelocityErr))
          o.error = "spin";  // the impulse is right; the free rotation after it is not
      });
  return out;
}

ImpactShrinkResult shrink_impact(const ImpactSample& start, const std::string& backend,
                                 const std::string& sig, int max_evaluations) {
  DesignShrinker<ImpactSample> k;
  k.sample = start;
  k.names = {backend};
  k.sig = sig;
  k.max_evaluations = max_evaluations;
  k.realize = realize_impact;
  k.evaluate = [](const ImpactSample& s, const std::vector<std::string>& names) {
    return evaluate_impact_sample(s, names);
  };
  // 1. Fewer points of A: its hull's own vertices, then chunks (halves first).
  if (k.sample.a.shape_class != "box") {
    ImpactSample c = k.sample;
    try {
      c.a.points = convex_hull(c.a.points).vertices();
      if (c.a.points.size() < k.sample.a.points.size()) k.accept(c);
    } catch (const std::exception&) {
    }
    for (size_t chunk = k.sample.a.points.size() / 2; chunk >= 1; chunk /= 2) {
      for (size_t at = 0; at < k.sample.a.points.size() && k.sample.a.points.size() > 4;) {
        ImpactSample d = k.sample;
        auto& p = d.a.points;
        const size_t end = std::min(at + chunk, p.size());
        if (p.size() - (end - at) < 4) break;
        p.erase(p.begin() + at, p.begin() + end);
        if (!k.accept(d)) at += chunk;
      }
      if (k.evaluations >= k.max_evaluations) break;
    }
  }
  // 2. Round numbers: e, masses, the point on the face, velocities.
  for (double e : {1.0, 0.5}) {
    ImpactSample c = k.sample;
    c.restitution = e;
    if (k.accept(c)) break;
  }
  {
    ImpactSample c = k.sample;
    c.mass_a = 1.0;
    c.mass_b = 1.0;
    k.accept(c);
  }
  {
    ImpactSample c = k.sample;
    c.face_u = c.face_v = 0.0;
    if (!k.accept(c)) {
      c.face_u = std::round(k.sample.face_u * 10) / 10;
      c.face_v = std::round(k.sample.face_v * 10) / 10;
      k.accept(c);
    }
  }
  for (double g : {0.5, 0.1, 0.01}) {
    ImpactSample c = k.sample;
    c.velocity_a = round_to(c.velocity_a, g);
    c.velocity_b = round_to(c.velocity_b, g);
    if (k.accept(c)) break;
  }
  // 3. Rotations toward axis-aligned, coarsest grid first.
  const double grids_deg[] = {90, 45, 15, 5, 1, 0.1};
  for (ExploreBody ImpactSample::*body : {&ImpactSample::a, &ImpactSample::b}) {
    const Vec3 deg = euler_deg(build_orientation(k.sample.*body));
    for (double g : grids_deg) {
      ImpactSample d = k.sample;
      (d.*body).use_degrees = true;
      (d.*body).rotation_deg = round_to(deg, g);
      if (k.accept(d)) break;
    }
  }
  ImpactShrinkResult r;
  r.vertices_before = impact_points(start);
  r.vertices_after = impact_points(k.sample);
  r.outcome = k.finish();
  r.sample = k.sample;
  r.steps_accepted = k.steps_accepted;
  r.evaluations = k.evaluations;
  return r;
}

// ---------------------------------------------------------------------------------------------
// Landing kind

namespace {

constexpr double kGravity = 9.81;  // m/s^2, down (-z)
// Drawn sizes keep mu sz at most this fraction of min(sx, sy): a fifth clear of tipping
// (mu sz = min(sx, sy)), so that a turn is the backend's, not the edge of the closed form.
constexpr double kNoTipMargin = 0.8;
// After the closed-form rest, the run goes on this long (s): a backend's rest is seen at rest.
constexpr double kSettleTime = 0.1;
// Below this horizontal speed (m/s) a body counts as at rest when the time to rest is measured:
// at the least deceleration drawn (mu g = 0.98 m/s^2) the slide takes about 1 ms (a step) from
// this speed to rest, so the measured time is late by about one step at most.
constexpr double kRestSpeed = 1e-3;

// The box and the floor of a landing as scene bodies (box first: A, then B as impact).
ExploreBody landing_box(const LandingSample& s) {
  ExploreBody e;
  e.shape_class = "box";
  e.box_size = s.size;
  e.position = s.start_position;
  e.use_degrees = true;
  e.rotation_deg = Vec3(0.0, 0.0, s.yaw_deg);
  return e;
}

// A floor slab 1 m thick, top at z = 0, whole metres wide, reaching at least 0.5 m past the
// box's whole path (from the origin to its rest).
ExploreBody landing_floor(const LandingSample& s, double travel) {
  ExploreBody e;
  e.shape_class = "box";
  const double reach = std::ceil(travel + 0.5 * std::hypot(s.size.x(), s.size.y()) + 0.5);
  e.box_size = Vec3(2.0 * reach, 2.0 * reach, 1.0);
  e.position = Vec3(0.0, 0.0, -0.5);
  return e;
}

// Time (s) after which the first body's horizontal speed stays below kRestSpeed in the run's
// samples; `end` when it never does.
double measured_rest_time(const std::vector<StateSample>& samples, double end) {
  double t = samples.empty() ? end : 0.0;
  for (size_t k = 0; k < samples.size(); ++k)
    if (!(samples[k].bodies[0].velocity.head<2>().norm() < kRestSpeed))
      t = k + 1 < samples.size() ? samples[k + 1].time : end;
  return t;
}

}  // namespace

bool realize_landing(LandingSample& s) {
  s.text.clear();
  const double mu = s.friction, g = kGravity;
  const double footprint = std::min(s.size.x(), s.size.y());
  if (!(s.size.minCoeff() > 0 && s.mass > 0 && s.fall_speed > 0 && s.slide_speed >= 0 && mu > 0 &&
        s.dt > 0 && s.steps_before >= 1 && s.phase >= 0.02 && s.phase <= 0.98))
    return false;
  if (!(mu * s.size.z() <= kNoTipMargin * footprint)) return false;  // could tip
  // 1. Free fall to the first touch at t_c = (k + phase) dt: the base starts h0 above the floor.
  const double tc = (s.steps_before + s.phase) * s.dt;
  s.contact_time = tc;
  s.drop = s.fall_speed * tc + 0.5 * g * tc * tc;
  // 2. The landing (e = 0): the normal impulse stops the fall; the friction impulse is Coulomb's,
  //    mu J while the base slips through it, else what stops the slip.
  const double vn = s.fall_speed + g * tc;
  s.normal_impulse = s.mass * vn;
  s.slides = s.slide_speed > mu * vn;
  s.friction_impulse = s.slides ? mu * s.normal_impulse : s.mass * s.slide_speed;
  s.speed_after = s.slides ? s.slide_speed - mu * vn : 0.0;
  // 3. The slide: deceleration mu g to rest, then static friction holds.
  s.rest_time = tc + s.speed_after / (mu * g);
  const double before = s.slide_speed * tc;
  const double after = s.speed_after * s.speed_after / (2.0 * mu * g);
  s.duration = std::ceil((s.rest_time + kSettleTime) / s.dt) * s.dt;
  const double heading = s.heading_deg * M_PI / 180.0;
  const Vec3 dir(std::cos(heading), std::sin(heading), 0.0);
  s.start_position = Vec3(0.0, 0.0, 0.5 * s.size.z() + s.drop);
  s.velocity = s.slide_speed * dir - Vec3(0.0, 0.0, s.fall_speed);
  s.expect_position = (before + after) * dir + Vec3(0.0, 0.0, 0.5 * s.size.z());

  std::ostringstream o;
  o << "description = \"rbx explore landing seed " << s.seed << " sample " << s.index << " ("
    << (s.slides ? "slides" : "sticks") << " after the landing, mu = " << num(mu) << ")\"\n";
  o << "checks = [\"impulse\"]\n\n[sim]\ndt = " << num(s.dt) << "\nduration = " << num(s.duration)
    << "\ngravity = " << vec(Vec3(0.0, 0.0, -g)) << "\nrestitution = 0.0\nfriction = " << num(mu)
    << "\n\n";
  o << dynamic_body_text(landing_box(s), "box", s.mass, s.velocity, false) << "\n"
    << dynamic_body_text(landing_floor(s, before + after), "floor", 1.0, Vec3::Zero(), true);
  o << "\n# Closed form (rbx explore, landing kind; g = " << num(g) << " m/s^2, m = " << num(s.mass)
    << " kg, mu = " << num(mu)
    << ").\n# Fall: the base starts h0 = vz t_c + g t_c^2 / 2 = " << num(s.drop)
    << " m above the floor, so it first\n# touches at t_c = (k + phase) dt = " << num(tc)
    << " s (k = " << s.steps_before << ", phase " << num(s.phase) << "), flat (no spin).\n"
    << "# Landing, e = 0: vn = vz + g t_c = " << num(vn)
    << " m/s stopped, J = m vn = " << num(s.normal_impulse)
    << " N s.\n# Friction impulse min(mu J, m |v_h|) = " << num(s.friction_impulse)
    << " N s against v_h (|v_h| = " << num(s.slide_speed) << " m/s, heading " << num(s.heading_deg)
    << " deg):\n# "
    << (s.slides ? "|v_h| > mu vn, the base slides on at |v_h'| = |v_h| - mu vn = "
                 : "|v_h| <= mu vn, the landing stops the slip: |v_h'| = ")
    << num(s.speed_after) << " m/s.\n# Slide: decelerating at mu g to rest at t = t_c + |v_h'| / "
    << "(mu g) = " << num(s.rest_time) << " s, over\n# |v_h'|^2 / (2 mu g) = " << num(after)
    << " m, after |v_h| t_c = " << num(before) << " m before the landing.\n"
    << "# No turn: friction's moment about the centre, mu N sz / 2, is balanced by the pressure\n"
    << "# shifting toward the front edge, possible while mu sz < min(sx, sy) (here "
    << num(mu * s.size.z()) << " < " << num(footprint) << ").\n"
    << "# At t = duration: at rest, centre " << vec(s.expect_position)
    << ", orientation unchanged.\n";
  o << "[expect]\nknown_failure = \"custom-seed: the seed omits friction and resting contact "
       "(seed correction 12 (what the seed admits it lacks)): the box slides on, or sinks\"\n"
       "# 1 mm (position; the explore mark), 1e-3 m/s and rad/s (at rest): a time-stepped slide\n"
       "# falls short of the integral by at most |v_h'| dt / 2 = "
    << num(0.5 * s.speed_after * s.dt) << " m.\ntolerance = " << num(kLandingPositionMark)
    << "\n[expect.body.box]\nposition = " << vec(s.expect_position)
    << "\nvelocity = [0.0, 0.0, 0.0]\nangular_velocity = [0.0, 0.0, 0.0]\n";
  s.text = o.str();
  return true;
}

LandingSample make_landing_sample(uint64_t seed, uint64_t index) {
  SampleRng r(seed, index);
  for (int attempt = 0; attempt < 10; ++attempt) {
    LandingSample s;
    s.seed = seed;
    s.index = index;
    s.friction = r.uniform(0.1, 1.0);
    // Footprint sides 0.2 to 2 m; height up to 3 footprints, kept clear of tipping.
    s.size.x() = std::pow(10.0, r.uniform(-0.7, 0.3));
    s.size.y() = std::pow(10.0, r.uniform(-0.7, 0.3));
    const double footprint = std::min(s.size.x(), s.size.y());
    s.size.z() = footprint * r.uniform(0.1, std::min(3.0, kNoTipMargin / s.friction));
    s.mass = std::pow(10.0, r.uniform(-1.0, 1.0));
    s.yaw_deg = r.uniform(0.0, 90.0);  // a box's yaw repeats every 90 degrees
    // Slide speeds to 1.5 m/s (kLandingPositionMark says why), falls of 0.2 to 2 m/s.
    s.slide_speed = r.uniform(0.05, 1.5);
    s.heading_deg = r.uniform(0.0, 360.0);
    s.fall_speed = r.uniform(0.2, 2.0);
    s.dt = 1e-3;
    s.steps_before = r.integer(2, 5);
    s.phase = r.uniform(0.02, 0.98);
    if (realize_landing(s)) return s;
  }
  throw std::runtime_error("no valid landing found in 10 attempts");
}

SampleOutcome evaluate_landing_sample(const LandingSample& s,
                                      const std::vector<std::string>& names) {
  SampleOutcome out;
  out.index = s.index;
  out.pose_class = "landing";
  out.shapes = "box-floor";
  out.feature = s.slides ? "slides" : "sticks";
  out.touching = true;
  out.phase = s.phase;
  const Scene scene = parse_scene(s.text, "explore.toml");
  const std::vector<RigidBody> inputs = make_bodies(scene);
  const double e0 = 0.5 * inputs[0].mass * inputs[0].velocity.squaredNorm();
  // At rest at the end: the KE norm falls back on the initial kinetic energy.
  const std::vector<std::optional<RefState>> ref = {RefState{Vec3::Zero(), Vec3::Zero()},
                                                    std::nullopt};
  // Every step sampled: the time to rest is read from the samples.
  run_dynamics_subjects(scene, names, DynamicsOptions{0.0, 1}, nullptr, out,
                        [&](BackendOutcome& o, const DynamicsResult& run) {
                          const BodyFinal& f = run.finals[0];
                          o.position_err_m = (f.position - s.expect_position).head<2>().norm();
                          o.turn_rad = rotation_angle(inputs[0].orientation, f.orientation);
                          o.velocity_err_ke = ke_norm_error(inputs, run.finals, ref, e0);
                          o.rest_time_err_s =
                              std::abs(measured_rest_time(run.samples, s.duration) - s.rest_time);
                          if (!(o.turn_rad <= kLandingTurnMark))
                            o.error = "turn";
                          else if (!(o.position_err_m <= kLandingPositionMark))
                            o.error = "position";
                        });
  return out;
}

LandingShrinkResult shrink_landing(const LandingSample& start, const std::string& backend,
                                   const std::string& sig, int max_evaluations) {
  DesignShrinker<LandingSample> k;
  k.sample = start;
  k.names = {backend};
  k.sig = sig;
  k.max_evaluations = max_evaluations;
  k.realize = realize_landing;
  k.evaluate = evaluate_landing_sample;
  // Each design number set to `first`, else toward rounder values, coarsest grid first; a grid
  // that leaves it as it is, or is kept, ends that number's search.
  auto round_down = [&k](double LandingSample::*field, double first,
                         std::initializer_list<double> grids) {
    LandingSample c = k.sample;
    c.*field = first;
    if (c.*field == k.sample.*field || k.accept(c)) return;
    for (double g : grids) {
      LandingSample c = k.sample;
      c.*field = round_to(c.*field, g);
      if (c.*field == k.sample.*field || k.accept(c)) break;
    }
  };
  // 1. Unit mass, no yaw, a slide along x (else an axis), the first touch two steps ahead.
  round_down(&LandingSample::mass, 1.0, {});
  round_down(&LandingSample::yaw_deg, 0.0, {90, 45, 15, 5, 1});
  round_down(&LandingSample::heading_deg, 0.0, {90, 45, 15, 5, 1});
  {
    LandingSample c = k.sample;
    c.steps_before = 2;
    if (c.steps_before != k.sample.steps_before) k.accept(c);
  }
  // 2. Rounder mu, sizes, speeds and phase.
  round_down(&LandingSample::friction, 0.5, {0.1, 0.05, 0.01});
  LandingSample cube = k.sample;
  cube.size = Vec3::Ones();
  if (cube.size != k.sample.size && !k.accept(cube))
    for (double g : {1.0, 0.5, 0.1, 0.05, 0.01}) {
      LandingSample c = k.sample;
      c.size = round_to(c.size, g);
      if (c.size == k.sample.size || k.accept(c)) break;
    }
  round_down(&LandingSample::slide_speed, 1.0, {0.5, 0.1, 0.01});
  round_down(&LandingSample::fall_speed, 1.0, {0.5, 0.1, 0.01});
  round_down(&LandingSample::phase, 0.5, {0.1, 0.01});
  LandingShrinkResult r;
  r.outcome = k.finish();
  r.sample = k.sample;
  r.steps_accepted = k.steps_accepted;
  r.evaluations = k.evaluations;
  return r;
}

}  // namespace rbx

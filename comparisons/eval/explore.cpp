#include "comparisons/eval/explore.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>

#include "comparisons/eval/contact_eval.h"
#include "comparisons/eval/explore_detail.h"
#include "comparisons/eval/harness.h"
#include "comparisons/eval/metrics.h"
#include "comparisons/eval/patch_cover.h"
#include "comparisons/scene/mesh_io.h"
#include "comparisons/scene/scene_file.h"
#include "engine/body.h"
#include "engine/bounding.h"
#include "engine/format.h"
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

Vec3 SampleRng::uniform3(double lo, double hi) {
  const double z = uniform(lo, hi), y = uniform(lo, hi), x = uniform(lo, hi);
  return Vec3(x, y, z);
}

Quat SampleRng::rotation() {
  const double u1 = uniform(), u2 = uniform(0.0, 2.0 * M_PI), u3 = uniform(0.0, 2.0 * M_PI);
  const double a = std::sqrt(1.0 - u1), b = std::sqrt(u1);
  return Quat(a * std::sin(u2), a * std::cos(u2), b * std::sin(u3), b * std::cos(u3)).normalized();
}

// ---------------------------------------------------------------------------------------------
// Samples

namespace explore_detail {

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
  if (style == 1) axes = r.uniform3(0.3, 1.0);
  std::vector<Vec3> p;
  for (int i = 0; i < n; ++i) {
    if (style == 2)
      p.push_back(0.5 * scale * r.uniform3(-1, 1));
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

}  // namespace explore_detail

using namespace explore_detail;

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
  s.a.position = r.uniform3(-1, 1);

  const auto shape_a = build_shape(s.a), shape_b = build_shape(s.b);
  const double small = std::min(shape_size(*shape_a), shape_size(*shape_b));
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
    const bool a_big = shape_size(*shape_a) >= shape_size(*shape_b);
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

namespace explore_detail {

std::string num(double x) {
  // The shortest text that reads back as the same double, plain decimals for ordinary
  // magnitudes ("90.0", not "9e+01").
  NumberFormat f;
  f.digits = 0;
  f.signed_zero = true;
  f.plain_decimals = true;
  std::string s = format_number(x, f);
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

}  // namespace explore_detail

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

// A library's answer on a sample, from the cache when it holds one and kept there when not
// (never an engine's: ResultCache::caches). Keyed apart from the harness's timed answers: these
// carry only the one call's time.
ContactRun sample_answer(const Backend& be, const RigidBody& a, const RigidBody& b,
                         const ResultCache* cache) {
  if (!cache || !cache->enabled() || !ResultCache::caches(be.name)) return run_contact(be, a, b);
  const std::string key = "explore " + cache->contact_key(be.name, a, b);
  if (auto hit = cache->load_contact(key)) {
    ContactRun run;
    run.result = std::move(hit->result);
    run.timing = hit->timing;
    run.cached = true;
    return run;
  }
  ContactRun run = run_contact(be, a, b);
  cache->store(key, run.result, run.timing);
  return run;
}

SampleOutcome evaluate_bodies(const RigidBody& a, const RigidBody& b,
                              const std::vector<std::string>& names, const std::string& shapes,
                              const std::vector<Backend>* table = nullptr,
                              const ResultCache* cache = nullptr) {
  SampleOutcome out;
  out.shapes = shapes;
  const SatResult sat = sat_query(*a.shape, a.pose(), *b.shape, b.pose());
  const double size = std::min(shape_size(*a.shape), shape_size(*b.shape));
  out.touching = sat.touching;
  out.depth_rel = sat.depth / size;
  out.feature = sat.touching ? sat.axis_kind : "separated";
  const double band = kTouchBand * size, true_depth = std::max(sat.depth, 0.0);
  for (const std::string& name : names) {
    const Backend* be = find_backend(name, table);
    if (!be || !be->contact) continue;
    const ContactRun run = sample_answer(*be, a, b, cache);
    if (run.result.status == Status::Unsupported) continue;
    BackendOutcome o;
    o.backend = name;
    if (run.result.status == Status::Error || run.result.status == Status::Timeout) {
      o.error = to_string(run.result.status);
      o.message = run.result.message;
      out.backends.push_back(o);
      continue;
    }
    // Touching with no normal: a false contact where the pair is clearly apart, a miss where it
    // clearly penetrates, else an answer at zero depth with nothing to score.
    if (run.result.status == Status::Touching) {
      if (!sat.touching && sat.depth < -band) o.error = "false_contact";
      if (sat.touching && sat.depth > band) o.error = "no_normal";
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
    // The harness's rule for ties: a tied normal is as right as the oracle's.
    double angle = angle_deg(c->normal, sat.normal);
    if (angle > 0 && ties_true_depth(a, b, c->normal, true_depth, size)) angle = 0.0;
    o.measured = true;
    o.normal_err_deg = angle;
    o.depth_err_rel = std::abs(c->depth - true_depth) / size;
    // Every point of the answer, not only the deepest, against the true region; and the whole
    // set against the patch.
    if (!sat.manifold.empty()) {
      const SatPatch truth = true_patch(run.result, a, b, sat);
      const PatchCover cover = patch_cover(run.result.contacts, a, b, truth.corners, truth.normal);
      o.point_err_rel = cover.worst_point_err / size;
      o.coverage_err_rel = cover.coverage_err / size;
    }
    // Clear disagreements, by the harness's marks (harness.h): 1 degree, 1 % of the size.
    if (!(angle <= kMarkAngleDeg))
      o.error = "normal";
    else if (!(o.depth_err_rel <= kMarkDepthRel))
      o.error = "depth";
    else if (!(o.point_err_rel <= kMarkDepthRel))
      o.error = "point";
    else if (!(o.coverage_err_rel <= kMarkDepthRel))
      o.error = "coverage";  // its points fall short of the patch (docs/contact_manifold.md)
    out.backends.push_back(o);
  }
  return out;
}

}  // namespace

SampleOutcome evaluate_contact_sample(const ContactSample& s, const std::vector<std::string>& names,
                                      const std::vector<Backend>* table, const ResultCache* cache) {
  const RigidBody a = build_body(s.a, "A"), b = build_body(s.b, "B");
  SampleOutcome out =
      evaluate_bodies(a, b, names, s.a.shape_class + "-" + s.b.shape_class, table, cache);
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
                      b.position_err_m, b.turn_rad, b.rest_time_err_s, b.reported_depth_m, b.rise_m,
                      b.coverage_err_rel, b.distance_err_rel, b.witness_err_rel, b.time_err,
                      b.separation_m});
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
    s.backends.push_back({b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7], b[8], b[9], b[10], b[11],
                          b[12], b[13], b[14], b[15], b[16], b[17], b[18]});
  s.phase = j.value("ph", -1.0);
  return s;
}

}  // namespace rbx

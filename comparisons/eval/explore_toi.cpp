// rbx explore --kind toi: the distance kind's separated pairs set moving, every backend's time of
// impact against the exact oracle (explore.h, "Toi kind").
#include <algorithm>
#include <cmath>
#include <sstream>

#include "comparisons/eval/explore.h"
#include "comparisons/eval/explore_detail.h"
#include "comparisons/eval/toi_query.h"
#include "comparisons/scene/scene_file.h"
#include "engine/format.h"
#include "reference/exact.h"

namespace rbx {

using explore_detail::build_body;
using explore_detail::build_shape;

namespace {

// A stream of its own for the motion, so that sample k's pair stays the distance kind's sample k.
constexpr uint64_t kMotionStream = 0xD1B54A32D192ED03ull;

const char* const kMotions[] = {"head-on", "oblique", "spinning", "hair-miss", "graze"};

std::string vec_text(const Vec3& v) {
  std::ostringstream o;
  o.precision(17);
  o << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  return o.str();
}

// The sample's bodies, moving.
std::pair<RigidBody, RigidBody> moving_bodies(const ToiSample& s) {
  RigidBody a = build_body(s.pair.a, "A"), b = build_body(s.pair.b, "B");
  a.velocity = s.velocity_a;
  a.angular_velocity = s.angular_velocity_a;
  b.velocity = s.velocity_b;
  b.angular_velocity = s.angular_velocity_b;
  return {a, b};
}

// A library's time of impact on a sample over `interval`, from the cache when it holds one and
// kept there when not (never an engine's: ResultCache::caches; a row's variant is in its name).
ToiResult sample_toi(const ToiSubject& subject, const RigidBody& a, const RigidBody& b,
                     double interval, const ResultCache* cache) {
  if (!cache || !cache->enabled() || !subject.library || !ResultCache::caches(subject.name))
    return run_toi(subject, a, b, interval);
  const std::string key = "explore toi " +
                          std::string(reinterpret_cast<const char*>(&interval), sizeof interval) +
                          cache->contact_key(subject.name, a, b);
  if (auto hit = cache->load_toi(key)) return hit->result;
  double runtime_s = 0.0;
  const ToiResult r = run_toi(subject, a, b, interval, &runtime_s);
  cache->store(key, r, runtime_s);
  return r;
}

}  // namespace

ToiSample make_toi_sample(uint64_t seed, uint64_t index) {
  ToiSample s;
  ContactSample pair = make_contact_sample(seed, index);
  for (ExploreBody* body : {&pair.a, &pair.b})
    if (body->points.size() > kToiMaxPoints) body->points.resize(kToiMaxPoints);
  s.pair = moved_apart(pair, seed, index);
  SampleRng r(seed ^ kMotionStream, index);
  const auto shape_a = build_shape(s.pair.a), shape_b = build_shape(s.pair.b);
  const double small = std::min(shape_size(*shape_a), shape_size(*shape_b));
  const Pose pa{s.pair.a.position, explore_detail::build_orientation(s.pair.a)};
  const Pose pb{s.pair.b.position, explore_detail::build_orientation(s.pair.b)};
  const ExactDistance e = exact_distance(*shape_a, pa, *shape_b, pb);
  const std::string motion = kMotions[r.integer(0, 4)];
  s.pair.pose_class = motion;
  // From B's closest point toward A's: B closing on A along it shrinks the gap at that speed.
  const Vec3 toward_a = (e.point_a - e.point_b) / e.distance;
  const double fraction = r.uniform(0.05, 0.95);
  const double share = r.uniform();  // how much of the approach is B's
  double approach = e.distance / (fraction * s.interval);
  if (motion == "hair-miss") {
    const double hair = std::min(0.5 * e.distance, small * std::pow(10.0, r.uniform(-9.0, -4.0)));
    approach = (e.distance - hair) / s.interval;
  }
  Vec3 closing = approach * toward_a;
  if (motion == "graze") closing = Vec3::Zero();
  // A sideways drift: across the closest direction, up to three sizes over the interval.
  Vec3 side = r.direction();
  side = (side - side.dot(toward_a) * toward_a).normalized();
  if (motion == "oblique" || motion == "graze")
    closing += r.uniform(0.0, 3.0) * small / s.interval * side;
  s.velocity_b = share * closing;
  s.velocity_a = -(1.0 - share) * closing;
  if (motion == "spinning") {
    // Turns of up to 2 rad, and no faster than ten times the approach at the bodies' reach, so
    // that the oracle's advancement (whose steps shrink as the turn outpaces the approach)
    // settles in hundreds of steps.
    auto reach = [](const ConvexPolyhedron& shape) {
      double r = 0;
      for (const Vec3& v : shape.vertices()) r = std::max(r, v.norm());
      return r;
    };
    const double turn_a = std::min(2.0, 10.0 * approach * s.interval / reach(*shape_a));
    const double turn_b = std::min(2.0, 10.0 * approach * s.interval / reach(*shape_b));
    s.angular_velocity_a = r.uniform(0.0, turn_a) / s.interval * r.direction();
    s.angular_velocity_b = r.uniform(0.0, turn_b) / s.interval * r.direction();
  }
  return s;
}

std::string toi_scene_text(const ToiSample& s, const std::string& header) {
  std::string text = sample_scene_text(s.pair, header);
  auto insert_after = [&text](const std::string& anchor, const std::string& lines) {
    const size_t at = text.find(anchor);
    if (at == std::string::npos) throw std::logic_error("toi scene: no '" + anchor + "'");
    text.insert(at + anchor.size(), lines);
  };
  std::ostringstream dt;
  dt.precision(17);
  dt << "dt = " << s.interval << "\n";
  insert_after("duration = 0\n", dt.str());
  insert_after("name = \"A\"\n", "velocity = " + vec_text(s.velocity_a) + "\nangular_velocity = " +
                                     vec_text(s.angular_velocity_a) + "\n");
  insert_after("name = \"B\"\n", "velocity = " + vec_text(s.velocity_b) + "\nangular_velocity = " +
                                     vec_text(s.angular_velocity_b) + "\n");
  return text;
}

SampleOutcome evaluate_toi_sample(const ToiSample& s, const std::vector<std::string>& names,
                                  const ResultCache* cache) {
  const auto [a, b] = moving_bodies(s);
  SampleOutcome out;
  out.index = s.pair.index;
  out.pose_class = s.pair.pose_class;
  out.shapes = s.pair.a.shape_class + "-" + s.pair.b.shape_class;
  const ToiResult truth = exact_toi(a, b, s.interval);
  out.touching = truth.hit;
  out.feature = truth.status != Status::Ok ? "unresolved" : truth.hit ? "touch" : "no_touch";
  if (truth.status != Status::Ok) return out;  // the oracle could not settle it: not counted
  for (const ToiSubject& subject : toi_subjects(names)) {
    if (!subject.fn || subject.name == "exact") continue;
    const ToiResult r = sample_toi(subject, a, b, s.interval, cache);
    if (r.status == Status::Unsupported) continue;
    BackendOutcome o;
    o.backend = subject.name;
    if (r.status != Status::Ok) {
      o.error = r.status == Status::Timeout ? "timeout" : "error";
      o.message = r.message;
      out.backends.push_back(o);
      continue;
    }
    const ToiVerdict v = judge_toi(r, truth, a, b, s.interval);
    o.measured = v.comparable;
    o.time_err = v.time_err;
    o.normal_err_deg = v.normal_err_deg;
    if (v.mark == "disagrees") {
      o.error = r.hit != truth.hit            ? (r.hit ? "false_contact" : "misses")
                : r.fraction < truth.fraction ? "early"
                                              : "late";
      o.separation_m = v.separation_m;
      o.message = v.why;
    }
    out.backends.push_back(o);
  }
  return out;
}

namespace explore_detail {

// One toi group: its first sample's pair shrunk while the row still shows the group's signature
// over the same motion, reproduced when `rbx toi`'s comparison of the written scene marks the row.
std::string toi_group(const Json& g, uint64_t seed, long count, int budget) {
  const ToiSample start = make_toi_sample(seed, g["first_sample"].get<uint64_t>());
  const std::string row = g["backend"], sig = g["signature"];
  const std::string backend = row.substr(0, row.find('/'));
  ToiSample shrunk = start;
  const ShrinkResult r = shrink_with(
      start.pair,
      [&](const ContactSample& c, SampleOutcome* out) {
        ToiSample t = start;
        t.pair = c;
        return shows_signature(evaluate_toi_sample(t, {backend}), sig, out);
      },
      budget);
  shrunk.pair = r.sample;
  const BackendOutcome found = outcome_of(r.outcome, row);
  if (found.error.empty()) return Json{{"ok", false}}.dump();
  std::ostringstream h;
  h << "# Found by `rbx explore --kind toi --seed " << seed << " --count " << count << "`: sample "
    << start.pair.index << " (" << start.pair.pose_class << "), group '" << sig << "',\n# "
    << g["count"].get<long>() << " samples. " << row
    << " against the exact oracle: " << describe_outcome(found) << ".\n# Shrunk "
    << points_shrunk(r.vertices_before, r.vertices_after, r.steps_accepted, r.evaluations)
    << ", the motion as drawn, while the disagreement stayed.\n# Reproduce: rbx toi THIS_FILE "
       "--backends "
    << backend << "\n";
  // The oracle's answer on the shrunk pair, stated: rbx toi checks it, and custom by it.
  const auto [sa, sb] = moving_bodies(shrunk);
  const ToiResult truth = exact_toi(sa, sb, shrunk.interval);
  std::string text = toi_scene_text(shrunk, h.str());
  if (truth.status == Status::Ok)
    text += "\n[expect]\ntruth = \"exact\"\n\n[expect.toi]\n" +
            (truth.hit ? "touch = true\nfraction = " + num(truth.fraction) + "\n"
                       : std::string("touch = false\n"));
  const Scene scene = parse_scene(text, "explore.toml");
  const ToiComparison c = compare_tois(scene, {backend}, scene.sim.dt, 0.0);
  std::string why = "no mark";
  bool reproduced = false;
  for (const ToiRow& x : c.pairs.at(0).rows)
    if (x.backend == row) {
      // A status error is the row's answer, not a mark: reproduced when the scene's is one.
      const bool failed = x.result.status != Status::Ok;
      reproduced = x.verdict.mark == "disagrees" ||
                   (failed && (found.error == "error" || found.error == "timeout"));
      if (failed) why = std::string("status ") + to_string(x.result.status);
      if (!failed && !x.verdict.why.empty()) why = x.verdict.why;
    }
  return Json{{"ok", true},
              {"text", text},
              {"reproduced", reproduced},
              {"harness", "rbx toi: " + why},
              {"message", found.message},
              {"points_before", r.vertices_before},
              {"points_after", r.vertices_after},
              {"evaluations", r.evaluations},
              {"time_err", found.time_err}}
      .dump();
}

}  // namespace explore_detail

}  // namespace rbx

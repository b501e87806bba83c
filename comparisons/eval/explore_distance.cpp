// rbx explore --kind distance: the contact kind's shapes and poses moved apart to a drawn gap,
// every backend's distance query against the exact oracle (explore.h, "Distance kind").
#include <algorithm>
#include <cmath>

#include "comparisons/eval/distance_query.h"
#include "comparisons/eval/explore.h"
#include "comparisons/eval/explore_detail.h"
#include "engine/detect.h"
#include "reference/exact.h"

namespace rbx {

using explore_detail::build_body;
using explore_detail::build_shape;

namespace {

// A stream of its own for the gap, so that sample k's shapes and turns stay the contact kind's
// sample k (any odd constant would do; this one is the golden ratio's, as in splitmix64).
constexpr uint64_t kGapStream = 0x9E3779B97F4A7C15ull;

// A library's distance answer on a sample, from the cache when it holds one and kept there when
// not (never an engine's: ResultCache::caches), keyed apart from the contact answers on the same
// bodies.
DistanceResult sample_distance(const Backend& be, const RigidBody& a, const RigidBody& b,
                               const ResultCache* cache) {
  if (!cache || !cache->enabled() || !ResultCache::caches(be.name)) return run_distance(be, a, b);
  const std::string key = "explore distance " + cache->contact_key(be.name, a, b);
  if (auto hit = cache->load_distance(key)) return hit->result;
  double runtime_s = 0.0;
  const DistanceResult r = run_distance(be, a, b, &runtime_s);
  cache->store(key, r, runtime_s);
  return r;
}

// "vertex-face" and the like: the exact closest features, A's first.
std::string feature_pair(const ExactDistance& e) { return e.feature_a + "-" + e.feature_b; }

}  // namespace

std::string gap_class(double gap_rel) {
  return gap_rel < 1e-4 ? "hair" : gap_rel < 0.1 ? "near" : "far";
}

ContactSample make_distance_sample(uint64_t seed, uint64_t index) {
  return moved_apart(make_contact_sample(seed, index), seed, index);
}

ContactSample moved_apart(ContactSample s, uint64_t seed, uint64_t index) {
  SampleRng r(seed ^ kGapStream, index);
  const auto shape_a = build_shape(s.a), shape_b = build_shape(s.b);
  const double small = std::min(shape_size(*shape_a), shape_size(*shape_b));
  const Pose pa{s.a.position, explore_detail::build_orientation(s.a)};
  Pose pb{s.b.position, explore_detail::build_orientation(s.b)};
  // Overlapping or touching: B out along the deepest-overlap axis, clear by 1 % of the smaller
  // body, so that a closest pair exists.
  const SatResult sat = sat_query(*shape_a, pa, *shape_b, pb);
  if (sat.touching) pb.position -= (std::max(sat.depth, 0.0) + 0.01 * small) * sat.normal;
  const ExactDistance e = exact_distance(*shape_a, pa, *shape_b, pb);
  const double gap = small * std::pow(10.0, r.uniform(-9.0, 1.0));
  const Vec3 across = (e.point_b - e.point_a) / e.distance;
  s.b.position = pb.position + (gap - e.distance) * across;
  s.pose_class = gap_class(gap / small);
  return s;
}

SampleOutcome evaluate_distance_sample(const ContactSample& s,
                                       const std::vector<std::string>& names,
                                       const std::vector<Backend>* table,
                                       const ResultCache* cache) {
  const RigidBody a = build_body(s.a, "A"), b = build_body(s.b, "B");
  SampleOutcome out;
  out.index = s.index;
  out.pose_class = s.pose_class;
  out.shapes = s.a.shape_class + "-" + s.b.shape_class;
  const ExactDistance e = exact_distance(*a.shape, a.pose(), *b.shape, b.pose());
  const double size = std::min(shape_size(*a.shape), shape_size(*b.shape));
  out.touching = e.overlapping;
  out.depth_rel = e.overlapping ? 0.0 : -e.distance / size;
  out.feature = e.overlapping ? "overlapping" : feature_pair(e);
  DistanceResult truth;
  truth.overlapping = e.overlapping;
  truth.distance = e.distance;
  truth.point_a = e.point_a;
  truth.point_b = e.point_b;
  for (const std::string& name : names) {
    const Backend* be = find_backend(name, table);
    if (!be || !be->distance) continue;
    const DistanceResult r = sample_distance(*be, a, b, cache);
    BackendOutcome o;
    o.backend = name;
    if (r.status != Status::Ok) {
      o.error = "error";
      o.message = r.message;
      out.backends.push_back(o);
      continue;
    }
    const DistanceVerdict v = judge_distance(r, truth, a, b);
    o.measured = v.comparable;
    o.distance_err_rel = v.distance_err;
    o.witness_err_rel = v.witness_err;
    if (v.mark == "disagrees") {
      if (r.overlapping != truth.overlapping)
        o.error = r.overlapping ? "overlap" : "false_distance";
      else
        o.error = v.distance_err > kDistanceDisagreeRel ? "distance" : "witness";
      o.message = v.why;
    }
    out.backends.push_back(o);
  }
  return out;
}

}  // namespace rbx

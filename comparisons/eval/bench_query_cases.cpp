// rbx bench's query families: the narrow phase (every contact query) and the distance queries,
// on the same shapes at the same kind of poses, built by one routine (query_cases).
#include <algorithm>
#include <iostream>
#include <memory>

#include "comparisons/eval/bench_cases.h"
#include "comparisons/eval/bench_detail.h"

namespace rbx {

// Every row timed is named in its registry entry (Backend::bench, QueryVariant::bench), in
// registry order, each backend's variants after it. The caps there keep the full run under ten
// minutes on two cores; each is named, with its reason, in perf.md: the seed loops' 16 N^2
// primitive tests, bullet-sat's polyhedral features rebuilt on every call, the exact oracle's,
// ODE's, MuJoCo's and DART's (triangle meshes) cost at the largest sizes, Bullet's and ODE's
// shapes built from 8,192 points on every call (about 2 s a query, 10 s a call of five poses).
std::vector<NarrowBackend> narrow_backends() {
  std::vector<NarrowBackend> rows;
  for (const Backend& b : backends()) {
    if (b.contact && b.bench.full > 0)
      rows.push_back({b.name, "default", b.contact, b.bench.full, b.bench.quick});
    for (const QueryVariant& v : query_variants())
      if (v.backend == b.name && v.bench.full > 0)
        rows.push_back({b.name, v.variant, v.contact, v.bench.full, v.bench.quick, v.boxes_only});
  }
  return rows;
}

std::vector<DistanceBackend> distance_backends() {
  // The libraries' plain rows build their shapes (MuJoCo its whole model) on every call, a
  // second or so a query at N = 8,192: they stop at 2,048, where custom and FCL's prebuilt row
  // go on (docs/bench.md).
  constexpr int kPerCallBuildCap = 2048;
  std::vector<DistanceBackend> rows;
  for (const Backend& b : backends()) {
    if (b.distance && b.bench.full > 0 && b.name != "exact")
      rows.push_back({b.name, "default", b.distance,
                      b.library ? std::min(b.bench.full, kPerCallBuildCap) : b.bench.full,
                      b.bench.quick});
    for (const QueryVariant& v : query_variants())
      if (v.backend == b.name && v.distance && v.bench.full > 0)
        rows.push_back({b.name, v.variant, v.distance, v.bench.full, v.bench.quick});
  }
  return rows;
}

std::vector<ToiBackend> toi_backends() {
  constexpr int kLibraryFull = 2048, kLibraryQuick = 512;
  std::vector<ToiBackend> rows;
  for (const Backend& b : backends()) {
    if (b.name == "exact") continue;
    if (b.toi)
      rows.push_back({b.name, "default", b.toi, b.library ? kLibraryFull : b.bench.full,
                      b.library ? kLibraryQuick : b.bench.quick});
    for (const QueryVariant& v : query_variants())
      if (v.backend == b.name && v.toi)
        rows.push_back({b.name, v.variant, v.toi, kLibraryFull, kLibraryQuick});
  }
  return rows;
}

namespace bench_detail {

namespace {

// One query of a timed row on a pair at its pose: "" when the answer is ok, else its status and
// message.
using PairQuery = std::function<std::string(const RigidBody& a, const RigidBody& b)>;

// A row of a query family: what is timed and up to which size.
struct QueryRow {
  std::string backend, variant;
  PairQuery query;
  int max_full = 0, max_quick = 0;
  bool boxes_only = false;
};

// A query family's groups: every row on every shape size and pose kind of `kinds` (one group
// each, named "<family>/<size>/<kind>"), the rows going to `into` (ns per query).
CaseSet query_cases(const BenchPlan& plan, const std::string& family,
                    const std::vector<QueryRow>& rows, const std::vector<PoseKind>& kinds,
                    std::vector<NarrowRow> BenchResults::*into) {
  struct State {
    NarrowRow row;
    std::shared_ptr<PosedPair> pair;
    PairQuery query;
    std::string name;
    std::string status = "ok";
    std::size_t next = 0;  // the pose the next query takes (modulo the cycle)
  };
  CaseSet set;
  std::vector<std::shared_ptr<State>> states;
  std::vector<int> sizes = {8};
  sizes.insert(sizes.end(), plan.hull_sizes.begin(), plan.hull_sizes.end());
  std::cerr << "bench: building shapes and poses (" << family << ")\n";
  for (int n : sizes) {
    const bool box = n == 8;
    // One generator per shape and per pose kind, seeded by them: the quick run times the first
    // poses of the full run's, on the same hulls.
    std::mt19937_64 shape_rng(1000003ull * static_cast<unsigned>(n));
    const ConvexPolyhedron shape =
        box ? make_box(Vec3::Constant(kBenchShapeSize)) : sphere_hull(n, shape_rng);
    for (const PoseKind& kind : kinds) {
      // The seed of the narrow phase's pose kind at the same place in kPoseKinds; a gap kind,
      // past them, its own.
      std::mt19937_64 pose_rng(1000003ull * static_cast<unsigned>(n) +
                               static_cast<unsigned>(&kind - kinds.data()) + 1 +
                               (family == "narrowphase" ? 0u : 100u));
      auto pair = std::make_shared<PosedPair>(make_poses(shape, box, kind, plan.poses, pose_rng));
      // A time-of-impact kind's turn: B's angular velocity, about an axis no face is square to
      // (the queries set the poses only, so it stays).
      pair->b.angular_velocity = kind.turn * Vec3(1, 2, 3).normalized();
      BenchGroup group;
      group.name = family + "/" + std::to_string(n) + "/" + kind.name;
      group.plan.min_time_s = plan.min_time;
      for (const QueryRow& b : rows) {
        if (b.boxes_only && !box) continue;
        if (n > (plan.quick ? b.max_quick : b.max_full)) continue;
        auto c = std::make_shared<State>();
        c->row.backend = b.backend;
        c->row.variant = b.variant;
        c->row.pose = kind.name;
        c->row.vertices = n;
        c->row.hull_vertices = static_cast<int>(shape.vertices().size());
        c->name =
            family + "/" + b.backend + "/" + b.variant + "/" + std::to_string(n) + "/" + kind.name;
        c->pair = pair;
        c->query = b.query;
        states.push_back(c);
        // One query at pose k of the pair.
        auto query = [c](std::size_t k) {
          k %= c->pair->poses_a.size();
          PosedPair& p = *c->pair;
          p.a.position = p.poses_a[k].position;
          p.a.orientation = p.poses_a[k].orientation;
          p.b.position = p.poses_b[k].position;
          p.b.orientation = p.poses_b[k].orientation;
          return c->query(p.a, p.b);
        };
        BenchCase bc;
        bc.name = c->name;
        // Warm-up: one call's poses (caches, lazily built hierarchies), the cold pass.
        const std::size_t per_iteration = static_cast<std::size_t>(plan.poses_per_iteration);
        bc.warm_up = [c, query, per_iteration] {
          for (std::size_t k = 0; k < per_iteration; ++k) query(k);
        };
        // Each call the next poses of the cycle: a sequence as long as the cycle is not one
        // a branch predictor learns, as it learns a few poses repeated (docs/bench.md). Every
        // status that is not ok is kept.
        bc.body = [c, query, per_iteration] {
          for (std::size_t k = 0; k < per_iteration; ++k) {
            const std::string status = query(c->next++);
            if (!status.empty()) c->status = status;
          }
        };
        group.cases.push_back(bc);
      }
      set.groups.push_back(std::move(group));
    }
  }
  set.collect = [states, poses = plan.poses_per_iteration, into](const CaseTimes& times,
                                                                 BenchResults& out) {
    for (const auto& c : states) {
      NarrowRow r = c->row;
      r.status = c->status;
      // A call queries `poses` poses: the row's unit is ns per query.
      r.ns_per_query = times.time(c->name, 1e9 / static_cast<double>(poses));
      if (times.errors.count(c->name)) r.status = "error: " + times.errors.at(c->name);
      (out.*into).push_back(r);
    }
  };
  return set;
}

}  // namespace

// Narrow phase: every backend of narrow_backends() on every shape size and pose kind.
CaseSet narrowphase_cases(const BenchPlan& plan, std::mt19937_64&) {
  std::vector<QueryRow> rows;
  for (const NarrowBackend& b : narrow_backends()) {
    const ContactFn contact = b.contact;
    rows.push_back({b.backend, b.variant,
                    [contact](const RigidBody& a, const RigidBody& bb) {
                      const ContactResult r = contact(a, bb);
                      return r.status == Status::Ok
                                 ? std::string()
                                 : std::string(to_string(r.status)) + ": " + r.message;
                    },
                    b.max_vertices_full, b.max_vertices_quick, b.boxes_only});
  }
  return query_cases(plan, "narrowphase", rows,
                     std::vector<PoseKind>(std::begin(kPoseKinds), std::end(kPoseKinds)),
                     &BenchResults::narrow);
}

// Distance: every query of distance_backends() on every shape size, 1 % and 20 % apart.
CaseSet distance_cases(const BenchPlan& plan, std::mt19937_64&) {
  std::vector<QueryRow> rows;
  for (const DistanceBackend& b : distance_backends()) {
    const DistanceFn distance = b.distance;
    rows.push_back({b.backend, b.variant,
                    [distance](const RigidBody& a, const RigidBody& bb) {
                      const DistanceResult r = distance(a, bb);
                      if (r.status != Status::Ok)
                        return std::string(to_string(r.status)) + ": " + r.message;
                      return r.overlapping ? std::string("said overlapping") : std::string();
                    },
                    b.max_vertices_full, b.max_vertices_quick});
  }
  return query_cases(plan, "distance", rows,
                     std::vector<PoseKind>(std::begin(kGapKinds), std::end(kGapKinds)),
                     &BenchResults::distance);
}

// Time of impact: every query of toi_backends() on the distance poses, B moving onto A at the
// centres' offset per second over 1 s, in pure translation on the gaps of kGapKinds (so every
// row, the translation-only casts too, answers the same question) and turning on the last kind
// of kToiKinds; the moving copy of B is made on every call, by every row alike.
CaseSet toi_cases(const BenchPlan& plan, std::mt19937_64&) {
  std::vector<QueryRow> rows;
  for (const ToiBackend& b : toi_backends()) {
    const ToiFn toi = b.toi;
    rows.push_back({b.backend, b.variant,
                    [toi](const RigidBody& a, const RigidBody& bb) {
                      RigidBody moving = bb;
                      moving.velocity = a.position - bb.position;
                      const ToiResult r = toi(a, moving, 1.0);
                      if (r.status != Status::Ok)
                        return std::string(to_string(r.status)) + ": " + r.message;
                      return r.hit ? std::string() : std::string("no touch");
                    },
                    b.max_vertices_full, b.max_vertices_quick});
  }
  return query_cases(plan, "toi", rows,
                     std::vector<PoseKind>(std::begin(kToiKinds), std::end(kToiKinds)),
                     &BenchResults::toi);
}

}  // namespace bench_detail

}  // namespace rbx

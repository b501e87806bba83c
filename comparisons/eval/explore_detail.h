// What the explore files share (explore.cpp and explore_shrink.cpp: contact kind;
// explore_dynamics.cpp, explore_landing.cpp, explore_slide.cpp, explore_tunnel.cpp: the closed-form
// kinds; explore_group_shrink.cpp and explore_campaign.cpp: the campaign): bodies built as the
// scene loader builds them, random bodies, scene text, dynamics runs judged against a closed form,
// and the shrinking. Internal to comparisons/eval/explore*.cpp.
#pragma once

#include <functional>
#include <initializer_list>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "comparisons/eval/explore.h"
#include "comparisons/eval/explore_campaign.h"
#include "comparisons/eval/json_io.h"
#include "comparisons/scene/scene.h"
#include "engine/body.h"
#include "reference/backend.h"

namespace rbx::explore_detail {

/// The body's shape exactly as the scene loader builds it (box or convex hull of the points).
std::shared_ptr<const ConvexPolyhedron> build_shape(const ExploreBody& e);
/// Orientation exactly as the scene loader builds it from what sample_scene_text writes.
Quat build_orientation(const ExploreBody& e);
/// The body as the scene loader builds it, named `name`.
RigidBody build_body(const ExploreBody& e, const std::string& name);
/// A random body of roughly `scale` metres: a box, a hull of 4 to 2000 points, or a sliver.
ExploreBody random_body(SampleRng& r, double scale);

/// The shortest text that reads back as the same double (TOML float syntax).
std::string num(double x);
/// A vector as a TOML array of num()s.
std::string vec(const Vec3& v);
/// A body's [[body]] table (shape, points, pose) as sample_scene_text writes it.
std::string body_text(const ExploreBody& e, const std::string& name);

/// Angle (rad, in [0, pi]) of the rotation taking orientation `from` to `to`; NaN when either
/// is not finite.
double rotation_angle(const Quat& from, const Quat& to);
/// Euler angles (degrees, R = Rz Ry Rx as the scene format) of a rotation.
Vec3 euler_deg(const Quat& q);
/// x to the nearest multiple of grid, as the decimal number a reader would write.
double round_to(double x, double grid);
/// Each coordinate to the nearest multiple of grid (as above).
Vec3 round_to(const Vec3& v, double grid);

/// A body of a dynamics sample (impact, landing, slide): its [[body]] table, its mass, and
/// either its velocity or `static = true`.
std::string dynamic_body_text(const ExploreBody& e, const std::string& name, double mass,
                              const Vec3& velocity, bool is_static);

/// Runs each named dynamics backend on `scene` (those without dynamics, or unsupported, left
/// out) and appends one outcome each to `out`: a status error, or a run returning the wrong
/// number of final states, as `error`; a finished run measured and classified by `judge`.
/// Backends are looked up in `table` (null: the registry); `cache`, when given, serves and keeps
/// the libraries' runs (result_cache.h; never the engines').
void run_dynamics_subjects(
    const Scene& scene, const std::vector<std::string>& names, const DynamicsOptions& options,
    const std::vector<Backend>* table, const ResultCache* cache, SampleOutcome& out,
    const std::function<void(BackendOutcome&, const DynamicsResult&)>& judge);

/// Landing and slide kinds: records the deepest contact `run` reported and, where `o` already
/// disagrees and that depth is above a tenth of the box's smallest side `side`, names the
/// disagreement "deep_contact": no landing or resting box reaches such a depth (a step of
/// approach, 2 mm here, or a soft contact's sink), so the library's collider answered wrong
/// (MuJoCo 2.2.2's box-box collider reports metres, MujocoKnownDefect.*).
void name_deep_contact(BackendOutcome& o, const DynamicsResult& run, double side);
/// Renames a turn or position miss of a box sliding on one surface "cone_excess" where the
/// friction it received beyond the Coulomb cone (the run's ConeExcess, measured by the recorder
/// on the library's own impulses) explains it: a turn of which that friction gave at least half
/// (its spin model is linear in the damping), or whose part past the mark it gave (the box's
/// turn from `start` to `end`, less that friction's turn about the surface's unit `normal`,
/// within the mark), or a resting place (`off_surface`, against the closed form, in the
/// surface) that would be within the mark without the shift of the stop that friction gave
/// along `slide_dir` at `deceleration` (m/s^2; 0: no slide to shift).
void name_cone_excess(BackendOutcome& o, const DynamicsResult& run, const Vec3& off_surface,
                      const Vec3& slide_dir, double deceleration, const Quat& start,
                      const Quat& end, const Vec3& normal);

/// The [expect] block of a box that ends at rest at `position`, unturned (landing and slide
/// kinds), the slide's discretisation bound written with the speed's name and value.
std::string box_at_rest_expect(const std::string& speed_name, double speed, double dt,
                               const Vec3& position);

/// A random box of the landing and slide kinds: mu in [0.1, 1], footprint sides 0.2 to 2 m,
/// a height up to 3 footprints with mu sz <= `no_tip_margin` min(sx, sy), mass 0.1 to 10 kg,
/// yaw 0 to 90 degrees.
void draw_box(SampleRng& r, double& friction, Vec3& size, double& mass, double& yaw_deg,
              double no_tip_margin);

// One line on what a backend did wrong on a sample, as a shrunk scene's comment and a group's
// "first_error" say it.
std::string describe_outcome(const BackendOutcome& b);

// The [expect] block of a shrunk contact scene (`text`, without one): the exact oracle's answer
// at its t = 0 poses, its normal and patch left out where another axis ties (or the reversed one,
// `either_sign`).
std::string expect_block(const std::string& text);

// One disagreement group of a campaign shrunk (explore_group_shrink.cpp): its first sample
// simplified while `group`'s backend still shows its signature, as the JSON text rank 0 collects
// ("ok", "text" with the scene and its [expect], "reproduced", the kind's measures).
std::string shrink_group(const Json& group, const ExploreSettings& set);

// The outcome of `backend` on a sample (an empty error when it is not there).
BackendOutcome outcome_of(const SampleOutcome& o, const std::string& backend);
// Whether some backend of `o` disagrees with signature `sig` (explore.h); `o` into `out` if so.
bool shows_signature(const SampleOutcome& o, const std::string& sig, SampleOutcome* out);
// "from N to M points (K simplifications kept, E tried)".
std::string points_shrunk(int before, int after, int kept, int tried);

// One toi group (explore_toi.cpp): its first sample's pair shrunk (shrink_with, at most `budget`
// tries) while the row's own query still shows the group's signature, the motion kept, as
// shrink_group's JSON.
std::string toi_group(const Json& g, uint64_t seed, long count, int budget);

// The landing and slide kinds' gravity (m/s^2, down: -z).
constexpr double kGravity = 9.81;
// Both kinds draw sizes that keep mu sz at most this fraction of min(sx, sy): a fifth clear of
// tipping (the friction's moment about the centre is mu N sz / 2, which the pressure can balance
// while the contact force stays inside the base: mu sz < min(sx, sy); on an incline at rest the
// same with tan(theta) < mu in place of mu), so that a turn is the backend's, not the edge of the
// closed form.
constexpr double kNoTipMargin = 0.8;

// The first of up to `attempts` draws from the sample's own stream that `draw` realizes (draw
// fills the sample and says whether it is valid); throws when none is.
template <class Sample, class Draw>
Sample first_realized(uint64_t seed, uint64_t index, int attempts, const char* what, Draw draw) {
  SampleRng r(seed, index);
  for (int attempt = 0; attempt < attempts; ++attempt) {
    Sample s;
    s.seed = seed;
    s.index = index;
    if (draw(r, s)) return s;
  }
  throw std::runtime_error(std::string("no valid ") + what + " found in " +
                           std::to_string(attempts) + " attempts");
}

// Greedy shrinking of a closed-form sample's design (impact, landing and slide kinds): a candidate
// is realized (its closed form and scene rebuilt) and kept while `backend` still shows signature
// `sig` on it; at most `max_evaluations` tries.
template <class Sample>
struct DesignShrinker {
  Sample sample;  // the simplest kept so far
  std::vector<std::string> names;
  std::string sig;
  int max_evaluations = 0, evaluations = 0, steps_accepted = 0;
  bool (*realize)(Sample&) = nullptr;
  SampleOutcome (*evaluate)(const Sample&, const std::vector<std::string>&) = nullptr;

  DesignShrinker(const Sample& start, const std::string& backend, const std::string& signature,
                 int budget, bool (*realize_fn)(Sample&),
                 SampleOutcome (*evaluate_fn)(const Sample&, const std::vector<std::string>&))
      : sample(start),
        names{backend},
        sig(signature),
        max_evaluations(budget),
        realize(realize_fn),
        evaluate(evaluate_fn) {}

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
  // The design number `field` set to `first`, else toward rounder values on `grids`, coarsest
  // first; a grid that leaves it as it is, or is kept, ends that number's search.
  void round_down(double Sample::*field, double first, std::initializer_list<double> grids) {
    Sample c = sample;
    c.*field = first;
    if (c.*field == sample.*field || accept(c)) return;
    for (double g : grids) {
      Sample r = sample;
      r.*field = round_to(r.*field, g);
      if (r.*field == sample.*field || accept(r)) break;
    }
  }
  // A box design's sides (`size`): a unit cube, else rounder sides, coarsest grid first.
  void round_size() {
    Sample cube = sample;
    cube.size = Vec3::Ones();
    if (cube.size == sample.size || accept(cube)) return;
    for (double g : {1.0, 0.5, 0.1, 0.05, 0.01}) {
      Sample c = sample;
      c.size = round_to(c.size, g);
      if (c.size == sample.size || accept(c)) break;
    }
  }
  // The shrink's result (a kind's ShrinkResult): the kept sample, its outcome evaluated once
  // more, the counts.
  template <class Result>
  Result result() {
    Result r;
    r.outcome = finish();
    r.sample = sample;
    r.steps_accepted = steps_accepted;
    r.evaluations = evaluations;
    return r;
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

}  // namespace rbx::explore_detail

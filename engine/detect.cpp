// The detector's entry points: the one switch between the faithful and the accelerated
// implementations of the tests in engine/features.h, and the explicit per-pair cache.
#include "engine/detect.h"

#include <algorithm>
#include <stdexcept>

#include "engine/detect_accelerated.h"
#include "engine/detect_faithful.h"

namespace rbx {

namespace {

// Size (m) of a shape: the diagonal of its local bounding box.

}  // namespace

const char* to_string(Detector detector) {
  return detector == Detector::Faithful ? "faithful" : "accelerated";
}

// The prepared pair of each implementation, their storage, and which one is live.
struct DetectionCache::State {
  enum class Live { None, Faithful, Accelerated } live = Live::None;
  detail::FaithfulPair faithful;
  detail::AcceleratedPair accelerated;
  detail::AcceleratedWorkspace workspace;
  detail::FeatureScratch scratch;
};

DetectionCache::DetectionCache() : state_(std::make_unique<State>()) {}
DetectionCache::~DetectionCache() = default;
DetectionCache::DetectionCache(DetectionCache&&) noexcept = default;
DetectionCache& DetectionCache::operator=(DetectionCache&&) noexcept = default;

void DetectionCache::prepare(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                             const Pose& pb, Detector detector) {
  // The one switch point between the two implementations.
  if (detector == Detector::Accelerated) {
    state_->accelerated.prepare(a, pa, b, pb, state_->workspace);
    state_->live = State::Live::Accelerated;
  } else {
    state_->faithful.prepare(a, pa, b, pb);
    state_->live = State::Live::Faithful;
  }
}

std::optional<ContactPoint> DetectionCache::test(Feature feature) {
  switch (state_->live) {
    case State::Live::Accelerated:
      return state_->accelerated.test(feature, state_->scratch);
    case State::Live::Faithful:
      return state_->faithful.test(feature, state_->scratch);
    case State::Live::None:
      break;
  }
  throw std::logic_error("DetectionCache::test before prepare");
}

std::optional<ContactPoint> DetectionCache::detect() {
  switch (state_->live) {
    case State::Live::Accelerated:
      return state_->accelerated.detect(state_->scratch);
    case State::Live::Faithful:
      return state_->faithful.detect(state_->scratch);
    case State::Live::None:
      break;
  }
  throw std::logic_error("DetectionCache::detect before prepare");
}

double point_in_mesh_tolerance(const ConvexPolyhedron& a, const ConvexPolyhedron& b) {
  // Placing a shape in the world and evaluating (p - q_f) . n_f costs a few ulps of the
  // coordinates, ~1e-15 of the size for shapes near the origin. 1e-9 of the larger size is
  // ~10^6 times that (room for poses up to ~10^6 sizes from the origin) and still far below any
  // penetration a time step produces, so it only changes the verdict for touching bodies. It is
  // also the convexity tolerance the polyhedron validation uses.
  return 1e-9 * std::max(shape_size(a), shape_size(b));
}

bool point_in_mesh(const ConvexPolyhedron& mesh, const Pose& pose, const Vec3& p_world,
                   double tol) {
  return detail::FaithfulView::place(mesh, pose, tol).inside(p_world);
}

double overlap_along(const ConvexPolyhedron& a, const Pose& pa, const ConvexPolyhedron& b,
                     const Pose& pb, const Vec3& n) {
  return detail::overlap(detail::FaithfulView::place(a, pa, 0.0),
                         detail::FaithfulView::place(b, pb, 0.0), n);
}

namespace {

// One order of one faithful test.
std::optional<ContactPoint> faithful_one(Feature feature, const ConvexPolyhedron& a, const Pose& pa,
                                         const ConvexPolyhedron& b, const Pose& pb) {
  detail::FaithfulPair pair;
  pair.prepare(a, pa, b, pb);
  detail::FeatureScratch scratch;
  return detail::one_order(feature, pair.a, pair.b, scratch);
}

}  // namespace

std::optional<ContactPoint> face_test(const ConvexPolyhedron& a, const Pose& pa,
                                      const ConvexPolyhedron& b, const Pose& pb) {
  return faithful_one(Feature::Face, a, pa, b, pb);
}

std::optional<ContactPoint> vertex_test(const ConvexPolyhedron& a, const Pose& pa,
                                        const ConvexPolyhedron& b, const Pose& pb) {
  return faithful_one(Feature::Vertex, a, pa, b, pb);
}

std::optional<ContactPoint> edge_test(const ConvexPolyhedron& a, const Pose& pa,
                                      const ConvexPolyhedron& b, const Pose& pb) {
  return faithful_one(Feature::Edge, a, pa, b, pb);
}

std::optional<ContactPoint> detect_feature(Feature feature, const ConvexPolyhedron& a,
                                           const Pose& pa, const ConvexPolyhedron& b,
                                           const Pose& pb, Detector detector,
                                           DetectionCache& cache) {
  cache.prepare(a, pa, b, pb, detector);
  return cache.test(feature);
}

std::optional<ContactPoint> detect_feature(Feature feature, const ConvexPolyhedron& a,
                                           const Pose& pa, const ConvexPolyhedron& b,
                                           const Pose& pb, Detector detector) {
  DetectionCache cache;
  return detect_feature(feature, a, pa, b, pb, detector, cache);
}

std::optional<ContactPoint> detect(const ConvexPolyhedron& a, const Pose& pa,
                                   const ConvexPolyhedron& b, const Pose& pb, Detector detector,
                                   DetectionCache& cache) {
  cache.prepare(a, pa, b, pb, detector);
  return cache.detect();
}

std::optional<ContactPoint> detect(const ConvexPolyhedron& a, const Pose& pa,
                                   const ConvexPolyhedron& b, const Pose& pb, Detector detector) {
  DetectionCache cache;
  return detect(a, pa, b, pb, detector, cache);
}

}  // namespace rbx

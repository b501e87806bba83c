// FCL 0.7 calls that can take the process down, run through run_isolated (reference/isolate.h).
//
// docs/references.md: "Distance with INDEP on Box-Convex can hit an assertion". This is what the
// Debian build really does. Kept apart from fcl_test.cpp, whose executable must never abort
// (it does not link the isolation helper); this one links the whole reference library.
//
// The cause, read from fcl/narrowphase/distance-inl.h (0.7.0): for a penetrating pair that is
// not GST_LIBCCD on two primitive shapes, fcl::distance with enable_signed_distance falls back
// on collide() and takes the deepest contact, starting from a maximum of
// numeric_limits<S>::min() (the smallest *positive* double). GST_INDEP's collide() returns
// its depths negated (the known defect pinned in fcl_test.cpp), so no contact beats the start
// value and `assert(index != static_cast<std::size_t>(-1))` (line 177) fails. libfcl.so.0.7
// is built without NDEBUG (the assertion text is in the library's strings), and the
// distance template for double is instantiated there, so our Release flags cannot disable it:
// the call ends in abort().
#include <fcl/geometry/shape/box.h>
#include <fcl/geometry/shape/convex.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/collision_object.h>
#include <fcl/narrowphase/distance.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "reference/isolate.h"

namespace rbx {
namespace {

// Round-off bound for a GJK distance between unit-scale boxes that ends on exact vertices.
constexpr double kGjkBoxRoundOff = 1e-12;

/// Unit cube as an fcl::Convex (quadrilateral faces, counter-clockwise seen from outside).
std::shared_ptr<fcl::Convexd> unit_cube_convex() {
  auto vertices = std::make_shared<std::vector<fcl::Vector3d>>();
  for (int i = 0; i < 8; ++i)
    vertices->emplace_back((i & 1) ? 0.5 : -0.5, (i & 2) ? 0.5 : -0.5, (i & 4) ? 0.5 : -0.5);
  auto faces = std::make_shared<std::vector<int>>(std::vector<int>{
      4, 0, 2, 3, 1,  // -z
      4, 4, 5, 7, 6,  // +z
      4, 0, 1, 5, 4,  // -y
      4, 2, 6, 7, 3,  // +y
      4, 0, 4, 6, 2,  // -x
      4, 1, 3, 7, 5   // +x
  });
  return std::make_shared<fcl::Convexd>(vertices, 6, faces, /*throw_if_invalid=*/true);
}

/// The query as a user would write it: fcl::distance, signed, nearest points, GST_INDEP, with
/// A = fcl::Box (unit) at the origin and B = the unit cube as fcl::Convex at (x_b, 0, 0). The
/// result travels back through ContactResult: depth = -min_distance, point = nearest_points[0],
/// normal = nearest_points[1] (not a contact: only a carrier through the pipe).
ContactResult indep_box_convex_distance(double x_b) {
  fcl::Transform3d tf_b = fcl::Transform3d::Identity();
  tf_b.translation() = fcl::Vector3d(x_b, 0, 0);
  fcl::CollisionObjectd a(std::make_shared<fcl::Boxd>(1, 1, 1), fcl::Transform3d::Identity());
  fcl::CollisionObjectd b(unit_cube_convex(), tf_b);
  fcl::DistanceRequestd request(/*enable_nearest_points=*/true, /*enable_signed_distance=*/true);
  request.gjk_solver_type = fcl::GST_INDEP;
  fcl::DistanceResultd result;
  fcl::distance(&a, &b, request, result);
  ContactPoint carrier;
  carrier.depth = -result.min_distance;
  carrier.point = result.nearest_points[0];
  carrier.normal = result.nearest_points[1];
  carrier.feature = "distance";
  return {Status::Ok, "", {carrier}};
}

/// Runs `query` isolated with the child's stderr sent to a temporary file; returns the result
/// and puts what the child wrote to stderr in `stderr_text`.
ContactResult run_isolated_capturing_stderr(const std::function<ContactResult()>& query,
                                            std::string* stderr_text) {
  char path[] = "/tmp/rbx_fcl_isolated_XXXXXX";
  const int fd = mkstemp(path);
  if (fd < 0) return {Status::Error, "mkstemp failed", {}};
  const ContactResult r = run_isolated([&]() -> ContactResult {
    dup2(fd, STDERR_FILENO);  // in the child only: the parent's stderr is untouched
    return query();
  });
  close(fd);
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  *stderr_text = text.str();
  std::remove(path);
  return r;
}

TEST(FclIndepDistance, CollideGivesTheNegativeDepthThatTheWorkaroundTrips) {
  // The cause, in this process (collide() is safe): A = Box at the origin, B = Convex unit
  // cube at (0.9, 0, 0), overlap 0.1 along x. GST_INDEP returns a contact whose depth is
  // negative (the sign defect), so distance()'s "deepest contact" search finds nothing.
  fcl::Transform3d tf_b = fcl::Transform3d::Identity();
  tf_b.translation() = fcl::Vector3d(0.9, 0, 0);
  fcl::CollisionObjectd a(std::make_shared<fcl::Boxd>(1, 1, 1), fcl::Transform3d::Identity());
  fcl::CollisionObjectd b(unit_cube_convex(), tf_b);
  fcl::CollisionRequestd request(8, true);
  request.gjk_solver_type = fcl::GST_INDEP;
  fcl::CollisionResultd result;
  fcl::collide(&a, &b, request, result);
  ASSERT_TRUE(result.isCollision());
  for (std::size_t i = 0; i < result.numContacts(); ++i)
    EXPECT_LT(result.getContact(i).penetration_depth, 0.0) << "contact " << i;
}

TEST(FclIndepDistance, PenetratingBoxConvexAbortsOnTheAssertionPinned) {
  // Pinned: the overlapping pair above through fcl::distance (signed, GST_INDEP) dies with
  // SIGABRT from the assertion at distance-inl.h:177. run_isolated turns that into status
  // Error naming the signal, and this process carries on. If FCL stops aborting here (an
  // upgrade, or a build with NDEBUG), this test fails and docs/references.md must change.
  std::string child_stderr;
  const ContactResult r =
      run_isolated_capturing_stderr([] { return indep_box_convex_distance(0.9); }, &child_stderr);
  EXPECT_EQ(r.status, Status::Error);
  EXPECT_NE(r.message.find(strsignal(SIGABRT)), std::string::npos) << r.message;
  EXPECT_TRUE(r.contacts.empty());
  EXPECT_NE(child_stderr.find("index != static_cast<std::size_t>(-1)"), std::string::npos)
      << child_stderr;
  EXPECT_NE(child_stderr.find("distance-inl.h"), std::string::npos) << child_stderr;
  EXPECT_NE(child_stderr.find("GJKSolver_indep"), std::string::npos) << child_stderr;
}

TEST(FclIndepDistance, SeparatedBoxConvexIsAnsweredThroughTheIsolation) {
  // The same query on a separated pair (B at x = 1.1, gap 0.1) never reaches the workaround:
  // GJK alone gives min_distance 0.1, nearest points on A's face x = 0.5 and B's face x = 0.6.
  // The isolation must pass that answer back intact.
  std::string child_stderr;
  const ContactResult r =
      run_isolated_capturing_stderr([] { return indep_box_convex_distance(1.1); }, &child_stderr);
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  ASSERT_EQ(r.contacts.size(), 1u);
  EXPECT_NEAR(-r.contacts[0].depth, 0.1, kGjkBoxRoundOff);      // min_distance
  EXPECT_NEAR(r.contacts[0].point.x(), 0.5, kGjkBoxRoundOff);   // nearest point on A
  EXPECT_NEAR(r.contacts[0].normal.x(), 0.6, kGjkBoxRoundOff);  // nearest point on B
  EXPECT_TRUE(child_stderr.empty()) << child_stderr;
}

}  // namespace
}  // namespace rbx

// The whole-contact metrics against hand-computed patches: coverage of the exact patch, the
// worst point, the support polygon, and a one-point answer failing coverage on a face contact.
#include "comparisons/eval/patch_cover.h"

#include <gtest/gtest.h>

#include <cmath>

#include "comparisons/scene/scene_file.h"
#include "engine/manifold.h"
#include "reference/custom.h"
#include "reference/exact.h"

namespace rbx {
namespace {

std::vector<RigidBody> bodies_of(const std::string& toml) {
  return make_bodies(parse_scene(toml, "patch_cover_test.toml"));
}

std::vector<ContactPoint> at(const std::vector<Vec3>& points) {
  std::vector<ContactPoint> out;
  for (const Vec3& p : points) out.push_back({p, Vec3::UnitZ(), 0.0, "test"});
  return out;
}

// Round-off of a handful of double operations on numbers of order 1.
constexpr double kRoundOff = 1e-14;

// A unit cube A resting 0.02 deep on a 4 x 4 x 1 slab B: the patch is A's bottom face, the
// square |x|, |y| <= 0.5 at z = 0.49 (the slab's top at 0.5, A's bottom at 0.48, midway 0.49).
const char* const kResting =
    "[[body]]\nname = \"A\"\nposition = [0, 0, 0.98]\n"
    "[[body]]\nname = \"B\"\nsize = [4, 4, 1]\nstatic = true\n";

const std::vector<Vec3> kSquare = {
    {-0.5, -0.5, 0.49}, {0.5, -0.5, 0.49}, {0.5, 0.5, 0.49}, {-0.5, 0.5, 0.49}};

TEST(PatchCover, OnePointLeavesThePatchUncoveredByItsFarthestCorner) {
  const auto in = bodies_of(kResting);
  // The patch's centre alone: every corner is half a diagonal away.
  const PatchCover one = patch_cover(at({{0, 0, 0.49}}), in[0], in[1], kSquare, Vec3::UnitZ());
  EXPECT_EQ(one.points, 1);
  EXPECT_EQ(one.worst_point_err, 0.0);
  EXPECT_NEAR(one.coverage_err, std::sqrt(0.5), kRoundOff);
  // The four corners cover it, wherever across the overlap each sits (on A's face, on B's,
  // midway): coverage is measured in the plane.
  const PatchCover four =
      patch_cover(at({{-0.5, -0.5, 0.48}, {0.5, -0.5, 0.5}, {0.5, 0.5, 0.49}, {-0.5, 0.5, 0.48}}),
                  in[0], in[1], kSquare, Vec3::UnitZ());
  EXPECT_EQ(four.points, 4);
  EXPECT_EQ(four.worst_point_err, 0.0);
  EXPECT_NEAR(four.coverage_err, 0.0, kRoundOff);
  // Two corners of one edge: the far corners are a side away.
  const PatchCover edge = patch_cover(at({{-0.5, -0.5, 0.49}, {0.5, -0.5, 0.49}}), in[0], in[1],
                                      kSquare, Vec3::UnitZ());
  EXPECT_NEAR(edge.coverage_err, 1.0, kRoundOff);
}

TEST(PatchCover, TheWorstPointIsTheFarthestFromTheTrueRegion) {
  const auto in = bodies_of(kResting);
  // One corner right, one point 0.3 beside the patch's edge at its height: outside A, so its
  // distance to the patch, 0.3, is its error.
  const PatchCover c =
      patch_cover(at({{0.5, 0.5, 0.49}, {0.8, 0.0, 0.49}}), in[0], in[1], kSquare, Vec3::UnitZ());
  EXPECT_NEAR(c.worst_point_err, 0.3, kRoundOff);
}

TEST(PatchCover, SupportAsksWhetherThePointsHoldTheCentreWhereThePatchDoes) {
  const auto in = bodies_of(kResting);
  // A's centre (0, 0) lies inside the square: the four corners hold it, one edge's two
  // corners do not (B is static: only A is asked).
  const auto four = patch_cover(at(kSquare), in[0], in[1], kSquare, Vec3::UnitZ());
  ASSERT_TRUE(four.support_err.has_value());
  EXPECT_EQ(*four.support_err, 0.0);
  const auto edge = patch_cover(at({kSquare[0], kSquare[1]}), in[0], in[1], kSquare, Vec3::UnitZ());
  ASSERT_TRUE(edge.support_err.has_value());
  EXPECT_EQ(*edge.support_err, 1.0);
  // A patch with no area (a segment) holds no centre: not measured.
  const auto segment =
      patch_cover(at(kSquare), in[0], in[1], {kSquare[0], kSquare[1]}, Vec3::UnitZ());
  EXPECT_FALSE(segment.support_err.has_value());
  // A body overhanging: its centre outside the patch, points spanning more than the patch
  // (a library's points off the region) claim it held.
  const auto over = bodies_of(
      "[[body]]\nname = \"A\"\nposition = [2.3, 0, 0.98]\n"
      "[[body]]\nname = \"B\"\nsize = [4, 4, 1]\nstatic = true\n");
  const std::vector<Vec3> strip = {
      {1.8, -0.5, 0.49}, {2.0, -0.5, 0.49}, {2.0, 0.5, 0.49}, {1.8, 0.5, 0.49}};
  const auto right = patch_cover(at(strip), over[0], over[1], strip, Vec3::UnitZ());
  EXPECT_EQ(right.support_err.value_or(-1), 0.0);
  const auto wrong =
      patch_cover(at({{1.8, -0.5, 0.49}, {2.8, -0.5, 0.49}, {2.8, 0.5, 0.49}, {1.8, 0.5, 0.49}}),
                  over[0], over[1], strip, Vec3::UnitZ());
  EXPECT_EQ(wrong.support_err.value_or(-1), 1.0);
}

TEST(PatchCover, DistanceToAHullIsMeasuredAcrossTheNormal) {
  const std::vector<Vec3> tri = {{0, 0, 0}, {1, 0, 5}, {0, 1, -5}};
  // Across z the heights vanish: inside the triangle, beside it, and beyond a corner.
  EXPECT_EQ(distance_to_hull_across({0.2, 0.2, 9}, tri, Vec3::UnitZ()), 0.0);
  EXPECT_NEAR(distance_to_hull_across({0.5, -0.4, 0}, tri, Vec3::UnitZ()), 0.4, kRoundOff);
  EXPECT_NEAR(distance_to_hull_across({-3, -4, 1}, tri, Vec3::UnitZ()), 5.0, kRoundOff);
  // A single point and a segment are hulls too.
  EXPECT_NEAR(distance_to_hull_across({3, 4, 0}, {Vec3::Zero()}, Vec3::UnitZ()), 5.0, kRoundOff);
  EXPECT_NEAR(distance_to_hull_across({0.5, 2, 0}, {Vec3::Zero(), Vec3::UnitX()}, Vec3::UnitZ()),
              2.0, kRoundOff);
}

// Chrono's face_rot_offset case, as the oracle computes its patch: a unit cube turned 30 degrees
// about z and offset, resting on a larger box. The oracle's own points cover the patch, and so
// does the manifold `custom`'s world steps with; `custom`'s contact query answers with one
// point, the region's centre, which leaves each corner half the face's diagonal away and cannot
// hold the cube.
TEST(PatchCover, TheOraclesPatchIsCoveredByItsOwnPointsAndCustomsManifoldNotByOnePoint) {
  const auto in = bodies_of(
      "[[body]]\nname = \"A\"\nposition = [0.3, 0.2, 0.99]\nrotation = [0, 0, 30]\n"
      "[[body]]\nname = \"B\"\nsize = [3, 3, 1]\nstatic = true\n");
  const SatResult sat = sat_query(*in[0].shape, in[0].pose(), *in[1].shape, in[1].pose());
  ASSERT_TRUE(sat.touching);
  ASSERT_EQ(sat.manifold.size(), 4u);
  const ContactResult exact = exact_contact(in[0], in[1]);
  const PatchCover own = patch_cover(exact.contacts, in[0], in[1], sat.manifold, sat.normal);
  EXPECT_LE(own.coverage_err, 1e-12);
  EXPECT_EQ(own.worst_point_err, 0.0);
  EXPECT_EQ(own.support_err.value_or(-1), 0.0);
  const auto m =
      build_manifold(*in[0].shape, in[0].pose(), *in[1].shape, in[1].pose(), Detector::Accelerated);
  ASSERT_TRUE(m);
  std::vector<ContactPoint> step;
  for (const ManifoldPoint& p : m->points) step.push_back({p.point, m->normal, p.depth, "step"});
  ASSERT_EQ(step.size(), 4u);
  const PatchCover stepped = patch_cover(step, in[0], in[1], sat.manifold, sat.normal);
  // The clipped patch's corners, midway across the 0.01 overlap: across the normal they are the
  // oracle's corners (round-off of the rotation).
  EXPECT_LE(stepped.coverage_err, 1e-12);
  EXPECT_EQ(stepped.support_err.value_or(-1), 0.0);
  // `custom` answers with the step's manifold (one pipeline): its one-point contact first, then
  // the same points.
  const ContactResult answer = find_backend("custom")->contact(in[0], in[1]);
  ASSERT_EQ(answer.contacts.size(), 1 + step.size());
  for (size_t i = 0; i < step.size(); ++i) {
    EXPECT_EQ(answer.contacts[i + 1].point, step[i].point);
    EXPECT_EQ(answer.contacts[i + 1].depth, step[i].depth);
  }
  EXPECT_LE(patch_cover(answer.contacts, in[0], in[1], sat.manifold, sat.normal).coverage_err,
            1e-12);
  // Its one point alone (the centre of the region) falls short of the square's corners by half
  // its diagonal and holds nothing.
  const PatchCover short_answer =
      patch_cover({answer.contacts[0]}, in[0], in[1], sat.manifold, sat.normal);
  EXPECT_NEAR(short_answer.coverage_err, std::sqrt(0.5), 1e-9);
  EXPECT_EQ(short_answer.support_err.value_or(-1), 1.0);
}

TEST(PatchCover, ATiedAxisIsMeasuredAgainstItsOwnPatch) {
  // A 0.1 m cube on a unit cube's diagonal near its corner: the least overlap, 0.15, is reached
  // along x, y and z alike. The oracle takes one of them; an answer on another tied axis is
  // measured against that axis's patch (the small cube's face on the big cube's face: a 0.1 m
  // square), not against the oracle's, across which it would fall short by 0.433 of the small
  // cube. A normal off every tied axis keeps the oracle's patch.
  const auto in = bodies_of(
      "[[body]]\nname = \"A\"\nsize = [0.1, 0.1, 0.1]\nposition = [0.4, 0.4, 0.4]\n"
      "[[body]]\nname = \"B\"\n");
  const SatResult sat = sat_query(*in[0].shape, in[0].pose(), *in[1].shape, in[1].pose());
  ASSERT_TRUE(sat.touching);
  ASSERT_NEAR(sat.depth, 0.15, 1e-12);
  for (const Vec3& axis : {Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0, 1)}) {
    ContactResult r;
    r.contacts.push_back({Vec3(0.4, 0.4, 0.4), axis, 0.15, "face"});
    const SatPatch truth = true_patch(r, in[0], in[1], sat);
    EXPECT_NEAR((truth.normal - axis).norm(), 0.0, 1e-12);
    ASSERT_EQ(truth.corners.size(), 4u);
    // The square spans 0.35 to 0.45 across the axis, in both other coordinates.
    for (const Vec3& c : truth.corners) {
      for (int k = 0; k < 3; ++k) {
        if (axis[k] == 0.0) {
          EXPECT_NEAR(std::abs(c[k] - 0.4), 0.05, 1e-12);
        }
      }
    }
    // On the oracle's own axis, its own patch.
    if ((axis - sat.normal).norm() < 1e-12) {
      EXPECT_EQ(truth.corners, sat.manifold);
    }
  }
  ContactResult off;
  off.contacts.push_back({Vec3(0.4, 0.4, 0.4), Vec3(1, 1, 1).normalized(), 0.26, "mpr"});
  const SatPatch kept = true_patch(off, in[0], in[1], sat);
  EXPECT_EQ(kept.normal, sat.normal);
  EXPECT_EQ(kept.corners, sat.manifold);
}

}  // namespace
}  // namespace rbx

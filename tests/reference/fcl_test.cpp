// Tests of the FCL 0.7 adapters: fcl-hull (Convex, MPR), fcl-epa (signed distance, GJK + EPA),
// fcl-indep (Convex, GST_INDEP, defects passed on) and fcl on boxes (fcl::Box, boxBoxIntersect;
// formerly the separate backend fcl-box).
//
// Every expected value is derived by hand from the geometry in the comment next to it. Known
// wrong answers of the library are pinned as they are, so that an upgrade that changes them is
// noticed. Nothing here can abort (the GST_INDEP distance query is never called), because this
// executable does not link the isolation helper.
#include "reference/fcl.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "tests/common/fixtures.h"

namespace rbx {
namespace {

// The backends under test, by their registry names.
const Backend& fcl = fcl_adapter().backend("fcl");
const Backend& fcl_epa = fcl_adapter().backend("fcl-epa");
const Backend& fcl_hull = fcl_adapter().backend("fcl-hull");
const Backend& fcl_indep = fcl_adapter().backend("fcl-indep");

using test::box_at;
using test::cube_symmetries;
using test::depth_along;
using test::generic_rotation;
using test::sat_depth;
using test::unit_cube;

// Round-off bound for results that FCL computes exactly up to floating point: unit-scale
// coordinates and a few dozen operations give errors ~1e-15; 1e-12 leaves a wide margin.
constexpr double kRoundOff = 1e-12;

// FCL's signed distance (EPA) stops when its depth bounds are within distance_tolerance, left at
// FCL's default 1e-6 m by the adapter: the documented bound on the EPA depth.
constexpr double kEpaTolerance = 1e-6;

/// Angle between two directions, degrees.
double angle_deg(const Vec3& a, const Vec3& b) {
  const double c = a.normalized().dot(b.normalized());
  return std::acos(std::max(-1.0, std::min(1.0, c))) * 180.0 / M_PI;
}

/// Expects one Ok result whose every contact has the given normal and depth.
void expect_all_contacts(const ContactResult& r, const Vec3& normal, double depth,
                         double tolerance) {
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  ASSERT_FALSE(r.contacts.empty());
  for (const ContactPoint& c : r.contacts) {
    EXPECT_NEAR((c.normal - normal).norm(), 0.0, tolerance)
        << "normal " << c.normal.transpose() << " expected " << normal.transpose();
    EXPECT_NEAR(c.depth, depth, tolerance);
  }
}

// ---------------------------------------------------------------------------------------------
// The face-overlap pair used by every convention test: unit cubes, A at the origin, B at
// (0.9, 0, 0). Overlap per axis = 1 - |offset|: 0.1 along x, 1 along y and z; the least is x.
// B is on A's +x side, so A leaves B toward -x: normal (B -> A) = (-1, 0, 0), depth 0.1.
// The overlap region is the slab x in [0.4, 0.5], |y|, |z| <= 0.5, whose mid-plane is x = 0.45.
const Vec3 kFaceOffset(0.9, 0, 0);
const Vec3 kFaceNormal(-1, 0, 0);
constexpr double kFaceDepth = 0.1;
constexpr double kMidPlaneX = 0.45;

/// Runs `query` on the face pair in both orders and, rotated as a whole by a generic R, in
/// both orders again; each must give the expected normal (R * n, flipped when swapped), depth
/// 0.1 and points on the overlap's mid-plane.
void check_face_pair(const ContactFn& query, double tolerance) {
  for (const Quat& q : {Quat::Identity(), generic_rotation()}) {
    const RigidBody a = unit_cube("A", Vec3::Zero(), q);
    const RigidBody b = unit_cube("B", q * kFaceOffset, q);
    // (A, B): n = R (-1, 0, 0); (B, A): the opposite.
    expect_all_contacts(query(a, b), q * kFaceNormal, kFaceDepth, tolerance);
    expect_all_contacts(query(b, a), -(q * kFaceNormal), kFaceDepth, tolerance);
    // Points: on the mid-plane x = 0.45 of the overlap (in A's frame), inside the |y|,|z| <= 0.5
    // square.
    for (const ContactPoint& c : query(a, b).contacts) {
      const Vec3 local = q.conjugate() * c.point;
      EXPECT_NEAR(local.x(), kMidPlaneX, tolerance);
      EXPECT_LE(std::abs(local.y()), 0.5 + tolerance);
      EXPECT_LE(std::abs(local.z()), 0.5 + tolerance);
    }
  }
}

/// Touching pair: B at (1, 0, 0), gap 0. Separated pair: B at (1.1, 0, 0), gap 0.1.
RigidBody touching_b() { return unit_cube("B", Vec3(1.0, 0, 0)); }
RigidBody separated_b() { return unit_cube("B", Vec3(1.1, 0, 0)); }

// ---------------------------------------------------------------------------------------------
// FCL issue 545 (docs/references.md): a cube of side 0.1 centred at (0.4, 0.4, 0.4), on the
// diagonal of a unit cube A at the origin. B spans [0.35, 0.45]^3, entirely inside A. The least
// translation of A that frees B is 0.5 - 0.35 = 0.15 along -x, -y or -z (a three-way tie; the
// other way round each axis costs 0.45 + 0.5 = 0.95): truth normal in {-x, -y, -z}, depth 0.15.
// MPR instead follows the ray from the Minkowski difference's interior point c_A - c_B =
// -(0.4, 0.4, 0.4) through the origin, i.e. along (1, 1, 1)/sqrt(3). A - B is the cube of
// half-extent 0.55 about -(0.4, 0.4, 0.4); the ray leaves it exactly at its corner
// (0.15, 0.15, 0.15). So MPR reports the A -> B direction (1, 1, 1)/sqrt(3) and depth
// |(0.15, 0.15, 0.15)| = 0.15 sqrt(3) ~ 0.2598: ours n = -(1, 1, 1)/sqrt(3).
constexpr double kDiagonalDepth = 0.15;
const Vec3 kDiagonalCentre(0.4, 0.4, 0.4);
RigidBody diagonal_big() { return unit_cube("A", Vec3::Zero()); }
RigidBody diagonal_small() { return box_at("B", Vec3::Constant(0.1), kDiagonalCentre); }

/// True when n is one of -x, -y, -z (within tol): a correct answer on the diagonal pair.
bool is_negative_axis(const Vec3& n, double tol) {
  for (int i = 0; i < 3; ++i)
    if ((n + Vec3::Unit(i)).norm() <= tol) return true;
  return false;
}

// ---------------------------------------------------------------------------------------------
// fcl: Convex, GST_LIBCCD (libccd MPR).

TEST(FclMpr, FacePairConventionBothOrdersAndRotated) {
  // MPR's portal lands on the exact hull face here: only round-off remains.
  check_face_pair(fcl_hull.contact, kRoundOff);
}

TEST(FclMpr, ExactTouchingOffCentreHasNoNormalAndIsTouching) {
  // scenes/contact/touching_zero_depth.toml: A exactly on top of B, shifted (0.3, 0.2). Unlike
  // the centred touching pair below, MPR here reports contact at a round-off depth with its
  // direction zeroed (mpr.c findPenetr, below CCD_EPS), which FCL copies as the normal.
  // Pinned: the adapter labels that as touching with no normal (status Touching, the library's
  // convention at zero depth), not a 180 deg miss and not an error.
  const ContactResult r =
      fcl_hull.contact(unit_cube("A", Vec3(0.3, 0.2, 1)), unit_cube("B", Vec3::Zero()));
  EXPECT_EQ(r.status, Status::Touching);
  EXPECT_NE(r.message.find("touching"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("no normal"), std::string::npos) << r.message;
}

TEST(FclMpr, OneContactLabelledMpr) {
  const ContactResult r =
      fcl_hull.contact(unit_cube("A", Vec3::Zero()), unit_cube("B", kFaceOffset));
  ASSERT_EQ(r.contacts.size(), 1u);  // Convex-Convex through MPR yields a single point
  EXPECT_EQ(r.contacts[0].feature, "mpr");
}

TEST(FclMpr, TouchingIsNoContactAndSeparatedIsNoContact) {
  // Pinned: at gap 0 libccd's MPR classifies the origin on the Minkowski boundary as outside
  // (ccdMPRPenetration returns -1), so FCL reports no collision. Truth is "touching, depth 0";
  // the difference is a boundary convention, not a depth error.
  const ContactResult touching = fcl_hull.contact(unit_cube("A", Vec3::Zero()), touching_b());
  EXPECT_EQ(touching.status, Status::Ok);
  EXPECT_TRUE(touching.contacts.empty());
  const ContactResult separated = fcl_hull.contact(unit_cube("A", Vec3::Zero()), separated_b());
  EXPECT_EQ(separated.status, Status::Ok);
  EXPECT_TRUE(separated.contacts.empty());
}

TEST(FclMpr, DiagonalCubeKnownWrongAnswerPinned) {
  // Known wrong answer (FCL issue 545), derived above: MPR gives n = -(1,1,1)/sqrt(3) and depth
  // 0.15 sqrt(3) where the truth is an axis and 0.15. MPR stops exactly at the corner of the
  // Minkowski difference, so the pin holds to round-off.
  const ContactResult r = fcl_hull.contact(diagonal_big(), diagonal_small());
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  ASSERT_EQ(r.contacts.size(), 1u);
  const ContactPoint& c = r.contacts[0];
  EXPECT_NEAR((c.normal - (-Vec3::Ones().normalized())).norm(), 0.0, kRoundOff);
  EXPECT_NEAR(c.depth, kDiagonalDepth * std::sqrt(3.0), kRoundOff);
  // The error against the truth: angle acos(1/sqrt(3)) = 54.74 deg, depth factor sqrt(3).
  EXPECT_NEAR(angle_deg(c.normal, -Vec3::UnitX()), std::acos(1.0 / std::sqrt(3.0)) * 180 / M_PI,
              1e-9);  // degrees; round-off of acos near 0.577 is ~1e-14 rad
  EXPECT_FALSE(is_negative_axis(c.normal, 0.1));
  // Swapping the order flips the (wrong) normal and keeps the depth.
  const ContactResult swapped = fcl_hull.contact(diagonal_small(), diagonal_big());
  ASSERT_EQ(swapped.contacts.size(), 1u);
  EXPECT_NEAR((swapped.contacts[0].normal - Vec3::Ones().normalized()).norm(), 0.0, kRoundOff);
  EXPECT_NEAR(swapped.contacts[0].depth, kDiagonalDepth * std::sqrt(3.0), kRoundOff);
}

// ---------------------------------------------------------------------------------------------
// fcl-epa: signed distance, GJK + EPA.

TEST(FclEpa, FacePairConventionBothOrdersAndRotated) {
  check_face_pair(fcl_epa.contact, kEpaTolerance);
}

TEST(FclEpa, TouchingHasNoNormalAndIsReportedAsTouching) {
  // Pinned: at gap 0 FCL returns min_distance 0 and two coincident nearest points, and 0.7's
  // DistanceResult carries no normal; the adapter says so (status Touching) instead of
  // inventing a direction.
  const ContactResult r = fcl_epa.contact(unit_cube("A", Vec3::Zero()), touching_b());
  EXPECT_EQ(r.status, Status::Touching);
  EXPECT_NE(r.message.find("no normal"), std::string::npos) << r.message;
  EXPECT_TRUE(r.contacts.empty());
}

TEST(FclEpa, DiagonalCubeGetsTheMinimumPenetration) {
  // Truth derived above: an axis among -x, -y, -z and depth 0.15, in both orders.
  const ContactResult r = fcl_epa.contact(diagonal_big(), diagonal_small());
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  ASSERT_EQ(r.contacts.size(), 1u);
  EXPECT_TRUE(is_negative_axis(r.contacts[0].normal, kEpaTolerance))
      << r.contacts[0].normal.transpose();
  EXPECT_NEAR(r.contacts[0].depth, kDiagonalDepth, kEpaTolerance);
  const ContactResult swapped = fcl_epa.contact(diagonal_small(), diagonal_big());
  ASSERT_EQ(swapped.contacts.size(), 1u);
  EXPECT_TRUE(is_negative_axis(-swapped.contacts[0].normal, kEpaTolerance));
  EXPECT_NEAR(swapped.contacts[0].depth, kDiagonalDepth, kEpaTolerance);
}

// ---------------------------------------------------------------------------------------------
// fcl-indep: GST_INDEP, defects shown as they are.

TEST(FclIndep, CarriesTheDefectNote) {
  const ContactResult r =
      fcl_indep.contact(unit_cube("A", Vec3::Zero()), unit_cube("B", Vec3(0.9, 0.2, 0.1)));
  EXPECT_EQ(r.status, Status::Ok);
  EXPECT_NE(r.message.find("local frame"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("negative"), std::string::npos) << r.message;
}

TEST(FclIndep, RotatedPairNormalInLocalFrameAndNegativeDepthPinned) {
  // Offset pair: B at (0.9, 0.2, 0.1) from A. Overlaps 0.1 (x), 0.8 (y), 0.9 (z): truth n =
  // (-1, 0, 0), depth 0.1. Rotated as a whole by R: truth n = R (-1, 0, 0), depth 0.1.
  // docs/references.md: GST_INDEP leaves the normal in A's local frame and negates the depth. With
  // only the documented A -> B flip applied, the adapter must show n = R^T (truth) = (-1, 0, 0)
  // and depth -0.1. EPA ends on the exact hull face (x = 0.1 of the Minkowski difference), so
  // round-off only.
  const Quat q = generic_rotation();
  const RigidBody a = unit_cube("A", Vec3::Zero(), q);
  const RigidBody b = unit_cube("B", q * Vec3(0.9, 0.2, 0.1), q);
  const Vec3 truth = q * Vec3(-1, 0, 0);
  const ContactResult r = fcl_indep.contact(a, b);
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  ASSERT_EQ(r.contacts.size(), 1u);
  const ContactPoint& c = r.contacts[0];
  EXPECT_NEAR((c.normal - q.conjugate() * truth).norm(), 0.0, kRoundOff);
  EXPECT_NEAR(c.depth, -0.1, kRoundOff);
  // It differs from the truth by exactly the rotation R: the angle between R^T t and t.
  const double rotation_angle_deg = 0.7 * 180.0 / M_PI;  // upper bound: angle of R itself
  EXPECT_GT(angle_deg(c.normal, truth), 1.0);            // clearly wrong, not round-off
  EXPECT_LE(angle_deg(c.normal, truth), rotation_angle_deg + 1e-9);
}

TEST(FclIndep, PublicBoxCaseNormalIsRotatedBackIntoALocalFrame) {
  // FCL's public case 1 (below, on fcl-box) as Convex through GST_INDEP: A is rotated 45 deg
  // about y, truth n = +z, depth sqrt(2)/2. The local-frame defect gives R_y(45)^T z =
  // (-sin 45, 0, cos 45); the depth is negated.
  const Quat q(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitY()));
  const ContactResult r = fcl_indep.contact(unit_cube("A", Vec3::Zero(), q),
                                            box_at("B", Vec3::Constant(3), Vec3(0, 0, -1.5)));
  ASSERT_EQ(r.contacts.size(), 1u);
  const double s = std::sqrt(0.5);
  EXPECT_NEAR((r.contacts[0].normal - Vec3(-s, 0, s)).norm(), 0.0, kRoundOff);
  EXPECT_NEAR(r.contacts[0].depth, -s, kRoundOff);
}

TEST(FclIndep, AlignedFacePairWrongEpaFacePinned) {
  // A further wrong answer, pinned: on the axis-aligned face pair (truth n = (-1, 0, 0), depth
  // 0.1) INDEP's EPA stops on a polytope face through the true witness (0.1, 0, 0) of the
  // Minkowski difference with a diagonal normal (1, -1, -1)/sqrt(3), so depth = 0.1/sqrt(3)
  // (negated). Ours (A -> B flipped): n = (-1, 1, 1)/sqrt(3), depth -0.1/sqrt(3). Depends on
  // EPA's tie-breaking on a degenerate (axis-aligned) pair: pinned so that a change is seen.
  const ContactResult r =
      fcl_indep.contact(unit_cube("A", Vec3::Zero()), unit_cube("B", kFaceOffset));
  ASSERT_EQ(r.contacts.size(), 1u);
  EXPECT_NEAR((r.contacts[0].normal - Vec3(-1, 1, 1).normalized()).norm(), 0.0, kRoundOff);
  EXPECT_NEAR(r.contacts[0].depth, -0.1 / std::sqrt(3.0), kRoundOff);
}

TEST(FclIndep, RotatedPairBothOrdersNormalInTheFirstBodysFramePinned) {
  // The rotated offset pair of RotatedPairNormalInLocalFrameAndNegativeDepthPinned in both
  // orders. (A, B): n = R^T (truth) = (-1, 0, 0), depth -0.1 (pinned above). (B, A): the truth
  // flips to R (1, 0, 0), and INDEP leaves it in the first body's (B's) frame, also R: (1, 0, 0),
  // depth -0.1. The point is the one defect-free output: FCL maps it to the world
  // (tf1 * (w0 - n d / 2)), on the overlap's mid-plane x = 0.45 of A's frame in both orders.
  const Quat q = generic_rotation();
  const RigidBody a = unit_cube("A", Vec3::Zero(), q);
  const RigidBody b = unit_cube("B", q * Vec3(0.9, 0.2, 0.1), q);
  for (bool swapped : {false, true}) {
    const ContactResult r = swapped ? fcl_indep.contact(b, a) : fcl_indep.contact(a, b);
    ASSERT_EQ(r.status, Status::Ok) << r.message;
    ASSERT_EQ(r.contacts.size(), 1u);
    const ContactPoint& c = r.contacts[0];
    EXPECT_NEAR((c.normal - Vec3(swapped ? 1 : -1, 0, 0)).norm(), 0.0, kRoundOff)
        << c.normal.transpose();
    EXPECT_NEAR(c.depth, -0.1, kRoundOff);
    const Vec3 local = q.conjugate() * c.point;  // A's frame
    EXPECT_NEAR(local.x(), kMidPlaneX, kRoundOff) << local.transpose();
    EXPECT_LE(std::abs(local.y() - 0.1), 0.4 + kRoundOff);  // |y - 0.2/2| within the overlap
    EXPECT_LE(std::abs(local.z() - 0.05), 0.45 + kRoundOff);
  }
}

TEST(FclIndep, PublicBoxCaseBothOrdersAndSymmetriesPinned) {
  // FCL's public case 1 (A = unit cube rotated 45 deg about y, B = size-3 cube below, truth:
  // ours n = +z for (A, B), depth sqrt(2)/2) with B in the 6 orientations that map it onto
  // itself. The geometry never changes, so any change in the output is INDEP's.
  //  - (B, A): FCL's A -> B normal is +z in the world, left in B's frame: S^T z for B's
  //    orientation S; ours is its opposite, -S^T z. Depth -sqrt(2)/2. B's frame shows through.
  //  - (A, B): A's frame does not change, so the local-frame normal is R_y(45)^T z =
  //    (-sin 45, 0, cos 45), depth -sqrt(2)/2, except for B turned 180 deg about x, where EPA
  //    stops on a wrong face of the Minkowski difference: the side face y = -2 (A's half-width
  //    0.5 + B's 1.5), ours (0, -1, 0) with depth -2. Pinned.
  const double s = std::sqrt(0.5);
  const RigidBody a =
      unit_cube("A", Vec3::Zero(), Quat(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitY())));
  const std::vector<Quat> syms = cube_symmetries();
  for (size_t k = 0; k < syms.size(); ++k) {
    const RigidBody b = box_at("B", Vec3::Constant(3), Vec3(0, 0, -1.5), syms[k]);
    const ContactResult ba = fcl_indep.contact(b, a);
    ASSERT_EQ(ba.contacts.size(), 1u) << "symmetry " << k;
    EXPECT_NEAR((ba.contacts[0].normal + syms[k].conjugate() * Vec3::UnitZ()).norm(), 0.0,
                kRoundOff)
        << "symmetry " << k << ": " << ba.contacts[0].normal.transpose();
    EXPECT_NEAR(ba.contacts[0].depth, -s, kRoundOff) << "symmetry " << k;

    const ContactResult ab = fcl_indep.contact(a, b);
    ASSERT_EQ(ab.contacts.size(), 1u) << "symmetry " << k;
    const bool wrong_face = k == 1;  // 180 deg about x
    const Vec3 n = wrong_face ? Vec3(0, -1, 0) : Vec3(-s, 0, s);
    EXPECT_NEAR((ab.contacts[0].normal - n).norm(), 0.0, kRoundOff)
        << "symmetry " << k << ": " << ab.contacts[0].normal.transpose();
    EXPECT_NEAR(ab.contacts[0].depth, wrong_face ? -2.0 : -s, kRoundOff) << "symmetry " << k;
  }
}

TEST(FclIndep, AlignedFacePairSwappedGivesAnotherWrongFacePinned) {
  // AlignedFacePairWrongEpaFacePinned with the bodies swapped: not the flip of (A, B)'s wrong
  // diagonal (1, -1, -1)/sqrt(3) but another one: FCL's A -> B normal (-1, -1, -1)/sqrt(3),
  // ours (1, 1, 1)/sqrt(3), same depth -0.1/sqrt(3). Truth: (1, 0, 0), 0.1.
  const ContactResult r =
      fcl_indep.contact(unit_cube("B", kFaceOffset), unit_cube("A", Vec3::Zero()));
  ASSERT_EQ(r.contacts.size(), 1u);
  EXPECT_NEAR((r.contacts[0].normal - Vec3(1, 1, 1).normalized()).norm(), 0.0, kRoundOff)
      << r.contacts[0].normal.transpose();
  EXPECT_NEAR(r.contacts[0].depth, -0.1 / std::sqrt(3.0), kRoundOff);
}

TEST(FclIndep, TouchingGivesAMinusZeroDepthContactPinned) {
  // Gap 0 (unlike MPR, which reports nothing): GJK ends "inside" and EPA returns depth 0,
  // negated to -0.0, at the corner (0.5, -0.5, -0.5) of the touching faces. The normal is
  // FCL's A -> B +x in both orders, so ours is (-1, 0, 0) for (A, B), right, and also
  // (-1, 0, 0) for (B, A), where the truth is (1, 0, 0): at zero depth the direction is
  // whatever EPA's first face was. Pinned exactly: 0 and its sign bit, no round-off.
  const RigidBody a = unit_cube("A", Vec3::Zero());
  for (bool swapped : {false, true}) {
    const ContactResult r =
        swapped ? fcl_indep.contact(touching_b(), a) : fcl_indep.contact(a, touching_b());
    ASSERT_EQ(r.status, Status::Ok) << r.message;
    ASSERT_EQ(r.contacts.size(), 1u) << "swapped " << swapped;
    const ContactPoint& c = r.contacts[0];
    EXPECT_EQ(c.depth, 0.0);
    EXPECT_TRUE(std::signbit(c.depth)) << "swapped " << swapped;
    EXPECT_NEAR((c.normal - Vec3(-1, 0, 0)).norm(), 0.0, kRoundOff)
        << "swapped " << swapped << ": " << c.normal.transpose();
    EXPECT_NEAR((c.point - Vec3(0.5, -0.5, -0.5)).norm(), 0.0, kRoundOff) << c.point.transpose();
  }
}

TEST(FclIndep, DiagonalCubeGetsTheMinimumPenetrationWithTheSignDefect) {
  // The MPR wrong answer's pair (DiagonalCubeKnownWrongAnswerPinned): INDEP's EPA finds the
  // true minimum, an axis (FCL picks +z of the three-way tie, A -> B) and 0.15, with the depth
  // negated. A is not rotated, so the local-frame defect does not show; the normal, ours -z,
  // flips with the order.
  for (bool swapped : {false, true}) {
    const ContactResult r = swapped ? fcl_indep.contact(diagonal_small(), diagonal_big())
                                    : fcl_indep.contact(diagonal_big(), diagonal_small());
    ASSERT_EQ(r.status, Status::Ok) << r.message;
    ASSERT_EQ(r.contacts.size(), 1u);
    EXPECT_NEAR((r.contacts[0].normal - Vec3(0, 0, swapped ? 1 : -1)).norm(), 0.0, kRoundOff)
        << r.contacts[0].normal.transpose();
    EXPECT_NEAR(r.contacts[0].depth, -kDiagonalDepth, kRoundOff);
  }
}

// ---------------------------------------------------------------------------------------------
// fcl on two boxes: fcl::Box, boxBoxIntersect (the former fcl-box).

TEST(FclBox, FacePairConventionBothOrdersAndRotated) { check_face_pair(fcl.contact, kRoundOff); }

TEST(FclBox, FacePairGivesTheFourCornersOfTheOverlapFace) {
  // B's -x face clipped by A's +x face is the whole unit square: 4 corners (0.45, +-0.5, +-0.5)
  // on the mid-plane, each at depth 0.1.
  const ContactResult r = fcl.contact(unit_cube("A", Vec3::Zero()), unit_cube("B", kFaceOffset));
  ASSERT_EQ(r.contacts.size(), 4u);
  for (const ContactPoint& c : r.contacts) {
    EXPECT_NEAR(std::abs(c.point.y()), 0.5, kRoundOff);
    EXPECT_NEAR(std::abs(c.point.z()), 0.5, kRoundOff);
    EXPECT_EQ(c.feature, "box-box");
  }
}

TEST(FclBox, TouchingGivesDepthZeroAndSeparatedNone) {
  // At gap 0 the face test passes with zero overlap: 4 contacts at x = 0.5, depth 0, n = -x
  // (the truth: touching).
  const ContactResult touching = fcl.contact(unit_cube("A", Vec3::Zero()), touching_b());
  expect_all_contacts(touching, kFaceNormal, 0.0, kRoundOff);
  const ContactResult separated = fcl.contact(unit_cube("A", Vec3::Zero()), separated_b());
  EXPECT_EQ(separated.status, Status::Ok);
  EXPECT_TRUE(separated.contacts.empty());
}

TEST(FclBox, VertexMassModelGivesTheSameBoxFrame) {
  // With mass_model = vertices the centre of mass is the corner average = the box centre, so
  // the answer is the solid model's: n = -x, depth 0.1.
  const RigidBody a =
      box_at("A", Vec3::Ones(), Vec3::Zero(), Quat::Identity(), MassModel::Vertices);
  const RigidBody b = box_at("B", Vec3::Ones(), kFaceOffset, Quat::Identity(), MassModel::Vertices);
  expect_all_contacts(fcl.contact(a, b), kFaceNormal, kFaceDepth, kRoundOff);
}

TEST(FclBox, ABoxAgainstAGeneralConvexRunsMpr) {
  // The same unit cube declared as a general convex shape is an fcl::Convex, so the pair runs
  // libccd MPR (one point), not boxBoxIntersect; the face overlap still gives n = -x, depth 0.1.
  RigidBody hull = unit_cube("B", kFaceOffset);
  hull.shape_kind = ShapeKind::Convex;
  const ContactResult r = fcl.contact(unit_cube("A", Vec3::Zero()), hull);
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  ASSERT_EQ(r.contacts.size(), 1u);
  EXPECT_EQ(r.contacts[0].feature, "mpr");
  expect_all_contacts(r, kFaceNormal, kFaceDepth, kRoundOff);
}

TEST(FclBox, DiagonalCubeGetsTheMinimumPenetration) {
  // Truth derived above: an axis among -x, -y, -z, depth 0.15 (SAT picks one of the tie).
  const ContactResult r = fcl.contact(diagonal_big(), diagonal_small());
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  ASSERT_FALSE(r.contacts.empty());
  for (const ContactPoint& c : r.contacts) {
    EXPECT_TRUE(is_negative_axis(c.normal, kRoundOff)) << c.normal.transpose();
    EXPECT_NEAR(c.depth, kDiagonalDepth, kRoundOff);
  }
}

TEST(FclBox, PublicCaseUnitCubeOnEdgeIntoBigCube) {
  // FCL box-box case 1: A = unit cube rotated 45 deg about y at the origin; B = cube of side 3
  // centred at (0, 0, -1.5), top face z = 0. A's lowest edge (along y) is at z = -sqrt(2)/2
  // (half the face diagonal), so depth sqrt(2)/2 along z; sideways A would have to move
  // 1.5 + sqrt(2)/2. Ours (B -> A): n = +z. The deepest points lie on that edge, x = 0, at the
  // mid-depth z = -sqrt(2)/4, |y| <= 0.5. Both orders and B's 6 symmetric orientations.
  const double depth = std::sqrt(2.0) / 2;
  const RigidBody a =
      unit_cube("A", Vec3::Zero(), Quat(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitY())));
  for (const Quat& sym : cube_symmetries()) {
    const RigidBody b = box_at("B", Vec3::Constant(3), Vec3(0, 0, -1.5), sym);
    for (bool swapped : {false, true}) {
      const ContactResult r = swapped ? fcl.contact(b, a) : fcl.contact(a, b);
      ASSERT_EQ(r.status, Status::Ok) << r.message;
      ASSERT_FALSE(r.contacts.empty());
      const Vec3 n = swapped ? Vec3(0, 0, -1) : Vec3(0, 0, 1);
      double deepest = 0.0;
      for (const ContactPoint& c : r.contacts) {
        EXPECT_NEAR((c.normal - n).norm(), 0.0, kRoundOff);
        // No point deeper than the true depth.
        EXPECT_LE(c.depth, depth + kRoundOff);
        // The deepest points: on the edge, at mid-depth.
        if (c.depth > depth - kRoundOff) {
          EXPECT_NEAR(c.point.x(), 0.0, kRoundOff);
          EXPECT_NEAR(c.point.z(), -depth / 2, kRoundOff);
          EXPECT_LE(std::abs(c.point.y()), 0.5 + kRoundOff);
        }
        deepest = std::max(deepest, c.depth);
      }
      EXPECT_NEAR(deepest, depth, kRoundOff);
    }
  }
}

TEST(FclBox, PublicCaseTiltedCubeOnRotatedCubeCullsToFour) {
  // FCL box-box case 2: A = unit cube tilted theta = 22.5 deg about x at the origin; B = unit
  // cube rotated 45 deg about z at (0, 0, -0.75), top face z = -0.25. A's lowest edge (along x)
  // sits at z = -(sqrt(2)/2) cos(pi/4 - theta) (half face diagonal, tilted), so depth =
  // sqrt(2)/2 cos(pi/4 - theta) - 0.25 ~ 0.40328 along z; ours n = +z. The clipped manifold has
  // 8 points; boxBoxIntersect keeps 4.
  const double theta = M_PI / 8;
  const double depth = std::sqrt(2.0) / 2 * std::cos(M_PI / 4 - theta) - 0.25;
  const RigidBody a = unit_cube("A", Vec3::Zero(), Quat(Eigen::AngleAxisd(theta, Vec3::UnitX())));
  const RigidBody b =
      unit_cube("B", Vec3(0, 0, -0.75), Quat(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitZ())));
  for (bool swapped : {false, true}) {
    const ContactResult r = swapped ? fcl.contact(b, a) : fcl.contact(a, b);
    ASSERT_EQ(r.status, Status::Ok) << r.message;
    ASSERT_EQ(r.contacts.size(), 4u);
    double deepest = 0.0;
    for (const ContactPoint& c : r.contacts) {
      EXPECT_NEAR((c.normal - Vec3(0, 0, swapped ? -1 : 1)).norm(), 0.0, kRoundOff);
      EXPECT_LE(c.depth, depth + kRoundOff);
      deepest = std::max(deepest, c.depth);
    }
    EXPECT_NEAR(deepest, depth, kRoundOff);
  }
}

TEST(FclConvexBackends, PublicCasesThroughMprAndEpa) {
  // The same two public cases on the Convex paths: a single deepest contact, n = +z, with the
  // depths derived above (both are face-vertex/edge cases where MPR's ray meets the right face).
  const Quat tilt_y(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitY()));
  const RigidBody a1 = unit_cube("A", Vec3::Zero(), tilt_y);
  const RigidBody b1 = box_at("B", Vec3::Constant(3), Vec3(0, 0, -1.5));
  const double theta = M_PI / 8;
  const RigidBody a2 = unit_cube("A", Vec3::Zero(), Quat(Eigen::AngleAxisd(theta, Vec3::UnitX())));
  const RigidBody b2 =
      unit_cube("B", Vec3(0, 0, -0.75), Quat(Eigen::AngleAxisd(M_PI / 4, Vec3::UnitZ())));
  const double depth1 = std::sqrt(2.0) / 2;
  const double depth2 = std::sqrt(2.0) / 2 * std::cos(M_PI / 4 - theta) - 0.25;
  expect_all_contacts(fcl_hull.contact(a1, b1), Vec3::UnitZ(), depth1, kRoundOff);
  expect_all_contacts(fcl_hull.contact(a2, b2), Vec3::UnitZ(), depth2, kRoundOff);
  expect_all_contacts(fcl_epa.contact(a1, b1), Vec3::UnitZ(), depth1, kEpaTolerance);
  expect_all_contacts(fcl_epa.contact(a2, b2), Vec3::UnitZ(), depth2, kEpaTolerance);
}

// ---------------------------------------------------------------------------------------------
// Randomised cross-check against the separating-axis theorem (fixed seed).

TEST(FclRandomBoxes, AgainstSeparatingAxes) {
  // Box sizes in [0.3, 1.5] m, B's centre uniform in a cube of half-side 1 m, random
  // orientations (most overlaps deep). Pairs within 1e-6 m of touching are skipped (boundary
  // convention). Invariants, whatever the library:
  //  - separated by SAT: no contact from any backend;
  //  - fcl-epa: depth = the SAT minimum and = the overlap along its own normal;
  //  - fcl (MPR): depth >= the SAT minimum (no direction needs less than the minimum);
  //  - fcl on boxes (Box-Box): deepest point between the SAT minimum and 1.05 times it: boxBox2
  //  prefers a face
  //    axis over an edge axis unless the edge is 5% shallower (fudge_factor = 1.05 in
  //    box_box-inl.h, inherited from ODE), so up to 5% too deep by design.
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> size(0.3, 1.5), offset(-1.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  auto random_vec = [&](std::uniform_real_distribution<double>& d) {
    const double x = d(rng), y = d(rng), z = d(rng);  // sequenced: same pairs on every compiler
    return Vec3(x, y, z);
  };
  auto random_quat = [&] {
    const double w = gauss(rng), x = gauss(rng), y = gauss(rng), z = gauss(rng);
    return Quat(w, x, y, z).normalized();
  };
  // EPA and MPR converge to FCL's default tolerances (1e-6 m for both: distance_tolerance and
  // gjk_tolerance), so kEpaTolerance bounds both; boxBox2 is a closed-form SAT: round-off only.
  const int samples = 300;
  int overlapping = 0, box_face_preferred = 0;
  for (int k = 0; k < samples; ++k) {
    const Vec3 size_a = random_vec(size);
    const Quat q_a = random_quat();
    const Vec3 size_b = random_vec(size);
    const Vec3 centre_b = random_vec(offset);
    const Quat q_b = random_quat();
    const RigidBody a = box_at("A", size_a, Vec3::Zero(), q_a);
    const RigidBody b = box_at("B", size_b, centre_b, q_b);
    const double truth = sat_depth(a, b);
    if (std::abs(truth) < 1e-6) continue;
    const ContactResult mpr = fcl_hull.contact(a, b);
    const ContactResult epa = fcl_epa.contact(a, b);
    const ContactResult box = fcl.contact(a, b);
    ASSERT_EQ(mpr.status, Status::Ok) << "sample " << k << ": " << mpr.message;
    ASSERT_EQ(epa.status, Status::Ok) << "sample " << k << ": " << epa.message;
    ASSERT_EQ(box.status, Status::Ok) << "sample " << k << ": " << box.message;
    if (truth < 0) {
      EXPECT_TRUE(mpr.contacts.empty() && epa.contacts.empty() && box.contacts.empty())
          << "sample " << k;
      continue;
    }
    ++overlapping;
    ASSERT_EQ(epa.contacts.size(), 1u) << "sample " << k;
    EXPECT_NEAR(epa.contacts[0].depth, truth, kEpaTolerance) << "sample " << k;
    EXPECT_NEAR(epa.contacts[0].depth, depth_along(a, b, epa.contacts[0].normal), kEpaTolerance)
        << "sample " << k;
    ASSERT_EQ(mpr.contacts.size(), 1u) << "sample " << k;
    EXPECT_GE(mpr.contacts[0].depth, truth - kEpaTolerance) << "sample " << k;
    ASSERT_FALSE(box.contacts.empty()) << "sample " << k;
    double deepest = 0.0;
    for (const ContactPoint& c : box.contacts) deepest = std::max(deepest, c.depth);
    EXPECT_GE(deepest, truth - kRoundOff) << "sample " << k;
    EXPECT_LE(deepest, 1.05 * truth + kRoundOff) << "sample " << k;
    if (deepest > truth + 1e-9) ++box_face_preferred;
  }
  // Representative sample: well over half the pairs overlap with these ranges.
  EXPECT_GT(overlapping, samples / 2);
  EXPECT_LT(overlapping, samples * 9 / 10);
  // The face preference does occur (about 1 pair in 5 here): the band's lower bound is the pin.
  EXPECT_GT(box_face_preferred, overlapping / 20);
}

TEST(FclEpa, PairWhereLibccdEpaUnderestimatesIsRight) {
  // The pair pinned in libccd_test.cpp (EpaUnderestimatesPinned), where libccd 2.1's own EPA
  // returns 0.7279 m: FCL's patched EPA returns the SAT minimum (~0.8124 m).
  const RigidBody a = box_at(
      "A", Vec3(1.1619617394816926, 1.1743795334951157, 1.1237059231902502), Vec3::Zero(),
      Quat(0.057171239174407154, 0.85098897643779126, -0.51827575490333189, 0.062765064104200047)
          .normalized());
  const RigidBody b = box_at(
      "B", Vec3(1.2277854676293352, 0.73704683757464129, 0.88691392538948266),
      Vec3(0.55841869342978101, 0.040565343341065541, -0.45090973054194416),
      Quat(0.31812010099052296, -0.8985848754636705, 0.28341090204507841, 0.10499087358296565)
          .normalized());
  const ContactResult r = fcl_epa.contact(a, b);
  ASSERT_EQ(r.status, Status::Ok) << r.message;
  ASSERT_EQ(r.contacts.size(), 1u);
  EXPECT_NEAR(r.contacts[0].depth, sat_depth(a, b), kEpaTolerance);
}

}  // namespace
}  // namespace rbx

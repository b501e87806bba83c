// A cause attaches to a contact answer only where its sign is measured on that answer: each sign
// on a hand-made answer against a stated truth, and, through the harness and the report, a
// library's explanation printed only where its symptom was measured in the run.
#include "comparisons/eval/contact_cause.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "comparisons/output/report_writer.h"
#include "comparisons/scene/scene_file.h"

namespace rbx {
namespace {

namespace s = contact_sign;

// Two unit cubes, A above B by 0.1 of overlap: the truth the signs are measured against. The
// line between the centres is the normal here; `off_line` moves it off (as for a small cube on
// a big one's diagonal).
ContactTruth face_truth(bool off_line = false) {
  ContactTruth t;
  t.touching = true;
  t.normal = Vec3::UnitZ();
  t.depth = 0.1;
  t.size = 1.0;
  t.centres = off_line ? Vec3(1, 1, 1).normalized() : Vec3::UnitZ();
  return t;
}

ContactPoint point(const Vec3& normal, double depth) {
  ContactPoint p;
  p.normal = normal.normalized();
  p.depth = depth;
  return p;
}

ContactResult answer(std::vector<ContactPoint> points) {
  return {Status::Ok, "", std::move(points)};
}

std::string sign_of(const ContactResult& r, const ContactTruth& t, double angle) {
  const auto c = contact_cause("lib", "scene", r, t, angle);
  return c ? c->kind : "none";
}

TEST(ContactCause, TouchingWithNoNormalIsAConventionAtZeroDepthAndAMissWhenDeep) {
  const ContactResult touching{Status::Touching, "no normal", {}};
  ContactTruth t = face_truth();
  EXPECT_EQ(sign_of(touching, t, 0), s::kTouchingWhenDeep);
  t.depth = 0.0;
  EXPECT_EQ(sign_of(touching, t, 0), s::kTouchingAtZeroDepth);
  t.depth = 1e-7;  // above round-off of a unit body (1e-6 of its size is the floor): 1e-7 is not
  EXPECT_EQ(sign_of(touching, t, 0), s::kTouchingAtZeroDepth);
  t.depth = 1e-5;
  EXPECT_EQ(sign_of(touching, t, 0), s::kTouchingWhenDeep);
  t.touching = false;
  EXPECT_EQ(sign_of(touching, t, 0), s::kFalseContact);
}

TEST(ContactCause, MissedAndFalseContacts) {
  EXPECT_EQ(sign_of(answer({}), face_truth(), 0), s::kMissed);
  ContactTruth apart = face_truth();
  apart.touching = false;
  EXPECT_EQ(sign_of(answer({point(Vec3::UnitZ(), 0.01)}), apart, 0), s::kFalseContact);
  EXPECT_EQ(sign_of(answer({}), apart, 0), "none");
}

TEST(ContactCause, HalfTheDepthOnlyWhereTheDepthIsHalf) {
  const ContactTruth t = face_truth();
  EXPECT_EQ(sign_of(answer({point(Vec3::UnitZ(), 0.05)}), t, 0), s::kHalfDepth);
  // The right depth (an edge-edge case MuJoCo answers exactly): no sign at all.
  EXPECT_EQ(sign_of(answer({point(Vec3::UnitZ(), 0.1)}), t, 0), "none");
  // Shallow by another factor: named as shallow, not half.
  EXPECT_EQ(sign_of(answer({point(Vec3::UnitZ(), 0.06)}), t, 0), s::kTooShallow);
  EXPECT_EQ(sign_of(answer({point(Vec3::UnitZ(), 0.1414)}), t, 0), s::kTooDeep);
  EXPECT_EQ(sign_of(answer({point(Vec3::UnitZ(), -0.1)}), t, 0), s::kNegatedDepth);
  // Within the marks (1 % of the body in depth): a deviation at most, no cause.
  EXPECT_EQ(sign_of(answer({point(Vec3::UnitZ(), 0.095)}), t, 0), "none");
}

TEST(ContactCause, NormalSigns) {
  // A normal along the centres' line where the truth is not on it: MPR's sign.
  const Vec3 diagonal = Vec3(1, 1, 1).normalized();
  const double off = std::acos(diagonal.z()) * 180 / M_PI;
  EXPECT_EQ(sign_of(answer({point(diagonal, 0.26)}), face_truth(true), off), s::kCentreLine);
  // The same wrong normal where the centres lie along the truth: just a wrong normal.
  EXPECT_EQ(sign_of(answer({point(diagonal, 0.26)}), face_truth(false), off), s::kWrongNormal);
  // A side face's normal on some points, the true one on others (DART's triangle pairs).
  EXPECT_EQ(
      sign_of(answer({point(Vec3::UnitX(), 0.8), point(Vec3::UnitZ(), 0.1)}), face_truth(), 90.0),
      s::kMixedNormals);
  // Every point with the same wrong normal is not "mixed".
  EXPECT_EQ(
      sign_of(answer({point(Vec3::UnitX(), 0.8), point(Vec3::UnitX(), 0.8)}), face_truth(), 90.0),
      s::kWrongNormal);
}

// --- Through the harness and the report -------------------------------------------------------

// A backend named as a library whose answer is the exact oracle's, its depth times `factor`, or,
// with `touching`, status Touching (no normal): the signs come from the answers, not the names.
Backend scaled_exact(const std::string& name, double factor, bool touching = false) {
  const Backend exact = *find_backend("exact");
  Backend b{name, "test: the exact answer, depth scaled",
            [exact, factor, touching](const RigidBody& a, const RigidBody& bb) {
              if (touching) return ContactResult{Status::Touching, "no normal", {}};
              ContactResult r = exact.contact(a, bb);
              for (ContactPoint& p : r.contacts) p.depth *= factor;
              return r;
            },
            nullptr};
  return b;
}

std::string details_for(const Backend& lib, Scene& scene, SceneEvaluation& ev) {
  const std::vector<Backend> table = {*find_backend("custom"), *find_backend("exact"), lib};
  HarnessOptions opt;
  opt.registry = &table;
  opt.studies = false;
  ev = evaluate_scene(scene, opt);
  return report_details_markdown({scene}, {ev}, "/nonexistent", false, false);
}

TEST(ContactCauseReport, AnExplanationIsPrintedOnlyWhereItsSignIsMeasured) {
  Scene scene = parse_scene(
      "checks = [\"contact\"]\n[sim]\nduration = 0\n[[body]]\nname = \"A\"\n"
      "position = [0, 0, 0.9]\n[[body]]\nname = \"B\"\n",
      "pair.toml");
  SceneEvaluation ev;
  const std::string half = details_for(scaled_exact("mujoco", 0.5), scene, ev);
  EXPECT_NE(half.find(s::kHalfDepth), std::string::npos);
  EXPECT_NE(half.find("**mujoco, half the depth**"), std::string::npos);
  // The same library answering the true depth: no sign, no explanation.
  const std::string right = details_for(scaled_exact("mujoco", 1.0), scene, ev);
  EXPECT_EQ(right.find("**mujoco, half the depth**"), std::string::npos);
  EXPECT_TRUE(ev.causes.empty());
  // Shallow by another factor: measured as such, and MuJoCo's explanation does not attach.
  const std::string shallow = details_for(scaled_exact("mujoco", 0.7), scene, ev);
  EXPECT_NE(shallow.find(s::kTooShallow), std::string::npos);
  EXPECT_EQ(shallow.find("**mujoco, half the depth**"), std::string::npos);
}

TEST(ContactCauseReport, TouchingOnAPenetratingPairIsAMarkedMiss) {
  Scene deep = parse_scene(
      "checks = [\"contact\"]\n[sim]\nduration = 0\n[[body]]\nname = \"A\"\n"
      "position = [0, 0, 0.9]\n[[body]]\nname = \"B\"\n",
      "deep.toml");
  SceneEvaluation ev;
  const std::string md = details_for(scaled_exact("libccd-epa", 1.0, true), deep, ev);
  bool miss = false;
  for (const std::string& d : ev.disagreements)
    miss = miss || d.find(
                       "libccd-epa on A-B: reports touching with no normal on a pair 0.1 m "
                       "deep (a miss)") != std::string::npos;
  EXPECT_TRUE(miss);
  double depth_err = -1;
  for (const Metric& m : ev.metrics)
    if (m.backend == "libccd-epa" && m.name == "depth_err") depth_err = m.value;
  EXPECT_NEAR(depth_err, 0.1, 1e-12);  // the true depth: the answer's zero, scored
  EXPECT_NE(md.find("touching, no normal ✗"), std::string::npos);
  EXPECT_NE(md.find("**libccd-epa, touching with no normal on a penetrating pair**"),
            std::string::npos);
  EXPECT_EQ(md.find("convention where the pair does touch"), std::string::npos);
  // Exactly touching: the convention, not marked, and its explanation instead.
  Scene flush = parse_scene(
      "checks = [\"contact\"]\n[sim]\nduration = 0\n[[body]]\nname = \"A\"\n"
      "position = [0, 0, 1]\n[[body]]\nname = \"B\"\n",
      "flush.toml");
  const std::string zero = details_for(scaled_exact("libccd-epa", 1.0, true), flush, ev);
  EXPECT_TRUE(ev.disagreements.empty());
  EXPECT_EQ(zero.find("touching, no normal ✗"), std::string::npos);
  EXPECT_NE(zero.find("convention where the pair does touch"), std::string::npos);
}

}  // namespace
}  // namespace rbx

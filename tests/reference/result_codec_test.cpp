// The byte encoding results cross the isolation pipe and the result cache in: every field comes
// back bit for bit, and an input that is not exactly one encoding is refused.
#include "reference/result_codec.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "tests/common/fixtures.h"

namespace rbx {
namespace {

using test::same_bits;

// Bitwise equality: the encoding promises the same bits (NaN and -0.0 included), not nearness.
bool same_bits(const Vec3& a, const Vec3& b) {
  return same_bits(a.x(), b.x()) && same_bits(a.y(), b.y()) && same_bits(a.z(), b.z());
}
bool same_bits(const Quat& a, const Quat& b) {
  return same_bits(a.w(), b.w()) && same_bits(a.vec(), b.vec());
}

BodyFinal final_of(const char* name, double k) {
  return {name, Vec3(k, -0.0, 1e-300), Quat(0.5, 0.5, -0.5, 0.5), Vec3(k / 3, 2, 3),
          Vec3(std::nextafter(1.0, 2.0), 0, -k)};
}

void expect_same(const BodyFinal& a, const BodyFinal& b) {
  EXPECT_EQ(a.name, b.name);
  EXPECT_TRUE(same_bits(a.position, b.position));
  EXPECT_TRUE(same_bits(a.orientation, b.orientation));
  EXPECT_TRUE(same_bits(a.velocity, b.velocity));
  EXPECT_TRUE(same_bits(a.angular_velocity, b.angular_velocity));
}

TEST(ResultCodec, ContactResultComesBackBitForBit) {
  ContactResult r;
  r.status = Status::Touching;
  r.message = std::string("with a \0 byte", 13);
  r.contacts.push_back({Vec3(0.1, 0.2, 0.3), Vec3(0, 0, 1), 1.0 / 3.0, "face-vertex"});
  r.contacts.push_back(
      {Vec3(std::numeric_limits<double>::quiet_NaN(), 0, 0), Vec3(1, 0, 0), -0.0, ""});
  ContactResult back;
  double runtime = 0;
  ASSERT_TRUE(decode_result(encode_result(r, 1.25e-6), back, runtime));
  EXPECT_TRUE(same_bits(runtime, 1.25e-6));
  EXPECT_EQ(back.status, r.status);
  EXPECT_EQ(back.message, r.message);
  ASSERT_EQ(back.contacts.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_TRUE(same_bits(back.contacts[i].point, r.contacts[i].point));
    EXPECT_TRUE(same_bits(back.contacts[i].normal, r.contacts[i].normal));
    EXPECT_TRUE(same_bits(back.contacts[i].depth, r.contacts[i].depth));
    EXPECT_EQ(back.contacts[i].feature, r.contacts[i].feature);
  }
}

TEST(ResultCodec, DynamicsResultComesBackBitForBit) {
  DynamicsResult r;
  r.status = Status::Error;
  r.message = "energy grew";
  CollisionEvent e;
  e.time = 0.125;
  e.step = 125;
  e.body_a = "cube";
  e.body_b = "floor";
  e.contact = {Vec3(0, 0, 0.5), Vec3(0, 0, 1), 1e-4, "vertex"};
  e.impulse = 2.5;
  r.events = {e, e};
  r.finals = {final_of("cube", 0.7), final_of("floor", 0.0)};
  r.samples = {{0.0, {final_of("cube", 1.0)}}, {0.01, {}}};
  r.first_impulse = {true, "cube", "floor", 125, 4, Vec3(0, 0, 1), Vec3(0.1, 0, 0),
                     1e-4, 2.5,    3.0,     0.3};
  DynamicsResult back;
  double runtime = 0;
  ASSERT_TRUE(decode_result(encode_result(r, 0.5), back, runtime));
  EXPECT_EQ(runtime, 0.5);
  EXPECT_EQ(back.status, r.status);
  EXPECT_EQ(back.message, r.message);
  ASSERT_EQ(back.events.size(), 2u);
  EXPECT_EQ(back.events[1].step, 125);
  EXPECT_EQ(back.events[1].body_b, "floor");
  EXPECT_TRUE(same_bits(back.events[1].contact.point, e.contact.point));
  EXPECT_EQ(back.events[1].impulse, 2.5);
  ASSERT_EQ(back.finals.size(), 2u);
  for (size_t i = 0; i < 2; ++i) expect_same(back.finals[i], r.finals[i]);
  ASSERT_EQ(back.samples.size(), 2u);
  ASSERT_EQ(back.samples[0].bodies.size(), 1u);
  expect_same(back.samples[0].bodies[0], r.samples[0].bodies[0]);
  EXPECT_TRUE(back.samples[1].bodies.empty());
  EXPECT_EQ(back.samples[1].time, 0.01);
  const FirstImpulse& f = back.first_impulse;
  EXPECT_TRUE(f.seen);
  EXPECT_EQ(f.body_a, "cube");
  EXPECT_EQ(f.step, 125);
  EXPECT_EQ(f.contact_points, 4);
  EXPECT_TRUE(same_bits(f.point, r.first_impulse.point));
  EXPECT_EQ(f.entry_phase, 0.3);
}

TEST(ResultCodec, MassResultComesBackBitForBit) {
  MassResult m;
  m.message = "default margin";
  m.mass = 2.0;
  m.volume = -1.0;
  m.center_of_mass = Vec3(0.1, -0.2, 0.3);
  m.inertia << 1, 0.1, 0.2, 0.1, 2, 0.3, 0.2, 0.3, 3;
  MassResult back;
  double runtime = -1;
  ASSERT_TRUE(decode_result(encode_result(m, 0.0), back, runtime));
  EXPECT_EQ(runtime, 0.0);
  EXPECT_EQ(back.message, m.message);
  EXPECT_EQ(back.volume, -1.0);
  EXPECT_TRUE(same_bits(back.center_of_mass, m.center_of_mass));
  EXPECT_EQ(back.inertia, m.inertia);
}

TEST(ResultCodec, DistanceResultComesBackBitForBit) {
  DistanceResult d;
  d.message = "btBoxShape with Bullet's margin";
  d.distance = 0.1 + 1e-17;
  d.point_a = Vec3(0.1, -0.2, 0.3 + 1e-16);
  d.point_b = Vec3(-0.0, 1e-300, 0.5);
  DistanceResult back;
  back.overlapping = true;
  double runtime = -1;
  ASSERT_TRUE(decode_result(encode_result(d, 2.5e-6), back, runtime));
  EXPECT_EQ(runtime, 2.5e-6);
  EXPECT_EQ(back.status, Status::Ok);
  EXPECT_EQ(back.message, d.message);
  EXPECT_FALSE(back.overlapping);
  EXPECT_EQ(back.distance, d.distance);
  EXPECT_TRUE(same_bits(back.point_a, d.point_a));
  EXPECT_TRUE(same_bits(back.point_b, d.point_b));
  // One encoding of another kind is not a distance.
  EXPECT_FALSE(decode_result(encode_result(MassResult{}, 0.0), back, runtime));
}

TEST(ResultCodec, TruncatedExtendedOrForeignBytesAreRefused) {
  ContactResult r;
  r.contacts.resize(3);
  const std::string bytes = encode_result(r, 1.0);
  ContactResult back;
  double runtime;
  for (size_t n = 0; n < bytes.size(); ++n)
    EXPECT_FALSE(decode_result(bytes.substr(0, n), back, runtime)) << n;
  EXPECT_FALSE(decode_result(bytes + "x", back, runtime));
  // A count larger than the bytes left is refused before anything is allocated for it.
  ByteWriter w;
  w.put(1.0);
  w.put(Status::Ok);
  w.put("");
  w.put(1L << 60);
  EXPECT_FALSE(decode_result(w.str(), back, runtime));
  // A mass encoding is not a contact's.
  EXPECT_FALSE(decode_result(encode_result(MassResult{}, 0.0), back, runtime));
}

}  // namespace
}  // namespace rbx

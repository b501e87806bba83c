// Determinism (docs/style.md, after Box2D's determinism check): the same many-body scene run twice
// gives bit-identical final states, hashed, and byte-identical JSON apart from runtime_s.
// Two scenes: the library's 64 cubes in a closed box (scenes/stress/many_bodies_walls.toml) and
// a 60-body scene built here that mixes shapes, rotations, gravity, restitution < 1 and both
// integrators.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "comparisons/eval/json_io.h"
#include "comparisons/scene/scene_file.h"
#include "engine/world.h"
#include "reference/backend.h"

namespace rbx {
namespace {

// FNV-1a, 64 bit, over raw bytes: any change of any bit of the hashed state changes it (up to
// collisions at 2^-64).
class Hash {
 public:
  void bytes(const void* p, size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (size_t i = 0; i < n; ++i) value_ = (value_ ^ b[i]) * 0x100000001b3ULL;
  }
  void number(double v) { bytes(&v, sizeof v); }
  void vec(const Vec3& v) {
    for (int k = 0; k < 3; ++k) number(v[k]);
  }
  void text(const std::string& s) { bytes(s.data(), s.size() + 1); }  // with the terminator
  uint64_t value() const { return value_; }

 private:
  uint64_t value_ = 0xcbf29ce484222325ULL;
};

// Hash of a run's outcome: every body's final state and every collision event, bitwise.
uint64_t state_hash(const RunResult& r) {
  Hash h;
  h.bytes(&r.steps_taken, sizeof r.steps_taken);
  h.text(r.message);
  for (const RigidBody& b : r.bodies) {
    h.text(b.name);
    h.vec(b.position);
    h.number(b.orientation.w());
    h.vec(b.orientation.vec());
    h.vec(b.velocity);
    h.vec(b.angular_velocity);
  }
  for (const CollisionEvent& e : r.events) {
    h.number(e.time);
    h.bytes(&e.step, sizeof e.step);
    h.text(e.body_a);
    h.text(e.body_b);
    h.vec(e.contact.point);
    h.vec(e.contact.normal);
    h.number(e.contact.depth);
    h.text(e.contact.feature);
    h.number(e.impulse);
  }
  return h.value();
}

// What `rbx run --json` writes for the custom backend, with runtime_s fixed at 0 (the one
// number that legitimately differs between runs).
std::string custom_json(const Scene& scene) {
  const Backend* custom = find_backend("custom");
  EXPECT_NE(custom, nullptr);
  if (!custom) return "";
  const DynamicsResult r = custom->dynamics(scene, DynamicsOptions{});
  EXPECT_EQ(r.status, Status::Ok) << r.message;
  return dynamics_result_json(make_bodies(scene), r, 0.0).dump();
}

// 60 free bodies (boxes, icosahedra, pentagonal prisms; rotated, moving and spinning) on a
// 3 x 4 x 5 grid, spacing 0.55 m, inside six static walls around [-1.5, 1.5]^3. Sizes are
// ~0.3 m, so the gaps are ~0.25 m, and speeds up to 4 m/s per axis close many of them within
// the 0.1 s run: body-body and body-wall collisions. Random numbers from a fixed seed.
Scene built_scene(Integrator integrator) {
  Scene s;
  s.name = "determinism 60";
  s.sim.dt = 1e-3;
  s.sim.duration = 0.1;
  s.sim.gravity = Vec3(0, 0, -9.81);
  s.sim.restitution = 0.8;
  s.sim.integrator = integrator;

  auto add = [&](const std::string& name, std::shared_ptr<const ConvexPolyhedron> shape,
                 ShapeKind kind) -> BodySpec& {
    BodySpec b;
    b.name = name;
    b.shape_kind = kind;
    b.shape = std::move(shape);
    s.bodies.push_back(b);
    return s.bodies.back();
  };
  // Walls: 0.2 m thick slabs whose inner faces are at +-1.5 m.
  for (int axis = 0; axis < 3; ++axis)
    for (int side : {-1, 1}) {
      Vec3 size = Vec3::Constant(3.4);
      size[axis] = 0.2;
      BodySpec& w = add("wall" + std::to_string(2 * axis + (side > 0)),
                        std::make_shared<const ConvexPolyhedron>(make_box(size)), ShapeKind::Box);
      w.box_size = size;
      w.is_static = true;
      w.position[axis] = side * 1.6;
    }
  std::mt19937 rng(20240607);  // fixed seed
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const auto box = std::make_shared<const ConvexPolyhedron>(make_box(Vec3(0.3, 0.25, 0.2)));
  const auto sphere = std::make_shared<const ConvexPolyhedron>(make_icosphere(0.15, 0));
  const auto prism = std::make_shared<const ConvexPolyhedron>(make_prism(0.15, 0.3, 5));
  int n = 0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 5; ++k, ++n) {
        const int kind = n % 3;
        BodySpec& b = add("b" + std::to_string(n),
                          kind == 0   ? box
                          : kind == 1 ? sphere
                                      : prism,
                          kind == 0   ? ShapeKind::Box
                          : kind == 1 ? ShapeKind::Icosphere
                                      : ShapeKind::Prism);
        if (kind == 0) b.box_size = Vec3(0.3, 0.25, 0.2);
        b.mass = 1.0 + 0.5 * kind;
        b.position = Vec3(-0.55 + 0.55 * i, -0.825 + 0.55 * j, -1.1 + 0.55 * k);
        b.orientation =
            Quat(Eigen::AngleAxisd(3.0 * unit(rng), Vec3(unit(rng), unit(rng), 1).normalized()));
        b.velocity = 4.0 * Vec3(unit(rng), unit(rng), unit(rng));
        b.angular_velocity = 5.0 * Vec3(unit(rng), unit(rng), unit(rng));
      }
  return s;
}

// Two runs of `scene` with each contact model (`custom-seed`'s and `custom`'s): equal hashes of
// the final states, equal JSON; and the run really is a many-collision run (the premise of the
// test, not an expected value).
void expect_deterministic(const Scene& scene, size_t min_events) {
  for (const ContactModel model : {ContactModel::Seed, ContactModel::Extended}) {
    const RunResult first = run_world(scene, model);
    const RunResult second = run_world(scene, model);
    ASSERT_TRUE(first.ok) << first.message;
    EXPECT_GE(first.events.size(), min_events) << "too few collisions to test anything";
    std::printf("%zu collision events\n", first.events.size());
    EXPECT_EQ(state_hash(first), state_hash(second));
    EXPECT_EQ(first.events.size(), second.events.size());
  }

  const std::string json_first = custom_json(scene);
  const std::string json_second = custom_json(scene);
  EXPECT_EQ(json_first, json_second);
  EXPECT_NE(json_first.find("\"runtime_s\":0.0"), std::string::npos)
      << "runtime_s is the only field allowed to differ; it must be the one fixed here";
}

TEST(Determinism, LibraryScene64CubesInABox) {
  // 0.15 s of the 2 s scene keeps the test short; 64 cubes at up to 2 m/s in a 3 m box already
  // collide with each other and the walls dozens of times by then.
  const Scene scene = load_scene(
      std::string(RBX_SOURCE_DIR) + "/scenes/stress/many_bodies_walls.toml", {"sim.duration=0.15"});
  ASSERT_GE(scene.bodies.size(), 60u);
  expect_deterministic(scene, 20);
}

TEST(Determinism, BuiltScene60MixedBodiesSymplectic) {
  expect_deterministic(built_scene(Integrator::Symplectic), 20);
}

TEST(Determinism, BuiltScene60MixedBodiesEuler) {
  expect_deterministic(built_scene(Integrator::Euler), 20);
}

TEST(Determinism, HashSeesATinyChange) {
  // The hash can fail: one body's initial velocity changed by 1e-9 m/s moves that body by
  // 1e-10 m over the 0.1 s if nothing else happens (~10^6 ulps of a position of order 1 m);
  // collisions only spread the change.
  const Scene scene = built_scene(Integrator::Symplectic);
  Scene nudged = scene;
  nudged.bodies[6].velocity.x() += 1e-9;
  for (const ContactModel model : {ContactModel::Seed, ContactModel::Extended})
    EXPECT_NE(state_hash(run_world(scene, model)), state_hash(run_world(nudged, model)));
}

}  // namespace
}  // namespace rbx

// Broad phase: sweep and prune and the tree find exactly the pairs of the seed's all-pairs
// bounding check (the reference: bounding_check over every pair), in (i, j) order, on random
// crowds of mixed sizes, after small motions (the sweep keeps its order between calls), with
// exactly touching spheres; and a world gives identical events and states with every method.
#include "engine/broadphase.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "engine/bounding.h"
#include "engine/world.h"
#include "tests/common/fixtures.h"

namespace rbx {
namespace {

constexpr BroadPhaseMethod kMethods[] = {BroadPhaseMethod::AllPairs,
                                         BroadPhaseMethod::SweepAndPrune, BroadPhaseMethod::Tree};

// The reference: the seed's double loop over bounding_check.
std::vector<BodyPair> oracle_pairs(const std::vector<RigidBody>& bodies) {
  std::vector<BodyPair> pairs;
  for (int i = 0; i < static_cast<int>(bodies.size()); ++i)
    for (int j = i + 1; j < static_cast<int>(bodies.size()); ++j)
      if (bounding_check(bodies[i], bodies[j])) pairs.push_back({i, j});
  return pairs;
}

// The grown reference: the pairs whose bounding spheres, each grown by `grow` (m), touch.
std::vector<BodyPair> grown_oracle_pairs(const std::vector<RigidBody>& bodies, double grow) {
  std::vector<BodyPair> pairs;
  for (int i = 0; i < static_cast<int>(bodies.size()); ++i)
    for (int j = i + 1; j < static_cast<int>(bodies.size()); ++j) {
      BoundingSphere a = bounding_sphere(bodies[i]), b = bounding_sphere(bodies[j]);
      a.radius += grow;
      b.radius += grow;
      if (spheres_touch(a, b)) pairs.push_back({i, j});
    }
  return pairs;
}

// A crowd of `n` boxes in a cube of side `extent` (m): sizes from 0.05 to 0.5 m, a few long
// slabs (walls, 20 x 0.2 x 20) so that small and large boxes mix, random orientations.
std::vector<RigidBody> crowd(int n, double extent, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<RigidBody> bodies;
  for (int i = 0; i < n; ++i) {
    const bool slab = i % 50 == 7;
    const Vec3 size =
        slab ? Vec3(20.0, 0.2, 20.0)
             : Vec3(0.05 + 0.45 * unit(rng), 0.05 + 0.45 * unit(rng), 0.05 + 0.45 * unit(rng));
    const Vec3 position = extent * Vec3(unit(rng), unit(rng), unit(rng));
    const Quat orientation = Quat(g(rng), g(rng), g(rng), g(rng)).normalized();
    bodies.push_back(test::box_body("b" + std::to_string(i), size, 1.0, position, orientation,
                                    Vec3::Zero(), Vec3::Zero(), slab));
  }
  return bodies;
}

TEST(BroadPhase, EveryMethodFindsTheOraclePairs) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> g(0.0, 1.0);
  // Density chosen so that each body has a few neighbours: the sample holds both pairs and
  // near misses (checked below, so the comparison cannot pass on empty sets).
  std::vector<RigidBody> bodies = crowd(600, 6.0, rng);
  BroadPhase sap(BroadPhaseMethod::SweepAndPrune), tree(BroadPhaseMethod::Tree),
      all(BroadPhaseMethod::AllPairs);
  for (int round = 0; round < 10; ++round) {
    const std::vector<BodyPair> expected = oracle_pairs(bodies);
    EXPECT_GT(expected.size(), bodies.size()) << "round " << round;
    EXPECT_LT(expected.size(), bodies.size() * bodies.size() / 20) << "round " << round;
    EXPECT_EQ(all.find_pairs(bodies), expected) << "round " << round;
    EXPECT_EQ(sap.find_pairs(bodies), expected) << "round " << round;
    EXPECT_EQ(tree.find_pairs(bodies), expected) << "round " << round;
    // A small motion (the sweep re-sorts its last order), and every fourth round a stretch along
    // a new axis (the sweep changes axis and sorts from scratch).
    for (RigidBody& b : bodies) {
      b.position += 0.05 * Vec3(g(rng), g(rng), g(rng));
      if (round % 4 == 3) b.position[round % 3] *= 3.0;
    }
  }
}

// Grown spheres (the extended step's one broad phase for a step's start and end): every method
// finds exactly the pairs whose spheres, each grown, touch, a strict superset of the seed's; on
// a crowd of mixed sizes (the tree's hierarchy) and one of like size (its grid).
TEST(BroadPhase, GrownSpheresGiveTheGrownOraclePairs) {
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<RigidBody> like;
  for (int i = 0; i < 600; ++i)
    like.push_back(test::box_body("c" + std::to_string(i), Vec3::Constant(0.3 + 0.2 * unit(rng)),
                                  1.0, 7.0 * Vec3(unit(rng), unit(rng), unit(rng))));
  const double grow = 0.03;
  // 290 boxes of 0.3 m and 10 of 2 m: beyond 2x of the median, the tree's hierarchy.
  std::vector<RigidBody> mixed;
  for (int i = 0; i < 300; ++i)
    mixed.push_back(test::box_body("m" + std::to_string(i), Vec3::Constant(i % 30 ? 0.3 : 2.0), 1.0,
                                   6.0 * Vec3(unit(rng), unit(rng), unit(rng))));
  const std::vector<RigidBody>* const crowds[] = {&mixed, &like};
  for (const std::vector<RigidBody>* crowd_of : crowds) {
    const std::vector<RigidBody>& bodies = *crowd_of;
    const std::vector<BodyPair> expected = grown_oracle_pairs(bodies, grow);
    EXPECT_GT(expected.size(), oracle_pairs(bodies).size());
    for (const BroadPhaseMethod m : kMethods) {
      BroadPhase bp(m);
      EXPECT_EQ(bp.find_pairs(bodies, grow), expected) << to_string(m);
      EXPECT_EQ(bp.find_pairs(bodies), oracle_pairs(bodies)) << to_string(m);
      if (m == BroadPhaseMethod::Tree) {
        EXPECT_EQ(bp.used_grid(), crowd_of == &like);
      }
    }
  }
}

TEST(BroadPhase, TheGridFindsTheOraclePairs) {
  // 800 moving boxes of like size (0.3 to 0.5 m: within 2x of the median, so the tree takes
  // its hashed grid), centred on the origin so that cells have negative coordinates too, two
  // static slabs among them; then moved and stretched as above. The grid's pairs are the
  // reference's, in order; moving boxes of widely mixed sizes take the hierarchy.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<RigidBody> bodies;
  for (int i = 0; i < 800; ++i) {
    const bool slab = i == 100 || i == 600;
    const Vec3 size = slab ? Vec3(20.0, 0.2, 20.0) : Vec3::Constant(0.3 + 0.2 * unit(rng));
    bodies.push_back(test::box_body(
        "b" + std::to_string(i), size, 1.0,
        8.0 * Vec3(unit(rng), unit(rng), unit(rng)) - Vec3::Constant(4.0),
        Quat(g(rng), g(rng), g(rng), g(rng)).normalized(), Vec3::Zero(), Vec3::Zero(), slab));
  }
  BroadPhase tree(BroadPhaseMethod::Tree);
  for (int round = 0; round < 6; ++round) {
    const std::vector<BodyPair> expected = oracle_pairs(bodies);
    EXPECT_GT(expected.size(), bodies.size()) << "round " << round;
    EXPECT_EQ(tree.find_pairs(bodies), expected) << "round " << round;
    EXPECT_TRUE(tree.used_grid()) << "round " << round;
    for (RigidBody& b : bodies) {
      b.position += 0.05 * Vec3(g(rng), g(rng), g(rng));
      if (round % 3 == 2) b.position[round % 3] *= 2.0;
    }
  }
  // 290 moving boxes of 0.3 m and 10 of 2 m: beyond 2x of the median, the hierarchy.
  std::vector<RigidBody> mixed;
  for (int i = 0; i < 300; ++i)
    mixed.push_back(test::box_body("m" + std::to_string(i), Vec3::Constant(i % 30 ? 0.3 : 2.0), 1.0,
                                   6.0 * Vec3(unit(rng), unit(rng), unit(rng))));
  EXPECT_EQ(tree.find_pairs(mixed), oracle_pairs(mixed));
  EXPECT_FALSE(tree.used_grid());
}

TEST(BroadPhase, ManyStaticBodiesGoIntoTheTree) {
  // 60 static boxes (beyond the 32 kept apart) among 240 moving ones, sizes mixed: every pair,
  // static against static included, is the reference's, in order.
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<RigidBody> bodies;
  for (int i = 0; i < 300; ++i)
    bodies.push_back(test::box_body("b" + std::to_string(i), Vec3::Constant(0.2 + unit(rng)), 1.0,
                                    5.0 * Vec3(unit(rng), unit(rng), unit(rng)), Quat::Identity(),
                                    Vec3::Zero(), Vec3::Zero(), i % 5 == 0));
  const std::vector<BodyPair> expected = oracle_pairs(bodies);
  int static_pairs = 0;
  for (const BodyPair& p : expected)
    static_pairs += bodies[p.first].is_static && bodies[p.second].is_static;
  EXPECT_GT(static_pairs, 10);
  BroadPhase tree(BroadPhaseMethod::Tree);
  EXPECT_EQ(tree.find_pairs(bodies), expected);
}

// The pairs kept from call to call: bodies creeping toward and away from each other across the
// touching distance, a growth that changes from call to call (up to near the kept pairs' room to
// move, so that a bound forgetting the growth fails), and now and then a jump (the kept pairs no
// longer hold): every call gives the grown reference's pairs, in order, on the grid and on
// the hierarchy; and most calls reuse the kept pairs (so the reuse is what is being checked).
TEST(BroadPhase, KeptPairsGiveTheOraclePairsFromCallToCall) {
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> g(0.0, 1.0);
  for (const bool like : {true, false}) {
    // 300 boxes of like size (the grid), or of 0.3 m with every thirtieth 2 m (the hierarchy),
    // each with a slow velocity of its own.
    std::vector<RigidBody> bodies;
    std::vector<Vec3> velocity;
    for (int i = 0; i < 300; ++i) {
      const double side = like ? 0.3 + 0.1 * unit(rng) : (i % 30 ? 0.3 : 2.0);
      bodies.push_back(test::box_body("c" + std::to_string(i), Vec3::Constant(side), 1.0,
                                      4.5 * Vec3(unit(rng), unit(rng), unit(rng))));
      velocity.push_back(0.002 * Vec3(g(rng), g(rng), g(rng)));
    }
    for (const BroadPhaseMethod m : {BroadPhaseMethod::SweepAndPrune, BroadPhaseMethod::Tree}) {
      std::vector<RigidBody> moving = bodies;
      BroadPhase bp(m);
      int calls = 0, changes = 0;
      std::vector<BodyPair> last;
      for (int round = 0; round < 200; ++round, ++calls) {
        const double grow = round % 3 == 0 ? 0.0 : 0.03 * unit(rng);
        const std::vector<BodyPair> expected = grown_oracle_pairs(moving, grow);
        ASSERT_EQ(bp.find_pairs(moving, grow), expected) << to_string(m) << " round " << round;
        if (expected != last) ++changes;
        last = expected;
        for (size_t i = 0; i < moving.size(); ++i) moving[i].position += velocity[i];
        if (round % 50 == 49) moving[round % 300].position += Vec3(1.0, 0.0, 0.0);
      }
      if (m == BroadPhaseMethod::Tree) {
        EXPECT_EQ(bp.used_grid(), like);
      }
      // Pairs came and went between reuses, and the jumps forced new indexes.
      EXPECT_GT(changes, 20) << to_string(m);
      EXPECT_GT(bp.index_builds(), 3) << to_string(m);
      EXPECT_LT(bp.index_builds(), calls / 3) << to_string(m);
    }
  }
}

TEST(BroadPhase, TheThresholdsChooseTheIndexNotThePairs) {
  // 100 moving boxes of like size and two static slabs: by default the grid (at least
  // grid_min_moving moving bodies) with the statics apart; with the thresholds moved, the
  // hierarchy, and the statics in it. The pairs are the reference's every time.
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<RigidBody> bodies;
  for (int i = 0; i < 102; ++i) {
    const bool slab = i == 10 || i == 60;
    const Vec3 size = slab ? Vec3(20.0, 0.2, 20.0) : Vec3::Constant(0.3 + 0.2 * unit(rng));
    bodies.push_back(test::box_body("b" + std::to_string(i), size, 1.0,
                                    4.0 * Vec3(unit(rng), unit(rng), unit(rng)), Quat::Identity(),
                                    Vec3::Zero(), Vec3::Zero(), slab));
  }
  const std::vector<BodyPair> expected = oracle_pairs(bodies);
  EXPECT_GT(expected.size(), bodies.size());
  BroadPhase by_default(BroadPhaseMethod::Tree);
  EXPECT_EQ(by_default.find_pairs(bodies), expected);
  EXPECT_TRUE(by_default.used_grid());
  WorldSettings moved;
  moved.grid_min_moving = 1000;
  moved.statics_apart = 0;
  BroadPhase hierarchy(BroadPhaseMethod::Tree, moved);
  EXPECT_EQ(hierarchy.find_pairs(bodies), expected);
  EXPECT_FALSE(hierarchy.used_grid());
}

TEST(BroadPhase, ExactlyTouchingSpheresArePairs) {
  // A (6, 4, 12) box has half extents (3, 2, 6), so its bounding sphere has radius
  // sqrt(9 + 4 + 36) = 7 exactly. Centres 14 apart: |c_a - c_b| = 14 = 7 + 7, touching
  // (seed correction 7 (bounding check on the sum of radii) counts equality); 14.000001 apart:
  // separated. Both distances and the radii are exact in floating point, so the answers are exact.
  std::vector<RigidBody> bodies = {
      test::box_body("a", Vec3(6, 4, 12), 1.0, Vec3(0, 0, 0)),
      test::box_body("b", Vec3(6, 4, 12), 1.0, Vec3(14, 0, 0)),
      test::box_body("c", Vec3(6, 4, 12), 1.0, Vec3(0, 14.000001, 0)),
      test::box_body("d", Vec3(6, 4, 12), 1.0, Vec3(0, 0, -14)),
  };
  const std::vector<BodyPair> expected = {{0, 1}, {0, 3}};
  ASSERT_EQ(oracle_pairs(bodies), expected);
  for (BroadPhaseMethod m : kMethods) {
    BroadPhase bp(m);
    EXPECT_EQ(bp.find_pairs(bodies), expected) << to_string(m);
  }
}

TEST(BroadPhase, EmptyAndSingleBody) {
  std::vector<RigidBody> bodies;
  for (BroadPhaseMethod m : kMethods) {
    BroadPhase bp(m);
    EXPECT_TRUE(bp.find_pairs(bodies).empty()) << to_string(m);
    bodies = {test::box_body("a", Vec3(1, 1, 1), 1.0, Vec3::Zero())};
    EXPECT_TRUE(bp.find_pairs(bodies).empty()) << to_string(m);
    bodies.clear();
  }
}

TEST(BroadPhase, CoincidentBodiesAreAllPairs) {
  // Five boxes at the same point: every one of the 5 * 4 / 2 = 10 pairs touches.
  std::vector<RigidBody> bodies;
  for (int i = 0; i < 5; ++i)
    bodies.push_back(test::box_body("b" + std::to_string(i), Vec3(1, 1, 1), 1.0, Vec3(1, 2, 3)));
  for (BroadPhaseMethod m : kMethods) {
    BroadPhase bp(m);
    EXPECT_EQ(bp.find_pairs(bodies).size(), 10u) << to_string(m);
  }
}

TEST(BroadPhase, WorldResultsDoNotDependOnTheMethod) {
  // 80 boxes with random velocities in a closed room of static walls, e = 1, 0.3 s: many
  // collisions. Every method must give the same events (same pairs, same order, same values)
  // and the same final states, bit for bit.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<RigidBody> bodies;
  const double room = 1.5;  // m, half side of the room's interior
  for (int axis = 0; axis < 3; ++axis)
    for (int side : {-1, 1}) {
      Vec3 size = Vec3::Constant(2 * room + 0.4);
      size[axis] = 0.2;
      Vec3 position = Vec3::Zero();
      position[axis] = side * (room + 0.1);
      bodies.push_back(test::box_body("wall" + std::to_string(bodies.size()), size, 1.0, position,
                                      Quat::Identity(), Vec3::Zero(), Vec3::Zero(), true));
    }
  for (int i = 0; i < 80; ++i) {
    const Vec3 p(-1.2 + 0.6 * (i % 5), -1.2 + 0.6 * ((i / 5) % 5), -1.0 + 0.5 * (i / 25));
    bodies.push_back(test::box_body("b" + std::to_string(i), Vec3(0.25, 0.25, 0.25), 1.0, p,
                                    Quat::Identity(), 2.0 * Vec3(unit(rng), unit(rng), unit(rng))));
  }
  SimSettings sim;
  sim.dt = 1e-3;
  sim.duration = 0.3;
  std::vector<RunResult> results;
  for (BroadPhaseMethod m : kMethods)
    results.push_back(World(sim, bodies, ContactModel::Seed, Detector::Accelerated, m).run());
  const RunResult& reference = results[0];
  ASSERT_TRUE(reference.ok) << reference.message;
  EXPECT_GT(reference.events.size(), 50u);  // the scene is busy: the comparison is not vacuous
  for (std::size_t k = 1; k < results.size(); ++k) {
    const RunResult& r = results[k];
    ASSERT_EQ(r.events.size(), reference.events.size()) << to_string(kMethods[k]);
    for (std::size_t e = 0; e < r.events.size(); ++e) {
      EXPECT_EQ(r.events[e].step, reference.events[e].step);
      EXPECT_EQ(r.events[e].body_a, reference.events[e].body_a);
      EXPECT_EQ(r.events[e].body_b, reference.events[e].body_b);
      EXPECT_EQ(r.events[e].contact.point, reference.events[e].contact.point);
      EXPECT_EQ(r.events[e].contact.normal, reference.events[e].contact.normal);
      EXPECT_EQ(r.events[e].impulse, reference.events[e].impulse);
    }
    for (std::size_t b = 0; b < r.bodies.size(); ++b) {
      EXPECT_EQ(r.bodies[b].position, reference.bodies[b].position) << r.bodies[b].name;
      EXPECT_EQ(r.bodies[b].velocity, reference.bodies[b].velocity) << r.bodies[b].name;
      EXPECT_EQ(r.bodies[b].angular_velocity, reference.bodies[b].angular_velocity)
          << r.bodies[b].name;
    }
  }
}

}  // namespace
}  // namespace rbx

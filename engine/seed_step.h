// The seed's step: for every pair passing the bounding check, in (i, j) order, the face, vertex
// and edge tests, each hit resolved at once by a single-point frictionless impulse; then Euler
// integration of every body (`custom-seed`).
#pragma once

#include "engine/detect.h"
#include "engine/response.h"
#include "engine/world_state.h"

namespace rbx {

/// The seed's contact model, one step at a time.
class SeedStep {
 public:
  /// Each hit is resolved by `response` instead of the seed's impulse (a researcher's own,
  /// engine/response.h); an empty function restores the seed's.
  void set_response(ResponseFn response) { response_ = std::move(response); }
  /// Detection and response for every pair, then integration: one step of sim.dt. Throws
  /// std::runtime_error when a response returns a non-finite impulse.
  void advance(WorldState& world);

 private:
  // Detection and response for bodies i and j; `bounded`: the pair already passed the bounding
  // check.
  void collide_pair(WorldState& world, int i, int j, bool bounded);

  DetectionCache detection_;  // the pair being resolved: placed once per pair per step
  ResponseFn response_;       // empty: the seed's impulse
};

}  // namespace rbx

// Scene files (TOML, the contract's format) to rbx::Scene, with validation.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "comparisons/scene/scene.h"

namespace rbx {

/// Bad input: the command exits 2 and prints what() as its one line, which names the file, the
/// line where there is one, and the key: "scenes/x.toml:12: body.A.mass: must be > 0, got -1".
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Reads and validates a scene file, applying `overrides` ("KEY=VALUE", TOML-typed, e.g.
/// "sim.dt=1e-4", "body.A.mass=2.5", "body.B.velocity=[0,-1,0]") after parsing. Relative mesh
/// paths are resolved against the scene file's folder. Throws InputError.
Scene load_scene(const std::string& path, const std::vector<std::string>& overrides = {});

/// The same from text already in memory; `path` is used in messages and for mesh paths.
Scene parse_scene(const std::string& text, const std::string& path,
                  const std::vector<std::string>& overrides = {});

/// Every valid key of a scene file, dotted ("sim.dt", "body.mass", "expect.contact.depth"), for
/// the nearest-key suggestion and the documentation.
const std::vector<std::string>& scene_keys();

}  // namespace rbx

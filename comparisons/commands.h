// The `rbx` subcommands. Each returns the process exit code: 0 success, 1 a check failed or a
// regression was found, 2 bad input (InputError, thrown to main, which prints its one line).
#pragma once

#include <string>
#include <vector>

#include "engine/scene.h"
#include "reference/backend.h"

namespace rbx {

/// Options shared by the scene commands.
struct SceneCommandOptions {
  std::vector<std::string> scenes;     // scene files (compare takes several)
  std::string json;                    // --json FILE|- ("" : none)
  std::vector<std::string> sets;       // --set KEY=VALUE
  std::string backends;                // --backends LIST ("" : the scene's, or every one)
  bool force = false;                  // --force: accept absurd step counts
};

/// What a backend is asked for.
enum class Capability { Contact, Dynamics };

/// Backends to run for a scene: --backends if given (unknown names are an InputError), else the
/// scene's `backends`, else every backend with the capability. Names are kept in registry order.
std::vector<std::string> select_backends(const Scene& scene, const std::string& list,
                                         Capability cap);

/// Loads a scene applying --set and --force (InputError on bad input).
Scene load_scene_for_command(const std::string& path, const SceneCommandOptions& opt);

/// `rbx run SCENE`: the custom engine (and dynamics references named by --backends).
int run_command(const SceneCommandOptions& opt);
/// `rbx contacts SCENE`: contact queries at the t = 0 poses, every backend, side by side.
int contacts_command(const SceneCommandOptions& opt);

}  // namespace rbx

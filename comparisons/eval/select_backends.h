// Which backends run for a scene: the --backends list, the scene's own list, or every backend
// that can serve the check.
#pragma once

#include <string>
#include <vector>

#include "comparisons/scene/scene.h"
#include "reference/backend.h"

namespace rbx {

/// What a backend is asked for.
enum class Capability { Contact, Dynamics, Distance, Toi };

/// The names of a comma-separated --backends LIST, in order, empty items dropped.
std::vector<std::string> split_list(const std::string& list);

/// The names of a --backends LIST checked against `table` (an unknown name is an InputError
/// naming the known ones); "all" (the whole list) gives every name of the table.
std::vector<std::string> parse_backend_list(const std::string& list,
                                            const std::vector<Backend>& table = backends());

/// Backends to run for a scene: --backends if given (unknown names are an InputError; "all" is
/// every backend with the capability, whatever the scene lists), else the scene's `backends`,
/// else every backend with the capability. Names are kept in registry order.
std::vector<std::string> select_backends(const Scene& scene, const std::string& list,
                                         Capability cap);
/// The same, choosing from `table` instead of the registry (the harness's seam for tests).
std::vector<std::string> select_backends(const Scene& scene, const std::string& list,
                                         Capability cap, const std::vector<Backend>& table);

}  // namespace rbx

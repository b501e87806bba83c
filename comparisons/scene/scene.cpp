#include "comparisons/scene/scene.h"

#include <algorithm>

namespace rbx {

const char* to_string(CheckKind check) {
  switch (check) {
    case CheckKind::Contact:
      return "contact";
    case CheckKind::Impulse:
      return "impulse";
    case CheckKind::Trajectory:
      return "trajectory";
    case CheckKind::Stability:
      return "stability";
    case CheckKind::Mass:
      return "mass";
  }
  return "contact";
}

std::optional<CheckKind> check_kind_from_string(const std::string& name) {
  for (CheckKind c : {CheckKind::Contact, CheckKind::Impulse, CheckKind::Trajectory,
                      CheckKind::Stability, CheckKind::Mass})
    if (name == to_string(c)) return c;
  return std::nullopt;
}

bool Scene::has_check(CheckKind c) const {
  return std::find(checks.begin(), checks.end(), c) != checks.end();
}

std::vector<std::string> Scene::check_names() const {
  std::vector<std::string> names;
  for (CheckKind c : checks) names.push_back(to_string(c));
  return names;
}

}  // namespace rbx

#include "engine/scene.h"

#include <algorithm>
#include <cmath>

namespace rbx {

long SimSettings::steps() const { return static_cast<long>(std::llround(duration / dt)); }

bool Scene::has_check(const std::string& c) const {
  return std::find(checks.begin(), checks.end(), c) != checks.end();
}

}  // namespace rbx

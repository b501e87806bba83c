#include "engine/scene.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace rbx {

long step_count(double duration, double dt) {
  // Range-check the quotient before casting: the negated test also catches NaN and infinity.
  const double steps = duration / dt;
  if (!(steps >= 0.0 && steps <= kMaxStepCount)) {
    std::ostringstream s;
    s << "duration " << duration << " s at dt = " << dt << " s is " << steps
      << " steps, not a step count a run can take (at most 2^53)";
    throw std::domain_error(s.str());
  }
  return static_cast<long>(std::llround(steps));
}

long SimSettings::steps() const { return step_count(duration, dt); }

bool Scene::has_check(const std::string& c) const {
  return std::find(checks.begin(), checks.end(), c) != checks.end();
}

}  // namespace rbx

#include "comparisons/eval/contact_eval.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <vector>

#include "comparisons/eval/json_io.h"

namespace rbx {

ContactRun run_contact(const Backend& b, const RigidBody& a, const RigidBody& bb, int repeats) {
  ContactRun run;
  if (!b.contact) {
    run.result = {Status::Unsupported, b.name + " has no contact query (dynamics only)", {}};
    return run;
  }
  std::vector<double> times;
  for (int k = 0; k < std::max(repeats, 1); ++k) {
    Stopwatch clock;
    try {
      run.result = b.contact(a, bb);
    } catch (const std::exception& e) {
      run.result = {Status::Error, e.what(), {}};
    }
    times.push_back(clock.seconds());
    if (run.result.status != Status::Ok) break;
  }
  std::nth_element(times.begin(), times.begin() + times.size() / 2, times.end());
  run.runtime_s = times[times.size() / 2];
  return run;
}

const ContactPoint* deepest(const ContactResult& r) {
  const ContactPoint* best = nullptr;
  for (const ContactPoint& c : r.contacts)
    if (!best || c.depth > best->depth) best = &c;
  return best;
}

double angle_deg(const Vec3& u, const Vec3& v) {
  const double c = u.normalized().dot(v.normalized());
  // atan2 of |u x v| and u.v is accurate near 0 and 180 degrees, where acos is not.
  const double s = u.normalized().cross(v.normalized()).norm();
  return std::atan2(s, c) * 180.0 / M_PI;
}

}  // namespace rbx

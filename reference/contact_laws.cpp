#include "reference/contact_laws.h"

#include <algorithm>
#include <cmath>

namespace rbx {

namespace {

// The histogram's span: 1e-30 to 1e10 at 100 bins per decade. Below: the zero bin; above: the
// last bin (the worst is kept exactly anyway).
constexpr double kLowest = 1e-30;
constexpr int kDecades = 40;
constexpr int kPerDecade = 100;
constexpr int kBins = 1 + kDecades * kPerDecade;

int bin_of(double value) {
  if (!(value >= kLowest)) return 0;  // zero, tiny, or NaN (NaN has its own worst)
  const int b = 1 + static_cast<int>(std::floor(std::log10(value / kLowest) * kPerDecade));
  return std::min(b, kBins - 1);
}

// The geometric centre of bin b >= 1.
double centre_of(int b) { return kLowest * std::pow(10.0, (b - 0.5) / kPerDecade); }

}  // namespace

const char* to_string(Law law) {
  switch (law) {
    case Law::Penetration:
      return "penetration";
    case Law::Pulling:
      return "pulling";
    case Law::Complementarity:
      return "complementarity";
    case Law::Cone:
      return "cone";
    case Law::Dissipation:
      return "dissipation";
  }
  return "?";
}

const char* law_unit(Law law) {
  switch (law) {
    case Law::Penetration:
      return "m";
    case Law::Pulling:
    case Law::Cone:
      return "N s";
    case Law::Complementarity:
    case Law::Dissipation:
      return "J";
  }
  return "?";
}

std::array<double, kLaws> law_residuals(const LawInputs& in) {
  const Vec3& n = in.normal;
  const double jn = in.impulse.dot(n);
  const Vec3 jt = in.impulse - jn * n;
  const double push = std::max(0.0, jn);
  const double vn_before = in.v_before.dot(n), vn_after = in.v_after.dot(n);
  const Vec3 vt_after = in.v_after - vn_after * n;
  // Newton's law: a pressing contact leaves at e times its approach speed (0 when separating).
  const double target = std::max(0.0, -in.restitution * vn_before);
  std::array<double, kLaws> r{};
  r[static_cast<int>(Law::Penetration)] = std::max(0.0, in.depth);
  r[static_cast<int>(Law::Pulling)] = std::max(0.0, -jn);
  r[static_cast<int>(Law::Complementarity)] = push * std::abs(vn_after - target);
  r[static_cast<int>(Law::Cone)] = std::max(0.0, jt.norm() - in.friction * push);
  // Maximum dissipation: j_t . v_t' >= -|j_t||v_t'| >= -mu j_n |v_t'|, equal only for the
  // friction at the cone's edge exactly against the slip; the excess is the power it missed.
  r[static_cast<int>(Law::Dissipation)] =
      std::max(0.0, jt.dot(vt_after) + in.friction * push * vt_after.norm());
  return r;
}

LawTally::LawTally() : bins_(static_cast<size_t>(kLaws) * kBins, 0) {}

void LawTally::add(const std::array<double, kLaws>& residuals) {
  ++count_;
  for (int l = 0; l < kLaws; ++l) {
    const double v = residuals[l];
    // A non-finite residual is the worst there is.
    if (!std::isfinite(v) || v > worst_[l]) worst_[l] = std::isfinite(v) ? v : INFINITY;
    ++bins_[static_cast<size_t>(l) * kBins + bin_of(v)];
  }
}

ContactLaws LawTally::summary() const {
  ContactLaws s;
  s.measured = true;
  s.contacts = count_;
  for (int l = 0; l < kLaws; ++l) {
    s.residuals[l].worst = worst_[l];
    if (count_ == 0) continue;
    // The lower middle value's bin (the count's (n + 1) / 2-th smallest).
    const long rank = (count_ + 1) / 2;
    long seen = 0;
    for (int b = 0; b < kBins; ++b) {
      seen += bins_[static_cast<size_t>(l) * kBins + b];
      if (seen < rank) continue;
      s.residuals[l].median = b == 0 ? 0.0 : std::min(centre_of(b), worst_[l]);
      break;
    }
  }
  return s;
}

}  // namespace rbx

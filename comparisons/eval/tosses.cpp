// Real cube tosses: reading, simulation through any dynamics backend, errors, fit.
#include "comparisons/eval/tosses.h"

#include <zlib.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

#include "comparisons/eval/contact_eval.h"
#include "comparisons/scene/scene_file.h"
#include "engine/format.h"
#include "reference/isolate.h"
#include "reference/result_codec.h"

namespace fs = std::filesystem;

namespace rbx {

namespace {

const char* const kHeader = "toss,t,px,py,pz,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz";
const char* const kColumns[] = {"toss", "t",  "px", "py", "pz", "qw", "qx", "qy",
                                "qz",   "vx", "vy", "vz", "wx", "wy", "wz"};
// A stored quaternion is unit to the data's 7 significant digits (largest norm error in the
// ContactNets file: 1.8e-7); 1e-5 accepts that rounding and refuses anything else.
constexpr double kUnitQuatTolerance = 1e-5;
// Samples must sit on the 148 Hz grid: the simulation samples at i / rate and compares sample
// i with sample i. 1 % of a period is far above the data's 5e-7 s rounding of t.
constexpr double kGridTolerance = 0.01;

// Whole file through zlib: gzread passes plain (uncompressed) files through unchanged.
std::string read_maybe_gzip(const std::string& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw InputError(path + ": no such data file");
  gzFile f = gzopen(path.c_str(), "rb");
  if (!f) throw InputError(path + ": cannot open");
  std::string text;
  char buf[1 << 16];
  int n = 0;
  while ((n = gzread(f, buf, sizeof(buf))) > 0) text.append(buf, static_cast<size_t>(n));
  int err = Z_OK;
  const char* msg = gzerror(f, &err);
  const std::string why = (n < 0 || (err != Z_OK && err != Z_STREAM_END)) ? msg : "";
  gzclose(f);
  if (!why.empty()) throw InputError(path + ": cannot read (" + why + ")");
  return text;
}

// One CSV field as a finite number, or InputError naming file, row and column.
double parse_field(const std::string& s, const std::string& where, const char* column) {
  const char* begin = s.c_str();
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(begin, &end);
  if (s.empty() || end != begin + s.size())
    throw InputError(where + ": column " + column + ": not a number: '" + s + "'");
  if (!std::isfinite(v))
    throw InputError(where + ": column " + column + ": not a finite number: '" + s + "'");
  return v;
}

std::string six_digits(double x) { return fmt_num(x, 6); }

}  // namespace

std::vector<Toss> parse_tosses(const std::string& text, const std::string& path) {
  std::vector<Toss> tosses;
  std::istringstream in(text);
  std::string line;
  long row = 0;
  std::map<long, bool> seen;
  const double rate = CubeTossModel{}.sample_rate;
  while (std::getline(in, line)) {
    ++row;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::string where = path + ":row " + std::to_string(row);
    if (row == 1) {
      if (line != kHeader)
        throw InputError(where + ": header must be '" + std::string(kHeader) + "'");
      continue;
    }
    if (line.empty()) continue;
    // Split into the 15 fields.
    std::vector<std::string> f;
    std::stringstream ls(line);
    std::string cell;
    while (std::getline(ls, cell, ',')) f.push_back(cell);
    if (line.back() == ',') f.push_back("");
    if (f.size() != 15)
      throw InputError(where + ": expected 15 columns, got " + std::to_string(f.size()));
    double v[15];
    for (int k = 0; k < 15; ++k) v[k] = parse_field(f[k], where, kColumns[k]);
    if (v[0] != std::floor(v[0]) || std::fabs(v[0]) > 1e15)
      throw InputError(where + ": column toss: not an integer id: '" + f[0] + "'");
    const long id = static_cast<long>(v[0]);
    TossSample s;
    s.time = v[1];
    s.position = Vec3(v[2], v[3], v[4]);
    const Eigen::Vector4d q(v[5], v[6], v[7], v[8]);
    if (std::fabs(q.norm() - 1.0) > kUnitQuatTolerance)
      throw InputError(where + ": quaternion (qw, qx, qy, qz) has norm " + fmt_num(q.norm(), 9) +
                       ", not 1");
    s.orientation = Quat(v[5], v[6], v[7], v[8]).normalized();
    s.velocity = Vec3(v[9], v[10], v[11]);
    s.angular_velocity = Vec3(v[12], v[13], v[14]);
    // A new toss starts when the id changes; an id must not come back later.
    if (tosses.empty() || tosses.back().id != id) {
      if (!tosses.empty() && tosses.back().samples.size() < 2)
        throw InputError(path + ":row " + std::to_string(tosses.back().first_row) + ": toss " +
                         std::to_string(tosses.back().id) + " has one sample (needs >= 2)");
      if (seen.count(id))
        throw InputError(where + ": toss " + std::to_string(id) +
                         " appears again after other tosses (rows of a toss must be together)");
      seen[id] = true;
      tosses.push_back({id, row, {}});
    } else {
      const TossSample& prev = tosses.back().samples.back();
      if (!(s.time > prev.time))
        throw InputError(where + ": time " + six_digits(s.time) + " s not after the previous " +
                         six_digits(prev.time) + " s of toss " + std::to_string(id));
      const double i = static_cast<double>(tosses.back().samples.size());
      const double at = (s.time - tosses.back().samples.front().time) * rate;
      if (std::fabs(at - i) > kGridTolerance)
        throw InputError(where + ": time " + six_digits(s.time) +
                         " s is off the 148 Hz sample grid (" + "sample " + fmt_num(i, 10) +
                         " of toss " + std::to_string(id) + " expected at " +
                         six_digits(tosses.back().samples.front().time + i / rate) + " s)");
    }
    tosses.back().samples.push_back(s);
  }
  if (row == 0)
    throw InputError(path + ":row 1: empty file (expected the header '" + std::string(kHeader) +
                     "')");
  if (tosses.empty()) throw InputError(path + ": no tosses (only a header)");
  if (tosses.back().samples.size() < 2)
    throw InputError(path + ":row " + std::to_string(tosses.back().first_row) + ": toss " +
                     std::to_string(tosses.back().id) + " has one sample (needs >= 2)");
  return tosses;
}

std::vector<Toss> read_tosses(const std::string& path) {
  return parse_tosses(read_maybe_gzip(path), path);
}

Scene toss_scene(const Toss& toss, const ContactParams& params, const CubeTossModel& model) {
  Scene scene;
  scene.name = "cube toss " + std::to_string(toss.id);
  scene.checks = {CheckKind::Trajectory};
  scene.sim.dt = 1.0 / (model.sample_rate * model.substeps);
  scene.sim.duration = toss.samples.back().time - toss.samples.front().time;
  scene.sim.gravity = Vec3(0, 0, -model.gravity);
  scene.sim.restitution = params.restitution;
  scene.sim.friction = params.friction;
  scene.sim.integrator = Integrator::Symplectic;

  const TossSample& s0 = toss.samples.front();
  BodySpec cube;
  cube.name = "cube";
  cube.box_size = Vec3::Constant(2.0 * model.half_width);
  cube.shape = std::make_shared<const ConvexPolyhedron>(make_box(cube.box_size));
  cube.mass = model.mass;
  cube.inertia = model.inertia * Mat3::Identity();
  cube.position = s0.position;
  cube.orientation = s0.orientation;
  cube.velocity = s0.velocity;
  cube.angular_velocity = s0.angular_velocity;

  BodySpec floor;
  floor.name = "floor";
  floor.box_size = Vec3(model.floor_size, model.floor_size, model.floor_thickness);
  floor.shape = std::make_shared<const ConvexPolyhedron>(make_box(floor.box_size));
  floor.is_static = true;
  floor.position = Vec3(0, 0, -0.5 * model.floor_thickness);
  scene.bodies = {cube, floor};
  return scene;
}

double rotation_angle_deg(const Quat& a, const Quat& b) {
  const double c = std::min(1.0, std::fabs(a.coeffs().dot(b.coeffs())));
  return 2.0 * std::acos(c) * 180.0 / M_PI;
}

TossErrors toss_errors(const Toss& real, const PoseTrack& sim, double cube_width) {
  TossErrors e;
  e.toss_id = real.id;
  const size_t n = real.samples.size();
  // Sample 0 is the initial condition itself (error 0 by construction): averaged from 1 on.
  for (size_t i = 1; i < n; ++i) {
    const double d = (sim.position[i] - real.samples[i].position).norm() / cube_width;
    e.position_by_sample.push_back(d);
    e.horizontal_by_sample.push_back((sim.position[i] - real.samples[i].position).head<2>().norm() /
                                     cube_width);
    e.position += d;
    e.orientation_deg += rotation_angle_deg(sim.orientation[i], real.samples[i].orientation);
  }
  e.position /= static_cast<double>(n - 1);
  e.orientation_deg /= static_cast<double>(n - 1);
  e.final_position = (sim.position[n - 1] - real.samples[n - 1].position).norm() / cube_width;
  e.final_orientation_deg =
      rotation_angle_deg(sim.orientation[n - 1], real.samples[n - 1].orientation);
  return e;
}

TossRun simulate_toss(const DynamicsFn& dynamics, const Toss& toss, const ContactParams& params,
                      const CubeTossModel& model) {
  TossRun run;
  const Scene scene = toss_scene(toss, params, model);
  DynamicsOptions opt;
  opt.dt = scene.sim.dt;
  opt.sample_every = model.substeps;
  const DynamicsResult r = dynamics(scene, opt);
  const size_t n = toss.samples.size();
  const std::string which = "toss " + std::to_string(toss.id);
  if (r.status != Status::Ok) {
    run.status = r.status;
    run.message = which + ": " + r.message;
    return run;
  }
  if (r.samples.size() < n) {
    run.status = Status::Error;
    run.message = which + ": the run stopped after " + std::to_string(r.samples.size()) + " of " +
                  std::to_string(n) + " samples";
    return run;
  }
  for (size_t i = 0; i < n; ++i) {
    const BodyFinal& c = r.samples[i].bodies.at(0);  // the cube is body 0
    // A sample off the measured time would compare different instants (a backend bug).
    if (std::fabs(r.samples[i].time - static_cast<double>(i) / model.sample_rate) > 0.5 * opt.dt) {
      run.status = Status::Error;
      run.message = which + ": sample " + std::to_string(i) +
                    " at t = " + six_digits(r.samples[i].time) + " s, expected " +
                    six_digits(static_cast<double>(i) / model.sample_rate) + " s";
      return run;
    }
    if (!c.position.allFinite() || !c.orientation.coeffs().allFinite()) {
      run.status = Status::Error;
      run.message = which + ": non-finite state at t = " + six_digits(r.samples[i].time) + " s";
      return run;
    }
    run.track.position.push_back(c.position);
    run.track.orientation.push_back(c.orientation.normalized());
  }
  return run;
}

Spread spread_of(std::vector<double> v) {
  Spread s;
  if (v.empty()) {
    s.median = s.mean = s.p90 = std::numeric_limits<double>::quiet_NaN();
    return s;
  }
  std::sort(v.begin(), v.end());
  auto at = [&](double p) {
    const double r = p * static_cast<double>(v.size() - 1);
    const size_t lo = static_cast<size_t>(std::floor(r));
    const size_t hi = std::min(lo + 1, v.size() - 1);
    return v[lo] + (r - static_cast<double>(lo)) * (v[hi] - v[lo]);
  };
  s.median = at(0.5);
  s.p90 = at(0.9);
  double sum = 0.0;
  for (double x : v) sum += x;
  s.mean = sum / static_cast<double>(v.size());
  return s;
}

namespace {

// A toss's errors, written and read by one field list (reference/result_codec.h).
template <class Io, class E>
void toss_error_fields(Io& io, E& e) {
  io.io(e.toss_id, e.position, e.orientation_deg, e.final_position, e.final_orientation_deg);
  io.io_list(e.position_by_sample, [](Io& i, auto& x) { i.io(x); });
  io.io_list(e.horizontal_by_sample, [](Io& i, auto& x) { i.io(x); });
}

}  // namespace

Backend toss_backend(const Backend& backend, const ContactParams& params) {
  if (params.soft.empty() || !backend.soft.dynamics) return backend;
  std::vector<double> values;
  for (const SoftParameter& p : backend.soft.parameters) {
    double v = p.value;
    for (const auto& [name, x] : params.soft)
      if (name == p.name) v = x;
    values.push_back(v);
  }
  Backend out = backend;
  out.dynamics = [run = backend.soft.dynamics, values](const WorldDefinition& scene,
                                                       const DynamicsOptions& opt) {
    return run(scene, opt, values);
  };
  return out;
}

std::string soft_text(const ContactParams& params) {
  std::string s;
  for (const auto& [name, v] : params.soft)
    s += (s.empty() ? "" : ", ") + name + " " + six_digits(v);
  return s;
}

BackendTosses evaluate_backend(const Backend& backend, const std::vector<Toss>& tosses,
                               const ContactParams& params, const CubeTossModel& model) {
  BackendTosses out;
  out.name = backend.name;
  out.params = params;
  if (!backend.dynamics) {
    out.status = Status::Unsupported;
    out.message = "no dynamics";
    return out;
  }
  Stopwatch clock;
  const Backend runs = toss_backend(backend, params);
  // One toss as bytes: its status and message, then its errors when it ran.
  auto one = [&](size_t i) {
    const TossRun run = simulate_toss(isolated_dynamics_fn(runs), tosses[i], params, model);
    ByteWriter w;
    w.io(run.status, run.message);
    if (run.status == Status::Ok) {
      const TossErrors e = toss_errors(tosses[i], run.track, 2.0 * model.half_width);
      toss_error_fields(w, e);
    }
    return w.str();
  };
  // The tosses run one after another in one supervised child (reference/isolate.h), each library
  // run still a supervised call: a child of its own per toss cost more than the toss (every child
  // resolved the libraries' symbols and faulted their memory in anew). Already in such a child,
  // they run here.
  std::vector<std::string> bytes;
  if (in_isolated_child()) {
    for (size_t i = 0; i < tosses.size(); ++i) bytes.push_back(one(i));
  } else {
    bytes = run_items_isolated(0, tosses.size(), one);
  }
  int failed = 0;
  for (const std::string& b : bytes) {
    ByteReader r(b);
    Status status = Status::Ok;
    std::string message;
    r.io(status, message);
    if (status != Status::Ok) {
      if (failed++ == 0) out.message = message;
      continue;
    }
    TossErrors e;
    toss_error_fields(r, e);
    out.tosses.push_back(std::move(e));
  }
  out.runtime_s = clock.seconds();
  if (failed > 0) {
    out.status = Status::Error;
    out.message = std::to_string(failed) + " of " + std::to_string(tosses.size()) +
                  " tosses failed (statistics over the others); first: " + out.message;
  }
  return out;
}

double fit_objective(const Backend& backend, const std::vector<Toss>& tosses,
                     const ContactParams& params, const CubeTossModel& model) {
  const BackendTosses r = evaluate_backend(backend, tosses, params, model);
  if (r.status != Status::Ok || r.tosses.empty()) return std::numeric_limits<double>::infinity();
  double sum = 0.0;
  for (const TossErrors& e : r.tosses) sum += e.position;
  return sum / static_cast<double>(r.tosses.size());
}

namespace {

// backends.<name>.soft of a params file: each key one of the backend's soft parameters
// (Backend::soft), each value a number in its range.
std::vector<std::pair<std::string, double>> read_soft(const std::string& path,
                                                      const std::string& key,
                                                      const std::string& name, const Json& soft) {
  if (!soft.is_object())
    throw InputError(path + ": " + key + ".soft: must be an object of parameter: value");
  const Backend* b = find_backend(name);
  std::string known;
  if (b)
    for (const SoftParameter& p : b->soft.parameters) known += (known.empty() ? "" : ", ") + p.name;
  std::vector<std::pair<std::string, double>> out;
  for (const auto& [k, v] : soft.items()) {
    const std::string where = path + ": " + key + ".soft." + k;
    const SoftParameter* sp = nullptr;
    if (b)
      for (const SoftParameter& p : b->soft.parameters)
        if (p.name == k) sp = &p;
    if (!sp)
      throw InputError(where + ": not a soft-contact parameter of " + name + " (" +
                       (known.empty() ? "it has none" : "it has " + known) + ")");
    if (!v.is_number() || !(v.get<double>() >= sp->lo && v.get<double>() <= sp->hi))
      throw InputError(where + ": must be a number in [" + six_digits(sp->lo) + ", " +
                       six_digits(sp->hi) + "], got " + v.dump());
    out.emplace_back(k, v.get<double>());
  }
  return out;
}

}  // namespace

std::vector<std::pair<std::string, ContactParams>> read_params_file(const std::string& path) {
  std::vector<std::pair<std::string, ContactParams>> out;
  std::error_code ec;
  if (!fs::exists(path, ec)) return out;
  std::ifstream in(path);
  Json j;
  try {
    j = Json::parse(in);
  } catch (const std::exception& e) {
    throw InputError(path + ": not valid JSON (" + e.what() + ")");
  }
  if (!j.contains("backends") || !j["backends"].is_object())
    throw InputError(path +
                     ": backends: missing (expected backends.<name>.{restitution, friction})");
  for (const auto& [name, b] : j["backends"].items()) {
    const std::string key = "backends." + name;
    ContactParams p;
    for (const char* k : {"restitution", "friction"})
      if (!b.is_object() || !b.contains(k) || !b[k].is_number())
        throw InputError(path + ": " + key + "." + k + ": missing or not a number");
    p.restitution = b["restitution"].get<double>();
    p.friction = b["friction"].get<double>();
    if (!(p.restitution >= 0.0 && p.restitution <= 1.0))
      throw InputError(path + ": " + key + ".restitution: must be in [0, 1], got " +
                       six_digits(p.restitution));
    if (!(p.friction >= 0.0 && std::isfinite(p.friction)))
      throw InputError(path + ": " + key + ".friction: must be >= 0, got " +
                       six_digits(p.friction));
    if (b.contains("soft")) p.soft = read_soft(path, key, name, b["soft"]);
    out.emplace_back(name, p);
  }
  return out;
}

namespace {

Json spread_json(const Spread& s) {
  return {{"median", s.median}, {"mean", s.mean}, {"p90", s.p90}};
}

// The three statistics of one error kind over a backend's tosses.
Spread spread_by(const BackendTosses& r, double TossErrors::*field) {
  std::vector<double> v;
  for (const TossErrors& e : r.tosses) v.push_back(e.*field);
  return spread_of(v);
}

}  // namespace

Json backend_tosses_json(const BackendTosses& r) {
  Json j;
  j["status"] = to_string(r.status);
  j["message"] = r.message;
  j["params"] = {{"restitution", r.params.restitution}, {"friction", r.params.friction}};
  for (const auto& [name, v] : r.params.soft) j["params"]["soft"][name] = v;
  j["params_source"] = r.params_source;
  j["tosses"] = r.tosses.size();
  j["position_error"] = spread_json(spread_by(r, &TossErrors::position));
  j["orientation_error_deg"] = spread_json(spread_by(r, &TossErrors::orientation_deg));
  j["final_position_error"] = spread_json(spread_by(r, &TossErrors::final_position));
  j["final_orientation_error_deg"] = spread_json(spread_by(r, &TossErrors::final_orientation_deg));
  j["runtime_s"] = r.runtime_s;
  Json per = Json::array();
  for (const TossErrors& e : r.tosses)
    per.push_back({{"toss", e.toss_id},
                   {"position_error", e.position},
                   {"orientation_error_deg", e.orientation_deg},
                   {"final_position_error", e.final_position},
                   {"final_orientation_error_deg", e.final_orientation_deg}});
  j["per_toss"] = per;
  return j;
}

}  // namespace rbx

// Real cube tosses (ContactNets data, scenes/real/cube_toss/): reading the measured
// trajectories, simulating each toss with a dynamics backend from its first sample, the errors
// against the measurement, and the per-backend fit of restitution and friction.
//
// Design note: every toss is one two-body scene (the cube and a static floor box) run through
// the backend's ordinary DynamicsFn, so a backend added to the registry is ranked here without
// any code of its own; the scene is the only model of the experiment.
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "comparisons/eval/json_io.h"
#include "comparisons/scene/scene.h"
#include "reference/backend.h"

namespace rbx {

/// The tossed cube and its world (ContactNets README; Acosta, Yang & Posa 2022).
struct CubeTossModel {
  double half_width = 0.0524;  // m: vertices at +-half_width on each body axis
  double mass = 0.37;          // kg
  // kg m^2 about each axis: the dataset's own value (its processing code), 19.6 % above a
  // uniform-density cube's m (2 half_width)^2 / 6; scenes/real/cube_toss/README.md.
  double inertia = 8.1e-4;
  double gravity = 9.81;       // m/s^2, along -z
  double sample_rate = 148.0;  // Hz, motion capture
  // Time step = 1 / (sample_rate * substeps). 10 substeps (0.68 ms): a cube falling at 2 m/s
  // moves 1.4 mm (1.3 % of its width) per step, and MuJoCo's soft contact, which lasts a fixed
  // number of steps, resolves an impact in ~17 ms; every simulated sample falls exactly on a
  // measured one. Measured on 10 test tosses at the published parameters: 20 and 40 substeps
  // move each backend's median position error by at most 0.025 widths (mujoco 0.272 -> 0.262
  // -> 0.248; bullet 0.147 -> 0.147 -> 0.162, ode 0.190 -> 0.191 -> 0.192), well below the
  // gaps between backends, at 2 and 4 times the cost (which the fit pays ~60 times).
  int substeps = 10;
  double floor_size = 4.0;       // m, width of the static floor box (tosses span < 1.1 m)
  double floor_thickness = 0.2;  // m; its top face is the plane z = 0
};

/// One measured sample: the cube's state at time t.
struct TossSample {
  double time = 0.0;                     // s since the toss's first sample
  Vec3 position = Vec3::Zero();          // m, centre of the cube, world
  Quat orientation = Quat::Identity();   // body to world, unit
  Vec3 velocity = Vec3::Zero();          // m/s, world
  Vec3 angular_velocity = Vec3::Zero();  // rad/s, world frame
};

/// One toss: release (in the air) to rest.
struct Toss {
  long id = 0;                      // the data's toss id
  long first_row = 0;               // 1-based line of its first sample in the file
  std::vector<TossSample> samples;  // time increasing, >= 2 samples
};

/// Reads tosses from a CSV file (plain or gzip, told apart by content) with the header
/// toss,t,px,py,pz,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz. Throws InputError naming the file and row for
/// a missing file, a bad header, a non-numeric or non-finite value, a quaternion whose norm is
/// off 1 by more than 1e-5, time not increasing within a toss, a toss of one sample, or a toss
/// id seen again after another toss.
std::vector<Toss> read_tosses(const std::string& path);
/// The same from text in memory (`path` is used in messages).
std::vector<Toss> parse_tosses(const std::string& text, const std::string& path);

/// A toss whose mechanical energy rises across an impact beyond the tracking noise (the data's
/// source reports such tosses). Energy: m |v|^2 / 2 + I |w|^2 / 2 + m g z from the data's own
/// states (the cube's inertia is isotropic). Flight: the samples whose lowest corner is more
/// than kFlightClearance above the floor. For each contact between two flights, `ratio` is the
/// largest energy of the later flight over the last of the earlier one; `noise` is the toss's
/// tracking noise, the largest relative swing of its energy within one flight (where it is
/// constant), at least 1 %. Flagged when ratio > 1 + noise.
struct EnergyGain {
  long toss_id = 0;
  double ratio = 0.0;  // the largest over the toss's impacts
  double noise = 0.0;
};
constexpr double kFlightClearance = 3e-3;  // m: the tracking's millimetres, above a resting cube

/// Every toss that gains energy across an impact (see EnergyGain), in data order.
std::vector<EnergyGain> energy_gains(const std::vector<Toss>& tosses,
                                     const CubeTossModel& model = {});

/// The tosses without the flagged ones: every fit and score runs on these.
std::vector<Toss> without_energy_gains(const std::vector<Toss>& tosses,
                                       const std::vector<EnergyGain>& flagged);

/// The flagged tosses for a sentence: "" when none, else " (toss 12: energy x1.08, noise 0.02;
/// ...)".
std::string energy_gains_list(const std::vector<EnergyGain>& flagged);

/// {"rule", "flagged": [{toss, ratio, noise}], "scored"}: what was left out and why.
Json energy_gains_json(const std::vector<EnergyGain>& flagged, size_t scored);

/// Contact parameters of one backend.
struct ContactParams {
  double restitution = 0.125;  // e in [0, 1]
  double friction = 0.18;      // Coulomb mu >= 0
  // The backend's contact softness (Backend::soft), by name; a parameter not named keeps the
  // backend's own value.
  std::vector<std::pair<std::string, double>> soft;
};

/// The parameters fitted to these tosses by the data's authors (ContactNets experiment.json);
/// every backend's softness as rbx configures it.
inline const ContactParams kPublishedParams{0.125, 0.18, {}};

/// `backend` with the softness of `params` set (itself when `params` names none): the dynamics a
/// toss runs with.
Backend toss_backend(const Backend& backend, const ContactParams& params);

/// "erp 0.4, cfm 1e-05" for the named softness values, "" for none.
std::string soft_text(const ContactParams& params);

/// The scene of one toss: body "cube" at the toss's first sample, static body "floor" whose top
/// face is z = 0, gravity -z, the given contact parameters, duration = the toss's last time.
Scene toss_scene(const Toss& toss, const ContactParams& params, const CubeTossModel& model = {});

/// Errors of one simulated toss against its measurement.
struct TossErrors {
  long toss_id = 0;
  double position = 0.0;         // mean |p_sim - p_real| / cube width over samples after t = 0
  double orientation_deg = 0.0;  // mean rotation angle between sim and real, same samples
  double final_position = 0.0;   // |p_sim - p_real| / cube width at the last sample
  double final_orientation_deg = 0.0;      // rotation angle between sim and real at the last sample
  std::vector<double> position_by_sample;  // |p_sim - p_real| / width at samples 1..n-1
  std::vector<double> horizontal_by_sample;  // the same, x and y only (sliding, rolling away)
};

/// Position (centre) and orientation of a simulated trajectory at each measured sample.
struct PoseTrack {
  std::vector<Vec3> position;     // m
  std::vector<Quat> orientation;  // unit
};

/// Angle (degrees) of the rotation taking a to b: 2 acos |<a, b>| (q and -q are one rotation).
double rotation_angle_deg(const Quat& a, const Quat& b);
/// Errors of `sim` (one pose per measured sample, same count) against the measured toss.
TossErrors toss_errors(const Toss& real, const PoseTrack& sim, double cube_width);

/// Simulated toss: status, and the poses at the measured sample times when ok.
struct TossRun {
  Status status = Status::Ok;
  std::string message;
  PoseTrack track;
};
/// Runs one toss with a dynamics function (dt = 1 / (rate * substeps), a sample every substeps).
TossRun simulate_toss(const DynamicsFn& dynamics, const Toss& toss, const ContactParams& params,
                      const CubeTossModel& model = {});

/// Median, mean and 90th percentile of a set (linear interpolation between order statistics,
/// numpy's default: p90 of n values is at rank 0.9 (n - 1)). NaN for an empty set.
struct Spread {
  double median = 0.0, mean = 0.0, p90 = 0.0;
};
Spread spread_of(std::vector<double> values);

/// One backend over a set of tosses.
struct BackendTosses {
  std::string name;
  Status status = Status::Ok;
  std::string message;
  ContactParams params;
  std::string params_source;       // "fitted" | "published" | "published (none stored)"
  std::vector<TossErrors> tosses;  // the tosses that ran, in data order
  double runtime_s = 0.0;          // wall time of all its simulations
};
/// Simulates every toss with `backend` at `params`. A failed toss makes the status Error (the
/// message names the first failing toss) and is left out of `tosses`.
BackendTosses evaluate_backend(const Backend& backend, const std::vector<Toss>& tosses,
                               const ContactParams& params, const CubeTossModel& model = {});

/// Mean position error over the tosses (the fit's objective); +inf when any toss fails.
double fit_objective(const Backend& backend, const std::vector<Toss>& tosses,
                     const ContactParams& params, const CubeTossModel& model = {});

/// One value of a softness parameter tried by the fit, with its objective.
struct SoftTrial {
  std::string parameter;
  double value = 0.0;
  double objective = 0.0;  // mean position error (cube widths) on the fit tosses
};

/// Outcome of fitting one backend.
struct FitResult {
  ContactParams params;
  double objective = 0.0;  // mean position error (cube widths) on the fit tosses
  int evaluations = 0;     // objective evaluations
  double seconds = 0.0;    // wall time
  // The objective after each stage: "e, mu"; then, with a softness, "softness" and, when the
  // softness moved from the backend's own, "e, mu at the softness".
  std::vector<std::pair<std::string, double>> stages;
  std::vector<SoftTrial> soft_scan;  // every softness value tried, the backend's own included
};
/// Fits restitution in [0, 1] and friction in [0, 1.5]: a 5 x 6 grid, then Nelder-Mead from
/// the best grid point (simplex of half a grid spacing, parameters clamped into the box, at most
/// 30 evaluations); then, for a backend with contact softness (Backend::soft), each of its
/// parameters in turn over its grid at the fitted e and mu, the best kept (one pass); then, if
/// the softness moved, Nelder-Mead on e and mu again at it from the fitted point (toss_fit.cpp).
/// Deterministic: no random numbers.
FitResult fit_backend(const Backend& backend, const std::vector<Toss>& tosses,
                      const CubeTossModel& model = {},
                      const std::function<void(const std::string&)>& progress = nullptr);

/// Stored per-backend parameters (params.json): backends.<name>.{restitution, friction, soft}.
/// Returns an empty map when the file does not exist; InputError naming the file and key when it
/// is malformed, a value is out of its range, or a soft parameter is not one of a registered
/// backend's.
std::vector<std::pair<std::string, ContactParams>> read_params_file(const std::string& path);

/// The JSON of one backend: status, message, params, tosses, position_error,
/// orientation_error_deg, final_position_error (median, mean, p90), runtime_s, per_toss.
Json backend_tosses_json(const BackendTosses& r);

/// Backends to toss: those named in `list` (unknown names are an InputError; names without
/// dynamics are kept and reported unsupported), else every backend with dynamics, in registry
/// order.
std::vector<const Backend*> select_toss_backends(const std::string& list);

/// Every selected backend over the tosses, at its stored parameters and at the published ones.
struct TossEvaluation {
  std::vector<BackendTosses> stored, published;
};

/// Runs `chosen` over `tosses` at the parameters in `stored` (the published ones where a
/// backend has none) and at the published parameters, each backend at each set on one of
/// `threads` threads (0: every core); the result does not depend on their number.
TossEvaluation evaluate_tosses(const std::vector<const Backend*>& chosen,
                               const std::vector<Toss>& tosses,
                               const std::vector<std::pair<std::string, ContactParams>>& stored,
                               int threads = 0);

/// The study's JSON (`rbx tosses --json`, the report's tosses.json): the data, the cube model,
/// the parameter file and every backend at both parameter sets.
Json toss_evaluation_json(const std::string& data, const std::vector<Toss>& tosses,
                          const std::string& params_file, const TossEvaluation& ev);

/// Backend indices ordered by median position error (failed-everything backends last).
std::vector<size_t> toss_ranking(const std::vector<BackendTosses>& rs);

/// params.json beside the data file.
std::string default_toss_params_path(const std::string& data);

/// The stored params file at `path` with the fitted backends replaced (others kept), as JSON.
Json updated_params_json(const std::string& path, const std::string& data,
                         const std::vector<std::pair<std::string, FitResult>>& fits);

/// Folders under `inputs` (recursively; "" : scenes/) holding a tosses data set: a
/// params.json beside test.csv or test.csv.gz. Sorted.
std::vector<std::string> find_toss_datasets(const std::vector<std::string>& inputs);

/// The test split of a data set folder: DIR/test.csv.gz, else DIR/test.csv.
std::string toss_test_split(const std::string& dir);

/// One toss picked for the report's figures and replays (the best, median and worst of the best
/// backend) with every chosen backend's run of it at its stored parameters.
struct PickedToss {
  std::string label;                                  // "best", "median" or "worst"
  long id = 0;                                        // the toss's id
  std::vector<std::pair<std::string, TossRun>> runs;  // backend name, its run
};

/// The report's "Real impacts" study of one data set: the test split with the tosses that gain
/// energy left out, every chosen backend at both parameter sets, and the picked tosses' runs.
struct TossReportStudy {
  std::string data;         // the test split's file
  std::string params_path;  // params.json beside it
  size_t all_tosses = 0;    // in the split, before the energy-gain flags
  std::vector<EnergyGain> flagged;
  std::vector<Toss> tosses;  // those scored
  std::vector<const Backend*> chosen;
  TossEvaluation ev;
  double eval_s = 0.0;            // wall time of the evaluation at both parameter sets
  std::vector<size_t> order;      // toss_ranking(ev.stored)
  std::vector<PickedToss> picks;  // empty: no backend scored a toss
};

/// Runs the data set in folder `dir` (test.csv[.gz] with params.json) through every dynamics
/// backend (or those of them named in `backend_list`) at the stored and at the published
/// parameters, and the best backend's best, median and worst toss through every chosen backend.
/// Empty `chosen`: no backend with dynamics was named. `threads`: as evaluate_tosses.
TossReportStudy run_toss_report_study(const std::string& dir, const std::string& backend_list,
                                      int threads = 0);

/// A backend's stored (fitted) parameters, or the published ones when it has none; `source`
/// (when given) gets "fitted" or "published (none stored)".
ContactParams stored_params(const std::vector<std::pair<std::string, ContactParams>>& stored,
                            const std::string& name, std::string* source = nullptr);

}  // namespace rbx

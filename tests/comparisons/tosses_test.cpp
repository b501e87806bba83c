// Real cube tosses: reading (.csv and .csv.gz), every bad-row kind, the error metrics on a
// hand-made trajectory, free fall against its closed form for every dynamics backend, the fit
// recovering parameters that generated a toss, and deterministic JSON from `rbx tosses`.
#include "comparisons/eval/tosses.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "comparisons/scene/scene_file.h"
#include "tests/common/fixtures.h"

namespace fs = std::filesystem;
using namespace rbx;

namespace {

using test::temp_dir;

const char* const kHeader = "toss,t,px,py,pz,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz\n";

// One CSV row of a cube at rest orientation, moving at v (m/s) along x.
std::string row(long toss, double t, double z, const std::string& quat = "1,0,0,0") {
  std::ostringstream s;
  s.precision(17);
  s << toss << "," << t << ",0.1,0.2," << z << "," << quat << ",0.5,0,0,0,0,1\n";
  return s.str();
}

// Two tosses, three and two samples on the 148 Hz grid.
std::string good_csv() {
  return std::string(kHeader) + row(7, 0, 0.2) + row(7, 1 / 148.0, 0.19) + row(7, 2 / 148.0, 0.18) +
         row(9, 0, 0.3) + row(9, 1 / 148.0, 0.29);
}

struct CmdResult {
  int code = -1;
  std::string out, err;
};

// Runs the built rbx binary from the source folder with stdout and stderr captured.
CmdResult run_rbx(const std::string& args) {
  const fs::path tmp = temp_dir("cmd");
  const std::string cmd = "cd '" RBX_SOURCE_DIR "' && '" RBX_BINARY_DIR "/comparisons/rbx' " +
                          args + " > '" + (tmp / "out").string() + "' 2> '" +
                          (tmp / "err").string() + "'";
  CmdResult r;
  const int status = std::system(cmd.c_str());
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::stringstream so, se;
  so << std::ifstream(tmp / "out").rdbuf();
  se << std::ifstream(tmp / "err").rdbuf();
  r.out = so.str();
  r.err = se.str();
  fs::remove_all(tmp);
  return r;
}

}  // namespace

TEST(TossesRead, PlainAndGzipFilesGiveTheSameTosses) {
  const fs::path dir = temp_dir("read");
  std::ofstream(dir / "a.csv") << good_csv();
  gzFile gz = gzopen((dir / "a.csv.gz").c_str(), "wb");
  const std::string text = good_csv();
  gzwrite(gz, text.data(), static_cast<unsigned>(text.size()));
  gzclose(gz);
  for (const char* name : {"a.csv", "a.csv.gz"}) {
    const std::vector<Toss> t = read_tosses((dir / name).string());
    ASSERT_EQ(t.size(), 2u) << name;
    EXPECT_EQ(t[0].id, 7);
    EXPECT_EQ(t[0].first_row, 2);
    EXPECT_EQ(t[1].first_row, 5);
    ASSERT_EQ(t[0].samples.size(), 3u);
    ASSERT_EQ(t[1].samples.size(), 2u);
    EXPECT_EQ(t[0].samples[2].position.z(), 0.18);
    EXPECT_EQ(t[1].samples[1].angular_velocity, Vec3(0, 0, 1));
    EXPECT_EQ(t[0].samples[0].velocity, Vec3(0.5, 0, 0));
  }
  fs::remove_all(dir);
}

TEST(TossesRead, CommittedSplitsHoldTheDocumentedCounts) {
  // scenes/real/cube_toss/README.md: 100 test tosses (11 150 samples), 300 training (31 342).
  const std::string base = std::string(RBX_SOURCE_DIR) + "/scenes/real/cube_toss/";
  size_t samples = 0;
  const std::vector<Toss> test = read_tosses(base + "test.csv.gz");
  for (const Toss& t : test) samples += t.samples.size();
  EXPECT_EQ(test.size(), 100u);
  EXPECT_EQ(samples, 11150u);
  const std::vector<Toss> train = read_tosses(base + "train.csv.gz");
  EXPECT_EQ(train.size(), 300u);
  // Disjoint: no test id is a training id.
  for (const Toss& a : test)
    for (const Toss& b : train) ASSERT_NE(a.id, b.id);
}

// Each bad-row kind: exit 2, one line naming the file and the row, no JSON file written.
struct BadRow {
  const char* name;
  std::string csv;
  const char* where;  // "bad.csv:row N"
  const char* what;   // a word of the message
};

// Test names say the kind; the parameter itself need not be printed.
void PrintTo(const BadRow& b, std::ostream* os) { *os << b.name; }

class TossesBadRow : public ::testing::TestWithParam<BadRow> {};

TEST_P(TossesBadRow, ExitsTwoNamingFileAndRow) {
  const BadRow& b = GetParam();
  const fs::path dir = temp_dir(b.name);
  std::ofstream(dir / "bad.csv") << b.csv;
  const fs::path json = dir / "out.json";
  const CmdResult r = run_rbx("tosses '" + (dir / "bad.csv").string() +
                              "' --backends ode --json '" + json.string() + "'");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find(b.where), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(b.what), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(json));
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(
    Kinds, TossesBadRow,
    ::testing::Values(
        BadRow{"nan",
               std::string(kHeader) + row(1, 0, 0.2) +
                   "1,0.00675675675675,0.1,0.2,nan,1,0,0,0,0.5,0,0,0,0,1\n",
               "bad.csv:row 3", "pz"},
        BadRow{"text",
               std::string(kHeader) + row(1, 0, 0.2) +
                   "1,0.00675675675675,0.1,abc,0.2,1,0,0,0,0.5,0,0,0,0,1\n",
               "bad.csv:row 3", "py"},
        BadRow{"non_unit_quaternion",
               std::string(kHeader) + row(1, 0, 0.2) + row(1, 1 / 148.0, 0.2, "1,0,0,0.1"),
               "bad.csv:row 3", "quaternion"},
        BadRow{
            "time_not_increasing",
            std::string(kHeader) + row(1, 0, 0.2) + row(1, 1 / 148.0, 0.2) + row(1, 1 / 148.0, 0.2),
            "bad.csv:row 4", "time"},
        BadRow{"off_grid", std::string(kHeader) + row(1, 0, 0.2) + row(1, 0.004, 0.2),
               "bad.csv:row 3", "148 Hz"},
        BadRow{"one_sample",
               std::string(kHeader) + row(1, 0, 0.2) + row(2, 0, 0.2) + row(2, 1 / 148.0, 0.2),
               "bad.csv:row 2", "one sample"},
        BadRow{"one_sample_last",
               std::string(kHeader) + row(1, 0, 0.2) + row(1, 1 / 148.0, 0.2) + row(2, 0, 0.2),
               "bad.csv:row 4", "one sample"},
        BadRow{"columns", std::string(kHeader) + row(1, 0, 0.2) + "1,0.0067,0.1\n", "bad.csv:row 3",
               "columns"},
        BadRow{"header", std::string("toss,t,x\n") + row(1, 0, 0.2), "bad.csv:row 1", "header"},
        BadRow{"id_again",
               std::string(kHeader) + row(1, 0, 0.2) + row(1, 1 / 148.0, 0.2) + row(2, 0, 0.2) +
                   row(2, 1 / 148.0, 0.2) + row(1, 0, 0.2),
               "bad.csv:row 6", "again"}),
    [](const ::testing::TestParamInfo<BadRow>& i) { return std::string(i.param.name); });

TEST(TossesMetrics, HandMadeTrajectoryGivesTheHandComputedErrors) {
  // Measured: three samples at rest at the origin, identity orientation.
  Toss real;
  real.id = 4;
  for (int i = 0; i < 3; ++i)
    real.samples.push_back({i / 148.0, Vec3::Zero(), Quat::Identity(), Vec3::Zero(), Vec3::Zero()});
  // Simulated: sample 1 off by (0.03, 0.04, 0) = 5 cm and turned 90 deg about z; sample 2 off
  // by 2 cm along z and turned 30 deg about x (sign of the quaternion flipped: same rotation).
  PoseTrack sim;
  sim.position = {Vec3::Zero(), Vec3(0.03, 0.04, 0), Vec3(0, 0, 0.02)};
  sim.orientation = {Quat::Identity(), Quat(Eigen::AngleAxisd(M_PI / 2, Vec3::UnitZ())),
                     Quat(-Quat(Eigen::AngleAxisd(M_PI / 6, Vec3::UnitX())).coeffs())};
  const TossErrors e = toss_errors(real, sim, 0.1);
  // Hand: position (0.5 + 0.2) / 2 widths; angle (90 + 30) / 2 deg; final 0.2 widths, 30 deg.
  // Tolerances: round-off of a few operations on numbers of order 1 (acos near 1 loses ~1e-8).
  EXPECT_NEAR(e.position, 0.35, 1e-12);
  EXPECT_NEAR(e.orientation_deg, 60.0, 1e-6);
  EXPECT_NEAR(e.final_position, 0.2, 1e-12);
  EXPECT_NEAR(e.final_orientation_deg, 30.0, 1e-6);
  EXPECT_EQ(e.toss_id, 4);
  ASSERT_EQ(e.position_by_sample.size(), 2u);
  EXPECT_NEAR(e.position_by_sample[0], 0.5, 1e-12);
}

TEST(TossesMetrics, SpreadIsMedianMeanAndInterpolatedP90) {
  // Sorted 1, 2, 3, 4, 10: median 3; mean 4; p90 at rank 0.9 * 4 = 3.6: 4 + 0.6 * (10 - 4).
  const Spread s = spread_of({10, 2, 4, 1, 3});
  EXPECT_DOUBLE_EQ(s.median, 3.0);
  EXPECT_DOUBLE_EQ(s.mean, 4.0);
  EXPECT_NEAR(s.p90, 7.6, 1e-12);
  // Even count: median between the middle two.
  EXPECT_DOUBLE_EQ(spread_of({1, 2, 3, 4}).median, 2.5);
  EXPECT_TRUE(std::isnan(spread_of({}).median));
}

// A flat cube's toss sampled at 148 Hz: falling from 0.2 m at rest, at the floor for 3 samples,
// then rising at `rebound` m/s (a free flight each side, energy exact in both).
Toss bounce(double rebound) {
  const CubeTossModel m;
  Toss t;
  t.id = 7;
  const double dt = 1.0 / m.sample_rate, rest = m.half_width;
  double z = rest + 0.2, v = 0.0, time = 0.0;
  auto add = [&](double zz, double vv) {
    TossSample s;
    s.time = time;
    s.position = Vec3(0, 0, zz);
    s.velocity = Vec3(0, 0, vv);
    t.samples.push_back(s);
    time += dt;
  };
  while (z > rest + 0.004) {  // falling freely
    add(z, v);
    v -= m.gravity * dt;
    z = rest + 0.2 - 0.5 * m.gravity * time * time;
  }
  for (int k = 0; k < 3; ++k) add(rest, 0.0);  // at the floor: lowest corner below 3 mm
  const double t0 = time;
  for (int k = 1; k <= 10; ++k) {  // rising freely
    const double tau = time - t0 + dt;
    add(rest + 0.004 + rebound * tau - 0.5 * m.gravity * tau * tau, rebound - m.gravity * tau);
  }
  return t;
}

TEST(TossesEnergy, ATossGainingEnergyAcrossAnImpactIsFlaggedAndLeftOut) {
  // Dropped from 0.2 m: it lands at sqrt(2 g 0.2) = 1.98 m/s. Back up at 2.2 m/s it has gained
  // energy, 1.23 times its fall's (far above the 1 % floor of the noise; its flights are exact,
  // so their swing is round-off); at 1.5 m/s it has lost some.
  const std::vector<Toss> tosses = {bounce(2.2), bounce(1.5)};
  std::vector<Toss> two = tosses;
  two[1].id = 8;
  const std::vector<EnergyGain> flagged = energy_gains(two);
  ASSERT_EQ(flagged.size(), 1u);
  EXPECT_EQ(flagged[0].toss_id, 7);
  EXPECT_GT(flagged[0].ratio, 1.2);
  EXPECT_LT(flagged[0].ratio, 1.26);
  EXPECT_DOUBLE_EQ(flagged[0].noise, 0.01);
  const std::vector<Toss> kept = without_energy_gains(two, flagged);
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_EQ(kept[0].id, 8);
  // Noisy flights raise the bar: one sample of the fall tracked 10 cm high swings that
  // flight's energy by 28 %, and the same gain is then within the noise.
  Toss noisy = bounce(2.2);
  noisy.samples[3].position.z() += 0.1;
  EXPECT_TRUE(energy_gains({noisy}).empty());
}

TEST(TossesEnergy, NoCommittedTossGainsEnergyBeyondItsTrackingNoise) {
  // Measured on both splits (train 300, test 100): the largest energy after a contact is at most
  // 0.96 of that before it, so every toss is scored; the rule above is what would leave one out.
  for (const char* split : {"train", "test"}) {
    const std::vector<Toss> t =
        read_tosses(std::string(RBX_SOURCE_DIR) + "/scenes/real/cube_toss/" + split + ".csv.gz");
    EXPECT_TRUE(energy_gains(t).empty()) << split;
  }
}

TEST(TossesSoft, OwnValuesReproduceTheBackendAndAnotherValueMovesIt) {
  // Every backend with a contact softness: its dynamics at its own values are the backend's, bit
  // for bit, on a real toss; a value off its own (the next one on its grid) moves the result, so
  // the fit's parameters are live.
  const std::vector<Toss> tosses =
      read_tosses(std::string(RBX_SOURCE_DIR) + "/scenes/real/cube_toss/test.csv.gz");
  const Toss& toss = tosses.front();
  int tuned = 0;
  for (const Backend& b : backends()) {
    if (b.soft.parameters.empty()) continue;
    ++tuned;
    const TossRun plain = simulate_toss(b.dynamics, toss, kPublishedParams);
    ASSERT_EQ(plain.status, Status::Ok) << b.name << ": " << plain.message;
    for (const SoftParameter& p : b.soft.parameters) {
      ContactParams own = kPublishedParams;
      own.soft = {{p.name, p.value}};
      const TossRun same = simulate_toss(toss_backend(b, own).dynamics, toss, own);
      ASSERT_EQ(same.status, Status::Ok) << b.name;
      EXPECT_EQ(same.track.position, plain.track.position) << b.name << " " << p.name;
      ContactParams other = own;
      other.soft[0].second = p.grid.front() != p.value ? p.grid.front() : p.grid.back();
      const TossRun moved = simulate_toss(toss_backend(b, other).dynamics, toss, other);
      ASSERT_EQ(moved.status, Status::Ok) << b.name;
      EXPECT_NE(moved.track.position, plain.track.position) << b.name << " " << p.name;
    }
  }
  EXPECT_EQ(tuned, 8);  // mujoco, ode, dart and bullet, each with its -hull backend
}

TEST(TossesSoft, AnUnknownOrOutOfRangeSoftParameterExitsTwoNamingFileAndKey) {
  const fs::path dir = temp_dir("soft_params");
  const std::string data = std::string(RBX_SOURCE_DIR) + "/scenes/real/cube_toss/test.csv.gz";
  const struct {
    const char* soft;
    const char* says;
  } cases[] = {
      {R"("ode": {"restitution": 0.1, "friction": 0.2, "soft": {"erp": -0.5}})",
       "backends.ode.soft.erp: must be a number in [0, 1], got -0.5"},
      {R"("mujoco": {"restitution": 0.1, "friction": 0.2, "soft": {"timeconst": 0.02}})",
       "backends.mujoco.soft.timeconst: not a soft-contact parameter of mujoco (it has "
       "contact_steps, impedance)"},
      {R"("mujoco": {"restitution": 0.1, "friction": 0.2, "soft": {"impedance": 1.0}})",
       "backends.mujoco.soft.impedance: must be a number in [0.0001, 0.9999], got 1.0"},
      {R"("bullet": {"restitution": 0.1, "friction": 0.2, "soft": {"erp": 1.5}})",
       "backends.bullet.soft.erp: must be a number in [0, 1], got 1.5"},
      {R"("custom": {"restitution": 0.1, "friction": 0.2, "soft": {"erp": 0.2}})",
       "backends.custom.soft.erp: not a soft-contact parameter of custom (it has none)"},
      {R"("dart": {"restitution": 0.1, "friction": 0.2, "soft": {"cfm": "1e-5"}})",
       "backends.dart.soft.cfm: must be a number in [1e-09, 1]"},
  };
  for (const auto& c : cases) {
    const fs::path params = dir / "params.json";
    std::ofstream(params) << "{\"backends\": {" << c.soft << "}}";
    const fs::path json = dir / "out.json";
    const CmdResult r = run_rbx("tosses '" + data + "' --backends ode --params '" +
                                params.string() + "' --json '" + json.string() + "'");
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(params.string() + ": " + c.says), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(json));
  }
  fs::remove_all(dir);
}

TEST(TossesSimulation, FlatCubeDroppedFromRestFallsFreelyInEveryBackend) {
  // Closed form z(t) = z0 - g t^2 / 2, sampled at 148 Hz for 0.2 s; from z0 = 0.3 m the cube's
  // bottom face reaches the floor only at t = sqrt(2 (0.3 - 0.0524) / 9.81) = 0.225 s.
  const CubeTossModel model;
  const double z0 = 0.3, duration = 0.2;
  Toss t;
  t.id = 1;
  const int n = static_cast<int>(std::lround(duration * model.sample_rate)) + 1;
  for (int i = 0; i < n; ++i) {
    const double time = i / model.sample_rate;
    t.samples.push_back({time, Vec3(0.1, -0.2, z0 - 0.5 * model.gravity * time * time),
                         Quat::Identity(), Vec3(0, 0, -model.gravity * time), Vec3::Zero()});
  }
  // A first-order integrator with step h is off the parabola by g h t / 2 at time t (symplectic
  // Euler: z_k = z0 - g h^2 k (k + 1) / 2), so no sample may be off by more than g h T / 2.
  const double h = 1.0 / (model.sample_rate * model.substeps);
  const double last = (n - 1) / model.sample_rate;  // s, time of the last sample
  // The bound is reached exactly by symplectic Euler; 1e-6 relative: round-off of the sums.
  const double bound = model.gravity * h * last / 2 / (2 * model.half_width);  // widths
  int ran = 0;
  for (const Backend& b : backends()) {
    if (!b.dynamics) continue;
    const TossRun run = simulate_toss(b.dynamics, t, {0.5, 0.5, {}}, model);
    ASSERT_EQ(run.status, Status::Ok) << b.name << ": " << run.message;
    const TossErrors e = toss_errors(t, run.track, 2 * model.half_width);
    for (double d : e.position_by_sample) EXPECT_LE(d, bound * (1 + 1e-6)) << b.name;
    // No torque, no spin: any rotation is round-off (MuJoCo integrates in double as well).
    EXPECT_LT(e.orientation_deg, 1e-6) << b.name;
    // The first sample is the initial condition itself.
    EXPECT_EQ(run.track.position[0], t.samples[0].position) << b.name;
    ++ran;
  }
  EXPECT_GE(ran, 4);  // custom, bullet, mujoco, ode at least
}

TEST(TossesEvaluate, ALibraryAbortingOnOneTossFailsThatTossAloneAndTheOthersAreKept) {
  // Three tosses in one supervised child; a library backend that aborts on the second (ODE's
  // dynamics behind it otherwise). The abort is that toss's failure; the other two come back
  // through the child with the errors an unsupervised run of ODE gives, to the bit.
  const CubeTossModel model;
  std::vector<Toss> tosses;
  for (long id = 1; id <= 3; ++id) {
    Toss t;
    t.id = id;
    for (int i = 0; i < 20; ++i) {
      const double time = i / model.sample_rate, z = 0.2 + 0.05 * id;
      t.samples.push_back({time, Vec3(0, 0, z - 0.5 * model.gravity * time * time),
                           Quat::Identity(), Vec3(0, 0, -model.gravity * time), Vec3::Zero()});
    }
    tosses.push_back(t);
  }
  const Backend* ode = find_backend("ode");
  ASSERT_NE(ode, nullptr);
  Backend aborting = *ode;
  aborting.name = "ode-aborting";
  aborting.library = true;
  // The second toss is the one whose cube starts at z = 0.3 (0.2 + 0.05 x 2).
  const double second_z = tosses[1].samples[0].position.z();
  aborting.dynamics = [ode, second_z](const WorldDefinition& scene, const DynamicsOptions& opt) {
    for (const BodySpec& b : scene.bodies)
      if (b.name == "cube" && b.position.z() == second_z) std::abort();
    return ode->dynamics(scene, opt);
  };
  const ContactParams params{0.5, 0.5, {}};
  const BackendTosses r = evaluate_backend(aborting, tosses, params, model);
  EXPECT_EQ(r.status, Status::Error);
  EXPECT_NE(r.message.find("1 of 3 tosses failed"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("Aborted"), std::string::npos) << r.message;
  ASSERT_EQ(r.tosses.size(), 2u);
  for (const TossErrors& e : r.tosses) {
    const Toss& t = tosses[static_cast<size_t>(e.toss_id - 1)];
    const TossRun direct = simulate_toss(ode->dynamics, t, params, model);
    ASSERT_EQ(direct.status, Status::Ok) << direct.message;
    const TossErrors d = toss_errors(t, direct.track, 2 * model.half_width);
    EXPECT_EQ(e.position, d.position) << e.toss_id;
    EXPECT_EQ(e.orientation_deg, d.orientation_deg) << e.toss_id;
    EXPECT_EQ(e.final_position, d.final_position) << e.toss_id;
    EXPECT_EQ(e.position_by_sample, d.position_by_sample) << e.toss_id;
    EXPECT_EQ(e.horizontal_by_sample, d.horizontal_by_sample) << e.toss_id;
  }
  EXPECT_EQ(r.tosses[0].toss_id, 1);
  EXPECT_EQ(r.tosses[1].toss_id, 3);
}

// A tumbling, sliding toss of 90 samples "measured" by `backend` itself at `params` (its
// softness set): a toss some parameter set reproduces exactly.
Toss toss_measured_by(const Backend& backend, const ContactParams& params,
                      const CubeTossModel& model) {
  Toss toss;
  toss.id = 0;
  for (int i = 0; i < 90; ++i)
    toss.samples.push_back(
        {i / model.sample_rate, Vec3::Zero(), Quat::Identity(), Vec3::Zero(), Vec3::Zero()});
  toss.samples[0] = {0.0, Vec3(0, 0, 0.15),
                     Quat(Eigen::AngleAxisd(0.4, Vec3(1, 2, 0).normalized())), Vec3(0.8, 0.1, -0.5),
                     Vec3(3, -2, 1)};
  const TossRun truth = simulate_toss(toss_backend(backend, params).dynamics, toss, params, model);
  EXPECT_EQ(truth.status, Status::Ok) << truth.message;
  for (size_t i = 0; i < toss.samples.size() && i < truth.track.position.size(); ++i) {
    toss.samples[i].position = truth.track.position[i];
    toss.samples[i].orientation = truth.track.orientation[i];
  }
  return toss;
}

TEST(TossesFit, RecoversTheParametersThatGeneratedATossOnTheGrid) {
  // A tumbling, sliding toss "measured" by ODE itself at e = 0.5, mu = 0.3 (a grid point): the
  // fit must find an objective of exactly 0 there (the runs are deterministic).
  const Backend* ode = find_backend("ode");
  ASSERT_NE(ode, nullptr);
  const CubeTossModel model;
  const Toss measured = toss_measured_by(*ode, {0.5, 0.3, {}}, model);
  // Another parameter set gives a visibly different toss (the fit has something to find).
  EXPECT_GT(fit_objective(*ode, {measured}, {0.125, 0.18, {}}, model), 1e-3);
  const FitResult fit = fit_backend(*ode, {measured}, model);
  EXPECT_EQ(fit.objective, 0.0);
  EXPECT_EQ(fit.params.restitution, 0.5);
  EXPECT_EQ(fit.params.friction, 0.3);
  EXPECT_GE(fit.evaluations, 30);
}

TEST(TossesFit, ASoftnessThatMovedIsFollowedByEAndMuFittedAgainAtIt) {
  // A toss "measured" by ODE at e = 0.5, mu = 0.3 and a softer contact than ODE's own (cfm 1e-3):
  // the first fit, at ODE's own softness, cannot reach it, so the softness pass moves; every grid
  // value's objective is kept beside the chosen; then e and mu are searched again at the chosen
  // softness (every call names it), and the stored parameters reproduce the stored objective.
  const Backend* ode = find_backend("ode");
  ASSERT_NE(ode, nullptr);
  const CubeTossModel model;
  const Toss measured = toss_measured_by(*ode, {0.5, 0.3, {{"cfm", 1e-3}}}, model);
  std::vector<std::string> calls;
  const FitResult fit =
      fit_backend(*ode, {measured}, model, [&](const std::string& line) { calls.push_back(line); });
  ASSERT_EQ(fit.stages.size(), 3u);
  EXPECT_EQ(fit.stages[0].first, "e, mu");
  EXPECT_EQ(fit.stages[1].first, "softness");
  EXPECT_EQ(fit.stages[2].first, "e, mu at the softness");
  EXPECT_LT(fit.stages[1].second, fit.stages[0].second);
  EXPECT_LE(fit.stages[2].second, fit.stages[1].second);
  EXPECT_EQ(fit.objective, fit.stages[2].second);
  ASSERT_EQ(fit.params.soft.size(), 2u);
  EXPECT_EQ(fit_objective(*ode, {measured}, fit.params, model), fit.objective);
  // The last search ran at the chosen softness: its calls name it.
  const std::string at = " at " + soft_text({0, 0, fit.params.soft}) + " -> ";
  ASSERT_FALSE(calls.empty());
  EXPECT_NE(calls.back().find(at), std::string::npos) << calls.back() << " / " << at;
  EXPECT_EQ(static_cast<int>(calls.size()), fit.evaluations);
  // Every value of both grids, and each parameter's own, has its objective beside the chosen.
  size_t tried = 0;
  for (const SoftParameter& p : ode->soft.parameters) {
    tried += p.grid.size() + 1;
    for (const double g : p.grid) {
      if (g == p.value) --tried;
      EXPECT_TRUE(std::any_of(fit.soft_scan.begin(), fit.soft_scan.end(),
                              [&](const SoftTrial& t) {
                                return t.parameter == p.name && t.value == g &&
                                       std::isfinite(t.objective);
                              }))
          << p.name << " " << g;
    }
  }
  EXPECT_EQ(fit.soft_scan.size(), tried);
}

TEST(TossesFit, TheCommittedParametersCarryEverySoftnessTriedAndKeepTheBest) {
  // scenes/real/cube_toss/params.json as `rbx tosses --fit` writes it: every backend with a
  // softness has every value of its grid and its own in soft_scan, the chosen value is the scan's
  // best of its parameter, and the stages never end worse than they began. A hand-edited softness
  // or a scan left out fails here.
  const std::string path = std::string(RBX_SOURCE_DIR) + "/scenes/real/cube_toss/params.json";
  std::ifstream in(path);
  const nlohmann::json j = nlohmann::json::parse(in);
  int scanned = 0;
  for (const Backend& b : backends()) {
    if (b.soft.parameters.empty() || !j["backends"].contains(b.name)) continue;
    const nlohmann::json& e = j["backends"][b.name];
    ASSERT_TRUE(e.contains("soft_scan")) << b.name;
    ++scanned;
    for (const SoftParameter& p : b.soft.parameters) {
      const nlohmann::json& scan = e["soft_scan"][p.name];
      std::vector<double> values;
      double best = INFINITY, best_value = NAN;
      for (const auto& t : scan) {
        values.push_back(t[0].get<double>());
        // A value at which a toss failed has an infinite objective, which JSON writes as null.
        const double v = t[1].is_null() ? INFINITY : t[1].get<double>();
        if (v < best) best = v, best_value = t[0].get<double>();
      }
      std::vector<double> expected = p.grid;
      if (std::find(expected.begin(), expected.end(), p.value) == expected.end())
        expected.push_back(p.value);
      std::sort(values.begin(), values.end());
      std::sort(expected.begin(), expected.end());
      EXPECT_EQ(values, expected) << b.name << " " << p.name;
      EXPECT_EQ(e["soft"][p.name].get<double>(), best_value) << b.name << " " << p.name;
    }
    const nlohmann::json& stages = e["fit_stages"];
    ASSERT_GE(stages.size(), 2u) << b.name;
    for (size_t i = 1; i < stages.size(); ++i)
      EXPECT_LE(stages[i]["train_position_error"].get<double>(),
                stages[i - 1]["train_position_error"].get<double>())
          << b.name;
    EXPECT_EQ(stages.back()["train_position_error"].get<double>(),
              e["train_position_error"].get<double>())
        << b.name;
  }
  EXPECT_EQ(scanned, 8);  // mujoco, ode, dart and bullet, each with its -hull backend
}

TEST(TossesCommand, JsonIsDeterministicAndHasTheContractFields) {
  // The first three test tosses, every dynamics backend, twice.
  const fs::path dir = temp_dir("json");
  const std::vector<Toss> all =
      read_tosses(std::string(RBX_SOURCE_DIR) + "/scenes/real/cube_toss/test.csv.gz");
  std::ofstream csv(dir / "three.csv");
  csv << kHeader;
  csv.precision(17);
  for (int k = 0; k < 3; ++k)
    for (const TossSample& s : all[k].samples)
      csv << all[k].id << "," << s.time << "," << s.position.x() << "," << s.position.y() << ","
          << s.position.z() << "," << s.orientation.w() << "," << s.orientation.x() << ","
          << s.orientation.y() << "," << s.orientation.z() << "," << s.velocity.x() << ","
          << s.velocity.y() << "," << s.velocity.z() << "," << s.angular_velocity.x() << ","
          << s.angular_velocity.y() << "," << s.angular_velocity.z() << "\n";
  csv.close();
  std::ofstream(dir / "params.json")
      << R"({"backends": {"ode": {"restitution": 0.3, "friction": 0.2}}})";
  nlohmann::json j[2];
  for (int run = 0; run < 2; ++run) {
    const fs::path out = dir / ("out" + std::to_string(run) + ".json");
    const CmdResult r =
        run_rbx("tosses '" + (dir / "three.csv").string() + "' --json '" + out.string() + "'");
    ASSERT_EQ(r.code, 0) << r.err;
    j[run] = nlohmann::json::parse(std::ifstream(out));
    // Run times are the only non-deterministic numbers.
    for (auto* set : {&j[run]["backends"], &j[run]["published_params"]["backends"]})
      for (auto& [name, b] : set->items()) b.erase("runtime_s");
  }
  EXPECT_EQ(j[0], j[1]);
  const auto& b = j[0]["backends"];
  for (const char* name : {"custom", "bullet", "ode", "mujoco"}) {
    ASSERT_TRUE(b.contains(name)) << name;
    EXPECT_EQ(b[name]["tosses"], 3) << name;
    for (const char* k : {"position_error", "orientation_error_deg", "final_position_error"})
      for (const char* s : {"median", "mean", "p90"})
        EXPECT_TRUE(b[name][k][s].is_number()) << name << k << s;
    EXPECT_TRUE(b[name]["status"].is_string());
    EXPECT_TRUE(b[name]["message"].is_string());
  }
  // The stored parameters are used where there are some, the published ones elsewhere.
  EXPECT_EQ(b["ode"]["params"]["restitution"], 0.3);
  EXPECT_EQ(b["ode"]["params"]["friction"], 0.2);
  EXPECT_EQ(b["bullet"]["params"]["restitution"], 0.125);
  EXPECT_EQ(j[0]["published_params"]["backends"]["ode"]["params"]["friction"], 0.18);
  fs::remove_all(dir);
}

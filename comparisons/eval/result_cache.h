// On-disk cache of the reference libraries' results, so that a check after an engine-only edit
// reruns only the engine under test.
//
// Design: one file per call, named by a hash of the call's fingerprint; the file holds the whole
// fingerprint and is used only when it matches byte for byte (no hash collision can return a
// wrong result). The fingerprint is a canonical binary serialization of everything the call
// reads: the bodies as the adapter receives them (hull vertices and triangles, mass properties,
// pose, velocities), the scene's [sim] settings and the call's options, plus the backend's name,
// a hash of the adapters' sources (reference/, and the engine geometry they call, computed at
// build time) and the libraries' versions. Values are stored bit-exact, so a cached result is
// byte-identical to the run it came from. `custom` (and its variants) and `exact` are ours and
// under test: never cached.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "comparisons/eval/timing.h"
#include "comparisons/scene/scene.h"
#include "engine/body.h"
#include "reference/backend.h"

namespace rbx {

/// A cached result with the run time measured when it was computed (s).
template <class Result>
struct CachedResult {
  Result result;
  double runtime_s = 0.0;
};

/// A cached contact query, with the timing measured when it was computed (timing.h).
struct CachedContact {
  ContactResult result;
  Timing timing;
};

/// The reference-result cache in one folder ("" : disabled; nothing is read or written).
class ResultCache {
 public:
  /// `code`: what identifies the reference code (tests pass another to see a miss). `reads`
  /// false: results are stored and never read (rbx report fills the cache with runs it timed
  /// itself; rbx check reads them).
  explicit ResultCache(std::string dir = "", std::string code = code_fingerprint(),
                       bool reads = true)
      : dir_(std::move(dir)), code_(std::move(code)), reads_(reads) {}

  /// True when results of `backend` may be cached: every backend except ours (custom*, exact) and
  /// those registered at run time (Backend::user).
  static bool caches(const std::string& backend);
  /// The folder used by `rbx check` unless --no-cache: build/cache in the build tree.
  static std::string default_dir();
  /// What identifies the reference code: the adapters' source hash, library versions, compiler.
  static std::string code_fingerprint();

  bool enabled() const { return !dir_.empty(); }

  /// Fingerprints of the three kinds of call.
  std::string contact_key(const std::string& backend, const RigidBody& a, const RigidBody& b) const;
  std::string dynamics_key(const std::string& backend, const Scene& scene,
                           const std::vector<RigidBody>& bodies, const DynamicsOptions& opt) const;
  std::string mass_key(const std::string& backend, const RigidBody& body) const;

  /// Lookups: nullopt on a miss (no file, another fingerprint, an unreadable file).
  std::optional<CachedContact> load_contact(const std::string& key) const;
  std::optional<CachedResult<DynamicsResult>> load_dynamics(const std::string& key) const;
  std::optional<CachedResult<MassResult>> load_mass(const std::string& key) const;
  /// A distance query's answer (explore's distance samples), keyed as the caller chooses.
  std::optional<CachedResult<DistanceResult>> load_distance(const std::string& key) const;
  /// A time-of-impact query's answer (explore's toi samples), keyed as the caller chooses.
  std::optional<CachedResult<ToiResult>> load_toi(const std::string& key) const;
  /// Numbers the harness derives from a cached run (keyed by the run's key; the harness's own
  /// code hash is added, so an edit of harness.cpp recomputes them).
  std::optional<std::vector<double>> load_derived(const std::string& run_key,
                                                  const std::string& what) const;
  void store_derived(const std::string& run_key, const std::string& what,
                     const std::vector<double>& v) const;

  /// Stores (atomically: a temporary file renamed into place); failures to write are ignored
  /// (the cache only saves time). A timeout is not stored: it depends on the machine's load at
  /// the time, not on the inputs, so the next run asks the library again.
  void store(const std::string& key, const ContactResult& r, const Timing& timing) const;
  void store(const std::string& key, const DynamicsResult& r, double runtime_s) const;
  void store(const std::string& key, const MassResult& r, double runtime_s) const;
  void store(const std::string& key, const DistanceResult& r, double runtime_s) const;
  void store(const std::string& key, const ToiResult& r, double runtime_s) const;

 private:
  std::optional<std::string> read(const std::string& key) const;
  void write(const std::string& key, const std::string& value) const;
  std::string dir_;
  std::string code_;
  bool reads_ = true;
};

}  // namespace rbx

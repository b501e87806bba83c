#include "comparisons/eval/result_cache.h"

#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "evaluation_source_hash.h"  // generated at build time: RBX_EVALUATION_SOURCE_HASH
#include "reference/result_codec.h"
#include "reference_source_hash.h"  // generated at build time: RBX_REFERENCE_SOURCE_HASH

namespace rbx {

namespace {

// A body exactly as an adapter receives it.
void put_body(ByteWriter& w, const RigidBody& b) {
  w.put(b.name);
  w.put(b.shape_kind);
  w.put(b.box_size);
  w.put(b.shape_origin_offset);
  w.put(b.is_static);
  w.put(b.mass);
  w.put(b.inertia_body);
  w.put(b.inverse_mass);
  w.put(b.inverse_inertia_body);
  w.put(b.position);
  w.put(b.orientation);
  w.put(b.velocity);
  w.put(b.angular_velocity);
  w.put(static_cast<long>(b.shape->vertices().size()));
  for (const Vec3& v : b.shape->vertices()) w.put(v);
  w.put(static_cast<long>(b.shape->triangles().size()));
  for (const auto& t : b.shape->triangles())
    for (int i : t) w.put(i);
}

// Common head of every key: what kind of call, which backend, which code.
ByteWriter key_head(const std::string& code, const char* kind, const std::string& backend) {
  ByteWriter w;
  w.put("rbx result cache v3");  // v3: results in reference/result_codec.h's encoding
  w.put(code);
  w.put(kind);
  w.put(backend);
  return w;
}

// 64-bit FNV-1a: names the file; the full key inside decides.
std::string file_name(const std::string& key) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : key) h = (h ^ c) * 1099511628211ull;
  std::ostringstream s;
  s << std::hex << h << ".bin";
  return s.str();
}

template <class Result>
std::optional<CachedResult<Result>> decode(const std::optional<std::string>& bytes) {
  CachedResult<Result> c;
  if (!bytes || !decode_result(*bytes, c.result, c.runtime_s)) return std::nullopt;
  return c;
}

// What is kept of a result: nothing for a timeout (the machine's load at the time, not an answer
// of the inputs), else the result with its run time.
template <class Result>
std::optional<std::string> kept(const Result& r, double runtime_s) {
  if (r.status == Status::Timeout) return std::nullopt;
  return encode_result(r, runtime_s);
}

}  // namespace

bool ResultCache::caches(const std::string& backend) {
  const Backend* b = find_backend(backend);
  if (b && b->user) return false;  // a registered function's code is not in the key
  return backend != "exact" && backend.rfind("custom", 0) != 0;
}

std::string ResultCache::default_dir() { return std::string(RBX_DEFAULT_BINARY_DIR) + "/cache"; }

std::string ResultCache::code_fingerprint() {
  return std::string("adapters ") + RBX_REFERENCE_SOURCE_HASH + "; libraries " +
         RBX_REFERENCE_LIBRARY_VERSIONS + "; compiler " + RBX_COMPILER_ID;
}

std::string ResultCache::contact_key(const std::string& backend, const RigidBody& a,
                                     const RigidBody& b) const {
  ByteWriter w = key_head(code_, "contact", backend);
  put_body(w, a);
  put_body(w, b);
  return w.str();
}

std::string ResultCache::dynamics_key(const std::string& backend, const Scene& scene,
                                      const std::vector<RigidBody>& bodies,
                                      const DynamicsOptions& opt) const {
  ByteWriter w = key_head(code_, "dynamics", backend);
  const SimSettings& s = scene.sim;
  w.put(s.dt);
  w.put(s.duration);
  w.put(s.gravity);
  w.put(s.restitution);
  w.put(s.friction);
  w.put(s.integrator);
  w.put(s.max_energy_ratio);
  w.put(opt.dt);
  w.put(opt.sample_every);
  w.put(static_cast<long>(opt.budget));
  // The specifications (what an adapter may read from the scene) and the bodies built from them.
  w.put(static_cast<long>(scene.bodies.size()));
  for (const BodySpec& b : scene.bodies) {
    w.put(b.name);
    w.put(b.shape_kind);
    w.put(b.box_size);
    w.put(b.mass);
    w.put(b.is_static);
    w.put(b.mass_model);
    w.put(b.position);
    w.put(b.orientation);
    w.put(b.velocity);
    w.put(b.angular_velocity);
  }
  w.put(static_cast<long>(bodies.size()));
  for (const RigidBody& b : bodies) put_body(w, b);
  return w.str();
}

std::string ResultCache::mass_key(const std::string& backend, const RigidBody& body) const {
  ByteWriter w = key_head(code_, "mass", backend);
  put_body(w, body);
  return w.str();
}

std::optional<std::string> ResultCache::read(const std::string& key) const {
  if (dir_.empty() || !reads_) return std::nullopt;
  std::ifstream in(std::filesystem::path(dir_) / file_name(key), std::ios::binary);
  if (!in) return std::nullopt;
  std::stringstream s;
  s << in.rdbuf();
  const std::string all = s.str();
  // The file: key length, key, value.
  try {
    ByteReader r(all);
    std::string stored;
    r.get(stored);
    if (stored != key) return std::nullopt;
    return all.substr(sizeof(std::int64_t) + stored.size());
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

void ResultCache::write(const std::string& key, const std::string& value) const {
  if (dir_.empty()) return;
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir_, ec);
  const fs::path target = fs::path(dir_) / file_name(key);
  const fs::path tmp = target.string() + ".tmp-" + std::to_string(getpid());
  {
    ByteWriter w;
    w.put(key);
    std::ofstream out(tmp, std::ios::binary);
    out << w.str() << value;
    if (!out) {
      fs::remove(tmp, ec);
      return;
    }
  }
  fs::rename(tmp, target, ec);
  if (ec) fs::remove(tmp, ec);
}

// A contact entry: the result as the codec writes it (with the cold call's time), then the rest
// of its timing.
std::optional<CachedContact> ResultCache::load_contact(const std::string& key) const {
  const std::optional<std::string> bytes = read(key);
  if (!bytes) return std::nullopt;
  try {
    ByteReader in(*bytes);
    std::string result;
    CachedContact c;
    in.get(result);
    in.io(c.timing.median_s, c.timing.q25_s, c.timing.q75_s, c.timing.calls, c.timing.rounds);
    if (!in.done() || !decode_result(result, c.result, c.timing.cold_s)) return std::nullopt;
    return c;
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

void ResultCache::store(const std::string& key, const ContactResult& c,
                        const Timing& timing) const {
  if (c.status == Status::Timeout) return;
  ByteWriter w;
  w.put(encode_result(c, timing.cold_s));
  w.io(timing.median_s, timing.q25_s, timing.q75_s, timing.calls, timing.rounds);
  write(key, w.str());
}

std::optional<CachedResult<DynamicsResult>> ResultCache::load_dynamics(
    const std::string& key) const {
  return decode<DynamicsResult>(read(key));
}

void ResultCache::store(const std::string& key, const DynamicsResult& d, double runtime_s) const {
  if (const auto bytes = kept(d, runtime_s)) write(key, *bytes);
}

namespace {
std::string derived_key(const std::string& run_key, const std::string& what) {
  ByteWriter w;
  w.put(run_key);
  w.put("derived");
  w.put(RBX_EVALUATION_SOURCE_HASH);
  w.put(what);
  return w.str();
}
}  // namespace

std::optional<std::vector<double>> ResultCache::load_derived(const std::string& run_key,
                                                             const std::string& what) const {
  const std::optional<std::string> bytes = read(derived_key(run_key, what));
  if (!bytes) return std::nullopt;
  try {
    ByteReader r(*bytes);
    std::vector<double> v;
    r.io_list(v, [](ByteReader& i, double& x) { i.io(x); });
    if (r.done()) return v;
  } catch (const std::exception&) {
  }
  return std::nullopt;
}

void ResultCache::store_derived(const std::string& run_key, const std::string& what,
                                const std::vector<double>& v) const {
  ByteWriter w;
  w.io_list(v, [](ByteWriter& o, double x) { o.io(x); });
  write(derived_key(run_key, what), w.str());
}

std::optional<CachedResult<MassResult>> ResultCache::load_mass(const std::string& key) const {
  return decode<MassResult>(read(key));
}

void ResultCache::store(const std::string& key, const MassResult& m, double runtime_s) const {
  if (const auto bytes = kept(m, runtime_s)) write(key, *bytes);
}

std::optional<CachedResult<DistanceResult>> ResultCache::load_distance(
    const std::string& key) const {
  return decode<DistanceResult>(read(key));
}

void ResultCache::store(const std::string& key, const DistanceResult& r, double runtime_s) const {
  if (const auto bytes = kept(r, runtime_s)) write(key, *bytes);
}

std::optional<CachedResult<ToiResult>> ResultCache::load_toi(const std::string& key) const {
  return decode<ToiResult>(read(key));
}

void ResultCache::store(const std::string& key, const ToiResult& r, double runtime_s) const {
  if (const auto bytes = kept(r, runtime_s)) write(key, *bytes);
}

}  // namespace rbx

#include "comparisons/eval/result_cache.h"

#include <unistd.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "evaluation_source_hash.h"  // generated at build time: RBX_EVALUATION_SOURCE_HASH
#include "reference_source_hash.h"   // generated at build time: RBX_REFERENCE_SOURCE_HASH

namespace rbx {

namespace {

// Canonical binary writer: fixed-width little-endian-as-in-memory values, strings with their
// length. Enums are written as their integer value (shape kinds and features may be either).
class Writer {
 public:
  void put(double x) { raw(&x, sizeof x); }
  void put(long x) {
    std::int64_t v = x;
    raw(&v, sizeof v);
  }
  void put(int x) { put(static_cast<long>(x)); }
  void put(bool x) { put(static_cast<long>(x)); }
  void put(const std::string& s) {
    put(static_cast<long>(s.size()));
    out_.append(s);
  }
  void put(const char* s) { put(std::string(s)); }
  template <class E, std::enable_if_t<std::is_enum_v<E>, int> = 0>
  void put(E e) {
    put(static_cast<long>(e));
  }
  void put(const Vec3& v) {
    for (int i = 0; i < 3; ++i) put(v[i]);
  }
  void put(const Quat& q) {
    put(q.w());
    put(q.x());
    put(q.y());
    put(q.z());
  }
  void put(const Mat3& m) {
    for (int i = 0; i < 9; ++i) put(m.data()[i]);
  }
  const std::string& str() const { return out_; }

 private:
  void raw(const void* p, size_t n) { out_.append(static_cast<const char*>(p), n); }
  std::string out_;
};

// The matching reader; throws std::runtime_error past the end (a truncated file is a miss).
class Reader {
 public:
  explicit Reader(const std::string& s) : in_(s) {}
  void get(double& x) { raw(&x, sizeof x); }
  void get(long& x) {
    std::int64_t v;
    raw(&v, sizeof v);
    x = static_cast<long>(v);
  }
  void get(int& x) {
    long v;
    get(v);
    x = static_cast<int>(v);
  }
  void get(bool& x) {
    long v;
    get(v);
    x = v != 0;
  }
  void get(std::string& s) {
    long n;
    get(n);
    if (n < 0 || static_cast<size_t>(n) > in_.size() - at_) throw std::runtime_error("truncated");
    s = in_.substr(at_, n);
    at_ += n;
  }
  template <class E, std::enable_if_t<std::is_enum_v<E>, int> = 0>
  void get(E& e) {
    long v;
    get(v);
    e = static_cast<E>(v);
  }
  void get(Vec3& v) {
    for (int i = 0; i < 3; ++i) get(v[i]);
  }
  void get(Quat& q) {
    double w, x, y, z;
    get(w);
    get(x);
    get(y);
    get(z);
    q = Quat(w, x, y, z);
  }
  void get(Mat3& m) {
    for (int i = 0; i < 9; ++i) get(m.data()[i]);
  }
  bool done() const { return at_ == in_.size(); }

 private:
  void raw(void* p, size_t n) {
    if (n > in_.size() - at_) throw std::runtime_error("truncated");
    std::memcpy(p, in_.data() + at_, n);
    at_ += n;
  }
  const std::string& in_;
  size_t at_ = 0;
};

// A body exactly as an adapter receives it.
void put_body(Writer& w, const RigidBody& b) {
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
Writer key_head(const std::string& code, const char* kind, const std::string& backend) {
  Writer w;
  w.put("rbx result cache v2");  // v2: dynamics entries hold the first impulse
  w.put(code);
  w.put(kind);
  w.put(backend);
  return w;
}

void put_contact(Writer& w, const ContactPoint& c) {
  w.put(c.point);
  w.put(c.normal);
  w.put(c.depth);
  w.put(c.feature);
}
void get_contact(Reader& r, ContactPoint& c) {
  r.get(c.point);
  r.get(c.normal);
  r.get(c.depth);
  r.get(c.feature);
}
void put_final(Writer& w, const BodyFinal& f) {
  w.put(f.name);
  w.put(f.position);
  w.put(f.orientation);
  w.put(f.velocity);
  w.put(f.angular_velocity);
}
void get_final(Reader& r, BodyFinal& f) {
  r.get(f.name);
  r.get(f.position);
  r.get(f.orientation);
  r.get(f.velocity);
  r.get(f.angular_velocity);
}

// 64-bit FNV-1a: names the file; the full key inside decides.
std::string file_name(const std::string& key) {
  std::uint64_t h = 1469598103934665603ull;
  for (unsigned char c : key) h = (h ^ c) * 1099511628211ull;
  std::ostringstream s;
  s << std::hex << h << ".bin";
  return s.str();
}

template <class Result, class Fill>
std::optional<CachedResult<Result>> decode(const std::optional<std::string>& bytes, Fill fill) {
  if (!bytes) return std::nullopt;
  try {
    Reader r(*bytes);
    CachedResult<Result> c;
    r.get(c.runtime_s);
    fill(r, c.result);
    if (!r.done()) return std::nullopt;
    return c;
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

}  // namespace

bool ResultCache::caches(const std::string& backend) {
  return backend != "exact" && backend.rfind("custom", 0) != 0;
}

std::string ResultCache::default_dir() { return std::string(RBX_DEFAULT_BINARY_DIR) + "/cache"; }

std::string ResultCache::code_fingerprint() {
  return std::string("adapters ") + RBX_REFERENCE_SOURCE_HASH + "; libraries " +
         RBX_REFERENCE_LIBRARY_VERSIONS + "; compiler " + RBX_COMPILER_ID;
}

std::string ResultCache::contact_key(const std::string& backend, const RigidBody& a,
                                     const RigidBody& b) const {
  Writer w = key_head(code_, "contact", backend);
  put_body(w, a);
  put_body(w, b);
  return w.str();
}

std::string ResultCache::dynamics_key(const std::string& backend, const Scene& scene,
                                      const std::vector<RigidBody>& bodies,
                                      const DynamicsOptions& opt) const {
  Writer w = key_head(code_, "dynamics", backend);
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
  Writer w = key_head(code_, "mass", backend);
  put_body(w, body);
  return w.str();
}

std::optional<std::string> ResultCache::read(const std::string& key) const {
  if (dir_.empty()) return std::nullopt;
  std::ifstream in(std::filesystem::path(dir_) / file_name(key), std::ios::binary);
  if (!in) return std::nullopt;
  std::stringstream s;
  s << in.rdbuf();
  const std::string all = s.str();
  // The file: key length, key, value.
  try {
    Reader r(all);
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
    Writer w;
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

std::optional<CachedResult<ContactResult>> ResultCache::load_contact(const std::string& key) const {
  return decode<ContactResult>(read(key), [](Reader& r, ContactResult& c) {
    r.get(c.status);
    r.get(c.message);
    long n;
    r.get(n);
    if (n < 0) throw std::runtime_error("bad count");
    c.contacts.resize(n);
    for (ContactPoint& p : c.contacts) get_contact(r, p);
  });
}

void ResultCache::store(const std::string& key, const ContactResult& c, double runtime_s) const {
  Writer w;
  w.put(runtime_s);
  w.put(c.status);
  w.put(c.message);
  w.put(static_cast<long>(c.contacts.size()));
  for (const ContactPoint& p : c.contacts) put_contact(w, p);
  write(key, w.str());
}

std::optional<CachedResult<DynamicsResult>> ResultCache::load_dynamics(
    const std::string& key) const {
  return decode<DynamicsResult>(read(key), [](Reader& r, DynamicsResult& d) {
    auto count = [&r]() {
      long n;
      r.get(n);
      if (n < 0) throw std::runtime_error("bad count");
      return static_cast<size_t>(n);
    };
    r.get(d.status);
    r.get(d.message);
    d.events.resize(count());
    for (CollisionEvent& e : d.events) {
      r.get(e.time);
      r.get(e.step);
      r.get(e.body_a);
      r.get(e.body_b);
      get_contact(r, e.contact);
      r.get(e.impulse);
    }
    d.finals.resize(count());
    for (BodyFinal& f : d.finals) get_final(r, f);
    d.samples.resize(count());
    for (StateSample& s : d.samples) {
      r.get(s.time);
      s.bodies.resize(count());
      for (BodyFinal& f : s.bodies) get_final(r, f);
    }
    FirstImpulse& fi = d.first_impulse;
    r.get(fi.seen);
    r.get(fi.body_a);
    r.get(fi.body_b);
    r.get(fi.step);
    r.get(fi.contact_points);
    r.get(fi.normal);
    r.get(fi.point);
    r.get(fi.depth);
    r.get(fi.impulse);
    r.get(fi.approach_speed);
    r.get(fi.entry_phase);
  });
}

void ResultCache::store(const std::string& key, const DynamicsResult& d, double runtime_s) const {
  Writer w;
  w.put(runtime_s);
  w.put(d.status);
  w.put(d.message);
  w.put(static_cast<long>(d.events.size()));
  for (const CollisionEvent& e : d.events) {
    w.put(e.time);
    w.put(e.step);
    w.put(e.body_a);
    w.put(e.body_b);
    put_contact(w, e.contact);
    w.put(e.impulse);
  }
  w.put(static_cast<long>(d.finals.size()));
  for (const BodyFinal& f : d.finals) put_final(w, f);
  w.put(static_cast<long>(d.samples.size()));
  for (const StateSample& s : d.samples) {
    w.put(s.time);
    w.put(static_cast<long>(s.bodies.size()));
    for (const BodyFinal& f : s.bodies) put_final(w, f);
  }
  const FirstImpulse& fi = d.first_impulse;
  w.put(fi.seen);
  w.put(fi.body_a);
  w.put(fi.body_b);
  w.put(fi.step);
  w.put(fi.contact_points);
  w.put(fi.normal);
  w.put(fi.point);
  w.put(fi.depth);
  w.put(fi.impulse);
  w.put(fi.approach_speed);
  w.put(fi.entry_phase);
  write(key, w.str());
}

namespace {
std::string derived_key(const std::string& run_key, const std::string& what) {
  Writer w;
  w.put(run_key);
  w.put("derived");
  w.put(RBX_EVALUATION_SOURCE_HASH);
  w.put(what);
  return w.str();
}
}  // namespace

std::optional<std::vector<double>> ResultCache::load_derived(const std::string& run_key,
                                                             const std::string& what) const {
  const auto c = decode<std::vector<double>>(read(derived_key(run_key, what)),
                                             [](Reader& r, std::vector<double>& v) {
                                               long n;
                                               r.get(n);
                                               if (n < 0) throw std::runtime_error("bad count");
                                               v.resize(n);
                                               for (double& x : v) r.get(x);
                                             });
  if (!c) return std::nullopt;
  return c->result;
}

void ResultCache::store_derived(const std::string& run_key, const std::string& what,
                                const std::vector<double>& v) const {
  Writer w;
  w.put(0.0);  // no run time: derived numbers
  w.put(static_cast<long>(v.size()));
  for (double x : v) w.put(x);
  write(derived_key(run_key, what), w.str());
}

std::optional<CachedResult<MassResult>> ResultCache::load_mass(const std::string& key) const {
  return decode<MassResult>(read(key), [](Reader& r, MassResult& m) {
    r.get(m.status);
    r.get(m.message);
    r.get(m.mass);
    r.get(m.volume);
    r.get(m.center_of_mass);
    r.get(m.inertia);
  });
}

void ResultCache::store(const std::string& key, const MassResult& m, double runtime_s) const {
  Writer w;
  w.put(runtime_s);
  w.put(m.status);
  w.put(m.message);
  w.put(m.mass);
  w.put(m.volume);
  w.put(m.center_of_mass);
  w.put(m.inertia);
  write(key, w.str());
}

}  // namespace rbx

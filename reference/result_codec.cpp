#include "reference/result_codec.h"

namespace rbx {

namespace {

// Chooses result_fields' overload by the result's type, const or not.
template <class R, class T>
using Is = std::enable_if_t<std::is_same_v<std::decay_t<R>, T>, int>;

// The fields of each result, in byte order, for both directions (Io is ByteWriter or
// ByteReader; R is the result, const when writing).
template <class Io, class R>
void contact_fields(Io& io, R& c) {
  io.io(c.point, c.normal, c.depth, c.feature);
}

template <class Io, class R>
void final_fields(Io& io, R& f) {
  io.io(f.name, f.position, f.orientation, f.velocity, f.angular_velocity);
}

template <class Io, class R>
void result_fields(Io& io, R& c, Is<R, ContactResult> = 0) {
  io.io(c.status, c.message);
  io.io_list(c.contacts, [](Io& i, auto& p) { contact_fields(i, p); });
}

template <class Io, class R>
void result_fields(Io& io, R& d, Is<R, DynamicsResult> = 0) {
  io.io(d.status, d.message);
  io.io_list(d.events, [](Io& i, auto& e) {
    i.io(e.time, e.step, e.body_a, e.body_b);
    contact_fields(i, e.contact);
    i.io(e.impulse);
  });
  io.io_list(d.finals, [](Io& i, auto& f) { final_fields(i, f); });
  io.io_list(d.samples, [](Io& i, auto& s) {
    i.io(s.time);
    i.io_list(s.bodies, [](Io& j, auto& f) { final_fields(j, f); });
  });
  auto& fi = d.first_impulse;
  io.io(fi.seen, fi.body_a, fi.body_b, fi.step, fi.contact_points, fi.normal, fi.point, fi.depth,
        fi.impulse, fi.approach_speed, fi.entry_phase);
  io.io(d.laws.measured, d.laws.contacts);
  for (auto& r : d.laws.residuals) io.io(r.worst, r.median);
  io.io_list(d.laws.cone_excess,
             [](Io& i, auto& u) { i.io(u.body, u.points, u.turn_rad, u.push_m2s2); });
}

template <class Io, class R>
void result_fields(Io& io, R& m, Is<R, MassResult> = 0) {
  io.io(m.status, m.message, m.mass, m.volume, m.center_of_mass, m.inertia);
}

template <class Io, class R>
void result_fields(Io& io, R& d, Is<R, DistanceResult> = 0) {
  io.io(d.status, d.message, d.overlapping, d.distance, d.point_a, d.point_b);
}

template <class Io, class R>
void result_fields(Io& io, R& t, Is<R, ToiResult> = 0) {
  io.io(t.status, t.message, t.hit, t.fraction, t.located, t.point, t.normal);
}

template <class R>
std::string encode(const R& r, double runtime_s) {
  ByteWriter w;
  w.put(runtime_s);
  result_fields(w, r);
  return w.str();
}

template <class R>
bool decode(const std::string& bytes, R& r, double& runtime_s) {
  try {
    ByteReader in(bytes);
    in.get(runtime_s);
    result_fields(in, r);
    return in.done();
  } catch (const std::exception&) {
    return false;
  }
}

}  // namespace

std::string encode_result(const ContactResult& r, double runtime_s) { return encode(r, runtime_s); }
std::string encode_result(const DynamicsResult& r, double runtime_s) {
  return encode(r, runtime_s);
}
std::string encode_result(const MassResult& r, double runtime_s) { return encode(r, runtime_s); }
std::string encode_result(const DistanceResult& r, double runtime_s) {
  return encode(r, runtime_s);
}
bool decode_result(const std::string& bytes, DistanceResult& r, double& runtime_s) {
  return decode(bytes, r, runtime_s);
}
std::string encode_result(const ToiResult& r, double runtime_s) { return encode(r, runtime_s); }
bool decode_result(const std::string& bytes, ToiResult& r, double& runtime_s) {
  return decode(bytes, r, runtime_s);
}
bool decode_result(const std::string& bytes, ContactResult& r, double& runtime_s) {
  return decode(bytes, r, runtime_s);
}
bool decode_result(const std::string& bytes, DynamicsResult& r, double& runtime_s) {
  return decode(bytes, r, runtime_s);
}
bool decode_result(const std::string& bytes, MassResult& r, double& runtime_s) {
  return decode(bytes, r, runtime_s);
}

}  // namespace rbx

// One byte encoding of a backend's results, shared by the two places results cross a boundary:
// the isolated child's answer to its parent (reference/isolate.cpp) and the result cache's files
// (comparisons/eval/result_cache.cpp). Values are written bit for bit in host order, strings and
// lists with their length, so a decoded result is identical to the one encoded.
#pragma once

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "reference/backend.h"

namespace rbx {

/// Appends values as bytes: doubles bit for bit, integers, booleans and enums as 64-bit
/// integers, strings with their length, vectors and quaternions (w, x, y, z) as their doubles.
class ByteWriter {
 public:
  void put(double x) { raw(&x, sizeof x); }
  void put(long x) {
    const std::int64_t v = x;
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
  /// The field lists are written once for both directions: io() puts values in order, io_list() the
  /// count and then each element through `each(writer, element)`.
  template <class... T>
  void io(const T&... x) {
    (put(x), ...);
  }
  template <class T, class Each>
  void io_list(const std::vector<T>& v, Each each) {
    put(static_cast<long>(v.size()));
    for (const T& x : v) each(*this, x);
  }
  /// The bytes so far.
  const std::string& str() const { return out_; }

 private:
  void raw(const void* p, size_t n) { out_.append(static_cast<const char*>(p), n); }
  std::string out_;
};

/// Reads what ByteWriter wrote, in the same order; throws std::runtime_error past the end or on
/// a negative count (a truncated or corrupt input).
class ByteReader {
 public:
  /// Reads `s`, which must outlive the reader.
  explicit ByteReader(const std::string& s) : in_(s) {}
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
    s = in_.substr(at_, static_cast<size_t>(n));
    at_ += static_cast<size_t>(n);
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
  /// The reading side of ByteWriter::io and ByteWriter::io_list.
  template <class... T>
  void io(T&... x) {
    (get(x), ...);
  }
  template <class T, class Each>
  void io_list(std::vector<T>& v, Each each) {
    long n;
    get(n);
    if (n < 0 || static_cast<size_t>(n) > in_.size() - at_) throw std::runtime_error("bad count");
    v.resize(static_cast<size_t>(n));
    for (T& x : v) each(*this, x);
  }
  /// True when every byte has been read.
  bool done() const { return at_ == in_.size(); }
  /// Bytes read so far.
  size_t position() const { return at_; }

 private:
  void raw(void* p, size_t n) {
    if (n > in_.size() - at_) throw std::runtime_error("truncated");
    std::memcpy(p, in_.data() + at_, n);
    at_ += n;
  }
  const std::string& in_;
  size_t at_ = 0;
};

/// A result and its run time (s) as bytes.
std::string encode_result(const ContactResult& r, double runtime_s);
std::string encode_result(const DynamicsResult& r, double runtime_s);
std::string encode_result(const MassResult& r, double runtime_s);
std::string encode_result(const DistanceResult& r, double runtime_s);
std::string encode_result(const ToiResult& r, double runtime_s);
/// The result and run time encode_result wrote; false (outputs unspecified) when `bytes` is not
/// exactly one such encoding.
bool decode_result(const std::string& bytes, ContactResult& r, double& runtime_s);
bool decode_result(const std::string& bytes, DynamicsResult& r, double& runtime_s);
bool decode_result(const std::string& bytes, MassResult& r, double& runtime_s);
bool decode_result(const std::string& bytes, DistanceResult& r, double& runtime_s);
bool decode_result(const std::string& bytes, ToiResult& r, double& runtime_s);

}  // namespace rbx

#include "reference/isolate.h"

#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <string>

namespace rbx {

namespace {

// Wire format child -> parent: status, message, then per contact 7 doubles and a feature string.
void put(std::string& out, const void* p, size_t n) { out.append(static_cast<const char*>(p), n); }
void put_string(std::string& out, const std::string& s) {
  const uint64_t n = s.size();
  put(out, &n, sizeof n);
  out += s;
}

struct Reader {
  const std::string& in;
  size_t pos = 0;
  bool get(void* p, size_t n) {
    if (pos + n > in.size()) return false;
    std::memcpy(p, in.data() + pos, n);
    pos += n;
    return true;
  }
  bool get_string(std::string& s) {
    uint64_t n = 0;
    if (!get(&n, sizeof n) || pos + n > in.size()) return false;
    s.assign(in, pos, n);
    pos += n;
    return true;
  }
};

std::string encode(const ContactResult& r) {
  std::string out;
  const int32_t status = static_cast<int32_t>(r.status);
  put(out, &status, sizeof status);
  put_string(out, r.message);
  const uint64_t n = r.contacts.size();
  put(out, &n, sizeof n);
  for (const ContactPoint& c : r.contacts) {
    const double d[7] = {c.point.x(),  c.point.y(),  c.point.z(), c.normal.x(),
                         c.normal.y(), c.normal.z(), c.depth};
    put(out, d, sizeof d);
    put_string(out, c.feature);
  }
  return out;
}

bool decode(const std::string& in, ContactResult& r) {
  Reader rd{in};
  int32_t status = 0;
  uint64_t n = 0;
  if (!rd.get(&status, sizeof status) || !rd.get_string(r.message) || !rd.get(&n, sizeof n))
    return false;
  r.status = static_cast<Status>(status);
  for (uint64_t i = 0; i < n; ++i) {
    double d[7];
    ContactPoint c;
    if (!rd.get(d, sizeof d) || !rd.get_string(c.feature)) return false;
    c.point = Vec3(d[0], d[1], d[2]);
    c.normal = Vec3(d[3], d[4], d[5]);
    c.depth = d[6];
    r.contacts.push_back(c);
  }
  return true;
}

}  // namespace

ContactResult run_isolated(const std::function<ContactResult()>& query, double timeout_s) {
  int fds[2];
  if (pipe(fds) != 0) return {Status::Error, std::string("pipe failed: ") + strerror(errno), {}};
  const pid_t pid = fork();
  if (pid < 0) {
    close(fds[0]);
    close(fds[1]);
    return {Status::Error, std::string("fork failed: ") + strerror(errno), {}};
  }
  if (pid == 0) {
    // Child: run the query, send the result, leave without running the parent's atexit hooks.
    close(fds[0]);
    ContactResult r;
    try {
      r = query();
    } catch (const std::exception& e) {
      r = {Status::Error, e.what(), {}};
    } catch (...) {  // anything else must not escape: the child would run on as a second rbx
      r = {Status::Error, "library call threw a non-standard exception", {}};
    }
    const std::string bytes = encode(r);
    size_t off = 0;
    while (off < bytes.size()) {
      const ssize_t w = write(fds[1], bytes.data() + off, bytes.size() - off);
      if (w <= 0) break;
      off += static_cast<size_t>(w);
    }
    close(fds[1]);
    _exit(0);
  }
  // Parent: read until EOF or the deadline.
  close(fds[1]);
  std::string bytes;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  bool timed_out = false;
  char buf[4096];
  for (;;) {
    // Rounded up: truncating would time out up to 1 ms before the deadline.
    const auto left =
        std::chrono::ceil<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      timed_out = true;
      break;
    }
    pollfd p{fds[0], POLLIN, 0};
    const int ready = poll(&p, 1, static_cast<int>(left.count()));
    if (ready == 0) continue;
    if (ready < 0 && errno == EINTR) continue;
    const ssize_t n = read(fds[0], buf, sizeof buf);
    if (n <= 0) break;
    bytes.append(buf, static_cast<size_t>(n));
  }
  close(fds[0]);
  if (timed_out) kill(pid, SIGKILL);
  int wstatus = 0;
  waitpid(pid, &wstatus, 0);
  if (timed_out) return {Status::Error, "library call timed out (isolated process killed)", {}};
  if (WIFSIGNALED(wstatus))
    return {Status::Error,
            std::string("library call died with signal ") + strsignal(WTERMSIG(wstatus)) +
                " (isolated process; e.g. a failed assertion)",
            {}};
  ContactResult r;
  if (!decode(bytes, r)) return {Status::Error, "isolated library call returned no result", {}};
  return r;
}

}  // namespace rbx

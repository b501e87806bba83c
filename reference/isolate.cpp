#include "reference/isolate.h"

#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <iostream>
#include <map>
#include <new>
#include <stdexcept>
#include <string>
#include <utility>

#include "engine/format.h"
#include "reference/result_codec.h"

namespace rbx {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t) {
  return std::chrono::duration<double>(Clock::now() - t).count();
}

// -- bytes: a record as reference/result_codec.h encodes it (a mass call has no run time) ---

std::string encode(const TimedContact& t) { return encode_result(t.result, t.runtime_s); }
bool decode(const std::string& bytes, TimedContact& t) {
  return decode_result(bytes, t.result, t.runtime_s);
}
std::string encode(const TimedDynamics& t) { return encode_result(t.result, t.runtime_s); }
bool decode(const std::string& bytes, TimedDynamics& t) {
  return decode_result(bytes, t.result, t.runtime_s);
}
std::string encode(const TimedDistance& t) { return encode_result(t.result, t.runtime_s); }
bool decode(const std::string& bytes, TimedDistance& t) {
  return decode_result(bytes, t.result, t.runtime_s);
}
std::string encode(const TimedToi& t) { return encode_result(t.result, t.runtime_s); }
bool decode(const std::string& bytes, TimedToi& t) {
  return decode_result(bytes, t.result, t.runtime_s);
}
std::string encode(const MassResult& m) { return encode_result(m, 0.0); }
bool decode(const std::string& bytes, MassResult& m) {
  double no_runtime;
  return decode_result(bytes, m, no_runtime);
}

// -- frames, child -> parent, and the call state the child shares with its parent -------------
// Frames: 'R' item bytes: an item's result.  'X' message: an item threw.  'C' bytes: the answer
// of a lone isolated call. A call's beginning and end are not frames but writes to a page
// shared with the parent (CallState): no system call per library call, so a block of 20,000
// queries costs what it costs in process.

void write_all(int fd, const std::string& s) {
  size_t off = 0;
  while (off < s.size()) {
    const ssize_t w = write(fd, s.data() + off, s.size() - off);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) _exit(3);  // the parent is gone: nobody to answer
    off += static_cast<size_t>(w);
  }
}

void send(int fd, char type, const std::string& payload) {
  ByteWriter w;
  w.put(static_cast<long>(type));
  w.put(payload);
  write_all(fd, w.str());
}

// The call a child is in, written by the child, read by its parent (a sequence lock: `seq` is
// odd while a call runs, and the parent trusts the other fields only if `seq` read the same
// before and after them).
struct CallState {
  std::atomic<uint64_t> seq{0};
  std::atomic<int64_t> start_ns{0};  // steady clock (shared by both processes)
  std::atomic<double> deadline_s{0.0};
  char backend[96] = {};
};

int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch())
      .count();
}

// The context of a supervised child process (set in the child only, right after the fork).
using FailureTable = std::map<std::pair<size_t, std::string>, CallOutcome>;
struct ChildContext {
  int fd = -1;                             // frames to the parent
  CallState* state = nullptr;              // shared with the parent
  pthread_t thread{};                      // the child's first thread: the one supervised
  size_t item = 0;                         // the item being run
  const FailureTable* failures = nullptr;  // calls already known to fail, answered at once
};
ChildContext* g_child = nullptr;

// Marks the start and the end of one supervised call.
void begin_call(CallState& st, const std::string& backend, double deadline_s) {
  const size_t n = std::min(backend.size(), sizeof st.backend - 1);
  std::memcpy(st.backend, backend.data(), n);
  st.backend[n] = '\0';
  st.deadline_s.store(deadline_s, std::memory_order_relaxed);
  st.start_ns.store(now_ns(), std::memory_order_relaxed);
  st.seq.fetch_add(1, std::memory_order_release);
}
void end_call(CallState& st) { st.seq.fetch_add(1, std::memory_order_release); }

// What a child process was, once it is over.
struct ChildEnd {
  bool timed_out = false;        // a call overran its deadline; the child was killed
  int wait_status = 0;           // from waitpid
  bool in_call = false;          // a call had begun and not ended
  std::string backend;           // that call's backend
  double call_deadline_s = 0.0;  // and its deadline
  double call_elapsed_s = 0.0;   // how long it had run
  std::string call_stderr;       // what the child wrote on stderr during that call
  std::string threw;             // an item's exception message ('X')
  bool has_answer = false;       // a lone call's answer ('C') arrived
  std::string answer;
};

// The signal or exit status of a child, in words.
std::string describe(int wait_status) {
  if (WIFSIGNALED(wait_status))
    return std::string("died with signal ") + strsignal(WTERMSIG(wait_status));
  if (WIFEXITED(wait_status))
    return "exited with status " + std::to_string(WEXITSTATUS(wait_status));
  return "ended";
}

// The last non-empty line of a text, shortened to a readable length.
std::string last_line(const std::string& text) {
  const size_t end = text.find_last_not_of("\r\n \t");
  if (end == std::string::npos) return "";
  const size_t nl = text.rfind('\n', end);
  const size_t start = nl == std::string::npos ? 0 : nl + 1;
  std::string line = text.substr(start, end + 1 - start);
  if (line.size() > 300) line = line.substr(0, 297) + "...";
  return line;
}

// A snapshot of the shared call state, consistent or not taken.
struct CallSnapshot {
  bool in_call = false;
  uint64_t seq = 0;
  double elapsed_s = 0.0, deadline_s = 0.0;
  std::string backend;
};
CallSnapshot snapshot(const CallState& st) {
  CallSnapshot s;
  for (int tries = 0; tries < 100; ++tries) {
    const uint64_t before = st.seq.load(std::memory_order_acquire);
    s.elapsed_s = 1e-9 * static_cast<double>(now_ns() - st.start_ns.load());
    s.deadline_s = st.deadline_s.load();
    s.backend.assign(st.backend, strnlen(st.backend, sizeof st.backend));
    if (st.seq.load(std::memory_order_acquire) != before) continue;
    s.seq = before;
    s.in_call = before % 2 == 1;
    return s;
  }
  return s;
}

// A forked child, as its parent holds it.
struct Child {
  pid_t pid = -1;
  void* page = nullptr;        // the shared page holding `state`
  CallState* state = nullptr;  // the call the child is in
  int frames = -1;             // read end of the frames pipe
  int errs = -1;               // read end of the child's stderr
};

// Maps the shared call state, opens the two pipes and forks a child that runs
// `body(frame_fd, state)` with its stderr into the pipe; returns the parent's side.
template <class Body>
Child fork_child(const Body& body) {
  Child child;
  child.page =
      mmap(nullptr, sizeof(CallState), PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0);
  if (child.page == MAP_FAILED) throw std::runtime_error(std::string("mmap: ") + strerror(errno));
  child.state = new (child.page) CallState();
  int frames[2], errs[2];
  if (pipe(frames) != 0 || pipe(errs) != 0)
    throw std::runtime_error(std::string("pipe: ") + strerror(errno));
  // Buffered output written before the fork would otherwise be written twice.
  std::fflush(nullptr);
  std::cout.flush();
  std::cerr.flush();
  child.pid = fork();
  if (child.pid < 0) throw std::runtime_error(std::string("fork: ") + strerror(errno));
  if (child.pid == 0) {
    close(frames[0]);
    close(errs[0]);
    dup2(errs[1], STDERR_FILENO);
    close(errs[1]);
    body(frames[1], *child.state);
    std::fflush(nullptr);
    _exit(0);  // not exit(): the parent's atexit hooks and static destructors are not ours
  }
  close(frames[1]);
  close(errs[1]);
  child.frames = frames[0];
  child.errs = errs[0];
  return child;
}

// The child's stderr as the parent passes it on: what arrives while a call runs is held until
// that call ends (it names a failure); the rest is written at once.
struct StderrRelay {
  std::string held;  // stderr of the call in progress
  uint64_t held_seq = 0;

  void write_held() {
    if (held.empty()) return;
    std::cerr.write(held.data(), static_cast<std::streamsize>(held.size())).flush();
    held.clear();
  }
  // Writes what was held once its call is over.
  void release_if_over(const CallSnapshot& now) {
    if (!now.in_call || now.seq != held_seq) write_held();
  }
  // Passes on, or holds, `n` bytes the child just wrote.
  void take(const char* buf, ssize_t n, const CallSnapshot& now) {
    if (!now.in_call) {
      std::cerr.write(buf, n).flush();
      return;
    }
    if (now.seq != held_seq) write_held();
    held.append(buf, static_cast<size_t>(n));
    held_seq = now.seq;
  }
};

// Every complete frame in `inbox` (a type, then a length-prefixed payload), consumed: 'X' an
// item's exception and 'C' a lone call's answer go to `end`, the others to `on_frame`.
template <class OnFrame>
void read_frames(std::string& inbox, ChildEnd& end, const OnFrame& on_frame) {
  for (;;) {
    long type = 0;
    std::string payload;
    try {
      ByteReader r(inbox);
      r.get(type);
      r.get(payload);
      inbox.erase(0, r.position());
    } catch (const std::runtime_error&) {
      break;  // the frame is not complete yet
    }
    if (type == 'X') {
      end.threw = payload;
    } else if (type == 'C') {
      end.has_answer = true;
      end.answer = payload;
    } else {
      on_frame(static_cast<char>(type), payload);
    }
  }
}

// Ends the child (killed when it timed out), closes the pipes, reaps it unless `exited`, and
// records the call it was in: a call begun and never ended is the one that failed.
void finish_child(const Child& child, pollfd (&fds)[2], bool exited, StderrRelay& relay,
                  ChildEnd& end) {
  if (end.timed_out) kill(child.pid, SIGKILL);
  for (pollfd& p : fds)
    if (p.fd >= 0) close(p.fd);
  while (!exited && waitpid(child.pid, &end.wait_status, 0) < 0 && errno == EINTR) {
  }
  const CallSnapshot last = snapshot(*child.state);
  end.in_call = last.in_call;
  end.backend = last.backend;
  end.call_deadline_s = last.deadline_s;
  end.call_elapsed_s = last.elapsed_s;
  if (last.in_call)
    end.call_stderr = relay.held;
  else
    relay.write_held();
  child.state->~CallState();
  munmap(child.page, sizeof(CallState));
}

// Forks a child that runs `body(frame_fd, state)` with its stderr captured, then supervises
// it: frames go to `on_frame`; the shared call state is read at every frame and every 50 ms,
// and a call past its deadline gets the child killed. The child's stderr is passed on, except
// what arrives while a call runs, held until the call ends (it names a failure).
template <class Body, class OnFrame>
ChildEnd supervise(const Body& body, const OnFrame& on_frame) {
  ChildEnd end;
  const Child child = fork_child(body);
  std::string inbox;  // frame bytes not yet parsed
  StderrRelay relay;
  pollfd fds[2] = {{child.frames, POLLIN, 0}, {child.errs, POLLIN, 0}};
  int open_fds = 2;
  char buf[65536];
  bool exited = false;
  while (open_fds > 0) {
    // The deadline of the call in progress, if any.
    const CallSnapshot last = snapshot(*child.state);
    if (!exited && last.in_call && last.elapsed_s > last.deadline_s) {
      end.timed_out = true;
      break;
    }
    relay.release_if_over(last);
    // Another thread's child, forked meanwhile, may hold copies of these pipes: the end of
    // this child is seen by waitpid, not by the pipes' end of file.
    const int ready = poll(fds, 2, exited ? 0 : 50);
    if (ready <= 0) {
      if (exited) break;
      if (waitpid(child.pid, &end.wait_status, WNOHANG) == child.pid) exited = true;
      continue;
    }
    for (int k = 0; k < 2; ++k) {
      if (fds[k].fd < 0 || !(fds[k].revents & (POLLIN | POLLHUP | POLLERR))) continue;
      const ssize_t n = read(fds[k].fd, buf, sizeof buf);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        close(fds[k].fd);
        fds[k].fd = -1;
        --open_fds;
        continue;
      }
      if (k == 1) {
        relay.take(buf, n, snapshot(*child.state));
        continue;
      }
      inbox.append(buf, static_cast<size_t>(n));
      read_frames(inbox, end, on_frame);
    }
  }
  finish_child(child, fds, exited, relay, end);
  return end;
}

// The failed outcome of the call a child was in when it ended.
CallOutcome failure_of(const ChildEnd& end) {
  CallOutcome out;
  out.elapsed_s = end.call_elapsed_s;
  if (end.timed_out) {
    out.status = Status::Timeout;
    out.message = "no answer within the deadline of " + fmt_num(end.call_deadline_s, 3) +
                  " s (timed out; the library call was abandoned and the run went on)";
    return out;
  }
  out.status = Status::Error;
  out.message = WIFEXITED(end.wait_status)
                    ? "the library call ended the process (" + describe(end.wait_status) +
                          ") without an answer (no result)"
                    : "the library call " + describe(end.wait_status) +
                          " (isolated process; e.g. a failed assertion)";
  const std::string said = last_line(end.call_stderr);
  if (!said.empty()) out.message += ": " + said;
  return out;
}

}  // namespace

bool in_isolated_child() { return g_child != nullptr; }

CallOutcome isolated(const std::string& backend, double deadline_s,
                     const std::function<std::string()>& call) {
  // In a supervised child, on its supervised thread: run here, unless known to fail.
  if (g_child && pthread_equal(pthread_self(), g_child->thread)) {
    auto known = g_child->failures->find({g_child->item, backend});
    if (known != g_child->failures->end()) return known->second;
    begin_call(*g_child->state, backend, deadline_s);
    const Clock::time_point start = Clock::now();
    CallOutcome out{Status::Ok, "", call(), 0.0};
    out.elapsed_s = seconds_since(start);
    end_call(*g_child->state);
    return out;
  }
  // Otherwise one child for this call.
  const Clock::time_point start = Clock::now();
  const ChildEnd end = supervise(
      [&](int fd, CallState& state) {
        begin_call(state, backend, deadline_s);
        const std::string answer = call();
        end_call(state);
        send(fd, 'C', answer);
      },
      [](char, const std::string&) {});
  if (end.has_answer) return {Status::Ok, "", end.answer, seconds_since(start)};
  return failure_of(end);
}

std::vector<std::string> run_items_isolated(size_t lo, size_t hi,
                                            const std::function<std::string(size_t)>& item,
                                            const std::function<void(size_t)>& done) {
  std::vector<std::string> results(hi - lo);
  FailureTable failures;
  size_t next = lo;
  while (next < hi) {
    const ChildEnd end = supervise(
        [&](int fd, CallState& state) {
          ChildContext ctx{fd, &state, pthread_self(), next, &failures};
          g_child = &ctx;
          for (size_t i = next; i < hi; ++i) {
            ctx.item = i;
            std::string bytes;
            try {
              bytes = item(i);
            } catch (const std::exception& e) {
              send(fd, 'X', e.what());
              return;
            } catch (...) {
              send(fd, 'X', "a non-standard exception");
              return;
            }
            ByteWriter w;
            w.put(static_cast<long>(i));
            send(fd, 'R', w.str() + bytes);
          }
        },
        [&](char type, const std::string& payload) {
          if (type != 'R') return;
          long i = -1;
          try {
            ByteReader r(payload);
            r.get(i);
          } catch (const std::runtime_error&) {
          }
          if (i < 0 || static_cast<size_t>(i) != next)
            throw std::runtime_error("isolated items: result out of order");
          results[static_cast<size_t>(i) - lo] = payload.substr(sizeof(std::int64_t));
          ++next;
          if (done) done(i);
        });
    if (!end.threw.empty()) throw std::runtime_error(end.threw);
    if (next >= hi) break;
    if (!end.in_call && !end.timed_out)
      throw std::runtime_error(
          "item " + std::to_string(next) + " " + describe(end.wait_status) +
          " outside any library call (a fault of rbx itself)" +
          (last_line(end.call_stderr).empty() ? std::string() : ": " + last_line(end.call_stderr)));
    // The failed call is answered at once from now on; the item starts again in a new child.
    if (!failures.emplace(std::make_pair(next, end.backend), failure_of(end)).second)
      throw std::runtime_error("isolated items: a recorded failure of " + end.backend +
                               " came back on item " + std::to_string(next));
  }
  return results;
}

namespace {

// Status and message of each kind of call's record, and where its wall time goes (a mass call
// has none).
template <class Record>
struct RecordAccess;
template <>
struct RecordAccess<TimedContact> {
  static Status& status(TimedContact& t) { return t.result.status; }
  static std::string& message(TimedContact& t) { return t.result.message; }
  static void set_runtime(TimedContact& t, double s) { t.runtime_s = s; }
};
template <>
struct RecordAccess<TimedDynamics> {
  static Status& status(TimedDynamics& t) { return t.result.status; }
  static std::string& message(TimedDynamics& t) { return t.result.message; }
  static void set_runtime(TimedDynamics& t, double s) { t.runtime_s = s; }
};
template <>
struct RecordAccess<TimedDistance> {
  static Status& status(TimedDistance& t) { return t.result.status; }
  static std::string& message(TimedDistance& t) { return t.result.message; }
  static void set_runtime(TimedDistance& t, double s) { t.runtime_s = s; }
};
template <>
struct RecordAccess<TimedToi> {
  static Status& status(TimedToi& t) { return t.result.status; }
  static std::string& message(TimedToi& t) { return t.result.message; }
  static void set_runtime(TimedToi& t, double s) { t.runtime_s = s; }
};
template <>
struct RecordAccess<MassResult> {
  static Status& status(MassResult& m) { return m.status; }
  static std::string& message(MassResult& m) { return m.message; }
  static void set_runtime(MassResult&, double) {}
};

// One library call in a supervised child: a thrown exception is the record's status error, a
// child that died, stalled or answered nothing is the record of its status and message.
template <class Record>
Record isolated_call(const std::string& backend, double deadline_s,
                     const std::function<Record()>& call) {
  using Access = RecordAccess<Record>;
  const CallOutcome out = isolated(backend, deadline_s, [&] {
    Record r;
    try {
      r = call();
    } catch (const std::exception& e) {
      r = Record{};
      Access::status(r) = Status::Error;
      Access::message(r) = e.what();
    } catch (...) {
      r = Record{};
      Access::status(r) = Status::Error;
      Access::message(r) = "library call threw a non-standard exception";
    }
    return encode(r);
  });
  Record r;
  if (out.status == Status::Ok && decode(out.bytes, r)) return r;
  r = Record{};
  Access::status(r) = out.status == Status::Ok ? Status::Error : out.status;
  Access::message(r) =
      out.status == Status::Ok ? backend + ": isolated call returned no result" : out.message;
  Access::set_runtime(r, out.elapsed_s);
  return r;
}

}  // namespace

TimedContact isolated_contact(const std::string& backend, double deadline_s,
                              const std::function<TimedContact()>& call) {
  return isolated_call(backend, deadline_s, call);
}

TimedDynamics isolated_dynamics(const std::string& backend, double deadline_s,
                                const std::function<TimedDynamics()>& call) {
  return isolated_call(backend, deadline_s, call);
}

TimedDistance isolated_distance(const std::string& backend, double deadline_s,
                                const std::function<TimedDistance()>& call) {
  return isolated_call(backend, deadline_s, call);
}

TimedToi isolated_toi(const std::string& backend, double deadline_s,
                      const std::function<TimedToi()>& call) {
  return isolated_call(backend, deadline_s, call);
}

MassResult isolated_mass(const std::string& backend, double deadline_s,
                         const std::function<MassResult()>& call) {
  return isolated_call(backend, deadline_s, call);
}

ContactResult run_isolated(const std::function<ContactResult()>& query, double timeout_s) {
  // Always a child of its own, even inside a supervised child: the caller isolates this one
  // call because it is known to abort, and its caller's own call must go on.
  ChildContext* const outer = g_child;
  g_child = nullptr;
  const TimedContact t = isolated_contact("library", timeout_s, [&] {
    return TimedContact{query(), 0.0};
  });
  g_child = outer;
  return t.result;
}

}  // namespace rbx

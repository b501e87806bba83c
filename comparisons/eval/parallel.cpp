#include "comparisons/eval/parallel.h"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <stdexcept>
#include <thread>

#include "reference/isolate.h"

#ifdef RBX_WITH_MPI
#include <mpi.h>
#endif

namespace rbx {

namespace {

#ifdef RBX_WITH_MPI
// True when a launcher (Open MPI's mpirun, or a PMI-based one) started this process.
bool launched_by_mpirun() {
  return std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMI_RANK") || std::getenv("PMIX_RANK");
}

#endif

// Items [lo, hi) of block `part` when n items are cut into `parts` contiguous blocks.
std::pair<size_t, size_t> block(size_t n, size_t parts, size_t part) {
  return {n * part / parts, n * (part + 1) / parts};
}

#ifdef RBX_WITH_MPI
// Length-prefixed concatenation of strings, and its inverse.
std::string pack(const std::vector<std::string>& items) {
  std::string out;
  for (const std::string& s : items) {
    const uint64_t len = s.size();
    out.append(reinterpret_cast<const char*>(&len), sizeof len);
    out += s;
  }
  return out;
}

void unpack(const std::string& bytes, std::vector<std::string>& out) {
  size_t at = 0;
  while (at + sizeof(uint64_t) <= bytes.size()) {
    uint64_t len = 0;
    std::memcpy(&len, bytes.data() + at, sizeof len);
    at += sizeof len;
    out.push_back(bytes.substr(at, len));
    at += len;
  }
}
#endif

}  // namespace

bool built_with_mpi() {
#ifdef RBX_WITH_MPI
  return true;
#else
  return false;
#endif
}

ParallelRun::ParallelRun(int threads) {
#ifdef RBX_WITH_MPI
  if (launched_by_mpirun()) {
    int ready = 0;
    MPI_Initialized(&ready);
    if (!ready) MPI_Init(nullptr, nullptr);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
    MPI_Comm_size(MPI_COMM_WORLD, &ranks_);
    mpi_ = true;
  }
#endif
  const int cores = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  // Ranks usually share a node: each takes its share of the cores (at least one thread).
  threads_ = threads > 0 ? threads : std::max(1, cores / ranks_);
}

ParallelRun::~ParallelRun() {
#ifdef RBX_WITH_MPI
  if (mpi_) {
    int done = 0;
    MPI_Finalized(&done);
    if (!done) MPI_Finalize();
  }
#endif
}

namespace {

// Under AddressSanitizer a fork while another thread holds the sanitizer's allocator lock leaves
// the child waiting on that lock for ever (seen in the sanitizer build: explore runs of a few
// seconds hanging until the test's deadline, now and then). There every block runs on this
// thread, one supervised child at a time; the answers are the same by design (the outputs are
// identical for any number of threads), so only the speed differs.
#if defined(RBX_SANITIZE)
constexpr bool kForkFromOneThread = true;
#else
constexpr bool kForkFromOneThread = false;
#endif

}  // namespace

int forking_threads(int wanted) {
  if (kForkFromOneThread) return 1;
  return wanted > 0 ? wanted : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

void run_jobs(size_t jobs, int threads, const std::function<void(size_t)>& job) {
  std::vector<std::exception_ptr> errors(jobs);
  std::atomic<size_t> next{0};
  auto work = [&] {
    for (size_t j = next++; j < jobs; j = next++) {
      try {
        job(j);
      } catch (...) {
        errors[j] = std::current_exception();
      }
    }
  };
  const size_t count = std::min(jobs, static_cast<size_t>(forking_threads(threads)));
  std::vector<std::thread> pool;
  for (size_t t = 1; t < count; ++t) pool.emplace_back(work);
  work();
  for (std::thread& th : pool) th.join();
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
}

std::vector<std::string> ParallelRun::map(size_t n, const std::function<std::string(size_t)>& item,
                                          const std::function<void(size_t)>& done) const {
  // This rank's block, cut into chunks that the threads take as they come free: the items' costs
  // differ by orders of magnitude (a scene of one contact query, a scene of a thousand bodies),
  // so fixed shares left one core idle for most of a run. One supervised child per chunk.
  // Plain variables, not a structured binding: the lambda below captures lo, which C++17 does
  // not allow of a binding (clang refuses it).
  const std::pair<size_t, size_t> range = block(n, ranks_, rank_);
  const size_t lo = range.first;
  const size_t count = range.second - lo;
  std::vector<std::string> local(count);
  const size_t nthreads =
      kForkFromOneThread ? 1 : std::max<size_t>(1, std::min<size_t>(threads_, count));
  constexpr size_t kChunksPerThread = 16;
  const size_t chunk = std::max<size_t>(1, count / (nthreads * kChunksPerThread));
  // Chunks are in index order, so the failure rethrown is the first in index order.
  run_jobs((count + chunk - 1) / chunk, static_cast<int>(nthreads), [&](size_t c) {
    const size_t a = c * chunk, b = std::min(count, a + chunk);
    std::vector<std::string> mine = run_items_isolated(lo + a, lo + b, item, done);
    for (size_t i = a; i < b; ++i) local[i] = std::move(mine[i - a]);
  });
  if (!mpi_ || ranks_ == 1) return local;

#ifdef RBX_WITH_MPI
  // Gather every rank's packed block on rank 0, in rank order (= index order).
  const std::string mine = pack(local);
  long long my_size = static_cast<long long>(mine.size());
  std::vector<long long> sizes(ranks_);
  MPI_Gather(&my_size, 1, MPI_LONG_LONG, sizes.data(), 1, MPI_LONG_LONG, 0, MPI_COMM_WORLD);
  std::vector<int> counts(ranks_), displs(ranks_);
  std::string all;
  if (rank_ == 0) {
    long long total = 0;
    for (int r = 0; r < ranks_; ++r) {
      if (sizes[r] > INT32_MAX || total > INT32_MAX)
        throw std::runtime_error("parallel map: results too large for one MPI message");
      counts[r] = static_cast<int>(sizes[r]);
      displs[r] = static_cast<int>(total);
      total += sizes[r];
    }
    all.resize(total);
  }
  MPI_Gatherv(mine.data(), static_cast<int>(mine.size()), MPI_BYTE, all.data(), counts.data(),
              displs.data(), MPI_BYTE, 0, MPI_COMM_WORLD);
  std::vector<std::string> out;
  if (rank_ == 0) {
    out.reserve(n);
    unpack(all, out);
  }
  return out;
#else
  return local;
#endif
}

std::string ParallelRun::broadcast(const std::string& text) const {
  if (!mpi_ || ranks_ == 1) return text;
#ifdef RBX_WITH_MPI
  long long size = static_cast<long long>(text.size());
  MPI_Bcast(&size, 1, MPI_LONG_LONG, 0, MPI_COMM_WORLD);
  std::string out = rank_ == 0 ? text : std::string(size, '\0');
  MPI_Bcast(out.data(), static_cast<int>(size), MPI_BYTE, 0, MPI_COMM_WORLD);
  return out;
#else
  return text;
#endif
}

}  // namespace rbx

// Spreading independent work items over MPI ranks and, inside each rank, over threads.
//
// Design note: every item is a pure function of its index, its result a byte string. Items are
// split into contiguous blocks (ranks first, then threads) and the results are concatenated in
// index order on rank 0, so the outcome is the same for any number of ranks and threads. MPI is
// optional at build time (RBX_WITH_MPI) and used at run time only when the process was started
// by mpirun (Open MPI's OMPI_COMM_WORLD_SIZE or a PMI rank in the environment); otherwise the
// process is rank 0 of 1 and uses every core.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace rbx {

/// The ranks and threads one command runs on. Construct once per command; MPI is initialised
/// in the constructor (when launched by mpirun) and finalised in the destructor.
class ParallelRun {
 public:
  /// `threads` <= 0: every core (hardware concurrency), divided among the ranks of this node.
  explicit ParallelRun(int threads = 0);
  ~ParallelRun();
  ParallelRun(const ParallelRun&) = delete;
  ParallelRun& operator=(const ParallelRun&) = delete;

  /// This process's rank (0 without MPI).
  int rank() const { return rank_; }
  /// Number of ranks (1 without MPI).
  int ranks() const { return ranks_; }
  /// Threads per rank.
  int threads() const { return threads_; }
  /// True on rank 0, which writes every output.
  bool root() const { return rank_ == 0; }
  /// True when MPI is in use.
  bool mpi() const { return mpi_; }

  /// Runs item(i) for i in [0, n) over all ranks and threads; every rank must call it. Returns
  /// the n results in index order on rank 0, an empty vector on the other ranks. An exception
  /// thrown by an item is rethrown on the rank that ran it (the first in index order per rank).
  /// Items run in chunks of consecutive indices, each in a supervised child process
  /// (reference/isolate.h) on whichever thread is free, so a library that aborts or loops fails
  /// that backend in that item only; an item must therefore return everything it computes (what
  /// it writes to this process's memory is lost). `done(i)` is called in this process, on the
  /// thread that ran the item, as item i finishes.
  std::vector<std::string> map(size_t n, const std::function<std::string(size_t)>& item,
                               const std::function<void(size_t)>& done = {}) const;

  /// Rank 0's `text` on every rank (every rank must call it).
  std::string broadcast(const std::string& text) const;

 private:
  int rank_ = 0;
  int ranks_ = 1;
  int threads_ = 1;
  bool mpi_ = false;
};

/// How many threads may fork supervised children at once: `wanted` (0: every core), or 1 in a
/// build with AddressSanitizer (parallel.cpp says why).
int forking_threads(int wanted);

/// Runs job(j) for j in [0, jobs) on forking_threads(threads) threads, each taking the next job
/// as it comes free; then rethrows the exception of the first job (in job order) that threw.
void run_jobs(size_t jobs, int threads, const std::function<void(size_t)>& job);

/// True when this build can use MPI (configured with RBX_WITH_MPI).
bool built_with_mpi();

}  // namespace rbx

#pragma once
// A sweep spread over the ranks of an MPI job (`mpirun -np N balance-design run sweep.yaml`):
// rank 0 writes sweep.csv and sweep.json as a run without MPI does (studies::write_sweep()) and
// hands out points on request; every other rank computes the points it is given on its own
// threads and sends their rows back. A study without a sweep whose optimisation is a multistart
// (mlsl) shares its local runs the same way (start_pool()). Built only with MPI (BD_HAVE_MPI);
// without it (cli/mpi_none.cpp), mpi_world() reports one process and the program runs as it
// always has.
#include <cstdlib>
#include <memory>

#include "optimize/optimize.hpp"
#include "studies/studies.hpp"

namespace bd::cli {

/// This process's place in an MPI job.
class MpiWorld {
 public:
  MpiWorld(const MpiWorld&) = delete;
  MpiWorld& operator=(const MpiWorld&) = delete;
  ~MpiWorld();  // MPI_Finalize

  int rank() const { return rank_; }
  int size() const { return size_; }
  /// Ranks of this job on this machine (for the default threads per rank).
  int local_size() const { return local_size_; }
  /// Threads per rank when neither --threads nor sweep.threads says: the machine's cores shared
  /// by the ranks on it.
  int default_threads() const;

  /// The workers of ranks 1..N-1 as rank 0's write_sweep() sees them. Collective: every other
  /// rank is in work() at the same time. `threads` is rank 0's own.
  /// @throws bd::InputError if a rank read another study file (a different fingerprint).
  std::unique_ptr<studies::SweepPeers> peers(const studies::Study& study, int threads);
  /// Ranks 1..N-1: compute the points rank 0 hands out, `threads` at a time, until it has no
  /// more. Returns when rank 0 says the sweep is over.
  void work(const studies::Study& study, int threads);

  /// The ranks as one pool for a multistart's local runs (mlsl), in a study without a sweep:
  /// every rank runs the same study, so each multistart is reached by all of them in the same
  /// order, and run_all() is collective. Rank 0 hands out the starts one at a time on request
  /// (dynamic load balancing), computing some itself on a second thread; every rank returns
  /// every run, the same bytes as a run in one process.
  std::unique_ptr<optimize::StartPool> start_pool();

 private:
  friend std::unique_ptr<MpiWorld> mpi_world(int& argc, char**& argv);
  MpiWorld() = default;
  int rank_ = 0, size_ = 1, local_size_ = 1;
};

/// The MPI job this process belongs to, initialised (MPI_Init_thread), when it was started by
/// mpirun (or srun) with more than one rank (in_mpi_job()); else null, and the program runs
/// alone.
/// @throws std::runtime_error in a job of several ranks when the program was built without MPI
///         (each rank would run the whole study into the same folder).
std::unique_ptr<MpiWorld> mpi_world(int& argc, char**& argv);

/// Whether this build can run sweeps across MPI ranks.
bool built_with_mpi();

/// The environment says this process was started by mpirun (or srun) as one of several ranks.
inline bool in_mpi_job() {
  for (const char* var : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"}) {
    if (const char* v = std::getenv(var); v && std::atoi(v) > 1) return true;
  }
  return false;
}

}  // namespace bd::cli

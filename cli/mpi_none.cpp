// The program built without MPI (find_package(MPI) found none): it always runs alone, and
// refuses to run as one of several ranks of an mpirun job.
#include <stdexcept>

#include "cli/mpi_sweep.hpp"

namespace bd::cli {

bool built_with_mpi() { return false; }

std::unique_ptr<MpiWorld> mpi_world(int&, char**&) {
  if (in_mpi_job()) {
    throw std::runtime_error(
        "this balance-design was built without MPI (libopenmpi-dev was not found when it was "
        "built), so it cannot share a sweep between mpirun's ranks: run it without mpirun, or "
        "install libopenmpi-dev and rebuild");
  }
  return nullptr;
}

MpiWorld::~MpiWorld() = default;
int MpiWorld::default_threads() const { return 1; }
std::unique_ptr<studies::SweepPeers> MpiWorld::peers(const studies::Study&, int) {
  return nullptr;
}
void MpiWorld::work(const studies::Study&, int) {}
std::unique_ptr<optimize::StartPool> MpiWorld::start_pool() { return nullptr; }

}  // namespace bd::cli

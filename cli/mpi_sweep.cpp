// A sweep over MPI ranks (cli/mpi_sweep.hpp). Rank 0 is the one writer: its write_sweep() polls
// the other ranks through MasterPeers, handing out chunks of points on request (dynamic load
// balancing: a rank that finishes early asks again) and taking their rows back; each other rank
// computes its chunks on its own threads. Only the main thread of a rank calls MPI
// (MPI_THREAD_FUNNELED).
//
// MPI is called by its PMPI_ names (the standard's profiling interface, the same functions):
// Ipopt's sequential MUMPS (libmumps_common_seq) exports stand-ins named MPI_Comm_rank,
// MPI_Init and MPI_Finalize that say rank 0 and do nothing, and the dynamic linker may bind the
// program's MPI_ calls to them.
#include <mpi.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "cli/mpi_sweep.hpp"
#include "core/input_error.hpp"

namespace bd::cli {

namespace st = bd::studies;

namespace {

// message tags: a worker's rows and request, rank 0's answer, a worker's farewell
constexpr int kTagRows = 1;
constexpr int kTagChunk = 2;
constexpr int kTagDone = 3;

// a worker's message: [want, rows] then per row [point, ok, length] and its text
void put_int(std::string& buf, std::int32_t v) {
  buf.append(reinterpret_cast<const char*>(&v), sizeof v);
}
std::int32_t get_int(const std::string& buf, std::size_t& at) {
  std::int32_t v = 0;
  std::memcpy(&v, buf.data() + at, sizeof v);
  at += sizeof v;
  return v;
}

// the study's identity as every rank read it (sweep.json's fingerprint of the study text)
std::uint64_t study_key(const st::Study& study) {
  return std::strtoull(st::sweep_fingerprint(study.sweep->study_text).c_str(), nullptr, 16);
}

// Rank 0's view of ranks 1..N-1.
class MasterPeers final : public st::SweepPeers {
 public:
  MasterPeers(int ranks, int threads, int total_threads)
      : ranks_(ranks), threads_(threads), total_threads_(total_threads) {}
  // a sweep that ended early (an error on rank 0) still lets every rank finish
  ~MasterPeers() override {
    NoMoreWork none;
    while (!poll(none)) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }

  int threads() const override { return threads_; }

  bool poll(st::SweepWork& work) override {
    for (;;) {
      int flag = 0;
      MPI_Status status;
      PMPI_Iprobe(MPI_ANY_SOURCE, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &status);
      if (!flag) break;
      if (status.MPI_TAG == kTagDone) {
        PMPI_Recv(nullptr, 0, MPI_BYTE, status.MPI_SOURCE, kTagDone, MPI_COMM_WORLD,
                 MPI_STATUS_IGNORE);
        ++done_;
        continue;
      }
      int bytes = 0;
      PMPI_Get_count(&status, MPI_BYTE, &bytes);
      buf_.resize(static_cast<std::size_t>(bytes));
      PMPI_Recv(buf_.data(), bytes, MPI_BYTE, status.MPI_SOURCE, kTagRows, MPI_COMM_WORLD,
               MPI_STATUS_IGNORE);
      std::size_t at = 0;
      const std::int32_t want = get_int(buf_, at);
      const std::int32_t rows = get_int(buf_, at);
      for (std::int32_t r = 0; r < rows; ++r) {
        const std::int32_t point = get_int(buf_, at);
        st::SweepRow row;
        row.ok = get_int(buf_, at) != 0;
        const auto length = static_cast<std::size_t>(get_int(buf_, at));
        row.text.assign(buf_, at, length);
        at += length;
        work.deliver(point, std::move(row));
      }
      if (want > 0) {
        // guided chunks: large while many points are left (few messages for cheap points),
        // down to one point per thread at the end (no rank left holding a long tail)
        const int per_thread =
            std::clamp(work.unclaimed() / (4 * std::max(total_threads_, 1)), 1, 32);
        const st::SweepClaim c = work.claim(want * per_thread);
        const std::int32_t answer[3] = {c.begin, c.end, c.later ? 1 : 0};
        PMPI_Send(answer, 3, MPI_INT32_T, status.MPI_SOURCE, kTagChunk, MPI_COMM_WORLD);
      }
    }
    return done_ == ranks_ - 1;
  }

 private:
  // the answer to every request once rank 0 has stopped
  class NoMoreWork final : public st::SweepWork {
   public:
    st::SweepClaim claim(int) override { return {}; }
    int unclaimed() const override { return 0; }
    void deliver(int, st::SweepRow) override {}
  };

  int ranks_, threads_, total_threads_;
  int done_ = 0;
  std::string buf_;
};

}  // namespace

bool built_with_mpi() { return true; }

std::unique_ptr<MpiWorld> mpi_world(int& argc, char**& argv) {
  if (!in_mpi_job()) return nullptr;
  int provided = 0;
  PMPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  std::unique_ptr<MpiWorld> world(new MpiWorld());
  PMPI_Comm_rank(MPI_COMM_WORLD, &world->rank_);
  PMPI_Comm_size(MPI_COMM_WORLD, &world->size_);
  MPI_Comm local;
  PMPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &local);
  PMPI_Comm_size(local, &world->local_size_);
  PMPI_Comm_free(&local);
  return world;
}

MpiWorld::~MpiWorld() { PMPI_Finalize(); }

int MpiWorld::default_threads() const {
  const int cores = static_cast<int>(std::thread::hardware_concurrency());
  return std::max(1, cores / std::max(local_size_, 1));
}

std::unique_ptr<st::SweepPeers> MpiWorld::peers(const st::Study& study, int threads) {
  // every rank's threads and study, then go (1) or stop (0)
  const std::int64_t mine[2] = {threads, static_cast<std::int64_t>(study_key(study))};
  std::vector<std::int64_t> all(2 * static_cast<std::size_t>(size_));
  PMPI_Gather(mine, 2, MPI_INT64_T, all.data(), 2, MPI_INT64_T, 0, MPI_COMM_WORLD);
  int others = 0, odd = 0;
  for (int r = 1; r < size_; ++r) {
    others += static_cast<int>(all[2 * static_cast<std::size_t>(r)]);
    if (all[2 * static_cast<std::size_t>(r) + 1] != mine[1] && odd == 0) odd = r;
  }
  int go = odd == 0 ? 1 : 0;
  PMPI_Bcast(&go, 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (!go) {
    throw InputError("MPI rank " + std::to_string(odd) +
                     " read another study file than rank 0 (the study's fingerprint differs): "
                     "every rank must see the same file");
  }
  return std::make_unique<MasterPeers>(size_, others, threads + others);
}

void MpiWorld::work(const st::Study& study, int threads) {
  const std::int64_t mine[2] = {threads, static_cast<std::int64_t>(study_key(study))};
  PMPI_Gather(mine, 2, MPI_INT64_T, nullptr, 0, MPI_INT64_T, 0, MPI_COMM_WORLD);
  int go = 0;
  PMPI_Bcast(&go, 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (!go) return;

  st::PointCursor points(*study.sweep);  // the chunks come in increasing order
  std::mutex mutex;
  std::condition_variable for_workers, for_main;
  std::deque<int> queue;                          // points given, not started
  std::vector<std::pair<int, st::SweepRow>> out;  // rows not sent yet
  int busy = 0;
  bool over = false;
  std::vector<std::jthread> pool;
  for (int t = 0; t < threads; ++t) {
    pool.emplace_back([&] {
      std::vector<double> values;
      std::unique_lock<std::mutex> lock(mutex);
      for (;;) {
        for_workers.wait(lock, [&] { return !queue.empty() || over; });
        if (queue.empty()) return;
        const int i = queue.front();
        queue.pop_front();
        const std::span<const double> v = points.at(i);
        values.assign(v.begin(), v.end());
        ++busy;
        lock.unlock();
        st::SweepRow row = st::sweep_row(study, i, values);
        lock.lock();
        out.emplace_back(i, std::move(row));
        --busy;
        for_main.notify_one();
      }
    });
  }

  // the main thread: send rows (every few milliseconds) and ask for points while the queue runs
  // short, until rank 0 has none left and every point taken is sent
  bool exhausted = false;
  auto ask_after = std::chrono::steady_clock::now();
  std::string buf;
  for (;;) {
    std::vector<std::pair<int, st::SweepRow>> rows;
    int want = 0;
    {
      std::unique_lock<std::mutex> lock(mutex);
      const auto hungry = [&] {
        return !exhausted && static_cast<int>(queue.size()) < threads &&
               std::chrono::steady_clock::now() >= ask_after;
      };
      for_main.wait_for(lock, std::chrono::milliseconds(5), [&] {
        return out.size() >= 256 || hungry() || (exhausted && queue.empty() && busy == 0);
      });
      rows.swap(out);
      if (hungry()) want = threads;
      if (rows.empty() && exhausted && queue.empty() && busy == 0) break;
    }
    if (rows.empty() && want == 0) continue;
    buf.clear();
    put_int(buf, want);
    put_int(buf, static_cast<std::int32_t>(rows.size()));
    for (const auto& [point, row] : rows) {
      put_int(buf, point);
      put_int(buf, row.ok ? 1 : 0);
      put_int(buf, static_cast<std::int32_t>(row.text.size()));
      buf += row.text;
    }
    PMPI_Send(buf.data(), static_cast<int>(buf.size()), MPI_BYTE, 0, kTagRows, MPI_COMM_WORLD);
    if (want == 0) continue;
    std::int32_t answer[3] = {0, 0, 0};
    PMPI_Recv(answer, 3, MPI_INT32_T, 0, kTagChunk, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    if (answer[2] != 0) {  // rank 0 holds many rows for an earlier point: ask again shortly
      ask_after = std::chrono::steady_clock::now() + std::chrono::milliseconds(10);
    } else if (answer[1] <= answer[0]) {
      exhausted = true;
    } else {
      const std::lock_guard<std::mutex> lock(mutex);
      for (int i = answer[0]; i < answer[1]; ++i) queue.push_back(i);
      for_workers.notify_all();
    }
  }
  {
    const std::lock_guard<std::mutex> lock(mutex);
    over = true;
  }
  for_workers.notify_all();
  pool.clear();
  PMPI_Send(nullptr, 0, MPI_BYTE, 0, kTagDone, MPI_COMM_WORLD);
}

}  // namespace bd::cli

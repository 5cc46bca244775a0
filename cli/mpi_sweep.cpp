// A sweep over MPI ranks (cli/mpi_sweep.hpp). Rank 0 is the one writer: its write_sweep() polls
// the other ranks through MasterPeers, handing out chunks of points on request (dynamic load
// balancing: a rank that finishes early asks again) and taking their rows back; each other rank
// computes its chunks on its own threads. A multistart's local runs (RankStartPool) are shared
// the same way, one start at a time. Only the main thread of a rank calls MPI
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
#include <functional>
#include <mutex>
#include <span>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "cli/mpi_sweep.hpp"
#include "core/input_error.hpp"

namespace bd::cli {

namespace st = bd::studies;

namespace {

// message tags: a worker's rows and request, rank 0's answer, a worker's farewell; a
// multistart's request (with the run just computed) and rank 0's answer (a start, or none)
constexpr int kTagRows = 1;
constexpr int kTagChunk = 2;
constexpr int kTagDone = 3;
constexpr int kTagStartRequest = 4;
constexpr int kTagStartAnswer = 5;

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

// the message `status` announced (by a probe), whole, into buf
void receive(const MPI_Status& status, std::string& buf) {
  int bytes = 0;
  PMPI_Get_count(&status, MPI_BYTE, &bytes);
  buf.resize(static_cast<std::size_t>(bytes));
  PMPI_Recv(buf.data(), bytes, MPI_BYTE, status.MPI_SOURCE, status.MPI_TAG, MPI_COMM_WORLD,
            MPI_STATUS_IGNORE);
}

void put_double(std::string& buf, double v) {
  buf.append(reinterpret_cast<const char*>(&v), sizeof v);
}
double get_double(const std::string& buf, std::size_t& at) {
  double v = 0;
  std::memcpy(&v, buf.data() + at, sizeof v);
  at += sizeof v;
  return v;
}
void put_text(std::string& buf, const std::string& text) {
  put_int(buf, static_cast<std::int32_t>(text.size()));
  buf += text;
}
std::string get_text(const std::string& buf, std::size_t& at) {
  const auto length = static_cast<std::size_t>(get_int(buf, at));
  std::string text = buf.substr(at, length);
  at += length;
  return text;
}

// a multistart's local run as bytes (the doubles as they are: every rank gets the same bits);
// `failure` is what the run threw ("" when it returned)
void put_run(std::string& buf, const optimize::LocalRun& run, const std::string& failure) {
  put_int(buf, static_cast<std::int32_t>(run.x.size()));
  for (Eigen::Index i = 0; i < run.x.size(); ++i) put_double(buf, run.x[i]);
  put_double(buf, run.objective);
  put_double(buf, run.violation);
  put_int(buf, run.evaluations);
  put_int(buf, run.result);
  put_text(buf, run.error);
  put_text(buf, failure);
}
optimize::LocalRun get_run(const std::string& buf, std::size_t& at, std::string& failure) {
  optimize::LocalRun run;
  run.x.resize(get_int(buf, at));
  for (Eigen::Index i = 0; i < run.x.size(); ++i) run.x[i] = get_double(buf, at);
  run.objective = get_double(buf, at);
  run.violation = get_double(buf, at);
  run.evaluations = get_int(buf, at);
  run.result = get_int(buf, at);
  run.error = get_text(buf, at);
  failure = get_text(buf, at);
  return run;
}

// one start computed: its run, or what it threw as the failure
optimize::LocalRun run_start(const std::function<optimize::LocalRun(int)>& run, int start,
                             std::string& failure) {
  try {
    return run(start);
  } catch (const std::exception& e) {
    failure = "multistart, start " + std::to_string(start + 1) + ": " + e.what();
  } catch (...) {
    failure = "multistart, start " + std::to_string(start + 1) + ": unknown exception";
  }
  return {};
}

// A multistart's local runs shared among the ranks (MpiWorld::start_pool()).
class RankStartPool final : public optimize::StartPool {
 public:
  RankStartPool(int rank, int size) : rank_(rank), size_(size) {}

  std::vector<optimize::LocalRun> run_all(
      int count, const std::function<optimize::LocalRun(int)>& run) override {
    std::vector<optimize::LocalRun> runs(static_cast<std::size_t>(count));
    std::vector<std::string> failures(runs.size());
    if (rank_ == 0) {
      hand_out(count, run, runs, failures);
    } else {
      take(run);
    }
    // every run to every rank, so that each goes on from the same result
    std::string buf;
    if (rank_ == 0) {
      for (std::size_t i = 0; i < runs.size(); ++i) put_run(buf, runs[i], failures[i]);
    }
    auto bytes = static_cast<std::int64_t>(buf.size());
    PMPI_Bcast(&bytes, 1, MPI_INT64_T, 0, MPI_COMM_WORLD);
    buf.resize(static_cast<std::size_t>(bytes));
    PMPI_Bcast(buf.data(), static_cast<int>(bytes), MPI_BYTE, 0, MPI_COMM_WORLD);
    std::size_t at = 0;
    for (std::size_t i = 0; i < runs.size(); ++i) runs[i] = get_run(buf, at, failures[i]);
    for (const std::string& f : failures) {
      if (!f.empty()) throw std::runtime_error(f);
    }
    return runs;
  }

 private:
  // rank 0: its second thread computes starts while this one answers the other ranks' requests
  // (only this thread calls MPI), each start given to whoever asks first
  void hand_out(int count, const std::function<optimize::LocalRun(int)>& run,
                std::vector<optimize::LocalRun>& runs, std::vector<std::string>& failures) {
    std::mutex mutex;
    int next = 0, done = 0;
    const auto claim = [&] {
      const std::lock_guard<std::mutex> lock(mutex);
      return next < count ? next++ : -1;
    };
    const auto store = [&](int i, optimize::LocalRun r, std::string failure) {
      const std::lock_guard<std::mutex> lock(mutex);
      runs[static_cast<std::size_t>(i)] = std::move(r);
      failures[static_cast<std::size_t>(i)] = std::move(failure);
      ++done;
    };
    std::jthread own([&] {
      for (int i; (i = claim()) >= 0;) {
        std::string failure;
        optimize::LocalRun r = run_start(run, i, failure);
        store(i, std::move(r), std::move(failure));
      }
    });
    int released = 0;  // ranks told that no start is left
    std::string buf;
    for (;;) {
      {
        const std::lock_guard<std::mutex> lock(mutex);
        if (done == count && released == size_ - 1) break;
      }
      int flag = 0;
      MPI_Status status;
      PMPI_Iprobe(MPI_ANY_SOURCE, kTagStartRequest, MPI_COMM_WORLD, &flag, &status);
      if (!flag) {
        std::this_thread::sleep_for(std::chrono::milliseconds(1));
        continue;
      }
      receive(status, buf);
      std::size_t at = 0;
      const std::int32_t finished = get_int(buf, at);  // the start computed, or -1
      if (finished >= 0) {
        std::string failure;
        optimize::LocalRun r = get_run(buf, at, failure);
        store(finished, std::move(r), std::move(failure));
      }
      const std::int32_t start = claim();
      if (start < 0) ++released;
      PMPI_Send(&start, 1, MPI_INT32_T, status.MPI_SOURCE, kTagStartAnswer, MPI_COMM_WORLD);
    }
  }

  // ranks 1..N-1: ask for a start, compute it, send it back with the next request, until none
  // is left
  void take(const std::function<optimize::LocalRun(int)>& run) {
    std::string buf;
    std::int32_t finished = -1;
    optimize::LocalRun r;
    std::string failure;
    for (;;) {
      buf.clear();
      put_int(buf, finished);
      if (finished >= 0) put_run(buf, r, failure);
      PMPI_Send(buf.data(), static_cast<int>(buf.size()), MPI_BYTE, 0, kTagStartRequest,
                MPI_COMM_WORLD);
      std::int32_t start = -1;
      PMPI_Recv(&start, 1, MPI_INT32_T, 0, kTagStartAnswer, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      if (start < 0) return;
      failure.clear();
      r = run_start(run, start, failure);
      finished = start;
    }
  }

  int rank_, size_;
};

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
      receive(status, buf_);
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

std::unique_ptr<optimize::StartPool> MpiWorld::start_pool() {
  return std::make_unique<RankStartPool>(rank_, size_);
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

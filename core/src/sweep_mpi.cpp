#include "vdyn/core/sweep_mpi.h"

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <deque>
#include <filesystem>
#include <mutex>
#include <thread>

#include <mpi.h>

namespace vdyn {

namespace {
constexpr int kTagUp = 1;    // worker -> manager: hello or a journal line
constexpr int kTagTask = 2;  // manager -> worker: variation index, or -1 to stop

/// Waits for a request by testing and sleeping (Open MPI's blocking waits spin
/// a core at 100 %, taking it from the runs on the same machine).
void waitPolling(MPI_Request& req) {
  int done = 0;
  long sleep_us = 20;
  for (;;) {
    MPI_Test(&req, &done, MPI_STATUS_IGNORE);
    if (done) return;
    std::this_thread::sleep_for(std::chrono::microseconds(sleep_us));
    sleep_us = std::min(sleep_us * 2, 1000L);
  }
}

void sendTask(int rank, std::int64_t index) {
  MPI_Request req;
  MPI_Isend(&index, 1, MPI_INT64_T, rank, kTagTask, MPI_COMM_WORLD, &req);
  waitPolling(req);
}

void sendUp(const std::string& text) {
  MPI_Request req;
  MPI_Isend(text.data(), int(text.size()), MPI_CHAR, 0, kTagUp, MPI_COMM_WORLD, &req);
  waitPolling(req);
}

std::string hello(std::uint64_t fingerprint) { return "hello " + std::to_string(fingerprint); }
}  // namespace

MpiSession::MpiSession(int* argc, char*** argv) {
  int provided = 0;
  MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
  if (provided < MPI_THREAD_FUNNELED) {
    std::fprintf(stderr, "MPI library does not provide MPI_THREAD_FUNNELED\n");
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
}

MpiSession::~MpiSession() { MPI_Finalize(); }

void MpiSession::abort(int code) {
  MPI_Abort(MPI_COMM_WORLD, code);
  std::abort();
}

SweepResult runSweepMpi(const SweepDescription& d, const SweepRunFunction& run, const SweepOptions& o) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  if (o.threads < 0) throw Error("sweep: --threads must not be negative, got " + std::to_string(o.threads));
  const auto t0 = std::chrono::steady_clock::now();
  const double cpu0 = processCpuSeconds();
  SweepResult res;
  res.runner = "mpi";

  if (rank != 0) {
    // --- worker ------------------------------------------------------------------
    sendUp(hello(d.fingerprint()));
    for (;;) {
      std::int64_t index = -1;
      MPI_Request req;
      MPI_Irecv(&index, 1, MPI_INT64_T, 0, kTagTask, MPI_COMM_WORLD, &req);
      waitPolling(req);
      if (index < 0) break;
      if (std::size_t(index) >= d.variations.size())
        throw Error("sweep (MPI rank " + std::to_string(rank) + "): the manager sent variation " +
                    std::to_string(index) + " of " + std::to_string(d.variations.size()));
      sendUp(sweepJournalLine(d, runVariation(d, d.variations[std::size_t(index)], run)));
      ++res.ran;
    }
    // Every rank leaves the sweep together: a worker that went on to a next
    // sweep at once would send its hello while the manager still serves this
    // one, which would hand it this sweep's variations and count it out twice.
    MPI_Barrier(MPI_COMM_WORLD);
    res.workers = 1;
    res.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    res.cpu_s = processCpuSeconds() - cpu0;
    return res;
  }

  // --- manager (rank 0) ------------------------------------------------------------
  const int localThreads = size == 1 ? std::max(1, o.threads) : o.threads;
  const std::size_t n = d.variations.size();
  std::unique_ptr<AppendFile> journal;
  const std::vector<std::size_t> pending = prepareSweepRun(d, o, res, journal);
  std::deque<std::size_t> queue(pending.begin(), pending.end());
  const std::size_t pendingCount = queue.size();

  SweepProgress prog;
  prog.total = n;
  prog.skipped = res.resumed;
  auto record = [&](SweepRow&& row) {  // manager thread only
    if (journal) journal->appendLine(sweepJournalLine(d, row));
    ++prog.done;
    if (sweepStatus(row) == "failed") ++prog.failed;
    if (!row.outcome.empty()) ++prog.outcomes[row.outcome];
    res.rows[row.index] = std::move(row);
    prog.elapsed_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    prog.eta_s = prog.elapsed_s / prog.done * double(pendingCount - prog.done);
    if (o.progress) o.progress(prog);
  };

  std::mutex mu;  // guards queue and localDone
  std::vector<SweepRow> localDone;
  std::atomic<int> localRunning{localThreads};
  auto take = [&](std::size_t& i) {
    std::lock_guard<std::mutex> lock(mu);
    if (queue.empty()) return false;
    i = queue.front();
    queue.pop_front();
    return true;
  };
  auto localWorker = [&] {
    for (std::size_t i; take(i);) {
      SweepRow row = runVariation(d, d.variations[i], run);
      std::lock_guard<std::mutex> lock(mu);
      localDone.push_back(std::move(row));
    }
    --localRunning;
  };
  std::vector<std::thread> pool;
  for (int t = 0; t < localThreads; ++t) pool.emplace_back(localWorker);

  int remoteActive = size - 1;
  long sleep_us = 20;
  std::string buffer;
  const std::string expected = hello(d.fingerprint());
  try {
    for (;;) {
      // A local worker pushes its last row before it counts itself out, so
      // reading the count first and then taking the rows misses none.
      const int running = localRunning.load();
      std::vector<SweepRow> done;
      {
        std::lock_guard<std::mutex> lock(mu);
        done.swap(localDone);
      }
      for (auto& row : done) record(std::move(row));
      if (remoteActive == 0 && running == 0) break;
      int flag = 0;
      MPI_Status st;
      if (remoteActive > 0) MPI_Iprobe(MPI_ANY_SOURCE, kTagUp, MPI_COMM_WORLD, &flag, &st);
      if (!flag) {
        if (done.empty()) {
          std::this_thread::sleep_for(std::chrono::microseconds(sleep_us));
          sleep_us = std::min(sleep_us * 2, 500L);
        }
        continue;
      }
      sleep_us = 20;
      int count = 0;
      MPI_Get_count(&st, MPI_CHAR, &count);
      buffer.assign(std::size_t(count), '\0');
      MPI_Recv(buffer.data(), count, MPI_CHAR, st.MPI_SOURCE, kTagUp, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      const std::string where = "sweep: MPI rank " + std::to_string(st.MPI_SOURCE);
      if (buffer.rfind("hello ", 0) == 0) {
        if (buffer != expected)
          throw Error(where + " read a different sweep (fingerprint " + buffer.substr(6) + ", rank 0: " +
                      expected.substr(6) + "): do all machines see the same sweep and scene files?");
      } else {
        record(parseSweepJournalLine(d, buffer, where));
      }
      std::size_t i;
      if (take(i)) {
        sendTask(st.MPI_SOURCE, std::int64_t(i));
      } else {
        sendTask(st.MPI_SOURCE, -1);
        --remoteActive;
      }
    }
  } catch (...) {
    {
      std::lock_guard<std::mutex> lock(mu);
      queue.clear();
    }
    for (auto& t : pool) t.join();
    journal.reset();
    throw;
  }
  for (auto& t : pool) t.join();
  if (journal) journal->close();
  MPI_Barrier(MPI_COMM_WORLD);  // every worker has had its -1; see the worker's barrier
  if (pendingCount == 0 && o.progress) o.progress(prog);
  res.workers = localThreads + size - 1;
  res.ran = prog.done;
  finishSweepRun(d, o, res, t0, cpu0);
  return res;
}

void runSweepMpiJob(SweepMpiJob& job, const char* program) {
  if (!job.sweep || !job.run) throw Error("runSweepMpiJob: the job has no sweep or no run function");
  int argc = 0;
  char** argv = nullptr;
  MpiSession mpi(&argc, &argv);
  job.manager = mpi.rank() == 0;
  SweepOptions o = job.options;
  if (!job.manager) o.progress = nullptr;
  try {
    job.result = runSweepMpi(*job.sweep, *job.run, o);
    if (job.manager && job.on_manager) job.on_manager(job.result);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: error (MPI rank %d): %s\n", program, mpi.rank(), e.what());
    if (mpi.size() > 1) MpiSession::abort(1);
    throw;
  }
}

}  // namespace vdyn

void vdyn_run_sweep_mpi_job(vdyn::SweepMpiJob* job, const char* program) { vdyn::runSweepMpiJob(*job, program); }

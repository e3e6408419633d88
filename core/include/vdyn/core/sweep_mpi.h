#pragma once
// The MPI sweep runner (target vdyn_sweep_mpi; built when CMake finds MPI,
// option VDYN_WITH_MPI). Uses the MPI C API (Open MPI from Debian): the
// messages are an integer (the variation to run) and a text line (the run's
// journal line, JSON), so no serialization library is needed, and every
// blocking wait is a test-and-sleep loop, so an idle rank does not spin a core
// that a working rank on the same machine needs.
//
// Every rank reads the same sweep description; rank 0 is the manager: it
// resumes from the journal, hands out variations one at a time to whichever
// rank asks (dynamic load balancing: runs may differ 10x in cost), writes each
// returned row to the journal and, at the end, the outputs. While managing it
// also runs variations on `options.threads` local worker threads (default 1;
// 0 = manager only). Ranks check at start that they read the same sweep
// (SweepDescription::fingerprint). Rows are byte-identical to the thread
// runner's: a row travels as its journal line, which the thread runner's rows
// also pass through.
#include <functional>

#include "vdyn/core/sweep.h"

namespace vdyn {

/// MPI_Init_thread (MPI_THREAD_FUNNELED: only the main thread calls MPI) and
/// MPI_Finalize. One per process.
class MpiSession {
 public:
  MpiSession(int* argc, char*** argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  int rank() const { return rank_; }
  int size() const { return size_; }
  /// MPI_Abort(MPI_COMM_WORLD, code): ends every rank (after a user error on one).
  [[noreturn]] static void abort(int code);

 private:
  int rank_ = 0, size_ = 1;
};

/// Runs the sweep over MPI_COMM_WORLD (an MpiSession must exist). On rank 0
/// returns the full result (and writes the outputs when options.out_dir is
/// set); on other ranks returns a result with no rows (runner "mpi", `ran` =
/// the runs this rank did).
SweepResult runSweepMpi(const SweepDescription& d, const SweepRunFunction& run, const SweepOptions& options);

/// A whole MPI sweep for a program that loads this library only when asked
/// (`vdyn sweep --mpi` opens it with dlopen, so a process without --mpi does
/// not load Open MPI's libraries: about 2 ms of user CPU per start, see
/// docs/benchmarks.md): the session, the runs, and `on_manager` on rank 0.
struct SweepMpiJob {
  const SweepDescription* sweep = nullptr;
  const SweepRunFunction* run = nullptr;
  /// options.progress is kept on rank 0 only.
  SweepOptions options;
  /// After the runs, on rank 0 (the sweep's plots); may be empty.
  std::function<void(const SweepResult&)> on_manager;
  /// Set by runSweepMpiJob: rank 0's full result (other ranks: no rows), and
  /// whether this process is rank 0.
  SweepResult result;
  bool manager = true;
};

/// Starts an MpiSession, runs runSweepMpi and job.on_manager. An error on a
/// rank is printed there ("<program>: error (MPI rank R): ...", `program`
/// names the caller) and, with more than one rank, ends every rank
/// (MpiSession::abort: the others would wait for it forever); with one rank
/// it is rethrown.
void runSweepMpiJob(SweepMpiJob& job, const char* program);

}  // namespace vdyn

/// runSweepMpiJob with C linkage, the symbol a program looks up after dlopen
/// of this library (its soname: the build's VDYN_SWEEP_MPI_LIBRARY).
extern "C" __attribute__((visibility("default"))) void vdyn_run_sweep_mpi_job(vdyn::SweepMpiJob* job,
                                                                             const char* program);

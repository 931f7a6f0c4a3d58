// A sweep's runs over the ranks of an MPI job (mpirun, srun) or the threads of one process.
// app/mpi_sweep.cpp is the only file that includes mpi.h; built without MPI (FURROW_MPI off) a Job
// is always the one local process.
#pragma once
#include <functional>
#include <string>
#include <vector>

namespace furrow::cli::mpi {

// "yes (Open MPI v4.1.4)" or "no (built without)", for `furrow --version`.
std::string build_text();
bool built_with_mpi();

// This process's rank in the job an MPI launcher started, read from the launcher's environment
// (OMPI_COMM_WORLD_SIZE, PMI_SIZE or PMIX_RANK present); -1 when no launcher started it. Plain
// `furrow sweep` therefore never initialises MPI (a singleton MPI_Init costs seconds).
int launched_rank();

// How one run of the sweep ended, as its rank reports it to rank 0.
struct Outcome {
  size_t index = 0;
  int rank = 0;  // that ran it
  bool ok = false;
  double wall_s = 0.0;
  std::string error;
};

class Job {
 public:
  Job();   // MPI_Init_thread when launched_rank() >= 0 and built with MPI
  ~Job();  // MPI_Finalize
  Job(const Job&) = delete;
  Job& operator=(const Job&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }
  int ranks_on_node() const { return ranks_on_node_; }  // MPI_COMM_TYPE_SHARED: this job's ranks here

  // rank 0's text, on every rank
  std::string broadcast(const std::string& text) const;

  // Runs every index of `todo` once, in that order, over the whole job: whichever rank is free
  // takes the next (rank 0 hands them out and runs them too). Alone, `threads_when_alone`
  // runs at a time. `on_done` sees every Outcome, one at a time, on rank 0 only. Neither `run`
  // nor `on_done` may throw (they run on threads of their own).
  void distribute(const std::vector<size_t>& todo, int threads_when_alone,
                  const std::function<Outcome(size_t)>& run, const std::function<void(const Outcome&)>& on_done);

  // Ends every rank with `status` (MPI_Abort) when other ranks may be waiting on this one.
  void abort(int status);

 private:
  bool initialised_ = false, serialized_ = false;
  int rank_ = 0, size_ = 1, ranks_on_node_ = 1;
};

}  // namespace furrow::cli::mpi

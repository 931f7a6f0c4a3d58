#include "app/mpi_sweep.hpp"

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#if FURROW_HAVE_MPI
#define OMPI_SKIP_MPICXX 1  // the C API only: MPI::MPI_C links no C++ bindings
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>
#endif

namespace furrow::cli::mpi {

namespace {

int env_int(const char* name) {
  const char* v = std::getenv(name);
  return v && *v ? std::atoi(v) : -1;
}

// Several local threads share one queue; `on_done` is called under a lock.
void run_locally(const std::vector<size_t>& todo, int threads, const std::function<Outcome(size_t)>& run,
                 const std::function<void(const Outcome&)>& on_done) {
  std::atomic<size_t> next{0};
  std::mutex done_mutex;
  auto worker = [&] {
    for (size_t k = next++; k < todo.size(); k = next++) {
      const Outcome o = run(todo[k]);
      std::lock_guard<std::mutex> lock(done_mutex);
      on_done(o);
    }
  };
  std::vector<std::thread> pool;
  for (int t = 0; t < std::max(1, threads); ++t) pool.emplace_back(worker);
  for (auto& t : pool) t.join();
}

}  // namespace

bool built_with_mpi() { return FURROW_HAVE_MPI; }

int launched_rank() {
  if (!std::getenv("OMPI_COMM_WORLD_SIZE") && !std::getenv("PMI_SIZE") && !std::getenv("PMIX_RANK")) return -1;
  for (const char* name : {"OMPI_COMM_WORLD_RANK", "PMIX_RANK", "PMI_RANK"})
    if (env_int(name) >= 0) return env_int(name);
  return 0;
}

#if FURROW_HAVE_MPI

namespace {

// Rank 0 receives "what I finished" (empty on a rank's first request) and answers with the
// next index to run, or -1: that rank is done.
constexpr int kTagReport = 1, kTagWork = 2;

std::string encode(const Outcome& o) {
  return nlohmann::json{{"index", o.index}, {"rank", o.rank}, {"ok", o.ok}, {"wall_s", o.wall_s}, {"error", o.error}}
      .dump();
}

Outcome decode(const std::string& text) {
  const auto j = nlohmann::json::parse(text);
  return {j.at("index").get<size_t>(), j.at("rank").get<int>(), j.at("ok").get<bool>(), j.at("wall_s").get<double>(),
          j.at("error").get<std::string>()};
}

}  // namespace

std::string build_text() {
  char text[MPI_MAX_LIBRARY_VERSION_STRING];
  int n = 0;
  MPI_Get_library_version(text, &n);
  std::string v(text, size_t(n));
  v = v.substr(0, v.find_first_of(",\n"));  // "Open MPI v4.1.4, package: ..." -> the name and version
  return "yes (" + v + ")";
}

Job::Job() {
  if (launched_rank() < 0) return;
  int provided = MPI_THREAD_SINGLE;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided);
  initialised_ = true;
  serialized_ = provided >= MPI_THREAD_SERIALIZED;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  MPI_Comm node;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node);
  MPI_Comm_size(node, &ranks_on_node_);
  MPI_Comm_free(&node);
}

Job::~Job() {
  if (initialised_) MPI_Finalize();
}

std::string Job::broadcast(const std::string& text) const {
  if (size_ == 1) return text;
  long long n = (long long)text.size();
  MPI_Bcast(&n, 1, MPI_LONG_LONG, 0, MPI_COMM_WORLD);
  std::string out = rank_ == 0 ? text : std::string(size_t(n), '\0');
  MPI_Bcast(out.data(), int(n), MPI_CHAR, 0, MPI_COMM_WORLD);
  return out;
}

void Job::abort(int status) {
  if (size_ > 1) MPI_Abort(MPI_COMM_WORLD, status);
}

void Job::distribute(const std::vector<size_t>& todo, int threads_when_alone, const std::function<Outcome(size_t)>& run,
                     const std::function<void(const Outcome&)>& on_done) {
  if (size_ == 1) return run_locally(todo, threads_when_alone, run, on_done);

  if (rank_ != 0) {
    std::string report;  // empty: the first request
    for (;;) {
      MPI_Send(report.data(), int(report.size()), MPI_CHAR, 0, kTagReport, MPI_COMM_WORLD);
      long long index = -1;
      MPI_Recv(&index, 1, MPI_LONG_LONG, 0, kTagWork, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      if (index < 0) return;
      report = encode(run(size_t(index)));
    }
  }

  std::mutex queue_mutex, done_mutex;
  size_t next = 0;
  auto take = [&]() -> long long {
    std::lock_guard<std::mutex> lock(queue_mutex);
    return next < todo.size() ? (long long)todo[next++] : -1;
  };
  auto done = [&](const Outcome& o) {
    std::lock_guard<std::mutex> lock(done_mutex);
    on_done(o);
  };
  // the only thread that calls MPI while the runs go on (MPI_THREAD_SERIALIZED); it polls with
  // pauses because a blocking receive in Open MPI spins a core that the runs need
  auto coordinate = [&] {
    for (int finished_ranks = 0; finished_ranks < size_ - 1;) {
      int pending = 0;
      MPI_Status st;
      MPI_Iprobe(MPI_ANY_SOURCE, kTagReport, MPI_COMM_WORLD, &pending, &st);
      if (!pending) {
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
        continue;
      }
      int n = 0;
      MPI_Get_count(&st, MPI_CHAR, &n);
      std::string report(size_t(n), '\0');
      MPI_Recv(report.data(), n, MPI_CHAR, st.MPI_SOURCE, kTagReport, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      long long index = take();
      MPI_Send(&index, 1, MPI_LONG_LONG, st.MPI_SOURCE, kTagWork, MPI_COMM_WORLD);
      finished_ranks += index < 0;
      if (!report.empty()) done(decode(report));
    }
  };
  if (!serialized_) return coordinate();  // this MPI allows no second thread: rank 0 only hands out
  std::thread coordinator(coordinate);
  for (long long index = take(); index >= 0; index = take()) done(run(size_t(index)));
  coordinator.join();
}

#else

std::string build_text() { return "no (built without)"; }
Job::Job() {}
Job::~Job() {}
std::string Job::broadcast(const std::string& text) const { return text; }
void Job::abort(int) {}
void Job::distribute(const std::vector<size_t>& todo, int threads_when_alone, const std::function<Outcome(size_t)>& run,
                     const std::function<void(const Outcome&)>& on_done) {
  run_locally(todo, threads_when_alone, run, on_done);
}

#endif

}  // namespace furrow::cli::mpi

// Who runs what in a sweep: worker processes on this machine (fork, pipes), or MPI ranks. Both
// hand out runs one at a time as workers free up; results are written by one process only.
#include "sweep.hpp"

#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <iostream>
#include <optional>
#include <stdexcept>

#ifdef SSX_HAVE_MPI
// the C API only (OpenMPI would pull in its deprecated C++ bindings)
#define OMPI_SKIP_MPICXX 1
#define MPICH_SKIP_MPICXX 1
#include <mpi.h>
#endif

namespace ssx::sweep {

namespace {

bool writeAll(int fd, const void* data, std::size_t size) {
  const char* p = static_cast<const char*>(data);
  while (size > 0) {
    const ssize_t n = ::write(fd, p, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    p += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

bool readAll(int fd, void* data, std::size_t size) {
  char* p = static_cast<char*>(data);
  while (size > 0) {
    const ssize_t n = ::read(fd, p, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    p += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

// a worker process: reads run indices, answers with results, until it reads -1
[[noreturn]] void workerLoop(const Spec& spec, int in, int out) {
  for (;;) {
    std::int64_t run = -1;
    if (!readAll(in, &run, sizeof run) || run < 0) _exit(0);
    const std::string text = execute(spec, run).text();
    const auto size = static_cast<std::uint32_t>(text.size());
    if (!writeAll(out, &size, sizeof size) || !writeAll(out, text.data(), text.size())) _exit(1);
  }
}

struct Worker {
  pid_t pid = -1;
  int to = -1, from = -1;
  std::int64_t run = -1;  // outstanding
  std::string buffer;
};

Worker spawn(const Spec& spec, const std::vector<Worker>& others) {
  int down[2], up[2];
  if (pipe(down) != 0 || pipe(up) != 0) throw std::runtime_error(std::string("pipe: ") + std::strerror(errno));
  std::cout.flush();
  std::cerr.flush();
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
  if (pid == 0) {
    for (const auto& w : others) {
      if (w.to >= 0) close(w.to);
      if (w.from >= 0) close(w.from);
    }
    close(down[1]);
    close(up[0]);
    workerLoop(spec, down[0], up[1]);
  }
  close(down[0]);
  close(up[1]);
  Worker w;
  w.pid = pid;
  w.to = down[1];
  w.from = up[0];
  return w;
}

std::string howItDied(pid_t pid) {
  int status = 0;
  if (waitpid(pid, &status, 0) < 0) return "its process vanished";
  if (WIFSIGNALED(status))
    return "its process died of signal " + std::to_string(WTERMSIG(status)) + " (" + strsignal(WTERMSIG(status)) + ")";
  return "its process exited with status " + std::to_string(WEXITSTATUS(status)) + " before answering";
}

void record(Stats& stats, const Result& r) {
  ++stats.runs;
  if (!r.ok) {
    ++stats.failed;
    return;
  }
  stats.load_ms.push_back(r.load_ms);
  stats.start_ms.push_back(r.start_ms);
  stats.run_ms.push_back(r.run_ms);
}

void progressLine(bool on, const Output& out, std::int64_t total) {
  if (on) std::cerr << "\rssx sweep: " << (total - out.pending()) << "/" << total << " runs" << std::flush;
}

}  // namespace

Stats runLocal(const Spec& spec, Output& out, int jobs, bool progress) {
  Stats stats;
  std::deque<std::int64_t> todo;
  for (std::int64_t r = 0; r < spec.runCount(); ++r)
    if (!out.done()[static_cast<std::size_t>(r)]) todo.push_back(r);
  // a dead worker's pipe must not kill the sweep
  struct sigaction ignore {}, previous {};
  ignore.sa_handler = SIG_IGN;
  sigaction(SIGPIPE, &ignore, &previous);
  std::vector<Worker> workers;
  auto assign = [&](Worker& w) {
    if (todo.empty()) {
      const std::int64_t stop = -1;
      writeAll(w.to, &stop, sizeof stop);
      close(w.to);
      w.to = -1;
      return;
    }
    w.run = todo.front();
    todo.pop_front();
    if (!writeAll(w.to, &w.run, sizeof w.run)) {
      // it died between runs: it answers with EOF below, and its run is given to another
      todo.push_front(w.run);
      w.run = -1;
    }
  };
  const auto n = static_cast<std::size_t>(std::max<std::int64_t>(1, std::min<std::int64_t>(jobs, static_cast<std::int64_t>(todo.size()))));
  for (std::size_t i = 0; i < n && !todo.empty(); ++i) {
    workers.push_back(spawn(spec, workers));
    assign(workers.back());
  }
  try {
    while (!workers.empty()) {
      std::vector<pollfd> fds;
      for (const auto& w : workers) fds.push_back({w.from, POLLIN, 0});
      if (poll(fds.data(), fds.size(), -1) < 0) {
        if (errno == EINTR) continue;
        throw std::runtime_error(std::string("poll: ") + std::strerror(errno));
      }
      for (std::size_t i = workers.size(); i-- > 0;) {
        if (fds[i].revents == 0) continue;
        Worker& w = workers[i];
        char chunk[65536];
        const ssize_t got = ::read(w.from, chunk, sizeof chunk);
        if (got < 0 && errno == EINTR) continue;
        if (got > 0) {
          w.buffer.append(chunk, static_cast<std::size_t>(got));
          std::uint32_t size = 0;
          while (w.buffer.size() >= sizeof size) {
            std::memcpy(&size, w.buffer.data(), sizeof size);
            if (w.buffer.size() < sizeof size + size) break;
            const Result r = Result::parse(w.buffer.substr(sizeof size, size));
            w.buffer.erase(0, sizeof size + size);
            out.write(r);
            record(stats, r);
            progressLine(progress, out, spec.runCount());
            w.run = -1;
            assign(w);
          }
          continue;
        }
        // end of file: the worker is gone; an outstanding run is recorded as crashed
        close(w.from);
        if (w.to >= 0) close(w.to);
        const std::string why = howItDied(w.pid);
        const std::int64_t lost = w.run;
        workers.erase(workers.begin() + static_cast<std::ptrdiff_t>(i));
        if (lost >= 0) {
          const Result r = crashed(spec, lost, why);
          out.write(r);
          record(stats, r);
          progressLine(progress, out, spec.runCount());
        }
        if (!todo.empty()) {
          workers.push_back(spawn(spec, workers));
          assign(workers.back());
          break;  // fds no longer match workers
        }
      }
    }
  } catch (...) {
    for (auto& w : workers) {
      kill(w.pid, SIGKILL);
      waitpid(w.pid, nullptr, 0);
    }
    sigaction(SIGPIPE, &previous, nullptr);
    throw;
  }
  sigaction(SIGPIPE, &previous, nullptr);
  if (progress) std::cerr << '\n';
  return stats;
}

bool underMpi() {
#ifdef SSX_HAVE_MPI
  return std::getenv("OMPI_COMM_WORLD_SIZE") != nullptr || std::getenv("PMIX_RANK") != nullptr ||
         std::getenv("PMI_RANK") != nullptr;
#else
  return false;
#endif
}



#ifdef SSX_HAVE_MPI
namespace {
constexpr int kTagResult = 1, kTagWork = 2;
}

int runMpi(const fs::path& file, const std::vector<fs::path>& plugin_path, const fs::path& out_file,
           const fs::path& robots_file, bool check_only, std::uintmax_t max_input_bytes) {
  MPI_Init(nullptr, nullptr);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  // every rank reads the sweep (the points are the same everywhere); rank 0 checks it, opens the
  // output, and tells the others whether to go on
  std::optional<Spec> spec;
  std::string problem;
  int status = 0;
  try {
    spec = readSpec(file, plugin_path, max_input_bytes);
    if (rank == 0) check(*spec);
  } catch (const SceneError& e) {
    problem = e.what();
    status = 2;
  }
  std::optional<Output> out;
  if (rank == 0 && status == 0 && !check_only) try {
      out.emplace(*spec, out_file, robots_file);
    } catch (const std::exception& e) {
      problem = std::string("ssx: error: ") + e.what();
      status = 2;
    }
  MPI_Bcast(&status, 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (status != 0 || check_only) {
    if (rank == 0) {
      if (status != 0) std::cerr << problem << '\n';
      else std::cout << file.string() << ": ok: " << spec->points.size() << " point(s) x " << spec->seeds
                     << " seed(s) = " << spec->runCount() << " runs\n";
    }
    MPI_Finalize();
    return status;
  }
  const auto t0 = std::chrono::steady_clock::now();
  if (rank == 0) {
    Stats stats;
    try {
      if (size == 1) {
        stats = runLocal(*spec, *out, 1, false);
      } else {
        std::deque<std::int64_t> todo;
        for (std::int64_t r = 0; r < spec->runCount(); ++r)
          if (!out->done()[static_cast<std::size_t>(r)]) todo.push_back(r);
        int active = size - 1;
        while (active > 0) {
          MPI_Status st;
          MPI_Probe(MPI_ANY_SOURCE, kTagResult, MPI_COMM_WORLD, &st);
          int count = 0;
          MPI_Get_count(&st, MPI_CHAR, &count);
          std::string text(static_cast<std::size_t>(count), '\0');
          MPI_Recv(text.data(), count, MPI_CHAR, st.MPI_SOURCE, kTagResult, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
          if (count > 0) {
            const Result r = Result::parse(text);
            out->write(r);
            record(stats, r);
          }
          std::int64_t next = -1;
          if (!todo.empty()) {
            next = todo.front();
            todo.pop_front();
          } else {
            --active;
          }
          MPI_Send(&next, 1, MPI_INT64_T, st.MPI_SOURCE, kTagWork, MPI_COMM_WORLD);
        }
      }
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      printStats(stats, *out, wall, std::max(1, size - 1), out->writeSummary());
    } catch (const std::exception& e) {
      std::cerr << "ssx: error: " << e.what() << '\n';
      MPI_Abort(MPI_COMM_WORLD, 1);
    }
  } else {
    // a worker: ready, then one run per answer until told to stop
    std::string text;
    for (;;) {
      MPI_Send(text.data(), static_cast<int>(text.size()), MPI_CHAR, 0, kTagResult, MPI_COMM_WORLD);
      std::int64_t run = -1;
      MPI_Recv(&run, 1, MPI_INT64_T, 0, kTagWork, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      if (run < 0) break;
      text = execute(*spec, run).text();
    }
  }
  MPI_Finalize();
  return 0;
}
#else
int runMpi(const fs::path&, const std::vector<fs::path>&, const fs::path&, const fs::path&, bool, std::uintmax_t) {
  std::cerr << "ssx: error: this ssx was built without MPI (apt-get install libopenmpi-dev, then rebuild)\n";
  return 2;
}
#endif

namespace {
double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2];
}
}  // namespace

void printStats(const Stats& stats, const Output& out, double wall_s, int processes, const fs::path& summary) {
  char line[512];
  std::snprintf(line, sizeof line,
                "ssx sweep: %lld run(s) (%lld failed) in %.2f s on %d process(es): %.2f runs/s; per run (median): "
                "load %.1f ms, start %.1f ms, run %.1f ms, write %.3f ms\n",
                static_cast<long long>(stats.runs), static_cast<long long>(stats.failed), wall_s, processes,
                wall_s > 0 ? static_cast<double>(stats.runs) / wall_s : 0.0, median(stats.load_ms),
                median(stats.start_ms), median(stats.run_ms), out.writeMedianMs());
  std::cout << line << "ssx sweep: summary per point in " << summary.string() << '\n';
}

}  // namespace ssx::sweep

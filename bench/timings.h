// Run times for the error report, from several processes interleaved in time.
//
// A section measures its errors at once and registers what it times: a job that returns run
// times in ms (one per repeat, or one per seed for bolts) and gets a ticket. A job is told which
// process runs it (0, 1, ...), so that slow bolts can spread their seeds over the processes. Once every section
// has registered, run(processes) forks the processes one after another; each runs every job in
// registration order and sends its times back through a pipe. A ticket's spread is over the
// times of all processes, so that it holds what changes between runs (memory layout, the
// machine's state over minutes) and not only between repeats. Jobs must not rely on threads the
// parent started before the fork: they build what they time themselves (a renderer too).
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include <effects/common.h>

namespace bench {

class Timings {
 public:
  using Job = std::function<std::vector<double>(int process)>;
  static constexpr size_t kNone = size_t(-1);

  // A job that returns its own times (bolts: each seed's elapsed time).
  size_t add(std::string name, Job job) {
    jobs_.push_back({std::move(name), std::move(job)});
    return jobs_.size() - 1;
  }
  // `repeats` calls of f, each timed.
  size_t repeat(std::string name, int repeats, std::function<void()> f) {
    return add(std::move(name), [repeats, f = std::move(f)](int) {
      std::vector<double> t;
      for (int i = 0; i < repeats; ++i) {
        effects::Stopwatch w;
        f();
        t.push_back(w.ms());
      }
      return t;
    });
  }

  // Runs every job in `processes` forked processes, one after the other. False (with a message
  // on stderr) when a process fails.
  bool run(int processes) {
    times_.assign(jobs_.size(), {});
    runMedians_.assign(jobs_.size(), {});
    for (int run = 0; run < processes; ++run) {
      std::fprintf(stderr, "timing: process %d of %d, %zu jobs\n", run + 1, processes, jobs_.size());
      int fd[2];
      if (pipe(fd) != 0) return std::perror("pipe"), false;
      std::fflush(nullptr);
      const pid_t pid = fork();
      if (pid < 0) return std::perror("fork"), false;
      if (pid == 0) {  // the child: every job in turn, each job's count and times down the pipe
        close(fd[0]);
        for (const auto& [name, job] : jobs_) {
          const std::vector<double> t = job(run);
          const double n = double(t.size());
          if (!writeAll(fd[1], &n, sizeof n) || !writeAll(fd[1], t.data(), t.size() * sizeof(double))) _exit(3);
        }
        close(fd[1]);
        _exit(0);
      }
      close(fd[1]);
      bool ok = true;
      for (size_t j = 0; j < jobs_.size() && ok; ++j) {
        double n = 0;
        ok = readAll(fd[0], &n, sizeof n) && n >= 0 && n < 1e7;
        std::vector<double> t(ok ? size_t(n) : 0);
        ok = ok && readAll(fd[0], t.data(), t.size() * sizeof(double));
        times_[j].insert(times_[j].end(), t.begin(), t.end());
        runMedians_[j].push_back(median(t));
      }
      close(fd[0]);
      int status = 0;
      waitpid(pid, &status, 0);
      if (!ok || !WIFEXITED(status) || WEXITSTATUS(status) != 0) {
        std::fprintf(stderr, "timing: process %d failed (status %d)\n", run + 1, status);
        return false;
      }
    }
    return true;
  }

  // A ticket's times from every process, and each process's median.
  const std::vector<double>& times(size_t ticket) const { return times_.at(ticket); }
  const std::vector<double>& runMedians(size_t ticket) const { return runMedians_.at(ticket); }

 private:
  static bool writeAll(int fd, const void* p, size_t n) {
    const char* c = static_cast<const char*>(p);
    while (n > 0) {
      const ssize_t w = write(fd, c, n);
      if (w <= 0) return false;
      c += w, n -= size_t(w);
    }
    return true;
  }
  static bool readAll(int fd, void* p, size_t n) {
    char* c = static_cast<char*>(p);
    while (n > 0) {
      const ssize_t r = read(fd, c, n);
      if (r <= 0) return false;
      c += r, n -= size_t(r);
    }
    return true;
  }
  static double median(std::vector<double> v) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    return v.size() % 2 ? v[v.size() / 2] : (v[v.size() / 2 - 1] + v[v.size() / 2]) / 2;
  }

  struct Entry {
    std::string name;
    Job job;
  };
  std::vector<Entry> jobs_;
  std::vector<std::vector<double>> times_, runMedians_;
};

}  // namespace bench

// Prometheus text-format metrics: requests by route, method and status; a latency histogram
// per route; requests in flight. Thread-safe.
#pragma once

#include <array>
#include <atomic>
#include <functional>
#include <map>
#include <mutex>
#include <string>
#include <tuple>
#include <vector>

namespace effectd {

class Metrics {
 public:
  static constexpr std::array<double, 14> kBuckets = {0.0005, 0.001, 0.0025, 0.005, 0.01, 0.025, 0.05,
                                                      0.1,    0.25,  0.5,    1.0,   2.5,  5.0,   10.0};
  void requestStarted() { inFlight_.fetch_add(1); }
  void requestFinished(const std::string& route, const std::string& method, int status, double seconds);
  // A named counter (e.g. render passes by kind), exported as effectd_<name>_total{label}.
  void count(const std::string& name, const std::string& label, double by = 1.0);
  std::string render() const;
  // Extra exposition text appended by render() (gauges owned by other components).
  void addSource(std::function<std::string()> source) { sources_.push_back(std::move(source)); }

 private:
  struct Histogram {
    std::array<uint64_t, kBuckets.size()> buckets{};
    uint64_t count = 0;
    double sum = 0;
  };
  mutable std::mutex mu_;
  std::map<std::tuple<std::string, std::string, int>, uint64_t> requests_;
  std::map<std::string, Histogram> latency_;
  std::map<std::pair<std::string, std::string>, double> counters_;
  std::atomic<int64_t> inFlight_{0};
  std::vector<std::function<std::string()>> sources_;  // set up before serving
};

}  // namespace effectd

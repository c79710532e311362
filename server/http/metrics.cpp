#include "http/metrics.h"

#include <sstream>

namespace effectd {

void Metrics::requestFinished(const std::string& route, const std::string& method, int status, double seconds) {
  inFlight_.fetch_sub(1);
  std::lock_guard<std::mutex> lock(mu_);
  ++requests_[{route, method, status}];
  Histogram& h = latency_[route];
  for (size_t i = 0; i < kBuckets.size(); ++i)
    if (seconds <= kBuckets[i]) ++h.buckets[i];
  ++h.count;
  h.sum += seconds;
}

void Metrics::count(const std::string& name, const std::string& label, double by) {
  std::lock_guard<std::mutex> lock(mu_);
  counters_[{name, label}] += by;
}

std::string Metrics::render() const {
  std::ostringstream os;
  os.precision(10);
  std::lock_guard<std::mutex> lock(mu_);
  os << "# HELP effectd_http_requests_total HTTP requests by route, method and status.\n"
        "# TYPE effectd_http_requests_total counter\n";
  for (const auto& [key, n] : requests_) {
    const auto& [route, method, status] = key;
    os << "effectd_http_requests_total{route=\"" << route << "\",method=\"" << method << "\",status=\"" << status
       << "\"} " << n << "\n";
  }
  os << "# HELP effectd_http_request_duration_seconds Time from request line to response written.\n"
        "# TYPE effectd_http_request_duration_seconds histogram\n";
  for (const auto& [route, h] : latency_) {
    for (size_t i = 0; i < kBuckets.size(); ++i)
      os << "effectd_http_request_duration_seconds_bucket{route=\"" << route << "\",le=\"" << kBuckets[i] << "\"} "
         << h.buckets[i] << "\n";
    os << "effectd_http_request_duration_seconds_bucket{route=\"" << route << "\",le=\"+Inf\"} " << h.count << "\n";
    os << "effectd_http_request_duration_seconds_sum{route=\"" << route << "\"} " << h.sum << "\n";
    os << "effectd_http_request_duration_seconds_count{route=\"" << route << "\"} " << h.count << "\n";
  }
  os << "# HELP effectd_http_requests_in_flight Requests being served now.\n"
        "# TYPE effectd_http_requests_in_flight gauge\n"
        "effectd_http_requests_in_flight "
     << inFlight_.load() << "\n";
  std::string lastName;
  for (const auto& [key, v] : counters_) {
    const auto& [name, label] = key;
    if (name != lastName) {
      os << "# TYPE effectd_" << name << "_total counter\n";
      lastName = name;
    }
    os << "effectd_" << name << "_total{kind=\"" << label << "\"} " << v << "\n";
  }
  for (const auto& source : sources_) os << source();
  return os.str();
}

}  // namespace effectd

// The report's shared helpers (report.h): formatting, statistics, rows as data and their
// comparison with the committed data.
#include "report.h"

#include <algorithm>
#include <atomic>
#include <sstream>

#include <effects/parallel.h>

namespace report {

size_t Run::time(std::string name, bench::Timings::Job job) {
  return timed && timings ? timings->add(std::move(name), std::move(job)) : bench::Timings::kNone;
}

size_t Run::repeat(std::string name, int repeats, std::function<void()> f) {
  return timed && timings ? timings->repeat(std::move(name), repeats, std::move(f)) : bench::Timings::kNone;
}

size_t timeFrames(Run& run, const std::string& name, std::function<effects::render::Scene()> scene, int frames) {
  return run.time(name, [scene = std::move(scene), frames](int) {
    static auto renderer = effects::render::Renderer::create();
    std::vector<double> ms;
    if (!renderer.ok()) return ms;
    const effects::render::Scene built = scene();
    for (int i = 0; i <= frames; ++i)
      if (auto f = renderer.value()->render(built); f.ok() && i > 0) ms.push_back(f.value().ms);
    return ms;
  });
}

void onEveryCore(size_t n, const std::function<void(size_t)>& f) {
  effects::ThreadPool pool(effects::ThreadPool::besideCaller());
  std::atomic<size_t> next{0};  // each thread takes the next call when it is free: calls differ by 1000x
  pool.forRange(pool.threads() + 1, 1, [&](size_t, size_t) {
    for (size_t i; (i = next.fetch_add(1)) < n;) f(i);
  });
}

std::string fmt(double v, int digits) {
  if (v == 0) return "0";
  std::ostringstream s;
  s.precision(digits);
  s << v;
  return s.str();
}

double quantile(std::vector<double> v, double f) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const double at = f * double(v.size() - 1);
  const size_t i = size_t(at);
  return i + 1 < v.size() ? v[i] + (v[i + 1] - v[i]) * (at - double(i)) : v[i];
}

std::pair<double, double> meanSd(const std::vector<double>& v) {
  double mean = 0, var = 0;
  for (double x : v) mean += x / double(v.size());
  for (double x : v) var += (x - mean) * (x - mean) / double(std::max<size_t>(1, v.size() - 1));
  return {mean, std::sqrt(var)};
}

double errorOf(const Row& r, const std::string& id) {
  const auto it = r.errors.find(id);
  return it == r.errors.end() ? NAN : it->second;
}

double worstOf(const Run& run, const std::string& id) {
  double worst = 0;
  for (const Row& r : run.rows) worst = std::max(worst, errorOf(r, id));
  return worst;
}

const Row* fastestWithin(const Run& run, const std::string& id, double maxError, const std::string& series) {
  const Row* best = nullptr;
  for (const Row& r : run.rows)
    if (r.series.rfind(series, 0) == 0 && errorOf(r, id) <= maxError && r.ms > 0 && (!best || r.ms < best->ms))
      best = &r;
  return best;
}

json rowsJson(const std::vector<Row>& rows, bool withTimes) {
  json out = json::array();
  for (const Row& r : rows) {
    json errors = json::object();
    for (const auto& [id, v] : r.errors) errors[id] = std::isfinite(v) ? json(v) : json();
    json row = {{"series", r.series}, {"setting", r.setting}, {"group", r.group}, {"request", r.request},
                {"errors", errors},   {"note", r.note}};
    if (withTimes && r.ms > 0)
      row["time"] = {{"ms", r.ms}, {"q1", r.q1}, {"q3", r.q3}, {"repeats", r.repeats}, {"runMedians", r.runMedians}};
    out.push_back(row);
  }
  return out;
}

std::vector<std::string> differences(const Section& s, const json& measured, const json& committed) {
  std::vector<std::string> out;
  auto key = [](const json& r) { return r["series"].get<std::string>() + " | " + r["setting"].get<std::string>(); };
  std::map<std::string, const json*> was;
  for (const json& r : committed) was[key(r)] = &r;
  for (const json& r : measured) {
    const auto it = was.find(key(r));
    if (it == was.end()) {
      out.push_back("new row '" + key(r) + "'");
      continue;
    }
    const json& old = *it->second;
    for (const auto& [id, v] : r["errors"].items()) {
      const json w = old["errors"].value(id, json());
      if (v.is_null() != w.is_null()) {
        out.push_back("'" + key(r) + "' " + id + ": " + v.dump() + ", was " + w.dump());
        continue;
      }
      if (v.is_null()) continue;
      const double a = v.get<double>(), b = w.get<double>();
      if (std::abs(a - b) > s.checkAbsolute + s.checkRelative * std::max(std::abs(a), std::abs(b)))
        out.push_back("'" + key(r) + "' " + id + ": " + fmt(a, 10) + ", was " + fmt(b, 10));
    }
    if (r["errors"].size() != old["errors"].size()) out.push_back("'" + key(r) + "': other metrics than before");
    was.erase(it);
  }
  for (const auto& [k, r] : was) out.push_back("row '" + k + "' is gone");
  return out;
}

}  // namespace report

// The error-against-run-time report's parts: a section is one unit (one file under sections/)
// holding its configurations, its reference, its measurement and its conclusion; what it
// measures is data (Row), written as one JSON file per section by report.cpp and rendered to
// Markdown by scripts/report_render.py. docs/reports.md explains the whole.
#pragma once

#include <cmath>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include <render/render.h>

#include "../timings.h"
#include "sheets.h"

namespace report {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr double kPi = 3.14159265358979323846;

// One error measure of a section, and its limit of use: past it a setting is no budget's
// choice, however fast. X-Effect-Error states the limit with every figure (server/api/
// error_estimates.cpp reads it from the committed data).
struct Metric {
  std::string id;     // the key in Row::errors and in the data ("tv", "meanDeltaE", ...)
  std::string label;  // short, for the summary's cells ("TV", "ΔE")
  std::string name;   // what it is, in full
  double limit = INFINITY;
  std::string why;                // why the limit is there
  std::string kind = "measured";  // against the reference, on this configuration
};

// One measured configuration.
struct Row {
  std::string series, setting;  // a curve, and what varies along it
  std::string group;            // what a client fixes before choosing (a grid, a fog type, a mesh)
  json request = json::object();  // the fields a client sends for it (beyond the group's)
  std::map<std::string, double> errors;  // Metric::id -> value; absent or NaN: not measured here
  std::string note;
  size_t ticket = bench::Timings::kNone;  // its run times, once the timing processes have run
  double timeFactor = 1;                  // times x this = the section's unit (tangents: per 100k)
  // Filled from the timing processes (report.cpp): median, interquartile range, repeats.
  double ms = 0, q1 = 0, q3 = 0;
  int repeats = 0;
  std::vector<double> runMedians;  // each timing process's median
};

// What a group answers in the summary: the thing a game asks for ("a 128² bolt to the
// ground"), and the request fields that fix it. Groups of several sections with the same ask
// are joined there: a pick must be within every limit of every section that measures it.
struct Ask {
  std::string group, ask;
  json fixed = json::object();
};

// What a section's measurement writes into.
struct Run {
  bool quick = false;    // the reduced configuration (the check and the test suite)
  bool timed = true;     // false: register no timing jobs (the check)
  fs::path pictures;     // where its pictures go (docs/error-vs-time/)
  bench::Timings* timings = nullptr;
  std::vector<Row> rows;
  std::vector<Sheet> sheets;
  std::vector<std::pair<std::string, std::string>> pictureFiles;  // (caption, file under pictures)
  // Registers a timing job (when timed); the ticket for Row::ticket.
  size_t time(std::string name, bench::Timings::Job job);
  size_t repeat(std::string name, int repeats, std::function<void()> f);
};

struct Section {
  std::string id, effect, title, reference;
  std::vector<Metric> metrics;
  std::string timeName, settingName, noteName;
  double timeScale = 1;  // ms -> the unit shown (1000 for µs)
  std::vector<Ask> asks;
  // The paths whose change can move its times (the rendered report says when they changed
  // after the times were measured; errors are held current by the check instead).
  std::vector<std::string> code;
  // The check's tolerance on each error, relative and absolute: 0 for what the CPU computes
  // the same on every x86-64 machine; a GPU pass through llvmpipe rounds differently on
  // another CPU.
  double checkRelative = 1e-9, checkAbsolute = 1e-12;
  std::function<void(Run&)> measure;
  // Render sections: the errors of what was timed, once the timing processes are done (a
  // forked process cannot share the renderer).
  std::function<bool(Run&, effects::render::Renderer&)> afterTiming;
  std::function<std::string(const Section&, const Run&)> conclude;
};

// Every section, in report order (sections.cpp).
std::vector<Section> allSections();

// ---- shared helpers (report.cpp) ----
std::string fmt(double v, int digits = 3);
// The value at fraction f of v's order statistics (linear between them).
double quantile(std::vector<double> v, double f);
// Calls f(i) for every i in [0, n), on every core of the machine: for what a section measures
// untimed, each call writing only its own slot, so the result is the same on any number of
// cores. Its threads end before it returns: none is alive when the timing processes fork.
void onEveryCore(size_t n, const std::function<void(size_t)>& f);
// Mean and sample standard deviation.
std::pair<double, double> meanSd(const std::vector<double>& v);
// A row's error for metric `id` (NaN when not measured), and the largest over the rows.
double errorOf(const Row& r, const std::string& id);
double worstOf(const Run& run, const std::string& id);
// Render sections: a timing job for `frames` frames of `scene` after one untimed (it compiles the
// shader variants); each timing process makes its own renderer, as a forked one must.
size_t timeFrames(Run& run, const std::string& name, std::function<effects::render::Scene()> scene, int frames);
// The fastest timed row within `maxError` on metric `id` among series starting with `series`.
const Row* fastestWithin(const Run& run, const std::string& id, double maxError, const std::string& series = "");
// Whether two run times are a tie: their interquartile ranges overlap.
inline bool tie(const Row& a, const Row& b) { return a.q1 <= b.q3 && b.q1 <= a.q3; }

// The rows as data, and their comparison with committed data (report.cpp).
json rowsJson(const std::vector<Row>& rows, bool withTimes);
// Differences between `measured` and `committed` (rowsJson without times) beyond the section's
// tolerances, one line each; empty when they agree.
std::vector<std::string> differences(const Section& s, const json& measured, const json& committed);

}  // namespace report

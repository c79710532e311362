// The error-against-run-time report: each section (sections/*.cpp) measures its methods and
// settings on fixed seeds against its reference and writes its data, docs/error-vs-time/<id>.json;
// scripts/report_render.py renders docs/error-vs-time.md from them (docs/reports.md).
//
//   error_report --list                        the sections, one a line: id, effect, title
//   error_report [--section ID ...] [--out DIR] [--quick] [--meta JSON] [--command TEXT]
//                                              measures (all, or those sections) and writes DIR/<id>.json
//   error_report --check [--section ID ...] [--data DIR]
//                                              recomputes each section's errors in its quick, deterministic
//                                              configuration, untimed, and compares them with DIR/<id>.json's
//                                              "check" rows: exit 1 naming every section that moved
//
// DIR defaults to docs/error-vs-time. --quick writes the reduced configuration (the test suite
// runs it) with 2 timing processes instead of 3. --meta is scripts/report_meta.py's JSON (commit,
// date, machine), --command the command that regenerates the data (scripts/report.sh passes both).
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "report.h"

namespace {

using namespace report;

constexpr int kTimingProcesses = 3;

struct Options {
  bool list = false, check = false, quick = false;
  std::vector<std::string> only;
  fs::path dir = "docs/error-vs-time";
  json meta = json::object();
  std::string command;
};

// Times from the timing processes into the rows.
void collectTimes(Run& run, const bench::Timings& timings) {
  for (Row& r : run.rows) {
    if (r.ticket == bench::Timings::kNone) continue;
    std::vector<double> t = timings.times(r.ticket);
    for (double& x : t) x *= r.timeFactor;
    r.ms = quantile(t, 0.5), r.q1 = quantile(t, 0.25), r.q3 = quantile(t, 0.75), r.repeats = int(t.size());
    r.runMedians.clear();
    for (double m : timings.runMedians(r.ticket)) r.runMedians.push_back(m * r.timeFactor);
  }
}

json metricsJson(const Section& s) {
  json m = json::array();
  for (const Metric& x : s.metrics)
    m.push_back({{"id", x.id}, {"label", x.label}, {"name", x.name}, {"limit", std::isfinite(x.limit) ? json(x.limit) : json()},
                 {"why", x.why}, {"kind", x.kind}});
  return m;
}

json asksJson(const Section& s) {
  json a = json::array();
  for (const Ask& x : s.asks) a.push_back({{"group", x.group}, {"ask", x.ask}, {"fixed", x.fixed}});
  return a;
}

// The renderer made once, after every timing process has run (a forked process cannot share it).
effects::render::Renderer* renderer() {
  static auto r = effects::render::Renderer::create();
  if (!r.ok()) {
    std::fprintf(stderr, "error_report: %s\n", r.error().message.c_str());
    return nullptr;
  }
  return r.value().get();
}

// The section's check configuration: quick, untimed, its errors only.
bool checkRun(const Section& s, Run& run) {
  run.quick = true, run.timed = false;
  s.measure(run);
  if (!s.afterTiming) return true;
  auto* r = renderer();
  return r && s.afterTiming(run, *r);
}

int check(const std::vector<Section>& sections, const Options& o) {
  int stale = 0;
  for (const Section& s : sections) {
    effects::Stopwatch w;
    Run run;
    run.pictures = fs::temp_directory_path();
    if (!checkRun(s, run)) return 2;
    const json measured = rowsJson(run.rows, false);
    std::ifstream in(o.dir / (s.id + ".json"));
    std::vector<std::string> diff;
    if (!in) {
      diff.push_back("no committed data " + (o.dir / (s.id + ".json")).string());
    } else {
      const json committed = json::parse(in);
      diff = differences(s, measured, committed.at("check").at("rows"));
    }
    if (diff.empty()) {
      std::printf("current %-18s %zu rows as committed (%.1f s)\n", s.id.c_str(), run.rows.size(), w.ms() / 1000);
      continue;
    }
    ++stale;
    std::printf("STALE   %-18s %zu differences; first: %s\n", s.id.c_str(), diff.size(), diff.front().c_str());
    for (size_t i = 1; i < diff.size() && i < 6; ++i) std::printf("        %-18s %s\n", "", diff[i].c_str());
    std::printf("        regenerate it: scripts/report.sh --section %s\n", s.id.c_str());
  }
  return stale ? 1 : 0;
}

int write(const std::vector<Section>& sections, const Options& o) {
  if (std::system("gnuplot --version >/dev/null 2>&1") != 0) {
    std::fprintf(stderr, "error_report: gnuplot not found (Debian: gnuplot-nox; scripts/setup.sh installs it)\n");
    return 2;
  }
  fs::create_directories(o.dir);
  struct Done {
    Run run, checked;
    double seconds = 0;
  };
  std::vector<Done> done(sections.size());
  // Every section measured and timed in turn; the render sections' errors after all timing.
  for (size_t i = 0; i < sections.size(); ++i) {
    const Section& s = sections[i];
    std::fprintf(stderr, "error_report: %s\n", s.id.c_str());
    effects::Stopwatch w;
    bench::Timings timings;
    Run& run = done[i].run;
    run.quick = o.quick, run.timed = true, run.pictures = o.dir, run.timings = &timings;
    s.measure(run);
    if (!timings.run(o.quick ? 2 : kTimingProcesses)) return 1;
    collectTimes(run, timings);
    run.timings = nullptr;
    if (!s.afterTiming && !o.quick) {
      done[i].checked.pictures = fs::temp_directory_path();
      if (!checkRun(s, done[i].checked)) return 1;
    }
    done[i].seconds = w.ms() / 1000;
  }
  for (size_t i = 0; i < sections.size(); ++i) {
    const Section& s = sections[i];
    if (!s.afterTiming) continue;
    effects::Stopwatch w;
    auto* r = renderer();
    if (!r || !s.afterTiming(done[i].run, *r)) return 1;
    if (!o.quick) {
      done[i].checked.pictures = fs::temp_directory_path();
      if (!checkRun(s, done[i].checked)) return 1;
    }
    done[i].seconds += w.ms() / 1000;
  }
  for (size_t i = 0; i < sections.size(); ++i) {
    const Section& s = sections[i];
    Done& d = done[i];
    effects::Stopwatch w;
    json pictures = json::array();
    for (const auto& [caption, file] : d.run.pictureFiles) pictures.push_back({{"caption", caption}, {"file", file}});
    for (const Sheet& sheet : d.run.sheets)
      if (drawSheet(sheet, o.dir)) pictures.push_back({{"caption", sheet.caption}, {"file", sheet.id + ".png"}});
    d.seconds += w.ms() / 1000;
    json out = {{"id", s.id},
                {"effect", s.effect},
                {"title", s.title},
                {"reference", s.reference},
                {"metrics", metricsJson(s)},
                {"timeName", s.timeName},
                {"timeScale", s.timeScale},
                {"settingName", s.settingName},
                {"noteName", s.noteName},
                {"asks", asksJson(s)},
                {"code", s.code},
                {"configuration", o.quick ? "quick" : "full"},
                {"timingProcesses", o.quick ? 2 : kTimingProcesses},
                {"measuredAt", o.meta},
                {"command", o.command.empty() ? "build/bench/error_report --section " + s.id : o.command},
                {"regenerationSeconds", d.seconds},
                {"rows", rowsJson(d.run.rows, true)},
                {"conclusion", s.conclude ? s.conclude(s, d.run) : ""},
                {"pictures", pictures},
                {"check",
                 {{"configuration", "quick, untimed"},
                  {"relative", s.checkRelative},
                  {"absolute", s.checkAbsolute},
                  {"rows", rowsJson(o.quick ? d.run.rows : d.checked.rows, false)}}}};
    std::ofstream(o.dir / (s.id + ".json")) << out.dump(1) << "\n";
    std::fprintf(stderr, "error_report: %-18s regenerated in %6.1f s -> %s\n", s.id.c_str(), d.seconds,
                 (o.dir / (s.id + ".json")).c_str());
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool more = i + 1 < argc;
    if (a == "--list")
      o.list = true;
    else if (a == "--check")
      o.check = true;
    else if (a == "--quick")
      o.quick = true;
    else if (a == "--section" && more)
      o.only.push_back(argv[++i]);
    else if ((a == "--out" || a == "--data") && more)
      o.dir = argv[++i];
    else if (a == "--meta" && more)
      o.meta = json::parse(argv[++i], nullptr, false);
    else if (a == "--command" && more)
      o.command = argv[++i];
    else {
      std::fprintf(stderr,
                   "usage: error_report --list | [--section ID ...] [--out DIR] [--quick] [--meta JSON] [--command TEXT]"
                   " | --check [--section ID ...] [--data DIR]\n");
      return 2;
    }
  }
  std::vector<Section> sections;
  for (Section& s : allSections())
    if (o.only.empty() || std::find(o.only.begin(), o.only.end(), s.id) != o.only.end()) sections.push_back(std::move(s));
  if (sections.size() < std::max<size_t>(o.only.size(), 1)) {
    std::fprintf(stderr, "error_report: no such section (error_report --list names them)\n");
    return 2;
  }
  if (o.list) {
    for (const Section& s : sections) std::printf("%-18s %-10s %s\n", s.id.c_str(), s.effect.c_str(), s.title.c_str());
    return 0;
  }
  if (o.meta.is_discarded()) return std::fprintf(stderr, "error_report: --meta is not JSON\n"), 2;
  return o.check ? check(sections, o) : write(sections, o);
}

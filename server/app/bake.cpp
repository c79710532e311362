// `effectd bake EFFECT REQUEST.json -o OUT [--server URL] [--key SECRET]`: a request baked as a
// job on an effectd server (docs/api.md, "Jobs"), for work over the synchronous limits (a hero
// bolt at 1024^2): submits it (POST /v1/jobs), follows its events with a progress bar on a
// terminal (plain lines otherwise, one every 2 s), writes the answer to OUT. Ctrl-C cancels the
// job on the server (DELETE) before it exits. Exit 0 written, 1 the job or the server failed, 2
// bad arguments, 130 interrupted.
#include "app/bake.h"

#include <httplib.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>

#include <nlohmann/json.hpp>

namespace effectd {
namespace {

using nlohmann::json;

std::atomic<bool> interrupted{false};

void onInterrupt(int) { interrupted = true; }

std::string duration(double s) {
  char out[32];
  if (s < 60) std::snprintf(out, sizeof out, "%.1f s", s);
  else std::snprintf(out, sizeof out, "%d min %02d s", int(s / 60), int(std::fmod(s, 60)));
  return out;
}

// One line of progress from a job's state: the bar on a terminal, else plain text.
std::string progressLine(const json& state, bool tty) {
  const json& p = state["progress"];
  const double f = p.value("fraction", 0.0);
  std::string line;
  if (tty) {
    const int width = 30, done = int(f * width + 0.5);
    line = "[" + std::string(size_t(done), '#') + std::string(size_t(width - done), '.') + "] ";
  }
  char text[160];
  std::snprintf(text, sizeof text, "%3.0f%%  %s  %zu cells  %s running", f * 100, state.value("state", "").c_str(),
                p.value("cells", size_t(0)), duration(state.value("runningS", 0.0)).c_str());
  line += text;
  if (p.contains("etaS") && p["etaS"].is_number() && state.value("state", "") == "running")
    line += ", at least " + duration(p["etaS"].get<double>()) + " left";
  return line;
}

int usage() {
  std::fputs("usage: effectd bake EFFECT REQUEST.json -o OUT [--server http://host:port] [--key SECRET]\n"
             "  runs the request as a job on the server (default http://127.0.0.1:8080; the key also from "
             "EFFECTD_KEY)\n",
             stderr);
  return 2;
}

}  // namespace

int bakeCommand(const std::vector<std::string>& args) {
  std::string effect, requestPath, outPath, server = "http://127.0.0.1:8080";
  std::string key = std::getenv("EFFECTD_KEY") ? std::getenv("EFFECTD_KEY") : "";
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    const bool value = i + 1 < args.size();
    if ((a == "-o" || a == "--output") && value) outPath = args[++i];
    else if (a == "--server" && value) server = args[++i];
    else if (a == "--key" && value) key = args[++i];
    else if (a.rfind("--server=", 0) == 0) server = a.substr(9);
    else if (a.rfind("--key=", 0) == 0) key = a.substr(6);
    else if (effect.empty()) effect = a;
    else if (requestPath.empty()) requestPath = a;
    else return usage();
  }
  if (effect.empty() || requestPath.empty() || outPath.empty()) return usage();
  std::ifstream in(requestPath, std::ios::binary);
  if (!in) {
    std::fprintf(stderr, "effectd bake: cannot read %s\n", requestPath.c_str());
    return 2;
  }
  json request;
  try {
    request = json::parse(std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "effectd bake: %s is not JSON: %s\n", requestPath.c_str(), e.what());
    return 2;
  }

  httplib::Client client(server);
  client.set_read_timeout(60, 0);  // a quiet event stream sends a comment every 15 s
  httplib::Headers headers;
  if (!key.empty()) headers.emplace("Authorization", "Bearer " + key);
  auto failed = [&](const char* what, const httplib::Result& r) {
    if (!r) {
      std::fprintf(stderr, "effectd bake: %s: %s cannot be reached (%s)\n", what, server.c_str(),
                   httplib::to_string(r.error()).c_str());
    } else {
      std::string detail = r->body;
      try {
        detail = json::parse(r->body).value("detail", r->body);
      } catch (const std::exception&) {
      }
      std::fprintf(stderr, "effectd bake: %s: HTTP %d: %s\n", what, r->status, detail.c_str());
    }
    return 1;
  };

  const auto submitted = client.Post("/v1/jobs", headers, json{{"effect", effect}, {"request", request}}.dump(),
                                     "application/json");
  if (!submitted || submitted->status != 202) return failed("submitting the job", submitted);
  const std::string job = submitted->get_header_value("Location");
  std::fprintf(stderr, "effectd bake: job %s on %s\n", job.c_str(), server.c_str());

  struct sigaction action {};
  action.sa_handler = onInterrupt;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
  const bool tty = isatty(STDERR_FILENO);
  std::string buffer, lastEvent, finalState;
  auto lastLine = std::chrono::steady_clock::now() - std::chrono::seconds(10);
  const auto followed = client.Get(job + "/events", headers, [&](const char* data, size_t size) {
    buffer.append(data, size);
    for (size_t end; (end = buffer.find("\n\n")) != std::string::npos; buffer.erase(0, end + 2)) {
      const std::string event = buffer.substr(0, end);
      const size_t at = event.find("data: ");
      if (at == std::string::npos) continue;  // a comment that keeps the stream open
      lastEvent = event.substr(0, event.find('\n'));
      const json state = json::parse(event.substr(at + 6));
      finalState = state.value("state", "");
      const bool last = finalState == "done" || finalState == "failed" || finalState == "cancelled";
      const auto now = std::chrono::steady_clock::now();
      if (tty) {
        std::fprintf(stderr, "\r\033[K%s", progressLine(state, true).c_str());
      } else if (last || now - lastLine >= std::chrono::seconds(2)) {
        std::fprintf(stderr, "%s\n", progressLine(state, false).c_str());
        lastLine = now;
      }
    }
    return !interrupted;
  });
  if (tty) std::fputs("\n", stderr);
  if (interrupted) {
    const auto cancelled = client.Delete(job, headers);
    std::fprintf(stderr, "effectd bake: interrupted; job %s %s\n", job.c_str(),
                 cancelled && cancelled->status < 300 ? "cancelled" : "could not be cancelled");
    return 130;
  }
  if (!followed && finalState.empty()) return failed("following the job", followed);
  const auto result = client.Get(job + "/result", headers);
  if (!result || result->status != 200) return failed(("the job " + finalState).c_str(), result);
  std::ofstream out(outPath, std::ios::binary);
  out << result->body;
  if (!out.flush()) {
    std::fprintf(stderr, "effectd bake: cannot write %s\n", outPath.c_str());
    return 1;
  }
  std::fprintf(stderr, "effectd bake: %s: %zu bytes, %s, ETag %s\n", outPath.c_str(), result->body.size(),
               result->get_header_value("X-Effect-Method").c_str(), result->get_header_value("ETag").c_str());
  return 0;
}

}  // namespace effectd

// effectd: the effect-generation HTTP service.
//   effectd [serve] [flags]                          serve HTTP until SIGTERM/SIGINT
//   effectd render SCENE.json -o OUT.png [flags]     render a scene without a server
//   effectd bake EFFECT REQUEST.json -o OUT [--server URL]  a job on a server, with progress
//   effectd --help
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <memory>
#include <stdexcept>
#include <thread>

#include "contract/config.h"
#include "app/bake.h"
#include "app/endpoints.h"
#include "http/access_log.h"
#include "http/idle_trim.h"
#include "contract/json_reader.h"
#include "api/api_render.h"
#include "api/movie.h"
#include "api/scene.h"
#include "app/playground.h"
#include "http/service.h"

namespace {

// `effectd render`'s arguments: the scene, -o/--output, and the rest as flags for parseConfig.
void renderArgs(const std::vector<std::string>& args, std::string& scenePath, std::string& outPath,
                std::vector<std::string>& flags) {
  for (size_t i = 0; i < args.size(); ++i) {
    if ((args[i] == "-o" || args[i] == "--output") && i + 1 < args.size())
      outPath = args[++i];
    else if (args[i].rfind("--", 0) == 0)
      flags.push_back(args[i]);
    else if (scenePath.empty())
      scenePath = args[i];
    else
      flags.push_back(args[i]);
  }
}

// Reads the scene file as JSON; false, having said why, when it cannot.
bool readScene(const std::string& scenePath, nlohmann::json& body) {
  std::ifstream in(scenePath, std::ios::binary);
  if (!in) {
    std::fprintf(stderr, "effectd render: cannot read %s\n", scenePath.c_str());
    return false;
  }
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  try {
    body = effectd::readJson(text);
  } catch (const effectd::JsonSyntaxError& e) {
    std::fprintf(stderr, "effectd render: %s is not valid JSON: %s\n", scenePath.c_str(), e.what());
    return false;
  }
  return true;
}

// Renders a schema-valid scene into `outPath` (a PNG; with "frames" a GIF or a flipbook PNG);
// returns the exit status. What it rendered goes to stderr as one JSON line.
int renderToFile(const nlohmann::json& body, const effectd::Config& config, const std::string& outPath) {
  try {
    effectd::Animation animation;
    effects::ThreadPool pool(effects::ThreadPool::besideCaller());  // as the server's
    const effectd::RequestContext ctx{"render", config, &pool};
    effects::render::Scene scene =
        effectd::buildScene(effectd::parseRenderRequest(body, ctx), body, ctx, nullptr, &animation);
    // The file's name says what it holds: a .gif only for an animated GIF, a .png for the rest.
    const bool gif = animation.frames.count > 0 && !animation.frames.flipbook;
    auto ends = [&](const char* ext) {
      const std::string e(ext);
      if (outPath.size() < e.size()) return false;
      std::string tail = outPath.substr(outPath.size() - e.size());
      for (char& c : tail) c = char(std::tolower(static_cast<unsigned char>(c)));
      return tail == e;
    };
    if (!(gif ? ends(".gif") : ends(".png"))) {
      std::fprintf(stderr, "effectd render: %s: this scene renders %s; name the file .%s%s\n", outPath.c_str(),
                   gif ? "an animated GIF" : "a PNG", gif ? "gif" : "png",
                   gif ? "" : " (an animated GIF needs \"frames\", without \"format\": \"flipbook\")");
      return 2;
    }
    auto renderer = effects::render::Renderer::create(config.eglPlatform);
    if (!renderer.ok()) throw effectd::toApiError(renderer.error());
    auto drawn = effectd::renderScene(std::move(scene), animation, &pool,
                                      [&](effects::render::Scene s, const effects::render::Sequence* sequence) {
                                        return sequence ? renderer.value()->render(s, *sequence) : renderer.value()->render(s);
                                      });
    if (!drawn.ok()) throw effectd::toApiError(drawn.error());
    const effectd::Rendered& r = drawn.value();
    nlohmann::json said = {{"renderer", renderer.value()->description()},
                           {"passes", r.frame.passList()},
                           {"renderMs", r.frame.ms},
                           {"contentType", r.output.contentType}};
    for (const auto& [name, value] : r.output.headers) said[name] = value;
    std::ofstream out(outPath, std::ios::binary);
    out << r.output.bytes;
    if (!out.flush()) {
      std::fprintf(stderr, "effectd render: cannot write %s\n", outPath.c_str());
      return 1;
    }
    said["bytes"] = r.output.bytes.size();
    std::fprintf(stderr, "%s\n", said.dump().c_str());
    return 0;
  } catch (const effectd::ApiError& e) {
    std::fprintf(stderr, "effectd render: %s\n", e.detail.c_str());
    return e.status >= 500 || e.status == 422 ? 1 : 2;
  }
}

// `effectd render scene.json -o out.png`: the same validation, scene building and renderer
// as POST /v1/render, on this thread. Exit 0 written, 1 render failure, 2 bad input.
int renderCommand(std::vector<std::string> args) {
  std::string scenePath, outPath;
  std::vector<std::string> flags;
  renderArgs(args, scenePath, outPath, flags);
  if (scenePath.empty() || outPath.empty()) {
    std::fputs("usage: effectd render SCENE.json -o OUT.png|OUT.gif [--egl-platform=auto|device|surfaceless] [--max-*=N]\n",
               stderr);
    return 2;
  }
  effectd::Config config;
  bool help = false;
  if (std::string err = effectd::parseConfig(flags, config, help); !err.empty()) {
    std::fprintf(stderr, "effectd render: %s\n", err.c_str());
    return 2;
  }
  nlohmann::json body;
  if (!readScene(scenePath, body)) return 2;
  effectd::Service service(config);  // for its schemas; it never listens
  auto violations = service.schemas().validate("scene.json", body);
  if (!violations.empty()) {
    for (const auto& v : violations)
      std::fprintf(stderr, "effectd render: %s: %s\n", v.pointer.c_str(), v.message.c_str());
    return 2;
  }
  return renderToFile(body, config, outPath);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (!args.empty() && args.front() == "render") return renderCommand({args.begin() + 1, args.end()});
  if (!args.empty() && args.front() == "bake") return effectd::bakeCommand({args.begin() + 1, args.end()});
  if (args.size() == 1 && args.front() == "--version") {
    std::printf("effectd %s\n", effectd::buildVersion().c_str());
    return 0;
  }
  if (!args.empty() && args.front() == "serve") args.erase(args.begin());

  effectd::Config config;
  bool help = false;
  std::string err = effectd::parseConfig(args, config, help);
  if (help) {
    std::fputs(effectd::usage().c_str(), stdout);
    return 0;
  }
  if (!err.empty()) {
    std::fprintf(stderr, "effectd: %s (effectd --help lists the flags)\n", err.c_str());
    return 2;
  }

  // Block the termination signals in every thread; one thread waits for them and stops the
  // server, which finishes the requests in flight before run() returns.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGHUP);  // rereads the key files (--url-signing-key-file, --api-keys)
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  std::signal(SIGPIPE, SIG_IGN);

  effectd::IdleTrim::configureAllocator();  // freed memory kept while busy, returned when idle

  std::unique_ptr<effectd::Service> served;
  try {
    served = std::make_unique<effectd::Service>(config);
  } catch (const std::runtime_error& e) {  // a key file that cannot be read or is wrong
    std::fprintf(stderr, "effectd: %s\n", e.what());
    return 2;
  }
  effectd::Service& service = *served;
  effectd::addEffectEndpoints(service);
  if (effectd::playgroundEnabled(config)) effectd::addPlayground(service, config.playgroundThree);
  int port = service.bind();
  if (port < 0) {
    const int error = errno;
    std::fprintf(stderr, "effectd: cannot listen on %s:%d%s: %s\n", config.host.c_str(), config.port,
                 config.adminPort ? (" or its admin port " + std::to_string(config.adminPort)).c_str() : "",
                 error == EADDRINUSE ? "the port is in use (another effectd? choose one with --port)" : std::strerror(error));
    return 1;
  }
  std::fprintf(stderr,
               "{\"level\":\"info\",\"msg\":\"listening\",\"host\":\"%s\",\"port\":%d,\"adminPort\":%d,\"threads\":%d,"
               "\"playground\":%s}\n",
               config.host.c_str(), port, service.adminPort(), config.threads,
               effectd::playgroundEnabled(config) ? "true" : "false");

  std::atomic<bool> signalled{false};
  std::thread waiter([&] {
    int sig = 0;
    while (sigwait(&signals, &sig) == 0 && sig == SIGHUP) {  // connections stay open
      const std::string error = service.reloadAccess();
      std::fprintf(stderr, "{\"level\":\"%s\",\"msg\":\"%s\"%s%s}\n", error.empty() ? "info" : "error",
                   error.empty() ? "key files reread" : "key files not reread: the old keys stay",
                   error.empty() ? "" : ",\"why\":", error.empty() ? "" : effectd::jsonEscape(error).c_str());
    }
    signalled = true;
    std::fprintf(stderr, "{\"level\":\"info\",\"msg\":\"shutting down\",\"signal\":%d,\"graceS\":%d}\n", sig,
                 config.shutdownGraceS);
    // Requests being computed get --shutdown-grace to finish; past it the process exits anyway.
    std::thread([&service, grace = config.shutdownGraceS] {
      std::this_thread::sleep_for(std::chrono::seconds(grace));
      std::fprintf(stderr, "{\"level\":\"warn\",\"msg\":\"shutdown grace passed: exiting with requests in progress\","
                           "\"inFlight\":%zu}\n", service.openConnections());
      std::fflush(stderr);
      _exit(1);
    }).detach();
    service.stop();
  });
  bool ok = service.run();
  // run() can also return on its own (listen failure): wake the waiter so it can be joined.
  if (!signalled) kill(getpid(), SIGTERM);
  waiter.join();
  std::fprintf(stderr, "{\"level\":\"info\",\"msg\":\"stopped\"}\n");
  return ok ? 0 : 1;
}

// effectd: the effect-generation HTTP service.
//   effectd [serve] [flags]   serve HTTP until SIGTERM/SIGINT (in-flight requests finish)
//   effectd --help
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <thread>

#include "config.h"
#include "endpoints.h"
#include "service.h"

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (!args.empty() && args.front() == "serve") args.erase(args.begin());

  effectd::Config config;
  bool help = false;
  std::string err = effectd::parseConfig(args, config, help);
  if (help) {
    std::fputs(effectd::usage().c_str(), stdout);
    return 0;
  }
  if (!err.empty()) {
    std::fprintf(stderr, "effectd: %s\n\n%s", err.c_str(), effectd::usage().c_str());
    return 2;
  }

  // Block the termination signals in every thread; one thread waits for them and stops the
  // server, which finishes the requests in flight before run() returns.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  std::signal(SIGPIPE, SIG_IGN);

  effectd::Service service(config);
  effectd::addEffectEndpoints(service);
  int port = service.bind();
  if (port < 0) {
    std::fprintf(stderr, "effectd: cannot listen on %s:%d\n", config.host.c_str(), config.port);
    return 1;
  }
  std::fprintf(stderr, "{\"level\":\"info\",\"msg\":\"listening\",\"host\":\"%s\",\"port\":%d,\"threads\":%d}\n",
               config.host.c_str(), port, config.threads);

  std::atomic<bool> signalled{false};
  std::thread waiter([&] {
    int sig = 0;
    sigwait(&signals, &sig);
    signalled = true;
    std::fprintf(stderr, "{\"level\":\"info\",\"msg\":\"shutting down\",\"signal\":%d}\n", sig);
    service.stop();
  });
  bool ok = service.run();
  // run() can also return on its own (listen failure): wake the waiter so it can be joined.
  if (!signalled) kill(getpid(), SIGTERM);
  waiter.join();
  std::fprintf(stderr, "{\"level\":\"info\",\"msg\":\"stopped\"}\n");
  return ok ? 0 : 1;
}

// Server configuration: embedded defaults, overridden by environment variables
// (EFFECTD_HOST, EFFECTD_PORT, ...), overridden by command-line flags (--host, --port, ...).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include <effects/lightning.h>

namespace effectd {

struct Limits {
  size_t maxBodyBytes = 16u << 20;          // request body (and a GET's decoded ?r=)
  size_t maxUrlBytes = 8192;                // a GET's path and query
  // Lightning's bounds, with the library's defaults (effects::lightning::Limits).
  size_t maxGridCells = effects::lightning::Limits{}.maxGridCells;
  size_t maxGrowthSteps = effects::lightning::Limits{}.maxGrowthSteps;
  size_t maxSolverGridCells = effects::lightning::Limits{}.maxSolverGridCells;
  size_t maxSolverVolumeCells = effects::lightning::Limits{}.maxSolverVolumeCells;
  // The flags that raise the solver bounds where these limits apply (a job's: --max-job-*, set by
  // Service::installJobs), and whether a request past them may go as a job instead, whose bounds
  // are the Config's maxJob* (the synchronous routes: their 413 says so).
  const char* solverGridKnob = "--max-solver-grid-cells";
  const char* solverVolumeKnob = "--max-solver-volume-cells";
  bool jobsTakeMore = true;
  size_t maxTableSize = 65536;              // fog table entries (all dimensions together)
  size_t maxMeshVertices = 2'000'000;       // tangents / bubble meshes
  size_t maxMeshTriangles = 4'000'000;
  size_t maxRenderPixels = 4096u * 4096u;    // render width*height, and decoded background images
  size_t maxThinFilmTexels = 1024u * 1024u;  // bubble thin-film table width*height
};

struct Config {
  std::string host = "127.0.0.1";
  int port = 8080;
  int threads = 8;           // HTTP threads kept ready
  int maxConnections = 512;  // connections served at once (one thread each); more get 503 at once
  int adminPort = 0;         // /healthz, /readyz and /metrics on their own listener; 0 = none
  std::string adminHost;     // its address; empty = host
  int shutdownGraceS = 20;   // SIGTERM: longest wait for requests being computed, then exit
  int readTimeoutS = 10;     // a request's headers and body, all of them
  int writeTimeoutS = 10;
  int keepAliveTimeoutS = 5;
  int keepAliveMaxCount = 100;
  bool accessLog = true;
  int renderThreads = 2;                 // render pool: threads, one EGL context each
  int renderQueue = 8;                   // renders waiting beyond the running ones; more -> 503
  std::string eglPlatform;               // auto | device | surfaceless; "" = EFFECTD_EGL_PLATFORM or auto
  size_t memoryBudgetMb = 0;             // 0 = kDefaultBudgetFraction of the cgroup limit or physical memory
  int heavyThreads = 0;                  // heavy computations at once; 0 = cores - 1 (at least 1)
  int admissionQueue = 64;               // requests waiting for memory or a heavy slot; more -> 503
  int admissionTimeoutMs = 10000;        // longest wait for admission before 503
  size_t responseCacheMb = 64;           // encoded answers kept for repeats; 0 = off
  int cacheMaxAgeS = 3600;               // Cache-Control max-age of GET answers (CDNs, browsers)
  std::string urlSigningKeyFile;         // "" = GETs need no signature
  std::string apiKeysFile;               // "" = no API keys: the service is open
  std::string quotaRedis;                // redis://host:port: quotas shared by replicas; "" = per process
  int keyMaxConcurrent = 8;              // an API key's requests in progress at once (per replica)
  // Event streams (GET /v1/jobs/{id}/events) held at once (http/streams.h): an API key's (the
  // key file's maxStreams wins), a keyless client address's (0 = no limit: behind a proxy that
  // limits them), and all of them (0 = a quarter of maxConnections).
  int keyMaxStreams = 8;
  int maxStreamsPerAddress = 8;
  int maxStreams = 0;
  // Jobs (POST /v1/jobs, Prefer: respond-async; server/http/jobs.h): the work's own limits.
  int jobWorkers = 1;                    // jobs running at once
  size_t maxJobGridCells = size_t(1024) * 1024;        // dbm and charges grids in a job (2-D)
  size_t maxJobVolumeCells = size_t(128) * 128 * 128;  // dbm grids in a job (3-D)
  int maxJobs = 256;                     // jobs kept at once, in any state
  int jobTtlS = 3600;                    // a finished job (and its answer) is kept this long
  size_t jobStoreMb = 256;               // queued requests and kept answers of jobs at once
  int keyMaxJobs = 2;                    // an API key's jobs queued or running at once
  std::string jobsRedis;                 // redis://host:port: jobs shared by replicas; "" = in this process
  std::vector<std::string> corsOrigins;  // allowed browser origins; {"*"} = any; empty = no CORS
  std::string playground = "auto";       // auto | on | off: the page at /; auto = on for loopback hosts
  // three.js's ES module the playground's live view imports (it draws through clients/three/);
  // "" = the copy built into this binary, served at /playground/three.module.js.
  std::string playgroundThree;
  Limits limits;
};

// Parses argv (after the program name and an optional sub-command) on top of the
// environment on top of the defaults. Returns "" on success, otherwise the message to print.
// Sets `help` when --help was given.
std::string parseConfig(const std::vector<std::string>& args, Config& config, bool& help);

std::string usage();

// Whether / serves the browser playground. "auto" turns it on only when the server listens on
// loopback: there the only visitor is the developer at that machine. Bound elsewhere, a page
// that lets anyone who can reach the port start renders is the operator's decision to make.
bool playgroundEnabled(const Config& config);

// This build: the project version and the hash of the sources it was built from (effectd
// --version; part of every ETag, since a new build may answer differently).
std::string buildVersion();

}  // namespace effectd

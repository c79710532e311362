#include "contract/config.h"

#include <effects/fog.h>

#include <algorithm>
#include <cstdlib>
#include <functional>
#include <limits>
#include <sstream>

namespace effectd {
namespace {

struct Option {
  const char* flag;  // without the leading "--"
  const char* env;
  const char* help;
  std::function<bool(const std::string&, Config&)> set;
};

bool parseInt(const std::string& s, long long lo, long long hi, long long& out) {
  if (s.empty()) return false;
  char* end = nullptr;
  errno = 0;
  long long v = std::strtoll(s.c_str(), &end, 10);
  if (errno || *end != '\0' || v < lo || v > hi) return false;
  out = v;
  return true;
}

template <class T>
std::function<bool(const std::string&, Config&)> intField(T Config::*field, long long lo, long long hi) {
  return [=](const std::string& s, Config& c) {
    long long v;
    if (!parseInt(s, lo, hi, v)) return false;
    c.*field = static_cast<T>(v);
    return true;
  };
}

std::function<bool(const std::string&, Config&)> limitField(size_t Limits::*field, long long lo, long long hi) {
  return [=](const std::string& s, Config& c) {
    long long v;
    if (!parseInt(s, lo, hi, v)) return false;
    c.limits.*field = static_cast<size_t>(v);
    return true;
  };
}

// A file's path, taken as given (the file is read, and its errors named, when the server starts).
std::function<bool(const std::string&, Config&)> pathField(std::string Config::*field) {
  return [=](const std::string& s, Config& c) {
    c.*field = s;
    return true;
  };
}

// --cors-origins: a comma list of origins (scheme://host[:port]) or "*"; spaces around an
// entry and trailing slashes are dropped.
bool setCorsOrigins(const std::string& s, Config& c) {
  c.corsOrigins.clear();
  size_t pos = 0;
  while (pos <= s.size()) {
    size_t end = std::min(s.find(',', pos), s.size());
    std::string o = s.substr(pos, end - pos);
    while (!o.empty() && o.front() == ' ') o.erase(0, 1);
    while (!o.empty() && (o.back() == ' ' || o.back() == '/')) o.pop_back();
    if (!o.empty()) {
      if (o != "*" && o.find("://") == std::string::npos) return false;
      c.corsOrigins.push_back(o);
    }
    pos = end + 1;
  }
  return true;
}

// Long because it is the flag table, one entry per flag in --help order: it reads best whole.
const std::vector<Option>& options() {
  static const std::vector<Option> opts = {
      {"host", "EFFECTD_HOST", "address to listen on (default 127.0.0.1)",
       [](const std::string& s, Config& c) {
         c.host = s;
         return !s.empty();
       }},
      {"port", "EFFECTD_PORT", "TCP port, 0 = any free port (default 8080)", intField(&Config::port, 0, 65535)},
      {"threads", "EFFECTD_THREADS", "HTTP worker threads kept ready (default 8)", intField(&Config::threads, 1, 1024)},
      {"max-connections", "EFFECTD_MAX_CONNECTIONS",
       "connections served at once, one thread each, growing from --threads (default 512); slow clients cannot starve "
       "the rest below it, and past it a new connection gets 503 at once",
       intField(&Config::maxConnections, 1, 65536)},
      {"admin-port", "EFFECTD_ADMIN_PORT",
       "TCP port of an operations listener on --host serving /healthz, /readyz and /metrics, answered even when the "
       "public port is full; /metrics then leaves the public port (default 0 = none)",
       intField(&Config::adminPort, 0, 65535)},
      {"admin-host", "EFFECTD_ADMIN_HOST",
       "address of the --admin-port listener, for effectd on loopback behind a proxy with its operations reachable "
       "from the cluster (default: --host)",
       [](const std::string& s, Config& c) {
         c.adminHost = s;
         return !s.empty();
       }},
      {"shutdown-grace", "EFFECTD_SHUTDOWN_GRACE",
       "seconds SIGTERM waits for requests being computed; connections idle or still sending close at once (default 20)",
       intField(&Config::shutdownGraceS, 0, 3600)},
      {"read-timeout", "EFFECTD_READ_TIMEOUT",
       "seconds to receive a whole request, headers and body, from its first byte; later: 408 (default 10)",
       intField(&Config::readTimeoutS, 1, 3600)},
      {"write-timeout", "EFFECTD_WRITE_TIMEOUT", "seconds to send a response (default 10)",
       intField(&Config::writeTimeoutS, 1, 3600)},
      {"keep-alive-timeout", "EFFECTD_KEEP_ALIVE_TIMEOUT",
       "idle seconds before a keep-alive connection closes (default 5)", intField(&Config::keepAliveTimeoutS, 0, 3600)},
      {"keep-alive-max", "EFFECTD_KEEP_ALIVE_MAX", "requests per connection (default 100)",
       intField(&Config::keepAliveMaxCount, 1, 1000000)},
      {"access-log", "EFFECTD_ACCESS_LOG", "1/0: one JSON line per request on stderr (default 1)",
       [](const std::string& s, Config& c) {
         if (s != "0" && s != "1" && s != "true" && s != "false") return false;
         c.accessLog = s == "1" || s == "true";
         return true;
       }},
      {"max-body-bytes", "EFFECTD_MAX_BODY_BYTES", "largest request body, and a GET's decoded ?r= (default 16777216)",
       limitField(&Limits::maxBodyBytes, 1024, 1LL << 32)},
      {"max-url-bytes", "EFFECTD_MAX_URL_BYTES",
       "longest GET path and query; longer gets 414 (default and most 8192: cpp-httplib's compiled limit)",
       limitField(&Limits::maxUrlBytes, 256, 8192)},
      {"max-grid-cells", "EFFECTD_MAX_GRID_CELLS", "largest lightning grid, width*height (default 16777216)",
       limitField(&Limits::maxGridCells, 9, 1LL << 28)},
      {"max-growth-steps", "EFFECTD_MAX_GROWTH_STEPS", "lightning cells added per request (default 2000000)",
       limitField(&Limits::maxGrowthSteps, 1, 1LL << 30)},
      {"max-solver-grid-cells", "EFFECTD_MAX_SOLVER_GRID_CELLS",
       "largest grid for the dbm and charges methods, whose every step costs O(cells) (default 65536)",
       limitField(&Limits::maxSolverGridCells, 9, 1LL << 28)},
      {"max-solver-volume-cells", "EFFECTD_MAX_SOLVER_VOLUME_CELLS",
       "largest 3-D grid (width*height*depth) for method dbm (default 262144 = 64^3)",
       limitField(&Limits::maxSolverVolumeCells, 27, 1LL << 28)},
      {"max-table-size", "EFFECTD_MAX_TABLE_SIZE", "fog table entries (default 65536)",
       limitField(&Limits::maxTableSize, 2, effects::fog::kMaxTableEntries)},
      {"max-mesh-vertices", "EFFECTD_MAX_MESH_VERTICES", "vertices per mesh (default 2000000)",
       limitField(&Limits::maxMeshVertices, 3, 1LL << 28)},
      {"max-mesh-triangles", "EFFECTD_MAX_MESH_TRIANGLES", "triangles per mesh (default 4000000)",
       limitField(&Limits::maxMeshTriangles, 1, 1LL << 28)},
      {"max-render-pixels", "EFFECTD_MAX_RENDER_PIXELS",
       "render width*height and decoded image pixels (default 16777216)",
       limitField(&Limits::maxRenderPixels, 1, 1LL << 28)},
      {"max-thin-film-texels", "EFFECTD_MAX_THIN_FILM_TEXELS", "bubble thin-film table width*height (default 1048576)",
       limitField(&Limits::maxThinFilmTexels, 4, 1LL << 26)},
      {"render-threads", "EFFECTD_RENDER_THREADS", "render threads, one EGL context each (default 2)",
       intField(&Config::renderThreads, 1, 64)},
      {"render-queue", "EFFECTD_RENDER_QUEUE", "renders waiting beyond the running ones before 503 (default 8)",
       intField(&Config::renderQueue, 0, 10000)},
      {"egl-platform", "EFFECTD_EGL_PLATFORM", "auto (device, then surfaceless), device or surfaceless (default auto)",
       [](const std::string& s, Config& c) {
         c.eglPlatform = s;
         return s == "auto" || s == "device" || s == "surfaceless";
       }},
      {"memory-budget-mb", "EFFECTD_MEMORY_BUDGET_MB",
       "memory all requests together may reserve at their estimated peaks; beyond it they wait, then 503 "
       "(default 0 = 60 % of the cgroup memory limit, or of physical memory without one)",
       intField(&Config::memoryBudgetMb, 0, 1LL << 22)},
      {"heavy-threads", "EFFECTD_HEAVY_THREADS",
       "heavy computations (Laplace solvers, huge grids and meshes) at once, so cheap requests keep a core "
       "(default 0 = cores - 1, at least 1)",
       intField(&Config::heavyThreads, 0, 1024)},
      {"admission-queue", "EFFECTD_ADMISSION_QUEUE",
       "requests waiting for memory or a heavy slot before 503 (default 64)",
       intField(&Config::admissionQueue, 0, 100000)},
      {"admission-timeout-ms", "EFFECTD_ADMISSION_TIMEOUT_MS",
       "longest wait for memory or a heavy slot before 503 (default 10000)",
       intField(&Config::admissionTimeoutMs, 0, 3600000)},
      {"response-cache-mb", "EFFECTD_RESPONSE_CACHE_MB",
       "encoded answers kept to serve repeats (LRU, by ETag); 0 = off (default 64)",
       intField(&Config::responseCacheMb, 0, 1LL << 20)},
      {"cache-max-age", "EFFECTD_CACHE_MAX_AGE",
       "seconds a CDN or browser may reuse a GET answer without asking again (Cache-Control: public, max-age); after "
       "an upgrade that changes answers, caches revalidate within it (default 3600)",
       intField(&Config::cacheMaxAgeS, 0, 31536000)},
      {"url-signing-key-file", "EFFECTD_URL_SIGNING_KEY_FILE",
       "file of URL signing keys, one per line (two during a rotation): every GET must then carry sig, the base64url "
       "HMAC-SHA256 of its path and query (docs/serving.md); SIGHUP rereads it (default none)",
       pathField(&Config::urlSigningKeyFile)},
      {"api-keys", "EFFECTD_API_KEYS",
       "JSON file of API keys with quotas ({\"keys\": [{\"id\", \"sha256\", \"perMinute\", \"burst\", "
       "\"endpoints\"}]}): POSTs and unsigned GETs then need Authorization: Bearer <secret>; SIGHUP rereads it "
       "(default none: open)",
       pathField(&Config::apiKeysFile)},
      {"quota-redis", "EFFECTD_QUOTA_REDIS",
       "redis://[[user]:password@]host:port holding the API keys' quotas, so that they hold across replicas; unreachable, each process "
       "falls back to its own buckets (default none: per process)",
       [](const std::string& s, Config& c) {
         c.quotaRedis = s;
         return s.empty() || s.rfind("redis://", 0) == 0;
       }},
      {"key-max-concurrent", "EFFECTD_KEY_MAX_CONCURRENT",
       "an API key's requests in progress at once on this replica; more get 429 before their body is read (the key "
       "file's maxConcurrent wins) (default 8)",
       intField(&Config::keyMaxConcurrent, 1, 100000)},
      {"key-max-streams", "EFFECTD_KEY_MAX_STREAMS",
       "an API key's job event streams held at once on this replica; more get 429 (the key file's maxStreams wins) "
       "(default 8)",
       intField(&Config::keyMaxStreams, 1, 100000)},
      {"max-streams-per-address", "EFFECTD_MAX_STREAMS_PER_ADDRESS",
       "job event streams one client address holds at once when it sends no API key; more get 429; 0 = no limit, "
       "for a server behind a proxy that limits them, which all its clients reach it through (default 8)",
       intField(&Config::maxStreamsPerAddress, 0, 100000)},
      {"max-streams", "EFFECTD_MAX_STREAMS",
       "job event streams held at once in all, each on a connection and a thread of its own beyond "
       "--max-connections; more get 503; 0 = a quarter of --max-connections (default 0)",
       intField(&Config::maxStreams, 0, 65536)},
      {"job-workers", "EFFECTD_JOB_WORKERS", "jobs (POST /v1/jobs, Prefer: respond-async) running at once (default 1)",
       intField(&Config::jobWorkers, 1, 64)},
      {"max-job-grid-cells", "EFFECTD_MAX_JOB_GRID_CELLS",
       "largest grid for the dbm and charges methods in a job, in place of --max-solver-grid-cells (default 1048576 "
       "= 1024^2)",
       intField(&Config::maxJobGridCells, 9, 1LL << 30)},
      {"max-job-volume-cells", "EFFECTD_MAX_JOB_VOLUME_CELLS",
       "largest 3-D grid for method dbm in a job, in place of --max-solver-volume-cells (default 2097152 = 128^3)",
       intField(&Config::maxJobVolumeCells, 27, 1LL << 30)},
      {"max-jobs", "EFFECTD_MAX_JOBS", "jobs kept at once, in any state; more get 503 (default 256)",
       intField(&Config::maxJobs, 1, 1000000)},
      {"job-ttl", "EFFECTD_JOB_TTL", "seconds a finished job and its answer are kept (default 3600)",
       intField(&Config::jobTtlS, 1, 30 * 86400)},
      {"job-store-mb", "EFFECTD_JOB_STORE_MB",
       "queued jobs' requests and finished jobs' answers kept at once; past it the oldest answers are dropped, and "
       "a job whose request does not fit gets 503 (default 256)",
       intField(&Config::jobStoreMb, 1, 1LL << 20)},
      {"key-max-jobs", "EFFECTD_KEY_MAX_JOBS", "an API key's jobs queued or running at once; more get 429 (default 2)",
       intField(&Config::keyMaxJobs, 1, 100000)},
      {"jobs-redis", "EFFECTD_JOBS_REDIS",
       "redis://[[user]:password@]host:port holding the jobs (queue, states, progress, answers), so that every replica sharing it answers "
       "any job and idle ones take queued work; unreachable, the job routes answer 503 (default none: jobs in this "
       "process)",
       [](const std::string& s, Config& c) {
         c.jobsRedis = s;
         return s.empty() || s.rfind("redis://", 0) == 0;
       }},
      {"cors-origins", "EFFECTD_CORS_ORIGINS",
       "browser origins allowed to call the API: comma list (https://a.example,http://localhost:5173) or * (default "
       "none)",
       setCorsOrigins},
      {"playground", "EFFECTD_PLAYGROUND",
       "auto|on|off: the browser playground at / (default auto: on when listening on loopback only)",
       [](const std::string& s, Config& c) {
         if (s == "1" || s == "true") c.playground = "on";
         else if (s == "0" || s == "false") c.playground = "off";
         else if (s == "auto" || s == "on" || s == "off") c.playground = s;
         else return false;
         return true;
       }},
      {"playground-three", "EFFECTD_PLAYGROUND_THREE",
       "URL of three.js's ES module (three.module.js, r187) for the playground's live view, instead of the copy "
       "built in; the page imports it as a module, so its server must send Access-Control-Allow-Origin (default "
       "none: the built-in copy, from this server's own origin)",
       [](const std::string& s, Config& c) {
         // http(s) or "" (the built-in copy), and nothing that could leave the JavaScript string
         // or the CSP it is put in.
         const bool scheme = s.empty() || s.rfind("https://", 0) == 0 || s.rfind("http://", 0) == 0;
         if (!scheme || s.find_first_of(" \t\r\n'\"\\<>;`") != std::string::npos) return false;
         c.playgroundThree = s;
         return true;
       }},
  };
  return opts;
}

}  // namespace

std::string usage() {
  std::ostringstream os;
  os << "usage: effectd [serve] [--flag=value ...]          serve HTTP until SIGTERM/SIGINT\n"
        "       effectd render SCENE.json -o OUT.png [--egl-platform=...] [--max-*=N]\n"
        "                                                   render a /v1/render scene to a PNG, no server\n"
        "       effectd bake EFFECT REQUEST.json -o OUT [--server URL] [--key SECRET]\n"
        "                                                   run a request as a job on a server, with progress\n"
        "       effectd --help | --version\n\n"
        "Flags (environment variable in brackets; flags win over the environment):\n";
  for (const auto& o : options()) os << "  --" << o.flag << " [" << o.env << "]\n      " << o.help << "\n";
  return os.str();
}

bool playgroundEnabled(const Config& config) {
  if (config.playground != "auto") return config.playground == "on";
  const std::string& h = config.host;
  return h == "localhost" || h == "::1" || h == "[::1]" || h.rfind("127.", 0) == 0;
}

std::string parseConfig(const std::vector<std::string>& args, Config& config, bool& help) {
  help = false;
  for (const auto& o : options()) {
    if (const char* v = std::getenv(o.env)) {
      if (!o.set(v, config)) return std::string("invalid value for ") + o.env + ": '" + v + "'";
    }
  }
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--help" || a == "-h") {
      help = true;
      return "";
    }
    if (a.rfind("--", 0) != 0) return "unexpected argument '" + a + "'";
    std::string name = a.substr(2), value;
    auto eq = name.find('=');
    if (eq != std::string::npos) {
      value = name.substr(eq + 1);
      name = name.substr(0, eq);
    }
    const auto option = std::find_if(options().begin(), options().end(), [&](const Option& o) { return name == o.flag; });
    if (option == options().end()) return "unknown flag --" + name;
    if (eq == std::string::npos) {
      if (i + 1 >= args.size()) return "flag --" + name + " needs a value";
      value = args[++i];
    }
    if (!option->set(value, config)) return "invalid value for --" + name + ": '" + value + "'";
  }
  return "";
}

std::string buildVersion() { return EFFECTD_VERSION; }

}  // namespace effectd

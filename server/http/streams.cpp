#include "http/streams.h"

namespace effectd {

std::optional<ApiError> Streams::enter(const std::string& client, int most, const std::string& whose,
                                       std::shared_ptr<void>& place) {
  {
    std::lock_guard lock(mu_);
    auto it = held_.find(client);
    const int mine = it == held_.end() ? 0 : it->second;
    if (most > 0 && mine >= most) {
      ++refusedClient_;
      if (client.rfind("key ", 0) == 0) ++refusedByKey_[client.substr(4)];
      return ApiError{429,
                      "too-many-streams",
                      "Too Many Requests",
                      whose + " holds " + std::to_string(mine) + " event streams, the most it may: close one, or poll "
                                  "the job's status instead",
                      {},
                      {{"Retry-After", "5"}, {"Cache-Control", "no-store"}, {"Connection", "close"}}};
    }
    if (all_ >= size_t(total_)) {
      ++refusedTotal_;
      return ApiError{503,
                      "overloaded",
                      "Service Unavailable",
                      "the server holds all the event streams it serves at once (--max-streams): poll the job's "
                      "status instead, or follow it later",
                      {},
                      {{"Retry-After", "5"}, {"Cache-Control", "no-store"}, {"Connection", "close"}}};
    }
    ++held_[client];
    ++all_;
  }
  place = std::shared_ptr<void>(nullptr, [this, client](void*) {
    std::lock_guard lock(mu_);
    if (--held_[client] <= 0) held_.erase(client);
    --all_;
  });
  return std::nullopt;
}

Streams::Counts Streams::counts() const {
  std::lock_guard lock(mu_);
  return {all_, refusedClient_, refusedTotal_};
}

std::string Streams::metricsText() const {
  const Counts c = counts();
  std::string byKey =
      "# HELP effectd_key_streams_refused_total Event streams refused to an API key past its share (429).\n"
      "# TYPE effectd_key_streams_refused_total counter\n";
  {
    std::lock_guard lock(mu_);
    for (const auto& [id, n] : refusedByKey_)
      byKey += "effectd_key_streams_refused_total{key=\"" + id + "\"} " + std::to_string(n) + "\n";
  }
  return byKey + "# HELP effectd_streams_held Event streams being served (GET /v1/jobs/{id}/events).\n"
         "# TYPE effectd_streams_held gauge\n"
         "effectd_streams_held " + std::to_string(c.held) + "\n" +
         "# HELP effectd_streams_refused_total Event streams refused, by reason: the client's own share "
         "(an API key's maxStreams or --key-max-streams, else --max-streams-per-address: 429) or all of them "
         "(--max-streams: 503).\n# TYPE effectd_streams_refused_total counter\n"
         "effectd_streams_refused_total{reason=\"client\"} " + std::to_string(c.refusedClient) + "\n" +
         "effectd_streams_refused_total{reason=\"total\"} " + std::to_string(c.refusedTotal) + "\n";
}

}  // namespace effectd

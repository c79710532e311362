// A bounded LRU of encoded answers. Answers are deterministic (the same request gives the
// same bytes), so an answer is stored once per representation — its strong ETag, which names
// the canonical request and the coding — and found again either by that tag or, before any
// parsing, by the exact request bytes that produced it (an alias: route, coding and body).
// Thread-safe; entries are shared, immutable, and stay alive while a response still sends one.
#pragma once

#include <cstdint>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <unordered_map>

namespace effectd {

struct CachedAnswer {
  std::string etag;  // the representation's strong ETag
  std::string contentType;
  std::string contentEncoding;                 // "" = identity
  std::string body;                            // encoded bytes as sent
  std::map<std::string, std::string> headers;  // representation headers (X-Effect-Method, ...)
  size_t bytes() const;
};

class ResponseCache {
 public:
  explicit ResponseCache(size_t maxBytes) : maxBytes_(maxBytes) {}
  bool enabled() const { return maxBytes_ > 0; }
  // Request bytes longer than this are never used as alias keys (the tag still finds them).
  static constexpr size_t kMaxAliasKeyBytes = 64 << 10;

  std::shared_ptr<const CachedAnswer> byTag(const std::string& etag);
  std::shared_ptr<const CachedAnswer> byRequest(const std::string& requestKey);
  // Stores `answer` under its tag and, when given, `requestKey` as an alias of it. An answer
  // larger than an eighth of the cache is not stored (it would evict everything else).
  void put(std::shared_ptr<const CachedAnswer> answer, const std::string& requestKey);
  // Adds `requestKey` as an alias of an answer already stored under `etag`.
  void alias(const std::string& requestKey, const std::string& etag);

  struct Counts {
    uint64_t hits = 0, misses = 0, evictions = 0;
    size_t bytes = 0, entries = 0;
  };
  Counts counts() const;

 private:
  struct Node {
    std::string key;                             // "t" + etag or "r" + request key
    std::shared_ptr<const CachedAnswer> answer;  // for tag nodes
    std::string target;                          // for alias nodes: the etag
    size_t bytes = 0;
  };
  using List = std::list<Node>;
  std::shared_ptr<const CachedAnswer> find(const std::string& key);  // mu_ held
  void insert(Node node);                                            // mu_ held
  void evict();                                                      // mu_ held

  const size_t maxBytes_;
  mutable std::mutex mu_;
  List lru_;  // front = most recent
  std::unordered_map<std::string, List::iterator> index_;
  Counts counts_;
};

}  // namespace effectd

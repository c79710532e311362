#include "http/response_cache.h"

namespace effectd {

namespace {
constexpr size_t kNodeOverhead = 160;  // list node, index entry, shared_ptr control block
}

size_t CachedAnswer::bytes() const {
  size_t n = sizeof(CachedAnswer) + etag.size() + contentType.size() + contentEncoding.size() + body.size();
  for (const auto& [k, v] : headers) n += k.size() + v.size() + 64;
  return n;
}

std::shared_ptr<const CachedAnswer> ResponseCache::find(const std::string& key) {
  auto it = index_.find(key);
  if (it == index_.end()) return nullptr;
  lru_.splice(lru_.begin(), lru_, it->second);
  const Node& node = *it->second;
  if (node.answer) return node.answer;
  auto target = index_.find("t" + node.target);  // an alias whose answer may be gone
  if (target == index_.end()) return nullptr;
  lru_.splice(lru_.begin(), lru_, target->second);
  return target->second->answer;
}

std::shared_ptr<const CachedAnswer> ResponseCache::byTag(const std::string& etag) {
  if (!enabled()) return nullptr;
  std::lock_guard<std::mutex> lock(mu_);
  auto a = find("t" + etag);
  ++(a ? counts_.hits : counts_.misses);
  return a;
}

std::shared_ptr<const CachedAnswer> ResponseCache::byRequest(const std::string& requestKey) {
  if (!enabled() || requestKey.size() > kMaxAliasKeyBytes) return nullptr;
  std::lock_guard<std::mutex> lock(mu_);
  auto a = find("r" + requestKey);
  if (a) ++counts_.hits;  // a miss here is counted when the tag is looked up
  return a;
}

void ResponseCache::insert(Node node) {
  auto it = index_.find(node.key);
  if (it != index_.end()) {
    counts_.bytes -= it->second->bytes;
    lru_.erase(it->second);
    index_.erase(it);
  }
  counts_.bytes += node.bytes;
  lru_.push_front(std::move(node));
  index_[lru_.front().key] = lru_.begin();
  evict();
}

void ResponseCache::evict() {
  while (counts_.bytes > maxBytes_ && !lru_.empty()) {
    counts_.bytes -= lru_.back().bytes;
    index_.erase(lru_.back().key);
    lru_.pop_back();
    ++counts_.evictions;
  }
}

void ResponseCache::put(std::shared_ptr<const CachedAnswer> answer, const std::string& requestKey) {
  if (!enabled() || answer->bytes() > maxBytes_ / 8) return;
  std::lock_guard<std::mutex> lock(mu_);
  const std::string etag = answer->etag;
  Node tag{"t" + etag, std::move(answer), "", 0};
  tag.bytes = tag.key.size() + tag.answer->bytes() + kNodeOverhead;
  insert(std::move(tag));
  if (!requestKey.empty() && requestKey.size() <= kMaxAliasKeyBytes) {
    Node alias{"r" + requestKey, nullptr, etag, 0};
    alias.bytes = alias.key.size() + etag.size() + kNodeOverhead;
    insert(std::move(alias));
  }
}

void ResponseCache::alias(const std::string& requestKey, const std::string& etag) {
  if (!enabled() || requestKey.empty() || requestKey.size() > kMaxAliasKeyBytes) return;
  std::lock_guard<std::mutex> lock(mu_);
  Node alias{"r" + requestKey, nullptr, etag, 0};
  alias.bytes = alias.key.size() + etag.size() + kNodeOverhead;
  insert(std::move(alias));
}

ResponseCache::Counts ResponseCache::counts() const {
  std::lock_guard<std::mutex> lock(mu_);
  Counts c = counts_;
  c.entries = lru_.size();
  return c;
}

}  // namespace effectd

#include "map_cache.h"

#include <algorithm>
#include <cstring>
#include <list>
#include <mutex>

namespace effects::lightning::detail {

std::vector<uint64_t> obstacleBits(const std::vector<uint8_t>& obstacles) {
  std::vector<uint64_t> bits((obstacles.size() + 63) / 64, 0);
  uint64_t any = 0;
  for (size_t i = 0; i < obstacles.size(); i += 8) {
    uint64_t v = 0;
    std::memcpy(&v, obstacles.data() + i, std::min<size_t>(8, obstacles.size() - i));
    // 0x80 in each non-zero byte, then byte k's to bit k (the products do not overlap).
    const uint64_t nonzero = (((v & 0x7f7f7f7f7f7f7f7full) + 0x7f7f7f7f7f7f7f7full) | v) & 0x8080808080808080ull;
    const uint64_t byte = ((nonzero >> 7) * 0x0102040810204080ull) >> 56;
    bits[i / 64] |= byte << (i % 64);
    any |= byte;
  }
  if (!any) bits.clear();
  return bits;
}

std::shared_ptr<const void> cachedMap(int width, int height, int depth, const std::vector<uint64_t>& obstacleKey,
                                      bool* hit, const std::function<std::shared_ptr<const void>()>& build,
                                      size_t (*mapBytes)(const void*)) {
  // Least recently used first out, bounded in bytes (maps and their keys); 2-D and 3-D maps
  // share the budget.
  struct Entry {
    int w, h, d;
    std::vector<uint64_t> key;
    std::shared_ptr<const void> map;
    size_t mapBytes;
    size_t bytes() const { return key.size() * sizeof(uint64_t) + mapBytes; }
  };
  static std::mutex mu;
  static std::list<Entry> lru;  // most recent first
  constexpr size_t kBudgetBytes = size_t(64) << 20;
  {
    std::lock_guard<std::mutex> lock(mu);
    for (auto it = lru.begin(); it != lru.end(); ++it) {
      if (it->w == width && it->h == height && it->d == depth && it->key == obstacleKey) {
        lru.splice(lru.begin(), lru, it);
        if (hit) *hit = true;
        return lru.front().map;
      }
    }
  }
  if (hit) *hit = false;
  std::shared_ptr<const void> map = build();  // built outside the lock
  Entry entry{width, height, depth, obstacleKey, map, mapBytes(map.get())};
  if (entry.bytes() > kBudgetBytes) return map;  // used by this request only
  std::lock_guard<std::mutex> lock(mu);
  lru.push_front(std::move(entry));
  size_t total = 0;
  for (auto it = lru.begin(); it != lru.end();) {
    total += it->bytes();
    if (total > kBudgetBytes)
      it = lru.erase(it);
    else
      ++it;
  }
  return map;
}

}  // namespace effects::lightning::detail

// Welding (internal to effects/tangents/): rep[i] = the first index whose key equals key(i)
// (N floats, compared as floats, so -0 == +0). Open addressing over the indices themselves,
// no per-entry allocation; keys are made again where compared rather than stored (a stored
// copy was 32 bytes a vertex of fresh memory to fault in).
#pragma once

#include <array>
#include <cstdint>
#include <cstring>
#include <vector>

namespace effects::tangents {

template <int N, class KeyFn>
std::vector<uint32_t> weld(size_t count, KeyFn key) {
  size_t cap = 16;
  while (cap < 2 * count) cap <<= 1;
  std::vector<uint32_t> table(cap, UINT32_MAX), rep(count);
  std::array<float, N> k, other;
  for (size_t i = 0; i < count; ++i) {
    key(i, k.data());
    uint64_t h = 1469598103934665603ull;  // FNV-1a over the key's bits, -0 hashed as +0
    for (float f : k) {
      f = f == 0.0f ? 0.0f : f;
      uint32_t b;
      std::memcpy(&b, &f, 4);
      h = (h ^ b) * 1099511628211ull;
    }
    size_t slot = size_t(h ^ (h >> 31)) & (cap - 1);
    for (; table[slot] != UINT32_MAX; slot = (slot + 1) & (cap - 1)) {
      key(table[slot], other.data());
      if (other == k) break;
    }
    if (table[slot] == UINT32_MAX) table[slot] = uint32_t(i);
    rep[i] = table[slot];
  }
  return rep;
}

}  // namespace effects::tangents

// Animated GIFs, written here rather than through OpenImageIO's writer (one thread, ~20 ms a
// 256² frame: most of an animated preview once the GPU drew the frames). Frames are encoded
// in batches on several threads: each gets its own 255-colour palette (median cut over a
// 6-bit-per-channel histogram of its exact colours, each colour mapped to its nearest entry),
// pixels unchanged from the frame before left transparent (delta frames), then LZW. Index 0
// is transparent. A frame with pixels of alpha < 1/2 is written whole and the frame before it
// is cleared after showing (disposal 2), so that what is transparent shows the page.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include "render/render.h"

namespace effects::render {
namespace {

constexpr int kBits = 6;  // of each channel in the histogram
constexpr int kSide = 1 << kBits, kMask = kSide - 1, kBins = kSide * kSide * kSide;
constexpr size_t kBatch = 8;  // frames encoded at once (and held at most, beside the last)

int binOf(const uint8_t* p) {
  return (p[0] >> (8 - kBits)) << (2 * kBits) | (p[1] >> (8 - kBits)) << kBits | p[2] >> (8 - kBits);
}

struct Palette {
  std::array<uint8_t, 256 * 3> rgb{};  // entry 0: transparent
  std::vector<uint8_t> indexOfBin = std::vector<uint8_t>(kBins, 1);
};

// Median cut: the box of occupied bins with the most pixels times its longest side is split
// at the pixel-weighted median of that side, until 255 boxes; each box's colour is the mean
// of the exact colours in it; every occupied bin then takes its mean colour's nearest entry.
Palette paletteOf(const std::vector<uint32_t>& count, const std::vector<std::array<uint32_t, 3>>& sum) {
  struct Box {
    std::vector<int> bins;
    uint64_t pixels = 0;
    int longest = 0, side = 0;
  };
  auto measure = [&](Box& b) {
    int lo[3] = {kMask, kMask, kMask}, hi[3] = {0, 0, 0};
    b.pixels = 0;
    for (int bin : b.bins) {
      const int c[3] = {bin >> (2 * kBits), (bin >> kBits) & kMask, bin & kMask};
      for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], c[k]), hi[k] = std::max(hi[k], c[k]);
      b.pixels += count[size_t(bin)];
    }
    b.longest = 0;
    for (int k = 1; k < 3; ++k)
      if (hi[k] - lo[k] > hi[b.longest] - lo[b.longest]) b.longest = k;
    b.side = hi[b.longest] - lo[b.longest];
  };
  std::vector<Box> boxes(1);
  for (int bin = 0; bin < kBins; ++bin)
    if (count[size_t(bin)]) boxes[0].bins.push_back(bin);
  measure(boxes[0]);
  while (boxes.size() < 255) {
    size_t pick = boxes.size();
    for (size_t i = 0; i < boxes.size(); ++i)
      if (boxes[i].side > 0 &&
          (pick == boxes.size() || boxes[i].pixels * uint64_t(boxes[i].side) > boxes[pick].pixels * uint64_t(boxes[pick].side)))
        pick = i;
    if (pick == boxes.size()) break;  // every box holds one bin
    Box& b = boxes[pick];
    const int shift = (2 - b.longest) * kBits;
    auto side = [shift](int bin) { return (bin >> shift) & kMask; };
    std::sort(b.bins.begin(), b.bins.end(), [&](int x, int y) { return side(x) < side(y); });
    uint64_t seen = 0;
    size_t cut = 1;
    for (; cut < b.bins.size(); ++cut) {
      seen += count[size_t(b.bins[cut - 1])];
      const bool sameSide = side(b.bins[cut]) == side(b.bins[cut - 1]);
      if (2 * seen >= b.pixels && !sameSide) break;
    }
    if (cut == b.bins.size())  // the median's side is the last: cut before it
      while (cut > 1 && side(b.bins[cut - 1]) == side(b.bins.back())) --cut;
    Box upper;
    upper.bins.assign(b.bins.begin() + ptrdiff_t(cut), b.bins.end());
    b.bins.resize(cut);
    measure(b);
    measure(upper);
    boxes.push_back(std::move(upper));
  }
  Palette p;
  for (size_t i = 0; i < boxes.size(); ++i) {
    uint64_t s[3] = {0, 0, 0};
    for (int bin : boxes[i].bins)
      for (int k = 0; k < 3; ++k) s[k] += sum[size_t(bin)][size_t(k)];
    for (int k = 0; k < 3; ++k)
      p.rgb[(i + 1) * 3 + size_t(k)] = uint8_t((s[k] + boxes[i].pixels / 2) / std::max<uint64_t>(1, boxes[i].pixels));
  }
  const int entries = int(boxes.size());
  for (const Box& b : boxes)
    for (int bin : b.bins) {
      int mean[3];
      for (int k = 0; k < 3; ++k)
        mean[k] = int((sum[size_t(bin)][size_t(k)] + count[size_t(bin)] / 2) / count[size_t(bin)]);
      int best = 1, bestDistance = 1 << 30;
      for (int e = 1; e <= entries; ++e) {
        const uint8_t* c = &p.rgb[size_t(e) * 3];
        const int d = (mean[0] - c[0]) * (mean[0] - c[0]) + (mean[1] - c[1]) * (mean[1] - c[1]) +
                      (mean[2] - c[2]) * (mean[2] - c[2]);
        if (d < bestDistance) bestDistance = d, best = e;
      }
      p.indexOfBin[size_t(bin)] = uint8_t(best);
    }
  return p;
}

// GIF's LZW (8-bit symbols, codes of 9 ... 12 bits, least significant bit first).
std::string lzw(const std::vector<uint8_t>& symbols) {
  constexpr uint32_t kClear = 256, kEnd = 257;
  std::string out;
  uint32_t bits = 0, held = 0, width = 9, next = kEnd + 1;
  auto emit = [&](uint32_t code) {
    bits |= code << held;
    held += width;
    for (; held >= 8; held -= 8, bits >>= 8) out.push_back(char(bits & 0xFF));
  };
  // Open addressing: key (prefix << 8 | symbol) + 1 -> code, cleared with the dictionary.
  constexpr size_t kSlots = 8192;
  std::vector<uint32_t> keys(kSlots), codes(kSlots);
  auto slotOf = [&](uint32_t key) {
    size_t s = (key * 2654435761u) >> 19;  // 13 bits
    while (keys[s] && keys[s] != key + 1) s = (s + 1) & (kSlots - 1);
    return s;
  };
  emit(kClear);
  uint32_t prefix = symbols[0];
  for (size_t i = 1; i < symbols.size(); ++i) {
    const uint32_t key = prefix << 8 | symbols[i];
    const size_t s = slotOf(key);
    if (keys[s]) {
      prefix = codes[s];
      continue;
    }
    emit(prefix);
    keys[s] = key + 1, codes[s] = next;
    if (next == (1u << width) && width < 12) ++width;
    if (++next == 4096) {  // the dictionary is full: start again
      emit(kClear);
      std::fill(keys.begin(), keys.end(), 0u);
      width = 9, next = kEnd + 1;
    }
    prefix = symbols[i];
  }
  emit(prefix);
  // A decoder adds its entry for that code too: past a power of two, the end code is wider.
  if (next == (1u << width) && width < 12) ++width;
  emit(kEnd);
  if (held) out.push_back(char(bits & 0xFF));
  return out;
}

}  // namespace

int gifDelay(double fps) { return std::max(2, int(std::lround(100.0 / fps))); }

struct GifEncoder::Impl {
  int width, height, count, delay;
  Parallel* parallel;
  std::vector<std::vector<uint8_t>> pending;  // RGBA8 frames not yet encoded
  std::vector<uint8_t> previous;              // the last encoded frame's RGBA8
  struct Encoded {
    bool transparent = false;  // has pixels of alpha < 1/2 (written whole)
    std::string table, data;   // local colour table, LZW bytes
  };
  std::vector<Encoded> encoded;
  int added = 0;

  Encoded encode(const std::vector<uint8_t>& rgba, const std::vector<uint8_t>* before) const {
    const size_t pixels = size_t(width) * size_t(height);
    Encoded e;
    for (size_t i = 0; i < pixels && !e.transparent; ++i) e.transparent = rgba[i * 4 + 3] < 128;
    if (e.transparent) before = nullptr;  // the frame before is cleared: nothing to keep
    // Which pixels this frame writes, and the histogram of their colours.
    std::vector<uint32_t> count(kBins);
    std::vector<std::array<uint32_t, 3>> sum(kBins);
    std::vector<uint8_t> writes(pixels, 1);
    for (size_t i = 0; i < pixels; ++i) {
      const uint8_t* p = &rgba[i * 4];
      if (p[3] < 128 || (before && std::memcmp(p, &(*before)[i * 4], 4) == 0)) {
        writes[i] = 0;
        continue;
      }
      const int bin = binOf(p);
      ++count[size_t(bin)];
      for (int k = 0; k < 3; ++k) sum[size_t(bin)][size_t(k)] += p[k];
    }
    const Palette palette = paletteOf(count, sum);
    std::vector<uint8_t> symbols(pixels, 0);
    for (size_t i = 0; i < pixels; ++i)
      if (writes[i]) symbols[i] = palette.indexOfBin[size_t(binOf(&rgba[i * 4]))];
    e.table.assign(palette.rgb.begin(), palette.rgb.end());
    e.data = lzw(symbols);
    return e;
  }

  // Encodes the pending frames, several at once.
  void flush() {
    const size_t first = encoded.size();
    encoded.resize(first + pending.size());
    forRange(parallel, pending.size(), 1, [&](size_t begin, size_t end) {
      for (size_t i = begin; i < end; ++i)
        encoded[first + i] = encode(pending[i], i ? &pending[i - 1] : previous.empty() ? nullptr : &previous);
    });
    if (!pending.empty()) previous = std::move(pending.back());
    pending.clear();
  }
};

GifEncoder::GifEncoder(int width, int height, int count, double fps, Parallel* parallel)
    : impl_(new Impl{width, height, std::max(1, count), gifDelay(fps), parallel, {}, {}, {}, 0}) {}

GifEncoder::~GifEncoder() = default;

std::optional<Error> GifEncoder::add(const Image& frame) {
  Impl& g = *impl_;
  if (g.added >= g.count) return invalid("/frames", "more frames than announced");
  if (frame.width != g.width || frame.height != g.height || frame.values() != size_t(g.width) * g.height * 4)
    return invalid("/frames", "a frame of another size");
  g.pending.push_back(bytes8(frame));
  ++g.added;
  if (g.pending.size() == kBatch) g.flush();
  return std::nullopt;
}

Result<std::string> GifEncoder::finish() {
  Impl& g = *impl_;
  if (g.added != g.count) return invalid("/frames", "fewer frames than announced");
  g.flush();
  std::string out = "GIF89a";
  auto put16 = [&out](int v) { out.push_back(char(v & 0xFF)), out.push_back(char((v >> 8) & 0xFF)); };
  put16(g.width), put16(g.height);
  out += {char(0), char(0), char(0)};  // no global colour table
  out += "\x21\xFF\x0BNETSCAPE2.0\x03\x01";
  put16(0);  // loop forever
  out.push_back(0);
  for (size_t i = 0; i < g.encoded.size(); ++i) {
    const Impl::Encoded& e = g.encoded[i];
    // The last frame's successor is the first, when the animation loops.
    const bool nextClears = g.encoded[i + 1 < g.encoded.size() ? i + 1 : 0].transparent;
    out += "\x21\xF9\x04";
    out.push_back(char((nextClears ? 2 : 1) << 2 | 1));  // disposal; transparent index given
    put16(g.delay);
    out += {char(0), char(0)};  // transparent index 0, end of block
    out.push_back(0x2C);
    put16(0), put16(0), put16(g.width), put16(g.height);
    out.push_back(char(0x87));  // a local colour table of 256 entries
    out += e.table;
    out.push_back(8);  // LZW minimum code size
    for (size_t at = 0; at < e.data.size(); at += 255) {
      const size_t n = std::min<size_t>(255, e.data.size() - at);
      out.push_back(char(n));
      out.append(e.data, at, n);
    }
    out.push_back(0);
  }
  out.push_back(0x3B);
  g.encoded.clear();
  return out;
}

}  // namespace effects::render

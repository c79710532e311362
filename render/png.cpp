// PNG out, written here with zlib rather than through OpenImageIO (which still reads images
// and writes GIFs): the encoding was most of a preview request once the GPU drew the frame in a
// millisecond. The rows are cut into strips that are filtered and deflated on several threads
// at once, each strip's deflate primed with the 32 KiB of filtered rows before it (as pigz
// does), so the strips join into one zlib stream: raw deflate blocks ended by sync flushes, the
// last one final, their Adler-32 sums combined. One IDAT chunk.
#include <zlib.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>

#include "render/render.h"

namespace effects::render {
namespace {

constexpr size_t kWindow = 32768;          // deflate's window: the dictionary a strip is primed with
constexpr size_t kStripBytes = 64 * 1024;  // of filtered rows, at least, per strip
constexpr int kLevel = 2;                  // zlib level: previews are sent, not archived

void put32(std::string& out, uint32_t v) {
  for (int s = 24; s >= 0; s -= 8) out.push_back(char((v >> s) & 0xFF));
}

void chunk(std::string& out, const char type[4], const std::string& data) {
  put32(out, uint32_t(data.size()));
  const size_t at = out.size();
  out.append(type, 4);
  out += data;
  put32(out, uint32_t(crc32(0, reinterpret_cast<const Bytef*>(out.data() + at), uInt(out.size() - at))));
}

// One row filtered into out[0] (the filter type) and out[1 ... n]: of the five filters, the one
// whose output has the least sum of magnitudes (as signed bytes), libpng's heuristic. `above`
// is the row before (zeros for the first); `left` and `upLeft` are `row` and `above` shifted by
// one pixel (zeros before the first), so that the loop has no branches.
// (The pointers do not alias: __restrict lets the loop be vectorised.)
void filterRow(const uint8_t* __restrict row, const uint8_t* __restrict above, const uint8_t* __restrict left,
               const uint8_t* __restrict upLeft, size_t n, uint8_t* out, std::array<std::vector<uint8_t>, 5>& trial) {
  uint8_t* __restrict none = trial[0].data();
  uint8_t* __restrict sub = trial[1].data();
  uint8_t* __restrict up = trial[2].data();
  uint8_t* __restrict avg = trial[3].data();
  uint8_t* __restrict pae = trial[4].data();
  auto magnitude = [](uint8_t v) { return std::abs(int(int8_t(v))); };
  int sums[5] = {0, 0, 0, 0, 0};
  for (size_t i = 0; i < n; ++i) {
    const int x = row[i], a = left[i], b = above[i], c = upLeft[i];
    const int pa = std::abs(b - c), pb = std::abs(a - c), pc = std::abs(a + b - 2 * c);
    const int predicted = pa <= pb ? (pa <= pc ? a : c) : (pb <= pc ? b : c);  // Paeth
    none[i] = uint8_t(x), sub[i] = uint8_t(x - a), up[i] = uint8_t(x - b), avg[i] = uint8_t(x - (a + b) / 2);
    pae[i] = uint8_t(x - predicted);
    sums[0] += magnitude(none[i]), sums[1] += magnitude(sub[i]), sums[2] += magnitude(up[i]);
    sums[3] += magnitude(avg[i]), sums[4] += magnitude(pae[i]);
  }
  const size_t best = size_t(std::min_element(sums, sums + 5) - sums);
  out[0] = uint8_t(best);
  std::copy_n(trial[best].data(), n, out + 1);
}

// A float image's samples as PNG rows (RGBA, big-endian for 16 bits), without filter bytes.
std::vector<uint8_t> samples(const Image& image, int bitDepth) {
  if (bitDepth == 8) return bytes8(image);
  const size_t n = image.rgba.size();
  std::vector<uint8_t> out(n * 2);
  for (size_t i = 0; i < n; ++i) {
    const auto s = uint16_t(std::lround(std::clamp(image.rgba[i], 0.0f, 1.0f) * 65535.0f));
    out[2 * i] = uint8_t(s >> 8), out[2 * i + 1] = uint8_t(s & 0xFF);
  }
  return out;
}

}  // namespace

// Long because it is one PNG written in order (signature, IHDR, the strips filtered and deflated
// on `parallel` and joined into one zlib stream, IEND), each chunk with its CRC.
Result<std::string> encodePng(const Image& image, int bitDepth, Parallel* parallel) {
  if (bitDepth != 8 && bitDepth != 16) return invalid("/bitDepth", "must be 8 or 16");
  if (image.width <= 0 || image.height <= 0 || image.values() != size_t(image.width) * image.height * 4)
    return invalid("/image", "has no pixels");
  if (!image.rgba8.empty() && bitDepth != 8) return invalid("/bitDepth", "an 8-bit frame is written as 8 bits");
  const std::vector<uint8_t> converted = image.rgba8.empty() ? samples(image, bitDepth) : std::vector<uint8_t>();
  const uint8_t* raw = image.rgba8.empty() ? converted.data() : image.rgba8.data();
  const size_t bpp = size_t(4 * bitDepth / 8), rowBytes = size_t(image.width) * bpp, line = rowBytes + 1;
  const size_t height = size_t(image.height);
  const size_t rowsPerStrip = std::max<size_t>(1, (kStripBytes + line - 1) / line);
  const size_t strips = (height + rowsPerStrip - 1) / rowsPerStrip;

  // Filter, deflate and sum each strip on its own.
  std::vector<uint8_t> filtered(line * height);
  std::vector<std::string> deflated(strips);
  std::vector<uLong> adler(strips);
  std::vector<uint8_t> failed(strips);  // per strip: strips fail (or not) on their own threads
  auto filterStrip = [&](size_t s) {
    std::array<std::vector<uint8_t>, 5> trial;
    for (auto& t : trial) t.resize(rowBytes);
    std::vector<uint8_t> zeros(rowBytes + bpp), left(rowBytes + bpp), upLeft(rowBytes + bpp);
    for (size_t y = s * rowsPerStrip; y < std::min(height, (s + 1) * rowsPerStrip); ++y) {
      const uint8_t* row = &raw[y * rowBytes];
      const uint8_t* above = y ? &raw[(y - 1) * rowBytes] : zeros.data();
      std::copy_n(row, rowBytes - bpp, left.begin() + ptrdiff_t(bpp));
      std::copy_n(above, rowBytes - bpp, upLeft.begin() + ptrdiff_t(bpp));
      filterRow(row, above, left.data(), upLeft.data(), rowBytes, &filtered[y * line], trial);
    }
  };
  forRange(parallel, strips, 1, [&](size_t begin, size_t end) {
    for (size_t s = begin; s < end; ++s) filterStrip(s);
  });
  forRange(parallel, strips, 1, [&](size_t begin, size_t end) {
    for (size_t s = begin; s < end; ++s) {
      const size_t from = s * rowsPerStrip * line, to = std::min(height, (s + 1) * rowsPerStrip) * line;
      const bool last = s + 1 == strips;
      z_stream z{};
      if (deflateInit2(&z, kLevel, Z_DEFLATED, -15, 8, Z_DEFAULT_STRATEGY) != Z_OK) {
        failed[s] = 1;
        continue;
      }
      const size_t dictionary = std::min(kWindow, from);  // the rows before this strip
      if (dictionary) deflateSetDictionary(&z, &filtered[from - dictionary], uInt(dictionary));
      std::string& out = deflated[s];
      out.resize(deflateBound(&z, uLong(to - from)) + 16);  // + a sync flush's empty block
      z.next_in = &filtered[from];
      z.avail_in = uInt(to - from);
      z.next_out = reinterpret_cast<Bytef*>(out.data());
      z.avail_out = uInt(out.size());
      const int r = deflate(&z, last ? Z_FINISH : Z_SYNC_FLUSH);
      // Every row taken, and (a sync flush) room left: a full buffer may hold an unfinished flush.
      failed[s] = (last ? r != Z_STREAM_END : r != Z_OK || z.avail_out == 0) || z.avail_in != 0;
      out.resize(out.size() - z.avail_out);
      deflateEnd(&z);
      adler[s] = adler32(adler32(0, nullptr, 0), &filtered[from], uInt(to - from));
    }
  });
  if (std::find(failed.begin(), failed.end(), 1) != failed.end())
    return unsatisfiable("/image", "PNG encoding failed: zlib did not take every row");

  // One zlib stream: header, the strips' blocks, the Adler-32 of every filtered row.
  std::string idat = {char(0x78), char(0x5E)};  // deflate, 32 KiB window, "fast" level; FCHECK holds
  uLong sum = adler[0];
  for (size_t s = 0; s < strips; ++s) {
    idat += deflated[s];
    if (s > 0) {
      const size_t length = (std::min(height, (s + 1) * rowsPerStrip) - s * rowsPerStrip) * line;
      sum = adler32_combine(sum, adler[s], z_off_t(length));
    }
  }
  put32(idat, uint32_t(sum));
  std::string header;
  put32(header, uint32_t(image.width));
  put32(header, uint32_t(image.height));
  header += {char(bitDepth), char(6), char(0), char(0), char(0)};  // RGBA, deflate, adaptive filters, no interlace
  std::string png = "\x89PNG\r\n\x1a\n";
  chunk(png, "IHDR", header);
  chunk(png, "IDAT", idat);
  chunk(png, "IEND", "");
  return png;
}

}  // namespace effects::render

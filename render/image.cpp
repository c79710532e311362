// Flipbook sheets, and PNG/JPEG in, in memory, through OpenImageIO (PNGs out: png.cpp; GIFs
// out: gif.cpp).
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "render/render.h"

namespace effects::render {

std::vector<uint8_t> bytes8(const Image& image) {
  if (!image.rgba8.empty()) return image.rgba8;
  std::vector<uint8_t> out(image.rgba.size());
  for (size_t i = 0; i < out.size(); ++i) out[i] = uint8_t(std::lround(std::clamp(image.rgba[i], 0.0f, 1.0f) * 255.0f));
  return out;
}

int Flipbook::cells(int count) {
  const int columns = std::max(1, int(std::ceil(std::sqrt(double(count)))));
  return columns * ((count + columns - 1) / columns);
}

Flipbook::Flipbook(int width, int height, int count) : frameWidth(width), frameHeight(height) {
  columns = std::max(1, int(std::ceil(std::sqrt(double(count)))));
  rows = (count + columns - 1) / columns;
  sheet.width = columns * width;
  sheet.height = rows * height;
}

void Flipbook::put(const Image& frame, int index) {
  // Allocated with the first frame, on the render thread: a queued request holds no sheet. The
  // sheet holds the frames' kind of values (bytes from an 8-bit render, else floats).
  const size_t values = size_t(sheet.width) * size_t(sheet.height) * 4;
  const bool bytes8 = !frame.rgba8.empty();
  if (sheet.values() == 0) (bytes8 ? sheet.rgba8.assign(values, 0) : sheet.rgba.assign(values, 0.0f));
  const int cx = index % columns, cy = index / columns;
  for (int y = 0; y < std::min(frame.height, frameHeight); ++y) {
    const size_t from = size_t(y) * size_t(frame.width) * 4, n = size_t(std::min(frame.width, frameWidth)) * 4;
    const size_t to = ((size_t(cy) * frameHeight + size_t(y)) * size_t(sheet.width) + size_t(cx) * frameWidth) * 4;
    if (bytes8)
      std::copy_n(&frame.rgba8[from], n, &sheet.rgba8[to]);
    else
      std::copy_n(&frame.rgba[from], n, &sheet.rgba[to]);
  }
}

Result<Image> decodeImage(const std::string& bytes, size_t maxPixels) {
  const auto* data = reinterpret_cast<const unsigned char*>(bytes.data());
  const char* name = nullptr;
  if (bytes.size() >= 8 && std::memcmp(data, "\x89PNG\r\n\x1a\n", 8) == 0)
    name = "image.png";
  else if (bytes.size() >= 3 && data[0] == 0xFF && data[1] == 0xD8 && data[2] == 0xFF)
    name = "image.jpg";
  else
    return invalid("", "is neither a PNG nor a JPEG image");
  try {
    OIIO::Filesystem::IOMemReader proxy(data, bytes.size());
    // Straight alpha, as a PNG stores it (OpenImageIO would otherwise multiply it in).
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    auto in = OIIO::ImageInput::create(name, false, &config, &proxy);
    OIIO::ImageSpec spec;
    if (!in || !in->set_ioproxy(&proxy) || !in->open(name, spec, config))
      return invalid("", "cannot be decoded: " + (in ? in->geterror() : std::string("no reader")));
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0 || spec.depth != 1)
      return invalid("", "has no usable pixels");
    const size_t pixels = size_t(spec.width) * size_t(spec.height);
    if (pixels > maxPixels)
      return overLimit("", std::to_string(spec.width) + "x" + std::to_string(spec.height) + " exceeds the limit of " +
                               std::to_string(maxPixels) + " pixels");
    const int n = spec.nchannels;
    std::vector<float> raw(pixels * size_t(n));
    if (!in->read_image(0, 0, 0, n, OIIO::TypeDesc::FLOAT, raw.data()))
      return invalid("", "cannot be decoded: " + in->geterror());
    Image out{spec.width, spec.height, std::vector<float>(pixels * 4), {}};
    for (size_t i = 0; i < pixels; ++i) {
      const float* s = &raw[i * size_t(n)];
      float* d = &out.rgba[i * 4];
      if (n <= 2) {
        d[0] = d[1] = d[2] = s[0];
        d[3] = n == 2 ? s[1] : 1.0f;
      } else {
        d[0] = s[0], d[1] = s[1], d[2] = s[2];
        d[3] = n >= 4 ? s[3] : 1.0f;
      }
      for (int c = 0; c < 4; ++c) d[c] = std::clamp(d[c], 0.0f, 1.0f);
    }
    return out;
  } catch (const std::exception& e) {
    return invalid("", std::string("cannot be decoded: ") + e.what());
  }
}

}  // namespace effects::render

// PNG out and PNG/JPEG in, in memory, through OpenImageIO.
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "render/render.h"

namespace effects::render {

Result<std::string> encodePng(const Image& image, int bitDepth) {
  if (bitDepth != 8 && bitDepth != 16) return invalid("/bitDepth", "must be 8 or 16");
  if (image.width <= 0 || image.height <= 0 || image.rgba.size() != size_t(image.width) * image.height * 4)
    return invalid("/image", "has no pixels");
  std::vector<unsigned char> bytes;
  OIIO::Filesystem::IOVecOutput proxy(bytes);
  auto out = OIIO::ImageOutput::create("frame.png", &proxy);
  if (!out) return unsatisfiable("/image", "OpenImageIO has no PNG writer");
  OIIO::ImageSpec spec(image.width, image.height, 4, bitDepth == 8 ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::UINT16);
  spec.attribute("oiio:UnassociatedAlpha", 1);  // the pixels are straight alpha already
  spec.attribute("png:compressionLevel", 3);    // fast; previews are not archived
  if (!out->open("frame.png", spec) || !out->write_image(OIIO::TypeDesc::FLOAT, image.rgba.data()) || !out->close())
    return unsatisfiable("/image", "PNG encoding failed: " + out->geterror());
  return std::string(bytes.begin(), bytes.end());
}

int gifDelay(double fps) { return std::max(2, int(std::lround(100.0 / fps))); }

struct GifEncoder::Impl {
  std::vector<unsigned char> bytes;
  OIIO::Filesystem::IOVecOutput proxy{bytes};
  std::unique_ptr<OIIO::ImageOutput> out;
  std::vector<OIIO::ImageSpec> specs;
  std::vector<unsigned char> pixels;
  int added = 0;
  std::string error;
};

GifEncoder::GifEncoder(int width, int height, int count, double fps) : impl_(std::make_unique<Impl>()) {
  OIIO::ImageSpec spec(width, height, 4, OIIO::TypeDesc::UINT8);
  // GIF delays are whole hundredths of a second: the rate is 100 / delay (gifDelay()).
  const int rate[2] = {100, gifDelay(fps)};
  spec.attribute("FramesPerSecond", OIIO::TypeRational, rate);
  spec.attribute("gif:LoopCount", 0);  // forever
  spec.attribute("oiio:UnassociatedAlpha", 1);
  impl_->specs.assign(size_t(std::max(1, count)), spec);
  impl_->out = OIIO::ImageOutput::create("frames.gif", &impl_->proxy);
  if (!impl_->out)
    impl_->error = "OpenImageIO has no GIF writer";
  else if (!impl_->out->open("frames.gif", int(impl_->specs.size()), impl_->specs.data()))
    impl_->error = impl_->out->geterror();
}

GifEncoder::~GifEncoder() = default;

std::optional<Error> GifEncoder::add(const Image& frame) {
  Impl& g = *impl_;
  if (!g.error.empty()) return unsatisfiable("/frames", "GIF encoding failed: " + g.error);
  if (g.added >= int(g.specs.size())) return invalid("/frames", "more frames than announced");
  if (g.added > 0 && !g.out->open("frames.gif", g.specs[size_t(g.added)], OIIO::ImageOutput::AppendSubimage))
    return unsatisfiable("/frames", "GIF encoding failed: " + g.out->geterror());
  // OpenImageIO's GIF writer takes 8-bit pixels; round as encodePng does.
  g.pixels.resize(frame.rgba.size());
  for (size_t i = 0; i < frame.rgba.size(); ++i)
    g.pixels[i] = static_cast<unsigned char>(std::lround(std::clamp(frame.rgba[i], 0.0f, 1.0f) * 255.0f));
  if (!g.out->write_image(OIIO::TypeDesc::UINT8, g.pixels.data()))
    return unsatisfiable("/frames", "GIF encoding failed: " + g.out->geterror());
  ++g.added;
  return std::nullopt;
}

Result<std::string> GifEncoder::finish() {
  Impl& g = *impl_;
  if (!g.error.empty()) return unsatisfiable("/frames", "GIF encoding failed: " + g.error);
  if (g.added != int(g.specs.size())) return invalid("/frames", "fewer frames than announced");
  if (!g.out->close()) return unsatisfiable("/frames", "GIF encoding failed: " + g.out->geterror());
  return std::string(g.bytes.begin(), g.bytes.end());
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
  // Allocated with the first frame, on the render thread: a queued request holds no sheet.
  if (sheet.rgba.empty()) sheet.rgba.assign(size_t(sheet.width) * size_t(sheet.height) * 4, 0.0f);
  const int cx = index % columns, cy = index / columns;
  for (int y = 0; y < std::min(frame.height, frameHeight); ++y)
    std::copy_n(&frame.rgba[size_t(y) * size_t(frame.width) * 4], size_t(std::min(frame.width, frameWidth)) * 4,
                &sheet.rgba[((size_t(cy) * frameHeight + size_t(y)) * size_t(sheet.width) + size_t(cx) * frameWidth) * 4]);
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
    auto in = OIIO::ImageInput::create(name, false, nullptr, &proxy);
    OIIO::ImageSpec spec;
    if (!in || !in->set_ioproxy(&proxy) || !in->open(name, spec))
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
    Image out{spec.width, spec.height, std::vector<float>(pixels * 4)};
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

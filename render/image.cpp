// PNG out and PNG/JPEG in, in memory, through OpenImageIO.
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
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

// libFuzzer: background and flow-texture images (PNG/JPEG through OpenImageIO), bounded.
#include <cstdint>
#include <cstdlib>
#include <string>

#include <render/render.h>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  auto image = effects::render::decodeImage(std::string(reinterpret_cast<const char*>(data), size), 256 * 256);
  if (image.ok() && image.value().rgba.size() != size_t(image.value().width) * size_t(image.value().height) * 4)
    std::abort();
  return 0;
}

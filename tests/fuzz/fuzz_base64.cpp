// libFuzzer: the strict base64 decoder; whatever it accepts must encode back to the input.
#include <cstdint>
#include <cstdlib>
#include <string>

#include "contract/codec.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  auto decoded = effectd::base64Decode(text);
  if (decoded && effectd::base64Encode(*decoded) != text) std::abort();
  return 0;
}

// Byte encodings used on the wire: base64 (RFC 4648) and IEEE half floats.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace effectd {

std::string base64Encode(std::string_view bytes);
// Strict decode: standard alphabet, '=' padding required, no whitespace. nullopt if invalid.
std::optional<std::string> base64Decode(std::string_view text);
// Round-to-nearest-even float -> binary16 (overflow -> inf, NaN kept NaN).
uint16_t floatToHalf(float value);
float halfToFloat(uint16_t half);

}  // namespace effectd

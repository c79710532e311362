// Byte encodings used on the wire: base64 (RFC 4648), IEEE half floats, SHA-256 digests.
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
// SHA-256 (FIPS 180-4) of `bytes` as 64 lower-case hex digits.
std::string sha256Hex(std::string_view bytes);

}  // namespace effectd

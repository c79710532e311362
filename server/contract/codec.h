// Byte encodings used on the wire: base64 and base64url (RFC 4648), IEEE half floats, SHA-256
// digests and HMAC-SHA256 (RFC 2104) signatures.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace effectd {

std::string base64Encode(std::string_view bytes);
// Strict decode: standard alphabet, '=' padding required, no whitespace. nullopt if invalid.
std::optional<std::string> base64Decode(std::string_view text);
// base64url (RFC 4648 §5) without padding, as URLs carry it. Decode is strict: its alphabet
// only, no '=', canonical (unused bits zero). nullopt if invalid.
std::string base64UrlEncode(std::string_view bytes);
std::optional<std::string> base64UrlDecode(std::string_view text);
// Round-to-nearest-even float -> binary16 (overflow -> inf, NaN kept NaN).
uint16_t floatToHalf(float value);
float halfToFloat(uint16_t half);
// SHA-256 (FIPS 180-4) of `bytes` as 64 lower-case hex digits.
std::string sha256Hex(std::string_view bytes);
// HMAC-SHA256 of `message` under `key`: the 32 raw bytes.
std::string hmacSha256(std::string_view key, std::string_view message);
// Equal strings, in a time that depends on their lengths only (not on where they differ).
bool constantTimeEqual(std::string_view a, std::string_view b);

}  // namespace effectd

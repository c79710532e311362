// Content-Encoding negotiation (RFC 9110 12.5.3) and the encoders. cpp-httplib 0.11.4 picks
// br or gzip by substring ("gzip;q=0" would still get gzip) and gives every encoding the same
// ETag; effectd negotiates itself instead, and each coding is a representation of its own
// with its own strong ETag (the identity tag plus "-gzip" / "-br").
#pragma once

#include <string>
#include <string_view>

namespace effectd {

enum class Coding { kIdentity, kGzip, kBrotli };

// The coding to send for this Accept-Encoding value: the acceptable one (q > 0) with the
// highest q, br before gzip before identity on ties; identity when nothing else is
// acceptable (also when identity itself was refused: a 406 helps no client).
Coding negotiate(std::string_view acceptEncoding);
// "gzip", "br", or "" for identity.
const char* codingName(Coding coding);
// Media types worth compressing (JSON, YAML, text); PNG and glTF binaries are not.
bool compressible(std::string_view contentType);
// Bodies below this many bytes go out as they are whatever the client accepts.
constexpr size_t kMinCompressBytes = 256;
// The encoded bytes (gzip level 6, brotli quality 5: close to the best ratio at a fraction
// of the time of brotli's default 11, which costs ~1 s on a 3 MB mesh).
std::string encode(Coding coding, std::string_view body);

}  // namespace effectd

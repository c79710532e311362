// Validators for deterministic answers: a strong ETag per representation (request, route,
// build and coding), and If-None-Match matching.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "http/encoding.h"

namespace effectd {

// True when the request asks for timings in the body ("stats" in any include list): such a
// response differs from run to run and gets no ETag.
bool asksForTimings(const nlohmann::json& j);
// If-None-Match uses the weak comparison (RFC 9110 13.1.2): W/ prefixes are ignored.
bool etagMatches(const std::string& ifNoneMatch, const std::string& etag);
// The ETag of the answer to `canonical` (what determines the answer) on `path`, with the
// route's salt (e.g. the renderer in use) and this build's version; coded answers get their
// coding as a suffix ("…-gzip"), so that caches never mix representations.
std::string etagFor(const std::string& path, const std::string& salt, const std::string& canonical, Coding coding);

}  // namespace effectd

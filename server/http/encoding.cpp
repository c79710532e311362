#include "http/encoding.h"

#include <brotli/encode.h>
#include <zlib.h>

#include <cctype>
#include <cstdlib>

namespace effectd {

namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

bool iequals(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(a[i])) != std::tolower(static_cast<unsigned char>(b[i]))) return false;
  return true;
}

// q of one list member "coding;q=0.5" (1 when absent, 0 when malformed: a client that
// writes garbage did not clearly accept it).
double qValue(std::string_view params) {
  double q = 1;
  while (!params.empty()) {
    size_t semi = params.find(';');
    std::string_view p = trim(params.substr(0, semi));
    params = semi == std::string_view::npos ? std::string_view() : params.substr(semi + 1);
    if (p.size() >= 2 && (p[0] == 'q' || p[0] == 'Q') && p[1] == '=') {
      std::string v(p.substr(2));
      char* end = nullptr;
      q = std::strtod(v.c_str(), &end);
      if (v.empty() || *end != '\0' || !(q >= 0 && q <= 1)) return 0;
    }
  }
  return q;
}

}  // namespace

Coding negotiate(std::string_view header) {
  // -1: not mentioned. "*" covers every coding not named; identity is acceptable unless
  // refused by name or by "*;q=0".
  double br = -1, gzip = -1, identity = -1, star = -1;
  while (!header.empty()) {
    size_t comma = header.find(',');
    std::string_view item = trim(header.substr(0, comma));
    header = comma == std::string_view::npos ? std::string_view() : header.substr(comma + 1);
    if (item.empty()) continue;
    size_t semi = item.find(';');
    std::string_view name = trim(item.substr(0, semi));
    double q = semi == std::string_view::npos ? 1.0 : qValue(item.substr(semi + 1));
    if (iequals(name, "br"))
      br = q;
    else if (iequals(name, "gzip") || iequals(name, "x-gzip"))
      gzip = q;
    else if (iequals(name, "identity"))
      identity = q;
    else if (name == "*")
      star = q;
  }
  if (star >= 0) {
    if (br < 0) br = star;
    if (gzip < 0) gzip = star;
    if (identity < 0) identity = star;
  }
  if (identity < 0) identity = 0.001;  // acceptable, but any named coding wins
  if (br > 0 && br >= gzip && br >= identity) return Coding::kBrotli;
  if (gzip > 0 && gzip >= identity) return Coding::kGzip;
  return Coding::kIdentity;
}

const char* codingName(Coding coding) {
  switch (coding) {
    case Coding::kGzip: return "gzip";
    case Coding::kBrotli: return "br";
    case Coding::kIdentity: break;
  }
  return "";
}

bool compressible(std::string_view type) {
  type = type.substr(0, type.find(';'));
  return type.rfind("text/", 0) == 0 || type == "application/json" || type == "application/problem+json" ||
         type == "application/schema+json" || type == "application/yaml";
}

std::string encode(Coding coding, std::string_view body) {
  std::string out;
  if (coding == Coding::kBrotli) {
    size_t size = BrotliEncoderMaxCompressedSize(body.size());
    out.resize(size);
    if (!BrotliEncoderCompress(5, BROTLI_DEFAULT_WINDOW, BROTLI_MODE_TEXT, body.size(),
                               reinterpret_cast<const uint8_t*>(body.data()), &size,
                               reinterpret_cast<uint8_t*>(out.data())))
      return std::string(body);  // cannot happen with a MaxCompressedSize buffer
    out.resize(size);
    return out;
  }
  if (coding == Coding::kGzip) {
    z_stream z{};
    deflateInit2(&z, 6, Z_DEFLATED, 15 + 16 /* gzip wrapper */, 8, Z_DEFAULT_STRATEGY);
    out.resize(deflateBound(&z, body.size()));
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(body.data()));
    z.avail_in = static_cast<uInt>(body.size());
    z.next_out = reinterpret_cast<Bytef*>(out.data());
    z.avail_out = static_cast<uInt>(out.size());
    deflate(&z, Z_FINISH);
    out.resize(z.total_out);
    deflateEnd(&z);
    return out;
  }
  return std::string(body);
}

}  // namespace effectd

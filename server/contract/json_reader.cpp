#include "contract/json_reader.h"

#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <utility>
#include <vector>

#include "contract/field_error.h"

namespace effectd {

using nlohmann::json;

namespace {

// Bytes a string can hold as they are: printable ASCII other than '"' and '\'.
constexpr std::array<bool, 256> kPlain = [] {
  std::array<bool, 256> t{};
  for (int c = 0x20; c < 0x80; ++c) t[c] = c != '"' && c != '\\';
  return t;
}();

bool isDigit(char c) { return c >= '0' && c <= '9'; }

int hexDigit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

void appendUtf8(std::string& s, uint32_t cp) {
  if (cp < 0x80) {
    s += char(cp);
  } else if (cp < 0x800) {
    s += char(0xC0 | (cp >> 6));
    s += char(0x80 | (cp & 0x3F));
  } else if (cp < 0x10000) {
    s += char(0xE0 | (cp >> 12));
    s += char(0x80 | ((cp >> 6) & 0x3F));
    s += char(0x80 | (cp & 0x3F));
  } else {
    s += char(0xF0 | (cp >> 18));
    s += char(0x80 | ((cp >> 12) & 0x3F));
    s += char(0x80 | ((cp >> 6) & 0x3F));
    s += char(0x80 | (cp & 0x3F));
  }
}

class Reader {
 public:
  Reader(std::string_view text, size_t maxDepth)
      : p_(text.data()), begin_(text.data()), end_(text.data() + text.size()), maxDepth_(maxDepth) {}

  json document() {
    if (p_ != end_ && uint8_t(*p_) == 0xEF) {  // a UTF-8 byte order mark
      if (end_ - p_ < 3 || uint8_t(p_[1]) != 0xBB || uint8_t(p_[2]) != 0xBF) fail("invalid byte order mark");
      p_ += 3;
    }
    json v;
    value(v, 0);
    skipSpace();
    if (p_ != end_) fail("unexpected text after the document");
    return v;
  }

 private:
  [[noreturn]] void fail(const char* what) const { throw JsonSyntaxError(size_t(p_ - begin_), what, false, pointer()); }

  // The JSON pointer of the value being read (RFC 6901), for the error: which field is broken.
  std::string pointer() const {
    std::string out;
    for (const auto& [key, index] : path_) {
      out += '/';
      out += key ? pointerEscape(*key) : std::to_string(index);
    }
    return out;
  }

  void skipSpace() {
    while (p_ != end_ && (*p_ == ' ' || *p_ == '\n' || *p_ == '\r' || *p_ == '\t')) ++p_;
  }

  void value(json& out, size_t depth) {
    skipSpace();
    if (p_ == end_) fail("expected a value, got the end of the text");
    switch (*p_) {
      case '{': return object(out, depth + 1);
      case '[': return array(out, depth + 1);
      case '"': {
        std::string s;
        string(s);
        out = std::move(s);
        return;
      }
      case 't': return literal("true", json(true), out);
      case 'f': return literal("false", json(false), out);
      case 'n': return literal("null", json(nullptr), out);
      default: return number(out);
    }
  }

  void literal(std::string_view word, json v, json& out) {
    if (size_t(end_ - p_) < word.size() || std::memcmp(p_, word.data(), word.size()) != 0) fail("invalid literal");
    p_ += word.size();
    out = std::move(v);
  }

  void enter(size_t depth) const {
    if (depth > maxDepth_)
      throw JsonSyntaxError(size_t(p_ - begin_), "nested deeper than " + std::to_string(maxDepth_) + " levels", true);
  }

  // Skips white space, then `c` if it comes next; whether it did.
  bool take(char c) {
    skipSpace();
    if (p_ == end_ || *p_ != c) return false;
    ++p_;
    return true;
  }

  void array(json& out, size_t depth) {
    enter(depth);
    ++p_;
    out = json::array();
    auto& items = out.get_ref<json::array_t&>();
    if (take(']')) return;
    path_.emplace_back(nullptr, 0);
    do {
      path_.back().second = items.size();
      value(items.emplace_back(), depth);
    } while (take(','));
    path_.pop_back();
    if (!take(']')) fail("expected ',' or ']'");
  }

  void object(json& out, size_t depth) {
    enter(depth);
    ++p_;
    out = json::object();
    auto& members = out.get_ref<json::object_t&>();
    if (take('}')) return;
    std::string key;
    do {
      skipSpace();
      if (p_ == end_ || *p_ != '"') fail("expected a member name in double quotes");
      key.clear();
      string(key);
      if (!take(':')) fail("expected ':' after a member name");
      path_.emplace_back(&key, 0);
      value(members[key], depth);  // a repeated name: the last value wins
      path_.pop_back();
    } while (take(','));
    if (!take('}')) fail("expected ',' or '}'");
  }

  // A string from its opening quote; plain runs are appended whole.
  void string(std::string& s) {
    ++p_;
    for (;;) {
      const char* run = p_;
      while (p_ != end_ && kPlain[uint8_t(*p_)]) ++p_;
      s.append(run, p_);
      if (p_ == end_) fail("unterminated string");
      const uint8_t c = uint8_t(*p_);
      if (c == '"') {
        ++p_;
        return;
      }
      if (c == '\\')
        escape(s);
      else if (c < 0x20)
        fail("control character in a string (it must be escaped)");
      else
        utf8(s);
    }
  }

  // One UTF-8 sequence of two to four bytes, well-formed as RFC 3629 defines it: no overlong
  // forms, no surrogates, nothing past U+10FFFF.
  void utf8(std::string& s) {
    const uint8_t c = uint8_t(*p_);
    int more = 0;
    uint8_t lo = 0x80, hi = 0xBF;  // the range of the second byte
    if (c >= 0xC2 && c <= 0xDF) {
      more = 1;
    } else if (c >= 0xE0 && c <= 0xEF) {
      more = 2;
      if (c == 0xE0) lo = 0xA0;
      if (c == 0xED) hi = 0x9F;
    } else if (c >= 0xF0 && c <= 0xF4) {
      more = 3;
      if (c == 0xF0) lo = 0x90;
      if (c == 0xF4) hi = 0x8F;
    } else {
      fail("ill-formed UTF-8 in a string");
    }
    if (end_ - p_ <= more) fail("ill-formed UTF-8 in a string");
    for (int i = 1; i <= more; ++i) {
      const uint8_t b = uint8_t(p_[i]);
      if (b < (i == 1 ? lo : 0x80) || b > (i == 1 ? hi : 0xBF)) fail("ill-formed UTF-8 in a string");
    }
    s.append(p_, size_t(more + 1));
    p_ += more + 1;
  }

  uint32_t hex4() {
    if (end_ - p_ < 4) fail("expected four hex digits after \\u");
    uint32_t v = 0;
    for (int i = 0; i < 4; ++i) {
      const int d = hexDigit(p_[i]);
      if (d < 0) fail("expected four hex digits after \\u");
      v = v * 16 + uint32_t(d);
    }
    p_ += 4;
    return v;
  }

  void escape(std::string& s) {
    ++p_;
    if (p_ == end_) fail("unterminated string");
    const char e = *p_++;
    switch (e) {
      case '"': s += '"'; return;
      case '\\': s += '\\'; return;
      case '/': s += '/'; return;
      case 'b': s += '\b'; return;
      case 'f': s += '\f'; return;
      case 'n': s += '\n'; return;
      case 'r': s += '\r'; return;
      case 't': s += '\t'; return;
      case 'u': break;
      default: --p_; fail("invalid escape in a string");
    }
    uint32_t cp = hex4();
    if (cp >= 0xDC00 && cp <= 0xDFFF) fail("a low surrogate \\u escape without a high one before it");
    if (cp >= 0xD800 && cp <= 0xDBFF) {
      if (end_ - p_ < 2 || p_[0] != '\\' || p_[1] != 'u')
        fail("a high surrogate \\u escape must be followed by a low one");
      p_ += 2;
      const uint32_t low = hex4();
      if (low < 0xDC00 || low > 0xDFFF) fail("a high surrogate \\u escape must be followed by a low one");
      cp = 0x10000 + ((cp - 0xD800) << 10) + (low - 0xDC00);
    }
    appendUtf8(s, cp);
  }

  // -?(0|[1-9][0-9]*)(\.[0-9]+)?([eE][+-]?[0-9]+)?: a 64-bit integer (unsigned unless negative)
  // when it has neither fraction nor exponent and fits, else the nearest double.
  void number(json& out) {
    const char* start = p_;
    const bool negative = *p_ == '-';
    if (negative) ++p_;
    if (p_ == end_ || !isDigit(*p_)) fail(negative ? "expected a digit after '-'" : "expected a value");
    if (*p_ == '0')
      ++p_;
    else
      while (p_ != end_ && isDigit(*p_)) ++p_;
    bool integral = true;
    if (p_ != end_ && *p_ == '.') {
      integral = false;
      ++p_;
      if (p_ == end_ || !isDigit(*p_)) fail("expected a digit after '.'");
      while (p_ != end_ && isDigit(*p_)) ++p_;
    }
    if (p_ != end_ && (*p_ == 'e' || *p_ == 'E')) {
      integral = false;
      ++p_;
      if (p_ != end_ && (*p_ == '+' || *p_ == '-')) ++p_;
      if (p_ == end_ || !isDigit(*p_)) fail("expected a digit in the exponent");
      while (p_ != end_ && isDigit(*p_)) ++p_;
    }
    if (integral) {
      if (negative) {
        int64_t v = 0;
        if (std::from_chars(start, p_, v).ec == std::errc()) {
          out = v;
          return;
        }
      } else {
        uint64_t v = 0;
        if (std::from_chars(start, p_, v).ec == std::errc()) {
          out = v;
          return;
        }
      }
    }
    double d = 0;
    if (std::from_chars(start, p_, d).ec == std::errc::result_out_of_range) {
      d = std::strtod(std::string(start, p_).c_str(), nullptr);  // the underflow, as strtod rounds it
      if (!std::isfinite(d)) {
        p_ = start;
        fail("number out of the range of a double");
      }
    }
    out = d;
  }

  const char* p_;
  const char* begin_;
  const char* end_;
  size_t maxDepth_;
  std::vector<std::pair<const std::string*, size_t>> path_;  // member name (or null) and index per level
};

}  // namespace

json readJson(std::string_view text, size_t maxDepth) { return Reader(text, maxDepth).document(); }

}  // namespace effectd

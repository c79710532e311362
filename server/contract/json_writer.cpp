#include "contract/json_writer.h"

#include <charconv>
#include <cmath>

namespace effectd {

namespace {

using nlohmann::json;

void writeString(const std::string& s, std::string& out) {
  // Plain ASCII (every key and almost every value effectd writes) is copied as is; anything
  // else goes through nlohmann's escaping, which also replaces invalid UTF-8.
  for (unsigned char c : s) {
    if (c < 0x20 || c >= 0x7F || c == '"' || c == '\\') {
      out += json(s).dump(-1, ' ', false, json::error_handler_t::replace);
      return;
    }
  }
  out += '"';
  out += s;
  out += '"';
}

void writeFloat(double d, std::string& out) {
  if (!std::isfinite(d)) {
    out += "null";
    return;
  }
  char buf[32];
  const float f = static_cast<float>(d);
  char* end = static_cast<double>(f) == d ? std::to_chars(buf, buf + sizeof buf, f).ptr
                                          : std::to_chars(buf, buf + sizeof buf, d).ptr;
  out.append(buf, end);
  // Keep the number a float for readers that care (1.0, not 1), as dump() does.
  bool integral = true;
  for (char* p = buf; p != end; ++p) integral = integral && (*p == '-' || (*p >= '0' && *p <= '9'));
  if (integral) out += ".0";
}

void write(const json& j, std::string& out) {
  switch (j.type()) {
    case json::value_t::object: {
      out += '{';
      bool first = true;
      for (const auto& [key, value] : j.items()) {
        if (!first) out += ',';
        first = false;
        writeString(key, out);
        out += ':';
        write(value, out);
      }
      out += '}';
      return;
    }
    case json::value_t::array: {
      out += '[';
      bool first = true;
      for (const auto& value : j) {
        if (!first) out += ',';
        first = false;
        write(value, out);
      }
      out += ']';
      return;
    }
    case json::value_t::string: writeString(j.get_ref<const std::string&>(), out); return;
    case json::value_t::boolean: out += j.get<bool>() ? "true" : "false"; return;
    case json::value_t::number_integer: {
      char buf[24];
      out.append(buf, std::to_chars(buf, buf + sizeof buf, j.get<json::number_integer_t>()).ptr);
      return;
    }
    case json::value_t::number_unsigned: {
      char buf[24];
      out.append(buf, std::to_chars(buf, buf + sizeof buf, j.get<json::number_unsigned_t>()).ptr);
      return;
    }
    case json::value_t::number_float: writeFloat(j.get<double>(), out); return;
    case json::value_t::binary:  // never in an answer; dump() would write it as an object
      out += j.dump();
      return;
    case json::value_t::null:
    case json::value_t::discarded: out += "null"; return;
  }
}

}  // namespace

std::string writeJson(const json& value) {
  std::string out;
  out.reserve(4096);
  write(value, out);
  return out;
}

}  // namespace effectd

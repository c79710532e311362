// A rule broken by one field of a request: where (a JSON pointer into the document, "" for
// the whole of it) and what. Schema violations, glTF problems and library errors all end up
// as a list of these in the answer's problem document (problem.h).
#pragma once

#include <string>

namespace effectd {

struct FieldError {
  std::string pointer;
  std::string message;
};

// Escapes a key for use in a JSON pointer (RFC 6901: "~" -> "~0", "/" -> "~1").
inline std::string pointerEscape(const std::string& key) {
  std::string out;
  out.reserve(key.size());
  for (char c : key) {
    if (c == '~')
      out += "~0";
    else if (c == '/')
      out += "~1";
    else
      out += c;
  }
  return out;
}

}  // namespace effectd

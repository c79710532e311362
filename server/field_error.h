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

}  // namespace effectd

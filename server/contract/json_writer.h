// Answers as JSON text, compact, with every number in the shortest form that reads back to
// the same value: a number that is exactly a float32 (geometry, tables and colours are float
// on the wire) as the shortest decimal that reads back to that float32 (0.7f goes out as 0.7,
// not 0.699999988079071); any other double as the shortest decimal of the double. Non-finite
// numbers become null, as nlohmann's dump() writes them. One pass over the document with
// std::to_chars, which is also faster than dump() (grisu2 plus a float round trip).
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace effectd {

std::string writeJson(const nlohmann::json& value);

}  // namespace effectd

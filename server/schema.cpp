#include "schema.h"

#include <cmath>
#include <set>
#include <sstream>
#include <stdexcept>

namespace effectd {

using nlohmann::json;

std::string pointerEscape(const std::string& key) {
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

namespace {

const std::set<std::string> kKeywords = {
    "type", "enum", "const", "properties", "required", "additionalProperties", "items", "minItems", "maxItems",
    "minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum", "minLength", "maxLength", "oneOf", "anyOf", "allOf",
    "$ref", "$defs",
    // annotations
    "title", "description", "default", "examples", "$schema", "$id", "$comment", "format", "contentEncoding",
    "contentMediaType", "deprecated", "readOnly", "writeOnly"};

std::string typeOf(const json& v) {
  switch (v.type()) {
    case json::value_t::null: return "null";
    case json::value_t::boolean: return "boolean";
    case json::value_t::number_integer:
    case json::value_t::number_unsigned: return "integer";
    case json::value_t::number_float: return "number";
    case json::value_t::string: return "string";
    case json::value_t::array: return "array";
    case json::value_t::object: return "object";
    default: return "unknown";
  }
}

bool hasType(const json& v, const std::string& t) {
  if (t == "number") return v.is_number();
  if (t == "integer") {
    if (v.is_number_integer()) return true;
    if (v.is_number_float()) {
      double d = v.get<double>();
      return std::isfinite(d) && std::floor(d) == d && std::fabs(d) < 9.007199254740992e15;
    }
    return false;
  }
  return typeOf(v) == t;
}

std::string fmtNumber(const json& n) {
  std::ostringstream os;
  os << n.get<double>();
  return os.str();
}

// Counts UTF-8 code points (the JSON Schema notion of string length).
size_t codePoints(const std::string& s) {
  size_t n = 0;
  for (unsigned char c : s) n += (c & 0xC0) != 0x80;
  return n;
}

// The violations found so far, capped: once `maxErrors` are in, the rest are dropped.
struct Errors {
  std::vector<FieldError> errors;
  size_t maxErrors;
  bool full() const { return errors.size() >= maxErrors; }
  void add(const std::string& pointer, std::string message) {
    if (!full()) errors.push_back({pointer, std::move(message)});
  }
};

// The keyword families of SchemaRegistry::check, in the order it applies them. Those that
// descend into members take `walk(schema, value, pointer)`, which checks one member against
// its subschema with the same errors and depth.

// "type"; false when `v` has the wrong type: the remaining keywords would only repeat the
// same complaint.
bool checkType(const json& s, const json& v, const std::string& ptr, Errors& out) {
  auto it = s.find("type");
  if (it == s.end()) return true;
  bool ok = false;
  std::string expected;
  if (it->is_string()) {
    ok = hasType(v, it->get<std::string>());
    expected = it->get<std::string>();
  } else {
    for (const auto& t : *it) {
      ok = ok || hasType(v, t.get<std::string>());
      expected += (expected.empty() ? "" : " or ") + t.get<std::string>();
    }
  }
  if (!ok) out.add(ptr, "must be " + expected + ", got " + typeOf(v));
  return ok;
}

// "const" and "enum".
void checkValue(const json& s, const json& v, const std::string& ptr, Errors& out) {
  if (auto it = s.find("const"); it != s.end() && v != *it) out.add(ptr, "must be " + it->dump());
  if (auto it = s.find("enum"); it != s.end()) {
    bool found = false;
    for (const auto& e : *it) found = found || e == v;
    if (!found) out.add(ptr, "must be one of " + it->dump());
  }
}

// "minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum".
void checkNumber(const json& s, const json& v, const std::string& ptr, Errors& out) {
  if (!v.is_number()) return;
  double d = v.get<double>();
  if (auto it = s.find("minimum"); it != s.end() && d < it->get<double>()) out.add(ptr, "must be >= " + fmtNumber(*it));
  if (auto it = s.find("maximum"); it != s.end() && d > it->get<double>()) out.add(ptr, "must be <= " + fmtNumber(*it));
  if (auto it = s.find("exclusiveMinimum"); it != s.end() && d <= it->get<double>())
    out.add(ptr, "must be > " + fmtNumber(*it));
  if (auto it = s.find("exclusiveMaximum"); it != s.end() && d >= it->get<double>())
    out.add(ptr, "must be < " + fmtNumber(*it));
}

// "minLength", "maxLength", in code points.
void checkString(const json& s, const json& v, const std::string& ptr, Errors& out) {
  if (!v.is_string()) return;
  size_t n = codePoints(v.get_ref<const std::string&>());
  if (auto it = s.find("minLength"); it != s.end() && n < it->get<size_t>())
    out.add(ptr, "must have at least " + it->dump() + " characters");
  if (auto it = s.find("maxLength"); it != s.end() && n > it->get<size_t>())
    out.add(ptr, "must have at most " + it->dump() + " characters");
}

// "minItems", "maxItems", "items"; false for an array over maxItems, which is not walked and
// ends the check.
template <typename Walk>
bool checkArray(const json& s, const json& v, const std::string& ptr, Errors& out, const Walk& walk) {
  if (!v.is_array()) return true;
  if (auto it = s.find("minItems"); it != s.end() && v.size() < it->get<size_t>())
    out.add(ptr, "must have at least " + it->dump() + " items");
  if (auto it = s.find("maxItems"); it != s.end() && v.size() > it->get<size_t>()) {
    out.add(ptr, "must have at most " + it->dump() + " items");
    return false;
  }
  if (auto it = s.find("items"); it != s.end()) {
    for (size_t i = 0; i < v.size() && !out.full(); ++i) walk(*it, v[i], ptr + "/" + std::to_string(i));
  }
  return true;
}

// "required", "properties", "additionalProperties".
template <typename Walk>
void checkObject(const json& s, const json& v, const std::string& ptr, Errors& out, const Walk& walk) {
  if (!v.is_object()) return;
  const json* props = nullptr;
  if (auto it = s.find("properties"); it != s.end()) props = &*it;
  if (auto it = s.find("required"); it != s.end()) {
    for (const auto& r : *it) {
      if (!v.contains(r.get<std::string>())) out.add(ptr + "/" + pointerEscape(r.get<std::string>()), "is required");
    }
  }
  auto additional = s.find("additionalProperties");
  for (const auto& [key, val] : v.items()) {
    std::string child = ptr + "/" + pointerEscape(key);
    if (props && props->contains(key)) {
      walk((*props)[key], val, child);
    } else if (additional != s.end()) {
      if (additional->is_boolean() && !additional->get<bool>())
        out.add(child, "is not a known field");
      else
        walk(*additional, val, child);
    }
  }
}

// For alternatives that each only require one member ({"required": ["box"]}, ...): the members
// as "box or sphere" ("color, gradient or image"); "" for any other kind of alternatives.
std::string exclusiveMembers(const json& alternatives) {
  std::vector<std::string> names;
  for (const auto& branch : alternatives) {
    if (!branch.is_object() || branch.size() != 1 || !branch.contains("required") || branch["required"].size() != 1)
      return "";
    names.push_back(branch["required"][0].get<std::string>());
  }
  std::string out;
  for (size_t i = 0; i < names.size(); ++i) out += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
  return out;
}

// "oneOf" and "anyOf". `tryBranch(schema)` checks the value at `ptr` against one alternative
// on its own (a few errors at most) and returns what it found; the report names the
// alternative the client most likely meant.
template <typename TryBranch>
void checkAlternatives(const json& s, const std::string& ptr, Errors& out, const TryBranch& tryBranch) {
  for (const char* kw : {"oneOf", "anyOf"}) {
    auto it = s.find(kw);
    if (it == s.end()) continue;
    size_t matches = 0;
    std::vector<FieldError> firstErrors;
    std::vector<std::string> missing;  // branches that fail only for a missing member
    for (const auto& branch : *it) {
      std::vector<FieldError> errors = tryBranch(branch);
      if (errors.empty())
        ++matches;
      else if (firstErrors.empty() || errors.front().pointer.size() > firstErrors.front().pointer.size())
        firstErrors = errors;  // the branch that got deepest is the one the client meant
      if (errors.size() == 1 && errors.front().message == "is required" &&
          errors.front().pointer.rfind(ptr + "/", 0) == 0)
        missing.push_back(errors.front().pointer.substr(ptr.size() + 1));
    }
    bool ok = std::string(kw) == "oneOf" ? matches == 1 : matches >= 1;
    if (!ok) {
      if (matches > 1) {
        const std::string members = exclusiveMembers(*it);
        out.add(ptr, members.empty() ? "matches more than one alternative" : "give exactly one of " + members);
      } else if (missing.size() == it->size()) {  // none of the alternatives' members given
        std::string names;
        for (const auto& m : missing) names += (names.empty() ? "" : ", ") + m;
        out.add(ptr, "needs one of: " + names);
      } else {
        for (auto& e : firstErrors) out.add(e.pointer, e.message);
      }
    }
  }
}

}  // namespace

struct SchemaRegistry::Ctx : Errors {
  explicit Ctx(size_t maxErrors) : Errors{{}, maxErrors} {}
  int depth = 0;  // $ref nesting, to stop a cyclic reference
};

SchemaRegistry::SchemaRegistry(const std::map<std::string, std::string>& documents) {
  for (const auto& [name, text] : documents) {
    if (name.size() < 5 || name.substr(name.size() - 5) != ".json") continue;
    try {
      docs_[name] = json::parse(text);
    } catch (const json::exception& e) {
      throw std::runtime_error("schema " + name + " is not valid JSON: " + e.what());
    }
  }
  for (const auto& [name, doc] : docs_) lint(doc, name, "");
}

void SchemaRegistry::lint(const json& schema, const std::string& doc, const std::string& where) const {
  if (schema.is_boolean()) return;
  if (!schema.is_object()) throw std::runtime_error(doc + where + ": schema must be an object");
  for (const auto& [key, sub] : schema.items()) {
    if (key.rfind("x-", 0) == 0) continue;
    if (!kKeywords.count(key)) throw std::runtime_error(doc + where + ": unsupported keyword '" + key + "'");
    if (key == "properties" || key == "$defs") {
      for (const auto& [k, s] : sub.items()) lint(s, doc, where + "/" + key + "/" + k);
    } else if (key == "items" || key == "additionalProperties") {
      lint(sub, doc, where + "/" + key);
    } else if (key == "oneOf" || key == "anyOf" || key == "allOf") {
      for (size_t i = 0; i < sub.size(); ++i) lint(sub[i], doc, where + "/" + key + "/" + std::to_string(i));
    } else if (key == "$ref") {
      std::string d;
      resolve(sub.get<std::string>(), doc, d);
    }
  }
}

const json& SchemaRegistry::document(const std::string& name) const {
  auto it = docs_.find(name);
  if (it == docs_.end()) throw std::runtime_error("no schema document " + name);
  return it->second;
}

const json& SchemaRegistry::resolve(const std::string& ref, const std::string& doc, std::string& outDoc) const {
  auto hash = ref.find('#');
  outDoc = hash == 0 ? doc : ref.substr(0, hash);
  const json& root = document(outDoc);
  if (hash == std::string::npos || hash + 1 == ref.size()) return root;
  try {
    return root.at(json::json_pointer(ref.substr(hash + 1)));
  } catch (const json::exception&) {
    throw std::runtime_error("unresolvable $ref " + ref + " in " + doc);
  }
}

std::vector<FieldError> SchemaRegistry::validate(const std::string& name, const json& instance,
                                                 size_t maxErrors) const {
  Ctx ctx{maxErrors};
  check(document(name), name, instance, "", ctx);
  return ctx.errors;
}

void SchemaRegistry::check(const json& s, const std::string& doc, const json& v, const std::string& ptr,
                           Ctx& ctx) const {
  if (ctx.full()) return;
  if (s.is_boolean()) {
    if (!s.get<bool>()) ctx.add(ptr, "is not allowed here");
    return;
  }
  if (++ctx.depth > 64) {  // the contract is far shallower; deeper means a cyclic $ref
    ctx.add(ptr, "nesting too deep");
    --ctx.depth;
    return;
  }
  struct DepthGuard {
    int& d;
    ~DepthGuard() { --d; }
  } guard{ctx.depth};
  auto walk = [&](const json& sub, const json& member, const std::string& memberPtr) {
    check(sub, doc, member, memberPtr, ctx);
  };
  auto tryBranch = [&](const json& branch) {
    Ctx sub{4};
    check(branch, doc, v, ptr, sub);
    return std::move(sub.errors);
  };

  if (auto it = s.find("$ref"); it != s.end()) {
    std::string target;
    const json& sub = resolve(it->get<std::string>(), doc, target);
    check(sub, target, v, ptr, ctx);
  }
  if (!checkType(s, v, ptr, ctx)) return;
  checkValue(s, v, ptr, ctx);
  checkNumber(s, v, ptr, ctx);
  checkString(s, v, ptr, ctx);
  if (!checkArray(s, v, ptr, ctx, walk)) return;
  checkObject(s, v, ptr, ctx, walk);
  checkAlternatives(s, ptr, ctx, tryBranch);
  if (auto it = s.find("allOf"); it != s.end()) {
    for (const auto& branch : *it) check(branch, doc, v, ptr, ctx);
  }
}

}  // namespace effectd

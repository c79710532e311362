#include "contract/schema.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <set>
#include <stdexcept>
#include <string_view>
#include <vector>

namespace effectd {

using nlohmann::json;

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

// JSON Schema's types as bits, so that "type" is one AND per value.
enum TypeBit : unsigned {
  kNull = 1,
  kBoolean = 2,
  kInteger = 4,  // an integer, or a float with an integral value
  kFloat = 8,    // a float with a fractional part (or out of the exact-integer range)
  kString = 16,
  kArray = 32,
  kObject = 64,
};

unsigned typeBitsOf(const std::string& t) {
  if (t == "null") return kNull;
  if (t == "boolean") return kBoolean;
  if (t == "integer") return kInteger;
  if (t == "number") return kInteger | kFloat;
  if (t == "string") return kString;
  if (t == "array") return kArray;
  if (t == "object") return kObject;
  return 0;  // an unknown type name matches nothing
}

unsigned typeBitOf(const json& v) {
  switch (v.type()) {
    case json::value_t::null: return kNull;
    case json::value_t::boolean: return kBoolean;
    case json::value_t::number_integer:
    case json::value_t::number_unsigned: return kInteger;
    case json::value_t::number_float: {
      const double d = v.get<double>();
      return std::isfinite(d) && std::floor(d) == d && std::fabs(d) < 9.007199254740992e15 ? kInteger : kFloat;
    }
    case json::value_t::string: return kString;
    case json::value_t::array: return kArray;
    case json::value_t::object: return kObject;
    default: return 0;
  }
}

// A schema's number as written: 16777216, 0.5, 1e-300 (the shortest text that reads back the
// same double; iostream's default cut 16777216 to 1.67772e+07).
std::string fmtNumber(const json& n) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, n.get<double>());
  return ec == std::errc() ? std::string(buf, end) : n.dump();
}

// Counts UTF-8 code points (the JSON Schema notion of string length).
size_t codePoints(const std::string& s) {
  size_t n = 0;
  for (unsigned char c : s) n += (c & 0xC0) != 0x80;
  return n;
}

// A bound on a number ("minimum", ...) or a size ("minItems", ...), with its message.
struct Bound {
  bool set = false;
  double value = 0;
  std::string message;
};

Bound numberBound(const json& s, const char* keyword, const char* prefix) {
  auto it = s.find(keyword);
  if (it == s.end()) return {};
  if (!it->is_number()) throw std::invalid_argument(std::string(keyword) + " must be a number");
  return {true, it->get<double>(), prefix + fmtNumber(*it)};
}

Bound sizeBound(const json& s, const char* keyword, const char* prefix, const char* suffix) {
  auto it = s.find(keyword);
  if (it == s.end()) return {};
  if (typeBitOf(*it) != kInteger || it->get<double>() < 0)
    throw std::invalid_argument(std::string(keyword) + " must be a non-negative integer");
  return {true, it->get<double>(), prefix + it->dump() + suffix};
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

// Letters to turn `a` into `b` (insertions, deletions, substitutions and swaps of neighbours,
// case ignored): how far an unknown field is from a known one.
size_t editDistance(std::string_view a, std::string_view b) {
  const auto lower = [](char c) { return char(std::tolower(static_cast<unsigned char>(c))); };
  std::vector<std::vector<size_t>> d(a.size() + 1, std::vector<size_t>(b.size() + 1));
  for (size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (size_t i = 1; i <= a.size(); ++i)
    for (size_t j = 1; j <= b.size(); ++j) {
      const bool same = lower(a[i - 1]) == lower(b[j - 1]);
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + (same ? 0 : 1)});
      if (i > 1 && j > 1 && lower(a[i - 1]) == lower(b[j - 2]) && lower(a[i - 2]) == lower(b[j - 1]))
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
    }
  return d[a.size()][b.size()];
}

// "is not a known field", with the one known field it most likely meant: within a third of its
// letters (at least one), and nearer than any other ("colour" -> "color", "fogtype" -> "fogType").
template <typename Properties>
std::string unknownField(const std::string& key, const Properties& known) {
  std::string best;
  size_t bestDistance = std::max<size_t>(1, key.size() / 3) + 1, ties = 0;
  if (key.size() <= 64)  // a long key is no typo; the distance costs its length squared
    for (const auto& [name, _] : known) {
      const size_t d = editDistance(key, name);
      if (d < bestDistance) best = name, bestDistance = d, ties = 0;
      else if (d == bestDistance) ++ties;
    }
  if (best.empty() || ties) return "is not a known field";
  return "is not a known field: did you mean \"" + best + "\"?";
}

}  // namespace

// One schema object (or boolean schema) with its keywords looked up once, at load.
struct SchemaRegistry::Node {
  int boolean = -1;  // a boolean schema: 0 (false) or 1 (true); -1 for an object
  const Node* ref = nullptr;
  bool typed = false;       // has "type"
  unsigned types = 0;       // "type" as TypeBits
  std::string typeMessage;  // "must be integer or null" (", got <type>" follows)
  const json* constValue = nullptr;
  std::string constMessage;
  const json* enumValues = nullptr;
  std::string enumMessage;
  Bound minimum, maximum, exclusiveMinimum, exclusiveMaximum;
  Bound minLength, maxLength, minItems, maxItems;
  const Node* items = nullptr;
  std::vector<std::string> required;
  std::map<std::string, const Node*, std::less<>> properties;
  enum class Additional { kAny, kForbidden, kSchema } additional = Additional::kAny;
  const Node* additionalSchema = nullptr;
  struct Alternatives {
    bool oneOf = false;
    std::vector<const Node*> branches;
    std::string exclusiveMembers;  // exclusiveMembers() of the branches
  };
  std::vector<Alternatives> alternatives;  // oneOf, then anyOf
  std::vector<const Node*> allOf;
};

// Where a value sits in the instance, spelled out as a JSON pointer only when reported.
struct SchemaRegistry::Path {
  const Path* parent = nullptr;
  const std::string* key = nullptr;  // an object member; else an array index
  size_t index = 0;
  std::string str() const {
    if (!parent) return "";
    return parent->str() + "/" + (key ? pointerEscape(*key) : std::to_string(index));
  }
};

// The violations found so far, capped: once `maxErrors` are in, the rest are dropped.
struct SchemaRegistry::Ctx {
  std::vector<FieldError> errors;
  size_t maxErrors;
  int depth = 0;  // schema nesting (every check, alternatives included), to stop a cyclic $ref
  bool full() const { return errors.size() >= maxErrors; }
  void add(const Path& at, std::string message) {
    if (!full()) errors.push_back({at.str(), std::move(message)});
  }
};

SchemaRegistry::~SchemaRegistry() = default;
SchemaRegistry::SchemaRegistry(SchemaRegistry&&) noexcept = default;

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
  for (const auto& [name, doc] : docs_) roots_[name] = &compile(doc, name);
}

const SchemaRegistry::Node& SchemaRegistry::compile(const json& s, const std::string& doc) {
  if (auto it = nodes_.find(&s); it != nodes_.end()) return *it->second;
  Node& n = *nodes_.emplace(&s, std::make_unique<Node>()).first->second;  // before the members: $ref cycles
  if (s.is_boolean()) {
    n.boolean = s.get<bool>();
    return n;
  }
  try {
    if (auto it = s.find("$ref"); it != s.end()) {
      std::string target;
      const json& sub = resolve(it->get<std::string>(), doc, target);
      n.ref = &compile(sub, target);
    }
    if (auto it = s.find("type"); it != s.end()) {
      n.typed = true;
      std::string names;
      for (const auto& t : it->is_string() ? json::array({*it}) : *it) {
        n.types |= typeBitsOf(t.get<std::string>());
        names += (names.empty() ? "" : " or ") + t.get<std::string>();
      }
      n.typeMessage = "must be " + names;
    }
    if (auto it = s.find("const"); it != s.end()) {
      n.constValue = &*it;
      n.constMessage = "must be " + it->dump();
    }
    if (auto it = s.find("enum"); it != s.end()) {
      n.enumValues = &*it;
      n.enumMessage = "must be one of " + it->dump();
    }
    n.minimum = numberBound(s, "minimum", "must be >= ");
    n.maximum = numberBound(s, "maximum", "must be <= ");
    n.exclusiveMinimum = numberBound(s, "exclusiveMinimum", "must be > ");
    n.exclusiveMaximum = numberBound(s, "exclusiveMaximum", "must be < ");
    n.minLength = sizeBound(s, "minLength", "must have at least ", " characters");
    n.maxLength = sizeBound(s, "maxLength", "must have at most ", " characters");
    n.minItems = sizeBound(s, "minItems", "must have at least ", " items");
    n.maxItems = sizeBound(s, "maxItems", "must have at most ", " items");
    if (auto it = s.find("items"); it != s.end()) n.items = &compile(*it, doc);
    if (auto it = s.find("required"); it != s.end())
      for (const auto& r : *it) n.required.push_back(r.get<std::string>());
    if (auto it = s.find("properties"); it != s.end())
      for (const auto& [key, sub] : it->items()) n.properties[key] = &compile(sub, doc);
    if (auto it = s.find("additionalProperties"); it != s.end()) {
      if (it->is_boolean() && !it->get<bool>()) {
        n.additional = Node::Additional::kForbidden;
      } else {
        n.additional = Node::Additional::kSchema;
        n.additionalSchema = &compile(*it, doc);
      }
    }
    for (const char* kw : {"oneOf", "anyOf"}) {
      auto it = s.find(kw);
      if (it == s.end()) continue;
      Node::Alternatives a{std::string(kw) == "oneOf", {}, exclusiveMembers(*it)};
      for (const auto& branch : *it) a.branches.push_back(&compile(branch, doc));
      n.alternatives.push_back(std::move(a));
    }
    if (auto it = s.find("allOf"); it != s.end())
      for (const auto& branch : *it) n.allOf.push_back(&compile(branch, doc));
  } catch (const json::exception& e) {  // a keyword's value of the wrong JSON type
    throw std::runtime_error("schema " + doc + ": malformed keyword value: " + e.what());
  } catch (const std::invalid_argument& e) {  // a bound that is no number or size
    throw std::runtime_error("schema " + doc + ": " + e.what());
  }
  return n;
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
  auto root = roots_.find(name);
  if (root == roots_.end()) document(name);  // throws: no such document
  Ctx ctx{{}, maxErrors};
  check(*root->second, instance, Path{}, ctx);
  return std::move(ctx.errors);
}

// The keyword families in a fixed order: $ref; type (a wrong type ends the check: the rest would
// only repeat it); const and enum; number bounds; string lengths; array sizes and items (an
// array over maxItems is not walked, and ends the check); required, properties and
// additionalProperties; oneOf and anyOf; allOf.
// Long because the keyword families run in this one fixed order, each a few lines.
void SchemaRegistry::check(const Node& s, const json& v, const Path& path, Ctx& ctx) const {
  if (ctx.full()) return;
  if (s.boolean >= 0) {
    if (!s.boolean) ctx.add(path, "is not allowed here");
    return;
  }
  if (++ctx.depth > 64) {  // the contract is far shallower; deeper means a cyclic $ref
    ctx.add(path, "nesting too deep");
    --ctx.depth;
    return;
  }
  struct DepthGuard {
    int& d;
    ~DepthGuard() { --d; }
  } guard{ctx.depth};

  if (s.ref) check(*s.ref, v, path, ctx);
  const unsigned type = typeBitOf(v);
  if (s.typed && !(s.types & type)) {
    ctx.add(path, s.typeMessage + ", got " + typeOf(v));
    return;
  }
  if (s.constValue && v != *s.constValue) ctx.add(path, s.constMessage);
  if (s.enumValues) {
    bool found = false;
    for (const auto& e : *s.enumValues) found = found || e == v;
    if (!found) ctx.add(path, s.enumMessage);
  }
  if (type & (kInteger | kFloat)) {
    const double d = v.get<double>();
    if (s.minimum.set && d < s.minimum.value) ctx.add(path, s.minimum.message);
    if (s.maximum.set && d > s.maximum.value) ctx.add(path, s.maximum.message);
    if (s.exclusiveMinimum.set && d <= s.exclusiveMinimum.value) ctx.add(path, s.exclusiveMinimum.message);
    if (s.exclusiveMaximum.set && d >= s.exclusiveMaximum.value) ctx.add(path, s.exclusiveMaximum.message);
  } else if (type == kString && (s.minLength.set || s.maxLength.set)) {
    const double n = double(codePoints(v.get_ref<const std::string&>()));
    if (s.minLength.set && n < s.minLength.value) ctx.add(path, s.minLength.message);
    if (s.maxLength.set && n > s.maxLength.value) ctx.add(path, s.maxLength.message);
  } else if (type == kArray) {
    const double n = double(v.size());
    if (s.minItems.set && n < s.minItems.value) ctx.add(path, s.minItems.message);
    if (s.maxItems.set && n > s.maxItems.value) {
      ctx.add(path, s.maxItems.message);
      return;
    }
    if (s.items) {
      Path item{&path, nullptr, 0};
      for (; item.index < v.size() && !ctx.full(); ++item.index) check(*s.items, v[item.index], item, ctx);
    }
  } else if (type == kObject) {
    for (const auto& r : s.required)
      if (!v.contains(r)) {
        const Path member{&path, &r, 0};
        ctx.add(member, "is required");
      }
    for (const auto& [key, value] : v.items()) {
      const Path member{&path, &key, 0};
      if (auto p = s.properties.find(key); p != s.properties.end())
        check(*p->second, value, member, ctx);
      else if (s.additional == Node::Additional::kForbidden)
        ctx.add(member, unknownField(key, s.properties));
      else if (s.additional == Node::Additional::kSchema)
        check(*s.additionalSchema, value, member, ctx);
    }
  }
  // Each alternative is tried on its own (a few errors at most); the report names the one the
  // client most likely meant.
  for (const auto& alt : s.alternatives) {
    std::string ptr;  // spelled out only for a branch that misses one member
    size_t matches = 0;
    std::vector<FieldError> firstErrors;
    std::vector<std::string> missing;  // branches that fail only for a missing member
    for (const Node* branch : alt.branches) {
      Ctx sub{{}, 4, ctx.depth};
      check(*branch, v, path, sub);
      const std::vector<FieldError>& errors = sub.errors;
      if (errors.empty())
        ++matches;
      else if (firstErrors.empty() || errors.front().pointer.size() > firstErrors.front().pointer.size())
        firstErrors = errors;  // the branch that got deepest is the one the client meant
      if (errors.size() == 1 && errors.front().message == "is required") {
        if (ptr.empty()) ptr = path.str() + "/";
        if (errors.front().pointer.rfind(ptr, 0) == 0) missing.push_back(errors.front().pointer.substr(ptr.size()));
      }
    }
    if (alt.oneOf ? matches == 1 : matches >= 1) continue;
    if (matches > 1) {
      ctx.add(path, alt.exclusiveMembers.empty() ? "matches more than one alternative"
                                                 : "give exactly one of " + alt.exclusiveMembers);
    } else if (missing.size() == alt.branches.size()) {  // none of the alternatives' members given
      std::string names;
      for (const auto& m : missing) names += (names.empty() ? "" : ", ") + m;
      ctx.add(path, "needs one of: " + names);
    } else {
      for (auto& e : firstErrors)
        if (!ctx.full()) ctx.errors.push_back(std::move(e));
    }
  }
  for (const Node* branch : s.allOf) check(*branch, v, path, ctx);
}

}  // namespace effectd

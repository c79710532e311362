// JSON Schema validation of request bodies against the contract in proto/schemas.
//
// A focused subset of JSON Schema 2020-12, exactly what proto/ uses: type, enum, const,
// properties, required, additionalProperties (false or a schema), items, minItems, maxItems,
// minimum, maximum, exclusiveMinimum, exclusiveMaximum, minLength, maxLength, oneOf, anyOf,
// allOf, $ref (within a document, "#/$defs/x", or across documents, "common.json#/$defs/x").
// Annotation keywords (title, description, default, examples, $schema, $id, x-*) are ignored.
// A keyword outside this subset is a programming error: the registry refuses to load it, so
// the contract cannot silently say more than the server checks. tests/schema_suite_test.cpp
// runs the official JSON-Schema-Test-Suite on this subset.
//
// Each schema object is compiled once, at load, into a Node holding its keywords already looked
// up and their messages already written, and a member's JSON pointer is only spelled out when
// it is reported: a 250 000-number mesh is checked in a few milliseconds, not tens.
#pragma once

#include <map>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include <nlohmann/json.hpp>

#include "contract/field_error.h"

namespace effectd {

class SchemaRegistry {
 public:
  // Loads every document whose key ends in ".json"; keys are file names ("fog.json").
  // Throws std::runtime_error on a malformed schema (startup only).
  explicit SchemaRegistry(const std::map<std::string, std::string>& documents);
  ~SchemaRegistry();
  SchemaRegistry(SchemaRegistry&&) noexcept;

  // Validates `instance` against document `name`; returns at most `maxErrors` violations.
  std::vector<FieldError> validate(const std::string& name, const nlohmann::json& instance,
                                   size_t maxErrors = 16) const;

  const nlohmann::json& document(const std::string& name) const;

 private:
  struct Node;
  struct Path;
  struct Ctx;
  void check(const Node& schema, const nlohmann::json& value, const Path& path, Ctx& ctx) const;
  const Node& compile(const nlohmann::json& schema, const std::string& doc);
  const nlohmann::json& resolve(const std::string& ref, const std::string& doc, std::string& outDoc) const;
  void lint(const nlohmann::json& schema, const std::string& doc, const std::string& where) const;

  std::map<std::string, nlohmann::json> docs_;
  // Every schema object of docs_ reachable from a document's root, by its address in docs_.
  std::unordered_map<const nlohmann::json*, std::unique_ptr<Node>> nodes_;
  std::map<std::string, const Node*> roots_;
};

}  // namespace effectd

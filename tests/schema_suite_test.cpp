// server/contract/schema.cpp against the official JSON-Schema-Test-Suite (Debian's json-schema-test-suite;
// draft 7 is the newest it ships). Every test group whose schema stays within the validator's
// keyword subset must give the suite's verdict on every instance; groups using a keyword
// outside the subset are refused at load (as the registry refuses any such contract) and only
// counted. Draft 7's "definitions" are read as 2020-12's "$defs" so that the $ref tests run.
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "contract/schema.h"

namespace effectd {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

// The keywords server/contract/schema.h accepts, one suite file each, plus $ref and boolean schemas.
const char* const kFiles[] = {"type",
                              "enum",
                              "const",
                              "properties",
                              "required",
                              "additionalProperties",
                              "items",
                              "minItems",
                              "maxItems",
                              "minimum",
                              "maximum",
                              "exclusiveMinimum",
                              "exclusiveMaximum",
                              "minLength",
                              "maxLength",
                              "oneOf",
                              "anyOf",
                              "allOf",
                              "ref",
                              "boolean_schema",
                              "default"};

// Where draft 7 and 2020-12 (the contract's dialect) disagree, the group is 2020-12's to win.
const char* const kDraft7Only[] = {
    "ref overrides any sibling keywords",  // 2020-12 applies $ref's siblings (Core 8.2.3.1)
};

// Draft 7's "definitions" -> "$defs", in keys and in "#/definitions/..." references.
json toDefs(json s) {
  if (s.is_object()) {
    json out = json::object();
    for (auto& [k, v] : s.items()) {
      if (k == "$ref" && v.is_string()) {
        std::string r = v.get<std::string>();
        if (r.rfind("#/definitions/", 0) == 0) r = "#/$defs/" + r.substr(14);
        out[k] = r;
      } else {
        out[k == "definitions" ? "$defs" : k] = toDefs(v);
      }
    }
    return out;
  }
  if (s.is_array())
    for (auto& v : s) v = toDefs(v);
  return s;
}

TEST(JsonSchemaTestSuite, Draft7GroupsWithinTheSubsetGiveTheSuitesVerdicts) {
  const fs::path dir = EFFECTD_JSON_SCHEMA_SUITE;
  ASSERT_TRUE(fs::is_directory(dir)) << dir << " missing: scripts/setup.sh installs json-schema-test-suite";
  size_t groups = 0, cases = 0, refused = 0;
  for (const char* file : kFiles) {
    std::ifstream in(dir / (std::string(file) + ".json"));
    ASSERT_TRUE(in) << file;
    size_t ranHere = 0;
    for (const json& group : json::parse(in)) {
      const std::string what = std::string(file) + ": " + group["description"].get<std::string>();
      if (std::find(std::begin(kDraft7Only), std::end(kDraft7Only), group["description"]) != std::end(kDraft7Only))
        continue;
      std::unique_ptr<SchemaRegistry> registry;
      try {
        registry = std::make_unique<SchemaRegistry>(
            std::map<std::string, std::string>{{"t.json", toDefs(group["schema"]).dump()}});
      } catch (const std::runtime_error&) {
        ++refused;  // a keyword (or a remote $ref) outside the subset
        continue;
      }
      ++groups;
      ++ranHere;
      for (const json& t : group["tests"]) {
        ++cases;
        const auto errors = registry->validate("t.json", t["data"]);
        EXPECT_EQ(errors.empty(), t["valid"].get<bool>())
            << what << " / " << t["description"].get<std::string>() << "\n  data " << t["data"].dump()
            << (errors.empty() ? std::string() : "\n  first error " + errors[0].pointer + " " + errors[0].message);
      }
    }
    EXPECT_GT(ranHere, 0u) << file << ": no group ran; the subset should cover it";
  }
  std::printf("JSON-Schema-Test-Suite draft 7: %zu groups, %zu instances checked; %zu groups refused at load\n", groups,
              cases, refused);
  EXPECT_GE(cases, 200u);  // 222 with the suite Debian 12 ships
}

}  // namespace
}  // namespace effectd

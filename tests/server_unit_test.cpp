// Server building blocks without sockets: schema validator, codecs, configuration, bolt ribbons.
#include <cmath>
#include <cstdlib>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>
#include <gtest/gtest.h>

#include "api/bolt_ribbons.h"
#include "contract/codec.h"
#include "contract/config.h"
#include "contract/json_reader.h"
#include "contract/problem.h"
#include "contract/schema.h"

namespace effectd {
namespace {

using nlohmann::json;

SchemaRegistry registry() {
  return SchemaRegistry(
      {{"a.json", R"({
      "type": "object", "additionalProperties": false, "required": ["n"],
      "properties": {
        "n": {"type": "integer", "minimum": 1, "maximum": 10},
        "v": {"$ref": "b.json#/$defs/vec"},
        "e": {"enum": ["x", "y"]},
        "s": {"type": "string", "maxLength": 3},
        "o": {"oneOf": [{"type": "object", "required": ["p"], "additionalProperties": false, "properties": {"p": {"type": "number"}}},
                        {"type": "object", "required": ["q"], "additionalProperties": false, "properties": {"q": {"type": "number"}}}]}
      }})"},
       {"b.json",
        R"({"$defs": {"vec": {"type": "array", "items": {"type": "number"}, "minItems": 2, "maxItems": 2}}})"}});
}

// An effect's field placed in a request through an endpoint's table: renamed, scaled to the
// wire's flat arrays, pointed at as a whole, or left under the prefix passed down.
TEST(Problem, PlacesAnEffectsFieldThroughItsTable) {
  const FieldTable mesh = {{"positions", {"/mesh/positions", 3}}, {"level", {"/mesh/level"}}};
  EXPECT_EQ(placeField("/positions/7", "/mesh", mesh), "/mesh/positions/21");
  EXPECT_EQ(placeField("/positions", "/mesh", mesh), "/mesh/positions");
  EXPECT_EQ(placeField("/level", "", mesh), "/mesh/level");
  EXPECT_EQ(placeField("/indices/4", "/mesh", mesh), "/mesh/indices/4");
  EXPECT_EQ(placeField("", "/fog", mesh), "/fog");
  EXPECT_EQ(placeField("/range/1", "/fog", {{"range", {"/table/range"}}}), "/table/range/1");
  const FieldTable whole = {{"uvs", {"/p/attributes/TEXCOORD_1", 0}}, {"", {"/p/indices", 0}}};
  EXPECT_EQ(placeField("/uvs/3", "/p", whole), "/p/attributes/TEXCOORD_1");
  EXPECT_EQ(placeField("/weights/3", "/p", whole), "/p/indices");
  EXPECT_EQ(placeField("", "/p", whole), "/p/indices");
  // A limit's flag is named in a 413's message, only there.
  const FieldTable limited = {{"size", {"/table/size", 1, "--max-table-size"}}};
  ApiError over = toApiError({effects::ErrorKind::kLimitExceeded, "/size", "too large"}, "/fog", limited);
  EXPECT_EQ(over.errors.at(0).pointer, "/table/size");
  EXPECT_EQ(over.errors.at(0).message, "too large (--max-table-size)");
  ApiError invalid = toApiError({effects::ErrorKind::kInvalidArgument, "/size", "must be >= 2"}, "/fog", limited);
  EXPECT_EQ(invalid.errors.at(0).message, "must be >= 2");
}

TEST(Schema, AcceptsValidInstances) {
  auto r = registry();
  EXPECT_TRUE(r.validate("a.json", json{{"n", 3}}).empty());
  EXPECT_TRUE(
      r.validate("a.json", json{{"n", 3.0}, {"v", {1, 2.5}}, {"e", "y"}, {"s", "\xc3\xa9\xc3\xa9\xc3\xa9"}}).empty());
  EXPECT_TRUE(r.validate("a.json", json{{"n", 1}, {"o", {{"q", 1}}}}).empty());
}

TEST(Schema, ReportsPointers) {
  auto r = registry();
  auto first = [&](const json& j) {
    auto v = r.validate("a.json", j);
    return v.empty() ? std::string("<none>") : v.front().pointer + " " + v.front().message;
  };
  EXPECT_EQ(first(json::object()), "/n is required");
  EXPECT_EQ(first(json{{"n", 0}}), "/n must be >= 1");
  EXPECT_EQ(first(json{{"n", 2.5}}), "/n must be integer, got number");
  EXPECT_EQ(first(json{{"n", 2}, {"x~y/z", 1}}), "/x~0y~1z is not a known field");
  // The nearest known field, when one is near and nearer than the others.
  EXPECT_EQ(first(json{{"n", 2}, {"V", {1}}}), "/V is not a known field: did you mean \"v\"?");
  EXPECT_EQ(first(json{{"n", 2}, {"oo", {1}}}), "/oo is not a known field: did you mean \"o\"?");
  EXPECT_EQ(first(json{{"n", 2}, {"v", {1, "a"}}}), "/v/1 must be number, got string");
  EXPECT_EQ(first(json{{"n", 2}, {"v", {1, 2, 3}}}), "/v must have at most 2 items");
  EXPECT_EQ(first(json{{"n", 2}, {"e", "z"}}), "/e must be one of [\"x\",\"y\"]");
  EXPECT_EQ(first(json{{"n", 2}, {"s", "abcd"}}), "/s must have at most 3 characters");
  EXPECT_EQ(first(json{{"n", 2}, {"o", {{"p", "no"}}}}), "/o/p must be number, got string");
  EXPECT_EQ(first(json::array()), " must be object, got array");
}

TEST(Schema, RefusesKeywordsItDoesNotCheck) {
  using Docs = std::map<std::string, std::string>;
  EXPECT_THROW(SchemaRegistry(Docs{{"c.json", R"({"type": "string", "pattern": "^a"})"}}), std::runtime_error);
  EXPECT_THROW(SchemaRegistry(Docs{{"c.json", R"({"$ref": "#/$defs/missing"})"}}), std::runtime_error);
}

// The request reader gives nlohmann's document, value types included, and refuses what it
// refuses (tests/fuzz/fuzz_request.cpp compares the two on every input it accepts).
TEST(JsonReader, GivesNlohmannsDocument) {
  for (const char* text :
       {R"({"a": [1, -1, 0, -0, 1.5, 1e3, 18446744073709551615, 18446744073709551616,
                              -9223372036854775808, -9223372036854775809, 1e-400, 4.9e-324], "b": {"c": null}})",
        R"(["\u00e9\ud83d\ude00\"\\\/\b\f\n\r\t\u0000"])", "[\"\xc3\xa9\xe2\x82\xac\xf0\x9f\x98\x80\"]",
        "\xef\xbb\xbf [true, false, null] ", R"({"a": 1, "a": [2]})", "0", "\"\"", "[]", "{}"}) {
    const json ours = readJson(text);
    const json theirs = json::parse(text);
    EXPECT_EQ(ours, theirs) << text;
    EXPECT_EQ(json::to_cbor(ours), json::to_cbor(theirs)) << text;  // types too: 1 vs 1.0, -0 vs -0.0
  }
  const json a = readJson("[1, -1, 18446744073709551616]");
  EXPECT_TRUE(a[0].is_number_unsigned());
  EXPECT_TRUE(a[1].is_number_integer() && !a[1].is_number_unsigned());
  EXPECT_TRUE(a[2].is_number_float());
  EXPECT_EQ(readJson(R"({"a": 1, "a": [2]})")["a"], json::array({2}));  // the last duplicate wins
}

TEST(JsonReader, RefusesWhatIsNotJson) {
  // clang-format off
  const std::vector<std::string> notJson = {
      "", " ", "{", "[1,]", "[,1]", "{\"a\":1,}", "{\"a\" 1}", "{1:2}", "01", "1.", ".5", "+1", "1e", "-", "NaN",
      "Infinity", "1e400", "-1e400", "tru", "nul", "\"\\x\"", "\"\\u12\"", "\"\\ud83d\"", "\"\\ude00\"",
      "\"\xc0\x80\"", "\"\xed\xa0\x80\"", "\"\xf4\x90\x80\x80\"", "\"\xff\"", "\"\x01\"", "\"abc", "/**/ 1",
      "[1] x", "\xef\xbb", std::string("[1]\0[", 5)};
  // clang-format on
  for (const std::string& text : notJson) {
    EXPECT_THROW(readJson(text), JsonSyntaxError) << json(text).dump(-1, ' ', true, json::error_handler_t::replace);
  }
  try {
    readJson("[1, 2, x]");
    FAIL();
  } catch (const JsonSyntaxError& e) {
    EXPECT_EQ(e.offset, 7u);
    EXPECT_FALSE(e.tooDeep);
  }
}

TEST(JsonReader, RefusesDeepNestingBeforeReadingIt) {
  std::string deep(100000, '[');
  try {
    readJson(deep);  // not even closed: refused at the 65th level
    FAIL();
  } catch (const JsonSyntaxError& e) {
    EXPECT_TRUE(e.tooDeep);
    EXPECT_EQ(e.offset, kMaxJsonDepth);
  }
  EXPECT_NO_THROW(readJson(std::string(kMaxJsonDepth, '[') + std::string(kMaxJsonDepth, ']')));
}

TEST(Codec, Base64RoundTripAndStrictness) {
  for (std::string s :
       std::vector<std::string>{"", "f", "fo", "foo", "foob", "fooba", "foobar", std::string("\0\xff\x10", 3)}) {
    auto d = base64Decode(base64Encode(s));
    ASSERT_TRUE(d);
    EXPECT_EQ(*d, s);
  }
  EXPECT_EQ(base64Encode("foobar"), "Zm9vYmFy");
  EXPECT_FALSE(base64Decode("Zm9"));
  EXPECT_FALSE(base64Decode("Zm9v YmFy"));
  EXPECT_FALSE(base64Decode("Zm=v"));
  EXPECT_FALSE(base64Decode("Z==="));
  // Non-canonical: bits left over by the padding must be zero (found by fuzz_base64).
  EXPECT_TRUE(base64Decode("Zm8="));
  EXPECT_FALSE(base64Decode("Zm9="));
  EXPECT_TRUE(base64Decode("Zg=="));
  EXPECT_FALSE(base64Decode("Zh=="));
}

TEST(Codec, HalfFloats) {
  EXPECT_EQ(floatToHalf(1.0f), 0x3C00);
  EXPECT_EQ(floatToHalf(-2.0f), 0xC000);
  EXPECT_EQ(floatToHalf(65504.0f), 0x7BFF);
  EXPECT_EQ(floatToHalf(1e6f), 0x7C00);
  EXPECT_EQ(floatToHalf(0.0f), 0);
  for (float f : {0.1f, 0.5f, 1.0f / 255, 3.14159f, 6e-5f, 1e-7f})
    EXPECT_NEAR(halfToFloat(floatToHalf(f)), f, std::max(f * 1e-3f, 6e-8f)) << f;
}

TEST(Codec, Sha256KnownAnswers) {  // FIPS 180-4 examples
  EXPECT_EQ(sha256Hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256Hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256Hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(sha256Hex(std::string(1000000, 'a')), "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(Config, FlagsOverrideEnvironmentOverrideDefaults) {
  Config c;
  bool help;
  setenv("EFFECTD_PORT", "9000", 1);
  setenv("EFFECTD_THREADS", "3", 1);
  EXPECT_EQ(parseConfig({"--port", "9100", "--max-body-bytes=2048"}, c, help), "");
  unsetenv("EFFECTD_PORT");
  unsetenv("EFFECTD_THREADS");
  EXPECT_EQ(c.port, 9100);
  EXPECT_EQ(c.threads, 3);
  EXPECT_EQ(c.limits.maxBodyBytes, 2048u);
  EXPECT_EQ(c.host, "127.0.0.1");
  Config d;
  EXPECT_NE(parseConfig({"--port", "70000"}, d, help), "");
  EXPECT_NE(parseConfig({"--nope", "1"}, d, help), "");
  EXPECT_NE(parseConfig({"--threads"}, d, help), "");
  EXPECT_EQ(parseConfig({"--help"}, d, help), "");
  EXPECT_TRUE(help);
}

}  // namespace
}  // namespace effectd

namespace effectd {
namespace {

namespace lt = effects::lightning;

lt::Polyline line(bool main, float width, std::vector<std::array<float, 3>> points) {
  lt::Polyline l;
  l.main = main;
  l.width = width;
  for (const auto& p : points) l.vertices.push_back({p[0], p[1], p[2], 0, main ? 1.0f : 0.5f, 0});
  return l;
}

glm::dvec3 at(const Ribbons& r, size_t v) { return {r.positions[3 * v], r.positions[3 * v + 1], r.positions[3 * v + 2]}; }

TEST(BoltRibbons, WidthAsGivenAlongAStraightLineInGltfAxes) {
  const auto r = boltRibbons({line(true, 2, {{1, 1, 0}, {1, 5, 0}, {1, 9, 0}}), line(false, 1, {{1, 5, 0}, {4, 5, 0}})}, 0,
                             World{}, nullptr);
  ASSERT_EQ(r[0].positions.size(), 3u * 6);  // two edges per polyline vertex
  ASSERT_EQ(r[1].positions.size(), 3u * 4);
  EXPECT_EQ(r[0].indices.size(), 12u);
  for (size_t v = 0; v < 6; v += 2) {
    EXPECT_NEAR(glm::length(at(r[0], v + 1) - at(r[0], v)), 2.0, 1e-6);
    EXPECT_NEAR((at(r[0], v) + at(r[0], v + 1)).y / 2, -1.0 - 4.0 * double(v / 2), 1e-6);  // y down -> -y
  }
  EXPECT_EQ(r[0].uvs[4], 4.0f);  // u: distance along, v: 0 / 1 across
  EXPECT_EQ(r[0].uvs[5], 0.0f);
  EXPECT_EQ(r[0].uvs[7], 1.0f);
  EXPECT_EQ(r[1].intensity[0], 0.5f);
}

TEST(BoltRibbons, CrossedRibbonsInThreeDAreSquareToEachOtherAndFiniteOnStiffPolylines) {
  World world;
  world.given = true;
  world.cellSize = 0.5;
  // A helix-like turn, a U-turn back onto itself, and a repeated point.
  const auto r = boltRibbons({line(true, 2, {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {1, 1, 1}, {0, 1, 1}, {1, 1, 1}, {1, 1, 1}, {2, 2, 2}})},
                             1, world, nullptr);
  const Ribbons& m = r[0];
  ASSERT_EQ(m.positions.size(), 3u * 2 * 2 * 8);  // two ribbons
  for (float x : m.positions) ASSERT_TRUE(std::isfinite(x));
  for (size_t v = 0; v < 16; v += 2) {
    const glm::dvec3 a = at(m, v + 1) - at(m, v), b = at(m, 16 + v + 1) - at(m, 16 + v);
    EXPECT_NEAR(glm::dot(a, b), 0.0, 1e-5) << v;  // crossed at right angles
    EXPECT_GE(glm::length(a), 1.0 - 1e-6);        // the width (2 cells of 0.5), mitred up to twice
    EXPECT_LE(glm::length(a), 2.0 + 1e-6);
  }
}

}  // namespace
}  // namespace effectd

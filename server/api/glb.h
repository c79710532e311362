// Binary glTF 2.0 (GLB) container: the JSON chunk as a document, the BIN chunk as bytes, and
// typed access to accessors. Written for /v1/tangents instead of using tinygltf so that a
// round trip is lossless (unknown extensions, images and extras pass through untouched),
// nothing is decoded that is not needed, and no external URI is ever followed.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "contract/field_error.h"

namespace effectd::glb {

using effectd::FieldError;

struct Asset {
  nlohmann::json gltf;
  std::string bin;  // buffer 0's bytes (the BIN chunk), possibly empty
};

// Problems are FieldErrors with a JSON pointer into the glTF document ("" = the container).

std::optional<FieldError> parse(const std::string& bytes, Asset& out);

// A glTF index, count or offset: a JSON integer in [0, max]. Anything else (a float such as
// 5e26, a negative number, a string) is a FieldError at `pointer` — never a silent conversion.
std::optional<FieldError> unsignedValue(const nlohmann::json& value, const std::string& pointer, uint64_t max,
                                        uint64_t& out);
// The same for `object[key]`, `fallback` when the key is absent.
std::optional<FieldError> unsignedMember(const nlohmann::json& object, const char* key, const std::string& pointer,
                                         uint64_t fallback, uint64_t max, uint64_t& out);
std::string serialize(const Asset& asset);
// Drops accessors nothing references (after vertex splits replaced them) and the bytes only
// they used, renumbering references. Leaves the asset untouched when it uses an extension that
// may name accessors or buffer views itself, has more than one buffer, or a reference is
// malformed: then nothing can be known unused.
void compact(Asset& asset);

// Accessor `index` as floats, `components` per element (normalized integers scaled to [0, 1]
// or [-1, 1] as the spec has it). Fails for sparse accessors, other buffers, out-of-range views.
std::optional<FieldError> readFloats(const Asset& asset, int index, int components, std::vector<float>& out);
std::optional<FieldError> readIndices(const Asset& asset, int index, std::vector<uint32_t>& out);

// glm vectors as one flat float array (x0, y0, z0, x1, ...), as accessors hold them.
template <int N, class V>
std::vector<float> floats(const std::vector<V>& v) {
  std::vector<float> out;
  out.reserve(v.size() * N);
  for (const V& x : v)
    for (int c = 0; c < N; ++c) out.push_back(float(x[c]));
  return out;
}

// New accessors over data appended to the BIN chunk (tightly packed, 4-byte aligned rows).
int addFloatAccessor(Asset& asset, const std::vector<float>& data, int components, bool vertexAttribute);
// A POSITION accessor over flat x, y, z floats, with the min and max glTF requires of it.
int addPositionAccessor(Asset& asset, const std::vector<float>& xyz);
int addIndexAccessor(Asset& asset, const std::vector<uint32_t>& indices);
// A PNG embedded in the BIN chunk as a new image (bufferView + mimeType); its index.
int addPngImage(Asset& asset, const std::string& png);
// A copy of accessor `index` with element k = original element remap[k] (any type).
std::optional<FieldError> addRemappedAccessor(Asset& asset, int index, const std::vector<uint32_t>& remap,
                                              int& newIndex);

}  // namespace effectd::glb

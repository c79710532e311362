#include "api/glb.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <set>

#include "contract/json_reader.h"

namespace effectd::glb {
namespace {

using nlohmann::json;

constexpr uint32_t kMagic = 0x46546C67, kJson = 0x4E4F534A, kBin = 0x004E4942;

// The value of type T stored at p, any alignment (host order: glTF and x86-64 are little-endian).
template <class T>
T load(const char* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
uint32_t u32(const std::string& s, size_t at) { return load<uint32_t>(s.data() + at); }
void put32(std::string& s, uint32_t v) { s.append(reinterpret_cast<const char*>(&v), 4); }

constexpr uint64_t kAny = SIZE_MAX / 4;  // sums of two stay representable

int componentSize(int type) {
  switch (type) {
    case 5120:
    case 5121: return 1;  // BYTE, UNSIGNED_BYTE
    case 5122:
    case 5123: return 2;  // SHORT, UNSIGNED_SHORT
    case 5125:
    case 5126: return 4;  // UNSIGNED_INT, FLOAT
    default: return 0;
  }
}
int componentCount(const std::string& type) {
  if (type == "SCALAR") return 1;
  if (type == "VEC2") return 2;
  if (type == "VEC3") return 3;
  if (type == "VEC4" || type == "MAT2") return 4;
  if (type == "MAT3") return 9;
  if (type == "MAT4") return 16;
  return 0;
}
const char* typeName(int components) {
  static const char* names[] = {"", "SCALAR", "VEC2", "VEC3", "VEC4"};
  return names[components];
}

const json& member(const json& root, const char* key);

// Where accessor `index`'s elements lie in the BIN chunk.
struct View {
  const json* accessor = nullptr;
  size_t count = 0, offset = 0, stride = 0, elementSize = 0;
  int componentType = 0, components = 0;
  bool zeros = false;  // no bufferView: all elements are zero
};

std::optional<FieldError> view(const Asset& a, int index, View& v) {
  std::string at = "/accessors/" + std::to_string(index);
  const json& accessors = member(a.gltf, "accessors");
  if (index < 0 || size_t(index) >= accessors.size()) return FieldError{at, "does not exist"};
  const json& acc = accessors[size_t(index)];
  v.accessor = &acc;
  if (acc.contains("sparse")) return FieldError{at + "/sparse", "sparse accessors are not supported"};
  uint64_t componentType = 0, count = 0, bvIndex = 0, buffer = 0, stride = 0, bvOffset = 0, bvLength = 0, accOffset = 0;
  if (auto p = unsignedMember(acc, "componentType", at + "/componentType", 0, 0xFFFF, componentType)) return p;
  v.componentType = int(componentType);
  v.components = componentCount(acc.contains("type") && acc["type"].is_string() ? acc["type"].get<std::string>() : "");
  int cs = componentSize(v.componentType);
  if (!cs || !v.components) return FieldError{at, "has an unknown componentType or type"};
  if (auto p = unsignedMember(acc, "count", at + "/count", 0, kAny, count)) return p;
  v.count = size_t(count);
  v.elementSize = size_t(cs) * size_t(v.components);
  if (!acc.contains("bufferView")) {
    v.zeros = true;
    return std::nullopt;
  }
  if (auto p = unsignedValue(acc["bufferView"], at + "/bufferView", kAny, bvIndex)) return p;
  const json& views = member(a.gltf, "bufferViews");
  if (bvIndex >= views.size()) return FieldError{at + "/bufferView", "does not exist"};
  const json& bv = views[size_t(bvIndex)];
  const std::string bvAt = "/bufferViews/" + std::to_string(bvIndex);
  if (auto p = unsignedMember(bv, "buffer", bvAt + "/buffer", 0, kAny, buffer)) return p;
  if (buffer != 0) return FieldError{bvAt + "/buffer", "only the GLB binary chunk (buffer 0) is supported"};
  const json& buffers = member(a.gltf, "buffers");
  if (buffers.empty() || buffers[0].contains("uri"))
    return FieldError{"/buffers/0", "must be the GLB binary chunk (no uri)"};
  if (auto p = unsignedMember(bv, "byteStride", bvAt + "/byteStride", 0, 252, stride)) return p;
  if (auto p = unsignedMember(bv, "byteOffset", bvAt + "/byteOffset", 0, kAny, bvOffset)) return p;
  if (auto p = unsignedMember(bv, "byteLength", bvAt + "/byteLength", 0, kAny, bvLength)) return p;
  if (auto p = unsignedMember(acc, "byteOffset", at + "/byteOffset", 0, kAny, accOffset)) return p;
  v.stride = stride == 0 ? v.elementSize : size_t(stride);
  v.offset = size_t(bvOffset + accOffset);
  size_t bvEnd = size_t(bvOffset + bvLength);
  if (v.stride < v.elementSize) return FieldError{bvAt + "/byteStride", "is smaller than an element"};
  if (v.count > 0 && (v.count - 1 > (SIZE_MAX - v.elementSize - v.offset) / v.stride ||
                      v.offset + (v.count - 1) * v.stride + v.elementSize > std::min(bvEnd, a.bin.size())))
    return FieldError{at, "reaches past the end of its bufferView or of the binary chunk"};
  return std::nullopt;
}

double component(const char* p, int type, bool normalized) {
  switch (type) {
    case 5120: return normalized ? std::max(load<int8_t>(p) / 127.0, -1.0) : load<int8_t>(p);
    case 5121: return normalized ? load<uint8_t>(p) / 255.0 : load<uint8_t>(p);
    case 5122: return normalized ? std::max(load<int16_t>(p) / 32767.0, -1.0) : load<int16_t>(p);
    case 5123: return normalized ? load<uint16_t>(p) / 65535.0 : load<uint16_t>(p);
    case 5125: return load<uint32_t>(p);
    default: return load<float>(p);
  }
}

size_t appendBin(Asset& a, const std::string& bytes, int target, size_t stride) {
  while (a.bin.size() % 4) a.bin.push_back('\0');
  size_t offset = a.bin.size();
  a.bin += bytes;
  json bv = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", bytes.size()}, {"target", target}};
  if (stride) bv["byteStride"] = stride;
  a.gltf["bufferViews"].push_back(bv);
  return a.gltf["bufferViews"].size() - 1;
}

const json& member(const json& root, const char* key) {
  static const json empty = json::array();
  auto it = root.find(key);
  return it == root.end() ? empty : *it;
}

int pushAccessor(Asset& a, json accessor) {
  a.gltf["accessors"].push_back(std::move(accessor));
  return int(a.gltf["accessors"].size() - 1);
}

}  // namespace

std::optional<FieldError> unsignedValue(const json& value, const std::string& pointer, uint64_t max, uint64_t& out) {
  // JSON parsed from the body has unsigned integers; those this file writes may be signed.
  if (!value.is_number_integer() || value.get<int64_t>() < 0 || value.get<uint64_t>() > max)
    return FieldError{pointer, "must be an integer from 0 to " + std::to_string(max)};
  out = value.get<uint64_t>();
  return std::nullopt;
}

std::optional<FieldError> unsignedMember(const json& object, const char* key, const std::string& pointer,
                                         uint64_t fallback, uint64_t max, uint64_t& out) {
  auto it = object.find(key);
  if (it == object.end()) {
    out = fallback;
    return std::nullopt;
  }
  return unsignedValue(*it, pointer, max, out);
}

std::optional<FieldError> parse(const std::string& b, Asset& out) {
  if (b.size() < 20 || u32(b, 0) != kMagic) return FieldError{"", "is not a binary glTF (magic 'glTF' missing)"};
  if (u32(b, 4) != 2) return FieldError{"", "must be glTF version 2"};
  if (u32(b, 8) != b.size())
    return FieldError{"", "header length " + std::to_string(u32(b, 8)) + " does not match the body (" +
                              std::to_string(b.size()) + " bytes)"};
  size_t at = 12;
  bool haveJson = false;
  while (at + 8 <= b.size()) {
    size_t len = u32(b, at), type = u32(b, at + 4);
    if (len > b.size() - at - 8) return FieldError{"", "a chunk runs past the end of the body"};
    std::string data = b.substr(at + 8, len);
    if (!haveJson) {
      if (type != kJson) return FieldError{"", "the first chunk must be JSON"};
      // glTF pads the JSON chunk with spaces; some exporters pad with zero bytes (which
      // nlohmann's parser read as the end of the text), so trailing ones are dropped too.
      while (!data.empty() && data.back() == '\0') data.pop_back();
      try {
        out.gltf = readJson(data);
      } catch (const JsonSyntaxError& e) {
        return FieldError{"", std::string("the JSON chunk is not JSON: ") + e.what()};
      }
      if (!out.gltf.is_object()) return FieldError{"", "the JSON chunk is not a JSON object"};
      haveJson = true;
    } else if (type == kBin) {
      out.bin = std::move(data);
    }
    at += 8 + len;
  }
  if (!haveJson) return FieldError{"", "has no JSON chunk"};
  if (!out.gltf.contains("asset") || !out.gltf["asset"].is_object() || out.gltf["asset"].value("version", "") != "2.0")
    return FieldError{"/asset/version", "must be \"2.0\""};
  // Trust nothing structural: the arrays we index must be arrays of objects.
  for (const char* key : {"accessors", "bufferViews", "buffers", "meshes"}) {
    if (!out.gltf.contains(key)) continue;
    if (!out.gltf[key].is_array()) return FieldError{std::string("/") + key, "must be an array"};
    for (size_t i = 0; i < out.gltf[key].size(); ++i)
      if (!out.gltf[key][i].is_object())
        return FieldError{std::string("/") + key + "/" + std::to_string(i), "must be an object"};
  }
  return std::nullopt;
}

namespace {

// Extensions whose JSON names no accessor and no buffer view: renumbering cannot miss them.
bool onlySafeExtensions(const json& gltf) {
  static const std::set<std::string> kSafe = {"KHR_materials_anisotropy",
                                              "KHR_materials_clearcoat",
                                              "KHR_materials_dispersion",
                                              "KHR_materials_emissive_strength",
                                              "KHR_materials_ior",
                                              "KHR_materials_iridescence",
                                              "KHR_materials_sheen",
                                              "KHR_materials_specular",
                                              "KHR_materials_transmission",
                                              "KHR_materials_unlit",
                                              "KHR_materials_variants",
                                              "KHR_materials_volume",
                                              "KHR_materials_pbrSpecularGlossiness",
                                              "KHR_texture_transform",
                                              "KHR_texture_basisu",
                                              "KHR_lights_punctual",
                                              "KHR_mesh_quantization",
                                              "EXT_texture_webp"};
  for (const auto& e : member(gltf, "extensionsUsed"))
    if (!e.is_string() || !kSafe.count(e.get<std::string>())) return false;
  return true;
}

// Every reference to an element of an array of `count`, or false if one is not a valid index.
bool validRefs(const std::vector<json*>& refs, size_t count) {
  for (const json* r : refs)
    if (uint64_t index = 0; count == 0 || unsignedValue(*r, "", count - 1, index)) return false;
  return true;
}

// object[key] as a reference to renumber, when there is one.
void addRef(std::vector<json*>& refs, json& object, const char* key) {
  if (object.is_object() && object.contains(key)) refs.push_back(&object[key]);
}

std::vector<json*> accessorRefs(json& g) {
  std::vector<json*> refs;
  auto add = [&](json& object, const char* key) { addRef(refs, object, key); };
  auto all = [&](json& object) {
    if (object.is_object())
      for (auto& [k, v] : object.items()) refs.push_back(&v);
  };
  if (g.contains("meshes") && g["meshes"].is_array())
    for (auto& mesh : g["meshes"]) {
      if (!mesh.is_object() || !mesh.contains("primitives") || !mesh["primitives"].is_array()) continue;
      for (auto& p : mesh["primitives"]) {
        if (!p.is_object()) continue;
        if (p.contains("attributes")) all(p["attributes"]);
        add(p, "indices");
        if (p.contains("targets") && p["targets"].is_array())
          for (auto& t : p["targets"]) all(t);
      }
    }
  if (g.contains("skins") && g["skins"].is_array())
    for (auto& s : g["skins"]) add(s, "inverseBindMatrices");
  if (g.contains("animations") && g["animations"].is_array())
    for (auto& an : g["animations"])
      if (an.is_object() && an.contains("samplers") && an["samplers"].is_array())
        for (auto& s : an["samplers"]) add(s, "input"), add(s, "output");
  return refs;
}

std::vector<json*> bufferViewRefs(json& g) {
  std::vector<json*> refs;
  auto add = [&](json& object, const char* key) { addRef(refs, object, key); };
  for (auto& acc : g["accessors"]) {
    add(acc, "bufferView");
    if (acc.contains("sparse") && acc["sparse"].is_object()) {
      json& sp = acc["sparse"];
      if (sp.contains("indices")) add(sp["indices"], "bufferView");
      if (sp.contains("values")) add(sp["values"], "bufferView");
    }
  }
  if (g.contains("images") && g["images"].is_array())
    for (auto& img : g["images"]) add(img, "bufferView");
  return refs;
}

// Keeps only the items `refs` (valid indices into `items`) name, renumbering the references;
// returns whether any item was dropped.
bool keepUsed(json& items, const std::vector<json*>& refs) {
  std::vector<int64_t> renumber(items.size(), -1);
  for (const json* r : refs) renumber[r->get<size_t>()] = 0;
  json kept = json::array();
  for (size_t i = 0; i < items.size(); ++i)
    if (renumber[i] == 0) {
      renumber[i] = int64_t(kept.size());
      kept.push_back(std::move(items[i]));
    }
  const bool dropped = kept.size() < items.size();
  items = std::move(kept);
  for (json* r : refs) *r = renumber[r->get<size_t>()];
  return dropped;
}

}  // namespace

void compact(Asset& a) {
  json& g = a.gltf;
  if (!onlySafeExtensions(g) || member(g, "buffers").size() > 1 || !g.contains("accessors")) return;
  const std::vector<json*> accRefs = accessorRefs(g);
  if (!validRefs(accRefs, g["accessors"].size())) return;
  if (!keepUsed(g["accessors"], accRefs) || !g.contains("bufferViews")) return;  // nothing replaced
  const std::vector<json*> viewRefs = bufferViewRefs(g);
  if (!validRefs(viewRefs, g["bufferViews"].size())) return;
  for (const json& bv : g["bufferViews"]) {  // every view must lie in the BIN chunk
    uint64_t offset = 0, length = 0, buffer = 0;
    if (!bv.contains("buffer") || unsignedMember(bv, "buffer", "", 0, 0, buffer) ||
        unsignedMember(bv, "byteOffset", "", 0, kAny, offset) ||
        unsignedMember(bv, "byteLength", "", 0, kAny, length) || offset > a.bin.size() ||
        length > a.bin.size() - offset)
      return;
  }
  if (!keepUsed(g["bufferViews"], viewRefs)) return;  // the bytes stay where they are
  std::string bin;
  for (json& bv : g["bufferViews"]) {  // in order, each at its old offset modulo 4 (alignment kept)
    const size_t offset = bv.value("byteOffset", size_t(0)), length = bv.value("byteLength", size_t(0));
    while (bin.size() % 4 != offset % 4) bin.push_back('\0');
    bv["byteOffset"] = bin.size();
    bin.append(a.bin, offset, length);
  }
  a.bin = std::move(bin);
}

std::string serialize(const Asset& a) {
  json gltf = a.gltf;
  if (!a.bin.empty()) {
    if (!gltf.contains("buffers") || gltf["buffers"].empty()) gltf["buffers"] = json::array({json::object()});
    gltf["buffers"][0]["byteLength"] = a.bin.size();
  }
  std::string js = gltf.dump(-1, ' ', false, json::error_handler_t::replace);
  while (js.size() % 4) js += ' ';
  std::string bin = a.bin;
  while (bin.size() % 4) bin.push_back('\0');
  std::string out;
  put32(out, kMagic);
  put32(out, 2);
  put32(out, uint32_t(12 + 8 + js.size() + (bin.empty() ? 0 : 8 + bin.size())));
  put32(out, uint32_t(js.size()));
  put32(out, kJson);
  out += js;
  if (!bin.empty()) {
    put32(out, uint32_t(bin.size()));
    put32(out, kBin);
    out += bin;
  }
  return out;
}

std::optional<FieldError> readFloats(const Asset& a, int index, int components, std::vector<float>& out) {
  View v;
  if (auto p = view(a, index, v)) return p;
  std::string at = "/accessors/" + std::to_string(index);
  if (v.components != components) return FieldError{at + "/type", std::string("must be ") + typeName(components)};
  bool normalized = v.accessor->value("normalized", false);
  if (v.componentType != 5126 && !normalized) return FieldError{at + "/componentType", "must be FLOAT or normalized"};
  out.assign(v.count * size_t(components), 0.0f);
  if (v.zeros) return std::nullopt;
  int cs = componentSize(v.componentType);
  for (size_t k = 0; k < v.count; ++k)
    for (int c = 0; c < components; ++c)
      out[k * size_t(components) + size_t(c)] =
          float(component(a.bin.data() + v.offset + k * v.stride + size_t(c * cs), v.componentType, normalized));
  return std::nullopt;
}

std::optional<FieldError> readIndices(const Asset& a, int index, std::vector<uint32_t>& out) {
  View v;
  if (auto p = view(a, index, v)) return p;
  std::string at = "/accessors/" + std::to_string(index);
  if (v.components != 1 || (v.componentType != 5121 && v.componentType != 5123 && v.componentType != 5125))
    return FieldError{at, "indices must be SCALAR unsigned byte, short or int"};
  out.assign(v.count, 0);
  if (v.zeros) return std::nullopt;
  for (size_t k = 0; k < v.count; ++k)
    out[k] = uint32_t(component(a.bin.data() + v.offset + k * v.stride, v.componentType, false));
  return std::nullopt;
}

int addFloatAccessor(Asset& a, const std::vector<float>& data, int components, bool vertexAttribute) {
  std::string bytes(reinterpret_cast<const char*>(data.data()), data.size() * sizeof(float));
  size_t bv = appendBin(a, bytes, vertexAttribute ? 34962 : 0, 0);
  return pushAccessor(a, {{"bufferView", bv},
                          {"componentType", 5126},
                          {"count", data.size() / size_t(components)},
                          {"type", typeName(components)}});
}

int addPositionAccessor(Asset& a, const std::vector<float>& xyz) {
  const int index = addFloatAccessor(a, xyz, 3, true);
  json lo = json::array(), hi = json::array();
  for (size_t c = 0; c < 3; ++c) {
    float mn = xyz.size() > c ? xyz[c] : 0.0f, mx = mn;
    for (size_t i = c; i < xyz.size(); i += 3) mn = std::min(mn, xyz[i]), mx = std::max(mx, xyz[i]);
    lo.push_back(mn);
    hi.push_back(mx);
  }
  a.gltf["accessors"][index]["min"] = lo;
  a.gltf["accessors"][index]["max"] = hi;
  return index;
}

int addPngImage(Asset& a, const std::string& png) {
  const size_t bv = appendBin(a, png, 0, 0);
  a.gltf["bufferViews"][bv].erase("target");  // images are no vertex or index data
  if (!a.gltf.contains("images")) a.gltf["images"] = json::array();
  a.gltf["images"].push_back({{"bufferView", bv}, {"mimeType", "image/png"}});
  return int(a.gltf["images"].size() - 1);
}

int addIndexAccessor(Asset& a, const std::vector<uint32_t>& indices) {
  size_t maxIndex = 0;
  for (uint32_t i : indices) maxIndex = std::max<size_t>(maxIndex, i);
  std::string bytes;
  int type = maxIndex < 65535 ? 5123 : 5125;
  for (uint32_t i : indices) {
    if (type == 5123) {
      uint16_t s = uint16_t(i);
      bytes.append(reinterpret_cast<const char*>(&s), 2);
    } else {
      bytes.append(reinterpret_cast<const char*>(&i), 4);
    }
  }
  size_t bv = appendBin(a, bytes, 34963, 0);
  return pushAccessor(a, {{"bufferView", bv}, {"componentType", type}, {"count", indices.size()}, {"type", "SCALAR"}});
}

std::optional<FieldError> addRemappedAccessor(Asset& a, int index, const std::vector<uint32_t>& remap, int& newIndex) {
  View v;
  if (auto p = view(a, index, v)) return p;
  const size_t row = (v.elementSize + 3) / 4 * 4;  // vertex attributes stay 4-byte aligned
  std::string bytes(remap.size() * row, '\0');
  for (size_t k = 0; k < remap.size(); ++k) {
    if (remap[k] >= v.count)
      return FieldError{"/accessors/" + std::to_string(index) + "/count", "is smaller than the vertex count"};
    if (!v.zeros) std::memcpy(bytes.data() + k * row, a.bin.data() + v.offset + remap[k] * v.stride, v.elementSize);
  }
  size_t bv = appendBin(a, bytes, 34962, row != v.elementSize ? row : 0);
  json acc = *v.accessor;
  acc.erase("byteOffset");
  acc["bufferView"] = bv;
  acc["count"] = remap.size();
  newIndex = pushAccessor(a, std::move(acc));
  return std::nullopt;
}

}  // namespace effectd::glb

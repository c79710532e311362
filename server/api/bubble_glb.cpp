#include "api/bubble_glb.h"

#include "api/glb.h"

namespace effectd {

using nlohmann::json;

namespace {

// KHR_materials_transmission makes the film see-through; KHR_materials_iridescence (when the
// film is iridescent) gives it thin-film colour. The thickness texture, when there is one, is
// texture 0.
json material(const effects::bubble::Params& p, const GltfFilm& film) {
  json extensions = {{"KHR_materials_transmission", {{"transmissionFactor", 1.0}}},
                     {"KHR_materials_ior", {{"ior", baseIor(p, film)}}}};
  if (film.iridescent) {
    extensions["KHR_materials_iridescence"] = {{"iridescenceFactor", 1.0},
                                               {"iridescenceIor", p.n2},
                                               {"iridescenceThicknessMinimum", film.minNm},
                                               {"iridescenceThicknessMaximum", film.maxNm}};
    if (!film.thicknessPng.empty())
      extensions["KHR_materials_iridescence"]["iridescenceThicknessTexture"] = {{"index", 0}};
  }
  return {{"name", "soap film"},
          {"doubleSided", true},
          {"pbrMetallicRoughness",
           {{"baseColorFactor", {1.0, 1.0, 1.0, 1.0}}, {"metallicFactor", 0.0}, {"roughnessFactor", 0.05}}},
          {"extensions", extensions}};
}

}  // namespace

std::string bubbleGlb(const effects::bubble::Mesh& mesh, const effects::bubble::Params& params, const GltfFilm& film) {
  glb::Asset a;
  // Arrays of one element spelled json::array(...): a braced single element may collapse to
  // the element itself depending on the compiler (nlohmann::json's initializer lists).
  a.gltf = json::object();
  a.gltf["asset"] = {{"version", "2.0"}, {"generator", "effectd /v1/bubble"}};
  a.gltf["scene"] = 0;
  a.gltf["scenes"] = json::array({json{{"nodes", json::array({0})}}});
  a.gltf["nodes"] = json::array({json{{"mesh", 0}, {"name", "bubble"}}});
  a.gltf["accessors"] = json::array();
  a.gltf["bufferViews"] = json::array();
  std::vector<float> tangents = glb::floats<4>(mesh.tangents);
  for (size_t i = 3; i < tangents.size(); i += 4) tangents[i] = -tangents[i];  // glTF: UV origin top left
  const int position = glb::addPositionAccessor(a, glb::floats<3>(mesh.positions));
  json attributes = {{"POSITION", position},
                     {"NORMAL", glb::addFloatAccessor(a, glb::floats<3>(mesh.normals), 3, true)},
                     {"TEXCOORD_0", glb::addFloatAccessor(a, glb::floats<2>(mesh.uvs), 2, true)},
                     {"TANGENT", glb::addFloatAccessor(a, tangents, 4, true)}};
  const int indices = glb::addIndexAccessor(a, mesh.indices);
  const json primitive = {{"attributes", attributes}, {"indices", indices}, {"material", 0}};
  a.gltf["meshes"] = json::array({json{{"name", "bubble"}, {"primitives", json::array({primitive})}}});
  a.gltf["materials"] = json::array({material(params, film)});
  if (film.iridescent && !film.thicknessPng.empty()) {
    const int image = glb::addPngImage(a, film.thicknessPng);
    // u wraps around the sphere (seam triangles run past 1); v stops at the poles.
    a.gltf["samplers"] = json::array({json{{"magFilter", 9729}, {"minFilter", 9729}, {"wrapS", 10497}, {"wrapT", 33071}}});
    a.gltf["textures"] = json::array({json{{"source", image}, {"sampler", 0}}});
  }
  json used = {"KHR_materials_transmission", "KHR_materials_ior"};
  if (film.iridescent) used.push_back("KHR_materials_iridescence");
  a.gltf["extensionsUsed"] = used;
  return glb::serialize(a);
}

}  // namespace effectd

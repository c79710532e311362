// GLSL -> SPIR-V (glslang) -> HLSL / MSL (SPIRV-Cross), with the resources each declares.
#include "api/shader_targets.h"

#include "contract/codec.h"

#include <memory>
#include <mutex>
#include <tuple>

#include <glslang/Public/ResourceLimits.h>
#include <glslang/Public/ShaderLang.h>
#include <glslang/SPIRV/GlslangToSpv.h>
#include <spirv_cross/spirv_hlsl.hpp>
#include <spirv_cross/spirv_msl.hpp>

namespace effectd {
namespace {

// glslang's process-wide tables, set up once (they are never torn down: the process ends).
void initialise() {
  static std::once_flag once;
  std::call_once(once, [] { glslang::InitializeProcess(); });
}

std::unique_ptr<glslang::TShader> parse(EShLanguage stage, const std::string& source, std::string& log) {
  auto shader = std::make_unique<glslang::TShader>(stage);
  const char* text = source.c_str();
  shader->setStrings(&text, 1);
  shader->setEnvInput(glslang::EShSourceGlsl, stage, glslang::EShClientVulkan, 100);
  shader->setEnvClient(glslang::EShClientVulkan, glslang::EShTargetVulkan_1_0);
  shader->setEnvTarget(glslang::EShTargetSpv, glslang::EShTargetSpv_1_0);
  shader->setEnvInputVulkanRulesRelaxed();  // loose uniforms -> one block
  shader->setGlobalUniformBlockName("Uniforms");
  shader->setGlobalUniformSet(0);
  shader->setGlobalUniformBinding(0);
  shader->setAutoMapBindings(true);
  shader->setAutoMapLocations(true);
  if (!shader->parse(GetDefaultResources(), 100, false, EShMsgDefault)) {
    log = shader->getInfoLog();
    return nullptr;
  }
  return shader;
}

// The resources of one stage as `compiler` sees them (after compile(), for MSL's indices).
void reflect(spirv_cross::Compiler& c, const char* stage, bool msl, std::vector<ShaderResource>& out) {
  const spirv_cross::ShaderResources r = c.get_shader_resources();
  auto add = [&](const spirv_cross::Resource& res, const char* kind) {
    ShaderResource s;
    s.name = res.name;
    s.kind = kind;
    s.stage = stage;
    if (c.has_decoration(res.id, spv::DecorationDescriptorSet))
      s.set = int(c.get_decoration(res.id, spv::DecorationDescriptorSet));
    if (c.has_decoration(res.id, spv::DecorationBinding)) s.binding = int(c.get_decoration(res.id, spv::DecorationBinding));
    if (c.has_decoration(res.id, spv::DecorationLocation))
      s.location = int(c.get_decoration(res.id, spv::DecorationLocation));
    if (msl) {
      const uint32_t index = static_cast<spirv_cross::CompilerMSL&>(c).get_automatic_msl_resource_binding(res.id);
      if (index != uint32_t(-1)) s.mslIndex = int(index);
    }
    return s;
  };
  for (const auto& u : r.uniform_buffers) {
    ShaderResource s = add(u, "uniformBlock");
    const spirv_cross::SPIRType& type = c.get_type(u.base_type_id);
    for (uint32_t m = 0; m < type.member_types.size(); ++m)
      s.members.emplace_back(c.get_member_name(u.base_type_id, m), c.type_struct_member_offset(type, m));
    out.push_back(std::move(s));
  }
  for (const auto& t : r.sampled_images) out.push_back(add(t, "texture"));
  if (std::string(stage) == "vertex")
    for (const auto& a : r.stage_inputs) out.push_back(add(a, "attribute"));
}

}  // namespace

effects::Result<TranslatedShader> translateShader(const std::string& vertexGlsl, const std::string& fragmentGlsl,
                                                  ShaderTarget target) {
  initialise();
  effects::Stopwatch watch;
  std::string log;
  std::unique_ptr<glslang::TShader> vs;
  if (!vertexGlsl.empty()) {
    vs = parse(EShLangVertex, vertexGlsl, log);
    if (!vs) return effects::unsatisfiable("/shader", "glslang refused the vertex shader: " + log);
  }
  auto fs = parse(EShLangFragment, fragmentGlsl, log);
  if (!fs) return effects::unsatisfiable("/shader", "glslang refused the fragment shader: " + log);
  glslang::TProgram program;
  if (vs) program.addShader(vs.get());
  program.addShader(fs.get());
  if (!program.link(EShMsgDefault) || !program.mapIO())
    return effects::unsatisfiable("/shader", std::string("glslang could not link the stages: ") + program.getInfoLog());
  TranslatedShader out;
  for (auto [stage, name, dst] : {std::tuple{EShLangVertex, "vertex", &out.vertex},
                                  std::tuple{EShLangFragment, "fragment", &out.fragment}}) {
    if (!program.getIntermediate(stage)) continue;  // a fragment-only translation
    std::vector<uint32_t> words;
    glslang::GlslangToSpv(*program.getIntermediate(stage), words);
    try {
      if (target == ShaderTarget::kSpirv) {
        spirv_cross::Compiler c(words);
        reflect(c, name, false, out.resources);
        dst->entryPoint = "main";
        dst->spirv = std::move(words);
      } else if (target == ShaderTarget::kHlsl) {
        spirv_cross::CompilerHLSL c(std::move(words));
        spirv_cross::CompilerHLSL::Options o;
        o.shader_model = 50;
        c.set_hlsl_options(o);
        dst->source = c.compile();
        dst->entryPoint = "main";
        reflect(c, name, false, out.resources);
      } else {
        spirv_cross::CompilerMSL c(std::move(words));
        spirv_cross::CompilerMSL::Options o;
        o.set_msl_version(2, 0);
        c.set_msl_options(o);
        dst->source = c.compile();
        const auto entries = c.get_entry_points_and_stages();
        dst->entryPoint = entries.empty() ? "main0"
                                          : c.get_cleansed_entry_point_name(entries[0].name, entries[0].execution_model);
        reflect(c, name, true, out.resources);
      }
    } catch (const spirv_cross::CompilerError& e) {
      return effects::unsatisfiable("/shader", std::string("SPIRV-Cross refused the ") + name + " stage: " + e.what());
    }
  }
  out.compileMs = watch.ms();
  return out;
}

bool shaderTarget(const std::string& language, ShaderTarget& target) {
  if (language == "spirv") return target = ShaderTarget::kSpirv, true;
  if (language == "hlsl") return target = ShaderTarget::kHlsl, true;
  if (language == "msl") return target = ShaderTarget::kMsl, true;
  return false;
}

// A translated stage's code: text, or SPIR-V words as little-endian base64.
nlohmann::json stageCode(const ShaderStage& s) {
  if (s.spirv.empty()) return s.source;
  return base64Encode(std::string(reinterpret_cast<const char*>(s.spirv.data()), s.spirv.size() * 4));
}

nlohmann::json resourcesJson(const std::vector<ShaderResource>& resources) {
  nlohmann::json out = nlohmann::json::array();
  for (const ShaderResource& r : resources) {
    nlohmann::json j = {{"name", r.name}, {"kind", r.kind}, {"stage", r.stage}};
    if (r.set >= 0) j["set"] = r.set;
    if (r.binding >= 0) j["binding"] = r.binding;
    if (r.location >= 0) j["location"] = r.location;
    if (r.mslIndex >= 0) j["mslIndex"] = r.mslIndex;
    if (!r.members.empty()) {
      j["members"] = nlohmann::json::array();
      for (const auto& [name, offset] : r.members) j["members"].push_back({{"name", name}, {"offset", offset}});
    }
    out.push_back(std::move(j));
  }
  return out;
}

}  // namespace effectd

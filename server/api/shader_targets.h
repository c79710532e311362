// The bubble's shaders for every engine from one source: the assembled GLSL (330 core)
// compiled by glslang to SPIR-V (Vulkan 1.0 / SPIR-V 1.0; loose uniforms gathered into one
// uniform block "Uniforms" at set 0, binding 0 by glslang's relaxed Vulkan rules; samplers and
// locations assigned by glslang's IO mapping), then SPIR-V cross-compiled by SPIRV-Cross to HLSL
// (shader model 5.0) and MSL (Metal 2.0). No hand translation: a disabled feature, absent
// from the GLSL, is absent from every target.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <effects/common.h>

namespace effectd {

enum class ShaderTarget { kSpirv, kHlsl, kMsl };

struct ShaderStage {
  std::string entryPoint;       // the function an engine binds (SPIR-V and HLSL: main; MSL: main0)
  std::string source;           // HLSL or MSL text
  std::vector<uint32_t> spirv;  // SPIR-V words (kSpirv)
};

// One resource as the target declares it. kind: "uniformBlock", "texture" (a combined image
// sampler in SPIR-V; HLSL: Texture + SamplerState at t<binding>/s<binding>; MSL: texture and
// sampler indices) or "attribute". members: a uniform block's members and byte offsets.
struct ShaderResource {
  std::string name, kind, stage;  // stage: "vertex" or "fragment"
  int set = -1, binding = -1, location = -1;
  int mslIndex = -1;  // MSL buffer / texture index
  std::vector<std::pair<std::string, uint32_t>> members;
};

struct TranslatedShader {
  ShaderStage vertex, fragment;
  std::vector<ShaderResource> resources;
  double compileMs = 0;
};

// Throws nothing: a source glslang or SPIRV-Cross refuses is kUnsatisfiable with its log (a bug
// of effectd's, as the GLSL is its own). An empty vertexGlsl translates the fragment stage alone.
effects::Result<TranslatedShader> translateShader(const std::string& vertexGlsl, const std::string& fragmentGlsl,
                                                  ShaderTarget target);

// "spirv", "hlsl", "msl" -> the target; false for the GLSL languages.
bool shaderTarget(const std::string& language, ShaderTarget& target);
// A translated stage's code as the answer carries it: text, or SPIR-V words as little-endian
// base64; and the resources as JSON (proto/schemas/common.json#/$defs/shaderResource).
nlohmann::json stageCode(const ShaderStage& s);
nlohmann::json resourcesJson(const std::vector<ShaderResource>& resources);

}  // namespace effectd

// The bubble's shaders for every engine, each checked by its own language's tools: SPIR-V by
// spirv-val (Vulkan 1.0), HLSL compiled back by glslang's HLSL front end, for every feature set
// of both shading models. MSL has no compiler on Linux: it is SPIRV-Cross's output from the
// validated SPIR-V, checked here for its entry points and resources only.
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include <effects/bubble.h>

#include "api/shader_targets.h"

namespace effectd::testing {
namespace {

namespace bb = effects::bubble;
namespace fs = std::filesystem;

// Runs `command` on `bytes` written to a temporary file; true when it exits 0 (log in `log`).
bool accepts(const std::string& command, const std::string& bytes, const std::string& suffix, std::string& log) {
  const fs::path dir = fs::temp_directory_path();
  const std::string path = (dir / ("effectd_shader_" + std::to_string(::getpid()) + suffix)).string();
  std::ofstream(path, std::ios::binary) << bytes;
  const int rc = std::system((command + " " + path + " > " + path + ".log 2>&1").c_str());
  std::ifstream in(path + ".log");
  log.assign(std::istreambuf_iterator<char>(in), {});
  fs::remove(path);
  fs::remove(path + ".log");
  return rc == 0;
}

// Every feature set of both models: the paper's six flags, the film's four (wobble, thickness,
// back face, highlight).
std::vector<bb::Features> everyFeatureSet() {
  std::vector<bb::Features> out;
  for (int mask = 0; mask < 64; ++mask) {
    bb::Features f{bool(mask & 1), bool(mask & 2), bool(mask & 4), bool(mask & 8), bool(mask & 16), bool(mask & 32)};
    f.shading = bb::Shading::kPaper;
    out.push_back(f);
  }
  for (int mask = 0; mask < 16; ++mask) {
    bb::Features f;
    f.wobble = mask & 1, f.thickness = mask & 2, f.backFace = mask & 4, f.highlight = mask & 8;
    out.push_back(f);
  }
  return out;
}

std::string words(const std::vector<uint32_t>& w) {
  return std::string(reinterpret_cast<const char*>(w.data()), w.size() * 4);
}

TEST(ShaderTargets, SpirvValidatesAndHlslCompilesForEveryFeatureSet) {
  ASSERT_EQ(std::system("spirv-val --version > /dev/null 2>&1"), 0) << "spirv-tools missing: scripts/setup.sh";
  ASSERT_EQ(std::system("glslangValidator -v > /dev/null 2>&1"), 0) << "glslang-tools missing: scripts/setup.sh";
  int checked = 0;
  for (const bb::Features& f : everyFeatureSet()) {
    const bb::ShaderSource glsl = bb::shader(f, bb::Glsl::kCore330);
    auto spirv = translateShader(glsl.vertex, glsl.fragment, ShaderTarget::kSpirv);
    ASSERT_TRUE(spirv.ok()) << spirv.error().message << "\n" << glsl.fragment;
    auto hlsl = translateShader(glsl.vertex, glsl.fragment, ShaderTarget::kHlsl);
    ASSERT_TRUE(hlsl.ok()) << hlsl.error().message;
    for (auto [stage, sv, sh, name] :
         {std::tuple{"vert", &spirv.value().vertex, &hlsl.value().vertex, "vertex"},
          std::tuple{"frag", &spirv.value().fragment, &hlsl.value().fragment, "fragment"}}) {
      std::string log;
      EXPECT_TRUE(accepts("spirv-val --target-env vulkan1.0", words(sv->spirv), ".spv", log)) << name << log;
      EXPECT_TRUE(accepts("glslangValidator -V -o /dev/null -D -e " + sh->entryPoint + " -S " + stage, sh->source,
                          ".hlsl", log))
          << name << "\n" << sh->source << log;
      ++checked;
    }
    // No trace of a disabled feature in any language: the uniform block holds exactly the
    // GLSL's uniforms (samplers aside, which are textures).
    for (const ShaderResource& r : spirv.value().resources) {
      if (r.kind != "uniformBlock") continue;
      for (const auto& [member, offset] : r.members) {
        EXPECT_NE(std::find(glsl.uniforms.begin(), glsl.uniforms.end(), member), glsl.uniforms.end()) << member;
      }
    }
  }
  EXPECT_EQ(checked, 2 * (64 + 16));
}

TEST(ShaderTargets, MslNamesItsEntryPointsAndBindings) {
  bb::Features f;  // the film, every feature on
  const bb::ShaderSource glsl = bb::shader(f, bb::Glsl::kCore330);
  auto msl = translateShader(glsl.vertex, glsl.fragment, ShaderTarget::kMsl);
  ASSERT_TRUE(msl.ok()) << msl.error().message;
  const TranslatedShader& t = msl.value();
  EXPECT_EQ(t.vertex.entryPoint, "main0");
  EXPECT_NE(t.vertex.source.find("vertex main0_out main0("), std::string::npos) << t.vertex.source;
  EXPECT_NE(t.fragment.source.find("fragment main0_out main0("), std::string::npos) << t.fragment.source;
  int textures = 0;
  for (const ShaderResource& r : t.resources) {
    if (r.kind == "texture") {
      ++textures;
      EXPECT_GE(r.mslIndex, 0) << r.name;
      EXPECT_NE(t.fragment.source.find("[[texture(" + std::to_string(r.mslIndex) + ")]]"), std::string::npos) << r.name;
    }
  }
  EXPECT_EQ(textures, 3);  // environment, thin-film table, thickness
  // The uniform block's members carry offsets an engine fills at.
  bool model = false;
  for (const ShaderResource& r : t.resources)
    for (const auto& [member, offset] : r.members) model |= member == "uModel" && offset == 0;
  EXPECT_TRUE(model);
}

}  // namespace
}  // namespace effectd::testing

// three.js's ES modules (r187: three.module.js and the three.core.js it imports), built into
// the binary when scripts/setup.sh has installed them in server/playground/vendor/ (npm ci: the
// version its package-lock.json pins, checked against the integrity hash there). The bytes are
// taken in by the assembler (.incbin): 2 MB as a C++ array initializer would cost the compiler
// far more than the file. server/CMakeLists.txt defines EFFECTD_THREE_DIR when the files exist.
#include "app/playground.h"

#ifdef EFFECTD_THREE_DIR
asm(".section .rodata\n"
    ".global effectd_three_module\n"
    "effectd_three_module:\n"
    ".incbin \"" EFFECTD_THREE_DIR "/three.module.js\"\n"
    ".global effectd_three_module_end\n"
    "effectd_three_module_end:\n"
    ".global effectd_three_core\n"
    "effectd_three_core:\n"
    ".incbin \"" EFFECTD_THREE_DIR "/three.core.js\"\n"
    ".global effectd_three_core_end\n"
    "effectd_three_core_end:\n"
    ".previous\n");
extern "C" const char effectd_three_module[], effectd_three_module_end[], effectd_three_core[], effectd_three_core_end[];
#endif

namespace effectd {

std::map<std::string, std::string_view> builtInThree() {
#ifdef EFFECTD_THREE_DIR
  return {{"three.module.js", {effectd_three_module, size_t(effectd_three_module_end - effectd_three_module)}},
          {"three.core.js", {effectd_three_core, size_t(effectd_three_core_end - effectd_three_core)}}};
#else
  return {};
#endif
}

}  // namespace effectd

// CHECK macros for programming errors (broken invariants, not bad input: bad input is an
// `Error` value, see common.h). Internal to the library: its bare CHECK names stay out of the
// headers an engine includes. A failed CHECK prints the expression, both
// operands where there are two, and the place, then aborts; CHECKs stay on in Release because
// a wrong answer served is worse than a crash that names its cause. DCHECK is for checks on
// hot paths and compiles to nothing with NDEBUG. After pbrt-v4's src/pbrt/util/check.h.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>

namespace effects::detail {

[[noreturn]] inline void checkFailed(const char* file, int line, const char* expr, const std::string& operands) {
  std::fprintf(stderr, "%s:%d: CHECK failed: %s%s\n", file, line, expr, operands.c_str());
  std::fflush(stderr);
  std::abort();
}

template <class A, class B>
std::string operands(const A& a, const B& b) {
  std::ostringstream s;
  s << " (" << a << " vs " << b << ")";
  return s.str();
}

}  // namespace effects::detail

#define EFFECTS_CHECK(x) ((x) ? (void)0 : ::effects::detail::checkFailed(__FILE__, __LINE__, #x, std::string()))

#define EFFECTS_CHECK_OP(a, op, b)                                                   \
  do {                                                                               \
    const auto& checkA_ = (a);                                                       \
    const auto& checkB_ = (b);                                                       \
    if (!(checkA_ op checkB_))                                                       \
      ::effects::detail::checkFailed(__FILE__, __LINE__, #a " " #op " " #b,          \
                                     ::effects::detail::operands(checkA_, checkB_)); \
  } while (false)

#define CHECK(x) EFFECTS_CHECK(x)
#define CHECK_EQ(a, b) EFFECTS_CHECK_OP(a, ==, b)
#define CHECK_NE(a, b) EFFECTS_CHECK_OP(a, !=, b)
#define CHECK_LT(a, b) EFFECTS_CHECK_OP(a, <, b)
#define CHECK_LE(a, b) EFFECTS_CHECK_OP(a, <=, b)
#define CHECK_GT(a, b) EFFECTS_CHECK_OP(a, >, b)
#define CHECK_GE(a, b) EFFECTS_CHECK_OP(a, >=, b)

#ifdef NDEBUG
#define DCHECK(x) ((void)0)
#define DCHECK_LT(a, b) ((void)0)
#define DCHECK_LE(a, b) ((void)0)
#else
#define DCHECK(x) CHECK(x)
#define DCHECK_LT(a, b) CHECK_LT(a, b)
#define DCHECK_LE(a, b) CHECK_LE(a, b)
#endif

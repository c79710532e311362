// effects/common.h — shared vocabulary of the effects library.
//
// Contract for every effect module:
//  * Bad input is reported as an `Error` value naming the field (a JSON-pointer-like path
//    relative to the params struct, e.g. "/visibilityRange") and the rule broken. No
//    exception crosses the library boundary; programming errors are CHECKs (effects/util/
//    check.h, internal to the library).
//  * Every result carries `Stats`: which method ran, how long it took, work counters, and
//    an error estimate against the effect's reference method with the metric's name.
//  * Deterministic: same params + seed -> same output, bit for bit. Randomness comes from
//    `Rng` (PCG32) with distributions written out here, never from <random> distributions.
//  * Thread-safety: functions are reentrant; caches are internally synchronised.
#pragma once

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "effects/export.h"

EFFECTS_API_BEGIN
namespace effects {

enum class ErrorKind {
  kInvalidArgument,  // a field breaks its documented range or type rule   -> HTTP 400
  kUnsatisfiable,    // well-formed, but cannot be served (unreachable...)  -> HTTP 422
  kLimitExceeded,    // over a configured resource bound                     -> HTTP 413/422
  kCancelled,        // the caller's progress callback asked the work to stop (a cancelled job)
};

struct Error {
  ErrorKind kind = ErrorKind::kInvalidArgument;
  std::string field;    // path of the offending field, "" when it is the request as a whole
  std::string message;  // the rule that was broken, for humans
};

// Either a value or an Error. Minimal on purpose: `ok()`, `value()`, `error()`. Dropping one
// unread is a compile warning: an ignored Result is an ignored error.
template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : v_(std::move(value)) {}      // NOLINT(google-explicit-constructor)
  Result(Error error) : v_(std::move(error)) {}  // NOLINT(google-explicit-constructor)
  bool ok() const { return v_.index() == 0; }
  T& value() { return std::get<0>(v_); }
  const T& value() const { return std::get<0>(v_); }
  const Error& error() const { return std::get<1>(v_); }

 private:
  std::variant<T, Error> v_;
};

inline Error invalid(std::string field, std::string message) {
  return Error{ErrorKind::kInvalidArgument, std::move(field), std::move(message)};
}
inline Error unsatisfiable(std::string field, std::string message) {
  return Error{ErrorKind::kUnsatisfiable, std::move(field), std::move(message)};
}
inline Error overLimit(std::string field, std::string message) {
  return Error{ErrorKind::kLimitExceeded, std::move(field), std::move(message)};
}

// What every effect reports about the work it did.
struct Stats {
  std::string method;                      // e.g. "fast", "dbm-multigrid", "mikktspace"
  double elapsedMs = 0.0;                  // wall time of the computation itself
  double errorMs = 0.0;                    // wall time of measuring `error` (not in elapsedMs)
  std::map<std::string, double> counters;  // steps, candidates, iterations, residual ...
  std::optional<double> error;             // estimated error against the reference
  std::string errorMetric;                 // what `error` measures, e.g. "max |f - f_exact|"
  std::string reference;                   // the reference method the error is measured against
  std::string errorKind;                   // "measured" (against `reference`) or "estimate" (computed cheaply)
};

// Wall-clock stopwatch in milliseconds.
class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}
  double ms() const {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::chrono::steady_clock::time_point start_;
};

// PCG32 (O'Neill 2014, XSH-RR variant): small, fast, identical on every platform.
class Rng {
 public:
  explicit Rng(uint64_t seed, uint64_t stream = 0x5851f42d4c957f2dULL) {
    inc_ = (stream << 1u) | 1u;
    state_ = 0;
    next();
    state_ += seed;
    next();
  }
  uint32_t next() {
    uint64_t old = state_;
    state_ = old * 6364136223846793005ULL + inc_;
    auto xorshifted = static_cast<uint32_t>(((old >> 18u) ^ old) >> 27u);
    auto rot = static_cast<uint32_t>(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
  }
  // Uniform double in [0, 1) with 53 random bits.
  double uniform() {
    uint64_t hi = next(), lo = next();
    return static_cast<double>(((hi << 32) | lo) >> 11) * 0x1.0p-53;
  }

 private:
  uint64_t state_ = 0, inc_ = 0;
};

}  // namespace effects
EFFECTS_API_END

// CIE tables used by the thin-film colour (see cie.cpp for the source).
#pragma once

namespace effects::bubble::cie {

constexpr int kSamples = 81;  // 380, 385, ..., 780 nm
constexpr double kFirstNm = 380.0, kStepNm = 5.0;
extern const double kXBar[kSamples], kYBar[kSamples], kZBar[kSamples], kD65[kSamples];

}  // namespace effects::bubble::cie

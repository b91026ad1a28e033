// The factors of the stable time-step bound (analysis/DtBound.cpp states it at compile time,
// codegen/DtBoundCpp.cpp makes the solver compute it at start-up): one definition for both.
#pragma once

namespace sphc::dt_bound {

constexpr double kAcoustic = 0.25;   // dt <= kAcoustic h / (c0 (1 + kAlpha alpha))
constexpr double kAlpha = 0.6;       //   Monaghan 1992: signal speed c + 0.6 alpha c
constexpr double kViscous = 0.125;   // dt <= kViscous h^2 / nu        (Morris et al. 1997)
constexpr double kForce = 0.25;      // dt <= kForce sqrt(h / |g|)     (Monaghan 1992)

constexpr const char* kAcousticText = "acoustic limit 0.25 h / (c0 (1 + 0.6 alpha))";
constexpr const char* kViscousText = "viscous limit 0.125 h^2 / nu";
constexpr const char* kForceText = "force limit 0.25 sqrt(h / |g|)";
constexpr const char* kAcousticSource = "Monaghan 1992; Morris et al. 1997";
constexpr const char* kViscousSource = "Morris et al. 1997";
constexpr const char* kForceSource = "Monaghan 1992; Morris et al. 1997";

}  // namespace sphc::dt_bound

#pragma once
/// Which IcoBoard channel carries which RELbot wheel, for both sides of the link (thesis
/// appendix G). The twin reads `u[0] = channel2 // Left` and `u[1] = channel1 // Right`, and
/// writes `enc1 = right`, `enc2 = left`; the ECS is wired the same way on the real robot. Board
/// channel n is array index n - 1 everywhere in hiltwin (frame opcodes PWM1..4, ENC1..4).

#include <cstddef>

namespace hiltwin::app {

constexpr std::size_t kRightChannel = 0;  ///< board channel 1: right motor PWM, right encoder
constexpr std::size_t kLeftChannel = 1;   ///< board channel 2: left motor PWM, left encoder

}  // namespace hiltwin::app

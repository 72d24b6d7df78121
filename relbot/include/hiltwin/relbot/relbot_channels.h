#pragma once
/// Which IcoBoard channel carries which RELbot wheel, for both sides of the link (thesis
/// appendix G). The twin reads `u[0] = channel2 // Left` and `u[1] = channel1 // Right`, and
/// writes `enc1 = right`, `enc2 = left`; the ECS is wired the same way on the real robot. Board
/// channel n (appendix G's `channel1`, `enc1`, ...) is array index and frame slot n - 1
/// everywhere in hiltwin (opcodes PWM c = 4 + c and ENC c = 8 + c, docs/spi-protocol.md).
/// tests/unit/app/wheel_channels_test.cpp drives one channel through both boards and checks
/// which wheel moves and which way the robot turns.

#include <cstddef>

namespace hiltwin::app {

constexpr std::size_t kRightChannel = 0;  ///< board channel 1: right motor PWM, right encoder
constexpr std::size_t kLeftChannel = 1;   ///< board channel 2: left motor PWM, left encoder

}  // namespace hiltwin::app

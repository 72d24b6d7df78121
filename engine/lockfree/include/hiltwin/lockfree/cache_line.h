#pragma once
/// The cache-line size every lock-free structure pads its shared indices to, so that a writer's
/// and a reader's hot words never share a line (false sharing costs both cores a miss per write).

#include <cstddef>

namespace hiltwin::lockfree {

/// 64 bytes on both machines hiltwin targets: x86-64 and the Raspberry Pi 4's Cortex-A72 (its L1
/// and L2 lines are 64 bytes). Not std::hardware_destructive_interference_size: g++ ties that
/// to -mtune and warns when a header uses it, as the value would then be part of the ABI.
inline constexpr std::size_t kCacheLineBytes = 64;

}  // namespace hiltwin::lockfree

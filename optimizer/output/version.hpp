#pragma once

namespace beamrail {
inline constexpr const char* kVersion = "0.1.0";
}  // namespace beamrail

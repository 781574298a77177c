// Small exact helpers kit-scenes' parts share: pi, an integer hash for deterministic
// variation, smoothstep.
#pragma once

#include <algorithm>
#include <cstdint>

namespace kit_scenes {

constexpr double kPi = 3.14159265358979323846;

// Integer hash (lowbias32) for per-brick colour variation: exact on every platform,
// unlike the standard library's random distributions.
inline std::uint32_t hash32(std::uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return x;
}

inline float hash01(std::uint32_t x) { return float(hash32(x) & 0xffffU) / 65535.0f; }

inline float smoothstep(float e0, float e1, float x) {
  const float t = std::clamp((x - e0) / (e1 - e0), 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}

}  // namespace kit_scenes

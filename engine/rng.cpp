#include "engine/rng.h"

#include <cmath>

#include "engine/check.h"

namespace jsa {
namespace {

uint64_t splitmix64(uint64_t& x) {
  uint64_t z = (x += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

}  // namespace

Rng::Rng(uint64_t seed, uint64_t stream) {
  uint64_t x = seed ^ (0xD1B54A32D192ED03ull * (stream + 1));
  for (auto& w : s_) w = splitmix64(x);
}

uint64_t Rng::next() {
  const uint64_t result = rotl(s_[1] * 5, 7) * 9;
  const uint64_t t = s_[1] << 17;
  s_[2] ^= s_[0];
  s_[3] ^= s_[1];
  s_[1] ^= s_[2];
  s_[0] ^= s_[3];
  s_[2] ^= t;
  s_[3] = rotl(s_[3], 45);
  return result;
}

double Rng::uniform() { return double(next() >> 11) * 0x1.0p-53; }

uint64_t Rng::below(uint64_t n) {
  JSA_CHECK(n > 0, "below(0): the range [0, 0) is empty");
  // Lemire's rejection: unbiased without a division in the common case.
  const uint64_t threshold = (0 - n) % n;
  for (;;) {
    const uint64_t r = next();
    const __uint128_t m = __uint128_t(r) * n;
    if (uint64_t(m) >= threshold) return uint64_t(m >> 64);
  }
}

double Rng::normal() {
  // z = sqrt(-2 ln u1) cos(2 pi u2); 1 - uniform() is in (0, 1], so the log is finite.
  const double u1 = 1.0 - uniform(), u2 = uniform();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

Rng Rng::stream(uint64_t k) const {
  Rng r(0, 0);
  uint64_t x = s_[0] ^ rotl(s_[1], 13) ^ (0x9E3779B97F4A7C15ull * (k + 1));
  for (auto& w : r.s_) w = splitmix64(x);
  return r;
}

}  // namespace jsa

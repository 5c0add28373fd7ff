// A seeded random generator with explicit state: xoshiro256** (Blackman & Vigna),
// seeded through splitmix64 from (seed, stream). There is no global generator:
// whoever draws owns an Rng. Independent streams (one per thread, one per
// purpose) come from the same seed with different stream numbers, so results
// depend on the seed and the thread count only.
#pragma once
#include <array>
#include <cstdint>

namespace jsa {

class Rng {
 public:
  explicit Rng(uint64_t seed = 0, uint64_t stream = 0);
  uint64_t next();   // 64 random bits
  double uniform();  // [0, 1), 53-bit resolution
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  uint64_t below(uint64_t n);    // uniform integer in [0, n), unbiased
  double normal();               // N(0, 1) by Box-Muller (one draw, two uniforms)
  Rng stream(uint64_t k) const;  // an independent generator derived from this state

  std::array<uint64_t, 4> state() const { return s_; }
  void set_state(const std::array<uint64_t, 4>& s) { s_ = s; }

 private:
  std::array<uint64_t, 4> s_;
};

}  // namespace jsa

// Random numbers for the simulator. Scene and traffic draw from a seeded std::mt19937_64 (one per sequence:
// seed + sequence index); per-ray noise uses a counter-based hash of (seed, frame, ray), so a ray's noise does not
// depend on which thread casts it or in which order: that is what makes the output byte-identical run to run.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>

namespace ret3d {
namespace sim {

class Rng {
 public:
  explicit Rng(std::uint64_t seed) : gen_(seed) {}
  // Uniform in [a, b). Implemented on the raw 64-bit output (not std::uniform_real_distribution), so the stream is
  // the same with every standard library.
  double uniform(double a = 0.0, double b = 1.0) {
    return a + (b - a) * (static_cast<double>(gen_() >> 11) * (1.0 / 9007199254740992.0));
  }
  double normal(double mean = 0.0, double sigma = 1.0) {
    const double u1 = uniform(1e-12, 1.0), u2 = uniform();
    return mean + sigma * std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  }
  bool chance(double p) { return uniform() < p; }
  // Integer in [a, b].
  int integer(int a, int b) { return a + static_cast<int>(uniform() * (b - a + 1) * 0.999999999); }
  std::uint64_t next() { return gen_(); }

 private:
  std::mt19937_64 gen_;
};

// SplitMix64 finaliser: a good 64-bit mixing function.
inline std::uint64_t mix64(std::uint64_t z) {
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// Stateless per-ray random numbers: stream k of counter (a, b, c).
struct HashRng {
  std::uint64_t state;
  HashRng(std::uint64_t a, std::uint64_t b, std::uint64_t c) : state(mix64(a ^ mix64(b ^ mix64(c)))) {}
  double uniform() {
    state = mix64(state);
    return static_cast<double>(state >> 11) * (1.0 / 9007199254740992.0);
  }
  double normal() {
    const double u1 = uniform() + 1e-12, u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  }
};

}  // namespace sim
}  // namespace ret3d

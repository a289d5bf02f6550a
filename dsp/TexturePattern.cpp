#include "TexturePattern.hpp"

namespace kf::patterns {

namespace {

// splitmix64 (Steele, Lea, Flood 2014): a well-mixed 64-bit sequence from any seed.
uint64_t splitmix64(uint64_t& state) {
  uint64_t z = (state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// Uniform in [0, 1) from the top 53 bits.
double unit(uint64_t& state) { return static_cast<double>(splitmix64(state) >> 11) * 0x1.0p-53; }

uint64_t seedOf(double seed) {
  const double whole = std::trunc(std::clamp(seed, -9e15, 9e15));
  return static_cast<uint64_t>(static_cast<int64_t>(whole));
}

}  // namespace

double TexturePattern::amplitude() { return 1.0 / (6.0 * std::sqrt(kComponents / 2.0)); }

void TexturePattern::draw(double lo, double hi, uint64_t seed, Components& out) {
  uint64_t state = seed;
  for (int k = 0; k < kComponents; ++k) {
    out.frequency[k] = lo + (hi - lo) * unit(state);
    out.phase[k] = 2.0 * kPi * unit(state);
  }
}

double TexturePattern::at(double lo, double hi, uint64_t seed, double xMm) {
  Components c;
  draw(lo, hi, seed, c);
  double sum = 0.0;
  for (int k = 0; k < kComponents; ++k) sum += std::sin(2.0 * kPi * c.frequency[k] * xMm + c.phase[k]);
  return clampLevel(0.5 + amplitude() * sum);
}

void TexturePattern::set(double lo, double hi, double seed, double sampleRateHz) {
  if (lo > 0.0 && std::isfinite(lo)) lo_ = lo;
  if (hi > 0.0 && std::isfinite(hi)) hi_ = hi;
  const uint64_t s = std::isfinite(seed) ? seedOf(seed) : seed_;
  const double a = std::min(lo_, hi_), b = std::max(lo_, hi_);
  Components wanted;
  draw(a, b, s, wanted);
  auto same = [](const Components& a, const Components& b) {
    return std::equal(a.frequency, a.frequency + kComponents, b.frequency) &&
           std::equal(a.phase, a.phase + kComponents, b.phase);
  };
  seed_ = s;
  sampleRateHz_ = sampleRateHz;
  if (!set_) {
    current_ = wanted;
    set_ = true;
  } else if (fade_ < 1.0) {
    // Fading to current_: a different texture waits until the fade ends.
    hasPending_ = !same(wanted, current_);
    if (hasPending_) pending_ = wanted;
  } else if (!same(wanted, current_)) {
    startFade(wanted);
  }
}

void TexturePattern::startFade(const Components& to) {
  previous_ = current_;
  current_ = to;
  fade_ = 0.0;
  fadeStep_ = 1.0 / std::max(1.0, kCrossfadeS * sampleRateHz_);
}

double TexturePattern::render(const Components& c, const Travel& travel, bool antialias) {
  double sum = 0.0;
  for (int k = 0; k < kComponents; ++k) {
    const double w = 2.0 * kPi * c.frequency[k];
    if (!antialias) {
      sum += std::sin(w * travel.toMm + c.phase[k]);
      continue;
    }
    // Mean of sin(w x + phi) over [from, to]: sin(w mid + phi) * sin(w half) / (w half).
    const double mid = 0.5 * (travel.fromMm + travel.toMm), half = 0.5 * w * (travel.toMm - travel.fromMm);
    const double sinc = std::fabs(half) < 1e-8 ? 1.0 : std::sin(half) / half;
    const double gain = bandLimitGain(travel.speedMmPerS * c.frequency[k], travel.framePeriodS);
    sum += gain * sinc * std::sin(w * mid + c.phase[k]);
  }
  return clampLevel(0.5 + amplitude() * sum);
}

double TexturePattern::level(const Travel& travel, bool antialias) {
  if (fade_ >= 1.0 && hasPending_) {
    hasPending_ = false;
    startFade(pending_);
  }
  const double now = render(current_, travel, antialias);
  if (fade_ >= 1.0) return now;
  const double before = render(previous_, travel, antialias);
  const double w = fade_;
  fade_ = std::min(1.0, fade_ + fadeStep_);
  return (1.0 - w) * before + w * now;
}

}  // namespace kf::patterns

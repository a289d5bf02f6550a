#include "patterns/TexturePattern.hpp"

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

// No components (before the first set()): the level is 1/2, not 0 * inf.
double TexturePattern::amplitude(int count) { return count > 0 ? 1.0 / (6.0 * std::sqrt(count / 2.0)) : 0.0; }

void TexturePattern::draw(double lo, double hi, uint64_t seed, Components& out) {
  uint64_t state = seed;
  out.count = kComponents;
  for (int k = 0; k < kComponents; ++k) {
    out.frequencyX[k] = lo + (hi - lo) * unit(state);
    out.frequencyY[k] = 0.0;
    out.phase[k] = 2.0 * kPi * unit(state);
  }
}

void TexturePattern::draw2D(double lo, double hi, uint64_t seed, Components& out) {
  uint64_t state = seed;
  out.count = kComponents2D;
  for (int k = 0; k < kComponents2D; ++k) {
    const double magnitude = lo + (hi - lo) * unit(state), angle = 2.0 * kPi * unit(state);
    out.frequencyX[k] = magnitude * std::cos(angle);
    out.frequencyY[k] = magnitude * std::sin(angle);
    out.phase[k] = 2.0 * kPi * unit(state);
  }
}

double TexturePattern::sum(const Components& c, double xMm, double yMm) {
  double total = 0.0;
  for (int k = 0; k < c.count; ++k)
    total += std::sin(2.0 * kPi * c.frequencyX[k] * xMm + 2.0 * kPi * c.frequencyY[k] * yMm + c.phase[k]);
  return total;
}

double TexturePattern::at(double lo, double hi, uint64_t seed, double xMm) {
  Components c;
  draw(lo, hi, seed, c);
  return clampLevel(0.5 + amplitude(c.count) * sum(c, xMm, 0.0));
}

double TexturePattern::at2D(double lo, double hi, uint64_t seed, double xMm, double yMm) {
  Components c;
  draw2D(lo, hi, seed, c);
  return clampLevel(0.5 + amplitude(c.count) * sum(c, xMm, yMm));
}

void TexturePattern::set(double lo, double hi, double seed, double sampleRateHz) {
  if (lo > 0.0 && std::isfinite(lo)) lo_ = lo;
  if (hi > 0.0 && std::isfinite(hi)) hi_ = hi;
  const uint64_t s = std::isfinite(seed) ? seedOf(seed) : seed_;
  const double a = std::min(lo_, hi_), b = std::max(lo_, hi_);
  sampleRateHz_ = sampleRateHz;
  // Called every block: the same band and seed as the last call leave every state as it is.
  if (set_ && a == drawnLo_ && b == drawnHi_ && s == seed_) return;
  drawnLo_ = a;
  drawnHi_ = b;
  Components wanted;
  if (twoD_) {
    draw2D(a, b, s, wanted);
  } else {
    draw(a, b, s, wanted);
  }
  auto same = [](const Components& a, const Components& b) {
    return std::equal(a.frequencyX, a.frequencyX + a.count, b.frequencyX) &&
           std::equal(a.frequencyY, a.frequencyY + a.count, b.frequencyY) &&
           std::equal(a.phase, a.phase + a.count, b.phase);
  };
  seed_ = s;
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

double TexturePattern::render(const Components& c, const Step& step, bool antialias) {
  if (!antialias) return clampLevel(0.5 + amplitude(c.count) * sum(c, step.toX, step.toY));
  // The velocity (mm/s): each wave's temporal frequency is |f.v| (Hz).
  const double vx = step.dx / step.framePeriodS, vy = step.dy / step.framePeriodS;
  double total = 0.0;
  for (int k = 0; k < c.count; ++k) {
    const double gain = bandLimitGain(std::fabs(c.frequencyX[k] * vx + c.frequencyY[k] * vy), step.framePeriodS);
    if (gain == 0.0) continue;  // at or above the frames' Nyquist frequency: nothing left to compute
    const double wx = 2.0 * kPi * c.frequencyX[k], wy = 2.0 * kPi * c.frequencyY[k];
    // Mean of sin(w.p + phi) over the straight travel: sin(w.mid + phi) * sin(w.d / 2) / (w.d / 2).
    const double half = 0.5 * (wx * step.dx + wy * step.dy);
    const double sinc = std::fabs(half) < 1e-8 ? 1.0 : std::sin(half) / half;
    total += gain * sinc * std::sin(wx * step.midX + wy * step.midY + c.phase[k]);
  }
  return clampLevel(0.5 + amplitude(c.count) * total);
}

double TexturePattern::level(const Travel& travel, bool antialias) {
  return level(Step{0.5 * (travel.fromMm + travel.toMm), 0.0, travel.toMm - travel.fromMm, 0.0, travel.framePeriodS,
                    travel.toMm, 0.0},
               antialias);
}

double TexturePattern::level(double x0, double y0, double x1, double y1, double framePeriodS, bool antialias) {
  return level(Step{0.5 * (x0 + x1), 0.5 * (y0 + y1), x1 - x0, y1 - y0, framePeriodS, x1, y1}, antialias);
}

double TexturePattern::level(const Step& step, bool antialias) {
  if (fade_ >= 1.0 && hasPending_) {
    hasPending_ = false;
    startFade(pending_);
  }
  const double now = render(current_, step, antialias);
  if (fade_ >= 1.0) return now;
  const double before = render(previous_, step, antialias);
  const double w = fade_;
  fade_ = std::min(1.0, fade_ + fadeStep_);
  return (1.0 - w) * before + w * now;
}

}  // namespace kf::patterns

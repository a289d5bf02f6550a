// Texture fidelity against the force rate: a sinusoidal grating (0.14 .. 1.4 N, the paper's
// range) crossed at constant speed, for periods 0.2 .. 5 mm and speeds 10 .. 400 mm/s (temporal
// frequencies 2 Hz .. 2 kHz), rendered as the device does at 1 kHz (protocol 2.0: one set-point
// per 1 ms USB frame) and at 8 kHz (2.1: eight per frame), each frame the mean of its samples, and
// at 8 kHz also through the anti-alias filter the device uses there (FrameFilter.hpp):
//
//   audio force at 48 kHz -> ForceFramer at the rate (mean or filter) -> drive levels ->
//   one set-point frame per 1 ms (the level just completed at 1 kHz; the eight completed since
//   the last frame at 8 kHz, as UsbBoardBackend sends them) -> BoardEmulator (the firmware the
//   gadget runs) -> the coil's target timeline, the force applied.
//
// Per case: the applied force's line at the grating's frequency against the ideal's (gain, in dB
// and in Weber fractions of 0.11 for a friction change: Gueorguiev et al. 2017), and the largest
// other line inside the touch band (10 Hz .. 1 kHz: what an alias folds into), relative to it.
// Textures too (FrictionPattern.texture: 16 sines of spatial frequencies drawn in a band, on the
// paper's range), three bands (periods 1-5, 0.5-2 and 0.2-0.5 mm) at the same speeds, against the
// ideal through their spectra: the texture's band's amplitude (root of its power) and its worst
// third-octave's, in Weber fractions, and the power in the touch band outside the texture's band
// (aliases, images of the held steps), relative to the texture's.
// Per variant: the latency from the audio's step to the applied force's half-way point (mean over
// 64 phases of the step against the frames), and the CPU time per second of force of the
// framing, encoding and firmware (thread CPU, the variants interleaved in each round).
// Prints one JSON object (bench/kfbench/texture_rate.py reads it).
#include <time.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "ForceFramer.hpp"
#include "board/BoardEmulator.hpp"
#include "patterns/TexturePattern.hpp"

namespace {

using kf::board::BoardEmulator;

constexpr double kPi = 3.14159265358979323846;
constexpr double kSampleRate = 48000;
constexpr int kBlock = 64;
constexpr double kMinN = 0.14, kMaxN = 1.4;
constexpr double kMeanN = 0.5 * (kMinN + kMaxN), kAmplitudeN = 0.5 * (kMaxN - kMinN);
constexpr double kWeber = 0.11;
constexpr double kUsbOffsetS = 0.37e-3;  // the USB frames' phase against the audio's frames

double cpuS() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

uint16_t driveOf(double forceN) {
  const double level = std::clamp((forceN - kMinN) / (kMaxN - kMinN), 0.0, 1.0);
  return static_cast<uint16_t>(std::lround(level * kf::board::kDriveFull));
}

double forceOf(uint16_t drive) { return kMinN + (kMaxN - kMinN) * drive / kf::board::kDriveFull; }

// The applied force: the coil's target on a grid of the rate's steps (every change falls on it).
struct Applied {
  double startS, stepS;
  std::vector<double> forceN;
};

// A way to render force: levels per 1 ms USB frame (1 or 8), and how the frames are taken.
struct Variant {
  const char* name;
  int perFrame;
  kf::FrameFilter filter;
};
const Variant kVariants[] = {{"1 kHz", 1, kf::FrameFilter::kMean},
                             {"8 kHz", 8, kf::FrameFilter::kMean},
                             {"8 kHz, anti-alias filter", 8, kf::FrameFilter::kAntiAlias}};
constexpr int kNumVariants = sizeof kVariants / sizeof kVariants[0];

// Renders `audio(t)` (N) for durationS as `variant` does.
template <class Audio>
std::vector<BoardEmulator::Change> render(Audio audio, double durationS, const Variant& variant) {
  const int perFrame = variant.perFrame;
  const double framePeriodS = kf::board::kFramePeriodS / perFrame;
  kf::ForceFramer framer(framePeriodS, kMinN, kMaxN, variant.filter);
  BoardEmulator board(0.0);
  uint8_t scratch[kf::board::kClearReplySize];
  int moved = 0;
  board.control(0xC1, static_cast<uint8_t>(kf::board::Request::kClearErrors), 0, scratch, sizeof scratch, &moved, 0.0);
  board.control(0x41, static_cast<uint8_t>(kf::board::Request::kArm), kf::board::kArmKey, nullptr, 0, nullptr, 0.0);

  std::vector<uint16_t> levels;  // every completed frame's drive, in order
  auto sink = [&](double, float forceN) { levels.push_back(driveOf(forceN)); };
  size_t sent = 0;
  uint16_t sequence = 0;
  // One USB frame at usbS: what was completed before it, as UsbBoardBackend sends it.
  auto sendFrame = [&](double usbS) {
    if (levels.empty()) return;
    uint8_t bytes[kf::board::kMaxSetPointFrameSize];
    size_t size = kf::board::kSetPointSize;
    if (perFrame == 1) {
      kf::board::encodeSetPoint({++sequence, levels.back()}, bytes);
    } else {
      kf::board::MultiSetPoint frame;
      frame.sequence = ++sequence;
      frame.count = perFrame;
      const uint16_t held = sent > 0 ? levels[sent - 1] : levels[0];
      for (int k = 0; k < perFrame; ++k) frame.drives[k] = sent < levels.size() ? levels[sent++] : held;
      kf::board::encodeMultiSetPoint(frame, bytes);
      size = kf::board::multiSetPointSize(perFrame);
    }
    board.receiveSetPoint(bytes, size, usbS);
  };
  double nextUsbS = kUsbOffsetS;
  std::vector<float> block(kBlock);
  const auto samples = static_cast<int64_t>(durationS * kSampleRate);
  for (int64_t start = 0; start < samples; start += kBlock) {
    // The USB frames that fall in this block go out with what was completed before them: the
    // block is split at each, so a frame sees only the levels of audio before its time.
    int done = 0;
    while (done < kBlock) {
      if ((start + done) / kSampleRate >= nextUsbS - 1e-12) {
        sendFrame(nextUsbS);
        nextUsbS += kf::board::kFramePeriodS;
        continue;
      }
      const int until = std::min<int>(kBlock, static_cast<int>(std::ceil(nextUsbS * kSampleRate - 1e-9) - start));
      const int n = until - done;
      for (int i = 0; i < n; ++i) block[i] = static_cast<float>(audio((start + done + i) / kSampleRate));
      framer.process((start + done) / kSampleRate, 1.0 / kSampleRate, block.data(), n, nullptr, sink);
      done += n;
    }
  }
  board.advance(durationS);
  return board.timeline();
}

// The coil's target on the grid of the rate's steps from the first USB frame on (every change
// falls on the grid).
Applied onGrid(const std::vector<BoardEmulator::Change>& timeline, double durationS, int perFrame) {
  const double framePeriodS = kf::board::kFramePeriodS / perFrame;
  Applied applied{kUsbOffsetS, framePeriodS, {}};
  const auto steps = static_cast<size_t>((durationS - kUsbOffsetS) / framePeriodS);
  applied.forceN.assign(steps, kMinN);
  size_t c = 0;
  uint16_t drive = 0;
  for (size_t k = 0; k < steps; ++k) {
    const double t = applied.startS + (k + 0.5) * framePeriodS;
    while (c < timeline.size() && timeline[c].timeS <= t) drive = timeline[c++].drive;
    applied.forceN[k] = forceOf(drive);
  }
  return applied;
}

// The 4-term Blackman-Harris window's value at step k of count (sidelobes under -92 dB).
double blackmanHarris(size_t k, size_t count) {
  const double x = 2 * kPi * (k + 0.5) / count;
  return 0.35875 - 0.48829 * std::cos(x) + 0.14128 * std::cos(2 * x) - 0.01168 * std::cos(3 * x);
}

// The applied force's complex amplitude at f over [fromS, fromS + spanS) (4-term Blackman-Harris
// window: sidelobes under -92 dB, so that the grating's own line leaks nothing into the others),
// exact for a force held over each step: the steps' sum times the step's own transform.
std::complex<double> line(const Applied& a, double f, double fromS, double spanS) {
  const double w = 2 * kPi * f;
  const auto first = static_cast<size_t>(std::ceil((fromS - a.startS) / a.stepS));
  const auto count = static_cast<size_t>(spanS / a.stepS);
  const std::complex<double> hold =
      w == 0 ? 1.0 : (1.0 - std::polar(1.0, -w * a.stepS)) / std::complex<double>(0, w * a.stepS);
  const std::complex<double> turn = std::polar(1.0, -w * a.stepS);
  std::complex<double> phasor = std::polar(1.0, -w * (a.startS + first * a.stepS));
  std::complex<double> sum = 0;
  double windowSum = 0;
  for (size_t k = 0; k < count && first + k < a.forceN.size(); ++k, phasor *= turn) {
    const double window = blackmanHarris(k, count);
    sum += window * (a.forceN[first + k] - kMeanN) * phasor;
    windowSum += window;
  }
  return 2.0 * sum * hold / windowSum;
}

struct Case {
  double periodMm, speedMmPerS, frequencyHz;
  double gainDb[kNumVariants], weber[kNumVariants], spurDb[kNumVariants];
};

// Texture cases: one band of FrictionPattern.texture crossed at one speed, compared with the
// ideal force through their spectra over the same 2.048 s (a power of two of steps at 1, 8 and
// 64 kHz, so that the bins are the same 0.49 Hz apart in all three).
using kf::patterns::TexturePattern;
constexpr uint64_t kTextureSeed = 7;
constexpr double kTextureSpanS = 2.048, kTextureFromS = 0.02, kIdealRateHz = 64000;

struct TextureCase {
  double loPerMm, hiPerMm, speedMmPerS;
  double bandWeber[kNumVariants], worstWeber[kNumVariants], worstHz[kNumVariants], spurDb[kNumVariants];
};

// In-place radix-2 FFT (size a power of two).
void fft(std::vector<std::complex<double>>& x) {
  const size_t n = x.size();
  for (size_t i = 1, j = 0; i < n; ++i) {
    size_t bit = n >> 1;
    for (; j & bit; bit >>= 1) j ^= bit;
    j ^= bit;
    if (i < j) std::swap(x[i], x[j]);
  }
  for (size_t len = 2; len <= n; len <<= 1) {
    const std::complex<double> turn = std::polar(1.0, -2 * kPi / len);
    for (size_t i = 0; i < n; i += len) {
      std::complex<double> w = 1;
      for (size_t k = 0; k < len / 2; ++k, w *= turn) {
        const std::complex<double> u = x[i + k], v = x[i + k + len / 2] * w;
        x[i + k] = u + v;
        x[i + k + len / 2] = u - v;
      }
    }
  }
}

// The force's power per bin (amplitude squared, bins 1 / kTextureSpanS apart) from kTextureFromS
// over kTextureSpanS, 4-term Blackman-Harris window, the hold of each step taken into account.
std::vector<double> powerSpectrum(const Applied& a) {
  const auto first = static_cast<size_t>(std::ceil((kTextureFromS - a.startS) / a.stepS));
  const auto count = static_cast<size_t>(std::lround(kTextureSpanS / a.stepS));
  std::vector<std::complex<double>> x(count);
  double windowSum = 0;
  for (size_t k = 0; k < count; ++k) {
    const double window = blackmanHarris(k, count);
    x[k] = window * (first + k < a.forceN.size() ? a.forceN[first + k] - kMeanN : 0.0);
    windowSum += window;
  }
  fft(x);
  std::vector<double> power(count / 2);
  for (size_t k = 0; k < power.size(); ++k) {
    const double w = 2 * kPi * k / kTextureSpanS * a.stepS;
    const double hold = k == 0 ? 1.0 : std::fabs(std::sin(w / 2) / (w / 2));
    power[k] = std::norm(2.0 * x[k] * hold / windowSum);
  }
  return power;
}

double bandPower(const std::vector<double>& power, double fromHz, double toHz) {
  double sum = 0;
  for (size_t k = 0; k < power.size(); ++k) {
    const double f = k / kTextureSpanS;
    if (f >= fromHz && f < toHz) sum += power[k];
  }
  return sum;
}

TextureCase measureTexture(double lo, double hi, double speed) {
  TextureCase c{lo, hi, speed, {}, {}, {}, {}};
  auto audio = [&](double t) { return kMinN + (kMaxN - kMinN) * TexturePattern::at(lo, hi, kTextureSeed, speed * t); };
  const double durationS = kTextureFromS + kTextureSpanS + 0.01;
  Applied ideal{0.0, 1.0 / kIdealRateHz, {}};
  for (int k = 0; (k + 0.5) / kIdealRateHz < durationS; ++k) ideal.forceN.push_back(audio((k + 0.5) / kIdealRateHz));
  const std::vector<double> idealPower = powerSpectrum(ideal);
  // The texture's band, widened by the window's main lobe (4 bins) on each side; its third-octave
  // bands (at least one), and the touch band (10 Hz .. 1 kHz) outside it.
  const double lobeHz = 4 / kTextureSpanS, bandLoHz = std::max(lo * speed - lobeHz, 0.5 / kTextureSpanS),
               bandHiHz = hi * speed + lobeHz;
  std::vector<double> edges{bandLoHz};
  while (edges.back() * std::pow(2.0, 1.0 / 3) < bandHiHz) edges.push_back(edges.back() * std::pow(2.0, 1.0 / 3));
  edges.back() = bandHiHz;
  if (edges.size() < 2) edges.push_back(bandHiHz);
  const double idealBand = bandPower(idealPower, bandLoHz, bandHiHz);
  for (int r = 0; r < kNumVariants; ++r) {
    const std::vector<double> power =
        powerSpectrum(onGrid(render(audio, durationS, kVariants[r]), durationS, kVariants[r].perFrame));
    c.bandWeber[r] = std::fabs(std::sqrt(bandPower(power, bandLoHz, bandHiHz) / idealBand) - 1) / kWeber;
    for (size_t b = 0; b + 1 < edges.size(); ++b) {
      const double want = bandPower(idealPower, edges[b], edges[b + 1]);
      // Only a third-octave that holds at least half of one component's power (1/16 of the band's):
      // in one the drawn components leave (nearly) empty the ratio measures the window's skirts.
      if (want < 0.5 * idealBand / TexturePattern::kComponents) continue;
      const double weber = std::fabs(std::sqrt(bandPower(power, edges[b], edges[b + 1]) / want) - 1) / kWeber;
      if (weber >= c.worstWeber[r]) {
        c.worstWeber[r] = weber;
        c.worstHz[r] = std::sqrt(edges[b] * edges[b + 1]);
      }
    }
    // Power in the touch band outside the texture's: below it and above it, relative to the
    // texture's (what the ideal has there is its clamp's, shown for the ideal too).
    const double outside =
        bandPower(power, 10, std::min(bandLoHz, 1000.0)) + bandPower(power, std::max(bandHiHz, 10.0), 1000);
    c.spurDb[r] = 10 * std::log10(std::max(outside, 1e-18) / idealBand);
  }
  return c;
}

}  // namespace

int main(int argc, char** argv) {
  const int rounds = argc > 1 ? std::atoi(argv[1]) : 5;
  const double periods[] = {0.2, 0.5, 1.0, 2.0, 5.0};
  const double speeds[] = {10, 25, 50, 100, 200, 400};
  std::vector<Case> cases;
  for (double p : periods)
    for (double v : speeds) {
      Case c{p, v, v / p, {}, {}, {}};
      // At least 8 cycles and 0.5 s (bins of 2 Hz or finer), after 20 ms of start-up.
      const double spanS = std::max(0.5, 8.0 / c.frequencyHz), fromS = 0.02;
      for (int r = 0; r < kNumVariants; ++r) {
        const double phase = 0.3;
        auto audio = [&](double t) { return kMeanN + kAmplitudeN * std::sin(2 * kPi * c.frequencyHz * t + phase); };
        const double durationS = fromS + spanS + 0.01;
        const Applied a = onGrid(render(audio, durationS, kVariants[r]), durationS, kVariants[r].perFrame);
        const double gain = std::abs(line(a, c.frequencyHz, fromS, spanS)) / kAmplitudeN;
        // The largest other line in the touch band, 10 Hz .. 1 kHz, away from the grating's main
        // lobe (+-4 bins of 1 / span; the ideal has no other line), relative to the grating's
        // ideal amplitude.
        double spur = 0;
        for (double f = 10; f <= 1000; f += 1 / spanS) {
          if (std::fabs(f - c.frequencyHz) < 5 / spanS) continue;
          spur = std::max(spur, std::abs(line(a, f, fromS, spanS)));
        }
        c.weber[r] = std::fabs(gain - 1) / kWeber;
        c.gainDb[r] = 20 * std::log10(std::max(gain, 1e-9));
        c.spurDb[r] = 20 * std::log10(std::max(spur, 1e-9) / kAmplitudeN);
      }
      cases.push_back(c);
    }

  // Textures: three bands of periods (1-5, 0.5-2 and 0.2-0.5 mm) at the gratings' speeds.
  const double bands[][2] = {{0.2, 1.0}, {0.5, 2.0}, {2.0, 5.0}};
  std::vector<TextureCase> textures;
  for (const auto& band : bands)
    for (double v : speeds) textures.push_back(measureTexture(band[0], band[1], v));

  // The headline: the highest frequency whose line is within one Weber fraction, per variant, by
  // bisection (below the rate's Nyquist frequency the gain leaves 1 once, for good, as f rises).
  double withinWeberHz[kNumVariants] = {};
  for (int r = 0; r < kNumVariants; ++r) {
    double lo = 10, hi = 500.0 * kVariants[r].perFrame;
    while (hi - lo > 0.5) {
      const double f = 0.5 * (lo + hi), spanS = std::max(0.5, 8.0 / f), fromS = 0.02;
      const double durationS = fromS + spanS + 0.01;
      const Applied a = onGrid(render([&](double t) { return kMeanN + kAmplitudeN * std::sin(2 * kPi * f * t + 0.3); },
                                      durationS, kVariants[r]),
                               durationS, kVariants[r].perFrame);
      const double gain = std::abs(line(a, f, fromS, spanS)) / kAmplitudeN;
      (std::fabs(gain - 1) <= kWeber ? lo : hi) = f;
    }
    withinWeberHz[r] = lo;
  }

  // Latency: an audio step from the minimum to the maximum at 64 phases within a frame.
  double latencyMs[kNumVariants] = {};
  for (int r = 0; r < kNumVariants; ++r) {
    const int phases = 64;
    for (int i = 0; i < phases; ++i) {
      const double stepS = 0.05 + i * (kf::board::kFramePeriodS / phases);
      const Applied a = onGrid(render([&](double t) { return t >= stepS ? kMaxN : kMinN; }, 0.06, kVariants[r]), 0.06,
                               kVariants[r].perFrame);
      for (size_t k = 0; k < a.forceN.size(); ++k)
        if (a.forceN[k] >= kMeanN) {
          latencyMs[r] += 1e3 * (a.startS + k * a.stepS - stepS) / phases;
          break;
        }
    }
  }

  // CPU per second of force: a 100 Hz grating, the variants interleaved in each round.
  std::vector<double> cpu[kNumVariants];
  for (int round = 0; round < rounds; ++round)
    for (int k = 0; k < kNumVariants; ++k) {
      const int r = (round + k) % kNumVariants;
      const double t0 = cpuS();
      const auto timeline =
          render([](double t) { return kMeanN + kAmplitudeN * std::sin(2 * kPi * 100 * t); }, 1.0, kVariants[r]);
      cpu[r].push_back(cpuS() - t0);
      if (timeline.empty()) return 1;
    }

  // Prints values as a JSON list, by default one per variant.
  auto list = [](const double* values, const char* format, size_t count = kNumVariants) {
    std::printf("[");
    for (size_t i = 0; i < count; ++i) {
      std::printf(format, values[i]);
      std::printf(i + 1 < count ? ", " : "]");
    }
  };
  // Prints `, "name": [values...]`, one per variant.
  auto field = [&](const char* name, const double* values, const char* format) {
    std::printf(", \"%s\": ", name);
    list(values, format);
  };
  std::printf("{\"sampleRateHz\": %g, \"block\": %d, \"rounds\": %d, \"weber\": %g,\n \"variants\": [", kSampleRate,
              kBlock, rounds, kWeber);
  for (int r = 0; r < kNumVariants; ++r)
    std::printf("{\"name\": \"%s\", \"rateHz\": %d}%s", kVariants[r].name, 1000 * kVariants[r].perFrame,
                r + 1 < kNumVariants ? ", " : "],\n");
  std::printf(" \"withinWeberHz\": ");
  list(withinWeberHz, "%.1f");
  std::printf(",\n \"latencyMs\": ");
  list(latencyMs, "%.4f");
  std::printf(",\n \"cpuS\": [");
  for (int r = 0; r < kNumVariants; ++r) {
    list(cpu[r].data(), "%.6f", cpu[r].size());
    std::printf(r + 1 < kNumVariants ? ", " : "],\n");
  }
  std::printf(" \"cases\": [\n");
  for (size_t i = 0; i < cases.size(); ++i) {
    const Case& c = cases[i];
    std::printf("  {\"periodMm\": %g, \"speedMmPerS\": %g, \"frequencyHz\": %g", c.periodMm, c.speedMmPerS,
                c.frequencyHz);
    field("gainDb", c.gainDb, "%.4f");
    field("weber", c.weber, "%.4f");
    field("spurDb", c.spurDb, "%.2f");
    std::printf("}%s\n", i + 1 < cases.size() ? "," : "");
  }
  std::printf(" ],\n \"textures\": [\n");
  for (size_t i = 0; i < textures.size(); ++i) {
    const TextureCase& c = textures[i];
    std::printf("  {\"loPerMm\": %g, \"hiPerMm\": %g, \"speedMmPerS\": %g", c.loPerMm, c.hiPerMm, c.speedMmPerS);
    field("bandWeber", c.bandWeber, "%.4f");
    field("worstWeber", c.worstWeber, "%.4f");
    field("worstHz", c.worstHz, "%.1f");
    field("spurDb", c.spurDb, "%.2f");
    std::printf("}%s\n", i + 1 < textures.size() ? "," : "");
  }
  std::printf(" ]}\n");
  return 0;
}

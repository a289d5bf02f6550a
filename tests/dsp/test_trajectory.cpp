// TrajectoryReconstructor: error and lag against a known trajectory in each mode, exact final
// positions, several reports per block, gaps, reversals, zero reports, and a 10-minute run
// with 100 ppm clock drift through DeviceClockMapper.
#include <catch2/catch.hpp>

#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include "DeviceClockMapper.hpp"
#include "TrajectoryReconstructor.hpp"

using kf::TrajectoryMode;
using kf::TrajectoryReconstructor;

namespace {

constexpr double kCountMm = 0.021;
constexpr double kRateHz = 125.0;
constexpr double kIntervalS = 1.0 / kRateHz;
constexpr double kPi = 3.14159265358979323846;
const TrajectoryMode kModes[] = {TrajectoryMode::Hold, TrajectoryMode::Linear, TrajectoryMode::Predictive};

using Motion = std::function<double(double)>;  // true x (mm) at time t (s)

// The mouse: at each poll the counts moved since the previous one (cumulative quantization,
// so the counts add up to the quantized true position).
struct Report {
  double timeS;
  double dxMm;
};
std::vector<Report> mouseReports(const Motion& x, double durationS) {
  std::vector<Report> reports;
  double lastCounts = std::floor(x(0.0) / kCountMm);
  for (int k = 1; k * kIntervalS <= durationS; ++k) {
    const double t = k * kIntervalS;
    const double counts = std::floor(x(t) / kCountMm);
    reports.push_back({t, (counts - lastCounts) * kCountMm});
    lastCounts = counts;
  }
  return reports;
}

struct Rendered {
  std::vector<double> timeS;
  std::vector<float> xMm, vxMmPerS;
};

// Lockstep delivery: before each block, every report timed before the block's end is added.
Rendered renderReports(TrajectoryMode mode, const std::vector<Report>& reports, double durationS, double sampleRateHz,
                       int blockSize, double originMm = 0.0) {
  TrajectoryReconstructor rec(kRateHz, mode);
  Rendered out;
  const double durS = 1.0 / sampleRateHz;
  const int64_t total = static_cast<int64_t>(durationS * sampleRateHz);
  out.xMm.resize(total);
  out.vxMmPerS.resize(total);
  size_t next = 0;
  for (int64_t start = 0; start < total; start += blockSize) {
    const int n = static_cast<int>(std::min<int64_t>(blockSize, total - start));
    const double startS = start * durS;
    while (next < reports.size() && reports[next].timeS < startS + n * durS) {
      rec.addReport(reports[next].timeS, reports[next].dxMm, 0.0);
      ++next;
    }
    rec.render(startS, durS, n, originMm, out.xMm.data() + start, nullptr, out.vxMmPerS.data() + start, nullptr);
  }
  for (int64_t i = 0; i < total; ++i) out.timeS.push_back(i * durS);
  return out;
}

double rmsError(const Rendered& r, const Motion& x, double shiftS, double fromS) {
  double sum = 0.0;
  int n = 0;
  for (size_t i = 0; i < r.timeS.size(); ++i) {
    if (r.timeS[i] < fromS) continue;
    const double e = r.xMm[i] - x(r.timeS[i] - shiftS);
    sum += e * e;
    ++n;
  }
  return std::sqrt(sum / n);
}

// The time shift (s) of the true trajectory that best explains the output.
double lagS(const Rendered& r, const Motion& x, double fromS) {
  double best = 0.0, bestRms = 1e300;
  for (double shift = -0.006; shift <= 0.016; shift += 0.0002) {
    const double rms = rmsError(r, x, shift, fromS);
    if (rms < bestRms) bestRms = rms, best = shift;
  }
  return best;
}

double maxStep(const std::vector<float>& v) {
  double worst = 0.0;
  for (size_t i = 1; i < v.size(); ++i) worst = std::max(worst, std::fabs(double(v[i]) - v[i - 1]));
  return worst;
}

bool allFinite(const std::vector<float>& v) {
  for (float f : v)
    if (!std::isfinite(f)) return false;
  return true;
}

struct Score {
  double rmsMm, lagMs;
};
Score score(TrajectoryMode mode, const Motion& x, double durationS) {
  const auto reports = mouseReports(x, durationS);
  const auto r = renderReports(mode, reports, durationS, 8000.0, 64);
  return {rmsError(r, x, 0.0, 0.1), 1000.0 * lagS(r, x, 0.1)};
}

}  // namespace

TEST_CASE("TrajectoryReconstructor: error and lag against a known trajectory", "[trajectory]") {
  struct Case {
    const char* name;
    Motion x;
  };
  const Case cases[] = {
      {"steady 60 mm/s", [](double t) { return 60.0 * t; }},
      {"slow sine, peak 19 mm/s", [](double t) { return 6.0 * std::sin(2 * kPi * 0.5 * t); }},
      {"sine, peak 126 mm/s", [](double t) { return 20.0 * std::sin(2 * kPi * 1.0 * t); }},
      {"fast sine, peak 314 mm/s", [](double t) { return 25.0 * std::sin(2 * kPi * 2.0 * t); }},
  };
  for (const Case& c : cases) {
    const Score hold = score(TrajectoryMode::Hold, c.x, 3.0);
    const Score linear = score(TrajectoryMode::Linear, c.x, 3.0);
    const Score predictive = score(TrajectoryMode::Predictive, c.x, 3.0);
    INFO(c.name << ": rms mm / lag ms: hold " << hold.rmsMm << " / " << hold.lagMs << ", linear " << linear.rmsMm
                << " / " << linear.lagMs << ", predictive " << predictive.rmsMm << " / " << predictive.lagMs);
    // The paper's linear interpolation lags by about one update interval (8 ms).
    CHECK(linear.lagMs == Approx(8.0).margin(1.0));
    CHECK(hold.lagMs == Approx(4.0).margin(1.0));
    CHECK(std::fabs(predictive.lagMs) < linear.lagMs / 2);
    CHECK(predictive.rmsMm <= linear.rmsMm);
  }
}

TEST_CASE("TrajectoryReconstructor: ends exactly on the sum of the displacements", "[trajectory]") {
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> counts(-127, 127);
  for (TrajectoryMode mode : kModes) {
    for (int blockSize : {1, 64, 1024}) {
      TrajectoryReconstructor rec(kRateHz, mode);
      double sumX = 0.0, sumY = 0.0;
      const double durS = 1.0 / 48000.0, originMm = 1234.5;
      std::vector<float> x(blockSize), y(blockSize), vx(blockSize), vy(blockSize);
      int64_t sample = 0;
      for (int k = 1; k <= 300; ++k) {
        const int cx = k % 7 == 0 ? 0 : counts(rng), cy = counts(rng);
        rec.addReport(k * kIntervalS, cx * kCountMm, cy * kCountMm);
        sumX += cx * kCountMm;
        sumY += cy * kCountMm;
        for (; sample * durS < k * kIntervalS; sample += blockSize)
          rec.render(sample * durS, durS, blockSize, originMm, x.data(), y.data(), vx.data(), vy.data());
      }
      for (int i = 0; i < 10; ++i, sample += blockSize)  // let the last one play out
        rec.render(sample * durS + 4 * kIntervalS, durS, blockSize, originMm, x.data(), y.data(), vx.data(), vy.data());
      INFO("mode " << int(mode) << " block " << blockSize);
      CHECK(rec.reportedXMm() == sumX);
      CHECK(rec.renderedXMm() == sumX);
      CHECK(rec.renderedYMm() == sumY);
      CHECK(x[blockSize - 1] == static_cast<float>(sumX - originMm));
      CHECK(y[blockSize - 1] == static_cast<float>(sumY));
      CHECK(vx[blockSize - 1] == 0.0f);
      CHECK(rec.reportsTaken() == 300);
    }
  }
}

TEST_CASE("TrajectoryReconstructor: several reports in one block", "[trajectory]") {
  const Motion x = [](double t) { return 30.0 * std::sin(2 * kPi * 1.5 * t); };  // <= 283 mm/s
  const auto reports = mouseReports(x, 2.0);
  for (TrajectoryMode mode : kModes) {
    // 1024 samples at 48 kHz: 21 ms, 2-3 reports in each block.
    const auto r = renderReports(mode, reports, 2.2, 48000.0, 1024);
    INFO("mode " << int(mode));
    CHECK(allFinite(r.xMm));
    double sum = 0.0;
    for (const Report& rep : reports) sum += rep.dxMm;
    CHECK(r.xMm.back() == static_cast<float>(sum));
    // Same output as block size 1: reports are taken at their own times, not at block starts.
    const auto fine = renderReports(mode, reports, 2.2, 48000.0, 1);
    // (A report on a sample instant may be taken one sample apart: the sample times are
    // start + i * dur in one case and (start + i) * dur in the other, an ulp apart.)
    double worst = 0.0;
    for (size_t i = 1; i + 1 < r.xMm.size(); ++i) {
      const double oneSample =
          std::max(std::fabs(fine.xMm[i] - fine.xMm[i - 1]), std::fabs(fine.xMm[i + 1] - fine.xMm[i]));
      worst = std::max(worst, std::fabs(r.xMm[i] - fine.xMm[i]) - oneSample);
    }
    CHECK(worst < 1e-5);
    // Continuous: at most the top speed per sample (283 mm/s), twice that for predictive
    // while it catches up with a motion that started between two reports.
    const double topStepMm = 283.0 * 1.05 / 48000.0;
    if (mode == TrajectoryMode::Linear) CHECK(maxStep(r.xMm) < topStepMm);
    if (mode == TrajectoryMode::Predictive) CHECK(maxStep(r.xMm) < 2.0 * topStepMm);
  }
  // A burst: 10 reports with the same time (a backlog). Taken in order; linear stays
  // continuous and reaches the sum one interval later.
  TrajectoryReconstructor rec(kRateHz, TrajectoryMode::Linear);
  std::vector<float> out(4800);
  for (int k = 0; k < 10; ++k) rec.addReport(0.01, 0.5, 0.0);
  rec.render(0.0, 1.0 / 48000, 4800, 0.0, out.data(), nullptr, nullptr, nullptr);
  CHECK(out[479] == 0.0f);                                  // before 10 ms
  CHECK(maxStep(out) < 5.0 / (kIntervalS * 48000) * 1.01);  // 5 mm over one interval
  CHECK(out.back() == 5.0f);
  CHECK(rec.reportsTaken() == 10);
}

TEST_CASE("TrajectoryReconstructor: a 100 ms gap", "[trajectory]") {
  // 100 mm/s, then no reports for 100 ms (puck still), then 100 mm/s again.
  for (TrajectoryMode mode : kModes) {
    TrajectoryReconstructor rec(kRateHz, mode);
    std::vector<float> x, v;
    const double durS = 1.0 / 48000.0, dx = 0.8;  // 0.8 mm per 8 ms
    std::vector<float> bx(64), bv(64);
    double reportS = 0.0, sum = 0.0, reportedBeforeGap = 0.0;
    int64_t sample = 0;
    for (int k = 1; k <= 60; ++k) {
      reportS += (k == 31) ? 0.1 : kIntervalS;
      if (k == 31) reportedBeforeGap = sum;
      rec.addReport(reportS, dx, 0.0);
      sum += dx;
      for (; sample * durS < reportS; sample += 64) {
        rec.render(sample * durS, durS, 64, 0.0, bx.data(), nullptr, bv.data(), nullptr);
        x.insert(x.end(), bx.begin(), bx.end());
        v.insert(v.end(), bv.begin(), bv.end());
      }
    }
    INFO("mode " << int(mode));
    CHECK(allFinite(x));
    // In the gap: no runaway (at most 1.5 T of extrapolation), speed 0 after 3 T.
    const double gapStartS = 30 * kIntervalS;
    double worstBeyond = 0.0;
    for (size_t i = 0; i < x.size(); ++i) {
      const double t = i * durS;
      if (t <= gapStartS || t >= gapStartS + 0.099) continue;
      worstBeyond = std::max(worstBeyond, x[i] - reportedBeforeGap);
      if (t > gapStartS + 3.05 * kIntervalS) {
        CHECK(v[i] == 0.0f);
        CHECK(x[i] == static_cast<float>(reportedBeforeGap));
      }
    }
    CHECK(worstBeyond <= dx / kIntervalS * 1.5 * kIntervalS + 1e-4);
    if (mode != TrajectoryMode::Hold) CHECK(maxStep(x) < 1.0 / 48000 * 250.0);
  }
}

TEST_CASE("TrajectoryReconstructor: reversals stay bounded", "[trajectory]") {
  // Triangle: +-10 mm at 150 mm/s, sharp turns.
  const Motion x = [](double t) {
    const double period = 4 * 10.0 / 150.0, phase = std::fmod(t, period) / period;
    return phase < 0.5 ? -10.0 + 40.0 * phase : 30.0 - 40.0 * phase;
  };
  const auto reports = mouseReports(x, 2.0);
  for (TrajectoryMode mode : kModes) {
    const auto r = renderReports(mode, reports, 2.0, 48000.0, 64);
    double lo = 1e9, hi = -1e9;
    for (size_t i = 0; i < r.xMm.size(); ++i) lo = std::min<double>(lo, r.xMm[i]), hi = std::max<double>(hi, r.xMm[i]);
    INFO("mode " << int(mode) << " range " << lo << " .. " << hi);
    CHECK(allFinite(r.xMm));
    // Counts are taken relative to x(0) = -10 mm: the true range is [0, 20] mm.
    const double slack = mode == TrajectoryMode::Predictive ? 150.0 * 1.5 * kIntervalS : 0.0;
    CHECK(lo >= -slack - kCountMm);
    CHECK(hi <= 20.0 + slack + kCountMm);
  }
  const Score linear = score(TrajectoryMode::Linear, x, 2.0);
  const Score predictive = score(TrajectoryMode::Predictive, x, 2.0);
  INFO("rms mm: linear " << linear.rmsMm << ", predictive " << predictive.rmsMm);
  CHECK(predictive.rmsMm < linear.rmsMm);
}

TEST_CASE("TrajectoryReconstructor: zero-count reports, flags, bad values", "[trajectory]") {
  for (TrajectoryMode mode : kModes) {
    TrajectoryReconstructor rec(kRateHz, mode);
    rec.addReport(0.008, 1.0, -1.0);
    for (int k = 2; k <= 20; ++k) rec.addReport(k * kIntervalS, 0.0, 0.0, k == 5 ? 2u : 0u);
    rec.addReport(0.2, std::nan(""), INFINITY);
    std::vector<float> x(48000 / 4), y(x.size()), vx(x.size()), vy(x.size());
    rec.render(0.0, 1.0 / 48000, static_cast<int>(x.size()), 0.0, x.data(), y.data(), vx.data(), vy.data());
    INFO("mode " << int(mode));
    CHECK(allFinite(x));
    CHECK(allFinite(vx));
    // From the first zero report on (after its interval), speed is exactly 0 and x sits at 1.
    for (size_t i = static_cast<size_t>((2 * kIntervalS + kIntervalS) * 48000) + 1; i < x.size(); ++i) {
      REQUIRE(vx[i] == 0.0f);
      REQUIRE(x[i] == 1.0f);
      REQUIRE(y[i] == -1.0f);
    }
    CHECK(rec.reportsAfterLoss() == 1);
  }
}

TEST_CASE("TrajectoryReconstructor: switching mode never jumps", "[trajectory]") {
  const Motion x = [](double t) { return 20.0 * std::sin(2 * kPi * 1.0 * t); };
  const auto reports = mouseReports(x, 1.0);
  TrajectoryReconstructor rec(kRateHz, TrajectoryMode::Predictive);
  std::vector<float> out, block(64);
  size_t next = 0;
  const double durS = 1.0 / 48000.0;
  for (int64_t start = 0; start < 48000; start += 64) {
    if (start % 4800 == 0) rec.setMode(static_cast<TrajectoryMode>((start / 4800) % 2 + 1));
    while (next < reports.size() && reports[next].timeS < (start + 64) * durS)
      rec.addReport(reports[next].timeS, reports[next].dxMm, 0.0), ++next;
    rec.render(start * durS, durS, 64, 0.0, block.data(), nullptr, nullptr, nullptr);
    out.insert(out.end(), block.begin(), block.end());
  }
  CHECK(maxStep(out) < 130.0 * 2.0 / 48000);
}

TEST_CASE("TrajectoryReconstructor: 100 ppm drift through DeviceClockMapper, 10 minutes", "[trajectory][long]") {
  // The device clock runs 100 ppm fast against audio; reports reach the audio side at the
  // next 64-sample block after 3 ms + 0..0.4 ms. Mapped times feed the reconstructor.
  const Motion x = [](double t) {
    return 40.0 * std::sin(2 * kPi * 0.37 * t) + 15.0 * std::sin(2 * kPi * 1.3 * t);
  };  // up to ~215 mm/s
  const double sampleRateHz = 48000.0, durS = 1.0 / sampleRateHz;
  const int block = 64;
  const double totalS = 600.0;
  auto audioOfDevice = [](double deviceS) { return deviceS * (1.0 - 100e-6) + 7.0; };
  for (TrajectoryMode mode : {TrajectoryMode::Linear, TrajectoryMode::Predictive}) {
    kf::DeviceClockMapper mapper;
    TrajectoryReconstructor rec(kRateHz, mode);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> queueS(0.0, 0.0004);
    std::vector<float> out(block), vel(block);
    double lastCounts = std::floor(x(0.0) / kCountMm);
    int k = 1;
    double nextArrivalS = 0.0, nextDeviceS = kIntervalS;
    auto scheduleNext = [&]() {
      nextDeviceS = k * kIntervalS;
      nextArrivalS = std::ceil((audioOfDevice(nextDeviceS) + 0.003 + queueS(rng)) / (block * durS)) * (block * durS);
    };
    scheduleNext();
    double worstErrorMm = 0.0, worstStepMm = 0.0, lastX = 0.0, worstSpeed = 0.0;
    double driftSum = 0.0;
    int driftCount = 0;
    bool finite = true;
    const int64_t totalSamples = static_cast<int64_t>((totalS + 7.0) * sampleRateHz);
    for (int64_t start = static_cast<int64_t>(7.0 * sampleRateHz); start < totalSamples; start += block) {
      const double blockS = start * durS;
      while (nextArrivalS <= blockS) {  // every report that has arrived by this block
        const double counts = std::floor(x(nextDeviceS) / kCountMm);
        const double dx = (counts - lastCounts) * kCountMm;
        lastCounts = counts;
        rec.addReport(mapper.map(nextDeviceS, nextArrivalS), dx, 0.0);
        ++k;
        scheduleNext();
      }
      rec.render(blockS, durS, block, 0.0, out.data(), nullptr, vel.data(), nullptr);
      for (int i = 0; i < block; ++i) {
        finite = finite && std::isfinite(out[i]) && std::isfinite(vel[i]);
        worstStepMm = std::max(worstStepMm, std::fabs(out[i] - lastX));
        worstSpeed = std::max(worstSpeed, static_cast<double>(std::fabs(vel[i])));
        lastX = out[i];
      }
      if (start % (block * 16) == 0 && blockS > 8.0) {
        // Against the true position one mapping latency (3..4.7 ms) earlier, relative to x(0).
        const double deviceS = (blockS - 7.0) / (1.0 - 100e-6) - 0.0037;
        const double trueMm = x(deviceS) - kCountMm * std::floor(x(0.0) / kCountMm);
        worstErrorMm = std::max(worstErrorMm, std::fabs(out[0] - trueMm));
      }
      if (start % 48000 == 0 && blockS > 30.0) driftSum += mapper.driftPpm(), ++driftCount;
    }
    INFO("mode " << int(mode) << ": worst error " << worstErrorMm << " mm, worst step " << worstStepMm << " mm, reset "
                 << mapper.resetCount() << ", mean drift " << driftSum / driftCount << " ppm");
    CHECK(finite);
    CHECK(mapper.resetCount() == 0);
    CHECK(driftSum / driftCount == Approx(-100.0).margin(10.0));  // the loop's drift, averaged
    CHECK(worstSpeed <= 127 * kCountMm / kIntervalS + 1e-3);
    // One interval of lag at ~215 mm/s is 1.7 mm; drift must not make it grow.
    CHECK(worstErrorMm < (mode == TrajectoryMode::Linear ? 2.5 : 1.0));
    CHECK(worstStepMm < 0.02);
  }
}

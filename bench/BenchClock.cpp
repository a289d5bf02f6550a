// KFBenchClock: a bench-only UGen that outputs, per block, how long this unit has existed in
// wall time (steady_clock) and in CPU time of the thread that runs the graph. Run at the head of
// the graph in an NRT render, the block-to-block differences are the time scsynth spent on each
// block, so the cost of a phase of a Score can be read off the rendered file.
// Outputs (all constant over a block): wall whole seconds, wall fraction of a second, thread CPU
// whole seconds, thread CPU fraction. Split so that float outputs keep ~60 ns resolution.
#include <SC_PlugIn.hpp>

#include <chrono>
#include <cmath>
#include <ctime>

InterfaceTable* ft;

namespace {

double threadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

class KFBenchClock : public SCUnit {
 public:
  KFBenchClock() : mWallStart(std::chrono::steady_clock::now()), mCpuStart(threadCpuSeconds()) {
    set_calc_function<KFBenchClock, &KFBenchClock::next>();
    next(1);
  }

 private:
  void next(int numSamples) {
    const double wallS = std::chrono::duration<double>(std::chrono::steady_clock::now() - mWallStart).count();
    const double cpuS = threadCpuSeconds() - mCpuStart;
    write(0, wallS, numSamples);
    write(2, cpuS, numSamples);
  }

  void write(int firstOut, double seconds, int numSamples) {
    const double whole = std::floor(seconds);
    const float w = static_cast<float>(whole), f = static_cast<float>(seconds - whole);
    float* a = out(firstOut);
    float* b = out(firstOut + 1);
    for (int i = 0; i < numSamples; ++i) {
      a[i] = w;
      b[i] = f;
    }
  }

  std::chrono::steady_clock::time_point mWallStart;
  double mCpuStart;
};

}  // namespace

PluginLoad(KFBenchClock) {
  ft = inTable;
  registerUnit<KFBenchClock>(ft, "KFBenchClock");
}

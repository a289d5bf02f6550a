// ExitSafety on Windows: the C runtime's signals are the ways out a handler sees there — Ctrl-C
// and Ctrl-Break in a console (SIGINT, SIGBREAK), abort (SIGABRT, an exception escaping a
// thread) and the crashes the runtime maps to signals (SIGSEGV, SIGFPE, SIGILL). Each handler
// drives every device's magnet off (kf::sc::haltAllDevices) and hands the signal on: to the
// handler installed before ours if there was one, else with the default action restored and the
// signal raised again. SIGTERM is never raised by Windows itself: a process ended from outside
// (TerminateProcess, the task manager) runs no code of ours, so a real magnet's own watchdog
// must act, as for SIGKILL on Linux. Untested on Windows: under Wine only built.
#include <atomic>
#include <csignal>

#include "DeviceSlots.hpp"
#include "ExitSafety.hpp"

namespace {

constexpr int kSignals[] = {SIGINT, SIGBREAK, SIGTERM, SIGABRT, SIGSEGV, SIGFPE, SIGILL};
constexpr int kMaxSignal = 32;
using Handler = void (*)(int);
Handler gPrevious[kMaxSignal];
std::atomic<bool> gInstalled[kMaxSignal];
std::atomic<bool> gDrivenOff{false};

void onExitSignal(int signalNumber) {
  if (!gDrivenOff.exchange(true)) kf::sc::haltAllDevices();
  const Handler previous = gPrevious[signalNumber];
  if (previous != SIG_DFL && previous != SIG_IGN && previous != SIG_ERR && previous != nullptr) {
    gDrivenOff.store(false);
    return previous(signalNumber);
  }
  std::signal(signalNumber, SIG_DFL);
  std::raise(signalNumber);
}

}  // namespace

void installExitSafety() {
  for (const int signalNumber : kSignals) {
    if (gInstalled[signalNumber].load()) continue;
    const Handler previous = std::signal(signalNumber, onExitSignal);
    if (previous == SIG_ERR) continue;
    if (previous == SIG_IGN) {  // ignored when the plugin loads: stays ignored
      std::signal(signalNumber, SIG_IGN);
      continue;
    }
    gPrevious[signalNumber] = previous;
    gInstalled[signalNumber].store(true);
  }
}

// ExitSafety: the magnet goes off however scsynth leaves. /quit runs the static destructors
// (DeviceSlots' exit hook closes every device); a signal does not, so at plugin load this
// installs handlers for every signal whose default action ends the process — SIGTERM, SIGINT,
// SIGHUP, SIGQUIT, SIGUSR1, SIGUSR2, SIGPIPE, SIGALRM, SIGVTALRM, SIGPROF, SIGXCPU, SIGPWR,
// SIGSTKFLT, and the crashes SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT (an exception escaping a
// thread aborts), SIGSYS, SIGTRAP. SIGXFSZ (a write past the file size limit) is ignored
// instead: the write fails with EFBIG, the recording that made it stops with its message, and
// the server and the magnet go on. Each handler drives the force backend of every open device,
// and of every device whose close has not finished, off, and every audio drive to 0
// (haltAllDrives), with async-signal-safe work only (atomic slot loads, stores, write(2) of an
// off record to a recording), then hands the signal on: to the handler
// installed before ours if there was one, else the original disposition is restored and the
// signal raised again, so the exit status is the signal's. A signal ignored when the plugin
// loads (nohup's SIGHUP) stays ignored. SIGKILL cannot be caught: the device thread dies with
// the process and a real magnet's own watchdog must act. POSIX (SIGPWR and SIGSTKFLT where the
// system has them: Linux); Windows has ExitSafetyWindows.cpp.
#include "ExitSafety.hpp"

#include <signal.h>

#include <atomic>

#include "DeviceSlots.hpp"
#include "SlotDrive.hpp"

namespace {

constexpr int kSignals[] = {
    SIGTERM,   SIGINT, SIGHUP, SIGQUIT, SIGUSR1, SIGUSR2, SIGPIPE, SIGALRM, SIGVTALRM, SIGPROF, SIGXCPU,
#ifdef SIGPWR
    SIGPWR,
#endif
    SIGSEGV,   SIGBUS, SIGFPE, SIGILL,  SIGABRT, SIGSYS,  SIGTRAP,
#ifdef SIGSTKFLT
    SIGSTKFLT,
#endif
};

struct sigaction gPrevious[NSIG];
std::atomic<bool> gInstalled[NSIG];
std::atomic<bool> gDrivenOff{false};

void onExitSignal(int signalNumber, siginfo_t* info, void* context) {
  // Once: a second signal (or a crash inside the first handler) goes straight on.
  if (!gDrivenOff.exchange(true)) {
    kf::sc::haltAllDevices();
    kf::sc::haltAllDrives();
  }
  const struct sigaction& previous = gPrevious[signalNumber];
  if (previous.sa_flags & SA_SIGINFO) {
    if (previous.sa_sigaction != nullptr) return previous.sa_sigaction(signalNumber, info, context);
  } else if (previous.sa_handler != SIG_DFL && previous.sa_handler != SIG_IGN) {
    // The host's own handler (it may shut down gracefully). Our devices stay halted, magnet
    // off, should the process live on: they must be opened again.
    gDrivenOff.store(false);
    return previous.sa_handler(signalNumber);
  }
  ::sigaction(signalNumber, &previous, nullptr);
  ::raise(signalNumber);  // delivered when this handler returns (the signal is blocked in it)
}

}  // namespace

void installExitSafety() {
  // A file size limit (RLIMIT_FSIZE) must not kill the server with the magnet on: ignored, the
  // write that passes it fails with EFBIG, which the recorder reports. Unless the host handles it.
  struct sigaction fileSize {};
  if (::sigaction(SIGXFSZ, nullptr, &fileSize) == 0 && !(fileSize.sa_flags & SA_SIGINFO) &&
      fileSize.sa_handler == SIG_DFL)
    ::signal(SIGXFSZ, SIG_IGN);
  for (const int signalNumber : kSignals) {
    if (gInstalled[signalNumber].load()) continue;
    struct sigaction previous {};
    if (::sigaction(signalNumber, nullptr, &previous) != 0) continue;
    if (!(previous.sa_flags & SA_SIGINFO) && previous.sa_handler == SIG_IGN) continue;
    gPrevious[signalNumber] = previous;
    struct sigaction action {};
    action.sa_sigaction = onExitSignal;
    action.sa_flags = SA_SIGINFO | SA_RESTART | SA_ONSTACK;
    sigemptyset(&action.sa_mask);
    for (const int other : kSignals) sigaddset(&action.sa_mask, other);  // no handler inside another
    if (::sigaction(signalNumber, &action, nullptr) == 0) gInstalled[signalNumber].store(true);
  }
}

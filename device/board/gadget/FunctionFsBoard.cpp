#include "board/gadget/FunctionFsBoard.hpp"

#include <fcntl.h>
#include <linux/usb/functionfs.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/timerfd.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>

#include "board/gadget/FunctionFsDescriptors.hpp"

namespace kf::board::gadget {

namespace {

constexpr int64_t kTickNs = 1000000;  // the board's 1 ms tick
constexpr uint8_t kDirIn = 0x80;

bool writeAll(int fd, const std::vector<uint8_t>& data) {
  return ::write(fd, data.data(), data.size()) == static_cast<ssize_t>(data.size());
}

}  // namespace

int64_t FunctionFsBoard::nowNs() { return monotonicNs(); }

FunctionFsBoard::FunctionFsBoard(std::string functionFsDir, BoardFirmware& firmware, GadgetLog& log)
    : dir_(std::move(functionFsDir)), firmware_(firmware), log_(log) {}

FunctionFsBoard::~FunctionFsBoard() {
  if (aio_ != nullptr) io_destroy(aio_);  // cancels and waits for what is still queued
  for (int fd : {stepTimer_, timer_, events_, in_, out_, ep0_})
    if (fd >= 0) ::close(fd);
}

bool FunctionFsBoard::open(std::string& error) {
  const auto fail = [&error](const std::string& what) {
    error = what + ": " + std::strerror(errno);
    return false;
  };
  ep0_ = ::open((dir_ + "/ep0").c_str(), O_RDWR | O_CLOEXEC);
  if (ep0_ < 0) return fail("cannot open " + dir_ + "/ep0 (is FunctionFS mounted there?)");
  if (!writeAll(ep0_, functionFsDescriptors())) return fail("FunctionFS refused the descriptors");
  if (!writeAll(ep0_, functionFsStrings())) return fail("FunctionFS refused the strings");
  // Non-blocking: AIO on an endpoint that is not enabled answers EAGAIN instead of waiting for it.
  out_ = ::open((dir_ + "/" + kOutEndpointFile).c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (out_ < 0) return fail("cannot open the set-point endpoint");
  in_ = ::open((dir_ + "/" + kInEndpointFile).c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (in_ < 0) return fail("cannot open the status endpoint");
  const int setup = io_setup(kQueuedReads + 2, &aio_);
  if (setup < 0) {
    errno = -setup;
    return fail("io_setup");
  }
  events_ = ::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC);
  if (events_ < 0) return fail("eventfd");
  timer_ = ::timerfd_create(CLOCK_MONOTONIC, TFD_NONBLOCK | TFD_CLOEXEC);
  if (timer_ < 0) return fail("timerfd_create");
  nextTickNs_ = (nowNs() / kTickNs + 1) * kTickNs;
  itimerspec period{};
  period.it_interval.tv_nsec = kTickNs;
  period.it_value.tv_sec = nextTickNs_ / 1000000000;
  period.it_value.tv_nsec = nextTickNs_ % 1000000000;
  if (::timerfd_settime(timer_, TFD_TIMER_ABSTIME, &period, nullptr) != 0) return fail("timerfd_settime");
  stepTimer_ = ::timerfd_create(CLOCK_MONOTONIC, TFD_NONBLOCK | TFD_CLOEXEC);
  if (stepTimer_ < 0) return fail("timerfd_create");
  return true;
}

void FunctionFsBoard::run(const std::vector<int>& extraFds, const std::function<bool(int fd)>& onReadable) {
  std::vector<pollfd> fds{{ep0_, POLLIN, 0}, {events_, POLLIN, 0}, {timer_, POLLIN, 0}, {stepTimer_, POLLIN, 0}};
  constexpr size_t kFirstExtra = 4;
  for (int fd : extraFds) fds.push_back({fd, POLLIN, 0});
  for (;;) {
    if (::poll(fds.data(), fds.size(), -1) < 0) {
      if (errno == EINTR) continue;
      std::perror("kf_board_gadget: poll");
      return;
    }
    // The tick first: the watchdog's moment is not held up by a burst of frames.
    if (fds[2].revents & POLLIN) onTick();
    if (fds[3].revents & POLLIN) onStep();
    if (fds[1].revents & POLLIN) onCompletions();
    if (fds[0].revents & POLLIN) onEp0();
    for (size_t i = kFirstExtra; i < fds.size(); ++i)
      if ((fds[i].revents & (POLLIN | POLLHUP)) && !onReadable(fds[i].fd)) return;
  }
}

// --- ep0: events and control requests --------------------------------------------------------

void FunctionFsBoard::onEp0() {
  usb_functionfs_event event{};
  if (::read(ep0_, &event, sizeof event) != static_cast<ssize_t>(sizeof event)) return;
  const int64_t now = nowNs();
  switch (event.type) {
    case FUNCTIONFS_BIND:  // plugged in: a fresh board, disarmed, USB_RESET set
      log_.event(now, "bind");
      firmware_.powerOn(seconds(now));
      break;
    case FUNCTIONFS_UNBIND:  // unplugged
      log_.event(now, "unbind");
      enabled_ = false;
      firmware_.powerLoss(seconds(now));
      break;
    case FUNCTIONFS_ENABLE:  // configured: the endpoints carry transfers
      log_.event(now, "enable");
      enabled_ = true;
      queueReads();
      break;
    case FUNCTIONFS_DISABLE:  // bus reset, configuration 0, disconnect: off and disarmed
      log_.event(now, "disable");
      enabled_ = false;
      firmware_.usbReset(seconds(now), "disable");
      break;
    case FUNCTIONFS_SUSPEND:
      log_.event(now, "suspend");
      firmware_.usbReset(seconds(now), "suspend");
      break;
    case FUNCTIONFS_RESUME:
      log_.event(now, "resume");  // stays disarmed until ARM
      break;
    case FUNCTIONFS_SETUP:
      onSetup(event.u.setup.bRequestType, event.u.setup.bRequest, le16toh(event.u.setup.wValue),
              le16toh(event.u.setup.wLength));
      break;
    default:
      break;
  }
}

void FunctionFsBoard::onSetup(uint8_t requestType, uint8_t request, uint16_t value, uint16_t length) {
  const bool in = (requestType & kDirIn) != 0;
  const int64_t now = nowNs();
  uint8_t data[64] = {};
  // No request of the protocol carries data from the host: one that does is refused unread.
  ControlReply reply;
  if (in || length == 0)
    reply = firmware_.control(requestType, request, value, data, std::min<uint16_t>(length, sizeof data), seconds(now));
  log_.control(now, request, value, reply.stall);
  // FunctionFS: the data stage in the request's direction answers it (a read of 0 bytes acks an
  // OUT request); I/O in the other direction STALLs it.
  if (reply.stall) {
    if (in)
      (void)::read(ep0_, data, 0);
    else
      (void)::write(ep0_, data, 0);
  } else if (in) {
    (void)::write(ep0_, data, std::min(reply.length, length));
  } else {
    (void)::read(ep0_, data, 0);
  }
}

// --- set-points and status through AIO ---------------------------------------------------------

void FunctionFsBoard::queueReads() {
  if (!enabled_ || !reading_) return;
  for (Read& read : reads_) {
    if (read.queued) continue;
    // One packet: a set-point, or a multi set-point frame of up to 8 levels (a short packet ends it).
    io_prep_pread(&read.cb, out_, read.buffer, kMaxSetPointFrameSize, 0);
    io_set_eventfd(&read.cb, events_);
    iocb* one = &read.cb;
    const int result = io_submit(aio_, 1, &one);
    if (result == 1) {
      read.queued = true;
    } else {
      if (result != -EAGAIN && result != -ESHUTDOWN)  // disabled meanwhile; ENABLE queues them again
        std::fprintf(stderr, "kf_board_gadget: cannot queue a set-point read: %s\n", std::strerror(-result));
      return;
    }
  }
}

void FunctionFsBoard::submitStatus() {
  const int64_t now = nowNs();
  status_.status = firmware_.status(seconds(now));
  encodeStatus(status_.status, status_.frame);
  status_.builtNs = now;
  io_prep_pwrite(&status_.cb, in_, status_.frame, kStatusSize, 0);
  io_set_eventfd(&status_.cb, events_);
  iocb* one = &status_.cb;
  const int result = io_submit(aio_, 1, &one);
  if (result == 1)
    status_.queued = true;
  else if (result != -EAGAIN)
    std::fprintf(stderr, "kf_board_gadget: cannot queue a status frame: %s\n", std::strerror(-result));
}

void FunctionFsBoard::cancel(iocb& cb) {
  io_event event{};
  // Its completion (cancelled, or done before the cancel reached it) comes as an event.
  const int result = io_cancel(aio_, &cb, &event);
  if (result != 0 && result != -EINPROGRESS && result != -EAGAIN && result != -EINVAL)
    std::fprintf(stderr, "kf_board_gadget: io_cancel: %s\n", std::strerror(-result));
}

void FunctionFsBoard::onCompletions() {
  uint64_t count = 0;
  (void)::read(events_, &count, sizeof count);
  io_event events[kQueuedReads + 2];
  timespec none{0, 0};
  int got = 0;
  while ((got = io_getevents(aio_, 0, kQueuedReads + 2, events, &none)) > 0) {
    for (int i = 0; i < got; ++i) {
      const long result = static_cast<long>(events[i].res);
      if (events[i].obj == &status_.cb) {
        onStatus(result);
        continue;
      }
      for (Read& read : reads_)
        if (events[i].obj == &read.cb) onRead(read, result);
    }
  }
}

void FunctionFsBoard::onRead(Read& read, long result) {
  read.queued = false;
  if (result >= 0) {
    const int64_t now = nowNs();
    const uint64_t validBefore = firmware_.validFrames();
    firmware_.receiveSetPoint(read.buffer, static_cast<size_t>(result), seconds(now));
    armStepTimer();
    MultiSetPoint frame;
    const bool decoded = decodeAnySetPoint(read.buffer, static_cast<size_t>(result), frame);
    const GadgetLog::Verdict verdict = firmware_.validFrames() > validBefore ? GadgetLog::Verdict::kApplied
                                       : decoded                             ? GadgetLog::Verdict::kStale
                                                                             : GadgetLog::Verdict::kBad;
    log_.frame(now, static_cast<int>(result), frame.sequence, frame.drives[0], verdict, firmware_.validFrames());
    if (decoded && read.buffer[0] == kMultiSetPointType)
      for (int i = 0; i < frame.count; ++i) log_.level(now, i, frame.drives[i]);
    queueReads();  // not while reading is off or the endpoint disabled
  }
  // A read that failed (cancelled, the endpoint going away, halted) is queued again by the next
  // tick, not here: while the gadget is unbound a new read can fail at once, and queueing it
  // again from its own completion spun this realtime thread in onCompletions, so that it never
  // read ep0's UNBIND and starved the guest's one CPU (seen: the unplug case hung the run).
}

void FunctionFsBoard::onStatus(long result) {
  status_.queued = false;
  const bool replaced = status_.cancelling;
  status_.cancelling = false;
  if (result == static_cast<long>(kStatusSize)) {
    log_.statusTaken(nowNs(), status_.builtNs, status_.status.lastSequence, status_.status.framesReceived);
  } else if (replaced && enabled_) {
    log_.statusReplaced(nowNs() - status_.cancelledNs);
    submitStatus();  // not taken within its tick: a fresh one in its place
  }
}

void FunctionFsBoard::onTick() {
  uint64_t expirations = 0;
  if (::read(timer_, &expirations, sizeof expirations) != sizeof expirations || expirations == 0) return;
  const int64_t now = nowNs();
  // Late from the first tick this read covers: a watchdog due just after it waited until now.
  const int64_t dueNs = nextTickNs_;
  nextTickNs_ += static_cast<int64_t>(expirations) * kTickNs;
  firmware_.advance(seconds(now));
  // Late: when the tick's work is done (the coil's pin set, in advance), not when it woke, since
  // that is when its effects show; the thread can be preempted in between.
  log_.tick(nowNs() - dueNs, expirations - 1);
  if (!enabled_) return;
  queueReads();  // those that failed since the last tick
  if (!status_.queued) {
    submitStatus();  // the tick after the previous frame was taken
  } else if (!status_.cancelling && now - status_.builtNs >= kTickNs) {
    status_.cancelling = true;  // not taken by this tick: replaced once its cancel is back
    status_.cancelledNs = now;
    cancel(status_.cb);
  }
}

void FunctionFsBoard::armStepTimer() {
  const double dueS = firmware_.nextStepS();
  itimerspec when{};  // zero: disarmed
  if (dueS >= 0.0) {
    const auto dueNs = std::max<int64_t>(static_cast<int64_t>(dueS * 1e9), 1);
    when.it_value.tv_sec = dueNs / 1000000000;
    when.it_value.tv_nsec = dueNs % 1000000000;
  }
  (void)::timerfd_settime(stepTimer_, TFD_TIMER_ABSTIME, &when, nullptr);
}

void FunctionFsBoard::onStep() {
  uint64_t expirations = 0;
  if (::read(stepTimer_, &expirations, sizeof expirations) != sizeof expirations) return;
  firmware_.advance(seconds(nowNs()));  // every level due by now, each at its own time in the log
  armStepTimer();
}

// --- test hooks ----------------------------------------------------------------------------------

void FunctionFsBoard::setReading(bool reading) {
  reading_ = reading;
  if (reading) {
    queueReads();
    return;
  }
  for (Read& read : reads_)
    if (read.queued) cancel(read.cb);
}

bool FunctionFsBoard::halt(bool out, std::string& error) {
  if (!enabled_) {
    error = "the endpoints are not enabled";
    return false;
  }
  uint8_t none[1] = {};
  // FunctionFS halts an endpoint on I/O in the wrong direction, and says so with EBADMSG. A
  // device controller halts an IN endpoint only with nothing queued on it (EAGAIN otherwise):
  // the status frame is taken back first (its completion reaped here; the tick queues the next
  // one, which waits behind the halt until the host clears it). dummy_hcd was seen to answer
  // EAGAIN with no frame of ours queued, ten times in a row at once (1 run in 6): so between
  // tries the completions of up to 1 ms are reaped, 50 times at most (a hook, not the firmware:
  // its halt only has to happen).
  const auto reap = [&](long timeoutNs) {
    io_event event{};
    timespec limit{0, timeoutNs};
    while (io_getevents(aio_, 1, 1, &event, &limit) == 1) {
      if (event.obj == &status_.cb) {
        status_.queued = status_.cancelling = false;
        if (!out) return;
        continue;
      }
      for (Read& read : reads_)
        if (event.obj == &read.cb) onRead(read, static_cast<long>(event.res));
      if (!out && !status_.queued) return;
    }
  };
  int lastErrno = 0;
  for (int attempt = 0; attempt < 50; ++attempt) {
    if (!out && status_.queued) {
      if (!status_.cancelling) cancel(status_.cb);
      status_.cancelling = true;
      reap(100000000);
    }
    const ssize_t result = out ? ::write(out_, none, 0) : ::read(in_, none, 0);
    if (result < 0 && errno == EBADMSG) return true;
    lastErrno = result < 0 ? errno : 0;
    if (lastErrno != EAGAIN) break;
    std::fprintf(stderr, "kf_board_gadget: halt %s: EAGAIN (status queued %d cancelling %d)\n", out ? "out" : "in",
                 status_.queued, status_.cancelling);
    reap(1000000);
  }
  error = std::string("the endpoint did not halt: ") + (lastErrno ? std::strerror(lastErrno) : "no error, no halt");
  return false;
}

}  // namespace kf::board::gadget

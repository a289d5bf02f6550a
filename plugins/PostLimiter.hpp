// PostLimiter: at most one message per cause per interval of audio time, so a storm (300
// buffer reallocations in a second, a flood of bad commands) posts a few lines, not hundreds.
// The next message let through says how many were held back. One limiter per cause, used
// from one thread (the audio thread); no allocation.
#pragma once

namespace kf::sc {

class PostLimiter {
 public:
  explicit PostLimiter(double intervalS = 1.0) : intervalS_(intervalS) {}

  // True when a message may be posted at audio time nowS; `suppressed` then holds how many
  // were held back since the last one.
  bool allow(double nowS, int& suppressed) {
    if (posted_ && nowS >= lastS_ && nowS - lastS_ < intervalS_) {
      ++suppressed_;
      return false;
    }
    posted_ = true;
    lastS_ = nowS;
    suppressed = suppressed_;
    suppressed_ = 0;
    return true;
  }

 private:
  double intervalS_;
  double lastS_ = 0.0;
  bool posted_ = false;
  int suppressed_ = 0;
};

}  // namespace kf::sc

// PostLimiter: at most one message per cause per interval of audio time, so a storm (300
// buffer reallocations in a second, a flood of bad commands) posts a few lines, not hundreds.
// The next message let through says how many were held back. One limiter per cause, used
// from one thread (the audio thread); no allocation.
#pragma once

namespace kf::sc {

class PostLimiter {
 public:
  explicit PostLimiter(float intervalS = 1.0f) : intervalS_(intervalS) {}

  // True when a message may be posted at audio time nowS; `suppressed` then holds how many
  // were held back since the last one.
  bool allow(double nowS, int& suppressed) {
    const float now = static_cast<float>(nowS);
    if (posted_ && now >= lastS_ && now - lastS_ < intervalS_) {
      ++suppressed_;
      return false;
    }
    posted_ = true;
    lastS_ = now;
    suppressed = suppressed_;
    suppressed_ = 0;
    return true;
  }

 private:
  // float, not double: it lives in units, which scsynth may place only 4-byte aligned; a
  // second's resolution survives days of audio time in float.
  float intervalS_;
  float lastS_ = 0.f;
  bool posted_ = false;
  int suppressed_ = 0;
};

}  // namespace kf::sc

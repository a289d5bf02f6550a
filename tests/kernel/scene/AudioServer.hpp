// AudioServer: scsynth with our plugin in the guest, as a user runs it on a machine with the
// board and the mouse: jackd on its dummy driver (no sound card in the guest; a large period,
// since the guest's one emulated CPU is slow), scsynth on it listening on every interface so that
// sclang on the host reaches it through QEMU's user network. Both are children of the test,
// their output in the results folder (scene-jackd.log, scene-scsynth.log); they are ended, and
// waited for, with the object.
#pragma once

#include <sys/types.h>

#include <string>

namespace kf::guest {

// The guest's network as QEMU's user network expects it (10.0.2.15, the host at 10.0.2.2).
void networkUp();

class AudioServer {
 public:
  static constexpr int kPeriodFrames = 1024;  // 21 ms at 48 kHz: function, not timing, is tested
  explicit AudioServer(int udpPort);          // throws with their output if they do not start
  ~AudioServer();
  // The last "kfStatus <slot>: realtime, ..." line scsynth posted (the device's counts), or "".
  std::string statusLine() const;
  AudioServer(const AudioServer&) = delete;
  AudioServer& operator=(const AudioServer&) = delete;

 private:
  pid_t jackd_ = -1;
  pid_t scsynth_ = -1;
  std::string scsynthLog_;
};

}  // namespace kf::guest

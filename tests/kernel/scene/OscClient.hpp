// OscClient: the few OSC messages the scene test sends scsynth in the guest itself (UDP on the
// loopback): what its control buses hold now (/c_getn, answered /c_setn).
#pragma once

#include <string>
#include <vector>

namespace kf::guest {

class OscClient {
 public:
  explicit OscClient(int port);
  ~OscClient();
  OscClient(const OscClient&) = delete;
  OscClient& operator=(const OscClient&) = delete;

  // Control buses first .. first + count - 1; throws if scsynth does not answer within 5 s.
  std::vector<float> controlBuses(int first, int count);

 private:
  int fd_ = -1;
};

}  // namespace kf::guest

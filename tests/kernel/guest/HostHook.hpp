// HostHook: a test program's line to the host while it runs in the kernel rig's guest
// (python/kfharness/guest.py): the guest's second serial port, /dev/ttyS1, is a socket on the
// host, which passes a QMP command to QEMU (input-send-event, device_del, device_add ...) or
// calls one of the run's host-side hooks and sends the answer back. One line each way.
#pragma once

#include <string>

namespace kf::guest {

class HostHook {
 public:
  // The one hook of this process (opened on first use; throws if /dev/ttyS1 cannot be opened).
  static HostHook& instance();

  // Sends a QMP command (a JSON object on one line) and returns QEMU's answer (JSON text:
  // {"return": ...} or {"error": ...}).
  std::string qmp(const std::string& json);
  // The same, throwing with QEMU's words when the answer is an error.
  void qmpOrThrow(const std::string& json);
  // A host-side hook of the run (GuestSpec.hooks): its one line of answer.
  std::string host(const std::string& name, const std::string& argument);

 private:
  HostHook();
  std::string ask(const std::string& word, const std::string& text);
  int fd_ = -1;
};

}  // namespace kf::guest

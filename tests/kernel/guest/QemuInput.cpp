#include "QemuInput.hpp"

#include "HostHook.hpp"

namespace kf::guest {

void qemuMove(int dx, int dy) {
  HostHook::instance().qmpOrThrow(
      R"({"execute": "input-send-event", "arguments": {"events": [{"type": "rel", "data": {"axis": "x", "value": )" +
      std::to_string(dx) + R"(}}, {"type": "rel", "data": {"axis": "y", "value": )" + std::to_string(dy) + "}}]}}");
}

void qemuButton(const std::string& button, bool down) {
  HostHook::instance().qmpOrThrow(
      R"({"execute": "input-send-event", "arguments": {"events": [{"type": "btn", "data": {"down": )" +
      std::string(down ? "true" : "false") + R"(, "button": ")" + button + "\"}}]}}");
}

}  // namespace kf::guest

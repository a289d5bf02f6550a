// The EvdevApi off Linux (macOS, Windows): evdev is the Linux kernel's, so there is no mouse to
// list and opening one says to use hidapi.
#include "mouse/MouseIo.hpp"

namespace kf {

namespace {
class NoEvdevApi : public EvdevApi {
 public:
  bool enumerateMice(std::vector<MouseInfo>& out, std::string&) override {
    out.clear();
    return true;
  }
  std::unique_ptr<EvdevHandle> open(const std::string&, std::string& error, OpenFailure& why) override {
    error = "evdev is Linux only; use the hidapi backend";
    why = OpenFailure::kOther;
    return nullptr;
  }
};
}  // namespace

std::shared_ptr<EvdevApi> realEvdevApi() {
  static std::shared_ptr<EvdevApi> api = std::make_shared<NoEvdevApi>();
  return api;
}

std::shared_ptr<EvdevApi> evdevApiReadingSysfsAt(const std::string&) { return realEvdevApi(); }

}  // namespace kf

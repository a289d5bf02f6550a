// realHidApi in a build without hardware backends (KF_WITH_HARDWARE=OFF: Debian ships no MinGW
// hidapi, so the Windows build checked here has none): listing and opening a mouse fail with
// the reason; the simulated and replay devices need no hidapi.
#include "mouse/MouseIo.hpp"

namespace kf {

namespace {

constexpr const char* kNotBuilt = "this build has no hidapi (built with KF_WITH_HARDWARE=OFF): no real mouse";

class AbsentHidApi : public HidApi {
 public:
  bool enumerateMice(std::vector<MouseInfo>& out, std::string& error) override {
    out.clear();
    error = kNotBuilt;
    return false;
  }
  std::unique_ptr<HidHandle> openPath(const std::string&, std::string& error, OpenFailure& why) override {
    error = kNotBuilt;
    why = OpenFailure::kOther;
    return nullptr;
  }
};

}  // namespace

std::shared_ptr<HidApi> realHidApi() {
  static std::shared_ptr<HidApi> api = std::make_shared<AbsentHidApi>();
  return api;
}

}  // namespace kf

// makeLibusbPort in a build without hardware backends (KF_WITH_HARDWARE=OFF: Debian ships no
// MinGW libusb, so the Windows build checked here has none). The board's commands answer with
// kNotBuilt's reason; the emulated board needs no libusb and works.
#include "board/UsbPort.hpp"

namespace kf::usb {

namespace {

class AbsentPort : public Port {
 public:
  Result init() override { return Result::kNotBuilt; }
  void exit() override {}
  Result open(const DeviceIds&) override { return Result::kNotBuilt; }
  std::string skipped() const override { return {}; }
  std::string openSerial() const override { return {}; }
  InterfaceEndpoints openEndpoints() const override { return {}; }
  Result claimInterface(int) override { return Result::kNotBuilt; }
  void releaseInterface(int) override {}
  void close(double) override {}
  Result control(uint8_t, uint8_t, uint16_t, uint16_t, uint8_t*, uint16_t, unsigned, int*) override {
    return Result::kNotBuilt;
  }
  Result clearHalt(uint8_t) override { return Result::kNotBuilt; }
  Result submit(Transfer&) override { return Result::kNotBuilt; }
  Result cancel(Transfer&) override { return Result::kNotBuilt; }
  Result handleEvents(int) override { return Result::kNotBuilt; }
};

}  // namespace

std::unique_ptr<Port> makeLibusbPort() { return std::make_unique<AbsentPort>(); }

}  // namespace kf::usb

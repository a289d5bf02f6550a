// A build without hardware backends (KF_WITH_HARDWARE=OFF, the Windows build checked under
// Wine): a real mouse and a real board are refused with the reason, the simulated and emulated
// devices are not. Built only into such a build (tests/device/CMakeLists.txt).
#include <catch2/catch.hpp>
#include <string>
#include <vector>

#include "MouseDeviceFactory.hpp"
#include "board/UsbBoardBackend.hpp"
#include "board/UsbPort.hpp"

using namespace kf;

TEST_CASE("without hardware backends, listing and opening a real mouse fail with the reason", "[absent]") {
  std::vector<std::string> lines;
  std::string error;
  CHECK_FALSE(listMice(MouseBackendKind::kHidapi, lines, error));
  CHECK(lines.empty());
  CHECK(error.find("KF_WITH_HARDWARE=OFF") != std::string::npos);
  MouseOpenOptions options;
  options.kind = MouseBackendKind::kHidapi;
  error.clear();
  OpenFailure why = OpenFailure::kNone;
  CHECK_FALSE(openMouseDevice(options, DeviceSpec{}, error, &why));
  CHECK(why == OpenFailure::kOther);
  CHECK(error.find("KF_WITH_HARDWARE=OFF") != std::string::npos);
}

TEST_CASE("without hardware backends, the real board is refused with the reason", "[absent]") {
  UsbBoardBackend backend(usb::makeLibusbPort());
  std::string error;
  CHECK_FALSE(backend.open(error));
  CHECK(error == std::string("libusb could not start: ") + usb::describe(usb::Result::kNotBuilt));
  CHECK(error.find("KF_WITH_HARDWARE=OFF") != std::string::npos);
  backend.close();
}

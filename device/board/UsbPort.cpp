// UsbPort's words for results and transfer states and the interface check: no libusb, so the
// emulator and a build without hardware (KF_WITH_HARDWARE=OFF) have them too.
#include <cstdio>
#include <string>

#include "board/UsbPort.hpp"

namespace kf::usb {

const char* describe(Result result) {
  switch (result) {
    case Result::kOk:
      return "ok";
    case Result::kIo:
      return "input/output error";
    case Result::kInvalid:
      return "invalid parameter";
    case Result::kAccess:
      return "permission denied (is the udev rule 70-kineticfriction.rules installed? then replug the board)";
    case Result::kNoDevice:
      return "no device (unplugged)";
    case Result::kNotFound:
      return "not found";
    case Result::kBusy:
      return "busy (another program or a kernel driver holds the interface; it is not detached)";
    case Result::kTimeout:
      return "timed out";
    case Result::kPipe:
      return "stall (the board refused the request)";
    case Result::kLeaked:
      return "a USB transfer never completed; restart the server to use the board again";
    case Result::kNotBuilt:
      return "this build has no USB backend (built with KF_WITH_HARDWARE=OFF); the emulated board works";
    case Result::kOther:
      break;
  }
  return "error";
}

const char* describe(TransferStatus status) {
  switch (status) {
    case TransferStatus::kCompleted:
      return "completed";
    case TransferStatus::kError:
      return "error";
    case TransferStatus::kTimedOut:
      return "timed out";
    case TransferStatus::kCancelled:
      return "cancelled";
    case TransferStatus::kStall:
      return "stall";
    case TransferStatus::kNoDevice:
      return "no device";
    case TransferStatus::kOverflow:
      return "overflow";
  }
  return "?";
}

std::string interfaceMismatch(const InterfaceIdentity* found, const InterfaceIdentity& wanted) {
  char text[96];
  if (found == nullptr) {
    std::snprintf(text, sizeof text, "no interface %d", wanted.number);
    return text;
  }
  if (found->interfaceClass == wanted.interfaceClass && found->subclass == wanted.subclass &&
      found->protocol == wanted.protocol)
    return "";
  // class/subclass/protocol, short: it goes into a /kfFail reason of 200 characters.
  std::snprintf(text, sizeof text, "interface %d is class %02x/%02x/%02x, not %02x/%02x/%02x", wanted.number,
                found->interfaceClass, found->subclass, found->protocol, wanted.interfaceClass, wanted.subclass,
                wanted.protocol);
  return text;
}

}  // namespace kf::usb

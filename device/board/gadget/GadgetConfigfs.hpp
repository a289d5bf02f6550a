// GadgetConfigfs: the USB gadget the board's function lives in, made through configfs (the
// kernel's libcomposite): the board's IDs and strings (PROTOCOL.md section 1, its serial given),
// one configuration with one FunctionFS function, that function's file system mounted, and the
// gadget bound to a USB device controller (UDC) once the function is ready. Everything it made
// is taken down again in reverse order. Needs root, libcomposite and usb_f_fs.
#pragma once

#include <string>

namespace kf::board::gadget {

struct GadgetIdentity {
  std::string name = "kf-board";  // the configfs gadget's and the FunctionFS instance's name
  std::string serial = "KF-GADGET-0001";
  std::string manufacturer = "KineticFriction";
  std::string product = "Friction board";
  unsigned bcdDevice = 0x0100;  // firmware 1.0
};

class GadgetConfigfs {
 public:
  explicit GadgetConfigfs(GadgetIdentity identity);
  ~GadgetConfigfs();
  GadgetConfigfs(const GadgetConfigfs&) = delete;
  GadgetConfigfs& operator=(const GadgetConfigfs&) = delete;

  // Makes the gadget and mounts its FunctionFS at functionFsDir(); false with the reason.
  bool create(std::string& error);
  // Binds it to `udc` ("" : the first in /sys/class/udc): the host sees it plugged in. The
  // function must have written its descriptors first.
  bool bind(const std::string& udc, std::string& error);
  void unbind();  // unplugged
  // The configfs folder (its UDC file binds and unbinds) and the FunctionFS mount point.
  std::string gadgetDir() const;
  std::string functionFsDir() const;
  std::string boundUdc() const { return udc_; }

 private:
  void remove();

  GadgetIdentity identity_;
  bool created_ = false;
  bool mounted_ = false;
  std::string udc_;
};

}  // namespace kf::board::gadget

// HidMouseDecoder: finds, in a parsed report descriptor, the relative Generic Desktop X/Y
// inputs and the buttons of each report ID, and decodes raw input reports to dx, dy, buttons,
// flagging a delta at its field's limit (the descriptor's logical minimum or maximum, within
// what the field's bits hold) as saturated. A mouse report is one with X or Y, or one with
// buttons in the application collection of such a report: some mice send their buttons in a
// report of their own (the Xiaomi Mi Wireless Mouse's receiver, 2717:003B: buttons, wheel and
// AC Pan in report 1, X and Y in report 2), which Linux's hid-input decodes into the same input
// device as the motion.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "hid/HidReportDescriptor.hpp"

namespace kf {

struct HidMouseDelta {
  uint8_t reportId = 0;
  int32_t dxCounts = 0;
  int32_t dyCounts = 0;
  uint32_t buttons = 0;  // bit i = Button usage i + 1
  // The report carries the buttons. When false (the X/Y report of a mouse that sends its buttons
  // in another report) `buttons` is 0 and means nothing: the buttons stay as the last report
  // that carried them left them, as the kernel keeps them.
  bool hasButtons = false;
  // dx or dy at its field's limit: the sensor moved at least that far, maybe more (the excess
  // is lost). A value beyond the logical range is clamped to it first, as Linux's input layer
  // and Windows do, so hidraw and evdev give the same counts.
  bool saturated = false;
};

class HidMouseDecoder {
 public:
  // Buttons are 1..32, so no report needs more button bits or array elements than this.
  static constexpr size_t kMaxButtonElements = 32;

  // False (with a message) when no report carries a relative X or Y input.
  bool build(const HidReportDescriptor& descriptor, std::string& error);

  // Decodes one raw input report (report ID byte first when the descriptor uses IDs). False
  // when the report is not a mouse report (other report ID) or too short for its fields.
  bool decode(const uint8_t* bytes, size_t size, HidMouseDelta& out) const;

  bool usesReportIds() const { return usesReportIds_; }
  // The range the mouse reports' X and Y are clamped to (a value at either end, other than 0, is
  // saturated), for a reader that gets the values decoded by someone else: evdev passes the HID
  // field's value on without saying which report it came from, so with several mouse reports
  // the widest range (no false flags; a narrower report's limit then goes unflagged). False
  // before build or without such a report.
  bool axisRange(int64_t& xLowest, int64_t& xHighest, int64_t& yLowest, int64_t& yHighest) const;
  // Report IDs of the mouse reports, X/Y or buttons (0 when the descriptor has no IDs).
  std::vector<uint8_t> mouseReportIds() const;

 private:
  struct Element {
    uint32_t bitOffset = 0;
    uint32_t bitSize = 0;
    bool isSigned = false;
  };
  // An X or Y element and the range its values are clamped to; a value at either end (other
  // than 0) is a saturated delta.
  struct Axis {
    Element element;
    int64_t lowest = 0, highest = 0;
  };
  // One element of an array item; its selectable usages are shared by all elements of the
  // item (arrayUsages_[usagesIndex]), never copied per element.
  struct ButtonArray {
    Element element;
    int64_t logicalMin = 0;
    size_t usagesIndex = 0;
  };
  struct Layout {
    uint8_t reportId = 0;
    int application = -1;  // the application collection of its first field (index), -1 none
    size_t minBytes = 0;   // without the ID byte
    bool haveX = false, haveY = false;
    Axis x, y;
    std::vector<std::pair<Element, uint32_t>> buttonBits;  // element, button number (1-based)
    std::vector<ButtonArray> buttonArrays;
  };

  void noteExtent(Layout& layout, const Element& element);
  static Axis axisOf(const HidField& field, const Element& element);
  // The axis' value in `bytes` (0 if it has none), clamped to its range; `saturated` set at a limit.
  static int32_t readAxis(const uint8_t* bytes, size_t size, bool have, const Axis& axis, bool& saturated);

  std::vector<Layout> layouts_;
  std::vector<std::vector<HidUsage>> arrayUsages_;
  bool usesReportIds_ = false;
};

}  // namespace kf

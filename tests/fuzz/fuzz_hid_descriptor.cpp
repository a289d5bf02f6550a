// libFuzzer target: the HID report-descriptor parser and the mouse decoder. The input is a
// descriptor; its tail doubles as raw reports to decode. Bounded work and memory whatever the
// bytes (issue 13: a usage range that wrapped, usage lists copied per array element).
#include <cstddef>
#include <cstdint>
#include <string>

#include "hid/HidMouseDecoder.hpp"
#include "hid/HidReportDescriptor.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  kf::HidReportDescriptor descriptor;
  std::string error;
  if (!kf::parseHidReportDescriptor(data, size, descriptor, error)) return 0;
  for (const kf::HidField& field : descriptor.fields) (void)field.usageOfElement(field.count);
  for (int id = 0; id < 256; ++id) (void)descriptor.inputReportBytes(static_cast<uint8_t>(id));
  kf::HidMouseDecoder decoder;
  if (!decoder.build(descriptor, error)) return 0;
  // Every suffix up to 64 bytes as a report, with each report ID in front.
  kf::HidMouseDelta delta;
  for (size_t start = size > 64 ? size - 64 : 0; start < size; ++start)
    decoder.decode(data + start, size - start, delta);
  for (uint8_t id : decoder.mouseReportIds()) {
    uint8_t report[65] = {id};
    for (size_t i = 0; i < 64 && i < size; ++i) report[i + 1] = data[i];
    decoder.decode(report, sizeof report, delta);
  }
  return 0;
}

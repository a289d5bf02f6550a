#include "mouse/DescriptorKind.hpp"

#include <string>

#include "hid/HidReportDescriptor.hpp"

namespace kf {

DescriptorKind descriptorKind(const std::vector<uint8_t>& bytes) {
  DescriptorKind kind;
  HidReportDescriptor descriptor;
  std::string error;
  if (bytes.empty() || !parseHidReportDescriptor(bytes.data(), bytes.size(), descriptor, error)) return kind;
  kind.parsed = true;
  bool x = false, y = false;
  for (const HidField& field : descriptor.fields) {
    if (field.kind != HidField::Kind::kInput || !field.isVariable() || !field.isRelative()) continue;
    for (uint32_t i = 0; i < field.count; ++i) {
      x = x || field.usageOfElement(i) == hidUsage(kHidPageGenericDesktop, 0x30);
      y = y || field.usageOfElement(i) == hidUsage(kHidPageGenericDesktop, 0x31);
    }
  }
  kind.hasXY = x && y;
  for (const HidCollection& collection : descriptor.collections)
    kind.hasKeyboard =
        kind.hasKeyboard || (collection.type == 1 && (collection.usage == hidUsage(kHidPageGenericDesktop, 6) ||
                                                      collection.usage == hidUsage(kHidPageGenericDesktop, 7)));
  return kind;
}

}  // namespace kf

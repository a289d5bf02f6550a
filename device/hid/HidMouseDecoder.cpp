#include "hid/HidMouseDecoder.hpp"

#include <algorithm>

namespace kf {

void HidMouseDecoder::noteExtent(Layout& layout, const Element& element) {
  layout.minBytes = std::max<size_t>(layout.minBytes, (element.bitOffset + element.bitSize + 7) / 8);
}

bool HidMouseDecoder::build(const HidReportDescriptor& descriptor, std::string& error) {
  layouts_.clear();
  arrayUsages_.clear();
  usesReportIds_ = descriptor.usesReportIds;
  auto layoutFor = [this](uint8_t reportId) -> Layout& {
    for (Layout& layout : layouts_)
      if (layout.reportId == reportId) return layout;
    layouts_.push_back(Layout{});
    layouts_.back().reportId = reportId;
    return layouts_.back();
  };
  constexpr HidUsage kX = hidUsage(kHidPageGenericDesktop, 0x30);
  constexpr HidUsage kY = hidUsage(kHidPageGenericDesktop, 0x31);

  for (const HidField& field : descriptor.fields) {
    if (field.kind != HidField::Kind::kInput || field.isConstant()) continue;
    if (field.bitSize == 0 || field.bitSize > 32) continue;
    Layout& layout = layoutFor(field.reportId);
    if (field.isVariable()) {
      for (uint32_t i = 0; i < field.count; ++i) {
        const HidUsage usage = field.usageOfElement(i);
        const Element element{field.bitOffset + i * field.bitSize, field.bitSize, field.isSigned()};
        if (usage == kX && field.isRelative() && !layout.haveX) {
          layout.x = element;
          layout.haveX = true;
          noteExtent(layout, element);
        } else if (usage == kY && field.isRelative() && !layout.haveY) {
          layout.y = element;
          layout.haveY = true;
          noteExtent(layout, element);
        } else if (usage >> 16 == kHidPageButton && (usage & 0xFFFF) >= 1 && (usage & 0xFFFF) <= 32 &&
                   layout.buttonBits.size() < kMaxButtonElements) {
          layout.buttonBits.emplace_back(element, usage & 0xFFFF);
          noteExtent(layout, element);
        }
      }
    } else {
      const bool anyButton =
          std::any_of(field.usages.begin(), field.usages.end(), [](HidUsage u) { return u >> 16 == kHidPageButton; });
      if (!anyButton) continue;
      arrayUsages_.push_back(field.usages);
      for (uint32_t i = 0; i < field.count && layout.buttonArrays.size() < kMaxButtonElements; ++i) {
        ButtonArray array;
        array.element = {field.bitOffset + i * field.bitSize, field.bitSize, field.isSigned()};
        array.logicalMin = field.logicalMin;
        array.usagesIndex = arrayUsages_.size() - 1;
        noteExtent(layout, array.element);
        layout.buttonArrays.push_back(std::move(array));
      }
    }
  }
  // Only reports with motion are mouse reports.
  layouts_.erase(std::remove_if(layouts_.begin(), layouts_.end(), [](const Layout& l) { return !l.haveX && !l.haveY; }),
                 layouts_.end());
  if (layouts_.empty()) {
    error = "the HID report descriptor has no relative Generic Desktop X or Y input";
    return false;
  }
  return true;
}

std::vector<uint8_t> HidMouseDecoder::mouseReportIds() const {
  std::vector<uint8_t> ids;
  for (const Layout& layout : layouts_) ids.push_back(layout.reportId);
  return ids;
}

bool HidMouseDecoder::decode(const uint8_t* bytes, size_t size, HidMouseDelta& out) const {
  uint8_t reportId = 0;
  if (usesReportIds_) {
    if (size < 1) return false;
    reportId = bytes[0];
    ++bytes;
    --size;
  }
  const Layout* layout = nullptr;
  for (const Layout& candidate : layouts_)
    if (candidate.reportId == reportId) layout = &candidate;
  if (!layout || size < layout->minBytes) return false;

  out = HidMouseDelta{};
  out.reportId = reportId;
  int64_t value = 0;
  if (layout->haveX && extractHidBits(bytes, size, layout->x.bitOffset, layout->x.bitSize, layout->x.isSigned, value))
    out.dxCounts = static_cast<int32_t>(value);
  if (layout->haveY && extractHidBits(bytes, size, layout->y.bitOffset, layout->y.bitSize, layout->y.isSigned, value))
    out.dyCounts = static_cast<int32_t>(value);
  for (const auto& [element, button] : layout->buttonBits)
    if (extractHidBits(bytes, size, element.bitOffset, element.bitSize, false, value) && value != 0)
      out.buttons |= 1u << (button - 1);
  for (const ButtonArray& array : layout->buttonArrays) {
    if (!extractHidBits(bytes, size, array.element.bitOffset, array.element.bitSize, array.element.isSigned, value))
      continue;
    const std::vector<HidUsage>& usages = arrayUsages_[array.usagesIndex];
    const int64_t index = value - array.logicalMin;
    if (index < 0 || index >= static_cast<int64_t>(usages.size())) continue;  // none pressed
    const HidUsage usage = usages[static_cast<size_t>(index)];
    const uint32_t button = usage & 0xFFFF;
    if (usage >> 16 == kHidPageButton && button >= 1 && button <= 32) out.buttons |= 1u << (button - 1);
  }
  return true;
}

}  // namespace kf

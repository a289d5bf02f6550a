#include "hid/HidMouseDecoder.hpp"

#include <algorithm>
#include <cstdint>
#include <string>

namespace kf {

void HidMouseDecoder::noteExtent(Layout& layout, const Element& element) {
  layout.minBytes = std::max<size_t>(layout.minBytes, (element.bitOffset + element.bitSize + 7) / 8);
}

HidMouseDecoder::Axis HidMouseDecoder::axisOf(const HidField& field, const Element& element) {
  // What the field's bits hold; the logical range narrows it when the descriptor gives one
  // (minimum below maximum: a descriptor without one leaves both 0, as Linux also reads it).
  const int64_t span = int64_t(1) << element.bitSize;
  Axis axis{element, element.isSigned ? -span / 2 : 0, element.isSigned ? span / 2 - 1 : span - 1};
  axis.highest = std::min<int64_t>(axis.highest, INT32_MAX);  // an unsigned 32-bit delta is no mouse's
  if (field.logicalMin < field.logicalMax) {
    const int64_t lowest = std::max(axis.lowest, field.logicalMin);
    const int64_t highest = std::min(axis.highest, field.logicalMax);
    // A logical range the field's bits cannot hold (a broken descriptor) keeps the bits' range.
    if (lowest < highest) axis.lowest = lowest, axis.highest = highest;
  }
  return axis;
}

int32_t HidMouseDecoder::readAxis(const uint8_t* bytes, size_t size, bool have, const Axis& axis, bool& saturated) {
  int64_t value = 0;
  if (!have || !extractHidBits(bytes, size, axis.element.bitOffset, axis.element.bitSize, axis.element.isSigned, value))
    return 0;
  value = std::clamp(value, axis.lowest, axis.highest);
  // 0 is no movement, whatever the range (an unsigned axis would otherwise saturate at rest).
  if (value != 0 && (value == axis.lowest || value == axis.highest)) saturated = true;
  return static_cast<int32_t>(value);
}

bool HidMouseDecoder::axisRange(int64_t& xLowest, int64_t& xHighest, int64_t& yLowest, int64_t& yHighest) const {
  bool found = false;
  for (const Layout& layout : layouts_) {
    if (!layout.haveX || !layout.haveY) continue;
    xLowest = found ? std::min(xLowest, layout.x.lowest) : layout.x.lowest;
    xHighest = found ? std::max(xHighest, layout.x.highest) : layout.x.highest;
    yLowest = found ? std::min(yLowest, layout.y.lowest) : layout.y.lowest;
    yHighest = found ? std::max(yHighest, layout.y.highest) : layout.y.highest;
    found = true;
  }
  return found;
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

  // The top-level (application) collection a field is in: hid-input makes one input device of
  // each (hid-generic), so a report's buttons belong to the mouse of their application.
  auto applicationOf = [&descriptor](int collection) {
    for (int guard = 0; collection >= 0 && guard < 4096; ++guard) {
      const HidCollection& c = descriptor.collections[static_cast<size_t>(collection)];
      if (c.parent < 0) return collection;
      collection = c.parent;
    }
    return collection;
  };

  for (const HidField& field : descriptor.fields) {
    if (field.kind != HidField::Kind::kInput || field.isConstant()) continue;
    if (field.bitSize == 0 || field.bitSize > 32) continue;
    Layout& layout = layoutFor(field.reportId);
    if (layout.application < 0) layout.application = applicationOf(field.collection);
    if (field.isVariable()) {
      for (uint32_t i = 0; i < field.count; ++i) {
        const HidUsage usage = field.usageOfElement(i);
        const Element element{field.bitOffset + i * field.bitSize, field.bitSize, field.isSigned()};
        if (usage == kX && field.isRelative() && !layout.haveX) {
          layout.x = axisOf(field, element);
          layout.haveX = true;
          noteExtent(layout, element);
        } else if (usage == kY && field.isRelative() && !layout.haveY) {
          layout.y = axisOf(field, element);
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
  // Mouse reports: those with motion, and those with buttons in the application collection of a
  // report with motion (not a gamepad's or a keyboard's buttons beside the mouse).
  auto hasMotion = [](const Layout& l) { return l.haveX || l.haveY; };
  auto isMouseReport = [&](const Layout& l) {
    if (hasMotion(l)) return true;
    if (l.buttonBits.empty() && l.buttonArrays.empty()) return false;
    return std::any_of(layouts_.begin(), layouts_.end(),
                       [&](const Layout& m) { return hasMotion(m) && m.application == l.application; });
  };
  std::vector<bool> keep;
  for (const Layout& layout : layouts_) keep.push_back(isMouseReport(layout));
  std::vector<Layout> mouseLayouts;
  for (size_t i = 0; i < layouts_.size(); ++i)
    if (keep[i]) mouseLayouts.push_back(std::move(layouts_[i]));
  layouts_ = std::move(mouseLayouts);
  if (layouts_.empty()) {
    error = "the HID report descriptor has no relative Generic Desktop X or Y input";
    if (!descriptor.skipNotes.empty())
      error +=
          " (" + descriptor.skipNotes.front() +
          (descriptor.skippedItems > 1 ? "; " + std::to_string(descriptor.skippedItems - 1) + " more skipped" : "") +
          ")";
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
  out.dxCounts = readAxis(bytes, size, layout->haveX, layout->x, out.saturated);
  out.dyCounts = readAxis(bytes, size, layout->haveY, layout->y, out.saturated);
  out.hasButtons = !layout->buttonBits.empty() || !layout->buttonArrays.empty();
  int64_t value = 0;
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

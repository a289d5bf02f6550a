// HidReportDescriptor: a parser of USB HID report descriptors (HID 1.11, section 6.2.2) into
// the fields of each report — enough to find and decode any mouse's relative X/Y and buttons
// in recorded raw reports, whatever their bit sizes and offsets.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace kf {

// A usage with its page: page << 16 | id.
using HidUsage = uint32_t;
constexpr HidUsage hidUsage(uint16_t page, uint16_t id) { return uint32_t(page) << 16 | id; }
constexpr uint16_t kHidPageGenericDesktop = 0x01;
constexpr uint16_t kHidPageButton = 0x09;

enum HidMainFlag : uint32_t { kHidConstant = 1, kHidVariable = 2, kHidRelative = 4 };

struct HidCollection {
  uint8_t type = 0;  // 0 physical, 1 application, 2 logical, ...
  HidUsage usage = 0;
  int parent = -1;  // index into HidReportDescriptor::collections, -1 at top level
};

// One Input, Output or Feature main item: `count` elements of `bitSize` bits each.
struct HidField {
  enum class Kind { kInput, kOutput, kFeature };
  Kind kind = Kind::kInput;
  uint8_t reportId = 0;    // 0 when the descriptor declares no report IDs
  uint32_t bitOffset = 0;  // of the first element, after the report ID byte
  uint32_t bitSize = 0;
  uint32_t count = 0;
  uint32_t flags = 0;  // HidMainFlag bits (and the rest of the item's data)
  int64_t logicalMin = 0;
  int64_t logicalMax = 0;
  // Variable items: element i has usages[min(i, size - 1)]. Array items: the selectable
  // usages, value v selecting usages[v - logicalMin].
  std::vector<HidUsage> usages;
  int collection = -1;

  bool isConstant() const { return flags & kHidConstant; }
  bool isVariable() const { return flags & kHidVariable; }
  bool isRelative() const { return flags & kHidRelative; }
  bool isSigned() const { return logicalMin < 0; }
  HidUsage usageOfElement(uint32_t index) const;
};

struct HidReportDescriptor {
  std::vector<HidField> fields;
  std::vector<HidCollection> collections;
  bool usesReportIds = false;
  // Main items accepted but not kept, each with its byte offset and why: reserved main tags
  // and item types, and the items of a report with an item beyond our bounds (that report's
  // fields are all dropped, so it is never half decoded). The first kMaxSkipNotes are named.
  static constexpr size_t kMaxSkipNotes = 8;
  std::vector<std::string> skipNotes;
  size_t skippedItems = 0;

  // Size in bytes of the input report with this ID as sent, the ID byte included.
  size_t inputReportBytes(uint8_t reportId) const;
};

// Parses `size` bytes. A descriptor whose structure is broken (truncated item, unbalanced
// collections or push/pop, report ID 0, unknown global item, longer than 65535 bytes) is
// refused: false with a message naming the byte offset. Main items a mouse does not need are
// skipped, not refused (a vendor report with an odd item must not stop the mouse beside it;
// Linux's parser also passes over reserved main items): see skipNotes. Never reads past the
// end; bounded memory.
bool parseHidReportDescriptor(const uint8_t* bytes, size_t size, HidReportDescriptor& out, std::string& error);

// The little-endian bit field [bitOffset, bitOffset + bitSize) of `data` (bitSize 1..32),
// sign-extended if `isSigned`. False if it does not lie within `sizeBytes`.
bool extractHidBits(const uint8_t* data, size_t sizeBytes, uint32_t bitOffset, uint32_t bitSize, bool isSigned,
                    int64_t& value);

}  // namespace kf

#include "hid/HidReportDescriptor.hpp"

#include <algorithm>
#include <map>
#include <set>
#include <utility>

namespace kf {

namespace {

constexpr size_t kMaxPushDepth = 16;
constexpr uint32_t kMaxReportSizeBits = 1024;
constexpr uint64_t kMaxReportBits = 8u * 4096u;  // a HID report larger than 4 KiB is malformed
constexpr uint32_t kMaxUsageRange = 65536;       // one whole usage page
constexpr size_t kMaxTotalUsages = 1u << 18;     // over all fields: 1 MiB of usages at most
constexpr size_t kMaxDescriptorBytes = 65535;    // the USB descriptor length is 16 bits

struct GlobalState {
  uint16_t usagePage = 0;
  uint32_t logicalMinRaw = 0;
  int logicalMinBytes = 0;
  uint32_t logicalMaxRaw = 0;
  int logicalMaxBytes = 0;
  uint32_t reportSize = 0;
  uint32_t reportCount = 0;
  uint8_t reportId = 0;
};

struct LocalUsage {
  uint32_t value = 0;
  int bytes = 0;  // 4: value carries its own page
};

struct LocalState {
  std::vector<LocalUsage> usages;
  bool haveMin = false, haveMax = false;
  bool tooManyUsages = false;  // more than kMaxUsageRange usages before one main item
  LocalUsage usageMin, usageMax;
};

int64_t signExtend(uint32_t raw, int bytes) {
  if (bytes == 0) return 0;
  if (bytes >= 4) return static_cast<int32_t>(raw);
  const uint32_t signBit = 1u << (bytes * 8 - 1);
  return raw & signBit ? static_cast<int64_t>(raw) - (int64_t(1) << (bytes * 8)) : raw;
}

HidUsage fullUsage(const LocalUsage& usage, uint16_t page) {
  return usage.bytes == 4 ? usage.value : hidUsage(page, static_cast<uint16_t>(usage.value));
}

std::string at(size_t offset, const std::string& what) {
  return "HID report descriptor, byte " + std::to_string(offset) + ": " + what;
}

const char* kindName(HidField::Kind kind) {
  return kind == HidField::Kind::kInput ? "input" : kind == HidField::Kind::kOutput ? "output" : "feature";
}

void noteSkipped(HidReportDescriptor& out, size_t offset, const std::string& what) {
  ++out.skippedItems;
  if (out.skipNotes.size() < HidReportDescriptor::kMaxSkipNotes)
    out.skipNotes.push_back("byte " + std::to_string(offset) + ": " + what);
}

}  // namespace

HidUsage HidField::usageOfElement(uint32_t index) const {
  if (usages.empty()) return 0;
  return usages[std::min<size_t>(index, usages.size() - 1)];
}

size_t HidReportDescriptor::inputReportBytes(uint8_t reportId) const {
  uint64_t bits = 0;
  for (const HidField& field : fields)
    if (field.kind == HidField::Kind::kInput && field.reportId == reportId)
      bits = std::max<uint64_t>(bits, field.bitOffset + uint64_t(field.bitSize) * field.count);
  return static_cast<size_t>((bits + 7) / 8) + (usesReportIds ? 1 : 0);
}

bool parseHidReportDescriptor(const uint8_t* bytes, size_t size, HidReportDescriptor& out, std::string& error) {
  out = HidReportDescriptor{};
  GlobalState global;
  std::vector<GlobalState> pushed;
  LocalState local;
  std::vector<int> openCollections;
  std::map<std::pair<int, int>, uint64_t> nextBit;  // (kind, report ID) -> bit offset
  std::set<std::pair<int, int>> droppedReports;     // (kind, report ID) with an item beyond our bounds
  size_t totalUsages = 0;
  if (size > kMaxDescriptorBytes) {
    error =
        "HID report descriptor of " + std::to_string(size) + " bytes, more than " + std::to_string(kMaxDescriptorBytes);
    return false;
  }

  size_t pos = 0;
  while (pos < size) {
    const size_t itemStart = pos;
    const uint8_t prefix = bytes[pos++];
    if (prefix == 0xFE) {  // long item: skip its data
      if (size - pos < 2) {
        error = at(itemStart, "truncated long item");
        return false;
      }
      const size_t dataBytes = bytes[pos];
      pos += 2;
      if (size - pos < dataBytes) {
        error = at(itemStart, "truncated long item");
        return false;
      }
      pos += dataBytes;
      continue;
    }
    const int dataBytes = (prefix & 3) == 3 ? 4 : (prefix & 3);
    const int type = (prefix >> 2) & 3;
    const int tag = prefix >> 4;
    if (size - pos < static_cast<size_t>(dataBytes)) {
      static const char digits[] = "0123456789abcdef";
      const std::string hex{digits[prefix >> 4], digits[prefix & 15]};
      error = at(itemStart, "truncated item (prefix 0x" + hex + " needs " + std::to_string(dataBytes) + " data bytes)");
      return false;
    }
    uint32_t data = 0;
    for (int i = 0; i < dataBytes; ++i) data |= uint32_t(bytes[pos + i]) << (8 * i);
    pos += dataBytes;

    if (type == 0) {  // main
      if (tag == 0x8 || tag == 0x9 || tag == 0xB) {
        const HidField::Kind kind = tag == 0x8   ? HidField::Kind::kInput
                                    : tag == 0x9 ? HidField::Kind::kOutput
                                                 : HidField::Kind::kFeature;
        const std::pair<int, int> report{static_cast<int>(kind), global.reportId};
        uint64_t& bit = nextBit[report];
        const uint64_t fieldBits = uint64_t(global.reportSize) * global.reportCount;
        uint64_t rangeCount = 0;
        HidUsage first = 0;
        std::string problem;
        if (global.reportSize > kMaxReportSizeBits) {
          problem = "report size " + std::to_string(global.reportSize) + " too large";
        } else if (bit + fieldBits > kMaxReportBits) {
          problem = "report longer than 4096 bytes";
        } else if (local.tooManyUsages) {
          problem = "more than " + std::to_string(kMaxUsageRange) + " usages before one main item";
        } else if (local.haveMin && local.haveMax) {
          first = fullUsage(local.usageMin, global.usagePage);
          const HidUsage last = fullUsage(local.usageMax, global.usagePage);
          if (last < first || last - first >= kMaxUsageRange)
            problem = "bad usage minimum/maximum range";
          else
            rangeCount = uint64_t(last) - first + 1;
        }
        if (problem.empty() && totalUsages + local.usages.size() + rangeCount > kMaxTotalUsages)
          problem = "more than " + std::to_string(kMaxTotalUsages) + " usages in all";
        if (!problem.empty()) {
          // Its offsets, and those after it in the report, would be guesses: the report goes.
          droppedReports.insert(report);
          noteSkipped(out, itemStart,
                      problem + ": " + kindName(kind) + " report " + std::to_string(global.reportId) + " skipped");
        } else if (!droppedReports.count(report) && fieldBits > 0) {
          HidField field;
          field.kind = kind;
          field.reportId = global.reportId;
          field.bitOffset = static_cast<uint32_t>(bit);
          field.bitSize = global.reportSize;
          field.count = global.reportCount;
          field.flags = data;
          field.logicalMin = signExtend(global.logicalMinRaw, global.logicalMinBytes);
          // A maximum is signed only when the minimum is negative (as the Linux parser does).
          field.logicalMax = field.logicalMin < 0 ? signExtend(global.logicalMaxRaw, global.logicalMaxBytes)
                                                  : int64_t(global.logicalMaxRaw);
          totalUsages += local.usages.size() + rangeCount;
          for (const LocalUsage& usage : local.usages) field.usages.push_back(fullUsage(usage, global.usagePage));
          // Counted, not compared with `last`: a range ending at 0xFFFFFFFF must not wrap.
          for (uint64_t i = 0; i < rangeCount; ++i) field.usages.push_back(static_cast<HidUsage>(first + i));
          field.collection = openCollections.empty() ? -1 : openCollections.back();
          out.fields.push_back(std::move(field));
        }
        if (problem.empty()) bit += fieldBits;
      } else if (tag == 0xA) {  // collection
        HidCollection collection;
        collection.type = static_cast<uint8_t>(data);
        if (!local.usages.empty()) collection.usage = fullUsage(local.usages.front(), global.usagePage);
        collection.parent = openCollections.empty() ? -1 : openCollections.back();
        out.collections.push_back(collection);
        openCollections.push_back(static_cast<int>(out.collections.size()) - 1);
      } else if (tag == 0xC) {  // end collection
        if (openCollections.empty()) {
          error = at(itemStart, "End Collection without an open collection");
          return false;
        }
        openCollections.pop_back();
      } else {
        noteSkipped(out, itemStart, "reserved main item tag " + std::to_string(tag) + " skipped");
      }
      local = LocalState{};
    } else if (type == 1) {  // global
      switch (tag) {
        case 0x0:
          global.usagePage = static_cast<uint16_t>(data);
          break;
        case 0x1:
          global.logicalMinRaw = data;
          global.logicalMinBytes = dataBytes;
          break;
        case 0x2:
          global.logicalMaxRaw = data;
          global.logicalMaxBytes = dataBytes;
          break;
        case 0x3:
        case 0x4:
        case 0x5:
        case 0x6:
          break;  // physical range, unit: not needed
        case 0x7:
          global.reportSize = data;
          break;
        case 0x8:
          if (data == 0 || data > 255) {
            error = at(itemStart, "report ID " + std::to_string(data) + " out of 1..255");
            return false;
          }
          global.reportId = static_cast<uint8_t>(data);
          out.usesReportIds = true;
          break;
        case 0x9:
          global.reportCount = data;
          break;
        case 0xA:
          if (pushed.size() >= kMaxPushDepth) {
            error = at(itemStart, "Push nested deeper than " + std::to_string(kMaxPushDepth));
            return false;
          }
          pushed.push_back(global);
          break;
        case 0xB:
          if (pushed.empty()) {
            error = at(itemStart, "Pop without Push");
            return false;
          }
          global = pushed.back();
          pushed.pop_back();
          break;
        default:
          error = at(itemStart, "unknown global item tag " + std::to_string(tag));
          return false;
      }
    } else if (type == 2) {  // local
      const LocalUsage usage{data, dataBytes};
      if (tag == 0x0) {
        if (local.usages.size() >= kMaxUsageRange)
          local.tooManyUsages = true;  // the main item they belong to is skipped
        else
          local.usages.push_back(usage);
      } else if (tag == 0x1) {
        local.usageMin = usage;
        local.haveMin = true;
      } else if (tag == 0x2) {
        local.usageMax = usage;
        local.haveMax = true;
      }
      // Designators, strings and delimiters do not matter for decoding.
    } else {
      noteSkipped(out, itemStart, "reserved item type skipped");
    }
  }
  if (!openCollections.empty()) {
    error = "HID report descriptor: " + std::to_string(openCollections.size()) + " collection(s) not closed at the end";
    return false;
  }
  // Fields kept before a report's bad item go too.
  out.fields.erase(std::remove_if(out.fields.begin(), out.fields.end(),
                                  [&](const HidField& field) {
                                    return droppedReports.count({static_cast<int>(field.kind), field.reportId}) > 0;
                                  }),
                   out.fields.end());
  return true;
}

bool extractHidBits(const uint8_t* data, size_t sizeBytes, uint32_t bitOffset, uint32_t bitSize, bool isSigned,
                    int64_t& value) {
  if (bitSize == 0 || bitSize > 32) return false;
  if (uint64_t(bitOffset) + bitSize > uint64_t(sizeBytes) * 8) return false;
  uint64_t raw = 0;
  for (uint32_t i = 0; i < bitSize; ++i) {
    const uint32_t bit = bitOffset + i;
    raw |= uint64_t((data[bit / 8] >> (bit % 8)) & 1u) << i;
  }
  if (isSigned && (raw >> (bitSize - 1)) & 1u) {
    value = static_cast<int64_t>(raw) - (int64_t(1) << bitSize);
  } else {
    value = static_cast<int64_t>(raw);
  }
  return true;
}

}  // namespace kf

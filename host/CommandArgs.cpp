#include "CommandArgs.hpp"

#include <cmath>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstring>

#include "core/PrintfFormat.hpp"
namespace kf::sc {

namespace {

uint32_t bigEndian32(const char* at) {
  uint32_t value = 0;
  for (int i = 0; i < 4; ++i) value = value << 8 | static_cast<uint8_t>(at[i]);
  return value;
}

uint64_t bigEndian64(const char* at) { return uint64_t(bigEndian32(at)) << 32 | bigEndian32(at + 4); }

bool fail(char* error, size_t errorSize, const char* format, ...) KF_PRINTF_FORMAT(3, 4);
bool fail(char* error, size_t errorSize, const char* format, ...) {
  va_list args;
  va_start(args, format);
  std::vsnprintf(error, errorSize, format, args);
  va_end(args);
  return false;
}

// NaN without the sign printf would show ("-nan").
double shown(double value) { return std::isnan(value) ? std::fabs(value) : value; }

// A whole number in [min, max], finite.
bool isWholeIn(double value, double min, double max) {
  return std::isfinite(value) && value >= min && value <= max && value == std::floor(value);
}

}  // namespace

OscArgReader::OscArgReader(const char* tags, const char* tagsLimit, const char* data, const char* end)
    : tags_(tags), data_(data), end_(end) {
  if (data_ == nullptr || end_ == nullptr || data_ > end_) {
    malformed_ = true;
    return;
  }
  if (tags_ != nullptr && (tagsLimit == nullptr || tags_ >= tagsLimit ||
                           std::memchr(tags_, '\0', static_cast<size_t>(tagsLimit - tags_)) == nullptr))
    malformed_ = true;
}

OscArgReader OscArgReader::fromMessage(const char* bytes, size_t size) {
  const char* end = bytes + size;
  if (size == 0 || bytes[0] != ',') return OscArgReader(nullptr, nullptr, nullptr, nullptr);
  const void* zero = std::memchr(bytes, '\0', size);
  if (zero == nullptr) return OscArgReader(nullptr, nullptr, nullptr, nullptr);
  const size_t tagBytes = static_cast<size_t>(static_cast<const char*>(zero) - bytes) + 1;
  const size_t padded = (tagBytes + 3) & ~size_t(3);
  const char* data = padded <= size ? bytes + padded : end;
  return OscArgReader(bytes + 1, end, data, end);
}

bool OscArgReader::take(size_t bytes, const char*& at) {
  if (static_cast<size_t>(end_ - data_) < bytes) {
    malformed_ = true;
    return false;
  }
  at = data_;
  data_ += bytes;
  ++tags_;
  ++position_;
  return true;
}

bool OscArgReader::readNumber(double& value) {
  const char tag = nextTag();
  const char* at = nullptr;
  if (tag == 'i' || tag == 'f') {
    if (static_cast<size_t>(end_ - data_) < 4) return malformed_ = true, false;
    const uint32_t bits = bigEndian32(data_);
    if (tag == 'i') {
      value = static_cast<int32_t>(bits);
    } else {
      float f;
      std::memcpy(&f, &bits, 4);
      value = f;
    }
    return take(4, at);
  }
  if (tag == 'h' || tag == 'd') {
    if (static_cast<size_t>(end_ - data_) < 8) return malformed_ = true, false;
    const uint64_t bits = bigEndian64(data_);
    if (tag == 'h') {
      value = static_cast<double>(static_cast<int64_t>(bits));
    } else {
      std::memcpy(&value, &bits, 8);
    }
    return take(8, at);
  }
  return false;
}

bool OscArgReader::readString(const char*& text, size_t& length) {
  const char tag = nextTag();
  if (tag != 's' && tag != 'S') return false;
  const size_t available = static_cast<size_t>(end_ - data_);
  const void* zero = std::memchr(data_, '\0', available);
  if (zero == nullptr) return malformed_ = true, false;  // cut inside the string
  length = static_cast<size_t>(static_cast<const char*>(zero) - data_);
  const size_t padded = (length + 4) & ~size_t(3);
  text = data_;
  const char* at = nullptr;
  if (padded > available) {  // terminator present but its padding cut: accept up to the end
    data_ = end_;
    ++tags_;
    ++position_;
    return true;
  }
  return take(padded, at);
}

bool OscArgReader::skip() {
  double number = 0.0;
  const char* text = nullptr;
  size_t length = 0;
  const char* at = nullptr;
  switch (nextTag()) {
    case 'i':
    case 'f':
    case 'h':
    case 'd':
      return readNumber(number);
    case 's':
    case 'S':
      return readString(text, length);
    case 'c':
    case 'r':
    case 'm':
      return take(4, at);
    case 't':
      return take(8, at);
    case 'T':
    case 'F':
    case 'N':
    case 'I':
      return take(0, at);
    case 'b': {
      if (static_cast<size_t>(end_ - data_) < 4) return malformed_ = true, false;
      const uint32_t size = bigEndian32(data_);
      const size_t padded = (static_cast<size_t>(size) + 3) & ~size_t(3);
      if (padded > static_cast<size_t>(end_ - data_) - 4) return malformed_ = true, false;
      return take(4 + padded, at);
    }
    default:
      return false;
  }
}

namespace {

const char* describe(OscArgReader& args) {
  if (args.isMalformed()) return "the message is cut short or malformed";
  if (args.atEnd()) return "missing";
  switch (args.nextTag()) {
    case 's':
    case 'S':
      return "a string, not a number";
    case 'b':
      return "a blob";
    case 'i':
    case 'f':
    case 'h':
    case 'd':
      return "a number, not a string";
    default:
      return "of an unsupported type";
  }
}

bool readIndex(OscArgReader& args, int numSlots, CommandArgs& out, char* error, size_t errorSize) {
  double value = 0.0;
  if (!args.readNumber(value)) return fail(error, errorSize, "device index: %s", describe(args));
  if (!isWholeIn(value, 0.0, numSlots - 1.0))
    return fail(error, errorSize, "device index %g is not a slot number 0..%d", shown(value), numSlots - 1);
  out.index = static_cast<int>(value);
  return true;
}

// A string argument into `to` (capacity chars with the terminator); `what` names it in errors.
bool readText(OscArgReader& args, char* to, size_t capacity, const char* what, char* error, size_t errorSize) {
  const char* text = nullptr;
  size_t length = 0;
  if (!args.readString(text, length)) return fail(error, errorSize, "%s: %s", what, describe(args));
  if (length >= capacity)
    return fail(error, errorSize, "%s of %zu characters is longer than %zu", what, length, capacity - 1);
  std::memcpy(to, text, length);
  to[length] = '\0';
  return true;
}

// A whole number within [min, max] into `to`; `what` names it in errors.
bool readWhole(OscArgReader& args, double min, double max, const char* what, double& to, char* error,
               size_t errorSize) {
  if (!args.readNumber(to)) return fail(error, errorSize, "%s: %s", what, describe(args));
  if (!isWholeIn(to, min, max))
    return fail(error, errorSize, "%s %g is not a whole number %g..%g", what, shown(to), min, max);
  return true;
}

bool readPath(OscArgReader& args, CommandArgs& out, char* error, size_t errorSize) {
  return readText(args, out.path, kMaxPathChars, "path", error, errorSize);
}

bool readOverrides(OscArgReader& args, CommandArgs& out, char* error, size_t errorSize) {
  while (!args.atEnd()) {
    const char* key = nullptr;
    size_t length = 0;
    if (!args.readString(key, length))
      return fail(error, errorSize, "argument %d: a setting name was expected, it is %s", args.position() + 1,
                  describe(args));
    if (out.numOverrides == kMaxOverrides) return fail(error, errorSize, "more than %d settings", kMaxOverrides);
    if (length == 0) return fail(error, errorSize, "argument %d: a setting name is empty", args.position());
    if (length >= static_cast<size_t>(kMaxKeyChars))
      return fail(error, errorSize, "setting name of %zu characters is longer than %d", length, kMaxKeyChars - 1);
    double value = 0.0;
    if (!args.readNumber(value))
      return fail(error, errorSize, "setting '%.*s' has no numeric value (%s)", static_cast<int>(length), key,
                  describe(args));
    std::memcpy(out.keys[out.numOverrides], key, length);
    out.keys[out.numOverrides][length] = '\0';
    out.overrideValues[out.numOverrides++] = value;  // its range is checked by the setting's bounds
  }
  return !args.isMalformed() || fail(error, errorSize, "the message is cut short or malformed");
}

bool noneLeft(OscArgReader& args, char* error, size_t errorSize) {
  if (args.isMalformed()) return fail(error, errorSize, "the message is cut short or malformed");
  if (!args.atEnd()) return fail(error, errorSize, "unexpected argument %d", args.position() + 1);
  return true;
}

}  // namespace

bool parseCommandArgs(CommandShape shape, OscArgReader& args, int numSlots, CommandArgs& out, ValueStorage storage,
                      void* storageContext, char* error, size_t errorSize) {
  out.index = -1;
  out.kind = -1;
  out.numValues = 0;
  out.values = nullptr;
  out.numOverrides = 0;
  out.path[0] = out.which[0] = out.backend[0] = '\0';
  if (errorSize > 0) error[0] = '\0';
  if (args.isMalformed()) return fail(error, errorSize, "the message is cut short or malformed");
  if (shape == CommandShape::kListMice)
    return readText(args, out.backend, kMaxKeyChars, "backend", error, errorSize) &&
           readPath(args, out, error, errorSize) && noneLeft(args, error, errorSize);
  if (!readIndex(args, numSlots, out, error, errorSize)) return false;
  switch (shape) {
    case CommandShape::kIndex:
      return noneLeft(args, error, errorSize);
    case CommandShape::kRecord:
      return readPath(args, out, error, errorSize) && noneLeft(args, error, errorSize);
    case CommandShape::kOpenMouse:
      return readText(args, out.which, kMaxPathChars, "mouse", error, errorSize) &&
             readText(args, out.backend, kMaxKeyChars, "backend", error, errorSize) &&
             readPath(args, out, error, errorSize) && readOverrides(args, out, error, errorSize);
    case CommandShape::kListMice:
      return true;  // read above
    case CommandShape::kBoardOpen:
      return readText(args, out.which, kMaxPathChars, "serial", error, errorSize) &&
             readWhole(args, 0.0, 1.0, "emulate", out.numbers[0], error, errorSize) &&
             readWhole(args, 1.0, 4.0, "transfers in flight", out.numbers[1], error, errorSize) &&
             noneLeft(args, error, errorSize);
    case CommandShape::kFlag:
      return readWhole(args, 0.0, 1.0, "flag", out.numbers[0], error, errorSize) && noneLeft(args, error, errorSize);
    case CommandShape::kStatus:
      out.numbers[0] = 1.0;
      return (args.atEnd() || readWhole(args, 0.0, 1.0, "post", out.numbers[0], error, errorSize)) &&
             noneLeft(args, error, errorSize);
    case CommandShape::kHeartbeat:
      out.numbers[0] = -1.0;
      if (args.atEnd()) return true;
      if (!args.readNumber(out.numbers[0])) return fail(error, errorSize, "timeoutS: %s", describe(args));
      if (!(out.numbers[0] >= 0.0 && out.numbers[0] <= 3600.0))
        return fail(error, errorSize, "timeoutS = %g is out of range 0..3600 s", shown(out.numbers[0]));
      return noneLeft(args, error, errorSize);
    case CommandShape::kPosition:
      out.positionMm[0] = out.positionMm[1] = 0.0;
      for (int axis = 0; axis < 2 && !args.atEnd(); ++axis) {
        const char* name = axis == 0 ? "xMm" : "yMm";
        if (!args.readNumber(out.positionMm[axis])) return fail(error, errorSize, "%s: %s", name, describe(args));
        if (!(std::fabs(out.positionMm[axis]) <= 1e6))
          return fail(error, errorSize, "%s = %g is out of range -1e6..1e6 mm", name, shown(out.positionMm[axis]));
      }
      return noneLeft(args, error, errorSize);
    case CommandShape::kOpenReplay:
      if (!readPath(args, out, error, errorSize)) return false;
      if (out.path[0] == '\0') return fail(error, errorSize, "path: empty");
      return readOverrides(args, out, error, errorSize);
    case CommandShape::kOpenSim: {
      double kind = 0.0, count = 0.0;
      if (!args.readNumber(kind)) return fail(error, errorSize, "hand script kind: %s", describe(args));
      if (!isWholeIn(kind, -1.0, 7.0))
        return fail(error, errorSize,
                    "hand script kind %g is not -1 (none), 0 (path), 1 (speeds), 2 (force), 3 (path2D), 4 (line), "
                    "5 (circle), 6 (raster) or 7 (explore)",
                    shown(kind));
      if (!args.readNumber(count)) return fail(error, errorSize, "hand script value count: %s", describe(args));
      if (!isWholeIn(count, 0.0, kMaxHandValues))
        return fail(error, errorSize, "hand script value count %g is out of range 0..%d", shown(count), kMaxHandValues);
      out.kind = static_cast<int>(kind);
      const int wanted = static_cast<int>(count);
      if ((out.kind == 0 || out.kind == 1) && wanted % 2 != 0)
        return fail(error, errorSize, "hand script of %d values: pairs expected", wanted);
      if (out.kind == -1 && wanted != 0) return fail(error, errorSize, "no hand script (kind -1) takes no values");
      if (out.kind == 2 && wanted != 1)
        return fail(error, errorSize, "a force hand script takes 1 value, not %d", wanted);
      if (out.kind == 3 && wanted % 3 != 0)
        return fail(error, errorSize, "a path2D hand script of %d values: triples expected", wanted);
      if ((out.kind == 4 || out.kind == 5) && wanted != 5)
        return fail(error, errorSize, "a line or circle hand script takes 5 values, not %d", wanted);
      if (out.kind == 6 && wanted != 6)
        return fail(error, errorSize, "a raster hand script takes 6 values, not %d", wanted);
      if (out.kind == 7 && wanted != 9)
        return fail(error, errorSize, "an explore hand script takes 9 values, not %d", wanted);
      if (wanted > 0) {
        out.values = storage(storageContext, wanted);
        if (out.values == nullptr) return fail(error, errorSize, "RT memory allocation failed for the hand script");
      }
      for (; out.numValues < wanted; ++out.numValues) {
        if (!args.readNumber(out.values[out.numValues]))
          return fail(error, errorSize, "hand script value %d of %d: %s (the count is larger than the values sent)",
                      out.numValues + 1, wanted, describe(args));
      }
      return readOverrides(args, out, error, errorSize);
    }
  }
  return fail(error, errorSize, "unknown command shape");
}

}  // namespace kf::sc

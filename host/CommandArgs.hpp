// CommandArgs: the arguments of the device plugin commands, read from the raw OSC message
// with every bound checked before a byte is read — type tags, counts, string terminators,
// the end of the packet — and every value checked (finite, whole, in range) with one clear
// message per problem. Pure C++ with no SC headers and no allocation, so it runs in the RT
// stage of a command and in the fuzzer (tests/fuzz/fuzz_command_args.cpp).
#pragma once

#include <cstddef>

namespace kf::sc {

constexpr int kMaxHandValues = 8192;
constexpr int kMaxOverrides = 32;
constexpr int kMaxKeyChars = 48;     // with the terminating zero
constexpr int kMaxPathChars = 1024;  // with the terminating zero: PATH_MAX is refused clearly

// Arguments of one OSC message after the command name.
class OscArgReader {
 public:
  // tags: the type tags of the remaining arguments (no ','), a zero-terminated string that
  // must end before tagsLimit; data .. end: their bytes. tags null: an untyped message.
  OscArgReader(const char* tags, const char* tagsLimit, const char* data, const char* end);
  // The arguments of an OSC message body from its type tag string on: ",tags\0" padded to 4
  // bytes, then the argument data; malformed if the tags do not end within `size`.
  static OscArgReader fromMessage(const char* bytes, size_t size);

  bool isMalformed() const { return malformed_; }  // tags unterminated or data past the end
  bool atEnd() const { return malformed_ || tags_ == nullptr || *tags_ == '\0'; }
  char nextTag() const { return atEnd() ? '\0' : *tags_; }
  int position() const { return position_; }  // 0-based index of the next argument

  // An int32, int64, float or double as a double; false (nothing consumed) if the next
  // argument is missing, of another type or runs past the end.
  bool readNumber(double& value);
  // A string (or symbol) and its length; false if missing, another type, or its terminator
  // is not within the message.
  bool readString(const char*& text, size_t& length);
  // Skips one argument of any standard type; false when it cannot.
  bool skip();

 private:
  bool take(size_t bytes, const char*& at);

  const char* tags_;
  const char* data_;
  const char* end_;
  bool malformed_ = false;
  int position_ = 0;
};

enum class CommandShape {
  kIndex,       // kfClose: index
  kStatus,      // kfStatus: index [post(0/1), 1 by default]
  kOpenSim,     // index kind count values... [key value]...
  kOpenReplay,  // index path [key value]...
  kRecord,      // index path ("" stops)
  kPosition,    // kfZero: index [xMm yMm]
  kOpenMouse,   // index which backend profilePath [key value]...
  kListMice,    // backend answerPath (no index)
  kBoardOpen,   // index serial emulate(0/1) inFlight(1..4)
  kFlag,        // index flag(0/1)
  kHeartbeat,   // kfHeartbeat: index [timeoutS (0 no watch, up to 3600)]
};

struct CommandArgs {
  int index = -1;
  int kind = -1;
  int numValues = 0;
  double* values = nullptr;  // numValues values in storage from the ValueStorage callback
  int numOverrides = 0;
  char keys[kMaxOverrides][kMaxKeyChars];
  double overrideValues[kMaxOverrides];
  char path[kMaxPathChars];
  double positionMm[2] = {0.0, 0.0};  // kPosition: x, y
  char which[kMaxPathChars];          // kOpenMouse: the mouse selector ("" the first)
  char backend[kMaxKeyChars];         // kOpenMouse, kListMice: "hidapi", "evdev" ("" default)
  double numbers[2] = {0.0, 0.0};     // kBoardOpen: emulate, inFlight; kFlag, kStatus: the flag;
                                      // kHeartbeat: the timeout (-1 when not given)
};

// Storage for `count` hand script values (RTAlloc in the plugin); null: out of memory.
using ValueStorage = double* (*)(void* context, int count);

// Reads a whole command. False with a message in error (of errorSize chars): a missing,
// wrong-typed, non-finite, fractional or out-of-range index (0 .. numSlots - 1), kind or
// count; fewer values than the count; an unterminated or too long path or key; a key
// without a numeric value; more than kMaxOverrides settings; arguments left over.
// On false, values already obtained from `storage` are in out.values (the caller frees).
bool parseCommandArgs(CommandShape shape, OscArgReader& args, int numSlots, CommandArgs& out, ValueStorage storage,
                      void* storageContext, char* error, size_t errorSize);

}  // namespace kf::sc

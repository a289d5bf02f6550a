#include "board/gadget/GadgetLog.hpp"

#include <algorithm>
#include <cinttypes>
#include <cstdio>

namespace kf::board::gadget {

GadgetLog::GadgetLog(size_t capacity) : records_(capacity) {}

void GadgetLog::add(const Record& record) {
  if (used_ < records_.size())
    records_[used_++] = record;
  else
    ++dropped_;
}

void GadgetLog::frame(int64_t timeNs, int bytes, uint16_t sequence, uint16_t drive, Verdict verdict,
                      uint64_t validFrames) {
  add({timeNs, 0, nullptr, static_cast<uint32_t>(validFrames), sequence, drive, static_cast<uint8_t>(bytes),
       Kind::kFrame, static_cast<uint8_t>(verdict)});
}

void GadgetLog::level(int64_t timeNs, int index, uint16_t drive) {
  add({timeNs, 0, nullptr, 0, drive, 0, static_cast<uint8_t>(index), Kind::kLevel, 0});
}

void GadgetLog::target(int64_t timeNs, uint16_t drive, const char* why) {
  add({timeNs, 0, why, 0, drive, 0, 0, Kind::kTarget, 0});
}

void GadgetLog::control(int64_t timeNs, uint8_t request, uint16_t value, bool stalled) {
  add({timeNs, 0, nullptr, 0, value, 0, request, Kind::kControl, static_cast<uint8_t>(stalled)});
}

void GadgetLog::event(int64_t timeNs, const char* name) { add({timeNs, 0, name, 0, 0, 0, 0, Kind::kEvent, 0}); }

void GadgetLog::statusTaken(int64_t timeNs, int64_t builtNs, uint16_t lastSequence, uint16_t framesReceived) {
  add({timeNs, builtNs, nullptr, 0, lastSequence, framesReceived, 0, Kind::kStatus, 0});
}

void GadgetLog::tick(int64_t lateNs, uint64_t missed) {
  ++ticks_;
  missedTicks_ += missed;
  maxLateNs_ = std::max(maxLateNs_, lateNs);
}

void GadgetLog::statusReplaced(int64_t cancelNs) {
  ++statusReplaced_;
  maxCancelNs_ = std::max(maxCancelNs_, cancelNs);
}

long GadgetLog::report(const std::string& path) {
  std::FILE* out = std::fopen(path.c_str(), "w");
  if (out == nullptr) return -1;
  static const char* const kVerdicts[] = {"applied", "stale", "bad"};
  long frames = 0;
  for (size_t i = 0; i < used_; ++i) {
    const Record& r = records_[i];
    switch (r.kind) {
      case Kind::kFrame:
        std::fprintf(out, "frame %" PRId64 " %u %u %u %s %u\n", r.timeNs, r.c, r.a, r.b, kVerdicts[r.flag], r.count);
        ++frames;
        break;
      case Kind::kLevel:
        std::fprintf(out, "level %" PRId64 " %u %u\n", r.timeNs, r.c, r.a);
        break;
      case Kind::kTarget:
        std::fprintf(out, "target %" PRId64 " %u %s\n", r.timeNs, r.a, r.text);
        break;
      case Kind::kControl:
        std::fprintf(out, "control %" PRId64 " %u %u %s\n", r.timeNs, r.c, r.a, r.flag ? "stall" : "ok");
        break;
      case Kind::kEvent:
        std::fprintf(out, "event %" PRId64 " %s\n", r.timeNs, r.text);
        break;
      case Kind::kStatus:
        std::fprintf(out, "status %" PRId64 " %" PRId64 " %u %u\n", r.timeNs, r.otherNs, r.a, r.b);
        break;
    }
  }
  std::fprintf(out,
               "ticks %" PRIu64 " missed %" PRIu64 " late-max-ns %" PRId64 " dropped %" PRIu64 " replaced %" PRIu64
               " cancel-max-ns %" PRId64 "\n",
               ticks_, missedTicks_, maxLateNs_, dropped_, statusReplaced_, maxCancelNs_);
  const bool written = std::fclose(out) == 0;
  used_ = 0;
  dropped_ = ticks_ = missedTicks_ = statusReplaced_ = 0;
  maxLateNs_ = maxCancelNs_ = 0;
  return written ? frames : -1;
}

}  // namespace kf::board::gadget

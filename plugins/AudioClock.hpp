// Audio time of the current block, in seconds since the server started (double). In a Score
// render this is the Score's time, which lockstep devices run on.
#pragma once

#include "PluginShared.hpp"
#include "SlotTrajectory.hpp"

namespace kf::sc {

inline double blockStartTimeS(const World* world) {
  return static_cast<double>(world->mBufCounter) * world->mFullRate.mBufLength * world->mFullRate.mSampleDur;
}

inline double blockDurationS(const World* world) { return world->mFullRate.mBufLength * world->mFullRate.mSampleDur; }

// The full-rate block being computed. Audio-rate device UGens render with exactly this
// sample duration, so that all readers of a slot compute the same sample times.
inline BlockClock blockClockOf(const World* world) {
  BlockClock clock;
  clock.block = world->mBufCounter;
  clock.startS = blockStartTimeS(world);
  clock.sampleDurS = 1.0 / world->mFullRate.mSampleRate;
  clock.numSamples = world->mFullRate.mBufLength;
  return clock;
}

}  // namespace kf::sc

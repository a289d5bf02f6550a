// Audio time of the current block, in seconds since the server started (double). In a Score
// render this is the Score's time, which lockstep devices run on.
#pragma once

#include "PluginShared.hpp"
#include "SlotTrajectory.hpp"

namespace kf::sc {

// The index of the block being computed (0 for the first). scsynth counts mBufCounter up after
// a block, supernova before it (run_scheduler_tick: ++mBufCounter, then the tick), so under
// supernova the block being computed is mBufCounter - 1. Read as mBufCounter, every audio time
// of the plugin ran a block (1.33 ms at 64/48 kHz) ahead of the samples' own: the force framer's
// 1 ms grid lay 32 samples off the output's, and a 50 Hz square framed into 0.4 and 0.6 N
// frames between its 0.2 and 0.8 N ones (tests/scenes/test_device_nrt.py).
inline int64_t blockIndexOf(const World* world) {
#ifdef SUPERNOVA
  return static_cast<int64_t>(world->mBufCounter) - 1;
#else
  return world->mBufCounter;
#endif
}

inline double blockStartTimeS(const World* world) {
  return static_cast<double>(blockIndexOf(world)) * world->mFullRate.mBufLength * world->mFullRate.mSampleDur;
}

inline double blockDurationS(const World* world) { return world->mFullRate.mBufLength * world->mFullRate.mSampleDur; }

// The full-rate block being computed. Audio-rate device UGens render with exactly this
// sample duration, so that all readers of a slot compute the same sample times.
inline BlockClock blockClockOf(const World* world) {
  BlockClock clock;
  clock.block = blockIndexOf(world);
  clock.startS = blockStartTimeS(world);
  clock.sampleDurS = 1.0 / world->mFullRate.mSampleRate;
  clock.numSamples = world->mFullRate.mBufLength;
  return clock;
}

}  // namespace kf::sc

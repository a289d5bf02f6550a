// Audio time of the current block, in seconds since the server started (double). In a Score
// render this is the Score's time, which lockstep devices run on.
#pragma once

#include "PluginShared.hpp"

namespace kf::sc {

inline double blockStartTimeS(const World* world) {
  return static_cast<double>(world->mBufCounter) * world->mFullRate.mBufLength * world->mFullRate.mSampleDur;
}

inline double blockDurationS(const World* world) { return world->mFullRate.mBufLength * world->mFullRate.mSampleDur; }

}  // namespace kf::sc

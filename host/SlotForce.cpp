#include "SlotForce.hpp"

namespace kf::sc {

void SlotForce::reset(const DeviceSpec& spec) {
  minForceN_ = spec.minForceN;
  framer_ = ForceFramer(spec.forceFramePeriodS, spec.minForceN, spec.maxForceN,
                        frame_filter::forPeriod(spec.forceFramePeriodS));
  arrived_ = 0;
  open_ = false;
  framedBlock_ = -1;
  combinedBlock_[0] = combinedBlock_[1] = -1;
}

void SlotForce::begin(const BlockClock& clock) {
  block_ = clock;
  arrived_ = 0;
  open_ = true;
  std::fill_n(excessN_, std::min(clock.numSamples, kMaxBlockSamples), 0.0);
}

}  // namespace kf::sc

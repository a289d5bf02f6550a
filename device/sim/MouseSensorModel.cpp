#include "sim/MouseSensorModel.hpp"

#include <algorithm>
#include <cmath>

namespace kf {

MouseSensorModel::MouseSensorModel(const DeviceSpec& spec, const SimParams& params, double initialPositionMm)
    : spec_(spec),
      params_(params),
      random_(params.seed),
      lastQuantumCounts_(static_cast<int64_t>(std::floor(initialPositionMm / spec.countMm))) {
  scheduleNext();
}

void MouseSensorModel::scheduleNext() {
  ++reportIndex_;
  const double periodS = spec_.updatePeriodS();
  double offsetS = 0.0;
  if (params_.reportJitterS > 0.0) {
    // Clipped so reports never change order.
    const double limitS = 0.45 * periodS;
    offsetS = std::clamp(params_.reportJitterS * random_.gaussian(), -limitS, limitS);
  }
  nextReportTimeS_ = static_cast<double>(reportIndex_) * periodS + offsetS;
}

bool MouseSensorModel::isLifted(double timeS) const {
  for (const auto& [startS, endS] : params_.liftIntervalsS)
    if (timeS >= startS && timeS < endS) return true;
  return false;
}

bool MouseSensorModel::takeReport(double xMm, double yMm, MouseReport& out) {
  const double trueTimeS = nextReportTimeS_;
  const bool lifted = isLifted(trueTimeS);
  uint32_t flags = lifted ? kLifted : 0u;
  // Counts since the last report along one axis. The sensor's reference follows the surface even
  // when counts are clipped or lifted: what does not fit into a report is lost, as in real sensors.
  auto counts = [&](double positionMm, int64_t& lastQuantum) {
    const int64_t quantum = static_cast<int64_t>(std::floor(positionMm / spec_.countMm));
    int64_t delta = lifted ? 0 : quantum - lastQuantum;
    lastQuantum = quantum;
    const int64_t limit = spec_.maxCountsPerReport;
    if (delta > limit || delta < -limit) {
      delta = std::clamp(delta, -limit, limit);
      flags |= kSaturated;
    }
    return delta;
  };
  const int64_t deltaCounts = counts(xMm, lastQuantumCounts_);
  const int64_t deltaYCounts = counts(yMm, lastQuantumYCounts_);
  const bool dropped = params_.dropProbability > 0.0 && random_.uniform() < params_.dropProbability;
  scheduleNext();

  pendingDxCounts_ += static_cast<int32_t>(deltaCounts);
  pendingDyCounts_ += static_cast<int32_t>(deltaYCounts);
  pendingFlags_ |= flags;
  if (dropped) {
    ++droppedReports_;
    pendingFlags_ |= kAfterLoss;
    return false;
  }
  out.deviceTimeS = trueTimeS * (1.0 + params_.clockDriftPpm * 1e-6);
  out.dxCounts = pendingDxCounts_;
  out.dyCounts = pendingDyCounts_;
  out.buttons = 0;
  out.flags = pendingFlags_;
  pendingDxCounts_ = 0;
  pendingDyCounts_ = 0;
  pendingFlags_ = 0;
  return true;
}

}  // namespace kf

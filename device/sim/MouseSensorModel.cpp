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

bool MouseSensorModel::takeReport(double positionMm, MouseReport& out) {
  const double trueTimeS = nextReportTimeS_;
  const int64_t quantum = static_cast<int64_t>(std::floor(positionMm / spec_.countMm));
  int64_t deltaCounts = quantum - lastQuantumCounts_;
  // The sensor's reference follows the surface even when counts are clipped or lifted:
  // what does not fit into a report is lost, as in real sensors.
  lastQuantumCounts_ = quantum;
  uint32_t flags = 0;
  if (isLifted(trueTimeS)) {
    deltaCounts = 0;
    flags |= kLifted;
  }
  const int64_t limit = spec_.maxCountsPerReport;
  if (deltaCounts > limit || deltaCounts < -limit) {
    deltaCounts = std::clamp(deltaCounts, -limit, limit);
    flags |= kSaturated;
  }
  const bool dropped = params_.dropProbability > 0.0 && random_.uniform() < params_.dropProbability;
  scheduleNext();

  pendingDxCounts_ += static_cast<int32_t>(deltaCounts);
  pendingFlags_ |= flags;
  if (dropped) {
    ++droppedReports_;
    pendingFlags_ |= kAfterLoss;
    return false;
  }
  out.deviceTimeS = trueTimeS * (1.0 + params_.clockDriftPpm * 1e-6);
  out.dxCounts = pendingDxCounts_;
  out.dyCounts = 0;
  out.buttons = 0;
  out.flags = pendingFlags_;
  pendingDxCounts_ = 0;
  pendingFlags_ = 0;
  return true;
}

}  // namespace kf

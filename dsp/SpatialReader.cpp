#include "SpatialReader.hpp"

namespace kf {

Interpolation interpolationFromCode(int code) {
  if (code == 1) return Interpolation::None;
  if (code == 2) return Interpolation::Linear;
  return Interpolation::Cubic;
}

}  // namespace kf

#include "SurfaceReader.hpp"

namespace kf {

namespace {

// Sample (column, row) of the zero-padded matrix.
inline float at(const SurfaceView& s, int64_t column, int64_t row) {
  if (column < 0 || column >= s.width || row < 0 || row >= s.height) return 0.f;
  return s.data[row * s.width + column];
}

// Row `row` of the padded matrix read along x at whole part i, fraction f.
inline float alongRow(const SurfaceView& s, int64_t row, int64_t i, float f, Interpolation interpolation) {
  if (interpolation == Interpolation::Linear) {
    const float y1 = at(s, i, row), y2 = at(s, i + 1, row);
    return y1 + f * (y2 - y1);
  }
  if (row >= 0 && row < s.height && i >= 1 && i + 2 < s.width) {  // all four taps inside
    const float* q = s.data + row * s.width + i - 1;
    return cubicHermite(f, q[0], q[1], q[2], q[3]);
  }
  return cubicHermite(f, at(s, i - 1, row), at(s, i, row), at(s, i + 1, row), at(s, i + 2, row));
}

}  // namespace

float readSurface(const SurfaceView& s, double column, double row, Interpolation interpolation) {
  if (s.data == nullptr || s.width <= 0 || s.height <= 0) return 0.f;
  // Outside (-1, size) in either axis every tap is a padded zero; this also rejects NaN and
  // +-Inf, and keeps the integer conversions in range.
  if (!(column > -1.0 && column < static_cast<double>(s.width))) return 0.f;
  if (!(row > -1.0 && row < static_cast<double>(s.height))) return 0.f;
  const int64_t i = detail::floorAboveMinusOne(column);
  const int64_t j = detail::floorAboveMinusOne(row);
  const float fx = static_cast<float>(column - static_cast<double>(i));
  const float fy = static_cast<float>(row - static_cast<double>(j));
  switch (interpolation) {
    case Interpolation::None:
      return at(s, i, j);
    case Interpolation::Linear: {
      const float r1 = alongRow(s, j, i, fx, interpolation), r2 = alongRow(s, j + 1, i, fx, interpolation);
      return r1 + fy * (r2 - r1);
    }
    case Interpolation::Cubic:
    default:
      return cubicHermite(fy, alongRow(s, j - 1, i, fx, Interpolation::Cubic),
                          alongRow(s, j, i, fx, Interpolation::Cubic), alongRow(s, j + 1, i, fx, Interpolation::Cubic),
                          alongRow(s, j + 2, i, fx, Interpolation::Cubic));
  }
}

void readSurfaceBlock(const SurfaceView& s, const float* xMm, int xStride, const float* yMm, int yStride,
                      const SurfaceLayout& layout, Interpolation interpolation, float* out, int numSamples) {
  for (int k = 0; k < numSamples; ++k) {
    const double column = spatialIndex(xMm[k * xStride], layout.originXMm, layout.samplesPerMmX);
    const double row = spatialIndex(yMm[k * yStride], layout.originYMm, layout.samplesPerMmY);
    out[k] = readSurface(s, column, row, interpolation);
  }
}

}  // namespace kf

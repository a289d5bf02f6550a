// Reads a 2D surface: a matrix of `width` columns and `height` rows stored row-major (row after
// row, as Buffer.loadCollection(matrix.flat) leaves it in a mono buffer), read at (x, y) mm.
// Column index = (x - originX) * samplesPerMmX, row index = (y - originY) * samplesPerMmY, each
// in double as SpatialReader's index (spatialIndex), so a position far from the origin stays
// exact. The edges are SpatialReader's in each axis: the matrix is taken as zero outside its
// samples, the interpolators fade it in and out at the borders, and the output is exactly 0
// once either index is a whole sample or more outside [0, size - 1]. Interpolation: none (the
// sample at the floor of both indices), linear (bilinear), cubic (bicubic: SpatialReader's
// 4-point Hermite along x on four rows, then along y).
#pragma once

#include <cstdint>

#include "SpatialReader.hpp"

namespace kf {

struct SurfaceView {
  const float* data = nullptr;
  int64_t width = 0;   // columns, along x
  int64_t height = 0;  // rows, along y
};

// The layout of a surface on the table: indices = (position - origin) * samplesPerMm per axis.
struct SurfaceLayout {
  double originXMm = 0.0;
  double originYMm = 0.0;
  double samplesPerMmX = 1.0;
  double samplesPerMmY = 1.0;
};

// The surface at fractional (column, row) indices: 0 for a NaN/Inf index, an empty surface, or an
// index at or beyond one sample outside in either axis.
float readSurface(const SurfaceView& s, double column, double row, Interpolation interpolation);

// out[i] = readSurface(s, spatialIndex(xMm[i * xStride], ...), spatialIndex(yMm[i * yStride], ...)).
// A stride is 1 for an audio-rate position, 0 for one held over the block. Each sample's
// positions are read before its output is written, so out may share memory with xMm or yMm.
void readSurfaceBlock(const SurfaceView& s, const float* xMm, int xStride, const float* yMm, int yStride,
                      const SurfaceLayout& layout, Interpolation interpolation, float* out, int numSamples);

}  // namespace kf

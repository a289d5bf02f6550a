// The 2D pattern tests' paths of the puck: positions per sample in x and y (mm, float as the
// UGen's inputs are), made of straight lines at a speed and angle.
#pragma once

#include <cmath>
#include <vector>

namespace kf::testpaths {

struct Path {
  std::vector<float> x, y;
  void append(const Path& p) {
    x.insert(x.end(), p.x.begin(), p.x.end());
    y.insert(y.end(), p.y.begin(), p.y.end());
  }
};

// A line from (x0, y0) at speed mm/s along angle (rad), for seconds, at rate samples per second.
inline Path line(double x0, double y0, double angle, double speed, double seconds, double rate) {
  Path p;
  for (int i = 0; i < static_cast<int>(seconds * rate); ++i) {
    p.x.push_back(static_cast<float>(x0 + std::cos(angle) * speed * i / rate));
    p.y.push_back(static_cast<float>(y0 + std::sin(angle) * speed * i / rate));
  }
  return p;
}

}  // namespace kf::testpaths

// The buffer a bufnum input names, global or local to the synth, for the spatial readers. As
// GET_BUF does, the SndBuf is found again only when bufnum changes: its slot stays put, and a
// freed or reallocated buffer shows in its fields at once.
#pragma once

#include <SC_PlugIn.hpp>

namespace kf::sc {

class BufferLookup {
 public:
  // The buffer for bufnum, or nullptr (isBad() tells a bad number from a free slot).
  const SndBuf* find(World* world, Graph* parent, float fbufnum) {
    if (fbufnum == input_) return buf_;
    input_ = fbufnum;
    buf_ = nullptr;
    // Checked as a float first: 2^32, 1e30, inf and NaN are no buffer (a cast to an integer
    // would be undefined, and read buffer 0).
    const double numBufs = static_cast<double>(world->mNumSndBufs) + parent->localBufNum;
    bad_ = !(fbufnum >= 0.f) || !(static_cast<double>(fbufnum) < numBufs);
    if (bad_) return nullptr;
    const auto bufnum = static_cast<uint32>(fbufnum);
    bufnum_ = static_cast<int>(bufnum);
    buf_ =
        bufnum < world->mNumSndBufs ? world->mSndBufs + bufnum : parent->mLocalSndBufs + (bufnum - world->mNumSndBufs);
    return buf_;
  }
  bool isBad() const { return bad_; }
  float input() const { return input_; }
  int bufnum() const { return bufnum_; }

 private:
  float input_ = -1e9f;  // the bufnum input buf_ was found for
  const SndBuf* buf_ = nullptr;
  int bufnum_ = -1;
  bool bad_ = false;
};

}  // namespace kf::sc

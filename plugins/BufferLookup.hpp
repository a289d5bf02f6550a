// The buffer a bufnum input names, global or local to the synth, for the spatial readers, and
// which of its problems to post. As
// GET_BUF does, the SndBuf is found again only when bufnum changes: its slot stays put, and a
// freed or reallocated buffer shows in its fields at once.
#pragma once

#include <SC_PlugIn.hpp>

#include <cstdio>

#include "AudioClock.hpp"
#include "PostLimiter.hpp"

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

// Which buffer problem of a reader to post: one message per change of problem, and per kind at
// most one a second (a buffer reallocated 300 times a second posts a line, not hundreds); none
// when the server runs quiet (verbosity -2 and below, as for SC's own buffer UGens). Problems are
// numbered 1..kKinds-1, 0 is none.
template <int kKinds>
class BufferProblemPosts {
 public:
  // True when `problem` is to be posted now; `more` then says how many like it were held back.
  bool shouldPost(World* world, int problem, char (&more)[64]) {
    more[0] = '\0';
    if (problem == current_) return false;
    current_ = problem;
    if (problem <= 0 || problem >= kKinds || world->mVerbosity <= -2) return false;
    int heldBack = 0;
    if (!limits_[problem].allow(blockStartTimeS(world), heldBack)) return false;
    if (heldBack > 0) std::snprintf(more, sizeof more, " (%d more like it held back)", heldBack);
    return true;
  }

 private:
  int current_ = 0;
  PostLimiter limits_[kKinds];
};

}  // namespace kf::sc

#include "Synth.hpp"

#include <stdexcept>

#include "Counting.h"

namespace kf::rules {

Unit* Synth::add(const UnitDefInfo& def, int calcRate, std::vector<Input> inputs, int numOutputs,
                 const std::string& what) {
  auto member = std::make_unique<Member>();
  member->def = &def;
  // Zeroed, as scsynth's graph memory comes: the UGen's constructor sets what it uses.
  member->memory.reset(new unsigned char[def.allocSize]());
  Unit* unit = reinterpret_cast<Unit*>(member->memory.get());
  Rate* rate = calcRate == calc_FullRate ? &world_->mFullRate : &world_->mBufRate;
  unit->mWorld = world_;
  unit->mParent = parent_;
  unit->mNumInputs = static_cast<uint32>(inputs.size());
  unit->mNumOutputs = static_cast<uint32>(numOutputs);
  unit->mCalcRate = static_cast<int16>(calcRate);
  unit->mSpecialIndex = 0;  // none of the plugin's UGens uses one (their sclang classes send 0)
  unit->mParentIndex = static_cast<int16>(members_.size());
  unit->mRate = rate;
  unit->mBufLength = rate->mBufLength;
  for (Input& input : inputs) {
    Wire* wire = input.wire != nullptr ? input.wire : newWire(input.rate, input.value);
    if (input.driver) driven_.push_back(Driven{wire, std::move(input.driver)});
    member->inputs.push_back(wire);
    member->inBufs.push_back(wire->mBuffer);
  }
  for (int i = 0; i < numOutputs; ++i) {
    Wire* wire = newWire(calcRate, 0.f);
    wire->mFromUnit = unit;
    member->outputs.push_back(wire);
    member->outBufs.push_back(wire->mBuffer);
  }
  unit->mInput = member->inputs.data();
  unit->mOutput = member->outputs.data();
  unit->mInBuf = member->inBufs.data();
  unit->mOutBuf = member->outBufs.data();
  member->label = def.name + (calcRate == calc_FullRate ? ".ar" : ".kr") + " (" + what + ") in synth '" + name_ + "'";
  member->unit = unit;
  members_.push_back(std::move(member));
  return unit;
}

Wire* Synth::out(Unit* unit, int index) const {
  for (const auto& member : members_)
    if (member->unit == unit) return member->outputs.at(static_cast<size_t>(index));
  throw std::logic_error("Synth::out: not a unit of synth " + name_);
}

Wire* Synth::newWire(int rate, float value) {
  auto wire = std::make_unique<Wire>();
  wire->mFromUnit = nullptr;  // a constant's wire, as scsynth's, has no unit
  wire->mCalcRate = rate;
  wire->mScalarValue = value;
  if (rate == calc_ScalarRate) {
    wire->mBuffer = &wire->mScalarValue;
  } else {
    const int length = rate == calc_FullRate ? world_->mFullRate.mBufLength : 1;
    buffers_.emplace_back(new float[static_cast<size_t>(length)]());
    wire->mBuffer = buffers_.back().get();
  }
  wires_.push_back(std::move(wire));
  return wires_.back().get();
}

void Synth::drive(int64_t block) {
  kf_rules_set_activity("driving inputs (the harness)", name_.c_str());
  for (Driven& driven : driven_) {
    if (driven.wire->mCalcRate == calc_FullRate) {
      const int length = world_->mFullRate.mBufLength;
      for (int i = 0; i < length; ++i) driven.wire->mBuffer[i] = driven.driver(block * length + i);
    } else {
      driven.wire->mBuffer[0] = driven.driver(block);
    }
  }
}

// As scsynth's Graph_Ctor: the inputs hold this block's values when each constructor runs (the
// Controls before them have run theirs), and the constructor sets the calculation function.
bool Synth::construct(int64_t block) {
  drive(block);
  bool allSet = true;
  for (auto& member : members_) {
    kf_rules_set_activity("ctor", member->label.c_str());
    member->unit->mCalcFunc = nullptr;
    member->def->ctor(member->unit);
    allSet = allSet && member->unit->mCalcFunc != nullptr;
  }
  return allSet;
}

void Synth::calc(int64_t block) {
  drive(block);
  for (auto& member : members_) {
    kf_rules_set_activity("calc", member->label.c_str());
    if (member->unit->mCalcFunc != nullptr) (member->unit->mCalcFunc)(member->unit, member->unit->mBufLength);
  }
  kf_rules_set_activity("watching outputs (the harness)", name_.c_str());
  for (auto& probe : probes_) probe();
}

void Synth::destruct() {
  for (auto& member : members_) {
    if (member->def->dtor == nullptr) continue;
    kf_rules_set_activity("dtor", member->label.c_str());
    member->def->dtor(member->unit);
  }
}

}  // namespace kf::rules

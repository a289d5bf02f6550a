// A synth built by hand as scsynth builds one from a SynthDef: the plugin's units in order,
// each allocated at the size its definition registered, with its wires, input and output buffers,
// rate and block length as scsynth sets them, constant inputs, inputs driven by the harness
// (a value per block at control rate, per sample at audio rate: what a Control or another
// UGen would feed) and inputs from other units' outputs. Built on the NRT thread; constructed,
// run and destructed on the audio thread (FakeServer).
#pragma once

#include <SC_Graph.h>
#include <SC_Rate.h>
#include <SC_Unit.h>
#include <SC_Wire.h>
#include <SC_World.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace kf::rules {

struct UnitDefInfo {
  std::string name;
  size_t allocSize;
  UnitCtorFunc ctor;
  UnitDtorFunc dtor;
};

// An input of a unit.
struct Input {
  // A constant of the SynthDef (scalar rate).
  static Input constant(float value) { return Input{calc_ScalarRate, value, nullptr, nullptr}; }
  // Control rate: value(block) at each block.
  static Input control(std::function<float(int64_t block)> value) {
    return Input{calc_BufRate, 0.f, std::move(value), nullptr};
  }
  // Audio rate: value(sample) for each sample since the start.
  static Input audio(std::function<float(int64_t sample)> value) {
    return Input{calc_FullRate, 0.f, std::move(value), nullptr};
  }
  // Another unit's output (Synth::out).
  static Input from(Wire* output) { return Input{output->mCalcRate, 0.f, nullptr, output}; }

  int rate;
  float value;
  std::function<float(int64_t)> driver;  // these run on the audio thread: no allocation in them
  Wire* wire;
};

class Synth {
 public:
  Synth(World* world, Graph* parent, std::string name) : world_(world), parent_(parent), name_(std::move(name)) {}
  Synth(const Synth&) = delete;
  Synth& operator=(const Synth&) = delete;

  // Adds a unit of `def` at calcRate (calc_FullRate or calc_BufRate) with its inputs and
  // numOutputs outputs; `what` says which mode it is in, for reports.
  Unit* add(const UnitDefInfo& def, int calcRate, std::vector<Input> inputs, int numOutputs, const std::string& what);
  Wire* out(Unit* unit, int index) const;
  // After each block, on the audio thread (it must not allocate): a look at the outputs.
  void watch(std::function<void()> probe) { probes_.push_back(std::move(probe)); }
  const std::string& name() const { return name_; }

  // Audio thread. construct: false if a constructor set no calculation function.
  bool construct(int64_t block);
  void calc(int64_t block);
  void destruct();

 private:
  struct Member {
    const UnitDefInfo* def;
    std::unique_ptr<unsigned char[]> memory;  // def->allocSize bytes: the Unit and the UGen's state
    Unit* unit;
    std::vector<Wire*> inputs, outputs;
    std::vector<float*> inBufs, outBufs;
    std::string label;
  };
  struct Driven {
    Wire* wire;
    std::function<float(int64_t)> driver;
  };

  Wire* newWire(int rate, float value);
  void drive(int64_t block);

  World* world_;
  Graph* parent_;
  std::string name_;
  std::vector<std::unique_ptr<Member>> members_;
  std::vector<std::unique_ptr<Wire>> wires_;
  std::vector<std::unique_ptr<float[]>> buffers_;
  std::vector<Driven> driven_;
  std::vector<std::function<void()>> probes_;
};

}  // namespace kf::rules

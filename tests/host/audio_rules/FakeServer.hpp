// FakeServer: scsynth's threads around the real plugin, for the audio-thread rules test. It
// loads the built plugin (dlopen, then its load() with an InterfaceTable of its own) and runs
// as a realtime scsynth does:
//   - the audio thread, once per block (64 samples at 48 kHz, paced by the clock): the messages
//     sent to the RT side, in order (plugin commands, which scsynth runs there; stage 3 of
//     asynchronous commands and their cleanup; synths started and freed: the units'
//     constructors and destructors), then every playing unit's calculation function;
//   - the NRT thread, which is the caller's (the test's main thread): stages 2 and 4 and every
//     message sent from the RT side, whenever it serves (serveUntil, serveBlocks, settle).
// What the harness does on the audio thread is fixed rings and a preallocated pool (RTAlloc),
// so whatever the counters (Counting.h) see there is the plugin's. Misuse of the interface (RT
// functions called off the audio thread, and the like) is collected as problems.
#pragma once

#include <SC_Graph.h>
#include <SC_InterfaceTable.h>
#include <SC_Node.h>
#include <SC_World.h>

#include <array>
#include <atomic>
#include <chrono>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "Osc.hpp"
#include "Ring.hpp"
#include "RtPool.hpp"
#include "Synth.hpp"

namespace kf::rules {

// A reply sent with SendNodeReply (/kfFail, /kfStatus, ...): its name, reply ID and values.
struct Reply {
  std::string name;
  int id;
  std::vector<float> values;
};

class FakeServer {
 public:
  static constexpr double kSampleRate = 48000.0;
  static constexpr int kBlockSamples = 64;
  static constexpr int kAudioPriority = 5;                   // SCHED_FIFO, where allowed (audioMain)
  static constexpr int kNumBuffers = 4;                      // 0 mono, 1 stereo, 2 never allocated, 3 mono
  static constexpr size_t kRtMemoryBytes = size_t{8} << 20;  // scsynth's default memSize

  // Loads the plugin (throws std::runtime_error if it cannot). One server per process.
  explicit FakeServer(const std::string& pluginPath);
  ~FakeServer();
  FakeServer(const FakeServer&) = delete;
  FakeServer& operator=(const FakeServer&) = delete;

  const UnitDefInfo& unitDef(const std::string& name) const;  // throws if the plugin has none
  std::unique_ptr<Synth> newSynth(const std::string& name) { return std::make_unique<Synth>(&world_, &graph_, name); }

  void start();
  // Frees the synths still playing, then ends the audio thread.
  void stop();

  // NRT thread. A plugin command, as /cmd: it runs on the audio thread at the next block.
  void command(const OscMessage& message);
  // Starts a synth at the next block (its constructors run there); the server owns it.
  Synth* play(std::unique_ptr<Synth> synth);
  // Ends a synth at the next block (its destructors run there); deleted afterwards.
  void free(Synth* synth);
  int numSynths() const { return static_cast<int>(synths_.size()); }
  // Serves the NRT side until `done`, for at most `timeout` (false if it never was).
  bool serveUntil(const std::function<bool()>& done, std::chrono::milliseconds timeout);
  // Serves the NRT side until the audio thread has run `count` more blocks (false if it has not
  // within `timeout`): audio time, which a loaded machine stretches, not the wall clock's.
  bool serveBlocks(int64_t count, std::chrono::milliseconds timeout);
  // Lets what is in flight between the two sides go round `rounds` times: each round the NRT
  // side serves, then the audio thread runs a whole block begun after that; then it serves once
  // more. An asynchronous command moves on one stage a round (false if a block took `timeout`).
  bool settle(int rounds, std::chrono::milliseconds timeout);

  int64_t blocks() const { return blocks_.load(); }
  bool realtime() const { return realtime_.load(); }  // the audio thread runs SCHED_FIFO
  int doneCount(const std::string& command) const;    // `/done command` replies so far
  const std::vector<Reply>& replies() const { return replies_; }
  int repliesNamed(const std::string& name) const;
  std::vector<std::string> posts() const;
  std::vector<std::string> problems() const;

 private:
  struct PlugInCmd {
    PlugInCmdFunc func;
    void* userData;
  };
  // SC_SequencedCommand's AsyncPlugInCmd, in RT memory as scsynth keeps it.
  struct AsyncCommand {
    const char* name;
    void* data;
    AsyncStageFn stage2, stage3, stage4;
    AsyncFreeFn cleanup;
    int nextStage;
    bool sendsDone;
  };
  struct CommandTask;
  struct ReplyRecord {
    char name[32];
    int id;
    int numValues;
    float values[256];
  };
  static constexpr int kMaxPlaying = 64;
  static constexpr int kMaxProblems = 64;

  void setUpWorld();
  void audioMain();
  void runMessages();
  void serveOnce();
  void problem(const char* what);  // any thread; `what` must outlive the server
  bool sendToRt(FifoMsg& message);
  bool sendFromRt(FifoMsg& message);
  void startSynth(Synth* synth);
  void endSynth(Synth* synth);
  void callNextStage(AsyncCommand* command);
  void deleteCommand(AsyncCommand* command);

  // The InterfaceTable's functions (ServerInterface.cpp).
  static InterfaceTable* interfaceTable();
  static int print(const char* format, ...);
  static bool defineUnit(const char* name, size_t allocSize, UnitCtorFunc ctor, UnitDtorFunc dtor, uint32 flags);
  static bool definePlugInCmd(const char* name, PlugInCmdFunc func, void* userData);
  static void clearUnitOutputs(Unit* unit, int numSamples);
  static void* rtAlloc(World* world, size_t size);
  static void* rtRealloc(World* world, void* pointer, size_t size);
  static void rtFree(World* world, void* pointer);
  static void sendNodeReply(Node* node, int replyId, const char* name, int numArgs, const float* values);
  static bool sendMsgFromRt(World* world, FifoMsg& message);
  static bool sendMsgToRt(World* world, FifoMsg& message);
  static int doAsynchronousCommand(World* world, void* replyAddr, const char* name, void* data, AsyncStageFn stage2,
                                   AsyncStageFn stage3, AsyncStageFn stage4, AsyncFreeFn cleanup, int completionMsgSize,
                                   void* completionMsgData);

  static FakeServer* instance_;  // the table's functions have no server argument of their own
  static thread_local bool onAudioThread_;

  void* plugin_ = nullptr;
  World world_{};
  Graph graph_{};  // the parent of every unit: its local buffer
  Node topGroup_{};
  std::array<SndBuf, kNumBuffers> buffers_{};
  std::array<SndBuf, kNumBuffers> nrtBuffers_{};
  std::array<SndBufUpdates, kNumBuffers> bufferUpdates_{};
  SndBuf localBuffer_{};
  std::vector<std::vector<float>> samples_;
  RtPool rtMemory_;
  std::map<std::string, UnitDefInfo> unitDefs_;
  std::map<std::string, PlugInCmd> commands_;
  char replyAddress_[64] = {};  // what commands get as their reply address: /done is sent

  std::thread audio_;
  std::atomic<bool> running_{false};
  std::thread::id nrtThread_;
  std::atomic<bool> audioStarted_{false};
  std::atomic<bool> realtime_{false};
  std::atomic<int64_t> blocks_{0};

  // Each message is performed on the receiving side, then freed (FifoMsg::Free) on the sending
  // side, as scsynth's MsgFifo does.
  Ring<FifoMsg, 4096> toRt_, toRtPerformed_, fromRt_, fromRtPerformed_;
  Ring<ReplyRecord, 256> replyRing_;

  // Audio thread.
  std::array<Synth*, kMaxPlaying> playing_{};
  int numPlaying_ = 0;

  // NRT thread.
  std::set<Synth*> synths_;
  std::map<std::string, int> dones_;
  std::vector<Reply> replies_;

  mutable std::mutex postsMutex_;  // Print comes from the NRT thread and from device threads
  std::vector<std::string> posts_;

  std::array<std::atomic<const char*>, kMaxProblems> problems_{};
  std::atomic<int> numProblems_{0};
};

}  // namespace kf::rules

// The server's side of the plugin interface (FakeServer.hpp): the InterfaceTable's functions
// and the asynchronous commands' stages, each as scsynth runs it and on the thread scsynth runs
// it on; what a realtime scsynth allows on one thread only is a problem on any other.
#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "Counting.h"
#include "FakeServer.hpp"

namespace kf::rules {

// --- asynchronous commands, as scsynth's SC_SequencedCommand ------------------------------------

// Stages 1 and 3 on the audio thread, 2 and 4 on the NRT thread, each hop a message; a stage
// returning false ends the command. The command is deleted (its cleanup called) on the RT side:
// after stage 4 or a false stage 2 by one more message to it, after a false stage 3 at once.
void FakeServer::callNextStage(AsyncCommand* command) {
  const bool realTime = (command->nextStage & 1) != 0;
  bool sendAgain = false;
  switch (command->nextStage) {
    case 1:  // RT: nothing, on to the NRT thread
      sendAgain = true;
      break;
    case 2:
      sendAgain = command->stage2 == nullptr || command->stage2(&world_, command->data);
      break;
    case 3:
      kf_rules_set_activity("stage 3", command->name);
      sendAgain = command->stage3 == nullptr || command->stage3(&world_, command->data);
      break;
    case 4:
      if ((command->stage4 == nullptr || command->stage4(&world_, command->data)) && command->sendsDone)
        ++dones_[command->name];  // SendDone("/done", name)
      break;
  }
  ++command->nextStage;
  FifoMsg message;
  if (sendAgain) {
    message.Set(
        &world_, [](FifoMsg* m) { instance_->callNextStage(static_cast<AsyncCommand*>(m->mData)); }, nullptr, command);
    if (realTime)
      sendFromRt(message);
    else
      sendToRt(message);
  } else if (realTime) {
    deleteCommand(command);
  } else {
    message.Set(
        &world_, [](FifoMsg* m) { instance_->deleteCommand(static_cast<AsyncCommand*>(m->mData)); }, nullptr, command);
    sendToRt(message);
  }
}

void FakeServer::deleteCommand(AsyncCommand* command) {  // RT
  kf_rules_set_activity("cleanup", command->name);
  if (command->cleanup != nullptr) command->cleanup(&world_, command->data);
  rtMemory_.release(command);
}

// --- the interface table -------------------------------------------------------------------------

int FakeServer::print(const char* format, ...) {
  if (onAudioThread_) {  // scsynth's Print is for the NRT thread: I/O on the audio thread
    kf_rules_note(kf_call_server_Print);
    return 0;
  }
  va_list args;
  va_start(args, format);
  char text[1024];
  const int length = std::vsnprintf(text, sizeof text, format, args);
  va_end(args);
  std::printf("post| %s", text);
  std::fflush(stdout);
  if (instance_ != nullptr) {
    std::lock_guard<std::mutex> lock(instance_->postsMutex_);
    instance_->posts_.emplace_back(text);
  }
  return length;
}

bool FakeServer::defineUnit(const char* name, size_t allocSize, UnitCtorFunc ctor, UnitDtorFunc dtor, uint32) {
  instance_->unitDefs_[name] = UnitDefInfo{name, allocSize, ctor, dtor};
  return true;
}

bool FakeServer::definePlugInCmd(const char* name, PlugInCmdFunc func, void* userData) {
  instance_->commands_[name] = PlugInCmd{func, userData};
  return true;
}

void FakeServer::clearUnitOutputs(Unit* unit, int numSamples) {
  for (uint32 i = 0; i < unit->mNumOutputs; ++i) std::fill_n(unit->mOutBuf[i], numSamples, 0.f);
}

// scsynth's RT pool belongs to the audio thread: another thread's use would race with it.
void* FakeServer::rtAlloc(World*, size_t size) {
  if (!onAudioThread_) {
    instance_->problem("RTAlloc off the audio thread");
    return nullptr;
  }
  return instance_->rtMemory_.allocate(size);
}

void* FakeServer::rtRealloc(World*, void* pointer, size_t size) {
  if (!onAudioThread_) {
    instance_->problem("RTRealloc off the audio thread");
    return nullptr;
  }
  return instance_->rtMemory_.reallocate(pointer, size);
}

void FakeServer::rtFree(World*, void* pointer) {
  if (!onAudioThread_) return instance_->problem("RTFree off the audio thread");
  instance_->rtMemory_.release(pointer);
}

// scsynth builds the reply in RT memory and sends it to the NRT thread: a ring here.
void FakeServer::sendNodeReply(Node*, int replyId, const char* name, int numArgs, const float* values) {
  if (!onAudioThread_) return instance_->problem("SendNodeReply off the audio thread");
  ReplyRecord record;
  std::strncpy(record.name, name, sizeof record.name - 1);
  record.name[sizeof record.name - 1] = '\0';
  record.id = replyId;
  record.numValues = std::max(0, std::min(numArgs, static_cast<int>(sizeof record.values / sizeof(float))));
  std::copy_n(values, record.numValues, record.values);
  if (!instance_->replyRing_.push(record)) instance_->problem("the ring of node replies overflowed");
}

bool FakeServer::sendMsgFromRt(World*, FifoMsg& message) { return instance_->sendFromRt(message); }

bool FakeServer::sendMsgToRt(World*, FifoMsg& message) { return instance_->sendToRt(message); }

int FakeServer::doAsynchronousCommand(World*, void* replyAddr, const char* name, void* data, AsyncStageFn stage2,
                                      AsyncStageFn stage3, AsyncStageFn stage4, AsyncFreeFn cleanup,
                                      int completionMsgSize, void*) {
  // Plugin commands run on the audio thread, and so does this (scsynth's PerformAsynchronousCommand).
  if (!onAudioThread_) instance_->problem("DoAsynchronousCommand off the audio thread");
  if (completionMsgSize > 0) instance_->problem("a completion message (the harness performs none)");
  auto* command = static_cast<AsyncCommand*>(instance_->rtMemory_.allocate(sizeof(AsyncCommand)));
  if (command == nullptr) return -1;
  *command = AsyncCommand{name, data, stage2, stage3, stage4, cleanup, 1, replyAddr != nullptr && name != nullptr};
  instance_->callNextStage(command);
  return 0;
}

// What the plugin does not use is a problem if called; the FFT and scope functions stay null.
// The table outlives the server: the plugin keeps a pointer to it until the process exits.
InterfaceTable* FakeServer::interfaceTable() {
  static InterfaceTable table = [] {
    InterfaceTable table{};
    table.fPrint = print;
    table.fRanSeed = []() -> int32 { return 12345; };
    table.fDefineUnit = defineUnit;
    table.fDefinePlugInCmd = definePlugInCmd;
    table.fDefineUnitCmd = [](const char*, const char*, UnitCmdFunc) { return true; };
    table.fDefineBufGen = [](const char*, BufGenFunc) { return true; };
    table.fClearUnitOutputs = clearUnitOutputs;
    table.fNRTAlloc = [](size_t size) { return std::malloc(size); };
    table.fNRTRealloc = [](void* pointer, size_t size) { return std::realloc(pointer, size); };
    table.fNRTFree = [](void* pointer) { std::free(pointer); };
    table.fRTAlloc = rtAlloc;
    table.fRTRealloc = rtRealloc;
    table.fRTFree = rtFree;
    table.fNodeRun = [](Node*, int) { instance_->problem("NodeRun (not in the harness)"); };
    table.fNodeEnd = [](Node*) { instance_->problem("NodeEnd (not in the harness)"); };
    table.fSendTrigger = [](Node*, int, float) { instance_->problem("SendTrigger (not in the harness)"); };
    table.fSendNodeReply = sendNodeReply;
    table.fSendMsgFromRT = sendMsgFromRt;
    table.fSendMsgToRT = sendMsgToRt;
    table.fGetNode = [](World*, int) -> Node* {
      instance_->problem("GetNode (not in the harness)");
      return nullptr;
    };
    table.fGetGraph = [](World*, int) -> Graph* {
      instance_->problem("GetGraph (not in the harness)");
      return nullptr;
    };
    table.fNRTLock = [](World*) { instance_->problem("NRTLock (not in the harness)"); };
    table.fNRTUnlock = [](World*) { instance_->problem("NRTUnlock (not in the harness)"); };
    table.fDoneAction = [](int, Unit*) { instance_->problem("DoneAction (not in the harness)"); };
    table.fDoAsynchronousCommand = doAsynchronousCommand;
    table.fBufAlloc = [](SndBuf*, int, int, double) {
      instance_->problem("BufAlloc (not in the harness)");
      return -1;
    };
    return table;
  }();
  return &table;
}

}  // namespace kf::rules

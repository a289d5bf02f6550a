#include "FakeServer.hpp"

#include <dlfcn.h>
#include <pthread.h>
#include <sc_msg_iter.h>
#include <sched.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "Counting.h"

namespace kf::rules {

FakeServer* FakeServer::instance_ = nullptr;
thread_local bool FakeServer::onAudioThread_ = false;

namespace {

constexpr double kPi = 3.14159265358979323846;

Rate rateOf(double sampleRate, int bufLength) {
  Rate rate{};
  rate.mSampleRate = sampleRate;
  rate.mSampleDur = 1.0 / sampleRate;
  rate.mBufDuration = bufLength / sampleRate;
  rate.mBufRate = sampleRate / bufLength;
  rate.mSlopeFactor = 1.0 / bufLength;
  rate.mRadiansPerSample = 2.0 * kPi / sampleRate;
  rate.mBufLength = bufLength;
  rate.mFilterLoops = bufLength / 3;
  rate.mFilterRemain = bufLength % 3;
  rate.mFilterSlope = rate.mFilterLoops > 0 ? 1.0 / rate.mFilterLoops : 0.0;
  return rate;
}

// A buffer of `frames` frames of a tone, as /b_alloc and /b_gen would leave it.
void allocate(SndBuf& buffer, std::vector<float>& samples, int channels, int frames) {
  samples.resize(static_cast<size_t>(channels) * frames);
  for (size_t i = 0; i < samples.size(); ++i) samples[i] = static_cast<float>(0.5 * std::sin(0.05 * i));
  buffer.samplerate = FakeServer::kSampleRate;
  buffer.sampledur = 1.0 / FakeServer::kSampleRate;
  buffer.data = samples.data();
  buffer.channels = channels;
  buffer.samples = channels * frames;
  buffer.frames = frames;
  buffer.mask = buffer.mask1 = 0;
  buffer.coord = 0;
  buffer.sndfile = nullptr;
}

}  // namespace

struct FakeServer::CommandTask {
  std::vector<char> bytes;
  PlugInCmd command;
  std::string name;
};

FakeServer::FakeServer(const std::string& pluginPath) : rtMemory_(kRtMemoryBytes) {
  if (instance_ != nullptr) throw std::logic_error("one FakeServer per process");
  instance_ = this;
  nrtThread_ = std::this_thread::get_id();
  setUpWorld();

  plugin_ = dlopen(pluginPath.c_str(), RTLD_NOW);
  if (plugin_ == nullptr) throw std::runtime_error(std::string("dlopen: ") + dlerror());
  auto apiVersion = reinterpret_cast<int (*)()>(dlsym(plugin_, "api_version"));
  auto serverType = reinterpret_cast<int (*)()>(dlsym(plugin_, "server_type"));
  auto load = reinterpret_cast<LoadPlugInFunc>(dlsym(plugin_, "load"));
  if (apiVersion == nullptr || load == nullptr) throw std::runtime_error(pluginPath + " is no SC plugin");
  if (apiVersion() != sc_api_version) throw std::runtime_error(pluginPath + ": another plugin API version");
  if (serverType != nullptr && serverType() != sc_server_scsynth)
    throw std::runtime_error(pluginPath + ": not scsynth's");
  load(interfaceTable());  // scsynth loads plugins on its main thread, before any audio runs
}

FakeServer::~FakeServer() {
  stop();
  instance_ = nullptr;
  // The plugin stays loaded, as in scsynth until exit: its exit hook runs then.
}

void FakeServer::setUpWorld() {
  samples_.resize(kNumBuffers + 1);
  allocate(buffers_[0], samples_[0], 1, 48000);
  allocate(buffers_[1], samples_[1], 2, 24000);
  allocate(buffers_[3], samples_[3], 1, 4096);
  allocate(localBuffer_, samples_[kNumBuffers], 1, 8192);
  nrtBuffers_ = buffers_;
  world_.ft = interfaceTable();
  world_.mSampleRate = kSampleRate;
  world_.mBufLength = kBlockSamples;
  world_.mNumSndBufs = kNumBuffers;
  world_.mSndBufs = buffers_.data();
  world_.mSndBufsNonRealTimeMirror = nrtBuffers_.data();
  world_.mSndBufUpdates = bufferUpdates_.data();
  topGroup_.mWorld = &world_;
  topGroup_.mIsGroup = 1;
  // The plugin headers do not define Group; the server's starts with its Node (SC_Group.h).
  world_.mTopGroup = reinterpret_cast<Group*>(&topGroup_);
  world_.mFullRate = rateOf(kSampleRate, kBlockSamples);
  world_.mBufRate = rateOf(kSampleRate / kBlockSamples, 1);
  world_.mRealTime = true;
  world_.mRunning = true;
  graph_.mNode.mID = 1000;
  graph_.mNode.mWorld = &world_;
  graph_.mLocalSndBufs = &localBuffer_;
  graph_.localBufNum = 1;
  graph_.localMaxBufNum = 1;
}

const UnitDefInfo& FakeServer::unitDef(const std::string& name) const {
  auto found = unitDefs_.find(name);
  if (found == unitDefs_.end()) throw std::runtime_error("the plugin defines no unit " + name);
  return found->second;
}

// --- threads ---------------------------------------------------------------------------------

void FakeServer::start() {
  running_ = true;
  audio_ = std::thread([this] { audioMain(); });
  while (!audioStarted_.load()) std::this_thread::yield();
}

void FakeServer::stop() {
  if (!audio_.joinable()) return;
  for (Synth* synth : std::set<Synth*>(synths_)) free(synth);
  serveUntil([this] { return synths_.empty(); }, std::chrono::seconds(5));
  running_ = false;
  audio_.join();
  serveOnce();
}

void FakeServer::audioMain() {
  onAudioThread_ = true;
  // SCHED_FIFO where this user may, as JACK runs a performer's scsynth's audio thread. The UGens
  // here take about 0.9 ms of CPU a 1.33 ms block: at normal priority, beside realtime work of any
  // priority (two SCHED_FIFO 1 loops here; servers started SCHED_FIFO 1 in a fresh clone, see
  // kfharness.sclang.server_program_code), it fell behind the clock by up to the 50 ms this loop
  // allows, and the reports reached the UGens that late (p50 35 and 50 ms). Below the realtime
  // tests' servers (65 and up), above every normal thread; the plugin notes this priority and runs
  // the device threads one above it, as under JACK.
  sched_param param{};
  param.sched_priority = kAudioPriority;
  realtime_ = ::pthread_setschedparam(::pthread_self(), SCHED_FIFO, &param) == 0;
  audioStarted_ = true;
  using Clock = std::chrono::steady_clock;
  const auto period =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(kBlockSamples / kSampleRate));
  Clock::time_point next = Clock::now();
  while (running_.load()) {
    kf_rules_set_audio(1);
    runMessages();
    for (int i = 0; i < numPlaying_; ++i) playing_[i]->calc(world_.mBufCounter);
    kf_rules_set_activity(nullptr, nullptr);
    kf_rules_set_audio(0);
    ++world_.mBufCounter;
    blocks_.store(world_.mBufCounter);
    // Waits for the next block's time, unmarked: the harness's own sleep is no violation. After
    // a stall of the machine, the blocks go on from now rather than in a burst.
    next += period;
    if (Clock::now() - next > std::chrono::milliseconds(50)) next = Clock::now();
    std::this_thread::sleep_until(next);
  }
}

// Audio thread, at the start of a block, as scsynth does before it runs the graph.
void FakeServer::runMessages() {
  FifoMsg message;
  kf_rules_set_activity("freeing a message the NRT thread performed", nullptr);
  while (fromRtPerformed_.pop(message)) message.Free();
  while (toRt_.pop(message)) {
    kf_rules_set_activity("a message from the NRT thread", nullptr);  // harness messages say more
    message.Perform();
    if (!toRtPerformed_.push(message)) problem("the ring of performed messages to the RT side overflowed");
  }
}

void FakeServer::serveOnce() {
  FifoMsg message;
  while (toRtPerformed_.pop(message)) message.Free();
  // The plugin's NRT work (stages 2 and 4, posts) is witnessed: its allocations and locks must
  // reach the interposers, or a clean audio thread would prove nothing.
  kf_rules_set_witness(1);
  while (fromRt_.pop(message)) {
    message.Perform();
    if (!fromRtPerformed_.push(message)) problem("the ring of performed messages from the RT side overflowed");
  }
  kf_rules_set_witness(0);
  ReplyRecord record;
  while (replyRing_.pop(record))
    replies_.push_back(
        Reply{record.name, record.id, std::vector<float>(record.values, record.values + record.numValues)});
}

bool FakeServer::serveUntil(const std::function<bool()>& done, std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (true) {
    serveOnce();
    if (done()) return true;
    if (std::chrono::steady_clock::now() >= end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

bool FakeServer::serveBlocks(int64_t count, std::chrono::milliseconds timeout) {
  const int64_t end = blocks() + count;
  return serveUntil([&] { return blocks() >= end; }, timeout);
}

bool FakeServer::settle(int rounds, std::chrono::milliseconds timeout) {
  for (int i = 0; i < rounds; ++i) {
    serveOnce();
    // The block running now may have begun before that serve; the one after it has not.
    if (!serveBlocks(2, timeout)) return false;
  }
  serveOnce();
  return true;
}

void FakeServer::problem(const char* what) {
  const int index = numProblems_.fetch_add(1);
  if (index < kMaxProblems) problems_[static_cast<size_t>(index)].store(what);
}

std::vector<std::string> FakeServer::problems() const {
  std::vector<std::string> all;
  for (int i = 0; i < std::min(numProblems_.load(), kMaxProblems); ++i) all.emplace_back(problems_[i].load());
  return all;
}

bool FakeServer::sendToRt(FifoMsg& message) {
  if (std::this_thread::get_id() != nrtThread_) problem("a message to the RT side sent off the NRT thread");
  if (toRt_.push(message)) return true;
  problem("the ring of messages to the RT side overflowed");
  return false;
}

bool FakeServer::sendFromRt(FifoMsg& message) {
  if (!onAudioThread_) problem("a message from the RT side sent off the audio thread");
  return fromRt_.push(message);  // full: refused, as scsynth's fifo refuses
}

// --- commands and synths -----------------------------------------------------------------------

void FakeServer::command(const OscMessage& message) {
  auto found = commands_.find(message.command());
  if (found == commands_.end()) throw std::runtime_error("the plugin defines no command " + message.command());
  auto* task = new CommandTask{message.bytes(), found->second, message.command()};
  FifoMsg fifo;
  fifo.Set(
      &world_,
      [](FifoMsg* m) {  // audio thread: scsynth's /cmd, PlugIn_DoCmd
        auto* task = static_cast<CommandTask*>(m->mData);
        sc_msg_iter args(static_cast<int>(task->bytes.size()), task->bytes.data());
        args.gets();  // the command's name
        kf_rules_set_activity("command", task->name.c_str());
        task->command.func(m->mWorld, task->command.userData, &args, instance_->replyAddress_);
      },
      [](FifoMsg* m) { delete static_cast<CommandTask*>(m->mData); }, task);
  sendToRt(fifo);
}

Synth* FakeServer::play(std::unique_ptr<Synth> owned) {
  Synth* synth = owned.release();
  synths_.insert(synth);
  FifoMsg fifo;
  fifo.Set(
      &world_, [](FifoMsg* m) { instance_->startSynth(static_cast<Synth*>(m->mData)); }, nullptr, synth);
  sendToRt(fifo);
  return synth;
}

void FakeServer::free(Synth* synth) {
  FifoMsg fifo;
  fifo.Set(
      &world_, [](FifoMsg* m) { instance_->endSynth(static_cast<Synth*>(m->mData)); },
      [](FifoMsg* m) {  // NRT, once the destructors have run
        auto* synth = static_cast<Synth*>(m->mData);
        instance_->synths_.erase(synth);
        delete synth;
      },
      synth);
  sendToRt(fifo);
}

void FakeServer::startSynth(Synth* synth) {
  if (!synth->construct(world_.mBufCounter)) problem("a unit's constructor set no calculation function");
  if (numPlaying_ == kMaxPlaying) return problem("more synths than the harness plays");
  playing_[static_cast<size_t>(numPlaying_++)] = synth;
}

void FakeServer::endSynth(Synth* synth) {
  for (int i = 0; i < numPlaying_; ++i) {
    if (playing_[static_cast<size_t>(i)] != synth) continue;
    playing_[static_cast<size_t>(i)] = playing_[static_cast<size_t>(--numPlaying_)];
    break;
  }
  synth->destruct();
}

int FakeServer::doneCount(const std::string& command) const {
  auto found = dones_.find(command);
  return found == dones_.end() ? 0 : found->second;
}

int FakeServer::repliesNamed(const std::string& name) const {
  int count = 0;
  for (const Reply& reply : replies_) count += reply.name == name;
  return count;
}

std::vector<std::string> FakeServer::posts() const {
  std::lock_guard<std::mutex> lock(postsMutex_);
  return posts_;
}

}  // namespace kf::rules

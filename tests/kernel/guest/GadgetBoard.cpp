#include "GadgetBoard.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "GuestSystem.hpp"

namespace kf::guest {

namespace {

constexpr const char* kGadgetName = "kf-board";
constexpr int kAnswerGuardMs = 30000;  // a hang guard for one answer, not a timing tolerance

std::string readFirstLine(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  return line;
}

void writeFile(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text << "\n";
  out.flush();
  if (!out) throw std::runtime_error("cannot write '" + text + "' to " + path);
}

}  // namespace

std::vector<GadgetFrame> GadgetReport::applied() const {
  std::vector<GadgetFrame> out;
  for (const GadgetFrame& frame : frames)
    if (frame.verdict == "applied") out.push_back(frame);
  return out;
}

std::vector<GadgetControl> GadgetReport::controlsOf(int request) const {
  std::vector<GadgetControl> out;
  for (const GadgetControl& control : controls)
    if (control.request == request) out.push_back(control);
  return out;
}

bool GadgetReport::hasEvent(const std::string& name) const {
  for (const GadgetEvent& event : events)
    if (event.name == name) return true;
  return false;
}

GadgetBoard::GadgetBoard(const std::string& serial, const std::vector<std::string>& arguments) : serial_(serial) {
  int in[2], out[2];
  if (::pipe2(in, O_CLOEXEC) != 0 || ::pipe2(out, O_CLOEXEC) != 0) throw std::runtime_error("pipe");
  std::vector<std::string> argv{KF_BOARD_GADGET, "--serial", serial, "--name", kGadgetName};
  argv.insert(argv.end(), arguments.begin(), arguments.end());
  pid_ = ::fork();
  if (pid_ < 0) throw std::runtime_error("fork");
  if (pid_ == 0) {
    ::dup2(in[0], STDIN_FILENO);
    ::dup2(out[1], STDOUT_FILENO);
    std::vector<char*> raw;
    for (std::string& word : argv) raw.push_back(word.data());
    raw.push_back(nullptr);
    ::execv(raw[0], raw.data());
    ::_exit(127);
  }
  ::close(in[0]);
  ::close(out[1]);
  toGadget_ = in[1];
  fromGadget_ = out[0];
  const std::string ready = command("");  // its first line, once bound
  std::istringstream words(ready);
  std::string word;
  words >> word >> udc_;
  if (word != "ready") throw std::runtime_error("kf_board_gadget did not start: " + ready);
  if (!waitConfigured()) throw std::runtime_error("the host did not configure the gadget board");
}

bool GadgetBoard::waitConfigured() {
  const bool configured = waitUntil(
      [this] {
        for (const auto& entry : std::filesystem::directory_iterator("/sys/bus/usb/devices")) {
          const std::string dir = entry.path().string();
          if (readFirstLine(dir + "/idVendor") == "1209" && readFirstLine(dir + "/idProduct") == "0001" &&
              readFirstLine(dir + "/serial") == serial_ && readFirstLine(dir + "/bConfigurationValue") == "1")
            return true;
        }
        return false;
      },
      30.0);
  if (configured) udevSettle();
  return configured;
}

GadgetBoard::~GadgetBoard() {
  if (pid_ <= 0) return;
  const std::string quit = "quit\n";
  (void)::write(toGadget_, quit.data(), quit.size());
  ::close(toGadget_);
  int status = 0;
  const bool ended = waitUntil([&] { return ::waitpid(pid_, &status, WNOHANG) == pid_; }, kAnswerGuardMs / 1000.0);
  if (!ended) {
    std::fprintf(stderr, "kf_board_gadget did not quit: %s; killed\n", whereItWaits().c_str());
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, &status, 0);
  }
  ::close(fromGadget_);
}

std::string GadgetBoard::whereItWaits() const {
  // The kernel's view of a process that does not answer: where each of its threads sleeps.
  std::string where;
  for (const auto& task : std::filesystem::directory_iterator("/proc/" + std::to_string(pid_) + "/task")) {
    std::ifstream stack(task.path().string() + "/stack");
    std::string line, frames;
    for (int i = 0; i < 8 && std::getline(stack, line); ++i) frames += (frames.empty() ? "" : " < ") + line;
    where += "[thread " + task.path().filename().string() + ": " + readFirstLine(task.path().string() + "/wchan") +
             ": " + frames + "] ";
  }
  return where;
}

std::string GadgetBoard::command(const std::string& line) {
  if (!line.empty()) {
    const std::string text = line + "\n";
    if (::write(toGadget_, text.data(), text.size()) != static_cast<ssize_t>(text.size()))
      throw std::runtime_error("the gadget's console is closed");
  }
  const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(kAnswerGuardMs);
  for (;;) {
    const size_t newline = buffered_.find('\n');
    if (newline != std::string::npos) {
      const std::string answer = buffered_.substr(0, newline);
      buffered_.erase(0, newline + 1);
      if (!line.empty() && answer.rfind("ok", 0) != 0)
        throw std::runtime_error("kf_board_gadget: '" + line + "' answered: " + answer);
      return answer;
    }
    pollfd fd{fromGadget_, POLLIN, 0};
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(end - std::chrono::steady_clock::now());
    if (left.count() <= 0 || ::poll(&fd, 1, static_cast<int>(left.count())) <= 0)
      throw std::runtime_error("kf_board_gadget did not answer '" + line + "': " + whereItWaits());
    char chunk[256];
    const ssize_t got = ::read(fromGadget_, chunk, sizeof chunk);
    if (got <= 0) throw std::runtime_error("kf_board_gadget ended (before answering '" + line + "')");
    buffered_.append(chunk, static_cast<size_t>(got));
  }
}

GadgetReport GadgetBoard::report() {
  const std::string path = "/tmp/kf-gadget-report-" + std::to_string(++reports_) + ".txt";
  command("report " + path);
  GadgetReport report;
  std::ifstream in(path);
  std::string kind, line;
  while (std::getline(in, line)) {
    std::istringstream words(line);
    words >> kind;
    if (kind == "frame") {
      GadgetFrame f{};
      words >> f.timeNs >> f.bytes >> f.sequence >> f.drive >> f.verdict >> f.validFrames;
      report.frames.push_back(f);
    } else if (kind == "level") {
      int64_t timeNs = 0;
      unsigned index = 0, drive = 0;
      words >> timeNs >> index >> drive;
      if (!report.frames.empty()) report.frames.back().levels.push_back(static_cast<uint16_t>(drive));
    } else if (kind == "target") {
      GadgetTarget t{};
      words >> t.timeNs >> t.drive >> t.why;
      report.targets.push_back(t);
    } else if (kind == "control") {
      GadgetControl c{};
      std::string outcome;
      words >> c.timeNs >> c.request >> c.value >> outcome;
      c.stalled = outcome == "stall";
      report.controls.push_back(c);
    } else if (kind == "event") {
      GadgetEvent e{};
      words >> e.timeNs >> e.name;
      report.events.push_back(e);
    } else if (kind == "status") {
      GadgetStatusTaken s{};
      words >> s.timeNs >> s.builtNs >> s.lastSequence >> s.framesReceived;
      report.statuses.push_back(s);
    } else if (kind == "ticks") {
      std::string word;
      words >> report.ticks >> word >> report.missedTicks >> word >> report.tickLateMaxNs >> word >> report.dropped >>
          word >> report.statusReplaced >> word >> report.statusCancelMaxNs;
    }
  }
  ::unlink(path.c_str());
  return report;
}

std::string GadgetBoard::gadgetDir() const { return std::string("/sys/kernel/config/usb_gadget/") + kGadgetName; }

void GadgetBoard::unplug() { writeFile(gadgetDir() + "/UDC", ""); }

void GadgetBoard::plug() {
  writeFile(gadgetDir() + "/UDC", udc_);
  if (!waitConfigured()) throw std::runtime_error("the host did not configure the gadget board after its plug");
}

void GadgetBoard::setSerial(const std::string& serial) {
  writeFile(gadgetDir() + "/strings/0x409/serialnumber", serial);
  serial_ = serial;
}

}  // namespace kf::guest

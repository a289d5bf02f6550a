// kf_board_gadget: the friction board's firmware (BoardFirmware, the code the emulator runs)
// as a USB gadget on Linux, through configfs and FunctionFS: a reference firmware for any Linux
// board with a USB device port (PROTOCOL.md, "The gadget: a reference firmware on Linux"), and
// the board the kernel tests talk to through dummy_hcd (tests/kernel/test_board_gadget.cpp).
//
//   kf_board_gadget [--serial S] [--name N] [--udc UDC] [--pwm DIR] [--pwm-period-ns NS]
//                   [--temperature FILE] [--full-scale-ma MA] [--priority P]
//
// Runs as root until it reads "quit" or end of input on stdin, or gets SIGINT or SIGTERM. Once
// the gadget is bound it prints "ready <udc> <serial>". Its console, one command a line on
// stdin, each answered with one line on stdout ("ok ...", or "error <reason>"):
//   report PATH        what the board saw since the last report (GadgetLog), into PATH
//   reading off|on     stop and resume reading set-points (a board that stops reading)
//   halt out|in        halt EP 0x01 or EP 0x81
//   quit
#include <signal.h>
#include <sys/mman.h>
#include <sys/signalfd.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>

#include "board/BoardFirmware.hpp"
#include "board/gadget/FunctionFsBoard.hpp"
#include "board/gadget/GadgetCoil.hpp"
#include "board/gadget/GadgetConfigfs.hpp"
#include "board/gadget/GadgetLog.hpp"
#include "core/threads/ThreadScheduling.hpp"

using namespace kf::board;
using namespace kf::board::gadget;

namespace {

struct Options {
  GadgetIdentity identity;
  std::string udc;
  CoilPins pins;
  unsigned fullScaleMa = 500;  // docs/current-source.md: 0.5 A at 5 V in
  int priority = kf::kAutoPriority;
};

[[noreturn]] void usage(const char* why) {
  std::fprintf(stderr,
               "kf_board_gadget: %s\nusage: kf_board_gadget [--serial S] [--name N] [--udc UDC] [--pwm DIR] "
               "[--pwm-period-ns NS] [--temperature FILE] [--full-scale-ma MA] [--priority P]\n",
               why);
  std::exit(2);
}

Options parse(int argc, char** argv) {
  Options options;
  for (int i = 1; i < argc; ++i) {
    const std::string name = argv[i];
    if (i + 1 >= argc) usage(("no value for " + name).c_str());
    const std::string value = argv[++i];
    if (name == "--serial")
      options.identity.serial = value;
    else if (name == "--name")
      options.identity.name = value;
    else if (name == "--udc")
      options.udc = value;
    else if (name == "--pwm")
      options.pins.pwmDir = value;
    else if (name == "--pwm-period-ns")
      options.pins.pwmPeriodNs = std::strtoull(value.c_str(), nullptr, 10);
    else if (name == "--temperature")
      options.pins.temperatureFile = value;
    else if (name == "--full-scale-ma")
      options.fullScaleMa = static_cast<unsigned>(std::strtoul(value.c_str(), nullptr, 10));
    else if (name == "--priority")
      options.priority = std::atoi(value.c_str());
    else
      usage(("unknown option " + name).c_str());
  }
  if (options.pins.pwmPeriodNs == 0 || options.fullScaleMa > 65535)
    usage("a PWM period of 0, or a full scale > 65535 mA");
  return options;
}

// One console command; false: quit.
bool command(const std::string& line, FunctionFsBoard& board, GadgetLog& log) {
  std::istringstream words(line);
  std::string verb, argument;
  words >> verb >> argument;
  std::string error;
  if (verb == "quit") return false;
  if (verb == "report") {
    const long frames = log.report(argument);
    if (frames < 0)
      std::printf("error cannot write %s\n", argument.c_str());
    else
      std::printf("ok reported %ld frames\n", frames);
  } else if (verb == "reading" && (argument == "on" || argument == "off")) {
    board.setReading(argument == "on");
    std::printf("ok reading %s\n", argument.c_str());
  } else if (verb == "halt" && (argument == "out" || argument == "in")) {
    if (board.halt(argument == "out", error))
      std::printf("ok halted %s\n", argument.c_str());
    else
      std::printf("error %s\n", error.c_str());
  } else {
    std::printf("error unknown command: %s\n", line.c_str());
  }
  std::fflush(stdout);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  const Options options = parse(argc, argv);
  // The loop's thread is the board's one thread: realtime, so that its 1 ms tick and the
  // watchdog keep time beside whatever else the Linux board runs.
  const kf::ThreadScheduling scheduling = kf::scheduleThisThread("gadget", {0, options.priority});
  ::mlockall(MCL_CURRENT | MCL_FUTURE);  // a small process: none of it pages out

  sigset_t stop;
  sigemptyset(&stop);
  sigaddset(&stop, SIGINT);
  sigaddset(&stop, SIGTERM);
  sigprocmask(SIG_BLOCK, &stop, nullptr);
  const int signals = ::signalfd(-1, &stop, SFD_CLOEXEC);

  GadgetLog log;
  GadgetCoil coil(log, options.pins);
  std::string error;
  if (!coil.open(error)) {
    std::fprintf(stderr, "kf_board_gadget: %s\n", error.c_str());
    return 1;
  }
  VersionReply version;
  version.firmwareMajor = 1;
  version.flags = 0;  // no current sensor: the status's current is the target
  version.fullScaleCurrentMa = static_cast<uint16_t>(options.fullScaleMa);
  // Up to 8 levels per frame (PROTOCOL.md 3.1): a step timer plays each at its own time.
  version.maxSubSetPoints = kMaxSubSetPoints;
  BoardFirmware firmware(coil, version, FunctionFsBoard::nowNs() * 1e-9);

  GadgetConfigfs gadget(options.identity);
  FunctionFsBoard board(gadget.functionFsDir(), firmware, log);
  if (!gadget.create(error) || !board.open(error) || !gadget.bind(options.udc, error)) {
    std::fprintf(stderr, "kf_board_gadget: %s\n", error.c_str());
    return 1;
  }
  std::fprintf(stderr, "kf_board_gadget: serial %s on %s, %s\n", options.identity.serial.c_str(),
               gadget.boundUdc().c_str(), kf::describe(scheduling).c_str());
  std::printf("ready %s %s\n", gadget.boundUdc().c_str(), options.identity.serial.c_str());
  std::fflush(stdout);

  std::string pending;
  board.run({STDIN_FILENO, signals}, [&](int fd) {
    if (fd == signals) return false;
    char chunk[512];
    const ssize_t got = ::read(STDIN_FILENO, chunk, sizeof chunk);
    if (got <= 0) return false;  // end of input: quit
    pending.append(chunk, static_cast<size_t>(got));
    for (size_t end; (end = pending.find('\n')) != std::string::npos;) {
      const std::string line = pending.substr(0, end);
      pending.erase(0, end + 1);
      if (!command(line, board, log)) return false;
    }
    return true;
  });
  // Unplugged first (the host sees the board go), then the function and the gadget are taken
  // down by their destructors; the coil's PWM is set to 0 and disabled by its own.
  gadget.unbind();
  return 0;
}

// The plugin's exit hook (plugins/DeviceSlots.cpp): when scsynth exits, every device still in a
// slot, and every device taken out of its slot whose close has not run yet (a kfClose followed
// at once by /quit), is closed, so its magnet goes off. Run in a child process, whose exit
// runs the hook; the magnet's drive-offs are written to a pipe.
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cstdlib>
#include <memory>
#include <string>

#include "DeviceSlots.hpp"
#include "ReplayBackend.hpp"

namespace {

class PipeSink : public kf::ForceBackend {
 public:
  PipeSink(int fd, char name) : fd_(fd), name_(name) {}
  void commandForce(double, float) override {}
  void driveOff() override { (void)!write(fd_, &name_, 1); }

 private:
  int fd_;
  char name_;
};

kf::Device* newDevice(int fd, char name) {
  auto device = new kf::Device(kf::DeviceSpec{}, std::make_shared<kf::ReplayBackend>(std::vector<kf::TimedReport>{}),
                               std::make_shared<PipeSink>(fd, name), false);
  device->start();
  return device;
}

}  // namespace

TEST_CASE("server exit closes open devices and those whose close has not finished", "[safety]") {
  int fds[2];
  REQUIRE(pipe(fds) == 0);
  const pid_t child = fork();
  REQUIRE(child >= 0);
  if (child == 0) {
    close(fds[0]);
    kf::sc::exchangeSlot(5, newDevice(fds[1], 'a'));  // open at exit
    kf::sc::exchangeSlot(6, newDevice(fds[1], 'b'));
    kf::sc::exchangeSlot(6, nullptr);  // kfClose's RT stage ran, its NRT stage (delete) did not
    kf::sc::exchangeSlot(7, newDevice(fds[1], 'c'));
    kf::sc::deleteRetired(kf::sc::exchangeSlot(7, nullptr));  // a close that finished: 'c' now
    std::exit(0);                                             // static destructors: the exit hook
  }
  close(fds[1]);
  std::string offs;
  char buffer[16];
  for (ssize_t n; (n = read(fds[0], buffer, sizeof buffer)) > 0;) offs.append(buffer, static_cast<size_t>(n));
  close(fds[0]);
  int status = 0;
  REQUIRE(waitpid(child, &status, 0) == child);
  CHECK(WIFEXITED(status));
  CHECK(WEXITSTATUS(status) == 0);
  // Each magnet went off exactly once: 'c' at its close, 'a' and 'b' by the exit hook.
  CHECK(offs.size() == 3);
  CHECK(offs.find('a') != std::string::npos);
  CHECK(offs.find('b') != std::string::npos);
  CHECK(offs.find('c') == 0);
}

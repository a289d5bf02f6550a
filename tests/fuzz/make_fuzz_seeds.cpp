// Writes the seed corpora of the fuzz targets from real data: the report descriptors and
// files of the hid-recorder recordings given as arguments, a kf-session recording of the
// simulated device (made by the device library itself), and the OSC bodies of the device
// commands as FrictionDevice sends them.
// Usage: make_fuzz_seeds <out-dir> <file.hid>...
#include <sys/stat.h>

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "DeviceFactory.hpp"
#include "recordings/HidRecorderFile.hpp"

namespace {

void writeBytes(const std::string& path, const std::string& bytes) { std::ofstream(path, std::ios::binary) << bytes; }

std::string readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// An OSC message body from its tags on.
class Osc {
 public:
  Osc& i(int32_t v) { return add('i', be32(static_cast<uint32_t>(v))); }
  Osc& f(float v) {
    uint32_t bits;
    std::memcpy(&bits, &v, 4);
    return add('f', be32(bits));
  }
  Osc& s(const std::string& v) {
    std::string bytes = v + '\0';
    while (bytes.size() % 4) bytes += '\0';
    return add('s', bytes);
  }
  std::string body() const {
    std::string all = "," + tags_ + '\0';
    while (all.size() % 4) all += '\0';
    return all + data_;
  }

 private:
  static std::string be32(uint32_t v) { return std::string{char(v >> 24), char(v >> 16), char(v >> 8), char(v)}; }
  Osc& add(char tag, const std::string& bytes) {
    tags_ += tag;
    data_ += bytes;
    return *this;
  }
  std::string tags_, data_;
};

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s <out-dir> <file.hid>...\n", argv[0]);
    return 2;
  }
  const std::string out = argv[1];
  for (const char* dir :
       {"", "/hid_descriptor", "/hid_recorder", "/session_file", "/command_args", "/calibration_table"})
    ::mkdir((out + dir).c_str(), 0755);

  for (int i = 2; i < argc; ++i) {
    kf::HidRecording recording;
    std::string error;
    if (!kf::readHidRecorderFile(argv[i], recording, error)) {
      std::fprintf(stderr, "%s\n", error.c_str());
      return 1;
    }
    const std::string name = std::to_string(i - 1);
    writeBytes(out + "/hid_descriptor/" + name, std::string(recording.descriptor.begin(), recording.descriptor.end()));
    // The recorder seeds: the head of the file (whole lines), small enough to mutate quickly.
    const std::string text = readAll(argv[i]);
    const size_t cut = text.rfind('\n', 6000);
    writeBytes(out + "/hid_recorder/" + name, text.substr(0, cut == std::string::npos ? text.size() : cut + 1));
  }

  // A lockstep sim recording: reports, frames at changing forces, an off record.
  auto device = kf::openSimDevice(kf::DeviceSpec{}, kf::SimParams{}, kf::HandScript::speeds({{80.0, 0.3}}), true);
  std::string error;
  const std::string session = out + "/session_file/sim";
  if (!device || !device->startRecording(session, error)) {
    std::fprintf(stderr, "cannot record the seed session: %s\n", error.c_str());
    return 1;
  }
  for (int ms = 1; ms <= 100; ++ms) {
    device->pushForceFrame(kf::ForceFrame{ms * 0.001, ms < 50 ? 0.4f : 1.2f});
    device->pump(ms * 0.001);
  }
  device->close();

  const std::vector<std::string> commands = {
      Osc().i(0).i(1).i(4).f(50.f).f(1.5f).f(20.f).f(0.5f).s("maxForceN").f(1.0f).body(),
      Osc().i(0).i(2).i(1).f(1.4f).s("stepS").f(1e-4f).body(),
      Osc().i(0).i(-1).i(0).body(),
      Osc().i(2).s("/tmp/session.txt").s("countMm").f(0.021f).body(),
      Osc().i(1).s("/tmp/record.txt").body(),
      Osc().i(1).s("").body(),
      Osc().i(15).body(),
  };
  for (size_t i = 0; i < commands.size(); ++i) writeBytes(out + "/command_args/" + std::to_string(i), commands[i]);
  writeBytes(out + "/calibration_table/board",
             "kf-calibration 1\nserial KF-0001\n# drive force\n0 0.14\n0.25 0.41\n0.5 0.72\n1 1.3\n");
  writeBytes(out + "/calibration_table/flat", "kf-calibration 1\n0 0.14\n0.5 0.14\n1 1.4\n");
  return 0;
}

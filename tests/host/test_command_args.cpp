// Issue 13, item 5: the plugin commands' arguments are checked before they are read — never
// past the packet — and every refusal says what is wrong (host/CommandArgs.hpp).
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "CommandArgs.hpp"

using namespace kf::sc;

namespace {

// An OSC message body from the type tags on, built argument by argument.
class Message {
 public:
  Message& i(int32_t v) { return add('i', be32(static_cast<uint32_t>(v))); }
  Message& f(float v) {
    uint32_t bits;
    std::memcpy(&bits, &v, 4);
    return add('f', be32(bits));
  }
  Message& d(double v) {
    uint64_t bits;
    std::memcpy(&bits, &v, 8);
    std::string bytes = be32(static_cast<uint32_t>(bits >> 32)) + be32(static_cast<uint32_t>(bits));
    return add('d', bytes);
  }
  Message& s(const std::string& v) {
    std::string bytes = v + '\0';
    while (bytes.size() % 4) bytes += '\0';
    return add('s', bytes);
  }
  // The whole body; `cutBytes` removes that many bytes from its end.
  std::vector<char> bytes(size_t cutBytes = 0) const {
    std::string all = "," + tags_ + '\0';
    while (all.size() % 4) all += '\0';
    all += data_;
    all.resize(all.size() - cutBytes);
    return std::vector<char>(all.begin(), all.end());  // exactly sized: ASan sees any overread
  }

 private:
  static std::string be32(uint32_t v) { return std::string{char(v >> 24), char(v >> 16), char(v >> 8), char(v)}; }
  Message& add(char tag, const std::string& bytes) {
    tags_ += tag;
    data_ += bytes;
    return *this;
  }
  std::string tags_, data_;
};

double* storage(void* context, int count) {
  auto* values = static_cast<std::vector<double>*>(context);
  values->assign(static_cast<size_t>(count), 0.0);
  return values->data();
}

struct Parsed {
  bool ok;
  std::string error;
  CommandArgs args;
  std::vector<double> values;
};

Parsed parse(CommandShape shape, const std::vector<char>& bytes) {
  Parsed parsed{};
  char error[200];
  OscArgReader reader = OscArgReader::fromMessage(bytes.data(), bytes.size());
  parsed.ok = parseCommandArgs(shape, reader, 16, parsed.args, storage, &parsed.values, error, sizeof error);
  parsed.error = error;
  return parsed;
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

TEST_CASE("well-formed commands as sclang sends them", "[commands]") {
  Parsed sim =
      parse(CommandShape::kOpenSim,
            Message().i(3).i(1).i(4).f(50.f).f(1.5f).f(20.f).f(0.5f).s("maxForceN").f(1.0f).s("stepS").d(1e-5).bytes());
  REQUIRE(sim.ok);
  CHECK(sim.args.index == 3);
  CHECK(sim.args.kind == 1);
  REQUIRE(sim.args.numValues == 4);
  CHECK(sim.args.values[2] == 20.0);
  REQUIRE(sim.args.numOverrides == 2);
  CHECK(std::string(sim.args.keys[1]) == "stepS");
  CHECK(sim.args.overrideValues[1] == 1e-5);

  CHECK(parse(CommandShape::kOpenSim, Message().i(0).i(-1).i(0).bytes()).ok);
  Parsed replay = parse(CommandShape::kOpenReplay, Message().i(2).s("/tmp/a b.hid").bytes());
  REQUIRE(replay.ok);
  CHECK(std::string(replay.args.path) == "/tmp/a b.hid");
  Parsed stop = parse(CommandShape::kRecord, Message().f(1.0f).s("").bytes());
  REQUIRE(stop.ok);
  CHECK(stop.args.path[0] == '\0');
  CHECK(parse(CommandShape::kIndex, Message().i(15).bytes()).ok);
}

TEST_CASE("a packet cut inside its path string is refused, not read past", "[commands]") {
  const std::vector<char> whole = Message().i(0).s("/tmp/a-recording.txt").bytes();
  for (size_t cut = 1; cut <= 24; ++cut) {
    INFO(cut);
    Parsed parsed = parse(CommandShape::kOpenReplay, Message().i(0).s("/tmp/a-recording.txt").bytes(cut));
    if (cut <= 3) {  // only padding zeros cut: the string still ends inside the packet
      CHECK(parsed.ok);
    } else {
      CHECK_FALSE(parsed.ok);
      CHECK(contains(parsed.error, "cut short"));
    }
  }
  // Tags that do not end, a data part shorter than an int.
  CHECK_FALSE(parse(CommandShape::kIndex, std::vector<char>{',', 'i', 'i', 'i'}).ok);
  CHECK_FALSE(parse(CommandShape::kIndex, std::vector<char>{',', 'i', 0, 0, 0, 0}).ok);
  CHECK_FALSE(parse(CommandShape::kIndex, std::vector<char>{}).ok);
}

TEST_CASE("device indices: non-finite, fractional, out of range or not numbers", "[commands]") {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  for (double bad : {nan, inf, -inf, 1e30, 4294967296.0, -1.0, 16.0, 1.5}) {
    INFO(bad);
    Parsed parsed = parse(CommandShape::kIndex, Message().d(bad).bytes());
    CHECK_FALSE(parsed.ok);
    CHECK(contains(parsed.error, "is not a slot number 0..15"));
  }
  CHECK(parse(CommandShape::kIndex, Message().f(std::nanf("")).bytes()).error ==
        "device index nan is not a slot number 0..15");
  CHECK(parse(CommandShape::kIndex, Message().s("zero").bytes()).error == "device index: a string, not a number");
  CHECK(parse(CommandShape::kIndex, Message().bytes()).error == "device index: missing");
  CHECK(contains(parse(CommandShape::kIndex, Message().i(1).i(2).bytes()).error, "unexpected argument 2"));
}

TEST_CASE("kfStatus posts by default, post 0 asks for the figures only", "[commands]") {
  Parsed plain = parse(CommandShape::kStatus, Message().i(2).bytes());
  REQUIRE(plain.ok);
  CHECK(plain.args.numbers[0] == 1.0);
  Parsed quiet = parse(CommandShape::kStatus, Message().i(2).i(0).bytes());
  REQUIRE(quiet.ok);
  CHECK(quiet.args.numbers[0] == 0.0);
  CHECK_FALSE(parse(CommandShape::kStatus, Message().i(2).f(0.5f).bytes()).ok);
  CHECK_FALSE(parse(CommandShape::kStatus, Message().i(2).i(2).bytes()).ok);
  CHECK(contains(parse(CommandShape::kStatus, Message().i(2).i(0).i(0).bytes()).error, "unexpected argument 3"));
}

TEST_CASE("kfHeartbeat: a beat alone, or the client watch's timeout in s (0 none)", "[commands]") {
  Parsed beat = parse(CommandShape::kHeartbeat, Message().i(1).bytes());
  REQUIRE(beat.ok);
  CHECK(beat.args.numbers[0] == -1.0);
  Parsed watch = parse(CommandShape::kHeartbeat, Message().i(1).f(2.5f).bytes());
  REQUIRE(watch.ok);
  CHECK(watch.args.numbers[0] == 2.5);
  CHECK(parse(CommandShape::kHeartbeat, Message().i(1).i(0).bytes()).args.numbers[0] == 0.0);
  CHECK(contains(parse(CommandShape::kHeartbeat, Message().i(1).f(-1.0f).bytes()).error, "out of range 0..3600"));
  CHECK_FALSE(parse(CommandShape::kHeartbeat, Message().i(1).f(std::nanf("")).bytes()).ok);
  CHECK_FALSE(parse(CommandShape::kHeartbeat, Message().i(1).s("2").bytes()).ok);
  CHECK(contains(parse(CommandShape::kHeartbeat, Message().i(1).i(1).i(1).bytes()).error, "unexpected argument"));
}

TEST_CASE("hand script counts must match the values sent", "[commands]") {
  // Count 4, two values, then a key: the key used to be eaten as a value.
  Parsed short_ = parse(CommandShape::kOpenSim, Message().i(0).i(0).i(4).f(0.f).f(0.f).s("maxForceN").f(1.f).bytes());
  CHECK_FALSE(short_.ok);
  CHECK(contains(short_.error, "hand script value 3 of 4: a string, not a number"));
  CHECK(contains(parse(CommandShape::kOpenSim, Message().i(0).i(1).i(3).f(1).f(2).f(3).bytes()).error, "pairs"));
  CHECK(contains(parse(CommandShape::kOpenSim, Message().i(0).i(1).i(9000).bytes()).error, "out of range 0..8192"));
  CHECK(contains(parse(CommandShape::kOpenSim, Message().i(0).i(8).i(0).bytes()).error, "kind 8"));
  CHECK(contains(parse(CommandShape::kOpenSim, Message().i(0).f(NAN).i(0).bytes()).error, "kind nan"));
  CHECK(contains(parse(CommandShape::kOpenSim, Message().i(0).i(2).i(2).f(1).f(1).bytes()).error, "takes 1 value"));
  // The 2D scripts: path2D in triples, line and circle 5 values, raster 6.
  CHECK(contains(parse(CommandShape::kOpenSim, Message().i(0).i(3).i(4).f(0).f(0).f(0).f(1).bytes()).error, "triples"));
  CHECK(parse(CommandShape::kOpenSim, Message().i(0).i(3).i(3).f(0).f(1).f(2).bytes()).ok);
  CHECK(contains(parse(CommandShape::kOpenSim, Message().i(0).i(4).i(4).f(0).f(0).f(0).f(1).bytes()).error,
                 "takes 5 values"));
  CHECK(parse(CommandShape::kOpenSim, Message().i(0).i(5).i(5).f(0).f(0).f(10).f(50).f(1).bytes()).ok);
  CHECK(contains(parse(CommandShape::kOpenSim, Message().i(0).i(6).i(5).f(0).f(0).f(10).f(5).f(2).bytes()).error,
                 "takes 6 values"));
  // The exploring participant: 9 values.
  CHECK(contains(parse(CommandShape::kOpenSim, Message().i(0).i(7).i(2).f(0).f(10).bytes()).error, "takes 9 values"));
  Message explore;
  explore.i(0).i(7).i(9);
  for (float v : {0.f, 10.f, 5.f, 50.f, 3.f, 1.f, 1.5f, 10.f, 1.f}) explore.f(v);
  CHECK(parse(CommandShape::kOpenSim, explore.bytes()).ok);
}

TEST_CASE("settings: at most 32, each a name with a number", "[commands]") {
  Message many;
  many.i(0).s("/tmp/x");
  for (int i = 0; i < 32; ++i) many.s("countMm").f(0.02f);
  CHECK(parse(CommandShape::kOpenReplay, many.bytes()).ok);
  many.s("countMm").f(0.02f);
  CHECK(parse(CommandShape::kOpenReplay, many.bytes()).error == "more than 32 settings");
  CHECK(contains(parse(CommandShape::kOpenReplay, Message().i(0).s("/x").s("countMm").bytes()).error,
                 "setting 'countMm' has no numeric value (missing)"));
  CHECK(contains(parse(CommandShape::kOpenReplay, Message().i(0).s("/x").f(1).f(2).bytes()).error,
                 "a setting name was expected"));
  CHECK(contains(parse(CommandShape::kOpenReplay, Message().i(0).s("/x").s(std::string(60, 'k')).f(2).bytes()).error,
                 "setting name of 60 characters"));
}

TEST_CASE("paths longer than 1023 characters are refused, not cut", "[commands]") {
  const std::string longest(1023, 'p');
  Parsed ok = parse(CommandShape::kRecord, Message().i(0).s(longest).bytes());
  REQUIRE(ok.ok);
  CHECK(std::string(ok.args.path) == longest);
  Parsed tooLong = parse(CommandShape::kRecord, Message().i(0).s(longest + "q").bytes());
  CHECK_FALSE(tooLong.ok);
  CHECK(tooLong.error == "path of 1024 characters is longer than 1023");
  CHECK(parse(CommandShape::kOpenReplay, Message().i(0).s("").bytes()).error == "path: empty");
}

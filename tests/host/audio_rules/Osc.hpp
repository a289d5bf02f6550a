// An OSC message as scsynth hands one to a plugin command (/cmd name args...): the type tags
// (",s" for the name, then one per argument), then the name and the arguments, big-endian, each
// padded to 4 bytes. The command function gets an sc_msg_iter over it, past the name.
#pragma once

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace kf::rules {

class OscMessage {
 public:
  explicit OscMessage(std::string command) : command_(std::move(command)) { appendString(data_, command_); }

  OscMessage& i(int32_t value) {
    tags_ += 'i';
    appendWord(static_cast<uint32_t>(value));
    return *this;
  }
  OscMessage& f(float value) {
    uint32_t word;
    std::memcpy(&word, &value, sizeof word);
    tags_ += 'f';
    appendWord(word);
    return *this;
  }
  OscMessage& s(const std::string& value) {
    tags_ += 's';
    appendString(data_, value);
    return *this;
  }

  const std::string& command() const { return command_; }
  // What the scenario's messages say, for reports: the name and the tags.
  std::string describe() const { return command_ + " " + tags_; }

  std::vector<char> bytes() const {
    std::vector<char> bytes;
    appendString(bytes, tags_);
    bytes.insert(bytes.end(), data_.begin(), data_.end());
    return bytes;
  }

 private:
  static void appendString(std::vector<char>& to, const std::string& text) {
    to.insert(to.end(), text.begin(), text.end());
    to.insert(to.end(), 4 - text.size() % 4, '\0');  // the terminator, then padding to 4 bytes
  }
  void appendWord(uint32_t word) {
    for (int shift = 24; shift >= 0; shift -= 8) data_.push_back(static_cast<char>((word >> shift) & 0xff));
  }

  std::string command_;
  std::string tags_ = ",s";
  std::vector<char> data_;
};

}  // namespace kf::rules

#include "core/force/TableLines.hpp"

namespace kf {

bool TableLines::next(std::istringstream& fields, std::string& first) {
  std::string line;
  while (std::getline(lines_, line)) {
    ++lineNumber_;
    const size_t hash = line.find('#');
    if (hash != std::string::npos) line.erase(hash);
    fields.clear();
    fields.str(line);
    if (!(fields >> first)) continue;  // blank or comment
    if (haveHeader_) return true;
    int version = 0;
    if (first != name_ || !(fields >> version))
      failure_ = error(std::string("expected the header \"") + name_ + " " + std::to_string(version_) + "\"");
    else if (version != version_)
      failure_ =
          error(std::string(what_) + " version " + std::to_string(version) + " is not " + std::to_string(version_));
    if (!failure_.empty()) return false;
    haveHeader_ = true;
  }
  if (!haveHeader_)
    failure_ = std::string("empty file: expected the header \"") + name_ + " " + std::to_string(version_) + "\"";
  return false;
}

std::string TableLines::error(const std::string& what) const {
  return "line " + std::to_string(lineNumber_) + ": " + what;
}

}  // namespace kf

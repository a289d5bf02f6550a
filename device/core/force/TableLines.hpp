// TableLines: the lines of a file in the repository's small table formats (docs/calibration-format.md,
// docs/drive-format.md): a header "<name> <version>" first; '#' starts a comment to the end of
// the line; blank lines are skipped; fields are split on whitespace. Errors name their line.
#pragma once

#include <sstream>
#include <string>

namespace kf {

class TableLines {
 public:
  // `name`: the header's word ("kf-drive"); `what`: the format in messages ("drive format").
  TableLines(const std::string& text, const char* name, int version, const char* what)
      : lines_(text), name_(name), what_(what), version_(version) {}

  // The next line after the header that has fields: `fields` reads them, `first` is the first.
  // False at the end of the text, or with error() set when the header is missing or wrong.
  bool next(std::istringstream& fields, std::string& first);

  // "line <n>: <what>" for the line read last.
  std::string error(const std::string& what) const;
  // Set by next(): the header was wrong, or the text ended without one.
  const std::string& failure() const { return failure_; }

 private:
  std::istringstream lines_;
  const char* name_;
  const char* what_;
  int version_;
  int lineNumber_ = 0;
  bool haveHeader_ = false;
  std::string failure_;
};

}  // namespace kf

#include "mouse/MouseProfile.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <initializer_list>
#include <locale>
#include <sstream>

namespace kf {

namespace {

std::string trim(const std::string& text) {
  const size_t first = text.find_first_not_of(" \t\r");
  if (first == std::string::npos) return {};
  return text.substr(first, text.find_last_not_of(" \t\r") - first + 1);
}

bool parsePositive(const std::string& text, double& out) {
  std::istringstream in(text);
  in.imbue(std::locale::classic());
  double value = 0.0;
  if (!(in >> value) || !(in >> std::ws).eof() || !std::isfinite(value) || value <= 0.0) return false;
  out = value;
  return true;
}

// One of two whole numbers ("0"/"1", "-1"/"1").
template <typename T>
bool parseChoice(const std::string& text, std::initializer_list<int> allowed, T& out) {
  for (int choice : allowed)
    if (text == std::to_string(choice)) {
      out = static_cast<T>(choice);
      return true;
    }
  return false;
}

bool parseHexId(const std::string& text, uint16_t& out) {
  char* end = nullptr;
  const unsigned long value = std::strtoul(text.c_str(), &end, 16);
  if (text.empty() || *end != '\0' || value > 0xFFFF) return false;
  out = static_cast<uint16_t>(value);
  return true;
}

}  // namespace

double countMmFromStroke(int64_t counts, double strokeMm) {
  if (counts == 0 || !std::isfinite(strokeMm) || strokeMm <= 0.0) return std::nan("");
  return strokeMm / std::fabs(static_cast<double>(counts));
}

double countMmFromCpi(double cpi) { return std::isfinite(cpi) && cpi > 0.0 ? 25.4 / cpi : std::nan(""); }

double MouseProfile::countMm() const { return std::isfinite(countMmX) ? countMmX : countMmFromCpi(cpi); }

bool MouseProfile::applyTo(DeviceSpec& spec) const {
  spec.swapXY = swapXY ? 1.0 : 0.0;
  spec.signX = signX;
  spec.signY = signY;
  const double mm = countMm();
  if (!std::isfinite(mm)) return false;
  spec.countMm = mm;
  spec.countMmY = std::isfinite(countMmY) ? countMmY : 0.0;  // 0: as x (cpi is the same on both)
  if (std::isfinite(updateRateHz)) spec.updateRateHz = updateRateHz;
  return true;
}

bool writeMouseProfile(const std::string& path, const MouseProfile& p, std::string& error) {
  std::ofstream out(path);
  if (!out) {
    error = "cannot write " + path;
    return false;
  }
  out.imbue(std::locale::classic());
  out.precision(10);
  char ids[64];
  std::snprintf(ids, sizeof(ids), "vendorId = %04x\nproductId = %04x\n", p.vendorId, p.productId);
  out << "# kf-mouse-profile 1\n"
      << "name = " << p.name << "\n"
      << ids << "serial = " << p.serial << "\n"
      << "surface = " << p.surface << "\n";
  auto number = [&out](const char* key, double value) {
    if (std::isfinite(value)) out << key << " = " << value << "\n";
  };
  number("cpi", p.cpi);
  number("countMmX", p.countMmX);
  number("countMmY", p.countMmY);
  number("updateRateHz", p.updateRateHz);
  out << "swapXY = " << (p.swapXY ? 1 : 0) << "\nsignX = " << p.signX << "\nsignY = " << p.signY << "\n";
  if (!out) error = "cannot write " + path;
  return static_cast<bool>(out);
}

bool readMouseProfile(const std::string& path, MouseProfile& out, std::string& error) {
  std::ifstream in(path);
  if (!in) {
    error = "cannot read the mouse profile " + path;
    return false;
  }
  out = MouseProfile{};
  std::string line;
  int lineNumber = 0;
  while (std::getline(in, line)) {
    ++lineNumber;
    const std::string content = trim(line);
    if (content.empty() || content[0] == '#') continue;
    const size_t equals = content.find('=');
    auto fail = [&](const std::string& what) {
      error = path + ":" + std::to_string(lineNumber) + ": " + what;
      return false;
    };
    if (equals == std::string::npos) return fail("not 'key = value'");
    const std::string key = trim(content.substr(0, equals)), value = trim(content.substr(equals + 1));
    bool ok = true;
    if (key == "name")
      out.name = value;
    else if (key == "serial")
      out.serial = value;
    else if (key == "surface")
      out.surface = value;
    else if (key == "vendorId")
      ok = parseHexId(value, out.vendorId);
    else if (key == "productId")
      ok = parseHexId(value, out.productId);
    else if (key == "cpi")
      ok = parsePositive(value, out.cpi);
    else if (key == "countMmX")
      ok = parsePositive(value, out.countMmX);
    else if (key == "countMmY")
      ok = parsePositive(value, out.countMmY);
    else if (key == "updateRateHz")
      ok = parsePositive(value, out.updateRateHz);
    else if (key == "swapXY")
      ok = parseChoice(value, {0, 1}, out.swapXY);
    else if (key == "signX")
      ok = parseChoice(value, {-1, 1}, out.signX);
    else if (key == "signY")
      ok = parseChoice(value, {-1, 1}, out.signY);
    if (!ok) return fail(key + " = '" + value + "' is not a valid value");
  }
  return true;
}

}  // namespace kf

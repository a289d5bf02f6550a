#include "board/gadget/FunctionFsDescriptors.hpp"

#include <linux/usb/ch9.h>
#include <linux/usb/functionfs.h>

#include <cstring>

#include "board/BoardProtocol.hpp"

namespace kf::board::gadget {

namespace {

constexpr char kInterfaceName[] = "Friction board";
constexpr uint16_t kLanguageUsEnglish = 0x0409;
constexpr uint8_t kFullSpeedInterval = 1;                    // frames of 1 ms
constexpr uint8_t kHighSpeedInterval = 4;                    // 2^(4-1) microframes of 125 us: 1 ms
constexpr uint16_t kSetPointPacket = kMaxSetPointFrameSize;  // 22 bytes: a frame of 8 levels (2.1)
constexpr uint16_t kStatusPacket = kStatusSize;

// Little-endian fields, whatever the board's processor.
void put8(std::vector<uint8_t>& out, unsigned value) { out.push_back(static_cast<uint8_t>(value)); }
void put16(std::vector<uint8_t>& out, unsigned value) {
  put8(out, value & 0xFF);
  put8(out, (value >> 8) & 0xFF);
}
void put32(std::vector<uint8_t>& out, uint32_t value) {
  put16(out, value & 0xFFFF);
  put16(out, value >> 16);
}
void set32(std::vector<uint8_t>& out, size_t at, uint32_t value) {
  for (int i = 0; i < 4; ++i) out[at + i] = static_cast<uint8_t>(value >> (8 * i));
}

void interfaceAndEndpoints(std::vector<uint8_t>& out, uint8_t interval) {
  put8(out, USB_DT_INTERFACE_SIZE);
  put8(out, USB_DT_INTERFACE);
  put8(out, kInterfaceNumber);
  put8(out, 0);  // alternate setting
  put8(out, 2);  // endpoints
  put8(out, kInterfaceClass);
  put8(out, kInterfaceSubclass);
  put8(out, kInterfaceProtocol);
  put8(out, 1);  // iInterface: the first string of the strings block
  for (const auto& [address, packet] : {std::pair<uint8_t, uint16_t>{kSetPointEndpoint, kSetPointPacket},
                                        std::pair<uint8_t, uint16_t>{kStatusEndpoint, kStatusPacket}}) {
    put8(out, USB_DT_ENDPOINT_SIZE);
    put8(out, USB_DT_ENDPOINT);
    put8(out, address);
    put8(out, USB_ENDPOINT_XFER_INT);
    put16(out, packet);
    put8(out, interval);
  }
}

}  // namespace

std::vector<uint8_t> functionFsDescriptors() {
  std::vector<uint8_t> out;
  put32(out, FUNCTIONFS_DESCRIPTORS_MAGIC_V2);
  put32(out, 0);  // length, below
  put32(out, FUNCTIONFS_HAS_FS_DESC | FUNCTIONFS_HAS_HS_DESC);
  put32(out, 3);  // full speed: the interface and its two endpoints
  put32(out, 3);  // high speed
  interfaceAndEndpoints(out, kFullSpeedInterval);
  interfaceAndEndpoints(out, kHighSpeedInterval);
  set32(out, 4, static_cast<uint32_t>(out.size()));
  return out;
}

std::vector<uint8_t> functionFsStrings() {
  std::vector<uint8_t> out;
  put32(out, FUNCTIONFS_STRINGS_MAGIC);
  put32(out, 0);  // length, below
  put32(out, 1);  // strings per language
  put32(out, 1);  // languages
  put16(out, kLanguageUsEnglish);
  out.insert(out.end(), kInterfaceName, kInterfaceName + sizeof kInterfaceName);  // with its NUL
  set32(out, 4, static_cast<uint32_t>(out.size()));
  return out;
}

}  // namespace kf::board::gadget

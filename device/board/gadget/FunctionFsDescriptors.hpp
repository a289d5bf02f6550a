// The friction board's USB function as FunctionFS takes it (PROTOCOL.md section 1): interface 0,
// vendor class ff/4b/01, EP 0x01 interrupt OUT (8 bytes, set-points) and EP 0x81 interrupt IN
// (16 bytes, status), every 1 ms at full speed (bInterval 1) and at high speed (bInterval 4: 2^3
// microframes). The device controller numbers the endpoints as its hardware allows (0x01 and
// 0x81 on most: a Raspberry Pi's dwc2; dummy_hcd gives the OUT endpoint 0x02), and the host takes
// them from the interface's descriptors. FunctionFS names the endpoint files in the descriptors'
// order: ep1 the set-points, ep2 the status. (Its virtual addresses, which would keep 0x01, make
// FunctionFS fail to enable the endpoints when the controller's numbers differ: Linux 6.1.)
#pragma once

#include <cstdint>
#include <vector>

namespace kf::board::gadget {

constexpr const char* kOutEndpointFile = "ep1";
constexpr const char* kInEndpointFile = "ep2";

// What is written to ep0 first: FunctionFS's v2 descriptor block.
std::vector<uint8_t> functionFsDescriptors();
// Then its strings block: the interface's name, in US English.
std::vector<uint8_t> functionFsStrings();

}  // namespace kf::board::gadget

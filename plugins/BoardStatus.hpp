// The friction board's lines of kfStatus (BoardCommands.cpp), and the device's frame timing.
#pragma once

namespace kf {
class Device;
}

namespace kf::sc {

// NRT stage: posts the board's telemetry when the device has a board; nothing otherwise.
void postBoardStatus(int index, Device& device);

}  // namespace kf::sc

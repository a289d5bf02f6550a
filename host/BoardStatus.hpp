// The friction board's lines of kfStatus (BoardCommands.cpp), and the device's frame timing.
#pragma once

namespace kf {
class Device;
}

namespace kf::sc {

// NRT stage: posts the force path's drive limiting and heat estimate (once there is any) and
// the board's telemetry when the device has a board.
void postBoardStatus(int index, Device& device);

}  // namespace kf::sc

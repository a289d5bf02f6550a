// DeviceMessages: how the device library tells the user of something that happened on its
// own (a recording that stopped on a write error). The host (the plugin) sets the sink; by
// default messages go to stderr. Called from the device thread or a command thread, never
// from the audio thread.
#pragma once

namespace kf {

using DeviceMessageSink = void (*)(const char* message);

void setDeviceMessageSink(DeviceMessageSink sink);
void postDeviceMessage(const char* message);

}  // namespace kf

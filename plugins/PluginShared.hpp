// What every UGen file of the plugin shares: the interface table and RT-safe posting.
#pragma once

#include <SC_PlugIn.hpp>

extern InterfaceTable* ft;

namespace kf::sc {

// Posts a message without doing I/O on the audio thread: the text is formatted into static
// storage and printed by the NRT thread (directly when rendering a Score, where there is no
// realtime audio thread to protect).
void postFromRt(World* world, const char* format, ...) __attribute__((format(printf, 2, 3)));

// Turns a unit whose RTAlloc failed into one that outputs silence, with one message.
void clearUnitOnAllocFailure(Unit* unit, const char* ugenName);

}  // namespace kf::sc

// Registration hooks, one per UGen file, called from PluginLoad.
void registerSpatialBufRd();
void registerLoudnessToFriction();
void registerFrictionMouseIn();
void registerFrictionOut();
void registerDeviceCommands();

// Asynchronous plugin commands for real mice (device/MouseDeviceFactory). As in
// DeviceCommands.cpp, the RT stage only copies arguments and swaps slot pointers; enumerating,
// opening (the reader thread starts) and closing run in the NRT stages.
//
//   kfListMice    backend path   backend "hidapi", "evdev" or "" (both); posts the mice and,
//                                if path is not empty, writes them there (one a line, tab-
//                                separated: backend index path vendor product serial
//                                interface name) for sclang to read after /done
//   kfOpenMouse   index which backend [key value]...   which: "" the first mouse, an index
//                 of kfListMice, a path, or "VVVV:PPPP[:serial]"; keys: device settings,
//                 grab (evdev: 1 keeps the desktop cursor still), profile (a string: a mouse
//                 profile file, applied before the other settings). Realtime servers only.
//   kfReopenMouse index          looks for the slot's mouse again after an unplug
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "AudioClock.hpp"
#include "DeviceSlots.hpp"
#include "MouseDeviceFactory.hpp"
#include "MouseProfile.hpp"
#include "MouseSelect.hpp"
#include "PluginShared.hpp"
#include "RealMouseBackend.hpp"

namespace {

constexpr int kMaxOverrides = 32;
constexpr int kMaxKeyChars = 48;
constexpr int kMaxTextChars = 1024;

struct MouseCommand {
  const char* name;
  int index;
  char which[kMaxTextChars];
  char backend[kMaxKeyChars];
  char path[kMaxTextChars];  // kfListMice: the answer file; kfOpenMouse: the profile file
  bool grab;
  int numOverrides;
  char keys[kMaxOverrides][kMaxKeyChars];
  double overrideValues[kMaxOverrides];
  kf::Device* device;
  kf::Device* previous;
};

void copyString(char* to, const char* from, size_t capacity) {
  std::snprintf(to, capacity, "%s", from != nullptr ? from : "");
}

MouseCommand* newCommand(World* world, const char* name) {
  auto* data = static_cast<MouseCommand*>(RTAlloc(world, sizeof(MouseCommand)));
  if (data == nullptr) {
    kf::sc::postFromRt(world, "%s: RT memory allocation failed\n", name);
    return nullptr;
  }
  data->name = name;
  data->index = -1;
  data->which[0] = data->backend[0] = data->path[0] = '\0';
  data->grab = false;
  data->numOverrides = 0;
  data->device = data->previous = nullptr;
  return data;
}

void freeCommand(World* world, void* raw) { RTFree(world, raw); }

void run(World* world, void* replyAddr, MouseCommand* data, AsyncStageFn stage2, AsyncStageFn stage3,
         AsyncStageFn stage4) {
  DoAsynchronousCommand(world, replyAddr, data->name, data, stage2, stage3, stage4, freeCommand, 0, nullptr);
}

bool checkSlot(World* world, MouseCommand* data) {
  if (kf::sc::isValidSlot(data->index)) return true;
  kf::sc::postFromRt(world, "%s: device index %d is out of range 0..%d\n", data->name, data->index,
                     kf::sc::kNumDeviceSlots - 1);
  return false;
}

bool nrtHop(World*, void*) { return true; }

// --- kfListMice ----------------------------------------------------------------------------

bool listStage(World*, void* raw) {  // NRT
  auto* data = static_cast<MouseCommand*>(raw);
  const std::string only = data->backend;
  std::ofstream answer;
  if (data->path[0] != '\0') {
    answer.open(data->path);
    if (!answer) Print("kfListMice: cannot write %s\n", data->path);
  }
  for (kf::MouseBackendKind kind : {kf::MouseBackendKind::kHidapi, kf::MouseBackendKind::kEvdev}) {
    const char* kindName = kind == kf::MouseBackendKind::kHidapi ? "hidapi" : "evdev";
    if (!only.empty() && only != kindName) continue;
    std::vector<kf::MouseInfo> mice;
    std::string error;
    const bool ok = kind == kf::MouseBackendKind::kHidapi ? kf::realHidApi()->enumerateMice(mice, error)
                                                          : kf::realEvdevApi()->enumerateMice(mice, error);
    if (!ok) {
      Print("kfListMice: %s enumeration failed: %s\n", kindName, error.c_str());
      continue;
    }
    Print("kfListMice: %s: %d mice\n", kindName, static_cast<int>(mice.size()));
    for (size_t i = 0; i < mice.size(); ++i) {
      const kf::MouseInfo& m = mice[i];
      Print("  %s\n", kf::describeMouse(static_cast<int>(i), m).c_str());
      if (answer) {
        char ids[32];
        std::snprintf(ids, sizeof(ids), "%04x\t%04x", m.vendorId, m.productId);
        const std::string name = m.manufacturer.empty() ? m.product : m.manufacturer + " " + m.product;
        answer << kindName << '\t' << i << '\t' << m.path << '\t' << ids << '\t' << m.serial << '\t'
               << m.interfaceNumber << '\t' << name << '\n';
      }
    }
  }
  return true;
}

void listMiceCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  MouseCommand* data = newCommand(world, "kfListMice");
  if (data == nullptr) return;
  copyString(data->backend, args->gets(""), kMaxKeyChars);
  copyString(data->path, args->gets(""), kMaxTextChars);
  run(world, replyAddr, data, listStage, nullptr, nullptr);
}

// --- kfOpenMouse ---------------------------------------------------------------------------

bool openStage(World* world, void* raw) {  // NRT
  auto* data = static_cast<MouseCommand*>(raw);
  if (!world->mRealTime) {
    Print("kfOpenMouse: a real mouse needs a realtime server (in a Score, replay a recording of it)\n");
    return false;
  }
  kf::MouseOpenOptions options;
  if (!kf::mouseBackendKindFromName(data->backend[0] ? data->backend : "hidapi", options.kind)) {
    Print("kfOpenMouse: unknown backend '%s' (hidapi or evdev)\n", data->backend);
    return false;
  }
  options.which = data->which;
  options.grab = data->grab;
  kf::DeviceSpec spec;
  if (data->path[0] != '\0') {
    kf::MouseProfile profile;
    std::string error;
    if (!kf::readMouseProfile(data->path, profile, error)) {
      Print("kfOpenMouse: %s\n", error.c_str());
      return false;
    }
    if (!profile.applyTo(spec)) Print("kfOpenMouse: %s has no count size (countMmX or cpi)\n", data->path);
  }
  for (int i = 0; i < data->numOverrides; ++i) {
    if (spec.applyOverride(data->keys[i], data->overrideValues[i])) continue;
    Print("kfOpenMouse: unknown setting or value out of range: %s = %g\n", data->keys[i], data->overrideValues[i]);
    return false;
  }
  if (!spec.isValid()) {
    Print("kfOpenMouse: the device settings do not fit together (check force range and rates)\n");
    return false;
  }
  std::string error;
  data->device = kf::openMouseDevice(options, spec, error).release();
  if (data->device == nullptr) {
    Print("kfOpenMouse: %s\n", error.c_str());
    return false;
  }
  Print("kfOpenMouse %d: %s\n", data->index, data->device->mouseBackend().statusLine().c_str());
  return true;
}

bool publishStage(World*, void* raw) {  // RT
  auto* data = static_cast<MouseCommand*>(raw);
  data->previous = kf::sc::exchangeSlot(data->index, data->device);
  return true;
}

bool deletePreviousStage(World*, void* raw) {  // NRT
  // Through the retired list: the exit hook must not close it a second time.
  kf::sc::deleteRetired(static_cast<MouseCommand*>(raw)->previous);
  return true;
}

void openMouseCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  MouseCommand* data = newCommand(world, "kfOpenMouse");
  if (data == nullptr) return;
  data->index = args->geti(-1);
  copyString(data->which, args->gets(""), kMaxTextChars);
  copyString(data->backend, args->gets(""), kMaxKeyChars);
  while (args->remain() > 0) {
    const char* key = args->gets(nullptr);
    if (key == nullptr) break;
    if (std::strcmp(key, "profile") == 0) {
      copyString(data->path, args->gets(""), kMaxTextChars);
    } else if (std::strcmp(key, "grab") == 0) {
      data->grab = args->getd(0.0) != 0.0;
    } else if (data->numOverrides < kMaxOverrides) {
      copyString(data->keys[data->numOverrides], key, kMaxKeyChars);
      data->overrideValues[data->numOverrides++] = args->getd(0.0);
    }
  }
  if (!checkSlot(world, data)) return freeCommand(world, data);
  run(world, replyAddr, data, openStage, publishStage, deletePreviousStage);
}

// --- kfReopenMouse -------------------------------------------------------------------------

bool lookUpDeviceStage(World*, void* raw) {  // RT
  auto* data = static_cast<MouseCommand*>(raw);
  data->device = kf::sc::peekSlot(data->index);
  return true;
}

bool reopenStage(World*, void* raw) {  // NRT
  auto* data = static_cast<MouseCommand*>(raw);
  auto* mouse = data->device ? dynamic_cast<kf::RealMouseBackend*>(&data->device->mouseBackend()) : nullptr;
  if (mouse == nullptr) {
    Print("kfReopenMouse: no mouse is open at index %d\n", data->index);
    return false;
  }
  mouse->requestReopen();
  Print("kfReopenMouse %d: looking for %s again\n", data->index, kf::reselector(mouse->info()).c_str());
  return true;
}

void reopenMouseCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  MouseCommand* data = newCommand(world, "kfReopenMouse");
  if (data == nullptr) return;
  data->index = args->geti(-1);
  if (!checkSlot(world, data)) return freeCommand(world, data);
  run(world, replyAddr, data, nrtHop, lookUpDeviceStage, reopenStage);
}

}  // namespace

void registerMouseCommands() {
  DefinePlugInCmd("kfListMice", listMiceCmd, nullptr);
  DefinePlugInCmd("kfOpenMouse", openMouseCmd, nullptr);
  DefinePlugInCmd("kfReopenMouse", reopenMouseCmd, nullptr);
}

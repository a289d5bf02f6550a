// Asynchronous plugin commands for real mice (device/MouseDeviceFactory), on the machinery of
// CommandRunner.hpp (checked arguments, /done or /kfFail, a taken slot refused unless replace).
// The RT stage only swaps slot pointers; enumerating, opening (the reader thread starts) and
// closing run in the NRT stages.
//
//   kfListMice    backend path   backend "hidapi", "evdev" or "" (both); posts the mice and,
//                                if path is not empty, writes them there (one a line, tab-
//                                separated: backend index path vendor product serial
//                                interface name) for sclang to read after /done
//   kfOpenMouse   index which backend profile [key value]...   which: "" the first mouse, an
//                 index of kfListMice, a path, or "VVVV:PPPP[:serial]"; profile: "" or a mouse
//                 profile file, applied before the settings; keys: device settings, replace,
//                 grab (evdev: 1 keeps the desktop cursor still). Realtime servers only.
//   kfReopenMouse index          looks for the slot's mouse again after an unplug
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "CommandRunner.hpp"
#include "DeviceSlots.hpp"
#include "MouseDeviceFactory.hpp"
#include "PluginShared.hpp"
#include "mouse/MouseProfile.hpp"
#include "mouse/MouseSelect.hpp"
#include "mouse/RealMouseBackend.hpp"

namespace {

using namespace kf::sc;

// --- kfListMice ----------------------------------------------------------------------------

bool listStage(World*, void* raw) {  // NRT
  auto* data = static_cast<CommandData*>(raw);
  const std::string only = data->args.backend;
  if (!only.empty() && only != "hidapi" && only != "evdev") {
    failWith(data, "kfListMice: unknown backend '%s' (hidapi, evdev, or \"\" for both)", only.c_str());
    return false;
  }
  std::ofstream answer;
  if (data->args.path[0] != '\0') {
    answer.open(data->args.path);
    if (!answer) {
      failWith(data, "kfListMice: cannot write the answer file %s", data->args.path);
      return false;
    }
  }
  for (kf::MouseBackendKind kind : {kf::MouseBackendKind::kHidapi, kf::MouseBackendKind::kEvdev}) {
    const char* kindName = kind == kf::MouseBackendKind::kHidapi ? "hidapi" : "evdev";
    if (!only.empty() && only != kindName) continue;
    std::vector<kf::MouseInfo> mice;
    std::string error;
    const bool ok = kind == kf::MouseBackendKind::kHidapi ? kf::realHidApi()->enumerateMice(mice, error)
                                                          : kf::realEvdevApi()->enumerateMice(mice, error);
    if (!ok && !only.empty()) {  // the one backend asked for: a failure
      failWith(data, "kfListMice: %s enumeration failed: %s", kindName, error.c_str());
      return false;
    }
    if (!ok) {  // one of both: the other's mice still come
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
  CommandData* data = newCommand(world, "kfListMice", CommandShape::kListMice, args);
  if (data != nullptr) run(world, replyAddr, data, listStage, nullptr, nullptr);
}

// --- kfOpenMouse ---------------------------------------------------------------------------

bool openStage(World* world, void* raw) {  // NRT
  auto* data = static_cast<CommandData*>(raw);
  if (!world->mRealTime) {
    failWith(data, "kfOpenMouse: a real mouse needs a realtime server (in a Score, replay a recording of it)");
    return false;
  }
  kf::MouseOpenOptions options;
  // An empty backend keeps options.kind at kDefaultMouseBackend (evdev on Linux).
  const char* backend = data->args.backend;
  if (backend[0] != '\0' && !kf::mouseBackendKindFromName(backend, options.kind)) {
    failWith(data, "kfOpenMouse: unknown backend '%s' (hidapi or evdev)", backend);
    return false;
  }
  options.which = data->args.which;
  kf::DeviceSpec spec;
  if (data->args.path[0] != '\0') {
    kf::MouseProfile profile;
    std::string error;
    if (!kf::readMouseProfile(data->args.path, profile, error)) {
      failWith(data, "kfOpenMouse: %s", error.c_str());
      return false;
    }
    if (!profile.applyTo(spec)) Print("kfOpenMouse: %s has no count size (countMmX or cpi)\n", data->args.path);
  }
  // grab (evdev: keep the desktop cursor still) is an option, not a device setting.
  for (int i = 0; i < data->args.numOverrides; ++i)
    if (std::strcmp(data->args.keys[i], "grab") == 0) options.grab = data->args.overrideValues[i] != 0.0;
  if (!applyOverrides(data, spec, nullptr, nullptr, "grab")) return false;
  std::string error;
  data->ownsDevice = true;
  data->device =
      kf::openMouseDevice(options, spec, error, nullptr, nullptr, nullptr, deviceOptionsOf(world, data)).release();
  if (data->device == nullptr) {
    failWith(data, "kfOpenMouse: %s", error.c_str());
    return false;
  }
  Print("kfOpenMouse %d: %s\n", data->args.index, data->device->mouseBackend().statusLine().c_str());
  return true;
}

void openMouseCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  CommandData* data = newCommand(world, "kfOpenMouse", CommandShape::kOpenMouse, args);
  if (data != nullptr) run(world, replyAddr, data, openStage, publishStage, deletePreviousStage);
}

// --- kfReopenMouse -------------------------------------------------------------------------

bool reopenStage(World*, void* raw) {  // NRT
  auto* data = static_cast<CommandData*>(raw);
  auto* mouse = data->device ? dynamic_cast<kf::RealMouseBackend*>(&data->device->mouseBackend()) : nullptr;
  if (mouse == nullptr) {
    failWith(data, "kfReopenMouse: no mouse is open at index %d", data->args.index);
    return false;
  }
  mouse->requestReopen();
  Print("kfReopenMouse %d: looking for %s again\n", data->args.index, kf::reselector(mouse->info()).c_str());
  return true;
}

void reopenMouseCmd(World* world, void*, sc_msg_iter* args, void* replyAddr) {
  CommandData* data = newCommand(world, "kfReopenMouse", CommandShape::kIndex, args);
  if (data != nullptr) run(world, replyAddr, data, nrtHop, lookUpDeviceStage, reopenStage);
}

}  // namespace

void registerMouseCommands() {
  DefinePlugInCmd("kfListMice", listMiceCmd, nullptr);
  DefinePlugInCmd("kfOpenMouse", openMouseCmd, nullptr);
  DefinePlugInCmd("kfReopenMouse", reopenMouseCmd, nullptr);
}

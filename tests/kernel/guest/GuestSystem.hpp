// GuestSystem: what the kernel group's tests ask of the guest itself, apart from the code under
// test: udev's view of a node (udevadm), an open as the seat's unprivileged user, waiting for the
// kernel and udev to finish a plug-in, and the figures a test reports (written to the results
// folder the rig brings back).
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

namespace kf::guest {

// The user the rig logs in at seat0 (GuestSpec.seat_user) and udev's uaccess grants.
constexpr unsigned kSeatUid = 1000;

// `udevadm info --query=property --name=<node>`: udev's properties of the node (TAGS, ID_INPUT_*).
std::map<std::string, std::string> udevProperties(const std::string& node);
// udev's current tags of the node (CURRENT_TAGS, else TAGS), e.g. ":seat:uaccess:".
std::string udevTags(const std::string& node);
// `udevadm settle`: every event queued so far has been handled (its rules applied).
void udevSettle();
// Opens `path` with `flags` in a child running as kSeatUid (no supplementary groups): 0 when it
// opened, else the errno (EACCES when udev did not grant it).
int openAsSeatUser(const std::string& path, int flags);
// Polls `done` every 10 ms until it is true or `hangGuardS` passed (a guard against a test
// that would hang, not a timing tolerance): whether it became true.
bool waitUntil(const std::function<bool()>& done, double hangGuardS);
// One line "<test>: <text>" in figures.txt of the results folder (KF_GUEST_RESULTS), which the
// group prints: the counts and outcomes the closing notes quote.
void reportFigure(const std::string& test, const std::string& text);
// /sys/class/input/eventN nodes whose device name is `name` (the kernel's, with hid-input's
// suffix for one application collection of several: " Mouse", " Keyboard").
std::vector<std::string> eventNodesNamed(const std::string& name);
// /dev/hidrawN of the HID device whose HID_NAME is `name`.
std::vector<std::string> hidrawNodesNamed(const std::string& name);

}  // namespace kf::guest

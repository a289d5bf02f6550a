// Signal handlers that drive every device's magnet off on the way out (ExitSafety.cpp).
#pragma once

// Installs them once per process; called when the plugin loads.
void installExitSafety();

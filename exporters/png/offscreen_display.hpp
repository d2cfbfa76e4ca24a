// The X display VTK's off-screen rendering needs on Linux (Debian's VTK 9.1 renders through GLX:
// without a reachable X server it aborts the process). The tools check first and either re-run
// themselves under xvfb-run or stop with a clear message (docs/output-formats.md, "Pictures").
#pragma once
#include <string>

namespace hm {

/// "" when $DISPLAY names an X server that accepts a connection, else the reason.
std::string display_problem();

/// Environment variable set on the re-run under xvfb-run (so that it is tried once).
inline const char* kXvfbRerunVariable = "HM_UNDER_XVFB_RUN";

/// Makes sure pictures can be rendered by this process: returns "" when the display is usable;
/// otherwise, if xvfb-run is on PATH and this is not already the re-run, replaces the process by
/// `xvfb-run -n N -a -s "-screen 0 1600x1200x24" argv...` (does not return; same arguments, same
/// exit code); otherwise returns what is wrong and what to do.
std::string ensure_display_or_rerun_under_xvfb(char** argv);

}  // namespace hm

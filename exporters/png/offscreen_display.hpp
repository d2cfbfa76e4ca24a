// The X display VTK's off-screen rendering needs on Linux (Debian's VTK 9.1 renders through GLX:
// without a reachable X server it aborts the process). The tools check first and either re-run
// themselves under xvfb-run or stop with a clear message (docs/output-formats.md, "Pictures").
#pragma once
#include <string>

namespace hm {

/// "" when $DISPLAY names an X server that accepts a connection, else the reason.
std::string display_problem();

/// An open connection to the X display, held while pictures are rendered: an X server resets when
/// its last client disconnects, and a window that connects during the reset fails (VTK aborts), so
/// the connection of each picture's window must never be the only one. Closed on destruction.
class DisplayConnection {
 public:
  DisplayConnection();  ///< connects to $DISPLAY; ok() tells whether it worked
  ~DisplayConnection();
  DisplayConnection(const DisplayConnection&) = delete;
  DisplayConnection& operator=(const DisplayConnection&) = delete;
  bool ok() const { return display_ != nullptr; }

 private:
  void* display_ = nullptr;  // Display*; Xlib stays out of the header
};

/// Environment variable set on the re-run under xvfb-run (so that it is tried once).
inline const char* kXvfbRerunVariable = "HM_UNDER_XVFB_RUN";

/// Makes sure pictures can be rendered by this process: returns "" when the display is usable;
/// otherwise, if xvfb-run is on PATH and this is not already the re-run, replaces the process by
/// `xvfb-run -n N -a -s "-screen 0 1600x1200x24 -noreset" argv...` (does not return; same arguments, same
/// exit code); otherwise returns what is wrong and what to do.
std::string ensure_display_or_rerun_under_xvfb(char** argv);

}  // namespace hm
